//! Importers for capture files: C3D, OptiTrack Motive CSV, Vicon Nexus CSV and our own
//! plain CSV. (The C3D writer for our own exports is in the `io` layer: `io::c3d_write`.)
//!
//! Every importer returns a [`Take`]: labelled tracks at one fixed rate, positions in
//! metres in the file's own axes (converted from the file's length unit), `None` where a
//! marker was not seen, and rotations for rigid bodies. A sample the file marks unseen
//! is `None` too: an empty cell, a coordinate written as `NaN` (any case) in every text
//! format, or (in every format) exactly (0, 0, 0); the last two are counted in one note
//! ([`crate::mocap::MarkedGaps`]). A file that is not what it claims
//! to be, or is corrupt or truncated, gives an [`ImportError::Format`] that names the place
//! (byte offset, C3D parameter, or CSV line and column) and says what was expected; no
//! file content can make an importer panic.
//!
//! * [`c3d`]: binary C3D (Intel, DEC and MIPS processor formats, integer or float data).
//! * [`motive`]: OptiTrack Motive CSV export, format version 1.2x.
//! * [`vicon`]: Vicon Nexus CSV export (the `Trajectories` section).
//! * [`plain_csv`]: our own documented CSV (`time_s,<label>_x,<label>_y,<label>_z,…`).
//! * [`trc`]: OpenSim / Cortex TRC marker files (read through [`table`]).
//! * [`table`] with a [`profile::CaptureProfile`]: any other column-mapped text export
//!   (Qualisys TSV, Vicon and Motive CSV with any names, …), described in RON
//!   ([`read_with_profile`]); shipped profiles are in `mocap/profiles/`.

pub mod c3d;
mod csv_text;
pub mod motive;
pub mod plain_csv;
pub mod profile;
pub mod table;
pub mod trc;
pub mod vicon;

pub use profile::CaptureProfile;

use super::take::{ImportError, Take};
use std::path::Path;

/// A capture file format.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// Binary C3D.
    C3d,
    /// OptiTrack Motive CSV export.
    Motive,
    /// Vicon Nexus CSV export.
    Vicon,
    /// Our own plain CSV.
    Csv,
    /// OpenSim / Cortex TRC.
    Trc,
}

impl Format {
    /// The format for a user-given name: `c3d`, `motive` (or `optitrack`), `vicon` (or
    /// `nexus`), `csv` (or `plain`); case-insensitive.
    pub fn from_name(s: &str) -> Option<Format> {
        match s.trim().to_ascii_lowercase().as_str() {
            "c3d" => Some(Format::C3d),
            "motive" | "optitrack" => Some(Format::Motive),
            "vicon" | "nexus" => Some(Format::Vicon),
            "csv" | "plain" | "plain-csv" | "plain_csv" => Some(Format::Csv),
            "trc" => Some(Format::Trc),
            _ => None,
        }
    }

    /// The name [`Format::from_name`] accepts for this format.
    pub fn name(self) -> &'static str {
        match self {
            Format::C3d => "c3d",
            Format::Motive => "motive",
            Format::Vicon => "vicon",
            Format::Csv => "csv",
            Format::Trc => "trc",
        }
    }

    /// Guess the format from the file's content, falling back on its extension (`.c3d`).
    /// Text files are told apart by their first line: `Format Version,…` is Motive, a
    /// Vicon section name (`Trajectories`, `Devices`, …) is Vicon, `time_s,…` is plain CSV,
    /// `PathFileType…` (tab- or space-separated) is TRC.
    pub fn guess(path: &Path, bytes: &[u8]) -> Option<Format> {
        if let [first, 0x50, ..] = bytes {
            // Header byte 1: the parameter block number (a small binary value, never a
            // printable character or a line break); byte 2: the C3D key 0x50.
            if (1..0x20).contains(first) && !matches!(first, 9 | 10 | 13) {
                return Some(Format::C3d);
            }
        }
        let head = &bytes[..bytes.len().min(4096)];
        let text = String::from_utf8_lossy(head);
        let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
        let first_line = text.lines().map(str::trim).find(|l| !l.is_empty());
        if let Some(line) = first_line {
            let cell = line
                .split(',')
                .next()
                .unwrap_or("")
                .trim()
                .trim_matches('"');
            if cell.eq_ignore_ascii_case("Format Version") {
                return Some(Format::Motive);
            }
            if vicon::is_section_name(cell) {
                return Some(Format::Vicon);
            }
            if cell.eq_ignore_ascii_case("time_s") {
                return Some(Format::Csv);
            }
            let word = line.split(['\t', ' ', ',']).next().unwrap_or("");
            if word.eq_ignore_ascii_case("PathFileType") {
                return Some(Format::Trc);
            }
        }
        let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
        if ext.eq_ignore_ascii_case("c3d") {
            return Some(Format::C3d);
        }
        None
    }
}

/// A length unit a capture file can be in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LengthUnit {
    /// Millimetres.
    Millimetre,
    /// Centimetres.
    Centimetre,
    /// Metres.
    Metre,
}

impl LengthUnit {
    /// Parse a unit name as files and users write it: `mm`, `cm`, `m`, or the words
    /// (`millimeters`, `Centimetres`, `Meters`, …); case-insensitive.
    pub fn parse(s: &str) -> Option<LengthUnit> {
        match s.trim().to_ascii_lowercase().as_str() {
            "mm" | "millimeter" | "millimeters" | "millimetre" | "millimetres" => {
                Some(LengthUnit::Millimetre)
            }
            "cm" | "centimeter" | "centimeters" | "centimetre" | "centimetres" => {
                Some(LengthUnit::Centimetre)
            }
            "m" | "meter" | "meters" | "metre" | "metres" => Some(LengthUnit::Metre),
            _ => None,
        }
    }

    /// Metres per unit.
    pub fn metres(self) -> f64 {
        match self {
            LengthUnit::Millimetre => 0.001,
            LengthUnit::Centimetre => 0.01,
            LengthUnit::Metre => 1.0,
        }
    }

    /// The short symbol: "mm", "cm" or "m".
    pub fn symbol(self) -> &'static str {
        match self {
            LengthUnit::Millimetre => "mm",
            LengthUnit::Centimetre => "cm",
            LengthUnit::Metre => "m",
        }
    }

    /// Among `candidates`, the unit that, had the file been read in it instead of in
    /// `self`, would give a span read as `span_m` metres the length nearest `target_m`
    /// (by ratio): what a capture whose sticks move absurdly little or far was written in.
    pub fn nearest_for(self, span_m: f64, target_m: f64, candidates: &[LengthUnit]) -> LengthUnit {
        let off = |u: &LengthUnit| (span_m * u.metres() / self.metres() / target_m).ln().abs();
        candidates
            .iter()
            .copied()
            .min_by(|a, b| off(a).total_cmp(&off(b)))
            .unwrap_or(self)
    }
}

/// Read a capture file. With `format` `None` the format is guessed from the content and
/// extension ([`Format::guess`]).
pub fn read(path: &Path, format: Option<Format>) -> Result<Take, ImportError> {
    read_with_unit(path, format, None)
}

/// Read a capture file whose length unit is overridden by `unit` ("mm", "cm" or "m"),
/// for files that state a wrong unit or none. `None` uses the file's own unit. The
/// returned [`Take::file_unit`] is the unit actually used.
pub fn read_with_unit(
    path: &Path,
    format: Option<Format>,
    unit: Option<&str>,
) -> Result<Take, ImportError> {
    read_detecting(path, format, unit).map(|(take, _)| take)
}

/// [`read_with_unit`], also saying which format the file was read as (the one given, or
/// the one recognised).
pub fn read_detecting(
    path: &Path,
    format: Option<Format>,
    unit: Option<&str>,
) -> Result<(Take, Format), ImportError> {
    let (bytes, unit) = read_file(path, unit)?;
    // A UTF-16 text export (Excel's "Unicode text") is read as the same text in UTF-8.
    let utf16 = (bytes.starts_with(b"\xff\xfe") || bytes.starts_with(b"\xfe\xff"))
        .then(|| csv_text::decode_text(&bytes).into_owned().into_bytes());
    let bytes = utf16.unwrap_or(bytes);
    // A spreadsheet's European "CSV" (semicolons, decimal commas) is read as the same
    // export written with commas.
    let semicolons = (format != Some(Format::C3d)
        && Format::guess(path, &bytes) != Some(Format::C3d))
    .then(|| csv_text::from_semicolons(&bytes))
    .flatten();
    let bytes = semicolons.as_deref().unwrap_or(&bytes);
    let format = match format {
        Some(f) => f,
        None => Format::guess(path, bytes).ok_or_else(|| {
            ImportError::format(
                path,
                "start of file",
                "cannot tell the capture format: expected a C3D file, an OptiTrack Motive \
                 CSV export (first line \"Format Version,…\"), a Vicon CSV export (a \
                 \"Trajectories\" section), an OpenSim TRC file (\"PathFileType…\") or a plain \
                 CSV (header \"time_s,…\"); name the format explicitly if it is one of these, \
                 or read it with a capture profile",
            )
        })?,
    };
    let mut take = read_bytes_with_unit(path, bytes, format, unit)?;
    if semicolons.is_some() {
        take.notes.push(
            "read with semicolons between cells and decimal commas (a spreadsheet's \
             European CSV)"
                .to_string(),
        );
    }
    Ok((take, format))
}

/// Read a capture held in memory; `path` is only used for [`Take::source`] and errors.
pub fn read_bytes(path: &Path, bytes: &[u8], format: Format) -> Result<Take, ImportError> {
    read_bytes_with_unit(path, bytes, format, None)
}

/// [`read_bytes`] with the file's length unit overridden by `unit` (`None`: the file's).
pub fn read_bytes_with_unit(
    path: &Path,
    bytes: &[u8],
    format: Format,
    unit: Option<LengthUnit>,
) -> Result<Take, ImportError> {
    match format {
        Format::C3d => c3d::read(path, bytes, unit),
        Format::Motive => motive::read(path, bytes, unit),
        Format::Vicon => vicon::read(path, bytes, unit),
        Format::Csv => plain_csv::read(path, bytes, unit),
        Format::Trc => trc::read(path, bytes, unit),
    }?
    .checked()
}

/// Read a column-mapped text capture as `profile` describes it (see [`profile`] and
/// [`table`]); `unit` ("mm", "cm" or "m") overrides every unit the profile or file gives.
/// Hands are not in the take: look them up with [`CaptureProfile::hand_of`].
pub fn read_with_profile(
    path: &Path,
    profile: &CaptureProfile,
    unit: Option<&str>,
) -> Result<Take, ImportError> {
    let (bytes, unit) = read_file(path, unit)?;
    table::read(path, &bytes, profile, unit)?.checked()
}

/// The bytes of a capture file and the unit override parsed (checked first, so a bad
/// `--unit` is said before any reading).
fn read_file(
    path: &Path,
    unit: Option<&str>,
) -> Result<(Vec<u8>, Option<LengthUnit>), ImportError> {
    let unit = parse_unit_override(path, unit)?;
    let bytes = crate::base::limits::read_at_most(
        path,
        crate::base::limits::MAX_CAPTURE_FILE_BYTES,
        "capture file",
    )
    .map_err(|source| ImportError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    Ok((bytes, unit))
}

fn parse_unit_override(path: &Path, unit: Option<&str>) -> Result<Option<LengthUnit>, ImportError> {
    match unit {
        None => Ok(None),
        Some(s) => LengthUnit::parse(s).map(Some).ok_or_else(|| {
            ImportError::format(
                path,
                "unit override",
                format!("expected \"mm\", \"cm\" or \"m\", found \"{s}\""),
            )
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn format_names_and_guessing() {
        assert_eq!(Format::from_name("C3D"), Some(Format::C3d));
        assert_eq!(Format::from_name("optitrack"), Some(Format::Motive));
        assert_eq!(Format::from_name("nexus"), Some(Format::Vicon));
        assert_eq!(Format::from_name("csv"), Some(Format::Csv));
        assert_eq!(Format::from_name("bvh"), None);
        assert_eq!(Format::from_name("TRC"), Some(Format::Trc));
        for f in [
            Format::C3d,
            Format::Motive,
            Format::Vicon,
            Format::Csv,
            Format::Trc,
        ] {
            assert_eq!(Format::from_name(f.name()), Some(f));
        }
        let p = Path::new("x.csv");
        assert_eq!(
            Format::guess(p, b"Format Version,1.23,Take Name,a\r\n"),
            Some(Format::Motive)
        );
        assert_eq!(
            Format::guess(p, b"\xef\xbb\xbfDevices,,\n1000\n"),
            Some(Format::Vicon)
        );
        assert_eq!(
            Format::guess(p, b"Trajectories\n100\n"),
            Some(Format::Vicon)
        );
        assert_eq!(Format::guess(p, b"time_s,a_x,a_y,a_z\n"), Some(Format::Csv));
        assert_eq!(
            Format::guess(p, b"PathFileType\t4\t(X/Y/Z)\ta.trc\n"),
            Some(Format::Trc)
        );
        assert_eq!(Format::guess(p, b"\nPlain text"), None);
        assert_eq!(Format::guess(p, b"\x02\x50\x00"), Some(Format::C3d));
        assert_eq!(Format::guess(Path::new("a.C3D"), b""), Some(Format::C3d));
        assert_eq!(Format::guess(p, b""), None);
    }

    #[test]
    fn reads_files_with_a_profile_or_as_trc() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/capture");
        let tsv = dir.join("qualisys_3d_200hz.tsv");
        let profile = CaptureProfile::shipped("qualisys-3d").unwrap();
        let take = read_with_profile(&tsv, &profile, Some("cm")).unwrap();
        assert_eq!((take.file_unit.as_str(), take.rate_hz), ("cm", 200.0));
        assert!(read_with_profile(&tsv, &profile, Some("furlong")).is_err());
        assert!(read_with_profile(&dir.join("missing.tsv"), &profile, None).is_err());
        let trc = read(&dir.join("opensim_walk.trc"), None).unwrap();
        assert_eq!(trc.labels(), vec!["R.Stick.Tip", "L.Stick.Tip", "C7"]);
    }

    #[test]
    fn units() {
        assert_eq!(
            LengthUnit::parse("Millimeters"),
            Some(LengthUnit::Millimetre)
        );
        assert_eq!(LengthUnit::parse(" cm "), Some(LengthUnit::Centimetre));
        assert_eq!(LengthUnit::parse("Meters"), Some(LengthUnit::Metre));
        assert_eq!(LengthUnit::parse("in"), None);
        let e = parse_unit_override(Path::new("f"), Some("inch")).unwrap_err();
        assert!(
            e.to_string().contains("expected \"mm\", \"cm\" or \"m\""),
            "{e}"
        );
    }
}
