//! Splitting a capture table into rows and locating its parts: the delimiter, a section,
//! the header rows, the units row and the first data row.

use super::*;

/// The file split into rows at the chosen delimiter.
pub(super) struct Sheet<'a> {
    pub(super) rows: Vec<Row<'a>>,
    pub(super) delimiter: Delimiter,
    pub(super) decimal_comma: bool,
}

impl<'a> Sheet<'a> {
    pub(super) fn split(text: &'a str, profile: &CaptureProfile) -> Sheet<'a> {
        let delimiter = match profile.delimiter {
            Delimiter::Auto => detect_delimiter(text),
            d => d,
        };
        let rows: Vec<Row> = csv_text::rows_on(text, delimiter.char()).collect();
        let decimal_comma = profile.decimal_comma.unwrap_or_else(|| {
            delimiter == Delimiter::Semicolon
                && rows.iter().take(200).any(|r| {
                    r.cells
                        .iter()
                        .any(|c| c.contains(',') && c.replace(',', ".").parse::<f64>().is_ok())
                })
        });
        Sheet {
            rows,
            delimiter,
            decimal_comma,
        }
    }

    /// Whether a cell reads as a number (a decimal comma allowed in `;` files).
    pub(super) fn numeric(&self, cell: &str) -> bool {
        let comma_ok = self.decimal_comma || self.delimiter == Delimiter::Semicolon;
        !cell.is_empty()
            && (cell.parse::<f64>().is_ok()
                || (comma_ok && cell.replace(',', ".").parse::<f64>().is_ok()))
    }

    /// Whether a row has at least two numeric cells.
    pub(super) fn data_like(&self, row: &Row) -> bool {
        row.cells.iter().filter(|c| self.numeric(c)).count() >= 2
    }

    /// The index of the next non-blank row at or after `i`.
    pub(super) fn next_filled(&self, i: usize) -> Option<usize> {
        (i..self.rows.len()).find(|&j| !self.rows[j].is_blank())
    }
}

/// Tab if at least half of the first non-blank lines hold one, else `;`, else `,`, else
/// whitespace.
pub(super) fn detect_delimiter(text: &str) -> Delimiter {
    let lines: Vec<&str> = text
        .lines()
        .filter(|l| !l.trim().is_empty())
        .take(200)
        .collect();
    let most = |c: char| 2 * lines.iter().filter(|l| l.contains(c)).count() >= lines.len();
    if lines.is_empty() {
        Delimiter::Comma
    } else if most('\t') {
        Delimiter::Tab
    } else if most(';') {
        Delimiter::Semicolon
    } else if most(',') {
        Delimiter::Comma
    } else {
        Delimiter::Whitespace
    }
}

/// Where the parts of the table are (indices into the sheet's rows).
pub(super) struct Located {
    /// The first metadata row (the section line, or 0).
    pub(super) region: usize,
    pub(super) header: Vec<usize>,
    pub(super) unit_row: Option<usize>,
    pub(super) data: usize,
}

impl Located {
    /// The first row below the metadata: the header's first, else the unit row or data.
    pub(super) fn header_start(&self) -> usize {
        let below = self.unit_row.unwrap_or(self.data);
        self.header.first().copied().unwrap_or(below)
    }

    /// "header, line 4" or "header, lines 4–5", for errors.
    pub(super) fn header_place(&self, sheet: &Sheet) -> String {
        let first = sheet.rows[self.header_start()].line;
        let last = sheet.rows[self.header.last().copied().unwrap_or(self.header_start())].line;
        if self.header.is_empty() {
            format!("line {first} (no header)")
        } else if first == last {
            format!("header, line {first}")
        } else {
            format!("header, lines {first}–{last}")
        }
    }
}

/// Find the section, header, unit row and first data row.
pub(super) fn locate(
    path: &Path,
    sheet: &Sheet,
    profile: &CaptureProfile,
) -> Result<Located, ImportError> {
    let region = section_start(path, sheet, profile)?;
    let search = region + usize::from(profile.section.is_some());
    let wanted = profile.header_rows + usize::from(profile.unit_row);
    let (above, data) = match &profile.header {
        HeaderLocation::Auto => auto_header(path, sheet, search, wanted)?,
        at => named_header(path, sheet, search, at, wanted)?,
    };
    let (header, units) = above.split_at(profile.header_rows);
    Ok(Located {
        region,
        header: header.to_vec(),
        unit_row: units.first().copied(),
        data,
    })
}

/// The `wanted` non-blank rows (header, then unit row) directly above the first data
/// block, and that block's first row.
pub(super) fn auto_header(
    path: &Path,
    sheet: &Sheet,
    search: usize,
    wanted: usize,
) -> Result<(Vec<usize>, usize), ImportError> {
    let data = auto_data_start(path, sheet, search)?;
    let mut above: Vec<usize> = (search..data)
        .rev()
        .filter(|&i| !sheet.rows[i].is_blank())
        .take(wanted)
        .collect();
    if above.len() < wanted {
        return Err(ImportError::format(
            path,
            format!("line {}", sheet.rows[data].line),
            format!(
                "expected {wanted} header row(s) above the first data row, found {}",
                above.len()
            ),
        ));
    }
    above.reverse();
    Ok((above, data))
}

/// The `wanted` non-blank rows (header, then unit row) from a `Line(n)` or
/// `StartsWith(s)` header on, and the first data row below them.
pub(super) fn named_header(
    path: &Path,
    sheet: &Sheet,
    search: usize,
    at: &HeaderLocation,
    wanted: usize,
) -> Result<(Vec<usize>, usize), ImportError> {
    let first = named_header_start(path, sheet, search, at)?;
    let mut rows = filled_from(sheet, first, wanted + 1);
    if rows.len() < wanted + 1 {
        return Err(ImportError::format(
            path,
            format!("line {}", sheet.rows[first].line),
            format!("expected {wanted} header row(s) and data below, found the end of the file"),
        ));
    }
    let data = rows.pop().unwrap_or(first);
    Ok((rows, data))
}

/// Up to `n` non-blank row indices from `first` on.
pub(super) fn filled_from(sheet: &Sheet, first: usize, n: usize) -> Vec<usize> {
    (first..sheet.rows.len())
        .filter(|&i| !sheet.rows[i].is_blank())
        .take(n)
        .collect()
}

/// The row index of the profile's section line (0 without a section).
pub(super) fn section_start(
    path: &Path,
    sheet: &Sheet,
    profile: &CaptureProfile,
) -> Result<usize, ImportError> {
    let Some(section) = &profile.section else {
        return Ok(0);
    };
    let want = key_of(section);
    sheet
        .rows
        .iter()
        .position(|r| key_of(r.cell(0)) == want)
        .ok_or_else(|| {
            ImportError::format(
                path,
                "whole file",
                format!("expected a line \"{section}\" (the profile's section), found none"),
            )
        })
}

/// The first row of a `Line(n)` or `StartsWith(s)` header.
pub(super) fn named_header_start(
    path: &Path,
    sheet: &Sheet,
    search: usize,
    at: &HeaderLocation,
) -> Result<usize, ImportError> {
    let found = match at {
        HeaderLocation::Line(n) => sheet.rows[search..]
            .iter()
            .position(|r| r.line == *n && !r.is_blank()),
        HeaderLocation::StartsWith(s) => {
            let want = s.trim().to_lowercase();
            sheet.rows[search..]
                .iter()
                .position(|r| r.cell(0).to_lowercase().starts_with(&want))
        }
        HeaderLocation::Auto => None,
    };
    found.map(|i| search + i).ok_or_else(|| {
        let what = match at {
            HeaderLocation::Line(n) => format!("a non-blank header line {n}"),
            HeaderLocation::StartsWith(s) => format!("a header line starting with \"{s}\""),
            HeaderLocation::Auto => "a header".into(),
        };
        ImportError::format(path, "whole file", format!("expected {what}, found none"))
    })
}

/// The first row from `search` on where it and the next two non-blank rows each have at
/// least two numeric cells and the same width (fewer rows suffice at the end of file).
pub(super) fn auto_data_start(
    path: &Path,
    sheet: &Sheet,
    search: usize,
) -> Result<usize, ImportError> {
    let same_width =
        |a: &Row, b: &Row| a.cells.len() == b.cells.len() || a.used_width() == b.used_width();
    let mut i = search;
    while let Some(start) = sheet.next_filled(i) {
        let row = &sheet.rows[start];
        let mut next = start + 1;
        let mut ok = sheet.data_like(row);
        for _ in 0..2 {
            let Some(j) = sheet.next_filled(next).filter(|_| ok) else {
                break;
            };
            ok = sheet.data_like(&sheet.rows[j]) && same_width(row, &sheet.rows[j]);
            next = j + 1;
        }
        if ok {
            return Ok(start);
        }
        i = start + 1;
    }
    Err(ImportError::format(
        path,
        "whole file",
        "expected a block of data rows (three lines with at least two numbers each and the \
         same number of cells), found none; set the profile's `header: Line(n)`",
    ))
}
