//! Vicon Nexus CSV export: the `Trajectories` section.
//!
//! # Layout
//!
//! ```text
//! Devices                      ← optional sections before (skipped)
//! …
//!
//! Trajectories
//! 100                          ← frame rate, Hz
//! ,,Subject:LASI,,,Subject:RASI,,,
//! Frame,Sub Frame,X,Y,Z,X,Y,Z
//! ,,mm,mm,mm,mm,mm,mm          ← units (mm if the row is absent)
//! 1,0,123.4,-56.7,890.1,,,     ← empty cells (or NaN): marker not seen
//! …
//!                              ← a blank line before the next section ends it
//! Model Outputs
//! …
//! ```
//!
//! Each label's columns run up to the next label; of them, the ones headed exactly `X`,
//! `Y`, `Z` are its position (velocity and acceleration columns `X'`, `X''` are ignored).
//! Units may be `mm`, `cm` or `m` per trajectory. Frame numbers must rise by one per row.
//!
//! The data end at the next section's name, at a blank line followed by it, or at the
//! end of the file. Blank lines followed by more data rows (the frame numbers running on)
//! are skipped with a note; a blank line followed by anything else that is not a number
//! ends the data with a note naming the line where the unread rest begins.

use super::LengthUnit;
use super::csv_text::{self, Row};
use crate::mocap::take::{ImportError, MarkedGaps, Take, Track};
use std::path::Path;

/// Section names a Nexus CSV export uses.
const SECTIONS: [&str; 6] = [
    "Trajectories",
    "Devices",
    "Joints",
    "Model Outputs",
    "Segments",
    "Events",
];

/// True for a Nexus CSV section name (case-insensitive).
pub fn is_section_name(s: &str) -> bool {
    SECTIONS.iter().any(|n| n.eq_ignore_ascii_case(s.trim()))
}

/// One trajectory's columns.
struct Columns {
    label: String,
    xyz: [usize; 3],
}

/// How the data rows are laid out: each trajectory's columns and unit, the row width.
struct Layout<'c> {
    columns: &'c [Columns],
    scales: &'c [LengthUnit],
    width: usize,
}

/// The Trajectories data as read.
struct Data {
    /// One track per trajectory, positions in metres.
    tracks: Vec<Track>,
    /// The number of frames (1 or more).
    frames: usize,
    /// What was skipped, or where the data ended early.
    notes: Vec<String>,
    /// The samples written as NaN.
    gaps: MarkedGaps,
}

/// Read the `Trajectories` section of a Vicon Nexus CSV export; `unit` overrides the
/// units row.
pub fn read(path: &Path, bytes: &[u8], unit: Option<LengthUnit>) -> Result<Take, ImportError> {
    let text = csv_text::decode(bytes);
    let mut rows = csv_text::rows(&text);
    let line = find_section(&mut rows).ok_or_else(|| {
        ImportError::format(
            path,
            "whole file",
            "expected a \"Trajectories\" section (a Vicon Nexus CSV export), found none",
        )
    })?;
    let rate_row = next_row(
        path,
        &mut rows,
        "the frame rate after \"Trajectories\"",
        line,
    )?;
    let rate_hz = frame_rate(path, &rate_row)?;
    let label_row = next_row(path, &mut rows, "the trajectory label row", rate_row.line)?;
    let axis_row = next_row(
        path,
        &mut rows,
        "the row \"Frame,Sub Frame,X,Y,Z,…\"",
        label_row.line,
    )?;
    if !axis_row.cell(0).eq_ignore_ascii_case("Frame") {
        return Err(ImportError::format(
            path,
            csv_text::place(axis_row.line, 0),
            format!(
                "expected \"Frame\" (the row \"Frame,Sub Frame,X,Y,Z,…\"), found \"{}\"",
                csv_text::shorten(axis_row.cell(0))
            ),
        ));
    }
    let width = axis_row.used_width().max(label_row.used_width());
    let columns = trajectory_columns(path, &label_row, &axis_row, width)?;

    // Units row (optional), then data.
    let mut pending: Option<Row> = None;
    let mut scales = vec![LengthUnit::Millimetre; columns.len()];
    if let Some(row) = rows.next() {
        if row.cell(0).is_empty() && !row.is_blank() {
            read_units(path, &row, &columns, unit.is_some(), &mut scales)?;
        } else {
            pending = Some(row);
        }
    }
    if let Some(u) = unit {
        scales.iter_mut().for_each(|s| *s = u);
    }
    let file_unit = scales
        .first()
        .copied()
        .or(unit)
        .unwrap_or(LengthUnit::Millimetre);
    let data = pending.into_iter().chain(rows);
    let layout = Layout {
        columns: &columns,
        scales: &scales,
        width,
    };
    let data = read_data(path, data, &layout, axis_row.line)?;
    let mut take = Take {
        source: path.to_path_buf(),
        rate_hz,
        frames: data.frames,
        file_unit: file_unit.symbol().to_string(),
        tracks: data.tracks,
        notes: data.notes,
    };
    take.zeros_as_gaps(data.gaps);
    Ok(take)
}

/// The next row, or an error saying `what` was expected after line `after`.
fn next_row<'a>(
    path: &Path,
    rows: &mut impl Iterator<Item = Row<'a>>,
    what: &str,
    after: usize,
) -> Result<Row<'a>, ImportError> {
    rows.next().ok_or_else(|| {
        ImportError::format(
            path,
            format!("line {}", after + 1),
            format!("expected {what}, found the end of the file"),
        )
    })
}

/// Skip to the `Trajectories` section's name row (the name alone on its line); its line
/// number, or `None` at the end of the file.
fn find_section<'a>(rows: &mut impl Iterator<Item = Row<'a>>) -> Option<usize> {
    rows.find(|row| row.cell(0).eq_ignore_ascii_case("Trajectories") && row.used_width() == 1)
        .map(|row| row.line)
}

/// The frame rate in the row after the section name, Hz (above 0).
fn frame_rate(path: &Path, rate_row: &Row) -> Result<f64, ImportError> {
    match csv_text::number(path, rate_row, 0)? {
        Some(r) if r > 0.0 => Ok(r),
        other => Err(ImportError::format(
            path,
            csv_text::place(rate_row.line, 0),
            format!(
                "expected the frame rate in Hz, found {}",
                other.map_or("an empty cell".to_string(), |r| r.to_string())
            ),
        )),
    }
}

/// Each trajectory's label and X, Y, Z columns: a label's columns run up to the next
/// label, and of them the ones headed exactly `X`, `Y`, `Z` are its position.
fn trajectory_columns(
    path: &Path,
    label_row: &Row,
    axis_row: &Row,
    width: usize,
) -> Result<Vec<Columns>, ImportError> {
    let label_cols: Vec<usize> = (2..width)
        .filter(|&c| !label_row.cell(c).is_empty())
        .collect();
    let mut columns = Vec::with_capacity(label_cols.len());
    for (i, &c) in label_cols.iter().enumerate() {
        let end = label_cols.get(i + 1).copied().unwrap_or(width);
        let find = |axis: &str| (c..end).find(|&k| axis_row.cell(k).eq_ignore_ascii_case(axis));
        let (Some(x), Some(y), Some(z)) = (find("X"), find("Y"), find("Z")) else {
            return Err(ImportError::format(
                path,
                csv_text::place(label_row.line, c),
                format!(
                    "expected X, Y and Z columns under \"{}\" (line {}), found only some or none",
                    label_row.cell(c),
                    axis_row.line
                ),
            ));
        };
        columns.push(Columns {
            label: label_row.cell(c).to_string(),
            xyz: [x, y, z],
        });
    }
    Ok(columns)
}

/// Read the units row into `scales`, one unit per trajectory (the same for its X, Y and
/// Z); with `overridden` (a unit override given) unreadable units are let pass.
fn read_units(
    path: &Path,
    row: &Row,
    columns: &[Columns],
    overridden: bool,
    scales: &mut [LengthUnit],
) -> Result<(), ImportError> {
    for (c, s) in columns.iter().zip(scales.iter_mut()) {
        let cells = c.xyz.map(|k| row.cell(k));
        let parsed = cells.map(LengthUnit::parse);
        match parsed {
            [Some(a), Some(b), Some(d)] if a == b && b == d => *s = a,
            _ if overridden => {}
            _ => {
                return Err(ImportError::format(
                    path,
                    csv_text::place(row.line, c.xyz[0]),
                    format!(
                        "expected the same unit mm, cm or m for X, Y and Z of \"{}\", found \
                         \"{}\", \"{}\", \"{}\" (give a unit override if the data are in one of \
                         these)",
                        c.label, cells[0], cells[1], cells[2]
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// Read the data rows into one track per trajectory, up to the next section's name (with
/// or without a blank line before it) or the end of the file. Blank lines followed by
/// more data rows are skipped (noted); a blank line followed by a row that is neither a
/// section name nor a number ends the data (noted, naming the line). Frame numbers must
/// rise by one per row, across skipped blank lines too; `axis_line` is the line of the
/// `Frame` row.
fn read_data<'a>(
    path: &Path,
    rows: impl Iterator<Item = Row<'a>>,
    layout: &Layout,
    axis_line: usize,
) -> Result<Data, ImportError> {
    let mut data = Data {
        tracks: layout
            .columns
            .iter()
            .map(|c| Track::empty(c.label.clone()))
            .collect(),
        frames: 0,
        notes: Vec::new(),
        gaps: MarkedGaps::default(),
    };
    let mut prev_frame: Option<f64> = None;
    let mut blanks = csv_text::BlankLines::default();
    let mut last_line = axis_line;
    for row in rows {
        last_line = row.line;
        if blanks.skip(&row) {
            continue;
        }
        if is_section_name(row.cell(0)) {
            break;
        }
        if let Some(blank) = blanks.pending()
            && !csv_text::is_number(row.cell(0))
        {
            data.notes.push(unread_rest(blank, &row));
            break;
        }
        blanks.data_row(row.line);
        let after_blank = blanks.run_before(row.line);
        let frame = frame_number(path, &row, layout.width, prev_frame, after_blank)?;
        prev_frame = Some(frame);
        read_row(path, &row, layout, &mut data.tracks, &mut data.gaps)?;
        data.frames += 1;
    }
    if data.frames == 0 {
        return Err(ImportError::format(
            path,
            format!("line {}", last_line),
            "expected data rows in the Trajectories section, found none",
        ));
    }
    data.notes.extend(blanks.note("the Trajectories data"));
    Ok(data)
}

/// A data row's frame number, checked against the row width and the previous frame
/// (`prev`: it must be one more); `blank`: the first of the blank lines just before it,
/// for the message when a block after blank lines does not run on.
fn frame_number(
    path: &Path,
    row: &Row,
    width: usize,
    prev: Option<f64>,
    blank: Option<usize>,
) -> Result<f64, ImportError> {
    csv_text::check_width(path, row, width)?;
    let frame = csv_text::required_number(path, row, 0, "frame number")?;
    if let Some(p) = prev
        && frame != p + 1.0
    {
        return Err(ImportError::format(
            path,
            csv_text::place(row.line, 0),
            format!(
                "expected frame {} after frame {p} (one row per frame), found {frame}{}",
                p + 1.0,
                csv_text::not_run_on(blank)
            ),
        ));
    }
    Ok(frame)
}

/// Append one data row's position of every trajectory to `tracks`, counting those
/// written as NaN in `gaps`.
fn read_row(
    path: &Path,
    row: &Row,
    layout: &Layout,
    tracks: &mut [Track],
    gaps: &mut MarkedGaps,
) -> Result<(), ImportError> {
    for ((c, track), s) in layout.columns.iter().zip(tracks).zip(layout.scales) {
        track
            .positions
            .push(csv_text::sample(path, row, c.xyz, s.metres(), gaps)?);
    }
    Ok(())
}

/// The note for data that end at the blank line `blank` before `row`, which is neither a
/// data row nor a section name Nexus writes: the rest of the file is not read.
fn unread_rest(blank: usize, row: &Row) -> String {
    format!(
        "the Trajectories data end at the blank line {blank}: line {} (\"{}\") is not a \
         section Nexus writes nor a data row, so it and the rest of the file are not read",
        row.line,
        csv_text::shorten(row.cell(0))
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p() -> &'static Path {
        Path::new("v.csv")
    }

    #[test]
    fn reads_without_units_row_and_stops_at_next_section() {
        let text = "Trajectories\n120\n,,S:A,,,S:B,,,\nFrame,Sub Frame,X,Y,Z,X,Y,Z\n\
                    5,0,1000,0,0,,,\n6,0,0,0,0,1,1,1\nModel Outputs\n120\n";
        let take = read(p(), text.as_bytes(), None).unwrap();
        assert_eq!(take.frames, 2);
        assert_eq!(take.rate_hz, 120.0);
        assert_eq!(take.file_unit, "mm");
        assert_eq!(take.track("A").unwrap().positions[0], Some(glam::DVec3::X));
        assert_eq!(take.track("B").unwrap().positions[0], None);
        let take = read(p(), text.as_bytes(), Some(LengthUnit::Metre)).unwrap();
        assert_eq!(
            take.track("A").unwrap().positions[0],
            Some(glam::DVec3::X * 1000.0)
        );
    }

    #[test]
    fn errors() {
        let head = "Trajectories\n100\n,,S:A,,\nFrame,Sub Frame,X,Y,Z\n,,mm,mm,mm\n";
        let cases = [
            (
                "Devices\n100\n".to_string(),
                "whole file: expected a \"Trajectories\" section",
            ),
            (
                "Trajectories\nfast\n".to_string(),
                "line 2, column 1: expected a number",
            ),
            (
                "Trajectories\n100\n,,A,,\nTime\n".to_string(),
                "line 4, column 1",
            ),
            (
                "Trajectories\n100\n,,A,,\nFrame,Sub Frame,X,Y,Q\n".to_string(),
                "line 3, column 3",
            ),
            (head.to_string(), "expected data rows"),
            (
                format!("{head}1,0,1,2,3\n3,0,1,2,3\n"),
                "line 7, column 1: expected frame 2",
            ),
            (format!("{head}1,0,1,2\n"), "line 6: expected 5 cells"),
            (
                format!("{head}1,0,1,2,z\n"),
                "line 6, column 5: expected a number, found \"z\"",
            ),
            (
                "Trajectories\n100\n,,A,,\nFrame,Sub Frame,X,Y,Z\n,,in,in,in\n1,0,1,2,3\n"
                    .to_string(),
                "line 5, column 3",
            ),
        ];
        for (text, want) in cases {
            let e = read(p(), text.as_bytes(), None).unwrap_err().to_string();
            assert!(e.contains(want), "want {want:?} in {e}");
        }
    }
}
