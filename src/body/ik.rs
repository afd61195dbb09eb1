//! Position inverse kinematics for one arm chain (shoulder, elbow, wrist, grip; the trunk
//! optionally included), bringing a stick tip to a target: Jacobian transpose,
//! pseudo-inverse, or damped least squares Δθ = W·Jᵀ(J·W·Jᵀ + λ²I)⁻¹·e (seed 000 eq. 3),
//! with per-joint weights and a null-space pull toward a reference pose so the redundant
//! arm keeps a natural posture.
//!
//! Each ball joint contributes three columns, one per world axis a: a × (tip − joint).
//! A step ω (world frame) is applied to a joint's local rotation as
//! q ← (R_parent⁻¹·exp(ω)·R_parent)·q.

use super::limits::JointLimits;
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
/// redundant degrees of freedom toward `reference` if given and holding every chain joint
/// within its ellipsoid of `limits` (see [`iterate`]). Never produces NaN: an unreachable
/// target leaves the arm stretched toward it with the remaining error reported.
pub fn solve(
    skeleton: &Skeleton,
    start: &Pose,
    side: Side,
    target: DVec3,
    reference: Option<&Pose>,
    params: &IkParams,
    limits: &JointLimits,
) -> IkResult {
    solve_task(
        skeleton,
        start,
        (side, Task::Tip),
        target,
        reference,
        params,
        limits,
    )
}

/// [`solve`] for any [`Task`] of the `side` arm; the error is the task's effector's.
pub fn solve_task(
    skeleton: &Skeleton,
    start: &Pose,
    (side, task): (Side, Task),
    target: DVec3,
    reference: Option<&Pose>,
    params: &IkParams,
    limits: &JointLimits,
) -> IkResult {
    let mut pose = *start;
    let mut iterations = 0;
    let mut error = f64::INFINITY;
    while iterations < params.max_iterations {
        let frames = skeleton.forward(&pose);
        error = (target - task.effector(&frames, side)).length();
        if error <= params.tolerance_m {
            break;
        }
        iterations += 1;
        iterate_task(
            &frames,
            &mut pose,
            (side, task),
            target,
            reference,
            params,
            limits,
        );
    }
    if iterations == params.max_iterations {
        error = (target - task.effector(&skeleton.forward(&pose), side)).length();
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
/// solver, every joint within `limits`), so a simulation started in it has its tips on
/// their first targets instead of hanging at rest ~0.8 m away. A tip out of reach leaves
/// that arm stretched toward it.
pub fn posture_reaching(skeleton: &Skeleton, tips: [DVec3; 2], limits: &JointLimits) -> Pose {
    let params = IkParams {
        max_iterations: 500,
        use_trunk: false,
        ..IkParams::default()
    };
    let mut pose = super::skeleton::REST;
    for (side, tip) in [Side::Left, Side::Right].into_iter().zip(tips) {
        pose = solve(skeleton, &pose, side, tip, None, &params, limits).pose;
    }
    pose
}

/// One column of the chain's Jacobian: the joint, the world axis of rotation a, the tip's
/// velocity a × (tip − joint) per unit rotation about it, and the joint's weight.
type Column = (usize, DVec3, DVec3, f64);

/// One iteration of the solver: the joint steps that move the `side` tip toward `target`,
/// computed from `frames` (the forward kinematics of the pose the steps are applied to) and
/// applied to `pose`. HIMC runs exactly this once per arm at each nested solve, both arms
/// from one forward-kinematics pass (the arms' chains share at most the trunk).
///
/// **Joint limits.** A chain joint with a limit in `limits` that is on (or beyond) its
/// ellipsoid and whose step would take it further out is clamped: its rotations are
/// restricted to the ellipsoid's tangent plane (its outward normal,
/// [`JointLimit::outward`](super::limits::JointLimit::outward), removed from its three
/// axes and from its null-space pull) and the step solved again, so the other joints of
/// the redundant chain take over what it cannot do (at most once per joint). A joint
/// that a step takes across its ellipsoid is put back on it
/// ([`JointLimit::boundary`](super::limits::JointLimit::boundary)); one already outside
/// is moved onto it. The pose leaves every limited chain joint within its ellipsoid.
pub fn iterate(
    frames: &Frames,
    pose: &mut Pose,
    side: Side,
    target: DVec3,
    reference: Option<&Pose>,
    params: &IkParams,
    limits: &JointLimits,
) {
    iterate_task(
        frames,
        pose,
        (side, Task::Tip),
        target,
        reference,
        params,
        limits,
    );
}

/// What an IK step brings to its target, and with which joints.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Task {
    /// The stick tip, with the whole arm (and the trunk when the parameters say so).
    Tip,
    /// The hand (the grip joint, where the fingers hold the stick), with the arm up to the
    /// wrist: a hand resting on a head to damp it.
    Hand,
    /// The stick tip, with the grip joint alone: the stick turned about the hand (which it
    /// does not move) to point at the target.
    StickAim,
}

impl Task {
    /// The point the task moves, m.
    fn effector(self, frames: &Frames, side: Side) -> DVec3 {
        match self {
            Task::Tip | Task::StickAim => frames.tip(side),
            Task::Hand => frames.position[Joint::arm(side)[3].index()],
        }
    }
}

/// [`iterate`] for any [`Task`] of the `side` arm.
pub fn iterate_task(
    frames: &Frames,
    pose: &mut Pose,
    (side, task): (Side, Task),
    target: DVec3,
    reference: Option<&Pose>,
    params: &IkParams,
    limits: &JointLimits,
) {
    // Fixed-size buffers: the solver runs every simulation step and must not allocate.
    let mut chain = [(Joint::Trunk, 0.0); 5];
    let mut len = 0;
    if params.use_trunk && task != Task::StickAim {
        chain[0] = (Joint::Trunk, params.weights[0]);
        len = 1;
    }
    let (skip, take) = match task {
        Task::Tip => (0, 4),
        Task::Hand => (0, 3),
        Task::StickAim => (3, 1),
    };
    let arm = Joint::arm(side)
        .into_iter()
        .zip(params.weights[1..].iter().copied());
    for (j, w) in arm.skip(skip).take(take) {
        chain[len] = (j, w);
        len += 1;
    }
    let chain = &chain[..len];
    let effector = task.effector(frames, side);
    // Outward normals (world) of the limited joints on or beyond their ellipsoids.
    let mut at_limit = [None; 5];
    for (normal, &(j, _)) in at_limit.iter_mut().zip(chain) {
        if let Some(limit) = &limits[j.index()]
            && limit.radius(pose[j.index()]) >= 1.0 - 1e-9
        {
            let n =
                (frames.parent_rotation(j) * limit.outward(pose[j.index()])).normalize_or_zero();
            *normal = (n != DVec3::ZERO).then_some(n);
        }
    }
    let mut clamped = [None; 5];
    let mut step = chain_step(
        frames, pose, chain, &clamped, effector, target, reference, params,
    );
    for _ in 0..chain.len() {
        let mut more = false;
        for slot in 0..chain.len() {
            if let (None, Some(n)) = (clamped[slot], at_limit[slot])
                && step[chain[slot].0.index()].dot(n) > 0.0
            {
                clamped[slot] = Some(n);
                more = true;
            }
        }
        if !more {
            break;
        }
        step = chain_step(
            frames, pose, chain, &clamped, effector, target, reference, params,
        );
    }
    for &(j, _) in chain {
        let i = j.index();
        let mut w = step[i];
        if w.length() > params.max_step_rad {
            w = w.normalize() * params.max_step_rad;
        }
        let parent = frames.parent_rotation(j);
        pose[i] = (parent.inverse() * DQuat::from_scaled_axis(w) * parent * pose[i]).normalize();
        if let Some(limit) = &limits[i] {
            pose[i] = limit.boundary(pose[i]);
        }
    }
}

/// The joint steps (world rotation vectors, rad) of one iteration over `chain`, each
/// clamped joint's (`clamped[slot]`: its outward normal) kept out of that normal.
#[allow(clippy::too_many_arguments)]
fn chain_step(
    frames: &Frames,
    pose: &Pose,
    chain: &[(Joint, f64)],
    clamped: &[Option<DVec3>; 5],
    effector: DVec3,
    target: DVec3,
    reference: Option<&Pose>,
    params: &IkParams,
) -> [DVec3; JOINT_COUNT] {
    let tip = effector;
    let e = target - tip;
    // Columns: three world axes per joint (a clamped joint's projected on its tangent
    // plane: three vectors spanning it, whose outer products sum to the projector).
    let mut buffer: [Column; 15] = [(0, DVec3::ZERO, DVec3::ZERO, 0.0); 15];
    for ((slot, &(j, w)), normal) in buffer.chunks_mut(3).zip(chain).zip(clamped) {
        let r = tip - frames.position[j.index()];
        for (column, a) in slot.iter_mut().zip([DVec3::X, DVec3::Y, DVec3::Z]) {
            let a = normal.map_or(a, |n| a - n * n.dot(a));
            *column = (j.index(), a, a.cross(r), w);
        }
    }
    let columns = &buffer[..3 * chain.len()];
    let jwjt = columns
        .iter()
        .fold(DMat3::ZERO, |m, &(_, _, c, w)| m + outer(c, c) * w);
    // (JWJᵀ + λ²I)⁻¹, zero where singular: the damped solve of the step and of the
    // null-space pull share it.
    let damped = safe_inverse(jwjt + DMat3::IDENTITY * params.damping_m.powi(2), 0.0);
    let y = match params.method {
        IkMethod::Transpose => {
            let jjt_e = jwjt * e;
            e * (e.dot(jjt_e) / jjt_e.length_squared().max(1e-12))
        }
        IkMethod::PseudoInverse => safe_inverse(jwjt, 1e-9) * e,
        IkMethod::DampedLeastSquares => damped * e,
    };
    let mut step = [DVec3::ZERO; JOINT_COUNT];
    for &(i, a, c, w) in columns {
        step[i] += a * (w * c.dot(y));
    }
    if let Some(reference) = reference {
        let mut normals = [None; JOINT_COUNT];
        for (&(j, _), n) in chain.iter().zip(clamped) {
            normals[j.index()] = *n;
        }
        add_null_space_pull(
            &mut step, columns, frames, pose, reference, damped, params, &normals,
        );
    }
    step
}

/// Add z − W·Jᵀ(JWJᵀ + λ²I)⁻¹·J·z (`damped`: the inverse), where z turns each chain
/// joint toward `reference` (a clamped joint's turn without its component along its
/// outward normal `normals`).
#[allow(clippy::too_many_arguments)]
fn add_null_space_pull(
    step: &mut [DVec3],
    columns: &[Column],
    frames: &Frames,
    pose: &Pose,
    reference: &Pose,
    damped: DMat3,
    params: &IkParams,
    normals: &[Option<DVec3>; JOINT_COUNT],
) {
    let mut z = [DVec3::ZERO; JOINT_COUNT];
    for &(i, _, _, w) in columns.iter().step_by(3) {
        let joint = super::skeleton::Joint::ALL[i];
        // 2·vec(q) = 2·sin(θ/2)·axis: the rotation toward the reference, exact to second
        // order in the angle and free of trigonometry (this runs every simulation step).
        let local = reference[i] * pose[i].inverse();
        let toward = 2.0 * local.xyz() * local.w.signum();
        z[i] = frames.parent_rotation(joint) * toward * (params.reference_gain * w);
        if let Some(n) = normals[i] {
            z[i] -= n * n.dot(z[i]);
        }
    }
    let jz = columns
        .iter()
        .fold(DVec3::ZERO, |s, &(i, a, c, _)| s + c * a.dot(z[i]));
    let y = damped * jz;
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

/// The inverse of `m`, zero where `m` is singular (so a solve m⁻¹·e gives zero there).
fn safe_inverse(m: DMat3, min_det: f64) -> DMat3 {
    let det = m.determinant();
    if det.abs() <= min_det.max(f64::MIN_POSITIVE) || !det.is_finite() {
        DMat3::ZERO
    } else {
        m.inverse()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::body::limits::NO_LIMITS;
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
            let r = solve(
                &s,
                &bent_start(),
                Side::Right,
                target,
                None,
                &params,
                &NO_LIMITS,
            );
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
            &NO_LIMITS,
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
        let pose = posture_reaching(&s, tips, &NO_LIMITS);
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
            &NO_LIMITS,
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
            &NO_LIMITS,
        );
        assert!(pulled.error_m < 5e-4, "{}", pulled.error_m);
        let wrist = Joint::WristR.index();
        let dist = |p: &Pose| p[wrist].angle_between(reference[wrist]);
        assert!(dist(&pulled.pose) < dist(&free.pose));
    }

    /// A target the free solver reaches only by bending the elbow far outside a limit
    /// about its starting rotation: with the limit the elbow ends inside its ellipsoid and
    /// the other joints of the redundant arm still bring the tip onto the target; an
    /// elbow starting outside its ellipsoid is brought onto it.
    #[test]
    fn limits_hold_and_the_arm_reaches_another_way() {
        use crate::body::limits::JointLimit;
        let s = Skeleton::default();
        let elbow = Joint::ElbowR.index();
        let start = bent_start();
        let mut limits = NO_LIMITS;
        limits[elbow] = Some(JointLimit {
            mean: start[elbow],
            axes: [DVec3::X, DVec3::Y, DVec3::Z],
            semi_axes: [0.1; 3],
            centre: DVec3::ZERO,
        });
        let limit = limits[elbow].unwrap();
        let params = IkParams::default();
        let target = DVec3::new(0.2, 0.3, 0.6);
        let free = solve(&s, &start, Side::Right, target, None, &params, &NO_LIMITS);
        assert!(free.converged, "free: {} m", free.error_m);
        assert!(
            limit.radius(free.pose[elbow]) > 1.5,
            "the free solution should leave the limit (2.3 measured): {}",
            limit.radius(free.pose[elbow])
        );
        let held = solve(&s, &start, Side::Right, target, None, &params, &limits);
        assert!(
            limit.contains(held.pose[elbow]),
            "elbow at {} of its ellipsoid",
            limit.radius(held.pose[elbow])
        );
        assert!(
            held.error_m < 1e-3,
            "limited arm {} m from the target",
            held.error_m
        );
        let mut outside = start;
        outside[elbow] = start[elbow] * DQuat::from_rotation_x(0.8);
        let from_outside = solve(&s, &outside, Side::Right, target, None, &params, &limits);
        assert!(limit.contains(from_outside.pose[elbow]));
    }

    /// The hand task puts the grip joint on its target without the grip joint's help, and
    /// aiming the stick turns only the grip: the hand stays where it is.
    #[test]
    fn the_hand_reaches_and_the_stick_turns_about_it() {
        let s = Skeleton::default();
        let params = IkParams::default();
        let grip = Joint::GripR.index();
        let target = DVec3::new(0.3, 0.35, 1.0);
        let placed = solve_task(
            &s,
            &bent_start(),
            (Side::Right, Task::Hand),
            target,
            None,
            &params,
            &NO_LIMITS,
        );
        assert!(placed.converged, "{}", placed.error_m);
        assert_eq!(placed.pose[grip], bent_start()[grip]);
        let hand = s.forward(&placed.pose).position[grip];
        assert!(hand.distance(target) < 1e-4);
        let aim = hand + DVec3::new(0.0, 0.6, 0.8) * s.stick_length_m;
        let aimed = solve_task(
            &s,
            &placed.pose,
            (Side::Right, Task::StickAim),
            aim,
            None,
            &params,
            &NO_LIMITS,
        );
        assert!(aimed.converged, "{}", aimed.error_m);
        let frames = s.forward(&aimed.pose);
        assert!(frames.position[grip].distance(hand) < 1e-12);
        assert!(frames.tip(Side::Right).distance(aim) < 1e-4);
        for j in Joint::ALL.into_iter().filter(|&j| j != Joint::GripR) {
            assert_eq!(aimed.pose[j.index()], placed.pose[j.index()], "{j:?}");
        }
    }
}
