//! timpanist: compose timpani gesture scores and hear and see them performed by a
//! physically simulated timpanist. The library holds every capability; the binary's CLI
//! and the eframe editor (`app`) are two thin faces over it.
//!
//! Data flows one way: score + kit → sticking and planning (`motion`) → trajectories →
//! simulation → sound and motion; `io` reads and writes files.

pub mod app;
pub mod body;
pub mod cli;
pub mod drum;
pub mod io;
pub mod kit;
pub mod mocap;
pub mod motion;
pub mod pitch;
pub mod problem;
pub mod render;
pub mod rng;
pub mod score;
pub mod sound;
