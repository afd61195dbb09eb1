//! Driving the simulated body along a reference motion with one of the three control
//! pipelines of seed 000 (Fig. 1):
//!
//! * **IK** — kinematic only: each task step, inverse kinematics brings both tips to
//!   their targets; no dynamics.
//! * **ID** — PD inverse dynamics tracking the captured joint rotations (seed 000 eq. 2):
//!   PD on the joint error plus the feed-forward torques of the target motion (gravity,
//!   velocity terms and M·q̈, once per task step).
//! * **HIMC** — hybrid inverse motion control (seed 000 Alg. 2): each task step IK turns
//!   the tip targets into joint targets (its redundancy pulled toward the captured
//!   posture where known); *every simulation step* damped least squares from the
//!   simulated pose toward the tip targets, Δq = J⁺(X_t − X), gives the PD target (IK
//!   nested in PD), tracked with the same PD and feed-forward as ID.
//!
//! Task rate 250 Hz and simulation rate 10 kHz by default (40 sub-steps). The run stops
//! with an error naming the time if the state becomes non-finite or diverges.

use super::control::{Gains, pd_torques, rotation_error};
use super::dynamics::{Dynamics, State};
use super::ik::{self, IkParams};
use super::model::BodyModel;
use super::skeleton::{JOINT_COUNT, Joint, Pose};
use crate::kit::Side;
use glam::DVec3;

/// A control pipeline.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pipeline {
    Ik,
    Id,
    Himc,
}

impl Pipeline {
    /// Lower-case name.
    pub fn name(self) -> &'static str {
        match self {
            Pipeline::Ik => "ik",
            Pipeline::Id => "id",
            Pipeline::Himc => "himc",
        }
    }
}

/// Simulation settings.
#[derive(Clone, Debug, PartialEq)]
pub struct SimParams {
    /// Physics rate, Hz.
    pub sim_hz: f64,
    /// Natural frequency of each joint's PD loop, Hz.
    pub frequency_hz: [f64; JOINT_COUNT],
    /// Damping ratio of the PD loops.
    pub zeta: f64,
    /// Torque limit of every joint, N·m.
    pub max_torque: f64,
    /// The IK solver (method, damping, weights).
    pub ik: IkParams,
    /// DLS iterations HIMC runs every simulation step.
    pub nested_iterations: usize,
    /// Angular speed beyond which the simulation counts as diverged, rad/s.
    pub max_angular_speed: f64,
}

impl Default for SimParams {
    fn default() -> Self {
        SimParams {
            sim_hz: 10_000.0,
            frequency_hz: super::control::DEFAULT_FREQUENCY_HZ,
            zeta: 1.0,
            max_torque: 300.0,
            ik: IkParams {
                tolerance_m: 1e-5,
                max_iterations: 30,
                weights: [0.1, 0.5, 0.8, 1.0, 0.8],
                use_trunk: true,
                reference_gain: 0.2,
                ..IkParams::default()
            },
            nested_iterations: 1,
            max_angular_speed: 500.0,
        }
    }
}

/// What to follow: task-rate samples of both tips, and the joint rotations if known.
#[derive(Clone, Debug)]
pub struct Reference {
    /// Task rate, Hz.
    pub rate_hz: f64,
    /// Tip targets per sample, [left, right], m.
    pub tips: [Vec<DVec3>; 2],
    /// Joint rotations per sample (needed by ID; HIMC pulls its IK toward them).
    pub poses: Option<Vec<Pose>>,
    /// Scored impact times (s, from the first sample) with their beat index, in time
    /// order, so that a failure can name the beat it happened in.
    pub beats: Vec<(f64, usize)>,
}

/// What the body did, at the task rate.
#[derive(Clone, Debug, PartialEq)]
pub struct Motion {
    pub rate_hz: f64,
    /// Tip positions per sample, [left, right], m.
    pub tips: [Vec<DVec3>; 2],
    /// Joint rotations per sample.
    pub poses: Vec<Pose>,
}

/// The simulation stopped.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("the simulation {what} at {time_s:.4} s{}", beat.map_or(String::new(), |b| format!(", during beat {b}")))]
pub struct Diverged {
    pub time_s: f64,
    /// The beat being played (the next impact's), when the reference names beats.
    pub beat: Option<usize>,
    pub what: String,
}

/// Why a simulation did not finish.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SimError {
    #[error(transparent)]
    Diverged(#[from] Diverged),
    /// The environment asked to stop (e.g. the user edited the score meanwhile).
    #[error("the simulation was cancelled")]
    Cancelled,
}

/// What the simulated body meets, asked every simulation step: forces on the stick tips
/// (the drum heads) and whether to go on.
pub trait Environment {
    /// Forces (N, performer frame) on the left and right stick tips at `time_s` (s from the
    /// reference's first sample), given each tip's position (m) and velocity (m/s) at the
    /// start of the step. The IK pipeline has no dynamics: its tips are interpolated
    /// between task samples and the forces it gets back are ignored.
    fn tip_forces(&mut self, time_s: f64, tips: [(DVec3, DVec3); 2]) -> [DVec3; 2];

    /// Called once per task step with the samples done and the total; `false` cancels.
    fn progress(&mut self, _done: usize, _total: usize) -> bool {
        true
    }
}

/// Empty space: no contact, never cancelled.
pub struct FreeSpace;

impl Environment for FreeSpace {
    fn tip_forces(&mut self, _time_s: f64, _tips: [(DVec3, DVec3); 2]) -> [DVec3; 2] {
        [DVec3::ZERO; 2]
    }
}

impl Reference {
    /// The beat being played at `time_s`: the first whose impact is not yet past.
    pub fn beat_at(&self, time_s: f64) -> Option<usize> {
        self.beats
            .iter()
            .find(|(t, _)| *t >= time_s)
            .or(self.beats.last())
            .map(|&(_, b)| b)
    }
}

/// Follow `reference` with `pipeline` in free space, starting from `initial` at rest, with
/// `gains_scale` multiplying each joint's PD gains (1 = nominal).
pub fn simulate(
    model: &BodyModel,
    reference: &Reference,
    pipeline: Pipeline,
    params: &SimParams,
    initial: &Pose,
    gains_scale: &[f64; JOINT_COUNT],
) -> Result<Motion, SimError> {
    simulate_in(
        &mut FreeSpace,
        model,
        reference,
        pipeline,
        params,
        initial,
        gains_scale,
    )
}

/// Joint targets at the task rate: IK brings both tips to each reference sample, warm
/// started from the captured posture when there is one (so it only corrects what the tips
/// need), else from the previous solution.
pub fn ik_targets(
    model: &BodyModel,
    reference: &Reference,
    params: &SimParams,
    initial: &Pose,
) -> Vec<Pose> {
    let mut pose = *initial;
    (0..reference.tips[0].len())
        .map(|k| {
            let pull = reference.poses.as_ref().map(|p| &p[k]);
            let start = pose;
            pose = *pull.unwrap_or(&start);
            for (h, side) in [Side::Left, Side::Right].into_iter().enumerate() {
                pose = ik::solve(
                    &model.skeleton,
                    &pose,
                    side,
                    reference.tips[h][k],
                    pull.or(Some(&start)),
                    &params.ik,
                )
                .pose;
            }
            pose
        })
        .collect()
}

/// [`simulate`] with the body meeting `environment` (e.g. the drums) every simulation step.
pub fn simulate_in(
    environment: &mut dyn Environment,
    model: &BodyModel,
    reference: &Reference,
    pipeline: Pipeline,
    params: &SimParams,
    initial: &Pose,
    gains_scale: &[f64; JOINT_COUNT],
) -> Result<Motion, SimError> {
    let n = reference.tips[0].len();
    let skeleton = &model.skeleton;
    let substeps = (params.sim_hz / reference.rate_hz).round().max(1.0) as usize;
    let dt = 1.0 / (reference.rate_hz * substeps as f64);
    let mut motion = Motion {
        rate_hz: reference.rate_hz,
        tips: [Vec::with_capacity(n), Vec::with_capacity(n)],
        poses: Vec::with_capacity(n),
    };
    let record = |motion: &mut Motion, pose: &Pose| {
        let frames = skeleton.forward(pose);
        motion.tips[0].push(frames.tip(Side::Left));
        motion.tips[1].push(frames.tip(Side::Right));
        motion.poses.push(*pose);
    };
    // Joint targets at the task rate.
    let targets: Vec<Pose> = match pipeline {
        Pipeline::Id => reference.poses.clone().ok_or_else(|| Diverged {
            time_s: 0.0,
            beat: None,
            what: "cannot run ID without captured joint rotations".into(),
        })?,
        _ => ik_targets(model, reference, params, initial),
    };
    if pipeline == Pipeline::Ik {
        for (k, pose) in targets.iter().enumerate() {
            record(&mut motion, pose);
            if k == 0 {
                continue;
            }
            if !environment.progress(k, n) {
                return Err(SimError::Cancelled);
            }
            // The drums still hear the kinematic sticks, at the simulation rate.
            let (a, b) = (k - 1, k);
            let velocity: [DVec3; 2] = std::array::from_fn(|h| {
                (motion.tips[h][b] - motion.tips[h][a]) * reference.rate_hz
            });
            for s in 0..substeps {
                let u = s as f64 / substeps as f64;
                let tips = std::array::from_fn(|h| {
                    (motion.tips[h][a].lerp(motion.tips[h][b], u), velocity[h])
                });
                environment.tip_forces(a as f64 / reference.rate_hz + s as f64 * dt, tips);
            }
        }
        return Ok(motion);
    }
    let mut dynamics = Dynamics::new(model.clone());
    let mut state = State {
        q: *initial,
        w: [DVec3::ZERO; JOINT_COUNT],
    };
    let gains = Gains::from_effective_inertia(
        &mut dynamics,
        &state,
        &params.frequency_hz,
        params.zeta,
        params.max_torque,
    )
    .scaled(gains_scale);
    let nested = IkParams {
        reference_gain: 1.0,
        ..params.ik.clone()
    };
    // Target joint velocities (over each task interval) and accelerations.
    let velocity = |k: usize| -> [DVec3; JOINT_COUNT] {
        let k = k.clamp(1, n.max(2) - 1);
        std::array::from_fn(|j| {
            rotation_error(targets[k - 1][j], targets[k][j]) * reference.rate_hz
        })
    };
    state.w = velocity(1);
    record(&mut motion, &state.q);
    for k in 1..n {
        if !environment.progress(k, n) {
            return Err(SimError::Cancelled);
        }
        let (from, to) = (&targets[k - 1], &targets[k]);
        let target_w = velocity(k);
        let next_w = velocity(k + 1);
        let qdd: [DVec3; JOINT_COUNT] =
            std::array::from_fn(|j| (next_w[j] - target_w[j]) * reference.rate_hz);
        // Feed-forward inverse dynamics of the target motion, once per task step.
        let bias = dynamics.inverse_dynamics(
            &State {
                q: *from,
                w: target_w,
            },
            &qdd,
        );
        for s in 1..=substeps {
            let u = s as f64 / substeps as f64;
            let time_s = (k - 1) as f64 / reference.rate_hz + (s - 1) as f64 * dt;
            // Normalised lerp: within one 4 ms task interval it matches slerp to ~1e-7 rad.
            let mut goal: Pose = std::array::from_fn(|j| from[j].lerp(to[j], u));
            if pipeline == Pipeline::Himc {
                // IK nested in PD (seed 000 Alg. 2): every step, solve the tips' targets from
                // the simulated pose, Δq = J⁺(X_t − X(q)), with the redundancy pulled toward
                // the task-rate IK posture; PD then tracks that.
                let reference_pose = goal;
                goal = state.q;
                for _ in 0..params.nested_iterations {
                    let frames = skeleton.forward(&goal);
                    for (h, side) in [Side::Left, Side::Right].into_iter().enumerate() {
                        let target = reference.tips[h][k - 1].lerp(reference.tips[h][k], u);
                        ik::iterate(
                            &frames,
                            &mut goal,
                            side,
                            target,
                            Some(&reference_pose),
                            &nested,
                        );
                    }
                }
            }
            let tau = pd_torques(&gains, &state, &goal, &target_w, &bias);
            dynamics.step_with_tip_forces(
                &mut state,
                &tau,
                |tips| environment.tip_forces(time_s, tips),
                dt,
            );
            let speed = state.w.iter().map(|w| w.length()).fold(0.0, f64::max);
            if !state.is_finite() || speed > params.max_angular_speed {
                let time_s = time_s + dt;
                let joint = state
                    .w
                    .iter()
                    .position(|w| !w.is_finite() || w.length() > params.max_angular_speed)
                    .map_or("?", |j| Joint::ALL[j].name());
                return Err(Diverged {
                    time_s,
                    beat: reference.beat_at(time_s),
                    what: format!("diverged ({joint} spinning at {speed:.0} rad/s)"),
                }
                .into());
            }
        }
        record(&mut motion, &state.q);
    }
    Ok(motion)
}

/// RMS distance between two equally long point sequences, m.
pub fn rms_error(a: &[DVec3], b: &[DVec3]) -> f64 {
    let n = a.len().min(b.len()).max(1);
    (a.iter()
        .zip(b)
        .map(|(x, y)| x.distance_squared(*y))
        .sum::<f64>()
        / n as f64)
        .sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::body::skeleton::REST;

    /// A target the body cannot follow without blowing up (a 2 m jump of the tip in one
    /// 4 ms task step with absurd gains) stops with the time and the beat, never NaN.
    #[test]
    fn divergence_names_time_and_beat() {
        let model = BodyModel::default();
        let here = model.skeleton.forward(&REST);
        let hold = |side: Side, far: bool| {
            (0..20)
                .map(|k| {
                    here.tip(side)
                        + if far && k >= 10 {
                            DVec3::new(0.0, 2.0, 0.0)
                        } else {
                            DVec3::ZERO
                        }
                })
                .collect()
        };
        let reference = Reference {
            rate_hz: 250.0,
            tips: [hold(Side::Left, false), hold(Side::Right, true)],
            poses: None,
            beats: vec![(0.02, 3), (0.06, 4)],
        };
        let params = SimParams {
            frequency_hz: [2000.0; JOINT_COUNT],
            max_torque: 1e9,
            ..SimParams::default()
        };
        let err = simulate(
            &model,
            &reference,
            Pipeline::Himc,
            &params,
            &REST,
            &[1.0; JOINT_COUNT],
        )
        .unwrap_err();
        let SimError::Diverged(err) = err else {
            panic!("{err}")
        };
        assert!(err.time_s > 0.0 && err.beat.is_some(), "{err}");
        assert!(err.to_string().contains("during beat"), "{err}");
    }
}
