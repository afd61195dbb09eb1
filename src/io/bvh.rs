//! Biovision Hierarchy (BVH) export of the simulated performer, for Blender and other
//! animation tools: the 11 joints of `body::skeleton` (trunk as the root, `grip_l` and
//! `grip_r` carrying the sticks, each stick ending in an `End Site` at its tip, the head
//! in one at the top of the skull), offsets from the skeleton's rest geometry, and one
//! frame per task sample (250 Hz) or resampled to a lower rate (slerp between samples).
//!
//! Axes: BVH files are read as Y-up (Blender's importer assumes Y up and maps the file's
//! +Z to its −Y). The performer frame (x right, y forward, z up) is written as
//! (X, Y, Z) = (−x, z, y): the performer faces +Z, as in the CMU captures, which Blender
//! stands facing its front view (−Y), right hand at −X. Rest pose: standing,
//! arms and sticks hanging (every joint rotation zero). Units: metres or centimetres for
//! offsets and the root position; angles in degrees. Every joint declares its channels:
//! the root `Xposition Yposition Zposition` then, like every joint, `Xrotation Zrotation
//! Yrotation` (R = Rx·Rz·Ry, the middle axis the rarely large side bend, away from the
//! 90° flexions of playing); each frame's angles are chosen nearest the previous frame's
//! (no 360° jumps), so tools interpolating the curves do not spin.

use super::y_up;
use crate::body::model::segment_axis;
use crate::body::sim::Motion;
use crate::body::skeleton::{Joint, Pose, Skeleton};
use glam::{DQuat, DVec3, EulerRot};
use std::f64::consts::{PI, TAU};
use std::fmt::Write;

/// Length unit of offsets and positions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Units {
    Metres,
    Centimetres,
}

impl Units {
    /// File units per metre.
    pub fn per_metre(self) -> f64 {
        match self {
            Units::Metres => 1.0,
            Units::Centimetres => 100.0,
        }
    }
}

/// How to write the file.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Options {
    /// Frames per second; `None` keeps the motion's own rate (the task rate, 250 Hz).
    pub rate_hz: Option<f64>,
    pub units: Units,
}

impl Default for Options {
    /// The motion's own rate, in metres.
    fn default() -> Self {
        Options {
            rate_hz: None,
            units: Units::Metres,
        }
    }
}

/// Why a BVH could not be made.
#[derive(Debug, thiserror::Error, PartialEq)]
#[non_exhaustive]
pub enum BvhError {
    #[error("the motion has no samples")]
    Empty,
    #[error("frame rate {0} Hz is not a positive rate of at most the motion's {1} Hz")]
    Rate(f64, f64),
}

/// The rotation channels every joint declares, in order, and the matching glam order.
const ROTATION_CHANNELS: &str = "Xrotation Zrotation Yrotation";
const EULER: EulerRot = EulerRot::XZY;

/// The joints in the file's order: depth first, children in [`Joint::ALL`] order.
fn depth_first() -> Vec<Joint> {
    fn visit(j: Joint, out: &mut Vec<Joint>) {
        out.push(j);
        for c in Joint::ALL.into_iter().filter(|c| c.parent() == Some(j)) {
            visit(c, out);
        }
    }
    let mut out = Vec::new();
    for root in Joint::ALL.into_iter().filter(|j| j.parent().is_none()) {
        visit(root, &mut out);
    }
    out
}

/// The BVH text of `motion` played by `skeleton`.
pub fn to_bvh(motion: &Motion, skeleton: &Skeleton, options: &Options) -> Result<String, BvhError> {
    if motion.poses.is_empty() {
        return Err(BvhError::Empty);
    }
    let source_hz = motion.rate_hz;
    let rate_hz = options.rate_hz.unwrap_or(source_hz);
    if !(rate_hz.is_finite() && rate_hz > 0.0 && rate_hz <= source_hz * (1.0 + 1e-12)) {
        return Err(BvhError::Rate(rate_hz, source_hz));
    }
    let scale = options.units.per_metre();
    let order = depth_first();
    let mut out = String::from("HIERARCHY\n");
    write_joint(&mut out, skeleton, order[0], 0, scale);
    let poses = resample(&motion.poses.to_vec(), source_hz, rate_hz);
    writeln!(out, "MOTION\nFrames: {}", poses.len()).expect("writing to a String");
    writeln!(out, "Frame Time: {:.8}", 1.0 / rate_hz).expect("writing to a String");
    let root = y_up::vector(skeleton.trunk_origin) * scale;
    let mut previous: Vec<Option<[f64; 3]>> = vec![None; order.len()];
    for pose in &poses {
        write!(out, "{} {} {}", fixed(root.x), fixed(root.y), fixed(root.z))
            .expect("writing to a String");
        for (slot, j) in previous.iter_mut().zip(&order) {
            let angles = euler_near(y_up::rotation(pose[j.index()]), *slot);
            *slot = Some(angles);
            for a in angles {
                write!(out, " {}", fixed(a.to_degrees())).expect("writing to a String");
            }
        }
        out.push('\n');
    }
    Ok(out)
}

/// Write `joint` and its children at `depth`.
fn write_joint(out: &mut String, skeleton: &Skeleton, joint: Joint, depth: usize, scale: f64) {
    let pad = "  ".repeat(depth);
    let offset = if joint.parent().is_none() {
        DVec3::ZERO // the root's place is in its position channels
    } else {
        y_up::vector(skeleton.offsets[joint.index()]) * scale
    };
    let kind = if depth == 0 { "ROOT" } else { "JOINT" };
    let channels = if depth == 0 {
        format!("6 Xposition Yposition Zposition {ROTATION_CHANNELS}")
    } else {
        format!("3 {ROTATION_CHANNELS}")
    };
    let w = |out: &mut String, line: std::fmt::Arguments| {
        writeln!(out, "{line}").expect("writing to a String")
    };
    w(out, format_args!("{pad}{kind} {}", joint.name()));
    w(out, format_args!("{pad}{{"));
    let v = |v: DVec3| format!("{} {} {}", fixed(v.x), fixed(v.y), fixed(v.z));
    w(out, format_args!("{pad}  OFFSET {}", v(offset)));
    w(out, format_args!("{pad}  CHANNELS {channels}"));
    let children: Vec<Joint> = Joint::ALL
        .into_iter()
        .filter(|c| c.parent() == Some(joint))
        .collect();
    for c in &children {
        write_joint(out, skeleton, *c, depth + 1, scale);
    }
    if children.is_empty() {
        let end = y_up::vector(segment_axis(skeleton, joint)) * scale;
        w(out, format_args!("{pad}  End Site"));
        w(out, format_args!("{pad}  {{"));
        w(out, format_args!("{pad}    OFFSET {}", v(end)));
        w(out, format_args!("{pad}  }}"));
    }
    w(out, format_args!("{pad}}}"));
}

/// `v` with six decimals, a value that rounds to zero written without a sign.
fn fixed(v: f64) -> String {
    let s = format!("{v:.6}");
    match s.strip_prefix('-') {
        Some(unsigned) if unsigned.bytes().all(|c| c == b'0' || c == b'.') => unsigned.into(),
        _ => s,
    }
}

/// `poses` sampled at `from_hz` resampled to `to_hz` (≤ `from_hz`), each joint's rotation
/// interpolated along the shorter arc; frame k at k / `to_hz` s, up to the last sample.
fn resample(poses: &[Pose], from_hz: f64, to_hz: f64) -> Vec<Pose> {
    if to_hz == from_hz {
        return poses.to_vec();
    }
    let last_s = (poses.len() - 1) as f64 / from_hz;
    let frames = (last_s * to_hz + 1e-9).floor() as usize + 1;
    (0..frames)
        .map(|k| {
            let s = k as f64 / to_hz * from_hz;
            let i = (s.floor() as usize).min(poses.len() - 1);
            let f = s - i as f64;
            match poses.get(i + 1) {
                Some(next) if f > 1e-9 => {
                    std::array::from_fn(|j| poses[i][j].slerp(next[j], f).normalize())
                }
                _ => poses[i],
            }
        })
        .collect()
}

/// Euler angles (rad, channel order) of `q`, of its two equivalent sets and their turns
/// by whole revolutions the one nearest `previous`.
fn euler_near(q: DQuat, previous: Option<[f64; 3]>) -> [f64; 3] {
    let (a, b, c) = q.normalize().to_euler(EULER);
    let Some(p) = previous else {
        return [a, b, c];
    };
    let near = |x: f64, to: f64| x + TAU * ((to - x) / TAU).round();
    [[a, b, c], [a + PI, PI - b, c + PI]]
        .map(|s| [near(s[0], p[0]), near(s[1], p[1]), near(s[2], p[2])])
        .into_iter()
        .min_by(|x, y| {
            let d = |s: &[f64; 3]| (0..3).map(|i| (s[i] - p[i]).powi(2)).sum::<f64>();
            d(x).total_cmp(&d(y))
        })
        .expect("two candidates")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::body::skeleton::{JOINT_COUNT, REST};

    fn motion(poses: Vec<Pose>) -> Motion {
        Motion::new(250.0, [Vec::new(), Vec::new()], poses)
    }

    /// The declared order's angles rebuild the rotation (R = Rx·Rz·Ry), also for the
    /// alternative set chosen for continuity and near the side-bend singularity.
    #[test]
    fn euler_angles_rebuild_the_rotation() {
        let qs = [
            DQuat::from_rotation_x(1.4) * DQuat::from_rotation_y(-0.3),
            DQuat::from_axis_angle(DVec3::new(0.3, -0.5, 0.8).normalize(), 2.9),
            DQuat::from_rotation_z(std::f64::consts::FRAC_PI_2 - 1e-4),
        ];
        for q in qs {
            for previous in [None, Some([3.0, 3.0, 3.0]), Some([-7.0, 0.0, 7.0])] {
                let [a, b, c] = euler_near(q, previous);
                let back = DQuat::from_rotation_x(a)
                    * DQuat::from_rotation_z(b)
                    * DQuat::from_rotation_y(c);
                assert!(back.dot(q).abs() > 1.0 - 1e-12, "{q:?} {previous:?}");
            }
        }
    }

    /// A slow full turn about x gives angles that never jump between frames.
    #[test]
    fn angles_are_continuous() {
        let poses: Vec<Pose> = (0..400)
            .map(|k| {
                let mut p = REST;
                p[Joint::ElbowR.index()] = DQuat::from_rotation_x(k as f64 * 0.03)
                    * DQuat::from_rotation_y(0.2 * (k as f64 * 0.05).sin());
                p
            })
            .collect();
        let text = to_bvh(&motion(poses), &Skeleton::default(), &Options::default()).unwrap();
        let rows: Vec<Vec<f64>> = text
            .lines()
            .skip_while(|l| !l.starts_with("Frame Time"))
            .skip(1)
            .map(|l| l.split(' ').map(|v| v.parse().unwrap()).collect())
            .collect();
        assert_eq!(rows.len(), 400);
        for w in rows.windows(2) {
            for (x, y) in w[0].iter().zip(&w[1]) {
                assert!((x - y).abs() < 5.0, "{x} -> {y}");
            }
        }
    }

    /// The hierarchy names 11 joints, two stick tips and the head top; the root has six
    /// channels and the others three; centimetres scale the offsets by 100; resampling to
    /// 60 Hz keeps the frames up to the last sample.
    #[test]
    fn hierarchy_units_and_rate() {
        let poses = vec![REST; 251];
        let s = Skeleton::default();
        let m = to_bvh(&motion(poses.clone()), &s, &Options::default()).unwrap();
        assert_eq!(m.matches("JOINT ").count() + 1, JOINT_COUNT);
        assert_eq!(m.matches("End Site").count(), 3);
        assert_eq!(m.matches("CHANNELS 6 ").count(), 1);
        assert_eq!(
            m.matches("CHANNELS 3 Xrotation Zrotation Yrotation")
                .count(),
            10
        );
        assert!(m.contains("Frames: 251\nFrame Time: 0.00400000\n"));
        let cm = to_bvh(
            &motion(poses.clone()),
            &s,
            &Options {
                rate_hz: Some(60.0),
                units: Units::Centimetres,
            },
        )
        .unwrap();
        assert!(m.contains("OFFSET 0.000000 0.480000 0.000000"), "{m}");
        assert!(cm.contains("OFFSET 0.000000 48.000000 0.000000"));
        assert!(cm.contains("Frames: 61\nFrame Time: 0.01666667\n"));
        assert_eq!(
            to_bvh(
                &motion(poses),
                &s,
                &Options {
                    rate_hz: Some(500.0),
                    units: Units::Metres
                }
            ),
            Err(BvhError::Rate(500.0, 250.0))
        );
        assert_eq!(
            to_bvh(&motion(Vec::new()), &s, &Options::default()),
            Err(BvhError::Empty)
        );
    }
}
