//! Which motion database a command uses when none is named, and the copy of the shipped
//! synthetic database compiled into the program, so an installed binary (after
//! `cargo install`, from the Debian package, or copied alone) works with no source tree.
//!
//! The search order ([`locate`]): the folder named with `--db`; `./mocap` when the working
//! directory has one; the user's data folder (`~/.local/share/timpanist/mocap`); the data
//! installed with the program (`<prefix>/share/timpanist/mocap`, e.g.
//! `/usr/share/timpanist/mocap`); else the built-in copy. A folder counts only when it
//! holds an `index.ron`.

use super::db::MotionDb;
use crate::base::dirs;
use crate::base::ron_file::FileError;
use include_dir::{Dir, include_dir};
use std::fmt;
use std::path::{Path, PathBuf};

/// The shipped `mocap/` folder (index, takes, capture profiles), compiled in.
static BUILT_IN: Dir<'static> = include_dir!("$CARGO_MANIFEST_DIR/mocap");

/// How the built-in database's files are named in messages.
const BUILT_IN_LABEL: &str = "<built-in>/mocap";

/// Where a motion database is read from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum DbSource {
    /// A database folder (holding `index.ron` and the sample files).
    Folder(PathBuf),
    /// The copy of the shipped database compiled into the program.
    BuiltIn,
}

impl fmt::Display for DbSource {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DbSource::Folder(dir) => write!(f, "{}", dir.display()),
            DbSource::BuiltIn => write!(f, "the built-in synthetic database"),
        }
    }
}

impl DbSource {
    /// `--db DIR` when given, else [`locate`].
    pub fn named_or_located(named: Option<PathBuf>) -> DbSource {
        named.map_or_else(locate, DbSource::Folder)
    }

    /// Read the database.
    pub fn load(&self) -> Result<MotionDb, FileError> {
        match self {
            DbSource::Folder(dir) => MotionDb::load(dir),
            DbSource::BuiltIn => built_in(),
        }
    }
}

/// The folders searched, in order, before the built-in copy.
pub fn search_folders() -> Vec<PathBuf> {
    let mut folders = vec![PathBuf::from("mocap")];
    folders.extend(dirs::data_dir().map(|d| d.join("mocap")));
    folders.extend(dirs::installed_data_dir().map(|d| d.join("mocap")));
    folders
}

/// The first of [`search_folders`] holding an `index.ron`, else the built-in copy.
pub fn locate() -> DbSource {
    search_folders()
        .into_iter()
        .find(|d| d.join("index.ron").is_file())
        .map_or(DbSource::BuiltIn, DbSource::Folder)
}

/// The shipped synthetic database, from the copy compiled into the program.
pub fn built_in() -> Result<MotionDb, FileError> {
    let dir = Path::new(BUILT_IN_LABEL);
    let missing = |path: &Path| {
        FileError::io(
            path,
            std::io::Error::new(std::io::ErrorKind::NotFound, "not in the built-in database"),
        )
    };
    let file = |path: &Path| {
        let inside = path.strip_prefix(dir).unwrap_or(path);
        BUILT_IN.get_file(inside).ok_or_else(|| missing(path))
    };
    let index_path = dir.join("index.ron");
    let text = file(&index_path)?
        .contents_utf8()
        .ok_or_else(|| FileError::invalid(&index_path, "text", "not UTF-8"))?;
    MotionDb::from_parts(dir, text, &|path| Ok(file(path)?.contents().to_vec()))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The built-in copy is the shipped folder, unit for unit and sample for sample.
    #[test]
    fn the_built_in_database_is_the_shipped_folder() {
        let folder = MotionDb::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("mocap"))
            .expect("the shipped folder loads");
        let embedded = built_in().expect("the built-in copy loads");
        assert_eq!(embedded.index, folder.index);
        assert_eq!(embedded.takes.len(), folder.takes.len());
        for (a, b) in embedded.takes.iter().zip(&folder.takes) {
            assert_eq!(a.tips, b.tips);
            assert_eq!(a.joints, b.joints);
        }
    }

    /// A folder without `index.ron` is passed over; one with it is chosen.
    #[test]
    fn the_search_takes_the_first_folder_with_an_index() {
        assert!(search_folders()[0] == Path::new("mocap"));
        let named = DbSource::named_or_located(Some(PathBuf::from("/nowhere")));
        assert_eq!(named, DbSource::Folder(PathBuf::from("/nowhere")));
        let err = named.load().expect_err("no database there");
        assert!(err.to_string().contains("/nowhere/index.ron"), "{err}");
    }
}
