//! The beat of a recording and a tempo map that follows it. The beat period comes from the
//! autocorrelation of the onset strength, weighted towards 100 bpm (a log-Gaussian prior
//! one octave wide) — or, for strokes further apart than the slowest beat, from their
//! interval ([`sparse_period_s`]) — and is then taken a third faster or slower when that
//! writes the strokes plainly ([`plainest_period_s`]). Beats are tracked by dynamic
//! programming (Ellis 2007: each beat rewards onset strength and pays for departing from
//! the period), so tempo changes are followed. A second pass holds each beat more firmly
//! to the *local* period (the median beat interval of the first pass around it, or the
//! pace of evenly spaced strokes near it): inside a roll, where every 32nd is as strong an
//! onset as the beat, the first pass may take a roll stroke next to the beat (a one-beat
//! tempo swing of ±12 %), while a gradual accelerando still moves the local period with
//! it. Beats within 25 ms of a stroke move onto it. The tempo map is the fewest steps of
//! constant tempo that keep every beat on a stroke within 4 ms.

use super::onsets::Strength;
use crate::score::{TempoChange, TempoPoint};

/// The prior's centre, bpm, and its width (standard deviation in octaves).
const PRIOR_BPM: f64 = 100.0;
const PRIOR_OCTAVES: f64 = 1.0;
/// Periods considered, bpm.
const BPM_SPAN: (f64, f64) = (40.0, 220.0);
/// How strongly a beat holds to the period (Ellis's α, with the strength normalised).
const TIGHTNESS: f64 = 30.0;
/// How strongly a beat holds to the local period in the second pass.
const LOCAL_TIGHTNESS: f64 = 150.0;
/// Beats on each side whose intervals give the local period (their median).
const LOCAL_BEATS: usize = 4;
/// A beat this close to a stroke moves onto it, s.
const SNAP_S: f64 = 0.025;
/// Largest error a constant-tempo step may leave at a beat that carries a stroke, s.
pub const TEMPO_TOLERANCE_S: f64 = 0.004;

/// The beat period, s: the lag in [`BPM_SPAN`] where the prior-weighted autocorrelation of
/// the onset strength (mean removed) is largest. `None` for a signal too short for two
/// beats.
pub fn period_s(strength: &Strength) -> Option<f64> {
    let v = &strength.values;
    let mean = v.iter().sum::<f64>() / v.len().max(1) as f64;
    let x: Vec<f64> = v.iter().map(|s| s - mean).collect();
    let lag_of = |bpm: f64| (60.0 / bpm / strength.hop_s).round() as usize;
    let (shortest, longest) = (lag_of(BPM_SPAN.1).max(1), lag_of(BPM_SPAN.0));
    if x.len() <= 2 * shortest {
        return None;
    }
    (shortest..=longest.min(x.len() / 2).max(shortest))
        .map(|lag| {
            let ac: f64 = x.iter().zip(&x[lag..]).map(|(a, b)| a * b).sum();
            let bpm = 60.0 / (lag as f64 * strength.hop_s);
            let octaves = (bpm / PRIOR_BPM).log2() / PRIOR_OCTAVES;
            (lag, ac * (-0.5 * octaves * octaves).exp())
        })
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(lag, _)| lag as f64 * strength.hop_s)
}

/// Beat times, s, tracked through the onset strength with period `period_s` (the local
/// period following the pace of evenly spaced strokes, [`follow_strokes`]), extended by
/// whole periods to cover the first to the last of `strokes_s` (s, sorted).
pub fn track(strength: &Strength, period_s: f64, strokes_s: &[f64]) -> Vec<f64> {
    let (first_s, last_s) = match (strokes_s.first(), strokes_s.last()) {
        (Some(&a), Some(&b)) => (a, b),
        _ => (0.0, 0.0),
    };
    let p = period_s / strength.hop_s;
    let first = dynamic_beats(strength, &|_| p, TIGHTNESS);
    let mut local = local_period_frames(&first, p, strength.values.len());
    follow_strokes(&mut local, strokes_s, strength.hop_s);
    let frames = dynamic_beats(strength, &|n| local[n], LOCAL_TIGHTNESS);
    let mut beats: Vec<f64> = frames.iter().map(|&f| strength.time_s(f)).collect();
    extend(&mut beats, period_s, first_s, last_s);
    beats
}

/// Strokes around a frame whose intervals give the strokes' own pace there.
const PACE_STROKES: usize = 4;
/// The strokes' pace replaces the local period where it is within this ratio of it:
/// strokes on every beat show the beat better than a first pass held to one period for
/// the whole piece (the tempo-change study's 120 bpm stretch, under a period of 81 bpm,
/// was tracked at 96 and written a beat short); eighths, halves, dotted quarters and
/// triplets lie outside it and leave the period alone.
const PACE_RATIO: (f64, f64) = (0.75, 1.3);
/// Only strokes evenly spaced show a pace: their longest interval within this ratio of
/// their shortest (a hall's echo heard as a stroke made the minute study's pace wander:
/// 101 of its 109 beat positions written, against 108).
const EVEN_PACE: f64 = 1.25;

/// Where the strokes around a frame (`strokes_s`, s, sorted; [`PACE_STROKES`] on each
/// side) are evenly spaced ([`EVEN_PACE`]) and their median interval is within
/// [`PACE_RATIO`] of the local period (frames of `hop_s`), take it as the period there.
fn follow_strokes(local: &mut [f64], strokes_s: &[f64], hop_s: f64) {
    if strokes_s.len() < 3 {
        return;
    }
    // Frames between the same two strokes see the same strokes around them.
    let paces: Vec<Option<f64>> = (0..=strokes_s.len())
        .map(|k| even_pace_s(strokes_s, k))
        .collect();
    // A pace followed from the frame before is what the next is held to: a ramp's pace
    // drifts further from the first pass's period than [`PACE_RATIO`] allows, a little
    // each stroke.
    let mut followed: Option<f64> = None;
    for (n, period) in local.iter_mut().enumerate() {
        let t = n as f64 * hop_s;
        let Some(pace_s) = paces[strokes_s.partition_point(|&s| s < t)] else {
            followed = None;
            continue;
        };
        let pace = pace_s / hop_s;
        let held_to = followed.unwrap_or(*period);
        if (PACE_RATIO.0..=PACE_RATIO.1).contains(&(pace / held_to)) {
            *period = pace;
            followed = Some(pace);
        } else {
            followed = None;
        }
    }
}

/// ...or, in an accelerando or a ritardando, each interval within this ratio of the one
/// before (the tempo-change study's ramp from 80 to 120 bpm spans 1.5 over eight
/// strokes: its pace was followed or not as its intervals fell a millisecond either way
/// of [`EVEN_PACE`], and the ramp's top written off the beat). Dotted notes, eighths
/// among quarters, triplets and an echo heard as a stroke change the interval by far
/// more.
const STEADY_PACE: f64 = 1.2;

/// The median interval of the strokes around the one at index `k` of `strokes_s` (s,
/// sorted; [`PACE_STROKES`] on each side), s, if they are evenly spaced ([`EVEN_PACE`])
/// or steadily faster or slower ([`STEADY_PACE`]).
fn even_pace_s(strokes_s: &[f64], k: usize) -> Option<f64> {
    let span = k.saturating_sub(PACE_STROKES)..(k + PACE_STROKES).min(strokes_s.len());
    let mut gaps: Vec<f64> = strokes_s[span].windows(2).map(|w| w[1] - w[0]).collect();
    if gaps.len() < 2 {
        return None;
    }
    let steady = gaps
        .windows(2)
        .all(|w| w[1] <= STEADY_PACE * w[0] && w[0] <= STEADY_PACE * w[1]);
    gaps.sort_by(f64::total_cmp);
    (steady || gaps[gaps.len() - 1] <= EVEN_PACE * gaps[0]).then(|| gaps[gaps.len() / 2])
}

/// For each frame, the median interval (frames) of the beats `frames` around it
/// ([`LOCAL_BEATS`] on each side of the beat interval it falls in); `p` where there are
/// too few beats.
fn local_period_frames(frames: &[usize], p: f64, len: usize) -> Vec<f64> {
    let intervals: Vec<f64> = frames.windows(2).map(|w| (w[1] - w[0]) as f64).collect();
    if intervals.is_empty() {
        return vec![p; len];
    }
    let medians: Vec<f64> = (0..intervals.len())
        .map(|k| {
            let span = k.saturating_sub(LOCAL_BEATS)..(k + LOCAL_BEATS + 1).min(intervals.len());
            let mut near = intervals[span].to_vec();
            near.sort_by(f64::total_cmp);
            near[near.len() / 2]
        })
        .collect();
    (0..len)
        .map(|n| {
            // The interval ending at or after frame n (the first beat after it).
            let k = frames.partition_point(|&f| f < n).clamp(1, intervals.len());
            medians[k - 1]
        })
        .collect()
}

/// Ellis's dynamic programme: the beat frames that maximise onset strength (normalised)
/// less `tightness`·ln(interval / period)², the period (frames) taken where the later beat
/// falls.
fn dynamic_beats(
    strength: &Strength,
    period_at: &dyn Fn(usize) -> f64,
    tightness: f64,
) -> Vec<usize> {
    let v = &strength.values;
    let sd = {
        let mean = v.iter().sum::<f64>() / v.len().max(1) as f64;
        (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / v.len().max(1) as f64)
            .sqrt()
            .max(1e-12)
    };
    let mut score = vec![0.0; v.len()];
    let mut back: Vec<Option<usize>> = vec![None; v.len()];
    for n in 0..v.len() {
        let p = period_at(n);
        let (near, far) = ((p / 2.0).round() as usize, (2.0 * p).round() as usize);
        let own = v[n] / sd;
        let candidates = match n.checked_sub(near.max(1)) {
            Some(latest) => n.saturating_sub(far)..latest + 1,
            None => 0..0,
        };
        let best = candidates
            .map(|m| {
                let ratio = ((n - m) as f64 / p).ln();
                (m, score[m] - tightness * ratio * ratio)
            })
            .max_by(|a, b| a.1.total_cmp(&b.1));
        match best {
            Some((m, s)) if s > 0.0 => {
                score[n] = own + s;
                back[n] = Some(m);
            }
            _ => score[n] = own,
        }
    }
    let last_period = period_at(v.len().saturating_sub(1));
    let tail = v.len().saturating_sub(last_period.round() as usize)..v.len();
    let Some(mut n) = tail.max_by(|&a, &b| score[a].total_cmp(&score[b])) else {
        return Vec::new();
    };
    let mut frames = vec![n];
    while let Some(m) = back[n] {
        frames.push(m);
        n = m;
    }
    frames.reverse();
    frames
}

/// Add whole periods before the first beat and after the last until they cover
/// `[first_s, last_s]`, keeping every beat at or after 0.
fn extend(beats: &mut Vec<f64>, period_s: f64, first_s: f64, last_s: f64) {
    if beats.is_empty() {
        beats.push(first_s);
    }
    while beats[0] > first_s + SNAP_S && beats[0] - period_s >= -SNAP_S {
        beats.insert(0, (beats[0] - period_s).max(0.0));
    }
    while *beats.last().expect("not empty") < last_s - SNAP_S {
        let last = *beats.last().expect("not empty");
        beats.push(last + period_s);
    }
    beats.dedup_by(|b, a| *b - *a < 0.5 * period_s);
}

/// Move each beat within [`SNAP_S`] of a stroke onto the nearest stroke (`strokes_s`
/// sorted), keeping the beats in order.
pub fn snap(beats: &mut [f64], strokes_s: &[f64]) {
    for b in beats.iter_mut() {
        let i = strokes_s.partition_point(|&s| s < *b);
        let nearest = [i.checked_sub(1), Some(i)]
            .into_iter()
            .flatten()
            .filter_map(|j| strokes_s.get(j))
            .min_by(|x, y| (*x - *b).abs().total_cmp(&(*y - *b).abs()));
        if let Some(&s) = nearest
            && (s - *b).abs() <= SNAP_S
        {
            *b = s;
        }
    }
    for i in 1..beats.len() {
        if beats[i] <= beats[i - 1] {
            beats[i] = beats[i - 1] + 1e-3;
        }
    }
}

/// A tempo map in which beat `k` of `beats` (s, rising, each a quarter note) falls at
/// tick `first_tick + k·tpq`, score time 0 at tick 0: the fewest constant-tempo steps that
/// keep every beat on a stroke (`on_stroke[k]`) within [`TEMPO_TOLERANCE_S`], each step
/// starting on such a beat (or the first). The beats between them count the beats but do
/// not bend the tempo: where a beat falls in a silence only shapes how the silence is
/// written, and the tracker's beats there follow the decays' noise (three strokes 3 s
/// apart gave twelve tempo steps). The span before the first beat is one step of
/// `first_tick` ticks, unless the first step's tempo keeps the first beat within the
/// tolerance too. Without two beats, the prior's tempo.
pub fn tempo_map(beats: &[f64], on_stroke: &[bool], tpq: u32, first_tick: u64) -> Vec<TempoPoint> {
    let q = f64::from(tpq);
    let mut points = Vec::new();
    if first_tick > 0 {
        let bpm = 60.0 * first_tick as f64 / q / beats[0].max(1e-3);
        points.push(step(0, bpm));
    }
    let mut anchors: Vec<usize> = (0..beats.len()).filter(|&k| on_stroke[k]).collect();
    if !beats.is_empty() && anchors.first() != Some(&0) {
        anchors.insert(0, 0);
    }
    if anchors.len() < 2 {
        anchors = (0..beats.len()).collect();
    }
    let mut a = 0;
    while a + 1 < anchors.len() {
        let mut b = a + 1;
        while b + 1 < anchors.len() && fits(beats, &anchors[a..=b + 1]) {
            b += 1;
        }
        let (from, to) = (anchors[a], anchors[b]);
        let beat_s = (beats[to] - beats[from]) / (to - from) as f64;
        points.push(step(
            first_tick + from as u64 * u64::from(tpq),
            60.0 / beat_s,
        ));
        a = b;
    }
    if points.is_empty() {
        points.push(step(0, PRIOR_BPM));
    }
    // The lead-in takes the first step's tempo when that keeps the first beat within the
    // tolerance (a stroke 5 ms into a file is not a tempo of its own).
    if first_tick > 0
        && let [_, first, ..] = points.as_slice()
    {
        let at_first_tempo_s = 60.0 * first_tick as f64 / q / first.bpm;
        if (at_first_tempo_s - beats[0]).abs() <= TEMPO_TOLERANCE_S {
            points.remove(0);
            points[0].tick = 0;
        }
    }
    points.dedup_by(|b, a| (a.bpm - b.bpm).abs() < 1e-9);
    points
}

/// The beat period of the prior's tempo, s.
pub fn prior_period_s() -> f64 {
    60.0 / PRIOR_BPM
}

fn step(tick: u64, bpm: f64) -> TempoPoint {
    TempoPoint {
        tick,
        bpm,
        change: TempoChange::Step,
    }
}

/// Whether one constant tempo through the first and last of the beats `anchors` (indices
/// into `beats`, rising) keeps every one between within [`TEMPO_TOLERANCE_S`].
fn fits(beats: &[f64], anchors: &[usize]) -> bool {
    let (first, last) = (anchors[0], anchors[anchors.len() - 1]);
    let slope = (beats[last] - beats[first]) / (last - first) as f64;
    anchors.iter().all(|&k| {
        let line = beats[first] + slope * (k - first) as f64;
        (line - beats[k]).abs() <= TEMPO_TOLERANCE_S
    })
}

/// Ratios to a beat period that confuse duple and triple time: a beat heard a third too
/// slow writes quarters as triplets, a third too fast writes them as dotted notes.
const TRIPLE_RATIOS: [f64; 2] = [2.0 / 3.0, 1.5];
/// An interval within this share of a beat (at most [`GRID_TOLERANCE_S`]) of a whole or
/// half number of beats counts as written plainly.
const GRID_SHARE: f64 = 0.08;
const GRID_TOLERANCE_S: f64 = 0.04;
/// A related period replaces the autocorrelation's when it writes this many more
/// intervals plainly (whole beats 1, half beats ½), and at least this share of all of
/// them: a piece whose tempo changes is written plainly by no one period, and its
/// autocorrelation's stands (a study at 80, 120 and 90 bpm was written at 120
/// throughout, its opening at 80 in dotted quarters).
const PLAINER_BY: f64 = 1.0;
const PLAIN_SHARE: f64 = 0.7;

/// How plainly the intervals between `times` (s, sorted) are written at a beat of
/// `period_s`: each interval of a whole number of beats counts 1, of a half number ½;
/// with the number of intervals counted (a chord's is not).
fn plainness(times: &[f64], period_s: f64) -> (f64, usize) {
    let tolerance = (GRID_SHARE * period_s).min(GRID_TOLERANCE_S) / period_s;
    let off = |x: f64| (x - x.round()).abs();
    (times.windows(2))
        .map(|w| (w[1] - w[0]) / period_s)
        .filter(|&beats| beats > 2.0 * tolerance)
        .fold((0.0, 0), |(score, n), beats| {
            let plain = if off(beats) <= tolerance {
                1.0
            } else if off(2.0 * beats) <= 2.0 * tolerance {
                0.5
            } else {
                0.0
            };
            (score + plain, n + 1)
        })
}

/// The beat period that writes the strokes at `times` most plainly: `period_s` (the
/// autocorrelation's), or the period a third faster or slower (within the periods
/// considered) when that writes clearly more intervals, and most of them, as whole or
/// half beats. The autocorrelation cannot tell 48 from 72 bpm in five strokes of an
/// improvisation at 72 (0, 1, 1½, 3 and 4 beats, which 48 bpm writes as triplets), nor
/// 114 from 76 bpm in a study of half notes and quarters at 76 (written in dotted notes
/// at 114).
pub fn plainest_period_s(period_s: f64, times: &[f64]) -> f64 {
    let (fastest, slowest) = (60.0 / BPM_SPAN.1, 60.0 / BPM_SPAN.0);
    let mut best = (plainness(times, period_s).0, period_s);
    for ratio in TRIPLE_RATIOS {
        let p = period_s * ratio;
        let (score, n) = plainness(times, p);
        if (fastest..=slowest).contains(&p)
            && score >= best.0 + PLAINER_BY
            && score >= PLAIN_SHARE * n as f64
        {
            best = (score, p);
        }
    }
    best.1
}

/// The beat period of strokes whose median interval is `interval_s`, when that is slower
/// than the slowest beat considered (sparse playing, whose onset strength shows no beat
/// in its autocorrelation): the interval divided by the whole number of beats that
/// brings it nearest the prior's tempo.
pub fn sparse_period_s(interval_s: f64) -> Option<f64> {
    let slowest_s = 60.0 / BPM_SPAN.0;
    if interval_s.is_nan() || interval_s <= slowest_s {
        return None;
    }
    let beats = (interval_s / prior_period_s()).round().max(1.0);
    Some(interval_s / beats)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::score::TempoMap;

    /// Strokes from 80 to 120 bpm over eight beats show their pace, however their
    /// intervals fall; dotted rhythms, and a stroke with its echo heard as another, do not.
    #[test]
    fn a_ramp_shows_its_pace_and_uneven_strokes_do_not() {
        let mut ramp = vec![0.0];
        for k in 0..8 {
            let bpm = 80.0 + 40.0 * f64::from(k) / 7.0;
            ramp.push(ramp[ramp.len() - 1] + 60.0 / bpm);
        }
        let pace = even_pace_s(&ramp, 4).expect("the ramp's pace");
        assert!((0.55..0.7).contains(&pace), "{pace} s");
        let dotted: Vec<f64> = (0..9)
            .map(|k| f64::from(k / 2) + 0.75 * f64::from(k % 2))
            .collect();
        assert_eq!(even_pace_s(&dotted, 4), None);
        let mut echoed: Vec<f64> = (0..8).map(|k| 0.6 * f64::from(k)).collect();
        echoed.insert(4, 0.6 * 3.0 + 0.08);
        assert_eq!(even_pace_s(&echoed, 4), None);
    }

    fn pulses(times: &[f64], seconds: f64) -> Strength {
        let hop = 0.005;
        let mut values = vec![0.01; (seconds / hop) as usize];
        for t in times {
            values[(t / hop).round() as usize] = 1.0;
        }
        Strength {
            hop_s: hop,
            frame_s: 0.046,
            values,
        }
    }

    /// Quarter notes at 90 bpm give a 90 bpm period, with eighths sprinkled in too.
    #[test]
    fn finds_the_period() {
        let mut times: Vec<f64> = (0..24).map(|k| 0.3 + k as f64 * 60.0 / 90.0).collect();
        times.extend((0..6).map(|k| 0.3 + (2 * k + 1) as f64 * 30.0 / 90.0));
        let p = period_s(&pulses(&times, 18.0)).unwrap();
        assert!((60.0 / p - 90.0).abs() < 2.0, "{} bpm", 60.0 / p);
    }

    /// A soft roll of 32nds between quarter notes at 96 bpm: the beats stay on the quarter grid through it, none taken
    /// from a roll stroke beside its beat, and the tempo map stays one step.
    #[test]
    fn a_roll_does_not_bend_the_beat() {
        let beat = 60.0 / 96.0;
        let mut times: Vec<f64> = (0..8).map(|k| 0.5 + k as f64 * beat).collect();
        let roll_start = 0.5 + 8.0 * beat;
        times.extend((0..64).map(|k| roll_start + k as f64 * beat / 8.0));
        times.extend((0..8).map(|k| roll_start + (8 + k) as f64 * beat));
        // A soft roll (onsets 0.6 of the beats'), unevenly played: now and then the stroke
        // after a beat is nearly as strong as the beat itself.
        let mut s = pulses(&times, times.last().unwrap() + 1.0);
        for (k, t) in times.iter().enumerate().skip(8).take(64) {
            // The roll's first stroke is a beat as loud as the others; the stroke after
            // its second and third beats is leaned on.
            let r = k - 8;
            let strength = match (r / 8, r % 8) {
                (0, 0) => 1.0,
                (1 | 2, 1) => 0.8,
                _ => 0.6,
            };
            s.values[(t / s.hop_s).round() as usize] = strength;
        }
        let p = period_s(&s).unwrap();
        let mut beats = track(&s, p, &times);
        snap(&mut beats, &times);
        for b in &beats {
            let k = ((b - 0.5) / beat).round();
            assert!(
                (b - (0.5 + k * beat)).abs() < 0.006,
                "beat at {b:.3} s is off the quarter grid: {beats:?}"
            );
        }
        let points = tempo_map(&beats, &vec![true; beats.len()], 960, 960);
        assert!(points.len() <= 2, "{points:?}");
    }

    /// Beats slowing from 120 to 80 bpm are tracked; the tempo map puts each within 4 ms.
    #[test]
    fn follows_a_tempo_change() {
        let mut t = 0.5;
        let mut times = Vec::new();
        for k in 0..32 {
            times.push(t);
            let bpm = 120.0 - 40.0 * (f64::from(k) / 31.0);
            t += 60.0 / bpm;
        }
        let s = pulses(&times, t + 1.0);
        let p = period_s(&s).unwrap();
        let mut beats = track(&s, p, &times);
        snap(&mut beats, &times);
        for x in &times {
            assert!(
                beats.iter().any(|b| (b - x).abs() < 1e-9),
                "{x} not a beat: {beats:?}"
            );
        }
        let first = beats[0];
        let first_tick = (first / p).round() as u64 * 960;
        let points = tempo_map(&beats, &vec![true; beats.len()], 960, first_tick);
        let map = TempoMap::new(&points, 960);
        for (k, b) in beats.iter().enumerate() {
            let at = map.seconds_at((first_tick + k as u64 * 960) as f64);
            assert!(
                (at - b).abs() <= TEMPO_TOLERANCE_S + 1e-9,
                "beat {k}: {at} vs {b}"
            );
        }
        assert!(points.len() < beats.len(), "{} points", points.len());
    }

    /// A lead-in a few milliseconds long (the first stroke just after the file starts)
    /// takes the tempo after it, not a tempo of its own; a lead-in that the tempo after it
    /// would misplace keeps its own; no beats give the prior's tempo.
    #[test]
    fn a_short_lead_in_takes_the_first_tempo() {
        let beats: Vec<f64> = (0..8).map(|k| 0.0055 + f64::from(k) * 0.5).collect();
        let points = tempo_map(&beats, &[true; 8], 960, 11);
        assert_eq!(points.len(), 1, "{points:?}");
        assert_eq!(points[0].tick, 0);
        assert!((points[0].bpm - 120.0).abs() < 1e-9, "{points:?}");
        let map = TempoMap::new(&points, 960);
        assert!((map.seconds_at(11.0) - beats[0]).abs() <= TEMPO_TOLERANCE_S);
        // A first beat at 0.3 s written one beat in: 200 bpm before it, 120 after.
        let late: Vec<f64> = beats.iter().map(|b| b - 0.0055 + 0.3).collect();
        let points = tempo_map(&late, &[true; 8], 960, 960);
        assert_eq!(points.len(), 2, "{points:?}");
        assert!((points[0].bpm - 200.0).abs() < 1e-9, "{points:?}");
        let prior = tempo_map(&[], &[], 960, 0);
        assert_eq!(prior.len(), 1);
        assert!((prior[0].bpm - PRIOR_BPM).abs() < 1e-12);
    }

    /// A beat a third off is taken back when the strokes read plainly at the right one:
    /// five strokes at 0, 1, 1½, 3 and 4 beats of 72 bpm heard at 48 bpm; half notes and
    /// quarters at 76 bpm heard at 114. Sixteenths stay at their beat, and so does a
    /// piece at 80, 120 and 90 bpm, which no one period writes plainly.
    #[test]
    fn a_beat_a_third_off_is_taken_back() {
        let at = |bpm: f64, beats: &[f64]| -> Vec<f64> {
            beats.iter().map(|b| 0.5 + b * 60.0 / bpm).collect()
        };
        let close = |p: f64, bpm: f64| (60.0 / p - bpm).abs() < 1e-6;
        let improvisation = at(72.0, &[0.0, 1.0, 1.5, 3.0, 4.0]);
        assert!(close(plainest_period_s(60.0 / 48.0, &improvisation), 72.0));
        let study = at(
            76.0,
            &[0.0, 2.0, 4.0, 6.0, 8.0, 9.0, 10.0, 11.0, 12.0, 14.0],
        );
        assert!(close(plainest_period_s(60.0 / 114.0, &study), 76.0));
        assert!(close(plainest_period_s(60.0 / 76.0, &study), 76.0));
        let sixteenths: Vec<f64> = (0..64).map(|k| 0.5 + f64::from(k) * 0.15).collect();
        assert!(close(plainest_period_s(0.6, &sixteenths), 100.0));
        let mut changing = at(80.0, &(0..13).map(f64::from).collect::<Vec<_>>());
        for beat_s in [0.5, 60.0 / 90.0] {
            let last = *changing.last().unwrap();
            changing.extend((1..=8).map(|k| last + f64::from(k) * beat_s));
        }
        assert!(close(plainest_period_s(0.75, &changing), 80.0));
    }

    /// Three strokes 3 s apart: a beat of their own (five beats each, 100 bpm) and one
    /// tempo, however the tracker's beats in the silences between them wander; were those
    /// beats strokes, the tempo would follow them.
    #[test]
    fn sparse_strokes_keep_one_tempo() {
        assert_eq!(
            sparse_period_s(1.2),
            None,
            "a beat of 50 bpm is heard as it is"
        );
        let period = sparse_period_s(3.0).unwrap();
        assert!((period - 0.6).abs() < 1e-12, "{period}");
        assert!((sparse_period_s(2.0).unwrap() - 2.0 / 3.0).abs() < 1e-12);
        let wander = [0.0, 0.03, -0.025, 0.04, -0.035];
        let beats: Vec<f64> = (0..11)
            .map(|k| {
                1.0 + 0.6 * f64::from(k)
                    + if k % 5 == 0 {
                        0.0
                    } else {
                        wander[k as usize % 5]
                    }
            })
            .collect();
        let on_stroke: Vec<bool> = (0..11).map(|k| k % 5 == 0).collect();
        let points = tempo_map(&beats, &on_stroke, 960, 0);
        assert_eq!(points.len(), 1, "{points:?}");
        assert!((points[0].bpm - 100.0).abs() < 1e-9, "{points:?}");
        // Heard, the same wandering beats are followed.
        assert!(tempo_map(&beats, &[true; 11], 960, 0).len() > 1);
    }
}
