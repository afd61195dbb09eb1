//! Writing a rendered performance as a C3D file, the motion-capture exchange format
//! (Mokka, ezc3d, Vicon Nexus, Visual3D, Blender add-ons read it), for teaching: one
//! point per joint (its segment's origin, by forward kinematics of the simulated pose),
//! each stick's simulated tip and each target tip, at the task rate (250 Hz), in the
//! performer frame (x right, y forward, z up) and millimetres. Frame 1 is score time
//! `start_s` of the rendering.

use crate::body::sim::{Motion, Reference};
use crate::body::skeleton::{Joint, Skeleton};
use crate::io::c3d_write::write_c3d;
use crate::mocap::{Take, Track};
use std::path::PathBuf;

/// Labels of the stick points: simulated tips, then target tips, [left, right].
pub const TIP_LABELS: [[&str; 2]; 2] = [["LTIP", "RTIP"], ["LTIP_TARGET", "RTIP_TARGET"]];

/// The point label of a joint ("TRUNK", "ELBOW_L", ...).
pub fn joint_label(joint: Joint) -> String {
    joint.name().to_ascii_uppercase()
}

/// `motion` of a body with `skeleton` following `reference`, as a capture: the joints'
/// positions, then [`TIP_LABELS`].
pub fn take_of(motion: &Motion, reference: &Reference, skeleton: &Skeleton) -> Take {
    let frames = motion.poses.len();
    let mut tracks: Vec<Track> = Joint::ALL
        .iter()
        .map(|&j| Track::empty(joint_label(j)))
        .collect();
    for pose in motion.poses.iter() {
        let f = skeleton.forward(pose);
        for (track, p) in tracks.iter_mut().zip(f.position) {
            track.positions.push(Some(p));
        }
    }
    for (labels, tips) in TIP_LABELS.iter().zip([&motion.tips, &reference.tips]) {
        for (label, points) in labels.iter().zip(tips) {
            let mut track = Track::empty(*label);
            track.positions = (0..frames).map(|k| points.get(k).copied()).collect();
            tracks.push(track);
        }
    }
    Take {
        source: PathBuf::new(),
        rate_hz: motion.rate_hz,
        frames,
        file_unit: "mm".into(),
        tracks,
        notes: Vec::new(),
    }
}

/// The C3D bytes of [`take_of`].
pub fn to_c3d(motion: &Motion, reference: &Reference, skeleton: &Skeleton) -> Vec<u8> {
    write_c3d(&take_of(motion, reference, skeleton))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::body::skeleton::REST;
    use crate::mocap::import::c3d::read;
    use glam::{DQuat, DVec3};
    use std::path::Path;

    /// Written and read back by the C3D reader: every label, the rate, the frame count
    /// and the points (to float precision, in metres).
    #[test]
    fn round_trip_through_the_c3d_reader() {
        let skeleton = Skeleton::new(1.75, 0.38);
        let mut bent = REST;
        bent[Joint::ElbowR.index()] = DQuat::from_rotation_x(1.2);
        let tips = |z: f64| {
            [
                vec![DVec3::new(-0.3, 0.5, z); 3],
                vec![DVec3::new(0.3, 0.5, z); 3],
            ]
        };
        let motion = Motion::new(250.0, tips(0.8), vec![REST, bent, REST]);
        let reference = Reference::following(250.0, tips(0.75));
        let bytes = to_c3d(&motion, &reference, &skeleton);
        let back = read(Path::new("motion.c3d"), &bytes, None).unwrap();
        assert_eq!(back.frames, 3);
        assert_eq!(back.rate_hz, 250.0);
        assert_eq!(back.tracks.len(), Joint::ALL.len() + 4);
        let elbow = back.track("ELBOW_R").unwrap();
        let wrist = back.track("WRIST_R").unwrap();
        let expected = skeleton.forward(&bent).position[Joint::WristR.index()];
        let got = wrist.positions[1].unwrap();
        assert!((got - expected).length() < 1e-6, "{got} vs {expected}");
        assert_ne!(wrist.positions[0], wrist.positions[1], "the elbow bends");
        assert_eq!(elbow.positions[0], elbow.positions[1], "the elbow stays");
        let tip = back.track("RTIP_TARGET").unwrap().positions[2].unwrap();
        assert!((tip - DVec3::new(0.3, 0.5, 0.75)).length() < 1e-6, "{tip}");
    }
}
