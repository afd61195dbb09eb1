//! File adapters: strict RON files with atomic saving, Standard MIDI Files in and out,
//! and composed and simulated motion as CSV and C3D.

pub mod midi_export;
pub mod midi_import;
pub mod motion_c3d;
pub mod motion_csv;
pub mod plot;
pub mod ron_file;
pub mod tips_csv;

pub use ron_file::FileError;
