//! Capture profiles: a RON description of how to read one system's text export as a
//! table (delimiter, where the header and data are, which columns hold the time, the
//! positions and the rotations, the frame rate and the length unit), so a new capture
//! system needs a profile file, not code. The profiles shipped in `mocap/profiles/` are
//! embedded in the program; [`crate::mocap::import::table`] does the reading.
//!
//! # Schema
//!
//! ```ron
//! CaptureProfile(
//!     name: "Qualisys TSV 6DOF",  // the only required field
//!     delimiter: Auto,            // Auto | Comma | Tab | Semicolon | Whitespace
//!     decimal_comma: None,        // None: auto (true when ';'-delimited data look like 1,25)
//!     section: None,              // Some("Trajectories"): the table starts below the first
//!                                 //   line whose first cell is this (multi-section exports)
//!     header: Auto,               // Auto | Line(12) | StartsWith("Frame"): the FIRST header row
//!     header_rows: 1,             // rows joined into column names (0: none, use "#N")
//!     unit_row: false,            // true: a row of units ("mm") between header and data
//!     time: Seconds("Time"),      // Seconds(col) | Milliseconds(col) | Frame(col) | None
//!     rate_hz: None,              // a fixed frame rate, Hz; else `rate_key`, else the times
//!     rate_key: Some("FREQUENCY"),// metadata key above the header that gives the rate, Hz
//!     unit: None,                 // "mm" | "cm" | "m"; else `unit_key`, else the unit row,
//!     unit_key: None,             //   else metres
//!     frames_key: Some("NO_OF_FRAMES"), // metadata key giving the number of frames: a
//!                                 //   file with fewer (or more) data rows gets a note
//!     zero_is_missing: false,     // a position (quaternion, matrix) of all zeros is unseen
//!     up: None,                   // Some(Y) | Some(Z) | Some(NegY) …: the capture's up axis
//!     tracks: [                   // explicit tracks
//!         Track(label: "StickR", position: ("StickR X", "StickR Y", "StickR Z"),
//!               orientation: Some(Euler(columns: ("Roll", "Pitch", "Yaw"), order: "XYZ",
//!                                       angles: Degrees, frame: Intrinsic)),
//!               hand: Some(Right)),
//!     ],
//!     patterns: [                 // discovered tracks
//!         Pattern(position: ("{name} X", "{name} Y", "{name} Z"), orientation: None),
//!     ],
//!     tip_offset_m: None,         // Some((x, y, z)): the stick tip in the body's frame, m
//! )
//! ```
//!
//! * **Column references** are header names, matched case-insensitively with runs of
//!   whitespace collapsed; `"#N"` is the N-th column (1-based); `"+N"` is the column N
//!   places right of the track's first position column (for layouts that name only the
//!   first column of a group, like Qualisys 6DOF `Body X, Y, Z, Roll, …`).
//! * **Column names** with several header rows: each upper row is forward-filled across
//!   empty cells (Vicon writes a marker name only above its X), then the rows are joined
//!   with a space (`"RHEAD" + "X"` → `"RHEAD X"`), empty parts skipped.
//! * **Patterns** discover every track for which all the columns exist. Braces are
//!   placeholders: `{name}` captures the track label and must be in the first position
//!   column; any other (`{id}`, `{n}`) matches any text, the same text wherever it
//!   recurs in the pattern. A label already taken by an explicit track or an earlier
//!   pattern is skipped, so a rigid-body pattern goes before a plain-marker one.
//! * **Orientation**: `Quaternion(x: c, y: c, z: c, w: c)` (normalised on reading);
//!   `Matrix(columns: [9 columns])`, the world-from-body rotation matrix in row-major order
//!   (R11, R12, R13, R21, …; it must be orthonormal); or `Euler(columns: (c1, c2, c3),
//!   order: "XYZ", angles: Degrees | Radians, frame: Intrinsic | Extrinsic)` where `order`
//!   is any three of X, Y, Z with no letter twice in a row ("XYZ", "ZYX", "ZXZ", …) and
//!   angle i (from column ci) turns about the i-th letter's axis, right-handed.
//!   **Intrinsic** (rotating axes) "XYZ" is q = Rx(a1)·Ry(a2)·Rz(a3); **extrinsic**
//!   (fixed axes) "XYZ" is q = Rz(a3)·Ry(a2)·Rx(a1): a1 is applied first, about the world
//!   X axis. `angles` defaults to `Degrees`, `frame` to `Intrinsic`.
//! * **Header `Auto`**: the data start at the first line where this and the next two
//!   non-blank lines all have at least two numeric cells and the same width; the header
//!   is the `header_rows` non-blank lines directly above (above the unit row, if any);
//!   everything above that is metadata. `Line(n)` and `StartsWith(s)` name the header's
//!   first row (by 1-based line number, or as the first line whose first cell starts with
//!   `s`, case-insensitively).
//! * **Metadata** (for `rate_key`, `unit_key` and `frames_key`; matched like column
//!   names): a key's value is the next non-empty cell on its line (the next cell, on a
//!   line of alternating keys and values like Motive's); on a line of keys only over a
//!   line of values, or a key alone over a value alone, it is the cell in the same column
//!   of the next line (TRC, Vicon).
//! * **Frame count**: with `frames_key`, a file holding fewer data rows than its value
//!   (cut short) or more (a header out of date) is read with a note saying both counts;
//!   a value that is not a whole number is an error naming its line.
//! * **Time**: rows go on a uniform grid at the rate (see [`crate::mocap::import::table`]).
//!   The rate is `rate_hz`, else the `rate_key` value, else 1 / the median time step.
//! * **Hands**: [`CaptureProfile::hand_of`] gives an explicit track's `hand` (`Left`,
//!   `Right`); the take itself carries no hands.

use super::LengthUnit;
use crate::kit::Side;
use crate::mocap::take::ImportError;
use glam::DVec3;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The profiles shipped in `mocap/profiles/`: (short name, RON text).
const SHIPPED: [(&str, &str); 6] = [
    ("motive", include_str!("../../../mocap/profiles/motive.ron")),
    ("vicon", include_str!("../../../mocap/profiles/vicon.ron")),
    (
        "qualisys-3d",
        include_str!("../../../mocap/profiles/qualisys-3d.ron"),
    ),
    (
        "qualisys-6d",
        include_str!("../../../mocap/profiles/qualisys-6d.ron"),
    ),
    ("trc", include_str!("../../../mocap/profiles/trc.ron")),
    ("plain", include_str!("../../../mocap/profiles/plain.ron")),
];

/// How to read one system's text export as a table of tracks. See the module doc for
/// the RON schema.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CaptureProfile {
    /// A name for reports.
    pub name: String,
    /// The cell separator.
    #[serde(default)]
    pub delimiter: Delimiter,
    /// `Some(true)`: numbers are written `1,25`; `None`: detected for `;`-delimited files.
    #[serde(default)]
    pub decimal_comma: Option<bool>,
    /// The table starts below the first line whose first cell is this (e.g. Vicon's
    /// `Trajectories`); after a blank line, a line not starting with a number ends it.
    #[serde(default)]
    pub section: Option<String>,
    /// Where the header's first row is.
    #[serde(default)]
    pub header: HeaderLocation,
    /// How many non-blank rows make the column names (0: no header; refer to columns
    /// as `"#N"`, and `Line(n)` names the first data line).
    #[serde(default = "one")]
    pub header_rows: usize,
    /// A row of length units (`mm`, `cm`, `m` per column) between header and data.
    #[serde(default)]
    pub unit_row: bool,
    /// The time (or frame number) column.
    #[serde(default)]
    pub time: TimeColumn,
    /// A fixed frame rate, Hz.
    #[serde(default)]
    pub rate_hz: Option<f64>,
    /// The metadata key whose value is the frame rate, Hz.
    #[serde(default)]
    pub rate_key: Option<String>,
    /// The positions' length unit: "mm", "cm" or "m" (or as [`LengthUnit::parse`] takes).
    #[serde(default)]
    pub unit: Option<String>,
    /// The metadata key whose value is the length unit.
    #[serde(default)]
    pub unit_key: Option<String>,
    /// The metadata key whose value is the number of frames the file holds (Qualisys
    /// `NO_OF_FRAMES`, TRC `NumFrames`): data rows fewer or more than it give a note.
    #[serde(default)]
    pub frames_key: Option<String>,
    /// A position (or quaternion, or matrix) whose cells are all 0 is a missing sample.
    #[serde(default)]
    pub zero_is_missing: bool,
    /// The capture's up axis: a hint for the caller (nothing is rotated on reading).
    #[serde(default)]
    pub up: Option<Up>,
    /// Tracks named explicitly.
    #[serde(default)]
    pub tracks: Vec<TrackSpec>,
    /// Tracks discovered from the column names.
    #[serde(default)]
    pub patterns: Vec<Pattern>,
    /// The stick tip in the rigid body's frame, m (data for the caller).
    #[serde(default)]
    pub tip_offset_m: Option<(f64, f64, f64)>,
}

fn one() -> usize {
    1
}

/// The cell separator of a table.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum Delimiter {
    /// Tab if at least half the first lines hold one, else `;`, else `,`, else whitespace.
    #[default]
    Auto,
    Comma,
    Tab,
    Semicolon,
    /// Runs of spaces and tabs (no empty cells: write missing values as `NaN`).
    Whitespace,
}

impl Delimiter {
    /// The separator character; `None` for whitespace (and for `Auto`, not yet decided).
    pub fn char(self) -> Option<char> {
        match self {
            Delimiter::Comma => Some(','),
            Delimiter::Tab => Some('\t'),
            Delimiter::Semicolon => Some(';'),
            Delimiter::Auto | Delimiter::Whitespace => None,
        }
    }
}

/// Where the header's first row is.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum HeaderLocation {
    /// Directly above the first block of numeric rows.
    #[default]
    Auto,
    /// On this line (1-based).
    Line(usize),
    /// On the first line whose first cell starts with this (case-insensitive).
    StartsWith(String),
}

/// The column that places rows in time.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum TimeColumn {
    /// Time in seconds.
    Seconds(String),
    /// Time in milliseconds.
    Milliseconds(String),
    /// A frame number (the rate must come from `rate_hz` or `rate_key`).
    Frame(String),
    /// No time column: rows are consecutive frames.
    #[default]
    None,
}

/// The capture's up axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Up {
    X,
    Y,
    Z,
    NegX,
    NegY,
    NegZ,
}

impl From<Up> for crate::mocap::ingest::UpAxis {
    fn from(up: Up) -> Self {
        match up {
            Up::X => crate::mocap::ingest::UpAxis::X,
            Up::Y => crate::mocap::ingest::UpAxis::Y,
            Up::Z => crate::mocap::ingest::UpAxis::Z,
            Up::NegX => crate::mocap::ingest::UpAxis::NegX,
            Up::NegY => crate::mocap::ingest::UpAxis::NegY,
            Up::NegZ => crate::mocap::ingest::UpAxis::NegZ,
        }
    }
}

/// One explicitly named track (`Track(…)` in RON).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename = "Track", deny_unknown_fields)]
pub struct TrackSpec {
    /// The track's label in the take.
    pub label: String,
    /// The X, Y, Z position columns.
    pub position: (String, String, String),
    /// The rotation columns, for a rigid body.
    #[serde(default)]
    pub orientation: Option<Orientation>,
    /// The hand holding it.
    #[serde(default)]
    pub hand: Option<Side>,
}

/// A rule that discovers tracks from the column names (`Pattern(…)` in RON).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Pattern {
    /// The X, Y, Z position column templates; the first holds `{name}`.
    pub position: (String, String, String),
    /// The rotation column templates, for rigid bodies.
    #[serde(default)]
    pub orientation: Option<Orientation>,
}

/// Where and how a rigid body's rotation is written.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Orientation {
    /// A quaternion's X, Y, Z, W columns (normalised on reading).
    Quaternion {
        x: String,
        y: String,
        z: String,
        w: String,
    },
    /// Three Euler angles.
    Euler {
        columns: (String, String, String),
        /// Three of X, Y, Z, no letter twice in a row.
        order: String,
        #[serde(default)]
        angles: AngleUnit,
        #[serde(default)]
        frame: EulerFrame,
    },
    /// The world-from-body rotation matrix, 9 columns in row-major order.
    Matrix { columns: Vec<String> },
}

/// The unit of Euler angles.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum AngleUnit {
    #[default]
    Degrees,
    Radians,
}

/// Whether Euler angles turn about the rotating (intrinsic) or fixed (extrinsic) axes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum EulerFrame {
    #[default]
    Intrinsic,
    Extrinsic,
}

/// A column reference as written in a profile.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum ColumnRef<'a> {
    /// `#N`: the 0-based column index N − 1.
    Index(usize),
    /// `+N`: N columns right of the track's first position column.
    Offset(usize),
    /// A header name (or pattern template).
    Name(&'a str),
}

impl<'a> ColumnRef<'a> {
    /// Parse a reference: `#N` (N ≥ 1), `+N` (N ≥ 1) or a name.
    pub(super) fn parse(s: &'a str) -> Result<ColumnRef<'a>, String> {
        let t = s.trim();
        let number = |digits: &str, what: &str| match digits.trim().parse::<usize>() {
            Ok(n) if n >= 1 => Ok(n),
            _ => Err(format!(
                "expected {what} with a whole number of at least 1, found \"{s}\""
            )),
        };
        if let Some(d) = t.strip_prefix('#') {
            return number(d, "\"#N\" (the N-th column)").map(|n| ColumnRef::Index(n - 1));
        }
        if let Some(d) = t.strip_prefix('+') {
            return number(d, "\"+N\" (N columns right of the first position column)")
                .map(ColumnRef::Offset);
        }
        if t.is_empty() {
            return Err("expected a column name, \"#N\" or \"+N\", found an empty string".into());
        }
        Ok(ColumnRef::Name(t))
    }
}

/// A piece of a pattern template.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Part<'a> {
    Text(&'a str),
    /// A `{placeholder}`'s name.
    Hole(&'a str),
}

/// Split a template into text and `{placeholders}`; braces must pair up around a name.
pub(super) fn template_parts(s: &str) -> Result<Vec<Part<'_>>, String> {
    let mut parts = Vec::new();
    let mut rest = s;
    while let Some(open) = rest.find(['{', '}']) {
        let (text, tail) = rest.split_at(open);
        let close = tail.find('}').filter(|_| tail.starts_with('{'));
        let Some(close) = close.filter(|&c| c > 1 && !tail[1..c].contains('{')) else {
            return Err(format!(
                "expected a placeholder like \"{{name}}\" between braces, found \"{s}\""
            ));
        };
        if !text.is_empty() {
            parts.push(Part::Text(text));
        }
        parts.push(Part::Hole(&tail[1..close]));
        rest = &tail[close + 1..];
    }
    if !rest.is_empty() {
        parts.push(Part::Text(rest));
    }
    Ok(parts)
}

/// The axes of an Euler order ("XYZ", "zxz", …): three of X, Y, Z, none twice in a row.
pub(super) fn euler_axes(order: &str) -> Result<[DVec3; 3], String> {
    let bad = || {
        format!(
            "expected an Euler order of three letters X, Y, Z with no letter twice in a row \
             (\"XYZ\", \"ZYX\", \"ZXZ\", …), found \"{order}\""
        )
    };
    let axes: Vec<DVec3> = order
        .trim()
        .chars()
        .map(|c| match c.to_ascii_uppercase() {
            'X' => Some(DVec3::X),
            'Y' => Some(DVec3::Y),
            'Z' => Some(DVec3::Z),
            _ => None,
        })
        .collect::<Option<_>>()
        .ok_or_else(bad)?;
    match axes[..] {
        [a, b, c] if a != b && b != c => Ok([a, b, c]),
        _ => Err(bad()),
    }
}

impl Orientation {
    /// The column references, in reading order.
    pub(super) fn columns(&self) -> Vec<&str> {
        match self {
            Orientation::Quaternion { x, y, z, w } => vec![x, y, z, w],
            Orientation::Euler {
                columns: (a, b, c), ..
            } => vec![a, b, c],
            Orientation::Matrix { columns } => columns.iter().map(String::as_str).collect(),
        }
    }

    /// What is wrong with it, if anything.
    fn problem(&self) -> Option<String> {
        match self {
            Orientation::Matrix { columns } if columns.len() != 9 => Some(format!(
                "expected 9 matrix columns (row-major R11, R12, … R33), found {}",
                columns.len()
            )),
            Orientation::Euler { order, .. } => euler_axes(order).err(),
            _ => None,
        }
    }
}

impl CaptureProfile {
    /// A profile with only a name and every other field at its default.
    pub fn named(name: impl Into<String>) -> CaptureProfile {
        CaptureProfile {
            name: name.into(),
            delimiter: Delimiter::Auto,
            decimal_comma: None,
            section: None,
            header: HeaderLocation::Auto,
            header_rows: 1,
            unit_row: false,
            time: TimeColumn::None,
            rate_hz: None,
            rate_key: None,
            unit: None,
            unit_key: None,
            frames_key: None,
            zero_is_missing: false,
            up: None,
            tracks: Vec::new(),
            patterns: Vec::new(),
            tip_offset_m: None,
        }
    }

    /// Parse a profile from RON text; `source` names it in errors, which give the RON
    /// line and column (or the field at fault).
    pub fn parse(text: &str, source: &Path) -> Result<CaptureProfile, ImportError> {
        let options = ron::Options::default()
            .with_default_extension(ron::extensions::Extensions::IMPLICIT_SOME);
        let profile: CaptureProfile = options.from_str(text).map_err(|e| {
            ImportError::format(
                source,
                format!("line {}, column {}", e.span.start.line, e.span.start.col),
                format!("expected a CaptureProfile(…) in RON: {}", e.code),
            )
        })?;
        profile.check(source)?;
        Ok(profile)
    }

    /// Read a user's profile file.
    pub fn load(path: &Path) -> Result<CaptureProfile, ImportError> {
        let text = std::fs::read_to_string(path).map_err(|source| ImportError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        CaptureProfile::parse(&text, path)
    }

    /// A shipped profile by its short name ([`CaptureProfile::shipped_names`]) or its
    /// `name`, case-insensitively.
    pub fn shipped(name: &str) -> Option<CaptureProfile> {
        let want = name.trim();
        SHIPPED.iter().find_map(|(key, text)| {
            let path = Path::new("mocap/profiles").join(format!("{key}.ron"));
            let profile = CaptureProfile::parse(text, &path).ok()?;
            (key.eq_ignore_ascii_case(want) || profile.name.eq_ignore_ascii_case(want))
                .then_some(profile)
        })
    }

    /// The short names of the shipped profiles.
    pub fn shipped_names() -> Vec<&'static str> {
        SHIPPED.iter().map(|(key, _)| *key).collect()
    }

    /// A profile file if `name_or_path` is one, else a shipped profile of that name.
    pub fn resolve(name_or_path: &str) -> Result<CaptureProfile, ImportError> {
        let path = Path::new(name_or_path);
        if path.is_file() {
            return CaptureProfile::load(path);
        }
        CaptureProfile::shipped(name_or_path).ok_or_else(|| {
            ImportError::format(
                path,
                "capture profile",
                format!(
                    "expected a profile file or a shipped profile ({}), found neither",
                    CaptureProfile::shipped_names().join(", ")
                ),
            )
        })
    }

    /// The hand of the explicit track labelled `label` (equal, or the end after a `:`
    /// subject prefix; case-insensitive).
    pub fn hand_of(&self, label: &str) -> Option<Side> {
        let want = label.trim().to_lowercase();
        self.tracks.iter().find_map(|t| {
            let own = t.label.trim().to_lowercase();
            let hit = own == want || want.ends_with(&format!(":{own}"));
            if hit { t.hand } else { None }
        })
    }

    /// The stick tip in the rigid body's frame, m.
    pub fn tip_offset(&self) -> Option<DVec3> {
        self.tip_offset_m.map(|(x, y, z)| DVec3::new(x, y, z))
    }

    /// The fixed length unit (`unit`), if any and valid.
    pub(super) fn length_unit(&self) -> Option<LengthUnit> {
        self.unit.as_deref().and_then(LengthUnit::parse)
    }

    /// Check what serde cannot: references, Euler orders, matrix sizes, values in range.
    /// `source` names the profile in the error, whose place is the field at fault.
    pub fn check(&self, source: &Path) -> Result<(), ImportError> {
        self.problem().map_or(Ok(()), |(field, message)| {
            Err(ImportError::format(
                source,
                format!("profile \"{}\", field {field}", self.name),
                message,
            ))
        })
    }

    /// The first problem: (field, message).
    fn problem(&self) -> Option<(String, String)> {
        let at = |field: &str, m: String| Some((field.to_string(), m));
        if self.name.trim().is_empty() {
            return at("name", "expected a non-empty name".into());
        }
        if self.header_rows > 16 {
            return at(
                "header_rows",
                format!("expected 0 to 16 rows, found {}", self.header_rows),
            );
        }
        match &self.header {
            HeaderLocation::Line(0) => return at("header", "expected Line(n) with n ≥ 1".into()),
            HeaderLocation::StartsWith(s) if s.trim().is_empty() => {
                return at("header", "expected StartsWith(text) with some text".into());
            }
            _ => {}
        }
        if let Some(r) = self.rate_hz.filter(|r| !(r.is_finite() && *r > 0.0)) {
            return at("rate_hz", format!("expected a rate above 0 Hz, found {r}"));
        }
        if let Some(u) = self
            .unit
            .as_deref()
            .filter(|u| LengthUnit::parse(u).is_none())
        {
            return at(
                "unit",
                format!("expected \"mm\", \"cm\" or \"m\", found \"{u}\""),
            );
        }
        if let Some((x, y, z)) = self
            .tip_offset_m
            .filter(|(x, y, z)| ![x, y, z].iter().all(|v| v.is_finite()))
        {
            return at(
                "tip_offset_m",
                format!("expected finite metres, found ({x}, {y}, {z})"),
            );
        }
        if let TimeColumn::Seconds(c) | TimeColumn::Milliseconds(c) | TimeColumn::Frame(c) =
            &self.time
            && let Err(m) = ColumnRef::parse(c)
        {
            return at("time", m);
        }
        self.track_problem().or_else(|| self.pattern_problem())
    }

    fn track_problem(&self) -> Option<(String, String)> {
        for (i, t) in self.tracks.iter().enumerate() {
            let field = format!("tracks[{i}] (\"{}\")", t.label);
            if t.label.trim().is_empty() {
                return Some((field, "expected a non-empty label".into()));
            }
            let dup = self.tracks[..i]
                .iter()
                .any(|o| o.label.trim().eq_ignore_ascii_case(t.label.trim()));
            if dup {
                return Some((field, "expected each label once, found it twice".into()));
            }
            let refs = spec_columns(&t.position, t.orientation.as_ref());
            let m = refs.iter().find_map(|r| ColumnRef::parse(r).err());
            let m = m.or_else(|| t.orientation.as_ref().and_then(Orientation::problem));
            if let Some(m) = m {
                return Some((field, m));
            }
        }
        None
    }

    fn pattern_problem(&self) -> Option<(String, String)> {
        for (i, p) in self.patterns.iter().enumerate() {
            let field = format!("patterns[{i}]");
            if let Some(m) = pattern_problem(p) {
                return Some((field, m));
            }
        }
        None
    }
}

/// Every column reference of a track or pattern: position X, Y, Z, then orientation.
pub(super) fn spec_columns<'a>(
    position: &'a (String, String, String),
    orientation: Option<&'a Orientation>,
) -> Vec<&'a str> {
    let mut refs = vec![
        position.0.as_str(),
        position.1.as_str(),
        position.2.as_str(),
    ];
    refs.extend(orientation.map(Orientation::columns).unwrap_or_default());
    refs
}

/// What is wrong with a pattern: its first column must be a template holding `{name}`,
/// and every other placeholder must appear in that first column.
fn pattern_problem(p: &Pattern) -> Option<String> {
    let refs = spec_columns(&p.position, p.orientation.as_ref());
    let first = match template_parts(refs[0]) {
        Ok(parts) => parts,
        Err(m) => return Some(m),
    };
    if !matches!(ColumnRef::parse(refs[0]), Ok(ColumnRef::Name(_)))
        || !first.contains(&Part::Hole("name"))
    {
        return Some(format!(
            "expected the first position column to be a name holding \"{{name}}\", found \"{}\"",
            refs[0]
        ));
    }
    for r in &refs {
        if let Err(m) = ColumnRef::parse(r) {
            return Some(m);
        }
        match template_parts(r) {
            Err(m) => return Some(m),
            Ok(parts) => {
                let stray = parts.iter().find_map(|p| match p {
                    Part::Hole(h) if !first.contains(&Part::Hole(h)) => Some(*h),
                    _ => None,
                });
                if let Some(h) = stray {
                    return Some(format!(
                        "expected placeholder \"{{{h}}}\" in the first position column \"{}\" \
                         too (it is what gives it a value)",
                        refs[0]
                    ));
                }
            }
        }
    }
    p.orientation.as_ref().and_then(Orientation::problem)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p() -> &'static Path {
        Path::new("p.ron")
    }

    #[test]
    fn brief_example_parses_with_defaults() {
        let text = r#"CaptureProfile(
            name: "Qualisys TSV 6DOF",
            delimiter: Auto,
            decimal_comma: None,
            header: Auto,
            header_rows: 1,
            time: Seconds("Time"),
            rate_hz: None,
            rate_key: Some("FREQUENCY"),
            unit: None,
            unit_key: None,
            zero_is_missing: false,
            up: None,
            tracks: [
                Track(label: "StickR", position: ("StickR X", "StickR Y", "StickR Z"),
                      orientation: Some(Euler(columns: ("Roll", "Pitch", "Yaw"), order: "XYZ", angles: Degrees, frame: Intrinsic)),
                      hand: Some(Right)),
            ],
            patterns: [
                Pattern(position: ("{name} X", "{name} Y", "{name} Z"), orientation: None),
            ],
            tip_offset_m: None,
        )"#;
        let profile = CaptureProfile::parse(text, p()).unwrap();
        assert_eq!(profile.rate_key.as_deref(), Some("FREQUENCY"));
        assert_eq!(profile.hand_of("stickr"), Some(Side::Right));
        assert_eq!(profile.hand_of("Subject:StickR"), Some(Side::Right));
        assert_eq!(profile.hand_of("StickL"), None);
        let minimal = CaptureProfile::parse("CaptureProfile(name: \"x\")", p()).unwrap();
        assert_eq!(minimal, CaptureProfile::named("x"));
        let implicit =
            "CaptureProfile(name: \"x\", rate_hz: 100, up: Z, tip_offset_m: (0, 0, 0.3))";
        let implicit = CaptureProfile::parse(implicit, p()).unwrap();
        assert_eq!(implicit.rate_hz, Some(100.0));
        assert_eq!(implicit.up, Some(Up::Z));
        assert_eq!(
            crate::mocap::ingest::UpAxis::from(Up::Y),
            crate::mocap::ingest::UpAxis::Y
        );
        assert_eq!(implicit.tip_offset(), Some(DVec3::new(0.0, 0.0, 0.3)));
    }

    #[test]
    fn errors_name_the_file_and_the_ron_position_or_field() {
        let cases = [
            (
                "CaptureProfile(name: \"x\", colour: 1)",
                "p.ron: line 1, column",
            ),
            ("CaptureProfile(rate_hz: 1)", "p.ron: line 1, column"),
            (
                "CaptureProfile(name: \"x\",\n  delimiter: Pipe)",
                "p.ron: line 2, column",
            ),
            ("CaptureProfile(name: \"x\", rate_hz: -1)", "field rate_hz"),
            ("CaptureProfile(name: \"x\", unit: \"in\")", "field unit"),
            (
                "CaptureProfile(name: \"x\", header_rows: 17)",
                "field header_rows",
            ),
            (
                "CaptureProfile(name: \"x\", header: Line(0))",
                "field header",
            ),
            (
                "CaptureProfile(name: \"x\", time: Frame(\"#0\"))",
                "field time",
            ),
            (
                "CaptureProfile(name: \"x\", tracks: [Track(label: \"a\", position: (\"a\", \"b\", \"+x\"))])",
                "field tracks[0] (\"a\"): expected \"+N\"",
            ),
            (
                "CaptureProfile(name: \"x\", tracks: [Track(label: \"a\", position: (\"a\", \"b\", \"c\"), orientation: Euler(columns: (\"r\", \"p\", \"y\"), order: \"XXY\"))])",
                "expected an Euler order",
            ),
            (
                "CaptureProfile(name: \"x\", tracks: [Track(label: \"a\", position: (\"a\", \"b\", \"c\"), orientation: Matrix(columns: [\"1\"]))])",
                "expected 9 matrix columns",
            ),
            (
                "CaptureProfile(name: \"x\", tracks: [Track(label: \"a\", position: (\"a\", \"b\", \"c\")), Track(label: \"A\", position: (\"a\", \"b\", \"c\"))])",
                "field tracks[1] (\"A\"): expected each label once",
            ),
            (
                "CaptureProfile(name: \"x\", patterns: [Pattern(position: (\"X\", \"Y\", \"Z\"))])",
                "field patterns[0]: expected the first position column",
            ),
            (
                "CaptureProfile(name: \"x\", patterns: [Pattern(position: (\"{name} X\", \"{name} Y{n}\", \"{name} Z\"))])",
                "expected placeholder \"{n}\"",
            ),
            (
                "CaptureProfile(name: \"x\", patterns: [Pattern(position: (\"{name X\", \"Y\", \"Z\"))])",
                "expected a placeholder",
            ),
        ];
        for (text, want) in cases {
            let e = CaptureProfile::parse(text, p()).unwrap_err().to_string();
            assert!(e.contains(want), "{text}: {e}");
        }
        let e = CaptureProfile::load(Path::new("/no/such/profile.ron")).unwrap_err();
        assert!(e.to_string().contains("/no/such/profile.ron"), "{e}");
        let e = CaptureProfile::resolve("no-such-profile")
            .unwrap_err()
            .to_string();
        assert!(e.contains("motive, vicon, qualisys-3d"), "{e}");
    }

    #[test]
    fn shipped_profiles_load_by_short_or_full_name_and_from_a_path() {
        for name in CaptureProfile::shipped_names() {
            let profile = CaptureProfile::shipped(name).unwrap_or_else(|| {
                let (_, text) = SHIPPED.iter().find(|(k, _)| *k == name).unwrap();
                panic!("{name}: {}", CaptureProfile::parse(text, p()).unwrap_err())
            });
            assert_eq!(
                CaptureProfile::shipped(&profile.name),
                Some(profile.clone())
            );
            assert_eq!(CaptureProfile::resolve(name).unwrap(), profile);
        }
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("mine.ron");
        std::fs::write(&file, "CaptureProfile(name: \"mine\", rate_hz: 60)").unwrap();
        let mine = CaptureProfile::resolve(file.to_str().unwrap()).unwrap();
        assert_eq!(mine.rate_hz, Some(60.0));
        std::fs::write(&file, "CaptureProfile(\n  name: \"mine\",\n  rate: 60)").unwrap();
        let e = CaptureProfile::load(&file).unwrap_err().to_string();
        assert!(e.contains("mine.ron: line 3, column"), "{e}");
    }

    #[test]
    fn references_templates_and_orders() {
        assert_eq!(ColumnRef::parse(" #3 "), Ok(ColumnRef::Index(2)));
        assert_eq!(ColumnRef::parse("+7"), Ok(ColumnRef::Offset(7)));
        assert_eq!(ColumnRef::parse("Rot[0]"), Ok(ColumnRef::Name("Rot[0]")));
        assert!(ColumnRef::parse("#").is_err());
        assert!(ColumnRef::parse("+0").is_err());
        assert_eq!(
            template_parts("{name} X{n}").unwrap(),
            vec![Part::Hole("name"), Part::Text(" X"), Part::Hole("n")]
        );
        assert!(template_parts("a}b").is_err());
        assert!(template_parts("{}").is_err());
        assert!(template_parts("{a{b}}").is_err());
        assert_eq!(euler_axes("zxz").unwrap(), [DVec3::Z, DVec3::X, DVec3::Z]);
        assert!(euler_axes("XY").is_err());
        assert!(euler_axes("XYW").is_err());
    }
}
