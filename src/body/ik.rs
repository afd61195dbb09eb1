//! Position inverse kinematics for one arm chain (shoulder, elbow, wrist, grip; the trunk
//! optionally included), bringing a stick tip to a target: Jacobian transpose,
//! pseudo-inverse, or damped least squares Δθ = W·Jᵀ(J·W·Jᵀ + λ²I)⁻¹·e (seed 000 eq. 3),
//! with per-joint weights and a null-space pull toward a reference pose so the redundant
//! arm keeps a natural posture.
//!
//! Each ball joint contributes three columns, one per world axis a: a × (tip − joint).
//! A step ω (world frame) is applied to a joint's local rotation as
//! q ← (R_parent⁻¹·exp(ω)·R_parent)·q.

use super::skeleton::{Frames, JOINT_COUNT, Joint, Pose, Skeleton};
pub use crate::base::choices::IkMethod;
use crate::kit::Side;
use glam::{DMat3, DQuat, DVec3};

/// Solver settings.
#[derive(Clone, Debug, PartialEq)]
pub struct IkParams {
    pub method: IkMethod,
    /// Damping λ of damped least squares, m.
    pub damping_m: f64,
    /// Stop when the tip is this close to the target, m.
    pub tolerance_m: f64,
    pub max_iterations: usize,
    /// Largest rotation of one joint in one iteration, rad.
    pub max_step_rad: f64,
    /// Include the trunk joint in the chain.
    pub use_trunk: bool,
    /// Relative mobility of trunk, shoulder, elbow, wrist, grip (higher moves more).
    pub weights: [f64; 5],
    /// Gain of the null-space pull toward the reference pose, per iteration (0–1).
    pub reference_gain: f64,
}

impl Default for IkParams {
    fn default() -> Self {
        IkParams {
            method: IkMethod::DampedLeastSquares,
            damping_m: 0.02,
            tolerance_m: 1e-5,
            max_iterations: 200,
            max_step_rad: 0.2,
            use_trunk: false,
            weights: [0.2, 1.0, 1.0, 1.0, 1.0],
            reference_gain: 0.1,
        }
    }
}

/// What the solver reached.
#[derive(Clone, Debug)]
pub struct IkResult {
    pub pose: Pose,
    /// Remaining distance from tip to target, m.
    pub error_m: f64,
    pub iterations: usize,
    pub converged: bool,
}

/// Move the `side` stick tip of `start` toward `target` (performer frame, m), pulling the
/// redundant degrees of freedom toward `reference` if given. Never produces NaN: an
/// unreachable target leaves the arm stretched toward it with the remaining error reported.
pub fn solve(
    skeleton: &Skeleton,
    start: &Pose,
    side: Side,
    target: DVec3,
    reference: Option<&Pose>,
    params: &IkParams,
) -> IkResult {
    let mut pose = *start;
    let mut iterations = 0;
    let mut error = f64::INFINITY;
    while iterations < params.max_iterations {
        let frames = skeleton.forward(&pose);
        error = (target - frames.tip(side)).length();
        if error <= params.tolerance_m {
            break;
        }
        iterations += 1;
        iterate(&frames, &mut pose, side, target, reference, params);
    }
    if iterations == params.max_iterations {
        error = (target - skeleton.tip(&pose, side)).length();
    }
    IkResult {
        pose,
        error_m: error,
        iterations,
        converged: error <= params.tolerance_m,
    }
}

/// A posture with both stick tips on `tips` ([left, right], m, performer frame): each arm
/// solved in turn from the rest pose (trunk upright, 500 iterations of the default
/// solver), so a simulation started in it has its tips on their first targets instead of
/// hanging at rest ~0.8 m away. A tip out of reach leaves that arm stretched toward it.
pub fn posture_reaching(skeleton: &Skeleton, tips: [DVec3; 2]) -> Pose {
    let params = IkParams {
        max_iterations: 500,
        use_trunk: false,
        ..IkParams::default()
    };
    let mut pose = super::skeleton::REST;
    for (side, tip) in [Side::Left, Side::Right].into_iter().zip(tips) {
        pose = solve(skeleton, &pose, side, tip, None, &params).pose;
    }
    pose
}

/// One iteration of the solver: the joint steps that move the `side` tip toward `target`,
/// computed from `frames` (the forward kinematics of the pose the steps are applied to) and
/// applied to `pose`. HIMC runs exactly this once per arm every simulation step, both arms
/// from one forward-kinematics pass (the arms' chains share at most the trunk).
pub fn iterate(
    frames: &Frames,
    pose: &mut Pose,
    side: Side,
    target: DVec3,
    reference: Option<&Pose>,
    params: &IkParams,
) {
    // Fixed-size buffers: the solver runs every simulation step and must not allocate.
    let mut chain = [(Joint::Trunk, 0.0); 5];
    let mut len = 0;
    if params.use_trunk {
        chain[0] = (Joint::Trunk, params.weights[0]);
        len = 1;
    }
    for (&j, &w) in Joint::arm(side).iter().zip(&params.weights[1..]) {
        chain[len] = (j, w);
        len += 1;
    }
    let chain = &chain[..len];
    let tip = frames.tip(side);
    let e = target - tip;
    // Columns: three world axes per joint.
    let mut buffer = [(0usize, DVec3::ZERO, DVec3::ZERO, 0.0); 15];
    for (slot, &(j, w)) in buffer.chunks_mut(3).zip(chain) {
        let r = tip - frames.position[j.index()];
        for (column, a) in slot.iter_mut().zip([DVec3::X, DVec3::Y, DVec3::Z]) {
            *column = (j.index(), a, a.cross(r), w);
        }
    }
    let columns = &buffer[..3 * chain.len()];
    let jwjt = columns
        .iter()
        .fold(DMat3::ZERO, |m, &(_, _, c, w)| m + outer(c, c) * w);
    let y = match params.method {
        IkMethod::Transpose => {
            let jjt_e = jwjt * e;
            e * (e.dot(jjt_e) / jjt_e.length_squared().max(1e-12))
        }
        IkMethod::PseudoInverse => safe_solve(jwjt, e, 1e-9),
        IkMethod::DampedLeastSquares => {
            safe_solve(jwjt + DMat3::IDENTITY * params.damping_m.powi(2), e, 0.0)
        }
    };
    let mut step = [DVec3::ZERO; JOINT_COUNT];
    for &(i, a, c, w) in columns {
        step[i] += a * (w * c.dot(y));
    }
    if let Some(reference) = reference {
        add_null_space_pull(&mut step, columns, frames, pose, reference, jwjt, params);
    }
    for &(j, _) in chain {
        let i = j.index();
        let mut w = step[i];
        if w.length() > params.max_step_rad {
            w = w.normalize() * params.max_step_rad;
        }
        let parent = frames.parent_rotation(j);
        pose[i] = (parent.inverse() * DQuat::from_scaled_axis(w) * parent * pose[i]).normalize();
    }
}

/// Add z − W·Jᵀ(JWJᵀ + λ²I)⁻¹·J·z, where z turns each chain joint toward `reference`.
fn add_null_space_pull(
    step: &mut [DVec3],
    columns: &[(usize, DVec3, DVec3, f64)],
    frames: &Frames,
    pose: &Pose,
    reference: &Pose,
    jwjt: DMat3,
    params: &IkParams,
) {
    let mut z = [DVec3::ZERO; JOINT_COUNT];
    for &(i, _, _, w) in columns.iter().step_by(3) {
        let joint = super::skeleton::Joint::ALL[i];
        // 2·vec(q) = 2·sin(θ/2)·axis: the rotation toward the reference, exact to second
        // order in the angle and free of trigonometry (this runs every simulation step).
        let local = reference[i] * pose[i].inverse();
        let toward = 2.0 * local.xyz() * local.w.signum();
        z[i] = frames.parent_rotation(joint) * toward * (params.reference_gain * w);
    }
    let jz = columns
        .iter()
        .fold(DVec3::ZERO, |s, &(i, a, c, _)| s + c * a.dot(z[i]));
    let y = safe_solve(jwjt + DMat3::IDENTITY * params.damping_m.powi(2), jz, 0.0);
    for &(i, a, c, w) in columns {
        step[i] -= a * (w * c.dot(y));
    }
    for (s, zi) in step.iter_mut().zip(z) {
        *s += zi;
    }
}

fn outer(a: DVec3, b: DVec3) -> DMat3 {
    DMat3::from_cols(a * b.x, a * b.y, a * b.z)
}

/// Solve m·y = e, returning zero where `m` is singular.
fn safe_solve(m: DMat3, e: DVec3, min_det: f64) -> DVec3 {
    let det = m.determinant();
    if det.abs() <= min_det.max(f64::MIN_POSITIVE) || !det.is_finite() {
        DVec3::ZERO
    } else {
        m.inverse() * e
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::body::skeleton::REST;

    fn bent_start() -> Pose {
        let mut p = REST;
        p[Joint::ShoulderR.index()] = DQuat::from_rotation_x(0.5);
        p[Joint::ElbowR.index()] = DQuat::from_rotation_x(1.0);
        p
    }

    /// Every method converges to a reachable target within tolerance.
    #[test]
    fn reaches_reachable_targets() {
        let s = Skeleton::default();
        let target = DVec3::new(0.35, 0.55, 0.80);
        for method in [
            IkMethod::Transpose,
            IkMethod::PseudoInverse,
            IkMethod::DampedLeastSquares,
        ] {
            let params = IkParams {
                method,
                max_iterations: if method == IkMethod::Transpose {
                    5000
                } else {
                    200
                },
                tolerance_m: 1e-4,
                ..IkParams::default()
            };
            let r = solve(&s, &bent_start(), Side::Right, target, None, &params);
            assert!(r.converged, "{method:?}: error {} m", r.error_m);
            assert!((s.tip(&r.pose, Side::Right) - target).length() < 1e-4);
        }
    }

    /// An unreachable target leaves a finite pose stretched toward it, error reported.
    #[test]
    fn unreachable_target_degrades_gracefully() {
        let s = Skeleton::default();
        let target = DVec3::new(3.0, 3.0, 1.0);
        let r = solve(
            &s,
            &bent_start(),
            Side::Right,
            target,
            None,
            &IkParams::default(),
        );
        assert!(!r.converged);
        assert!(r.pose.iter().all(|q| q.is_finite()));
        let tip = s.tip(&r.pose, Side::Right);
        let shoulder = s.forward(&r.pose).position[Joint::ShoulderR.index()];
        let reach = 0.30 + 0.26 + 0.08 + 0.33;
        assert!(
            (tip - shoulder).length() > reach - 0.01,
            "arm not stretched"
        );
        assert!((target - tip).length() - r.error_m < 1e-9);
    }

    /// Both tips of the reaching posture are on their targets (to the solver's
    /// tolerance), whichever hand's target is nearer the rest pose.
    #[test]
    fn posture_reaching_puts_both_tips_on_target() {
        let s = Skeleton::default();
        let tips = [DVec3::new(-0.3, 0.5, 0.85), DVec3::new(0.35, 0.55, 0.8)];
        let pose = posture_reaching(&s, tips);
        for (side, tip) in [Side::Left, Side::Right].into_iter().zip(tips) {
            assert!(s.tip(&pose, side).distance(tip) < 1e-4, "{side:?}");
        }
    }

    /// The null-space pull keeps the tip on target while moving toward the reference.
    #[test]
    fn reference_pull_keeps_task() {
        let s = Skeleton::default();
        let target = DVec3::new(0.3, 0.5, 0.85);
        let free = solve(
            &s,
            &bent_start(),
            Side::Right,
            target,
            None,
            &IkParams::default(),
        );
        let mut reference = REST;
        reference[Joint::WristR.index()] = DQuat::from_rotation_x(-0.6);
        let pulled = solve(
            &s,
            &bent_start(),
            Side::Right,
            target,
            Some(&reference),
            &IkParams::default(),
        );
        assert!(pulled.error_m < 5e-4, "{}", pulled.error_m);
        let wrist = Joint::WristR.index();
        let dist = |p: &Pose| p[wrist].angle_between(reference[wrist]);
        assert!(dist(&pulled.pose) < dist(&free.pose));
    }
}
