//! Strikes on the beat, settled front to back. The simulated body lags its
//! targets, so each stroke's target is played earlier by however late its contact was,
//! and aims deeper or shallower until its peak force meets its dynamic's. Strokes closer
//! than [`CLUSTER_GAP_S`] (either hand) are settled together: from a saved state before
//! the cluster, the body and the drums are simulated a little past its last stroke, the
//! contacts measured, the cluster's shifts and depths corrected and the span simulated
//! again (from the latest state the attempt before saved that the corrected targets leave
//! unchanged), a few times (not once more when a correction would only repeat an attempt);
//! the best attempt is kept (fewest strokes missed, then re-contacts —
//! the stick falling back on a head —, then contacts out of time, forces far off their
//! aim, contacts pressed too long, forces a little off, then the worst timing) and the
//! performance moves on. Each
//! cluster starts from what its predecessors' contacts say they should have had (same
//! hand, mode, dynamic and spot, else the nearest kind; across dynamics by the line of
//! depth against force aim), so repeated material settles at once.
//!
//! Every cluster's start and end is a [`Commit`]: the performance can rewind there and
//! resume with a changed score — bit for bit what a whole rendering of it would give, as long as
//! nothing before the commit changed (the editor's re-simulation after an edit).

use super::reference::{Targets, Warp};
use super::strikes;
use crate::body::sim::{Checkpoint, Environment, Reference, SimError, Simulator};
use crate::drum::{DrumCheckpoint, DrumSet};
use crate::motion::plan::PlannedStroke;
use glam::DVec3;
use std::ops::Range;
use std::time::{Duration, Instant};

/// Strokes closer together than this, s, are settled together.
pub const CLUSTER_GAP_S: f64 = 0.09;
/// Timing errors within this of a tolerance, s, are within it: contact times are whole
/// contact steps and beat times any time, so a contact 1.5 ms off its beat measured
/// 0.0015000000000000568 s off and was retried against a 1.5 ms tolerance.
const TIME_ROUNDING_S: f64 = 1e-9;
/// How far past a cluster's last stroke its attempts simulate, s.
const LOOKAHEAD_S: f64 = 0.035;
/// The most a stroke's target is played earlier or later, s (with the gap and the
/// look-ahead, it keeps the next cluster's dips out of a cluster's targets).
const MAX_SHIFT_S: f64 = 0.035;
// A dip shifted by the most stays within its fine targets.
const _: () = assert!(MAX_SHIFT_S < super::reference::FINE_MARGIN_S);
/// A contact weaker than this fraction of its stroke's aimed force is a graze, ranked with
/// a stroke that did not sound when the compensation picks its best attempt.
const GRAZE_FRACTION: f64 = 0.25;
/// The shallowest a stroke aims below the head, m.
const MIN_DEPTH_M: f64 = 0.002;
/// The deepest a stroke aims below the head, m.
const MAX_DEPTH_M: f64 = 0.06;
/// A stroke off its aimed force by more than this fraction is far off: its cluster gets
/// more attempts.
const FAR_FRACTION: f64 = 0.15;
/// How much shallower a stroke on its force aims when its contact lasted too long.
const PRESSED_DEPTH: f64 = 0.85;
/// The shift moves to a cluster's over at most this long before its first dip, s.
const TRANSITION_S: f64 = 0.06;
/// Placements of a cluster whose shifts and depths all differ by less than these (s, m)
/// are the same attempt: settling stops rather than go round a cycle (a stroke pressed at
/// the deepest aim and too weak one step shallower).
const REPEAT_SHIFT_S: f64 = 1e-4;
const REPEAT_DEPTH_M: f64 = 1e-4;
/// Impacts on one drum closer than this, m, strike the same spot of its head (which
/// gives as much at one spot as at the other).
const SAME_SPOT_M: f64 = 0.03;
/// A stroke starts from the mean of what this many of the latest strokes most like it
/// suggest.
const WARM_FROM: usize = 2;
/// Strokes alike in all but the dynamic (of one hand and mode) set a depth by the line
/// through the latest this many of them (force aim, depth).
const DEPTH_LINE_FROM: usize = 8;
/// Their force aims must span at least this, N, for a line.
const DEPTH_LINE_SPAN_N: f64 = 5.0;

/// Along an attempt, a state is saved every this many task-rate samples (40 ms), for the
/// next attempt to resume from.
const ATTEMPT_SAVE_EVERY: usize = 10;

/// The targets an attempt followed over its span (what [`Targets::write`] writes: the
/// tips and the grip).
struct Followed {
    from: usize,
    tips: [Vec<DVec3>; 2],
    grip: [Vec<f64>; 2],
    /// The fine targets between those samples, per hand and sample of the span.
    fine: [Vec<Option<FineStep>>; 2],
}

/// The fine tip and grip targets over one task step (see [`fine_step`]).
type FineStep = (Vec<DVec3>, Vec<f64>);

impl Followed {
    /// `reference`'s targets over `span`.
    fn of(reference: &Reference, span: Range<usize>) -> Followed {
        Followed {
            from: span.start,
            tips: std::array::from_fn(|h| reference.tips[h][span.clone()].to_vec()),
            grip: std::array::from_fn(|h| {
                reference
                    .grip
                    .as_ref()
                    .map_or_else(Vec::new, |g| g[h][span.clone()].to_vec())
            }),
            fine: std::array::from_fn(|h| {
                span.clone()
                    .map(|k| fine_step(reference, h, k).map(|(t, g)| (t.to_vec(), g.to_vec())))
                    .collect()
            }),
        }
    }

    /// The first sample of `span` where `reference` differs from these targets (the span's
    /// end when it does not; any sample before where these begin counts as changed).
    fn first_change(&self, reference: &Reference, span: Range<usize>) -> usize {
        let differs = |k: usize| {
            let Some(i) = k.checked_sub(self.from) else {
                return true;
            };
            (0..2).any(|h| {
                self.tips[h].get(i) != Some(&reference.tips[h][k])
                    || reference
                        .grip
                        .as_ref()
                        .is_some_and(|g| self.grip[h].get(i) != Some(&g[h][k]))
                    || self.fine[h].get(i).is_none_or(|followed| {
                        followed.as_ref().map(|(t, g)| (&t[..], &g[..]))
                            != fine_step(reference, h, k)
                    })
            })
        };
        let end = span.end;
        span.into_iter().find(|&k| differs(k)).unwrap_or(end)
    }
}

/// `reference`'s fine targets of hand `h` over the task step ending at sample `k`.
fn fine_step(reference: &Reference, h: usize, k: usize) -> Option<(&[DVec3], &[f64])> {
    reference.fine.as_ref().and_then(|f| f.step(h, k))
}

/// The depth (m) at force aim `aim` (N) on the least-squares line through `points`
/// (force aim, depth), when their aims span [`DEPTH_LINE_SPAN_N`] and deeper aims
/// strike harder on it; `None` otherwise (strokes of one dynamic only).
fn depth_line(points: &[(f64, f64)], aim: f64) -> Option<f64> {
    let (lo, hi) = points
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p.0), hi.max(p.0))
        });
    let line = crate::base::stats::least_squares_line(points);
    (hi - lo >= DEPTH_LINE_SPAN_N && line.slope > 0.0).then(|| line.at(aim))
}

/// Within a lead-in, a state is saved every this many seconds (so an edit there resumes
/// close to it).
pub const LEAD_COMMIT_EVERY_S: f64 = 0.05;

/// What each stroke aims for and when a cluster is settled.
#[derive(Clone, Debug, PartialEq)]
pub struct Aims {
    /// Peak contact force aimed at per stroke, N.
    pub force_n: Vec<f64>,
    /// A stroke's force counts as met within this fraction of its aim.
    pub force_tolerance: f64,
    /// A cluster is settled once every contact is this close to its time, s, and every
    /// force met...
    pub tolerance_s: f64,
    /// ...or, from attempt `settle_attempts` on, every contact this close, s...
    pub acceptable_s: f64,
    pub settle_attempts: usize,
    /// ...or after this many attempts (the best is kept).
    pub max_attempts: usize,
    /// Depth of a stroke with no settled predecessor, m.
    pub first_depth_m: f64,
    /// A contact longer than this, s, with a mass behind it well above the free tip's
    /// ([`pressed`]) is the hand pressing the stick into the head: the stroke aims
    /// shallower and its attempt ranks below one without.
    pub max_contact_s: f64,
    /// The stick tip's effective mass when nothing holds it into the head, kg.
    pub free_tip_mass_kg: f64,
}

/// A contact pressed by the arm has more than this many times the free tip's mass behind it.
const PRESSED_MASS_RATIO: f64 = 1.2;

/// The mass that met the head in `contact`, kg: a half-sine force of peak F over τ that
/// reverses a mass m arriving at speed v has m = F·τ/(π·v). A free stick gives about its
/// tip's effective mass, one the arm presses into the head much more.
pub fn contact_mass_kg(contact: &crate::drum::ContactEvent) -> f64 {
    contact.peak_force_n * contact.duration_s()
        / (std::f64::consts::PI * contact.impact_speed_mps.max(0.5))
}

/// Whether `contact` lasted too long because the arm pressed the stick into the head. A
/// free stroke on a slack head lasts π·√(m/k) (the 32-inch drum in D2: about 8.5–8.9 ms)
/// whatever the aim: no depth makes it shorter, so it is not corrected for.
fn pressed(contact: &crate::drum::ContactEvent, aims: &Aims) -> bool {
    contact.duration_s() > aims.max_contact_s
        && contact_mass_kg(contact) > PRESSED_MASS_RATIO * aims.free_tip_mass_kg
}

/// A cluster's start or end, or a point in a lead-in: a state the performance can resume
/// from.
#[derive(Clone, Debug)]
pub struct Commit {
    /// Strokes settled before it.
    pub strokes: usize,
    /// Task-rate samples simulated before it.
    pub samples: usize,
    /// In or at the end of a lead-in (a cluster's start), the samples simulated before
    /// the lead-in and at its end; `None` at a cluster's end.
    lead: Option<(usize, usize)>,
    sim: Checkpoint,
    drums: DrumCheckpoint,
    warp: [usize; 2],
}

/// The drums as the simulated body meets them, in score time, timed, with progress.
pub struct Stage<'a> {
    /// Score time of the reference's sample 0, s.
    pub start_s: f64,
    /// Wall time spent in the drums so far, estimated from every
    /// [`DRUM_TIMING_EVERY`]th step (reading the clock twice a step cost ~1 % of a
    /// render).
    pub drum_time: Duration,
    /// Told the fraction of the score simulated; `false` cancels.
    pub report: &'a mut dyn FnMut(f64) -> bool,
    /// Shown the performance each time a cluster is settled: everything it has simulated
    /// is final then (later attempts rewind no further than the next cluster's lead-in);
    /// `true` when it is the last this run settles (it goes on only to its horizon).
    pub settled: &'a mut dyn FnMut(&Performance, bool),
}

/// The drums' wall time is read on one step in this many (by the drums' own step count:
/// prime, so the sample is not in step with the membrane frames, whose catch-up makes
/// every [`crate::drum::set::MEMBRANE_FRAME_STEPS`]th step dearer).
const DRUM_TIMING_EVERY: u64 = 17;

struct Meeting<'a, 'b> {
    drums: &'a mut DrumSet,
    stage: &'a mut Stage<'b>,
}

impl Environment for Meeting<'_, '_> {
    fn tip_forces(&mut self, time_s: f64, tips: [(DVec3, DVec3); 2]) -> [DVec3; 2] {
        let stage = &mut *self.stage;
        if !self.drums.steps_taken().is_multiple_of(DRUM_TIMING_EVERY) {
            return self.drums.step(stage.start_s + time_s, tips);
        }
        let began = Instant::now();
        let forces = self.drums.step(stage.start_s + time_s, tips);
        stage.drum_time += began.elapsed() * DRUM_TIMING_EVERY as u32;
        forces
    }

    fn progress(&mut self, done: usize, total: usize) -> bool {
        !done.is_multiple_of(64) || (self.stage.report)(done as f64 / total.max(1) as f64)
    }
}

/// A performance of a composition, settled up to some stroke.
#[derive(Clone, Debug)]
pub struct Performance {
    pub targets: Targets,
    pub warp: Warp,
    /// The targets followed so far (written as far as simulated, plus one sample).
    pub reference: Reference,
    pub sim: Simulator,
    pub drums: DrumSet,
    /// Per stroke, how much earlier its target is played, s.
    pub shift_s: Vec<f64>,
    /// Per settled stroke, the shift and depth (s, m) its kept attempt's contact says
    /// it should have had: what a stroke like it starts from.
    pub suggested: Vec<(f64, f64)>,
    /// Strokes settled.
    pub settled: usize,
    /// Each settled cluster's start.
    pub commits: Vec<Commit>,
    /// Simulation attempts over clusters, and task-rate samples simulated in all.
    pub attempts: usize,
    pub simulated_samples: usize,
    /// Clusters settled (since the start or resume) by the attempts they took: entry n
    /// counts those that took n + 1.
    pub attempts_per_cluster: Vec<usize>,
    /// Resumed within a lead-in: where that lead-in began (samples).
    lead_from: Option<usize>,
}

impl Performance {
    /// A performance of `targets` about to start, `sim` and `drums` at rest.
    pub fn new(targets: Targets, sim: Simulator, drums: DrumSet, strokes: usize) -> Self {
        let reference = targets.blank();
        Performance {
            targets,
            warp: Warp::default(),
            reference,
            sim,
            drums,
            shift_s: vec![0.0; strokes],
            suggested: vec![(0.0, 0.0); strokes],
            settled: 0,
            commits: Vec::new(),
            attempts: 0,
            simulated_samples: 0,
            attempts_per_cluster: Vec::new(),
            lead_from: None,
        }
    }

    /// Stroke clusters settled.
    pub fn clusters_settled(&self) -> usize {
        self.commits
            .iter()
            .filter(|c| c.lead.is_some_and(|(_, to)| to == c.samples))
            .count()
    }

    /// Go back to commit `index` and continue with `targets` (of a changed score whose
    /// strokes before the commit, and targets up to its samples, are unchanged).
    pub fn resume_at(&mut self, index: usize, mut targets: Targets, strokes: usize) {
        let commit = self.commits[index].clone();
        self.commits.truncate(index);
        self.sim.rewind(&commit.sim);
        self.drums.rewind(&commit.drums);
        self.warp.truncate(commit.warp);
        for i in 0..commit.strokes {
            targets.set_depth(i, self.targets.depth(i));
        }
        self.shift_s.resize(strokes, 0.0);
        self.suggested.resize(strokes, (0.0, 0.0));
        self.targets = targets;
        self.reference = self.targets.blank();
        // The fine targets only from the step the simulation goes on with (a state of n
        // samples steps next from sample n − 1 to n); those before it are never read.
        let resumes = commit.samples.saturating_sub(1)..commit.samples + 1;
        self.targets
            .write_task_samples(&self.warp, &mut self.reference, 0..resumes.start);
        self.targets.write(&self.warp, &mut self.reference, resumes);
        self.settled = commit.strokes;
        self.lead_from = commit.lead.map(|(from, _)| from);
        self.attempts = 0;
        self.simulated_samples = 0;
        self.attempts_per_cluster.clear();
    }

    /// The latest commit from which the score of `new` strokes and `targets` can resume,
    /// the performance having played `old` strokes: every stroke before it unchanged, the
    /// cluster starting there as it did, and the targets unchanged up to
    /// `same_until` samples, beyond what the commit's targets read.
    pub fn resumable(
        &self,
        old: &[PlannedStroke],
        new: &[PlannedStroke],
        targets: &Targets,
        same_until: usize,
    ) -> Option<usize> {
        let clusters = clusters(new);
        let rate = self.reference.rate_hz;
        (0..self.commits.len()).rev().find(|&c| {
            let commit = &self.commits[c];
            let k = commit.strokes;
            // The targets the reference read up to the commit (and a sample past it),
            // through the warp as it was there.
            let reads = self
                .warp
                .reads_through(commit.warp, commit.samples + 1, rate, MAX_SHIFT_S)
                + 1;
            reads < same_until
                && k <= new.len()
                && k <= old.len()
                && old[..k] == new[..k]
                && targets.same_dips(&self.targets, k)
                && clusters.iter().find(|r| r.start == k).is_some_and(|r| {
                    commit
                        .lead
                        .is_none_or(|(from, to)| lead_in(targets, r.clone(), rate, from) == to)
                })
        })
    }

    /// Settle every stroke from `self.settled` on and simulate to the end; or, given a
    /// `horizon` (samples), stop before the first cluster that starts after it. Returns
    /// whether the performance is complete.
    pub fn run(
        &mut self,
        strokes: &[PlannedStroke],
        aims: &Aims,
        stage: &mut Stage,
        horizon: Option<usize>,
    ) -> Result<bool, SimError> {
        let rate = self.reference.rate_hz;
        for cluster in clusters(strokes) {
            if cluster.start < self.settled {
                continue;
            }
            let from = self.lead_from.unwrap_or(self.sim.samples());
            let lead = lead_in(&self.targets, cluster.clone(), rate, from);
            if let Some(h) = horizon.filter(|&h| lead > h) {
                (stage.settled)(self, true);
                // Up to the horizon the shifts are held as the lead-in would hold them.
                self.lead_into(cluster.start, (from, lead), h, stage)?;
                return Ok(false);
            }
            self.settle(cluster, strokes, aims, stage)?;
            (stage.settled)(self, false);
        }
        let (now, n) = (self.sim.samples(), self.targets.len());
        self.warp.anchor(now as f64 / rate);
        self.targets.write(&self.warp, &mut self.reference, now..n);
        self.advance(n, stage)?;
        Ok(true)
    }

    /// Simulate the lead-in `from..to` to the cluster starting at stroke `first` as far
    /// as `until`, saving a state every [`LEAD_COMMIT_EVERY_S`] within it.
    fn lead_into(
        &mut self,
        first: usize,
        (from, to): (usize, usize),
        until: usize,
        stage: &mut Stage,
    ) -> Result<(), SimError> {
        let now = self.sim.samples();
        if until <= now {
            return Ok(());
        }
        self.targets
            .write(&self.warp, &mut self.reference, now..until + 1);
        let every = ((LEAD_COMMIT_EVERY_S * self.reference.rate_hz).round() as usize).max(1);
        let mut next = (now / every + 1) * every;
        while next < until.min(to) {
            self.advance(next, stage)?;
            self.commits.push(Commit {
                strokes: first,
                samples: next,
                lead: Some((from, to)),
                sim: self.sim.checkpoint(),
                drums: self.drums.checkpoint(),
                warp: self.warp.lens(),
            });
            next += every;
        }
        self.advance(until, stage)
    }

    /// [`Self::advance`], saving a state into `along` at every multiple of
    /// [`ATTEMPT_SAVE_EVERY`] samples.
    fn advance_saving(
        &mut self,
        until: usize,
        along: &mut Vec<(Checkpoint, DrumCheckpoint)>,
        stage: &mut Stage,
    ) -> Result<(), SimError> {
        let mut next = (self.sim.samples() / ATTEMPT_SAVE_EVERY + 1) * ATTEMPT_SAVE_EVERY;
        while next < until {
            self.advance(next, stage)?;
            along.push((self.sim.checkpoint(), self.drums.checkpoint()));
            next += ATTEMPT_SAVE_EVERY;
        }
        self.advance(until, stage)
    }

    fn advance(&mut self, until: usize, stage: &mut Stage) -> Result<(), SimError> {
        let from = self.sim.samples();
        let mut meeting = Meeting {
            drums: &mut self.drums,
            stage,
        };
        self.sim.advance(&mut meeting, &self.reference, until)?;
        self.simulated_samples += self.sim.samples().saturating_sub(from);
        Ok(())
    }

    /// Start each stroke of `cluster` from what the earlier strokes most like it
    /// suggest ([`Self::suggest`]): the latest strokes of its hand, mode and dynamic at
    /// the same spot of the same head; else of its hand and mode at that spot; else of
    /// its hand, mode and dynamic on that drum; else of its hand, mode and dynamic; else
    /// of its hand and mode; else of its hand. The shift is the mean of the latest
    /// [`WARM_FROM`]'s; the depth comes from the line through up to
    /// [`DEPTH_LINE_FROM`] of them (force aim, depth: a ladder of dynamics) when their
    /// aims differ, else from the latest [`WARM_FROM`]'s in proportion to the force aims
    /// (geometric mean). No stroke like it: no shift and the first depth.
    fn warm_start(&mut self, cluster: Range<usize>, strokes: &[PlannedStroke], aims: &Aims) {
        for i in cluster {
            let like = most_alike(&strokes[..self.settled], &strokes[i]);
            let (shift, depth) = if like.is_empty() {
                (0.0, aims.first_depth_m)
            } else {
                let latest = &like[..like.len().min(WARM_FROM)];
                let n = latest.len() as f64;
                let shift = latest.iter().map(|&j| self.suggested[j].0).sum::<f64>() / n;
                let points: Vec<(f64, f64)> = like
                    .iter()
                    .map(|&j| (aims.force_n[j], self.suggested[j].1))
                    .collect();
                let depth = depth_line(&points, aims.force_n[i]).unwrap_or_else(|| {
                    let log_depth: f64 = latest
                        .iter()
                        .map(|&j| {
                            let scale = aims.force_n[i].max(1e-3) / aims.force_n[j].max(1e-3);
                            (self.suggested[j].1 * scale).ln()
                        })
                        .sum();
                    (log_depth / n).exp()
                });
                (shift, depth.clamp(MIN_DEPTH_M, MAX_DEPTH_M))
            };
            self.shift_s[i] = shift;
            self.targets.set_depth(i, depth);
        }
    }

    /// What each stroke of the settled `cluster` should have had by its contact in the
    /// kept attempt: the shift corrected by how late it was, the depth by how far its
    /// force was off (by [`depth_for_force`], at most a quarter either way), the shift
    /// allowing for the deeper aim reaching the head earlier (as [`Self::correct`]).
    fn suggest(
        &mut self,
        cluster: Range<usize>,
        strokes: &[PlannedStroke],
        aims: &Aims,
        commit: &Commit,
    ) {
        let contacts = self.drums.contacts();
        let matches =
            strikes::match_range(strokes, cluster.clone(), contacts, commit.drums.contacts());
        for (i, m) in cluster.zip(matches) {
            let (shift, depth) = (self.shift_s[i], self.targets.depth(i));
            self.suggested[i] = m.map_or((shift, depth), |c| {
                let c = &contacts[c];
                let ratio = aims.force_n[i] / c.peak_force_n.max(1e-3);
                let better = (depth * depth_for_force(ratio).clamp(0.8, 1.25))
                    .clamp(MIN_DEPTH_M, MAX_DEPTH_M);
                let late = c.start_s - strokes[i].time_s;
                let shift = shift + late - (better - depth) / c.impact_speed_mps.max(0.5);
                (shift.clamp(-MAX_SHIFT_S, MAX_SHIFT_S), better)
            });
        }
    }

    /// The shift and depth of each stroke of `cluster`.
    fn placement(&self, cluster: Range<usize>) -> Vec<(f64, f64)> {
        cluster
            .map(|i| (self.shift_s[i], self.targets.depth(i)))
            .collect()
    }

    /// The cluster's knots in the warp and its targets in the reference up to `until`.
    fn place(&mut self, cluster: Range<usize>, commit: &Commit, until: usize) {
        self.warp.truncate(commit.warp);
        for i in cluster {
            let hand = self.targets.hand(i);
            for knot in self.targets.knots(i, self.shift_s[i]) {
                self.warp.push(hand, knot);
            }
        }
        self.targets
            .write(&self.warp, &mut self.reference, commit.samples..until + 2);
    }

    fn settle(
        &mut self,
        cluster: Range<usize>,
        strokes: &[PlannedStroke],
        aims: &Aims,
        stage: &mut Stage,
    ) -> Result<(), SimError> {
        let rate = self.reference.rate_hz;
        let n = self.targets.len();
        self.warm_start(cluster.clone(), strokes, aims);
        // Lead-in: hold the shifts until shortly before the cluster's first dip, simulated
        // once.
        let from = self.lead_from.take().unwrap_or(self.sim.samples());
        let lead = lead_in(&self.targets, cluster.clone(), rate, from);
        self.warp.anchor(lead as f64 / rate);
        self.lead_into(cluster.start, (from, lead), lead, stage)?;
        let commit = Commit {
            strokes: cluster.start,
            lead: Some((from, lead)),
            samples: self.sim.samples(),
            sim: self.sim.checkpoint(),
            drums: self.drums.checkpoint(),
            warp: self.warp.lens(),
        };
        self.commits.push(commit.clone());
        let last_s = self.targets.knots(cluster.end - 1, 0.0)[1].0;
        let until = (((last_s + LOOKAHEAD_S) * rate).ceil() as usize).clamp(commit.samples, n);
        type Attempt = (
            (usize, usize, bool, usize, usize, usize, f64),
            Vec<f64>,
            Vec<f64>,
            usize,
        );
        let mut best: Option<Attempt> = None;
        // Per stroke of the cluster, the (depth, peak force) its attempts met, for the
        // secant on the depth.
        let mut tried: Vec<Vec<(f64, f64)>> = vec![Vec::new(); cluster.len()];
        // Every placement (shift and depth per stroke) attempted: one that comes round
        // again would only repeat its attempt.
        let mut placed: Vec<Vec<(f64, f64)>> = Vec::new();
        let mut attempt = 0;
        let mut diverged = false;
        // States saved along the latest attempt, and the targets it followed: the next
        // attempt resumes from the latest state its own targets leave unchanged (a roll
        // settling from the front plays its settled strokes once, not once per attempt).
        // (A single stroke's attempts change its targets from the commit on: none saved.)
        let saving = cluster.len() > 1;
        let mut along: Vec<(Checkpoint, DrumCheckpoint)> = Vec::new();
        let mut followed: Option<Followed> = None;
        loop {
            attempt += 1;
            self.place(cluster.clone(), &commit, until);
            let span = commit.samples..(until + 2).min(n);
            if attempt > 1 {
                if let Some(followed) = &followed {
                    let changed = followed.first_change(&self.reference, span.clone());
                    // A state of n samples read the targets up to sample n (one ahead).
                    along.retain(|(sim, _)| sim.samples() + 1 < changed);
                }
                let (sim, drums) = along
                    .last()
                    .map_or((&commit.sim, &commit.drums), |(s, d)| (s, d));
                self.sim.rewind(sim);
                self.drums.rewind(drums);
            }
            self.attempts += 1;
            let outcome = if saving {
                followed = Some(Followed::of(&self.reference, span));
                self.advance_saving(until, &mut along, stage)
            } else {
                self.advance(until, stage)
            };
            match outcome {
                // A correction that makes the body diverge is dropped for the best so far;
                // a warm start that does is replaced by no shift and the first depth.
                Err(SimError::Diverged(_)) if best.is_some() => {
                    diverged = true;
                    break;
                }
                Err(SimError::Diverged(_)) if attempt == 1 && attempt < aims.max_attempts => {
                    for i in cluster.clone() {
                        self.shift_s[i] = 0.0;
                        self.targets.set_depth(i, aims.first_depth_m);
                    }
                    continue;
                }
                outcome => outcome?,
            }
            let contacts = self.drums.contacts();
            let matches =
                strikes::match_range(strokes, cluster.clone(), contacts, commit.drums.contacts());
            let mut missed = 0;
            let mut worst = 0.0f64;
            // Strokes whose force is off its aim by more than the tolerance.
            let mut off_force = 0;
            // Strokes far off it.
            let mut far = 0;
            // Strokes whose contact lasts too long.
            let mut long = 0;
            for ((i, m), tried) in cluster.clone().zip(&matches).zip(&mut tried) {
                match m {
                    Some(c) => {
                        worst = worst.max((contacts[*c].start_s - strokes[i].time_s).abs());
                        let ratio = contacts[*c].peak_force_n / aims.force_n[i];
                        tried.push((self.targets.depth(i), contacts[*c].peak_force_n));
                        long += usize::from(pressed(&contacts[*c], aims));
                        if ratio < GRAZE_FRACTION {
                            // A graze is not a stroke: as bad as none.
                            missed += 1;
                        } else if (ratio - 1.0).abs() > aims.force_tolerance {
                            off_force += 1;
                            far += usize::from((ratio - 1.0).abs() > FAR_FRACTION);
                        }
                    }
                    None => missed += 1,
                }
            }
            // The touches after the cluster's contacts: the stick falling back on a head.
            let claimed: Vec<usize> = matches.iter().flatten().copied().collect();
            let recontacts = (commit.drums.contacts()..contacts.len())
                .filter(|c| {
                    !claimed.contains(c) && contacts[*c].peak_force_n >= strikes::RECONTACT_MIN_N
                })
                .count();
            // A stroke that does not sound is worse than a stick falling back on a head,
            // that worse than a contact out of time, that worse than a force far off, that
            // worse than a pressed (long) contact, and that worse than a force a little off.
            let late = out_of_time(worst, aims.acceptable_s);
            let key = (missed, recontacts, late, far, long, off_force, worst);
            if best.as_ref().is_none_or(|b| key <= b.0) {
                best = Some((
                    key,
                    self.shift_s[cluster.clone()].to_vec(),
                    cluster.clone().map(|i| self.targets.depth(i)).collect(),
                    attempt,
                ));
            }
            let clean = missed + recontacts + long + off_force == 0;
            let on_time = clean && !out_of_time(worst, aims.tolerance_s);
            let acceptable = clean && !late && attempt >= aims.settle_attempts;
            // A cluster that sounds but has a force far off or a pressed contact gets up
            // to half as many attempts again.
            // A long cluster (a roll) settles from the front, a stroke or two per attempt:
            // it gets an attempt for every two strokes if that is more.
            let max_attempts = aims.max_attempts.max(cluster.len().div_ceil(2));
            let ran_out = attempt >= max_attempts
                && (missed > 0 || far + long == 0 || attempt >= max_attempts * 3 / 2);
            if on_time || acceptable || ran_out {
                break;
            }
            // Only the cluster's own contacts (the record is borrowed from the drums).
            let found: Vec<_> = matches
                .iter()
                .map(|m| m.map(|c| contacts[c].clone()))
                .collect();
            placed.push(self.placement(cluster.clone()));
            // The strokes before the first one that needs a correction keep their
            // placement: they play the same again (the simulation is causal and
            // deterministic), so a long cluster (a roll) settles from the front instead of
            // every stroke shifting a little and stirring up all those after it.
            let needs = |i: usize, c: &Option<crate::drum::ContactEvent>| {
                c.as_ref().is_none_or(|c| {
                    let ratio = c.peak_force_n / aims.force_n[i];
                    (ratio - 1.0).abs() > aims.force_tolerance
                        || out_of_time((c.start_s - strokes[i].time_s).abs(), aims.tolerance_s)
                        || pressed(c, aims)
                })
            };
            let first = cluster
                .clone()
                .zip(&found)
                .position(|(i, c)| needs(i, c))
                .unwrap_or(0);
            for ((i, contact), tried) in cluster.clone().zip(found).zip(&tried).skip(first) {
                self.correct(i, contact.as_ref(), strokes[i].time_s, aims, tried);
            }
            let next = self.placement(cluster.clone());
            if placed.iter().any(|p| same_placement(p, &next)) {
                break;
            }
        }
        if self.attempts_per_cluster.len() < attempt {
            self.attempts_per_cluster.resize(attempt, 0);
        }
        self.attempts_per_cluster[attempt - 1] += 1;
        let (_, shifts, depths, kept) = best.expect("one attempt ran");
        if kept != attempt || diverged {
            for ((i, shift), depth) in cluster.clone().zip(shifts).zip(depths) {
                self.shift_s[i] = shift;
                self.targets.set_depth(i, depth);
            }
            self.sim.rewind(&commit.sim);
            self.drums.rewind(&commit.drums);
            self.place(cluster.clone(), &commit, until);
            self.advance(until, stage)?;
        }
        self.suggest(cluster.clone(), strokes, aims, &commit);
        self.settled = cluster.end;
        self.commits.push(Commit {
            strokes: cluster.end,
            samples: self.sim.samples(),
            lead: None,
            sim: self.sim.checkpoint(),
            drums: self.drums.checkpoint(),
            warp: self.warp.lens(),
        });
        Ok(())
    }

    /// Late contacts play their target earlier; strokes off their force aim deeper or
    /// shallower (a deeper strike-through drives the stick faster into the head): by the
    /// secant through the two latest attempts' (depth, force) when they differ, else by
    /// [`depth_for_force`] (at most halved or doubled). A stroke on its force whose
    /// contact lasts too long (the arm pressing the stick into the giving head) aims
    /// [`PRESSED_DEPTH`] as deep. A deeper aim reaches the head earlier, by about the
    /// extra depth over the impact speed: the shift allows for that so the two
    /// corrections do not fight.
    fn correct(
        &mut self,
        i: usize,
        contact: Option<&crate::drum::ContactEvent>,
        scheduled_s: f64,
        aims: &Aims,
        tried: &[(f64, f64)],
    ) {
        let aim = aims.force_n[i];
        let mut shift = self.shift_s[i] + contact.map_or(0.0, |c| c.start_s - scheduled_s);
        let force = contact.map(|c| c.peak_force_n);
        let old = self.targets.depth(i);
        let on_force = force.is_some_and(|f| (f / aim - 1.0).abs() <= aims.force_tolerance);
        let pressed = contact.is_some_and(|c| pressed(c, aims));
        let depth = if on_force && pressed {
            Some(old * PRESSED_DEPTH)
        } else if !on_force {
            let ratio = force.map_or(2.0, |f| depth_for_force(aim / f.max(1e-3)).clamp(0.5, 2.0));
            Some(match tried {
                [.., (d0, f0), (d1, f1)] if (d1 - d0).abs() > 1e-5 && (f1 - f0).abs() > 0.5 => {
                    let slope = (f1 - f0) / (d1 - d0);
                    if slope > 0.0 {
                        (d1 + (aim - f1) / slope).clamp(0.5 * old, 2.0 * old)
                    } else {
                        old * ratio
                    }
                }
                _ => old * ratio,
            })
        } else {
            None
        };
        if let Some(depth) = depth.map(|d| d.clamp(MIN_DEPTH_M, MAX_DEPTH_M)) {
            if let Some(c) = contact {
                shift -= (depth - old) / c.impact_speed_mps.max(0.5);
            }
            self.targets.set_depth(i, depth);
        }
        self.shift_s[i] = shift.clamp(-MAX_SHIFT_S, MAX_SHIFT_S);
    }
}

/// The latest (up to [`DEPTH_LINE_FROM`], latest first) of the `settled` strokes in
/// the first of [`Performance::warm_start`]'s kinds that has any like `stroke`.
fn most_alike(settled: &[PlannedStroke], stroke: &PlannedStroke) -> Vec<usize> {
    let s = stroke;
    let played = |o: &PlannedStroke| o.hand == s.hand && o.mode == s.mode;
    let spot = |o: &PlannedStroke| o.drum == s.drum && o.target.distance(s.target) < SAME_SPOT_M;
    let alike: [&dyn Fn(&PlannedStroke) -> bool; 6] = [
        &|o| played(o) && o.dynamic == s.dynamic && spot(o),
        &|o| played(o) && spot(o),
        &|o| played(o) && o.dynamic == s.dynamic && o.drum == s.drum,
        &|o| played(o) && o.dynamic == s.dynamic,
        &played,
        &|o| o.hand == s.hand,
    ];
    alike
        .iter()
        .map(|a| {
            (0..settled.len())
                .rev()
                .filter(|&j| a(&settled[j]))
                .take(DEPTH_LINE_FROM)
                .collect::<Vec<_>>()
        })
        .find(|like| !like.is_empty())
        .unwrap_or_default()
}

/// Whether a timing error of `error_s` is beyond `tolerance_s` (by more than
/// [`TIME_ROUNDING_S`]).
fn out_of_time(error_s: f64, tolerance_s: f64) -> bool {
    error_s > tolerance_s + TIME_ROUNDING_S
}

/// Whether two placements of a cluster are the same to [`REPEAT_SHIFT_S`] and
/// [`REPEAT_DEPTH_M`] (an attempt of one would repeat the other's).
fn same_placement(a: &[(f64, f64)], b: &[(f64, f64)]) -> bool {
    a.iter().zip(b).all(|((sa, da), (sb, db))| {
        (sa - sb).abs() < REPEAT_SHIFT_S && (da - db).abs() < REPEAT_DEPTH_M
    })
}

/// How a stroke's peak force grows with its aimed depth below the head, about: F ∝ dᵉ
/// (over the one-minute study's 226 attempts the impact speed went as d^0.48–0.60 for
/// one hand, mode and drum — d^0.60 for one stroke —, and the peak force in proportion
/// to it, 10.4 N per m/s, 4.4 N RMS off that line; the approach the composed motion
/// brings gives most of the force, the strike-through the rest).
const FORCE_DEPTH_EXPONENT: f64 = 0.5;

/// The depth ratio that changes a stroke's peak force by `force_ratio` (by
/// [`FORCE_DEPTH_EXPONENT`]).
fn depth_for_force(force_ratio: f64) -> f64 {
    force_ratio.powf(1.0 / FORCE_DEPTH_EXPONENT)
}

/// Where the lead-in to `cluster` ends, from `now` samples: shortly before its first dip.
fn lead_in(targets: &Targets, cluster: Range<usize>, rate: f64, now: usize) -> usize {
    let first_knot = cluster
        .map(|i| targets.knots(i, 0.0)[0].0)
        .fold(f64::INFINITY, f64::min);
    (((first_knot - TRANSITION_S) * rate).floor().max(0.0) as usize).max(now)
}

/// The strokes (in time order) split where consecutive ones are at least
/// [`CLUSTER_GAP_S`] apart.
pub fn clusters(strokes: &[PlannedStroke]) -> Vec<Range<usize>> {
    let mut out = Vec::new();
    let mut start = 0;
    for i in 1..=strokes.len() {
        if i == strokes.len() || strokes[i].time_s - strokes[i - 1].time_s >= CLUSTER_GAP_S {
            if i > start {
                out.push(start..i);
            }
            start = i;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A ladder of dynamics: depths on a line of force aim give that line back; aims of
    /// one dynamic, or a line where deeper strikes softer, give none.
    #[test]
    fn depth_line_through_a_ladder_of_dynamics() {
        let ladder = [(46.0, 0.012), (59.0, 0.020), (72.0, 0.029), (86.0, 0.037)];
        let fitted = depth_line(&ladder, 99.0).expect("a ladder has a line");
        // Least squares through the four, about their mean (65.75 N, 24.5 mm).
        let (mx, my) = (65.75, 0.0245);
        let (sxy, sxx) = ladder.iter().fold((0.0, 0.0), |(xy, xx), (x, y)| {
            (xy + (x - mx) * (y - my), xx + (x - mx) * (x - mx))
        });
        assert!((fitted - (my + sxy / sxx * (99.0 - mx))).abs() < 1e-12);
        assert!(fitted > 0.043 && fitted < 0.047, "{fitted}");
        let exact = [(40.0, 0.010), (80.0, 0.030)];
        assert!((depth_line(&exact, 60.0).unwrap() - 0.020).abs() < 1e-12);
        assert_eq!(depth_line(&[(72.0, 0.02), (74.0, 0.03)], 99.0), None);
        assert_eq!(depth_line(&[(40.0, 0.03), (80.0, 0.02)], 99.0), None);
        assert_eq!(depth_line(&[(72.0, 0.02)], 99.0), None);
    }

    #[test]
    fn placements_within_a_tenth_of_a_millisecond_and_millimetre_are_one() {
        let a = [(-0.008318, 0.060), (0.001, 0.02)];
        // The drift of a cycle between a pressed stroke at the deepest aim and a weak one.
        let again = [(-0.008316, 0.060), (0.001, 0.02)];
        assert!(same_placement(&a, &again));
        let later = [(-0.008118, 0.060), (0.001, 0.02)];
        assert!(!same_placement(&a, &later), "0.2 ms apart");
        let deeper = [(-0.008318, 0.0602), (0.001, 0.02)];
        assert!(!same_placement(&a, &deeper), "0.2 mm apart");
        let other = [(-0.008318, 0.060), (0.001, 0.021)];
        assert!(!same_placement(&a, &other), "another stroke moved");
    }
}
