//! The simulated timpanist's upper body: the 11-segment skeleton with ball joints and its
//! forward kinematics, its mass model, articulated-body dynamics, inverse kinematics for
//! the arm chains, PD control with joint limits (and their estimation from data, seed 000
//! Alg. 1), the IK / ID / HIMC pipelines.

pub mod control;
pub mod dynamics;
pub mod gaze;
pub mod ik;
pub mod lean;
pub mod limits;
pub mod model;
pub mod sim;
pub mod skeleton;

pub use skeleton::{JOINT_COUNT, Joint, Pose, Skeleton};
