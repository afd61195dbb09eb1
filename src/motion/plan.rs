//! Planning a performance: the strokes of a score (rolls expanded into their single
//! strokes, hands from the sticking), each with its time, target point on the head, and
//! the motion unit chosen for it from the database — the nearest by playing mode, impact
//! location, dynamic, grip and hand, with a seeded choice among near equals so repeats
//! are not robotic (the same seed gives the same plan).
//!
//! A database need not hold every label (real captures often have one hand, a few modes,
//! one dynamic): the nearest unit is taken all the same, and [`substitutions`] lists the
//! beats whose unit is of another mode, hand, location, dynamic or grip than asked, for
//! the user to be told.

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

/// What a motion unit is labelled with, or what a stroke asks of one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Labels {
    pub mode: PlayingMode,
    pub hand: Side,
    pub location: ImpactLocation,
    pub dynamic: Dynamic,
    pub grip: Grip,
}

impl Labels {
    /// The labels of unit `u`.
    pub fn of(u: &UnitEntry) -> Labels {
        Labels {
            mode: u.mode,
            hand: u.hand,
            location: u.location,
            dynamic: u.dynamic,
            grip: u.grip,
        }
    }

    /// How far apart unit `u`'s labels are from these (0 = the same): a mode costs 10, a
    /// grip 5, a hand 1, the radius 3 per head radius, the angle 0.5 per half turn, the
    /// dynamic 2 per unit of velocity.
    pub fn cost(&self, u: &UnitEntry) -> f64 {
        let (r1, a1) = u.location.polar();
        let (r2, a2) = self.location.polar();
        let angle = (turn_remainder(a1 - a2 + 540.0) - 180.0).abs() / 180.0;
        10.0 * f64::from(u.mode != self.mode)
            + 3.0 * (r1 - r2).abs()
            + 0.5 * angle
            + 2.0 * (u.dynamic.velocity() - self.dynamic.velocity()).abs()
            + 5.0 * f64::from(u.grip != self.grip)
            + 1.0 * f64::from(u.hand != self.hand)
    }

    /// Which labels of `other` differ from these as a player names them: the dynamic by
    /// its nearest marking, the location by the nearest of centre, playing spot and rim
    /// (so velocity 0.6 played from an mf unit, or a point near the playing spot from a
    /// playing-spot unit, is no substitution).
    pub fn differences(&self, other: &Labels) -> Differences {
        Differences {
            mode: self.mode != other.mode,
            hand: self.hand != other.hand,
            location: named_location(self.location) != named_location(other.location),
            dynamic: self.dynamic.nearest_mark() != other.dynamic.nearest_mark(),
            grip: self.grip != other.grip,
        }
    }

    /// The labels in words, e.g. "accent, right, mf": mode, hand and dynamic, then the
    /// location and the grip where `shown` says so.
    pub fn describe(&self, shown: &Differences) -> String {
        let mut words = vec![self.mode.name().to_string(), side_name(self.hand).into()];
        if shown.location {
            words.push(self.location.name());
        }
        words.push(dynamic_name(self.dynamic));
        if shown.grip {
            words.push(format!("{:?}", self.grip));
        }
        words.join(", ")
    }
}

/// Which labels differ.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Differences {
    pub mode: bool,
    pub hand: bool,
    pub location: bool,
    pub dynamic: bool,
    pub grip: bool,
}

impl Differences {
    /// Whether any label differs.
    pub fn any(&self) -> bool {
        self.mode || self.hand || self.location || self.dynamic || self.grip
    }
}

/// "left" or "right".
pub fn side_name(side: Side) -> &'static str {
    match side {
        Side::Left => "left",
        Side::Right => "right",
    }
}

/// A marking's name ("mf"), or an exact velocity with its nearest marking ("0.60 ≈ mf").
fn dynamic_name(dynamic: Dynamic) -> String {
    match dynamic {
        Dynamic::Velocity(v) => format!("{v:.2} ≈ {}", dynamic.nearest_mark()),
        mark => mark.nearest_mark().to_string(),
    }
}

/// The named location (centre, playing spot, rim) nearest in radius to `location`.
fn named_location(location: ImpactLocation) -> ImpactLocation {
    let radius = location.polar().0;
    [
        ImpactLocation::Centre,
        ImpactLocation::PlayingSpot,
        ImpactLocation::Rim,
    ]
    .into_iter()
    .min_by(|a, b| {
        (a.polar().0 - radius)
            .abs()
            .total_cmp(&(b.polar().0 - radius).abs())
    })
    .expect("three named locations")
}

/// A beat played with a unit whose labels differ from what its stroke asked.
#[derive(Clone, Debug, PartialEq)]
pub struct Substitution {
    /// Index of the beat in the score.
    pub beat: usize,
    pub wanted: Labels,
    pub used: Labels,
}

impl std::fmt::Display for Substitution {
    /// E.g. "beat 12 (staccato, right, mf): no such unit; used accent, right, mf".
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let shown = self.wanted.differences(&self.used);
        write!(
            f,
            "beat {} ({}): no such unit; used {}",
            self.beat,
            self.wanted.describe(&shown),
            self.used.describe(&shown)
        )
    }
}

/// `x.rem_euclid(360.0)`, the same to the bit (x − 360 and x − 720 are exact where they
/// are taken, by Sterbenz's lemma), without the division for the angles a cost compares.
fn turn_remainder(x: f64) -> f64 {
    if (0.0..360.0).contains(&x) {
        x
    } else if (360.0..720.0).contains(&x) {
        x - 360.0
    } else if (720.0..1080.0).contains(&x) {
        x - 720.0
    } else {
        x.rem_euclid(360.0)
    }
}

/// What `stroke` of `score` asks of its unit.
pub fn wanted(stroke: &PlannedStroke, score: &Score) -> Labels {
    Labels {
        mode: stroke.mode,
        hand: stroke.hand,
        location: score.beats[stroke.beat].location,
        dynamic: stroke.dynamic,
        grip: score.grip,
    }
}

/// The beats of `strokes` (planned for `score` with `db`) played with a unit whose labels
/// differ from what was asked ([`Labels::differences`]), each beat and pair of labels
/// once (a roll's strokes share their beat), in time order.
pub fn substitutions(strokes: &[PlannedStroke], score: &Score, db: &MotionDb) -> Vec<Substitution> {
    let mut found: Vec<Substitution> = Vec::new();
    for s in strokes {
        let wanted = wanted(s, score);
        let used = Labels::of(&db.index.units[s.unit]);
        let substitution = Substitution {
            beat: s.beat,
            wanted,
            used,
        };
        if wanted.differences(&used).any() && !found.contains(&substitution) {
            found.push(substitution);
        }
    }
    found
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
                toward_player: drum.toward_player().extend(0.0),
                drum: beat.drum,
                mode: beat.mode,
                dynamic: beat.dynamic,
                unit: 0,
            });
        };
        let mut hand = side;
        for tick in beat.stroke_ticks(score.ticks_per_quarter) {
            push(tick, hand);
            hand = hand.other();
        }
    }
    strokes.sort_by(|a, b| a.time_s.total_cmp(&b.time_s));
    release_rolls(&mut strokes, score, kit);
    choose_units(&mut strokes, score, db, params);
    Ok(strokes)
}

/// Let a hand leave a roll in time for its next stroke on another drum: its roll strokes
/// closer than that drum's `min_same_hand_gap_s` before it are left out, from the roll's
/// end back (the other hand plays on alone), never the roll's first stroke. A roll written
/// right up to a note on another drum is ordinary writing, and a player ends it so; played
/// to its last stroke, the hand had to cross to the other drum in one roll stroke (an
/// eighth of a second in a roll of 32nds at 120 bpm), which no arm can.
fn release_rolls(strokes: &mut Vec<PlannedStroke>, score: &Score, kit: &Kit) {
    let mut dropped = vec![false; strokes.len()];
    // Each beat's first and last stroke (in time order), found in one pass.
    let mut span: Vec<Option<(usize, usize)>> = vec![None; score.beats.len()];
    for (i, s) in strokes.iter().enumerate() {
        let first = span[s.beat].map_or(i, |(f, _)| f);
        span[s.beat] = Some((first, i));
    }
    for (b, beat) in score.beats.iter().enumerate() {
        let Some((first, end)) = span[b].filter(|_| beat.roll.is_some()) else {
            continue;
        };
        for hand in [Side::Left, Side::Right] {
            let mine: Vec<usize> = (first..=end)
                .filter(|&i| strokes[i].beat == b && strokes[i].hand == hand)
                .collect();
            let Some(&last) = mine.last() else {
                continue;
            };
            let Some(next) = (last + 1..strokes.len())
                .map(|i| &strokes[i])
                .find(|s| s.hand == hand && s.beat != b)
            else {
                continue;
            };
            if next.drum == beat.drum {
                continue;
            }
            let needed = kit.drums[next.drum].min_same_hand_gap_s;
            for &i in mine.iter().rev() {
                if i == first || next.time_s - strokes[i].time_s >= needed {
                    break;
                }
                dropped[i] = true;
            }
        }
    }
    let mut k = 0;
    strokes.retain(|_| {
        k += 1;
        !dropped[k - 1]
    });
}

/// Pick a unit for every stroke: the seeded choice among near equals, avoiding the unit
/// the same hand used last when another is as good. The near equals depend only on what
/// a stroke asks ([`wanted`]), so they are found once per distinct ask (a score asks a
/// few dozen things of 1 440 units, not one per stroke).
fn choose_units(strokes: &mut [PlannedStroke], score: &Score, db: &MotionDb, params: &PlanParams) {
    let rng = Rng::new(params.seed);
    let mut last = [usize::MAX; 2];
    let mut asked: Vec<(Labels, Vec<usize>)> = Vec::new();
    for (i, s) in strokes.iter_mut().enumerate() {
        let wanted = wanted(s, score);
        let known = asked.iter().position(|(labels, _)| *labels == wanted);
        let k = known.unwrap_or_else(|| {
            asked.push((wanted, near_equals(&wanted, db, params.near_equal)));
            asked.len() - 1
        });
        let mut near = asked[k].1.clone();
        let h = crate::mocap::db::side_index(s.hand);
        if near.len() > 1 {
            near.retain(|&k| k != last[h]);
        }
        let pick = near[(rng.fork(i as u64).next_u64() % near.len() as u64) as usize];
        s.unit = pick;
        last[h] = pick;
    }
}

/// The units of `db` whose cost for `wanted` is within `near_equal` of the best, in order.
fn near_equals(wanted: &Labels, db: &MotionDb, near_equal: f64) -> Vec<usize> {
    let costs: Vec<f64> = db.index.units.iter().map(|u| wanted.cost(u)).collect();
    let best = costs.iter().copied().fold(f64::INFINITY, f64::min);
    (0..costs.len())
        .filter(|&k| costs[k] <= best + near_equal)
        .collect()
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
        // A 2-beat and a 4-beat roll of 32nds; the second runs into the closing chord,
        // whose right-hand stroke is on the other drum: the right hand leaves the roll's
        // last stroke out to get there ([`release_rolls`]).
        assert_eq!(strokes.len(), plain + 16 + 32 - 1);
        let roll = rolls
            .score
            .beats
            .iter()
            .rposition(|b| b.roll.is_some())
            .unwrap();
        let last_roll_stroke = |hand: Side| {
            strokes
                .iter()
                .filter(|s| s.beat == roll && s.hand == hand)
                .map(|s| s.time_s)
                .fold(f64::NEG_INFINITY, f64::max)
        };
        let chord = strokes.iter().find(|s| s.beat > roll).unwrap().time_s;
        assert!(chord - last_roll_stroke(Side::Right) >= rolls.kit.drums[1].min_same_hand_gap_s);
        assert!(
            chord - last_roll_stroke(Side::Left) < 0.2,
            "the left hand plays on"
        );
        let etude = demo("etude-modes.ron");
        for s in plan(&etude.score, &etude.kit, &db, &PlanParams::default()).unwrap() {
            let u = &db.index.units[s.unit];
            assert_eq!((u.mode, u.grip), (s.mode, etude.score.grip));
            assert!((u.dynamic.velocity() - s.dynamic.velocity()).abs() < 0.15);
        }
    }

    /// A database without staccato units: the études' staccato beats are played with the
    /// nearest units of another mode and listed, once per beat; the other beats only
    /// where their dynamic has no unit (the soft legato: mp played from mf or p).
    #[test]
    fn substitutions_list_the_beats_without_their_units() {
        let mut db = shipped_db();
        db.index.units.retain(|u| u.mode != PlayingMode::Staccato);
        let etude = demo("etude-modes.ron");
        let strokes = plan(&etude.score, &etude.kit, &db, &PlanParams::default()).unwrap();
        let found = substitutions(&strokes, &etude.score, &db);
        let beats = |f: &dyn Fn(&crate::score::Beat) -> bool| -> Vec<usize> {
            (0..etude.score.beats.len())
                .filter(|&b| f(&etude.score.beats[b]))
                .collect()
        };
        let staccato = beats(&|b| b.mode == PlayingMode::Staccato);
        let listed: Vec<usize> = found.iter().map(|s| s.beat).collect();
        let mut expected = [staccato.clone(), beats(&|b| b.dynamic == Dynamic::Mp)].concat();
        expected.sort();
        assert_eq!(listed, expected);
        for s in found.iter().filter(|s| staccato.contains(&s.beat)) {
            assert_eq!(s.wanted.mode, PlayingMode::Staccato);
            assert_ne!(s.used.mode, PlayingMode::Staccato);
            let stroke = (strokes.iter())
                .find(|t| t.beat == s.beat && t.hand == s.wanted.hand)
                .unwrap();
            assert_eq!(s.wanted, wanted(stroke, &etude.score));
        }
    }

    /// A substitution reads as a note naming the labels that differ, the location and
    /// grip only when they do.
    #[test]
    fn a_substitution_reads_as_a_note() {
        let wanted = Labels {
            mode: PlayingMode::Staccato,
            hand: Side::Right,
            location: ImpactLocation::PlayingSpot,
            dynamic: Dynamic::Mf,
            grip: Grip::French,
        };
        let note = |used: Labels| {
            Substitution {
                beat: 12,
                wanted,
                used,
            }
            .to_string()
        };
        let accent = Labels {
            mode: PlayingMode::Accent,
            ..wanted
        };
        assert_eq!(
            note(accent),
            "beat 12 (staccato, right, mf): no such unit; used accent, right, mf"
        );
        let rim = Labels {
            location: ImpactLocation::Rim,
            grip: Grip::German,
            dynamic: Dynamic::Velocity(0.6),
            ..wanted
        };
        assert_eq!(
            note(rim),
            "beat 12 (staccato, right, playing spot, mf, French): no such unit; \
             used staccato, right, rim, 0.60 ≈ mf, German"
        );
        let near = Labels {
            location: ImpactLocation::Point {
                radius: 0.6,
                angle_deg: 20.0,
            },
            dynamic: Dynamic::Velocity(0.6),
            ..wanted
        };
        assert!(!wanted.differences(&near).any(), "{}", note(near));
    }

    /// The cost's angle wrap is `rem_euclid(360)` to the bit, at the edges and over
    /// 100 000 angles either side of the range it takes exact subtractions in.
    #[test]
    fn turn_remainder_is_rem_euclid_to_the_bit() {
        let mut rng = crate::base::rng::Rng::new(7);
        let edges = [
            0.0,
            180.0,
            359.999_999_999_999_94,
            360.0,
            540.0,
            720.0,
            1080.0,
            -0.5,
        ];
        let drawn = (0..100_000).map(|_| rng.uniform(-400.0, 1500.0));
        for x in edges.into_iter().chain(drawn) {
            assert_eq!(
                turn_remainder(x).to_bits(),
                x.rem_euclid(360.0).to_bits(),
                "{x}"
            );
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
