//! Time signatures and bars: where each bar starts in ticks, and a tick's
//! bar:beat position for display and error messages.

use serde::{Deserialize, Serialize};
use std::fmt;

/// A time signature taking effect at the start of a bar.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeterChange {
    /// The bar (counting from 1) where this signature starts.
    pub bar: u32,
    /// Beats per bar (the upper number).
    pub numerator: u32,
    /// The note value of a beat (the lower number): 1, 2, 4, 8, 16 or 32.
    pub denominator: u32,
}

impl MeterChange {
    /// Ticks in one beat of this signature.
    pub fn beat_ticks(&self, ticks_per_quarter: u32) -> u64 {
        u64::from(ticks_per_quarter) * 4 / u64::from(self.denominator)
    }

    /// Ticks in one bar of this signature.
    pub fn bar_ticks(&self, ticks_per_quarter: u32) -> u64 {
        self.beat_ticks(ticks_per_quarter) * u64::from(self.numerator)
    }
}

/// A musical position: bar and beat (both from 1) and ticks into the beat.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BarBeat {
    pub bar: u64,
    pub beat: u64,
    pub tick: u64,
}

impl fmt::Display for BarBeat {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.tick == 0 {
            write!(f, "bar {} beat {}", self.bar, self.beat)
        } else {
            write!(f, "bar {} beat {}+{}", self.bar, self.beat, self.tick)
        }
    }
}

/// Bar positions for a validated list of meter changes.
#[derive(Clone, Debug)]
pub struct MeterMap {
    ticks_per_quarter: u32,
    /// (first bar, first tick, signature) for each change.
    spans: Vec<(u64, u64, MeterChange)>,
}

impl MeterMap {
    /// Build the map. `changes` must be valid (see [`validate_changes`]).
    pub fn new(changes: &[MeterChange], ticks_per_quarter: u32) -> Self {
        let mut spans = Vec::with_capacity(changes.len());
        let mut tick = 0u64;
        let mut bar = 1u64;
        for c in changes {
            let b = u64::from(c.bar);
            if let Some(&(_, _, prev)) = spans.last() {
                let prev: MeterChange = prev;
                tick += (b - bar) * prev.bar_ticks(ticks_per_quarter);
            }
            bar = b;
            spans.push((b, tick, *c));
        }
        if spans.is_empty() {
            let four = MeterChange {
                bar: 1,
                numerator: 4,
                denominator: 4,
            };
            spans.push((1, 0, four));
        }
        MeterMap {
            ticks_per_quarter,
            spans,
        }
    }

    /// Ticks per quarter note of the score it maps.
    pub fn ticks_per_quarter(&self) -> u32 {
        self.ticks_per_quarter
    }

    /// The tick where `bar` (from 1) starts.
    pub fn bar_start(&self, bar: u64) -> u64 {
        let i = self.spans.partition_point(|s| s.0 <= bar).saturating_sub(1);
        let (b0, t0, sig) = self.spans[i];
        t0 + bar.saturating_sub(b0) * sig.bar_ticks(self.ticks_per_quarter)
    }

    /// The signature in force at `tick`.
    pub fn signature_at(&self, tick: u64) -> MeterChange {
        let i = self
            .spans
            .partition_point(|s| s.1 <= tick)
            .saturating_sub(1);
        self.spans[i].2
    }

    /// Bar, beat and remaining ticks of `tick`.
    pub fn position(&self, tick: u64) -> BarBeat {
        let i = self
            .spans
            .partition_point(|s| s.1 <= tick)
            .saturating_sub(1);
        let (b0, t0, sig) = self.spans[i];
        let bar_ticks = sig.bar_ticks(self.ticks_per_quarter);
        let beat_ticks = sig.beat_ticks(self.ticks_per_quarter);
        let into = tick - t0;
        let in_bar = into % bar_ticks;
        BarBeat {
            bar: b0 + into / bar_ticks,
            beat: in_bar / beat_ticks + 1,
            tick: in_bar % beat_ticks,
        }
    }

    /// Whether `tick` is the first tick of a bar.
    pub fn is_bar_line(&self, tick: u64) -> bool {
        let p = self.position(tick);
        p.beat == 1 && p.tick == 0
    }
}

/// Problems with a list of meter changes, each as (index, message).
pub fn validate_changes(changes: &[MeterChange], ticks_per_quarter: u32) -> Vec<(usize, String)> {
    let mut problems = Vec::new();
    if changes.first().map(|c| c.bar) != Some(1) {
        problems.push((0, "the first time signature must start at bar 1".into()));
    }
    for (i, c) in changes.iter().enumerate() {
        if !(1..=64).contains(&c.numerator) {
            problems.push((i, format!("numerator {} is not 1 to 64", c.numerator)));
        }
        let den_ok = matches!(c.denominator, 1 | 2 | 4 | 8 | 16 | 32)
            && (u64::from(ticks_per_quarter) * 4).is_multiple_of(u64::from(c.denominator));
        if !den_ok {
            problems.push((
                i,
                format!(
                    "denominator {} is not one of 1, 2, 4, 8, 16, 32 (dividing {} ticks per whole note)",
                    c.denominator,
                    u64::from(ticks_per_quarter) * 4
                ),
            ));
        }
        if i > 0 && c.bar <= changes[i - 1].bar {
            problems.push((
                i,
                format!(
                    "bar {} does not come after bar {}",
                    c.bar,
                    changes[i - 1].bar
                ),
            ));
        }
    }
    problems
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sig(bar: u32, numerator: u32, denominator: u32) -> MeterChange {
        MeterChange {
            bar,
            numerator,
            denominator,
        }
    }

    /// Two bars of 4/4 then 3/4 and 6/8: bar starts and positions.
    #[test]
    fn bars_across_changes() {
        let map = MeterMap::new(&[sig(1, 4, 4), sig(3, 3, 4), sig(4, 6, 8)], 960);
        assert_eq!(map.bar_start(1), 0);
        assert_eq!(map.bar_start(3), 7680);
        assert_eq!(map.bar_start(4), 7680 + 2880);
        assert_eq!(map.bar_start(5), 7680 + 2880 + 2880);
        assert_eq!(
            map.position(7680 + 960 + 10),
            BarBeat {
                bar: 3,
                beat: 2,
                tick: 10
            }
        );
        assert_eq!(map.position(7680 + 2880 + 480).beat, 2);
        assert!(map.is_bar_line(7680));
        assert!(!map.is_bar_line(7680 + 960));
    }

    /// Bad signatures are reported.
    #[test]
    fn validation() {
        assert!(validate_changes(&[sig(1, 4, 4)], 960).is_empty());
        assert!(!validate_changes(&[sig(2, 4, 4)], 960).is_empty());
        assert!(!validate_changes(&[sig(1, 4, 3)], 960).is_empty());
        assert!(!validate_changes(&[sig(1, 0, 4)], 960).is_empty());
        assert!(!validate_changes(&[sig(1, 4, 4), sig(1, 3, 4)], 960).is_empty());
    }
}
