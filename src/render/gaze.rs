//! Where the simulated timpanist looks while playing: at the drum about to be struck.
//! The gaze turns to each stroke's point on its head [`LEAD_S`] before the stroke, the
//! turn spread over [`TURN_S`] (so it is on the drum about 0.05 s before the stroke);
//! strokes struck together are looked at between them. The head follows the hands
//! (seed 003 §4.3.3); `body::gaze` turns the neck and head toward these points.
//!
//! The turns are smoothed as bearings about the player's vertical axis (with the distance
//! and the height), not as points: the drums stand on an arc round the player, and the
//! mean of points on two sides of it lies near the player's body, where a few centimetres
//! swing the face by tens of degrees (a fast passage over four drums had the target neck
//! turning ±20° at the stroke rate).

use crate::motion::compose::Composition;
use glam::DVec3;

/// The gaze turns to the next drum this long before it is struck, s...
pub const LEAD_S: f64 = 0.2;
/// ...over this long, s: the turns are a triangular moving average (a box of half this
/// width, twice: the turn's speed has no jumps) of the drum to look at, so a fast
/// alternation between two drums is followed by a smaller sway between them rather than a
/// whipping head.
pub const TURN_S: f64 = 0.4;
/// Strokes closer than this are looked at together, s.
const TOGETHER_S: f64 = 0.01;

/// The point looked at per composition sample (m, performer frame), from the [`looks`] of
/// `comp`.
pub fn gaze_points(looks: &[(f64, DVec3)], comp: &Composition) -> Vec<DVec3> {
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
    smooth_turns(&steps, comp.rate_hz)
}

/// The points looked at per sample (`steps`, m, at `rate_hz`) turned to smoothly: their
/// bearings, distances and heights averaged over [`TURN_S`].
fn smooth_turns(steps: &[DVec3], rate_hz: f64) -> Vec<DVec3> {
    // Bearings run from straight behind on the right (−π) round the front to straight
    // behind on the left (π), so a turn between drums on the two sides, even a little
    // behind the player, averages through the front, never round the back.
    let bearings: Vec<DVec3> = steps.iter().map(|&p| bearing(p)).collect();
    let half = (0.25 * TURN_S * rate_hz).round() as usize;
    moving_average(&moving_average(&bearings, half), half)
        .into_iter()
        .map(point)
        .collect()
}

/// A point (m, performer frame) as (bearing from straight ahead, positive to the player's
/// left, rad; horizontal distance from the vertical axis through the origin, m; height, m):
/// the bearing `body::gaze::look_at` turns the face to.
fn bearing(p: DVec3) -> DVec3 {
    DVec3::new((-p.x).atan2(p.y), p.truncate().length(), p.z)
}

/// The point of a [`bearing`].
fn point(b: DVec3) -> DVec3 {
    let (sin, cos) = b.x.sin_cos();
    DVec3::new(-b.y * sin, b.y * cos, b.z)
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
/// point on its head, strokes struck together merged into the point of their mean
/// [`bearing`] (the mean of points on two sides of the arc lies next to the body, where
/// the face, turned from there to the next drum, swung round at 1000°/s: the secco
/// study's closing chord on the outer drums).
pub fn looks(comp: &Composition) -> Vec<(f64, DVec3)> {
    merged(comp.strokes.iter().map(|s| (s.time_s, s.target)).collect())
}

/// [`looks`] of strokes given as (time s, point m).
fn merged(mut strokes: Vec<(f64, DVec3)>) -> Vec<(f64, DVec3)> {
    strokes.sort_by(|a, b| a.0.total_cmp(&b.0));
    // (time, the first point, the sum of the bearings, how many)
    let mut looks: Vec<(f64, DVec3, DVec3, usize)> = Vec::new();
    for (t, p) in strokes {
        match looks.last_mut() {
            Some((t0, _, sum, n)) if t - *t0 < TOGETHER_S => {
                *sum += bearing(p);
                *n += 1;
            }
            _ => looks.push((t, p, bearing(p), 1)),
        }
    }
    looks
        .into_iter()
        .map(|(t, p, sum, n)| (t, if n == 1 { p } else { point(sum / n as f64) }))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Sixteenths at 120 bpm alternating between the outer drums (at the player's sides,
    /// a little behind): the gaze sways between them at their distance, slowly, round the
    /// front (not behind the player), instead of through their mean point next to the
    /// body, where the face would whip round.
    #[test]
    fn fast_alternation_sways_round_the_player() {
        let rate = 250.0;
        let (left, right) = (
            DVec3::new(-0.84, -0.10, 0.76),
            DVec3::new(0.80, -0.05, 0.74),
        );
        let steps: Vec<DVec3> = (0..2500)
            .map(|k| if (k / 31) % 2 == 0 { left } else { right })
            .collect();
        let looks = smooth_turns(&steps, rate);
        let middle = &looks[500..2000];
        for p in middle {
            let distance = p.truncate().length();
            assert!((0.78..0.86).contains(&distance), "{p}: {distance} m away");
        }
        let bearings: Vec<f64> = middle.iter().map(|&p| bearing(p).x).collect();
        assert!(bearings.iter().all(|b| b.abs() < 0.5), "{bearings:?}");
        let fastest = bearings
            .windows(2)
            .map(|w| (w[1] - w[0]).abs() * rate)
            .fold(0.0, f64::max);
        // Each eighth of a second the target jumps by ≈ 3.1 rad; the triangular 0.4 s
        // average leaves a sway far under that, turning at a few rad/s at most.
        let sway = bearings.iter().fold(f64::MIN, |a, &b| a.max(b))
            - bearings.iter().fold(f64::MAX, |a, &b| a.min(b));
        assert!(sway < 0.8, "sway {sway} rad");
        assert!(fastest < 4.0, "turns at {fastest} rad/s");
    }

    /// Two strokes struck together on drums at either side of the player are looked at
    /// between them at their distance, in front, not at their mean point by the body.
    #[test]
    fn a_chord_on_both_sides_is_looked_at_round_the_front() {
        let (left, right) = (DVec3::new(-0.80, 0.05, 0.76), DVec3::new(0.70, 0.30, 0.78));
        let looks = merged(vec![(1.0, left), (1.0, right), (2.0, left)]);
        assert_eq!(looks.len(), 2);
        let chord = looks[0].1;
        let distance = chord.truncate().length();
        assert!(
            (0.7..0.85).contains(&distance),
            "{chord}: {distance} m away"
        );
        assert!(chord.y > 0.6, "{chord}: not in front");
        assert_eq!(looks[1].1, left, "a single stroke's own point");
    }

    /// A turn from one drum to another is smooth: its speed changes by little from one
    /// sample to the next (no jump as a box average makes), and it ends on the new drum.
    #[test]
    fn a_turn_has_no_jumps_in_speed() {
        let rate = 250.0;
        let (a, b) = (DVec3::new(-0.5, 0.5, 0.76), DVec3::new(0.5, 0.5, 0.76));
        let steps: Vec<DVec3> = (0..500).map(|k| if k < 250 { a } else { b }).collect();
        let looks = smooth_turns(&steps, rate);
        let bearings: Vec<f64> = looks.iter().map(|&p| bearing(p).x).collect();
        let speeds: Vec<f64> = bearings.windows(2).map(|w| (w[1] - w[0]) * rate).collect();
        let jerk = speeds
            .windows(2)
            .map(|w| (w[1] - w[0]).abs())
            .fold(0.0, f64::max);
        let peak = speeds.iter().fold(0.0, |m: f64, s| m.max(s.abs()));
        assert!(jerk < 0.05 * peak, "speed jumps by {jerk} of {peak} rad/s");
        assert!((looks[499] - b).length() < 1e-9 && (looks[0] - a).length() < 1e-9);
    }
}
