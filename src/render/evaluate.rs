//! The evaluation of seed 000 §3.3 (Figs. 5–6): captured strokes of each playing mode are
//! followed with each pipeline (IK, ID, HIMC) over several trials with randomised initial
//! posture and gains, and the stick-tip RMS error of the playing hand is reported per mode
//! with its standard deviation across trials.
//!
//! **Any database.** Per mode the units nearest to what seed 000 evaluated — right hand,
//! playing spot, mf, French grip — are taken, by the planner's label cost
//! ([`Labels::cost`]); the report says which labels were used and how many units when they
//! are not those. A mode the database lacks is reported as skipped.
//!
//! **Tip-only captures** (no joint angles; often one stick per take, the other tip never
//! seen; any rate — each reference keeps its take's rate, the simulator sub-steps it to
//! 10 kHz): a hand whose tip is missing for the whole unit holds the idle rest point in
//! front of its shoulder ([`idle_rest`]); gaps up to [`EvalParams::max_gap_s`] are
//! filled linearly (at the unit's ends, held); a unit with a longer gap is skipped with the
//! reason. ID needs joint angles to replay: without captured ones, the reference's joint
//! angles are the inverse-kinematics solution of the captured tips on the *capture*
//! skeleton ([`capture_skeleton`], the 1.75 m performer the database describes), solved
//! offline as a motion-capture solver would — so ID still replays a performer's joint
//! angles on a body of other proportions and misplaces the tips, while HIMC tracks the
//! tips themselves, as with captured joints.

use crate::base::rng::Rng;
use crate::body::ik::posture_reaching;
use crate::body::limits::NO_LIMITS;
use crate::body::model::BodyModel;
use crate::body::sim::{
    Motion, Pipeline, Reference, SimError, SimParams, ik_target, ik_targets, rms_error, simulate,
};
use crate::body::skeleton::{JOINT_COUNT, Pose, Skeleton};
use crate::kit::Side;
use crate::mocap::db::{MotionDb, SIDES, UnitEntry, side_index};
use crate::mocap::segment::fill_gaps;
use crate::motion::compose::idle_rest;
use crate::motion::plan::{Labels, side_name};
use crate::score::{Dynamic, Grip, ImpactLocation, PlayingMode};
use glam::{DQuat, DVec3};
use serde::Serialize;

/// The simulated player of the evaluation: 1.72 m and 69 kg, while the database was
/// captured (synthesised) on a 1.75 m performer — as in seed 000, the virtual character's
/// anthropometry only approximates the performer's, so replaying captured joint angles
/// (ID) misplaces the tips while tracking the tips (HIMC) does not.
pub fn simulated_body() -> BodyModel {
    BodyModel::new(Skeleton::new(1.72, 0.37), 69.0)
}

/// Height of the performer the captures describe, m: the shipped database's synthetic
/// performer's (a tip-only capture does not say).
pub const CAPTURE_HEIGHT_M: f64 = crate::body::skeleton::DEFAULT_HEIGHT_M;

/// The performer the captures describe, [`CAPTURE_HEIGHT_M`] tall holding 0.37 m mallets:
/// a tip-only capture's joint angles are solved on this skeleton.
pub fn capture_skeleton() -> Skeleton {
    Skeleton::new(CAPTURE_HEIGHT_M, 0.37)
}

/// How trials are randomised.
#[derive(Clone, Debug, PartialEq)]
pub struct EvalParams {
    pub trials: usize,
    pub seed: u64,
    /// Each joint of the initial posture is turned by up to this much, degrees.
    pub posture_deg: f64,
    /// Each joint's gains are scaled by a factor in 1 ± this.
    pub gain_spread: f64,
    /// Strokes (units) per mode.
    pub strokes_per_mode: usize,
    /// Longest run of missing tip samples filled linearly, s (the segmentation's default);
    /// a unit with a longer one is skipped.
    pub max_gap_s: f64,
    pub sim: SimParams,
}

impl Default for EvalParams {
    fn default() -> Self {
        EvalParams {
            trials: 5,
            seed: 7,
            posture_deg: 2.0,
            gain_spread: 0.1,
            strokes_per_mode: 2,
            max_gap_s: 0.05,
            sim: SimParams::default(),
        }
    }
}

/// Mean tip RMS error and its spread across trials, m.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ErrorStat {
    pub rms_e_m: f64,
    pub rms_sd_m: f64,
}

/// Labels of some of a mode's evaluated units, and how many units had them.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct UsedLabels {
    pub hand: &'static str,
    pub location: String,
    pub dynamic: &'static str,
    pub grip: String,
    pub units: usize,
}

impl UsedLabels {
    /// `labels` in words, no unit counted yet.
    pub fn of(labels: &Labels) -> UsedLabels {
        UsedLabels {
            hand: side_name(labels.hand),
            location: labels.location.name(),
            dynamic: labels.dynamic.nearest_mark(),
            grip: format!("{:?}", labels.grip),
            units: 0,
        }
    }

    /// Whether `other` has the same labels (whatever the counts).
    pub fn same_labels(&self, other: &UsedLabels) -> bool {
        self.describe() == other.describe()
    }

    /// The labels in words, e.g. "right, playing spot, mf, French".
    pub fn describe(&self) -> String {
        format!(
            "{}, {}, {}, {}",
            self.hand, self.location, self.dynamic, self.grip
        )
    }
}

/// Whether every label set is the evaluation's preferred one ([`preferred`]).
fn only_preferred(labels: &[UsedLabels]) -> bool {
    let want = UsedLabels::of(&preferred(PlayingMode::Legato));
    labels.iter().all(|l| l.same_labels(&want))
}

impl ModeResult {
    /// Whether some unit evaluated is not of the preferred labels ([`preferred`]).
    pub fn substituted(&self) -> bool {
        !only_preferred(&self.labels)
    }
}

/// A unit passed over, and why.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SkippedUnit {
    /// Index into the database's units.
    pub unit: usize,
    pub reason: String,
}

/// One playing mode's result.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ModeResult {
    pub mode: String,
    /// Vertical range of the captured tip, m.
    pub amplitude_m: f64,
    pub ik: ErrorStat,
    pub id: ErrorStat,
    pub himc: ErrorStat,
    /// The labels of the units evaluated, with their counts (written only when they are
    /// not all right hand, playing spot, mf, French).
    #[serde(skip_serializing_if = "only_preferred")]
    pub labels: Vec<UsedLabels>,
    /// Whether ID replayed joint angles solved from the captured tips (the units have no
    /// captured joints; written only then).
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub joints_from_ik: bool,
    /// Better-labelled units passed over (written only when there are some).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub skipped_units: Vec<SkippedUnit>,
    /// Captured seconds of the units evaluated (one trial, one pipeline).
    #[serde(skip)]
    pub duration_s: f64,
}

/// A mode not evaluated, and why.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SkippedMode {
    pub mode: String,
    pub reason: String,
}

/// The whole report, serialised as `{"modes":[…]}` (and `"skipped":[…]` when a mode
/// was).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Report {
    pub modes: Vec<ModeResult>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub skipped: Vec<SkippedMode>,
}

/// Why a captured unit cannot be followed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum Unusable {
    /// The tip of `hand` is missing for longer than can be filled.
    #[error(
        "its {hand} tip is missing for {missing_s:.3} s at once (gaps up to {max_gap_s:.3} s are filled)"
    )]
    Gap {
        hand: &'static str,
        missing_s: f64,
        max_gap_s: f64,
    },
    /// The tip of the hand that plays the unit is never seen.
    #[error("the tip of its playing ({hand}) hand is never seen")]
    Unseen { hand: &'static str },
}

/// The captured reference of one unit at its take's rate: both tips (a hand never seen in
/// the unit holds [`idle_rest`]; gaps up to `max_gap_s` filled, longer ones refused) and
/// the joints — captured, else solved by IK on the [`capture_skeleton`].
pub fn captured_reference(
    db: &MotionDb,
    unit: &UnitEntry,
    max_gap_s: f64,
) -> Result<Reference, Unusable> {
    let take = &db.takes[unit.take];
    let max_gap = (max_gap_s * take.rate_hz).round() as usize;
    if take.tip(unit.hand)[unit.start..=unit.end]
        .iter()
        .all(Option::is_none)
    {
        return Err(Unusable::Unseen {
            hand: side_name(unit.hand),
        });
    }
    let track = |side: Side| {
        unit_track(take.tip(side), unit, side, max_gap).map_err(|frames| Unusable::Gap {
            hand: side_name(side),
            missing_s: frames as f64 / take.rate_hz,
            max_gap_s,
        })
    };
    let tips = [track(Side::Left)?, track(Side::Right)?];
    Ok(unit_reference(db, unit, tips))
}

/// [`captured_reference`] that never refuses: every gap is bridged, and a playing hand
/// never seen holds the rest point too.
pub fn reference_of(db: &MotionDb, unit: &UnitEntry) -> Reference {
    let take = &db.takes[unit.take];
    let tips = SIDES.map(|side| {
        unit_track(take.tip(side), unit, side, usize::MAX)
            .expect("with no gap limit every track is filled")
    });
    unit_reference(db, unit, tips)
}

/// The reference of `unit` following `tips` (its frames, at its take's rate) with the
/// take's joints, else those solved from the tips ([`solved_joints`]).
fn unit_reference(db: &MotionDb, unit: &UnitEntry, tips: [Vec<DVec3>; 2]) -> Reference {
    let take = &db.takes[unit.take];
    let poses = match &take.joints {
        Some(joints) => joints[unit.start..=unit.end].to_vec(),
        None => solved_joints(&tips, take.rate_hz),
    };
    Reference {
        poses: Some(poses),
        beats: vec![((unit.impact - unit.start) as f64 / take.rate_hz, 0)],
        ..Reference::following(take.rate_hz, tips)
    }
}

/// One tip of `unit`'s frames from a take's `track`: [`idle_rest`] of `side` when never
/// seen in the unit, else gaps of up to `max_gap` frames filled (linearly inside, using
/// samples just outside the unit too; held at its ends); `Err` gives the frames of a
/// longer gap.
fn unit_track(
    track: &[Option<DVec3>],
    unit: &UnitEntry,
    side: Side,
    max_gap: usize,
) -> Result<Vec<DVec3>, usize> {
    let own = &track[unit.start..=unit.end];
    if own.iter().all(Option::is_none) {
        return Ok(vec![idle_rest(side); own.len()]);
    }
    let from = unit.start.saturating_sub(max_gap.min(unit.start));
    let to = unit.end.saturating_add(max_gap).min(track.len() - 1);
    let filled = fill_gaps(&track[from..=to], max_gap);
    let filled = &filled[unit.start - from..=unit.end - from];
    let longest = longest_gap(filled);
    if longest > max_gap {
        return Err(longest);
    }
    let first = filled.iter().flatten().next().copied();
    let mut held = first.expect("the unit has a sample");
    Ok(filled
        .iter()
        .map(|p| {
            held = p.unwrap_or(held);
            held
        })
        .collect())
}

/// The longest run of missing samples, frames.
fn longest_gap(track: &[Option<DVec3>]) -> usize {
    track
        .split(Option::is_some)
        .map(<[_]>::len)
        .max()
        .unwrap_or(0)
}

/// The joint angles of a tip-only capture: the task-rate IK solution of `tips` on the
/// [`capture_skeleton`] (the simulation's IK, warm-started sample to sample from the
/// posture reaching the first tips), as a capture's solver would give them.
fn solved_joints(tips: &[Vec<DVec3>; 2], rate_hz: f64) -> Vec<Pose> {
    let skeleton = capture_skeleton();
    let start = posture_reaching(&skeleton, [tips[0][0], tips[1][0]], &NO_LIMITS);
    let reference = Reference::following(rate_hz, tips.clone());
    let model = BodyModel::new(skeleton, 70.0);
    ik_targets(&model, &reference, &SimParams::default(), &start)
}

/// What the evaluation asks of a unit of `mode`: what seed 000 evaluated, the right hand
/// at the playing spot, mf, French grip.
pub fn preferred(mode: PlayingMode) -> Labels {
    Labels {
        mode,
        hand: Side::Right,
        location: ImpactLocation::PlayingSpot,
        dynamic: Dynamic::Mf,
        grip: Grip::French,
    }
}

/// The units of `mode`, best first: nearest to [`preferred`] by the planner's label cost,
/// ties in database order; with their indices.
fn ranked(db: &MotionDb, mode: PlayingMode) -> Vec<(usize, &UnitEntry)> {
    let want = preferred(mode);
    let mut units: Vec<(usize, &UnitEntry)> = (db.index.units.iter().enumerate())
        .filter(|(_, u)| u.mode == mode)
        .collect();
    units.sort_by(|a, b| {
        want.cost(a.1)
            .total_cmp(&want.cost(b.1))
            .then(a.0.cmp(&b.0))
    });
    units
}

/// The `count` units evaluated for `mode` (usable or not): the best labelled
/// ([`preferred`], else the nearest).
pub fn units_for(db: &MotionDb, mode: PlayingMode, count: usize) -> Vec<&UnitEntry> {
    ranked(db, mode)
        .into_iter()
        .take(count)
        .map(|(_, u)| u)
        .collect()
}

/// The units evaluated for one mode.
#[derive(Clone, Debug)]
pub struct Selection<'a> {
    /// Each unit's index, entry and captured reference, best labelled first.
    pub units: Vec<(usize, &'a UnitEntry, Reference)>,
    /// Better-labelled units passed over as unusable.
    pub skipped: Vec<SkippedUnit>,
}

/// The first `count` usable units of `mode` in [`units_for`]'s order, with their
/// references (gaps up to `max_gap_s` filled).
pub fn select(db: &MotionDb, mode: PlayingMode, count: usize, max_gap_s: f64) -> Selection<'_> {
    let mut selection = Selection {
        units: Vec::new(),
        skipped: Vec::new(),
    };
    for (index, unit) in ranked(db, mode) {
        if selection.units.len() == count {
            break;
        }
        match captured_reference(db, unit, max_gap_s) {
            Ok(reference) => selection.units.push((index, unit, reference)),
            Err(why) => selection.skipped.push(SkippedUnit {
                unit: index,
                reason: why.to_string(),
            }),
        }
    }
    selection
}

/// A pipeline lost control of a captured stroke.
#[derive(Debug, thiserror::Error)]
#[error("{pipeline}: {source}")]
pub struct PipelineFailed {
    pub pipeline: &'static str,
    #[source]
    pub source: SimError,
}

/// Why the evaluation stopped.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum EvalError {
    /// A pipeline failed on a stroke of `mode` in trial `trial`.
    #[error("{mode} trial {trial}: {source}")]
    Trial {
        mode: &'static str,
        trial: usize,
        #[source]
        source: PipelineFailed,
    },
}

/// Run one trial of every pipeline on `reference`; `Err` names the pipeline that failed.
/// ID starts in the reference's first posture, IK and HIMC in their own first target (the
/// IK of the first tips from it); without captured joints every pipeline starts in the
/// posture reaching the first tips. Each joint is then turned at random by up to
/// `posture_deg` (the same turns for every pipeline).
pub fn trial(
    model: &BodyModel,
    reference: &Reference,
    params: &EvalParams,
    rng: &mut Rng,
) -> Result<[Motion; 3], PipelineFailed> {
    let start = reference.poses.as_ref().map_or_else(
        || {
            posture_reaching(
                &model.skeleton,
                reference.tips.each_ref().map(|t| t[0]),
                &params.sim.ik_limits(),
            )
        },
        |p| p[0],
    );
    let turns: [DQuat; JOINT_COUNT] = std::array::from_fn(|_| {
        let axis = DVec3::new(rng.normal(), rng.normal(), rng.normal()).normalize_or(DVec3::X);
        DQuat::from_axis_angle(axis, rng.uniform(0.0, params.posture_deg.to_radians()))
    });
    let scale: [f64; JOINT_COUNT] =
        std::array::from_fn(|_| rng.uniform(1.0 - params.gain_spread, 1.0 + params.gain_spread));
    // Tip pipelines start on their own first target (the IK of the first tips from the
    // captured posture: on a body of other proportions the captured posture itself puts
    // the tip some 18 mm off, a start no controller of tips would be given); ID replays
    // the captured joints from the captured posture.
    let tip_start = match &reference.poses {
        Some(_) => ik_target(model, reference, &params.sim, 0, &start, &start),
        _ => start,
    };
    let run = |p: Pipeline| {
        let own = if p == Pipeline::Id {
            &start
        } else {
            &tip_start
        };
        let initial: Pose = std::array::from_fn(|j| (own[j] * turns[j]).normalize());
        simulate(model, reference, p, &params.sim, &initial, &scale).map_err(|source| {
            PipelineFailed {
                pipeline: p.name(),
                source,
            }
        })
    };
    Ok([run(Pipeline::Ik)?, run(Pipeline::Id)?, run(Pipeline::Himc)?])
}

/// Evaluate every playing mode `db` has units of; the others are reported as skipped.
pub fn evaluate(
    db: &MotionDb,
    model: &BodyModel,
    params: &EvalParams,
) -> Result<Report, EvalError> {
    let mut report = Report {
        modes: Vec::new(),
        skipped: Vec::new(),
    };
    for (m, mode) in PlayingMode::ALL.into_iter().enumerate() {
        let selection = select(db, mode, params.strokes_per_mode, params.max_gap_s);
        if selection.units.is_empty() {
            report.skipped.push(SkippedMode {
                mode: mode.name().to_string(),
                reason: skip_reason(db, mode, &selection),
            });
            continue;
        }
        report
            .modes
            .push(evaluate_mode(db, model, params, (m, mode), selection)?);
    }
    Ok(report)
}

/// Why no unit of `mode` was evaluated.
fn skip_reason(db: &MotionDb, mode: PlayingMode, selection: &Selection) -> String {
    match selection.skipped.first() {
        None => format!("the database has no {} unit", mode.name()),
        Some(first) => format!(
            "none of its {} units is usable (unit {}: {})",
            db.index.units.iter().filter(|u| u.mode == mode).count(),
            first.unit,
            first.reason
        ),
    }
}

/// The trials of one mode (`m`-th of [`PlayingMode::ALL`]) on its selected units.
fn evaluate_mode(
    db: &MotionDb,
    model: &BodyModel,
    params: &EvalParams,
    (m, mode): (usize, PlayingMode),
    selection: Selection,
) -> Result<ModeResult, EvalError> {
    let root = Rng::new(params.seed);
    let strokes: Vec<(usize, &Reference)> = (selection.units.iter())
        .map(|(_, u, r)| (side_index(u.hand), r))
        .collect();
    let share = 1.0 / strokes.len() as f64;
    let amplitude = strokes
        .iter()
        .map(|(h, r)| {
            let zs = r.tips[*h].iter().map(|p| p.z);
            zs.clone().fold(f64::NEG_INFINITY, f64::max) - zs.fold(f64::INFINITY, f64::min)
        })
        .sum::<f64>()
        * share;
    // Per trial, the mean over strokes of each pipeline's tip RMS error (the playing hand).
    let mut per_trial: Vec<[f64; 3]> = Vec::new();
    for t in 0..params.trials {
        let mut rng = root.fork((m * 1000 + t) as u64);
        let mut sums = [0.0; 3];
        for (h, r) in &strokes {
            let motions = trial(model, r, params, &mut rng).map_err(|source| EvalError::Trial {
                mode: mode.name(),
                trial: t,
                source,
            })?;
            for (p, motion) in motions.iter().enumerate() {
                sums[p] += rms_error(&motion.tips[*h], &r.tips[*h]) * share;
            }
        }
        per_trial.push(sums);
    }
    let stat = |p: usize| {
        let xs: Vec<f64> = per_trial.iter().map(|t| t[p]).collect();
        let mean = xs.iter().sum::<f64>() / xs.len() as f64;
        let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>()
            / xs.len().saturating_sub(1).max(1) as f64;
        ErrorStat {
            rms_e_m: mean,
            rms_sd_m: var.sqrt(),
        }
    };
    Ok(ModeResult {
        mode: mode.name().to_string(),
        amplitude_m: amplitude,
        ik: stat(0),
        id: stat(1),
        himc: stat(2),
        labels: label_counts(&selection),
        joints_from_ik: (selection.units.iter()).any(|(_, u, _)| db.takes[u.take].joints.is_none()),
        duration_s: (selection.units.iter())
            .map(|(_, u, _)| (u.end - u.start) as f64 / db.takes[u.take].rate_hz)
            .sum(),
        skipped_units: selection.skipped,
    })
}

/// The distinct labels of the selected units with how many had each, best first.
fn label_counts(selection: &Selection) -> Vec<UsedLabels> {
    let mut counts: Vec<UsedLabels> = Vec::new();
    for (_, unit, _) in &selection.units {
        let labels = UsedLabels::of(&Labels::of(unit));
        match counts.iter_mut().find(|c| c.same_labels(&labels)) {
            Some(c) => c.units += 1,
            None => counts.push(UsedLabels { units: 1, ..labels }),
        }
    }
    counts
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mocap::db::{TakeData, TakeEntry};

    /// A tip-only take at `rate_hz`: the right tip bobbing in front of the body (a short
    /// gap at frames 20–21 and a long one at 60–79), the left tip never seen.
    fn tip_only(rate_hz: f64) -> MotionDb {
        let n = 120;
        let right = (0..n)
            .map(|f| {
                let t = f as f64 / rate_hz;
                let z = 0.85 + 0.1 * (t * 8.0).cos();
                (!(20..22).contains(&f) && !(60..80).contains(&f))
                    .then_some(DVec3::new(0.3, 0.5, z))
            })
            .collect();
        let mut db = MotionDb::empty("tip-only test");
        db.index.takes.push(TakeEntry {
            file: "t.tmot".into(),
            frames: n,
            rate_hz,
            performer: "test".into(),
            source: "test".into(),
            source_sha256: None,
        });
        db.takes.push(TakeData {
            rate_hz,
            tips: [vec![None; n], right],
            joints: None,
        });
        for (start, impact, end) in [(2, 25, 50), (50, 70, 100)] {
            db.index.units.push(UnitEntry {
                take: 0,
                start,
                impact,
                end,
                hand: Side::Right,
                mode: PlayingMode::Legato,
                location: ImpactLocation::Rim,
                dynamic: Dynamic::F,
                grip: Grip::French,
            });
        }
        db
    }

    /// The unseen hand holds its rest point, a short gap is filled on the line between
    /// its neighbours, the joints are solved on the capture skeleton (its tips on the
    /// targets), and the reference keeps the take's rate.
    #[test]
    fn tip_only_reference() {
        let db = tip_only(120.0);
        let r = captured_reference(&db, &db.index.units[0], 0.05).unwrap();
        assert_eq!(r.rate_hz, 120.0);
        assert_eq!(r.tips[0].len(), 49);
        assert!(r.tips[0].iter().all(|p| *p == idle_rest(Side::Left)));
        let right = &db.takes[0].tips[1];
        let (a, b) = (right[19].unwrap(), right[22].unwrap());
        assert!(r.tips[1][20 - 2].distance(a.lerp(b, 1.0 / 3.0)) < 1e-12);
        let skeleton = capture_skeleton();
        for (pose, tips) in r.poses.as_ref().unwrap().iter().zip(r.tips[1].iter()) {
            assert!(skeleton.tip(pose, Side::Right).distance(*tips) < 1e-3);
        }
    }

    /// A gap longer than `max_gap_s` makes the unit unusable, saying which tip and how
    /// long; the unit with only short gaps is selected and the other reported.
    #[test]
    fn long_gaps_skip_the_unit() {
        let db = tip_only(200.0);
        let err = captured_reference(&db, &db.index.units[1], 0.05).unwrap_err();
        assert_eq!(
            err,
            Unusable::Gap {
                hand: "right",
                missing_s: 0.1,
                max_gap_s: 0.05
            }
        );
        let selection = select(&db, PlayingMode::Legato, 2, 0.05);
        assert_eq!(selection.units.len(), 1);
        assert_eq!(selection.skipped.len(), 1);
        assert!(
            selection.skipped[0]
                .reason
                .contains("right tip is missing for 0.100 s")
        );
    }

    /// A tip-only database of one mode at 100 Hz evaluates without losing control (the
    /// body starting on the first targets), the other modes reported as skipped and the
    /// labels used as not the preferred ones.
    #[test]
    fn tip_only_database_evaluates() {
        let mut db = tip_only(100.0);
        db.index.units.truncate(1);
        let params = EvalParams {
            trials: 1,
            ..EvalParams::default()
        };
        let report = evaluate(&db, &simulated_body(), &params).unwrap();
        assert_eq!(report.modes.len(), 1);
        assert_eq!(report.skipped.len(), 4);
        let m = &report.modes[0];
        assert!(m.joints_from_ik && !only_preferred(&m.labels));
        assert_eq!(m.labels[0].describe(), "right, rim, f, French");
        assert!(m.himc.rms_e_m < m.id.rms_e_m, "{m:?}");
        let json = serde_json::to_string(&report).unwrap();
        assert!(json.contains("\"skipped\"") && json.contains("\"labels\""));
    }

    /// Without poses a trial starts on the first targets: never lost at t = 0.
    #[test]
    fn a_trial_without_poses_starts_on_the_targets() {
        let db = tip_only(250.0);
        let mut reference = captured_reference(&db, &db.index.units[0], 0.05).unwrap();
        reference.poses = None;
        let params = EvalParams::default();
        let motions = trial(&simulated_body(), &reference, &params, &mut Rng::new(1)).unwrap();
        for motion in &motions {
            for h in 0..2 {
                assert!(motion.tips[h][0].distance(reference.tips[h][0]) < 0.05);
            }
        }
    }
}
