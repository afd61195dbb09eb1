//! The simulated timpanist's upper body: the 11-segment skeleton with ball joints and its
//! forward kinematics, and inverse kinematics for the arm chains.

pub mod control;
pub mod dynamics;
pub mod evaluate;
pub mod ik;
pub mod model;
pub mod sim;
pub mod skeleton;

pub use skeleton::{JOINT_COUNT, Joint, Pose, Skeleton};
