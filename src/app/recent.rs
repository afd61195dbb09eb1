//! The recent-files list: most recent first, at most [`MAX_RECENT`], kept in a plain text
//! file (one path per line) whose location is injectable so tests never touch the real
//! home; by default `$XDG_CONFIG_HOME/timpanist/recent.txt` (or `~/.config/...`).

use crate::base::ron_file::{self, FileError};
use std::path::{Path, PathBuf};

/// How many recent files are kept.
pub const MAX_RECENT: usize = 10;

/// The recent files and where they are stored.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RecentFiles {
    /// The list file; `None` keeps the list in memory only.
    store: Option<PathBuf>,
    paths: Vec<PathBuf>,
}

/// The default list file under the user's config directory, if a home is known.
pub fn default_store() -> Option<PathBuf> {
    crate::base::dirs::config_dir().map(|d| d.join("recent.txt"))
}

impl RecentFiles {
    /// Read the list kept in `store` (a missing or unreadable file is an empty list).
    pub fn load(store: Option<PathBuf>) -> RecentFiles {
        let paths = store
            .as_deref()
            .and_then(|s| std::fs::read_to_string(s).ok())
            .map(|text| {
                text.lines()
                    .filter(|l| !l.trim().is_empty())
                    .map(PathBuf::from)
                    .take(MAX_RECENT)
                    .collect()
            })
            .unwrap_or_default();
        RecentFiles { store, paths }
    }

    /// The paths, most recent first.
    pub fn paths(&self) -> &[PathBuf] {
        &self.paths
    }

    /// Put `path` first and write the list; an error writing the list is returned.
    pub fn add(&mut self, path: &Path) -> Result<(), FileError> {
        let path = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
        self.paths.retain(|p| *p != path);
        self.paths.insert(0, path);
        self.paths.truncate(MAX_RECENT);
        self.write()
    }

    /// Drop `path` (e.g. it no longer opens) and write the list.
    pub fn remove(&mut self, path: &Path) -> Result<(), FileError> {
        self.paths.retain(|p| p != path);
        self.write()
    }

    fn write(&self) -> Result<(), FileError> {
        let Some(store) = &self.store else {
            return Ok(());
        };
        let text: String = self
            .paths
            .iter()
            .map(|p| format!("{}\n", p.display()))
            .collect();
        if let Some(dir) = store.parent() {
            std::fs::create_dir_all(dir).map_err(|source| FileError::Io {
                path: dir.to_path_buf(),
                source,
            })?;
        }
        ron_file::write_atomic(store, text.as_bytes())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Adding moves a path to the front without duplicates, keeps at most MAX_RECENT, and
    /// the list survives a reload from its file.
    #[test]
    fn add_dedup_persist() {
        let dir = tempfile::tempdir().unwrap();
        let store = dir.path().join("cfg/recent.txt");
        let mut r = RecentFiles::load(Some(store.clone()));
        assert!(r.paths().is_empty());
        for k in 0..12 {
            r.add(&dir.path().join(format!("s{k}.ron"))).unwrap();
        }
        r.add(&dir.path().join("s5.ron")).unwrap();
        assert_eq!(r.paths().len(), MAX_RECENT);
        assert_eq!(r.paths()[0], dir.path().join("s5.ron"));
        assert_eq!(r.paths()[1], dir.path().join("s11.ron"));
        let again = RecentFiles::load(Some(store));
        assert_eq!(again.paths(), r.paths());
        let mut r = again;
        r.remove(&dir.path().join("s5.ron")).unwrap();
        assert_eq!(r.paths()[0], dir.path().join("s11.ron"));
    }
}
