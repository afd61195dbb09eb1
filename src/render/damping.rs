//! When the secco beats' heads are stopped, from the simulated body: a muffling hand
//! touches its head at the first task-rate sample where its grip joint (the fingers) is
//! within [`TOUCH_TOLERANCE_M`] of its resting height above the head and over the head.
//! A hand that never gets there (or a beat no hand was free for) still stops the head at
//! the scored damp tick, and the report says so.

use crate::body::sim::Motion;
use crate::body::skeleton::{Joint, Skeleton};
use crate::kit::Kit;
use crate::motion::compose::Composition;
use crate::motion::muffle::{Damp, HAND_ABOVE_HEAD_M, Muffle};
use crate::sound::Touch;

/// How far above its resting height the hand still counts as on the head, m.
pub const TOUCH_TOLERANCE_M: f64 = 0.01;

/// How each damped beat's head was stopped.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DampReport {
    /// Beats a hand touched: (beat, touch time minus the scored one, s).
    pub by_hand: Vec<(usize, f64)>,
    /// Beats whose muffling hand did not reach the head (stopped at the scored time).
    pub missed: Vec<usize>,
    /// Beats no hand was free for (stopped at the scored time, without a gesture).
    pub without_hand: Vec<usize>,
}

/// The touches of `comp`'s damped beats over `motion` (simulated up to `simulated_s`,
/// score time), with what happened to each.
pub fn touches(
    comp: &Composition,
    motion: &Motion,
    skeleton: &Skeleton,
    kit: &Kit,
    simulated_s: f64,
) -> (Vec<Touch>, DampReport) {
    let mut report = DampReport::default();
    let scored = |d: &Damp| Touch {
        drum: d.drum,
        at_s: d.touch_s,
    };
    let mut touches: Vec<Touch> = comp.muffles.without_hand.iter().map(scored).collect();
    report.without_hand = comp.muffles.without_hand.iter().map(|d| d.beat).collect();
    for m in &comp.muffles.played {
        match touched_at(m, comp, motion, skeleton, kit) {
            Some(at_s) => {
                report.by_hand.push((m.damp.beat, at_s - m.damp.touch_s));
                touches.push(Touch {
                    drum: m.damp.drum,
                    at_s,
                });
            }
            None => {
                if m.back_s <= simulated_s {
                    report.missed.push(m.damp.beat);
                }
                touches.push(scored(&m.damp));
            }
        }
    }
    touches.sort_by(|a, b| a.at_s.total_cmp(&b.at_s));
    (touches, report)
}

/// The first time (s, score time) `m`'s hand is on its head in `motion`.
fn touched_at(
    m: &Muffle,
    comp: &Composition,
    motion: &Motion,
    skeleton: &Skeleton,
    kit: &Kit,
) -> Option<f64> {
    let drum = kit.drums.get(m.damp.drum)?;
    let centre = drum.centre();
    let grip = Joint::arm(m.hand)[3].index();
    let first = ((m.leave_s - comp.start_s) * comp.rate_hz).ceil().max(0.0) as usize;
    let last = ((m.back_s - comp.start_s) * comp.rate_hz).floor().max(0.0) as usize;
    (first..=last.min(motion.poses.len().saturating_sub(1)))
        .find(|&k| {
            let hand = skeleton.forward(&motion.poses[k]).position[grip];
            let over = (hand - centre).truncate().length() <= drum.radius_m();
            over && hand.z - centre.z <= HAND_ABOVE_HEAD_M + TOUCH_TOLERANCE_M
        })
        .map(|k| comp.time(k))
}
