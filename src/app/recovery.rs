//! Autosave and crash recovery. A few seconds after the score changes, the editor writes
//! it (with the file it came from) to a recovery file beside the recent-files list,
//! atomically, so a crash, a `kill -9` or a power cut costs at most those seconds. A save,
//! discarding the changes or a clean quit removes the file; the next start finds a file
//! left behind and offers to restore it. One recovery file serves one editor at a time.

use super::document::Document;
use crate::base::ron_file::{self, FileError};
use crate::score::{LoadedScore, Score};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The score is written once it has been left alone this long after a change, s.
pub const QUIET_S: f64 = 2.0;
/// ...or at the latest this long after the first change it has not written, s (edits
/// without a pause still get saved).
pub const AT_MOST_S: f64 = 10.0;

/// The recovery file's format version.
const VERSION: u32 = 1;

/// `recovery.ron` in the editor's configuration folder ($XDG_CONFIG_HOME/timpanist or
/// ~/.config/timpanist); `None` without a home.
pub fn default_file() -> Option<PathBuf> {
    crate::base::dirs::config_dir().map(|d| d.join("recovery.ron"))
}

/// What the recovery file holds.
#[derive(Serialize, Deserialize)]
#[serde(rename = "Recovery")]
struct RecoveryFile {
    version: u32,
    /// The file the score was opened from or last saved to (its kit path is relative to
    /// it); `None` for a new, imported or demo score.
    original: Option<PathBuf>,
    score: Score,
}

/// A score found in the recovery file.
pub struct Recovered {
    pub loaded: LoadedScore,
    pub original: Option<PathBuf>,
}

/// The autosave of one editor: when the open score changed and what was written.
pub struct Recovery {
    file: Option<PathBuf>,
    /// The revision written (a new document restarts it).
    written: Option<u64>,
    /// Whether the recovery file on disk is this session's to remove once nothing is
    /// unsaved (it wrote it, or restored from it).
    owned: bool,
    /// When the revision not yet written was first seen, and when the last change was
    /// seen (egui time, s).
    first_change_s: Option<f64>,
    last_change_s: f64,
    last_revision: Option<u64>,
}

impl Recovery {
    /// Autosave to `file` (`None`: nowhere).
    pub fn new(file: Option<PathBuf>) -> Recovery {
        Recovery {
            file,
            written: None,
            owned: false,
            first_change_s: None,
            last_change_s: 0.0,
            last_revision: None,
        }
    }

    /// The score a previous session left in the recovery file, if there is one. A file
    /// that cannot be read back is an error naming it (and is kept, for the user).
    pub fn left_behind(&self) -> Option<Result<Recovered, FileError>> {
        let file = self.file.as_deref().filter(|f| f.exists())?;
        Some(read(file))
    }

    /// The open document was restored from the recovery file: the file is this
    /// session's (a save removes it).
    pub fn adopt(&mut self) {
        self.owned = true;
    }

    /// A new document was opened: nothing of it is written yet.
    pub fn restart(&mut self) {
        self.written = None;
        self.first_change_s = None;
        self.last_revision = None;
    }

    /// Called once a frame at egui time `now_s` with the open document: writes it when it
    /// has unsaved changes not yet written and has been left alone [`QUIET_S`] (or
    /// changed for [`AT_MOST_S`]), and removes the file once there is nothing unsaved.
    /// Returns whether it wrote.
    pub fn tick(&mut self, doc: Option<&Document>, now_s: f64) -> Result<bool, FileError> {
        let Some(doc) = doc.filter(|d| d.is_dirty()) else {
            self.first_change_s = None;
            self.written = None;
            if self.owned {
                self.remove()?;
            }
            return Ok(false);
        };
        let revision = doc.revision();
        if self.written == Some(revision) {
            return Ok(false);
        }
        if self.last_revision != Some(revision) {
            self.last_revision = Some(revision);
            self.last_change_s = now_s;
            self.first_change_s.get_or_insert(now_s);
        }
        let first = self.first_change_s.unwrap_or(now_s);
        if now_s - self.last_change_s < QUIET_S && now_s - first < AT_MOST_S {
            return Ok(false);
        }
        self.write(doc)?;
        self.written = Some(revision);
        self.owned = true;
        self.first_change_s = None;
        Ok(true)
    }

    /// Whether a change is waiting to be written (the window should wake to write it).
    pub fn waiting(&self, doc: Option<&Document>) -> bool {
        doc.is_some_and(|d| d.is_dirty() && self.written != Some(d.revision()))
    }

    /// Write `doc` to the recovery file now (atomically).
    pub fn write(&self, doc: &Document) -> Result<(), FileError> {
        let Some(file) = &self.file else {
            return Ok(());
        };
        if let Some(dir) = file.parent() {
            std::fs::create_dir_all(dir).map_err(|source| FileError::Io {
                path: dir.to_path_buf(),
                source,
            })?;
        }
        let content = RecoveryFile {
            version: VERSION,
            original: doc.path.clone(),
            score: doc.loaded.score.clone(),
        };
        let text = format!(
            "// timpanist's autosave of a score with unsaved changes (README \"Editor\"):\n\
             // offered back at the next start, removed by a save or a clean quit.\n{}",
            ron_file::to_pretty(&content)
        );
        ron_file::write_atomic(file, text.as_bytes())
    }

    /// Remove the recovery file (nothing to recover: saved, discarded or quit cleanly).
    pub fn remove(&mut self) -> Result<(), FileError> {
        self.written = None;
        self.owned = false;
        let Some(file) = &self.file else {
            return Ok(());
        };
        match std::fs::remove_file(file) {
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => Err(FileError::Io {
                path: file.clone(),
                source: e,
            }),
            _ => Ok(()),
        }
    }
}

/// Read a recovery file back: its score loaded against the file it came from (so a kit
/// given by a relative path is found), or against the recovery file's folder.
fn read(file: &Path) -> Result<Recovered, FileError> {
    let content: RecoveryFile = ron_file::parse(file, &ron_file::read_text(file)?)?;
    let base = content
        .original
        .clone()
        .unwrap_or_else(|| file.to_path_buf());
    let loaded = LoadedScore::parse(&base, &content.score.to_ron())?;
    Ok(Recovered {
        loaded,
        original: content.original,
    })
}
