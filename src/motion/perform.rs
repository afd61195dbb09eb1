//! The whole path from a score to its two stick-tip trajectories: plan (sticking and
//! motion units), compose, the free hand's damping gestures, then the user's handles;
//! the composition carries the database performer's joint limits for the score's grip.

use super::compose::{ComposeParams, Composition, compose};
use super::handles;
use super::muffle;
use super::plan::{PlanError, PlanParams, plan};
use crate::kit::Kit;
use crate::mocap::db::MotionDb;
use crate::score::Score;

/// Compose `score` on `kit` from `db`.
pub fn trajectories(
    score: &Score,
    kit: &Kit,
    db: &MotionDb,
    plan_params: &PlanParams,
    compose_params: &ComposeParams,
) -> Result<Composition, PlanError> {
    let strokes = plan(score, kit, db, plan_params)?;
    let mut comp = compose(&strokes, db, compose_params);
    muffle::apply(&mut comp, muffle::plan(score, kit, &strokes));
    handles::apply(&mut comp, score);
    comp.limits = db.joint_limits(score.grip);
    Ok(comp)
}
