//! Where the simulated timpanist looks while playing: at the drum about to be struck.
//! The gaze turns to each stroke's point on its head [`LEAD_S`] before the stroke, the
//! turn spread over [`TURN_S`] (so it is on the drum about 0.05 s before the stroke);
//! strokes struck together are looked at between them. The head follows the hands
//! (seed 003 §4.3.3); `body::gaze` turns the neck and head toward these points.

use crate::motion::compose::Composition;
use glam::DVec3;

/// The gaze turns to the next drum this long before it is struck, s...
pub const LEAD_S: f64 = 0.2;
/// ...over this long, s: the turns are a moving average of the drum to look at, so a fast
/// alternation between two drums is followed by a smaller sway between them rather than a
/// whipping head.
pub const TURN_S: f64 = 0.4;
/// Strokes closer than this are looked at together, s.
const TOGETHER_S: f64 = 0.01;

/// The point looked at per composition sample (m, performer frame).
pub fn gaze_points(comp: &Composition) -> Vec<DVec3> {
    let looks = looks(comp);
    if looks.is_empty() {
        return vec![DVec3::new(0.0, 0.7, 0.8); comp.len()];
    }
    // The drum to look at: the last one struck, from LEAD_S before it is struck.
    let mut current = 0;
    let steps: Vec<DVec3> = (0..comp.len())
        .map(|k| {
            let t = comp.time(k) + LEAD_S;
            while current + 1 < looks.len() && looks[current + 1].0 <= t {
                current += 1;
            }
            looks[current].1
        })
        .collect();
    moving_average(&steps, (0.5 * TURN_S * comp.rate_hz).round() as usize)
}

/// The mean of `values` over k − half ..= k + half (cut at the ends), per k.
fn moving_average(values: &[DVec3], half: usize) -> Vec<DVec3> {
    let mut sums = Vec::with_capacity(values.len() + 1);
    sums.push(DVec3::ZERO);
    for v in values {
        sums.push(sums[sums.len() - 1] + *v);
    }
    (0..values.len())
        .map(|k| {
            let (a, b) = (k.saturating_sub(half), (k + half + 1).min(values.len()));
            (sums[b] - sums[a]) / (b - a) as f64
        })
        .collect()
}

/// The points to look at and when they are struck (score s), in time order: each stroke's
/// point on its head, strokes struck together merged into their mean.
fn looks(comp: &Composition) -> Vec<(f64, DVec3)> {
    let mut strokes: Vec<(f64, DVec3)> =
        comp.strokes.iter().map(|s| (s.time_s, s.target)).collect();
    strokes.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut looks: Vec<(f64, DVec3, usize)> = Vec::new();
    for (t, p) in strokes {
        match looks.last_mut() {
            Some((t0, sum, n)) if t - *t0 < TOGETHER_S => {
                *sum += p;
                *n += 1;
            }
            _ => looks.push((t, p, 1)),
        }
    }
    looks
        .into_iter()
        .map(|(t, sum, n)| (t, sum / n as f64))
        .collect()
}
