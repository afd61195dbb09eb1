//! A raw capture as read from a file: labelled 3D marker (and rigid-body) trajectories at
//! a fixed rate, converted to metres, before any axis remapping or segmentation.

use glam::{DQuat, DVec3};
use std::path::PathBuf;

/// One labelled trajectory: a marker, or a rigid body's origin.
#[derive(Clone, Debug, PartialEq)]
pub struct Track {
    /// Label as written in the file (e.g. "StickL:Tip", "RASI", "StickR").
    pub label: String,
    /// Position per frame, metres, in the file's own axes; `None` where the marker was not seen.
    pub positions: Vec<Option<DVec3>>,
    /// Orientation per frame for rigid bodies (file axes), empty for plain markers.
    pub rotations: Vec<Option<DQuat>>,
}

impl Track {
    /// A track with no samples yet.
    pub fn empty(label: impl Into<String>) -> Track {
        Track {
            label: label.into(),
            positions: Vec::new(),
            rotations: Vec::new(),
        }
    }
}

/// The highest frame rate a capture may have, Hz (capture systems run at up to a few
/// kHz; a rate past this is a corrupt header).
pub const MAX_CAPTURE_RATE_HZ: f64 = 100_000.0;
/// The farthest a sample may lie from a capture's origin along any axis, m; farther ones
/// are read as gaps ([`Take::checked`]). Far past any lab, and past millimetres read as
/// metres (which the strokes' speeds tell, `ingest`), but within what a take file stores
/// to 10 µm.
pub const MAX_COORDINATE_M: f64 = 1.0e6;

/// The largest extent along any axis of the seen `positions`, m (as read); `None` when
/// none is seen.
pub fn extent_m(positions: &[Option<DVec3>]) -> Option<f64> {
    let seen = positions.iter().flatten().copied();
    let lo = seen.clone().reduce(DVec3::min)?;
    let hi = seen.reduce(DVec3::max)?;
    Some((hi - lo).max_element())
}

/// A whole capture.
#[derive(Clone, Debug, PartialEq)]
pub struct Take {
    /// The file it came from.
    pub source: PathBuf,
    /// Frame rate, Hz.
    pub rate_hz: f64,
    /// Number of frames (every track has this many entries).
    pub frames: usize,
    /// Length unit found in the file ("mm", "cm", "m"), for reports.
    pub file_unit: String,
    /// The trajectories.
    pub tracks: Vec<Track>,
    /// What the reader noticed and worked around (e.g. a data section cut short).
    pub notes: Vec<String>,
}

impl Take {
    /// The track whose label equals `label`, or failing that ends with `:label`
    /// (C3D and Vicon prefix labels with the subject name); case-insensitive.
    pub fn track(&self, label: &str) -> Option<&Track> {
        let want = label.to_ascii_lowercase();
        let lower = |t: &Track| t.label.to_ascii_lowercase();
        self.tracks.iter().find(|t| lower(t) == want).or_else(|| {
            self.tracks
                .iter()
                .find(|t| lower(t).ends_with(&format!(":{want}")))
        })
    }

    /// Read every sample exactly at the origin (all three coordinates 0.0) as missing,
    /// as Vicon, Cortex and many C3D writers mark an unseen marker (a rigid body's
    /// rotation goes with it), and note them together with `read` (the samples the
    /// reader has already read as gaps for such a mark, e.g. written as NaN); returns
    /// how many were at the origin.
    pub fn zeros_as_gaps(&mut self, read: MarkedGaps) -> usize {
        let mut n = 0;
        for t in &mut self.tracks {
            for (f, p) in t.positions.iter_mut().enumerate() {
                if *p == Some(DVec3::ZERO) {
                    *p = None;
                    if let Some(q) = t.rotations.get_mut(f) {
                        *q = None;
                    }
                    n += 1;
                }
            }
        }
        let gaps = MarkedGaps {
            zero: read.zero + n,
            ..read
        };
        self.notes.extend(gaps.note());
        n
    }

    /// Check what every reader must hand on, whatever the file said: a frame rate
    /// within (0, [`MAX_CAPTURE_RATE_HZ`]] (an error naming the rate otherwise); samples
    /// farther than [`MAX_COORDINATE_M`] from the file's origin along any axis are read
    /// as gaps, with a note (a corrupt value: no lab is that large, and such a value
    /// cannot be stored).
    pub fn checked(mut self) -> Result<Take, ImportError> {
        if !(self.rate_hz > 0.0 && self.rate_hz <= MAX_CAPTURE_RATE_HZ) {
            return Err(ImportError::format(
                &self.source,
                "frame rate",
                format!(
                    "{} Hz is not a capture's frame rate (expected above 0 and at most {} kHz)",
                    self.rate_hz,
                    MAX_CAPTURE_RATE_HZ / 1000.0
                ),
            ));
        }
        let mut far = 0;
        let mut first: Option<(String, usize)> = None;
        for t in &mut self.tracks {
            for (f, p) in t.positions.iter_mut().enumerate() {
                if p.is_some_and(|p| p.abs().max_element() > MAX_COORDINATE_M) {
                    *p = None;
                    if let Some(q) = t.rotations.get_mut(f) {
                        *q = None;
                    }
                    far += 1;
                    first.get_or_insert_with(|| (t.label.clone(), f + 1));
                }
            }
        }
        if let Some((label, frame)) = first {
            let samples = if far == 1 { "sample" } else { "samples" };
            self.notes.push(format!(
                "{far} {samples} more than {} km from the capture's origin read as gaps (the \
                 first: track \"{label}\", frame {frame}): a corrupt value",
                MAX_COORDINATE_M / 1000.0
            ));
        }
        Ok(self)
    }

    /// The 1-based places in file order of the tracks labelled like `track`
    /// (case-insensitive): one place, or more when the file names two tracks alike.
    pub fn places_of(&self, track: &Track) -> Vec<usize> {
        (1..=self.tracks.len())
            .filter(|&i| self.tracks[i - 1].label.eq_ignore_ascii_case(&track.label))
            .collect()
    }

    /// Note each label two or more tracks share when none of them is among `used` (the
    /// labels of the tracks taken as sticks); a used one is refused where it is taken.
    pub fn note_unused_duplicates(&mut self, used: &[String]) {
        let mut notes = Vec::new();
        for (i, t) in self.tracks.iter().enumerate() {
            let places = self.places_of(t);
            let unused = !used.iter().any(|u| u.eq_ignore_ascii_case(&t.label));
            if places.len() > 1 && places[0] == i + 1 && unused {
                notes.push(format!(
                    "{} (not taken as a stick)",
                    duplicate_label(&t.label, &places)
                ));
            }
        }
        self.notes.extend(notes);
    }

    /// All labels, in file order.
    pub fn labels(&self) -> Vec<&str> {
        self.tracks.iter().map(|t| t.label.as_str()).collect()
    }
}

/// Samples a file marks unseen instead of leaving their cells empty: a coordinate
/// written as NaN or (in a binary file) ±infinity, or all three exactly 0. All are read
/// as gaps and counted in one note.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MarkedGaps {
    /// Samples with a coordinate written as NaN.
    pub nan: usize,
    /// Samples at exactly (0, 0, 0).
    pub zero: usize,
    /// Samples with a coordinate written as +infinity or −infinity (and none as NaN).
    pub infinite: usize,
}

impl MarkedGaps {
    /// The note counting them (`4 samples at exactly (0, 0, 0), 2 written as NaN and 1
    /// written as ±infinity read as gaps …`), or `None` when there are none.
    pub fn note(self) -> Option<String> {
        let samples = |n: usize| if n == 1 { "sample" } else { "samples" };
        let kinds = [
            (self.zero, "at exactly (0, 0, 0)"),
            (self.nan, "written as NaN"),
            (self.infinite, "written as ±infinity"),
        ];
        let mut parts: Vec<String> = Vec::new();
        for (n, how) in kinds.into_iter().filter(|&(n, _)| n > 0) {
            let first = parts.is_empty();
            parts.push(if first {
                format!("{n} {} {how}", samples(n))
            } else {
                format!("{n} {how}")
            });
        }
        let counted = match parts.split_last()? {
            (last, []) => last.clone(),
            (last, rest) => format!("{} and {last}", rest.join(", ")),
        };
        let why = if self.zero > 0 {
            " (the way Vicon, Cortex and many C3D writers mark an unseen marker)"
        } else {
            ""
        };
        Some(format!("{counted} read as gaps{why}"))
    }
}

/// `two tracks are named "L" (tracks 3 and 7)`.
pub fn duplicate_label(label: &str, places: &[usize]) -> String {
    let list: Vec<String> = places.iter().map(usize::to_string).collect();
    let (head, last) = list.split_at(list.len().saturating_sub(1));
    let count = match places.len() {
        2 => "two".to_string(),
        3 => "three".to_string(),
        n => n.to_string(),
    };
    format!(
        "{count} tracks are named \"{label}\" (tracks {}{}{})",
        head.join(", "),
        if head.is_empty() { "" } else { " and " },
        last.join("")
    )
}

/// Why a capture file could not be read.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ImportError {
    #[error("{}: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// The file is not in the expected format, or is corrupt or truncated; `place` says
    /// where (a byte offset, a line, a parameter).
    #[error("{}: {place}: {message}", path.display())]
    Format {
        path: PathBuf,
        place: String,
        message: String,
    },
}

impl ImportError {
    /// A format problem at `place` in `path`.
    pub fn format(
        path: &std::path::Path,
        place: impl Into<String>,
        message: impl Into<String>,
    ) -> Self {
        ImportError::Format {
            path: path.to_path_buf(),
            place: place.into(),
            message: message.into(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_note_counts_zeros_and_nans() {
        let note = |zero, nan| {
            MarkedGaps {
                nan,
                zero,
                infinite: 0,
            }
            .note()
        };
        assert_eq!(note(0, 0), None);
        assert_eq!(
            note(1, 0).unwrap(),
            "1 sample at exactly (0, 0, 0) read as gaps (the way Vicon, Cortex and many C3D writers mark an unseen marker)"
        );
        assert_eq!(note(0, 2).unwrap(), "2 samples written as NaN read as gaps");
        assert!(
            note(4, 1)
                .unwrap()
                .starts_with("4 samples at exactly (0, 0, 0) and 1 written as NaN read as gaps (")
        );
        let infinite = |nan, infinite| {
            MarkedGaps {
                nan,
                zero: 0,
                infinite,
            }
            .note()
            .unwrap()
        };
        assert_eq!(infinite(0, 1), "1 sample written as ±infinity read as gaps");
        assert_eq!(
            infinite(2, 3),
            "2 samples written as NaN and 3 written as ±infinity read as gaps"
        );
        let all = MarkedGaps {
            nan: 2,
            zero: 1,
            infinite: 1,
        };
        assert!(all.note().unwrap().starts_with(
            "1 sample at exactly (0, 0, 0), 2 written as NaN and 1 written as ±infinity read as gaps ("
        ));
    }
}
