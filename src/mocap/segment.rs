//! Stroke segmentation: find the impacts of a stick-tip trajectory and cut it into motion
//! units.
//!
//! An impact is a prominent height minimum where a fast descent turns abruptly into a
//! rebound: the tip must approach at [`SegmentParams::min_approach_speed`] or faster, the
//! vertical velocity must jump upward by at least [`SegmentParams::min_reversal_accel`]
//! across the minimum (the acceleration spike of a contact, measured over
//! [`SegmentParams::reversal_velocity_s`] on each side so 1 mm of marker noise does not
//! fake or hide it), the tip must rise again, and the minimum must lie near the membrane
//! plane, whose height is estimated from the data (the median of the candidate minima).
//! Minima shallower than [`SegmentParams::min_prominence_m`] are jitter, not candidates.
//! Every candidate turned down is counted by its [`Rejection`] reason.
//!
//! Short gaps are filled linearly first; a candidate next to a gap that stayed open cannot
//! be judged and is rejected as [`Rejection::NearGap`]. A unit runs from the end of the
//! previous stroke's rebound to the end of its own rebound; the first and last strokes of a
//! take are dropped as broken.

use crate::base::stats::median;
use glam::DVec3;

/// Segmentation thresholds.
#[derive(Clone, Debug, PartialEq)]
pub struct SegmentParams {
    /// A stroke must descend at least this fast somewhere in the window before impact, m/s.
    pub min_approach_speed: f64,
    /// Window before and after the minimum checked for the descent and the rebound, s.
    pub reversal_window_s: f64,
    /// Span of the one-sided velocities compared across a minimum, s.
    pub reversal_velocity_s: f64,
    /// The upward velocity change across an impact, divided by that span, must reach this,
    /// m/s² (a turn at the bottom of a smooth motion stays far below; a felt mallet on a
    /// head gives hundreds).
    pub min_reversal_accel: f64,
    /// The tip must rise at least this fast somewhere in the window after impact, m/s.
    pub min_rebound_speed: f64,
    /// A minimum is a candidate only if the height rises this much on both sides within
    /// the window, m.
    pub min_prominence_m: f64,
    /// Impacts lie within this distance of the estimated membrane plane, m; `None` skips
    /// the test (a rigid body's origin, whose height at impact varies with the stick angle).
    pub plane_tolerance_m: Option<f64>,
    /// Two impacts of one stick are at least this far apart, s.
    pub min_interval_s: f64,
    /// The rebound ends when the upward speed has fallen to this fraction of its peak.
    pub rebound_end_fraction: f64,
    /// Span of the central-difference velocity that finds the end of a rebound, s.
    pub rebound_velocity_s: f64,
    /// Gaps (missing samples) up to this long are filled linearly, s.
    pub max_gap_s: f64,
}

impl Default for SegmentParams {
    fn default() -> Self {
        SegmentParams {
            min_approach_speed: 0.3,
            reversal_window_s: 0.04,
            reversal_velocity_s: 0.012,
            min_reversal_accel: 40.0,
            min_rebound_speed: 0.05,
            min_prominence_m: 0.005,
            plane_tolerance_m: Some(0.05),
            min_interval_s: 0.08,
            rebound_end_fraction: 0.25,
            rebound_velocity_s: 0.004,
            max_gap_s: 0.05,
        }
    }
}

/// Why a candidate minimum was not taken as an impact.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Rejection {
    /// Next to a gap that was too long to fill.
    NearGap,
    /// The descent before it was slower than [`SegmentParams::min_approach_speed`].
    SlowApproach,
    /// The turn was smooth: no acceleration spike.
    SoftTurn,
    /// The tip did not rise again within the window.
    NoRebound,
    /// Too far from the membrane plane.
    OffPlane,
    /// Too soon after (or before) a deeper impact of the same stick.
    TooClose,
}

impl Rejection {
    /// Every reason, in report order.
    pub const ALL: [Rejection; 6] = [
        Rejection::NearGap,
        Rejection::SlowApproach,
        Rejection::SoftTurn,
        Rejection::NoRebound,
        Rejection::OffPlane,
        Rejection::TooClose,
    ];

    /// The reason in words, for reports.
    pub fn describe(self) -> &'static str {
        match self {
            Rejection::NearGap => "next to an unfilled gap",
            Rejection::SlowApproach => "slow approach",
            Rejection::SoftTurn => "smooth turn (no impact spike)",
            Rejection::NoRebound => "no rebound",
            Rejection::OffPlane => "off the membrane plane",
            Rejection::TooClose => "too close to a deeper impact",
        }
    }
}

/// How many candidates were rejected, per reason (indexed like [`Rejection::ALL`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RejectionCounts(pub [usize; 6]);

impl RejectionCounts {
    fn add(&mut self, reason: Rejection) {
        self.0[Rejection::ALL
            .iter()
            .position(|&r| r == reason)
            .unwrap_or(0)] += 1;
    }

    /// The count for `reason`.
    pub fn get(&self, reason: Rejection) -> usize {
        Rejection::ALL
            .iter()
            .position(|&r| r == reason)
            .map_or(0, |i| self.0[i])
    }

    /// All rejected candidates.
    pub fn total(&self) -> usize {
        self.0.iter().sum()
    }

    /// "3 slow approach, 1 off the membrane plane", or "none".
    pub fn summary(&self) -> String {
        let parts: Vec<String> = Rejection::ALL
            .iter()
            .filter(|&&r| self.get(r) > 0)
            .map(|&r| format!("{} {}", self.get(r), r.describe()))
            .collect();
        if parts.is_empty() {
            "none".into()
        } else {
            parts.join(", ")
        }
    }
}

impl std::ops::AddAssign for RejectionCounts {
    fn add_assign(&mut self, other: Self) {
        for (a, b) in self.0.iter_mut().zip(other.0) {
            *a += b;
        }
    }
}

/// One cut stroke, as frame indices into the take.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct UnitSpan {
    /// First frame (end of the previous stroke's rebound).
    pub start: usize,
    /// The impact frame.
    pub impact: usize,
    /// Last frame (end of this stroke's rebound), inclusive.
    pub end: usize,
}

/// What segmentation found in one tip trajectory.
#[derive(Clone, Debug, PartialEq)]
pub struct Segmentation {
    /// Every impact frame, in order.
    pub impacts: Vec<usize>,
    /// The same impacts with their heights, approach speeds and reversals.
    pub found: Vec<Impact>,
    /// The estimated membrane height, m (`None` without impacts).
    pub plane_height_m: Option<f64>,
    /// Complete units (the broken first and last strokes dropped).
    pub units: Vec<UnitSpan>,
    /// Candidates turned down, by reason.
    pub rejected: RejectionCounts,
    /// Samples missing in the capture.
    pub missing_frames: usize,
    /// Of those, samples filled by interpolation.
    pub filled_frames: usize,
}

/// Fill gaps of at most `max_gap` frames by linear interpolation; longer gaps stay `None`.
pub fn fill_gaps(samples: &[Option<DVec3>], max_gap: usize) -> Vec<Option<DVec3>> {
    let mut out = samples.to_vec();
    let mut i = 0;
    while i < out.len() {
        if out[i].is_some() {
            i += 1;
            continue;
        }
        let start = i;
        while i < out.len() && out[i].is_none() {
            i += 1;
        }
        let (before, after) = (
            start.checked_sub(1).and_then(|b| out[b]),
            out.get(i).copied().flatten(),
        );
        if let (Some(a), Some(b)) = (before, after)
            && i - start <= max_gap
        {
            let n = (i - start + 1) as f64;
            for (k, slot) in out[start..i].iter_mut().enumerate() {
                *slot = Some(a.lerp(b, (k + 1) as f64 / n));
            }
        }
    }
    out
}

/// An impact found in a height series.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Impact {
    /// Frame of the height minimum.
    pub frame: usize,
    /// Height there, m.
    pub height_m: f64,
    /// Fastest descent in the window before, m/s.
    pub approach_mps: f64,
    /// Upward velocity change across the minimum per unit time, m/s².
    pub reversal_accel: f64,
}

/// Find impacts in a height series sampled at `rate_hz` (NaN where unseen): every
/// prominent minimum judged as described in the module doc, the membrane plane estimated
/// and applied when `params.plane_tolerance_m` is set. Returns the impacts in time order,
/// the plane height, and the rejected candidates by reason.
pub fn find_impacts(
    height: &[f64],
    rate_hz: f64,
    params: &SegmentParams,
) -> (Vec<Impact>, Option<f64>, RejectionCounts) {
    let n = height.len();
    let frames = |s: f64| ((s * rate_hz).round() as usize).max(1);
    let window = frames(params.reversal_window_s);
    let k = frames(params.reversal_velocity_s);
    let dt = 1.0 / rate_hz;
    let slope = |a: usize, b: usize| (height[b] - height[a]) / ((b - a) as f64 * dt);
    let mut rejected = RejectionCounts::default();
    let mut accepted: Vec<Impact> = Vec::new();
    for i in 1..n.saturating_sub(1) {
        let h = height[i];
        if !(h.is_finite() && h <= height[i - 1] && h < height[i + 1]) {
            continue;
        }
        let before = &height[i.saturating_sub(window)..i];
        let after = &height[i + 1..(i + 1 + window).min(n)];
        let rise = |side: &[f64]| {
            side.iter()
                .copied()
                .filter(|x| x.is_finite())
                .fold(f64::NEG_INFINITY, f64::max)
                - h
        };
        let lowest_near = before.iter().chain(after).all(|&x| x.is_nan() || x >= h);
        if !lowest_near
            || rise(before) < params.min_prominence_m
            || rise(after) < params.min_prominence_m
        {
            continue;
        }
        let near = &height[i.saturating_sub(k)..(i + k + 1).min(n)];
        if i < k || i + k >= n || near.iter().any(|x| !x.is_finite()) {
            rejected.add(Rejection::NearGap);
            continue;
        }
        let approach = (i.saturating_sub(window).max(k)..=i)
            .map(|j| -slope(j - k, j))
            .filter(|v| v.is_finite())
            .fold(0.0, f64::max);
        let rebound = (i..(i + window).min(n - 1 - k))
            .map(|j| slope(j, j + k))
            .filter(|v| v.is_finite())
            .fold(0.0, f64::max);
        let reversal_accel = (i.saturating_sub(1).max(k)..=(i + 1).min(n - 1 - k))
            .map(|j| (slope(j, j + k) - slope(j - k, j)) / (k as f64 * dt))
            .fold(0.0, f64::max);
        let reason = if approach < params.min_approach_speed {
            Some(Rejection::SlowApproach)
        } else if reversal_accel < params.min_reversal_accel {
            Some(Rejection::SoftTurn)
        } else if rebound < params.min_rebound_speed {
            Some(Rejection::NoRebound)
        } else {
            None
        };
        match reason {
            Some(r) => rejected.add(r),
            None => accepted.push(Impact {
                frame: i,
                height_m: h,
                approach_mps: approach,
                reversal_accel,
            }),
        }
    }
    let plane = median(accepted.iter().map(|c| c.height_m));
    if let (Some(plane), Some(tolerance)) = (plane, params.plane_tolerance_m) {
        accepted.retain(|c| {
            let keep = (c.height_m - plane).abs() <= tolerance;
            if !keep {
                rejected.add(Rejection::OffPlane);
            }
            keep
        });
    }
    let min_gap = frames(params.min_interval_s);
    let mut impacts: Vec<Impact> = Vec::with_capacity(accepted.len());
    for c in accepted {
        match impacts.last_mut() {
            Some(last) if c.frame - last.frame < min_gap => {
                if c.height_m < last.height_m {
                    *last = c;
                }
                rejected.add(Rejection::TooClose);
            }
            _ => impacts.push(c),
        }
    }
    (impacts, plane, rejected)
}

/// Find impacts and units in a tip trajectory sampled at `rate_hz`, with +z up.
pub fn segment(tip: &[Option<DVec3>], rate_hz: f64, params: &SegmentParams) -> Segmentation {
    let filled = fill_gaps(tip, (params.max_gap_s * rate_hz).round() as usize);
    let missing_frames = tip.iter().filter(|p| p.is_none()).count();
    let still_missing = filled.iter().filter(|p| p.is_none()).count();
    let height: Vec<f64> = filled.iter().map(|p| p.map_or(f64::NAN, |p| p.z)).collect();
    let (found, plane, rejected) = find_impacts(&height, rate_hz, params);
    let impacts: Vec<usize> = found.iter().map(|i| i.frame).collect();
    let n = height.len();
    let k = ((params.rebound_velocity_s * rate_hz).round() as usize).max(1);
    let velocity = vertical_velocity(&height, rate_hz, k);
    let rebound_ends: Vec<Option<usize>> = impacts
        .iter()
        .enumerate()
        .map(|(j, &i)| {
            rebound_end(
                &velocity,
                i,
                impacts.get(j + 1).copied().unwrap_or(n),
                params,
            )
        })
        .collect();
    let units = (1..impacts.len().saturating_sub(1))
        .filter_map(|j| {
            let start = rebound_ends[j - 1]?;
            let end = rebound_ends[j]?;
            (start < impacts[j] && end > impacts[j]).then_some(UnitSpan {
                start,
                impact: impacts[j],
                end,
            })
        })
        .collect();
    Segmentation {
        impacts,
        found,
        plane_height_m: plane,
        units,
        rejected,
        missing_frames,
        filled_frames: missing_frames - still_missing,
    }
}

/// The frame after `impact` (and before `next`) where the rebound's upward speed has
/// fallen to the given fraction of its peak.
fn rebound_end(
    velocity: &[f64],
    impact: usize,
    next: usize,
    params: &SegmentParams,
) -> Option<usize> {
    let span = velocity.get(impact + 1..next)?;
    let (peak_at, peak) = span
        .iter()
        .enumerate()
        .take_while(|(_, v)| v.is_finite())
        .fold(
            (0, 0.0f64),
            |best, (k, &v)| if v > best.1 { (k, v) } else { best },
        );
    if peak <= 0.0 {
        return None;
    }
    span[peak_at..]
        .iter()
        .position(|&v| v.is_nan() || v <= params.rebound_end_fraction * peak)
        .map(|k| impact + 1 + peak_at + k)
        .filter(|&e| e < next)
}

/// Central-difference vertical velocity over ±`k` frames (fewer at the ends), m/s; NaN
/// next to missing samples.
fn vertical_velocity(height: &[f64], rate_hz: f64, k: usize) -> Vec<f64> {
    let n = height.len();
    (0..n)
        .map(|i| {
            let (a, b) = (i.saturating_sub(k), (i + k).min(n - 1));
            if a == b {
                0.0
            } else {
                (height[b] - height[a]) * rate_hz / (b - a) as f64
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A take of bouncing strokes with known impact times: a V at each impact (fast
    /// descent, slower rebound) over a smooth lift, membrane at 0.76 m.
    fn bouncing(impacts_s: &[f64], rate: f64, len_s: f64) -> Vec<Option<DVec3>> {
        let n = (len_s * rate) as usize;
        (0..n)
            .map(|f| {
                let t = f as f64 / rate;
                let k = impacts_s.partition_point(|&x| x <= t);
                let prev = if k == 0 {
                    impacts_s[0] - 0.6
                } else {
                    impacts_s[k - 1]
                };
                let next = impacts_s.get(k).copied().unwrap_or(prev + 0.6);
                let u = (t - prev) / (next - prev);
                // Lift peaks at u = 0.65: rise slowly, fall fast.
                let s = if u < 0.65 {
                    (u / 0.65 * std::f64::consts::FRAC_PI_2).sin()
                } else {
                    ((1.0 - u) / 0.35 * std::f64::consts::FRAC_PI_2).sin()
                };
                Some(DVec3::new(0.1, 0.5, 0.76 + 0.3 * s))
            })
            .collect()
    }

    /// Every impact of a synthetic take is found to ±1 frame, the plane is estimated, and
    /// the first and last strokes are dropped.
    #[test]
    fn finds_known_impacts() {
        let impacts = [0.5, 1.1, 1.62, 2.3, 2.9, 3.45, 4.1];
        let tip = bouncing(&impacts, 250.0, 4.5);
        let seg = segment(&tip, 250.0, &SegmentParams::default());
        assert_eq!(seg.impacts.len(), impacts.len());
        for (&found, &t) in seg.impacts.iter().zip(&impacts) {
            assert!(
                (found as f64 - t * 250.0).abs() <= 1.0,
                "{found} vs {}",
                t * 250.0
            );
        }
        assert!((seg.plane_height_m.unwrap() - 0.76).abs() < 1e-3);
        assert_eq!(seg.units.len(), impacts.len() - 2);
        for (u, &i) in seg.units.iter().zip(&seg.impacts[1..]) {
            assert!(u.start < u.impact && u.impact < u.end && u.impact == i);
        }
        for w in seg.units.windows(2) {
            assert_eq!(w[0].end, w[1].start, "units tile the take");
        }
    }

    /// Short gaps are filled; the impacts are still found.
    #[test]
    fn survives_short_gaps() {
        let impacts = [0.5, 1.1, 1.7, 2.3];
        let mut tip = bouncing(&impacts, 250.0, 2.8);
        for f in (100..600).step_by(37) {
            tip[f] = None;
            tip[f + 1] = None;
        }
        let seg = segment(&tip, 250.0, &SegmentParams::default());
        assert_eq!(seg.impacts.len(), impacts.len());
    }

    /// A still or empty trajectory has no impacts and no units (and does not panic).
    #[test]
    fn nothing_to_find() {
        let still = vec![Some(DVec3::new(0.0, 0.0, 1.0)); 500];
        assert!(
            segment(&still, 250.0, &SegmentParams::default())
                .impacts
                .is_empty()
        );
        assert!(
            segment(&[], 250.0, &SegmentParams::default())
                .units
                .is_empty()
        );
        assert!(
            segment(&[None; 10], 250.0, &SegmentParams::default())
                .units
                .is_empty()
        );
    }
}
