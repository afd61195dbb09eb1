//! Strict RON reading and atomic writing shared by score and kit files: parse errors name
//! the file, line and column; saving goes to a temporary file in the same folder that is
//! synced and then renamed over the target, so a crash never leaves a half-written file.

use super::problem::Problem;
use ron::error::Position;
use serde::Serialize;
use serde::de::DeserializeOwned;
use std::io::Write;
use std::path::{Path, PathBuf};

/// Anything that can go wrong reading or writing one of our files.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FileError {
    /// The file could not be read or written.
    #[error("{}: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// The text is not valid RON for the expected structure.
    #[error("{}:{line}:{col}: {message}", path.display())]
    Parse {
        path: PathBuf,
        line: usize,
        col: usize,
        message: String,
    },
    /// The file parsed but its content is not acceptable (`place` says where, e.g. "beat 3";
    /// `at`, when known, the line and column where that place starts in the file).
    #[error("{}{}: {place}: {message}", path.display(), at.map(|at| format!(":{at}")).unwrap_or_default())]
    Invalid {
        path: PathBuf,
        at: Option<Position>,
        place: String,
        message: String,
    },
    /// The file was written by a newer timpanist.
    #[error(
        "{}: format version {found} is newer than this timpanist reads (1 to {supported}); please update timpanist",
        path.display()
    )]
    TooNew {
        path: PathBuf,
        found: u32,
        supported: u32,
    },
}

impl FileError {
    /// Wrap an I/O error with the file it concerns.
    pub fn io(path: &Path, source: std::io::Error) -> Self {
        FileError::Io {
            path: path.to_path_buf(),
            source,
        }
    }

    /// A content problem at `place` in the file at `path`.
    pub fn invalid(path: &Path, place: impl Into<String>, message: impl Into<String>) -> Self {
        FileError::problem(path, Problem::new(place, message))
    }

    /// A problem found checking the file at `path`, at its line and column when it has
    /// them: `path:line:col: place: message`, else `path: place: message`.
    pub fn problem(path: &Path, problem: Problem) -> Self {
        FileError::Invalid {
            path: path.to_path_buf(),
            at: problem.at,
            place: problem.place,
            message: problem.message,
        }
    }
}

/// The error for a format `version` this program cannot read: 0 never existed, anything
/// above `supported` comes from a newer timpanist.
pub fn unsupported_version(path: &Path, found: u32, supported: u32) -> FileError {
    if found == 0 {
        FileError::invalid(path, "version", "format version 0 does not exist")
    } else {
        FileError::TooNew {
            path: path.to_path_buf(),
            found,
            supported,
        }
    }
}

/// Read a whole text file (at most [`MAX_TEXT_FILE_BYTES`](super::limits::MAX_TEXT_FILE_BYTES)),
/// without the byte-order mark an editor on Windows may put first. Bytes that are not
/// UTF-8 are refused naming their line and column (and what the file looks like, when it
/// is a recording or a MIDI file given where a score belongs).
pub fn read_text(path: &Path) -> Result<String, FileError> {
    let bytes = super::limits::read_at_most(path, super::limits::MAX_TEXT_FILE_BYTES, "text file")
        .map_err(|e| FileError::io(path, e))?;
    let mut text = String::from_utf8(bytes).map_err(|e| {
        let valid = &e.as_bytes()[..e.utf8_error().valid_up_to()];
        let line = valid.iter().filter(|&&b| b == b'\n').count() + 1;
        let column = valid.iter().rev().take_while(|&&b| b != b'\n').count() + 1;
        let looks_like = match e.as_bytes() {
            [b'M', b'T', b'h', b'd', ..] => "; it is a MIDI file: import it with import-midi",
            [b'R', b'I', b'F', b'F', ..]
            | [b'F', b'O', b'R', b'M', ..]
            | [b'f', b'L', b'a', b'C', ..] => "; it is a recording: transcribe it with transcribe",
            [b'P', b'K', ..] => {
                "; it is a zip (a compressed MusicXML?): import it with import-musicxml"
            }
            _ => "",
        };
        FileError::io(
            path,
            std::io::Error::new(
                std::io::ErrorKind::InvalidData,
                format!(
                    "not UTF-8 text (line {line}, column {column}, byte {}){looks_like}",
                    valid.len()
                ),
            ),
        )
    })?;
    if text.starts_with('\u{feff}') {
        text.drain(..'\u{feff}'.len_utf8());
    }
    Ok(text)
}

/// Parse RON text strictly into `T`, naming `path` and the line and column on error.
pub fn parse<T: DeserializeOwned>(path: &Path, text: &str) -> Result<T, FileError> {
    ron::from_str(text).map_err(|e| FileError::Parse {
        path: path.to_path_buf(),
        line: e.span.start.line,
        col: e.span.start.col,
        message: e.code.to_string(),
    })
}

/// Serialise `value` as pretty RON with struct names, ending in a newline.
pub fn to_pretty<T: Serialize>(value: &T) -> String {
    let config = ron::ser::PrettyConfig::new()
        .struct_names(true)
        .indentor("    ")
        .separate_tuple_members(false)
        .enumerate_arrays(false)
        .depth_limit(2);
    let mut text = ron::ser::to_string_pretty(value, config)
        .expect("our score and kit types always serialise to RON");
    text.push('\n');
    text
}

/// Write `bytes` to `path` atomically ([`super::staged`]: a temporary file beside it,
/// synced, then renamed; a link followed, a device written through). On any error the
/// target is untouched and no temporary file is left behind.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), FileError> {
    let dest = super::staged::destination(path);
    let io = |e| FileError::io(path, e);
    let mut tmp = super::staged::beside(&dest, ".tmp").map_err(io)?;
    tmp.write_all(bytes).map_err(io)?;
    tmp.as_file().sync_all().map_err(io)?;
    super::staged::put(tmp.into_temp_path(), &dest).map_err(io)
}

/// Save `value` as pretty RON to `path`, atomically.
pub fn save<T: Serialize>(path: &Path, value: &T) -> Result<(), FileError> {
    write_atomic(path, to_pretty(value).as_bytes())
}

/// The first identifier of a RON document (e.g. `Score` or `Kit`), skipping whitespace,
/// comments and `#![enable(...)]` attributes; `None` for an unnamed top-level value.
pub fn top_level_name(text: &str) -> Option<&str> {
    let mut rest = text;
    loop {
        rest = rest.trim_start();
        if let Some(r) = rest.strip_prefix("//") {
            rest = r.split_once('\n').map_or("", |(_, after)| after);
        } else if let Some(r) = rest.strip_prefix("/*") {
            rest = r.split_once("*/").map_or("", |(_, after)| after);
        } else if rest.starts_with("#!") {
            rest = rest.split_once(']').map_or("", |(_, after)| after);
        } else {
            break;
        }
    }
    let end = rest
        .find(|c: char| !(c.is_alphanumeric() || c == '_'))
        .unwrap_or(rest.len());
    (end > 0).then(|| &rest[..end])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A new file is created rw-r--r-- (less the umask), not private like a bare temporary
    /// file; a replaced one keeps its mode.
    #[cfg(unix)]
    #[test]
    fn written_files_have_ordinary_permissions() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.txt");
        write_atomic(&path, b"one").unwrap();
        let mode = |p: &Path| std::fs::metadata(p).unwrap().permissions().mode() & 0o777;
        // rw-r--r-- less whatever the umask removes (never more, never less for the owner).
        assert_eq!(mode(&path) & 0o600, 0o600);
        assert_eq!(mode(&path) & !0o644, 0);
        std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o600)).unwrap();
        write_atomic(&path, b"two").unwrap();
        assert_eq!(mode(&path), 0o600);
        assert_eq!(std::fs::read(&path).unwrap(), b"two");
    }
    use serde::Deserialize;

    #[derive(Debug, Deserialize, Serialize, PartialEq)]
    #[serde(deny_unknown_fields)]
    struct Thing {
        a: u32,
        b: String,
    }

    /// A typo in a field name reports 1-based line and column and the expected fields.
    #[test]
    fn parse_error_names_place() {
        let text = "Thing(\n    a: 1,\n    bb: \"x\",\n)";
        let err = parse::<Thing>(Path::new("t.ron"), text).unwrap_err();
        let msg = err.to_string();
        assert!(msg.starts_with("t.ron:3:"), "{msg}");
        assert!(msg.contains("bb") && msg.contains('b'), "{msg}");
    }

    /// A missing field is an error too.
    #[test]
    fn missing_field_is_error() {
        let err = parse::<Thing>(Path::new("t.ron"), "(a: 1)").unwrap_err();
        assert!(err.to_string().contains("`b`"), "{err}");
    }

    /// Atomic save writes the file and leaves no temporary behind; a failed save leaves
    /// the previous content intact.
    #[test]
    fn atomic_save() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("x.ron");
        let thing = Thing {
            a: 7,
            b: "seven".into(),
        };
        save(&path, &thing).unwrap();
        assert_eq!(
            parse::<Thing>(&path, &read_text(&path).unwrap()).unwrap(),
            thing
        );
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
        let missing_dir = dir.path().join("no/such/dir/x.ron");
        assert!(save(&missing_dir, &thing).is_err());
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    /// The top-level name is found past comments and extension attributes.
    /// A byte-order mark is dropped; bytes that are not UTF-8 are refused with their line
    /// and column, and a MIDI file given as text is named as one.
    #[test]
    fn text_files_read_as_editors_write_them() {
        let dir = tempfile::tempdir().unwrap();
        let bom = dir.path().join("bom.ron");
        std::fs::write(&bom, "\u{feff}Kit(a: 1)").unwrap();
        assert_eq!(read_text(&bom).unwrap(), "Kit(a: 1)");
        let latin = dir.path().join("latin.ron");
        std::fs::write(&latin, b"Score(\n  title: \"\xc9tude\",\n)").unwrap();
        let err = read_text(&latin).unwrap_err().to_string();
        assert!(err.contains("line 2, column 11, byte 17"), "{err}");
        let midi = dir.path().join("song.ron");
        std::fs::write(&midi, b"MThd\0\0\0\x06\0\x01\0\x01\x01\xe0").unwrap();
        let err = read_text(&midi).unwrap_err().to_string();
        assert!(err.contains("it is a MIDI file"), "{err}");
    }

    #[test]
    fn finds_top_level_name() {
        assert_eq!(
            top_level_name("// hi\n/* x */ #![enable(implicit_some)]\nKit(a: 1)"),
            Some("Kit")
        );
        assert_eq!(top_level_name("(a: 1)"), None);
    }
}
