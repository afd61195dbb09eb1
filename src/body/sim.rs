//! Driving the simulated body along a reference motion with one of the three control
//! pipelines of seed 000 (Fig. 1):
//!
//! * **IK** — kinematic only: each task step, inverse kinematics brings both tips to
//!   their targets; no dynamics.
//! * **ID** — PD inverse dynamics tracking the captured joint rotations (seed 000 eq. 2;
//!   for a composed reference without them, the task-rate IK solution of its tips):
//!   PD on the joint error plus the feed-forward torques of the target motion (gravity,
//!   velocity terms and M·q̈, once per task step).
//! * **HIMC** — hybrid inverse motion control (seed 000 Alg. 2): each task step IK turns
//!   the tip targets into joint targets (its redundancy pulled toward the captured
//!   posture where known); every [`SimParams::nested_every`] simulation steps (4 at
//!   10 kHz: 2.5 kHz, tracking as every step does) damped least squares from the
//!   simulated pose toward the tip targets, Δq = J⁺(X_t − X), gives the PD target (IK
//!   nested in PD), held until the next solve and tracked with the same PD and
//!   feed-forward as ID.
//!
//! Task rate 250 Hz and simulation rate 10 kHz by default (40 sub-steps). The body may
//! step coarser than the drums and the stick–head contact
//! ([`SimParams::contact_substeps`]): the contact then runs its own sub-steps, the tips
//! moving as point masses between the body's steps; and coarser still while it is calm,
//! away from every stroke and hand placement ([`SimParams::calm_substeps`]), its fast PD
//! loops then stepped implicitly (stable PD) so the light sticks no longer set the step.
//! The run stops with an error naming the time if the state becomes non-finite or
//! diverges.

use super::control::{Gains, limit_torques, pd_torque, pd_torques, rotation_error};
use super::dynamics::{Dynamics, Implicit, State, TipResponse};
use super::ik::{self, IkParams};
use super::limits::JointLimits;
use super::model::BodyModel;
use super::skeleton::{JOINT_COUNT, Joint, Pose};
pub use crate::base::choices::{BodyStep, Pipeline};
use crate::base::chunks::SharedChunks;
use crate::kit::Side;
use glam::{DMat3, DQuat, DVec3};
use std::f64::consts::TAU;

/// Simulation settings.
#[derive(Clone, Debug, PartialEq)]
pub struct SimParams {
    /// Physics rate, Hz: the drums and the stick–head contact step at this rate.
    pub sim_hz: f64,
    /// Contact steps per body step: the body's dynamics and PD control step at
    /// `sim_hz / contact_substeps` while the contact and the drums keep `sim_hz`, each
    /// stick tip moving between the body's steps as the body would move it under the
    /// contact's force (its operational-space response, [`TipResponse`]) and the body
    /// feeling the mean force. 1 steps the
    /// body at `sim_hz` too (the reference). The largest divisor of the contact steps per
    /// task interval (`sim_hz` over the task rate) not above it is used.
    pub contact_substeps: usize,
    /// Contact steps per body step while the body is calm — no stroke scored within
    /// [`CALM_MARGIN_S`], no hand placed, no stick on a head — with the PD loops stepped
    /// implicitly there (stable PD, [`Implicit`]: explicit loops of the light sticks
    /// would not stay stable at that step); 0 keeps `contact_substeps` throughout.
    pub calm_substeps: usize,
    /// Natural frequency of each joint's PD loop, Hz.
    pub frequency_hz: [f64; JOINT_COUNT],
    /// Damping ratio of the PD loops.
    pub zeta: f64,
    /// Torque limit of every joint, N·m.
    pub max_torque: f64,
    /// The IK solver (method, damping, weights).
    pub ik: IkParams,
    /// DLS iterations HIMC runs at each nested IK solve.
    pub nested_iterations: usize,
    /// Contact steps (at `sim_hz`) per nested IK solve, at least one body step (its goal
    /// pose held in between): 4 at 10 kHz
    /// solves at 2.5 kHz, which tracks as solving every step does (`timpanist evaluate
    /// --trials 2`: every mode's HIMC error within 0.03 mm) at about half the body's
    /// cost; 1 solves every step.
    pub nested_every: usize,
    /// Angular speed beyond which the simulation counts as diverged, rad/s.
    pub max_angular_speed: f64,
    /// A stick tip farther than this from its target counts as control lost (the arm
    /// flailing, typically at the edge of its reach), m: the demo scores stay within
    /// 0.16 m.
    pub max_tracking_error_m: f64,
    /// Joint limits the body cannot pass (seed 000 Alg. 1 ellipsoids, e.g. from the
    /// motion database: `MotionDb::joint_limits`); none by default. The IK (task rate
    /// and nested) holds its postures within them; the simulator's stops hold the body.
    pub limits: JointLimits,
    /// How many times stiffer than a joint's PD loop its limit stop is.
    pub limit_stiffness: f64,
    /// The IK holds each joint within this fraction of its limit ellipsoid (radius ≤
    /// this), so the joint targets leave room for what the dynamics add — the tracking
    /// error, a released stick's rebound — before the stops act: a stick aimed with its
    /// grip on the ellipsoid meets the stop as soon as it rebounds.
    pub ik_limit_fraction: f64,
}

impl SimParams {
    /// The limits the IK holds its postures within: [`SimParams::limits`] scaled by
    /// [`SimParams::ik_limit_fraction`].
    pub fn ik_limits(&self) -> JointLimits {
        self.limits
            .map(|l| l.map(|l| l.scaled(self.ik_limit_fraction)))
    }
}

impl Default for SimParams {
    fn default() -> Self {
        SimParams {
            sim_hz: 10_000.0,
            contact_substeps: 1,
            calm_substeps: 0,
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
            nested_every: 4,
            max_angular_speed: 500.0,
            max_tracking_error_m: 0.5,
            limits: [None; JOINT_COUNT],
            limit_stiffness: 8.0,
            ik_limit_fraction: 0.9,
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
    /// Where the performer looks per sample (m, performer frame): the neck and head turn
    /// toward it ([`super::gaze::look_at`]); `None` keeps them as the posture has them.
    pub gaze: Option<Vec<DVec3>>,
    /// Per sample, the fraction of each hand's grip control held, [left, right]: 1 firm,
    /// near 0 relaxed. A player lets the stick go around an impact so it rebounds freely
    /// about the fulcrum: the grip's PD and feed-forward scale by it (the arm keeps
    /// aiming). `None` holds both grips firm throughout.
    pub grip: Option<[Vec<f64>; 2]>,
    /// Hands brought to points of their own (a hand resting on a head to damp it); `None`
    /// when the hands only carry the sticks.
    pub hands: Option<HandTargets>,
    /// Per sample, the trunk's turn toward far strokes ([`super::lean::track`]: a world
    /// rotation applied to the upright trunk the IK pulls toward); `None` keeps it upright.
    pub lean: Option<Vec<DQuat>>,
    /// Tip and grip targets between the samples where they change faster than a task
    /// step resolves (around the strokes); `None`: the line between samples everywhere.
    pub fine: Option<FineTargets>,
}

/// Targets [`FineTargets::per_sample`] times per task step over spans of samples. A
/// stroke's strike-through dip lasts 16 ms, four task steps, and the composed tip turns
/// sharply at its impact: drawn through the task samples alone, a stroke played a
/// fraction of a step earlier or later reached up to 5 mm less deep and struck up to 15 %
/// softer or harder, in a cycle of one task step (4 ms), so its force depended on where
/// the beat fell between samples rather than on the stroke.
#[derive(Clone, Debug, PartialEq)]
pub struct FineTargets {
    /// Values per task step.
    pub per_sample: usize,
    /// Per hand [left, right], spans in time order, not overlapping.
    pub spans: [Vec<FineSpan>; 2],
}

/// One span of [`FineTargets`].
#[derive(Clone, Debug, PartialEq)]
pub struct FineSpan {
    /// The task sample of its first value.
    pub first: usize,
    /// Tip targets at task samples `first + j / per_sample`, m.
    pub tips: Vec<DVec3>,
    /// The fraction of the grip's control held at the same times (empty: no grip).
    pub grip: Vec<f64>,
}

impl FineTargets {
    /// Hand `h`'s span covering the task step from sample `k − 1` to `k`, and where in it
    /// (the fractional index of its values) the fraction `u` of that step falls.
    fn locate(&self, h: usize, k: usize, u: f64) -> Option<(&FineSpan, f64)> {
        let from = k.checked_sub(1)?;
        let spans = &self.spans[h];
        let span = &spans[spans.partition_point(|s| s.first <= from).checked_sub(1)?];
        let x = ((from - span.first) as f64 + u) * self.per_sample as f64;
        let last = span.tips.len().checked_sub(1)? as f64;
        (x <= last).then_some((span, x))
    }

    /// Hand `h`'s values over the task step from sample `k − 1` to `k` (past its start),
    /// tips and grip, where a span covers it.
    pub fn step(&self, h: usize, k: usize) -> Option<(&[DVec3], &[f64])> {
        let (span, x) = self.locate(h, k, 1.0)?;
        let end = x as usize + 1;
        let start = end.saturating_sub(self.per_sample);
        Some((
            &span.tips[start..end],
            span.grip.get(start..end).unwrap_or(&[]),
        ))
    }
}

/// Interpolation (by `lerp`) of `points` at fractional index `x`, held at the ends.
pub fn sample_at<T: Copy>(points: &[T], x: f64, lerp: impl Fn(T, T, f64) -> T) -> T {
    let last = points.len() - 1;
    let x = x.clamp(0.0, last as f64);
    let i = (x.floor() as usize).min(last.saturating_sub(1));
    let u = x - i as f64;
    if last == 0 {
        return points[0];
    }
    lerp(points[i], points[i + 1], u)
}

/// A body is calm (see [`SimParams::calm_substeps`]) this long, s, before and after every
/// scored stroke: the compensation moves a stroke's target by at most 35 ms, and its
/// contact and rebound are over well within this.
pub const CALM_MARGIN_S: f64 = 0.08;

/// A PD loop whose ω·dt is below this over a body step is stepped explicitly even in a
/// calm stretch (the 8 Hz loops of trunk, neck and head: 0.02 at 2.5 kHz).
const SLOW_LOOP: f64 = 0.1;

/// Rounds of [`place_hand`] in a task-rate IK solve.
const HAND_SOLVE_ROUNDS: usize = 40;

/// Fastest the trunk's IK target turns, rad/s (90°/s); the arms are solved again about a
/// trunk held to it. The tips' IK also reaches with the trunk, which turned it with every
/// fast excursion of a tip: a stroke's strike-through dip (10–20 ms below the head) at
/// up to 700°/s, a damping hand's reach (whose rounds meet the hand's point and the tip
/// together as soon as its weight leaves 0) 17° in 40 ms. The target's acceleration (up
/// to 2600 rad/s²) asked the feed-forward for the trunk's torque limit and, the face
/// kept on its drum, for the neck's and head's, and the light neck and head, driven for
/// a trunk that could not follow, whipped round at up to 5700°/s. A player's trunk
/// turns into a reach over tenths of a second and stays still through a stroke.
pub const MAX_TRUNK_TURN_RAD_PER_S: f64 = std::f64::consts::FRAC_PI_2;

/// Per sample and hand ([left, right]), where the hand goes (its grip joint, m) and how
/// much of the way: 0 leaves the hand to the stick's task, 1 puts it on its point. While
/// it is above 0 the stick turns about the hand to point its tip at the tip target.
#[derive(Clone, Debug, PartialEq)]
pub struct HandTargets {
    pub weight: [Vec<f64>; 2],
    pub points: [Vec<DVec3>; 2],
}

impl HandTargets {
    /// Hand `h`'s weight and point between samples `k − 1` and `k` (`u` ∈ [0, 1]), when
    /// its weight there is above 0. A sample of weight 0 has no point of its own: next to
    /// one the point is the other sample's.
    pub fn at(&self, h: usize, k: usize, u: f64) -> Option<(f64, DVec3)> {
        let (w, p) = (&self.weight[h], &self.points[h]);
        let (a, b) = (k.saturating_sub(1).min(w.len() - 1), k.min(w.len() - 1));
        let weight = w[a] + (w[b] - w[a]) * u;
        let point = match (w[a] > 0.0, w[b] > 0.0) {
            (true, true) => p[a].lerp(p[b], u),
            (true, false) => p[a],
            _ => p[b],
        };
        (weight > 0.0).then_some((weight, point))
    }
}

/// The `side` arm's IK when its hand also has a point of its own (weight `w`, `point`):
/// `rounds` rounds of a tip step toward `tip` scaled by 1 − w and a hand step (the arm up
/// to the wrist) toward `point` scaled by w, so the arm settles where the two weighted
/// pulls balance (at w = 1 the hand is on its point), then as many steps of the grip alone
/// turning the stick about the hand toward `tip`.
#[allow(clippy::too_many_arguments)]
fn place_hand(
    skeleton: &super::skeleton::Skeleton,
    pose: &mut Pose,
    side: Side,
    (weight, point): (f64, DVec3),
    tip: DVec3,
    reference: Option<&Pose>,
    (params, limits): (&IkParams, &JointLimits),
    rounds: usize,
) {
    let w = weight.min(1.0);
    let grip = Joint::arm(side)[3].index();
    for _ in 0..rounds {
        let frames = skeleton.forward(pose);
        let toward = frames.tip(side).lerp(tip, 1.0 - w);
        ik::iterate_task(
            &frames,
            pose,
            (side, ik::Task::Tip),
            toward,
            reference,
            params,
            limits,
        );
        let frames = skeleton.forward(pose);
        let toward = frames.position[grip].lerp(point, w);
        ik::iterate_task(
            &frames,
            pose,
            (side, ik::Task::Hand),
            toward,
            reference,
            params,
            limits,
        );
    }
    for _ in 0..rounds {
        let frames = skeleton.forward(pose);
        ik::iterate_task(
            &frames,
            pose,
            (side, ik::Task::StickAim),
            tip,
            reference,
            params,
            limits,
        );
    }
}

/// What the body did, at the task rate. The poses (the bulk: 352 bytes a sample) are kept
/// in shared chunks of [`MOTION_CHUNK`] samples: a rendering hands its motion over while
/// the performance that made it goes on, and a clone shares every chunk instead of
/// copying them.
#[derive(Clone, Debug, PartialEq)]
pub struct Motion {
    pub rate_hz: f64,
    /// Tip positions per sample, [left, right], m.
    pub tips: [Vec<DVec3>; 2],
    /// Joint rotations per sample.
    pub poses: SharedChunks<Pose>,
}

/// Samples per shared chunk of a [`Motion`] (4 s at the 250 Hz task rate).
pub const MOTION_CHUNK: usize = 1024;

impl Motion {
    /// `tips` and `poses` (one per sample) at `rate_hz`.
    pub fn new(rate_hz: f64, tips: [Vec<DVec3>; 2], poses: Vec<Pose>) -> Motion {
        Motion {
            rate_hz,
            tips,
            poses: SharedChunks::from_vec(poses, MOTION_CHUNK),
        }
    }
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

/// The mean force on each stick tip over `n` contact steps of `dt_s` from `time_s`, the
/// tips starting at `tips` (position, m; velocity, m/s) and moving between the steps as
/// the body moves them (semi-implicit Euler): a tip pushed on in an earlier contact step
/// accelerates by what the body does anyway plus the body's answer to the force
/// ([`TipResponse`] from `respond`, asked once per tip and body step); one not pushed on
/// keeps its velocity (its free acceleration moves it by micrometres within 0.2 ms).
/// With `n` = 1 it is the environment's force at `tips`. Also says which tips were
/// pressed on in the last contact step (the contact as it stands at the end of the body
/// step).
fn sub_stepped_forces(
    environment: &mut dyn Environment,
    time_s: f64,
    tips: [(DVec3, DVec3); 2],
    (n, dt_s): (usize, f64),
    respond: &mut dyn FnMut(usize) -> TipResponse,
) -> ([DVec3; 2], [bool; 2]) {
    let touching = |forces: &[DVec3; 2]| [forces[0].z > 0.0, forces[1].z > 0.0];
    if n <= 1 {
        let forces = environment.tip_forces(time_s, tips);
        return (forces, touching(&forces));
    }
    let (mut at, mut sum, mut last) = (tips, [DVec3::ZERO; 2], [false; 2]);
    let mut response: [Option<TipResponse>; 2] = [None; 2];
    for i in 0..n {
        let forces = environment.tip_forces(time_s + i as f64 * dt_s, at);
        last = touching(&forces);
        for (h, ((p, v), force)) in at.iter_mut().zip(forces).enumerate() {
            sum[h] += force;
            if i + 1 < n && (force != DVec3::ZERO || response[h].is_some()) {
                let r = *response[h].get_or_insert_with(|| respond(h));
                *v += (r.free + r.mobility * force) * dt_s;
            }
            *p += *v * dt_s;
        }
    }
    (sum.map(|f| f / n as f64), last)
}

/// Empty space: no contact, never cancelled.
pub struct FreeSpace;

impl Environment for FreeSpace {
    fn tip_forces(&mut self, _time_s: f64, _tips: [(DVec3, DVec3); 2]) -> [DVec3; 2] {
        [DVec3::ZERO; 2]
    }
}

impl Reference {
    /// Tip targets alone at `rate_hz`: no poses, beats, gaze, grip, hand targets or lean.
    pub fn following(rate_hz: f64, tips: [Vec<DVec3>; 2]) -> Reference {
        Reference {
            rate_hz,
            tips,
            poses: None,
            beats: Vec::new(),
            gaze: None,
            grip: None,
            hands: None,
            lean: None,
            fine: None,
        }
    }

    /// Hand `h`'s tip target a fraction `u` (0–1) of the way from sample `k − 1` to `k`,
    /// m: from the fine targets where they cover that step, else on the line between the
    /// two samples.
    pub fn tip_between(&self, h: usize, k: usize, u: f64) -> DVec3 {
        match self.fine.as_ref().and_then(|f| f.locate(h, k, u)) {
            Some((span, x)) => sample_at(&span.tips, x, DVec3::lerp),
            None => self.tips[h][k - 1].lerp(self.tips[h][k], u),
        }
    }

    /// The fraction of hand `h`'s grip control held a fraction `u` of the way from sample
    /// `k − 1` to `k` (as [`Self::tip_between`]); `None` without grip targets.
    pub fn grip_between(&self, h: usize, k: usize, u: f64) -> Option<f64> {
        let grip = self.grip.as_ref()?;
        Some(match self.fine.as_ref().and_then(|f| f.locate(h, k, u)) {
            Some((span, x)) if span.grip.len() == span.tips.len() => {
                sample_at(&span.grip, x, |a, b, u| a + (b - a) * u)
            }
            _ => grip[h][k - 1] + (grip[h][k] - grip[h][k - 1]) * u,
        })
    }

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
            pose = ik_target(model, reference, params, k, &pose, initial);
            pose
        })
        .collect()
}

/// How far the arms' redundancy is pulled from the previous IK pose toward the initial
/// posture at each task sample (a share of the way, 0–1). With none, a long fast passage
/// turned the arms through their null space stroke after stroke (720 sixteenths at
/// 120 bpm over four drums: elbows +27° → −68°, wrists 51° → 141° in 75 s), until the
/// flailing arms shook the trunk and head off their targets and 55 of the last 250
/// strokes missed; with 1.5 % the arms hold their posture for any length of score. Every
/// pull changes every stroke a little (the demo scores' compensation and forces move by
/// a few per cent either way: 0.5–1 % put the dynamics ladder's staccato f on the outer
/// drums under its mf); a full pull fights the strokes (15 of those 720 missed).
pub const ARM_POSTURE_PULL: f64 = 0.015;

/// The IK joint target of reference sample `k`, from the previous one (`previous`; the
/// initial pose for sample 0). The redundancy is pulled toward the captured posture when
/// there is one; else toward the previous pose, [`ARM_POSTURE_PULL`] of the way on to
/// `posture` (the initial pose, upright), for the arms, and fully toward `posture` for
/// the trunk, which would otherwise drift through the null space stroke after stroke
/// (53° in 10 s of fast strokes over four drums).
pub fn ik_target(
    model: &BodyModel,
    reference: &Reference,
    params: &SimParams,
    k: usize,
    previous: &Pose,
    posture: &Pose,
) -> Pose {
    let start = *previous;
    let pull = match &reference.poses {
        Some(poses) => poses[k],
        None => {
            let mut pull: Pose =
                std::array::from_fn(|j| start[j].slerp(posture[j], ARM_POSTURE_PULL));
            let trunk = Joint::Trunk.index();
            // No turn is no lean, to the bit: a score whose lean is still zero here plays
            // as one with none (an edit that adds a far stroke later resumes before it).
            pull[trunk] = match reference.lean.as_ref().map(|lean| lean[k]) {
                Some(turn) if turn != DQuat::IDENTITY => (turn * posture[trunk]).normalize(),
                _ => posture[trunk],
            };
            pull
        }
    };
    let mut pose = reference.poses.as_ref().map_or(start, |p| p[k]);
    let limits = params.ik_limits();
    arms_ik(model, reference, k, (&params.ik, &limits), &pull, &mut pose);
    let trunk = Joint::Trunk.index();
    let (turn, most) = (
        start[trunk].angle_between(pose[trunk]),
        MAX_TRUNK_TURN_RAD_PER_S / reference.rate_hz,
    );
    // (A captured posture's trunk is followed as it was.)
    if turn > most && reference.poses.is_none() {
        // The trunk held to its fastest turn, the arms solved again about it.
        pose[trunk] = start[trunk].slerp(pose[trunk], most / turn).normalize();
        let held = IkParams {
            use_trunk: false,
            ..params.ik
        };
        arms_ik(model, reference, k, (&held, &limits), &pull, &mut pose);
    }
    if let Some(gaze) = &reference.gaze {
        let frames = model.skeleton.forward(&pose);
        super::gaze::look_at(&frames, &mut pose, gaze[k]);
    }
    pose
}

/// Both arms' IK of reference sample `k` from `pose`, the redundancy pulled toward `pull`
/// ([`place_hand`] for a hand with a point of its own).
fn arms_ik(
    model: &BodyModel,
    reference: &Reference,
    k: usize,
    (ik, limits): (&IkParams, &JointLimits),
    pull: &Pose,
    pose: &mut Pose,
) {
    for (h, side) in [Side::Left, Side::Right].into_iter().enumerate() {
        *pose = ik::solve(
            &model.skeleton,
            pose,
            side,
            reference.tips[h][k],
            Some(pull),
            ik,
            limits,
        )
        .pose;
        if let Some(hand) = reference.hands.as_ref().and_then(|t| t.at(h, k, 1.0)) {
            place_hand(
                &model.skeleton,
                pose,
                side,
                hand,
                reference.tips[h][k],
                Some(pull),
                (ik, limits),
                HAND_SOLVE_ROUNDS,
            );
        }
    }
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
    let mut sim = Simulator::new(model, reference, pipeline, params, initial, gains_scale)?;
    sim.advance(environment, reference, reference.tips[0].len())?;
    Ok(sim.into_motion())
}

/// Where a [`Simulator`] was: enough to rewind it there (its history is truncated).
#[derive(Clone, Debug, PartialEq)]
pub struct Checkpoint {
    samples: usize,
    state: State,
    touching: [bool; 2],
}

impl Checkpoint {
    /// Task-rate samples recorded at the checkpoint.
    pub fn samples(&self) -> usize {
        self.samples
    }
}

/// A simulation advanced piecewise along a reference, which may change ahead of what has
/// been simulated: rewinding to a [`Checkpoint`] and advancing again gives bit for bit
/// what one run along the changed reference gives, provided the reference is unchanged
/// up to sample `checkpoint.samples()` (the feed-forward looks one task sample ahead).
#[derive(Clone, Debug)]
pub struct Simulator {
    model: BodyModel,
    params: SimParams,
    pipeline: Pipeline,
    /// The nested IK of HIMC: pulled fully toward the task-rate posture.
    nested: IkParams,
    /// The limits the IK holds (`SimParams::ik_limits`).
    ik_limits: JointLimits,
    dynamics: Dynamics,
    gains: Gains,
    /// Contact steps per task interval, and their length, s.
    substeps: usize,
    dt: f64,
    /// Contact steps per body step (a divisor of `substeps`), and while calm (0: never
    /// coarser).
    contact_substeps: usize,
    calm_substeps: usize,
    initial: Pose,
    state: State,
    /// Whether each tip (left, right) felt a contact force in the latest step.
    touching: [bool; 2],
    /// Task-rate joint targets computed so far.
    targets: Vec<Pose>,
    motion: Motion,
}

impl Simulator {
    /// A body at rest in `initial`, to follow references at `reference`'s rate with
    /// `pipeline`, PD gains scaled per joint by `gains_scale` (1 = nominal).
    pub fn new(
        model: &BodyModel,
        reference: &Reference,
        pipeline: Pipeline,
        params: &SimParams,
        initial: &Pose,
        gains_scale: &[f64; JOINT_COUNT],
    ) -> Result<Simulator, SimError> {
        let substeps = (params.sim_hz / reference.rate_hz).round().max(1.0) as usize;
        // The largest divisor of the task interval's steps not above a setting.
        let divisor = |setting: usize| {
            (1..=setting.clamp(1, substeps))
                .rev()
                .find(|n| substeps.is_multiple_of(*n))
                .unwrap_or(1)
        };
        let contact_substeps = divisor(params.contact_substeps);
        let calm_substeps = if params.calm_substeps > contact_substeps {
            divisor(params.calm_substeps)
        } else {
            0
        };
        let mut dynamics = Dynamics::new(model.clone());
        // The body starts within its limits (a stop met at full depth would fling it).
        let initial: &Pose = &std::array::from_fn(|j| {
            params.limits[j].map_or(initial[j], |limit| limit.boundary(initial[j]))
        });
        let state = State {
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
        Ok(Simulator {
            model: model.clone(),
            params: params.clone(),
            pipeline,
            nested: IkParams {
                reference_gain: 1.0,
                ..params.ik.clone()
            },
            ik_limits: params.ik_limits(),
            dynamics,
            gains,
            substeps,
            dt: 1.0 / (reference.rate_hz * substeps as f64),
            contact_substeps,
            calm_substeps,
            initial: *initial,
            state,
            touching: [false; 2],
            targets: Vec::new(),
            motion: Motion::new(reference.rate_hz, [Vec::new(), Vec::new()], Vec::new()),
        })
    }

    /// Task-rate samples recorded so far.
    pub fn samples(&self) -> usize {
        self.motion.poses.len()
    }

    /// What the body did so far.
    pub fn motion(&self) -> &Motion {
        &self.motion
    }

    /// The recorded motion.
    pub fn into_motion(self) -> Motion {
        self.motion
    }

    /// Where the simulation is now.
    pub fn checkpoint(&self) -> Checkpoint {
        Checkpoint {
            samples: self.samples(),
            state: self.state.clone(),
            touching: self.touching,
        }
    }

    /// Go back to `checkpoint` (taken from this simulator, not after a rewind before it).
    pub fn rewind(&mut self, checkpoint: &Checkpoint) {
        let m = checkpoint.samples;
        self.state = checkpoint.state.clone();
        self.touching = checkpoint.touching;
        self.targets.truncate(m + 1);
        for tips in &mut self.motion.tips {
            tips.truncate(m);
        }
        self.motion.poses.truncate(m);
    }

    /// The joint target of sample `k` (computed on first use; `k` ≤ one past the last
    /// computed).
    fn target(&mut self, reference: &Reference, k: usize) -> Pose {
        while self.targets.len() <= k {
            let next = self.targets.len();
            let pose = match (self.pipeline, &reference.poses) {
                (Pipeline::Id, Some(poses)) => poses[next],
                _ => {
                    let previous = self.targets.last().unwrap_or(&self.initial);
                    ik_target(
                        &self.model,
                        reference,
                        &self.params,
                        next,
                        previous,
                        &self.initial,
                    )
                }
            };
            self.targets.push(pose);
        }
        self.targets[k]
    }

    fn record(&mut self, pose: &Pose) {
        let frames = self.model.skeleton.forward(pose);
        self.motion.tips[0].push(frames.tip(Side::Left));
        self.motion.tips[1].push(frames.tip(Side::Right));
        self.motion.poses.push(*pose);
    }

    /// Target joint velocity over the task interval ending at sample `k` (clamped to the
    /// reference), rad/s.
    fn target_velocity(&mut self, reference: &Reference, k: usize) -> [DVec3; JOINT_COUNT] {
        let n = reference.tips[0].len();
        let k = k.clamp(1, n.max(2) - 1);
        let (a, b) = (self.target(reference, k - 1), self.target(reference, k));
        std::array::from_fn(|j| rotation_error(a[j], b[j]) * reference.rate_hz)
    }

    /// Simulate until `until` task-rate samples are recorded (at most the reference's
    /// length), meeting `environment` every simulation step.
    pub fn advance(
        &mut self,
        environment: &mut dyn Environment,
        reference: &Reference,
        until: usize,
    ) -> Result<(), SimError> {
        let n = reference.tips[0].len();
        let until = until.min(n);
        if self.samples() == 0 && until > 0 {
            let first = self.target(reference, 0);
            if self.pipeline == Pipeline::Ik {
                self.record(&first);
            } else {
                self.state.w = self.target_velocity(reference, 1);
                let q = self.state.q;
                self.record(&q);
            }
        }
        for k in self.samples()..until {
            if !environment.progress(k, n) {
                return Err(SimError::Cancelled);
            }
            if self.pipeline == Pipeline::Ik {
                self.kinematic_step(environment, reference, k);
            } else {
                self.dynamic_step(environment, reference, k)?;
            }
        }
        Ok(())
    }

    /// IK: the body takes the joint target of sample `k`; the drums still hear the
    /// kinematic sticks, at the simulation rate.
    fn kinematic_step(
        &mut self,
        environment: &mut dyn Environment,
        reference: &Reference,
        k: usize,
    ) {
        let pose = self.target(reference, k);
        self.record(&pose);
        let (a, b) = (k - 1, k);
        let tips = &self.motion.tips;
        let velocity: [DVec3; 2] =
            std::array::from_fn(|h| (tips[h][b] - tips[h][a]) * reference.rate_hz);
        for s in 0..self.substeps {
            let u = s as f64 / self.substeps as f64;
            let at = std::array::from_fn(|h| (tips[h][a].lerp(tips[h][b], u), velocity[h]));
            environment.tip_forces(a as f64 / reference.rate_hz + s as f64 * self.dt, at);
        }
    }

    /// ID or HIMC: the task interval from sample `k − 1` to `k` at the simulation rate.
    fn dynamic_step(
        &mut self,
        environment: &mut dyn Environment,
        reference: &Reference,
        k: usize,
    ) -> Result<(), SimError> {
        let (from, to) = (self.target(reference, k - 1), self.target(reference, k));
        let target_w = self.target_velocity(reference, k);
        let next_w = self.target_velocity(reference, k + 1);
        // The target's acceleration at the middle of this interval (the velocities over
        // the intervals before and after it, centred), so the feed-forward is not half a
        // task step early.
        let prev_w = self.target_velocity(reference, k.saturating_sub(1).max(1));
        let qdd: [DVec3; JOINT_COUNT] =
            std::array::from_fn(|j| (next_w[j] - prev_w[j]) * (0.5 * reference.rate_hz));
        // Feed-forward inverse dynamics of the target motion, once per task step.
        let bias = self.dynamics.inverse_dynamics(
            &State {
                q: from,
                w: target_w,
            },
            &qdd,
        );
        // The body steps `contact_substeps` contact steps at a time, one at a time while
        // a stick is on a head (as the reference does): a stiff contact stepped coarsely
        // by the body's semi-implicit Euler would leave the tip a little high each step
        // (by dt²·F/m) and strike a few per cent softer.
        let coarse = if self.is_calm(reference, k) {
            self.calm_substeps
        } else {
            self.contact_substeps
        };
        // The nested IK's goal, held between its solves.
        let mut solved: Option<Pose> = None;
        let mut c = 0;
        while c < self.substeps {
            let len = if self.touching.contains(&true) || c + coarse > self.substeps {
                1
            } else {
                coarse
            };
            let dt = self.dt * len as f64;
            // The goal of this step: the targets one contact step past its start, as the
            // reference (one contact step per body step) takes them at the step's end; a
            // coarser step taking them at its end would lead the reference by the
            // difference and strike a few per cent faster.
            let u = (c + 1) as f64 / self.substeps as f64;
            let time_s = (k - 1) as f64 / reference.rate_hz + c as f64 * self.dt;
            // Normalised lerp: within one 4 ms task interval it matches slerp to ~1e-7 rad.
            // (Not needed while the nested IK's goal is held: it is solved on the steps
            // that start at or just after a multiple of `nested_every` contact steps.)
            let held_goal = solved.filter(|_| c % self.params.nested_every.max(1) >= len);
            let mut goal: Pose =
                held_goal.unwrap_or_else(|| std::array::from_fn(|j| from[j].lerp(to[j], u)));
            if held_goal.is_none() && self.pipeline == Pipeline::Himc {
                // IK nested in PD (seed 000 Alg. 2): every `nested_every` steps, solve the
                // tips' targets from the simulated pose, Δq = J⁺(X_t − X(q)), with the
                // redundancy pulled toward the task-rate IK posture; PD then tracks that.
                let reference_pose = goal;
                goal = self.state.q;
                if reference.gaze.is_some() {
                    // The arms' IK leaves the neck and head: they follow the gaze targets.
                    for j in [Joint::Neck, Joint::Head] {
                        goal[j.index()] = reference_pose[j.index()];
                    }
                }
                // A tip on a head is let rebound: its goal does not chase the strike-through
                // target below where the tip is (the arm does not press it into the head).
                let floor: [Option<f64>; 2] = std::array::from_fn(|h| {
                    let side = [Side::Left, Side::Right][h];
                    self.touching[h].then(|| self.model.skeleton.tip(&self.state.q, side).z)
                });
                for _ in 0..self.params.nested_iterations {
                    let frames = self.model.skeleton.forward(&goal);
                    for (h, side) in [Side::Left, Side::Right].into_iter().enumerate() {
                        let mut target = reference.tip_between(h, k, u);
                        if let Some(z) = floor[h] {
                            target.z = target.z.max(z);
                        }
                        match reference.hands.as_ref().and_then(|t| t.at(h, k, u)) {
                            Some(hand) => place_hand(
                                &self.model.skeleton,
                                &mut goal,
                                side,
                                hand,
                                target,
                                Some(&reference_pose),
                                (&self.nested, &self.ik_limits),
                                1,
                            ),
                            None => ik::iterate(
                                &frames,
                                &mut goal,
                                side,
                                target,
                                Some(&reference_pose),
                                &self.nested,
                                &self.ik_limits,
                            ),
                        }
                    }
                }
                solved = Some(goal);
            }
            let held = reference
                .grip_between(0, k, u)
                .zip(reference.grip_between(1, k, u))
                .map(|(left, right)| [left, right]);
            let mut tau = pd_torques(&self.gains, &self.state, &goal, &target_w, &bias);
            if let Some(held) = held {
                for (side, fraction) in [Side::Left, Side::Right].into_iter().zip(held) {
                    if fraction < 1.0 {
                        let j = Joint::arm(side)[3].index();
                        tau[j] = pd_torque(
                            &self.gains,
                            &self.state,
                            j,
                            goal[j],
                            target_w[j],
                            bias[j],
                            fraction,
                        );
                    }
                }
            }
            let implicit = (len > self.contact_substeps)
                .then(|| self.implicit_terms(&mut tau, held, &target_w, dt));
            if self.params.limits.iter().any(Option::is_some) {
                let mut stops = limit_torques(
                    &self.gains,
                    &self.params.limits,
                    &self.state,
                    self.params.limit_stiffness,
                );
                if let Some(held) = held {
                    // A released grip holds the stick loosely: the fingers are open, so
                    // the stick rebounds freely about the fulcrum and has no stop until
                    // the grip is firm again. (A stop scaled with the closing grip found
                    // the stick far outside it, 25–50 ms after the impact, and flung it
                    // back onto the head: 25 re-strikes of 33 on the tempo-change study.)
                    for (side, fraction) in [Side::Left, Side::Right].into_iter().zip(held) {
                        if fraction < 1.0 {
                            stops[Joint::arm(side)[3].index()] = DVec3::ZERO;
                        }
                    }
                }
                for (t, stop) in tau.iter_mut().zip(stops) {
                    if stop != DVec3::ZERO {
                        *t += stop;
                    }
                }
            }
            let contact_dt = self.dt;
            let mut touching = [false; 2];
            self.dynamics.step_with_tip_forces(
                &mut self.state,
                (&tau, implicit.as_ref()),
                |tips, respond| {
                    let forces;
                    (forces, touching) =
                        sub_stepped_forces(environment, time_s, tips, (len, contact_dt), respond);
                    forces
                },
                dt,
            );
            self.touching = touching;
            let max_speed = self.params.max_angular_speed;
            let speed = self.state.w.iter().map(|w| w.length()).fold(0.0, f64::max);
            if !self.state.is_finite() || speed > max_speed {
                let time_s = time_s + dt;
                let joint = self
                    .state
                    .w
                    .iter()
                    .position(|w| !w.is_finite() || w.length() > max_speed)
                    .map_or("?", |j| Joint::ALL[j].name());
                return Err(Diverged {
                    time_s,
                    beat: reference.beat_at(time_s),
                    what: format!("diverged ({joint} spinning at {speed:.0} rad/s)"),
                }
                .into());
            }
            c += len;
        }
        let q = self.state.q;
        self.record(&q);
        self.check_tracking(reference, k)
    }

    /// Whether the task interval ending at sample `k` is calm (see
    /// [`SimParams::calm_substeps`]): coarser body steps are allowed, no stick on a head,
    /// no hand placed at either end and no scored stroke within [`CALM_MARGIN_S`].
    fn is_calm(&self, reference: &Reference, k: usize) -> bool {
        if self.calm_substeps == 0 || self.touching.contains(&true) {
            return false;
        }
        let placed = reference.hands.as_ref().is_some_and(|hands| {
            hands
                .weight
                .iter()
                .any(|w| w.get(k - 1..=k).is_some_and(|w| w.iter().any(|w| *w > 0.0)))
        });
        let (from, to) = (
            (k - 1) as f64 / reference.rate_hz,
            k as f64 / reference.rate_hz,
        );
        let first = reference
            .beats
            .partition_point(|(t, _)| *t < from - CALM_MARGIN_S);
        let near = reference
            .beats
            .get(first)
            .is_some_and(|(t, _)| *t <= to + CALM_MARGIN_S);
        !placed && !near
    }

    /// The PD loops' implicit terms over a body step of `dt` s (see [`Implicit`]):
    /// K = dt·Kd + dt²·Kp per joint, and `tau` less dt·Kp·(w − w_target), what the
    /// stiffness loses as the joint moves over the step (the grips' gains scaled by the
    /// fraction `held` as [`pd_torque`] scales them). A loop slow against the step
    /// (ω·dt below [`SLOW_LOOP`]: the trunk, neck and head) stays explicit, which spares
    /// the articulated pass a full inertia through its joint.
    fn implicit_terms(
        &self,
        tau: &mut [DVec3; JOINT_COUNT],
        held: Option<[f64; 2]>,
        target_w: &[DVec3; JOINT_COUNT],
        dt: f64,
    ) -> Implicit {
        let mut fraction = [1.0; JOINT_COUNT];
        if let Some(held) = held {
            for (side, f) in [Side::Left, Side::Right].into_iter().zip(held) {
                fraction[Joint::arm(side)[3].index()] = f.min(1.0);
            }
        }
        Implicit(std::array::from_fn(|j| {
            if TAU * self.params.frequency_hz[j] * dt < SLOW_LOOP {
                return DMat3::ZERO;
            }
            let (kp, kd) = (
                self.gains.stiffness[j] * fraction[j],
                self.gains.damping[j] * fraction[j].sqrt(),
            );
            tau[j] -= dt * (kp * (self.state.w[j] - target_w[j]));
            kd * dt + kp * (dt * dt)
        }))
    }

    /// Stop when a tip at task sample `k` is farther than the limit from its target.
    fn check_tracking(&self, reference: &Reference, k: usize) -> Result<(), SimError> {
        for (h, side) in ["left", "right"].into_iter().enumerate() {
            let error = self.motion.tips[h][k].distance(reference.tips[h][k]);
            if error > self.params.max_tracking_error_m {
                let time_s = k as f64 / reference.rate_hz;
                return Err(Diverged {
                    time_s,
                    beat: reference.beat_at(time_s),
                    what: format!(
                        "lost control of the {side} stick ({error:.2} m from its target: a \
                         reach the body cannot make, try the other hand, a nearer drum or a \
                         slower tempo)"
                    ),
                }
                .into());
            }
        }
        Ok(())
    }
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

    /// Sampling at a fractional index is linear and clamped.
    #[test]
    fn sampling_is_linear_and_clamped() {
        let pts = [DVec3::ZERO, DVec3::X];
        assert_eq!(
            sample_at(&pts, 0.25, DVec3::lerp),
            DVec3::new(0.25, 0.0, 0.0)
        );
        assert_eq!(sample_at(&pts, -3.0, DVec3::lerp), DVec3::ZERO);
        assert_eq!(sample_at(&pts, 9.0, DVec3::lerp), DVec3::X);
        assert_eq!(sample_at(&[2.0], 0.7, |a, b, u| a + (b - a) * u), 2.0);
    }

    /// Between task samples a tip or grip target comes from the fine targets where a
    /// span covers the step, else from the line between the two samples.
    #[test]
    fn targets_between_samples_come_from_fine_targets_where_given() {
        let line = |h: usize| -> Vec<DVec3> {
            (0..6)
                .map(|k| DVec3::new(k as f64, h as f64, 0.0))
                .collect()
        };
        let mut r = Reference::following(250.0, [line(0), line(1)]);
        r.grip = Some([vec![1.0; 6], vec![1.0; 6]]);
        // Hand 1, samples 2 to 3, four values a step, a notch 5 cm deep between them.
        let notch = [0.0, -0.02, -0.05, -0.02, 0.0];
        let tips = notch
            .iter()
            .enumerate()
            .map(|(j, z)| DVec3::new(2.0 + j as f64 / 4.0, 1.0, *z))
            .collect();
        let grip = vec![1.0, 0.5, 0.02, 0.5, 1.0];
        r.fine = Some(FineTargets {
            per_sample: 4,
            spans: [
                Vec::new(),
                vec![FineSpan {
                    first: 2,
                    tips,
                    grip,
                }],
            ],
        });
        assert_eq!(r.tip_between(1, 3, 0.5), DVec3::new(2.5, 1.0, -0.05));
        let quarter_way = r.tip_between(1, 3, 0.125);
        assert!((quarter_way.z + 0.01).abs() < 1e-12, "{quarter_way}");
        assert_eq!(r.grip_between(1, 3, 0.5), Some(0.02));
        // Past the span, and the other hand: the line.
        assert_eq!(r.tip_between(1, 4, 0.5), DVec3::new(3.5, 1.0, 0.0));
        assert_eq!(r.tip_between(0, 3, 0.5), DVec3::new(2.5, 0.0, 0.0));
        assert_eq!(r.grip_between(0, 3, 0.5), Some(1.0));
        // A step's values: from just past its start to its end.
        let fine = r.fine.as_ref().unwrap();
        let (tips, grip) = fine.step(1, 3).expect("covered");
        assert_eq!(tips.len(), 4);
        assert_eq!(tips[1].z, -0.05);
        assert_eq!(grip, &[0.5, 0.02, 0.5, 1.0]);
        assert!(fine.step(1, 2).is_none() && fine.step(1, 4).is_none());
        assert!(fine.step(0, 3).is_none());
    }

    /// A hand going to a point of its own that the arm reaches only with the trunk
    /// turned: the trunk's target turns no faster than
    /// [`MAX_TRUNK_TURN_RAD_PER_S`] (unheld it turned as soon as the hand's weight left
    /// 0), and the hand still gets to its point.
    #[test]
    fn a_placed_hand_turns_the_trunk_no_faster_than_a_player() {
        let model = BodyModel::default();
        let params = SimParams::default();
        let rate = 250.0;
        let n = (1.5 * rate) as usize;
        let tips = [
            vec![DVec3::new(-0.35, 0.45, 0.95); n],
            vec![DVec3::new(0.35, 0.45, 0.95); n],
        ];
        let initial = ik::posture_reaching(
            &model.skeleton,
            [tips[0][0], tips[1][0]],
            &params.ik_limits(),
        );
        // The left hand to a point in front of the body (unheld, the trunk's target turned
        // 18° at up to 560°/s), its weight rising smoothly from 0 at 0.2 s to 1 at 0.5 s.
        let point = DVec3::new(-0.1, 0.45, 0.85);
        let weight: Vec<f64> = (0..n)
            .map(|k| {
                let u = ((k as f64 / rate - 0.2) / 0.3).clamp(0.0, 1.0);
                u * u * (3.0 - 2.0 * u)
            })
            .collect();
        let mut reference = Reference::following(rate, tips);
        reference.hands = Some(HandTargets {
            weight: [weight, vec![0.0; n]],
            points: [vec![point; n], vec![DVec3::ZERO; n]],
        });
        let targets = ik_targets(&model, &reference, &params, &initial);
        let trunk = Joint::Trunk.index();
        let fastest = targets
            .windows(2)
            .map(|w| w[0][trunk].angle_between(w[1][trunk]) * rate)
            .fold(0.0, f64::max);
        let turned = targets[0][trunk].angle_between(targets[n - 1][trunk]);
        assert!(
            turned > 0.1,
            "the reach needs the trunk: it turned {:.1}°",
            turned.to_degrees()
        );
        assert!(
            fastest <= MAX_TRUNK_TURN_RAD_PER_S * (1.0 + 1e-9),
            "the trunk turned at {:.0}°/s",
            fastest.to_degrees()
        );
        let grip = Joint::arm(Side::Left)[3].index();
        let reached = model.skeleton.forward(&targets[n - 1]).position[grip];
        assert!(
            reached.distance(point) < 0.01,
            "the hand ended {:.3} m from its point",
            reached.distance(point)
        );
    }

    /// The task-rate IK of a long fast passage keeps the arms' posture: 40 s of strokes
    /// (four a second per hand) going round three drums of each side, a loop that turns a
    /// redundant arm a little further through its null space each time (with no pull back
    /// to the posture the elbows and wrists had turned by tens of degrees).
    #[test]
    fn long_passages_keep_the_arms_posture() {
        let model = BodyModel::default();
        let params = SimParams::default();
        let rate = 250.0;
        let spots = [
            [
                DVec3::new(-0.62, 0.30, 0.80),
                DVec3::new(-0.30, 0.55, 0.82),
                DVec3::new(-0.10, 0.45, 0.78),
            ],
            [
                DVec3::new(0.62, 0.30, 0.80),
                DVec3::new(0.10, 0.45, 0.78),
                DVec3::new(0.30, 0.55, 0.82),
            ],
        ];
        // Per hand a stroke every 0.25 s, from one spot to the next, lifted 15 cm between.
        let stroke = (0.25 * rate) as usize;
        let tips: [Vec<DVec3>; 2] = std::array::from_fn(|h| {
            (0..(40.0 * rate) as usize)
                .map(|k| {
                    let (i, u) = (k / stroke, (k % stroke) as f64 / stroke as f64);
                    let (a, b) = (spots[h][i % 3], spots[h][(i + 1) % 3]);
                    let smooth = u * u * (3.0 - 2.0 * u);
                    a.lerp(b, smooth) + DVec3::Z * (0.15 * (std::f64::consts::PI * u).sin())
                })
                .collect()
        });
        let initial = ik::posture_reaching(
            &model.skeleton,
            [tips[0][0], tips[1][0]],
            &params.ik_limits(),
        );
        let reference = Reference::following(rate, tips);
        let targets = ik_targets(&model, &reference, &params, &initial);
        // The same moment of the loop (whole loops apart): after the first seconds, in
        // which the arms settle from the posture the first targets asked, 9 s in and at
        // the end, 30 s later, the arms are where they were.
        let at = |loops: usize| &targets[3 * loops * stroke];
        for side in [Side::Left, Side::Right] {
            for j in Joint::arm(side) {
                let turn = |a: &Pose, b: &Pose| {
                    rotation_error(a[j.index()], b[j.index()])
                        .length()
                        .to_degrees()
                };
                let (settled, drift) = (turn(at(1), at(12)), turn(at(12), at(52)));
                assert!(settled < 8.0, "{j:?} settled {settled:.1}° away");
                assert!(drift < 0.5, "{j:?} turned {drift:.1}° in 30 s");
            }
        }
    }

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
            beats: vec![(0.02, 3), (0.06, 4)],
            ..Reference::following(250.0, [hold(Side::Left, false), hold(Side::Right, true)])
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

    /// A target moving out of reach (the right tip's, to 2 m ahead in 1.6 s) with the
    /// nominal gains: the body cannot follow, and the simulation stops saying control of
    /// a stick was lost, when and during which beat. (At a 0.5 m tracking limit the
    /// divergence check stops it first, as the wrist spins: the task-rate IK of an arm
    /// stretched toward a target out of reach thrashes between solutions at 20–80 rad/s,
    /// with or without the pull to the posture. Renders refuse such reaches beforehand.)
    #[test]
    fn lost_control_is_reported_with_the_beat() {
        let model = BodyModel::default();
        let here = model.skeleton.forward(&REST);
        let tips = |side: Side, far: f64| {
            (0..500)
                .map(|k| here.tip(side) + DVec3::new(0.0, far * (k as f64 / 400.0).min(1.0), 0.0))
                .collect()
        };
        let reference = Reference {
            beats: vec![(1.9, 7)],
            ..Reference::following(250.0, [tips(Side::Left, 0.0), tips(Side::Right, 2.0)])
        };
        let run = |limit: f64| {
            let params = SimParams {
                max_tracking_error_m: limit,
                ..SimParams::default()
            };
            let ones = [1.0; JOINT_COUNT];
            simulate(&model, &reference, Pipeline::Himc, &params, &REST, &ones)
        };
        let Err(SimError::Diverged(err)) = run(0.2) else {
            panic!("no loss of control reported")
        };
        // The right arm stretching drags the trunk, and with it the left stick.
        assert!(err.what.contains("lost control of the"), "{err}");
        assert_eq!(err.beat, Some(7));
        assert!(err.time_s > 0.1, "{err}");
    }

    /// A floor pushing a tip up with 100 N/m per metre below it, recording what it saw.
    struct Floor {
        seen: Vec<(f64, DVec3, DVec3)>,
    }

    impl Environment for Floor {
        fn tip_forces(&mut self, time_s: f64, tips: [(DVec3, DVec3); 2]) -> [DVec3; 2] {
            self.seen.push((time_s, tips[1].0, tips[1].1));
            tips.map(|(p, _)| DVec3::Z * (-100.0 * p.z).max(0.0))
        }
    }

    /// A sub-stepped contact asks the environment at each contact step, the tip moving in
    /// between as the body answers the force (semi-implicit Euler), and gives the body the
    /// mean force; one sub-step is the environment's own answer, asking nothing of the body.
    #[test]
    fn sub_stepped_contact_moves_the_tip_as_the_body_answers() {
        let tip = (DVec3::new(0.0, 0.0, -0.01), DVec3::new(0.0, 0.0, -2.0));
        // A tip of 25 g falling at 9.81 m/s² (its free acceleration).
        let mut asked = 0;
        let mut respond = |_: usize| {
            asked += 1;
            TipResponse {
                free: DVec3::new(0.0, 0.0, -9.81),
                mobility: glam::DMat3::from_diagonal(DVec3::splat(1.0 / 0.025)),
            }
        };
        let mut floor = Floor { seen: Vec::new() };
        let (once, touching) =
            sub_stepped_forces(&mut floor, 1.0, [tip; 2], (1, 1e-4), &mut respond);
        assert_eq!(once[1], DVec3::Z);
        assert_eq!(touching, [true; 2]);
        let mut floor = Floor { seen: Vec::new() };
        let (mean, touching) =
            sub_stepped_forces(&mut floor, 1.0, [tip; 2], (2, 1e-4), &mut respond);
        assert_eq!(touching, [true; 2]);
        assert_eq!(asked, 2, "once per pushed tip");
        let (t, p, v) = floor.seen[1];
        assert_eq!(floor.seen.len(), 2);
        assert!((t - 1.0001).abs() < 1e-12);
        // 1 N on 25 g for 0.1 ms, less gravity: the tip slowed by ~3 mm/s, then moved
        // with that speed.
        let v_next = -2.0 + (1.0 / 0.025 - 9.81) * 1e-4;
        assert!((v.z - v_next).abs() < 1e-12, "{v}");
        assert!((p.z - (-0.01 + v_next * 1e-4)).abs() < 1e-12, "{p}");
        assert!(
            (mean[1].z - 0.5 * (1.0 + 100.0 * -p.z)).abs() < 1e-9,
            "{mean:?}"
        );
    }

    /// Rewinding to a checkpoint and advancing along a reference changed after it gives
    /// bit for bit what one run along the changed reference gives (HIMC).
    #[test]
    fn rewind_then_advance_equals_one_run() {
        let model = BodyModel::default();
        let here = model.skeleton.forward(&REST);
        let path = |late: f64| -> [Vec<DVec3>; 2] {
            std::array::from_fn(|h| {
                let side = [Side::Left, Side::Right][h];
                (0..60)
                    .map(|k| {
                        let t = k as f64 / 250.0;
                        let bend = if k > 30 { late * (t - 0.12) } else { 0.0 };
                        here.tip(side) + DVec3::new(0.0, 0.05 * t, -0.2 * t * t + bend)
                    })
                    .collect()
            })
        };
        let reference = |late| Reference::following(250.0, path(late));
        let params = SimParams::default();
        let (a, b) = (reference(0.0), reference(0.5));
        let ones = [1.0; JOINT_COUNT];
        let mut sim = Simulator::new(&model, &a, Pipeline::Himc, &params, &REST, &ones).unwrap();
        sim.advance(&mut FreeSpace, &a, 30).unwrap();
        let checkpoint = sim.checkpoint();
        sim.advance(&mut FreeSpace, &a, 60).unwrap();
        let first = sim.motion().clone();
        sim.rewind(&checkpoint);
        assert_eq!(sim.samples(), 30);
        sim.advance(&mut FreeSpace, &b, 60).unwrap();
        let once = simulate(&model, &b, Pipeline::Himc, &params, &REST, &ones).unwrap();
        assert_eq!(sim.motion(), &once);
        assert_ne!(first, once, "the change after the checkpoint is followed");
        assert_eq!(first.poses.to_vec_of(0..30), once.poses.to_vec_of(0..30));
    }
}
