//! Reading documents into the editor: score files (`.ron`), MIDI (`.mid`) and MusicXML
//! (`.musicxml`, `.xml`, `.mxl`) imports, by explicit open or by drag and drop; every
//! failure becomes a message for the window. The reading itself is `io::open`'s (the
//! command line's `timpanist FILE` uses it too).

pub use crate::io::open::{FileKind, Opened, kind_of, read};
