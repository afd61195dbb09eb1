//! Stroke segmentation: find the impacts of a stick-tip trajectory and cut it into motion
//! units. An impact is a height minimum where a fast descent turns into a rebound, close
//! to the membrane plane, whose height is estimated from the data (the median of the
//! candidate minima). A unit runs from the end of the previous stroke's rebound to the end
//! of its own rebound; the first and last strokes of a take are dropped as broken.

use glam::DVec3;

/// Segmentation thresholds.
#[derive(Clone, Debug, PartialEq)]
pub struct SegmentParams {
    /// A stroke must descend at least this fast somewhere in the window before impact, m/s.
    pub min_approach_speed: f64,
    /// Window before and after the minimum checked for the reversal, s.
    pub reversal_window_s: f64,
    /// Impacts lie within this distance of the estimated membrane plane, m.
    pub plane_tolerance_m: f64,
    /// Two impacts of one stick are at least this far apart, s.
    pub min_interval_s: f64,
    /// The rebound ends when the upward speed has fallen to this fraction of its peak.
    pub rebound_end_fraction: f64,
    /// Gaps (missing samples) up to this long are filled linearly, s.
    pub max_gap_s: f64,
}

impl Default for SegmentParams {
    fn default() -> Self {
        SegmentParams {
            min_approach_speed: 0.3,
            reversal_window_s: 0.04,
            plane_tolerance_m: 0.05,
            min_interval_s: 0.08,
            rebound_end_fraction: 0.25,
            max_gap_s: 0.05,
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
    /// The estimated membrane height, m (`None` without impacts).
    pub plane_height_m: Option<f64>,
    /// Complete units (the broken first and last strokes dropped).
    pub units: Vec<UnitSpan>,
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

/// Find impacts and units in a tip trajectory sampled at `rate_hz`, with +z up.
pub fn segment(tip: &[Option<DVec3>], rate_hz: f64, params: &SegmentParams) -> Segmentation {
    let filled = fill_gaps(tip, (params.max_gap_s * rate_hz).round() as usize);
    let n = filled.len();
    let height: Vec<f64> = filled.iter().map(|p| p.map_or(f64::NAN, |p| p.z)).collect();
    let velocity = vertical_velocity(&height, rate_hz);
    let window = ((params.reversal_window_s * rate_hz).round() as usize).max(1);
    let mut candidates: Vec<usize> = (1..n.saturating_sub(1))
        .filter(|&i| {
            let h = height[i];
            h.is_finite()
                && h <= height[i - 1]
                && h < height[i + 1]
                && velocity[i.saturating_sub(window)..i]
                    .iter()
                    .any(|v| *v < -params.min_approach_speed)
                && velocity[i + 1..(i + 1 + window).min(n)]
                    .iter()
                    .any(|v| *v > 0.0)
        })
        .collect();
    let plane = median(candidates.iter().map(|&i| height[i]).collect());
    if let Some(plane) = plane {
        candidates.retain(|&i| (height[i] - plane).abs() <= params.plane_tolerance_m);
    }
    let min_gap = (params.min_interval_s * rate_hz).round() as usize;
    let mut impacts: Vec<usize> = Vec::with_capacity(candidates.len());
    for c in candidates {
        match impacts.last_mut() {
            Some(last) if c - *last < min_gap => {
                if height[c] < height[*last] {
                    *last = c;
                }
            }
            _ => impacts.push(c),
        }
    }
    let rebound_ends: Vec<Option<usize>> = impacts
        .iter()
        .enumerate()
        .map(|(k, &i)| {
            rebound_end(
                &velocity,
                i,
                impacts.get(k + 1).copied().unwrap_or(n),
                params,
            )
        })
        .collect();
    let units = (1..impacts.len().saturating_sub(1))
        .filter_map(|k| {
            let start = rebound_ends[k - 1]?;
            let end = rebound_ends[k]?;
            (start < impacts[k] && end > impacts[k]).then_some(UnitSpan {
                start,
                impact: impacts[k],
                end,
            })
        })
        .collect();
    Segmentation {
        impacts,
        plane_height_m: plane,
        units,
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

/// Central-difference vertical velocity, m/s (NaN next to missing samples).
fn vertical_velocity(height: &[f64], rate_hz: f64) -> Vec<f64> {
    let n = height.len();
    (0..n)
        .map(|i| {
            let a = height[i.saturating_sub(1)];
            let b = height[(i + 1).min(n - 1)];
            let span = ((i + 1).min(n - 1) - i.saturating_sub(1)) as f64;
            if span == 0.0 {
                0.0
            } else {
                (b - a) * rate_hz / span
            }
        })
        .collect()
}

fn median(mut xs: Vec<f64>) -> Option<f64> {
    xs.retain(|x| x.is_finite());
    if xs.is_empty() {
        return None;
    }
    xs.sort_by(f64::total_cmp);
    Some(xs[xs.len() / 2])
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
