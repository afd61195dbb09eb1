//! Motion capture: reading captures from real systems, cutting them into one-stroke motion
//! units, the on-disk motion database, the synthetic performer that builds the shipped
//! database (joint-limit estimation from its captures lives in `body::limits`).

pub mod db;
pub mod import;
pub mod ingest;
pub mod segment;
pub mod stats;
pub mod synth;
pub mod take;

pub use take::{ImportError, Take, Track};
