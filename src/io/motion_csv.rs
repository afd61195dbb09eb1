//! Writing a rendered performance as CSV for teaching and analysis: one row per task
//! sample (250 Hz) with the score time (s), each hand's simulated and target stick-tip
//! position (m, performer frame: x right, y forward, z up) and every joint's rotation as a
//! unit quaternion (w, x, y, z) relative to the rest pose, in the parent segment's frame.

use crate::body::sim::{Motion, Reference};
use crate::body::skeleton::Joint;
use std::fmt::Write;

/// The CSV text of `motion` following `reference`, sample 0 at score time `start_s`.
pub fn to_csv(motion: &Motion, reference: &Reference, start_s: f64) -> String {
    let mut out = String::from("time_s");
    for hand in ["left", "right"] {
        for kind in ["tip", "target"] {
            for axis in ["x", "y", "z"] {
                write!(out, ",{hand}_{kind}_{axis}_m").expect("writing to a String");
            }
        }
    }
    for joint in Joint::ALL {
        for c in ["w", "x", "y", "z"] {
            write!(out, ",{}_q{c}", joint.name()).expect("writing to a String");
        }
    }
    out.push('\n');
    for (k, pose) in motion.poses.iter().enumerate() {
        write!(out, "{:.4}", start_s + k as f64 / motion.rate_hz).expect("writing to a String");
        for h in 0..2 {
            for p in [motion.tips[h][k], reference.tips[h][k]] {
                write!(out, ",{:.6},{:.6},{:.6}", p.x, p.y, p.z).expect("writing to a String");
            }
        }
        for q in pose {
            write!(out, ",{:.6},{:.6},{:.6},{:.6}", q.w, q.x, q.y, q.z)
                .expect("writing to a String");
        }
        out.push('\n');
    }
    out
}
