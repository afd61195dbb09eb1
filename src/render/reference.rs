//! The targets the simulated body follows for a whole score, made from the composition:
//! the felt ball's centre carried one ball radius above the composed tip (the database's
//! tips touch the head surface at impact), a *strike-through* dip so each stroke aims a
//! few millimetres into the head (players strike through the head, not onto it), deepest
//! a few milliseconds before the impact so the target is already rising as the felt meets
//! the head (the player lifts out of the drum rather than pressing into it), and a
//! per-hand time warp that plays each stroke earlier or later by the shift the timing
//! compensation measured.
//!
//! The warp is a list of knots per hand: each stroke holds its shift over its dip, and
//! *anchors* fix the shift at times the compensation has settled; between knots the shift
//! is interpolated linearly, outside them it is held. A stroke's knots therefore change
//! the targets only after the anchor before it, which lets the compensation settle a
//! score front to back and resume from any settled point.

use crate::body::sim::{FineSpan, FineTargets, HandTargets, Reference, sample_at};
use crate::motion::compose::Composition;
use glam::{DQuat, DVec3};
use std::ops::Range;

/// How the targets are shaped around impacts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StrikeShape {
    /// Felt ball radius, m: the tip target is raised by it.
    pub ball_radius_m: f64,
    /// Half-width of the dip around an impact, s (narrowed for close strokes).
    pub half_width_s: f64,
    /// How long before the impact the dip is deepest, s (at most half the half-width).
    pub lead_s: f64,
    /// How the grip lets the stick go around each impact.
    pub release: Release,
}

/// The grip's release around an impact (timpani pedagogy: the stick is thrown at the head
/// and allowed to rebound, the fingers closing again only once it has left): the fraction
/// of the grip's control held falls from 1 to `held` over `ramp_in_s` ending `before_s`
/// before the impact, stays there until `after_s` after it, and comes back to 1 over
/// `ramp_out_s` (raised-cosine ramps). Times in s.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Release {
    pub held: f64,
    pub ramp_in_s: f64,
    pub before_s: f64,
    pub after_s: f64,
    pub ramp_out_s: f64,
}

impl Release {
    /// The grip held firm throughout.
    pub const FIRM: Release = Release {
        held: 1.0,
        ramp_in_s: 0.0,
        before_s: 0.0,
        after_s: 0.0,
        ramp_out_s: 0.0,
    };

    /// The release the renderer plays with: the grip keeps 2 % of its control from 6 ms
    /// before the impact (let go over 4 ms before that) to 25 ms after it, firm again 25 ms
    /// later. With 2 % the grip's loop runs at 14 % of its frequency (25 Hz for the
    /// 180 Hz stick), slow beside a 5–10 ms contact: the stick rebounds as a free mallet.
    /// Closing at 15 ms left the 32-inch head, swinging back, to catch 2 of 30 ff strokes.
    pub const DEFAULT: Release = Release {
        held: 0.02,
        ramp_in_s: 0.004,
        before_s: 0.006,
        after_s: 0.025,
        ramp_out_s: 0.025,
    };

    /// The fraction of control held `x_s` after an impact (negative: before it).
    pub fn held_at(&self, x_s: f64) -> f64 {
        let ease = |u: f64| 0.5 - 0.5 * (std::f64::consts::PI * u.clamp(0.0, 1.0)).cos();
        let relaxed = if x_s < -self.before_s {
            1.0 - ease((x_s + self.before_s + self.ramp_in_s) / self.ramp_in_s.max(1e-9))
        } else if x_s > self.after_s {
            ease((x_s - self.after_s) / self.ramp_out_s.max(1e-9))
        } else {
            0.0
        };
        self.held + (1.0 - self.held) * relaxed
    }

    /// How long before and after an impact the grip is not firm, s.
    fn span_s(&self) -> (f64, f64) {
        (
            self.before_s + self.ramp_in_s,
            self.after_s + self.ramp_out_s,
        )
    }
}

/// One stroke's strike-through dip.
#[derive(Clone, Debug, PartialEq)]
struct Dip {
    /// Hand index (0 left, 1 right).
    hand: usize,
    /// Impact time from sample 0, s.
    time_s: f64,
    /// Half-width, s.
    half_s: f64,
    /// How long before the impact it is deepest, s.
    lead_s: f64,
    /// Samples it lowers.
    samples: Range<usize>,
    /// How far below the head it aims, m.
    depth_m: f64,
}

impl Dip {
    /// How far the dip lowers the target at composed time `t_s` (from sample 0), m.
    fn lowered_at(&self, t_s: f64) -> f64 {
        let x = (t_s - (self.time_s - self.lead_s)) / self.half_s;
        if x.abs() < 1.0 {
            self.depth_m * 0.5 * (1.0 + (std::f64::consts::PI * x).cos())
        } else {
            0.0
        }
    }
}

/// Fine targets ([`FineTargets`]) are written this many times per task step: at 250 Hz
/// every 0.4 ms, the rate the nested IK reads them at (every 4 steps of 10 kHz).
pub const FINE_PER_SAMPLE: usize = 10;

/// Fine targets cover each dip's samples and this much either side, s: more than the
/// compensation's largest shift, so a dip played earlier or later stays inside.
pub const FINE_MARGIN_S: f64 = 0.04;

/// The composed tips shaped for striking, before the time warp: raised by the ball
/// radius, with each stroke's dip at its current depth.
#[derive(Clone, Debug, PartialEq)]
pub struct Targets {
    rate_hz: f64,
    /// Composed tips raised by the ball radius, [left, right], m.
    raised: [Vec<DVec3>; 2],
    /// `raised` with the dips, m.
    shaped: [Vec<DVec3>; 2],
    /// One per stroke of the composition, in its order.
    dips: Vec<Dip>,
    /// Scored impacts (s from sample 0, beat), in time order.
    beats: Vec<(f64, usize)>,
    /// Where the performer looks, per sample (see `render::gaze`), m.
    gaze: Vec<DVec3>,
    /// What `gaze` was made of: the points looked at and when ([`super::gaze::looks`]),
    /// and the composition's first sample, s.
    gaze_of: (Vec<(f64, DVec3)>, f64),
    /// The trunk's turn toward far strokes, per sample ([`crate::body::lean::track`]).
    lean: Option<Vec<DQuat>>,
    /// The fraction of each hand's grip control held per sample, [left, right].
    held: [Vec<f64>; 2],
    /// Where the hands damp heads (the composition's muffles), when any do.
    hands: Option<HandTargets>,
    /// How the grip lets go around each impact.
    release: Release,
    /// Per hand, its strokes' indices in time order.
    by_hand: [Vec<usize>; 2],
    /// Per hand, the task samples (first, last) the fine targets cover, in time order.
    fine_spans: [Vec<(usize, usize)>; 2],
    /// The furthest any dip lowers the target from its impact, s.
    dip_reach_s: f64,
}

impl Targets {
    /// The targets of `comp` with every stroke aiming `depth_m` below the head.
    pub fn new(comp: &Composition, shape: &StrikeShape, depth_m: f64) -> Targets {
        Targets::after(comp, shape, depth_m, None)
    }

    /// [`Targets::new`], the gaze taken from the `earlier` targets when they were made of
    /// the same points looked at, at the same times, over the same samples (an edit that
    /// moves no stroke: a mode, a dynamic or a hand changed) — the same values, without
    /// the trigonometry of every sample (on the one-minute study 0.25 ms to copy them
    /// against 2–5 ms to make them, in an edit's first step).
    pub fn after(
        comp: &Composition,
        shape: &StrikeShape,
        depth_m: f64,
        earlier: Option<&Targets>,
    ) -> Targets {
        let rate = comp.rate_hz;
        let n = comp.len();
        let raised: [Vec<DVec3>; 2] = std::array::from_fn(|h| {
            comp.tips[h]
                .iter()
                .map(|p| *p + DVec3::Z * shape.ball_radius_m)
                .collect()
        });
        let hand_of = |s: &crate::motion::plan::PlannedStroke| {
            crate::mocap::db::SIDES
                .iter()
                .position(|&side| side == s.hand)
                .unwrap_or(0)
        };
        let dips: Vec<Dip> = comp
            .strokes
            .iter()
            .enumerate()
            .map(|(i, s)| {
                let hand = hand_of(s);
                let t = s.time_s - comp.start_s;
                let gap = comp
                    .strokes
                    .iter()
                    .enumerate()
                    .filter(|&(j, o)| j != i && hand_of(o) == hand)
                    .map(|(_, o)| (o.time_s - s.time_s).abs())
                    .fold(f64::INFINITY, f64::min);
                let half = shape.half_width_s.min(0.4 * gap);
                let lead = shape.lead_s.clamp(0.0, 0.5 * half);
                let first = (((t - lead - half) * rate).ceil().max(0.0) as usize).min(n);
                let last = ((((t - lead + half) * rate).floor().max(0.0) as usize) + 1)
                    .min(n)
                    .max(first);
                Dip {
                    hand,
                    time_s: t,
                    half_s: half,
                    lead_s: lead,
                    samples: first..last,
                    depth_m: 0.0,
                }
            })
            .collect();
        let mut beats: Vec<(f64, usize)> = comp
            .strokes
            .iter()
            .map(|s| (s.time_s - comp.start_s, s.beat))
            .collect();
        beats.sort_by(|a, b| a.0.total_cmp(&b.0));
        let held = grip_held(&dips, &shape.release, rate, n);
        let hands = hand_targets(comp);
        let gaze_of = (super::gaze::looks(comp), comp.start_s);
        let gaze = match earlier {
            Some(e) if e.gaze_of == gaze_of && e.rate_hz == rate && e.gaze.len() == n => {
                e.gaze.clone()
            }
            _ => super::gaze::gaze_points(&gaze_of.0, comp),
        };
        let mut targets = Targets {
            rate_hz: rate,
            shaped: raised.clone(),
            raised,
            dips,
            beats,
            gaze,
            gaze_of,
            lean: None,
            held,
            hands,
            release: shape.release,
            by_hand: [Vec::new(), Vec::new()],
            fine_spans: [Vec::new(), Vec::new()],
            dip_reach_s: 0.0,
        };
        targets.index_dips();
        for i in 0..targets.dips.len() {
            targets.set_depth(i, depth_m);
        }
        targets
    }

    /// Each hand's strokes in time order, the spans the fine targets cover and how far
    /// the dips reach, from the dips.
    fn index_dips(&mut self) {
        let dips = &self.dips;
        self.by_hand = std::array::from_fn(|h| {
            let mut of_hand: Vec<usize> = (0..dips.len()).filter(|&i| dips[i].hand == h).collect();
            of_hand.sort_by(|&a, &b| dips[a].time_s.total_cmp(&dips[b].time_s));
            of_hand
        });
        self.fine_spans = fine_spans(dips, &self.by_hand, self.rate_hz, self.len());
        self.dip_reach_s = dips.iter().map(|d| d.lead_s + d.half_s).fold(0.0, f64::max);
    }

    /// Where the performer looks, per sample, m.
    pub fn gaze(&self) -> &[DVec3] {
        &self.gaze
    }

    /// Samples per hand.
    pub fn len(&self) -> usize {
        self.raised[0].len()
    }

    /// Whether there are no samples.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Hand index (0 left, 1 right) of stroke `i`.
    pub fn hand(&self, i: usize) -> usize {
        self.dips[i].hand
    }

    /// How far below the head stroke `i` aims, m.
    pub fn depth(&self, i: usize) -> f64 {
        self.dips[i].depth_m
    }

    /// Aim stroke `i` `depth_m` below the head (dips of one hand never overlap).
    pub fn set_depth(&mut self, i: usize, depth_m: f64) {
        let dip = &mut self.dips[i];
        dip.depth_m = depth_m;
        let (raised, shaped) = (&self.raised[dip.hand], &mut self.shaped[dip.hand]);
        for k in dip.samples.clone() {
            shaped[k] = raised[k] - DVec3::Z * dip.lowered_at(k as f64 / self.rate_hz);
        }
    }

    /// Whether the first `k` strokes' dips are placed as in `other` (depths aside).
    pub fn same_dips(&self, other: &Targets, k: usize) -> bool {
        let placed = |d: &Dip| (d.hand, d.time_s, d.half_s, d.lead_s, d.samples.clone());
        k <= self.dips.len()
            && k <= other.dips.len()
            && self.dips[..k]
                .iter()
                .zip(&other.dips[..k])
                .all(|(a, b)| placed(a) == placed(b))
    }

    /// The two knots that hold stroke `i`'s shift over its dip and its impact: (time
    /// from sample 0, s).
    pub fn knots(&self, i: usize, shift_s: f64) -> [(f64, f64); 2] {
        let dip = &self.dips[i];
        [
            (dip.time_s - dip.lead_s - dip.half_s, shift_s),
            (dip.time_s + dip.half_s, shift_s),
        ]
    }

    /// An empty reference of this length to [`write`](Targets::write) into.
    pub fn blank(&self) -> Reference {
        Reference {
            rate_hz: self.rate_hz,
            tips: std::array::from_fn(|h| self.shaped[h].clone()),
            poses: None,
            beats: self.beats.clone(),
            gaze: Some(self.gaze.clone()),
            grip: Some(self.held.clone()),
            hands: self.hands.clone(),
            lean: self.lean.clone(),
            fine: Some(self.blank_fine()),
        }
    }

    /// Fine targets over [`Self::fine_spans`] with no warp (the task samples' values on
    /// the line between them, to be [`write`](Targets::write)n).
    fn blank_fine(&self) -> FineTargets {
        let per = FINE_PER_SAMPLE;
        let spans = std::array::from_fn(|h| {
            let line = |first: usize, last: usize| {
                let at = |j: usize| first as f64 + j as f64 / per as f64;
                let values = (last - first) * per + 1;
                (
                    (0..values)
                        .map(|j| sample_at(&self.shaped[h], at(j), DVec3::lerp))
                        .collect(),
                    (0..values)
                        .map(|j| sample_at(&self.held[h], at(j), |a, b, u| a + (b - a) * u))
                        .collect(),
                )
            };
            self.fine_spans[h]
                .iter()
                .map(|&(first, last)| {
                    let (tips, grip) = line(first, last);
                    FineSpan { first, tips, grip }
                })
                .collect()
        });
        FineTargets {
            per_sample: per,
            spans,
        }
    }

    /// Hand `h`'s tip target and the fraction of its grip held at fractional composed
    /// sample `x`: the composed tip (raised) there less any dip, and the least grip any
    /// of its impacts leaves (as [`grip_held`], but at any time, not only on samples).
    fn at(&self, h: usize, x: f64) -> (DVec3, f64) {
        let t = x / self.rate_hz;
        let (before, after) = self.release.span_s();
        let of_hand = &self.by_hand[h];
        // Dips and releases reach at most this far from their impact.
        let reach = before.max(after).max(self.dip_reach_s);
        let from = of_hand.partition_point(|&i| self.dips[i].time_s < t - reach);
        let mut lowered = 0.0;
        let mut held = 1.0f64;
        for &i in of_hand[from..]
            .iter()
            .take_while(|&&i| self.dips[i].time_s <= t + reach)
        {
            let dip = &self.dips[i];
            lowered += dip.lowered_at(t);
            let since = t - dip.time_s;
            if (-before..=after).contains(&since) {
                held = held.min(self.release.held_at(since));
            }
        }
        (
            sample_at(&self.raised[h], x, DVec3::lerp) - DVec3::Z * lowered,
            held,
        )
    }

    /// Lean the trunk toward the composition's far strokes for a player of `skeleton`
    /// ([`crate::body::lean::track`] of the composed tips, before any warp: a lean is
    /// held over 0.3 s, far longer than a stroke's 35 ms shift).
    pub fn lean_for(&mut self, skeleton: &crate::body::Skeleton, comp: &Composition) {
        self.lean = crate::body::lean::track(skeleton, &comp.tips, comp.rate_hz);
    }

    /// The trunk's turn toward far strokes at sample `k` (none: the identity).
    pub fn lean_at(&self, k: usize) -> DQuat {
        self.lean
            .as_ref()
            .and_then(|lean| lean.get(k).copied())
            .unwrap_or(DQuat::IDENTITY)
    }

    /// Write samples `range` of `reference` (made by [`blank`](Targets::blank)) through
    /// `warp`: sample k at time t takes the shaped tip at t + shift(t), and so do the
    /// fine targets from sample `range.start` to the last one.
    pub fn write(&self, warp: &Warp, reference: &mut Reference, range: Range<usize>) {
        self.write_samples(warp, reference, range, true);
    }

    /// [`Self::write`] without the fine targets: what a performance resumed at a saved
    /// state needs before it (the task samples are shown and exported; the fine targets
    /// there are never read again, and writing them cost an edit about 1 ms).
    pub fn write_task_samples(&self, warp: &Warp, reference: &mut Reference, range: Range<usize>) {
        self.write_samples(warp, reference, range, false);
    }

    fn write_samples(
        &self,
        warp: &Warp,
        reference: &mut Reference,
        range: Range<usize>,
        fine: bool,
    ) {
        let rate = self.rate_hz;
        let end = range.end.min(self.len());
        for h in 0..2 {
            let knots = &warp.knots[h];
            // The first knot after the time: found once, then walked forward.
            let mut next = knots.partition_point(|&(u, _)| u <= range.start as f64 / rate);
            for k in range.start..end {
                let t = k as f64 / rate;
                while next < knots.len() && knots[next].0 <= t {
                    next += 1;
                }
                let x = (t + shift_between(knots, next, t)) * rate;
                let (tip, held) = self.at(h, x);
                reference.tips[h][k] = tip;
                if let Some(grip) = &mut reference.grip {
                    grip[h][k] = held;
                }
            }
            if let Some(targets) = reference.fine.as_mut().filter(|_| fine) {
                self.write_fine(h, knots, targets, range.start..end);
            }
        }
    }

    /// Hand `h`'s fine targets through `knots` over task samples `range` (from each one's
    /// time to the next's, the last one's own value included).
    fn write_fine(
        &self,
        h: usize,
        knots: &[(f64, f64)],
        fine: &mut FineTargets,
        range: Range<usize>,
    ) {
        let (rate, per) = (self.rate_hz, fine.per_sample);
        if range.is_empty() {
            return;
        }
        for span in &mut fine.spans[h] {
            let last = span.first + (span.tips.len().saturating_sub(1)) / per;
            if last < range.start || span.first >= range.end {
                continue;
            }
            let from = (range.start.max(span.first) - span.first) * per;
            let to = ((range.end - 1).min(last) - span.first) * per;
            let t0 = (span.first as f64 + from as f64 / per as f64) / rate;
            let mut next = knots.partition_point(|&(u, _)| u <= t0);
            for j in from..=to {
                let t = (span.first as f64 + j as f64 / per as f64) / rate;
                while next < knots.len() && knots[next].0 <= t {
                    next += 1;
                }
                let (tip, held) = self.at(h, (t + shift_between(knots, next, t)) * rate);
                span.tips[j] = tip;
                if let Some(g) = span.grip.get_mut(j) {
                    *g = held;
                }
            }
        }
    }

    /// The whole reference through `warp`.
    pub fn reference(&self, warp: &Warp) -> Reference {
        let mut reference = self.blank();
        self.write(warp, &mut reference, 0..self.len());
        reference
    }
}

/// Per hand, the shift (s; positive plays earlier) at knots (time from sample 0, shift)
/// in time order: linear between knots, held before the first and after the last.
#[derive(Clone, Debug, PartialEq)]
pub struct Warp {
    pub knots: [Vec<(f64, f64)>; 2],
}

impl Default for Warp {
    /// No shift, anchored at time 0.
    fn default() -> Self {
        Warp {
            knots: [vec![(0.0, 0.0)], vec![(0.0, 0.0)]],
        }
    }
}

impl Warp {
    /// Knots per hand: what [`truncate`](Warp::truncate) goes back to.
    pub fn lens(&self) -> [usize; 2] {
        [self.knots[0].len(), self.knots[1].len()]
    }

    /// Drop knots added since `lens`.
    pub fn truncate(&mut self, lens: [usize; 2]) {
        for (knots, len) in self.knots.iter_mut().zip(lens) {
            knots.truncate(len);
        }
    }

    /// The shift of `hand` after its last knot, s.
    pub fn held(&self, hand: usize) -> f64 {
        self.knots[hand].last().map_or(0.0, |k| k.1)
    }

    /// The furthest target sample that reference samples `0..=k` (at `rate_hz`) read
    /// through this warp cut to its first `lens` knots per hand (what a saved state's
    /// warp was), counting the next sample the interpolation reads; shifts are within
    /// ±`max_shift_s`, so only the samples from 2·`max_shift_s` before `k` can read
    /// furthest.
    pub fn reads_through(
        &self,
        lens: [usize; 2],
        k: usize,
        rate_hz: f64,
        max_shift_s: f64,
    ) -> usize {
        let from = k.saturating_sub((2.0 * max_shift_s * rate_hz).ceil() as usize);
        let mut furthest = k;
        for (knots, len) in self.knots.iter().zip(lens) {
            let knots = &knots[..len.min(knots.len())];
            for j in from..=k {
                let t = j as f64 / rate_hz;
                let next = knots.partition_point(|&(u, _)| u <= t);
                let x = (t + shift_between(knots, next, t)) * rate_hz;
                furthest = furthest.max(x.floor().max(0.0) as usize + 1);
            }
        }
        furthest
    }

    /// Add a knot to `hand` (at or after its last one).
    pub fn push(&mut self, hand: usize, knot: (f64, f64)) {
        debug_assert!(self.knots[hand].last().is_none_or(|k| k.0 <= knot.0));
        self.knots[hand].push(knot);
    }

    /// Hold every hand's shift up to time `t_s` (later knots change nothing before it).
    pub fn anchor(&mut self, t_s: f64) {
        for h in 0..2 {
            if self.knots[h].last().is_none_or(|k| k.0 < t_s) {
                let held = self.held(h);
                self.knots[h].push((t_s, held));
            }
        }
    }
}

/// Per hand and sample, the fraction of the grip's control held: the least over that
/// hand's strokes of [`Release::held_at`] (close strokes' releases merge).
fn grip_held(dips: &[Dip], release: &Release, rate: f64, n: usize) -> [Vec<f64>; 2] {
    let mut held: [Vec<f64>; 2] = [vec![1.0; n], vec![1.0; n]];
    let (before, after) = release.span_s();
    for dip in dips {
        let first = ((dip.time_s - before) * rate).floor().max(0.0) as usize;
        let last = (((dip.time_s + after) * rate).ceil().max(0.0) as usize).min(n);
        for (k, h) in held[dip.hand].iter_mut().enumerate().take(last).skip(first) {
            *h = (*h).min(release.held_at(k as f64 / rate - dip.time_s));
        }
    }
    held
}

/// Per hand, the task samples (first, last) within [`FINE_MARGIN_S`] of a dip of its
/// strokes (`by_hand`: each hand's strokes in time order), overlapping ones merged, over
/// `n` samples at `rate` Hz.
fn fine_spans(
    dips: &[Dip],
    by_hand: &[Vec<usize>; 2],
    rate: f64,
    n: usize,
) -> [Vec<(usize, usize)>; 2] {
    let margin = (FINE_MARGIN_S * rate).ceil() as usize + 1;
    std::array::from_fn(|h| {
        let mut spans: Vec<(usize, usize)> = Vec::new();
        for &i in &by_hand[h] {
            if n < 2 {
                break;
            }
            let dip = &dips[i];
            let first = dip.samples.start.saturating_sub(margin).min(n - 2);
            let last = (dip.samples.end + margin).min(n - 1).max(first + 1);
            match spans.last_mut() {
                Some(span) if first <= span.1 => span.1 = span.1.max(last),
                _ => spans.push((first, last)),
            }
        }
        spans
    })
}

/// The shift at time `t_s` between `knots[next - 1]` and `knots[next]` (`next`: the
/// first knot after `t_s`), held before the first knot and after the last, s.
fn shift_between(knots: &[(f64, f64)], next: usize, t_s: f64) -> f64 {
    match next {
        0 => knots.first().map_or(0.0, |p| p.1),
        i if i == knots.len() => knots[i - 1].1,
        i => {
            let ((t0, s0), (t1, s1)) = (knots[i - 1], knots[i]);
            s0 + (s1 - s0) * (t_s - t0) / (t1 - t0)
        }
    }
}

/// The hands' targets of the composition's muffles: per sample, the weight of the muffle
/// under way (none overlap for one hand) and its hand point; `None` without muffles.
fn hand_targets(comp: &Composition) -> Option<HandTargets> {
    let muffles = &comp.muffles.played;
    if muffles.is_empty() {
        return None;
    }
    let mut weight: [Vec<f64>; 2] = std::array::from_fn(|_| vec![0.0; comp.len()]);
    let mut points: [Vec<DVec3>; 2] = std::array::from_fn(|_| vec![DVec3::ZERO; comp.len()]);
    // The samples from one before the muffle leaves to one after it is back.
    let sample = |t: f64| ((t - comp.start_s) * comp.rate_hz).max(0.0) as usize;
    for m in muffles {
        let h = crate::mocap::db::side_index(m.hand);
        let last = (sample(m.back_s) + 2).min(comp.len());
        for k in sample(m.leave_s).saturating_sub(1).min(last)..last {
            let t = comp.time(k);
            weight[h][k] = m.weight(t);
            points[h][k] = m.hand_at(t);
        }
    }
    Some(HandTargets { weight, points })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn targets(n: usize) -> Targets {
        let line: Vec<DVec3> = (0..n).map(|k| DVec3::new(k as f64, 0.0, 1.0)).collect();
        Targets {
            rate_hz: 1.0,
            raised: [line.clone(), line.clone()],
            shaped: [line.clone(), line],
            dips: Vec::new(),
            beats: Vec::new(),
            gaze: Vec::new(),
            gaze_of: (Vec::new(), 0.0),
            lean: None,
            held: [vec![1.0; n], vec![1.0; n]],
            hands: None,
            release: Release::FIRM,
            by_hand: [Vec::new(), Vec::new()],
            fine_spans: [Vec::new(), Vec::new()],
            dip_reach_s: 0.0,
        }
    }

    /// The warp holds before its first knot and after its last and interpolates between.
    #[test]
    fn warp_interpolates_and_holds() {
        let t = targets(10);
        let mut warp = Warp::default();
        warp.push(0, (4.0, 2.0));
        warp.anchor(6.0);
        let r = t.reference(&warp);
        let x: Vec<f64> = r.tips[0].iter().map(|p| p.x).collect();
        // Shift 0 at 0, 1 at 2, 2 from 4 on (clamped at the end).
        assert_eq!(x[0], 0.0);
        assert_eq!(x[2], 3.0);
        assert_eq!(x[5], 7.0);
        assert_eq!(x[9], 9.0);
        // The other hand is anchored at 0 and 6 with no shift.
        assert!(r.tips[1].iter().enumerate().all(|(k, p)| p.x == k as f64));
    }

    /// What samples up to k read through a warp: k and the next one without a shift, the
    /// shifted sample and the next one with it, the most of both hands and of the samples
    /// before k that a falling shift makes read further; knots past `lens` are not read.
    #[test]
    fn reads_through_follows_the_shift_the_warp_had() {
        let rate = 1.0;
        let mut warp = Warp::default();
        assert_eq!(warp.reads_through(warp.lens(), 5, rate, 3.0), 6);
        // Hand 1: shift 2 held from time 4 (rising from 0 at time 0).
        warp.push(1, (4.0, 2.0));
        assert_eq!(warp.reads_through(warp.lens(), 6, rate, 3.0), 9);
        // Cut to the knots before that one: no shift.
        assert_eq!(warp.reads_through([1, 1], 6, rate, 3.0), 7);
        // Hand 0: shift 3 at time 5 falling to 0 at time 6: sample 5 reads 8, further
        // than sample 6 reads (6 on hand 0, 8 on hand 1).
        warp.push(0, (5.0, 3.0));
        warp.push(0, (6.0, 0.0));
        assert_eq!(warp.reads_through(warp.lens(), 6, rate, 3.0), 9);
        warp.push(1, (6.0, 0.0));
        assert_eq!(warp.reads_through(warp.lens(), 6, rate, 3.0), 9);
        assert_eq!(warp.reads_through(warp.lens(), 8, rate, 3.0), 9);
    }

    /// Writing a range equals the same samples of a whole write.
    #[test]
    fn range_writes_match_whole() {
        let t = targets(40);
        let mut warp = Warp::default();
        warp.push(1, (10.0, 0.5));
        warp.push(1, (20.0, -1.5));
        let whole = t.reference(&warp);
        let mut part = t.blank();
        t.write(&warp, &mut part, 13..27);
        assert_eq!(whole.tips[1][13..27], part.tips[1][13..27]);
    }

    /// A dip played a fraction of a task step earlier or later reaches the same depth in
    /// the fine targets the nested IK reads, where the task samples alone cut it by up to
    /// a seventh; and a write of part of the score gives the fine targets of a whole one.
    #[test]
    fn fine_targets_keep_a_dip_whole_at_any_phase() {
        let mut t = targets(100);
        t.rate_hz = 250.0;
        // Deepest at 0.196 s, on sample 49, 20 mm below the raised tip (z = 1 m).
        t.dips = vec![dip(1, (0.2, 0.008, 0.004), 47..52)];
        t.index_dips();
        t.set_depth(0, 0.02);
        let lowest = |points: &mut dyn Iterator<Item = &DVec3>| {
            points.map(|p| p.z).fold(f64::INFINITY, f64::min)
        };
        for shift in [0.0, 0.0013, 0.002, -0.0027] {
            let mut warp = Warp::default();
            warp.push(1, (0.15, shift));
            warp.push(1, (0.25, shift));
            let r = t.reference(&warp);
            let fine = r.fine.as_ref().expect("fine targets");
            let fine_lowest = lowest(&mut fine.spans[1].iter().flat_map(|s| s.tips.iter()));
            assert!((fine_lowest - 0.98).abs() < 1e-4, "{shift}: {fine_lowest}");
            let sampled = lowest(&mut r.tips[1].iter());
            if shift == 0.002 {
                // Half a step off the samples: they straddle the deepest point 2 ms
                // either side, 0.85 of the depth.
                assert!(sampled > 0.9825, "{sampled}");
            }
            assert!(fine.spans[0].is_empty() && fine.spans[1].len() == 1);
            // A part written over a blank is the whole's over that part.
            let mut part = t.blank();
            t.write(&warp, &mut part, 45..55);
            let (whole, part) = (&fine.spans[1][0], &part.fine.unwrap().spans[1][0]);
            let per = FINE_PER_SAMPLE;
            let covered = (45 - whole.first) * per..=(54 - whole.first) * per;
            assert_eq!(whole.tips[covered.clone()], part.tips[covered.clone()]);
            assert_eq!(whole.grip[covered.clone()], part.grip[covered]);
        }
    }

    /// The release lets go before the impact, holds through the contact and closes
    /// again smoothly; the grip is firm away from impacts.
    #[test]
    fn release_holds_through_the_contact() {
        let r = Release::DEFAULT;
        assert_eq!(r.held_at(-0.1), 1.0);
        assert_eq!(r.held_at(0.1), 1.0);
        for x in [-0.006, -0.003, 0.0, 0.008, 0.025] {
            assert!((r.held_at(x) - r.held).abs() < 1e-12, "{x}");
        }
        // Halfway down each ramp, halfway between firm and relaxed.
        let mid = 0.5 * (1.0 + r.held);
        assert!((r.held_at(-0.008) - mid).abs() < 1e-9);
        assert!((r.held_at(0.0375) - mid).abs() < 1e-9);
        assert_eq!(Release::FIRM.held_at(0.0), 1.0);
    }

    /// A dip of `hand` at (time, half-width, lead), s, over `samples`, not yet lowered.
    fn dip(hand: usize, (time_s, half_s, lead_s): (f64, f64, f64), samples: Range<usize>) -> Dip {
        Dip {
            hand,
            time_s,
            half_s,
            lead_s,
            samples,
            depth_m: 0.0,
        }
    }

    /// A dip is deepest its lead before the impact (the target already rising as the felt
    /// meets the head), holds its depth there and is back at the raised tip a half-width
    /// either side; the knots hold the shift from the dip's start to past the impact.
    #[test]
    fn dip_is_deepest_its_lead_before_the_impact() {
        let mut t = targets(100);
        t.rate_hz = 1000.0;
        t.dips = vec![dip(0, (0.050, 0.008, 0.004), 38..55)];
        t.index_dips();
        t.set_depth(0, 0.01);
        let z: Vec<f64> = t.shaped[0].iter().map(|p| p.z).collect();
        let deepest = (0..100).min_by(|&a, &b| z[a].total_cmp(&z[b])).unwrap();
        assert_eq!(deepest, 46);
        assert!((z[46] - 0.99).abs() < 1e-12, "{}", z[46]);
        assert_eq!(z[38], 1.0);
        assert_eq!(z[54], 1.0);
        // At the impact it has risen halfway back.
        assert!((z[50] - 0.995).abs() < 1e-9, "{}", z[50]);
        let [(start, _), (end, _)] = t.knots(0, 0.002);
        assert!(
            (start - 0.038).abs() < 1e-12 && end > 0.050,
            "{start} {end}"
        );
    }

    /// Each hand's grip is released around its own strokes only, through the warp.
    #[test]
    fn grip_follows_each_hands_strokes() {
        let mut t = targets(100);
        t.rate_hz = 250.0;
        t.dips = vec![dip(1, (0.2, 0.012, 0.0), 47..54)];
        t.held = grip_held(&t.dips, &Release::DEFAULT, 250.0, 100);
        t.release = Release::DEFAULT;
        t.index_dips();
        assert!(t.held[0].iter().all(|&h| h == 1.0));
        assert_eq!(t.held[1][50], Release::DEFAULT.held);
        assert_eq!(t.held[1][0], 1.0);
        // Played 8 ms earlier, the release comes 2 samples earlier.
        let mut warp = Warp::default();
        warp.push(1, (0.19, 0.008));
        warp.push(1, (0.21, 0.008));
        let r = t.reference(&warp);
        let grip = r.grip.unwrap();
        assert_eq!(grip[1][48], t.held[1][50]);
        assert_eq!(grip[1][40], t.held[1][42]);
    }
}
