//! Opening any file that holds a score, the way users open files: a score (`.ron`) is
//! loaded, a MIDI file (`.mid`), a MusicXML file (`.musicxml`, `.xml`, `.mxl`) or a
//! recording (`.wav`, `.aiff`, `.flac`, `.mp3`, `.ogg`: transcribed) is imported onto the bundled standard kit as a new,
//! unsaved score. Used by the editor's
//! Open, drag and drop, and by `timpanist FILE`; headless, so it is testable without a
//! window. A score listing its beats out of time order is opened with a note: the editor
//! holds and saves them in time order, so its beat numbers are not yet the file's.

use super::midi_import::{self, MidiError};
use super::musicxml::{self, MusicXmlError};
use crate::base::ron_file::FileError;
use crate::kit::Kit;
use crate::score::{BeatPlaces, LoadedScore};
use crate::sound::recording;
use crate::transcribe::{self, TranscribeError};
use std::path::{Path, PathBuf};

/// What a file is, judged by its extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FileKind {
    Score,
    Midi,
    MusicXml,
    /// A recording, transcribed.
    Audio,
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
        Some("musicxml" | "xml" | "mxl") => FileKind::MusicXml,
        Some(ext) if recording::EXTENSIONS.contains(&ext) => FileKind::Audio,
        _ => FileKind::Other,
    }
}

/// Every extension the editor opens: scores, MIDI, MusicXML and recordings.
pub const OPENABLE_EXTENSIONS: [&str; 15] = joined(
    ["ron", "mid", "midi", "musicxml", "xml", "mxl"],
    recording::EXTENSIONS,
);

/// `a` then `b`, at compile time (`N` = `A` + `B`, or it does not compile).
const fn joined<const A: usize, const B: usize, const N: usize>(
    a: [&'static str; A],
    b: [&'static str; B],
) -> [&'static str; N] {
    assert!(A + B == N);
    let mut out = [""; N];
    let mut i = 0;
    while i < N {
        out[i] = if i < A { a[i] } else { b[i - A] };
        i += 1;
    }
    out
}

/// What `timpanist FILE` does with a file.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum OpenAction {
    /// Open the score file in the editor (saving writes it back).
    Edit(PathBuf),
    /// Import the file into a new, unsaved score and open that in the editor.
    Import(PathBuf, FileKind),
}

/// The action for a file given on the command line: refused, naming the file, when it
/// does not exist or is not a score, MIDI, MusicXML or recording file.
pub fn action_for(path: &Path) -> Result<OpenAction, OpenError> {
    let kind = kind_of(path);
    if kind == FileKind::Other {
        return Err(OpenError::NotAScore(path.to_path_buf()));
    }
    if !path.is_file() {
        return Err(OpenError::Missing(path.to_path_buf()));
    }
    Ok(match kind {
        FileKind::Score => OpenAction::Edit(path.to_path_buf()),
        kind => OpenAction::Import(path.to_path_buf(), kind),
    })
}

/// A document read from disk, ready to open: the score, and whether it still has to be
/// saved somewhere (imports have no score file yet).
#[derive(Debug)]
pub struct Opened {
    pub loaded: LoadedScore,
    /// Where it is saved; `None` for an import.
    pub path: Option<PathBuf>,
    /// A message for the status bar.
    pub message: String,
    /// What the import reported (each also in `message`).
    pub notices: Vec<String>,
}

/// Why a file did not open.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum OpenError {
    #[error(transparent)]
    Score(#[from] FileError),
    #[error(transparent)]
    Midi(#[from] MidiError),
    #[error(transparent)]
    MusicXml(#[from] MusicXmlError),
    #[error(transparent)]
    Audio(#[from] TranscribeError),
    #[error(
        "{}: not a score (.ron), MIDI (.mid), MusicXML (.musicxml, .xml, .mxl) or recording (.wav, .aiff, .flac, .mp3, .ogg) file",
        .0.display()
    )]
    NotAScore(PathBuf),
    #[error("{}: no such file", .0.display())]
    Missing(PathBuf),
    #[error("the bundled standard kit is missing")]
    NoKit,
}

/// Read a score file or import a MIDI, MusicXML or recording file, by extension.
pub fn read(path: &Path) -> Result<Opened, OpenError> {
    match kind_of(path) {
        FileKind::Score => {
            let (mut loaded, places) = LoadedScore::load_placed(path)?;
            loaded.notices.extend(order_notice(path, &places));
            let mut message = format!("opened {}", path.display());
            if !loaded.notices.is_empty() {
                message = loaded.notices.join("; ");
            }
            Ok(Opened {
                notices: loaded.notices.clone(),
                loaded,
                path: Some(path.to_path_buf()),
                message,
            })
        }
        FileKind::Midi => import_midi(path),
        FileKind::MusicXml => import_musicxml(path),
        FileKind::Audio => import_audio(path),
        FileKind::Other => Err(OpenError::NotAScore(path.to_path_buf())),
    }
}

/// The note for a score file listing its beats out of time order (`places`): `check`
/// and `render` number its beats as the file lists them, the editor as it holds them.
fn order_notice(path: &Path, places: &BeatPlaces) -> Option<String> {
    (!places.in_time_order()).then(|| {
        format!(
            "{}: the beats are listed out of time order; the editor numbers them in time order, as Save writes them (check and render number the file's list)",
            path.display()
        )
    })
}

/// An import as a new, unsaved document on the bundled standard kit.
fn imported(score: crate::score::Score, kit: Kit, summary: String, notices: Vec<String>) -> Opened {
    let mut message = summary;
    for n in &notices {
        message.push_str("; ");
        message.push_str(n);
    }
    Opened {
        loaded: LoadedScore {
            score,
            kit,
            kit_source: "bundled kit \"standard\"".into(),
            notices: Vec::new(),
        },
        path: None,
        message,
        notices,
    }
}

/// Import a MIDI file onto the bundled standard kit as a new, unsaved score.
pub fn import_midi(path: &Path) -> Result<Opened, OpenError> {
    let kit = Kit::bundled("standard").ok_or(OpenError::NoKit)?;
    let options = midi_import::ImportOptions::default();
    let (score, report) = midi_import::import_file(path, &kit, &options)?;
    let summary = format!(
        "imported {} notes from {} ({})",
        report.notes,
        path.display(),
        report.source
    );
    Ok(imported(score, kit, summary, report.warnings))
}

/// Import a MusicXML file onto the bundled standard kit as a new, unsaved score.
pub fn import_musicxml(path: &Path) -> Result<Opened, OpenError> {
    let kit = Kit::bundled("standard").ok_or(OpenError::NoKit)?;
    let options = musicxml::ImportOptions::default();
    let (score, report) = musicxml::import_file(path, &kit, &options)?;
    let summary = format!(
        "imported {} notes from {} ({})",
        report.notes,
        path.display(),
        report.source
    );
    Ok(imported(score, kit, summary, report.notices))
}

/// Transcribe a recording onto the bundled standard kit as a new, unsaved score.
pub fn import_audio(path: &Path) -> Result<Opened, OpenError> {
    let kit = Kit::bundled("standard").ok_or(OpenError::NoKit)?;
    let (score, report) = transcribe::transcribe_file(path, &kit, &transcribe::Options::default())?;
    let summary = format!(
        "transcribed {} strokes from {} ({} rolls, {:.0} bpm)",
        report.strokes,
        path.display(),
        report.rolls,
        report.bpm
    );
    Ok(imported(score, kit, summary, report.notices))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Extensions decide the kind, case-insensitively.
    #[test]
    fn kinds() {
        assert_eq!(kind_of(Path::new("a/b.RON")), FileKind::Score);
        assert_eq!(kind_of(Path::new("x.mid")), FileKind::Midi);
        assert_eq!(kind_of(Path::new("x.MXL")), FileKind::MusicXml);
        assert_eq!(kind_of(Path::new("x.musicxml")), FileKind::MusicXml);
        assert_eq!(kind_of(Path::new("x.WAV")), FileKind::Audio);
        assert_eq!(kind_of(Path::new("take.flac")), FileKind::Audio);
        assert_eq!(kind_of(Path::new("take.Mp3")), FileKind::Audio);
        assert_eq!(kind_of(Path::new("take.m4a")), FileKind::Other);
        for ext in OPENABLE_EXTENSIONS {
            let kind = kind_of(Path::new(&format!("x.{ext}")));
            assert_ne!(kind, FileKind::Other, "{ext}");
        }
        assert_eq!(kind_of(Path::new("x.txt")), FileKind::Other);
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
        let xml = dir.path().join("bad.musicxml");
        std::fs::write(&xml, b"<score-partwise><part-list>").unwrap();
        assert!(
            read(&xml)
                .err()
                .unwrap()
                .to_string()
                .contains("bad.musicxml")
        );
        assert!(
            read(Path::new("x.txt"))
                .err()
                .unwrap()
                .to_string()
                .contains("x.txt")
        );
    }
}
