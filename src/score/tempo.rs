//! The tempo map: tempo points with step changes and linear ramps (accelerando and
//! ritardando), and exact conversion between score ticks and seconds.
//!
//! Within a ramp the tempo is linear in ticks, b(x) = b0 + k·x (quarter notes per minute),
//! so the time to reach tick offset x is t = 60/(q·k) · ln(1 + k·x/b0) with q ticks per
//! quarter, and its inverse x = b0·(exp(q·k·t/60) − 1)/k.

use serde::{Deserialize, Serialize};

/// Slowest and fastest tempo a score may use, in quarter notes per minute.
pub const BPM_RANGE: std::ops::RangeInclusive<f64> = 10.0..=400.0;

/// How the tempo arrives at a tempo point from the previous one.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum TempoChange {
    /// The new tempo starts at the point (the previous tempo holds until then).
    Step,
    /// The tempo moves linearly (in musical time) from the previous point's tempo to
    /// this one, arriving at the point: an accelerando or ritardando.
    Ramp,
}

/// A tempo marking at a position of the score.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TempoPoint {
    /// Position in ticks from the start of the score.
    pub tick: u64,
    /// Tempo in quarter notes per minute.
    pub bpm: f64,
    /// How the tempo gets here from the previous point.
    pub change: TempoChange,
}

/// A map of steps from `first_bpm` at tick 0 and `events` (tick, bpm) in time order: an
/// event at the tick of the one before replaces it, and a step to the tempo already
/// holding is left out (imported files repeat their tempo marks).
pub fn steps(first_bpm: f64, events: impl IntoIterator<Item = (u64, f64)>) -> Vec<TempoPoint> {
    let step = |tick, bpm| TempoPoint {
        tick,
        bpm,
        change: TempoChange::Step,
    };
    let mut points = vec![step(0, first_bpm)];
    for (tick, bpm) in events {
        let last = points.last_mut().expect("points start with one");
        if last.tick == tick {
            last.bpm = bpm;
        } else if last.bpm != bpm {
            points.push(step(tick, bpm));
        }
    }
    // A later event at the same tick may have made a point repeat the one before.
    points.dedup_by(|b, a| a.bpm == b.bpm);
    points
}

/// One stretch of the map between two tempo points.
#[derive(Clone, Copy, Debug)]
struct Segment {
    start_tick: u64,
    start_s: f64,
    start_bpm: f64,
    /// Tempo slope in bpm per tick (0 for a constant tempo).
    slope: f64,
}

/// Tick ↔ second conversion for a validated list of tempo points.
#[derive(Clone, Debug)]
pub struct TempoMap {
    ticks_per_quarter: f64,
    segments: Vec<Segment>,
}

impl TempoMap {
    /// Build the map. `points` must be valid (see [`validate_points`]).
    pub fn new(points: &[TempoPoint], ticks_per_quarter: u32) -> Self {
        let q = f64::from(ticks_per_quarter);
        let mut segments: Vec<Segment> = Vec::with_capacity(points.len());
        let mut start_s = 0.0;
        for (i, p) in points.iter().enumerate() {
            let next = points.get(i + 1);
            let slope = match next {
                Some(n) if n.change == TempoChange::Ramp => {
                    (n.bpm - p.bpm) / (n.tick - p.tick) as f64
                }
                _ => 0.0,
            };
            let seg = Segment {
                start_tick: p.tick,
                start_s,
                start_bpm: p.bpm,
                slope,
            };
            if let Some(n) = next {
                start_s += seconds_into(&seg, (n.tick - p.tick) as f64, q);
            }
            segments.push(seg);
        }
        if segments.is_empty() {
            segments.push(Segment {
                start_tick: 0,
                start_s: 0.0,
                start_bpm: 120.0,
                slope: 0.0,
            });
        }
        TempoMap {
            ticks_per_quarter: q,
            segments,
        }
    }

    /// Seconds from the start of the score to `tick` (which may be fractional).
    pub fn seconds_at(&self, tick: f64) -> f64 {
        let seg = self.segment_at_tick(tick);
        seg.start_s + seconds_into(seg, tick - seg.start_tick as f64, self.ticks_per_quarter)
    }

    /// The (fractional) tick reached `seconds` after the start of the score.
    pub fn tick_at(&self, seconds: f64) -> f64 {
        let i = self
            .segments
            .partition_point(|s| s.start_s <= seconds)
            .saturating_sub(1);
        let seg = &self.segments[i];
        let t = seconds - seg.start_s;
        let q = self.ticks_per_quarter;
        let x = if seg.slope == 0.0 {
            t * seg.start_bpm * q / 60.0
        } else {
            seg.start_bpm * (q * seg.slope * t / 60.0).exp_m1() / seg.slope
        };
        seg.start_tick as f64 + x
    }

    /// Tempo in quarter notes per minute at `tick`.
    pub fn bpm_at(&self, tick: f64) -> f64 {
        let seg = self.segment_at_tick(tick);
        seg.start_bpm + seg.slope * (tick - seg.start_tick as f64)
    }

    fn segment_at_tick(&self, tick: f64) -> &Segment {
        let i = self
            .segments
            .partition_point(|s| s.start_tick as f64 <= tick)
            .saturating_sub(1);
        &self.segments[i]
    }
}

/// Seconds spent in the first `x` ticks of a segment.
fn seconds_into(seg: &Segment, x: f64, q: f64) -> f64 {
    if seg.slope == 0.0 {
        x * 60.0 / (seg.start_bpm * q)
    } else {
        60.0 / (q * seg.slope) * (seg.slope * x / seg.start_bpm).ln_1p()
    }
}

/// Problems with a list of tempo points, each as (index, message).
pub fn validate_points(points: &[TempoPoint]) -> Vec<(usize, String)> {
    let mut problems = Vec::new();
    match points.first() {
        None => problems.push((
            0,
            "the tempo map is empty: give at least one point at tick 0".into(),
        )),
        Some(first) if first.tick != 0 || first.change != TempoChange::Step => problems.push((
            0,
            "the first tempo point must be at tick 0 with change: Step".into(),
        )),
        _ => {}
    }
    for (i, p) in points.iter().enumerate() {
        if !p.bpm.is_finite() || !BPM_RANGE.contains(&p.bpm) {
            problems.push((
                i,
                format!(
                    "tempo {} bpm is impossible: expected {}–{} quarter notes per minute",
                    p.bpm,
                    BPM_RANGE.start(),
                    BPM_RANGE.end()
                ),
            ));
        }
        if i > 0 && p.tick <= points[i - 1].tick {
            problems.push((
                i,
                format!(
                    "tick {} does not come after the previous tempo point's tick {}",
                    p.tick,
                    points[i - 1].tick
                ),
            ));
        }
    }
    problems
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(tick: u64, bpm: f64, change: TempoChange) -> TempoPoint {
        TempoPoint { tick, bpm, change }
    }

    /// Steps from imported tempo marks: a mark at tick 0 replaces the first tempo, a later
    /// mark at the same tick the earlier, a repeated tempo is left out, and a replacement
    /// that makes a point repeat the one before merges them.
    #[test]
    fn steps_merge_repeats_and_same_ticks() {
        let step = |tick, bpm| point(tick, bpm, TempoChange::Step);
        assert_eq!(steps(120.0, []), vec![step(0, 120.0)]);
        assert_eq!(
            steps(
                120.0,
                [(0, 90.0), (960, 90.0), (1920, 100.0), (1920, 110.0)]
            ),
            vec![step(0, 90.0), step(1920, 110.0)]
        );
        assert_eq!(
            steps(120.0, [(960, 100.0), (960, 120.0), (1920, 80.0)]),
            vec![step(0, 120.0), step(1920, 80.0)]
        );
    }

    /// A constant 120 bpm: one quarter (960 ticks) every half second, and back.
    #[test]
    fn constant_tempo() {
        let map = TempoMap::new(&[point(0, 120.0, TempoChange::Step)], 960);
        assert!((map.seconds_at(960.0) - 0.5).abs() < 1e-12);
        assert!((map.tick_at(2.0) - 3840.0).abs() < 1e-9);
    }

    /// A step change from 60 to 120 bpm after one quarter.
    #[test]
    fn step_change() {
        let pts = [
            point(0, 60.0, TempoChange::Step),
            point(960, 120.0, TempoChange::Step),
        ];
        let map = TempoMap::new(&pts, 960);
        assert!((map.seconds_at(960.0) - 1.0).abs() < 1e-12);
        assert!((map.seconds_at(1920.0) - 1.5).abs() < 1e-12);
        assert!((map.bpm_at(1000.0) - 120.0).abs() < 1e-12);
    }

    /// A ramp from 60 to 120 bpm over 4 quarters matches numerical integration of
    /// dt = 60/(q·b(x)) dx to 1 µs, and tick_at inverts seconds_at.
    #[test]
    fn ramp_matches_integration_and_inverts() {
        let pts = [
            point(0, 60.0, TempoChange::Step),
            point(3840, 120.0, TempoChange::Ramp),
        ];
        let map = TempoMap::new(&pts, 960);
        let n = 384_000;
        let dx = 3840.0 / n as f64;
        let integral: f64 = (0..n)
            .map(|i| {
                let x = (i as f64 + 0.5) * dx;
                60.0 / (960.0 * (60.0 + 60.0 * x / 3840.0)) * dx
            })
            .sum();
        assert!((map.seconds_at(3840.0) - integral).abs() < 1e-6);
        assert!((map.bpm_at(1920.0) - 90.0).abs() < 1e-9);
        for tick in [0.0, 100.0, 1919.5, 3840.0, 5000.0] {
            let back = map.tick_at(map.seconds_at(tick));
            assert!((back - tick).abs() < 1e-6, "{tick} -> {back}");
        }
        // After the ramp the tempo holds at 120 bpm.
        let d = map.seconds_at(3840.0 + 960.0) - map.seconds_at(3840.0);
        assert!((d - 0.5).abs() < 1e-12);
    }

    /// Bad maps are reported: empty, not starting at 0, impossible tempo, unordered.
    #[test]
    fn validation() {
        assert!(!validate_points(&[]).is_empty());
        assert!(!validate_points(&[point(10, 100.0, TempoChange::Step)]).is_empty());
        assert!(!validate_points(&[point(0, 0.0, TempoChange::Step)]).is_empty());
        assert!(!validate_points(&[point(0, f64::NAN, TempoChange::Step)]).is_empty());
        let unordered = [
            point(0, 100.0, TempoChange::Step),
            point(0, 90.0, TempoChange::Step),
        ];
        assert!(!validate_points(&unordered).is_empty());
        assert!(validate_points(&[point(0, 100.0, TempoChange::Step)]).is_empty());
    }
}
