//! The targets the simulated body follows for a whole score, made from the composition:
//! the felt ball's centre carried one ball radius above the composed tip (the database's
//! tips touch the head surface at impact), a *strike-through* dip so each stroke aims a
//! few millimetres into the head (players strike through the head, not onto it), and a
//! per-hand time warp that plays each stroke earlier or later by the shift the timing
//! compensation measured (issue 6 §5).

use crate::body::sim::Reference;
use crate::motion::compose::Composition;

/// What the compensation adjusts per stroke: the target of stroke i is played
/// `shift_s[i]` earlier and aims `depth_m[i]` below the head. Between a hand's strokes the
/// shift is interpolated linearly, before its first and after its last it is held, so the
/// warp stays smooth and monotonic (shifts ≪ stroke gaps).
#[derive(Clone, Debug, PartialEq)]
pub struct Adjustments {
    pub shift_s: Vec<f64>,
    pub depth_m: Vec<f64>,
}

impl Adjustments {
    /// No shift and the same depth for `strokes` strokes.
    pub fn uniform(strokes: usize, depth_m: f64) -> Adjustments {
        Adjustments {
            shift_s: vec![0.0; strokes],
            depth_m: vec![depth_m; strokes],
        }
    }
}

/// How the targets are shaped around impacts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StrikeShape {
    /// Felt ball radius, m: the tip target is raised by it.
    pub ball_radius_m: f64,
    /// Half-width of the dip around an impact, s (narrowed for close strokes).
    pub half_width_s: f64,
}

/// The reference of `comp` shaped by `shape` and `adjust` (one entry per stroke). Its time
/// 0 is `comp.start_s` of the score; its beats are the strokes' impacts.
pub fn targets(comp: &Composition, shape: &StrikeShape, adjust: &Adjustments) -> Reference {
    let rate = comp.rate_hz;
    let n = comp.len();
    let tips: [Vec<glam::DVec3>; 2] = std::array::from_fn(|h| {
        let side = crate::mocap::db::SIDES[h];
        // This hand's strokes: (reference time of the impact, shift) and depths.
        let (mine, depths): (Vec<(f64, f64)>, Vec<f64>) = comp
            .strokes
            .iter()
            .zip(adjust.shift_s.iter().zip(&adjust.depth_m))
            .filter(|(s, _)| s.hand == side)
            .map(|(s, (&d, &depth))| ((s.time_s - comp.start_s, d), depth))
            .unzip();
        let mut shaped = comp.tips[h].clone();
        for p in &mut shaped {
            p.z += shape.ball_radius_m;
        }
        for (i, &(t, _)) in mine.iter().enumerate() {
            let gap = |j: Option<&(f64, f64)>| j.map_or(f64::INFINITY, |&(u, _)| (u - t).abs());
            let half = shape
                .half_width_s
                .min(0.4 * gap(i.checked_sub(1).and_then(|j| mine.get(j))))
                .min(0.4 * gap(mine.get(i + 1)));
            let (first, last) = (((t - half) * rate).ceil(), ((t + half) * rate).floor());
            let first = (first.max(0.0) as usize).min(n);
            let last = (last.max(0.0) as usize + 1).min(n).max(first);
            for (k, p) in shaped.iter_mut().enumerate().take(last).skip(first) {
                let x = (k as f64 / rate - t) / half;
                if x.abs() < 1.0 {
                    p.z -= depths[i] * 0.5 * (1.0 + (std::f64::consts::PI * x).cos());
                }
            }
        }
        (0..n)
            .map(|k| {
                let t = k as f64 / rate;
                sample(&shaped, (t + shift_at(&mine, t)) * rate)
            })
            .collect()
    });
    let mut beats: Vec<(f64, usize)> = comp
        .strokes
        .iter()
        .map(|s| (s.time_s - comp.start_s, s.beat))
        .collect();
    beats.sort_by(|a, b| a.0.total_cmp(&b.0));
    Reference {
        rate_hz: rate,
        tips,
        poses: None,
        beats,
    }
}

/// The shift at time `t` from a hand's (time, shift) points.
fn shift_at(points: &[(f64, f64)], t: f64) -> f64 {
    match points.iter().position(|&(u, _)| u > t) {
        None => points.last().map_or(0.0, |p| p.1),
        Some(0) => points[0].1,
        Some(i) => {
            let ((t0, d0), (t1, d1)) = (points[i - 1], points[i]);
            d0 + (d1 - d0) * (t - t0) / (t1 - t0)
        }
    }
}

/// Linear interpolation of `points` at fractional index `x`, held at the ends.
fn sample(points: &[glam::DVec3], x: f64) -> glam::DVec3 {
    let last = points.len() - 1;
    let x = x.clamp(0.0, last as f64);
    let i = (x.floor() as usize).min(last.saturating_sub(1));
    let u = x - i as f64;
    if last == 0 {
        return points[0];
    }
    points[i].lerp(points[i + 1], u)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The warp interpolates between strokes and holds outside them.
    #[test]
    fn shift_interpolates_and_holds() {
        let points = [(1.0, 0.01), (2.0, -0.01)];
        assert_eq!(shift_at(&points, 0.0), 0.01);
        assert!((shift_at(&points, 1.5) - 0.0).abs() < 1e-12);
        assert_eq!(shift_at(&points, 3.0), -0.01);
        assert_eq!(shift_at(&[], 3.0), 0.0);
    }

    /// Sampling at a fractional index is linear and clamped.
    #[test]
    fn sampling_is_linear_and_clamped() {
        let pts = [glam::DVec3::ZERO, glam::DVec3::X];
        assert_eq!(sample(&pts, 0.25), glam::DVec3::new(0.25, 0.0, 0.0));
        assert_eq!(sample(&pts, -3.0), glam::DVec3::ZERO);
        assert_eq!(sample(&pts, 9.0), glam::DVec3::X);
    }
}
