//! How the composed stick-tip trajectories are coloured: plainly (one colour per hand),
//! by the tip's speed (m/s, on a ramp in [`SPEED_LEVELS`] steps from still to the
//! fastest of the composition), or by the phase of the stroke each sample belongs to —
//! preparation, downstroke, contact, rebound — read from the trajectory's vertical
//! velocity and the impact samples. Pure computation on sampled positions, no UI.

use super::marks::Rgba;
use glam::DVec3;

/// What the trajectories' colour shows.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TrailColour {
    /// One colour per hand.
    #[default]
    Plain,
    /// The tip's speed.
    Speed,
    /// The phase of the stroke.
    Phase,
}

impl TrailColour {
    /// Every colouring, in menu order.
    pub const ALL: [TrailColour; 3] = [TrailColour::Plain, TrailColour::Speed, TrailColour::Phase];

    /// The name in menus.
    pub fn name(self) -> &'static str {
        match self {
            TrailColour::Plain => "plain (by hand)",
            TrailColour::Speed => "by speed",
            TrailColour::Phase => "by phase",
        }
    }
}

/// The phase of a stroke a trajectory sample belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StrokePhase {
    /// Everything that is not one of the others: waiting, lifting the stick.
    Preparation,
    /// The last uninterrupted descent into an impact.
    Downstroke,
    /// Within [`CONTACT_S`] of an impact.
    Contact,
    /// The first uninterrupted rise out of an impact.
    Rebound,
}

impl StrokePhase {
    /// Every phase, in the order a stroke goes through them.
    pub const ALL: [StrokePhase; 4] = [
        StrokePhase::Preparation,
        StrokePhase::Downstroke,
        StrokePhase::Contact,
        StrokePhase::Rebound,
    ];

    /// The name in the legend.
    pub fn name(self) -> &'static str {
        match self {
            StrokePhase::Preparation => "preparation",
            StrokePhase::Downstroke => "downstroke",
            StrokePhase::Contact => "contact",
            StrokePhase::Rebound => "rebound",
        }
    }

    /// The colour it is drawn in.
    pub fn colour(self) -> Rgba {
        match self {
            StrokePhase::Preparation => Rgba::rgb(110, 190, 120),
            StrokePhase::Downstroke => Rgba::rgb(235, 85, 70),
            StrokePhase::Contact => Rgba::rgb(255, 255, 255),
            StrokePhase::Rebound => Rgba::rgb(175, 120, 240),
        }
    }
}

/// Samples this close to an impact are in contact, s.
pub const CONTACT_S: f64 = 0.006;

/// The speed ramp's number of steps.
pub const SPEED_LEVELS: usize = 12;

/// The speed ramp's stops, slow to fast: blue, cyan, yellow, red.
const RAMP: [[f64; 3]; 4] = [
    [40.0, 90.0, 230.0],
    [40.0, 210.0, 220.0],
    [250.0, 220.0, 60.0],
    [235.0, 50.0, 40.0],
];

/// Central-difference derivative of `values` sampled at `rate_hz` (one-sided at the
/// ends; empty for fewer than two samples).
fn derivative<T: Copy + std::ops::Sub<Output = T> + std::ops::Mul<f64, Output = T>>(
    values: &[T],
    rate_hz: f64,
) -> Vec<T> {
    let n = values.len();
    if n < 2 {
        return Vec::new();
    }
    (0..n)
        .map(|k| {
            let (a, b) = (k.saturating_sub(1), (k + 1).min(n - 1));
            (values[b] - values[a]) * (rate_hz / (b - a) as f64)
        })
        .collect()
}

/// The tip's speed at each sample of `tips` (sampled at `rate_hz`), m/s.
pub fn speeds(tips: &[DVec3], rate_hz: f64) -> Vec<f64> {
    let v = derivative(tips, rate_hz);
    if v.is_empty() {
        return vec![0.0; tips.len()];
    }
    v.iter().map(|v| v.length()).collect()
}

/// The top of the speed ramp for `speeds`: the fastest, rounded up to whole m/s (at least
/// 1 m/s).
pub fn speed_scale(speeds: &[f64]) -> f64 {
    speeds.iter().copied().fold(1.0, f64::max).ceil()
}

/// The ramp step of speed `v` on a ramp topping at `scale` (m/s), 0 to
/// [`SPEED_LEVELS`] − 1.
pub fn speed_level(v: f64, scale: f64) -> usize {
    let x = (v / scale.max(1e-9)).clamp(0.0, 1.0);
    ((x * SPEED_LEVELS as f64) as usize).min(SPEED_LEVELS - 1)
}

/// The colour of ramp step `level` (0: slowest).
pub fn level_colour(level: usize) -> Rgba {
    let x = level.min(SPEED_LEVELS - 1) as f64 / (SPEED_LEVELS - 1) as f64;
    let f = x * (RAMP.len() - 1) as f64;
    let i = (f as usize).min(RAMP.len() - 2);
    let t = f - i as f64;
    let c = |j: usize| (RAMP[i][j] + (RAMP[i + 1][j] - RAMP[i][j]) * t).round() as u8;
    Rgba::rgb(c(0), c(1), c(2))
}

/// The phase of each sample of one hand's `tips` (sampled at `rate_hz`) whose impacts
/// are at samples `impacts`: contact within [`CONTACT_S`] of an impact, the downstroke
/// back from it while the tip descended, the rebound on from it while the tip rose, and
/// preparation everywhere else.
pub fn phases(tips: &[DVec3], rate_hz: f64, impacts: &[usize]) -> Vec<StrokePhase> {
    let n = tips.len();
    let mut out = vec![StrokePhase::Preparation; n];
    let heights: Vec<f64> = tips.iter().map(|p| p.z).collect();
    let vz = derivative(&heights, rate_hz);
    if vz.is_empty() {
        return out;
    }
    let half = (CONTACT_S * rate_hz).round() as usize;
    for &i in impacts.iter().filter(|i| **i < n) {
        let mut k = i.saturating_sub(half + 1);
        while k > 0 && vz[k] < 0.0 && out[k] == StrokePhase::Preparation {
            out[k] = StrokePhase::Downstroke;
            k -= 1;
        }
        let mut k = i + half + 1;
        while k < n && vz[k] > 0.0 {
            out[k] = StrokePhase::Rebound;
            k += 1;
        }
    }
    for &i in impacts.iter().filter(|i| **i < n) {
        for phase in &mut out[i.saturating_sub(half)..(i + half + 1).min(n)] {
            *phase = StrokePhase::Contact;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A tip moving at 2 m/s has that speed everywhere; the ramp's steps run from the
    /// first colour to the last, each step a different colour, and speeds past the
    /// scale take the top step.
    #[test]
    fn speed_and_ramp() {
        let tips: Vec<DVec3> = (0..50)
            .map(|k| DVec3::new(0.0, k as f64 * 0.008, 1.0))
            .collect();
        for v in speeds(&tips, 250.0) {
            assert!((v - 2.0).abs() < 1e-9, "{v}");
        }
        assert_eq!(speed_scale(&[0.2, 2.3]), 3.0);
        assert_eq!(speed_scale(&[0.2]), 1.0);
        assert_eq!(speed_level(0.0, 3.0), 0);
        assert_eq!(speed_level(9.0, 3.0), SPEED_LEVELS - 1);
        assert!(speed_level(1.0, 3.0) < speed_level(2.0, 3.0));
        assert_eq!(level_colour(0), Rgba::rgb(40, 90, 230));
        assert_eq!(level_colour(SPEED_LEVELS - 1), Rgba::rgb(235, 50, 40));
        for l in 1..SPEED_LEVELS {
            assert_ne!(level_colour(l), level_colour(l - 1));
        }
        assert_eq!(speeds(&tips[..1], 250.0), vec![0.0]);
    }

    /// Down into an impact, a rebound up to a hold, a lift, down into the next impact,
    /// up again: each part gets its phase.
    #[test]
    fn phases_of_two_strokes() {
        let mut z = Vec::new();
        z.extend((0..10).map(|k| 0.1 - 0.01 * k as f64)); // down to the impact at 10
        z.extend((0..10).map(|k| 0.005 * k as f64)); // rebound to 0.05 at 20
        z.extend((0..10).map(|_| 0.05)); // hold
        z.extend((0..10).map(|k| 0.05 + 0.02 * k as f64)); // lift to 0.25 at 40
        z.extend((0..10).map(|k| 0.25 - 0.025 * k as f64)); // down to the impact at 50
        z.extend((0..6).map(|k| 0.01 * k as f64)); // rebound
        let tips: Vec<DVec3> = z.iter().map(|z| DVec3::new(0.0, 0.4, *z)).collect();
        let p = phases(&tips, 100.0, &[10, 50]);
        use StrokePhase::*;
        let expect = [
            (5, Downstroke),
            (9, Contact),
            (10, Contact),
            (11, Contact),
            (15, Rebound),
            (25, Preparation),
            (35, Preparation),
            (45, Downstroke),
            (50, Contact),
            (53, Rebound),
        ];
        for (k, phase) in expect {
            assert_eq!(p[k], phase, "sample {k}: {p:?}");
        }
        assert!(phases(&tips, 100.0, &[]).iter().all(|p| *p == Preparation));
    }
}
