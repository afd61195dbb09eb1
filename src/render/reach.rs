//! Whether the body can reach every stroke, checked before simulating: a stroke whose
//! target lies farther from its hand's shoulder (in the upright rest posture) than the
//! stretched arm and stick (`Skeleton::reach_m`) plus what leaning the trunk toward it
//! brings (`body::lean::gain_m`: up to 23°, about 0.1 m across the body) is refused with
//! the beat named.
//! Automatic sticking prefers the hand that reaches upright (`motion::sticking`).
//! Simulated, a reach beyond that leaves the arm fully stretched, where the nested IK and
//! the PD loops oscillate and the stick flails (see `body::sim`'s loss-of-control check).
//! Within it, a far target leans the trunk (`body::lean`): on the standard kit, the outer
//! drums played across the body — a roll on the 32- or the 23-inch drum.

use crate::body::skeleton::Skeleton;
use crate::kit::Side;
use crate::motion::plan::PlannedStroke;

/// A stroke the body cannot reach.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error(
    "beat {beat} is out of the {} hand's reach: its target on drum {drum} is {distance_m:.2} m \
     from the upright shoulder, the arm and stick reach {reach_m:.2} m with the trunk leaning \
     toward it ({})",
    if *hand == Side::Left { "left" } else { "right" },
    if *roll {
        "a roll takes both hands: roll on a drum both hands reach, tuned to this pitch, or \
         move this drum nearer the player"
    } else {
        "play it with the other hand, or nearer the player"
    }
)]
pub struct OutOfReach {
    pub beat: usize,
    pub hand: Side,
    pub drum: usize,
    /// Distance from the shoulder to the target, m.
    pub distance_m: f64,
    /// How far the tip can go from the upright shoulder toward the target, the trunk
    /// leaning ([`crate::body::lean::gain_m`]), m.
    pub reach_m: f64,
    /// Whether both hands play the beat (a roll), so the other hand is no way out.
    pub roll: bool,
}

/// The first stroke of `strokes` out of reach of `skeleton`, if any.
pub fn check(strokes: &[PlannedStroke], skeleton: &Skeleton) -> Result<(), OutOfReach> {
    let arm_m = skeleton.reach_m();
    for s in strokes {
        let distance_m = s.target.distance(skeleton.shoulder(s.hand));
        let reach_m = arm_m + crate::body::lean::gain_m(skeleton, s.hand, s.target);
        if distance_m > reach_m {
            return Err(OutOfReach {
                beat: s.beat,
                hand: s.hand,
                drum: s.drum,
                distance_m,
                reach_m,
                roll: strokes.iter().any(|o| o.beat == s.beat && o.hand != s.hand),
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kit::Kit;
    use crate::score::{Dynamic, PlayingMode};
    use glam::DVec3;

    fn stroke(hand: Side, target: DVec3) -> PlannedStroke {
        PlannedStroke {
            beat: 4,
            tick: 0,
            hand,
            time_s: 1.0,
            target,
            toward_player: DVec3::NEG_Y,
            drum: 0,
            mode: PlayingMode::Legato,
            dynamic: Dynamic::Mf,
            unit: 0,
        }
    }

    /// On the standard kit, the far-left drum's centre is within the left arm's reach and
    /// beyond the right arm's; the refusal names the beat, the hand and both distances.
    #[test]
    fn the_far_drum_across_the_body_is_out_of_reach() {
        let kit = Kit::standard();
        let skeleton = Skeleton::new(1.75, kit.mallets[0].length_m);
        let far_left = kit.drums[0].point_on_head(0.0, 0.0) + DVec3::Z * 0.03;
        assert!(check(&[stroke(Side::Left, far_left)], &skeleton).is_ok());
        let err = check(&[stroke(Side::Right, far_left)], &skeleton).unwrap_err();
        assert_eq!((err.beat, err.hand), (4, Side::Right));
        assert!(err.distance_m > err.reach_m, "{err}");
        assert!(
            err.to_string()
                .starts_with("beat 4 is out of the right hand's reach")
        );
        assert!(!err.roll && err.to_string().contains("play it with the other hand"));
        let r = skeleton.reach_m();
        assert!((0.9..1.1).contains(&r), "{r}");
    }

    /// A roll on the far-left drum (its strokes by both hands, one beat) is refused for
    /// the right hand with the roll named: the other hand is no way out.
    #[test]
    fn a_roll_out_of_one_hands_reach_says_so() {
        let kit = Kit::standard();
        let skeleton = Skeleton::new(1.75, kit.mallets[0].length_m);
        let far_left = kit.drums[0].point_on_head(0.0, 0.0) + DVec3::Z * 0.03;
        let roll = [stroke(Side::Left, far_left), stroke(Side::Right, far_left)];
        let err = check(&roll, &skeleton).unwrap_err();
        assert!(err.roll && err.hand == Side::Right, "{err}");
        assert!(err.to_string().contains("a roll takes both hands"), "{err}");
    }
}
