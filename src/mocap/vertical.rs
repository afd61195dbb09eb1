//! Which way is up in a capture: the six signed axes a lab may have as its vertical
//! ([`UpAxis`]), the quarter and half turns that bring each to +Z (the performer frame),
//! and finding it from the strokes themselves ([`detect`]) when neither the user nor the
//! file says.
//!
//! No capture format states its vertical reliably (Motive exports Y or Z up as set, C3D
//! and TRC keep whatever the lab's software used, a plain CSV says nothing), so the
//! format's usual axis is only a default. Drumming tells the vertical: along it the tip's
//! lowest points are impacts, where several m/s downward turn into a rebound within a
//! few milliseconds, while the tops of the strokes turn smoothly; along a horizontal axis
//! both extremes turn smoothly or, where the stick's tilt makes an impact an extreme
//! sideways, by a fraction of the vertical jump (its tangent: a third at 20°).

use super::take::Track;
use crate::base::stats::median;
use glam::{DQuat, DVec3};
use std::f64::consts::{FRAC_PI_2, PI};

/// Which signed axis of the capture points up.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UpAxis {
    /// +X up: (x, y, z) ↦ (−z, y, x).
    X,
    /// +Y up (OptiTrack Motive's default): (x, y, z) ↦ (x, −z, y).
    Y,
    /// +Z up (Vicon, Qualisys, most C3D files): kept.
    Z,
    /// −X up: (x, y, z) ↦ (z, y, −x).
    NegX,
    /// −Y up: (x, y, z) ↦ (x, z, −y).
    NegY,
    /// −Z up: (x, y, z) ↦ (x, −y, −z).
    NegZ,
}

impl UpAxis {
    /// Every signed axis.
    pub const ALL: [UpAxis; 6] = [
        UpAxis::X,
        UpAxis::Y,
        UpAxis::Z,
        UpAxis::NegX,
        UpAxis::NegY,
        UpAxis::NegZ,
    ];

    /// The axis as the reports write it: "+X" … "−Z" (ASCII minus).
    pub fn name(self) -> &'static str {
        ["+X", "+Y", "+Z", "-X", "-Y", "-Z"][self.index()]
    }

    /// The value `--up` takes for it: `x`, `y`, `z`, `neg-x`, `neg-y`, `neg-z`.
    pub fn arg(self) -> &'static str {
        ["x", "y", "z", "neg-x", "neg-y", "neg-z"][self.index()]
    }

    fn index(self) -> usize {
        UpAxis::ALL.iter().position(|a| *a == self).unwrap_or(2)
    }

    /// The signed axis along capture axis `axis` (0–2), positive or not.
    fn from_axis(axis: usize, positive: bool) -> UpAxis {
        UpAxis::ALL[axis + if positive { 0 } else { 3 }]
    }

    /// A capture position in the performer frame (this axis turned onto +Z), exactly.
    pub fn to_performer(self, p: DVec3) -> DVec3 {
        match self {
            UpAxis::X => DVec3::new(-p.z, p.y, p.x),
            UpAxis::Y => DVec3::new(p.x, -p.z, p.y),
            UpAxis::Z => p,
            UpAxis::NegX => DVec3::new(p.z, p.y, -p.x),
            UpAxis::NegY => DVec3::new(p.x, p.z, -p.y),
            UpAxis::NegZ => DVec3::new(p.x, -p.y, -p.z),
        }
    }

    /// A performer-frame position in the capture's axes: the inverse of
    /// [`UpAxis::to_performer`].
    pub fn from_performer(self, p: DVec3) -> DVec3 {
        match self {
            UpAxis::X => DVec3::new(p.z, p.y, -p.x),
            UpAxis::Y => DVec3::new(p.x, p.z, -p.y),
            UpAxis::Z => p,
            UpAxis::NegX => DVec3::new(-p.z, p.y, p.x),
            UpAxis::NegY => DVec3::new(p.x, -p.z, p.y),
            UpAxis::NegZ => DVec3::new(p.x, -p.y, -p.z),
        }
    }

    /// The turn [`UpAxis::to_performer`] makes, for orientations and directions.
    pub fn rotation(self) -> DQuat {
        match self {
            UpAxis::X => DQuat::from_rotation_y(-FRAC_PI_2),
            UpAxis::Y => DQuat::from_rotation_x(FRAC_PI_2),
            UpAxis::Z => DQuat::IDENTITY,
            UpAxis::NegX => DQuat::from_rotation_y(FRAC_PI_2),
            UpAxis::NegY => DQuat::from_rotation_x(-FRAC_PI_2),
            UpAxis::NegZ => DQuat::from_rotation_x(PI),
        }
    }
}

/// How sharply the strokes turn at their extremes along each signed axis.
#[derive(Clone, Debug, PartialEq)]
pub struct Detection {
    /// Per signed axis, best first: how much harder the strokes rebound at its lowest
    /// points than at its highest (the median jump of the velocity along it across them,
    /// 12 ms each side, m/s, summed over the sticks), and how many such points it had.
    pub scores: Vec<(UpAxis, f64, usize)>,
}

/// How many times the runner-up's score the best axis's must be to be taken as the
/// vertical (`cargo test --test lab_captures vertical -- --nocapture`: 3.0–20.7 on tip
/// markers of every layout written Y, Z, −Y and X up, with 1 or 3 mm of noise).
pub const CLEAR_RATIO: f64 = 2.5;

/// Fewest impacts the vertical is told from.
pub const MIN_EXTREMES: usize = 3;

impl Detection {
    /// The signed axis the strokes rebound along, when it is clearly the one.
    pub fn vertical(&self) -> Option<UpAxis> {
        let (best, score, n) = *self.scores.first()?;
        let runner_up = self.scores.get(1).map_or(0.0, |s| s.1);
        (n >= MIN_EXTREMES && score > 0.0 && score >= CLEAR_RATIO * runner_up).then_some(best)
    }

    /// The best axis's jump over the runner-up's (infinite when the runner-up has none).
    pub fn ratio(&self) -> f64 {
        match self.scores[..] {
            [(_, a, _), (_, b, _), ..] if b > 0.0 => a / b,
            [(_, a, _), ..] if a > 0.0 => f64::INFINITY,
            _ => 0.0,
        }
    }
}

/// The vertical to use when the format's usual one is `default` and nobody gave one, and
/// the note to print (without the file name): the detected axis when it is clear (a note
/// when it is not the default), else `default` with a note saying how to give it.
pub fn choose(default: UpAxis, detection: &Detection) -> (UpAxis, Option<String>) {
    match detection.vertical() {
        Some(up) if up == default => (up, None),
        Some(up) => (
            up,
            Some(format!(
                "the capture's vertical is {} (the strokes rebound along it), not the format's usual {}; give --up {} to keep it",
                up.name(),
                default.name(),
                default.arg()
            )),
        ),
        None => (
            default,
            Some(match detection.scores.first() {
                Some((best, _, n)) if *n >= MIN_EXTREMES => format!(
                    "the vertical could not be told from the strokes ({} rebounds {:.1}× as sharply as the next axis, {:.1} needed); kept the format's usual {}: give --up (x, y, z, neg-x, neg-y or neg-z) if it is another",
                    best.name(),
                    detection.ratio(),
                    CLEAR_RATIO,
                    default.name()
                ),
                _ => format!(
                    "the vertical is not told from these tracks (it is read from the rebounds of tip or stick markers, not from rigid bodies, and needs {MIN_EXTREMES} strokes); kept the format's usual {}: give --up (x, y, z, neg-x, neg-y or neg-z) if it is another",
                    default.name()
                ),
            }),
        ),
    }
}

/// Score every signed axis on `tracks` (the sticks' tracks, capture axes) sampled at
/// `rate_hz`: per capture axis, the median velocity jump across its prominent minima
/// less that across its maxima, summed over the tracks; the opposite axis scores the
/// opposite. Rigid bodies are left out: their origin sits near the grip, where the
/// rebound is weak and the hand's own motion can rebound sideways as hard (on the lab
/// corpus a Qualisys body's origin scored a horizontal axis 7× the vertical), and
/// their tip is not known yet.
pub fn detect(tracks: &[&Track], rate_hz: f64) -> Detection {
    let mut sum = [0.0; 3];
    let mut count = [0usize; 3];
    for track in tracks
        .iter()
        .filter(|t| !t.rotations.iter().any(Option::is_some))
    {
        for (axis, (d, n)) in axis_contrasts(&track.positions, rate_hz)
            .into_iter()
            .enumerate()
        {
            sum[axis] += d;
            count[axis] += n;
        }
    }
    let mut scores: Vec<(UpAxis, f64, usize)> = (0..3)
        .flat_map(|axis| {
            [(true, 1.0), (false, -1.0)].map(|(positive, sign)| {
                (
                    UpAxis::from_axis(axis, positive),
                    sign * sum[axis],
                    count[axis],
                )
            })
        })
        .collect();
    scores.sort_by(|a, b| b.1.total_cmp(&a.1));
    Detection { scores }
}

/// Per capture axis: the median velocity jump across the series' prominent minima along
/// it less that across its maxima (m/s; positive when the minima rebound harder), and
/// how many minima it had (none: 0).
fn axis_contrasts(points: &[Option<DVec3>], rate_hz: f64) -> [(f64, usize); 3] {
    std::array::from_fn(|axis| {
        let jumps = |sign: f64| {
            let h: Vec<Option<f64>> = points.iter().map(|p| p.map(|p| sign * p[axis])).collect();
            rebounds(&h, rate_hz)
        };
        let (lows, highs) = (jumps(1.0), jumps(-1.0));
        match (median(lows.iter().copied()), median(highs.iter().copied())) {
            (Some(l), Some(h)) => (l - h, lows.len().min(highs.len())),
            _ => (0.0, 0),
        }
    })
}

/// The velocity jumps (m/s, upward change) across the prominent minima of `h`: frames
/// lowest within 80 ms either side and at least 5 mm below the highest point of each
/// side, the velocity measured over 12 ms before and after.
fn rebounds(h: &[Option<f64>], rate_hz: f64) -> Vec<f64> {
    const PROMINENCE_M: f64 = 0.005;
    let w = ((0.08 * rate_hz).round() as usize).max(2);
    let k = ((0.012 * rate_hz).round() as usize).max(1);
    let dt = k as f64 / rate_hz;
    let mut jumps = Vec::new();
    for i in w..h.len().saturating_sub(w) {
        let Some(v) = h[i] else { continue };
        let side = |range: std::ops::Range<usize>| {
            h[range]
                .iter()
                .flatten()
                .fold(None, |m: Option<(f64, f64)>, &x| {
                    Some(m.map_or((x, x), |(lo, hi)| (lo.min(x), hi.max(x))))
                })
        };
        let (Some((lo_before, hi_before)), Some((lo_after, hi_after))) =
            (side(i - w..i), side(i + 1..i + w + 1))
        else {
            continue;
        };
        let lowest = v < lo_before && v <= lo_after;
        let prominent = hi_before >= v + PROMINENCE_M && hi_after >= v + PROMINENCE_M;
        if let (true, true, Some(before), Some(after)) = (lowest, prominent, h[i - k], h[i + k]) {
            jumps.push(((after - v) - (v - before)) / dt);
        }
    }
    jumps
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The capture axis (0 = X, 1 = Y, 2 = Z) and sign of `up`.
    fn axis_and_sign(up: UpAxis) -> (usize, f64) {
        let i = up.index();
        (i % 3, if i < 3 { 1.0 } else { -1.0 })
    }

    /// Every turn is a proper rotation that puts its axis on +Z, the exact remaps agree
    /// with the quaternions, and `from_performer` undoes `to_performer`.
    #[test]
    fn axes_turn_onto_z() {
        let p = DVec3::new(0.3, -0.7, 1.1);
        for up in UpAxis::ALL {
            let (axis, sign) = axis_and_sign(up);
            let mut along = DVec3::ZERO;
            along[axis] = sign;
            assert!(up.to_performer(along).distance(DVec3::Z) < 1e-15, "{up:?}");
            assert!(
                up.to_performer(p).distance(up.rotation() * p) < 1e-12,
                "{up:?}"
            );
            assert_eq!(up.from_performer(up.to_performer(p)), p, "{up:?}");
            assert_eq!(UpAxis::from_axis(axis, sign > 0.0), up);
        }
    }

    /// Strokes that rebound sharply at the bottom and turn smoothly at the top, in each
    /// of the six orientations (with a sideways sway that is extreme at the impacts too):
    /// the vertical is found; flat noise tells nothing.
    #[test]
    fn finds_the_axis_the_strokes_rebound_along() {
        let rate = 200.0;
        let period = 0.6;
        let performer: Vec<DVec3> = (0..1200)
            .map(|i| {
                let t = i as f64 / rate;
                let phase = (t / period).fract();
                // |sin| has a V at each impact and a round top.
                let height = 0.7 + 0.3 * (PI * phase).sin();
                let sway = 0.1 * (PI * phase).sin().powi(2) + 0.03 * (PI * phase).sin();
                DVec3::new(0.2 + sway, 0.4, height)
            })
            .collect();
        for up in UpAxis::ALL {
            let track = Track {
                label: "TipR".into(),
                positions: performer
                    .iter()
                    .map(|p| Some(up.from_performer(*p)))
                    .collect(),
                rotations: Vec::new(),
            };
            let d = detect(&[&track], rate);
            assert_eq!(d.vertical(), Some(up), "{d:?}");
            assert_eq!(choose(up, &d), (up, None));
            let other = if up == UpAxis::Z {
                UpAxis::Y
            } else {
                UpAxis::Z
            };
            let (chosen, note) = choose(other, &d);
            assert_eq!(chosen, up);
            assert!(
                note.unwrap()
                    .contains(&format!("give --up {}", other.arg()))
            );
        }
        let still = Track {
            label: "TipR".into(),
            positions: (0..400)
                .map(|i| Some(DVec3::splat(1e-4 * ((i * 7919) % 13) as f64)))
                .collect(),
            rotations: Vec::new(),
        };
        let d = detect(&[&still], rate);
        assert_eq!(d.vertical(), None);
        let (up, note) = choose(UpAxis::Y, &d);
        assert_eq!(up, UpAxis::Y);
        assert!(note.unwrap().contains("kept the format's usual +Y"));
    }
}
