//! Motion capture: reading captures from real systems, cutting them into one-stroke motion
//! units, the on-disk motion database, the synthetic performer that builds the shipped
//! database (joint-limit estimation from its captures lives in `body::limits`).

pub mod align;
pub mod db;
pub mod import;
pub mod ingest;
pub mod labcorpus;
pub mod marker_body;
pub mod segment;
pub mod shipped;
pub mod stats;
pub mod synth;
pub mod take;
pub mod tip_estimate;
pub mod vertical;

pub use take::{ImportError, MarkedGaps, Take, Track};
