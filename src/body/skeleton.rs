//! The upper-body skeleton of seed 000 (Table 1, Fig. 3): 11 rigid segments — trunk, neck,
//! head, two upper arms, forearms, hands and sticks — on 11 ball joints (33 DOF), the
//! pelvis fixed. A [`Pose`] holds each joint's rotation relative to the rest pose, and
//! forward kinematics gives joint positions and the stick tips in the performer frame
//! (metres; +x right, +y forward, +z up).
//!
//! Rest pose: standing upright, arms hanging straight down, the sticks continuing the
//! hands downward. Every segment's local frame is then aligned with the performer frame,
//! so a joint rotation about local x is a flexion (a forward swing for the arms), about
//! local z a twist along the segment (pronation and supination for the forearm).

use glam::{DQuat, DVec3};

/// Number of joints (and of moving segments).
pub const JOINT_COUNT: usize = 11;

/// The joints; each moves the segment of the same name.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Joint {
    Trunk,
    Neck,
    Head,
    ShoulderL,
    ElbowL,
    WristL,
    GripL,
    ShoulderR,
    ElbowR,
    WristR,
    GripR,
}

impl Joint {
    /// All joints, parents before children.
    pub const ALL: [Joint; JOINT_COUNT] = [
        Joint::Trunk,
        Joint::Neck,
        Joint::Head,
        Joint::ShoulderL,
        Joint::ElbowL,
        Joint::WristL,
        Joint::GripL,
        Joint::ShoulderR,
        Joint::ElbowR,
        Joint::WristR,
        Joint::GripR,
    ];

    /// Index into poses and joint arrays.
    pub fn index(self) -> usize {
        self as usize
    }

    /// The joint whose segment carries this one (`None` for the trunk, on the fixed pelvis).
    pub fn parent(self) -> Option<Joint> {
        use Joint::*;
        match self {
            Trunk => None,
            Neck | ShoulderL | ShoulderR => Some(Trunk),
            Head => Some(Neck),
            ElbowL => Some(ShoulderL),
            WristL => Some(ElbowL),
            GripL => Some(WristL),
            ElbowR => Some(ShoulderR),
            WristR => Some(ElbowR),
            GripR => Some(WristR),
        }
    }

    /// Lower-case name as used in files, e.g. "shoulder_l".
    pub fn name(self) -> &'static str {
        use Joint::*;
        match self {
            Trunk => "trunk",
            Neck => "neck",
            Head => "head",
            ShoulderL => "shoulder_l",
            ElbowL => "elbow_l",
            WristL => "wrist_l",
            GripL => "grip_l",
            ShoulderR => "shoulder_r",
            ElbowR => "elbow_r",
            WristR => "wrist_r",
            GripR => "grip_r",
        }
    }

    /// The arm chain of one side from shoulder to grip.
    pub fn arm(side: crate::kit::Side) -> [Joint; 4] {
        match side {
            crate::kit::Side::Left => {
                [Joint::ShoulderL, Joint::ElbowL, Joint::WristL, Joint::GripL]
            }
            crate::kit::Side::Right => {
                [Joint::ShoulderR, Joint::ElbowR, Joint::WristR, Joint::GripR]
            }
        }
    }
}

/// Joint rotations relative to the rest pose, indexed by [`Joint::index`].
pub type Pose = [DQuat; JOINT_COUNT];

/// The rest pose (every rotation the identity).
pub const REST: Pose = [DQuat::IDENTITY; JOINT_COUNT];

/// Segment dimensions.
#[derive(Clone, Debug, PartialEq)]
pub struct Skeleton {
    /// Position of the trunk joint (lumbar spine, on the fixed pelvis), m.
    pub trunk_origin: DVec3,
    /// Offset of each joint from its parent joint in the rest pose, m.
    pub offsets: [DVec3; JOINT_COUNT],
    /// Stick length from the grip to the tip, m.
    pub stick_length_m: f64,
}

/// Height of the default player, m: the one the segment lengths below are given for.
pub const DEFAULT_HEIGHT_M: f64 = 1.75;

impl Default for Skeleton {
    /// A standing adult of [`DEFAULT_HEIGHT_M`] (segment lengths after Winter's
    /// anthropometric tables) holding 0.37 m mallets 4 cm from their end.
    fn default() -> Self {
        Skeleton::new(DEFAULT_HEIGHT_M, 0.37)
    }
}

impl Skeleton {
    /// The default player ([`DEFAULT_HEIGHT_M`]) holding `kit`'s first mallets (0.37 m
    /// ones when it lists none): the body the sticking, the imports and the synthetic
    /// motion database judge reach and posture by.
    pub fn holding_mallets_of(kit: &crate::kit::Kit) -> Skeleton {
        Skeleton::new(
            DEFAULT_HEIGHT_M,
            kit.mallets.first().map_or(0.37, |m| m.length_m),
        )
    }

    /// A skeleton scaled to `height_m` holding mallets of `mallet_length_m`.
    pub fn new(height_m: f64, mallet_length_m: f64) -> Skeleton {
        let h = height_m / DEFAULT_HEIGHT_M;
        let mut offsets = [DVec3::ZERO; JOINT_COUNT];
        let mut set = |j: Joint, v: DVec3| offsets[j.index()] = v * h;
        set(Joint::Neck, DVec3::new(0.0, 0.0, 0.48));
        set(Joint::Head, DVec3::new(0.0, 0.0, 0.10));
        for (sign, arm) in [
            (-1.0, Joint::arm(crate::kit::Side::Left)),
            (1.0, Joint::arm(crate::kit::Side::Right)),
        ] {
            set(arm[0], DVec3::new(0.19 * sign, 0.0, 0.44));
            set(arm[1], DVec3::new(0.0, 0.0, -0.30));
            set(arm[2], DVec3::new(0.0, 0.0, -0.26));
            set(arm[3], DVec3::new(0.0, 0.0, -0.08));
        }
        Skeleton {
            trunk_origin: DVec3::new(0.0, 0.0, 1.00 * h),
            offsets,
            stick_length_m: mallet_length_m - 0.04,
        }
    }

    /// World positions and rotations of every joint for `pose`.
    pub fn forward(&self, pose: &Pose) -> Frames {
        let mut position = [DVec3::ZERO; JOINT_COUNT];
        let mut rotation = [DQuat::IDENTITY; JOINT_COUNT];
        for j in Joint::ALL {
            let i = j.index();
            let (parent_pos, parent_rot) = match j.parent() {
                Some(p) => (position[p.index()], rotation[p.index()]),
                None => (self.trunk_origin, DQuat::IDENTITY),
            };
            position[i] = parent_pos + parent_rot * self.offsets[i];
            rotation[i] = (parent_rot * pose[i]).normalize();
        }
        Frames {
            position,
            rotation,
            stick_length_m: self.stick_length_m,
        }
    }

    /// The stick tip of `side` for `pose`, m.
    pub fn tip(&self, pose: &Pose, side: crate::kit::Side) -> DVec3 {
        self.forward(pose).tip(side)
    }

    /// The shoulder of `side` in the upright rest posture, m.
    pub fn shoulder(&self, side: crate::kit::Side) -> DVec3 {
        self.forward(&REST).position[Joint::arm(side)[0].index()]
    }

    /// How far a stick tip can go from its shoulder, m: upper arm, forearm, hand and stick
    /// in a line.
    pub fn reach_m(&self) -> f64 {
        let [_, elbow, wrist, grip] = Joint::arm(crate::kit::Side::Right);
        let arm: f64 = [elbow, wrist, grip]
            .iter()
            .map(|j| self.offsets[j.index()].length())
            .sum();
        arm + self.stick_length_m
    }

    /// Whether a stick tip at `point` (m) is within the reach of `side`'s arm.
    pub fn reaches(&self, side: crate::kit::Side, point: DVec3) -> bool {
        point.distance(self.shoulder(side)) <= self.reach_m()
    }
}

/// Joint positions and segment orientations in the performer frame for one pose.
#[derive(Clone, Debug)]
pub struct Frames {
    /// Each joint's position, m.
    pub position: [DVec3; JOINT_COUNT],
    /// Each segment's orientation (world from segment).
    pub rotation: [DQuat; JOINT_COUNT],
    stick_length_m: f64,
}

impl Frames {
    /// The stick tip of `side`, m.
    pub fn tip(&self, side: crate::kit::Side) -> DVec3 {
        let grip = Joint::arm(side)[3].index();
        self.position[grip] + self.rotation[grip] * DVec3::new(0.0, 0.0, -self.stick_length_m)
    }

    /// Rotation of the segment carrying `joint` (world from parent segment).
    pub fn parent_rotation(&self, joint: Joint) -> DQuat {
        joint
            .parent()
            .map_or(DQuat::IDENTITY, |p| self.rotation[p.index()])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kit::Side;

    /// At rest the tips hang straight below the shoulders at arm + stick length.
    #[test]
    fn rest_pose_tips() {
        let s = Skeleton::default();
        let f = s.forward(&REST);
        let shoulder = f.position[Joint::ShoulderR.index()];
        let tip = f.tip(Side::Right);
        assert!((shoulder.z - tip.z - (0.30 + 0.26 + 0.08 + 0.33)).abs() < 1e-12);
        assert_eq!((tip.x, tip.y), (shoulder.x, shoulder.y));
        assert!(f.tip(Side::Left).x < 0.0);
    }

    /// A 90° shoulder flexion (about +x) swings the straight arm forward, horizontal.
    #[test]
    fn shoulder_flexion_swings_forward() {
        let s = Skeleton::default();
        let mut pose = REST;
        pose[Joint::ShoulderR.index()] = DQuat::from_rotation_x(std::f64::consts::FRAC_PI_2);
        let f = s.forward(&pose);
        let shoulder = f.position[Joint::ShoulderR.index()];
        let tip = f.tip(Side::Right);
        assert!((tip.z - shoulder.z).abs() < 1e-12);
        assert!((tip.y - shoulder.y - 0.97).abs() < 1e-12);
    }
}
