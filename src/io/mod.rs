//! File adapters over what the layers below make: Standard MIDI Files in and out (the
//! score, and the performed hits; their text in Latin-1 or ASCII, `midi_text`), MusicXML in, opening any score-bearing file (`open`),
//! composed and simulated motion as CSV, C3D and BVH, the scene as glTF (`.glb`; BVH and
//! glTF share the Y-up axes of `y_up`), OSC messages of the performed hits, PNG and SVG
//! figures (`plot`, and the performance's own in `figures`), and the lesson pack (`pack`).
//! A rendering reaches the writers as plain parts (`performance`). (Strict RON reading
//! and atomic writing are on the ground floor, `base::ron_file`, since kits and scores use
//! them.)

pub mod bvh;
pub mod c3d_write;
pub mod figures;
pub mod glb;
pub mod midi_export;
pub mod midi_import;
pub mod midi_performed;
pub mod midi_text;
pub mod motion_c3d;
pub mod motion_csv;
pub mod musicxml;
pub mod musicxml_export;
pub mod open;
pub mod osc;
pub mod pack;
pub mod performance;
pub mod plot;
pub mod tips_csv;
pub mod video;
pub mod y_up;
