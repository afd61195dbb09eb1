//! A stick tracked by loose markers — two or more on its shaft, or a cluster the capture
//! software never solved into a rigid body — made into the rigid body they form, so that
//! its tip is found as a rigid body's is (`mocap::tip_estimate`).
//!
//! 1. **The layout.** Where the markers sit on the stick is read from the frames in which
//!    all of them are seen: their mean shape, each frame turned and moved onto it
//!    (generalised Procrustes, three rounds, frames that do not fit left out). The body's
//!    axes are the shape's principal axes, x along the markers' longest extent (the
//!    shaft), its origin their centroid.
//! 2. **A line or a solid.** Markers within [`LINE_TOLERANCE_M`] of one line (two
//!    markers, or several along the shaft) give the stick's axis but not its roll about
//!    it: each frame's axis is then the least-squares line through the markers it sees
//!    (their positions against their places along the axis), and the roll is carried
//!    from frame to frame without twist (parallel transport) — a tip on the axis does not
//!    depend on it. Otherwise each frame's pose is the rotation and shift that best fit
//!    the markers it sees onto the shape (Kabsch: the singular vectors of their
//!    cross-covariance), which needs three of them not in a line.
//! 3. **Swaps and ghosts.** A frame whose markers stand more than [`MISFIT_M`] (RMS) off
//!    the shape, or a line whose markers' spacing is off by more than
//!    [`SPACING_TOLERANCE`], is fitted again with two markers' labels exchanged (a
//!    labelling pass that swapped them; a line of two that points the other way than a
//!    few frames before is turned back), else without its worst marker while enough
//!    remain, else left missing (a reflection taken for a marker); short gaps are filled
//!    downstream like any track's. Markers that
//!    misfit in most frames do not move as one stick (one of them is elsewhere): refused.
//! 4. **Where the tip is expected** ([`MarkerBody::tip_prior`]): on the axis of markers
//!    along the shaft, just past one end of them; a compact cluster says nothing of the
//!    stick's direction, so it gets a rigid body's prior.
//!
//! Positions are metres in the file's own axes; rotations are world from body.

use super::take::Track;
use super::tip_estimate::{self, TipPrior};
use crate::base::stats::median;
use crate::body::limits::symmetric_eigen;
use glam::{DMat3, DQuat, DVec3};

/// Markers within this distance of one line (RMS across it) are treated as a line, m
/// (markers on a shaft stand about 12 mm off its axis; a cluster's arms 3 cm and more).
pub const LINE_TOLERANCE_M: f64 = 0.015;
/// And at most this share of their RMS reach along it.
pub const LINE_SLENDERNESS: f64 = 0.25;
/// A frame's markers may stand this far off the shape (RMS), m.
pub const MISFIT_M: f64 = 0.01;
/// A line's markers may be spaced this much (relative) off their usual spacing.
pub const SPACING_TOLERANCE: f64 = 0.1;
/// Markers spread this far along the stick (m) show where its shaft runs.
pub const SPREAD_ALONG_M: f64 = 0.1;
/// The tip's expected distance past the last marker on the shaft, m (the mallet head's
/// radius and the marker's clearance from it).
pub const PAST_LAST_MARKER_M: f64 = 0.05;
/// A line seen within this many frames of its last pose keeps its direction: pointing
/// the other way, its markers were swapped.
const SWAP_FRAMES: usize = 25;
/// At most this many frames are used to find the layout.
const LAYOUT_FRAMES: usize = 2000;
/// Rounds of the generalised Procrustes mean.
const LAYOUT_ROUNDS: usize = 3;

/// The rigid body a stick's markers form.
#[derive(Clone, Debug, PartialEq)]
pub struct MarkerBody {
    /// The body's origin (the markers' centroid) per frame, m; `None` where too few
    /// markers were seen or they did not fit the layout.
    pub positions: Vec<Option<DVec3>>,
    /// The body's rotation (world from body) per frame.
    pub rotations: Vec<Option<DQuat>>,
    /// Each marker's place in the body frame, m (on the x axis for a line).
    pub layout: Vec<DVec3>,
    /// Whether the markers lie on one line (the roll about it is not measured).
    pub line: bool,
    /// Frames left missing because the markers seen there did not fit the layout.
    pub misfit_frames: usize,
}

impl MarkerBody {
    /// The markers' extent along the body's x axis (the stick), m: (least, greatest).
    pub fn along_m(&self) -> (f64, f64) {
        self.layout
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(p.x), hi.max(p.x))
            })
    }

    /// Whether the markers show where the shaft runs: on one line, or spread over
    /// [`SPREAD_ALONG_M`] of it.
    fn along_shaft(&self) -> bool {
        let (lo, hi) = self.along_m();
        self.line || hi - lo >= SPREAD_ALONG_M
    }

    /// The first marker's place along the shaft, m, and whether it is nearer the high
    /// end of the row than the low one.
    fn first_along(&self) -> (f64, bool) {
        let (lo, hi) = self.along_m();
        let first = self.layout.first().map_or(0.0, |p| p.x);
        (first, first >= 0.5 * (lo + hi))
    }

    /// The tip, known to lie `distance_m` past the first marker along the shaft (away
    /// from the others), in the body frame (m). Markers in a compact cluster, or listed
    /// with a middle one first, do not say which way the shaft runs.
    pub fn tip_past_first(&self, distance_m: f64) -> Result<DVec3, MarkerBodyError> {
        if !self.along_shaft() {
            return Err(MarkerBodyError::NotAlongShaft);
        }
        let (lo, hi) = self.along_m();
        let (first, high) = self.first_along();
        if (first - lo).abs() > 1e-9 && (first - hi).abs() > 1e-9 {
            return Err(MarkerBodyError::FirstInMiddle);
        }
        let outward = if high { 1.0 } else { -1.0 };
        Ok(DVec3::X * (first + outward * distance_m))
    }

    /// Where the tip is expected before the capture says (`tip_estimate`): markers on
    /// one line or spread over [`SPREAD_ALONG_M`] of the shaft put it on their axis,
    /// [`PAST_LAST_MARKER_M`] past one end of them (a marker sits on the shaft behind the
    /// mallet's head) — or [`tip_estimate::PRIOR_LENGTH_M`] from their centre when they
    /// sit close together; a compact cluster off a line says nothing of the stick's
    /// direction, so the rigid body's usual prior. The end is the one past the first
    /// marker when `first_nearest_tip` (the user listed them from the tip), else the
    /// estimate's choice (the end that comes down faster).
    pub fn tip_prior(&self, first_nearest_tip: bool) -> TipPrior {
        if !self.along_shaft() {
            return TipPrior::Cluster;
        }
        let (lo, hi) = self.along_m();
        let (ahead, behind) = if hi - lo >= SPREAD_ALONG_M {
            (hi + PAST_LAST_MARKER_M, lo - PAST_LAST_MARKER_M)
        } else {
            let reach = tip_estimate::PRIOR_LENGTH_M;
            (reach, -reach)
        };
        let ends_m = match (first_nearest_tip, self.first_along().1) {
            // Listed from the tip: the tip is past the end the first marker is nearer.
            (true, true) => [ahead, ahead],
            (true, false) => [behind, behind],
            (false, _) => [ahead, behind],
        };
        TipPrior::OnAxis { ends_m }
    }
}

/// Why the markers make no body.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum MarkerBodyError {
    #[error("a stick of loose markers needs at least two of them; {0} given")]
    TooFew(usize),
    #[error(
        "its markers are seen all together in {0} frames, too few to tell where they sit on the stick (at least 3 needed)"
    )]
    NeverTogether(usize),
    #[error("its markers stand within {0:.1} mm of one another: they show no direction")]
    OnePoint(f64),
    #[error(
        "its markers do not move as one stick: in {misfit} of the {seen} frames where enough of them are seen they do not keep their places (is one of them not on the stick?)"
    )]
    NotRigid { misfit: usize, seen: usize },
    #[error(
        "its markers sit in a compact cluster, not along the shaft, so a distance past the first says nothing of where the tip is"
    )]
    NotAlongShaft,
    #[error(
        "its first marker is not at an end of the row along the shaft: list the markers from the tip"
    )]
    FirstInMiddle,
}

/// The rigid body `tracks`' markers form (module doc).
pub fn from_markers(tracks: &[&Track]) -> Result<MarkerBody, MarkerBodyError> {
    let n = tracks.len();
    if n < 2 {
        return Err(MarkerBodyError::TooFew(n));
    }
    let frames = tracks.iter().map(|t| t.positions.len()).max().unwrap_or(0);
    let seen = |f: usize| -> Vec<(usize, DVec3)> {
        (0..n)
            .filter_map(|i| Some((i, tracks[i].positions.get(f).copied().flatten()?)))
            .collect()
    };
    let together: Vec<Vec<DVec3>> = (0..frames)
        .filter_map(|f| {
            let s = seen(f);
            (s.len() == n).then(|| s.into_iter().map(|(_, p)| p).collect())
        })
        .collect();
    if together.len() < 3 {
        return Err(MarkerBodyError::NeverTogether(together.len()));
    }
    let step = together.len().div_ceil(LAYOUT_FRAMES);
    let sample: Vec<&[DVec3]> = together.iter().step_by(step).map(Vec::as_slice).collect();
    let shape = mean_shape(&sample);
    let (values, vectors) = symmetric_eigen(scatter(&shape));
    let extent = (values[0] / n as f64).max(0.0).sqrt();
    if extent < 0.005 {
        return Err(MarkerBodyError::OnePoint(extent * 1e3));
    }
    let x = vectors[0].normalize();
    let y = (vectors[1] - x * vectors[1].dot(x)).normalize();
    let axes = DMat3::from_cols(x, y, x.cross(y));
    let mut layout: Vec<DVec3> = shape.iter().map(|p| axes.transpose() * *p).collect();
    let across = (layout.iter().map(|p| p.y * p.y + p.z * p.z).sum::<f64>() / n as f64).sqrt();
    // Across the line little, and little against the markers' reach along it (a small
    // cluster's triangle is not a line).
    let line = n == 2 || (across < LINE_TOLERANCE_M && across < LINE_SLENDERNESS * extent);
    if line {
        for p in &mut layout {
            *p = DVec3::X * p.x;
        }
    }
    let mut body = MarkerBody {
        positions: vec![None; frames],
        rotations: vec![None; frames],
        layout,
        line,
        misfit_frames: 0,
    };
    // The line's roll is carried on from the last pose found (none yet: no roll).
    let mut previous = DQuat::IDENTITY;
    let mut last_found: Option<usize> = None;
    for f in 0..frames {
        let markers = seen(f);
        let pose = if line {
            fitted_without_misfits(markers, |m| line_pose(&body.layout, m)).map(|(o, axis)| {
                let before = previous * DVec3::X;
                // Markers swapped end for end (their labels) fit the centred, symmetric
                // layout turned round about its centre; a stick cannot turn so far in a
                // few frames.
                let recent = last_found.is_some_and(|l| f - l <= SWAP_FRAMES);
                let axis = if recent && axis.dot(before) < 0.0 {
                    -axis
                } else {
                    axis
                };
                let turn = DQuat::from_rotation_arc(before, axis);
                (o, (turn * previous).normalize())
            })
        } else {
            fitted_without_misfits(markers, |m| solid_pose(&body.layout, m))
        };
        match pose {
            Ok((origin, rotation)) => {
                body.positions[f] = Some(origin);
                body.rotations[f] = Some(rotation);
                previous = rotation;
                last_found = Some(f);
            }
            Err(Misfit::Yes) => body.misfit_frames += 1,
            Err(Misfit::TooFewSeen) => {}
        }
    }
    let judged = body.misfit_frames + body.positions.iter().flatten().count();
    if 2 * body.misfit_frames > judged {
        return Err(MarkerBodyError::NotRigid {
            misfit: body.misfit_frames,
            seen: judged,
        });
    }
    Ok(body)
}

/// Why a frame has no pose.
enum Misfit {
    /// Too few markers seen (or seen in a line, for a solid).
    TooFewSeen,
    /// The markers seen do not fit the layout.
    Yes,
}

/// `fit` on the markers seen, then with two of them swapped, then without the
/// worst-fitting one while it misfits.
/// `fit` gives the pose, `Err(None)` for too few markers, or `Err(Some(k))` when the
/// fit is off, marker `k` of the slice fitting worst.
fn fitted_without_misfits<T>(
    mut markers: Vec<(usize, DVec3)>,
    fit: impl Fn(&[(usize, DVec3)]) -> Result<T, Option<usize>>,
) -> Result<T, Misfit> {
    let mut removed = false;
    loop {
        match fit(&markers) {
            Ok(pose) => return Ok(pose),
            Err(None) if removed => return Err(Misfit::Yes),
            Err(None) => return Err(Misfit::TooFewSeen),
            Err(Some(worst)) => {
                if let Some(pose) = with_two_swapped(&markers, &fit) {
                    return Ok(pose);
                }
                markers.remove(worst);
                removed = true;
            }
        }
    }
}

/// The first fit of the markers seen with two of them taking each other's places (a
/// labelling pass that swapped them), if one fits.
fn with_two_swapped<T>(
    markers: &[(usize, DVec3)],
    fit: &impl Fn(&[(usize, DVec3)]) -> Result<T, Option<usize>>,
) -> Option<T> {
    (0..markers.len())
        .flat_map(|a| (a + 1..markers.len()).map(move |b| (a, b)))
        .find_map(|(a, b)| {
            let mut swapped = markers.to_vec();
            let (ia, ib) = (swapped[a].0, swapped[b].0);
            swapped[a].0 = ib;
            swapped[b].0 = ia;
            fit(&swapped).ok()
        })
}

/// A line's origin and unit axis from the markers seen: the least-squares line through
/// their positions against their places along it (`layout[i].x`). `Err(None)`: fewer
/// than two markers 2 cm apart along the stick; `Err(Some(k))`: the fit is off (the
/// spacing or the RMS distance), marker `k` of `seen` the worst.
fn line_pose(layout: &[DVec3], seen: &[(usize, DVec3)]) -> Result<(DVec3, DVec3), Option<usize>> {
    let s: Vec<f64> = seen.iter().map(|(i, _)| layout[*i].x).collect();
    let span = s.iter().copied().fold(f64::NEG_INFINITY, f64::max)
        - s.iter().copied().fold(f64::INFINITY, f64::min);
    if seen.len() < 2 || span < 0.02 {
        return Err(None);
    }
    let k = seen.len() as f64;
    let s_mean = s.iter().sum::<f64>() / k;
    let x_mean = seen.iter().map(|m| m.1).sum::<DVec3>() / k;
    let spread: f64 = s.iter().map(|v| (v - s_mean).powi(2)).sum();
    let slope = seen
        .iter()
        .zip(&s)
        .map(|(m, v)| (m.1 - x_mean) * (v - s_mean))
        .sum::<DVec3>()
        / spread;
    let axis = slope.normalize_or_zero();
    let origin = x_mean - axis * s_mean;
    let misses: Vec<f64> = seen
        .iter()
        .zip(&s)
        .map(|(m, v)| (origin + axis * *v).distance(m.1))
        .collect();
    let off = (slope.length() - 1.0).abs() > SPACING_TOLERANCE || rms(&misses) > MISFIT_M;
    if off || axis == DVec3::ZERO {
        return Err(Some(worst_of(&misses)));
    }
    Ok((origin, axis))
}

/// A solid's pose from the markers seen (Kabsch). `Err(None)`: fewer than three seen, or
/// those seen lie in a line; `Err(Some(k))`: RMS misfit over [`MISFIT_M`], marker `k` of
/// `seen` the worst.
fn solid_pose(layout: &[DVec3], seen: &[(usize, DVec3)]) -> Result<(DVec3, DQuat), Option<usize>> {
    if seen.len() < 3 {
        return Err(None);
    }
    let k = seen.len() as f64;
    let body_mean = seen.iter().map(|(i, _)| layout[*i]).sum::<DVec3>() / k;
    let world_mean = seen.iter().map(|m| m.1).sum::<DVec3>() / k;
    let body: Vec<DVec3> = seen.iter().map(|(i, _)| layout[*i] - body_mean).collect();
    let world: Vec<DVec3> = seen.iter().map(|m| m.1 - world_mean).collect();
    let (values, _) = symmetric_eigen(scatter(&body));
    if values[1].max(0.0).sqrt() < 0.2 * LINE_TOLERANCE_M {
        return Err(None);
    }
    let rotation = best_rotation(&body, &world);
    let origin = world_mean - rotation * body_mean;
    let misses: Vec<f64> = seen
        .iter()
        .map(|(i, p)| (origin + rotation * layout[*i]).distance(*p))
        .collect();
    if rms(&misses) > MISFIT_M {
        return Err(Some(worst_of(&misses)));
    }
    Ok((origin, rotation))
}

/// The index of the largest miss (with two markers of a line both fit exactly, and
/// either is dropped).
fn worst_of(misses: &[f64]) -> usize {
    (0..misses.len())
        .max_by(|&a, &b| misses[a].total_cmp(&misses[b]))
        .unwrap_or(0)
}

/// Root mean square.
fn rms(xs: &[f64]) -> f64 {
    (xs.iter().map(|x| x * x).sum::<f64>() / xs.len().max(1) as f64).sqrt()
}

/// `Σ p pᵀ`.
fn scatter(points: &[DVec3]) -> DMat3 {
    points
        .iter()
        .map(|p| DMat3::from_cols(*p * p.x, *p * p.y, *p * p.z))
        .fold(DMat3::ZERO, |a, b| a + b)
}

/// `points` less their centroid.
fn centred(points: &[DVec3]) -> Vec<DVec3> {
    let c = points.iter().sum::<DVec3>() / points.len().max(1) as f64;
    points.iter().map(|p| *p - c).collect()
}

/// The rotation `R` minimising `Σ |R·body_i − world_i|²` over centred point sets
/// (Kabsch), from the singular vectors of `M = Σ world_i body_iᵀ`: `R = U·Vᵀ` with the
/// third pair made a right-handed completion of the first two (so a planar set, whose
/// third singular value is zero, still gives a proper rotation). Points in a line give
/// the shortest turn of their direction.
pub fn best_rotation(body: &[DVec3], world: &[DVec3]) -> DQuat {
    let m = body
        .iter()
        .zip(world)
        .map(|(b, w)| DMat3::from_cols(*w * b.x, *w * b.y, *w * b.z))
        .fold(DMat3::ZERO, |a, b| a + b);
    let (values, v) = symmetric_eigen(m.transpose() * m);
    let sigma = values.map(|l| l.max(0.0).sqrt());
    if sigma[0] <= 0.0 {
        return DQuat::IDENTITY;
    }
    let u1 = (m * v[0] / sigma[0]).normalize();
    if sigma[1] <= 1e-6 * sigma[0] {
        return DQuat::from_rotation_arc(v[0].normalize(), u1);
    }
    let u2 = m * v[1] / sigma[1];
    let u2 = (u2 - u1 * u2.dot(u1)).normalize();
    let v1 = v[0].normalize();
    let v2 = (v[1] - v1 * v[1].dot(v1)).normalize();
    let u = DMat3::from_cols(u1, u2, u1.cross(u2));
    let vt = DMat3::from_cols(v1, v2, v1.cross(v2)).transpose();
    DQuat::from_mat3(&(u * vt)).normalize()
}

/// The markers' mean shape, centred (module doc, step 1): two markers at their median
/// distance on a line; more by generalised Procrustes from the frame whose pairwise
/// distances are nearest the median ones.
fn mean_shape(frames: &[&[DVec3]]) -> Vec<DVec3> {
    let n = frames[0].len();
    let pairs: Vec<(usize, usize)> = (0..n)
        .flat_map(|i| (i + 1..n).map(move |j| (i, j)))
        .collect();
    let distances: Vec<f64> = pairs
        .iter()
        .map(|&(i, j)| median(frames.iter().map(|f| f[i].distance(f[j]))).unwrap_or(0.0))
        .collect();
    if n == 2 {
        return vec![
            DVec3::X * (-0.5 * distances[0]),
            DVec3::X * (0.5 * distances[0]),
        ];
    }
    let unlike = |f: &[DVec3]| -> f64 {
        pairs
            .iter()
            .zip(&distances)
            .map(|(&(i, j), d)| (f[i].distance(f[j]) - d).abs())
            .sum()
    };
    let start = frames
        .iter()
        .min_by(|a, b| unlike(a).total_cmp(&unlike(b)))
        .copied()
        .unwrap_or(frames[0]);
    let mut shape = centred(start);
    for _ in 0..LAYOUT_ROUNDS {
        let mut sum = vec![DVec3::ZERO; n];
        let mut count = 0usize;
        for f in frames {
            let world = centred(f);
            let r = best_rotation(&shape, &world);
            let back: Vec<DVec3> = world.iter().map(|w| r.inverse() * *w).collect();
            let misses: Vec<f64> = back
                .iter()
                .zip(&shape)
                .map(|(a, b)| a.distance(*b))
                .collect();
            if rms(&misses) <= MISFIT_M {
                for (s, b) in sum.iter_mut().zip(&back) {
                    *s += *b;
                }
                count += 1;
            }
        }
        if count == 0 {
            break;
        }
        shape = centred(&sum.iter().map(|s| *s / count as f64).collect::<Vec<_>>());
    }
    shape
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::rng::Rng;

    /// A stick swinging and rolling: its pose at frame `f` of `frames` (200 Hz).
    fn stick_pose(f: usize) -> (DVec3, DQuat) {
        let t = f as f64 / 200.0;
        let rotation = DQuat::from_rotation_z(0.3 * (1.3 * t).sin())
            * DQuat::from_rotation_y(-0.6 + 0.5 * (6.0 * t).sin())
            * DQuat::from_rotation_x(0.8 * (2.1 * t).sin());
        let origin = DVec3::new(0.1 * t.sin(), 0.4, 0.9 + 0.1 * (6.0 * t).cos());
        (origin, rotation)
    }

    /// Tracks of markers at `layout` (stick frame) on the moving stick, with noise (m).
    fn markers(layout: &[DVec3], frames: usize, noise: f64, seed: u64) -> Vec<Track> {
        let mut rng = Rng::new(seed);
        layout
            .iter()
            .enumerate()
            .map(|(i, p)| Track {
                label: format!("RSTK{}", i + 1),
                positions: (0..frames)
                    .map(|f| {
                        let (o, q) = stick_pose(f);
                        let jitter = DVec3::new(rng.normal(), rng.normal(), rng.normal());
                        Some(o + q * *p + jitter * noise)
                    })
                    .collect(),
                rotations: Vec::new(),
            })
            .collect()
    }

    /// Where the stick-frame point `p` is at frame `f`, through the body found.
    fn through_body(body: &MarkerBody, p: DVec3, f: usize) -> Option<DVec3> {
        // The body frame is the layout's own: carry `p` into it through frame 0's pose
        // of the true stick and the body.
        let (o0, q0) = stick_pose(0);
        let (bo0, bq0) = (body.positions[0]?, body.rotations[0]?);
        let in_body = bq0.inverse() * (o0 + q0 * p - bo0);
        Some(body.positions[f]? + body.rotations[f]? * in_body)
    }

    /// Three markers off a line (a cluster no software solved) give the stick's pose:
    /// a point 30 cm away from them follows the true stick exactly without noise, and
    /// within the noise's reach with it.
    #[test]
    fn a_cluster_of_three_follows_the_stick() {
        let layout = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(0.06, 0.03, 0.0),
            DVec3::new(0.02, -0.04, 0.05),
        ];
        let tip = DVec3::new(0.3, 0.0, -0.05);
        let rms_miss = |noise: f64| {
            let tracks = markers(&layout, 600, noise, 1);
            let refs: Vec<&Track> = tracks.iter().collect();
            let body = from_markers(&refs).unwrap();
            assert!(!body.line);
            let misses: Vec<f64> = (0..600)
                .map(|f| {
                    let (o, q) = stick_pose(f);
                    through_body(&body, tip, f).unwrap().distance(o + q * tip)
                })
                .collect();
            rms(&misses)
        };
        assert!(rms_miss(0.0) < 1e-9, "{}", rms_miss(0.0));
        // 0.5 mm of noise on markers 4–7 cm from their centroid turns the body by about
        // 0.5 / 60 rad: 2.5 mm per axis 30 cm away, twice over (the point is carried
        // through frame 0's noisy pose too).
        let noisy = rms_miss(0.0005);
        eprintln!("a point 30 cm off the cluster: RMS {:.1} mm", noisy * 1e3);
        assert!(noisy < 0.008, "RMS {:.1} mm", noisy * 1e3);
    }

    /// Two markers on the shaft: the axis through them, a point on it followed exactly
    /// (noise aside), the roll carried without twist.
    #[test]
    fn two_markers_give_the_stick_axis() {
        let layout = [DVec3::X * 0.05, DVec3::X * 0.25];
        let tracks = markers(&layout, 600, 0.0, 2);
        let refs: Vec<&Track> = tracks.iter().collect();
        let body = from_markers(&refs).unwrap();
        assert!(body.line);
        let (lo, hi) = body.along_m();
        assert!(((hi - lo) - 0.2).abs() < 1e-9, "{lo} {hi}");
        for f in 0..600 {
            let (o, q) = stick_pose(f);
            let tip = o + q * (DVec3::X * 0.35);
            // The tip on the axis, 0.25 m past the centroid (at 0.15).
            let found = body.positions[f].unwrap() + body.rotations[f].unwrap() * (DVec3::X * 0.2);
            let sign_flipped =
                body.positions[f].unwrap() - body.rotations[f].unwrap() * (DVec3::X * 0.2);
            let miss = found.distance(tip).min(sign_flipped.distance(tip));
            assert!(miss < 1e-9, "frame {f}: {miss}");
        }
        // No twist: the roll changes little from frame to frame.
        for f in 1..600 {
            let turn = body.rotations[f - 1].unwrap().inverse() * body.rotations[f].unwrap();
            let (axis, angle) = turn.to_axis_angle();
            assert!(
                (axis * angle).x.abs() < 1e-6,
                "frame {f}: {}",
                (axis * angle).x
            );
        }
    }

    /// Frames where two markers of a cluster swap labels are fitted with the swap undone;
    /// a marker that jumps away (a ghost) is fitted around; gaps with two markers left
    /// (in a line with the origin, too few for a solid) stay gaps.
    #[test]
    fn swaps_ghosts_and_gaps() {
        let layout = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(0.08, 0.02, 0.0),
            DVec3::new(0.03, -0.05, 0.02),
            DVec3::new(0.15, 0.0, 0.01),
        ];
        let mut tracks = markers(&layout, 400, 0.0005, 3);
        for f in 100..105 {
            let (a, b) = (tracks[0].positions[f], tracks[1].positions[f]);
            tracks[0].positions[f] = b;
            tracks[1].positions[f] = a;
        }
        for f in 150..155 {
            tracks[2].positions[f] = tracks[2].positions[f].map(|p| p + DVec3::Z * 0.2);
        }
        for f in 200..210 {
            for t in &mut tracks[..2] {
                t.positions[f] = None;
            }
        }
        let refs: Vec<&Track> = tracks.iter().collect();
        let body = from_markers(&refs).unwrap();
        let tip = DVec3::new(0.35, 0.0, 0.0);
        for f in 0..400 {
            let (o, q) = stick_pose(f);
            match through_body(&body, tip, f) {
                Some(p) => assert!(p.distance(o + q * tip) < 0.01, "frame {f}"),
                None => assert!((200..210).contains(&f), "frame {f}"),
            }
        }
        assert!((200..210).all(|f| body.positions[f].is_none()));
        assert_eq!(body.misfit_frames, 0);
    }

    /// Two markers whose labels swap for a while: the axis keeps its direction, so a
    /// point on it follows the stick through the swap.
    #[test]
    fn two_swapped_markers_keep_the_axis() {
        let layout = [DVec3::X * 0.05, DVec3::X * 0.25];
        let mut tracks = markers(&layout, 600, 0.0, 6);
        for f in 200..260 {
            let (a, b) = (tracks[0].positions[f], tracks[1].positions[f]);
            tracks[0].positions[f] = b;
            tracks[1].positions[f] = a;
        }
        let refs: Vec<&Track> = tracks.iter().collect();
        let body = from_markers(&refs).unwrap();
        let tip = DVec3::X * 0.35;
        for f in 0..600 {
            let (o, q) = stick_pose(f);
            let found = through_body(&body, tip, f).unwrap();
            assert!(found.distance(o + q * tip) < 1e-6, "frame {f}");
        }
    }

    /// A tip given as a distance past the first marker lands there, on the side away
    /// from the others; a middle marker listed first, or a compact cluster, is refused.
    #[test]
    fn a_tip_past_the_first_marker() {
        let shaft = markers(
            &[DVec3::X * 0.05, DVec3::X * 0.15, DVec3::X * 0.25],
            50,
            0.0,
            7,
        );
        let body = from_markers(&shaft.iter().collect::<Vec<_>>()).unwrap();
        // The markers sit 5, 15 and 25 cm from the stick frame's origin: the tip.
        let tip = body.tip_past_first(0.05).unwrap();
        for f in 0..50 {
            let (o, _) = stick_pose(f);
            let found = body.positions[f].unwrap() + body.rotations[f].unwrap() * tip;
            assert!(found.distance(o) < 1e-9, "frame {f}: {found} against {o}");
        }
        let reordered = [&shaft[1], &shaft[0], &shaft[2]];
        let body = from_markers(&reordered).unwrap();
        assert_eq!(
            body.tip_past_first(0.05),
            Err(MarkerBodyError::FirstInMiddle)
        );
        let cluster = markers(&[DVec3::ZERO, DVec3::Y * 0.04, DVec3::Z * 0.04], 50, 0.0, 8);
        let body = from_markers(&cluster.iter().collect::<Vec<_>>()).unwrap();
        assert_eq!(
            body.tip_past_first(0.05),
            Err(MarkerBodyError::NotAlongShaft)
        );
    }

    /// Too few markers, never seen together, or all in one place: a clear error.
    #[test]
    fn refuses_what_makes_no_body() {
        let tracks = markers(&[DVec3::ZERO], 10, 0.0, 4);
        let refs: Vec<&Track> = tracks.iter().collect();
        assert_eq!(from_markers(&refs), Err(MarkerBodyError::TooFew(1)));
        let mut tracks = markers(&[DVec3::ZERO, DVec3::X * 0.2], 10, 0.0, 4);
        for f in 0..10 {
            tracks[f % 2].positions[f] = None;
        }
        let refs: Vec<&Track> = tracks.iter().collect();
        assert_eq!(from_markers(&refs), Err(MarkerBodyError::NeverTogether(0)));
        let tracks = markers(&[DVec3::ZERO, DVec3::X * 0.001], 10, 0.0, 4);
        let refs: Vec<&Track> = tracks.iter().collect();
        assert!(matches!(
            from_markers(&refs),
            Err(MarkerBodyError::OnePoint(_))
        ));
    }

    /// A marker that is not on the stick (an arm marker joined by mistake) is refused.
    #[test]
    fn refuses_markers_that_do_not_move_together() {
        let mut tracks = markers(&[DVec3::ZERO, DVec3::X * 0.2], 400, 0.0005, 5);
        for (f, p) in tracks[1].positions.iter_mut().enumerate() {
            *p = Some(DVec3::new(0.3, 0.2 * (f as f64 * 0.03).sin(), 1.4));
        }
        let refs: Vec<&Track> = tracks.iter().collect();
        assert!(matches!(
            from_markers(&refs),
            Err(MarkerBodyError::NotRigid { .. })
        ));
    }

    /// Kabsch recovers a known rotation of a planar (three-point) set.
    #[test]
    fn best_rotation_of_a_planar_set() {
        let q = DQuat::from_euler(glam::EulerRot::ZYX, 0.7, -0.4, 2.0);
        let body = centred(&[DVec3::ZERO, DVec3::X * 0.1, DVec3::Y * 0.05]);
        let world: Vec<DVec3> = body.iter().map(|p| q * *p).collect();
        let r = best_rotation(&body, &world);
        assert!(r.angle_between(q) < 1e-9, "{}", r.angle_between(q));
    }
}
