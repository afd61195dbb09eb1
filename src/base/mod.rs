//! The ground floor: the vocabulary every other layer shares and nothing else. Musical
//! pitch, problems found while checking a file, the deterministic random generator,
//! strict RON reading, atomic writing (`staged`), the limits inputs are held to, the median, the
//! words of a gesture score (side, hand, playing mode, grip, dynamic, impact location), a
//! performed hit (`hit`: what `render` makes and `io` writes) and the choices its settings
//! make (control pipeline, IK method, mode frequencies, sound model), work spread over
//! threads in order (`parallel`) and records kept in shared chunks that clone without a
//! copy (`chunks`), and the names scores give the timpani part (`instrument_name`).
//! Imports no other module of the crate.

pub mod choices;
pub mod chunks;
pub mod dirs;
pub mod gesture;
pub mod hit;
pub mod instrument_name;
pub mod limits;
pub mod parallel;
pub mod pitch;
pub mod problem;
pub mod rng;
pub mod ron_file;
pub mod staged;
pub mod stats;
