//! The evaluation of seed 000 §3.3 (Figs. 5–6): captured strokes of each playing mode are
//! followed with each pipeline (IK, ID, HIMC) over several trials with randomised initial
//! posture and gains, and the stick-tip RMS error is reported per mode with its standard
//! deviation across trials.

use crate::base::rng::Rng;
use crate::body::model::BodyModel;
use crate::body::sim::{Motion, Pipeline, Reference, SimError, SimParams, rms_error, simulate};
use crate::body::skeleton::JOINT_COUNT;
use crate::kit::Side;
use crate::mocap::db::{MotionDb, UnitEntry};
use crate::score::{Dynamic, Grip, ImpactLocation, PlayingMode};
use glam::DQuat;
use serde::Serialize;

/// The simulated player of the evaluation: 1.72 m and 69 kg, while the database was
/// captured (synthesised) on a 1.75 m performer — as in seed 000, the virtual character's
/// anthropometry only approximates the performer's, so replaying captured joint angles
/// (ID) misplaces the tips while tracking the tips (HIMC) does not.
pub fn simulated_body() -> BodyModel {
    BodyModel::new(crate::body::skeleton::Skeleton::new(1.72, 0.37), 69.0)
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

/// One playing mode's result.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ModeResult {
    pub mode: String,
    /// Vertical range of the captured tip, m.
    pub amplitude_m: f64,
    pub ik: ErrorStat,
    pub id: ErrorStat,
    pub himc: ErrorStat,
}

/// The whole report, serialised as `{"modes":[…]}`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Report {
    pub modes: Vec<ModeResult>,
}

/// The captured reference of one unit (both tips and the joints, from its take).
pub fn reference_of(db: &MotionDb, unit: &UnitEntry) -> Reference {
    let take = &db.takes[unit.take];
    let range = unit.start..=unit.end;
    let tip = |side: Side| {
        take.tip(side)[range.clone()]
            .iter()
            .map(|p| p.unwrap_or_default())
            .collect()
    };
    Reference {
        rate_hz: take.rate_hz,
        tips: [tip(Side::Left), tip(Side::Right)],
        poses: take.joints.as_ref().map(|j| j[range.clone()].to_vec()),
        beats: vec![((unit.impact - unit.start) as f64 / take.rate_hz, 0)],
        gaze: None,
    }
}

/// The units evaluated for `mode`: French grip, right hand, playing spot, mf.
pub fn units_for(db: &MotionDb, mode: PlayingMode, count: usize) -> Vec<&UnitEntry> {
    db.index
        .units
        .iter()
        .filter(|u| {
            u.mode == mode
                && u.grip == Grip::French
                && u.hand == Side::Right
                && u.location == ImpactLocation::PlayingSpot
                && u.dynamic == Dynamic::Mf
        })
        .take(count)
        .collect()
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
pub fn trial(
    model: &BodyModel,
    reference: &Reference,
    params: &EvalParams,
    rng: &mut Rng,
) -> Result<[Motion; 3], PipelineFailed> {
    let start = reference
        .poses
        .as_ref()
        .map_or(crate::body::skeleton::REST, |p| p[0]);
    let initial: [DQuat; JOINT_COUNT] = std::array::from_fn(|j| {
        let axis =
            glam::DVec3::new(rng.normal(), rng.normal(), rng.normal()).normalize_or(glam::DVec3::X);
        (start[j] * DQuat::from_axis_angle(axis, rng.uniform(0.0, params.posture_deg.to_radians())))
            .normalize()
    });
    let scale: [f64; JOINT_COUNT] =
        std::array::from_fn(|_| rng.uniform(1.0 - params.gain_spread, 1.0 + params.gain_spread));
    let run = |p: Pipeline| {
        simulate(model, reference, p, &params.sim, &initial, &scale).map_err(|source| {
            PipelineFailed {
                pipeline: p.name(),
                source,
            }
        })
    };
    Ok([run(Pipeline::Ik)?, run(Pipeline::Id)?, run(Pipeline::Himc)?])
}

/// Evaluate every playing mode on `db`.
pub fn evaluate(
    db: &MotionDb,
    model: &BodyModel,
    params: &EvalParams,
) -> Result<Report, EvalError> {
    let root = Rng::new(params.seed);
    let mut modes = Vec::new();
    for (m, mode) in PlayingMode::ALL.into_iter().enumerate() {
        let units = units_for(db, mode, params.strokes_per_mode);
        if units.is_empty() {
            continue;
        }
        let references: Vec<Reference> = units.iter().map(|u| reference_of(db, u)).collect();
        let amplitude = references
            .iter()
            .map(|r| {
                let zs = r.tips[1].iter().map(|p| p.z);
                zs.clone().fold(f64::NEG_INFINITY, f64::max) - zs.fold(f64::INFINITY, f64::min)
            })
            .sum::<f64>()
            / references.len() as f64;
        // Per trial, the mean over strokes of each pipeline's tip RMS error.
        let mut per_trial: Vec<[f64; 3]> = Vec::new();
        for t in 0..params.trials {
            let mut rng = root.fork((m * 1000 + t) as u64);
            let mut sums = [0.0; 3];
            for r in &references {
                let motions =
                    trial(model, r, params, &mut rng).map_err(|source| EvalError::Trial {
                        mode: mode.name(),
                        trial: t,
                        source,
                    })?;
                for (p, motion) in motions.iter().enumerate() {
                    sums[p] += rms_error(&motion.tips[1], &r.tips[1]) / references.len() as f64;
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
        modes.push(ModeResult {
            mode: mode.name().to_string(),
            amplitude_m: amplitude,
            ik: stat(0),
            id: stat(1),
            himc: stat(2),
        });
    }
    Ok(Report { modes })
}
