//! Reading the data rows into numbers, positions and rotations (quaternion, Euler angles,
//! matrix).

use super::*;

/// Reads cells of data rows with errors that name the line and column.
pub(super) struct RowReader<'p> {
    pub(super) path: &'p Path,
    pub(super) cols: &'p Columns,
    pub(super) decimal_comma: bool,
    pub(super) zero_is_missing: bool,
    /// The table is one section of several: its end is expected, not noted.
    pub(super) in_section: bool,
}

/// The data as read, one entry per row (before placing rows on the grid).
pub(super) struct Rows {
    pub(super) lines: Vec<usize>,
    /// The time column's values (seconds or frame numbers), if any.
    pub(super) clock: Vec<f64>,
    pub(super) tracks: Vec<Track>,
    /// The positions written as NaN or (with `zero_is_missing`) as all zeros.
    pub(super) gaps: MarkedGaps,
}

impl RowReader<'_> {
    /// "line L, column C ("name")".
    pub(super) fn place(&self, line: usize, col: usize) -> String {
        match self.cols.names.get(col).filter(|n| !n.is_empty()) {
            Some(n) => format!("{} (\"{n}\")", csv_text::place(line, col)),
            None => csv_text::place(line, col),
        }
    }

    pub(super) fn number(&self, row: &Row, col: usize) -> Result<Option<f64>, ImportError> {
        parse_number(row.cell(col), self.decimal_comma)
            .map_err(|m| ImportError::format(self.path, self.place(row.line, col), m))
    }

    /// The numbers in `cols`, or `None` if any is missing (or, with `zero_is_missing`
    /// and `zeros_count`, if all are 0).
    pub(super) fn numbers<const N: usize>(
        &self,
        row: &Row,
        cols: &[usize; N],
        zeros_count: bool,
    ) -> Result<Option<[f64; N]>, ImportError> {
        let mut out = [0.0; N];
        let mut missing = false;
        for (slot, &c) in out.iter_mut().zip(cols) {
            match self.number(row, c)? {
                Some(v) => *slot = v,
                None => missing = true,
            }
        }
        let zero = zeros_count && self.zero_is_missing && out.iter().all(|v| *v == 0.0);
        Ok((!missing && !zero).then_some(out))
    }

    /// Read the data rows from `first` on.
    pub(super) fn read_rows(
        &self,
        sheet: &Sheet,
        first: usize,
        clock: Option<(usize, Clock)>,
        tracks: &[TrackCols],
        scales: &Scales,
        notes: &mut Vec<String>,
    ) -> Result<Rows, ImportError> {
        let mut rows = Rows {
            lines: Vec::new(),
            clock: Vec::new(),
            tracks: tracks
                .iter()
                .map(|t| Track::empty(t.label.clone()))
                .collect(),
            gaps: MarkedGaps::default(),
        };
        let mut blanks = csv_text::BlankLines::default();
        for row in &sheet.rows[first..] {
            if blanks.skip(row) {
                continue;
            }
            if blanks.pending().is_some() && !sheet.numeric(row.cell(0)) {
                if self.in_section {
                    break;
                }
                notes.push(format!(
                    "the table ends at the blank line before line {} (\"{}\")",
                    row.line,
                    csv_text::shorten(row.cell(0))
                ));
                break;
            }
            blanks.data_row(row.line);
            if let Some((c, _)) = clock {
                let t = self.number(row, c)?.ok_or_else(|| {
                    ImportError::format(
                        self.path,
                        self.place(row.line, c),
                        "expected a time (or frame number), found an empty cell",
                    )
                })?;
                rows.clock.push(t);
            }
            rows.lines.push(row.line);
            for ((t, out), scale) in tracks.iter().zip(&mut rows.tracks).zip(&scales.per_track) {
                self.read_sample(row, t, *scale, out, &mut rows.gaps)?;
            }
        }
        if rows.lines.is_empty() {
            return Err(ImportError::format(
                self.path,
                format!("line {}", sheet.rows[first].line),
                "expected data rows below the header, found none",
            ));
        }
        notes.extend(blanks.note("the data"));
        Ok(rows)
    }

    /// Append one row's position (and rotation) of track `t` to `out`; a position the
    /// file marks unseen is counted in `gaps`.
    pub(super) fn read_sample(
        &self,
        row: &Row,
        t: &TrackCols,
        scale: [f64; 3],
        out: &mut Track,
        gaps: &mut MarkedGaps,
    ) -> Result<(), ImportError> {
        let p = self.numbers(row, &t.position, true)?;
        if p.is_none() {
            self.count_marked(row, &t.position, gaps);
        }
        out.positions
            .push(p.map(|[x, y, z]| DVec3::new(x * scale[0], y * scale[1], z * scale[2])));
        let Some(rot) = &t.rotation else {
            return Ok(());
        };
        let q = match rot {
            RotCols::Quaternion(c) => self
                .numbers(row, c, true)?
                .map(|v| quaternion(v).map_err(|m| self.err(row, c[0], m)))
                .transpose()?,
            RotCols::Euler {
                cols,
                axes,
                scale,
                extrinsic,
            } => self
                .numbers(row, cols, false)?
                .map(|a| euler(a.map(|v| v * scale), *axes, *extrinsic)),
            RotCols::Matrix(c) => self
                .numbers(row, c, true)?
                .map(|m| matrix(m).map_err(|msg| self.err(row, c[0], msg)))
                .transpose()?,
        };
        out.rotations.push(q);
        Ok(())
    }

    /// Count a missing position the file marks unseen: a coordinate written NaN, or
    /// (with `zero_is_missing`) all three 0. Empty cells are not counted.
    pub(super) fn count_marked(&self, row: &Row, cols: &[usize; 3], gaps: &mut MarkedGaps) {
        if csv_text::written_nan(row, cols) {
            gaps.nan += 1;
        } else if self.zero_is_missing
            && matches!(self.numbers(row, cols, false), Ok(Some(v)) if v == [0.0; 3])
        {
            gaps.zero += 1;
        }
    }

    pub(super) fn err(&self, row: &Row, col: usize, message: String) -> ImportError {
        ImportError::format(self.path, self.place(row.line, col), message)
    }
}

/// A unit quaternion from X, Y, Z, W (normalised; its length must be 0.5 to 1.5).
pub(super) fn quaternion([x, y, z, w]: [f64; 4]) -> Result<DQuat, String> {
    let q = DQuat::from_xyzw(x, y, z, w);
    let len = q.length();
    if !(0.5..=1.5).contains(&len) {
        return Err(format!(
            "expected a unit quaternion X, Y, Z, W, found one of length {len:.3}"
        ));
    }
    Ok(q / len)
}

/// The rotation of Euler angles (radians) about `axes`: intrinsic q = R1·R2·R3,
/// extrinsic q = R3·R2·R1 (Ri turning by angle i about axis i).
pub(super) fn euler(angles: [f64; 3], axes: [DVec3; 3], extrinsic: bool) -> DQuat {
    let r = |i: usize| DQuat::from_axis_angle(axes[i], angles[i]);
    if extrinsic {
        r(2) * r(1) * r(0)
    } else {
        r(0) * r(1) * r(2)
    }
}

/// The rotation of a world-from-body matrix given row-major; it must be orthonormal
/// (to 0.01) and right-handed.
pub(super) fn matrix(m: [f64; 9]) -> Result<DQuat, String> {
    let r = DMat3::from_cols(
        DVec3::new(m[0], m[3], m[6]),
        DVec3::new(m[1], m[4], m[7]),
        DVec3::new(m[2], m[5], m[8]),
    );
    let off = (r.transpose() * r - DMat3::IDENTITY)
        .to_cols_array()
        .iter()
        .fold(0.0_f64, |a, v| a.max(v.abs()));
    if off > 0.01 || r.determinant() <= 0.0 {
        return Err(format!(
            "expected a rotation matrix (orthonormal, determinant +1), found one off by {off:.3} \
             with determinant {:.3}",
            r.determinant()
        ));
    }
    Ok(DQuat::from_mat3(&r).normalize())
}
