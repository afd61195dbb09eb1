//! Where the performer looks: the neck and head turned so the face points at a point in
//! the performer frame (the drum about to be struck: the head follows the hands, seed 003
//! §4.3.3). The turn is a yaw about the vertical then a pitch, within the neck's and
//! head's reach, split between the two joints; no roll.

use super::skeleton::{Frames, Joint, Pose};
use glam::{DQuat, DVec3};

/// Farthest the face turns left or right of straight ahead, rad (70°).
pub const MAX_YAW_RAD: f64 = 70.0 * std::f64::consts::PI / 180.0;
/// Farthest the face tilts down, rad (30°: the eyes look lower still), and up (20°).
pub const MAX_DOWN_RAD: f64 = 30.0 * std::f64::consts::PI / 180.0;
pub const MAX_UP_RAD: f64 = 20.0 * std::f64::consts::PI / 180.0;
/// The neck's share of the turn (the head takes the rest).
pub const NECK_SHARE: f64 = 0.4;
/// The eyes above the neck joint in the rest pose, m (the turn is aimed from there, so
/// it does not depend on the head's own turn).
const EYES_M: DVec3 = DVec3::new(0.0, 0.08, 0.20);
/// Points nearer the body than this ahead of the pelvis are looked at as if this far ahead,
/// m (the face never turns round through its side).
const MIN_AHEAD_M: f64 = 0.1;

/// Set `pose`'s neck and head so the face, from the body posed as `frames` (of the same
/// `pose`, trunk and all), points at `point` (m, performer frame).
pub fn look_at(frames: &Frames, pose: &mut Pose, point: DVec3) {
    let (neck, head) = (Joint::Neck.index(), Joint::Head.index());
    // The turn (yaw) is the point's bearing from the pelvis, the body's vertical axis: from
    // the eyes or the neck, leaning over the drums, a drum nearly below would swing the face
    // round for a small step.
    let ahead = point - frames.position[Joint::Trunk.index()];
    let yaw = (-ahead.x)
        .atan2(ahead.y.max(MIN_AHEAD_M))
        .clamp(-MAX_YAW_RAD, MAX_YAW_RAD);
    let eyes = frames.position[neck] + frames.parent_rotation(Joint::Neck) * EYES_M;
    let d = point - eyes;
    let pitch = d.z.atan2(d.truncate().length());
    let pitch = pitch.clamp(-MAX_DOWN_RAD, MAX_UP_RAD);
    // The face's rest direction is +y: yaw about z, then pitch about the turned x.
    let world = DQuat::from_rotation_z(yaw) * DQuat::from_rotation_x(pitch);
    // Relative to the trunk (the neck's parent), shared between neck and head.
    let local = (frames.parent_rotation(Joint::Neck).inverse() * world).normalize();
    pose[neck] = positive(DQuat::IDENTITY.slerp(local, NECK_SHARE));
    pose[head] = positive(pose[neck].inverse() * local);
}

/// `q` normalised with w ≥ 0 (targets interpolated sample to sample stay on one side).
fn positive(q: DQuat) -> DQuat {
    let q = q.normalize();
    if q.w < 0.0 { -q } else { q }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::body::skeleton::{REST, Skeleton};

    /// The face direction (+y of the head) after `look_at`.
    fn facing(skeleton: &Skeleton, pose: &Pose) -> DVec3 {
        skeleton.forward(pose).rotation[Joint::Head.index()] * DVec3::Y
    }

    /// Looking at a point ahead and below turns the face onto it, split between neck and
    /// head; a point behind the shoulder is as far as the neck turns.
    #[test]
    fn the_face_turns_toward_the_point_within_reach() {
        let skeleton = Skeleton::default();
        let mut pose = REST;
        let frames = skeleton.forward(&pose);
        let neck_at = frames.position[Joint::Neck.index()];
        let pelvis = frames.position[Joint::Trunk.index()];
        let eyes = neck_at + EYES_M;
        let point = eyes + DVec3::new(0.3, 1.0, -0.3);
        look_at(&frames, &mut pose, point);
        let got = facing(&skeleton, &pose);
        let bearing = |v: DVec3| (-v.x).atan2(v.y);
        let d = point - eyes;
        let pitch = d.z.atan2(d.truncate().length());
        assert!(
            (bearing(got) - bearing(point - pelvis)).abs() < 1e-9,
            "{got}"
        );
        assert!(
            (got.z.atan2(got.truncate().length()) - pitch).abs() < 1e-9,
            "{got}"
        );
        let want = DQuat::from_rotation_z(bearing(got)) * DQuat::from_rotation_x(pitch) * DVec3::Y;
        let neck = pose[Joint::Neck.index()].to_axis_angle().1;
        let total = DQuat::from_rotation_arc(DVec3::Y, want).to_axis_angle().1;
        assert!(
            (neck - NECK_SHARE * total).abs() < 0.05,
            "{neck} of {total}"
        );

        let mut behind = REST;
        look_at(&frames, &mut behind, DVec3::new(2.0, -1.0, 1.5));
        let face = facing(&skeleton, &behind);
        let yaw = (-face.x).atan2(face.y);
        assert!((yaw + MAX_YAW_RAD).abs() < 1e-9, "clamped yaw {yaw}");

        let mut down = REST;
        look_at(&frames, &mut down, eyes + DVec3::new(0.0, 0.3, -1.0));
        let face = facing(&skeleton, &down);
        let pitch = face.z.atan2(face.truncate().length());
        assert!((pitch + MAX_DOWN_RAD).abs() < 1e-9, "clamped pitch {pitch}");
    }
}
