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
//! 4. Data rows: blank lines are skipped; after a blank line, a line whose first cell is
//!    not a number ends the table (the next section of a multi-section export). A cell
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
use crate::mocap::take::{ImportError, Take, Track};
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
    /// The number of data rows read (not counting grid gaps).
    pub data_rows: usize,
}

/// Read a capture table as `profile` describes it; `unit` overrides every unit source.
pub fn read(
    path: &Path,
    bytes: &[u8],
    profile: &CaptureProfile,
    unit: Option<LengthUnit>,
) -> Result<Take, ImportError> {
    read_table(path, bytes, profile, unit).map(|(take, _)| take)
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

/// [`read`], also giving the metadata and the row count.
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
    let take = Take {
        source: path.to_path_buf(),
        rate_hz: grid.rate_hz,
        frames: grid.frames,
        file_unit: scales.file_unit.clone(),
        tracks: grid.scatter(rows.tracks),
        notes,
    };
    let info = TableInfo {
        metadata: meta,
        data_rows: rows.lines.len(),
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

// ---------------------------------------------------------------------------------------
// Splitting and locating

/// The file split into rows at the chosen delimiter.
struct Sheet<'a> {
    rows: Vec<Row<'a>>,
    delimiter: Delimiter,
    decimal_comma: bool,
}

impl<'a> Sheet<'a> {
    fn split(text: &'a str, profile: &CaptureProfile) -> Sheet<'a> {
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
    fn numeric(&self, cell: &str) -> bool {
        let comma_ok = self.decimal_comma || self.delimiter == Delimiter::Semicolon;
        !cell.is_empty()
            && (cell.parse::<f64>().is_ok()
                || (comma_ok && cell.replace(',', ".").parse::<f64>().is_ok()))
    }

    /// Whether a row has at least two numeric cells.
    fn data_like(&self, row: &Row) -> bool {
        row.cells.iter().filter(|c| self.numeric(c)).count() >= 2
    }

    /// The index of the next non-blank row at or after `i`.
    fn next_filled(&self, i: usize) -> Option<usize> {
        (i..self.rows.len()).find(|&j| !self.rows[j].is_blank())
    }
}

/// Tab if at least half of the first non-blank lines hold one, else `;`, else `,`, else
/// whitespace.
fn detect_delimiter(text: &str) -> Delimiter {
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
struct Located {
    /// The first metadata row (the section line, or 0).
    region: usize,
    header: Vec<usize>,
    unit_row: Option<usize>,
    data: usize,
}

impl Located {
    /// The first row below the metadata: the header's first, else the unit row or data.
    fn header_start(&self) -> usize {
        let below = self.unit_row.unwrap_or(self.data);
        self.header.first().copied().unwrap_or(below)
    }

    /// "header, line 4" or "header, lines 4–5", for errors.
    fn header_place(&self, sheet: &Sheet) -> String {
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
fn locate(path: &Path, sheet: &Sheet, profile: &CaptureProfile) -> Result<Located, ImportError> {
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
fn auto_header(
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
fn named_header(
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
fn filled_from(sheet: &Sheet, first: usize, n: usize) -> Vec<usize> {
    (first..sheet.rows.len())
        .filter(|&i| !sheet.rows[i].is_blank())
        .take(n)
        .collect()
}

/// The row index of the profile's section line (0 without a section).
fn section_start(
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
fn named_header_start(
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
fn auto_data_start(path: &Path, sheet: &Sheet, search: usize) -> Result<usize, ImportError> {
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

// ---------------------------------------------------------------------------------------
// Column names and metadata

/// A header name as displayed: trimmed, whitespace runs collapsed to one space.
fn display_name(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// A header name as matched: [`display_name`], lower case.
fn key_of(s: &str) -> String {
    display_name(s).to_lowercase()
}

/// The table's column names and their lookup.
struct Columns {
    names: Vec<String>,
    /// Matching key → first column with it.
    keys: HashMap<String, usize>,
}

impl Columns {
    fn new(sheet: &Sheet, found: &Located) -> Columns {
        let header: Vec<&Row> = found.header.iter().map(|&i| &sheet.rows[i]).collect();
        let width = header
            .iter()
            .map(|r| r.cells.len())
            .chain([sheet.rows[found.data].cells.len()])
            .max()
            .unwrap_or(0);
        let filled: Vec<Vec<&str>> = header
            .iter()
            .enumerate()
            .map(|(k, r)| forward_fill(r, width, k + 1 < header.len()))
            .collect();
        let names: Vec<String> = (0..width)
            .map(|c| {
                let parts: Vec<&str> = filled
                    .iter()
                    .map(|r| r[c])
                    .filter(|p| !p.is_empty())
                    .collect();
                display_name(&parts.join(" "))
            })
            .collect();
        let mut keys = HashMap::new();
        for (c, n) in names.iter().enumerate() {
            keys.entry(n.to_lowercase()).or_insert(c);
        }
        Columns { names, keys }
    }

    /// The column a reference names; `anchor` is the track's first position column.
    fn find(&self, r: &str, anchor: Option<usize>) -> Result<usize, String> {
        let width = self.names.len();
        let past = |c: usize| {
            format!(
                "expected column {} to exist, found only {width} columns",
                c.saturating_add(1)
            )
        };
        match ColumnRef::parse(r)? {
            ColumnRef::Index(c) if c < width => Ok(c),
            ColumnRef::Index(c) => Err(past(c)),
            ColumnRef::Offset(n) => match anchor.map(|a| a.saturating_add(n)) {
                Some(c) if c < width => Ok(c),
                Some(c) => Err(past(c)),
                None => Err(format!(
                    "expected a name or \"#N\" for the first position column, found \"{r}\""
                )),
            },
            ColumnRef::Name(n) => self.keys.get(&key_of(n)).copied().ok_or_else(|| {
                format!(
                    "expected a column named \"{n}\", found none (nearest: {})",
                    self.nearest(n)
                )
            }),
        }
    }

    /// The three existing names closest to `name`, quoted.
    fn nearest(&self, name: &str) -> String {
        let want: Vec<char> = key_of(name).chars().collect();
        let mut scored: Vec<(usize, usize)> = self
            .names
            .iter()
            .enumerate()
            .filter(|(_, n)| !n.is_empty())
            .map(|(c, n)| {
                (
                    edit_distance(&want, &n.to_lowercase().chars().collect::<Vec<_>>()),
                    c,
                )
            })
            .collect();
        scored.sort();
        let near: Vec<String> = scored
            .iter()
            .take(3)
            .map(|&(_, c)| format!("\"{}\"", self.names[c]))
            .collect();
        if near.is_empty() {
            "the header is empty".into()
        } else {
            near.join(", ")
        }
    }
}

/// A header row's cells to `width`; an upper row is forward-filled across empty cells.
fn forward_fill<'r>(row: &'r Row, width: usize, fill: bool) -> Vec<&'r str> {
    let mut last = "";
    (0..width)
        .map(|c| {
            let cell = row.cell(c);
            if !cell.is_empty() || !fill {
                last = cell;
                cell
            } else {
                last
            }
        })
        .collect()
}

/// Levenshtein distance between two strings (as chars).
fn edit_distance(a: &[char], b: &[char]) -> usize {
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.iter().enumerate() {
        let mut cur = vec![i + 1; b.len() + 1];
        for (j, cb) in b.iter().enumerate() {
            let swap = prev[j] + usize::from(ca != cb);
            cur[j + 1] = swap.min(prev[j + 1] + 1).min(cur[j] + 1);
        }
        prev = cur;
    }
    prev[b.len()]
}

/// The key/value pairs of the metadata rows: a line of two or more keys followed by a
/// line of as many cells starting with a number pairs column by column (TRC); a key alone
/// on its line takes the cell in its column of the next line if that is alone too
/// (Vicon's section and rate); a line of alternating keys and values with some numeric
/// values gives pairs (Motive); any other line is its first cell, valued by the next
/// non-empty cell (and listing all of them).
fn metadata(rows: &[Row]) -> Vec<MetaEntry> {
    let filled: Vec<&Row> = rows.iter().filter(|r| !r.is_blank()).collect();
    let mut out = Vec::new();
    let mut k = 0;
    while k < filled.len() {
        let (row, next) = (filled[k], filled.get(k + 1).copied());
        let first = row.cells.iter().position(|c| !c.is_empty()).unwrap_or(0);
        let below = |c: usize| next.map_or("", |n| n.cell(c));
        let entry = |c: usize, values: Vec<&str>| MetaEntry {
            line: row.line,
            column: c + 1,
            key: row.cell(c).to_string(),
            value: values.first().copied().unwrap_or("").to_string(),
            values: values.iter().map(|v| v.to_string()).collect(),
        };
        if next.is_some_and(|n| keys_over_values(row, n)) {
            let keys = (0..row.cells.len()).filter(|&c| !row.cell(c).is_empty());
            out.extend(keys.map(|c| entry(c, vec![below(c)])));
            k += 2;
        } else if filled_cells(row) == 1
            && next.is_some_and(|n| filled_cells(n) == 1 && !below(first).is_empty())
        {
            out.push(entry(first, vec![below(first)]));
            k += 2;
        } else if alternating(row) {
            let keys = (0..row.cells.len())
                .step_by(2)
                .filter(|&c| !row.cell(c).is_empty());
            out.extend(keys.map(|c| entry(c, vec![row.cell(c + 1)])));
            k += 1;
        } else {
            let rest: Vec<&str> = row.cells[first + 1..]
                .iter()
                .map(|c| c.as_ref())
                .filter(|c| !c.is_empty())
                .collect();
            out.push(entry(first, rest));
            k += 1;
        }
    }
    out
}

/// A metadata cell that reads as a number (a decimal comma allowed).
fn meta_numeric(c: &str) -> bool {
    !c.is_empty() && c.replace(',', ".").parse::<f64>().is_ok()
}

/// The number of non-empty cells.
fn filled_cells(row: &Row) -> usize {
    row.cells.iter().filter(|c| !c.is_empty()).count()
}

/// Whether `row` is two or more keys (no numbers) and `next` their values: as many
/// cells, the first a number, at least half of them numbers (TRC lines 2 and 3).
fn keys_over_values(row: &Row, next: &Row) -> bool {
    let n = filled_cells(row);
    let numbers = next.cells.iter().filter(|c| meta_numeric(c)).count();
    let lead = next.cells.iter().find(|c| !c.is_empty());
    n >= 2
        && !row.cells.iter().any(|c| meta_numeric(c))
        && filled_cells(next) == n
        && lead.is_some_and(|c| meta_numeric(c))
        && 2 * numbers >= n
}

/// Whether a line is key, value, key, value, … (four cells or more, keys not numeric,
/// some value numeric), like Motive's first line.
fn alternating(row: &Row) -> bool {
    row.cells.len() >= 4
        && !row.cell(0).is_empty()
        && row.cells.iter().step_by(2).all(|c| !meta_numeric(c))
        && row.cells.iter().skip(1).step_by(2).any(|c| meta_numeric(c))
}

/// The value of metadata key `key` (matched like column names), with its entry.
pub(super) fn lookup<'m>(meta: &'m [MetaEntry], key: &str) -> Option<&'m MetaEntry> {
    let want = key_of(key);
    meta.iter().find(|e| key_of(&e.key) == want)
}

// ---------------------------------------------------------------------------------------
// Tracks

/// Where a track's samples are (0-based columns).
#[derive(Clone, Debug, PartialEq)]
struct TrackCols {
    label: String,
    position: [usize; 3],
    rotation: Option<RotCols>,
}

/// Where and how a rigid body's rotation is written.
#[derive(Clone, Debug, PartialEq)]
enum RotCols {
    Quaternion([usize; 4]),
    Euler {
        cols: [usize; 3],
        axes: [DVec3; 3],
        /// Radians per file unit.
        scale: f64,
        extrinsic: bool,
    },
    Matrix([usize; 9]),
}

impl RotCols {
    fn columns(&self) -> &[usize] {
        match self {
            RotCols::Quaternion(c) => c,
            RotCols::Euler { cols, .. } => cols,
            RotCols::Matrix(c) => c,
        }
    }

    fn kind(&self) -> &'static str {
        match self {
            RotCols::Quaternion(_) => "quaternion",
            RotCols::Euler { .. } => "euler",
            RotCols::Matrix(_) => "matrix",
        }
    }
}

impl TrackCols {
    fn found(&self) -> FoundTrack {
        FoundTrack {
            label: self.label.clone(),
            position: self.position.map(|c| c + 1),
            orientation: self
                .rotation
                .as_ref()
                .map(|r| (r.kind(), r.columns().iter().map(|c| c + 1).collect())),
        }
    }
}

/// The profile's explicit tracks, then the tracks its patterns discover in column order
/// (an earlier pattern taking a label first); and what went wrong (a missing column, no
/// track at all).
fn find_tracks(profile: &CaptureProfile, cols: &Columns) -> (Vec<TrackCols>, Vec<String>) {
    let mut tracks = Vec::new();
    let mut problems = Vec::new();
    for t in &profile.tracks {
        let refs = spec_columns(&t.position, t.orientation.as_ref());
        match resolve(cols, &refs, t.orientation.as_ref(), &t.label) {
            Ok(tc) => tracks.push(tc),
            Err(e) => problems.push(format!("track \"{}\": {e}", t.label)),
        }
    }
    let explicit = tracks.len();
    for p in &profile.patterns {
        let refs = spec_columns(&p.position, p.orientation.as_ref());
        for (label, names) in discover(cols, &refs) {
            let taken = tracks
                .iter()
                .any(|t: &TrackCols| t.label.eq_ignore_ascii_case(&label));
            let names: Vec<&str> = names.iter().map(String::as_str).collect();
            if let (false, Ok(tc)) = (taken, resolve(cols, &names, p.orientation.as_ref(), &label))
            {
                tracks.push(tc);
            }
        }
    }
    tracks[explicit..].sort_by_key(|t| t.position[0]);
    if tracks.is_empty() && problems.is_empty() {
        problems.push(
            "expected at least one track, found none: no explicit track, and no pattern \
             matched the column names"
                .into(),
        );
    }
    (tracks, problems)
}

/// A track's columns from its references (position X, Y, Z, then rotation).
fn resolve(
    cols: &Columns,
    refs: &[&str],
    orientation: Option<&Orientation>,
    label: &str,
) -> Result<TrackCols, String> {
    let anchor = cols.find(refs[0], None)?;
    let found: Vec<usize> = refs
        .iter()
        .map(|r| cols.find(r, Some(anchor)))
        .collect::<Result<_, _>>()?;
    let rotation = orientation.map(|o| rot_cols(o, &found[3..])).transpose()?;
    Ok(TrackCols {
        label: label.to_string(),
        position: [found[0], found[1], found[2]],
        rotation,
    })
}

/// The rotation columns in the form `o` asks for.
fn rot_cols(o: &Orientation, c: &[usize]) -> Result<RotCols, String> {
    Ok(match o {
        Orientation::Quaternion { .. } => RotCols::Quaternion([c[0], c[1], c[2], c[3]]),
        Orientation::Euler {
            order,
            angles,
            frame,
            ..
        } => RotCols::Euler {
            cols: [c[0], c[1], c[2]],
            axes: euler_axes(order)?,
            scale: match angles {
                AngleUnit::Degrees => std::f64::consts::PI / 180.0,
                AngleUnit::Radians => 1.0,
            },
            extrinsic: *frame == EulerFrame::Extrinsic,
        },
        Orientation::Matrix { .. } => {
            let mut m = [0; 9];
            m.copy_from_slice(&c[..9]);
            RotCols::Matrix(m)
        }
    })
}

/// Column names longer than this (in characters) are not matched against patterns.
const MAX_PATTERN_NAME: usize = 160;

/// Every (label, column references) a pattern finds, in column order: for each column
/// fitting the first template, the first way of filling its placeholders for which all
/// the other columns exist.
fn discover(cols: &Columns, refs: &[&str]) -> Vec<(String, Vec<String>)> {
    let templates: Vec<String> = refs.iter().map(|r| display_name(r)).collect();
    let Ok(first) = template_parts(&templates[0]) else {
        return Vec::new();
    };
    let mut out: Vec<(String, Vec<String>)> = Vec::new();
    for name in &cols.names {
        let text: Vec<char> = name.chars().collect();
        if text.len() > MAX_PATTERN_NAME {
            continue;
        }
        let mut hit = None;
        fill_holes(&first, &text, &mut Vec::new(), &mut |caps| {
            let names: Vec<String> = templates.iter().map(|t| substitute(t, caps)).collect();
            let label = caps
                .iter()
                .find(|(h, _)| h == "name")
                .map(|(_, v)| v.clone());
            let anchor = cols.find(&names[0], None).ok();
            let all = anchor.is_some_and(|a| names.iter().all(|n| cols.find(n, Some(a)).is_ok()));
            hit = label.filter(|_| all).map(|l| (l, names));
            hit.is_some()
        });
        if let Some((label, names)) = hit.filter(|(l, _)| !out.iter().any(|(o, _)| o == l)) {
            out.push((label, names));
        }
    }
    out
}

/// Placeholder values: (name, text).
type Captures = Vec<(String, String)>;

/// Offer `found` every way `text` fits `parts` (text compared case-insensitively,
/// placeholders taking at least one character, a repeated placeholder the same text),
/// longest placeholder values first (so a name with spaces beats a short ID), until it
/// returns true; true if it did.
fn fill_holes(
    parts: &[Part],
    text: &[char],
    caps: &mut Captures,
    found: &mut dyn FnMut(&Captures) -> bool,
) -> bool {
    let Some((part, rest)) = parts.split_first() else {
        return text.is_empty() && found(caps);
    };
    let starts = |t: &[char], with: &str| -> Option<usize> {
        let with: Vec<char> = with.chars().collect();
        let same = t.len() >= with.len()
            && t.iter()
                .zip(&with)
                .all(|(a, b)| a.to_lowercase().eq(b.to_lowercase()));
        same.then_some(with.len())
    };
    match part {
        Part::Text(s) => starts(text, s).is_some_and(|n| fill_holes(rest, &text[n..], caps, found)),
        Part::Hole(h) => {
            if let Some((_, v)) = caps.iter().find(|(k, _)| k == h) {
                let n = starts(text, &v.clone());
                return n.is_some_and(|n| fill_holes(rest, &text[n..], caps, found));
            }
            for n in (1..=text.len()).rev() {
                caps.push((h.to_string(), text[..n].iter().collect()));
                let done = fill_holes(rest, &text[n..], caps, found);
                caps.pop();
                if done {
                    return true;
                }
            }
            false
        }
    }
}

/// A template with its placeholders filled in (a template that does not parse is kept).
fn substitute(template: &str, caps: &Captures) -> String {
    let Ok(parts) = template_parts(template) else {
        return template.to_string();
    };
    parts
        .iter()
        .map(|p| match p {
            Part::Text(t) => t.to_string(),
            Part::Hole(h) => caps
                .iter()
                .find(|(k, _)| k == h)
                .map_or_else(|| format!("{{{h}}}"), |(_, v)| v.clone()),
        })
        .collect()
}

// ---------------------------------------------------------------------------------------
// Units, time column and rate

/// The time column and how to read it.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Clock {
    /// Seconds per file unit.
    Time(f64),
    Frame,
}

/// The time column's index and kind, if the profile has one.
fn clock_column(
    path: &Path,
    profile: &CaptureProfile,
    cols: &Columns,
    header_place: &str,
) -> Result<Option<(usize, Clock)>, ImportError> {
    let (r, clock) = match &profile.time {
        TimeColumn::Seconds(r) => (r, Clock::Time(1.0)),
        TimeColumn::Milliseconds(r) => (r, Clock::Time(0.001)),
        TimeColumn::Frame(r) => (r, Clock::Frame),
        TimeColumn::None => return Ok(None),
    };
    let c = cols
        .find(r, None)
        .map_err(|m| ImportError::format(path, header_place, format!("time column: {m}")))?;
    Ok(Some((c, clock)))
}

/// The metres per file unit of each track's X, Y, Z columns, and the unit to report.
struct Scales {
    per_track: Vec<[f64; 3]>,
    file_unit: String,
}

impl Scales {
    /// The unit is the override, else the profile's `unit`, else its `unit_key` value,
    /// else the unit row (per column), else metres.
    fn new(
        path: &Path,
        profile: &CaptureProfile,
        over: Option<LengthUnit>,
        meta: &[MetaEntry],
        unit_row: Option<&Row>,
        tracks: &[TrackCols],
        notes: &mut Vec<String>,
    ) -> Result<Scales, ImportError> {
        let fixed = over.or(profile.length_unit());
        let keyed = match (&profile.unit_key, fixed) {
            (Some(key), None) => keyed_unit(path, key, meta, notes)?,
            _ => None,
        };
        if let Some(u) = fixed.or(keyed) {
            return Ok(Scales::uniform(u, tracks.len()));
        }
        let Some(row) = unit_row else {
            return Ok(Scales::uniform(LengthUnit::Metre, tracks.len()));
        };
        let unit_of = |c: usize| -> Result<LengthUnit, ImportError> {
            let cell = row.cell(c);
            if cell.is_empty() {
                return Ok(LengthUnit::Metre);
            }
            LengthUnit::parse(cell).ok_or_else(|| {
                ImportError::format(
                    path,
                    csv_text::place(row.line, c),
                    format!(
                        "expected a length unit (mm, cm or m) in the unit row, found \"{}\"",
                        csv_text::shorten(cell)
                    ),
                )
            })
        };
        let units: Vec<[LengthUnit; 3]> = tracks
            .iter()
            .map(|t| {
                Ok([
                    unit_of(t.position[0])?,
                    unit_of(t.position[1])?,
                    unit_of(t.position[2])?,
                ])
            })
            .collect::<Result<_, ImportError>>()?;
        Ok(Scales {
            per_track: units.iter().map(|u| u.map(LengthUnit::metres)).collect(),
            file_unit: units.first().map_or("m", |u| u[0].symbol()).to_string(),
        })
    }

    fn uniform(u: LengthUnit, n: usize) -> Scales {
        Scales {
            per_track: vec![[u.metres(); 3]; n],
            file_unit: u.symbol().to_string(),
        }
    }
}

/// The unit `unit_key` gives: `None` (with a note) when the key is absent; an error
/// naming the cell when its value is not a unit.
fn keyed_unit(
    path: &Path,
    key: &str,
    meta: &[MetaEntry],
    notes: &mut Vec<String>,
) -> Result<Option<LengthUnit>, ImportError> {
    let Some(e) = lookup(meta, key) else {
        notes.push(format!(
            "no \"{key}\" entry above the header to give the length unit"
        ));
        return Ok(None);
    };
    LengthUnit::parse(&e.value).map(Some).ok_or_else(|| {
        ImportError::format(
            path,
            format!("line {}, \"{}\"", e.line, e.key),
            format!(
                "expected a length unit (mm, cm or m), found \"{}\"",
                csv_text::shorten(&e.value)
            ),
        )
    })
}

/// The rate the profile or the file states: `rate_hz`, else the `rate_key` value (a key
/// that is absent or not a rate gives a note, and the times decide).
fn stated_rate(
    profile: &CaptureProfile,
    meta: &[MetaEntry],
    notes: &mut Vec<String>,
) -> Option<f64> {
    if let Some(r) = profile.rate_hz {
        return Some(r);
    }
    let key = profile.rate_key.as_ref()?;
    let Some(e) = lookup(meta, key) else {
        notes.push(format!(
            "no \"{key}\" entry above the header to give the frame rate"
        ));
        return None;
    };
    match parse_number(&e.value, e.value.contains(',') && !e.value.contains('.')) {
        Ok(Some(r)) if r > 0.0 => Some(r),
        _ => {
            notes.push(format!(
                "\"{}\" on line {} is \"{}\", not a frame rate",
                e.key,
                e.line,
                csv_text::shorten(&e.value)
            ));
            None
        }
    }
}

/// A cell as a number: `None` for a missing value (empty, `NaN`, `-`); an error message
/// for anything else that is not a finite number.
fn parse_number(cell: &str, decimal_comma: bool) -> Result<Option<f64>, String> {
    let cell = cell.trim();
    if cell.is_empty() || cell == "-" || cell.eq_ignore_ascii_case("nan") {
        return Ok(None);
    }
    let text = if decimal_comma {
        std::borrow::Cow::Owned(cell.replace(',', "."))
    } else {
        std::borrow::Cow::Borrowed(cell)
    };
    match text.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(Some(v)),
        Ok(_) => Err(format!("expected a finite number, found \"{cell}\"")),
        Err(_) => Err(format!(
            "expected a number, found \"{}\"",
            csv_text::shorten(cell)
        )),
    }
}

// ---------------------------------------------------------------------------------------
// Data rows

/// Reads cells of data rows with errors that name the line and column.
struct RowReader<'p> {
    path: &'p Path,
    cols: &'p Columns,
    decimal_comma: bool,
    zero_is_missing: bool,
    /// The table is one section of several: its end is expected, not noted.
    in_section: bool,
}

/// The data as read, one entry per row (before placing rows on the grid).
struct Rows {
    lines: Vec<usize>,
    /// The time column's values (seconds or frame numbers), if any.
    clock: Vec<f64>,
    tracks: Vec<Track>,
}

impl RowReader<'_> {
    /// "line L, column C ("name")".
    fn place(&self, line: usize, col: usize) -> String {
        match self.cols.names.get(col).filter(|n| !n.is_empty()) {
            Some(n) => format!("{} (\"{n}\")", csv_text::place(line, col)),
            None => csv_text::place(line, col),
        }
    }

    fn number(&self, row: &Row, col: usize) -> Result<Option<f64>, ImportError> {
        parse_number(row.cell(col), self.decimal_comma)
            .map_err(|m| ImportError::format(self.path, self.place(row.line, col), m))
    }

    /// The numbers in `cols`, or `None` if any is missing (or, with `zero_is_missing`
    /// and `zeros_count`, if all are 0).
    fn numbers<const N: usize>(
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
    fn read_rows(
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
        };
        let mut after_blank = false;
        for row in &sheet.rows[first..] {
            if row.is_blank() {
                after_blank = true;
                continue;
            }
            if after_blank && !sheet.numeric(row.cell(0)) {
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
            after_blank = false;
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
                self.read_sample(row, t, *scale, out)?;
            }
        }
        if rows.lines.is_empty() {
            return Err(ImportError::format(
                self.path,
                format!("line {}", sheet.rows[first].line),
                "expected data rows below the header, found none",
            ));
        }
        Ok(rows)
    }

    /// Append one row's position (and rotation) of track `t` to `out`.
    fn read_sample(
        &self,
        row: &Row,
        t: &TrackCols,
        scale: [f64; 3],
        out: &mut Track,
    ) -> Result<(), ImportError> {
        let p = self.numbers(row, &t.position, true)?;
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

    fn err(&self, row: &Row, col: usize, message: String) -> ImportError {
        ImportError::format(self.path, self.place(row.line, col), message)
    }
}

/// A unit quaternion from X, Y, Z, W (normalised; its length must be 0.5 to 1.5).
fn quaternion([x, y, z, w]: [f64; 4]) -> Result<DQuat, String> {
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
fn euler(angles: [f64; 3], axes: [DVec3; 3], extrinsic: bool) -> DQuat {
    let r = |i: usize| DQuat::from_axis_angle(axes[i], angles[i]);
    if extrinsic {
        r(2) * r(1) * r(0)
    } else {
        r(0) * r(1) * r(2)
    }
}

/// The rotation of a world-from-body matrix given row-major; it must be orthonormal
/// (to 0.01) and right-handed.
fn matrix(m: [f64; 9]) -> Result<DQuat, String> {
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

// ---------------------------------------------------------------------------------------
// The frame grid

/// Frames beyond this many times the rows (and 100 000) are refused as a broken time.
const MAX_GAP_FACTOR: usize = 10;

/// Each row's frame on the uniform grid, and the rate.
struct Grid {
    index: Vec<usize>,
    frames: usize,
    rate_hz: f64,
}

impl Grid {
    /// Place the rows: by time at the stated rate (or the rate the times give), by frame
    /// number, or one frame per row. Dropped frames are noted.
    fn place(
        path: &Path,
        rows: &Rows,
        clock: Option<Clock>,
        stated: Option<f64>,
        notes: &mut Vec<String>,
    ) -> Result<Grid, ImportError> {
        let no_rate = |what: &str| {
            ImportError::format(
                path,
                "frame rate",
                format!(
                    "expected a frame rate, found none: {what}; set `rate_hz` (or `rate_key`) in \
                     the profile"
                ),
            )
        };
        let (index, rate_hz) = match clock {
            None => {
                let rate = stated.ok_or_else(|| no_rate("the profile has no time column"))?;
                ((0..rows.lines.len()).collect(), rate)
            }
            Some(Clock::Frame) => {
                let rate = stated.ok_or_else(|| no_rate("a frame-number column gives no time"))?;
                (frame_numbers(path, rows)?, rate)
            }
            Some(Clock::Time(unit)) => {
                let times: Vec<f64> = rows.clock.iter().map(|t| t * unit).collect();
                check_increasing(path, rows, &times)?;
                let rate = match stated {
                    Some(r) => r,
                    None => rate_from_times(path, rows, &times, notes)?,
                };
                (time_steps(path, rows, &times, rate)?, rate)
            }
        };
        let frames = index.last().map_or(0, |&i| i + 1);
        let dropped = frames - rows.lines.len();
        if dropped > 0 {
            let s = if dropped == 1 { " was" } else { "s were" };
            notes.push(format!(
                "{dropped} dropped frame{s} filled as gaps ({frames} frames from {} rows)",
                rows.lines.len()
            ));
        }
        Ok(Grid {
            index,
            frames,
            rate_hz,
        })
    }

    /// Each track's samples spread onto the grid (`None` in dropped frames).
    fn scatter(&self, tracks: Vec<Track>) -> Vec<Track> {
        tracks
            .into_iter()
            .map(|t| Track {
                label: t.label,
                positions: self.spread(t.positions),
                rotations: self.spread(t.rotations),
            })
            .collect()
    }

    /// One sample per row spread onto the grid; no samples stay none (plain markers).
    fn spread<T: Copy>(&self, samples: Vec<Option<T>>) -> Vec<Option<T>> {
        if samples.is_empty() {
            return samples;
        }
        let mut out = vec![None; self.frames];
        for (&i, s) in self.index.iter().zip(samples) {
            out[i] = s;
        }
        out
    }
}

/// Refuse a grid far larger than the rows (a broken time or frame column).
fn check_span(path: &Path, rows: &Rows, row: usize, frame: usize) -> Result<(), ImportError> {
    let limit = rows.lines.len().saturating_mul(MAX_GAP_FACTOR).max(100_000);
    if frame > limit {
        return Err(ImportError::format(
            path,
            format!("line {}", rows.lines[row]),
            format!(
                "expected a continuous capture, found a jump to frame {frame} after only {} rows",
                row + 1
            ),
        ));
    }
    Ok(())
}

/// Frame numbers minus the first: whole numbers, increasing.
fn frame_numbers(path: &Path, rows: &Rows) -> Result<Vec<usize>, ImportError> {
    let first = rows.clock[0];
    let mut out: Vec<usize> = Vec::with_capacity(rows.clock.len());
    for (k, &f) in rows.clock.iter().enumerate() {
        let at = format!("line {}", rows.lines[k]);
        let d = f - first;
        if (d - d.round()).abs() > 1e-6 {
            return Err(ImportError::format(
                path,
                at,
                format!("expected a whole frame number, found {f}"),
            ));
        }
        let prev = out.last().copied();
        if d < 0.0 || prev.is_some_and(|p| d.round() as usize <= p) {
            return Err(ImportError::format(
                path,
                at,
                format!(
                    "expected a frame number after the previous row's, found {f} (duplicate or backwards)"
                ),
            ));
        }
        let frame = d.round() as usize;
        check_span(path, rows, k, frame)?;
        out.push(frame);
    }
    Ok(out)
}

/// Refuse a time that repeats or goes back.
fn check_increasing(path: &Path, rows: &Rows, times: &[f64]) -> Result<(), ImportError> {
    for (k, w) in times.windows(2).enumerate() {
        if w[1] <= w[0] {
            return Err(ImportError::format(
                path,
                format!("line {}", rows.lines[k + 1]),
                format!(
                    "expected a time after the previous row's {} s, found {} s (duplicate or \
                     backwards)",
                    w[0], w[1]
                ),
            ));
        }
    }
    Ok(())
}

/// Each row's frame: the previous row's plus round(Δt · rate), the step within a quarter
/// frame of a whole number of frames.
fn time_steps(
    path: &Path,
    rows: &Rows,
    times: &[f64],
    rate: f64,
) -> Result<Vec<usize>, ImportError> {
    let mut out = vec![0usize];
    for (k, w) in times.windows(2).enumerate() {
        let steps = (w[1] - w[0]) * rate;
        let n = steps.round();
        if n < 1.0 || (steps - n).abs() > 0.25 {
            return Err(ImportError::format(
                path,
                format!("line {}", rows.lines[k + 1]),
                format!(
                    "expected a time step of a whole number of frames at {rate} Hz, found {:.6} s \
                     ({steps:.2} frames) from the previous row",
                    w[1] - w[0]
                ),
            ));
        }
        let frame = out[k].saturating_add(n as usize);
        check_span(path, rows, k + 1, frame)?;
        out.push(frame);
    }
    Ok(out)
}

/// The rate from increasing times: 1 / the median step, refined over the whole take and
/// rounded (a whole Hz within 0.1 %, else 0.01 Hz); noted.
fn rate_from_times(
    path: &Path,
    rows: &Rows,
    times: &[f64],
    notes: &mut Vec<String>,
) -> Result<f64, ImportError> {
    if times.len() < 2 {
        return Err(ImportError::format(
            path,
            format!("line {}", rows.lines[0]),
            "expected at least two data rows to know the frame rate from the times (or a \
             `rate_hz` in the profile), found one",
        ));
    }
    let mut steps: Vec<f64> = times.windows(2).map(|w| w[1] - w[0]).collect();
    steps.sort_by(f64::total_cmp);
    let median = steps[steps.len() / 2];
    let frames: f64 = times
        .windows(2)
        .map(|w| ((w[1] - w[0]) / median).round().max(1.0))
        .sum();
    let raw = frames / (times[times.len() - 1] - times[0]);
    let rate = if (raw - raw.round()).abs() <= 1e-3 * raw {
        raw.round()
    } else {
        (raw * 100.0).round() / 100.0
    };
    notes.push(format!(
        "frame rate {rate} Hz from the time column (median step {:.4} ms): no rate was given",
        median * 1000.0
    ));
    Ok(rate)
}

// ---------------------------------------------------------------------------------------
// Display

impl fmt::Display for TableLayout {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let lines: Vec<String> = self.header_lines.iter().map(ToString::to_string).collect();
        writeln!(
            f,
            "delimiter {:?}, decimal {}, header line(s) {}{}, data from line {}",
            self.delimiter,
            if self.decimal_comma { "comma" } else { "point" },
            lines.join(", "),
            self.unit_line
                .map_or(String::new(), |u| format!(", unit row line {u}")),
            self.data_line
        )?;
        if !self.metadata.is_empty() {
            writeln!(f, "metadata:")?;
            for m in &self.metadata {
                writeln!(
                    f,
                    "  line {:>3}: {} = {}",
                    m.line,
                    m.key,
                    m.values.join(" | ")
                )?;
            }
        }
        writeln!(f, "columns:")?;
        for c in &self.columns {
            let unit = c.unit.as_deref().filter(|u| !u.is_empty());
            let unit = unit.map_or(String::new(), |u| format!(" [{u}]"));
            writeln!(
                f,
                "  #{:<4} {:<32}{unit} {}",
                c.index,
                format!("\"{}\"", c.name),
                c.first_value
            )?;
        }
        writeln!(f, "tracks:")?;
        for t in &self.tracks {
            let [x, y, z] = t.position;
            write!(f, "  {}: position #{x} #{y} #{z}", t.label)?;
            if let Some((kind, cols)) = &t.orientation {
                let cols: Vec<String> = cols.iter().map(|c| format!("#{c}")).collect();
                write!(f, ", {kind} {}", cols.join(" "))?;
            }
            writeln!(f)?;
        }
        for p in &self.problems {
            writeln!(f, "problem: {p}")?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kit::Side;
    use crate::mocap::import::{Format, read_bytes};

    const MOTIVE: &[u8] =
        include_bytes!("../../../tests/fixtures/capture/motive_two_sticks_120hz.csv");
    const VICON: &[u8] = include_bytes!("../../../tests/fixtures/capture/vicon_nexus_100hz.csv");
    const QTM_3D: &[u8] = include_bytes!("../../../tests/fixtures/capture/qualisys_3d_200hz.tsv");
    const QTM_6D: &[u8] = include_bytes!("../../../tests/fixtures/capture/qualisys_6d_100hz.tsv");
    const TRC: &[u8] = include_bytes!("../../../tests/fixtures/capture/opensim_walk.trc");
    const PLAIN: &[u8] =
        include_bytes!("../../../tests/fixtures/capture/plain_two_sticks_250hz.csv");

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
        let bytes = include_bytes!("../../../tests/fixtures/motive/timpani_roll_250hz.csv");
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
        let bytes = include_bytes!("../../../tests/fixtures/vicon/timpani_strokes_100hz.csv");
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
        let bytes = include_bytes!("../../../tests/fixtures/csv/two_sticks_250hz.csv");
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
