//! Summary statistics of a motion database, per playing mode (and grip and dynamic): tip
//! height and depth range, impact speed and stroke duration — the quantities of seed 000
//! Fig. 6a — for `timpanist mocap stats` and the database tests.

use super::db::{MotionDb, UnitEntry};
use crate::score::{Grip, PlayingMode};

/// Measurements of one unit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UnitStats {
    /// Highest minus lowest tip height, m.
    pub height_range_m: f64,
    /// Largest minus smallest forward (y) tip position, m.
    pub depth_range_m: f64,
    /// Downward tip speed over the last whole frame interval before the impact frame, m/s.
    pub impact_speed_mps: f64,
    /// From start to end of the unit, s.
    pub duration_s: f64,
}

/// Measure one unit of `db`.
pub fn unit_stats(db: &MotionDb, u: &UnitEntry) -> UnitStats {
    let tip = db.unit_tip(u);
    let rate_hz = db.takes[u.take].rate_hz;
    let range = |f: fn(glam::DVec3) -> f64| {
        let (lo, hi) = tip
            .iter()
            .flatten()
            .map(|p| f(*p))
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
                (lo.min(v), hi.max(v))
            });
        (hi - lo).max(0.0)
    };
    let k = u.impact - u.start;
    let speed = match (
        k.checked_sub(2).and_then(|j| tip[j]),
        k.checked_sub(1).and_then(|j| tip[j]),
    ) {
        (Some(before), Some(at)) => (before.z - at.z) * rate_hz,
        _ => f64::NAN,
    };
    UnitStats {
        height_range_m: range(|p| p.z),
        depth_range_m: range(|p| p.y),
        impact_speed_mps: speed,
        duration_s: (u.end - u.start) as f64 / rate_hz,
    }
}

/// Means over a group of units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GroupStats {
    pub units: usize,
    pub mean: UnitStats,
}

/// Mean statistics of the units that satisfy `keep`.
pub fn group(db: &MotionDb, keep: impl Fn(&UnitEntry) -> bool) -> GroupStats {
    let all: Vec<UnitStats> = db
        .index
        .units
        .iter()
        .filter(|u| keep(u))
        .map(|u| unit_stats(db, u))
        .collect();
    let n = all.len().max(1) as f64;
    let mean =
        |f: fn(&UnitStats) -> f64| all.iter().map(f).filter(|v| v.is_finite()).sum::<f64>() / n;
    GroupStats {
        units: all.len(),
        mean: UnitStats {
            height_range_m: mean(|s| s.height_range_m),
            depth_range_m: mean(|s| s.depth_range_m),
            impact_speed_mps: mean(|s| s.impact_speed_mps),
            duration_s: mean(|s| s.duration_s),
        },
    }
}

/// Per-mode statistics for one grip (all modes if `grip` is `None`).
pub fn by_mode(db: &MotionDb, grip: Option<Grip>) -> Vec<(PlayingMode, GroupStats)> {
    PlayingMode::ALL
        .iter()
        .map(|&m| {
            (
                m,
                group(db, |u| u.mode == m && grip.is_none_or(|g| u.grip == g)),
            )
        })
        .filter(|(_, g)| g.units > 0)
        .collect()
}
