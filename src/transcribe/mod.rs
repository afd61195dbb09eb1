//! Audio → score: a recording of timpani (ours or a real one) transcribed into a gesture
//! score on a kit. Onsets ([`onsets`]), what each stroke added and its pitch
//! ([`notes`]), the beat and a tempo map that follows it ([`beats`]), and the strokes as
//! beats — drums, ticks, rolls, dynamics ([`notate`]). Dynamics are read against the
//! levels of timpanist's own calibrated modal strokes at each marking, so a rendering
//! reads back at its own dynamics; [`Levels::Relative`] instead takes the median stroke as
//! mf, for recordings at an unknown gain. Hands are left to the sticking, modes legato.

pub mod beats;
pub mod notate;
pub mod notes;
pub mod onsets;

use crate::base::limits::MAX_SCORE_S;
use crate::base::pitch::Pitch;
use crate::base::stats::median;
use crate::kit::Kit;
use crate::score::{Dynamic, MeterChange, Score, TempoMap};
use crate::sound::analysis;
use crate::sound::calibration::Calibration;
use crate::sound::fit;
use crate::sound::recording::{self, ReadError};
use std::collections::BTreeMap;
use std::path::Path;

/// How stroke energies become dynamics.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Levels {
    /// Against timpanist's calibrated strokes at each marking (renders read back at
    /// their own dynamics).
    #[default]
    Absolute,
    /// Shifted so the median stroke reads mf (a recording at an unknown gain).
    Relative,
}

/// How to transcribe.
#[derive(Clone, Debug)]
pub struct Options {
    /// The kit reference written into the score (`"standard"` or a path).
    pub kit_ref: String,
    /// Title of the score (default: the file name).
    pub title: Option<String>,
    pub levels: Levels,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            kit_ref: "standard".into(),
            title: None,
            levels: Levels::Absolute,
        }
    }
}

/// What a transcription found.
#[derive(Clone, Debug, PartialEq)]
pub struct Report {
    /// The file or signal transcribed, for messages.
    pub source: String,
    /// Strokes heard (a chord counts once).
    pub strokes: usize,
    /// Runs of strokes written as rolls.
    pub rolls: usize,
    /// The beat found, bpm (the first tempo of the map).
    pub bpm: f64,
    /// The recording's tuning against A4 = 440 Hz, cents.
    pub tuning_cents: f64,
    /// Strokes whose pitch no drum reaches, moved by octaves into a drum's range.
    pub octave_moves: usize,
    /// Where each stroke was heard, s (for checks and plots).
    pub onsets_s: Vec<f64>,
    /// Things the user should know.
    pub notices: Vec<String>,
}

/// Why audio could not be transcribed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum TranscribeError {
    #[error(transparent)]
    Read(#[from] ReadError),
    #[error("{file}: no strokes were heard (silence, or no clear attacks)")]
    Silent { file: String },
    #[error(
        "{file}: no strokes: what starts in it stands only {contrast_db:.1} dB above its \
         resting level (a stroke's attack stands {needed_db} dB and more above: is it noise or \
         a sustained sound?)"
    )]
    NoStrike {
        file: String,
        contrast_db: f64,
        needed_db: f64,
    },
    #[error("{file}: sample {frame} is not a finite number")]
    NonFinite { file: String, frame: usize },
    #[error("{file}: {seconds:.0} s of audio is longer than a score may last ({max:.0} s)")]
    TooLong {
        file: String,
        seconds: f64,
        max: f64,
    },
    #[error("the kit has no drums to put the strokes on")]
    NoDrums,
}

/// A recording from which fewer strokes than this are heard must stand, within
/// [`ATTACK_S`] after one of them, `analysis::min_strike_contrast_db` above its resting
/// level (dB, `analysis::attack_contrast_db`), else it is refused as holding no playing.
const MIN_STROKES_UNLESS_STRUCK: usize = 3;
const ATTACK_S: f64 = 0.05;

/// Transcribe the WAV file `path` onto `kit`.
pub fn transcribe_file(
    path: &Path,
    kit: &Kit,
    options: &Options,
) -> Result<(Score, Report), TranscribeError> {
    let (samples, rate, read_notes) = recording::read_mono_noted(path)?;
    let mut options = options.clone();
    if options.title.is_none() {
        options.title = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .filter(|s| !s.is_empty());
    }
    let (score, mut report) =
        transcribe(&samples, rate, kit, &path.display().to_string(), &options)?;
    report.notices.splice(0..0, read_notes);
    Ok((score, report))
}

/// A sound with no kettledrum pitch this far under the loudest stroke is a click, not a
/// stroke, dB (a timpani's pp stands 30–40 dB under its ff).
pub const FAINT_CLICK_DB: f64 = 45.0;
/// Anything this far under the loudest stroke is below the instrument's range: a click,
/// whatever pitch its window seems to hold (the ringing drums lend it one), dB.
pub const FAINT_STROKE_DB: f64 = 55.0;

/// Transcribe mono `samples` at `rate_hz` (named `source` in messages) onto `kit`.
pub fn transcribe(
    samples: &[f32],
    rate_hz: u32,
    kit: &Kit,
    source: &str,
    options: &Options,
) -> Result<(Score, Report), TranscribeError> {
    let source = source.to_string();
    if kit.drums.is_empty() {
        return Err(TranscribeError::NoDrums);
    }
    if let Some(frame) = samples.iter().position(|s| !s.is_finite()) {
        return Err(TranscribeError::NonFinite {
            file: source,
            frame,
        });
    }
    let seconds = samples.len() as f64 / f64::from(rate_hz.max(1));
    if seconds > MAX_SCORE_S {
        return Err(TranscribeError::TooLong {
            file: source,
            seconds,
            max: MAX_SCORE_S,
        });
    }
    let strength = onsets::strength(samples, rate_hz);
    let found: Vec<f64> = onsets::pick(&strength)
        .into_iter()
        .map(|f| onsets::place(samples, rate_hz, &strength, f))
        .collect();
    let mut times = dedup_sorted(found);
    // A head stopped by a hand is heard as a change, not as a stroke.
    times.retain(|&t| !notes::is_damping(samples, rate_hz, t));
    if times.is_empty() {
        return Err(TranscribeError::Silent { file: source });
    }
    // A sound that only starts (noise, a held tone: one "stroke" where it begins) and does
    // not stand out of its own level there is no playing; a roll keeps its level up but
    // has many strokes.
    if times.len() < MIN_STROKES_UNLESS_STRUCK
        && let Some(contrast_db) = analysis::attack_contrast_db(samples, rate_hz, &times, ATTACK_S)
        && let needed_db = analysis::min_strike_contrast_db(samples.len(), rate_hz)
        && contrast_db < needed_db
    {
        return Err(TranscribeError::NoStrike {
            file: source,
            contrast_db,
            needed_db,
        });
    }
    let band = pitch_band(kit);
    let mut strokes: Vec<notate::Stroke> = times
        .iter()
        .enumerate()
        .map(|(i, &t)| {
            let heard = notes::hear(samples, rate_hz, t, times.get(i + 1).copied(), band);
            notate::Stroke {
                time_s: t,
                principal_hz: heard.principal_hz,
                level_db: heard.level_db,
            }
        })
        .collect();
    // A stroke of a fast run heard by one of the run's upper partials is put back on the
    // run's drum (each stroke alone is heard through a window of 60–120 ms, whose 8–16 Hz
    // resolution misplaces a low drum's (1,1) by a semitone or more — a recorded D2
    // roll's first stroke reads C♯2 — or hears a partial as the (1,1)); the rolls among
    // them take their pitch once the beats are known, below.
    let heard_alone: Vec<Option<f64>> = strokes.iter().map(|s| s.principal_hz).collect();
    let runs = fast_runs(&times);
    for run in runs.clone() {
        let span = (times[run.start], times[run.end - 1]);
        if let Some(run_hz) = notes::hear_run(samples, rate_hz, span, band) {
            for stroke in &mut strokes[run] {
                stroke.principal_hz = notes::onto_run(stroke.principal_hz, run_hz);
            }
        }
    }
    // A click far under the playing (a recording quantised to 8 bits flipping its last
    // bit, a stray tick) is no stroke; a roll's strokes, each adding little to the ringing
    // it keeps up, are kept.
    let loudest = strokes
        .iter()
        .map(|s| s.level_db)
        .fold(f64::NEG_INFINITY, f64::max);
    let clicks: Vec<bool> = strokes
        .iter()
        .enumerate()
        .map(|(i, s)| {
            let below = loudest - s.level_db;
            !runs.iter().any(|r| r.contains(&i))
                && (below > FAINT_STROKE_DB || (s.principal_hz.is_none() && below > FAINT_CLICK_DB))
        })
        .collect();
    let times = kept_where(times, &clicks);
    let mut strokes = kept_where(strokes, &clicks);
    let heard_alone = kept_where(heard_alone, &clicks);
    let clicks = clicks.iter().filter(|&&c| c).count();
    let mut score = Score::new(options.title.as_deref().unwrap_or("Transcription"));
    score.kit = options.kit_ref.clone();
    let tpq = score.ticks_per_quarter;
    // One or two strokes show no beat (the autocorrelation of a stroke's decay would name
    // a tempo of its own): they are written at the prior's tempo.
    score.tempo = if times.len() < MIN_BEAT_STROKES {
        beats::tempo_map(&[], &[], tpq, 0)
    } else {
        let median_interval_s = median(times.windows(2).map(|w| w[1] - w[0])).unwrap_or(0.0);
        let period = beats::sparse_period_s(median_interval_s)
            .or_else(|| beats::period_s(&strength))
            .unwrap_or_else(beats::prior_period_s);
        let period = beats::plainest_period_s(period, &times);
        let mut beat_times = beats::track(&strength, period, &times);
        beats::snap(&mut beat_times, &times);
        // `snap` puts a beat on a stroke exactly.
        let on_stroke: Vec<bool> = (beat_times.iter())
            .map(|b| times.binary_search_by(|t| t.total_cmp(b)).is_ok())
            .collect();
        let first_tick = lead_in_ticks(beat_times[0], period, tpq);
        beats::tempo_map(&beat_times, &on_stroke, tpq, first_tick)
    };
    score.meter = vec![MeterChange {
        bar: 1,
        numerator: 4,
        denominator: 4,
    }];
    let map = TempoMap::new(&score.tempo, tpq);
    // A roll (the strokes notation writes as one, by their timing) takes the pitch heard
    // over the whole roll, moved to where its strokes alone heard it; the note it resolves
    // to on a beat (`notate::roll_spans`) keeps its own.
    let levels: Vec<f64> = strokes.iter().map(|s| s.level_db).collect();
    let on_beat =
        |k: usize| notate::quantise(&map, tpq, times[k], None).is_multiple_of(u64::from(tpq));
    for (a, b) in notate::roll_spans(&times, &levels, &|_| false, &on_beat) {
        if let Some(run_hz) = notes::hear_run(samples, rate_hz, (times[a], times[b]), band) {
            let gaps = median(times[a..=b].windows(2).map(|w| w[1] - w[0]));
            let stroke_rate_hz = gaps.map_or(f64::NAN, |g| 1.0 / g);
            let before_hz = (a > 0 && times[a] - times[a - 1] <= notes::RUN_WINDOW_S)
                .then(|| heard_alone[a - 1])
                .flatten();
            let roll_hz = notes::roll_pitch(run_hz, &heard_alone[a..=b], stroke_rate_hz, before_hz);
            for stroke in &mut strokes[a..=b] {
                stroke.principal_hz = Some(roll_hz);
            }
        }
    }

    let shift = match options.levels {
        Levels::Absolute => 0.0,
        Levels::Relative => relative_shift(&strokes, kit),
    };
    let mut table = MarkLevels::default();
    let mut marks = |p: Pitch| table.at(p).map(|l| l + shift);
    let (placed, found_notes) = notate::place(&strokes, kit, &map, tpq, &mut marks);
    let (beats, rolls) = notate::beats(&placed, kit, tpq);
    score.beats = beats;
    score.sort_beats();

    let mut notices = Vec::new();
    if clicks > 0 {
        notices.push(format!(
            "{clicks} clicks were left out: sounds {FAINT_CLICK_DB} dB or more under the \
             loudest stroke with no pitch, or {FAINT_STROKE_DB} dB or more under it"
        ));
    }
    if found_notes.octave_moves > 0 {
        notices.push(format!(
            "{} strokes were moved by octaves into a drum's range",
            found_notes.octave_moves
        ));
    }
    if found_notes.unpitched > 0 {
        notices.push(format!(
            "{} strokes had no clear pitch and were put on the previous stroke's drum",
            found_notes.unpitched
        ));
    }
    let report = Report {
        source,
        strokes: placed.len(),
        rolls,
        bpm: score.tempo.last().map_or(0.0, |p| p.bpm),
        tuning_cents: notate::tuning_offset_cents(&strokes),
        octave_moves: found_notes.octave_moves,
        onsets_s: times,
        notices,
    };
    Ok((score, report))
}

/// Sorted times with any two closer than half the onset gap merged.
fn dedup_sorted(mut times: Vec<f64>) -> Vec<f64> {
    times.sort_by(f64::total_cmp);
    times.dedup_by(|b, a| *b - *a < onsets::MIN_GAP_S / 2.0);
    times
}

/// Principal partials are sought from a fifth below the kit's lowest pitch to a fifth
/// above its highest, Hz (pitches outside the drums' ranges are then moved by octaves).
fn pitch_band(kit: &Kit) -> (f64, f64) {
    let lo = kit
        .drums
        .iter()
        .map(|d| d.lowest.hz())
        .fold(f64::MAX, f64::min);
    let hi = kit.drums.iter().map(|d| d.highest.hz()).fold(0.0, f64::max);
    (lo / 1.5, hi * 1.5)
}

/// The fewest strokes whose onsets can show a beat.
const MIN_BEAT_STROKES: usize = 3;

/// Ticks from score time 0 to the first beat at `first_s`: whole beats of about
/// `period_s`, or the exact fraction when the first beat comes within half a beat.
fn lead_in_ticks(first_s: f64, period_s: f64, tpq: u32) -> u64 {
    if first_s <= 1e-4 {
        return 0;
    }
    let beats = (first_s / period_s).round();
    let ticks = if beats >= 1.0 {
        beats * f64::from(tpq)
    } else {
        (first_s / period_s * f64::from(tpq)).round().max(1.0)
    };
    ticks as u64
}

/// The items of `items` whose entry in `dropped` is false.
fn kept_where<T>(items: Vec<T>, dropped: &[bool]) -> Vec<T> {
    items
        .into_iter()
        .zip(dropped)
        .filter(|(_, d)| !**d)
        .map(|(x, _)| x)
        .collect()
}

/// The runs of at least [`notes::RUN_STROKES`] onsets (`times`, s, sorted) each within
/// [`notes::RUN_GAP_S`] of the next: index ranges.
fn fast_runs(times: &[f64]) -> Vec<std::ops::Range<usize>> {
    let mut runs = Vec::new();
    let mut start = 0;
    for i in 1..=times.len() {
        if i == times.len() || times[i] - times[i - 1] > notes::RUN_GAP_S {
            if i - start >= notes::RUN_STROKES {
                runs.push(start..i);
            }
            start = i;
        }
    }
    runs
}

/// How much louder than timpanist's strokes the recording is, dB: its median stroke
/// against an mf stroke at the median pitch.
fn relative_shift(strokes: &[notate::Stroke], kit: &Kit) -> f64 {
    let mut levels: Vec<f64> = strokes.iter().map(|s| s.level_db).collect();
    levels.sort_by(f64::total_cmp);
    let mut hz: Vec<f64> = strokes.iter().filter_map(|s| s.principal_hz).collect();
    hz.sort_by(f64::total_cmp);
    let pitch = hz.get(hz.len() / 2).map_or(kit.drums[0].tuning, |&f| {
        Pitch(notate::midi_of(f).round().clamp(0.0, 127.0) as u8)
    });
    let mf = MarkLevels::default().at(pitch)[3];
    levels[levels.len() / 2] - mf
}

/// The level (dB, as [`notes::added_level_db`] measures it) of timpanist's calibrated
/// modal stroke at each marking pp…ff on a drum tuned to a pitch, computed once per pitch.
#[derive(Default)]
struct MarkLevels {
    by_pitch: BTreeMap<Pitch, [f64; 6]>,
}

/// Length of each reference stroke rendered, s.
const REFERENCE_STROKE_S: f64 = 0.05;

impl MarkLevels {
    fn at(&mut self, pitch: Pitch) -> [f64; 6] {
        *self.by_pitch.entry(pitch).or_insert_with(|| {
            let kit = fit::kit_for(pitch.hz());
            let rate = crate::sound::SAMPLE_RATE_HZ;
            Dynamic::MARKS.map(|(dynamic, _, _)| {
                fit::struck(&kit, dynamic, Calibration::shipped(), REFERENCE_STROKE_S)
                    .ok()
                    .and_then(|(mono, _)| {
                        let at = analysis::onset(&mono, rate)? as f64 / f64::from(rate);
                        Some(notes::added_level_db(&mono, rate, at))
                    })
                    .unwrap_or(f64::NEG_INFINITY)
            })
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Strokes at p, mf and ff on D3, 1.5 s apart, as one recording at `gain`.
    fn three_dynamics(gain: f32) -> Vec<f32> {
        let kit = fit::kit_for(Pitch(50).hz());
        let mut out = vec![0.0f32; (5.0 * f64::from(crate::sound::SAMPLE_RATE_HZ)) as usize];
        for (k, dynamic) in [Dynamic::P, Dynamic::Mf, Dynamic::F]
            .into_iter()
            .enumerate()
        {
            let (mono, _) = fit::struck(&kit, dynamic, Calibration::shipped(), 1.5).unwrap();
            let at = ((0.2 + 1.5 * k as f64) * 48_000.0) as usize;
            for (o, x) in out[at..].iter_mut().zip(&mono) {
                *o += gain * x;
            }
        }
        out
    }

    /// With relative levels the median stroke reads mf whatever the recording's gain, and
    /// the others keep their order; absolute levels read a quiet recording as softer.
    #[test]
    fn relative_levels_undo_the_gain() {
        let kit = Kit::standard();
        let dynamics = |gain: f32, levels: Levels| -> Vec<f64> {
            let options = Options {
                levels,
                ..Options::default()
            };
            let samples = three_dynamics(gain);
            let (score, _) = transcribe(&samples, 48_000, &kit, "test", &options).unwrap();
            score.beats.iter().map(|b| b.dynamic.velocity()).collect()
        };
        let mf = Dynamic::Mf.velocity();
        for gain in [1.0, 0.1, 0.03] {
            let got = dynamics(gain, Levels::Relative);
            assert_eq!(got.len(), 3, "gain {gain}: {got:?}");
            assert_eq!(got[1], mf, "gain {gain}: {got:?}");
            assert!(got[0] < got[1] && got[1] < got[2], "gain {gain}: {got:?}");
        }
        let quiet = dynamics(0.03, Levels::Absolute);
        assert!(quiet[1] < mf, "{quiet:?}");
    }

    /// Four or more onsets each within 0.15 s of the next make a run; fewer, or a wider
    /// gap, do not.
    #[test]
    fn fast_runs_are_rolls_of_four_or_more() {
        let times = [0.0, 0.5, 0.6, 0.7, 0.8, 0.9, 1.5, 1.6, 1.7, 2.5];
        assert_eq!(fast_runs(&times), vec![1..6]);
        assert!(fast_runs(&[0.0, 0.1, 0.2]).is_empty());
        assert_eq!(fast_runs(&[0.0, 0.1, 0.2, 0.3]), vec![0..4]);
    }
}
