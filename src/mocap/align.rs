//! Calibration of a capture to the performer frame: the rotation about the vertical and
//! the translation that put a take's impacts on the head of the kit drum they were played
//! on, with the player where the kit expects them.
//!
//! A capture arrives in lab coordinates (z up once the up axis is remapped, metres): the
//! drum can be anywhere and the player can face any way. [`Transform`] maps lab to
//! performer coordinates: first a turn by `yaw` about the vertical through the lab origin,
//! then a translation. It is set by hand ([`Transform::parse`]) or fitted ([`fit`]):
//!
//! * **Height**: the median impact goes to the head height of its drum.
//! * **Place**: the centroid of each hand's impacts goes to its target, the point of the
//!   drum the take's impact location names (centre, playing spot or rim, toward the player).
//! * **Facing**: with two hands on two drums, the line between their centroids is turned
//!   onto the line between the targets (a 2D Procrustes fit). Otherwise the player's side
//!   is read from the strokes themselves, from two horizontal cues: the *approach* (a
//!   stick sloping down from the hand to the head swings its tip down and back toward the
//!   hand just before impact) and the *lift* (the direction from each impact to the top
//!   of the stroke before it). Each cue's mean direction is turned onto the direction the
//!   shipped performer shows at that drum ([`Habits`], measured on the synthetic database
//!   relative to the drum's direction toward the player, for strokes of the take's grip,
//!   mode and impact location: [`HabitBook`]); the cues are weighed by their length (a cue
//!   that hardly moves sideways hardly counts).
//!
//! [`report`] says how well it fits: how far the aligned impacts lie from the head plane
//! and how far each hand's centroid lies from its target.

use super::db::{MotionDb, side_index};
use crate::base::stats::median;
use crate::body::skeleton::Joint;
use crate::kit::{Kit, Side};
use crate::score::{Grip, ImpactLocation, PlayingMode};
use glam::{DQuat, DVec2, DVec3};

/// Lab → performer: `p' = Rz(yaw)·p + translation`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Transform {
    /// Turn about the vertical, radians (counter-clockwise seen from above).
    pub yaw_rad: f64,
    /// Translation after the turn, m.
    pub translation_m: DVec3,
}

impl Transform {
    /// No change.
    pub const IDENTITY: Transform = Transform {
        yaw_rad: 0.0,
        translation_m: DVec3::ZERO,
    };

    /// Parse `"x,y,z,yaw"`: the translation in metres and the turn in degrees.
    pub fn parse(text: &str) -> Result<Transform, String> {
        let parts: Vec<&str> = text.split(',').map(str::trim).collect();
        let numbers: Vec<f64> = parts
            .iter()
            .map(|p| p.parse::<f64>().ok().filter(|x| x.is_finite()))
            .collect::<Option<_>>()
            .ok_or_else(|| format!("\"{text}\" is not four numbers \"x,y,z,yaw\""))?;
        match numbers[..] {
            [x, y, z, yaw] => Ok(Transform {
                yaw_rad: yaw.to_radians(),
                translation_m: DVec3::new(x, y, z),
            }),
            _ => Err(format!(
                "\"{text}\" has {} numbers; expected four: \"x,y,z,yaw\" (metres, degrees)",
                numbers.len()
            )),
        }
    }

    /// The turn as a rotation.
    pub fn rotation(&self) -> DQuat {
        DQuat::from_rotation_z(self.yaw_rad)
    }

    /// A lab point in the performer frame.
    pub fn point(&self, p: DVec3) -> DVec3 {
        self.rotation() * p + self.translation_m
    }

    /// A lab orientation (world from body) in the performer frame.
    pub fn orientation(&self, q: DQuat) -> DQuat {
        (self.rotation() * q).normalize()
    }
}

/// One hand's strokes in one take, in lab coordinates (z up, m).
#[derive(Clone, Debug, PartialEq)]
pub struct HandStrokes {
    pub hand: Side,
    /// The tip at each impact.
    pub impacts: Vec<DVec3>,
    /// Horizontal travel from each impact to the top of the stroke before it (zero where
    /// there is none), m.
    pub lifts: Vec<DVec2>,
    /// Horizontal travel of the tip over the [`APPROACH_S`] before each impact, m.
    pub approaches: Vec<DVec2>,
    /// Where the stick's own frame is known (a rigid body): the horizontal part of the
    /// stick from its grip end to the tip at each impact, m; empty otherwise.
    pub sticks: Vec<DVec2>,
}

/// Span before an impact whose horizontal travel is the approach cue, s.
pub const APPROACH_S: f64 = 0.03;

impl HandStrokes {
    fn centroid(&self) -> DVec3 {
        self.impacts.iter().sum::<DVec3>() / self.impacts.len().max(1) as f64
    }

    /// The mean of each cue, [approach, lift, stick], m.
    fn cues(&self) -> [DVec2; 3] {
        let mean = |v: &[DVec2]| v.iter().sum::<DVec2>() / v.len().max(1) as f64;
        [
            mean(&self.approaches),
            mean(&self.lifts),
            mean(&self.sticks),
        ]
    }
}

/// Where one hand's impacts belong, in the performer frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Target {
    /// Kit drum index.
    pub drum: usize,
    /// The point on the head, m.
    pub point: DVec3,
}

/// How the shipped performer's strokes move sideways: per hand (left, right), the angle
/// from the drum's direction toward the player to the mean approach and lift directions,
/// radians (counter-clockwise seen from above).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Habits {
    pub approach_angle_rad: [f64; 2],
    pub lift_angle_rad: [f64; 2],
    /// The stick's horizontal direction at impact, from grip to tip.
    pub stick_angle_rad: [f64; 2],
}

impl Default for Habits {
    /// Straight back toward the player, both cues.
    fn default() -> Self {
        Habits {
            approach_angle_rad: [0.0; 2],
            lift_angle_rad: [0.0; 2],
            stick_angle_rad: [std::f64::consts::PI; 2],
        }
    }
}

/// Why a take could not be aligned.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum AlignError {
    #[error(
        "no impacts to align: no stick came down onto a head and rebounded; check the length unit (--unit mm|cm|m), which way is up (--up) and which tracks are the sticks (--tips)"
    )]
    NoImpacts,
    #[error(
        "cannot tell which way the player faces: the strokes move straight up and down (mean sideways travel {0:.3} m); give --align \"x,y,z,yaw\""
    )]
    NoFacing(f64),
}

/// Fit the lab → performer transform of one take: `strokes[k]` belong at `targets[k]`.
pub fn fit(
    strokes: &[HandStrokes],
    targets: &[Target],
    kit: &Kit,
    habits: &Habits,
) -> Result<Transform, AlignError> {
    let pairs: Vec<(&HandStrokes, &Target)> = strokes
        .iter()
        .zip(targets)
        .filter(|(s, _)| !s.impacts.is_empty())
        .collect();
    if pairs.is_empty() {
        return Err(AlignError::NoImpacts);
    }
    let yaw = match pairs[..] {
        [(a, ta), (b, tb), ..] if ta.point.truncate().distance(tb.point.truncate()) > 0.2 => {
            let lab = (b.centroid() - a.centroid()).truncate();
            let performer = (tb.point - ta.point).truncate();
            performer.to_angle() - lab.to_angle()
        }
        _ => facing_yaw(&pairs, kit, habits)?,
    };
    let rotation = DQuat::from_rotation_z(yaw);
    let weight = |s: &HandStrokes| s.impacts.len() as f64;
    let total: f64 = pairs.iter().map(|(s, _)| weight(s)).sum();
    let horizontal = pairs
        .iter()
        .map(|(s, t)| (t.point - rotation * s.centroid()).truncate() * weight(s))
        .sum::<DVec2>()
        / total;
    let vertical = median(pairs.iter().flat_map(|(s, t)| {
        let head = kit.drums[t.drum].placement.head_height_m;
        s.impacts.iter().map(move |p| head - p.z)
    }))
    .unwrap_or(0.0);
    Ok(Transform {
        yaw_rad: yaw,
        translation_m: horizontal.extend(vertical),
    })
}

/// The turn that points the strokes' approach and lift where the shipped performer's go:
/// the circular mean of each cue's needed turn, weighed by the cue's length.
fn facing_yaw(
    pairs: &[(&HandStrokes, &Target)],
    kit: &Kit,
    habits: &Habits,
) -> Result<f64, AlignError> {
    let mut sum = DVec2::ZERO;
    let mut travel: f64 = 0.0;
    for (s, t) in pairs {
        let h = side_index(s.hand);
        let toward = kit.drums[t.drum].toward_player();
        let expected = [
            habits.approach_angle_rad[h],
            habits.lift_angle_rad[h],
            habits.stick_angle_rad[h],
        ];
        for (cue, angle) in s.cues().into_iter().zip(expected) {
            let want = DVec2::from_angle(angle).rotate(toward);
            if cue.length() > 0.0 {
                let turn = want.to_angle() - cue.to_angle();
                sum += DVec2::from_angle(turn) * cue.length();
                travel = travel.max(cue.length());
            }
        }
    }
    if travel < 0.01 {
        return Err(AlignError::NoFacing(travel));
    }
    Ok(sum.to_angle())
}

/// How one hand's aligned impacts sit on their drum.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HandFit {
    pub hand: Side,
    pub drum: usize,
    /// Mean and largest distance of the impacts from the head plane, m.
    pub plane_mean_m: f64,
    pub plane_max_m: f64,
    /// Horizontal distance of the impacts' centroid from the target, m.
    pub target_distance_m: f64,
    /// Impacts farther than the drum's radius from its centre (played elsewhere).
    pub off_head: usize,
}

/// How well `transform` puts `strokes` on their `targets`.
pub fn report(
    strokes: &[HandStrokes],
    targets: &[Target],
    kit: &Kit,
    transform: &Transform,
) -> Vec<HandFit> {
    strokes
        .iter()
        .zip(targets)
        .filter(|(s, _)| !s.impacts.is_empty())
        .map(|(s, t)| {
            let drum = &kit.drums[t.drum];
            let aligned: Vec<DVec3> = s.impacts.iter().map(|&p| transform.point(p)).collect();
            let heights: Vec<f64> = aligned
                .iter()
                .map(|p| (p.z - drum.placement.head_height_m).abs())
                .collect();
            let centroid = aligned.iter().sum::<DVec3>() / aligned.len() as f64;
            HandFit {
                hand: s.hand,
                drum: t.drum,
                plane_mean_m: heights.iter().sum::<f64>() / heights.len() as f64,
                plane_max_m: heights.iter().copied().fold(0.0, f64::max),
                target_distance_m: centroid.truncate().distance(t.point.truncate()),
                off_head: aligned
                    .iter()
                    .filter(|p| p.truncate().distance(drum.centre().truncate()) > drum.radius_m())
                    .count(),
            }
        })
        .collect()
}

/// Measure [`Habits`] on strokes already in the performer frame, each with the drum it
/// was played on (the shipped database's units, for instance).
pub fn measure_habits(strokes: &[(HandStrokes, usize)], kit: &Kit) -> Habits {
    let mut sums = [[DVec2::ZERO; 2]; 3];
    for (s, drum) in strokes {
        let toward = kit.drums[*drum].toward_player();
        // Express a cue in the drum's frame: x toward the player.
        let local = |v: DVec2| DVec2::new(v.dot(toward), toward.perp_dot(v));
        for (k, cue) in s.cues().into_iter().enumerate() {
            sums[k][side_index(s.hand)] += local(cue) * s.impacts.len() as f64;
        }
    }
    let angles = |v: [DVec2; 2]| v.map(|v| if v == DVec2::ZERO { 0.0 } else { v.to_angle() });
    Habits {
        approach_angle_rad: angles(sums[0]),
        lift_angle_rad: angles(sums[1]),
        stick_angle_rad: angles(sums[2]),
    }
}

/// The [`Habits`] of a performer for each kind of stroke (playing mode and impact
/// location), and over all strokes.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct HabitBook {
    pub overall: Habits,
    /// Per kind of stroke.
    pub by_kind: Vec<(StrokeKind, Habits)>,
}

/// A kind of stroke: grip, playing mode and the impact location's name.
pub type StrokeKind = (Grip, PlayingMode, String);

impl HabitBook {
    /// The habits of strokes of `mode` at `location` with `grip`: that kind's, else the
    /// grip and mode's at any location, else the overall ones.
    pub fn for_stroke(&self, grip: Grip, mode: PlayingMode, location: ImpactLocation) -> Habits {
        let name = location.name();
        self.by_kind
            .iter()
            .find(|((g, m, l), _)| *g == grip && *m == mode && *l == name)
            .or_else(|| {
                self.by_kind
                    .iter()
                    .find(|((g, m, _), _)| *g == grip && *m == mode)
            })
            .map_or(self.overall, |(_, h)| *h)
    }
}

/// The [`HabitBook`] of the performer in a database already in the performer frame: each
/// unit's approach and lift, and where the take has joints its stick at impact (forward
/// kinematics on the synthetic performer's skeleton: 1.75 m, the kit's first mallet), on
/// the drum nearest its impact.
pub fn habits_of(db: &MotionDb, kit: &Kit) -> HabitBook {
    let skeleton = super::synth::performer_skeleton(kit);
    let mut groups: Vec<(StrokeKind, Vec<(HandStrokes, usize)>)> = Vec::new();
    for u in &db.index.units {
        let Some(data) = db.takes.get(u.take) else {
            continue;
        };
        let mut strokes = strokes_of(data.tip(u.hand), data.rate_hz, &[u.start, u.impact], u.hand);
        let Some(impact) = strokes.impacts.last().copied() else {
            continue;
        };
        if let Some(pose) = data.joints.as_ref().and_then(|j| j.get(u.impact)) {
            let frames = skeleton.forward(pose);
            let grip = frames.position[Joint::arm(u.hand)[3].index()];
            strokes.sticks.push((frames.tip(u.hand) - grip).truncate());
        }
        let Some(drum) = kit.nearest_drum(impact, None) else {
            continue;
        };
        let key = (u.grip, u.mode, u.location.name());
        match groups.iter_mut().find(|(k, _)| *k == key) {
            Some((_, g)) => g.push((strokes, drum)),
            None => groups.push((key, vec![(strokes, drum)])),
        }
    }
    let all: Vec<(HandStrokes, usize)> = groups.iter().flat_map(|(_, g)| g.clone()).collect();
    HabitBook {
        overall: measure_habits(&all, kit),
        by_kind: groups
            .iter()
            .map(|(k, g)| (k.clone(), measure_habits(g, kit)))
            .collect(),
    }
}

/// The strokes of a tip sampled at `rate_hz` whose impacts are at `frames`: the tip at
/// each impact (the first one only bounds the lift of the second and is not included),
/// the lift since the previous impact and the approach over [`APPROACH_S`].
pub fn strokes_of(
    tip: &[Option<DVec3>],
    rate_hz: f64,
    frames: &[usize],
    hand: Side,
) -> HandStrokes {
    let back = ((APPROACH_S * rate_hz).round() as usize).max(1);
    let mut out = HandStrokes {
        hand,
        impacts: Vec::new(),
        lifts: Vec::new(),
        approaches: Vec::new(),
        sticks: Vec::new(),
    };
    for (k, &i) in frames.iter().enumerate().skip(1) {
        let Some(at) = tip.get(i).copied().flatten() else {
            continue;
        };
        let top = tip
            .get(frames[k - 1]..i)
            .unwrap_or_default()
            .iter()
            .flatten()
            .max_by(|a, b| a.z.total_cmp(&b.z));
        let before = i
            .checked_sub(back)
            .and_then(|b| tip.get(b).copied().flatten());
        out.impacts.push(at);
        out.lifts
            .push(top.map_or(DVec2::ZERO, |t| (*t - at).truncate()));
        out.approaches
            .push(before.map_or(DVec2::ZERO, |b| (at - b).truncate()));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn kit() -> Kit {
        Kit::standard()
    }

    /// Strokes on `drum` at its playing spot in the performer frame, approaching and
    /// lifting as `habits` say, then carried into a lab by the inverse of `lab` (the
    /// transform to recover).
    fn strokes_on(
        kit: &Kit,
        hand: Side,
        drum: usize,
        habits: &Habits,
        lab: &Transform,
    ) -> HandStrokes {
        let h = side_index(hand);
        let target = kit.drums[drum].point_on_head(2.0 / 3.0, 0.0);
        let toward = kit.drums[drum].toward_player();
        let turn_back = DQuat::from_rotation_z(-lab.yaw_rad);
        let cue = |angle: f64, length: f64| {
            (turn_back * (DVec2::from_angle(angle).rotate(toward) * length).extend(0.0)).truncate()
        };
        let impacts: Vec<DVec3> = (0..8)
            .map(|k| target + DVec3::new(0.01 * (k % 3) as f64, -0.01 * (k % 2) as f64, 0.0))
            .map(|p| turn_back * (p - lab.translation_m))
            .collect();
        HandStrokes {
            hand,
            lifts: vec![cue(habits.lift_angle_rad[h], 0.08); impacts.len()],
            approaches: vec![cue(habits.approach_angle_rad[h], 0.04); impacts.len()],
            sticks: Vec::new(),
            impacts,
        }
    }

    #[test]
    fn parses_a_hand_given_transform() {
        let t = Transform::parse("1.5, -0.2, 0.03, 90").unwrap();
        assert!((t.point(DVec3::X) - DVec3::new(1.5, 0.8, 0.03)).length() < 1e-12);
        assert!(Transform::parse("1,2,3").unwrap_err().contains("four"));
        assert!(
            Transform::parse("1,2,x,4")
                .unwrap_err()
                .contains("not four numbers")
        );
    }

    /// One hand on one drum: the facing comes from the approach and lift directions, and
    /// the fit recovers the lab transform.
    #[test]
    fn one_hand_is_aligned_by_its_lifts() {
        let kit = kit();
        let truth = Transform {
            yaw_rad: 0.65,
            translation_m: DVec3::new(-1.2, 2.4, -0.04),
        };
        let habits = Habits {
            approach_angle_rad: [-0.1, 0.25],
            lift_angle_rad: [0.3, -0.2],
            stick_angle_rad: [2.9, -2.8],
        };
        let s = strokes_on(&kit, Side::Right, 2, &habits, &truth);
        let target = Target {
            drum: 2,
            point: kit.drums[2].point_on_head(2.0 / 3.0, 0.0),
        };
        let fitted = fit(std::slice::from_ref(&s), &[target], &kit, &habits).unwrap();
        assert!((fitted.yaw_rad - truth.yaw_rad).abs() < 1e-6, "{fitted:?}");
        let fits = report(&[s], &[target], &kit, &fitted);
        assert!(
            fits[0].plane_max_m < 1e-9 && fits[0].target_distance_m < 0.01,
            "{fits:?}"
        );
        assert_eq!(fits[0].off_head, 0);
    }

    /// Two hands on two drums: the centroids give the facing.
    #[test]
    fn two_drums_give_the_facing() {
        let kit = kit();
        let truth = Transform {
            yaw_rad: -2.1,
            translation_m: DVec3::new(0.4, 0.9, 0.1),
        };
        let left = strokes_on(&kit, Side::Left, 1, &Habits::default(), &truth);
        let right = strokes_on(&kit, Side::Right, 2, &Habits::default(), &truth);
        let targets = [1, 2].map(|d| Target {
            drum: d,
            point: kit.drums[d].point_on_head(2.0 / 3.0, 0.0),
        });
        let fitted = fit(&[left, right], &targets, &kit, &Habits::default()).unwrap();
        let wrapped = (fitted.yaw_rad - truth.yaw_rad + std::f64::consts::PI)
            .rem_euclid(std::f64::consts::TAU)
            - std::f64::consts::PI;
        assert!(wrapped.abs() < 1e-6, "{fitted:?}");
    }

    /// Strokes without sideways travel cannot tell the facing.
    #[test]
    fn straight_strokes_are_refused() {
        let kit = kit();
        let s = HandStrokes {
            hand: Side::Left,
            impacts: vec![DVec3::new(1.0, 1.0, 0.7); 4],
            lifts: vec![DVec2::ZERO; 4],
            approaches: vec![DVec2::new(0.001, 0.0); 4],
            sticks: Vec::new(),
        };
        let target = Target {
            drum: 1,
            point: kit.drums[1].centre(),
        };
        assert!(matches!(
            fit(&[s], &[target], &kit, &Habits::default()),
            Err(AlignError::NoFacing(_))
        ));
        assert_eq!(
            fit(&[], &[], &kit, &Habits::default()),
            Err(AlignError::NoImpacts)
        );
    }
}
