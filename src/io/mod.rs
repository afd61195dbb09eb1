//! File adapters: strict RON files with atomic saving, and Standard MIDI Files in and out.

pub mod midi_export;
pub mod midi_import;
pub mod ron_file;

pub use ron_file::FileError;
