//! The limits timpanist holds its inputs to, so a huge or hostile file is refused with a
//! clear message instead of exhausting memory: file sizes per kind (and what a compressed
//! file may unpack to), and the length of a score (beats and seconds: a render holds the
//! whole performance, 10 kHz motion and 48 kHz audio per drum, in memory — a 30-minute
//! score takes about 2 GB).

use std::io::Read;
use std::path::Path;

/// Largest score, kit or other RON file read, bytes (a 50 000-beat score is about 5 MB).
pub const MAX_TEXT_FILE_BYTES: u64 = 32 << 20;
/// Largest MIDI file imported, bytes (orchestral files are well under 1 MB).
pub const MAX_MIDI_FILE_BYTES: u64 = 16 << 20;
/// Largest MusicXML file imported (plain or `.mxl`), bytes (a whole orchestral score in
/// plain MusicXML is tens of MB).
pub const MAX_MUSICXML_FILE_BYTES: u64 = 256 << 20;
/// Most bytes one file inside a compressed MusicXML (`.mxl`) archive may unpack to
/// (64 MiB): the largest real scores unpack to a few MB, so an entry beyond it is taken
/// for a zip bomb and refused after reading this much, whatever size the archive declares.
pub const MAX_MXL_ENTRY_BYTES: u64 = 64 << 20;
/// Largest motion-capture file imported, bytes (an hour of 250 Hz C3D markers is a few
/// hundred MB).
pub const MAX_CAPTURE_FILE_BYTES: u64 = 1 << 30;
/// Most beats in a score.
pub const MAX_BEATS: usize = 50_000;
/// Longest score, s (to its last stroke; 30 minutes).
pub const MAX_SCORE_S: f64 = 1800.0;

/// Read a whole file of at most `max_bytes`: a larger one is refused (an `InvalidData`
/// error saying how large it is and what the limit is, for the caller to name the file)
/// without being read.
pub fn read_at_most(path: &Path, max_bytes: u64, what: &str) -> std::io::Result<Vec<u8>> {
    let file = std::fs::File::open(path)?;
    let len = file.metadata()?.len();
    let too_large = |len: u64| {
        std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!(
                "{} is larger than the {} a {what} may be",
                megabytes(len),
                megabytes(max_bytes)
            ),
        )
    };
    if len > max_bytes {
        return Err(too_large(len));
    }
    // The length may grow while reading (a file being written): never read past the limit.
    let mut bytes = Vec::with_capacity(len as usize);
    file.take(max_bytes + 1).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > max_bytes {
        return Err(too_large(bytes.len() as u64));
    }
    Ok(bytes)
}

fn megabytes(bytes: u64) -> String {
    if bytes >= 1 << 20 {
        format!("{:.1} MB", bytes as f64 / f64::from(1 << 20))
    } else {
        format!("{bytes} bytes")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A file over the limit is refused unread with its size and the limit; one at the
    /// limit is read whole.
    #[test]
    fn files_over_the_limit_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("big.ron");
        std::fs::write(&path, vec![b'x'; 3 << 20]).unwrap();
        let e = read_at_most(&path, 2 << 20, "score").unwrap_err();
        assert_eq!(e.kind(), std::io::ErrorKind::InvalidData);
        assert_eq!(
            e.to_string(),
            "3.0 MB is larger than the 2.0 MB a score may be"
        );
        assert_eq!(
            read_at_most(&path, 3 << 20, "score").unwrap().len(),
            3 << 20
        );
        assert!(read_at_most(&dir.path().join("missing"), 10, "score").is_err());
    }
}
