//! File adapters: strict RON files with atomic saving, and Standard MIDI Files in and out.

pub mod midi_export;
pub mod midi_import;
pub mod plot;
pub mod ron_file;
pub mod tips_csv;

pub use ron_file::FileError;
