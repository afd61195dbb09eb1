//! Planning a performance: the strokes of a score (rolls expanded into their single
//! strokes, hands from the sticking), each with its time, target point on the head, and
//! the motion unit chosen for it from the database — the nearest by playing mode, impact
//! location, dynamic, grip and hand, with a seeded choice among near equals so repeats
//! are not robotic (the same seed gives the same plan).

use super::sticking::{self, Method};
use crate::base::rng::Rng;
use crate::kit::{Kit, Side};
use crate::mocap::db::{MotionDb, UnitEntry};
use crate::score::{Dynamic, Grip, ImpactLocation, PlayingMode, Score};
use glam::DVec3;

/// One stroke to perform.
#[derive(Clone, Debug, PartialEq)]
pub struct PlannedStroke {
    /// The beat it belongs to (a roll's strokes share their beat).
    pub beat: usize,
    /// Its tick (a roll stroke's own tick).
    pub tick: u64,
    pub hand: Side,
    /// Scored time of the impact, s.
    pub time_s: f64,
    /// Where the tip meets the head, m (performer frame).
    pub target: DVec3,
    /// Unit vector pointing from the head centre toward the player (horizontal).
    pub toward_player: DVec3,
    pub drum: usize,
    pub mode: PlayingMode,
    pub dynamic: Dynamic,
    /// Index into the database's units.
    pub unit: usize,
}

/// Planning settings.
#[derive(Clone, Debug, PartialEq)]
pub struct PlanParams {
    /// Seed of the choice among near-equal units.
    pub seed: u64,
    /// Units whose match cost is within this of the best are near equals.
    pub near_equal: f64,
    /// Hand assignment for beats marked Auto.
    pub sticking: Method,
}

impl Default for PlanParams {
    fn default() -> Self {
        PlanParams {
            seed: 1,
            near_equal: 0.15,
            sticking: Method::Optimal,
        }
    }
}

/// How far apart a unit's labels are from what a stroke needs (0 = the same).
fn match_cost(
    u: &UnitEntry,
    mode: PlayingMode,
    location: ImpactLocation,
    dynamic: Dynamic,
    grip: Grip,
    hand: Side,
) -> f64 {
    let (r1, a1) = u.location.polar();
    let (r2, a2) = location.polar();
    let angle = ((a1 - a2 + 540.0).rem_euclid(360.0) - 180.0).abs() / 180.0;
    10.0 * f64::from(u.mode != mode)
        + 3.0 * (r1 - r2).abs()
        + 0.5 * angle
        + 2.0 * (u.dynamic.velocity() - dynamic.velocity()).abs()
        + 5.0 * f64::from(u.grip != grip)
        + 1.0 * f64::from(u.hand != hand)
}

/// Why a score could not be planned.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum PlanError {
    /// There is no stroke to splice from.
    #[error("the motion database has no units")]
    EmptyDatabase,
}

/// The strokes of `score` in time order, each with a motion unit from `db`.
/// Errors if the database is empty.
pub fn plan(
    score: &Score,
    kit: &Kit,
    db: &MotionDb,
    params: &PlanParams,
) -> Result<Vec<PlannedStroke>, PlanError> {
    if db.index.units.is_empty() {
        return Err(PlanError::EmptyDatabase);
    }
    let sides = sticking::assign(score, kit, params.sticking, &sticking::Params::default());
    let tempo = score.tempo_map();
    let mut strokes = Vec::new();
    for (b, (beat, &side)) in score.beats.iter().zip(&sides).enumerate() {
        let drum = &kit.drums[beat.drum];
        let (radius, angle) = beat.location.polar();
        let mut push = |tick: u64, hand: Side| {
            let pinned = score.pins.iter().find(|p| p.tick == tick && p.hand == hand);
            let target = pinned.map_or_else(
                || drum.point_on_head(radius, angle),
                |p| DVec3::from_array(p.point_m),
            );
            strokes.push(PlannedStroke {
                beat: b,
                tick,
                hand,
                time_s: tempo.seconds_at(tick as f64),
                target,
                toward_player: (-drum.centre().truncate())
                    .normalize_or(glam::DVec2::NEG_Y)
                    .extend(0.0),
                drum: beat.drum,
                mode: beat.mode,
                dynamic: beat.dynamic,
                unit: 0,
            });
        };
        match beat.roll {
            None => push(beat.tick, side),
            Some(roll) => {
                let step = u64::from(score.ticks_per_quarter / roll.strokes_per_quarter).max(1);
                let mut hand = side;
                for k in 0..roll.length_ticks.div_ceil(step) {
                    push(beat.tick + k * step, hand);
                    hand = hand.other();
                }
            }
        }
    }
    strokes.sort_by(|a, b| a.time_s.total_cmp(&b.time_s));
    choose_units(&mut strokes, score, db, params);
    Ok(strokes)
}

/// Pick a unit for every stroke: the seeded choice among near equals, avoiding the unit
/// the same hand used last when another is as good.
fn choose_units(strokes: &mut [PlannedStroke], score: &Score, db: &MotionDb, params: &PlanParams) {
    let rng = Rng::new(params.seed);
    let mut last = [usize::MAX; 2];
    for (i, s) in strokes.iter_mut().enumerate() {
        let location = score.beats[s.beat].location;
        let costs: Vec<f64> = db
            .index
            .units
            .iter()
            .map(|u| match_cost(u, s.mode, location, s.dynamic, score.grip, s.hand))
            .collect();
        let best = costs.iter().copied().fold(f64::INFINITY, f64::min);
        let h = crate::mocap::db::side_index(s.hand);
        let mut near: Vec<usize> = (0..costs.len())
            .filter(|&k| costs[k] <= best + params.near_equal)
            .collect();
        if near.len() > 1 {
            near.retain(|&k| k != last[h]);
        }
        let pick = near[(rng.fork(i as u64).next_u64() % near.len() as u64) as usize];
        s.unit = pick;
        last[h] = pick;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::score::LoadedScore;
    use std::path::Path;

    fn demo(name: &str) -> LoadedScore {
        LoadedScore::load(
            &Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("scores")
                .join(name),
        )
        .unwrap()
    }

    fn shipped_db() -> MotionDb {
        MotionDb::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("mocap")).unwrap()
    }

    /// Every stroke gets a unit of its own playing mode, grip and dynamic; rolls expand.
    #[test]
    fn units_match_the_strokes() {
        let db = shipped_db();
        let rolls = demo("roll-exercise.ron");
        let strokes = plan(&rolls.score, &rolls.kit, &db, &PlanParams::default()).unwrap();
        let plain = rolls
            .score
            .beats
            .iter()
            .filter(|b| b.roll.is_none())
            .count();
        assert_eq!(
            strokes.len(),
            plain + 16 + 32,
            "a 2-beat and a 4-beat roll of 32nds"
        );
        let etude = demo("etude-modes.ron");
        for s in plan(&etude.score, &etude.kit, &db, &PlanParams::default()).unwrap() {
            let u = &db.index.units[s.unit];
            assert_eq!((u.mode, u.grip), (s.mode, etude.score.grip));
            assert!((u.dynamic.velocity() - s.dynamic.velocity()).abs() < 0.15);
        }
    }

    /// The same seed gives the same plan; another seed varies the units, not the strokes.
    #[test]
    fn seeded_and_deterministic() {
        let db = shipped_db();
        let s = demo("tempo-change.ron");
        let a = plan(&s.score, &s.kit, &db, &PlanParams::default()).unwrap();
        let b = plan(&s.score, &s.kit, &db, &PlanParams::default()).unwrap();
        assert_eq!(a, b);
        let c = plan(
            &s.score,
            &s.kit,
            &db,
            &PlanParams {
                seed: 99,
                ..PlanParams::default()
            },
        )
        .unwrap();
        assert_ne!(
            a.iter().map(|s| s.unit).collect::<Vec<_>>(),
            c.iter().map(|s| s.unit).collect::<Vec<_>>()
        );
        assert_eq!(
            a.iter().map(|s| s.time_s).collect::<Vec<_>>(),
            c.iter().map(|s| s.time_s).collect::<Vec<_>>()
        );
    }
}
