//! OptiTrack Motive CSV export (format version 1.2x).
//!
//! # Layout
//!
//! ```text
//! Format Version,1.23,Take Name,…,Export Frame Rate,250.000000,…,Total Exported Frames,N,Rotation Type,Quaternion,Length Units,Meters,Coordinate Space,Global
//!
//! ,Type,Rigid Body,Rigid Body,…,Rigid Body Marker,…,Marker,…
//! ,Name,StickL,StickL,…,StickL:Marker1,…
//! ,ID,1,1,…
//! ,,Rotation,Rotation,Rotation,Rotation,Position,Position,Position,Mean Marker Error,Position,…
//! Frame,Time (Seconds),X,Y,Z,W,X,Y,Z,,X,Y,Z,…
//! 0,0.000000,0.01,0.02,…
//! ```
//!
//! * Line 1: key/value pairs. Used: `Export Frame Rate` (else `Capture Frame Rate`) for
//!   the rate, `Length Units` (`Meters`, `Centimeters`, `Millimeters`; metres if absent),
//!   `Rotation Type` (`Quaternion`, or Euler angles in degrees in one of the orders `XYZ`,
//!   `XZY`, `YXZ`, `YZX`, `ZXY`, `ZYX`: Motive's Euler angles are relative (intrinsic) and
//!   right-handed, so `XYZ` turns about X, then the new Y, then the new Z — R =
//!   Rx·Ry·Rz — with each angle in the column of its axis; NaturalPoint, "Changes in
//!   Motive's Reported Euler Angles", Motive 1.6 and later) and `Total Exported
//!   Frames` (checked against the rows, so a truncated export is caught).
//! * Header rows until the `Frame` row: `Type`, `Name`, optionally `ID` (told apart by
//!   their second cell, or by order when it is empty), and the Rotation/Position row.
//!   Columns are grouped by consecutive equal type, name and ID.
//! * `Rigid Body` (and skeleton `Bone`) columns give a track with positions and
//!   rotations (quaternion X, Y, Z, W, normalised); `Marker`, `Rigid Body Marker` and
//!   `Bone Marker` columns give position-only tracks. Other types and columns (`Mean
//!   Marker Error`, `Marker Quality`) are ignored. Tracks are labelled by name; a rigid
//!   body marker (the solved position) whose name is also a measured marker's gets the
//!   label `<name> (solved)`, and any other repeated label gets ` (2)`, ` (3)`, ….
//! * Data rows: frame, time in seconds, then values; an empty cell is a missing sample,
//!   and so is a position or rotation with a cell written `NaN` (counted in a note).
//!   The time step must match the rate to 1 %.
//! * Blank lines (nothing, or only commas and spaces) between data rows, as hand-edited or
//!   concatenated exports have, are skipped and named in a note; the rows after them must
//!   still run on in time. Blank lines at the end are ignored.

use super::LengthUnit;
use super::csv_text::{self, Row};
use super::plain_csv::quaternion;
use crate::mocap::take::{ImportError, MarkedGaps, Take, Track};
use std::path::Path;

/// What a group of columns is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    RigidBody,
    SolvedMarker,
    Marker,
}

/// One track's columns (0-based cell indices).
struct Entity {
    kind: Kind,
    label: String,
    /// Column of the type cell, for errors.
    first_col: usize,
    position: [Option<usize>; 3],
    rotation: [Option<usize>; 4],
}

/// What line 1's key/value pairs say.
struct Meta<'r> {
    /// The line's number (for errors).
    line: usize,
    /// Frame rate, Hz.
    rate_hz: f64,
    /// Length unit of the positions.
    unit: LengthUnit,
    /// `Rotation Type`: the value's column and text.
    rotation_type: Option<(usize, &'r str)>,
    /// The axes of an Euler rotation type, in order (0 = X); `None` for quaternions.
    euler: Option<[usize; 3]>,
    /// `Total Exported Frames`, when given.
    total_frames: Option<usize>,
}

/// The header rows above the `Frame` row, told apart.
struct HeaderRows<'r, 'a> {
    ty: &'r Row<'a>,
    name: &'r Row<'a>,
    id: Option<&'r Row<'a>>,
    kind: &'r Row<'a>,
}

/// Read a Motive CSV export; `unit` overrides `Length Units`.
pub fn read(path: &Path, bytes: &[u8], unit: Option<LengthUnit>) -> Result<Take, ImportError> {
    let text = csv_text::decode(bytes);
    let mut rows = csv_text::rows(&text);
    let first = rows.next().ok_or_else(|| {
        ImportError::format(
            path,
            "line 1",
            "expected \"Format Version,…\", found an empty file",
        )
    })?;
    let meta = read_meta(path, &first, unit)?;
    let (header, frame_row) = header_rows(path, &mut rows)?;
    let head = classify_header(path, &header, &frame_row)?;
    let width = frame_row
        .used_width()
        .max(header.iter().map(Row::used_width).max().unwrap_or(0));
    let entities = group_columns(path, &head, &frame_row, width)?;
    check_entities(path, &entities, &head, &meta)?;
    let data = read_data(path, rows, &entities, width, &meta, frame_row.line)?;
    let frames = data.frames;
    if let Some(n) = meta.total_frames.filter(|&n| n != frames) {
        return Err(ImportError::format(
            path,
            "line 1",
            format!(
                "expected {n} data rows as \"Total Exported Frames\" says, found {frames}: the \
                 export is truncated or was edited"
            ),
        ));
    }
    let mut take = Take {
        source: path.to_path_buf(),
        rate_hz: meta.rate_hz,
        frames,
        file_unit: meta.unit.symbol().to_string(),
        tracks: data.tracks,
        notes: data.blanks.note("the data").into_iter().collect(),
    };
    take.zeros_as_gaps(data.gaps);
    Ok(take)
}

/// Read line 1, `Format Version,…` and key/value pairs: the rate, the length unit
/// (`unit` overrides it), the rotation type and the frame count.
fn read_meta<'r>(
    path: &Path,
    first: &'r Row,
    unit: Option<LengthUnit>,
) -> Result<Meta<'r>, ImportError> {
    let err =
        |col: usize, msg: String| ImportError::format(path, csv_text::place(first.line, col), msg);
    if !first.cell(0).eq_ignore_ascii_case("Format Version") {
        return Err(err(
            0,
            format!(
                "expected \"Format Version\" (a Motive CSV export), found \"{}\"",
                csv_text::shorten(first.cell(0))
            ),
        ));
    }
    let meta = |key: &str| -> Option<(usize, &'r str)> {
        (0..first.cells.len())
            .step_by(2)
            .find(|&c| first.cell(c).eq_ignore_ascii_case(key))
            .map(|c| (c + 1, first.cell(c + 1)))
    };
    let (rate_col, rate_text) = meta("Export Frame Rate")
        .or_else(|| meta("Capture Frame Rate"))
        .ok_or_else(|| {
            ImportError::format(
                path,
                "line 1",
                "expected an \"Export Frame Rate\" or \"Capture Frame Rate\" entry, found neither",
            )
        })?;
    let rate_hz = match rate_text.parse::<f64>() {
        Ok(r) if r.is_finite() && r > 0.0 => r,
        _ => {
            return Err(err(
                rate_col,
                format!(
                    "expected a frame rate above 0 Hz, found \"{}\"",
                    csv_text::shorten(rate_text)
                ),
            ));
        }
    };
    let unit = match (unit, meta("Length Units")) {
        (Some(u), _) => u,
        (None, None) => LengthUnit::Metre,
        (None, Some((col, name))) => LengthUnit::parse(name).ok_or_else(|| {
            err(
                col,
                format!(
                    "expected Length Units Meters, Centimeters or Millimeters, found \"{}\"",
                    csv_text::shorten(name)
                ),
            )
        })?,
    };
    let total_frames = match meta("Total Exported Frames") {
        Some((col, t)) if !t.is_empty() => Some(t.parse::<usize>().map_err(|_| {
            err(
                col,
                format!("expected a frame count, found \"{}\"", csv_text::shorten(t)),
            )
        })?),
        _ => None,
    };
    let mut meta = Meta {
        line: first.line,
        rate_hz,
        unit,
        rotation_type: meta("Rotation Type"),
        euler: None,
        total_frames,
    };
    meta.euler = euler_order(path, &meta)?;
    Ok(meta)
}

/// The header rows between line 1 and the `Frame` row (blank lines before them
/// skipped), and the `Frame` row itself.
fn header_rows<'a>(
    path: &Path,
    rows: &mut impl Iterator<Item = Row<'a>>,
) -> Result<(Vec<Row<'a>>, Row<'a>), ImportError> {
    let mut header: Vec<Row> = Vec::new();
    loop {
        let Some(row) = rows.next() else {
            return Err(ImportError::format(
                path,
                "end of file",
                "expected the column header row \"Frame,Time (Seconds),X,Y,Z,…\", found the end \
                 of the file",
            ));
        };
        if row.cell(0).eq_ignore_ascii_case("Frame") {
            return Ok((header, row));
        }
        if row.is_blank() {
            if header.is_empty() {
                continue;
            }
            return Err(ImportError::format(
                path,
                format!("line {}", row.line),
                "expected a header row (Type, Name, ID, Rotation/Position) or the \"Frame\" \
                 row, found a blank line",
            ));
        }
        if header.len() >= 6 {
            return Err(ImportError::format(
                path,
                format!("line {}", row.line),
                "expected the \"Frame,Time (Seconds),…\" row after at most 5 header rows",
            ));
        }
        header.push(row);
    }
}

/// Group the columns into tracks by consecutive equal type, name and ID, and find each
/// track's Position and Rotation X, Y, Z (W) columns.
fn group_columns(
    path: &Path,
    rows: &HeaderRows,
    frame_row: &Row,
    width: usize,
) -> Result<Vec<Entity>, ImportError> {
    let mut entities: Vec<Entity> = Vec::new();
    let mut prev_key: Option<(String, String, String)> = None;
    for col in 2..width {
        let ty = rows.ty.cell(col);
        let key = (
            ty.to_string(),
            rows.name.cell(col).to_string(),
            rows.id.map_or("", |r| r.cell(col)).to_string(),
        );
        let new = prev_key.as_ref() != Some(&key);
        prev_key = Some(key);
        let kind = match ty.to_ascii_lowercase().as_str() {
            "rigid body" | "bone" => Kind::RigidBody,
            "rigid body marker" | "bone marker" => Kind::SolvedMarker,
            "marker" => Kind::Marker,
            _ => continue,
        };
        if new {
            entities.push(Entity {
                kind,
                label: rows.name.cell(col).to_string(),
                first_col: col,
                position: [None; 3],
                rotation: [None; 4],
            });
        }
        let Some(e) = entities.last_mut() else {
            continue;
        };
        let axis = frame_row.cell(col).to_ascii_uppercase();
        let part = rows.kind.cell(col);
        let slot = match (part.to_ascii_lowercase().as_str(), axis.as_str()) {
            ("position", "X") => &mut e.position[0],
            ("position", "Y") => &mut e.position[1],
            ("position", "Z") => &mut e.position[2],
            ("rotation", "X") if kind == Kind::RigidBody => &mut e.rotation[0],
            ("rotation", "Y") if kind == Kind::RigidBody => &mut e.rotation[1],
            ("rotation", "Z") if kind == Kind::RigidBody => &mut e.rotation[2],
            ("rotation", "W") if kind == Kind::RigidBody => &mut e.rotation[3],
            _ => continue,
        };
        if slot.is_some() {
            return Err(ImportError::format(
                path,
                csv_text::place(frame_row.line, col),
                format!(
                    "expected one {part} {axis} column for \"{}\", found a second",
                    e.label
                ),
            ));
        }
        *slot = Some(col);
    }
    Ok(entities)
}

/// Check that every track has all three position columns and, if it has rotation
/// columns, all of them: four for quaternions, three for Euler angles.
fn check_entities(
    path: &Path,
    entities: &[Entity],
    rows: &HeaderRows,
    meta: &Meta,
) -> Result<(), ImportError> {
    for e in entities {
        if e.position.iter().any(Option::is_none) {
            return Err(ImportError::format(
                path,
                csv_text::place(rows.ty.line, e.first_col),
                format!(
                    "expected Position X, Y and Z columns for \"{}\", found only some or none",
                    e.label
                ),
            ));
        }
        let rot = e.rotation.iter().filter(|c| c.is_some()).count();
        if rot > 0 {
            let euler = euler_order(path, meta)?;
            let (want, names) = match euler {
                Some(_) => (3, "X, Y and Z"),
                None => (4, "X, Y, Z and W"),
            };
            if rot != want || (euler.is_some() && e.rotation[3].is_some()) {
                return Err(ImportError::format(
                    path,
                    csv_text::place(rows.kind.line, e.first_col),
                    format!(
                        "expected Rotation {names} columns for \"{}\" (Rotation Type {}), found {rot} of them",
                        e.label,
                        meta.rotation_type.map_or("Quaternion", |(_, t)| t)
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// The Euler order the `Rotation Type` names (`None`: quaternions, also when absent), or
/// an error naming the place for a type Motive does not write.
fn euler_order(path: &Path, meta: &Meta) -> Result<Option<[usize; 3]>, ImportError> {
    let Some((col, text)) = meta.rotation_type else {
        return Ok(None);
    };
    if text.eq_ignore_ascii_case("Quaternion") {
        return Ok(None);
    }
    let axes: Vec<usize> = text
        .to_ascii_uppercase()
        .chars()
        .filter_map(|c| "XYZ".find(c))
        .collect();
    match axes[..] {
        [a, b, c] if text.len() == 3 && a != b && b != c && a != c => Ok(Some([a, b, c])),
        _ => Err(ImportError::format(
            path,
            csv_text::place(meta.line, col),
            format!(
                "expected Rotation Type Quaternion, XYZ, XZY, YXZ, YZX, ZXY or ZYX, found \"{}\"",
                csv_text::shorten(text)
            ),
        )),
    }
}

/// The rotation of Motive's relative (intrinsic) Euler angles: about the first axis of
/// `order`, then the new second, then the new third; `degrees` holds the X, Y and Z
/// angles.
fn intrinsic(order: [usize; 3], degrees: glam::DVec3) -> glam::DQuat {
    let axis = |i: usize| [glam::DVec3::X, glam::DVec3::Y, glam::DVec3::Z][i];
    order
        .iter()
        .map(|&i| glam::DQuat::from_axis_angle(axis(i), degrees[i].to_radians()))
        .fold(glam::DQuat::IDENTITY, |q, r| q * r)
        .normalize()
}

/// The data rows as read.
struct Data {
    /// One track per entity.
    tracks: Vec<Track>,
    /// The number of frames (1 or more).
    frames: usize,
    /// The positions written as NaN.
    gaps: MarkedGaps,
    /// The blank lines skipped.
    blanks: csv_text::BlankLines,
}

/// Read the data rows after the `Frame` row (line `frame_line`) into one track per
/// entity, checking the time step against the rate, counting the positions written as
/// NaN and the blank lines skipped.
fn read_data<'a>(
    path: &'a Path,
    rows: impl Iterator<Item = Row<'a>> + 'a,
    entities: &[Entity],
    width: usize,
    meta: &Meta,
    frame_line: usize,
) -> Result<Data, ImportError> {
    let labels = unique_labels(entities);
    let mut tracks: Vec<Track> = entities
        .iter()
        .zip(labels)
        .map(|(_, label)| Track::empty(label))
        .collect();
    let mut gaps = MarkedGaps::default();
    let mut blanks = csv_text::BlankLines::default();
    let (rate_hz, scale) = (meta.rate_hz, meta.unit.metres());
    let step = 1.0 / rate_hz;
    let mut prev_time: Option<f64> = None;
    let mut frames = 0usize;
    for row in rows {
        if !blanks.is_data(&row) {
            continue;
        }
        csv_text::check_width(path, &row, width)?;
        csv_text::required_number(path, &row, 0, "frame number")?;
        let t = csv_text::required_number(path, &row, 1, "time in seconds")?;
        if let Some(p) = prev_time {
            let d = t - p;
            if (d - step).abs() > 0.01 * step + 2e-6 {
                return Err(ImportError::format(
                    path,
                    csv_text::place(row.line, 1),
                    format!(
                        "expected a time step of {step:.6} s (the export frame rate \
                         {rate_hz} Hz), found {d:.6} s from the previous row{}",
                        csv_text::not_run_on(blanks.run_before(row.line))
                    ),
                ));
            }
        }
        prev_time = Some(t);
        for (e, track) in entities.iter().zip(tracks.iter_mut()) {
            let [Some(x), Some(y), Some(z)] = e.position else {
                continue;
            };
            track
                .positions
                .push(csv_text::sample(path, &row, [x, y, z], scale, &mut gaps)?);
            match (e.rotation, meta.euler) {
                ([Some(qx), Some(qy), Some(qz), Some(qw)], None) => track
                    .rotations
                    .push(quaternion(path, &row, [qx, qy, qz, qw])?),
                ([Some(rx), Some(ry), Some(rz), None], Some(order)) => {
                    let degrees = csv_text::position(path, &row, [rx, ry, rz], 1.0)?;
                    track.rotations.push(degrees.map(|a| intrinsic(order, a)));
                }
                _ => {}
            }
        }
        frames += 1;
    }
    if frames == 0 {
        return Err(ImportError::format(
            path,
            format!("line {}", frame_line + 1),
            "expected data rows after the \"Frame\" row, found none",
        ));
    }
    Ok(Data {
        tracks,
        frames,
        gaps,
        blanks,
    })
}

/// Tell the header rows apart: (Type, Name, ID if present, Rotation/Position).
fn classify_header<'r, 'a>(
    path: &Path,
    header: &'r [Row<'a>],
    frame_row: &Row,
) -> Result<HeaderRows<'r, 'a>, ImportError> {
    let tag = |r: &Row| -> String {
        let t = if r.cell(0).is_empty() {
            r.cell(1)
        } else {
            r.cell(0)
        };
        t.to_ascii_lowercase()
    };
    let is_kind_row = |r: &Row| {
        (2..r.cells.len()).any(|c| {
            let v = r.cell(c);
            v.eq_ignore_ascii_case("Position") || v.eq_ignore_ascii_case("Rotation")
        })
    };
    let (mut ty, mut name, mut id, mut kind) = (None, None, None, None);
    let mut untagged = Vec::new();
    for r in header {
        match tag(r).as_str() {
            "type" => ty = Some(r),
            "name" => name = Some(r),
            "id" => id = Some(r),
            _ if is_kind_row(r) => kind = Some(r),
            _ => untagged.push(r),
        }
    }
    for r in untagged {
        if ty.is_none() {
            ty = Some(r);
        } else if name.is_none() {
            name = Some(r);
        } else if id.is_none() {
            id = Some(r);
        }
    }
    let missing = |what: &str| {
        ImportError::format(
            path,
            format!("line {}", frame_row.line),
            format!("expected a {what} row above the \"Frame\" row, found none"),
        )
    };
    Ok(HeaderRows {
        ty: ty.ok_or_else(|| missing("Type"))?,
        name: name.ok_or_else(|| missing("Name"))?,
        id,
        kind: kind.ok_or_else(|| missing("Rotation/Position"))?,
    })
}

/// Labels without repeats: a solved rigid-body marker sharing a measured marker's name
/// gets " (solved)"; any other repeat gets " (2)", " (3)", ….
fn unique_labels(entities: &[Entity]) -> Vec<String> {
    let mut out: Vec<String> = Vec::with_capacity(entities.len());
    for e in entities {
        let mut label = e.label.clone();
        if e.kind == Kind::SolvedMarker
            && entities
                .iter()
                .any(|o| o.kind == Kind::Marker && o.label == e.label)
        {
            label = format!("{label} (solved)");
        }
        if out.contains(&label) {
            let base = label.clone();
            let mut n = 2;
            while out.contains(&label) {
                label = format!("{base} ({n})");
                n += 1;
            }
        }
        out.push(label);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DQuat;

    const HEAD: &str = "Format Version,1.23,Take Name,t,Export Frame Rate,100.000000,Total Exported Frames,2,Rotation Type,Quaternion,Length Units,Millimeters\n\n";

    fn p() -> &'static Path {
        Path::new("m.csv")
    }

    #[test]
    fn brief_style_header_without_id_row() {
        let text = format!(
            "{HEAD},,Rigid Body,Rigid Body,Rigid Body,Rigid Body,Rigid Body,Rigid Body,Rigid Body,Marker,Marker,Marker\n\
             ,,A,A,A,A,A,A,A,A,A,A\n\
             ,,Rotation,Rotation,Rotation,Rotation,Position,Position,Position,Position,Position,Position\n\
             Frame,Time (Seconds),X,Y,Z,W,X,Y,Z,X,Y,Z\n\
             0,0.000000,0,0,0,1,1000,0,0,,,\n\
             1,0.010000,,,,,,,,1,2,3,\n"
        );
        let take = read(p(), text.as_bytes(), None).unwrap();
        assert_eq!(take.labels(), vec!["A", "A (2)"]);
        assert_eq!(take.file_unit, "mm");
        assert_eq!(take.tracks[0].positions[0], Some(glam::DVec3::X));
        assert_eq!(
            take.tracks[0].rotations,
            vec![Some(glam::DQuat::IDENTITY), None]
        );
        assert!(take.tracks[1].rotations.is_empty());
        assert_eq!(take.tracks[1].positions[0], None);
    }

    /// Euler rotation types: relative (intrinsic) angles in degrees, each in its axis's
    /// column, composed in the named order.
    #[test]
    fn euler_rotation_types() {
        let body = ",Type,Rigid Body,Rigid Body,Rigid Body,Rigid Body,Rigid Body,Rigid Body\n\
                    ,Name,A,A,A,A,A,A\n\
                    ,,Rotation,Rotation,Rotation,Position,Position,Position\n\
                    Frame,Time (Seconds),X,Y,Z,X,Y,Z\n\
                    0,0,30,-20,90,1,2,3\n1,0.01,,,,,,\n";
        let (x, y, z) = (
            30f64.to_radians(),
            (-20f64).to_radians(),
            90f64.to_radians(),
        );
        for (order, want) in [
            (
                "XYZ",
                DQuat::from_rotation_x(x) * DQuat::from_rotation_y(y) * DQuat::from_rotation_z(z),
            ),
            (
                "ZYX",
                DQuat::from_rotation_z(z) * DQuat::from_rotation_y(y) * DQuat::from_rotation_x(x),
            ),
            (
                "YZX",
                DQuat::from_rotation_y(y) * DQuat::from_rotation_z(z) * DQuat::from_rotation_x(x),
            ),
        ] {
            let text = format!("{}{body}", HEAD.replace("Quaternion", order));
            let take = read(p(), text.as_bytes(), None).unwrap();
            let q = take.tracks[0].rotations[0].unwrap();
            assert!(q.dot(want).abs() > 1.0 - 1e-12, "{order}: {q} vs {want}");
            assert_eq!(take.tracks[0].rotations[1], None, "a gap stays a gap");
        }
    }

    /// Blank lines between data rows are skipped and named, CRLF or not; a blank line
    /// after the `Frame` row or at the end is not named.
    #[test]
    fn blank_lines_inside_the_data_are_skipped_and_named() {
        let body = ",Type,Rigid Body,Rigid Body,Rigid Body,Rigid Body,Rigid Body,Rigid Body,Rigid Body,Marker,Marker,Marker\n\
                    ,Name,A,A,A,A,A,A,A,B,B,B\n\
                    ,,Rotation,Rotation,Rotation,Rotation,Position,Position,Position,Position,Position,Position\n\
                    Frame,Time (Seconds),X,Y,Z,W,X,Y,Z,X,Y,Z\n";
        let rows = "0,0.000000,0,0,0,1,1,2,3,,,\n,,,,,,,,,,,\n\n1,0.010000,0,0,0,1,4,5,6,7,8,9\n\n";
        let text = format!("{HEAD}{body}{rows}");
        let after_frame_row =
            format!("{HEAD}{body}\n0,0,0,0,0,1,1,2,3,,,\n1,0.01,0,0,0,1,4,5,6,7,8,9\n");
        for text in [text.clone(), text.replace('\n', "\r\n")] {
            let take = read(p(), text.as_bytes(), None).unwrap();
            assert_eq!(take.frames, 2);
            assert_eq!(
                take.tracks[0].positions[1],
                Some(glam::DVec3::new(0.004, 0.005, 0.006))
            );
            assert_eq!(take.tracks[1].positions[0], None);
            assert_eq!(
                take.notes,
                [
                    "2 blank lines inside the data were skipped (lines 8, 9): the rows after them \
                  continue the frames above"
                ]
            );
        }
        let take = read(p(), after_frame_row.as_bytes(), None).unwrap();
        assert_eq!(take.frames, 2);
        assert!(take.notes.is_empty(), "{:?}", take.notes);
    }

    #[test]
    fn errors() {
        let body = ",Type,Rigid Body,Rigid Body,Rigid Body,Rigid Body,Rigid Body,Rigid Body,Rigid Body\n\
                    ,Name,A,A,A,A,A,A,A\n\
                    ,,Rotation,Rotation,Rotation,Rotation,Position,Position,Position\n\
                    Frame,Time (Seconds),X,Y,Z,W,X,Y,Z\n";
        let ok_rows = "0,0,0,0,0,1,1,2,3\n1,0.01,0,0,0,1,1,2,3\n";
        let cases = [
            (format!("Format,1\n\n{body}{ok_rows}"), "line 1, column 1"),
            (
                format!("{}{body}{ok_rows}", HEAD.replace("Quaternion", "Matrix")),
                "line 1, column 10: expected Rotation Type Quaternion, XYZ",
            ),
            (
                format!("{}{body}{ok_rows}", HEAD.replace("Quaternion", "XYZ")),
                "expected Rotation X, Y and Z columns for \"A\" (Rotation Type XYZ), found 4",
            ),
            (
                format!("{}{body}{ok_rows}", HEAD.replace("Millimeters", "Inches")),
                "line 1, column 12",
            ),
            (
                format!("{}{body}{ok_rows}", HEAD.replace("100.000000", "fast")),
                "line 1, column 6",
            ),
            (
                format!("{HEAD}{body}0,0,0,0,0,1,1,2,3\n"),
                "Total Exported Frames",
            ),
            (
                format!("{HEAD}{body}0,0,0,0,0,1,1,2,3\n1,0.02,0,0,0,1,1,2,3\n"),
                "line 8, column 2: expected a time step",
            ),
            (
                format!("{HEAD}{body}0,0,0,0,0,1,1,2,3\n1,0.01,0,0,0,1,1,x,3\n"),
                "line 8, column 8: expected a number, found \"x\"",
            ),
            (
                format!("{HEAD}{body}0,0,0,0,0,1,1,2,3\n1,0.01,0,0,0,1,1\n"),
                "line 8: expected 9 cells",
            ),
            (
                format!("{HEAD}{body}0,0,0,0,0,2.5,1,2,3\n1,0.01,0,0,0,1,1,2,3\n"),
                "line 7, column 3: expected a unit quaternion",
            ),
            (format!("{HEAD}{body}"), "line 7: expected data rows"),
            (
                format!("{HEAD},Type,Marker\n"),
                "expected the column header row",
            ),
            (
                format!("{HEAD},Type,Marker,Marker\nFrame,Time,X,Y\n"),
                "expected a Name row",
            ),
        ];
        for (text, want) in cases {
            let e = read(p(), text.as_bytes(), None).unwrap_err().to_string();
            assert!(e.contains(want), "want {want:?} in {e}");
        }
    }
}
