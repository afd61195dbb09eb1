//! The synthetic performer that builds the shipped motion database. No open timpani
//! capture may be redistributed, so strokes are synthesised in joint space on the body
//! model and turned into stick-tip trajectories by forward kinematics:
//!
//! 1. per stroke, inverse kinematics (DLS with a null-space pull toward a grip-specific
//!    reference posture) gives the **impact pose** (tip on the membrane at the impact
//!    location) and the **top pose** (tip lifted by the stroke height, drawn back toward
//!    the player by the depth travel of the playing mode);
//! 2. each joint moves from impact to impact along a base interpolation plus a lift
//!    profile s(u) — a two-piece cubic Hermite rising from the rebound (slope ρ) to a peak
//!    at phase p and falling to the impact (slope −δ). **Proximal-to-distal timing**
//!    (seed 003 §3.8 and §4.3.4): the shoulder peaks first and arrives gently, the wrist and
//!    stick peak last and arrive fastest, so the stick lags the forearm and whips into the
//!    head; the distal joints also rebound first;
//! 3. stroke-to-stroke variation (timing, height, depth, impact point) comes from a seeded
//!    generator, so the database rebuilds bit for bit;
//! 4. the takes are cut by the same segmentation as real captures.
//!
//! Calibration: the mean vertical tip range of mf strokes is scaled to the published
//! 434 mm (French) and 179 mm (German) grip figures (Bouënard, ENACTIVE 2008); accents
//! rise highest with the least depth travel, vertical accents and staccato travel far more
//! in depth (seed 000 Fig. 6a); heights, and so impact speeds, rise with the dynamic.

use super::db::{self, Index, MotionDb, TakeData, TakeEntry, UnitEntry};
use super::segment::{SegmentParams, segment};
use crate::base::rng::Rng;
use crate::body::ik::{self, IkParams};
use crate::body::skeleton::{JOINT_COUNT, Joint, Pose, REST, Skeleton};
use crate::kit::{Kit, Side};
use crate::score::{Dynamic, Grip, ImpactLocation, PlayingMode};
use glam::{DQuat, DVec3};

/// What to synthesise.
#[derive(Clone, Debug)]
pub struct SynthConfig {
    /// Seed of every random choice.
    pub seed: u64,
    /// Sample rate, Hz.
    pub rate_hz: f64,
    /// Complete strokes per dynamic in each take (each take adds one broken stroke at
    /// either end, dropped by segmentation).
    pub strokes_per_dynamic: usize,
    pub grips: Vec<Grip>,
    pub modes: Vec<PlayingMode>,
    pub locations: Vec<ImpactLocation>,
    pub hands: Vec<Side>,
    pub dynamics: Vec<Dynamic>,
}

impl Default for SynthConfig {
    /// The shipped database: 2 grips × 5 modes × 3 locations × 2 hands × 3 dynamics ×
    /// 8 strokes = 1440 units at 250 Hz.
    fn default() -> Self {
        SynthConfig {
            seed: 2008,
            rate_hz: 250.0,
            strokes_per_dynamic: 8,
            grips: vec![Grip::French, Grip::German],
            modes: PlayingMode::ALL.to_vec(),
            locations: vec![
                ImpactLocation::Centre,
                ImpactLocation::PlayingSpot,
                ImpactLocation::Rim,
            ],
            hands: vec![Side::Left, Side::Right],
            dynamics: vec![Dynamic::P, Dynamic::Mf, Dynamic::F],
        }
    }
}

/// How a playing mode shapes a stroke.
#[derive(Clone, Copy, Debug)]
struct ModeStyle {
    /// Stroke period, s.
    period_s: f64,
    /// Height relative to the grip's nominal height.
    height: f64,
    /// Depth travel toward the player at the top of the stroke, m.
    depth_m: f64,
    /// Scales every joint's rebound slope ρ.
    rebound: f64,
    /// Scales every joint's arrival slope δ.
    arrival: f64,
}

fn style(mode: PlayingMode) -> ModeStyle {
    let s = |period_s, height, depth_m, rebound, arrival| ModeStyle {
        period_s,
        height,
        depth_m,
        rebound,
        arrival,
    };
    match mode {
        PlayingMode::Legato => s(0.75, 0.85, 0.06, 1.0, 1.0),
        PlayingMode::Tenuto => s(0.75, 0.70, 0.04, 0.6, 0.9),
        PlayingMode::Accent => s(0.70, 1.00, 0.0, 1.1, 1.05),
        PlayingMode::VerticalAccent => s(0.80, 0.95, 0.13, 1.1, 1.05),
        PlayingMode::Staccato => s(0.60, 0.75, 0.12, 1.25, 1.0),
    }
}

/// Timing of one joint's lift: peak phase p, rebound slope ρ, arrival slope δ (both ≤ 3
/// keep the Hermite pieces monotone).
#[derive(Clone, Copy, Debug)]
struct JointTiming {
    peak: f64,
    rebound: f64,
    arrival: f64,
}

/// Trunk, shoulder, elbow, wrist, grip: proximal peaks first and arrives gently; distal
/// last and fast.
const TIMING: [JointTiming; 5] = [
    JointTiming {
        peak: 0.45,
        rebound: 0.4,
        arrival: 0.6,
    },
    JointTiming {
        peak: 0.50,
        rebound: 0.6,
        arrival: 1.0,
    },
    JointTiming {
        peak: 0.56,
        rebound: 1.0,
        arrival: 1.8,
    },
    JointTiming {
        peak: 0.63,
        rebound: 1.8,
        arrival: 2.6,
    },
    JointTiming {
        peak: 0.67,
        rebound: 2.3,
        arrival: 3.0,
    },
];

/// Nominal phase of the top pose between two impacts.
const TOP_PHASE: f64 = 0.6;

/// Lift profile: 0 at both impacts, 1 at the peak, slope ρ/p after the first impact and
/// −δ/(1−p) into the second.
fn lift(u: f64, t: JointTiming) -> f64 {
    if u <= t.peak {
        let x = u / t.peak;
        (x * x * x - 2.0 * x * x + x) * t.rebound + (-2.0 * x * x * x + 3.0 * x * x)
    } else {
        let x = (u - t.peak) / (1.0 - t.peak);
        (2.0 * x * x * x - 3.0 * x * x + 1.0) - (x * x * x - x * x) * t.arrival
    }
}

fn smoothstep(u: f64) -> f64 {
    u * u * (3.0 - 2.0 * u)
}

/// A joint rotation as a rotation vector (shortest arc), rad.
fn log(q: DQuat) -> DVec3 {
    let q = if q.w < 0.0 { -q } else { q };
    q.to_scaled_axis()
}

/// The mirror image of a right-side local rotation for the left side (x ↦ −x).
fn mirror(q: DQuat) -> DQuat {
    let v = log(q);
    DQuat::from_scaled_axis(DVec3::new(v.x, -v.y, -v.z))
}

/// The posture each grip returns to: arms forward and bent, sticks forward and down; the
/// German grip turns the palms down.
fn reference_pose(grip: Grip) -> Pose {
    let mut pose = REST;
    pose[Joint::Trunk.index()] = DQuat::from_rotation_x(0.08);
    let twist = match grip {
        Grip::French => 0.0,
        Grip::German => -1.2,
    };
    let right = [
        DQuat::from_rotation_y(-0.25) * DQuat::from_rotation_x(0.55),
        DQuat::from_rotation_x(1.3),
        DQuat::from_rotation_z(twist) * DQuat::from_rotation_x(-0.2),
        DQuat::from_rotation_x(0.9),
    ];
    for (k, q) in right.iter().enumerate() {
        pose[Joint::arm(Side::Right)[k].index()] = *q;
        pose[Joint::arm(Side::Left)[k].index()] = mirror(*q);
    }
    pose
}

/// Grip-specific nominal stroke height (before calibration), m, and arm IK weights
/// (trunk, shoulder, elbow, wrist, grip): the German grip works from the wrist.
fn grip_setup(grip: Grip) -> (f64, [f64; 5]) {
    match grip {
        Grip::French => (0.434, [0.1, 0.5, 0.8, 1.0, 0.8]),
        Grip::German => (0.179, [0.1, 0.3, 0.5, 1.0, 0.5]),
    }
}

/// Height factor of a dynamic.
fn dynamic_height(d: Dynamic) -> f64 {
    0.35 + 0.7 * d.velocity()
}

/// One planned stroke.
#[derive(Clone, Debug)]
struct Stroke {
    time_s: f64,
    dynamic: Dynamic,
    impact: Pose,
    top: Pose,
}

/// One synthesised take with its per-stroke labels.
struct SynthTake {
    data: TakeData,
    /// (impact time, dynamic) of every real stroke.
    strokes: Vec<(f64, Dynamic)>,
}

/// The synthetic performer's skeleton: 1.75 m tall, holding `kit`'s first mallets (the
/// body the shipped database's joint angles belong to).
pub fn performer_skeleton(kit: &Kit) -> Skeleton {
    Skeleton::holding_mallets_of(kit)
}

/// The synthetic performer.
pub struct Performer {
    pub skeleton: Skeleton,
    pub kit: Kit,
    /// Multiplies the nominal height of each grip (set by [`Performer::calibrate`]).
    pub height_scale: [f64; 2],
}

fn grip_index(grip: Grip) -> usize {
    match grip {
        Grip::French => 0,
        Grip::German => 1,
    }
}

impl Performer {
    /// A performer with the default skeleton at the standard kit.
    pub fn new() -> Performer {
        let kit = Kit::standard();
        Performer {
            skeleton: performer_skeleton(&kit),
            kit,
            height_scale: [1.0, 1.0],
        }
    }

    /// The drum each hand plays: the drum in front of that side.
    fn drum_for(&self, hand: Side) -> usize {
        match hand {
            Side::Left => 1,
            Side::Right => 2,
        }
    }

    fn ik(
        &self,
        start: &Pose,
        hand: Side,
        target: DVec3,
        reference: &Pose,
        weights: [f64; 5],
    ) -> Pose {
        let params = IkParams {
            weights,
            use_trunk: false,
            tolerance_m: 2e-5,
            max_iterations: 400,
            reference_gain: 0.05,
            ..IkParams::default()
        };
        ik::solve(
            &self.skeleton,
            start,
            hand,
            target,
            Some(reference),
            &params,
            &crate::body::limits::NO_LIMITS,
        )
        .pose
    }

    /// Synthesise one take: a lead-in stroke, `per_dynamic` strokes at each dynamic, a
    /// closing stroke.
    #[allow(clippy::too_many_arguments)]
    fn take(
        &self,
        rng: &mut Rng,
        grip: Grip,
        mode: PlayingMode,
        location: ImpactLocation,
        hand: Side,
        dynamics: &[Dynamic],
        per_dynamic: usize,
        rate_hz: f64,
    ) -> SynthTake {
        let st = style(mode);
        let (nominal, weights) = grip_setup(grip);
        let height = nominal * self.height_scale[grip_index(grip)];
        let reference = reference_pose(grip);
        let drum = &self.kit.drums[self.drum_for(hand)];
        let toward_player = drum.toward_player().extend(0.0);
        let (radius, angle) = location.polar();
        let mut labels: Vec<Dynamic> = vec![dynamics[0]];
        for d in dynamics {
            labels.extend(std::iter::repeat_n(*d, per_dynamic));
        }
        labels.push(*dynamics.last().expect("at least one dynamic"));
        // Two virtual strokes frame the take so that its first and last real strokes
        // have a preparation and a rebound.
        let mut strokes: Vec<Stroke> = Vec::with_capacity(labels.len() + 2);
        let mut pose = reference;
        let mut t = 0.0;
        for (k, dynamic) in std::iter::once(labels[0])
            .chain(labels.iter().copied())
            .chain(std::iter::once(labels[labels.len() - 1]))
            .enumerate()
        {
            if k > 0 {
                t += st.period_s * (1.0 + 0.015 * rng.normal());
            }
            let jitter = DVec3::new(rng.normal(), rng.normal(), 0.0) * 0.003;
            let point = drum.point_on_head(radius, angle) + jitter;
            let h = height * st.height * dynamic_height(dynamic) * (1.0 + 0.05 * rng.normal());
            let depth = st.depth_m * (0.8 + 0.4 * dynamic.velocity()) * (1.0 + 0.08 * rng.normal());
            pose = self.ik(&pose, hand, point, &reference, weights);
            debug_assert!(
                self.skeleton.tip(&pose, hand).distance(point) < 1e-3,
                "impact at {point} out of reach"
            );
            let top_target = point + toward_player * depth + DVec3::Z * h;
            let top = self.ik(&pose, hand, top_target, &reference, weights);
            strokes.push(Stroke {
                time_s: t,
                dynamic,
                impact: pose,
                top,
            });
        }
        // The idle hand waits above its own drum.
        let other = hand.other();
        let other_drum = &self.kit.drums[self.drum_for(other)];
        let rest_target =
            other_drum.point_on_head(ImpactLocation::PLAYING_SPOT_RADIUS, 0.0) + DVec3::Z * 0.12;
        let idle = self.ik(&reference, other, rest_target, &reference, weights);
        let frames =
            ((strokes[strokes.len() - 1].time_s - 0.5 * st.period_s) * rate_hz).floor() as usize;
        let arm = Joint::arm(hand);
        let animated = [Joint::Trunk, arm[0], arm[1], arm[2], arm[3]];
        let mut poses: Vec<Pose> = Vec::with_capacity(frames);
        let mut k = 1;
        for f in 0..frames {
            let time = f as f64 / rate_hz;
            while k + 1 < strokes.len() && strokes[k].time_s <= time {
                k += 1;
            }
            let (a, b) = (&strokes[k - 1], &strokes[k]);
            let u = ((time - a.time_s) / (b.time_s - a.time_s)).clamp(0.0, 1.0);
            let timing = |j: usize| JointTiming {
                peak: TIMING[j].peak,
                rebound: (TIMING[j].rebound * st.rebound).min(3.0),
                arrival: (TIMING[j].arrival * st.arrival).min(3.0),
            };
            let mut pose = idle;
            for (j, joint) in animated.iter().enumerate() {
                let i = joint.index();
                let base = |w: f64| log(a.impact[i]).lerp(log(b.impact[i]), smoothstep(w));
                let delta = log(b.top[i]) - base(TOP_PHASE);
                pose[i] = DQuat::from_scaled_axis(base(u) + delta * lift(u, timing(j)));
            }
            let sway = 0.01 * lift(u, timing(0));
            pose[Joint::Trunk.index()] =
                reference[Joint::Trunk.index()] * DQuat::from_rotation_x(sway);
            poses.push(pose);
        }
        let tips = [Side::Left, Side::Right].map(|s| {
            poses
                .iter()
                .map(|p| Some(self.skeleton.tip(p, s)))
                .collect()
        });
        SynthTake {
            data: TakeData {
                rate_hz,
                tips,
                joints: Some(poses),
            },
            strokes: strokes[1..strokes.len() - 1]
                .iter()
                .map(|s| (s.time_s, s.dynamic))
                .collect(),
        }
    }

    /// Scale each grip's stroke height so that the mean vertical tip range of mf strokes
    /// matches its published figure (three fixed-point passes, deterministic).
    pub fn calibrate(&mut self, config: &SynthConfig) {
        for _ in 0..3 {
            for grip in [Grip::French, Grip::German] {
                let mut probe = SynthConfig {
                    grips: vec![grip],
                    dynamics: vec![Dynamic::Mf],
                    hands: vec![Side::Right],
                    locations: vec![ImpactLocation::PlayingSpot],
                    strokes_per_dynamic: 4,
                    ..config.clone()
                };
                probe.seed ^= 0xCA11;
                let db = self.database(&probe);
                let ranges: Vec<f64> = db
                    .index
                    .units
                    .iter()
                    .map(|u| vertical_range(&db, u))
                    .collect();
                let mean = ranges.iter().sum::<f64>() / ranges.len().max(1) as f64;
                if mean > 0.0 {
                    self.height_scale[grip_index(grip)] *= grip_setup(grip).0 / mean;
                }
            }
        }
    }

    /// Synthesise and segment every take of `config`.
    pub fn database(&self, config: &SynthConfig) -> MotionDb {
        let root = Rng::new(config.seed);
        let mut index = Index {
            version: db::DB_FORMAT_VERSION,
            description: "SYNTHETIC motion database made by `timpanist mocap synth` (joint-space stroke synthesis on the 11-segment body model, forward kinematics to the stick tips). Not a real capture; see mocap/README.md.".into(),
            joints: db::joint_names(),
            takes: Vec::new(),
            units: Vec::new(),
        };
        let mut takes = Vec::new();
        let mut take_no = 0u64;
        for &grip in &config.grips {
            for &mode in &config.modes {
                for &location in &config.locations {
                    for &hand in &config.hands {
                        take_no += 1;
                        let mut rng = root.fork(take_no);
                        let synth = self.take(
                            &mut rng,
                            grip,
                            mode,
                            location,
                            hand,
                            &config.dynamics,
                            config.strokes_per_dynamic,
                            config.rate_hz,
                        );
                        let seg = segment(
                            synth.data.tip(hand),
                            config.rate_hz,
                            &SegmentParams::default(),
                        );
                        let take = index.takes.len();
                        for span in seg.units {
                            let t = span.impact as f64 / config.rate_hz;
                            let (_, dynamic) = synth
                                .strokes
                                .iter()
                                .min_by(|a, b| (a.0 - t).abs().total_cmp(&(b.0 - t).abs()))
                                .copied()
                                .expect("a take has strokes");
                            index.units.push(UnitEntry {
                                take,
                                start: span.start,
                                impact: span.impact,
                                end: span.end,
                                hand,
                                mode,
                                location,
                                dynamic,
                                grip,
                            });
                        }
                        let name = format!(
                            "{}-{}-{}-{}",
                            format!("{grip:?}").to_lowercase(),
                            mode.name().replace(' ', "-"),
                            location.name().replace(' ', "-"),
                            format!("{hand:?}").to_lowercase()
                        );
                        index.takes.push(TakeEntry {
                            file: format!("takes/{name}.tmot"),
                            frames: synth.data.frames(),
                            rate_hz: config.rate_hz,
                            performer: "synthetic".into(),
                            source: "synthetic".into(),
                            source_sha256: None,
                        });
                        takes.push(synth.data);
                    }
                }
            }
        }
        MotionDb {
            index,
            takes,
            limits: Default::default(),
        }
    }
}

impl Default for Performer {
    fn default() -> Self {
        Performer::new()
    }
}

/// Highest minus lowest tip height of a unit, m.
pub fn vertical_range(db: &MotionDb, u: &UnitEntry) -> f64 {
    let zs = db.unit_tip(u).iter().flatten().map(|p| p.z);
    let (lo, hi) = zs.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), z| {
        (lo.min(z), hi.max(z))
    });
    hi - lo
}

/// Build the calibrated database of `config`.
pub fn synthesize(config: &SynthConfig) -> MotionDb {
    let mut performer = Performer::new();
    performer.calibrate(config);
    performer.database(config)
}

/// Joint count check kept next to the data layout it guards.
const _: () = assert!(JOINT_COUNT == 11);

#[cfg(test)]
mod tests {
    use super::*;

    /// Segmentation finds every synthesised impact of a take to ±1 frame, and each
    /// impact puts the tip on the membrane (within the 2 mm the IK tolerance and the
    /// 250 Hz sampling of a fast stroke allow on the nearest frame, see below).
    #[test]
    fn segmentation_finds_every_synthetic_impact() {
        let performer = Performer::new();
        for (grip, mode) in [
            (Grip::French, PlayingMode::Staccato),
            (Grip::German, PlayingMode::Tenuto),
        ] {
            let mut rng = Rng::new(11);
            let take = performer.take(
                &mut rng,
                grip,
                mode,
                ImpactLocation::Centre,
                Side::Left,
                &[Dynamic::P, Dynamic::F],
                4,
                250.0,
            );
            let seg = segment(take.data.tip(Side::Left), 250.0, &SegmentParams::default());
            assert_eq!(seg.impacts.len(), take.strokes.len(), "{grip:?} {mode:?}");
            for (&found, &(t, _)) in seg.impacts.iter().zip(&take.strokes) {
                assert!(
                    (found as f64 - t * 250.0).abs() <= 1.0,
                    "{found} vs {}",
                    t * 250.0
                );
            }
            let membrane = performer.kit.drums[1].placement.head_height_m;
            let lowest = take
                .data
                .tip(Side::Left)
                .iter()
                .flatten()
                .map(|p| p.z)
                .fold(f64::INFINITY, f64::min);
            assert!(
                lowest > membrane - 1e-3,
                "the tip went {} mm through the head",
                (membrane - lowest) * 1e3
            );
        }
    }

    /// The lift profile is 0 at both impacts, 1 at its peak, within [0, 1] between, and
    /// leaves the first impact upward and reaches the second downward.
    #[test]
    fn lift_profile_shape() {
        let t = TIMING[4];
        assert_eq!(lift(0.0, t), 0.0);
        assert!(lift(1.0, t).abs() < 1e-12);
        assert!((lift(t.peak, t) - 1.0).abs() < 1e-12);
        assert!(
            (0..=1000)
                .map(|i| lift(i as f64 / 1000.0, t))
                .all(|s| (-1e-12..=1.0 + 1e-12).contains(&s))
        );
        assert!(lift(0.001, t) > 0.0 && lift(0.999, t) > 0.0);
        let slope_in = (lift(1.0, t) - lift(0.999, t)) / 0.001;
        assert!(slope_in < -5.0, "arrives fast: {slope_in}");
    }
}
