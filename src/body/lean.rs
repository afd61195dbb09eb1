//! Leaning toward far strokes: a tip target farther from its (upright) shoulder than a
//! comfortable reach ([`comfort_m`]) turns the trunk about its base so that shoulder comes
//! toward it, as a player leans toward an outer drum played across the body — a roll on
//! the 32- or the 23-inch drum, which takes the far hand too. The turn is held around the
//! far targets ([`HOLD_S`]) and smoothed, so it does not follow each stroke's lift and
//! drop, and it starts before the first far stroke. The IK's null-space pull draws the
//! trunk to it ([`super::sim::Reference::lean`]); a score with no far target has none
//! and plays exactly as before.

use super::skeleton::{Joint, REST, Skeleton};
use crate::kit::Side;
use glam::{DQuat, DVec3};

/// A tip target within the arm's reach less this of its upright shoulder needs no lean, m
/// (0.95 m for the default player and mallets: the farthest demo stroke is 0.95 m from
/// its shoulder).
pub const COMFORT_MARGIN_M: f64 = 0.02;

/// How far from its upright shoulder a tip target needs no lean, m: the stretched arm
/// and stick ([`Skeleton::reach_m`]) less [`COMFORT_MARGIN_M`] — shorter mallets or a
/// smaller player lean sooner.
pub fn comfort_m(skeleton: &Skeleton) -> f64 {
    skeleton.reach_m() - COMFORT_MARGIN_M
}

/// The largest lean, rad (about 23°).
pub const MAX_LEAN_RAD: f64 = 0.4;

/// A far target's lean is held this long either side of it, s, then eased in and out
/// over as long again.
pub const HOLD_S: f64 = 0.3;

/// The trunk's base and both upright shoulders, m.
fn levers(skeleton: &Skeleton) -> (DVec3, [DVec3; 2]) {
    let upright = skeleton.forward(&REST);
    let shoulder = |side: Side| upright.position[Joint::arm(side)[0].index()];
    (
        upright.position[Joint::Trunk.index()],
        [shoulder(Side::Left), shoulder(Side::Right)],
    )
}

/// The turn (rotation vector about the trunk's base, rad) that brings each shoulder as
/// much nearer its target as the target is beyond `comfort` (m), to first order: a
/// rotation ω moves a shoulder by ω × lever, straight toward the target about
/// lever × toward, |lever × toward| per radian.
fn demand(pivot: DVec3, shoulders: [DVec3; 2], tips: [DVec3; 2], comfort: f64) -> DVec3 {
    let mut turn = DVec3::ZERO;
    for (shoulder, tip) in shoulders.into_iter().zip(tips) {
        let beyond = tip.distance(shoulder) - comfort;
        if beyond <= 0.0 {
            continue;
        }
        let axis = (shoulder - pivot).cross((tip - shoulder).normalize_or_zero());
        let per_rad = axis.length();
        if per_rad > 1e-3 {
            turn += axis / per_rad * (beyond / per_rad);
        }
    }
    turn
}

/// How far leaning brings `side`'s shoulder toward `target` at most, m (the trunk turned
/// by [`MAX_LEAN_RAD`] straight toward it): what a reach check can allow beyond the arm's.
pub fn gain_m(skeleton: &Skeleton, side: Side, target: DVec3) -> f64 {
    let (pivot, shoulders) = levers(skeleton);
    let shoulder = shoulders[usize::from(side == Side::Right)];
    let lever = shoulder - pivot;
    let axis = lever.cross((target - shoulder).normalize_or_zero());
    let turned = DQuat::from_scaled_axis(axis.normalize_or_zero() * MAX_LEAN_RAD);
    (target.distance(shoulder) - target.distance(pivot + turned * lever)).max(0.0)
}

/// Per sample of the composed tip paths `tips` ([left, right], m, at `rate_hz`), the
/// trunk's turn toward far targets (a world rotation applied to the upright trunk):
/// [`demand`] held at its largest within [`HOLD_S`] either side, then smoothed by two
/// moving means of [`HOLD_S`], at most [`MAX_LEAN_RAD`]. `None` when no target is far.
pub fn track(skeleton: &Skeleton, tips: &[Vec<DVec3>; 2], rate_hz: f64) -> Option<Vec<DQuat>> {
    let (pivot, shoulders) = levers(skeleton);
    let comfort = comfort_m(skeleton);
    let n = tips[0].len().min(tips[1].len());
    let turn: Vec<DVec3> = (0..n)
        .map(|k| demand(pivot, shoulders, [tips[0][k], tips[1][k]], comfort))
        .collect();
    if turn.iter().all(|t| *t == DVec3::ZERO) {
        return None;
    }
    let w = ((HOLD_S * rate_hz).round() as usize).max(1);
    // Each turn's length once, not once per window it falls in (2·w + 1 of them).
    let lengths: Vec<f64> = turn.iter().map(|t| t.length()).collect();
    let held: Vec<DVec3> = (0..n)
        .map(|k| {
            let window = k.saturating_sub(w)..(k + w + 1).min(n);
            // The first longest in the window (none: no turn).
            let longest = window.fold(None, |best: Option<usize>, j| match best {
                Some(b) if lengths[j] <= lengths[b] => Some(b),
                _ if lengths[j] > 0.0 => Some(j),
                _ => best,
            });
            longest.map_or(DVec3::ZERO, |j| turn[j])
        })
        .collect();
    let eased = moving_mean(&moving_mean(&held, w / 2), w / 2);
    Some(
        eased
            .into_iter()
            .map(|t| DQuat::from_scaled_axis(t.clamp_length_max(MAX_LEAN_RAD)))
            .collect(),
    )
}

/// The mean of `values` over the `half` samples either side of each (fewer at the ends).
fn moving_mean(values: &[DVec3], half: usize) -> Vec<DVec3> {
    let n = values.len();
    (0..n)
        .map(|k| {
            let window = &values[k.saturating_sub(half)..(k + half + 1).min(n)];
            window.iter().copied().sum::<DVec3>() / window.len() as f64
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn skeleton() -> Skeleton {
        Skeleton::new(1.75, 0.37)
    }

    /// A target `distance_m` from `side`'s upright shoulder, toward the other side at
    /// head height (0.8 m): an outer drum played across the body.
    fn across(side: Side, distance_m: f64) -> DVec3 {
        let (_, shoulders) = levers(&skeleton());
        let shoulder = shoulders[usize::from(side == Side::Right)];
        let x = if side == Side::Right { -1.0 } else { 1.0 };
        let drop = shoulder.z - 0.8;
        let run = (distance_m * distance_m - drop * drop).sqrt();
        shoulder + DVec3::new(x * run, 0.0, -drop)
    }

    /// The default player with the standard mallets leans beyond 0.95 m, a shorter
    /// mallet sooner.
    #[test]
    fn comfort_follows_the_reach() {
        assert!((comfort_m(&skeleton()) - 0.95).abs() < 0.01);
        assert!(comfort_m(&Skeleton::new(1.75, 0.30)) < comfort_m(&skeleton()) - 0.04);
    }

    /// Targets within a comfortable reach lean nothing (no track at all); one beyond it
    /// leans the trunk so the shoulder comes nearer it, by about as much as it is beyond
    /// (first order), never more than the largest lean.
    #[test]
    fn a_far_target_brings_its_shoulder_nearer() {
        let s = skeleton();
        let near = [across(Side::Left, 0.7), across(Side::Right, 0.9)];
        assert!(track(&s, &[vec![near[0]; 50], vec![near[1]; 50]], 250.0).is_none());
        let far = across(Side::Right, 1.03);
        let turn = track(&s, &[vec![near[0]; 400], vec![far; 400]], 250.0).unwrap();
        let mut leaned = REST;
        leaned[Joint::Trunk.index()] = turn[200] * REST[Joint::Trunk.index()];
        let shoulder = |pose| s.forward(pose).position[Joint::ShoulderR.index()];
        let (before, after) = (
            far.distance(shoulder(&REST)),
            far.distance(shoulder(&leaned)),
        );
        assert!(
            (before - after - (1.03 - comfort_m(&s))).abs() < 0.02,
            "{before:.3} → {after:.3} m"
        );
        assert!(
            turn.iter()
                .all(|q| q.angle_between(DQuat::IDENTITY) <= MAX_LEAN_RAD + 1e-9)
        );
        assert!(
            gain_m(&s, Side::Right, far) > 0.08,
            "{}",
            gain_m(&s, Side::Right, far)
        );
    }

    /// Over a roll the tip lifts and drops at every stroke; the lean holds steady through
    /// it (within 1°), starts before the roll and eases back after it.
    #[test]
    fn the_lean_holds_through_a_roll() {
        let s = skeleton();
        let rate = 250.0;
        let rest = across(Side::Right, 0.8);
        let tips: Vec<DVec3> = (0..1000)
            .map(|k| {
                let t = k as f64 / rate;
                if (1.0..2.0).contains(&t) {
                    let lift = 0.05 * (0.5 - 0.5 * (std::f64::consts::TAU * 10.0 * t).cos());
                    across(Side::Right, 1.0) + DVec3::Z * lift
                } else {
                    rest
                }
            })
            .collect();
        let left = vec![across(Side::Left, 0.7); tips.len()];
        let turn = track(&s, &[left, tips], rate).unwrap();
        let angle = |k: usize| turn[k].angle_between(DQuat::IDENTITY).to_degrees();
        let during: Vec<f64> = (300..450).map(angle).collect();
        let (low, high) = during
            .iter()
            .fold((f64::INFINITY, 0.0f64), |(l, h), a| (l.min(*a), h.max(*a)));
        assert!(high - low < 1.0 && low > 3.0, "{low:.2}–{high:.2}°");
        assert!(
            angle(200) > 0.5 && angle(200) < low,
            "eases in: {:.2}°",
            angle(200)
        );
        assert!(angle(50) == 0.0 && angle(950) == 0.0);
    }
}
