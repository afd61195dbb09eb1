//! The edit layer on top of a composed trajectory: each [`Handle`] adds a smooth
//! displacement, a cubic B-spline bump — C2, exactly zero outside its support, so samples
//! outside it are left bit-identical — masked to zero (with zero velocity) at the hand's
//! impacts so that strokes still land where and when the score says. Impact points are
//! moved with [`ImpactPin`](crate::score::ImpactPin)s, applied when planning.

use super::compose::Composition;
use crate::mocap::db::side_index;
use crate::score::{Handle, Score};
use glam::DVec3;

/// Half-width of the mask that keeps handles off the impacts, s.
pub const IMPACT_MASK_S: f64 = 0.06;

/// The cubic B-spline basis scaled to 1 at its centre: support (−2, 2), C2.
pub fn bump(u: f64) -> f64 {
    let a = u.abs();
    if a >= 2.0 {
        0.0
    } else if a <= 1.0 {
        (2.0 / 3.0 - a * a + 0.5 * a * a * a) * 1.5
    } else {
        (2.0 - a).powi(3) / 6.0 * 1.5
    }
}

/// Centre and half-width in seconds of a handle's support.
pub fn support_s(score: &Score, handle: &Handle) -> (f64, f64) {
    let map = score.tempo_map();
    let tick = handle.tick as f64;
    let reach = handle.reach_ticks as f64;
    let half = 0.5 * (map.seconds_at(tick + reach) - map.seconds_at((tick - reach).max(0.0)));
    (map.seconds_at(tick), half)
}

/// Displacement of one handle at time `t`, before the impact mask, m.
fn raw(handle: &Handle, centre: f64, half: f64, t: f64) -> DVec3 {
    DVec3::from_array(handle.offset_m) * bump(2.0 * (t - centre) / half)
}

/// Add every handle of `score` to `comp`.
pub fn apply(comp: &mut Composition, score: &Score) {
    for handle in &score.handles {
        let (centre, half) = support_s(score, handle);
        let h = side_index(handle.hand);
        let impacts: Vec<f64> = comp
            .strokes
            .iter()
            .zip(&comp.impact_samples)
            .filter(|(s, _)| s.hand == handle.hand)
            .map(|(_, &k)| comp.time(k))
            .collect();
        let first = ((centre - half - comp.start_s) * comp.rate_hz)
            .floor()
            .max(0.0) as usize;
        let last = (((centre + half - comp.start_s) * comp.rate_hz)
            .ceil()
            .max(0.0) as usize)
            .min(comp.len());
        for k in first..last {
            let t = comp.time(k);
            let mask: f64 = impacts
                .iter()
                .filter(|&&ti| (t - ti).abs() < IMPACT_MASK_S)
                .map(|&ti| 1.0 - bump(2.0 * (t - ti) / IMPACT_MASK_S))
                .product();
            let d = raw(handle, centre, half, t) * mask;
            if d != DVec3::ZERO {
                comp.tips[h][k] += d;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The bump is 1 at its centre, 0 from ±2 on, smooth across the knots.
    #[test]
    fn bump_shape() {
        assert_eq!(bump(0.0), 1.0);
        assert_eq!(bump(2.0), 0.0);
        assert_eq!(bump(-2.5), 0.0);
        for knot in [1.0f64, 2.0] {
            let e = 1e-6;
            let d = |x: f64| (bump(x + e) - bump(x - e)) / (2.0 * e);
            let dd = |x: f64| (bump(x + e) - 2.0 * bump(x) + bump(x - e)) / (e * e);
            assert!(
                (d(knot - 1e-3) - d(knot + 1e-3)).abs() < 1e-2,
                "C1 at {knot}"
            );
            assert!(
                (dd(knot - 1e-3) - dd(knot + 1e-3)).abs() < 1e-1,
                "C2 at {knot}"
            );
        }
    }
}
