//! Reading documents into the editor: score files (`.ron`) and MIDI imports (`.mid`),
//! by explicit open or by drag and drop; every failure becomes a message for the window.

use crate::base::ron_file::FileError;
use crate::io::midi_import::{ImportOptions, MidiError, import_file};
use crate::kit::Kit;
use crate::score::LoadedScore;
use std::path::{Path, PathBuf};

/// What a file is, judged by its extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FileKind {
    Score,
    Midi,
    Other,
}

/// The kind of `path`, from its extension (case-insensitive).
pub fn kind_of(path: &Path) -> FileKind {
    match path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .as_deref()
    {
        Some("ron") => FileKind::Score,
        Some("mid" | "midi" | "smf") => FileKind::Midi,
        _ => FileKind::Other,
    }
}

/// A document read from disk, ready to open: the score, and whether it still has to be
/// saved somewhere (imports have no score file yet).
pub struct Opened {
    pub loaded: LoadedScore,
    /// Where it is saved; `None` for an import.
    pub path: Option<std::path::PathBuf>,
    /// A message for the status bar.
    pub message: String,
}

/// Why a file did not open.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum OpenError {
    #[error(transparent)]
    Score(#[from] FileError),
    #[error(transparent)]
    Midi(#[from] MidiError),
    #[error("{}: not a score (.ron) or MIDI (.mid) file", .0.display())]
    NotAScore(PathBuf),
    #[error("the bundled standard kit is missing")]
    NoKit,
}

/// Read a score file or import a MIDI file, by extension.
pub fn read(path: &Path) -> Result<Opened, OpenError> {
    match kind_of(path) {
        FileKind::Score => {
            let loaded = LoadedScore::load(path)?;
            let mut message = format!("opened {}", path.display());
            if !loaded.notices.is_empty() {
                message = loaded.notices.join("; ");
            }
            Ok(Opened {
                loaded,
                path: Some(path.to_path_buf()),
                message,
            })
        }
        FileKind::Midi => import_midi(path),
        FileKind::Other => Err(OpenError::NotAScore(path.to_path_buf())),
    }
}

/// Import a MIDI file onto the bundled standard kit as a new, unsaved score.
pub fn import_midi(path: &Path) -> Result<Opened, OpenError> {
    let kit = Kit::bundled("standard").ok_or(OpenError::NoKit)?;
    let (score, report) = import_file(path, &kit, &ImportOptions::default())?;
    let mut message = format!(
        "imported {} notes from {} ({})",
        report.notes,
        path.display(),
        report.source
    );
    for w in &report.warnings {
        message.push_str("; ");
        message.push_str(w);
    }
    Ok(Opened {
        loaded: LoadedScore {
            score,
            kit,
            kit_source: "bundled kit \"standard\"".into(),
            notices: Vec::new(),
        },
        path: None,
        message,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Extensions decide the kind, case-insensitively.
    #[test]
    fn kinds() {
        assert_eq!(kind_of(Path::new("a/b.RON")), FileKind::Score);
        assert_eq!(kind_of(Path::new("x.mid")), FileKind::Midi);
        assert_eq!(kind_of(Path::new("x.wav")), FileKind::Other);
        assert_eq!(kind_of(Path::new("noext")), FileKind::Other);
    }

    /// Unreadable files give messages naming them, never a panic.
    #[test]
    fn errors_are_messages() {
        let dir = tempfile::tempdir().unwrap();
        let bad = dir.path().join("bad.ron");
        std::fs::write(&bad, "Score(nonsense").unwrap();
        assert!(read(&bad).err().unwrap().to_string().contains("bad.ron"));
        let mid = dir.path().join("bad.mid");
        std::fs::write(&mid, b"not midi").unwrap();
        assert!(read(&mid).err().unwrap().to_string().contains("bad.mid"));
        assert!(
            read(Path::new("x.txt"))
                .err()
                .unwrap()
                .to_string()
                .contains("x.txt")
        );
    }
}
