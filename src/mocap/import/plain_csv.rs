//! Our own plain CSV capture format: the simplest way to bring a capture from any system
//! into timpanist, and what our own CSV exports write.
//!
//! # Format
//!
//! ```text
//! time_s,StickL:Tip_x,StickL:Tip_y,StickL:Tip_z,StickL_x,StickL_y,StickL_z,StickL_qx,StickL_qy,StickL_qz,StickL_qw
//! 0.000,0.512,0.130,0.874,0.401,0.102,0.912,0,0,0,1
//! 0.004,0.513,0.131,0.871,0.402,0.103,0.910,0,0,0.0087,0.99996
//! 0.008,,,,0.403,0.104,0.908,,,,
//! ```
//!
//! * The first line is the header. Its first cell is `time_s`; every other cell is a
//!   track label followed by a suffix: `_x`, `_y`, `_z` for the position (all three are
//!   required for every label) and optionally `_qx`, `_qy`, `_qz`, `_qw` for a
//!   rotation quaternion (all four or none), which makes the track a rigid body. The
//!   label is everything before the last `_` (labels may hold `_` and `:`); the columns of
//!   one label may come in any order; tracks are listed in order of first appearance.
//! * Every following line is one frame: the time in seconds, then numbers with `.` as
//!   the decimal point. Positions are in metres. An empty cell means "not seen" and must
//!   cover the whole position (x, y, z) or the whole quaternion; a cell written `NaN`
//!   (any case) makes its position or quaternion "not seen" (counted in a note).
//! * The frame rate is 1 / the median time step. Times must increase and every step must
//!   be within 1 % of the median, or the file is refused with the line that breaks it.
//!   At least two frames are needed.
//! * Lines may end in CRLF and have a trailing comma; a UTF-8 byte-order mark is skipped.
//!   Quaternions are normalised on reading.
//! * Blank lines (nothing, or only commas and spaces) between data rows, as hand-edited or
//!   concatenated files have, are skipped and named in a note; the rows after them must
//!   still run on in time. Blank lines before the first data row or at the end are ignored.
//!
//! A unit override (`mm`, `cm`) can be given for files written in another unit.

use super::LengthUnit;
use super::csv_text::{self, Row};
use crate::mocap::take::{ImportError, MarkedGaps, Take, Track};
use glam::DQuat;
use std::fmt::Write as _;
use std::path::Path;

/// Column roles: position axis 0..3, quaternion component 3..7 (qx, qy, qz, qw).
const SUFFIXES: [&str; 7] = ["_x", "_y", "_z", "_qx", "_qy", "_qz", "_qw"];

/// Where one label's columns are (0-based cell indices).
struct Columns {
    label: String,
    cols: [Option<usize>; 7],
}

/// Read a plain CSV capture; `unit` overrides metres.
pub fn read(path: &Path, bytes: &[u8], unit: Option<LengthUnit>) -> Result<Take, ImportError> {
    let text = csv_text::decode(bytes);
    let unit = unit.unwrap_or(LengthUnit::Metre);
    let scale = unit.metres();
    let mut rows = csv_text::rows(&text);
    let header = rows.next().filter(|r| !r.is_blank()).ok_or_else(|| {
        ImportError::format(
            path,
            "line 1",
            "expected a header \"time_s,<label>_x,<label>_y,<label>_z,…\", found an empty file",
        )
    })?;
    let (width, labels) = parse_header(path, &header)?;

    let mut times: Vec<(usize, f64)> = Vec::new();
    let mut tracks: Vec<Track> = labels
        .iter()
        .map(|c| Track::empty(c.label.clone()))
        .collect();
    let mut gaps = MarkedGaps::default();
    let mut blanks = csv_text::BlankLines::default();
    for row in rows.filter(|row| blanks.is_data(row)) {
        csv_text::check_width(path, &row, width)?;
        let t = csv_text::required_number(path, &row, 0, "time in seconds")?;
        times.push((row.line, t));
        for (c, track) in labels.iter().zip(tracks.iter_mut()) {
            let pos = match c.cols {
                [Some(x), Some(y), Some(z), ..] => {
                    csv_text::sample(path, &row, [x, y, z], scale, &mut gaps)?
                }
                _ => None,
            };
            track.positions.push(pos);
            if let [_, _, _, Some(qx), Some(qy), Some(qz), Some(qw)] = c.cols {
                track
                    .rotations
                    .push(quaternion(path, &row, [qx, qy, qz, qw])?);
            }
        }
    }
    let rate_hz = rate_from_times(path, &times, &blanks)?;
    let mut take = Take {
        source: path.to_path_buf(),
        rate_hz,
        frames: times.len(),
        file_unit: unit.symbol().to_string(),
        tracks,
        notes: blanks.note("the data").into_iter().collect(),
    };
    take.zeros_as_gaps(gaps);
    Ok(take)
}

/// The header's column count and each label's columns.
fn parse_header(path: &Path, header: &Row) -> Result<(usize, Vec<Columns>), ImportError> {
    if !header.cell(0).eq_ignore_ascii_case("time_s") {
        return Err(ImportError::format(
            path,
            csv_text::place(header.line, 0),
            format!(
                "expected \"time_s\" as the first header cell, found \"{}\"",
                csv_text::shorten(header.cell(0))
            ),
        ));
    }
    let width = header.used_width();
    let mut labels: Vec<Columns> = Vec::new();
    for col in 1..width {
        let name = header.cell(col);
        let found = SUFFIXES.iter().enumerate().find_map(|(role, suf)| {
            let n = name.len().checked_sub(suf.len())?;
            let (label, tail) = (name.get(..n)?, name.get(n..)?);
            tail.eq_ignore_ascii_case(suf).then_some((role, label))
        });
        let Some((role, label)) = found.filter(|(_, l)| !l.is_empty()) else {
            return Err(ImportError::format(
                path,
                csv_text::place(header.line, col),
                format!(
                    "expected a column named <label>_x, _y, _z, _qx, _qy, _qz or _qw, found \"{}\"",
                    csv_text::shorten(name)
                ),
            ));
        };
        let entry = match labels.iter_mut().position(|c| c.label == label) {
            Some(i) => &mut labels[i],
            None => {
                labels.push(Columns {
                    label: label.to_string(),
                    cols: [None; 7],
                });
                let last = labels.len() - 1;
                &mut labels[last]
            }
        };
        if entry.cols[role].is_some() {
            return Err(ImportError::format(
                path,
                csv_text::place(header.line, col),
                format!("expected each column once, found \"{name}\" a second time"),
            ));
        }
        entry.cols[role] = Some(col);
    }
    for c in &labels {
        let pos = c.cols[..3].iter().filter(|x| x.is_some()).count();
        let rot = c.cols[3..].iter().filter(|x| x.is_some()).count();
        if pos != 3 || (rot != 0 && rot != 4) {
            return Err(ImportError::format(
                path,
                format!("line {}", header.line),
                format!(
                    "expected columns {0}_x, {0}_y, {0}_z (and optionally all of {0}_qx, \
                     {0}_qy, {0}_qz, {0}_qw), found only some of them",
                    c.label
                ),
            ));
        }
    }
    if labels.is_empty() {
        return Err(ImportError::format(
            path,
            format!("line {}", header.line),
            "expected at least one track after time_s (columns <label>_x, <label>_y, <label>_z)",
        ));
    }
    Ok((width, labels))
}

/// A quaternion from cells X, Y, Z, W: all empty, or any NaN, gives `None`; it is
/// normalised.
pub(super) fn quaternion(
    path: &Path,
    row: &Row,
    cols: [usize; 4],
) -> Result<Option<DQuat>, ImportError> {
    let mut v = [0.0; 4];
    let mut given = 0;
    for (slot, &col) in v.iter_mut().zip(&cols) {
        if let Some(x) = csv_text::number(path, row, col)? {
            *slot = x;
            given += 1;
        }
    }
    if given == 0 || csv_text::written_nan(row, &cols) {
        return Ok(None);
    }
    let q = DQuat::from_xyzw(v[0], v[1], v[2], v[3]);
    let len = q.length();
    let problem = if given != 4 {
        Some(format!("found {given} of the 4 cells filled"))
    } else if !(0.5..=1.5).contains(&len) {
        Some(format!("found one of length {len:.3}"))
    } else {
        None
    };
    if let Some(problem) = problem {
        return Err(ImportError::format(
            path,
            csv_text::place(row.line, cols[0]),
            format!("expected a unit quaternion X, Y, Z, W (all four cells), {problem}"),
        ));
    }
    Ok(Some(q / len))
}

/// The frame rate from the rows' times: 1 / median step; steps must be uniform to 1 %.
/// `blanks`: the blank lines skipped among the rows, named when a step across them is
/// wrong.
fn rate_from_times(
    path: &Path,
    times: &[(usize, f64)],
    blanks: &csv_text::BlankLines,
) -> Result<f64, ImportError> {
    if times.len() < 2 {
        return Err(ImportError::format(
            path,
            "line 2",
            format!(
                "expected at least two data rows to know the frame rate, found {}",
                times.len()
            ),
        ));
    }
    let mut steps = Vec::with_capacity(times.len() - 1);
    for w in times.windows(2) {
        let [(_, t0), (line, t1)] = [w[0], w[1]];
        if t1 <= t0 {
            return Err(ImportError::format(
                path,
                csv_text::place(line, 0),
                format!(
                    "expected a time after the previous row's {t0} s, found {t1} s{}",
                    csv_text::not_run_on(blanks.run_before(line))
                ),
            ));
        }
        steps.push(t1 - t0);
    }
    let median = crate::base::stats::median(steps.iter().copied()).unwrap_or(0.0);
    for (step, w) in steps.iter().zip(times.windows(2)) {
        if (step - median).abs() > 0.01 * median {
            return Err(ImportError::format(
                path,
                csv_text::place(w[1].0, 0),
                format!(
                    "expected a uniform time step of {median} s (within 1 %), found a step of \
                     {step} s from the previous row{}",
                    csv_text::not_run_on(blanks.run_before(w[1].0))
                ),
            ));
        }
    }
    Ok(1.0 / median)
}

/// Write `take` in this format (positions in metres, times `frame / rate`, empty cells
/// for `None`; quaternion columns for tracks that have rotations).
pub fn write(take: &Take) -> String {
    let mut out = String::from("time_s");
    for t in &take.tracks {
        let _ = write!(out, ",{0}_x,{0}_y,{0}_z", csv_label(&t.label));
        if !t.rotations.is_empty() {
            let _ = write!(out, ",{0}_qx,{0}_qy,{0}_qz,{0}_qw", csv_label(&t.label));
        }
    }
    out.push('\n');
    for f in 0..take.frames {
        let _ = write!(out, "{}", f as f64 / take.rate_hz);
        for t in &take.tracks {
            match t.positions.get(f).copied().flatten() {
                Some(p) => {
                    let _ = write!(out, ",{},{},{}", p.x, p.y, p.z);
                }
                None => out.push_str(",,,"),
            }
            if !t.rotations.is_empty() {
                match t.rotations.get(f).copied().flatten() {
                    Some(q) => {
                        let _ = write!(out, ",{},{},{},{}", q.x, q.y, q.z, q.w);
                    }
                    None => out.push_str(",,,,"),
                }
            }
        }
        out.push('\n');
    }
    out
}

/// A label made safe for a header cell (quoted if it holds a comma or quote).
fn csv_label(label: &str) -> String {
    if label.contains([',', '"']) {
        format!("\"{}\"", label.replace('"', "\"\""))
    } else {
        label.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    fn p() -> &'static Path {
        Path::new("t.csv")
    }

    #[test]
    fn reads_positions_rotations_and_gaps() {
        let text = "time_s,a:tip_x,a:tip_y,a:tip_z,rb_qx,rb_qy,rb_qz,rb_qw,rb_x,rb_y,rb_z,\r\n\
                    0.00,1,2,3,0,0,0,1,0,0,0,\r\n\
                    0.01,,,,0,0,0,1.1,1,1,1,\r\n\
                    0.02,4,5,6,,,,,,,,\r\n";
        let take = read(p(), text.as_bytes(), None).unwrap();
        assert_eq!(take.frames, 3);
        assert!((take.rate_hz - 100.0).abs() < 1e-9);
        assert_eq!(take.labels(), vec!["a:tip", "rb"]);
        let a = take.track("tip").unwrap();
        assert_eq!(a.positions[0], Some(DVec3::new(1.0, 2.0, 3.0)));
        assert_eq!(a.positions[1], None);
        assert!(a.rotations.is_empty());
        let rb = take.track("rb").unwrap();
        assert_eq!(rb.rotations.len(), 3);
        assert_eq!(rb.rotations[1], Some(DQuat::IDENTITY));
        assert_eq!(rb.rotations[2], None);
        assert_eq!(rb.positions[2], None);
    }

    #[test]
    fn unit_override_scales() {
        let text = "time_s,a_x,a_y,a_z\n0,1000,0,0\n0.5,0,0,0\n";
        let take = read(p(), text.as_bytes(), Some(LengthUnit::Millimetre)).unwrap();
        assert_eq!(take.tracks[0].positions[0], Some(DVec3::X));
        assert_eq!(take.file_unit, "mm");
        assert!((take.rate_hz - 2.0).abs() < 1e-12);
    }

    #[test]
    fn errors_name_line_and_column() {
        let cases = [
            ("", "line 1"),
            ("t,a_x,a_y,a_z\n", "line 1, column 1"),
            (
                "time_s,a_x,a_y\n0,1,2\n1,1,2\n",
                "line 1: expected columns a_x",
            ),
            ("time_s,a_x,a_y,a_z,a_x\n", "line 1, column 5"),
            ("time_s,a_x,a_y,a_z,b\n", "line 1, column 5"),
            (
                "time_s,a_x,a_y,a_z\n0,1,2,3\n0.1,1,abc,3\n",
                "line 3, column 3: expected a number, found \"abc\"",
            ),
            (
                "time_s,a_x,a_y,a_z\n0,1,2,3\n",
                "expected at least two data rows",
            ),
            (
                "time_s,a_x,a_y,a_z\n0,1,2,3\n0.1,1,2,3\n0.3,1,2,3\n0.4,1,2,3\n",
                "line 4, column 1: expected a uniform",
            ),
            ("time_s,a_x,a_y,a_z\n0,1,2,3\n0,1,2,3\n", "line 3, column 1"),
            (
                "time_s,a_x,a_y,a_z\n0,1,2,3\n0.1,1,,3\n",
                "line 3, column 3",
            ),
            (
                "time_s,a_x,a_y,a_z\n0,1,2,3\n0.1,1,2,3\n\n0,1,2,3\n",
                "line 5, column 1: expected a time after the previous row's 0.1 s, found 0 s \
                 (the rows after the blank line 4 do not run on from those above it)",
            ),
            (
                "time_s,a_x,a_y,a_z\n0,1,2,3\n0.1,1,2\n",
                "line 3: expected 4 cells",
            ),
            (
                "time_s,a_x,a_y,a_z\n0,1,2,3\n0.1,1,2,3,4\n",
                "line 3, column 5",
            ),
            ("time_s,a_x,a_y,a_z\n0,1,2,3\n,1,2,3\n", "line 3, column 1"),
        ];
        for (text, want) in cases {
            let e = read(p(), text.as_bytes(), None).unwrap_err().to_string();
            assert!(e.contains(want), "{text:?}: {e}");
        }
    }

    /// Blank lines between data rows (empty, commas only, spaces and tabs) are skipped
    /// and named; those at the end are not.
    #[test]
    fn blank_lines_inside_the_data_are_skipped_and_named() {
        let text = "time_s,a_x,a_y,a_z,rb_x,rb_y,rb_z,rb_qx,rb_qy,rb_qz,rb_qw\n\
                    0.00,1000,0,0,0,0,500,0,0,0,1\n\
                    \n\
                    0.01,1250,0,0,0,0,750,0,0,0,1\n\
                    ,,,,,,,,,,\n\
                    \x20\t, ,\n\
                    0.02,,,,0,0,1000,,,,\n\
                    0.03,1500,0,0,0,0,1250,0,0,0,1\n\n\n";
        for text in [text.to_string(), text.replace('\n', "\r\n")] {
            let take = read(p(), text.as_bytes(), Some(LengthUnit::Millimetre)).unwrap();
            assert_eq!(take.frames, 4);
            assert!((take.rate_hz - 100.0).abs() < 1e-9);
            let a = &take.tracks[0].positions;
            assert_eq!(a[1], Some(DVec3::new(1.25, 0.0, 0.0)));
            assert_eq!(a[2], None);
            assert_eq!(a[3], Some(DVec3::new(1.5, 0.0, 0.0)));
            assert_eq!(take.tracks[1].positions[2], Some(DVec3::new(0.0, 0.0, 1.0)));
            assert_eq!(take.tracks[1].rotations[2], None);
            assert_eq!(take.tracks[1].rotations[3], Some(DQuat::IDENTITY));
            assert_eq!(
                take.notes,
                [
                    "3 blank lines inside the data were skipped (lines 3, 5, 6): the rows after \
                  them continue the frames above"
                ]
            );
        }
    }

    #[test]
    fn write_then_read_round_trips() {
        let take = Take {
            source: p().into(),
            rate_hz: 250.0,
            frames: 3,
            file_unit: "m".into(),
            tracks: vec![
                Track {
                    label: "x,\"y\"".into(),
                    positions: vec![Some(DVec3::new(0.1, -0.2, 1.5)), None, Some(DVec3::ZERO)],
                    rotations: vec![],
                },
                Track {
                    label: "StickL".into(),
                    positions: vec![None, Some(DVec3::ONE), Some(DVec3::ONE)],
                    rotations: vec![
                        Some(DQuat::from_rotation_z(0.3)),
                        None,
                        Some(DQuat::IDENTITY),
                    ],
                },
            ],
            notes: Vec::new(),
        };
        let back = read(p(), write(&take).as_bytes(), None).unwrap();
        assert_eq!(back.labels(), take.labels());
        assert_eq!(back.frames, 3);
        assert!((back.rate_hz - 250.0).abs() < 1e-9);
        assert_eq!(back.tracks[0].positions[..2], take.tracks[0].positions[..2]);
        assert_eq!(
            back.tracks[0].positions[2], None,
            "(0, 0, 0) reads as a gap"
        );
        assert_eq!(back.tracks[1].positions, take.tracks[1].positions);
        let q0 = back.tracks[1].rotations[0].unwrap();
        assert!(q0.abs_diff_eq(DQuat::from_rotation_z(0.3), 1e-12));
        assert_eq!(back.tracks[1].rotations[1], None);
    }
}
