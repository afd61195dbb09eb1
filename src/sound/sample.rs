//! The sample-replay sound model (seed 002): every contact replays a recorded timpani
//! note, the one whose measured (1,1) pitch is nearest the drum's tuning (in semitones),
//! resampled (cubic Hermite interpolation) so its (1,1) lands on the tuning, darkened by a
//! low-pass that opens with the impact speed, at an amplitude proportional to the impact
//! speed v: gain = `REFERENCE_LEVEL` × v / [`reference_speed_mps`] on the filtered note
//! (each recording is first normalised to peak 1; the low-pass has unit gain at 0 Hz).
//!
//! **Recordings and hands.** The FluidR3 GM timpani (MIT,
//! `kits/samples/COPYRIGHT-fluid-soundfont`), embedded in the program: three notes, each
//! as its left (`…L.wav`) and right (`…R.wav`) channel. The note is chosen by the left
//! recordings' pitches; strokes of the left stick replay the note's L recording and
//! strokes of the right stick its R recording, so a roll alternates two takes instead of
//! repeating one. Each recording's (1,1) is measured once, with this module's spectrum
//! code ([`principal_hz`] over the kettledrum ratios), and each is pitched to the tuning
//! from its own measurement: L 64.0, 73.3, 99.1 Hz; R 65.4, 73.3, 100.7 Hz. The left
//! recordings alone are what [`recordings`] gives the calibration fit (`super::fit`).
//!
//! **Brightness.** A felt mallet sounds darker when played softly. Each note is run through
//! a one-pole low-pass at the output rate f_s = 48 kHz, at rest at the note's onset:
//! y\[n\] = α·x\[n\] + (1 − α)·y\[n − 1\], α = 1 − exp(−2π f_c / f_s) (−3 dB at f_c,
//! −6 dB per octave above, unit gain at 0 Hz). For the recording at its own pitch the
//! cutoff is
//!
//! f_c(v) = [`CUTOFF_P_HZ`] × (v_ff − v_p) / (v_ff − v) for v < v_ff, none (α = 1) for v ≥ v_ff,
//!
//! where v_p = 3.09 m/s and v_ff = [`reference_speed_mps`] = 7.06 m/s are the impact speeds
//! of p and ff ([`crate::drum::strike::impact_speed_mps`]). So the filter's time constant
//! 1/(2π f_c) shrinks in proportion to how far the stroke falls short of ff, the ff
//! reference plays the recording unfiltered (bit for bit), and the cutoff never falls
//! below f_c(0) = 313 Hz: pp 2.08 m/s → 443 Hz, p → 556 Hz, mp 4.03 m/s → 728 Hz, mf
//! 5.04 m/s → 1.09 kHz, f 6.05 m/s → 2.19 kHz. Rendered strokes reach these speeds and
//! more (the dynamics ladder's medians: pp 3.1, p 3.8, mf 6.0, ff 8.4 m/s), so a
//! rendered p is brighter than the scripted one and everything from f up plays nearly
//! unfiltered. A pitched note's cutoff moves with it (× tuning / measured (1,1)), so the
//! filter shapes every recording's spectrum the same way at any tuning.
//!
//! [`CUTOFF_P_HZ`] = 556 Hz is chosen on the recordings: the guide puts the spectral
//! centroid of recorded timpani at ≈ 280 Hz for p and 330 Hz for ff, so each of the six
//! recordings is played at its own pitch with the p filter and unfiltered, and 556 Hz makes
//! the geometric mean of their centroid ratios (first second after the onset, Hann
//! window, [`super::analysis::profile`]) 280/330 = 0.85. Per recording the ratio is
//! 0.79–0.92 (1L 0.83, 2L 0.92, 3L 0.83, 1R 0.81, 2R 0.92, 3R 0.79): the brighter the
//! note, the more the filter takes. A one-pole suffices: the notes' centroids (100–280 Hz
//! unfiltered) lie below the cutoff, so the gentle slope tilts the upper partials and the
//! attack and takes a little of the (1,1).
//!
//! Pitching a note up also raises its top octave; content shifted above 24 kHz aliases
//! (the recordings hold little energy there).

use super::spectrum::{principal_hz, spectrum};
use super::{REFERENCE_LEVEL, SAMPLE_RATE_HZ, SoundError, reference_speed_mps};
use crate::drum::DrumSet;
use crate::drum::strike::impact_speed_mps;
use crate::kit::{Kit, Side};
use crate::score::Dynamic;
use std::f64::consts::TAU;
use std::io::Cursor;
use std::sync::OnceLock;

/// The embedded recordings: (file name, stick side that replays it, WAV bytes): the left
/// channels of the three notes, then their right channels in the same order.
pub const RECORDINGS: [(&str, Side, &[u8]); 6] = [
    (
        "Timpani_1L.wav",
        Side::Left,
        include_bytes!("../../kits/samples/Timpani_1L.wav"),
    ),
    (
        "Timpani_2L.wav",
        Side::Left,
        include_bytes!("../../kits/samples/Timpani_2L.wav"),
    ),
    (
        "Timpani_3L.wav",
        Side::Left,
        include_bytes!("../../kits/samples/Timpani_3L.wav"),
    ),
    (
        "Timpani_1R.wav",
        Side::Right,
        include_bytes!("../../kits/samples/Timpani_1R.wav"),
    ),
    (
        "Timpani_2R.wav",
        Side::Right,
        include_bytes!("../../kits/samples/Timpani_2R.wav"),
    ),
    (
        "Timpani_3R.wav",
        Side::Right,
        include_bytes!("../../kits/samples/Timpani_3R.wav"),
    ),
];

/// Recorded notes (each with an L and an R recording).
const NOTES: usize = 3;

/// Low-pass cutoff for a p stroke, Hz (see the module docs for the law and its calibration).
pub const CUTOFF_P_HZ: f64 = 556.0;

/// Kettledrum mode ratios used to recognise the (1,1) in a recording.
const KETTLEDRUM_RATIOS: [f64; 5] = [1.0, 1.5, 1.98, 2.44, 2.94];

/// One decoded recording.
#[derive(Clone, Debug)]
pub struct Recording {
    pub name: &'static str,
    /// Hz.
    pub rate_hz: u32,
    /// Mono samples normalised to peak 1.
    pub samples: Vec<f32>,
    /// Measured (1,1) frequency, Hz.
    pub principal_hz: f64,
    /// The stick whose strokes replay this recording.
    pub side: Side,
}

fn decode(name: &'static str, side: Side, bytes: &[u8]) -> Result<Recording, SoundError> {
    let bad = |message: String| SoundError::Sample {
        name: name.to_string(),
        message,
    };
    let mut reader = hound::WavReader::new(Cursor::new(bytes)).map_err(|e| bad(e.to_string()))?;
    let spec = reader.spec();
    if spec.sample_format != hound::SampleFormat::Int || spec.bits_per_sample != 16 {
        return Err(bad("expected 16-bit PCM".into()));
    }
    let ch = usize::from(spec.channels.max(1));
    let raw: Vec<i16> = reader
        .samples::<i16>()
        .collect::<Result<_, _>>()
        .map_err(|e| bad(e.to_string()))?;
    let mono: Vec<f32> = raw
        .chunks_exact(ch)
        .map(|f| f.iter().map(|&s| f32::from(s)).sum::<f32>() / ch as f32)
        .collect();
    let peak = mono.iter().fold(0.0f32, |m, s| m.max(s.abs()));
    if peak <= 0.0 {
        return Err(bad("the recording is silent".into()));
    }
    let samples: Vec<f32> = mono.iter().map(|s| s / peak).collect();
    let spec_mag = spectrum(&samples, spec.sample_rate);
    let principal_hz = principal_hz(&spec_mag, 40.0, 400.0, &KETTLEDRUM_RATIOS)
        .ok_or_else(|| bad("no (1,1) peak found".into()))?;
    Ok(Recording {
        name,
        rate_hz: spec.sample_rate,
        samples,
        principal_hz,
        side,
    })
}

/// The left recordings, one per note, with their measured pitches: what chooses the note
/// and what the calibration fit (`super::fit`) fits to.
pub fn recordings() -> Result<&'static [Recording], SoundError> {
    Ok(&all_recordings()?[..NOTES])
}

/// All six decoded recordings in [`RECORDINGS`] order, with their measured pitches
/// (decoded once per process).
pub fn all_recordings() -> Result<&'static [Recording], SoundError> {
    static CELL: OnceLock<Result<Vec<Recording>, String>> = OnceLock::new();
    let decoded = CELL.get_or_init(|| {
        RECORDINGS
            .iter()
            .map(|&(n, side, b)| decode(n, side, b))
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| e.to_string())
    });
    match decoded {
        Ok(v) => Ok(v),
        Err(message) => Err(SoundError::Sample {
            name: "recordings".into(),
            message: message.clone(),
        }),
    }
}

/// How far `r`'s (1,1) is from `hz`: |ln(f11 / hz)|.
fn log_distance(r: &Recording, hz: f64) -> f64 {
    (r.principal_hz / hz).ln().abs()
}

/// The recording whose (1,1) is nearest `hz` in log frequency.
pub fn nearest(recordings: &[Recording], hz: f64) -> Option<&Recording> {
    recordings
        .iter()
        .min_by(|a, b| log_distance(a, hz).total_cmp(&log_distance(b, hz)))
}

/// The (left, right) recordings of the note whose left recording's (1,1) is nearest `hz`.
pub fn nearest_pair(hz: f64) -> Result<(&'static Recording, &'static Recording), SoundError> {
    let (left, right) = all_recordings()?.split_at(NOTES);
    Ok(left
        .iter()
        .zip(right)
        .min_by(|a, b| log_distance(a.0, hz).total_cmp(&log_distance(b.0, hz)))
        .expect("three notes are embedded"))
}

/// Low-pass cutoff for a stroke at `speed_mps`, Hz: [`CUTOFF_P_HZ`] × (v_ff − v_p) /
/// (v_ff − v), infinite (no filter) from the reference (ff) speed up.
pub fn cutoff_hz(speed_mps: f64) -> f64 {
    let p = impact_speed_mps(Dynamic::P);
    let short = reference_speed_mps() - speed_mps;
    if short > 0.0 {
        CUTOFF_P_HZ * (reference_speed_mps() - p) / short
    } else {
        f64::INFINITY
    }
}

/// Add one note of `rec` to `out` from its first sample: `step` recording samples per
/// output sample, through the one-pole low-pass at `cutoff_hz` (at rest at the onset),
/// times `amp`.
pub fn play(rec: &Recording, step: f64, cutoff_hz: f64, amp: f64, out: &mut [f32]) {
    let len = ((rec.samples.len() as f64 - 1.0) / step).floor() as usize;
    let alpha = 1.0 - (-TAU * cutoff_hz / f64::from(SAMPLE_RATE_HZ)).exp();
    let mut y = 0.0;
    for (i, o) in out.iter_mut().take(len).enumerate() {
        y = alpha * interpolate(&rec.samples, i as f64 * step) + (1.0 - alpha) * y;
        *o += (amp * y) as f32;
    }
}

/// Cubic Hermite (Catmull–Rom) interpolation of `x` at fractional index `pos` (0 outside).
fn interpolate(x: &[f32], pos: f64) -> f64 {
    let i = pos.floor() as isize;
    let t = pos - i as f64;
    let at = |k: isize| {
        usize::try_from(k)
            .ok()
            .and_then(|k| x.get(k))
            .map_or(0.0, |&v| f64::from(v))
    };
    let (p0, p1, p2, p3) = (at(i - 1), at(i), at(i + 1), at(i + 2));
    p1 + 0.5
        * t
        * (p2 - p0 + t * (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3 + t * (3.0 * (p1 - p2) + p3 - p0)))
}

/// Render drum `j` of `kit`'s contacts into `out`, each at the pitch the drum is tuned to
/// when it starts (its pedal changes: `drums.retunes()`) and stopped by the hands resting
/// on the head after it (`touches`: from, until; s); returns whether any contact was on it.
pub fn render_drum(
    kit: &Kit,
    (drums, touches): (&DrumSet, &[(f64, f64)]),
    j: usize,
    out: &mut [f32],
) -> Result<bool, SoundError> {
    let contacts: Vec<_> = drums.contacts().iter().filter(|c| c.drum == j).collect();
    if contacts.is_empty() {
        return Ok(false);
    }
    let fs = f64::from(SAMPLE_RATE_HZ);
    for c in contacts {
        let Some(pitch) = crate::kit::pitch_at(kit, drums.retunes(), j, c.start_s) else {
            return Ok(false);
        };
        let tuning_hz = pitch.hz();
        let (left, right) = nearest_pair(tuning_hz)?;
        let rec = match c.side {
            Side::Left => left,
            Side::Right => right,
        };
        // Recording samples per output sample.
        let step = tuning_hz / rec.principal_hz * f64::from(rec.rate_hz) / fs;
        let amp = REFERENCE_LEVEL * c.impact_speed_mps / reference_speed_mps();
        let start = ((c.start_s * fs).round().max(0.0) as usize).min(out.len());
        let cutoff = cutoff_hz(c.impact_speed_mps) * tuning_hz / rec.principal_hz;
        let len = ((rec.samples.len() as f64 - 1.0) / step).floor().max(0.0) as usize;
        let mut note = vec![0.0f32; len.min(out.len() - start)];
        play(rec, step, cutoff, amp, &mut note);
        super::damp_note(&mut note, start, touches);
        for (o, n) in out[start..].iter_mut().zip(&note) {
            *o += n;
        }
    }
    Ok(true)
}

#[cfg(test)]
mod tests {
    use super::super::analysis::profile;
    use super::*;

    /// The embedded recordings decode and their measured (1,1) pitches are the stated
    /// L 64.0, 73.3, 99.1 Hz and R 65.4, 73.3, 100.7 Hz (within 0.5 %); the note is chosen
    /// by the left pitches and pairs each L with its R.
    #[test]
    fn recorded_pitches() {
        let all = all_recordings().unwrap();
        let got: Vec<f64> = all.iter().map(|r| r.principal_hz).collect();
        for (g, want) in got.iter().zip([64.0, 73.3, 99.1, 65.4, 73.3, 100.7]) {
            assert!((g / want - 1.0).abs() < 0.005, "{got:?}");
        }
        let recs = recordings().unwrap();
        assert_eq!(recs.len(), 3);
        assert!(recs.iter().all(|r| r.side == Side::Left));
        assert_eq!(nearest(recs, 146.8).unwrap().name, "Timpani_3L.wav");
        assert_eq!(nearest(recs, 68.0).unwrap().name, "Timpani_1L.wav");
        let (l, r) = nearest_pair(64.5).unwrap();
        assert_eq!((l.name, r.name), ("Timpani_1L.wav", "Timpani_1R.wav"));
        assert_eq!((l.side, r.side), (Side::Left, Side::Right));
    }

    /// The cutoff is [`CUTOFF_P_HZ`] at p, rises with speed, and is gone (α = 1, the
    /// recording itself) from ff up.
    #[test]
    fn cutoff_law() {
        for (d, _, _) in Dynamic::MARKS {
            let v = impact_speed_mps(d);
            eprintln!("{d:?}: {v:.3} m/s, cutoff {:.0} Hz", cutoff_hz(v));
        }
        eprintln!("0 m/s: cutoff {:.0} Hz", cutoff_hz(0.0));
        let p = cutoff_hz(impact_speed_mps(Dynamic::P));
        assert!((p / CUTOFF_P_HZ - 1.0).abs() < 1e-12, "{p}");
        let speeds = [0.0, 1.46, 2.16, 2.82, 3.53, 4.23, 4.9];
        assert!(speeds.windows(2).all(|w| cutoff_hz(w[0]) < cutoff_hz(w[1])));
        assert_eq!(cutoff_hz(reference_speed_mps()), f64::INFINITY);
        assert_eq!(cutoff_hz(f64::NAN), f64::INFINITY);
        let rec = &recordings().unwrap()[0];
        let mut out = vec![0.0; 1000];
        play(rec, 1.0, cutoff_hz(reference_speed_mps()), 1.0, &mut out);
        assert_eq!(out[..], rec.samples[..1000]);
    }

    /// The calibration of [`CUTOFF_P_HZ`]: over the six recordings played at their own
    /// pitch, the geometric mean of centroid(p filter) / centroid(unfiltered) is the
    /// guide's 280/330 within 1 %.
    #[test]
    fn p_filter_lowers_the_recorded_centroid_as_the_guide() {
        let fs = f64::from(SAMPLE_RATE_HZ);
        let mut ratios = Vec::new();
        for r in all_recordings().unwrap() {
            let step = f64::from(r.rate_hz) / fs;
            let centroid = |cutoff_hz| {
                let mut out = vec![0.0; (r.samples.len() as f64 / step) as usize];
                play(r, step, cutoff_hz, 1.0, &mut out);
                profile(&out, SAMPLE_RATE_HZ).unwrap().centroid_hz
            };
            ratios.push(centroid(CUTOFF_P_HZ) / centroid(f64::INFINITY));
        }
        let mean = (ratios.iter().map(|r| r.ln()).sum::<f64>() / ratios.len() as f64).exp();
        eprintln!("centroid ratios p / unfiltered: {ratios:.3?}, geometric mean {mean:.4}");
        assert!((mean / (280.0 / 330.0) - 1.0).abs() < 0.01, "{ratios:?}");
    }

    /// Interpolation passes through the samples and is 0 outside.
    #[test]
    fn interpolation_hits_samples() {
        let x = [0.0, 1.0, 4.0, 9.0, 16.0];
        assert_eq!(interpolate(&x, 2.0), 4.0);
        assert!((interpolate(&x, 2.5) - 6.25).abs() < 0.2);
        assert_eq!(interpolate(&x, 10.0), 0.0);
    }
}
