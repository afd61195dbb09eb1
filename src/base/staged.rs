//! Writing a file so that a crash or an error never leaves it half-written: the bytes go
//! to a temporary file beside the destination (rw-r--r--, or the mode of the file it
//! replaces), which is synced and then renamed over it. A destination that is a link is
//! followed (its target replaced, the link kept); one that is a device or a pipe
//! (`/dev/null`, a FIFO) is written through, never replaced by a plain file.

use std::path::{Path, PathBuf};

/// Where a write to `path` lands: the file a link leads to, else `path` itself.
pub fn destination(path: &Path) -> PathBuf {
    let is_link = std::fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink());
    if !is_link {
        return path.to_path_buf();
    }
    std::fs::canonicalize(path).unwrap_or_else(|_| {
        // A dangling link: the file it names, relative to the link's folder.
        let target = std::fs::read_link(path).unwrap_or_else(|_| path.to_path_buf());
        path.parent()
            .map_or(target.clone(), |dir| dir.join(&target))
    })
}

/// The folder `path` is in: its parent, or `.` for a bare file name.
pub fn folder_of(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// Whether `dest` is a device, a pipe or a socket: written into, never replaced.
fn is_special(dest: &Path) -> bool {
    std::fs::metadata(dest).is_ok_and(|m| !m.is_file() && !m.is_dir())
}

/// A temporary file in `dest`'s folder (named `.timpanist-….suffix`; for a device or a
/// pipe, in the system's temporary folder) to write what will replace `dest`, with the
/// permissions `dest` has, or rw-r--r-- (less the umask) for a new file.
pub fn beside(dest: &Path, suffix: &str) -> std::io::Result<tempfile::NamedTempFile> {
    let temp_dir = std::env::temp_dir();
    let dir = if is_special(dest) {
        temp_dir.as_path()
    } else {
        folder_of(dest)
    };
    let mut builder = tempfile::Builder::new();
    builder.prefix(".timpanist-").suffix(suffix);
    #[cfg(unix)]
    builder.permissions(std::fs::metadata(dest).map_or_else(
        |_| std::os::unix::fs::PermissionsExt::from_mode(0o644),
        |m| m.permissions(),
    ));
    builder.tempfile_in(dir)
}

/// Put the written temporary file `staged` in place of `dest` (from [`destination`]):
/// renamed over a regular file or a new name; copied into a device or a pipe.
pub fn put(staged: tempfile::TempPath, dest: &Path) -> std::io::Result<()> {
    if is_special(dest) {
        let mut from = std::fs::File::open(&staged)?;
        let mut to = std::fs::OpenOptions::new().write(true).open(dest)?;
        std::io::copy(&mut from, &mut to)?;
        return Ok(());
    }
    staged.persist(dest).map_err(|e| e.error)
}

#[cfg(all(test, unix))]
mod tests {
    use super::*;
    use std::io::Write;

    fn write(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
        let dest = destination(path);
        let mut tmp = beside(&dest, ".tmp")?;
        tmp.write_all(bytes)?;
        put(tmp.into_temp_path(), &dest)
    }

    /// A link is kept and its target replaced; a device is written through and stays a
    /// device; a full device's error comes back and nothing is left beside it.
    #[test]
    fn links_and_devices_are_written_through() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("score.ron");
        std::fs::write(&target, b"old").unwrap();
        let link = dir.path().join("link.ron");
        std::os::unix::fs::symlink("score.ron", &link).unwrap();
        write(&link, b"new").unwrap();
        assert!(
            std::fs::symlink_metadata(&link)
                .unwrap()
                .file_type()
                .is_symlink()
        );
        assert_eq!(std::fs::read(&target).unwrap(), b"new");
        let dangling = dir.path().join("dangling.ron");
        std::os::unix::fs::symlink("made.ron", &dangling).unwrap();
        write(&dangling, b"made").unwrap();
        assert_eq!(std::fs::read(dir.path().join("made.ron")).unwrap(), b"made");

        write(Path::new("/dev/null"), b"gone").unwrap();
        use std::os::unix::fs::FileTypeExt;
        assert!(
            std::fs::metadata("/dev/null")
                .unwrap()
                .file_type()
                .is_char_device()
        );
        if Path::new("/dev/full").exists() {
            assert!(write(Path::new("/dev/full"), b"no room").is_err());
            assert!(
                std::fs::metadata("/dev/full")
                    .unwrap()
                    .file_type()
                    .is_char_device()
            );
        }
        let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
        assert_eq!(left.len(), 4, "score, link, dangling link, made: {left:?}");
    }
}
