//! From score to motion: hand assignment (sticking) now; motion-unit planning, splicing and
//! co-articulation build on it.

pub mod compose;
pub mod plan;
pub mod sticking;
