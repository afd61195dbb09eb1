//! The dynamic level over the part's time: markings, single accented strokes and
//! hairpins, as MIDI velocities.

use super::*;

/// The dynamic level over time: markings, single accented strokes, hairpins.
pub(super) struct Levels {
    /// (tick, velocity) level changes, in time order.
    pub(super) marks: Vec<(u64, f64)>,
    /// (tick, velocity, accented) single strokes.
    pub(super) singles: Vec<(u64, f64, bool)>,
    /// (start, end, from, to) hairpins, linear in MIDI velocity.
    pub(super) ramps: Vec<(u64, u64, f64, f64)>,
}

impl Levels {
    pub(super) fn new(events: &[(u64, DynEvent)], tpq: u64) -> Self {
        let mut events = events.to_vec();
        events.sort_by_key(|e| e.0);
        let mut marks = Vec::new();
        let mut singles = Vec::new();
        let mut open: Vec<(u32, u64, bool)> = Vec::new();
        let mut wedges: Vec<(u64, u64, bool)> = Vec::new();
        for &(tick, e) in &events {
            match e {
                DynEvent::Level(v) => marks.push((tick, v)),
                DynEvent::Single { vel, then, accent } => {
                    singles.push((tick, vel, accent));
                    if let Some(t) = then {
                        marks.push((tick, t));
                    }
                }
                DynEvent::Wedge { up, number } => {
                    open.retain(|w| w.0 != number);
                    open.push((number, tick, up));
                }
                DynEvent::WedgeStop { number } => {
                    if let Some(k) = open.iter().position(|w| w.0 == number) {
                        let (_, start, up) = open.remove(k);
                        wedges.push((start, tick, up));
                    }
                }
            }
        }
        let mut levels = Levels {
            marks,
            singles,
            ramps: Vec::new(),
        };
        for (start, stop, up) in wedges {
            let from = levels.mark_at(start);
            // The marking that closes the hairpin: at its end or within a quarter after.
            let closing = levels
                .marks
                .iter()
                .find(|(t, _)| *t >= stop && *t <= stop + tpq)
                .copied();
            let (end, to) = closing.unwrap_or_else(|| (stop, step(from, up)));
            if closing.is_none() {
                let at = levels.marks.partition_point(|(t, _)| *t <= stop);
                levels.marks.insert(at, (stop, to));
            }
            if end > start {
                levels.ramps.push((start, end, from, to));
            }
        }
        levels
    }

    /// The level of the last marking at or before `tick` (mf before any).
    fn mark_at(&self, tick: u64) -> f64 {
        self.marks
            .iter()
            .rev()
            .find(|(t, _)| *t <= tick)
            .map_or(DEFAULT_VELOCITY, |m| m.1)
    }

    /// The MIDI velocity at `tick` (fractional inside hairpins) and whether the stroke
    /// there is accented (sf, sfz…).
    pub(super) fn at(&self, tick: u64) -> (f64, bool) {
        if let Some(&(_, v, accent)) = self.singles.iter().rev().find(|s| s.0 == tick) {
            return (v, accent);
        }
        for &(start, end, from, to) in self.ramps.iter().rev() {
            if tick > start && tick < end {
                let x = (tick - start) as f64 / (end - start) as f64;
                return ((from + (to - from) * x).clamp(1.0, 127.0), false);
            }
        }
        (self.mark_at(tick), false)
    }
}

/// The next marking up (or down) from velocity `v` among pp … ff, else `v` ± 16.
pub(super) fn step(v: f64, up: bool) -> f64 {
    let marks = Dynamic::MARKS.map(|(_, m, _)| f64::from(m));
    let next = if up {
        marks.iter().copied().find(|m| *m > v)
    } else {
        marks.iter().rev().copied().find(|m| *m < v)
    };
    next.unwrap_or(if up { v + 16.0 } else { v - 16.0 })
        .clamp(1.0, 127.0)
}
