//! Joint-space control of the simulated body (seed 000 §3.2): PD torques
//! τ = ks·e − kd·(ω − ω_t) (eq. 2) toward target joint rotations, with the quaternion error
//! e = 2·vec(q⁻¹·q_t) (the rotation vector log(q⁻¹·q_t) to second order) in the joint's child frame, per-joint gains and
//! torque limits; gains scaled to each joint's effective inertia; gravity compensation;
//! and joint limits as ellipsoids in the quaternion tangent space (seed 000 Alg. 1),
//! enforced by corrective torques.

use super::dynamics::{Dynamics, State};
use super::skeleton::{JOINT_COUNT, Pose};
use crate::body::limits::{JointLimits, quat_log};
use glam::{DMat3, DQuat, DVec3};

/// PD gains and torque limits per joint: ks = ω²·I and kd = 2ζω·I with I the joint's
/// 3×3 effective inertia, so every direction of every joint responds with the natural
/// frequency ω and damping ratio ζ, whatever its inertia.
#[derive(Clone, Debug, PartialEq)]
pub struct Gains {
    /// Stiffness ks, N·m/rad (a 3×3 matrix per joint, child frame).
    pub stiffness: [DMat3; JOINT_COUNT],
    /// Damping kd, N·m·s/rad (3×3 per joint).
    pub damping: [DMat3; JOINT_COUNT],
    /// Largest torque a joint may apply, N·m.
    pub max_torque: [f64; JOINT_COUNT],
}

/// Natural frequency of each joint's PD loop, Hz: the trunk, neck and head slow, the arms
/// and sticks fast enough to follow a stroke. Measured on the shipped database
/// (`timpanist evaluate --trials 5`): arms at 25–40 Hz leave HIMC 2–3 % of the stroke
/// amplitude behind, at 75–120 Hz 0.6–1.2 %, at 112–180 Hz 0.5–0.9 % (the error is the
/// recovery from the trials' 2° posture turns: unperturbed HIMC stays within 0.2 %); at
/// 10 kHz even 180 Hz is ω·dt ≈ 0.11, far inside the explicit integrator's stability.
pub const DEFAULT_FREQUENCY_HZ: [f64; JOINT_COUNT] = [
    8.0, 8.0, 8.0, 112.5, 135.0, 157.5, 180.0, 112.5, 135.0, 157.5, 180.0,
];

impl Gains {
    /// Gains giving each joint the natural frequency `freq_hz` and damping ratio `zeta`
    /// for its effective inertia at `state`: I_eff = (the joint's 3×3 block of M⁻¹)⁻¹, the
    /// inertia the joint really sees with the rest of the body free (gains from diag(M)
    /// overestimate it and blow up explicit integration, guide §5).
    pub fn from_effective_inertia(
        dynamics: &mut Dynamics,
        state: &State,
        freq_hz: &[f64; JOINT_COUNT],
        zeta: f64,
        max_torque: f64,
    ) -> Gains {
        let m = dynamics.mass_matrix(state);
        let inv = invert(&m, 3 * JOINT_COUNT);
        let mut stiffness = [DMat3::ZERO; JOINT_COUNT];
        let mut damping = [DMat3::ZERO; JOINT_COUNT];
        for j in 0..JOINT_COUNT {
            let block = DMat3::from_cols_array_2d(&std::array::from_fn(|c| {
                std::array::from_fn(|r| inv[(3 * j + r) * 3 * JOINT_COUNT + 3 * j + c])
            }));
            let inertia = block.inverse();
            let w = std::f64::consts::TAU * freq_hz[j];
            stiffness[j] = inertia * (w * w);
            damping[j] = inertia * (2.0 * zeta * w);
        }
        Gains {
            stiffness,
            damping,
            max_torque: [max_torque; JOINT_COUNT],
        }
    }

    /// The same joints with stiffness multiplied by `factor[j]` and damping by its square
    /// root (so the damping ratio stays the same).
    pub fn scaled(&self, factor: &[f64; JOINT_COUNT]) -> Gains {
        Gains {
            stiffness: std::array::from_fn(|j| self.stiffness[j] * factor[j]),
            damping: std::array::from_fn(|j| self.damping[j] * factor[j].sqrt()),
            max_torque: self.max_torque,
        }
    }
}

/// Quaternion feedback error from `q` to `target`, child frame: 2·vec(q⁻¹·q_t) on the
/// short arc, = 2·sin(θ/2)·axis. It equals the rotation vector to second order in the
/// angle θ, stays bounded for large errors, and needs no trigonometry (PD evaluates it for
/// every joint at every 0.1 ms step).
pub fn quaternion_error(q: DQuat, target: DQuat) -> DVec3 {
    let d = q.inverse() * target;
    2.0 * d.xyz() * d.w.signum()
}

/// Rotation error from `q` to `target` as a rotation vector in the child frame, rad.
pub fn rotation_error(q: DQuat, target: DQuat) -> DVec3 {
    let d = (q.inverse() * target).normalize();
    let d = if d.w < 0.0 { -d } else { d };
    d.to_scaled_axis()
}

/// PD torques toward `target` (with target angular velocities `target_w`, child frames; the
/// error is [`quaternion_error`]),
/// plus feed-forward `bias`, each clamped to its joint's torque limit.
pub fn pd_torques(
    gains: &Gains,
    state: &State,
    target: &Pose,
    target_w: &[DVec3; JOINT_COUNT],
    bias: &[DVec3; JOINT_COUNT],
) -> [DVec3; JOINT_COUNT] {
    std::array::from_fn(|j| pd_torque(gains, state, j, target[j], target_w[j], bias[j], 1.0))
}

/// The PD torque of joint `j` toward `target` (target angular velocity `target_w`, child
/// frame) plus feed-forward `bias`, with the joint holding the fraction `held` (0–1] of its
/// control: stiffness and feed-forward times `held`, damping times √`held` (the damping
/// ratio unchanged), clamped to its torque limit. A relaxed grip (`held` ≪ 1) lets the
/// stick turn freely about the fulcrum.
// Inlined so `pd_torques`' constant `held` = 1 folds away (its factors are exactly 1).
#[inline(always)]
pub fn pd_torque(
    gains: &Gains,
    state: &State,
    j: usize,
    target: DQuat,
    target_w: DVec3,
    bias: DVec3,
    held: f64,
) -> DVec3 {
    let e = quaternion_error(state.q[j], target);
    let tau = held * (gains.stiffness[j] * e)
        - held.sqrt() * (gains.damping[j] * (state.w[j] - target_w))
        + held * bias;
    tau.clamp_length_max(gains.max_torque[j])
}

/// Torques that hold `pose` still against gravity.
pub fn gravity_compensation(dynamics: &mut Dynamics, pose: &Pose) -> [DVec3; JOINT_COUNT] {
    let state = State {
        q: *pose,
        w: [DVec3::ZERO; JOINT_COUNT],
    };
    dynamics.inverse_dynamics(&state, &[DVec3::ZERO; JOINT_COUNT])
}

/// How many times a joint's (muscular) torque limit its limit stop may apply.
pub const LIMIT_TORQUE_FACTOR: f64 = 10.0;

/// Corrective torques pushing joints back inside their limit ellipsoids (seed 000 §3.2):
/// beyond its ellipsoid a joint meets a spring toward the ellipsoid's surface (along the ray
/// from its centre) `stiffness` times as stiff as the joint's PD loop, damped by √stiffness
/// times its PD damping along that direction, and at most [`LIMIT_TORQUE_FACTOR`] times the
/// joint's torque limit (a stop outlasts the muscles pulling against it, but tissue gives
/// way too); inside, nothing. Scaling with each joint's own gains
/// keeps the stop as fast relative to the joint everywhere, and stable for the light stick
/// as for the heavy trunk.
pub fn limit_torques(
    gains: &Gains,
    limits: &JointLimits,
    state: &State,
    stiffness: f64,
) -> [DVec3; JOINT_COUNT] {
    std::array::from_fn(|j| {
        let Some(limit) = &limits[j] else {
            return DVec3::ZERO;
        };
        let q = state.q[j];
        if limit.radius(q) <= 1.0 {
            return DVec3::ZERO;
        }
        let e = quaternion_error(q, limit.boundary(q));
        let inward = e.normalize_or_zero();
        let closing = state.w[j].dot(inward);
        let tau = stiffness * (gains.stiffness[j] * e)
            - stiffness.sqrt() * (gains.damping[j] * (inward * closing));
        tau.clamp_length_max(LIMIT_TORQUE_FACTOR * gains.max_torque[j])
    })
}

/// Half-angle log of each joint relative to `mean` (for checking limits).
pub fn tangent(q: DQuat, mean: DQuat) -> DVec3 {
    quat_log(mean.inverse() * q)
}

/// Invert a dense n×n matrix (row-major) by Gauss–Jordan elimination with partial
/// pivoting.
fn invert(m: &[f64], n: usize) -> Vec<f64> {
    let mut a = m.to_vec();
    let mut inv: Vec<f64> = (0..n * n)
        .map(|k| f64::from(u8::from(k / n == k % n)))
        .collect();
    for col in 0..n {
        let pivot = (col..n)
            .max_by(|&x, &y| a[x * n + col].abs().total_cmp(&a[y * n + col].abs()))
            .unwrap_or(col);
        for k in 0..n {
            a.swap(col * n + k, pivot * n + k);
            inv.swap(col * n + k, pivot * n + k);
        }
        let d = a[col * n + col];
        let d = if d.abs() < 1e-300 { 1e-300 } else { d };
        for k in 0..n {
            a[col * n + k] /= d;
            inv[col * n + k] /= d;
        }
        for row in 0..n {
            if row != col {
                let f = a[row * n + col];
                if f != 0.0 {
                    for k in 0..n {
                        a[row * n + k] -= f * a[col * n + k];
                        inv[row * n + k] -= f * inv[col * n + k];
                    }
                }
            }
        }
    }
    inv
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::body::model::BodyModel;
    use crate::body::skeleton::Joint;

    /// Dense inversion: M·M⁻¹ = I on the body's mass matrix.
    #[test]
    fn inverse_of_mass_matrix() {
        let mut dynamics = Dynamics::new(BodyModel::default());
        let m = dynamics.mass_matrix(&State::rest());
        let n = 33;
        let inv = invert(&m, n);
        for r in 0..n {
            for c in 0..n {
                let v: f64 = (0..n).map(|k| m[r * n + k] * inv[k * n + c]).sum();
                assert!(
                    (v - f64::from(u8::from(r == c))).abs() < 1e-8,
                    "({r},{c}) = {v}"
                );
            }
        }
    }

    /// PD with gravity compensation holds a bent-arm pose and settles onto a new target
    /// within 0.1° in 2 s of simulation at 10 kHz.
    #[test]
    fn pd_settles_to_target() {
        let mut dynamics = Dynamics::new(BodyModel::default());
        let mut start = crate::body::skeleton::REST;
        start[Joint::ShoulderR.index()] = DQuat::from_rotation_x(0.5);
        start[Joint::ElbowR.index()] = DQuat::from_rotation_x(1.2);
        let mut target = start;
        target[Joint::ShoulderR.index()] = DQuat::from_rotation_x(0.8);
        target[Joint::WristR.index()] = DQuat::from_rotation_x(-0.4);
        let mut state = State {
            q: start,
            w: [DVec3::ZERO; JOINT_COUNT],
        };
        let gains =
            Gains::from_effective_inertia(&mut dynamics, &state, &DEFAULT_FREQUENCY_HZ, 1.0, 200.0);
        let bias = gravity_compensation(&mut dynamics, &target);
        for _ in 0..20_000 {
            let tau = pd_torques(&gains, &state, &target, &[DVec3::ZERO; JOINT_COUNT], &bias);
            dynamics.step(&mut state, &tau, &[], 1e-4);
        }
        for (j, (q, t)) in state.q.iter().zip(&target).enumerate() {
            let err = rotation_error(*q, *t).length();
            assert!(
                err < 0.1f64.to_radians(),
                "{:?}: {} deg",
                Joint::ALL[j],
                err.to_degrees()
            );
        }
    }
}
