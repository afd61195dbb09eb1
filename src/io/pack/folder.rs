//! Writing a folder atomically: the pack is built in a hidden staging folder beside its
//! target (`.NAME.partial-XXXXXX`, same file system, so the final step is a rename) and
//! only renamed into place once every file is written. A target that exists and holds
//! anything is refused unless replacing was asked for; an error, or dropping the
//! [`Staging`] without committing, removes the staging folder, so no half-written pack is
//! ever seen at the target. (A process killed mid-way leaves only the hidden staging
//! folder.)

use super::PackError;
use std::path::{Path, PathBuf};

/// A folder being filled, to be renamed to its target by [`Staging::commit`].
#[derive(Debug)]
pub struct Staging {
    dir: tempfile::TempDir,
    target: PathBuf,
}

/// Whether `path` is a folder holding anything.
fn holds_anything(path: &Path) -> Result<bool, PackError> {
    let io = |source| PackError::Io {
        path: path.to_path_buf(),
        source,
    };
    Ok(std::fs::read_dir(path).map_err(io)?.next().is_some())
}

/// Whether a pack may be written at `target`: refused when it is a file, or a folder
/// holding anything unless `replace`. Changes nothing.
pub fn check(target: &Path, replace: bool) -> Result<(), PackError> {
    if target.exists() {
        if !target.is_dir() {
            return Err(PackError::NotAFolder {
                path: target.to_path_buf(),
            });
        }
        if !replace && holds_anything(target)? {
            return Err(PackError::NotEmpty {
                path: target.to_path_buf(),
            });
        }
    }
    Ok(())
}

impl Staging {
    /// [`check`] `target` and make the staging folder beside it (creating the folders
    /// above `target` if missing).
    pub fn begin(target: &Path, replace: bool) -> Result<Staging, PackError> {
        check(target, replace)?;
        let parent = crate::base::staged::folder_of(target).to_path_buf();
        let name = target
            .file_name()
            .ok_or_else(|| PackError::NoName {
                path: target.to_path_buf(),
            })?
            .to_string_lossy()
            .into_owned();
        let io = |source| PackError::Io {
            path: parent.clone(),
            source,
        };
        std::fs::create_dir_all(&parent).map_err(io)?;
        let dir = tempfile::Builder::new()
            .prefix(&format!(".{name}.partial-"))
            .tempdir_in(&parent)
            .map_err(io)?;
        Ok(Staging {
            dir,
            target: target.to_path_buf(),
        })
    }

    /// The staging folder to write into.
    pub fn path(&self) -> &Path {
        self.dir.path()
    }

    /// A folder `relative` inside the staging folder, created.
    pub fn folder(&self, relative: &str) -> Result<PathBuf, PackError> {
        let path = self.dir.path().join(relative);
        std::fs::create_dir_all(&path).map_err(|source| PackError::Io {
            path: path.clone(),
            source,
        })?;
        Ok(path)
    }

    /// Put the staged folder at its target: renamed into place; a target folder already
    /// there (empty, or allowed to be replaced by [`Staging::begin`]) is first moved aside
    /// and removed once the new one is in place (put back if the rename fails).
    pub fn commit(self) -> Result<PathBuf, PackError> {
        let Staging { dir, target } = self;
        let io = |path: &Path| {
            let path = path.to_path_buf();
            move |source| PackError::Io { path, source }
        };
        // Readable by others as a folder made by mkdir would be (the staging folder is
        // made private).
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            std::fs::set_permissions(dir.path(), std::fs::Permissions::from_mode(0o755))
                .map_err(io(dir.path()))?;
        }
        let old = if target.exists() {
            let parent = dir.path().parent().unwrap_or(Path::new("."));
            let aside = tempfile::Builder::new()
                .prefix(".timpanist-replaced-")
                .tempdir_in(parent)
                .map_err(io(parent))?;
            let aside_path = aside.path().join("old");
            std::fs::rename(&target, &aside_path).map_err(io(&target))?;
            Some((aside, aside_path))
        } else {
            None
        };
        let staged = dir.keep();
        if let Err(source) = std::fs::rename(&staged, &target) {
            if let Some((_, aside_path)) = &old {
                let _ = std::fs::rename(aside_path, &target);
            }
            let _ = std::fs::remove_dir_all(&staged);
            return Err(PackError::Io {
                path: target,
                source,
            });
        }
        // Dropping the aside folder removes the replaced pack.
        drop(old);
        Ok(target)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A new folder appears only at commit; dropping a staging leaves nothing; a folder
    /// holding a file is refused unless replaced, and replacing leaves only the new files.
    #[test]
    fn atomic_folder() {
        let root = tempfile::tempdir().unwrap();
        let target = root.path().join("pack");
        let staging = Staging::begin(&target, false).unwrap();
        std::fs::write(staging.path().join("a.txt"), "a").unwrap();
        assert!(!target.exists());
        drop(staging);
        assert_eq!(std::fs::read_dir(root.path()).unwrap().count(), 0);

        let staging = Staging::begin(&target, false).unwrap();
        std::fs::write(staging.path().join("a.txt"), "a").unwrap();
        assert_eq!(staging.commit().unwrap(), target);
        assert!(target.join("a.txt").exists());

        let refused = Staging::begin(&target, false).unwrap_err();
        assert!(matches!(refused, PackError::NotEmpty { .. }), "{refused}");
        assert!(refused.to_string().contains(&target.display().to_string()));

        let staging = Staging::begin(&target, true).unwrap();
        std::fs::write(staging.path().join("b.txt"), "b").unwrap();
        staging.commit().unwrap();
        assert!(!target.join("a.txt").exists() && target.join("b.txt").exists());
        let names: Vec<_> = std::fs::read_dir(root.path())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names, ["pack"], "nothing left beside the pack");

        let file = root.path().join("file");
        std::fs::write(&file, "x").unwrap();
        assert!(matches!(
            Staging::begin(&file, true).unwrap_err(),
            PackError::NotAFolder { .. }
        ));
    }
}
