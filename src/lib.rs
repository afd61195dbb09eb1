//! timpanist: compose timpani gesture scores and hear and see them performed by a
//! physically simulated timpanist. The library holds every capability; the binary's CLI
//! and the eframe editor (`app`, cargo feature `editor`) are two thin faces over it.
//!
//! Data flows one way: score + kit → sticking and planning (`motion`) → trajectories →
//! simulation (`body`, `drum`) → sound and motion (`render`, `sound`); `io` reads and
//! writes files. The modules are layered, each importing only those below it:
//! `base` → `kit` → `score` → {`body`, `drum`} → {`mocap`, `sound`} → `motion` →
//! {`render`, `io`, `scene`} → `exports` → `app` → `cli` (ARCHITECTURE.md; `tests/architecture.rs`
//! checks it).

#[cfg(feature = "editor")]
pub mod app;
pub mod base;
pub mod body;
pub mod cli;
pub mod drum;
pub mod exports;
pub mod io;
pub mod kit;
pub mod mocap;
pub mod motion;
pub mod render;
pub mod scene;
pub mod score;
pub mod sound;
pub mod transcribe;
