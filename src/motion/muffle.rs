//! Secco beats (timpani practice: the hand stops the head): a beat with
//! `damp: Some(ticks)` is stopped by a hand resting on its head at the damp tick. The *free* hand does it — the one not
//! playing around that time, preferably not the one that struck — by moving to the head
//! near the rim on the player's side, its fingers on the head and the stick turned up and
//! away so the felt stays clear, resting there for [`TOUCH_S`] and going back to its own
//! trajectory.
//!
//! Planning is pure geometry and timing: which hand, when it leaves, touches, lifts and is
//! back, where the hand (its grip joint, the fulcrum in the fingers) and the stick tip go.
//! [`apply`] blends the hand's composed tip toward the muffling tip so the composed
//! trajectories show the gesture; the renderer gives the body the hand's point
//! (`body::sim::HandTargets`) and times the touch on the head from where the simulated hand
//! actually is.

use super::compose::Composition;
use super::plan::PlannedStroke;
use crate::kit::{Kit, Side};
use crate::mocap::db::side_index;
use crate::score::Score;
use crate::sound::TOUCH_S;
use glam::DVec3;

/// How long the hand takes to reach the head, s.
pub const APPROACH_S: f64 = 0.3;
/// How long it takes to go back once it lifts, s.
pub const LEAVE_S: f64 = 0.3;
/// The shortest approach that still reads as a gesture (after the hand's own stroke), s.
const MIN_APPROACH_S: f64 = 0.15;
/// Time after a hand's stroke before it can leave for a head (its rebound), s.
const AFTER_STROKE_S: f64 = 0.1;
/// Time a hand needs, once back, before its next stroke's impact, s.
const BEFORE_STROKE_S: f64 = 0.35;
/// How far in from the rim the fingers rest, m.
const IN_FROM_RIM_M: f64 = 0.07;
/// Height of the grip joint above the head while the fingers rest on it, m.
pub const HAND_ABOVE_HEAD_M: f64 = 0.03;
/// How high above its resting point the hand comes over the head before it lowers onto
/// it, m, and how long it takes to lower (or to rise once it lifts), s.
const HOVER_M: f64 = 0.12;
const LOWER_S: f64 = 0.12;
/// The stick's direction while the hand damps: up at 60°, away from the player.
const STICK_UP: f64 = 0.866;
/// Distance from the hand to where the stick tip is aimed, m.
const STICK_REACH_M: f64 = 0.3;

/// A head to be stopped: the damped beat (its index in the score), its drum and the
/// scored touch (the beat's damp tick), s (score time).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Damp {
    pub beat: usize,
    pub drum: usize,
    pub touch_s: f64,
}

/// One hand damping one head.
#[derive(Clone, Debug, PartialEq)]
pub struct Muffle {
    pub damp: Damp,
    pub hand: Side,
    /// When the hand leaves its trajectory, s (score time).
    pub leave_s: f64,
    /// When the hand lifts off the head, s.
    pub lift_s: f64,
    /// When the hand is back on its own trajectory, s.
    pub back_s: f64,
    /// Where the hand (its grip joint) rests, m (performer frame).
    pub hand_point: DVec3,
    /// Where the stick tip points while the hand rests, m.
    pub tip_point: DVec3,
}

/// A raised-cosine ramp from 0 (x ≤ 0) to 1 (x ≥ 1).
fn ramp(x: f64) -> f64 {
    0.5 - 0.5 * (std::f64::consts::PI * x.clamp(0.0, 1.0)).cos()
}

impl Muffle {
    /// How far the hand is on its way to the head at `t_s` (score time): 0 on its own
    /// trajectory, 1 resting on the head, raised-cosine ramps between.
    pub fn weight(&self, t_s: f64) -> f64 {
        if t_s <= self.leave_s || t_s >= self.back_s {
            0.0
        } else if t_s < self.damp.touch_s {
            ramp((t_s - self.leave_s) / (self.damp.touch_s - self.leave_s))
        } else if t_s <= self.lift_s {
            1.0
        } else {
            ramp((self.back_s - t_s) / (self.back_s - self.lift_s))
        }
    }

    /// Where the hand is taken at `t_s`: hovering [`HOVER_M`] above its resting point,
    /// lowered onto it over the [`LOWER_S`] before the touch, raised again over the
    /// [`LOWER_S`] after the lift, m.
    pub fn hand_at(&self, t_s: f64) -> DVec3 {
        let down = ramp((t_s - (self.damp.touch_s - LOWER_S)) / LOWER_S)
            * (1.0 - ramp((t_s - self.lift_s) / LOWER_S));
        self.hand_point + DVec3::Z * (HOVER_M * (1.0 - down))
    }

    /// Where the stick tip is taken at `t_s`: held by the hand as it rests, m.
    pub fn tip_at(&self, t_s: f64) -> DVec3 {
        self.tip_point + (self.hand_at(t_s) - self.hand_point)
    }
}

/// The score's damped beats: the muffles a free hand plays, and the beats no hand is free
/// for (their heads are still stopped at the damp tick, without a gesture).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Muffles {
    pub played: Vec<Muffle>,
    pub without_hand: Vec<Damp>,
}

/// Plan a muffle for every damped beat of `score`, performed by `strokes` on `kit`.
pub fn plan(score: &Score, kit: &Kit, strokes: &[PlannedStroke]) -> Muffles {
    let tempo = score.tempo_map();
    let mut out = Muffles::default();
    for (beat, b) in score.beats.iter().enumerate() {
        let Some(tick) = b.damp_tick() else {
            continue;
        };
        let touch_s = tempo.seconds_at(tick as f64);
        let damp = Damp {
            beat,
            drum: b.drum,
            touch_s,
        };
        let struck_by = strokes.iter().find(|s| s.beat == beat).map(|s| s.hand);
        let order = match struck_by {
            Some(Side::Left) => [Side::Right, Side::Left],
            _ => [Side::Left, Side::Right],
        };
        let Some(drum) = kit.drums.get(b.drum) else {
            out.without_hand.push(damp);
            continue;
        };
        let window = order.into_iter().find_map(|hand| {
            free_window(hand, touch_s, strokes, &out.played)
                .map(|(leave, back)| (hand, leave, back))
        });
        let Some((hand, leave_s, back_s)) = window else {
            out.without_hand.push(damp);
            continue;
        };
        let toward_player = drum.toward_player().extend(0.0);
        let hand_point = drum.centre()
            + toward_player * (drum.radius_m() - IN_FROM_RIM_M)
            + DVec3::Z * HAND_ABOVE_HEAD_M;
        let up_and_away =
            (-toward_player * (1.0 - STICK_UP * STICK_UP).sqrt() + DVec3::Z * STICK_UP).normalize();
        out.played.push(Muffle {
            damp,
            hand,
            leave_s,
            lift_s: touch_s + TOUCH_S,
            back_s,
            hand_point,
            tip_point: hand_point + up_and_away * STICK_REACH_M,
        });
    }
    out
}

/// When `hand` can leave for a head touched at `touch_s` and be back (s), if it is free:
/// no stroke of its own from shortly before the approach to shortly after it is back, and
/// no other muffle of its own overlapping.
fn free_window(
    hand: Side,
    touch_s: f64,
    strokes: &[PlannedStroke],
    planned: &[Muffle],
) -> Option<(f64, f64)> {
    let own = strokes.iter().filter(|s| s.hand == hand).map(|s| s.time_s);
    let before = own
        .clone()
        .filter(|&t| t <= touch_s)
        .fold(f64::NEG_INFINITY, f64::max);
    let after = own.filter(|&t| t > touch_s).fold(f64::INFINITY, f64::min);
    let leave = (touch_s - APPROACH_S).max(before + AFTER_STROKE_S);
    let back = touch_s + TOUCH_S + LEAVE_S;
    let busy = planned
        .iter()
        .any(|m| m.hand == hand && m.leave_s < back && leave < m.back_s);
    (touch_s - leave >= MIN_APPROACH_S && after - back >= BEFORE_STROKE_S && !busy)
        .then_some((leave, back))
}

/// Blend each muffling hand's composed tip toward its muffle's tip point, by the muffle's
/// weight, and keep the muffles with the composition.
pub fn apply(comp: &mut Composition, muffles: Muffles) {
    for m in &muffles.played {
        let h = side_index(m.hand);
        for (k, tip) in comp.tips[h].iter_mut().enumerate() {
            let t = comp.start_s + k as f64 / comp.rate_hz;
            let w = m.weight(t);
            if w > 0.0 {
                *tip = tip.lerp(m.tip_at(t), w);
            }
        }
    }
    comp.muffles = muffles;
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::score::{Beat, Hand};

    fn stroke(beat: usize, hand: Side, time_s: f64) -> PlannedStroke {
        PlannedStroke {
            beat,
            tick: 0,
            hand,
            time_s,
            target: DVec3::ZERO,
            toward_player: DVec3::NEG_Y,
            drum: 2,
            mode: crate::score::PlayingMode::Legato,
            dynamic: crate::score::Dynamic::Mf,
            unit: 0,
        }
    }

    /// A 60 bpm score (a quarter a second) of `beats` (tick in quarters, hand, damp in
    /// quarters), all on the 26-inch drum.
    fn score(beats: &[(u64, Hand, Option<u64>)]) -> Score {
        let mut s = Score::new("muffles");
        s.tempo[0].bpm = 60.0;
        let q = u64::from(s.ticks_per_quarter);
        s.beats = beats
            .iter()
            .map(|&(tick, hand, damp)| Beat {
                hand,
                damp: damp.map(|d| d * q),
                ..Beat::plain(tick * q, 2)
            })
            .collect();
        s
    }

    fn strokes_of(s: &Score) -> Vec<PlannedStroke> {
        let q = f64::from(s.ticks_per_quarter);
        (s.beats.iter().enumerate())
            .map(|(i, b)| {
                let hand = if b.hand == Hand::Left {
                    Side::Left
                } else {
                    Side::Right
                };
                stroke(i, hand, b.tick as f64 / q)
            })
            .collect()
    }

    /// The hand that did not strike damps when it is free; else the striker damps its own
    /// drum after its rebound; with both busy the beat has no gesture.
    #[test]
    fn the_free_hand_damps() {
        let kit = Kit::standard();
        let free_left = score(&[(0, Hand::Right, Some(1)), (4, Hand::Right, None)]);
        let m = plan(&free_left, &kit, &strokes_of(&free_left));
        assert_eq!(m.played.len(), 1);
        let muffle = &m.played[0];
        assert_eq!((muffle.hand, muffle.damp.touch_s), (Side::Left, 1.0));
        assert_eq!(
            (muffle.leave_s, muffle.lift_s),
            (1.0 - APPROACH_S, 1.0 + TOUCH_S)
        );
        // The left hand plays 1.5 s in: too soon to go and come back, so the right damps.
        let busy_left = score(&[
            (0, Hand::Right, Some(1)),
            (3, Hand::Left, None),
            (5, Hand::Right, None),
        ]);
        let mut s = busy_left.clone();
        s.beats[1].tick = s.ticks_per_quarter as u64 * 3 / 2;
        let m = plan(&s, &kit, &strokes_of(&s));
        assert_eq!(m.played[0].hand, Side::Right, "{m:?}");
        assert!(m.played[0].leave_s >= 0.1);
        // Both hands strike around the touch: no gesture.
        let busy = score(&[
            (0, Hand::Right, Some(1)),
            (1, Hand::Left, None),
            (1, Hand::Right, None),
        ]);
        let m = plan(&busy, &kit, &strokes_of(&busy));
        assert!(m.played.is_empty());
        assert_eq!(m.without_hand.len(), 1);
        assert_eq!(m.without_hand[0].touch_s, 1.0);
    }

    /// The gesture: 0 before leaving and after coming back, rising to 1 at the touch, held
    /// while resting; the hand hovers above its point and is lowered onto it by the touch,
    /// the stick tip held above and away from it.
    #[test]
    fn the_hand_lowers_onto_the_head_by_the_touch() {
        let kit = Kit::standard();
        let s = score(&[(0, Hand::Right, Some(1)), (4, Hand::Right, None)]);
        let m = plan(&s, &kit, &strokes_of(&s)).played.remove(0);
        assert_eq!(m.weight(m.leave_s), 0.0);
        assert_eq!(m.weight(m.back_s), 0.0);
        assert!(m.weight(m.damp.touch_s - 0.1) < 1.0);
        assert_eq!(m.weight(m.damp.touch_s), 1.0);
        assert_eq!(m.weight(m.lift_s), 1.0);
        assert_eq!(m.hand_at(m.damp.touch_s), m.hand_point);
        assert!(m.hand_at(m.damp.touch_s - 0.2).z > m.hand_point.z + 0.1);
        let head = kit.drums[2].placement.head_height_m;
        assert!((m.hand_point.z - head - HAND_ABOVE_HEAD_M).abs() < 1e-12);
        assert!(m.tip_point.z - head > 0.25);
        let p = &kit.drums[2].placement;
        let centre = DVec3::new(p.x_m, p.y_m, m.hand_point.z);
        assert!(m.hand_point.distance(centre) < 0.5 * kit.drums[2].diameter_m);
        assert!(m.tip_point.truncate().length() > m.hand_point.truncate().length());
    }
}
