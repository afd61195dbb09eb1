//! Where the stick tip sits on a rigid body whose origin is not the tip, estimated from
//! the capture itself when the user gives no tip offset.
//!
//! The tip is the point of the stick's frame that meets the membrane at every impact, so
//! its height is the same (the head plane) at all of them, while the origin's height
//! changes with the stick's angle. With `o(t)` the body origin and `R(t)` its rotation,
//! the tip at offset `d` (body frame, m) has height `o_z(t) + g(t)·d`, where
//! `g(t) = R(t)ᵀ ẑ` is the vertical seen from the stick. At the impact frames `t_k`:
//!
//! `g(t_k)·d − h = −o_z(t_k)`,
//!
//! linear in `d` and the plane height `h`.
//!
//! 1. **Impact times** do not need the tip: every point of the stick turns abruptly at a
//!    contact. Impacts are found (segmentation without the plane test) on the origin and
//!    on probe points 0.3 m from it along 26 directions; an impact is a frame at least
//!    30 % of them agree on (a minimum at another phase of the stroke is one point's
//!    alone).
//! 2. **What the data can tell.** Only the components of `d` along which `g` changes
//!    between impacts are observable: the stick's pitch changing from stroke to stroke
//!    fixes the length along the stick, its roll the offset across it. The component along
//!    the mean of `g` (the stick's vertical at impact) moves every impact's height as `h`
//!    does, so no capture can tell it; and a steady player, who meets the head at the same
//!    angle every time, leaves the others free too.
//! 3. **Priors for what the data leaves free** (each with a 5 cm standard deviation):
//!    the head lies `head_height_m` above the capture's floor (z = 0 in most labs); the
//!    tip lies 0.30 m from the origin (a marker cluster near the grip of a 0.33–0.40 m
//!    mallet), in the stroke plane (perpendicular to the axis the stick mostly turns
//!    about), at the end of the stick that comes down faster (the far end from the grip
//!    it turns about).
//! 4. **Estimate**: the posterior mean — least squares on the impacts (2 mm per impact)
//!    plus the priors — iterated with each impact moved to the tip's lowest frame nearby
//!    and impacts over 3 MAD from the fit dropped. Each component's standard error is
//!    reported; one near 5 cm means the priors, not the capture, placed it.
//!
//! **Markers along the stick** (`TipPrior::OnAxis`, from `mocap::marker_body`): the tip
//! lies on the body's x axis near one end of the markers, so the impacts are that
//! point's own (with segmentation's plane test: a point a few centimetres off the tip
//! meets the head at nearly one height), and only its place along the axis is fitted,
//! from the x component of `g` (the stick's tilt): a line of markers tells no roll.
//!
//! An error in an unobservable direction moves every impact by nearly the same vector,
//! which the alignment to the drum (`mocap::align`) absorbs; it bends the path between
//! impacts a little. When the tip offset is known, give it.

use super::segment::{Impact, SegmentParams, find_impacts};
use crate::base::stats::median;
use crate::body::limits::symmetric_eigen;
use glam::{DMat3, DMat4, DQuat, DVec3, DVec4};

/// The estimated tip offset and how well the capture determines it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TipEstimate {
    /// The tip in the rigid body's frame, m.
    pub offset_m: DVec3,
    /// Standard error of each component of `offset_m`, m.
    pub standard_error_m: DVec3,
    /// The head plane height the fit found, m.
    pub plane_height_m: f64,
    /// RMS scatter of the tip's height at the impacts used, m.
    pub residual_m: f64,
    /// Impacts the fit used.
    pub impacts: usize,
}

impl TipEstimate {
    /// Whether the priors rather than the capture placed the tip (a standard error over
    /// 2 cm in some component).
    pub fn rests_on_priors(&self) -> bool {
        self.standard_error_m.max_element() > 0.02
    }
}

/// Why no tip could be estimated.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum TipEstimateError {
    #[error("the track has no orientation: a tip offset needs a rigid body")]
    NoRotations,
    #[error(
        "only {0} impacts found on the rigid body; at least 4 are needed to estimate the tip (give --tip-offset)"
    )]
    TooFewImpacts(usize),
}

/// What is known beforehand of where the tip lies in the body's frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TipPrior {
    /// A rigid body of unknown layout (a marker cluster near the grip): the tip
    /// [`PRIOR_LENGTH_M`] from its origin, in the stroke plane, at the end that comes
    /// down faster (module doc, step 3).
    Cluster,
    /// Markers along the stick (`mocap::marker_body`): the tip on the body's x axis, at
    /// one of the two places `ends_m` (one past each end of the markers, m): whichever
    /// comes down faster.
    OnAxis { ends_m: [f64; 2] },
}

/// Standard deviation of the prior across the stick, for markers along it, m.
const ACROSS_STICK_SD_M: f64 = 0.015;

/// Prior distance from the body origin to the tip, m (also used by `mocap::marker_body`
/// for markers close together on the shaft).
pub const PRIOR_LENGTH_M: f64 = 0.30;
/// Standard deviation of every prior, m.
const PRIOR_SD_M: f64 = 0.05;
/// Assumed scatter of one impact's tip height about the plane, m.
const IMPACT_SD_M: f64 = 0.002;
/// Distance of the probe points from the origin, m.
const PROBE_LENGTH_M: f64 = 0.30;
/// Share of the probe points that must find an impact for it to count.
const CONSENSUS: f64 = 0.3;
/// Frames either side of an impact searched for the candidate tip's lowest point.
const NEAR_FRAMES: usize = 2;

/// One frame of the body: origin (m) and rotation (world from body).
type Pose = (DVec3, DQuat);

/// Estimate the tip offset of a rigid body with `positions` (origin, m, z up) and
/// `rotations` (world from body) sampled at `rate_hz`; the head is assumed
/// `head_height_m` above the capture's z = 0 (see the module doc).
pub fn estimate(
    positions: &[Option<DVec3>],
    rotations: &[Option<DQuat>],
    rate_hz: f64,
    head_height_m: f64,
    known: TipPrior,
) -> Result<TipEstimate, TipEstimateError> {
    if rotations.iter().all(Option::is_none) {
        return Err(TipEstimateError::NoRotations);
    }
    let poses: Vec<Option<Pose>> = positions
        .iter()
        .zip(rotations.iter().chain(std::iter::repeat(&None)))
        .map(|(p, q)| Some((*p.as_ref()?, *q.as_ref()?)))
        .collect();
    let (impacts, prior) = match known {
        TipPrior::Cluster => {
            let impacts = impact_frames(&poses, rate_hz);
            let prior = cluster_prior(&poses, &impacts, rate_hz, head_height_m);
            (impacts, prior)
        }
        // The tip is known to lie on the axis near one end: that point's own impacts.
        TipPrior::OnAxis { ends_m } => {
            let tip = faster_end(&poses, DVec3::X * ends_m[0], DVec3::X * ends_m[1], rate_hz);
            let impacts = impacts_near_tip(&poses, tip, rate_hz);
            let sd = DVec3::new(PRIOR_SD_M, ACROSS_STICK_SD_M, ACROSS_STICK_SD_M);
            (impacts.iter().map(|i| i.frame).collect(), (tip, sd))
        }
    };
    if impacts.len() < 4 {
        return Err(TipEstimateError::TooFewImpacts(impacts.len()));
    }
    let noise = rotation_noise_var(&poses);
    // On the axis, only the stick's tilt counts: a line of markers tells no roll.
    let on_axis = matches!(known, TipPrior::OnAxis { .. });
    Ok(fit(&poses, &impacts, prior, noise, head_height_m, on_axis))
}

/// The world point of body point `d`.
fn point(pose: Pose, d: DVec3) -> DVec3 {
    pose.0 + pose.1 * d
}

/// The impacts of the body point `d`: segmentation of its height without the plane test
/// (a point off the tip meets the head at heights that vary with the stick's angle).
fn impacts_of_point(poses: &[Option<Pose>], d: DVec3, rate_hz: f64) -> Vec<Impact> {
    let params = SegmentParams {
        plane_tolerance_m: None,
        ..SegmentParams::default()
    };
    find_impacts(&heights(poses, d), rate_hz, &params).0
}

/// The impacts of a body point near the tip, with segmentation's plane test: a point a
/// few centimetres along the stick from the tip meets the head at nearly one height, and
/// a turn in mid-air (a bounce, a marker's wobble) is far above it.
fn impacts_near_tip(poses: &[Option<Pose>], d: DVec3, rate_hz: f64) -> Vec<Impact> {
    find_impacts(&heights(poses, d), rate_hz, &SegmentParams::default()).0
}

/// The height of body point `d` per frame (NaN where unseen), m.
fn heights(poses: &[Option<Pose>], d: DVec3) -> Vec<f64> {
    poses
        .iter()
        .map(|s| s.map_or(f64::NAN, |s| point(s, d).z))
        .collect()
}

/// The impact frames every point of the stick agrees on: impacts are found on the origin
/// and on probe points [`PROBE_LENGTH_M`] from it along 26 directions, and a frame is an
/// impact when at least [`CONSENSUS`] of the probes find one within [`NEAR_FRAMES`] of
/// it (a contact turns the whole stick; a minimum at another phase of the stroke is
/// one point's alone). Each kept impact is placed at the median of its votes.
fn impact_frames(poses: &[Option<Pose>], rate_hz: f64) -> Vec<usize> {
    let mut probes = vec![DVec3::ZERO];
    for x in -1..=1 {
        for y in -1..=1 {
            for z in -1..=1 {
                if (x, y, z) != (0, 0, 0) {
                    let u = DVec3::new(x as f64, y as f64, z as f64).normalize();
                    probes.push(u * PROBE_LENGTH_M);
                }
            }
        }
    }
    let mut votes: Vec<usize> = probes
        .iter()
        .flat_map(|&d| {
            impacts_of_point(poses, d, rate_hz)
                .into_iter()
                .map(|i| i.frame)
        })
        .collect();
    votes.sort_unstable();
    let needed = ((CONSENSUS * probes.len() as f64).ceil() as usize).max(2);
    let mut frames = Vec::new();
    let mut start = 0;
    while start < votes.len() {
        let mut end = start + 1;
        while end < votes.len() && votes[end] - votes[end - 1] <= NEAR_FRAMES {
            end += 1;
        }
        if end - start >= needed {
            frames.push(votes[(start + end) / 2]);
        }
        start = end;
    }
    frames
}

/// Of two body points, the one that comes down faster to its impacts (the tip end of
/// the stick, farther from the grip it turns about).
fn faster_end(poses: &[Option<Pose>], a: DVec3, b: DVec3, rate_hz: f64) -> DVec3 {
    let speed = |d: DVec3| {
        median_or_zero(
            impacts_of_point(poses, d, rate_hz)
                .iter()
                .map(|i| i.approach_mps),
        )
    };
    if speed(a) >= speed(b) { a } else { b }
}

/// The prior tip of a rigid body (module doc, step 3) and its standard deviation per
/// body axis (m): `a·ĝ ± b·ĥ` with `ĝ` the stick's vertical at impact, `ĥ` the
/// horizontal direction in the stroke plane, `a` putting the tip on a head
/// `head_height_m` above the floor and `b` making the distance [`PRIOR_LENGTH_M`], the
/// sign that of the end that comes down faster.
fn cluster_prior(
    poses: &[Option<Pose>],
    impacts: &[usize],
    rate_hz: f64,
    head_height_m: f64,
) -> (DVec3, DVec3) {
    let at: Vec<Pose> = impacts.iter().filter_map(|&i| poses[i]).collect();
    let g = at
        .iter()
        .map(|p| p.1.conjugate() * DVec3::Z)
        .sum::<DVec3>()
        .normalize_or(DVec3::Z);
    let axis = turning_axis(poses, rate_hz);
    let lateral = (axis - g * axis.dot(g)).normalize_or(g.any_orthonormal_vector());
    let forward = lateral.cross(g).normalize_or(DVec3::X);
    let origin_height = median_or_zero(at.iter().map(|p| p.0.z));
    let a = (head_height_m - origin_height).min(0.0);
    let b = (PRIOR_LENGTH_M * PRIOR_LENGTH_M - a * a).max(0.01).sqrt();
    (
        faster_end(poses, g * a + forward * b, g * a - forward * b, rate_hz),
        DVec3::splat(PRIOR_SD_M),
    )
}

/// The body axis the stick mostly turns about: the principal direction of its angular
/// velocity in the body frame.
fn turning_axis(poses: &[Option<Pose>], rate_hz: f64) -> DVec3 {
    let mut scatter = DMat3::ZERO;
    for w in poses.windows(2) {
        if let (Some(a), Some(b)) = (w[0], w[1]) {
            let omega = turn_between(a, b) * rate_hz;
            scatter += DMat3::from_cols(omega * omega.x, omega * omega.y, omega * omega.z);
        }
    }
    let mut v = DVec3::new(0.577, 0.577, 0.577);
    for _ in 0..50 {
        v = (scatter * v).normalize_or(DVec3::X);
    }
    v
}

/// The rows with the changes of `g` between impacts kept only along the directions where
/// they stand well above the orientation noise (variance over 5× `noise_var`): along the
/// others, fitting would explain height noise with angle noise, so the priors decide.
fn reliable(rows: Vec<(DVec3, f64)>, keep: &[bool], noise_var: f64) -> Vec<(DVec3, f64)> {
    let kept: Vec<DVec3> = rows
        .iter()
        .zip(keep)
        .filter(|(_, k)| **k)
        .map(|(r, _)| r.0)
        .collect();
    let n = kept.len().max(1) as f64;
    let mean = kept.iter().sum::<DVec3>() / n;
    let mut covariance = DMat3::ZERO;
    for g in &kept {
        let e = *g - mean;
        covariance += DMat3::from_cols(e * e.x, e * e.y, e * e.z) / n;
    }
    let (values, vectors) = symmetric_eigen(covariance);
    let mut keep = DMat3::ZERO;
    for (value, v) in values.iter().zip(vectors) {
        if *value > 5.0 * noise_var {
            keep += DMat3::from_cols(v * v.x, v * v.y, v * v.z);
        }
    }
    rows.into_iter()
        .map(|(g, z)| (mean + keep * (g - mean), z))
        .collect()
}

/// Which impacts met the head with the stick at a usual angle: `g` within 0.05 (about
/// 3°) or four median deviations of the median `g`, whichever is wider. A minimum found at
/// another phase of the stroke has the stick at another angle.
fn usual_angles(rows: &[(DVec3, f64)]) -> Vec<bool> {
    let component = |f: fn(DVec3) -> f64| median_or_zero(rows.iter().map(|r| f(r.0)));
    let centre = DVec3::new(component(|g| g.x), component(|g| g.y), component(|g| g.z));
    let spread = median_or_zero(rows.iter().map(|r| r.0.distance(centre)));
    let limit = (4.0 * spread).max(0.05);
    rows.iter().map(|r| r.0.distance(centre) <= limit).collect()
}

/// Variance of the orientation noise per axis, rad²: from the second differences of the
/// frame-to-frame rotations (white noise of variance σ² gives 6σ² per axis; the median of
/// a 3-axis χ² is 2.37 times the per-axis variance).
fn rotation_noise_var(poses: &[Option<Pose>]) -> f64 {
    let steps: Vec<Option<DVec3>> = poses
        .windows(2)
        .map(|w| Some(turn_between(w[0]?, w[1]?)))
        .collect();
    let squares = steps
        .windows(2)
        .filter_map(|w| Some((w[1]? - w[0]?).length_squared()));
    median_or_zero(squares) / (6.0 * 2.37)
}

/// The body's turn from pose `a` to pose `b` as a rotation vector in the body frame
/// (axis times angle, the angle in (−π, π]), rad.
fn turn_between(a: Pose, b: Pose) -> DVec3 {
    let (axis, angle) = (a.1.conjugate() * b.1).to_axis_angle();
    let angle = if angle > std::f64::consts::PI {
        angle - std::f64::consts::TAU
    } else {
        angle
    };
    axis * angle
}

/// The lowest height of point `d` within [`NEAR_FRAMES`] of each impact, with its frame.
fn lowest_near(poses: &[Option<Pose>], impacts: &[usize], d: DVec3) -> Vec<(usize, f64)> {
    impacts
        .iter()
        .filter_map(|&i| {
            (i.saturating_sub(NEAR_FRAMES)..=(i + NEAR_FRAMES).min(poses.len() - 1))
                .filter_map(|f| Some((f, point(poses[f]?, d).z)))
                .min_by(|a, b| a.1.total_cmp(&b.1))
        })
        .collect()
}

/// The posterior mean of `d` and `h` (module doc, step 4); `on_axis`: `d` on the body's x
/// axis, only the x component of `g` (the stick's tilt) used.
fn fit(
    poses: &[Option<Pose>],
    impacts: &[usize],
    prior: (DVec3, DVec3),
    noise_var: f64,
    head_height_m: f64,
    on_axis: bool,
) -> TipEstimate {
    let mut d = prior.0;
    let mut rows: Vec<(DVec3, f64)> = Vec::new();
    let mut keep: Vec<bool> = Vec::new();
    let mut solution = (d, head_height_m, DMat4::IDENTITY);
    for _ in 0..4 {
        let raw: Vec<(DVec3, f64)> = lowest_near(poses, impacts, d)
            .into_iter()
            .filter_map(|(f, _)| poses[f].map(|p| (p.1.conjugate() * DVec3::Z, p.0.z)))
            .map(|(g, z)| (if on_axis { DVec3::X * g.x } else { g }, z))
            .collect();
        let usual = usual_angles(&raw);
        keep = usual.clone();
        rows = reliable(raw, &keep, noise_var);
        for _ in 0..3 {
            solution = solve(&rows, &keep, prior, head_height_m);
            let residuals: Vec<f64> = rows
                .iter()
                .map(|&(g, z)| z + g.dot(solution.0) - solution.1)
                .collect();
            let spread = mad(&residuals).max(1e-4);
            let centre = median_or_zero(residuals.iter().copied());
            keep = residuals
                .iter()
                .zip(&usual)
                .map(|(r, u)| *u && (r - centre).abs() <= 3.0 * 1.4826 * spread)
                .collect();
        }
        solution = solve(&rows, &keep, prior, head_height_m);
        d = solution.0;
    }
    let (d, h, covariance) = solution;
    let used: Vec<f64> = rows
        .iter()
        .zip(&keep)
        .filter(|(_, k)| **k)
        .map(|(&(g, z), _)| z + g.dot(d) - h)
        .collect();
    let n = used.len().max(1) as f64;
    TipEstimate {
        offset_m: d,
        standard_error_m: DVec3::new(
            covariance.x_axis.x.sqrt(),
            covariance.y_axis.y.sqrt(),
            covariance.z_axis.z.sqrt(),
        ),
        plane_height_m: h,
        residual_m: (used.iter().map(|r| r * r).sum::<f64>() / n).sqrt(),
        impacts: used.len(),
    }
}

/// Solve `g·d − h = −z` over the kept rows (each with [`IMPACT_SD_M`]) together with the
/// priors `d ≈ prior.0` (standard deviations `prior.1`), `h ≈ head_height_m`
/// ([`PRIOR_SD_M`]). Returns `d`, `h` and the posterior covariance.
fn solve(
    rows: &[(DVec3, f64)],
    keep: &[bool],
    prior: (DVec3, DVec3),
    head_height_m: f64,
) -> (DVec3, f64, DMat4) {
    let data_weight = 1.0 / (IMPACT_SD_M * IMPACT_SD_M);
    let prior_weight = prior.1.extend(PRIOR_SD_M).powf(-2.0);
    let mut precision = DMat4::from_diagonal(prior_weight);
    let mut rhs = prior.0.extend(head_height_m) * prior_weight;
    for (&(g, z), _) in rows.iter().zip(keep).filter(|(_, k)| **k) {
        let a = DVec4::new(g.x, g.y, g.z, -1.0);
        precision += DMat4::from_cols(a * a.x, a * a.y, a * a.z, a * a.w) * data_weight;
        rhs += a * (-z * data_weight);
    }
    let covariance = precision.inverse();
    let x = covariance * rhs;
    (x.truncate(), x.w, covariance)
}

/// The median of the finite values, 0 for none.
fn median_or_zero(xs: impl IntoIterator<Item = f64>) -> f64 {
    median(xs).unwrap_or(0.0)
}

/// Median absolute deviation from the median (infinite for no values).
fn mad(xs: &[f64]) -> f64 {
    if xs.is_empty() {
        return f64::INFINITY;
    }
    let m = median_or_zero(xs.iter().copied());
    median_or_zero(xs.iter().map(|x| (x - m).abs()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::rng::Rng;

    /// A stick pivoting at a wrist that moves a little, striking a plane at 0.76 m: tip
    /// 0.36 m from the wrist along the stick, marker cluster 0.28 m behind the tip and
    /// 1.5 cm off the shaft, the cluster frame turned arbitrarily against the stick. The
    /// pitch at impact and the shaft's roll vary from stroke to stroke by a few degrees.
    fn rigid_stick(rate: f64, noise_m: f64) -> (Vec<Option<DVec3>>, Vec<Option<DQuat>>, DVec3) {
        let cluster = DQuat::from_rotation_x(1.1) * DQuat::from_rotation_z(0.4);
        let tip_in_stick = DVec3::new(0.0, 0.36, 0.0);
        let origin_in_stick = DVec3::new(0.015, 0.08, 0.0);
        let truth = cluster.conjugate() * (tip_in_stick - origin_in_stick);
        let mut rng = Rng::new(3);
        let period = 0.7;
        let strokes = 14;
        let n = (period * strokes as f64 * rate) as usize;
        let variation: Vec<(f64, f64)> = (0..=strokes)
            .map(|_| (rng.uniform(-0.06, 0.06), rng.uniform(-0.12, 0.12)))
            .collect();
        let mut positions = Vec::with_capacity(n);
        let mut rotations = Vec::with_capacity(n);
        for f in 0..n {
            let t = f as f64 / rate;
            let k = (t / period) as usize;
            let u = t / period - k as f64;
            // Each stroke's pitch and roll blend smoothly into the next one's.
            let blend = u * u * (3.0 - 2.0 * u);
            let (a, b) = (variation[k], variation[(k + 1).min(strokes)]);
            let pitch_var = a.0 + (b.0 - a.0) * blend;
            let roll = a.1 + (b.1 - a.1) * blend;
            // Lift: the stick rises after the impact at u = 0 and falls back fast.
            let lift = if u < 0.7 {
                (u / 0.7 * std::f64::consts::FRAC_PI_2).sin()
            } else {
                ((1.0 - u) / 0.3 * std::f64::consts::FRAC_PI_2).sin()
            };
            let impact_pitch = -(0.20 / 0.36f64).asin() + pitch_var;
            let pitch = impact_pitch + 0.9 * lift;
            let stick = DQuat::from_rotation_x(pitch) * DQuat::from_rotation_y(roll);
            // The wrist stands where the tip just meets the plane at impact.
            let tip_at_impact = (DQuat::from_rotation_x(impact_pitch) * tip_in_stick).z;
            let wrist = DVec3::new(0.2, 0.25, 0.76 - tip_at_impact + 0.04 * lift);
            let body = stick * cluster;
            let origin = wrist + stick * origin_in_stick;
            let jitter = DVec3::new(rng.normal(), rng.normal(), rng.normal()) * noise_m;
            positions.push(Some(origin + jitter));
            rotations.push(Some(body));
        }
        (positions, rotations, truth)
    }

    /// The tip of a rigid body is found to a few millimetres from 1 mm-noisy data at
    /// 200 Hz, and its height scatter at impacts is near the noise.
    #[test]
    fn finds_the_tip_of_a_rigid_stick() {
        let (p, q, truth) = rigid_stick(200.0, 0.001);
        let e = estimate(&p, &q, 200.0, 0.76, TipPrior::Cluster).unwrap();
        let error = (e.offset_m - truth).length();
        eprintln!("tip estimate off by {:.1} mm: {e:?}", error * 1e3);
        assert!(e.impacts >= 12, "{e:?}");
        assert!(
            error < 0.01,
            "off by {:.1} mm: {e:?} truth {truth}",
            error * 1e3
        );
        assert!(e.residual_m < 0.003, "{e:?}");
        assert!((e.plane_height_m - 0.76).abs() < 0.005, "{e:?}");
    }

    /// Markers without orientation, or no impacts, give a clear error.
    #[test]
    fn refuses_what_it_cannot_use() {
        let still = vec![Some(DVec3::new(0.0, 0.0, 1.0)); 400];
        assert_eq!(
            estimate(&still, &[], 200.0, 0.76, TipPrior::Cluster),
            Err(TipEstimateError::NoRotations)
        );
        let q = vec![Some(DQuat::IDENTITY); 400];
        assert!(matches!(
            estimate(&still, &q, 200.0, 0.76, TipPrior::Cluster),
            Err(TipEstimateError::TooFewImpacts(0))
        ));
    }
}
