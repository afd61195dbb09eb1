//! Composition: splicing the planned strokes' motion units into two continuous stick-tip
//! trajectories sampled at a fixed rate (250 Hz).
//!
//! **Splicing.** Each unit is time-warped so that its impact lands exactly on the
//! stroke's (sample-snapped) time: its preparation is fitted to the time since the same
//! hand's previous stroke and its rebound to the time until the next one; a gap shorter
//! than the unit's natural rebound + preparation compresses both in time and lowers the
//! lift in the same proportion, as players do (a roll is played low); a longer gap stretches them up to 1.5× and then holds.
//! In space the unit's motion relative to its impact point is turned about the vertical
//! to face the target drum, mirrored when taken from the other hand, scaled with the
//! dynamic (height ∝ 0.35 + 0.7·velocity, as in the database), and placed on the
//! stroke's target point.
//!
//! **Co-articulation.** Consecutive pieces of a hand's timeline (strokes and holds) are
//! cross-faded over a window around their junction with the quintic smootherstep
//! 6τ⁵ − 15τ⁴ + 10τ³, whose first and second derivatives vanish at both ends, so position,
//! velocity and acceleration stay continuous (C2) across every join; windows never reach
//! an impact, so impacts stay exact. A hand rests above its next drum before its first
//! stroke, after its last, and in rests longer than 1.5 s; shorter waits hold a ready
//! point between the strokes.

use super::muffle::Muffles;
use super::plan::PlannedStroke;
use crate::body::limits::{JointLimits, NO_LIMITS};
use crate::kit::Side;
use crate::mocap::db::{MotionDb, UnitEntry, side_index};
use glam::{DQuat, DVec3};

/// Composition settings.
#[derive(Clone, Debug, PartialEq)]
pub struct ComposeParams {
    /// Output sample rate, Hz.
    pub rate_hz: f64,
    /// Largest slow-down of a unit's rebound and preparation before the hand holds.
    pub max_stretch: f64,
    /// Waits longer than this go to the rest point, s.
    pub long_rest_s: f64,
    /// Rest point: this high above the next target, m …
    pub rest_height_m: f64,
    /// … and this far back toward the player, m.
    pub rest_back_m: f64,
    /// Time before the first and after the last stroke, s.
    pub margin_s: f64,
    /// Blend half-width as a fraction of the shorter neighbouring phase.
    pub blend_fraction: f64,
}

impl Default for ComposeParams {
    fn default() -> Self {
        ComposeParams {
            rate_hz: 250.0,
            max_stretch: 1.5,
            long_rest_s: 1.5,
            rest_height_m: 0.15,
            rest_back_m: 0.08,
            margin_s: 0.6,
            blend_fraction: 0.8,
        }
    }
}

/// What a sample of a trajectory is part of.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase {
    Rest,
    Preparation,
    Impact,
    Rebound,
}

impl Phase {
    /// Lower-case name for files.
    pub fn name(self) -> &'static str {
        match self {
            Phase::Rest => "rest",
            Phase::Preparation => "preparation",
            Phase::Impact => "impact",
            Phase::Rebound => "rebound",
        }
    }
}

/// Per-sample annotation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Tag {
    /// Index into [`Composition::strokes`], if the sample belongs to a stroke.
    pub stroke: Option<usize>,
    pub phase: Phase,
}

/// Two stick-tip trajectories on a common time grid.
#[derive(Clone, Debug, PartialEq)]
pub struct Composition {
    pub rate_hz: f64,
    /// Time of sample 0, s (before the score's start if the first stroke needs a lead-in).
    pub start_s: f64,
    /// Tip positions per sample, [left, right], m (performer frame).
    pub tips: [Vec<DVec3>; 2],
    pub tags: [Vec<Tag>; 2],
    /// The strokes performed, in time order.
    pub strokes: Vec<PlannedStroke>,
    /// Sample index of each stroke's impact.
    pub impact_samples: Vec<usize>,
    /// The ranges of motion of the performer whose units these are (from the motion
    /// database, `MotionDb::joint_limits` of the score's grip; none when composed without
    /// a score): a rendering holds the body within them.
    pub limits: JointLimits,
    /// The secco beats' damping gestures ([`super::muffle`]; none when composed without a
    /// score).
    pub muffles: Muffles,
}

impl Composition {
    /// Number of samples.
    pub fn len(&self) -> usize {
        self.tips[0].len()
    }

    /// Whether there are no samples.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Time of sample `k`, s.
    pub fn time(&self, k: usize) -> f64 {
        self.start_s + k as f64 / self.rate_hz
    }

    /// The trajectory of one hand.
    pub fn tip(&self, hand: Side) -> &[DVec3] {
        &self.tips[side_index(hand)]
    }
}

/// One stroke shaped for its place in time.
struct Shaped<'a> {
    stroke: &'a PlannedStroke,
    unit: &'a UnitEntry,
    take: &'a [Option<DVec3>],
    /// Snapped impact time, s.
    impact_s: f64,
    prep_s: f64,
    rebound_s: f64,
    prep_scale: f64,
    rebound_scale: f64,
    /// Unit impact position, m.
    origin: DVec3,
    /// Source motion → target orientation (yaw, with a mirror if from the other hand).
    turn: DQuat,
    mirror_normal: Option<DVec3>,
}

impl Shaped<'_> {
    fn natural_prep_s(unit: &UnitEntry, rate: f64) -> f64 {
        (unit.impact - unit.start) as f64 / rate
    }

    fn natural_rebound_s(unit: &UnitEntry, rate: f64) -> f64 {
        (unit.end - unit.impact) as f64 / rate
    }

    /// Tip position at time `t`, m.
    fn at(&self, t: f64) -> DVec3 {
        let u = self.unit;
        let (frame, scale) = if t <= self.impact_s {
            let back = (self.impact_s - t) / self.prep_s;
            (
                u.impact as f64 - back * (u.impact - u.start) as f64,
                self.prep_scale,
            )
        } else {
            let on = (t - self.impact_s) / self.rebound_s;
            (
                u.impact as f64 + on * (u.end - u.impact) as f64,
                self.rebound_scale,
            )
        };
        // Next to the impact the data has a kink (the rebound): interpolate linearly there
        // so the curve cannot overshoot through the head.
        let raw = if (frame - u.impact as f64).abs() < 1.0 {
            let i = frame.floor();
            let (a, b) = (
                nearest_present(self.take, i as usize),
                nearest_present(self.take, i as usize + 1),
            );
            a.lerp(b, frame - i)
        } else {
            sample(self.take, frame)
        };
        let mut rel = raw - self.origin;
        // The unit's impact is its lowest point: nothing goes below the head.
        rel.z = rel.z.max(0.0);
        if let Some(n) = self.mirror_normal {
            rel -= 2.0 * rel.dot(n) * n;
        }
        self.stroke.target + self.turn * rel * scale
    }
}

/// Catmull-Rom interpolation of a sampled track at a fractional frame, clamped to the
/// track; missing samples take the nearest present one.
fn sample(track: &[Option<DVec3>], frame: f64) -> DVec3 {
    let last = track.len().saturating_sub(1) as f64;
    let f = frame.clamp(0.0, last);
    let i = f.floor() as isize;
    let x = f - i as f64;
    let get = |k: isize| nearest_present(track, k.clamp(0, last as isize) as usize);
    let (p0, p1, p2, p3) = (get(i - 1), get(i), get(i + 1), get(i + 2));
    let x2 = x * x;
    let x3 = x2 * x;
    0.5 * ((2.0 * p1)
        + (p2 - p0) * x
        + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * x2
        + (3.0 * p1 - p0 - 3.0 * p2 + p3) * x3)
}

fn nearest_present(track: &[Option<DVec3>], k: usize) -> DVec3 {
    (0..track.len())
        .flat_map(|d| [k.checked_sub(d), k.checked_add(d)])
        .flatten()
        .find_map(|j| track.get(j).copied().flatten())
        .unwrap_or(DVec3::ZERO)
}

/// A stretch of one hand's timeline.
enum Piece {
    Stroke(usize),
    Hold(DVec3),
}

/// Where two pieces cross-fade: centre and half-width, s.
#[derive(Clone, Copy)]
struct Join {
    centre: f64,
    half: f64,
}

/// The quintic smootherstep: C2 at both ends.
fn smootherstep(x: f64) -> f64 {
    let x = x.clamp(0.0, 1.0);
    x * x * x * (x * (6.0 * x - 15.0) + 10.0)
}

/// Compose the planned `strokes` (in time order) with units from `db`.
pub fn compose(strokes: &[PlannedStroke], db: &MotionDb, params: &ComposeParams) -> Composition {
    let rate = params.rate_hz;
    let snap = |t: f64| (t * rate).round() / rate;
    let first = strokes
        .iter()
        .map(|s| snap(s.time_s))
        .fold(0.0f64, f64::min);
    let last = strokes
        .iter()
        .map(|s| snap(s.time_s))
        .fold(0.0f64, f64::max);
    let start_s = ((first - params.margin_s - 1.0).min(0.0) * rate).floor() / rate;
    let n = ((last + params.margin_s + 1.0 - start_s) * rate).ceil() as usize + 1;
    // The hands share nothing: each is composed on a thread of its own.
    let [(left, left_tags), (right, right_tags)]: [(Vec<DVec3>, Vec<Tag>); 2] =
        crate::base::parallel::each([Side::Left, Side::Right], |hand| {
            hand_path(strokes, db, params, hand, (start_s, n))
        })
        .try_into()
        .unwrap_or_else(|_| unreachable!("one path per hand"));
    let (tips, tags) = ([left, right], [left_tags, right_tags]);
    let impact_samples = strokes
        .iter()
        .map(|s| ((snap(s.time_s) - start_s) * rate).round() as usize)
        .collect();
    Composition {
        rate_hz: rate,
        start_s,
        tips,
        tags,
        strokes: strokes.to_vec(),
        impact_samples,
        limits: NO_LIMITS,
        muffles: Muffles::default(),
    }
}

/// One hand's tip path and tags over the `n` samples from `start_s`: its strokes' shaped
/// segments on the timeline, blended across each join.
fn hand_path(
    strokes: &[PlannedStroke],
    db: &MotionDb,
    params: &ComposeParams,
    hand: Side,
    (start_s, n): (f64, usize),
) -> (Vec<DVec3>, Vec<Tag>) {
    let rate = params.rate_hz;
    let (mut tips, mut tags) = (Vec::with_capacity(n), Vec::with_capacity(n));
    let mine: Vec<usize> = (0..strokes.len())
        .filter(|&i| strokes[i].hand == hand)
        .collect();
    let shaped = shape(strokes, &mine, db, params);
    let (pieces, joins) = timeline(&shaped, hand, params);
    let mut p = 0;
    for k in 0..n {
        let t = start_s + k as f64 / rate;
        while p < joins.len() && t >= joins[p].centre + joins[p].half {
            p += 1;
        }
        let eval = |piece: &Piece| match piece {
            Piece::Stroke(j) => shaped[*j].at(t),
            Piece::Hold(q) => *q,
        };
        let (position, main) = match joins.get(p) {
            Some(j) if t > j.centre - j.half => {
                let w = smootherstep((t - (j.centre - j.half)) / (2.0 * j.half));
                let (a, b) = (&pieces[p], &pieces[p + 1]);
                (
                    eval(a) * (1.0 - w) + eval(b) * w,
                    if w < 0.5 { a } else { b },
                )
            }
            _ => (eval(&pieces[p]), &pieces[p]),
        };
        tips.push(position);
        tags.push(match main {
            Piece::Hold(_) => Tag {
                stroke: None,
                phase: Phase::Rest,
            },
            Piece::Stroke(j) => {
                let s = &shaped[*j];
                let phase = if (t - s.impact_s).abs() < 0.5 / rate {
                    Phase::Impact
                } else if t < s.impact_s {
                    Phase::Preparation
                } else {
                    Phase::Rebound
                };
                Tag {
                    stroke: Some(mine[*j]),
                    phase,
                }
            }
        });
    }
    (tips, tags)
}

/// Fit each of one hand's strokes (`mine`, indices into `strokes`) to its neighbours.
fn shape<'a>(
    strokes: &'a [PlannedStroke],
    mine: &[usize],
    db: &'a MotionDb,
    params: &ComposeParams,
) -> Vec<Shaped<'a>> {
    let rate = params.rate_hz;
    let mut shaped: Vec<Shaped> = mine
        .iter()
        .map(|&i| {
            let stroke = &strokes[i];
            let unit = &db.index.units[stroke.unit];
            let data = &db.takes[unit.take];
            let take = data.tip(unit.hand);
            let origin = take[unit.impact].unwrap_or_else(|| nearest_present(take, unit.impact));
            let from = (-origin.truncate()).normalize_or(glam::DVec2::NEG_Y);
            let to = stroke
                .toward_player
                .truncate()
                .normalize_or(glam::DVec2::NEG_Y);
            let turn = DQuat::from_rotation_z(from.angle_to(to));
            let mirror_normal =
                (unit.hand != stroke.hand).then(|| DVec3::new(-from.y, from.x, 0.0));
            let dynamic =
                (0.35 + 0.7 * stroke.dynamic.velocity()) / (0.35 + 0.7 * unit.dynamic.velocity());
            Shaped {
                stroke,
                unit,
                take,
                impact_s: (stroke.time_s * rate).round() / rate,
                prep_s: Shaped::natural_prep_s(unit, data.rate_hz),
                rebound_s: Shaped::natural_rebound_s(unit, data.rate_hz),
                prep_scale: dynamic,
                rebound_scale: dynamic,
                origin,
                turn,
                mirror_normal,
            }
        })
        .collect();
    for k in 1..shaped.len() {
        let gap = shaped[k].impact_s - shaped[k - 1].impact_s;
        let need = shaped[k - 1].rebound_s + shaped[k].prep_s;
        let f = gap / need;
        if f <= params.max_stretch {
            shaped[k - 1].rebound_s *= f;
            shaped[k].prep_s *= f;
            if f < 1.0 {
                shaped[k - 1].rebound_scale *= f;
                shaped[k].prep_scale *= f;
            }
        }
    }
    // Strokes of one hand on the same sample (a score with problems, which the editor
    // still shows) squeeze each other's approach and rebound to nothing: keep one sample
    // of each, so positions stay finite.
    for s in &mut shaped {
        s.prep_s = s.prep_s.max(1.0 / rate);
        s.rebound_s = s.rebound_s.max(1.0 / rate);
    }
    shaped
}

/// Where a hand with no strokes rests, m (performer frame): in front of its shoulder,
/// above the drums' height.
pub fn idle_rest(hand: Side) -> DVec3 {
    DVec3::new(0.25 * hand.sign(), 0.35, 0.95)
}

/// The pieces of one hand's timeline and the joins between them.
fn timeline(shaped: &[Shaped], hand: Side, params: &ComposeParams) -> (Vec<Piece>, Vec<Join>) {
    let rest_above = |s: &PlannedStroke| {
        s.target + s.toward_player * params.rest_back_m + DVec3::Z * params.rest_height_m
    };
    let f = params.blend_fraction;
    let Some(first) = shaped.first() else {
        // An idle hand rests in front of its shoulder, clear of the drums: where the other
        // hand plays may be out of its comfortable reach (a stretched arm held still
        // under PD control oscillates).
        return (vec![Piece::Hold(idle_rest(hand))], Vec::new());
    };
    let mut pieces = vec![Piece::Hold(rest_above(first.stroke))];
    let mut joins = vec![Join {
        centre: first.impact_s - first.prep_s,
        half: f * first.prep_s.min(params.margin_s),
    }];
    for k in 0..shaped.len() {
        pieces.push(Piece::Stroke(k));
        let s = &shaped[k];
        let end = s.impact_s + s.rebound_s;
        let Some(next) = shaped.get(k + 1) else {
            pieces.push(Piece::Hold(rest_above(s.stroke)));
            joins.push(Join {
                centre: end,
                half: f * s.rebound_s.min(params.margin_s),
            });
            break;
        };
        let begin = next.impact_s - next.prep_s;
        if begin - end <= 1e-9 {
            joins.push(Join {
                centre: end,
                half: f * s.rebound_s.min(next.prep_s),
            });
        } else {
            let wait = begin - end;
            let hold = if wait > params.long_rest_s {
                rest_above(next.stroke)
            } else {
                s.at(end).lerp(next.at(begin), 0.5)
            };
            pieces.push(Piece::Hold(hold));
            joins.push(Join {
                centre: end,
                half: f * s.rebound_s.min(wait / 2.0),
            });
            joins.push(Join {
                centre: begin,
                half: f * next.prep_s.min(wait / 2.0),
            });
        }
    }
    (pieces, joins)
}
