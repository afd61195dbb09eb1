//! Sticking: which hand plays each beat whose hand is [`Hand::Auto`]. Beats with a fixed
//! hand are never changed, and two beats at the same tick always get different hands.
//!
//! Three methods, from the simple rule of seed 003 to an exact optimum:
//!
//! * [`Method::Simple`], seed 003 Alg. 3.1: every beat gets its drum's preferred hand,
//!   then the middle beat of every same-hand triplet that is too fast
//!   (a gap ≤ the drum's `min_same_hand_gap_s`) switches hands, in place, left to right.
//! * [`Method::Pairwise`], seed 003 §4.2.2: hand values in [−1, 1] (−1 left) from
//!   pair preferences `pair(e1, e2)` (−1: e1 left, e2 right) blended with the preferred
//!   hand by ρ^Δt, averaged over a beat's backward and forward pairs. Two drums' pair
//!   comes from their left–right order; on one drum it alternates from the previous
//!   beat's decided hand.
//!
//! Both use the gap from the end of the earlier beat (a roll's last stroke), and then
//! give two auto beats at one tick different hands (the left one to the left hand).
//! * [`Method::Optimal`], the shortest-path idea of seed 003 §4.2.3 made exact and
//!   linear: dynamic programming over the assignment that minimises the cost below.
//!
//! **Cost** of beat b played by hand h (weights are [`Params`] fields):
//! * reach: [`UNREACHABLE_COST`] if h cannot reach the beat's point;
//! * preference: `w_pref` if h is not the drum's preferred hand;
//! * travel of h from its previous stroke p (horizontal distance d, Δt = t_b − t_p):
//!   `w_dist·d + w_speed·max(0, d/Δt − v_comfort)²`;
//! * repetition: if Δt < the drum's minimum same-hand gap g, `w_rep·(g/Δt − 1)²`;
//!   Δt ≤ 0 costs [`IMPOSSIBLE_COST`];
//! * crossing: after the stroke, with the left hand's last point at x_L and the right
//!   hand's at x_R, `w_cross·(x_L − x_R)` if positive, plus `w_cross_fixed` if that is a
//!   counted crossing (more than [`CROSSING_TOLERANCE_M`], as in [`crossings`]).
//!
//! A hand that has not played yet has no point: it travels for free and crosses nothing.
//! A roll takes both hands: its beat's hand h starts it at the beat's time, the other hand
//! joins one roll stroke later (each pays travel and repetition for getting there), and
//! strokes alternate to the roll's end tick, so afterwards both hands are at the roll's
//! point: the hand of the last stroke at the end time, the other one stroke earlier.
//!
//! **Why the dynamic program is exact and linear.** The cost of beat b depends on the
//! past only through each hand's last (point, time). Time enters only through the speed
//! and repetition terms, which are zero once Δt ≥ H = max(largest minimum gap,
//! largest distance between the score's points / `v_comfort`). So the state after beat i
//! is (hand of beat i, both hands' last point, each with its time only while that is less
//! than H before beat i + 1, else "far in time"). States with equal keys have equal
//! futures, so only the cheapest is kept (ties: the first in a fixed order), in a
//! `BTreeMap`, with a back-pointer. One hand's anchor is beat i itself; the other is one of
//! the beats in the last H seconds or one of the score's distinct points (or none), so
//! a layer has at most 2·(beats per H + points + 1) states and the work is
//! O(n · (beats per H + points)), linear in the number of beats n for a given
//! density of notes and set of impact points.

use crate::body::skeleton::Skeleton;
use crate::kit::{Kit, Side};
use crate::score::{Hand, Score};
use glam::DVec2;
use std::collections::BTreeMap;
use std::collections::btree_map::Entry;

/// How far (m) the left hand's point must be right of the right hand's to count as a
/// crossing.
pub const CROSSING_TOLERANCE_M: f64 = 0.02;

/// Cost of a stroke at the same instant as (or before) the same hand's previous one:
/// in effect infinite, but finite so that the other terms still rank the assignments a
/// score forces into it (e.g. a fixed hand on a beat at the very end of its own roll).
pub const IMPOSSIBLE_COST: f64 = 1e9;

/// Cost of a beat played by a hand that cannot reach its point (the default player's
/// stretched arm and stick from the shoulder, `Skeleton::reaches`): far above the other
/// terms, far below [`IMPOSSIBLE_COST`]. Both hands pay it where neither reaches.
pub const UNREACHABLE_COST: f64 = 1e6;

/// How to choose hands.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    /// Preferred hands, then alternation of fast triplets (seed 003 Alg. 3.1).
    Simple,
    /// Pair preferences blended with preferred hands by ρ^Δt (seed 003 §4.2.2).
    Pairwise,
    /// Least total cost by dynamic programming (see the module docs).
    Optimal,
}

/// Tuning of the sticking methods.
#[derive(Clone, Debug, PartialEq)]
pub struct Params {
    /// Pairwise: weight ρ^Δt of the pair preference against the preferred hand after Δt
    /// seconds; ρ per second, in (0, 1). Default 0.1.
    pub rho: f64,
    /// Pairwise: left–right distance between two beats' points at which their pair
    /// preference is full strength, m. Default 0.3.
    pub pair_full_dx_m: f64,
    /// Optimal: cost of a stroke with the hand the drum does not prefer. Default 1.
    pub w_pref: f64,
    /// Optimal: cost per metre a hand travels in the horizontal plane, 1/m. Default 0.5.
    pub w_dist: f64,
    /// Optimal: cost per (m/s)² of travel speed above `v_comfort`, s²/m². Default 0.5.
    pub w_speed: f64,
    /// Optimal: travel speed that costs nothing extra, m/s (> 0). Default 3.
    pub v_comfort: f64,
    /// Optimal: weight of (g/Δt − 1)² for same-hand strokes closer than the drum's
    /// minimum gap g. Default 1.
    pub w_rep: f64,
    /// Optimal: cost per metre the left hand is right of the right hand, 1/m. Default 5.
    pub w_cross: f64,
    /// Optimal: cost of each beat after which the arms are crossed. Default 3.
    pub w_cross_fixed: f64,
}

impl Default for Params {
    fn default() -> Self {
        Params {
            rho: 0.1,
            pair_full_dx_m: 0.3,
            w_pref: 1.0,
            w_dist: 0.5,
            w_speed: 0.5,
            v_comfort: 3.0,
            w_rep: 1.0,
            w_cross: 5.0,
            w_cross_fixed: 3.0,
        }
    }
}

/// One side per beat (index = beat index): fixed hands as written, auto beats chosen by
/// `method`. The score must be valid for `kit`.
pub fn assign(score: &Score, kit: &Kit, method: Method, params: &Params) -> Vec<Side> {
    let prep = Prep::new(score, kit);
    match method {
        Method::Simple => prep.separate_simultaneous(prep.simple()),
        Method::Pairwise => prep.separate_simultaneous(prep.pairwise(params)),
        Method::Optimal => Costs {
            prep: &prep,
            params,
        }
        .optimal(),
    }
}

/// Give every auto beat its assigned side (`sides` as from [`assign`]); fixed hands stay.
pub fn apply(score: &mut Score, sides: &[Side]) {
    for (beat, &side) in score.beats.iter_mut().zip(sides) {
        if beat.hand == Hand::Auto {
            beat.hand = side.into();
        }
    }
}

/// Number of beats after which the left hand's last point is more than
/// [`CROSSING_TOLERANCE_M`] to the right of the right hand's.
pub fn crossings(score: &Score, kit: &Kit, sides: &[Side]) -> usize {
    let prep = Prep::new(score, kit);
    let mut hands = [Anchor::Rest; 2];
    let mut count = 0;
    for (i, &side) in sides.iter().enumerate().take(prep.strokes.len()) {
        hands = prep.place(&hands, i, side);
        count += usize::from(prep.cross_excess(&hands) > CROSSING_TOLERANCE_M);
    }
    count
}

/// What the methods need of one beat.
struct Stroke {
    tick: u64,
    /// Time of the beat, s.
    time: f64,
    drum: usize,
    /// Index into [`Prep::points`].
    point: usize,
    preferred: Side,
    fixed: Option<Side>,
    /// The drum's minimum same-hand gap, s.
    min_gap: f64,
    roll: Option<RollTimes>,
    /// Whether each hand (left, right) can reach the point.
    reachable: [bool; 2],
}

/// Times of a roll's strokes that matter to sticking, s.
struct RollTimes {
    /// The second stroke (the other hand's first).
    second: f64,
    /// The stroke before the last.
    penultimate: f64,
    /// The last stroke.
    end: f64,
    /// Whether the starting hand plays the last stroke.
    starter_ends: bool,
}

/// Where a hand last struck, as far as future costs can tell.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Anchor {
    /// Has not played yet.
    Rest,
    /// At a point (index), so long ago that the time no longer matters.
    Far(usize),
    /// At a point (index) at a time (the bits of its non-negative seconds).
    Near(usize, u64),
}

impl Anchor {
    fn at(point: usize, time: f64) -> Anchor {
        Anchor::Near(point, time.to_bits())
    }

    fn point(self) -> Option<usize> {
        match self {
            Anchor::Rest => None,
            Anchor::Far(p) | Anchor::Near(p, _) => Some(p),
        }
    }

    fn time(self) -> Option<f64> {
        match self {
            Anchor::Near(_, bits) => Some(f64::from_bits(bits)),
            _ => None,
        }
    }
}

/// Both hands' anchors, indexed by `Side as usize` (left, right).
type Hands = [Anchor; 2];

/// The score reduced to what sticking needs.
struct Prep {
    strokes: Vec<Stroke>,
    /// Distinct impact points (horizontal, performer frame), in order of first use.
    points: Vec<DVec2>,
}

impl Prep {
    fn new(score: &Score, kit: &Kit) -> Prep {
        let map = score.tempo_map();
        let body = Skeleton::holding_mallets_of(kit);
        let seconds = |tick: u64| map.seconds_at(tick as f64);
        let mut ids: BTreeMap<(usize, u64, u64), usize> = BTreeMap::new();
        let mut points = Vec::new();
        let strokes = score
            .beats
            .iter()
            .map(|b| {
                let drum = &kit.drums[b.drum];
                let (r, angle) = b.location.polar();
                let on_head = drum.point_on_head(r, angle);
                let reachable = [Side::Left, Side::Right].map(|h| body.reaches(h, on_head));
                let point = *ids
                    .entry((b.drum, r.to_bits(), angle.to_bits()))
                    .or_insert_with(|| {
                        points.push(on_head.truncate());
                        points.len() - 1
                    });
                let roll = b.roll.map(|roll| {
                    // Ticks between roll strokes (validated to divide a quarter).
                    let per_quarter = roll.strokes_per_quarter.max(1);
                    let step = u64::from(score.ticks_per_quarter / per_quarter).max(1);
                    let intervals = roll.length_ticks.div_ceil(step).max(1);
                    let stroke = |k: u64| seconds((b.tick + k * step).min(b.end_tick()));
                    RollTimes {
                        second: stroke(1),
                        penultimate: stroke(intervals - 1),
                        end: seconds(b.end_tick()),
                        starter_ends: intervals % 2 == 0,
                    }
                });
                Stroke {
                    tick: b.tick,
                    time: seconds(b.tick),
                    drum: b.drum,
                    point,
                    preferred: drum.preferred_hand,
                    fixed: b.hand.side(),
                    min_gap: drum.min_same_hand_gap_s,
                    roll,
                    reachable,
                }
            })
            .collect();
        Prep { strokes, points }
    }

    fn x(&self, i: usize) -> f64 {
        self.points[self.strokes[i].point].x
    }

    /// Whether beat `i` is at the same tick as beat `i − 1`.
    fn with_previous(&self, i: usize) -> bool {
        i > 0 && self.strokes[i - 1].tick == self.strokes[i].tick
    }

    /// Seconds from the end of beat `a` (its last roll stroke) to beat `b`, at least 0.
    fn gap(&self, a: usize, b: usize) -> f64 {
        let sa = &self.strokes[a];
        let free = sa.roll.as_ref().map_or(sa.time, |r| r.end);
        (self.strokes[b].time - free).max(0.0)
    }

    /// The hands after beat `i` is played by `side` (a roll leaves both at its point).
    fn place(&self, hands: &Hands, i: usize, side: Side) -> Hands {
        let s = &self.strokes[i];
        let mut after = *hands;
        match &s.roll {
            None => after[side as usize] = Anchor::at(s.point, s.time),
            Some(r) => {
                let last = if r.starter_ends { side } else { side.other() };
                after[last as usize] = Anchor::at(s.point, r.end);
                after[last.other() as usize] = Anchor::at(s.point, r.penultimate);
            }
        }
        after
    }

    /// How far the left hand's point is right of the right hand's (m; 0 unless both
    /// hands have played).
    fn cross_excess(&self, hands: &Hands) -> f64 {
        match (hands[0].point(), hands[1].point()) {
            (Some(l), Some(r)) => self.points[l].x - self.points[r].x,
            _ => 0.0,
        }
    }

    /// Seed 003 Alg. 3.1: preferred hands, then in-place alternation of fast triplets.
    fn simple(&self) -> Vec<Side> {
        let s = &self.strokes;
        let mut sides: Vec<Side> = s.iter().map(|b| b.fixed.unwrap_or(b.preferred)).collect();
        for i in 1..s.len().saturating_sub(1) {
            let (a, c) = (i - 1, i + 1);
            if s[i].fixed.is_none()
                && sides[a] == sides[i]
                && sides[i] == sides[c]
                && (self.gap(a, i) <= s[a].min_gap || self.gap(i, c) <= s[c].min_gap)
            {
                sides[i] = sides[i].other();
            }
        }
        sides
    }

    /// Seed 003 §4.2.2 `pair(a, b)`: −1 means a left, b right. Different drums: from
    /// their points' left–right order; the same drum: alternation from a's decided hand,
    /// if any, else no preference.
    fn pair(&self, a: usize, b: usize, decided_a: Option<Side>, params: &Params) -> f64 {
        if self.strokes[a].drum == self.strokes[b].drum {
            decided_a.map_or(0.0, Side::sign)
        } else {
            ((self.x(a) - self.x(b)) / params.pair_full_dx_m).clamp(-1.0, 1.0)
        }
    }

    /// Seed 003 §4.2.2, left to right so that the backward pair sees the decided hand.
    fn pairwise(&self, params: &Params) -> Vec<Side> {
        let n = self.strokes.len();
        let mut sides: Vec<Side> = Vec::with_capacity(n);
        for i in 0..n {
            let s = &self.strokes[i];
            if let Some(fixed) = s.fixed {
                sides.push(fixed);
                continue;
            }
            let default = s.preferred.sign();
            let blend = |pair: f64, w: f64| w * pair + (1.0 - w) * default;
            let mut values = Vec::with_capacity(2);
            if i > 0 {
                let pair = self.pair(i - 1, i, Some(sides[i - 1]), params);
                values.push(blend(-pair, params.rho.powf(self.gap(i - 1, i))));
            }
            if i + 1 < n {
                let pair = self.pair(i, i + 1, None, params);
                values.push(blend(pair, params.rho.powf(self.gap(i, i + 1))));
            }
            let value = values.iter().sum::<f64>() / values.len().max(1) as f64;
            sides.push(match value.partial_cmp(&0.0) {
                Some(std::cmp::Ordering::Less) => Side::Left,
                Some(std::cmp::Ordering::Greater) => Side::Right,
                _ => s.preferred,
            });
        }
        sides
    }

    /// Give two simultaneous beats different hands, changing only auto beats: if both are
    /// auto, the one further left gets the left hand.
    fn separate_simultaneous(&self, mut sides: Vec<Side>) -> Vec<Side> {
        for b in 1..sides.len() {
            let a = b - 1;
            if !self.with_previous(b) || sides[a] != sides[b] {
                continue;
            }
            match (self.strokes[a].fixed, self.strokes[b].fixed) {
                (None, None) => {
                    let left_first = self.x(a) <= self.x(b);
                    sides[a] = if left_first { Side::Left } else { Side::Right };
                    sides[b] = sides[a].other();
                }
                (Some(_), None) => sides[b] = sides[a].other(),
                (None, Some(_)) => sides[a] = sides[b].other(),
                (Some(_), Some(_)) => {} // Invalid score: two fixed equal hands at once.
            }
        }
        sides
    }

    /// The sides beat `i` may take, given the side of the previous beat.
    fn options(&self, i: usize, previous: Option<Side>) -> Vec<Side> {
        let s = &self.strokes[i];
        let allowed: Vec<Side> = [Side::Left, Side::Right]
            .into_iter()
            .filter(|&h| s.fixed.is_none_or(|f| f == h))
            .collect();
        let busy = previous.filter(|_| self.with_previous(i));
        let free: Vec<Side> = allowed
            .iter()
            .copied()
            .filter(|&h| Some(h) != busy)
            .collect();
        // An invalid score (two equal fixed hands at once) keeps its hands.
        if free.is_empty() { allowed } else { free }
    }
}

/// The optimal method's cost function over a prepared score.
struct Costs<'a> {
    prep: &'a Prep,
    params: &'a Params,
}

impl Costs<'_> {
    /// Seconds after which a hand's last stroke no longer affects any cost.
    fn horizon(&self) -> f64 {
        let prep = self.prep;
        let largest_gap = prep.strokes.iter().map(|s| s.min_gap).fold(0.0, f64::max);
        let (lo, hi) = prep.points.iter().fold(
            (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
            |(lo, hi), &p| (lo.min(p), hi.max(p)),
        );
        let largest_distance = if prep.points.is_empty() {
            0.0
        } else {
            (hi - lo).length()
        };
        let h = largest_gap.max(largest_distance / self.params.v_comfort);
        // A margin so that rounding never makes a dropped time matter.
        h * (1.0 + 1e-9) + 1e-9
    }

    /// Cost for a hand at `from` to strike `point` at `time` on a drum with minimum
    /// same-hand gap `min_gap`: travel, speed and repetition.
    fn travel(&self, from: Anchor, point: usize, time: f64, min_gap: f64) -> f64 {
        let p = self.params;
        let Some(start) = from.point() else {
            return 0.0;
        };
        let d = self.prep.points[start].distance(self.prep.points[point]);
        let mut cost = p.w_dist * d;
        if let Some(t0) = from.time() {
            let dt = time - t0;
            if dt <= 0.0 {
                return cost + IMPOSSIBLE_COST;
            }
            cost += p.w_speed * (d / dt - p.v_comfort).max(0.0).powi(2);
            if dt < min_gap {
                cost += p.w_rep * (min_gap / dt - 1.0).powi(2);
            }
        }
        cost
    }

    /// Cost of beat `i` played by `side` with the hands at `hands`, and the hands after.
    fn strike(&self, hands: &Hands, i: usize, side: Side) -> (f64, Hands) {
        let p = self.params;
        let s = &self.prep.strokes[i];
        let mut cost = if side == s.preferred { 0.0 } else { p.w_pref };
        if !s.reachable[side as usize] {
            cost += UNREACHABLE_COST;
        }
        cost += self.travel(hands[side as usize], s.point, s.time, s.min_gap);
        if let Some(r) = &s.roll {
            cost += self.travel(hands[side.other() as usize], s.point, r.second, s.min_gap);
        }
        let after = self.prep.place(hands, i, side);
        let excess = self.prep.cross_excess(&after);
        if excess > 0.0 {
            cost += p.w_cross * excess;
        }
        if excess > CROSSING_TOLERANCE_M {
            cost += p.w_cross_fixed;
        }
        (cost, after)
    }

    /// Total cost of a whole assignment, exactly (no state merging).
    #[cfg(test)]
    fn total(&self, sides: &[Side]) -> f64 {
        let mut hands = [Anchor::Rest; 2];
        let mut total = 0.0;
        for (i, &side) in sides.iter().enumerate() {
            let (cost, after) = self.strike(&hands, i, side);
            total += cost;
            hands = after;
        }
        total
    }

    /// The least-cost assignment by dynamic programming (see the module docs).
    fn optimal(&self) -> Vec<Side> {
        /// Side of the last beat (for simultaneous beats) and both hands' anchors.
        type State = (Option<Side>, Hands);
        let strokes = &self.prep.strokes;
        let horizon = self.horizon();
        let mut layer: Vec<(State, f64)> = vec![((None, [Anchor::Rest; 2]), 0.0)];
        // Per beat and state: (index of the previous state, side of this beat).
        let mut back: Vec<Vec<(usize, Side)>> = Vec::with_capacity(strokes.len());
        for i in 0..strokes.len() {
            let next_time = strokes.get(i + 1).map_or(f64::INFINITY, |s| s.time);
            let forget = |a: Anchor| match (a.point(), a.time()) {
                (Some(p), Some(t)) if next_time - t >= horizon => Anchor::Far(p),
                _ => a,
            };
            let mut best: BTreeMap<State, (f64, usize, Side)> = BTreeMap::new();
            for (k, &((previous, hands), so_far)) in layer.iter().enumerate() {
                for side in self.prep.options(i, previous) {
                    let (cost, after) = self.strike(&hands, i, side);
                    let candidate = (so_far + cost, k, side);
                    match best.entry((Some(side), after.map(forget))) {
                        Entry::Vacant(e) => {
                            e.insert(candidate);
                        }
                        Entry::Occupied(mut e) => {
                            if candidate.0 < e.get().0 {
                                e.insert(candidate);
                            }
                        }
                    }
                }
            }
            back.push(best.values().map(|&(_, k, side)| (k, side)).collect());
            layer = best
                .into_iter()
                .map(|(state, (cost, _, _))| (state, cost))
                .collect();
        }
        let mut k = (0..layer.len())
            .min_by(|&a, &b| layer[a].1.total_cmp(&layer[b].1))
            .unwrap_or(0);
        let mut sides = vec![Side::Left; strokes.len()];
        for (i, step) in back.iter().enumerate().rev() {
            let (previous, side) = step[k];
            sides[i] = side;
            k = previous;
        }
        sides
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::score::{Beat, ImpactLocation, Roll};

    /// Ticks in `s` seconds at the default 100 bpm and 960 ticks per quarter.
    fn ticks(s: f64) -> u64 {
        (s * 1600.0).round() as u64
    }

    fn beat(tick: u64, drum: usize) -> Beat {
        Beat::plain(tick, drum)
    }

    /// A score of auto beats at (tick, drum).
    fn score(beats: &[(u64, usize)]) -> Score {
        let mut s = Score::new("t");
        s.beats = beats.iter().map(|&(t, d)| beat(t, d)).collect();
        s
    }

    /// `count` beats `step_s` apart cycling through `drums`.
    fn sequence(drums: &[usize], count: usize, step_s: f64) -> Score {
        let beats: Vec<(u64, usize)> = (0..count)
            .map(|i| (ticks(i as f64 * step_s), drums[i % drums.len()]))
            .collect();
        score(&beats)
    }

    /// The standard kit with the 29- and 26-inch drums both preferring the right hand.
    fn crossing_kit() -> Kit {
        let mut kit = Kit::standard();
        kit.drums[1].preferred_hand = Side::Right;
        kit.drums[2].preferred_hand = Side::Right;
        kit
    }

    const METHODS: [Method; 3] = [Method::Simple, Method::Pairwise, Method::Optimal];

    fn run(s: &Score, kit: &Kit, method: Method) -> Vec<Side> {
        assert!(s.problems(kit).is_empty(), "{:?}", s.problems(kit));
        let sides = assign(s, kit, method, &Params::default());
        assert_eq!(sides.len(), s.beats.len());
        sides
    }

    fn total_cost(s: &Score, kit: &Kit, sides: &[Side]) -> f64 {
        let params = Params::default();
        let prep = Prep::new(s, kit);
        Costs {
            prep: &prep,
            params: &params,
        }
        .total(sides)
    }

    /// Fixed hands and different hands for simultaneous beats hold for every sticking.
    fn assert_rules(s: &Score, sides: &[Side]) {
        for (i, b) in s.beats.iter().enumerate() {
            if let Some(fixed) = b.hand.side() {
                assert_eq!(sides[i], fixed, "beat {i} has a fixed hand");
            }
            if i > 0 && s.beats[i - 1].tick == b.tick {
                assert_ne!(
                    sides[i - 1],
                    sides[i],
                    "beats {} and {i} are together",
                    i - 1
                );
            }
        }
    }

    /// The right hand cannot reach the far-left drum's playing spot (the left can): a
    /// fast double stroke there, which would otherwise alternate hands, stays in the left
    /// hand.
    #[test]
    fn optimal_keeps_beats_within_reach() {
        let kit = Kit::standard();
        let s = score(&[(0, 0), (ticks(0.06), 0)]);
        let prep = Prep::new(&s, &kit);
        assert_eq!(prep.strokes[0].reachable, [true, false]);
        assert_eq!(run(&s, &kit, Method::Optimal), [Side::Left, Side::Left]);
        let same_drum_elsewhere = score(&[(0, 1), (ticks(0.06), 1)]);
        assert_ne!(
            run(&same_drum_elsewhere, &kit, Method::Optimal)[0],
            run(&same_drum_elsewhere, &kit, Method::Optimal)[1],
            "within reach of both, a fast double stroke alternates"
        );
    }

    /// Every method keeps fixed hands and splits simultaneous beats, whatever the drums.
    #[test]
    fn fixed_hands_and_simultaneous_beats() {
        let mut s = score(&[
            (0, 2),
            (0, 2),
            (ticks(0.1), 0),
            (ticks(0.1), 3),
            (ticks(0.2), 3),
            (ticks(0.3), 3),
            (ticks(0.3), 1),
            (ticks(0.4), 1),
            (ticks(0.5), 0),
            (ticks(0.5), 0),
        ]);
        s.beats[2].hand = Hand::Right; // against the 32-inch drum's preference
        s.beats[4].hand = Hand::Left;
        s.beats[5].hand = Hand::Right;
        s.beats[9].hand = Hand::Left;
        for kit in [Kit::standard(), crossing_kit()] {
            for method in METHODS {
                let sides = run(&s, &kit, method);
                assert_rules(&s, &sides);
                let mut applied = s.clone();
                apply(&mut applied, &sides);
                let hands: Vec<Hand> = sides.iter().map(|&h| h.into()).collect();
                assert_eq!(
                    applied.beats.iter().map(|b| b.hand).collect::<Vec<_>>(),
                    hands
                );
            }
        }
    }

    /// Simple: fast repeats on one drum alternate hands; slow ones stay on the preferred.
    #[test]
    fn simple_alternates_only_fast_repeats() {
        let kit = Kit::standard();
        // An odd count: Alg. 3.1 only flips middles of triplets, never the last beat.
        let fast = run(&sequence(&[2], 15, 0.12), &kit, Method::Simple);
        assert!(fast.windows(2).all(|w| w[0] != w[1]), "{fast:?}");
        let slow = run(&sequence(&[2], 16, 1.0), &kit, Method::Simple);
        assert!(slow.iter().all(|&h| h == Side::Right), "{slow:?}");
    }

    /// Pairwise: simultaneous strokes on a left and a right drum take the left and right
    /// hands, even when both drums prefer the right hand and the right drum comes first.
    #[test]
    fn pairwise_splits_simultaneous_by_geometry() {
        let s = score(&[(0, 2), (0, 1), (ticks(1.0), 2), (ticks(1.0), 1)]);
        for kit in [Kit::standard(), crossing_kit()] {
            let sides = run(&s, &kit, Method::Pairwise);
            assert_eq!(sides, [Side::Right, Side::Left, Side::Right, Side::Left]);
        }
    }

    /// Pairwise: a slow sequence over all drums follows the preferred hands.
    #[test]
    fn pairwise_slow_follows_preferences() {
        let kit = Kit::standard();
        let s = sequence(&[0, 3, 1, 2, 2, 0, 3], 7, 1.5);
        let sides = run(&s, &kit, Method::Pairwise);
        let preferred: Vec<Side> = s
            .beats
            .iter()
            .map(|b| kit.drums[b.drum].preferred_hand)
            .collect();
        assert_eq!(sides, preferred);
    }

    /// Seed 003 §4.2.2's arm crossing on timpani: a fast 29-26-29 figure with both drums
    /// preferring the right hand makes the simple method cross the arms, never the optimal.
    #[test]
    fn optimal_avoids_the_simple_methods_arm_crossing() {
        let kit = crossing_kit();
        let s = sequence(&[1, 2], 12, 0.12);
        let simple = run(&s, &kit, Method::Simple);
        assert!(crossings(&s, &kit, &simple) > 0, "{simple:?}");
        let optimal = run(&s, &kit, Method::Optimal);
        assert_eq!(crossings(&s, &kit, &optimal), 0, "{optimal:?}");
        let expected: Vec<Side> = s
            .beats
            .iter()
            .map(|b| if b.drum == 1 { Side::Left } else { Side::Right })
            .collect();
        assert_eq!(optimal, expected);
        assert!(total_cost(&s, &kit, &optimal) < total_cost(&s, &kit, &simple));
    }

    /// A small deterministic pseudo-random generator for varied test scores.
    struct Lcg(u64);

    impl Lcg {
        fn below(&mut self, n: u64) -> u64 {
            self.0 = self
                .0
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (self.0 >> 33) % n
        }
    }

    /// A varied valid score of `n` beats on all drums at spot, rim and off-centre points.
    /// Plain: auto hands, gaps of 0.12–0.8 s, simultaneous strokes on different drums.
    /// Wild: also fixed hands, rolls, 0.06 s gaps and double strokes on one drum.
    fn varied(rng: &mut Lcg, n: usize, wild: bool) -> Score {
        let gaps: &[f64] = if wild {
            &[0.0, 0.06, 0.1, 0.12, 0.18, 0.25, 0.4, 0.8]
        } else {
            &[0.0, 0.12, 0.18, 0.25, 0.4, 0.8]
        };
        let locations = [
            ImpactLocation::PlayingSpot,
            ImpactLocation::Rim,
            ImpactLocation::Point {
                radius: 0.5,
                angle_deg: 40.0,
            },
        ];
        let mut s = Score::new("t");
        for i in 0..n {
            let previous = i.checked_sub(1).map(|j| s.beats[j]);
            let pair_free = previous.is_some_and(|p| p.roll.is_none())
                && (i < 2 || s.beats[i - 2].tick != s.beats[i - 1].tick);
            let gap = gaps[rng.below(gaps.len() as u64) as usize];
            let together = gap == 0.0 && pair_free;
            let tick = match previous {
                None => 0,
                Some(p) if together => p.tick,
                Some(p) => p.end_tick() + ticks(gap.max(gaps[1])),
            };
            let mut b = beat(tick, rng.below(4) as usize);
            b.location = locations[rng.below(3) as usize];
            if let Some(p) = previous.filter(|p| together && !wild && p.drum == b.drum) {
                b.drum = (p.drum + 1) % 4;
            }
            if wild && rng.below(6) == 0 {
                b.hand = [Hand::Left, Hand::Right][rng.below(2) as usize];
                if together && previous.is_some_and(|p| p.hand == b.hand) {
                    b.hand = Hand::Auto;
                }
            }
            if wild && !together && rng.below(8) == 0 {
                b.roll = Some(Roll {
                    length_ticks: 480 + 120 * rng.below(3),
                    strokes_per_quarter: 8,
                });
            }
            s.beats.push(b);
        }
        s
    }

    /// All assignments of `s` that keep fixed hands and split simultaneous beats.
    fn feasible(s: &Score) -> Vec<Vec<Side>> {
        let n = s.beats.len();
        (0..1u32 << n)
            .map(|mask| {
                (0..n)
                    .map(|i| [Side::Left, Side::Right][((mask >> i) & 1) as usize])
                    .collect::<Vec<Side>>()
            })
            .filter(|sides| {
                s.beats.iter().enumerate().all(|(i, b)| {
                    b.hand.side().is_none_or(|f| f == sides[i])
                        && (i == 0 || s.beats[i - 1].tick != b.tick || sides[i - 1] != sides[i])
                })
            })
            .collect()
    }

    /// Optimal: on varied short scores its cost equals the brute-force minimum over all
    /// 2^n assignments, and on the plain ones it never crosses the arms when some
    /// assignment does not.
    #[test]
    fn optimal_matches_brute_force() {
        let mut rng = Lcg(7);
        for round in 0..64 {
            let n = 3 + round % 8;
            let wild = round % 2 == 1;
            let s = varied(&mut rng, n, wild);
            let kit = if round % 3 == 0 {
                crossing_kit()
            } else {
                Kit::standard()
            };
            let optimal = run(&s, &kit, Method::Optimal);
            assert_rules(&s, &optimal);
            let got = total_cost(&s, &kit, &optimal);
            let all = feasible(&s);
            let least = all
                .iter()
                .map(|sides| total_cost(&s, &kit, sides))
                .fold(f64::INFINITY, f64::min);
            assert!(
                (got - least).abs() <= 1e-9 * least.max(1.0),
                "round {round}: optimal {got} vs brute force {least}"
            );
            if !wild && all.iter().any(|sides| crossings(&s, &kit, sides) == 0) {
                assert_eq!(crossings(&s, &kit, &optimal), 0, "round {round}");
            }
        }
    }

    /// Rolls take both hands: a beat at a roll's last tick goes to the hand that did not
    /// play the last roll stroke, and both hands sit at the roll's drum afterwards.
    #[test]
    fn rolls_take_both_hands() {
        let kit = Kit::standard();
        let mut s = score(&[(0, 1), (960, 1), (960 + ticks(0.1), 2)]);
        s.beats[0].roll = Some(Roll {
            length_ticks: 960,
            strokes_per_quarter: 8, // 8 intervals: the starting hand ends the roll
        });
        let sides = run(&s, &kit, Method::Optimal);
        assert_ne!(sides[1], sides[0], "{sides:?}");
        assert_eq!(crossings(&s, &kit, &sides), 0);
        assert!(total_cost(&s, &kit, &sides) < IMPOSSIBLE_COST);
    }

    /// Optimal handles a 20 000-beat score (linear time) and keeps the rules.
    #[test]
    fn optimal_runs_on_long_scores() {
        let mut rng = Lcg(11);
        let kit = Kit::standard();
        let s = varied(&mut rng, 20_000, true);
        // 95 minutes: past the length a score may have to be rendered (the only problem),
        // on purpose — the sticking itself scales further.
        let problems = s.problems(&kit);
        assert!(problems.iter().all(|p| p.place == "length"), "{problems:?}");
        let sides = assign(&s, &kit, Method::Optimal, &Params::default());
        assert_eq!(sides.len(), s.beats.len());
        assert_rules(&s, &sides);
    }

    /// The same input gives the same output, for every method.
    #[test]
    fn deterministic() {
        let mut rng = Lcg(3);
        let kit = crossing_kit();
        let s = varied(&mut rng, 300, true);
        for method in METHODS {
            assert_eq!(run(&s, &kit, method), run(&s.clone(), &kit, method));
        }
    }
}
