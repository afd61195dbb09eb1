//! What each stroke sounded: the spectrum it added (the window after the onset less the
//! window before it, so drums still ringing from earlier strokes drop out), its principal
//! (1,1) partial found by the kettledrum ratios (Fletcher & Rossing: 1, 1.50, 1.98, 2.44,
//! 2.94) near the pitches the kit reaches, and the energy it added over its first 40 ms
//! (dB re full scale). One pitch per stroke: two drums struck together are heard as the
//! stronger.

use crate::sound::analysis::KETTLEDRUM_RATIOS;
use crate::sound::spectrum::{bins_within, peak_in, peaks, spectrum};

/// The spectrum windows start this long after the onset (past the click), s.
const AFTER_ONSET_S: f64 = 0.005;
/// Window length: up to the next onset, within these bounds, s.
const WINDOW_S: (f64, f64) = (0.06, 0.4);
/// Span over which a stroke's added energy is measured, s.
pub const LEVEL_SPAN_S: f64 = 0.04;
/// Partials are looked for within ± this share of their frequency.
const PARTIAL_TOLERANCE: f64 = 0.02;
/// The drum an octave or a fifth below the best fit is heard instead when its (1,1) in
/// the window reaches this share of the best's…
const LOWER_SHARE: f64 = 0.3;
/// …and its partials score this share of the best's.
const LOWER_SCORE: f64 = 0.6;

/// What a stroke added.
#[derive(Clone, Debug, PartialEq)]
pub struct Heard {
    /// Its principal (1,1) frequency, Hz, when a kettledrum pattern was found.
    pub principal_hz: Option<f64>,
    /// Energy the stroke added over its first [`LEVEL_SPAN_S`], dB re a full-scale sine.
    pub level_db: f64,
}

/// What the stroke at `onset_s` added, `next_s` being the following onset (if any), its
/// principal sought within `band_hz`.
pub fn hear(
    samples: &[f32],
    rate_hz: u32,
    onset_s: f64,
    next_s: Option<f64>,
    band_hz: (f64, f64),
) -> Heard {
    let gap = next_s.map_or(WINDOW_S.1, |n| n - onset_s - 2.0 * AFTER_ONSET_S);
    let window = gap.clamp(WINDOW_S.0, WINDOW_S.1);
    let after = slice(samples, rate_hz, onset_s + AFTER_ONSET_S, window);
    let before = slice(samples, rate_hz, onset_s - AFTER_ONSET_S - window, window);
    let after = spectrum(&after, rate_hz);
    let added = added_spectrum(&after, &spectrum(&before, rate_hz));
    let principal_hz = principal(&added, &after, band_hz);
    Heard {
        principal_hz,
        level_db: added_level_db(samples, rate_hz, onset_s),
    }
}

/// Strokes closer than this follow each other as in a roll, s.
pub const RUN_GAP_S: f64 = 0.15;
/// A run of at least this many close strokes is heard as a whole too.
pub const RUN_STROKES: usize = 4;
/// A run's (1,1) is its best fit's fifth or octave below when that sounds at this share of
/// the best's (1,1) and explains this share of its partials (an even roll keeps its own
/// (1,1) low, see [`hear_run`]).
const RUN_LOWER: (f64, f64) = (0.1, 0.4);
/// The longest span of a run heard as a whole, s.
pub const RUN_WINDOW_S: f64 = 1.0;

/// The (1,1) of a run of close strokes (a roll) from `first_s` to `last_s` (onsets, s),
/// heard over the whole run: a roll struck evenly can meet the drum's own (1,1) in
/// opposite phase stroke after stroke (78 ms apart, a D3 drum's (1,1) turns 11.5 times
/// between strokes), so each stroke adds little there and much at its (2,1) — alone it
/// sounds a fifth higher — while the run's sound still holds the (1,1).
pub fn hear_run(
    samples: &[f32],
    rate_hz: u32,
    (first_s, last_s): (f64, f64),
    band_hz: (f64, f64),
) -> Option<f64> {
    let window = (last_s - first_s + WINDOW_S.0).clamp(WINDOW_S.0, RUN_WINDOW_S);
    let run = spectrum(
        &slice(samples, rate_hz, first_s + AFTER_ONSET_S, window),
        rate_hz,
    );
    // What rang before the run (another drum struck just before it) is left out as for a
    // single stroke.
    let before = spectrum(
        &slice(samples, rate_hz, first_s - AFTER_ONSET_S - window, window),
        rate_hz,
    );
    principal_with(&added_spectrum(&run, &before), &run, band_hz, RUN_LOWER)
}

/// How near (share of the frequency) a roll stroke's pitch must be to an upper partial of
/// its run's drum to be heard as that drum: a stroke of a roll is heard through a window of
/// 60–80 ms, whose 12–16 Hz resolution reads a 166 Hz partial anywhere in 154–171 Hz.
const RUN_PARTIAL_TOLERANCE: f64 = 0.08;
/// A roll's (1,1) within this share of its stroke rate from a multiple of it may be a line
/// of the roll's comb ([`roll_pitch`]).
const COMB_LINE_SHARE: f64 = 0.15;

/// `heard` (a stroke's (1,1), Hz) put back on the run's (1,1) `run_hz` when it is one of
/// that drum's upper partials (within [`RUN_PARTIAL_TOLERANCE`] of a kettledrum ratio
/// above the (1,1)): the stroke was heard by its (2,1) or higher. Another drum struck
/// within the run (a fourth or less above, or below) keeps its own pitch.
pub fn onto_run(heard: Option<f64>, run_hz: f64) -> Option<f64> {
    match heard {
        Some(f)
            if KETTLEDRUM_RATIOS[1..]
                .iter()
                .any(|r| (f / (r * run_hz) - 1.0).abs() <= RUN_PARTIAL_TOLERANCE) =>
        {
            Some(run_hz)
        }
        other => other,
    }
}

/// A roll's (1,1): the one heard over the whole roll (`run_hz`, [`hear_run`]) checked
/// against its strokes' own (1,1)s (`strokes_hz`), each heard between two strokes, where
/// the head rings at its own frequencies.
///
/// - **Another drum ringing under the roll**: when `run_hz` is the pitch of the stroke
///   just before the roll (`before_hz`: that drum may be what the roll's spectrum holds
///   most) and a third of the strokes or more are heard at no partial of it (within
///   [`RUN_PARTIAL_TOLERANCE`]), the pitch that
///   heard as their (1,1) or (2,1) by most strokes is the roll's, if by more than half of
///   them (the rendered
///   D3 roll after a bar of A2 and D3 on the pair kit was heard over the whole roll as the
///   A2 ringing under it: 110 Hz, while its strokes read 142–154 Hz and the D3's (2,1)).
/// - **A line of its comb**: a roll struck evenly at `stroke_rate_hz` sounds as lines at
///   the multiples of that rate, each weighted by the head's resonances, so the whole
///   roll's spectrum can read the (1,1) on the line nearest it, up to half the rate off (the
///   same roll on the standard kit read 154.4 Hz, the 12th line at 12.8 strokes a second:
///   E♭3). When `run_hz` is within [`COMB_LINE_SHARE`] of a spacing from a line, it moves
///   to the strokes it explains.
///
/// Either way the roll's (1,1) is then the median of the strokes it explains, taken back to
/// the (1,1) (twice: about that median again), if they are a third of the strokes or
/// more; else `run_hz`. A roll played by
/// hand, a few per cent uneven, smears its comb, and a low drum's strokes alone are heard
/// too coarsely to move it (refining every roll so put 4 of the 36 recorded rolls of
/// `tests/transcribe.rs` a semitone off; letting the strokes overrule a roll with nothing
/// before it put 4 recorded G2 rolls on E3 and A2, their strokes heard at 150–165 Hz).
pub fn roll_pitch(
    run_hz: f64,
    strokes_hz: &[Option<f64>],
    stroke_rate_hz: f64,
    before_hz: Option<f64>,
) -> f64 {
    let heard: Vec<f64> = strokes_hz.iter().flatten().copied().collect();
    let n = strokes_hz.len();
    let explained =
        |c: f64| -> Vec<f64> { heard.iter().filter_map(|&f| as_principal(c, f)).collect() };
    let unexplained: Vec<f64> = heard
        .iter()
        .copied()
        .filter(|&f| as_principal(run_hz, f).is_none())
        .collect();
    // Strokes alone are heard at their (1,1) or their (2,1); counting the higher partials
    // too, a drum an octave or a twelfth lower would explain as many.
    let first_two = &KETTLEDRUM_RATIOS[..2];
    let explains = |c: f64| {
        (heard.iter())
            .filter(|&&f| {
                first_two
                    .iter()
                    .any(|r| (f / (r * c) - 1.0).abs() <= RUN_PARTIAL_TOLERANCE)
            })
            .count()
    };
    let ringing_before =
        before_hz.is_some_and(|f| (run_hz / f - 1.0).abs() <= RUN_PARTIAL_TOLERANCE);
    let other = (ringing_before && 3 * unexplained.len() >= n)
        .then(|| {
            (unexplained.iter())
                .flat_map(|f| first_two.iter().map(move |r| f / r))
                .map(|c| (c, explains(c)))
                .max_by(|a, b| a.1.cmp(&b.1).then(a.0.total_cmp(&b.0)))
                .filter(|&(_, count)| 2 * count > n)
        })
        .flatten();
    let lines = run_hz / stroke_rate_hz;
    let on_a_line = stroke_rate_hz.is_finite() && (lines - lines.round()).abs() <= COMB_LINE_SHARE;
    let centre = match other {
        Some((c, _)) => c,
        None if on_a_line => run_hz,
        None => return run_hz,
    };
    // The median of the strokes it explains, taken again about that median (a centre half
    // a comb line off takes in strokes heard on another drum ringing a semitone beyond).
    let mut centre = centre;
    for _ in 0..2 {
        let mut near = explained(centre);
        if 3 * near.len() < n {
            return run_hz;
        }
        near.sort_by(f64::total_cmp);
        centre = near[near.len() / 2];
    }
    centre
}

/// `f` taken back to the (1,1) of a drum whose (1,1) is `c`, when it is within
/// [`RUN_PARTIAL_TOLERANCE`] of one of that drum's partials.
fn as_principal(c: f64, f: f64) -> Option<f64> {
    KETTLEDRUM_RATIOS
        .iter()
        .map(|r| f / r)
        .find(|p| (p / c - 1.0).abs() <= RUN_PARTIAL_TOLERANCE)
}

/// The stroke's (1,1), Hz: among the frequencies that would put one of their kettledrum
/// partials on a peak of the added spectrum, the one whose partials hold the most added
/// amplitude plus the amplitude of its (1,1) in the whole window after the onset. The
/// whole window counts because a drum struck again while still ringing adds little at its
/// (1,1) (the new vibration meets the old at a random phase) but much at its faster-decaying
/// upper partials, which alone would be mistaken for a higher drum.
fn principal(added: &[(f64, f64)], after: &[(f64, f64)], band: (f64, f64)) -> Option<f64> {
    principal_with(added, after, band, (LOWER_SHARE, LOWER_SCORE))
}

/// [`principal`] with the shares (of the best's (1,1) in the window, and of its partials'
/// score) at which a drum a fifth or an octave lower is heard instead.
fn principal_with(
    added: &[(f64, f64)],
    after: &[(f64, f64)],
    band: (f64, f64),
    (lower_share, lower_score): (f64, f64),
) -> Option<f64> {
    let top = KETTLEDRUM_RATIOS[KETTLEDRUM_RATIOS.len() - 1];
    let near = |spec: &[(f64, f64)], f: f64| {
        let margin = 1.0 + 1e-9;
        let (lo, hi) = (
            f * (1.0 - PARTIAL_TOLERANCE) / margin,
            f * (1.0 + PARTIAL_TOLERANCE) * margin,
        );
        spec[bins_within(spec, lo, hi)]
            .iter()
            .filter(|(g, _)| (g / f - 1.0).abs() <= PARTIAL_TOLERANCE)
            .map(|p| p.1)
            .fold(0.0, f64::max)
    };
    let score = |c: f64| -> f64 {
        KETTLEDRUM_RATIOS
            .iter()
            .map(|r| near(added, r * c))
            .sum::<f64>()
            + near(after, c)
    };
    let best = peaks(added, band.0, band.1 * top, 0.1)
        .iter()
        .flat_map(|p| KETTLEDRUM_RATIOS.iter().map(move |r| p.0 / r))
        .filter(|c| (band.0..=band.1).contains(c))
        .map(|c| (c, score(c)))
        .max_by(|a, b| a.1.total_cmp(&b.1))?;
    // A low drum whose (2,1) or (3,1) carries more than its (1,1) looks like a drum a
    // fifth or an octave higher: the lower one is heard when its (1,1) sounds in the
    // window as a peak of its own (in a short window a drum ringing a whole tone away
    // spreads over the band, and that is not the lower drum sounding) and its partials
    // explain nearly as much.
    let lower = [KETTLEDRUM_RATIOS[2], KETTLEDRUM_RATIOS[1]]
        .iter()
        .map(|r| best.0 / r)
        .find(|&c| {
            (band.0..=band.1).contains(&c)
                && near_peak(after, c) >= lower_share * near(after, best.0)
                && score(c) >= lower_score * best.1
        });
    let best = lower.unwrap_or(best.0);
    Some(peak_in(after, best * 0.99, best * 1.01).map_or(best, |p| p.0))
}

/// The largest local maximum of `spec` within [`PARTIAL_TOLERANCE`] of `f`, 0 if none.
fn near_peak(spec: &[(f64, f64)], f: f64) -> f64 {
    let (lo, hi) = (f * (1.0 - PARTIAL_TOLERANCE), f * (1.0 + PARTIAL_TOLERANCE));
    peaks(spec, lo, hi, 0.0)
        .iter()
        .map(|p| p.1)
        .fold(0.0, f64::max)
}

/// `len_s` of `samples` from `start_s`, zero where it runs off either end.
fn slice(samples: &[f32], rate_hz: u32, start_s: f64, len_s: f64) -> Vec<f32> {
    let rate = f64::from(rate_hz);
    let start = (start_s * rate).round() as isize;
    let len = (len_s * rate).round() as usize;
    (0..len)
        .map(|i| {
            let j = start + i as isize;
            if j >= 0 {
                samples.get(j as usize).copied().unwrap_or(0.0)
            } else {
                0.0
            }
        })
        .collect()
}

/// Amplitudes the later spectrum has above the earlier, bin by bin (none below).
fn added_spectrum(after: &[(f64, f64)], before: &[(f64, f64)]) -> Vec<(f64, f64)> {
    after
        .iter()
        .zip(before)
        .map(|(&(f, a), &(_, b))| (f, (a - b).max(0.0)))
        .collect()
}

/// Mean square of `samples` over `len_s` from `start_s` (zeros outside the recording).
fn mean_square(samples: &[f32], rate_hz: u32, start_s: f64, len_s: f64) -> f64 {
    let v = slice(samples, rate_hz, start_s, len_s);
    v.iter().map(|&s| f64::from(s) * f64::from(s)).sum::<f64>() / v.len().max(1) as f64
}

/// Energy added by the stroke at `onset_s`: mean square over [`LEVEL_SPAN_S`] after it
/// less the mean square over the same span before it, in dB re a full-scale sine (0.5).
pub fn added_level_db(samples: &[f32], rate_hz: u32, onset_s: f64) -> f64 {
    let after = mean_square(samples, rate_hz, onset_s, LEVEL_SPAN_S);
    let before = mean_square(samples, rate_hz, onset_s - LEVEL_SPAN_S, LEVEL_SPAN_S);
    10.0 * ((after - before).max(1e-12) / 0.5).log10()
}

/// The sound falls across an onset to under this share of its energy before it (−10 dB;
/// a stroke of a roll sounding after a louder one falls by up to 6 dB, a stopped head by
/// 20 and more): a hand stopping a head, not a stroke…
const DAMPED_SHARE: f64 = 0.1;
/// …measured over this span after the onset (past the touch's own click, which the
/// onset is placed on), s.
const DAMPED_AFTER_S: (f64, f64) = (0.02, 0.06);

/// Whether what changes at `onset_s` is a damping (20–60 ms after it the sound is 10 dB
/// and more below its level over the [`LEVEL_SPAN_S`] before): a hand or a mute on a
/// ringing head changes its spectrum at once, which the spectral flux sees as an onset,
/// but it takes energy away where a stroke, however soft, adds some.
pub fn is_damping(samples: &[f32], rate_hz: u32, onset_s: f64) -> bool {
    let before = mean_square(samples, rate_hz, onset_s - LEVEL_SPAN_S, LEVEL_SPAN_S);
    let (from, to) = DAMPED_AFTER_S;
    let after = mean_square(samples, rate_hz, onset_s + from, to - from);
    after < DAMPED_SHARE * before
}

#[cfg(test)]
mod tests {

    /// A roll stroke heard by its (2,1) (within the short window's resolution) or (3,1)
    /// goes back to the run's drum; a drum a fourth above or one below keeps its pitch.
    #[test]
    fn roll_strokes_heard_by_an_upper_partial_join_their_run() {
        let run = 110.0;
        assert_eq!(onto_run(Some(160.0), run), Some(run));
        assert_eq!(onto_run(Some(218.0), run), Some(run));
        assert_eq!(onto_run(Some(146.8), run), Some(146.8));
        assert_eq!(onto_run(Some(98.0), run), Some(98.0));
        assert_eq!(onto_run(None, run), None);
    }
    use super::*;
    use crate::sound::analysis::KETTLEDRUM_RATIOS;

    /// A ringing 147 Hz note stopped to a tenth of its amplitude at 0.5 s is a damping;
    /// a second, softer note struck into it there (a quarter of its amplitude) is not.
    #[test]
    fn a_hand_stopping_a_head_is_no_stroke() {
        let rate = 48_000u32;
        let tone = |t: f64| (std::f64::consts::TAU * 147.0 * t).sin() * (-t).exp();
        let render = |f: &dyn Fn(f64) -> f64| -> Vec<f32> {
            (0..rate)
                .map(|n| f(f64::from(n) / f64::from(rate)) as f32)
                .collect()
        };
        let stopped = render(&|t| tone(t) * if t < 0.5 { 1.0 } else { 0.1 });
        let struck = render(&|t| {
            tone(t)
                + if t < 0.5 {
                    0.0
                } else {
                    0.25 * (std::f64::consts::TAU * 220.0 * t).sin()
                }
        });
        assert!(is_damping(&stopped, rate, 0.5));
        assert!(!is_damping(&struck, rate, 0.5));
    }

    /// A kettledrum-like note (the five ratios, each partial 2 dB below the last) from `t0`.
    fn note(out: &mut [f32], rate: u32, t0: f64, hz: f64, amp: f64) {
        let start = (t0 * f64::from(rate)) as usize;
        for (i, s) in out.iter_mut().enumerate().skip(start) {
            let t = (i - start) as f64 / f64::from(rate);
            let v: f64 = KETTLEDRUM_RATIOS
                .iter()
                .enumerate()
                .map(|(k, r)| (std::f64::consts::TAU * r * hz * t).sin() * 0.8f64.powi(k as i32))
                .sum();
            *s += (amp * (-t / 0.8).exp() * v) as f32;
        }
    }

    /// A new note is heard over a louder one still ringing; the level follows the
    /// amplitude (6 dB per doubling).
    #[test]
    fn hears_new_notes_over_ringing_ones() {
        let rate = 48_000;
        let mut s = vec![0.0f32; rate as usize * 2];
        note(&mut s, rate, 0.1, 110.0, 0.6);
        note(&mut s, rate, 0.5, 146.83, 0.2);
        let heard = hear(&s, rate, 0.5, None, (60.0, 300.0));
        assert!(
            (heard.principal_hz.unwrap() / 146.83 - 1.0).abs() < 0.01,
            "{heard:?}"
        );

        let mut loud = vec![0.0f32; rate as usize];
        note(&mut loud, rate, 0.1, 110.0, 0.4);
        let mut soft = vec![0.0f32; rate as usize];
        note(&mut soft, rate, 0.1, 110.0, 0.2);
        let d = added_level_db(&loud, rate, 0.1) - added_level_db(&soft, rate, 0.1);
        assert!((d - 6.02).abs() < 0.1, "{d}");
    }

    /// The rendered D3 roll's strokes (142–154 Hz at its (1,1), 211–230 Hz at its (2,1),
    /// 161–166 Hz where the A2 rang): heard over the whole roll on a line of its comb
    /// (154.4 Hz at 12.74 strokes a second) it moves to its strokes' median; heard as the
    /// A2 that was struck just before it, the strokes overrule it, but not with nothing
    /// before the roll; off the comb's lines and with its strokes, it stays.
    #[test]
    fn a_roll_takes_the_pitch_its_strokes_hear() {
        let heard: Vec<Option<f64>> = [
            151.0, 230.0, 150.0, 166.0, 212.0, 161.0, 142.0, 154.0, 151.0, 221.0, 148.0, 212.0,
            145.0, 218.0, 146.0,
        ]
        .iter()
        .map(|&f| Some(f))
        .chain([None])
        .collect();
        let d3 = |f: f64| (f / 148.4 - 1.0).abs() < 0.015;
        let comb = roll_pitch(154.4, &heard, 12.74, None);
        assert!(d3(comb), "{comb}");
        let over_a2 = roll_pitch(110.1, &heard, 12.74, Some(110.0));
        assert!(d3(over_a2), "{over_a2}");
        assert_eq!(roll_pitch(110.1, &heard, 12.74, None), 110.1);
        assert_eq!(roll_pitch(110.1, &heard, 12.74, Some(147.0)), 110.1);
        // An A2 roll heard at its (1,1) and (2,1) off the comb's lines keeps its pitch.
        let a2: Vec<Option<f64>> = [110.0, 108.0, 166.0, 111.0, 168.0, 113.0]
            .iter()
            .map(|&f| Some(f))
            .collect();
        assert_eq!(roll_pitch(111.2, &a2, 12.82, Some(110.0)), 111.2);
    }
}
