//! OpenSim / Cortex TRC (Track Row Column) marker files, read through the table reader
//! with the shipped `trc` capture profile, checked against the counts the TRC header
//! states.
//!
//! # Layout
//!
//! ```text
//! PathFileType  4  (X/Y/Z)  walk.trc
//! DataRate  CameraRate  NumFrames  NumMarkers  Units  OrigDataRate  OrigDataStartFrame  OrigNumFrames
//! 100.00    100.00      250        2           mm     100.00        1                   250
//! Frame#  Time   RASI               LASI
//!                X1     Y1     Z1   X2     Y2     Z2
//!
//! 1       0.000  812.3  1003.5 201.7 …
//! ```
//!
//! * Cells are tab-separated (a file without tabs is split at whitespace); the data may
//!   follow a blank line; an empty cell (or `NaN`, counted in a note) is a marker not
//!   seen, and a row cut short leaves its last markers unseen.
//! * `DataRate` is the frame rate, Hz; `Units` the length unit (mm, cm, m); rows are
//!   placed on the frame grid by their `Time` (s), so a missing row is a gap (noted).
//! * `NumMarkers` must equal the number of marker column groups (name over `Xn Yn Zn`),
//!   or the file is refused; a `NumFrames` that differs from the rows read (a truncated
//!   file) gives a note in [`Take::notes`] (the profile's `frames_key`).

use super::LengthUnit;
use super::profile::CaptureProfile;
use super::table;
use crate::mocap::take::{ImportError, Take};
use std::path::Path;

/// Read a TRC file; `unit` overrides its `Units`.
pub fn read(path: &Path, bytes: &[u8], unit: Option<LengthUnit>) -> Result<Take, ImportError> {
    let profile = CaptureProfile::shipped("trc").ok_or_else(|| {
        ImportError::format(path, "TRC profile", "the shipped trc profile did not load")
    })?;
    let (mut take, info) = table::read_table(path, bytes, &profile, unit)?;
    if let Some((e, n)) = table::stated_count(path, &info.metadata, "NumMarkers")?
        && n != take.tracks.len()
    {
        return Err(ImportError::format(
            path,
            format!("line {}, \"{}\"", e.line, e.key),
            format!(
                "expected {n} markers as NumMarkers says, found {} (name over X, Y, Z \
                 columns): the header is cut short or was edited",
                take.tracks.len()
            ),
        ));
    }
    take.zeros_as_gaps(info.gaps);
    Ok(take)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    const FIXTURE: &[u8] = include_bytes!("../../../tests/fixtures/capture/opensim_walk.trc");

    fn p() -> &'static Path {
        Path::new("walk.trc")
    }

    /// The fixture with `from` replaced by `to`.
    fn edited(from: &str, to: &str) -> Vec<u8> {
        let text = String::from_utf8(FIXTURE.to_vec()).unwrap();
        assert!(text.contains(from), "{from}");
        text.replacen(from, to, 1).into_bytes()
    }

    #[test]
    fn reads_the_opensim_layout_with_gap_and_dropped_frame() {
        let take = read(p(), FIXTURE, None).unwrap();
        assert_eq!(take.labels(), vec!["R.Stick.Tip", "L.Stick.Tip", "C7"]);
        assert_eq!(take.rate_hz, 100.0);
        assert_eq!(take.file_unit, "mm");
        // Eight rows, frame 6 dropped: nine frames.
        assert_eq!(take.frames, 9);
        let r = &take.tracks[0];
        assert!(
            r.positions[0]
                .unwrap()
                .abs_diff_eq(DVec3::new(0.2501, 0.9502, 0.8003), 1e-12)
        );
        assert!(r.rotations.is_empty());
        assert_eq!(r.positions[5], None, "dropped frame");
        let l = &take.tracks[1];
        assert_eq!(l.positions[2], None, "empty cells");
        assert_eq!(l.positions[3], None, "NaN");
        assert_eq!(take.tracks[2].positions[8], None, "row cut short");
        assert!(take.tracks[2].positions[7].is_some());
        assert!(
            take.notes
                .iter()
                .any(|n| n.contains("1 dropped frame was filled")),
            "{:?}",
            take.notes
        );
        assert!(
            take.notes.iter().all(|n| !n.contains("NumFrames")),
            "{:?}",
            take.notes
        );
        let cm = read(p(), FIXTURE, Some(LengthUnit::Centimetre)).unwrap();
        assert!((cm.tracks[0].positions[0].unwrap().x - 2.501).abs() < 1e-12);
    }

    #[test]
    fn header_counts_are_checked() {
        let short = edited("\t8\t3\tmm", "\t12\t3\tmm");
        let take = read(p(), &short, None).unwrap();
        assert!(
            take.notes.iter().any(|n| n.contains(
                "NumFrames (line 2) says 12 frames, the file has 8 rows, the last on line 14: \
                 it is truncated"
            )),
            "{:?}",
            take.notes
        );
        let e = read(p(), &edited("\t8\t3\tmm", "\t8\t4\tmm"), None)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("line 2, \"NumMarkers\": expected 4 markers"),
            "{e}"
        );
        let e = read(p(), &edited("\t8\t3\tmm", "\t8\tthree\tmm"), None)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("expected a whole number below NumMarkers"),
            "{e}"
        );
    }

    #[test]
    fn a_trc_without_tabs_is_refused_not_misread() {
        let text = "PathFileType 4 (X/Y/Z) s.trc\n\
                    DataRate CameraRate NumFrames NumMarkers Units OrigDataRate OrigDataStartFrame OrigNumFrames\n\
                    50 50 3 1 m 50 1 3\n\
                    Frame# Time Tip\n\
                    X1 Y1 Z1\n\
                    1 0.00 1 2 3\n\
                    2 0.02 1 2 4\n\
                    3 0.04 NaN NaN NaN\n";
        let e = read(p(), text.as_bytes(), None).unwrap_err().to_string();
        assert!(e.contains("expected a block of data rows"), "{e}");
    }
}
