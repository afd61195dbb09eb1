//! From score to motion: hand assignment (sticking), planning strokes with motion units,
//! splicing and co-articulating them into two stick-tip trajectories, the free hand's
//! damping of secco beats, and the user's edit handles on top.

pub mod compose;
pub mod handles;
pub mod muffle;
pub mod perform;
pub mod plan;
pub mod sticking;
