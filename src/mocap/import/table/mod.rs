//! The column-mapped table reader: reads any delimited text capture (CSV, TSV, `;` with
//! decimal commas, whitespace-separated) the way a [`CaptureProfile`] describes it, and
//! lays the table out ([`inspect`]) for a user writing a profile.
//!
//! # Reading
//!
//! 1. The text is decoded (UTF-8 with or without a byte-order mark, UTF-16 with one, or
//!    Windows-1252) and split into cells (CRLF, quoted cells and trailing delimiters
//!    tolerated).
//! 2. The header is found ([`crate::mocap::import::profile`]: `header`, `header_rows`,
//!    `section`, `unit_row`) and its rows joined into column names; the lines above it
//!    are metadata.
//! 3. Tracks are the profile's explicit `tracks`, then every track its `patterns` find.
//!    A missing column is an error listing the nearest existing names.
//! 4. Data rows: blank lines are skipped (those between data rows with a note); after a
//!    blank line, a line whose first cell is not a number ends the table (the next
//!    section of a multi-section export). A cell
//!    that is empty, absent (a short row), `NaN` or `-` is a missing value: the position
//!    is `None` if any coordinate is missing, the rotation `None` if any of its cells is.
//!    Any other non-number in a used column is an error naming the line and column.
//!    Positions are scaled to metres.
//! 5. Rows go on a uniform grid at the frame rate: each row's frame is the previous
//!    row's plus round(Δt · rate) (for a `Frame` column, the frame number minus the
//!    first one; with no time column, rows are consecutive frames). So dropped frames
//!    become `None` samples, reported in [`Take::notes`]; a duplicate or backwards time,
//!    or a step more than a quarter frame off the grid, is an error naming the line.
//!    With only a time column the rate is 1 / the median step, refined over the whole
//!    take and rounded (to a whole Hz within 0.1 %, else to 0.01 Hz), with a note.

use super::LengthUnit;
use super::csv_text::{self, Row};
use super::profile::{
    AngleUnit, CaptureProfile, ColumnRef, Delimiter, EulerFrame, HeaderLocation, Orientation, Part,
    TimeColumn, euler_axes, spec_columns, template_parts,
};
use crate::mocap::take::{ImportError, MarkedGaps, Take, Track};
use glam::{DMat3, DQuat, DVec3};
use std::collections::HashMap;
use std::fmt;
use std::path::Path;

/// What [`inspect`] finds in a file: enough to write a profile for it.
#[derive(Clone, Debug, PartialEq)]
pub struct TableLayout {
    /// The cell separator used (never `Auto`).
    pub delimiter: Delimiter,
    /// Whether numbers are written with a decimal comma.
    pub decimal_comma: bool,
    /// The header's lines (1-based).
    pub header_lines: Vec<usize>,
    /// The unit row's line, if the profile has one.
    pub unit_line: Option<usize>,
    /// The first data line.
    pub data_line: usize,
    /// Every column.
    pub columns: Vec<ColumnInfo>,
    /// The key/value pairs above the header.
    pub metadata: Vec<MetaEntry>,
    /// The tracks the profile finds.
    pub tracks: Vec<FoundTrack>,
    /// Why some of the profile's tracks were not found, or none at all.
    pub problems: Vec<String>,
}

/// One column of the table.
#[derive(Clone, Debug, PartialEq)]
pub struct ColumnInfo {
    /// 1-based index (what `"#N"` refers to).
    pub index: usize,
    /// The joined header name.
    pub name: String,
    /// The unit row's cell, if any.
    pub unit: Option<String>,
    /// The cell in the first data row.
    pub first_value: String,
}

/// A metadata key and its value.
#[derive(Clone, Debug, PartialEq)]
pub struct MetaEntry {
    /// The key's line (1-based).
    pub line: usize,
    /// The key's column (1-based).
    pub column: usize,
    pub key: String,
    /// The value: the next non-empty cell on the key's line, or the cell below it.
    pub value: String,
    /// Every non-empty cell after the key on its line (lists like Qualisys
    /// `MARKER_NAMES`), or just the value.
    pub values: Vec<String>,
}

/// A track the profile finds, with its 1-based columns.
#[derive(Clone, Debug, PartialEq)]
pub struct FoundTrack {
    pub label: String,
    pub position: [usize; 3],
    /// "quaternion", "euler" or "matrix", and the columns.
    pub orientation: Option<(&'static str, Vec<usize>)>,
}

/// What [`read_table`] knows besides the take, for format-specific checks.
pub(super) struct TableInfo {
    pub metadata: Vec<MetaEntry>,
    /// The positions written as NaN or, with `zero_is_missing`, as all zeros (gaps).
    pub gaps: MarkedGaps,
}

/// Read a capture table as `profile` describes it; `unit` overrides every unit source.
/// The positions written as NaN (and, with `zero_is_missing`, as zeros) are gaps,
/// counted in a note.
pub fn read(
    path: &Path,
    bytes: &[u8],
    profile: &CaptureProfile,
    unit: Option<LengthUnit>,
) -> Result<Take, ImportError> {
    let (mut take, info) = read_table(path, bytes, profile, unit)?;
    take.notes.extend(info.gaps.note());
    Ok(take)
}

/// Lay out a capture table as `profile` finds it (delimiter, header, columns with their
/// first value, metadata, tracks) without reading the data.
pub fn inspect(
    path: &Path,
    bytes: &[u8],
    profile: &CaptureProfile,
) -> Result<TableLayout, ImportError> {
    let text = csv_text::decode_text(bytes);
    let table = Table::open(path, &text, profile)?;
    let (sheet, found, cols) = (&table.sheet, &table.found, &table.cols);
    let (tracks, problems) = find_tracks(profile, cols);
    let first = &sheet.rows[found.data];
    Ok(TableLayout {
        delimiter: sheet.delimiter,
        decimal_comma: sheet.decimal_comma,
        header_lines: found.header.iter().map(|&i| sheet.rows[i].line).collect(),
        unit_line: found.unit_row.map(|i| sheet.rows[i].line),
        data_line: first.line,
        columns: (0..cols.names.len())
            .map(|c| ColumnInfo {
                index: c + 1,
                name: cols.names[c].clone(),
                unit: found.unit_row.map(|u| sheet.rows[u].cell(c).to_string()),
                first_value: first.cell(c).to_string(),
            })
            .collect(),
        metadata: table.metadata(),
        tracks: tracks.iter().map(TrackCols::found).collect(),
        problems,
    })
}

/// [`read`] without the gap note, also giving the metadata and the gaps to note.
pub(super) fn read_table(
    path: &Path,
    bytes: &[u8],
    profile: &CaptureProfile,
    unit: Option<LengthUnit>,
) -> Result<(Take, TableInfo), ImportError> {
    let text = csv_text::decode_text(bytes);
    let table = Table::open(path, &text, profile)?;
    let (sheet, found, cols) = (&table.sheet, &table.found, &table.cols);
    let (tracks, problems) = find_tracks(profile, cols);
    let header_place = found.header_place(sheet);
    if let Some(p) = problems.into_iter().next() {
        return Err(ImportError::format(path, header_place, p));
    }
    let meta = table.metadata();
    let mut notes = Vec::new();
    let clock = clock_column(path, profile, cols, &header_place)?;
    let unit_row = found.unit_row.map(|u| &sheet.rows[u]);
    let scales = Scales::new(path, profile, unit, &meta, unit_row, &tracks, &mut notes)?;
    let reader = RowReader {
        path,
        cols,
        decimal_comma: sheet.decimal_comma,
        zero_is_missing: profile.zero_is_missing,
        in_section: profile.section.is_some(),
    };
    let rows = reader.read_rows(sheet, found.data, clock, &tracks, &scales, &mut notes)?;
    let stated = stated_rate(profile, &meta, &mut notes);
    let grid = Grid::place(path, &rows, clock.map(|c| c.1), stated, &mut notes)?;
    notes.extend(frame_count_note(path, profile, &meta, &rows, grid.frames)?);
    let info = TableInfo {
        metadata: meta,
        gaps: rows.gaps,
    };
    let take = Take {
        source: path.to_path_buf(),
        rate_hz: grid.rate_hz,
        frames: grid.frames,
        file_unit: scales.file_unit.clone(),
        tracks: grid.scatter(rows.tracks),
        notes,
    };
    Ok((take, info))
}

/// A decoded file as a table: its rows, where its parts are, its column names.
struct Table<'a> {
    sheet: Sheet<'a>,
    found: Located,
    cols: Columns,
}

impl<'a> Table<'a> {
    /// Check the profile, split the text and find the header, data and columns.
    fn open(
        path: &Path,
        text: &'a str,
        profile: &CaptureProfile,
    ) -> Result<Table<'a>, ImportError> {
        profile.check(path)?;
        let sheet = Sheet::split(text, profile);
        let found = locate(path, &sheet, profile)?;
        let cols = Columns::new(&sheet, &found);
        Ok(Table { sheet, found, cols })
    }

    /// The key/value pairs above the header.
    fn metadata(&self) -> Vec<MetaEntry> {
        metadata(&self.sheet.rows[self.found.region..self.found.header_start()])
    }
}

mod clock;
mod columns;
mod display;
mod grid;
mod rows;
mod sheet;
mod tracks;

pub(super) use clock::stated_count;
use clock::*;
pub(super) use columns::lookup;
use columns::*;
use grid::*;
use rows::*;
use sheet::*;
use tracks::*;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kit::Side;
    use crate::mocap::import::{Format, read_bytes};

    const MOTIVE: &[u8] =
        include_bytes!("../../../../tests/fixtures/capture/motive_two_sticks_120hz.csv");
    const VICON: &[u8] = include_bytes!("../../../../tests/fixtures/capture/vicon_nexus_100hz.csv");
    const QTM_3D: &[u8] =
        include_bytes!("../../../../tests/fixtures/capture/qualisys_3d_200hz.tsv");
    const QTM_6D: &[u8] =
        include_bytes!("../../../../tests/fixtures/capture/qualisys_6d_100hz.tsv");
    const TRC: &[u8] = include_bytes!("../../../../tests/fixtures/capture/opensim_walk.trc");
    const PLAIN: &[u8] =
        include_bytes!("../../../../tests/fixtures/capture/plain_two_sticks_250hz.csv");

    fn p() -> &'static Path {
        Path::new("t.csv")
    }

    fn shipped(name: &str) -> CaptureProfile {
        CaptureProfile::shipped(name).unwrap()
    }

    fn near(a: Option<DVec3>, b: DVec3) -> bool {
        a.is_some_and(|a| a.abs_diff_eq(b, 1e-9))
    }

    /// Same rotation (q and −q are one rotation).
    fn same_rot(a: DQuat, b: DQuat, tol: f64) -> bool {
        a.dot(b).abs() > 1.0 - tol
    }

    fn profile(ron: &str) -> CaptureProfile {
        CaptureProfile::parse(ron, Path::new("test.ron")).unwrap()
    }

    fn read_err(text: &[u8], prof: &CaptureProfile) -> String {
        read(p(), text, prof, None).unwrap_err().to_string()
    }

    fn noted(take: &Take, what: &str) -> bool {
        take.notes.iter().any(|n| n.contains(what))
    }

    #[test]
    fn motive_profile_reads_rigid_bodies_markers_gaps_and_a_dropped_frame() {
        let take = read(p(), MOTIVE, &shipped("motive"), None).unwrap();
        assert_eq!(
            take.labels(),
            vec![
                "Stick L",
                "StickR",
                "StickR:Marker1",
                "Stick L:Marker1",
                "Unlabeled 1000"
            ]
        );
        assert_eq!(
            (take.rate_hz, take.frames, take.file_unit.as_str()),
            (120.0, 9, "mm")
        );
        let l = take.track("Stick L").unwrap();
        assert!(near(l.positions[0], DVec3::new(-0.25, 0.95, 0.4)));
        assert!(same_rot(
            l.rotations[2].unwrap(),
            DQuat::from_rotation_x(0.2),
            1e-9
        ));
        assert_eq!(
            (l.positions[5], l.rotations[5]),
            (None, None),
            "dropped frame"
        );
        let r = take.track("StickR").unwrap();
        assert_eq!((r.positions[3], r.rotations[3]), (None, None), "gap");
        assert!(same_rot(
            r.rotations[4].unwrap(),
            DQuat::from_rotation_x(-0.4),
            1e-9
        ));
        let m = take.track("Stick L:Marker1").unwrap();
        assert!(m.rotations.is_empty());
        assert!(
            near(m.positions[0], DVec3::new(-0.25, 0.95, 0.7)),
            "the measured marker"
        );
        assert_eq!(m.positions[6], None);
        assert!(
            noted(&take, "1 dropped frame was filled as gaps"),
            "{:?}",
            take.notes
        );
    }

    #[test]
    fn motive_profile_agrees_with_the_motive_reader() {
        let bytes = include_bytes!("../../../../tests/fixtures/motive/timpani_roll_250hz.csv");
        let named = read_bytes(p(), bytes, Format::Motive).unwrap();
        let take = read(p(), bytes, &shipped("motive"), None).unwrap();
        assert_eq!((take.rate_hz, take.frames), (named.rate_hz, named.frames));
        assert!(take.notes.is_empty(), "{:?}", take.notes);
        for label in [
            "StickL",
            "StickR",
            "StickL:Marker1",
            "StickR:Marker3",
            "Unlabeled 1000",
        ] {
            assert_eq!(take.track(label), named.track(label), "{label}");
        }
    }

    #[test]
    fn vicon_profile_reads_the_trajectories_section_only() {
        let take = read(p(), VICON, &shipped("vicon"), None).unwrap();
        assert_eq!(
            take.labels(),
            vec![
                "Timpanist:STICKR_TIP",
                "Timpanist:STICKL_TIP",
                "Timpanist:C7"
            ]
        );
        assert_eq!(
            (take.rate_hz, take.frames, take.file_unit.as_str()),
            (100.0, 9, "mm")
        );
        let r = take.track("STICKR_TIP").unwrap();
        assert!(near(r.positions[0], DVec3::new(0.25, 0.95, 0.8)));
        assert!(near(r.positions[8], DVec3::new(0.258, 0.95, 0.72)));
        assert_eq!(r.positions[4], None, "frame 105 not exported");
        assert_eq!(take.track("STICKL_TIP").unwrap().positions[2], None, "gap");
        assert_eq!(take.notes.len(), 1, "{:?}", take.notes);
        assert!(noted(&take, "1 dropped frame"), "{:?}", take.notes);
        let metres = read(p(), VICON, &shipped("vicon"), Some(LengthUnit::Metre)).unwrap();
        assert_eq!(
            metres.tracks[2].positions[0],
            Some(DVec3::new(0.0, -100.0, 1450.0))
        );
    }

    #[test]
    fn vicon_profile_agrees_with_the_vicon_reader() {
        let bytes = include_bytes!("../../../../tests/fixtures/vicon/timpani_strokes_100hz.csv");
        let named = read_bytes(p(), bytes, Format::Vicon).unwrap();
        let take = read(p(), bytes, &shipped("vicon"), None).unwrap();
        assert_eq!(take.labels(), named.labels());
        assert_eq!((take.rate_hz, take.frames), (named.rate_hz, named.frames));
        for (a, b) in take.tracks.iter().zip(&named.tracks) {
            for (x, y) in a.positions.iter().zip(&b.positions) {
                assert_eq!(x.is_some(), y.is_some());
                assert!(x.zip(*y).is_none_or(|(x, y)| x.abs_diff_eq(y, 1e-12)));
            }
        }
    }

    #[test]
    fn qualisys_3d_profile_reads_zeros_as_gaps_and_names_with_spaces() {
        let take = read(p(), QTM_3D, &shipped("qualisys-3d"), None).unwrap();
        assert_eq!(take.labels(), vec!["Stick R tip", "Stick L tip", "C7"]);
        assert_eq!(
            (take.rate_hz, take.frames, take.file_unit.as_str()),
            (200.0, 9, "mm")
        );
        let l = take.track("Stick L tip").unwrap();
        assert_eq!(l.positions[2], None, "0 0 0 is unseen");
        assert!(
            noted(&take, "1 sample at exactly (0, 0, 0) read as gaps"),
            "{:?}",
            take.notes
        );
        assert!(near(l.positions[3], DVec3::new(-0.25, 0.953, 0.8)));
        assert_eq!(l.positions[4], None, "frame 5 dropped");
        assert!(near(
            take.tracks[2].positions[8],
            DVec3::new(0.0, -0.1, 1.45)
        ));
        let layout = inspect(p(), QTM_3D, &shipped("qualisys-3d")).unwrap();
        let meta = |k: &str| lookup(&layout.metadata, k).map(|e| e.value.clone());
        assert_eq!(meta("FREQUENCY").as_deref(), Some("200"));
        assert_eq!(meta("EVENT").as_deref(), Some("Hit"));
        let names = &lookup(&layout.metadata, "MARKER_NAMES").unwrap().values;
        assert_eq!(names, &["Stick R tip", "Stick L tip", "C7"]);
        assert_eq!(
            meta("TIME_STAMP").as_deref(),
            Some("2024-05-14, 15:12:45.120")
        );
    }

    #[test]
    fn qualisys_6d_profile_reads_the_matrix_column_by_column() {
        let take = read(p(), QTM_6D, &shipped("qualisys-6d"), None).unwrap();
        assert_eq!(take.labels(), vec!["StickR", "Stick L"]);
        assert_eq!(
            (take.rate_hz, take.frames, take.file_unit.as_str()),
            (100.0, 8, "mm")
        );
        let l = take.track("Stick L").unwrap();
        assert_eq!(
            (l.positions[1], l.rotations[1]),
            (None, None),
            "all zeros: not tracked"
        );
        assert_eq!(
            (l.positions[3], l.rotations[3]),
            (None, None),
            "frame 4 dropped"
        );
        assert!(near(
            take.tracks[0].positions[2],
            DVec3::new(0.27, 0.95, 0.8)
        ));
        // The same file read through its Roll, Pitch, Yaw columns as intrinsic XYZ
        // degrees (QTM's definition) gives the same rotations.
        let mut euler = shipped("qualisys-6d");
        euler.patterns[0].orientation = Some(Orientation::Euler {
            columns: ("+3".into(), "+4".into(), "+5".into()),
            order: "XYZ".into(),
            angles: AngleUnit::Degrees,
            frame: EulerFrame::Intrinsic,
        });
        let by_angles = read(p(), QTM_6D, &euler, None).unwrap();
        for (a, b) in take.tracks.iter().zip(&by_angles.tracks) {
            for (x, y) in a.rotations.iter().zip(&b.rotations) {
                match (x, y) {
                    (Some(x), Some(y)) => assert!(same_rot(*x, *y, 1e-8), "{x} vs {y}"),
                    (None, None) => {}
                    _ => assert_eq!(a.label, "Stick L", "only the untracked frame differs"),
                }
            }
        }
    }

    #[test]
    fn a_real_qtm_6d_row_agrees_only_column_by_column() {
        // Header and first row of a real QTM 6DOF export (github.com/shiplab/dt_cv,
        // data/basin/raw/M510A-IRR-EKFPID-020019_6D.tsv): roll, pitch, yaw, then Rot[0..8].
        let text = "NO_OF_FRAMES\t2\nFREQUENCY\t100\nDATA_INCLUDED\t6D\nBODY_NAMES\tPSVH\n\
            Frame\tTime\tPSVH X\tY\tZ\tRoll\tPitch\tYaw\tResidual\tRot[0]\tRot[1]\tRot[2]\tRot[3]\tRot[4]\tRot[5]\tRot[6]\tRot[7]\tRot[8]\t\n\
            1\t0.00000\t-194.91974\t2.24150\t0.99661\t-0.65630\t0.09391\t0.05772\t4.98536\t1.00000\t0.00099\t-0.00165\t-0.00101\t0.99993\t-0.01145\t0.00164\t0.01145\t0.99993\t\n\
            2\t0.01000\t-195.64748\t1.62077\t0.72224\t-0.78772\t0.05832\t0.12055\t4.77517\t1.00000\t0.00209\t-0.00105\t-0.00210\t0.99990\t-0.01375\t0.00102\t0.01375\t0.99990\t\n";
        let take = read(p(), text.as_bytes(), &shipped("qualisys-6d"), None).unwrap();
        let deg = |d: f64| d.to_radians();
        let by_angles = |r: f64, pi: f64, y: f64| {
            DQuat::from_rotation_x(deg(r))
                * DQuat::from_rotation_y(deg(pi))
                * DQuat::from_rotation_z(deg(y))
        };
        let q = take.tracks[0].rotations[0].unwrap();
        assert!(
            same_rot(q, by_angles(-0.65630, 0.09391, 0.05772), 1e-8),
            "{q}"
        );
        let q1 = take.tracks[0].rotations[1].unwrap();
        assert!(
            same_rot(q1, by_angles(-0.78772, 0.05832, 0.12055), 1e-8),
            "{q1}"
        );
        // Read row by row instead, the roll comes out with the wrong sign.
        assert!(!same_rot(q, by_angles(0.65630, -0.09391, -0.05772), 1e-8));
        assert!(same_rot(
            q.inverse(),
            by_angles(0.65630, -0.09391, -0.05772),
            1e-6
        ));
    }

    #[test]
    fn trc_profile_and_inspect_lay_the_file_out() {
        let take = read(p(), TRC, &shipped("trc"), None).unwrap();
        assert_eq!(take.labels(), vec!["R.Stick.Tip", "L.Stick.Tip", "C7"]);
        let layout = inspect(p(), TRC, &shipped("trc")).unwrap();
        assert_eq!(layout.delimiter, Delimiter::Tab);
        assert!(!layout.decimal_comma);
        assert_eq!(
            (layout.header_lines.clone(), layout.data_line),
            (vec![4, 5], 7)
        );
        let col = |i: usize| {
            (
                layout.columns[i].name.as_str(),
                layout.columns[i].first_value.as_str(),
            )
        };
        assert_eq!(col(0), ("Frame#", "1"));
        assert_eq!(col(1), ("Time", "0.000"));
        assert_eq!(col(2), ("R.Stick.Tip X1", "250.1"));
        assert_eq!(col(10), ("C7 Z3", "1450.0"));
        assert_eq!(layout.columns[10].index, 11);
        let rate = lookup(&layout.metadata, "datarate").unwrap();
        assert_eq!(
            (rate.line, rate.column, rate.value.as_str()),
            (2, 1, "100.00")
        );
        assert_eq!(lookup(&layout.metadata, "Units").unwrap().value, "mm");
        assert_eq!(lookup(&layout.metadata, "PathFileType").unwrap().value, "4");
        assert_eq!(layout.tracks[2].position, [9, 10, 11]);
        assert!(layout.problems.is_empty());
        let shown = layout.to_string();
        assert!(shown.contains("#3    \"R.Stick.Tip X1\""), "{shown}");
        assert!(shown.contains("C7: position #9 #10 #11"), "{shown}");
    }

    #[test]
    fn plain_profile_places_uneven_rows_on_the_grid_and_agrees_with_plain_csv() {
        let take = read(p(), PLAIN, &shipped("plain"), None).unwrap();
        assert_eq!(take.labels(), vec!["StickL:Tip", "StickL", "StickR:Tip"]);
        assert_eq!((take.rate_hz, take.frames), (250.0, 7));
        assert!(
            noted(&take, "frame rate 250 Hz from the time column"),
            "{:?}",
            take.notes
        );
        assert!(noted(&take, "1 dropped frame"), "{:?}", take.notes);
        let tip = take.track("StickL:Tip").unwrap();
        assert_eq!((tip.positions[2], tip.positions[3]), (None, None));
        let body = take.track("StickL").unwrap();
        assert!(same_rot(
            body.rotations[6].unwrap(),
            DQuat::from_rotation_x(0.3),
            1e-9
        ));
        let bytes = include_bytes!("../../../../tests/fixtures/csv/two_sticks_250hz.csv");
        let named = read_bytes(p(), bytes, Format::Csv).unwrap();
        let mine = read(p(), bytes, &shipped("plain"), None).unwrap();
        assert_eq!(mine.labels(), named.labels());
        assert_eq!((mine.rate_hz, mine.frames), (named.rate_hz, named.frames));
        for (a, b) in mine.tracks.iter().zip(&named.tracks) {
            assert_eq!(a.positions, b.positions, "{}", a.label);
            assert_eq!(a.rotations.len(), b.rotations.len());
            for (x, y) in a.rotations.iter().zip(&b.rotations) {
                assert!(x.zip(*y).is_none_or(|(x, y)| same_rot(x, y, 1e-12)));
            }
        }
    }

    /// Rx, Ry, Rz written out by hand.
    fn rx(a: f64) -> DMat3 {
        let (s, c) = a.sin_cos();
        DMat3::from_cols(DVec3::X, DVec3::new(0.0, c, s), DVec3::new(0.0, -s, c))
    }

    fn ry(a: f64) -> DMat3 {
        let (s, c) = a.sin_cos();
        DMat3::from_cols(DVec3::new(c, 0.0, -s), DVec3::Y, DVec3::new(s, 0.0, c))
    }

    fn rz(a: f64) -> DMat3 {
        let (s, c) = a.sin_cos();
        DMat3::from_cols(DVec3::new(c, s, 0.0), DVec3::new(-s, c, 0.0), DVec3::Z)
    }

    #[test]
    fn euler_orders_and_frames_match_hand_computed_rotations() {
        let q =
            |order: &str, a: [f64; 3], extrinsic| euler(a, euler_axes(order).unwrap(), extrinsic);
        let quarter = std::f64::consts::FRAC_PI_2;
        // Intrinsic XYZ (90°, 90°, 0): Ry first takes X to −Z, then Rx takes −Z to +Y.
        let v = q("XYZ", [quarter, quarter, 0.0], false) * DVec3::X;
        assert!(v.abs_diff_eq(DVec3::Y, 1e-12), "{v}");
        // Extrinsic XYZ: Rx first leaves X, then Ry takes it to −Z.
        let v = q("XYZ", [quarter, quarter, 0.0], true) * DVec3::X;
        assert!(v.abs_diff_eq(-DVec3::Z, 1e-12), "{v}");
        let [a, b, c] = [0.3, -1.1, 2.0];
        let cases = [
            ("XYZ", false, rx(a) * ry(b) * rz(c)),
            ("XYZ", true, rz(c) * ry(b) * rx(a)),
            ("ZYX", false, rz(a) * ry(b) * rx(c)),
            ("ZYX", true, rx(c) * ry(b) * rz(a)),
            ("ZXZ", false, rz(a) * rx(b) * rz(c)),
            ("yxy", true, ry(c) * rx(b) * ry(a)),
        ];
        for (order, extrinsic, m) in cases {
            let got = DMat3::from_quat(q(order, [a, b, c], extrinsic));
            assert!(
                got.abs_diff_eq(m, 1e-12),
                "{order} extrinsic {extrinsic}: {got} vs {m}"
            );
        }
        // And through a whole read: radians, extrinsic, an explicit track with a hand.
        let prof = profile(
            r#"CaptureProfile(name: "e", rate_hz: 10, tracks: [
                Track(label: "Stick", position: ("x", "y", "z"), hand: Some(Left),
                      orientation: Some(Euler(columns: ("a", "b", "c"), order: "ZYX",
                                              angles: Radians, frame: Extrinsic)))])"#,
        );
        let take = read(
            p(),
            b"x,y,z,a,b,c\n1,2,3,0.3,-1.1,2.0\n1,2,3,,1,1\n",
            &prof,
            None,
        )
        .unwrap();
        let got = DMat3::from_quat(take.tracks[0].rotations[0].unwrap());
        assert!(got.abs_diff_eq(rx(c) * ry(b) * rz(a), 1e-12));
        assert_eq!(take.tracks[0].rotations[1], None, "an angle missing");
        assert_eq!(prof.hand_of("Stick"), Some(Side::Left));
    }

    /// A Windows-1252, `;`-separated export with decimal commas, CRLF, a title, a quoted
    /// cell holding `;`, trailing delimiters and a short last row.
    fn european() -> Vec<u8> {
        let mut v = b"\"Messung; Pauke\";14.05.2024\r\nFrequenz;250\r\nEinheit;cm\r\n\r\n".to_vec();
        v.extend_from_slice(b"Zeit [ms];Schl\xe4gel X;Schl\xe4gel Y;Schl\xe4gel Z;Gier \xb0;Nick \xb0;Roll \xb0;\r\n");
        v.extend_from_slice(
            b"0;10,5;20,25;100;90;0;0;\r\n4;11,5;NaN;100;0;0;0;\r\n8;12,5;20;100;-;0;0;\r\n",
        );
        v.extend_from_slice(b"16;13,5;20;100\r\n");
        v
    }

    const EUROPEAN: &str = r##"CaptureProfile(
        name: "Lab export",
        time: Milliseconds("Zeit [ms]"),
        rate_key: "FREQUENZ",
        unit_key: "Einheit",
        tracks: [Track(label: "Schlägel", position: ("Schlägel X", "schlägel   y", "#4"),
            orientation: Euler(columns: ("Gier °", "Nick °", "Roll °"), order: "ZYX"))],
    )"##;

    #[test]
    fn reads_semicolons_decimal_commas_windows_1252_and_short_rows() {
        let take = read(p(), &european(), &profile(EUROPEAN), None).unwrap();
        assert_eq!(
            (take.rate_hz, take.frames, take.file_unit.as_str()),
            (250.0, 5, "cm")
        );
        let t = &take.tracks[0];
        assert_eq!(t.label, "Schlägel");
        assert!(near(t.positions[0], DVec3::new(0.105, 0.2025, 1.0)));
        assert_eq!(t.positions[1], None, "NaN");
        assert!(same_rot(
            t.rotations[0].unwrap(),
            DQuat::from_rotation_z(std::f64::consts::FRAC_PI_2),
            1e-12
        ));
        assert_eq!(t.rotations[2], None, "\"-\" is missing");
        assert_eq!(t.positions[3], None, "frame at 12 ms dropped");
        assert!(near(t.positions[4], DVec3::new(0.135, 0.2, 1.0)));
        assert_eq!(t.rotations[4], None, "short row");
        let layout = inspect(p(), &european(), &profile(EUROPEAN)).unwrap();
        assert_eq!(
            (layout.delimiter, layout.decimal_comma),
            (Delimiter::Semicolon, true)
        );
        assert_eq!(layout.header_lines, vec![5]);
        assert_eq!(layout.columns[4].name, "Gier °");
        assert_eq!(
            lookup(&layout.metadata, "Messung; Pauke").unwrap().value,
            "14.05.2024"
        );
        let mm = read(
            p(),
            &european(),
            &profile(EUROPEAN),
            Some(LengthUnit::Millimetre),
        )
        .unwrap();
        assert_eq!(mm.file_unit, "mm");
    }

    #[test]
    fn a_bom_crlf_file_without_time_uses_the_fixed_rate() {
        let prof = profile(
            r#"CaptureProfile(name: "n", rate_hz: 50, patterns: [Pattern(position: ("{name}.x", "{name}.y", "{name}.z"))])"#,
        );
        let text = b"\xef\xbb\xbfa.x,a.y,a.z,\r\n1,2,3,\r\n4,5,6,\r\n7,8,9\r\n\r\nEvents,Hit,2\r\n";
        let take = read(p(), text, &prof, None).unwrap();
        assert_eq!((take.rate_hz, take.frames), (50.0, 3));
        assert_eq!(take.tracks[0].positions[1], Some(DVec3::new(4.0, 5.0, 6.0)));
        assert_eq!(take.notes.len(), 1, "{:?}", take.notes);
        assert!(noted(
            &take,
            "the table ends at the blank line before line 6 (\"Events\")"
        ));
    }

    #[test]
    fn header_by_line_or_first_cell_and_whitespace_tables() {
        let text = b"Session 7 recorded 2024\n\nt  px py pz\n0.0 1 2 3\n0.5 1 2 3\n";
        for header in ["Line(3)", "StartsWith(\"T\")", "Auto"] {
            let prof = profile(&format!(
                r#"CaptureProfile(name: "w", header: {header}, time: Seconds("t"),
                   tracks: [Track(label: "p", position: ("px", "py", "pz"))])"#
            ));
            let take = read(p(), text, &prof, None).unwrap();
            assert_eq!((take.rate_hz, take.frames), (2.0, 2), "{header}");
        }
        let layout = inspect(p(), text, &profile(r#"CaptureProfile(name: "w")"#)).unwrap();
        assert_eq!(layout.delimiter, Delimiter::Whitespace);
        assert_eq!(layout.problems.len(), 1, "no tracks: {:?}", layout.problems);
    }

    #[test]
    fn frame_numbers_and_median_rates() {
        let frames = profile(
            r#"CaptureProfile(name: "f", time: Frame("f"), rate_key: "rate",
            patterns: [Pattern(position: ("{name}x", "{name}y", "{name}z"))])"#,
        );
        let text = b"rate,240\nf,ax,ay,az\n10,1,1,1\n11,1,1,1\n14,1,1,1\n";
        let take = read(p(), text, &frames, None).unwrap();
        assert_eq!((take.rate_hz, take.frames), (240.0, 5));
        assert!(
            noted(&take, "2 dropped frames were filled as gaps"),
            "{:?}",
            take.notes
        );
        let e = read_err(b"f,ax,ay,az\n10,1,1,1\n11,1,1,1\n12,1,1,1\n", &frames);
        assert!(e.contains("set `rate_hz`"), "{e}");
        // Times printed to the microsecond at 240 Hz, with one dropped frame.
        let times = profile(
            r#"CaptureProfile(name: "t", time: Seconds("t"),
            patterns: [Pattern(position: ("{name}x", "{name}y", "{name}z"))])"#,
        );
        let mut text = String::from("t,ax,ay,az\n");
        for k in (0..60).filter(|&k| k != 30) {
            text.push_str(&format!("{:.6},1,2,3\n", 12.5 + k as f64 / 240.0));
        }
        let take = read(p(), text.as_bytes(), &times, None).unwrap();
        assert_eq!((take.rate_hz, take.frames), (240.0, 60));
        assert_eq!(take.tracks[0].positions[30], None);
        assert!(
            noted(&take, "frame rate 240 Hz from the time column"),
            "{:?}",
            take.notes
        );
        let odd = b"t,ax,ay,az\n0,1,1,1\n0.0083,1,1,1\n0.0167,1,1,1\n0.025,1,1,1\n";
        assert_eq!(read(p(), odd, &times, None).unwrap().rate_hz, 120.0);
    }

    #[test]
    fn errors_name_the_line_column_and_nearest_names() {
        let prof = profile(
            r#"CaptureProfile(name: "e", time: Seconds("time"), rate_hz: 100,
            tracks: [Track(label: "R", position: ("StickR X", "StickR Y", "StickR Z"),
                           orientation: Quaternion(x: "qx", y: "qy", z: "qz", w: "qw"))])"#,
        );
        let head = "time,StickR X,StickR Y,StickR Z,qx,qy,qz,qw\n";
        let ok = "0,1,2,3,0,0,0,1\n0.01,1,2,3,0,0,0,1\n";
        let cases = [
            (
                format!("{head}{ok}0.02,1,abc,3,0,0,0,1\n"),
                "line 4, column 3 (\"StickR Y\"): expected a number, found \"abc\"",
            ),
            (
                format!("{head}{ok}0.01,1,2,3,0,0,0,1\n"),
                "line 4: expected a time after the previous row's 0.01 s",
            ),
            (
                format!("{head}{ok}0.005,1,2,3,0,0,0,1\n"),
                "line 4: expected a time after",
            ),
            (
                format!("{head}{ok}0.025,1,2,3,0,0,0,1\n"),
                "line 4: expected a time step of a whole number of frames at 100 Hz",
            ),
            (
                format!("{head}{ok},1,2,3,0,0,0,1\n"),
                "line 4, column 1 (\"time\"): expected a time",
            ),
            (
                format!("{head}{ok}0.02,1,2,3,0,0,0,3\n"),
                "line 4, column 5 (\"qx\"): expected a unit quaternion",
            ),
            (
                format!("{head}{ok}1e9,1,2,3,0,0,0,1\n"),
                "line 4: expected a continuous capture",
            ),
            (
                format!("{head}{ok}inf,1,2,3,0,0,0,1\n"),
                "expected a finite number",
            ),
            (
                format!("{}{ok}", head.replace("StickR Y", "Stick R-Y")),
                "header, line 1: track \"R\": expected a column named \"StickR Y\", found none (nearest: \"StickR X\", \"StickR Z\", \"Stick R-Y\")",
            ),
            ("title only\n".to_string(), "expected a block of data rows"),
            (head.to_string(), "expected a block of data rows"),
        ];
        for (text, want) in cases {
            let e = read_err(text.as_bytes(), &prof);
            assert!(e.contains(want), "want {want:?} in {e}");
        }
        let matrix = profile(
            r##"CaptureProfile(name: "m", rate_hz: 1, header_rows: 0, tracks: [Track(label: "b",
            position: ("#1", "#2", "#3"), orientation: Matrix(columns: ["#4","#5","#6","#7","#8","#9","#10","#11","#12"]))])"##,
        );
        let e = read_err(
            b"1,2,3,1,0,0,0,1,0,0,0,-1\n1,2,3,1,0,0,0,1,0,0,0,1\n1,2,3,1,0,0,0,1,0,0,0,1\n",
            &matrix,
        );
        assert!(
            e.contains("line 1, column 4: expected a rotation matrix"),
            "{e}"
        );
        let e = read_err(b"1,2,3\n1,2,3\n1,2,3\n", &matrix);
        assert!(
            e.contains("expected column 4 to exist, found only 3 columns"),
            "{e}"
        );
        let section = profile(
            r#"CaptureProfile(name: "s", section: "Trajectories", rate_hz: 1, patterns: [Pattern(position: ("{name} X", "+1", "+2"))])"#,
        );
        let e = read_err(b"Devices\n1,2\n", &section);
        assert!(e.contains("expected a line \"Trajectories\""), "{e}");
        let offset = profile(
            r##"CaptureProfile(name: "o", rate_hz: 1, header_rows: 0, tracks: [Track(label: "o", position: ("+1", "#2", "#3"))])"##,
        );
        let e = read_err(b"1,2,3\n1,2,3\n1,2,3\n", &offset);
        assert!(e.contains("for the first position column"), "{e}");
    }

    #[test]
    fn no_file_content_panics() {
        let profiles: Vec<CaptureProfile> = CaptureProfile::shipped_names()
            .iter()
            .map(|n| shipped(n))
            .collect();
        let mut inputs: Vec<Vec<u8>> = vec![
            Vec::new(),
            b"\n\n".to_vec(),
            b"\xff\xfe\x00".to_vec(),
            european(),
        ];
        for fixture in [MOTIVE, VICON, QTM_3D, QTM_6D, TRC, PLAIN] {
            for cut in [
                0,
                1,
                fixture.len() / 3,
                fixture.len() / 2,
                fixture.len() - 1,
            ] {
                inputs.push(fixture[..cut].to_vec());
            }
            let mut garbled = fixture.to_vec();
            let junk = b"0,\t;-\n9e9 x";
            for k in (0..garbled.len()).step_by(37) {
                garbled[k] = junk[k % junk.len()];
            }
            inputs.push(garbled);
        }
        for input in &inputs {
            for prof in &profiles {
                let _ = read(p(), input, prof, None);
                let _ = inspect(p(), input, prof);
            }
        }
    }
}
