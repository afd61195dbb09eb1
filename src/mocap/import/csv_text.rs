//! Text helpers shared by the CSV importers: decoding, splitting lines into cells (CRLF,
//! quoted cells and trailing commas tolerated) and reading numbers and positions with
//! errors that name the line and column.
//!
//! Line and column numbers are 1-based; a column is a CSV cell (field), not a character.
//! A cell that is empty or says `NaN` (any case, as MATLAB, pandas and many lab tools
//! write an unseen marker) holds no value: a position with one is a gap.

use crate::mocap::take::{ImportError, MarkedGaps};
use glam::DVec3;
use std::borrow::Cow;
use std::path::Path;

/// A text capture written with semicolons between cells and decimal commas (what a
/// spreadsheet set to a European locale saves as "CSV"), rewritten with commas between
/// cells and decimal points; `None` for any other text (or bytes that are no UTF-8 text).
/// Told by the first line holding either mark: more semicolons than commas there.
pub(super) fn from_semicolons(bytes: &[u8]) -> Option<Vec<u8>> {
    let text = std::str::from_utf8(bytes).ok()?;
    let first = text.lines().find(|l| l.contains([';', ',']))?;
    (first.matches(';').count() > first.matches(',').count())
        .then(|| text.replace(',', ".").replace(';', ",").into_bytes())
}

/// One line of a CSV file split into cells.
pub(super) struct Row<'a> {
    /// 1-based line number.
    pub line: usize,
    /// The cells, trimmed of surrounding spaces and quotes.
    pub cells: Vec<Cow<'a, str>>,
}

impl Row<'_> {
    /// The cell at 0-based `col`, or "" past the end of the row.
    pub fn cell(&self, col: usize) -> &str {
        self.cells.get(col).map(|c| c.as_ref()).unwrap_or("")
    }

    /// True when every cell is empty (a blank line, or only commas).
    pub fn is_blank(&self) -> bool {
        self.cells.iter().all(|c| c.is_empty())
    }

    /// The number of cells once trailing empty cells are dropped.
    pub fn used_width(&self) -> usize {
        self.cells
            .iter()
            .rposition(|c| !c.is_empty())
            .map_or(0, |i| i + 1)
    }
}

/// The file as text: UTF-8 (invalid sequences replaced), a byte-order mark dropped.
pub(super) fn decode(bytes: &[u8]) -> Cow<'_, str> {
    let bytes = bytes.strip_prefix(b"\xef\xbb\xbf").unwrap_or(bytes);
    String::from_utf8_lossy(bytes)
}

/// Every line of `text`, split into cells; line endings LF or CRLF.
pub(super) fn rows(text: &str) -> impl Iterator<Item = Row<'_>> {
    text.lines().enumerate().map(|(i, l)| Row {
        line: i + 1,
        cells: split_cells(l),
    })
}

/// Every line of `text`, split at `sep` ([`split_cells_on`]); line endings LF or CRLF.
pub(super) fn rows_on(text: &str, sep: Option<char>) -> impl Iterator<Item = Row<'_>> {
    text.lines().enumerate().map(move |(i, l)| Row {
        line: i + 1,
        cells: split_cells_on(l, sep),
    })
}

/// The file as text, whatever its encoding: UTF-16 (little or big endian) when it starts
/// with that byte-order mark; else UTF-8 (a BOM dropped) when it is valid UTF-8; else
/// Windows-1252 (which every byte decodes in, so Latin-1 exports keep their "°" and "é").
pub(super) fn decode_text(bytes: &[u8]) -> Cow<'_, str> {
    let utf16 = |b: &[u8], unit: fn([u8; 2]) -> u16| -> Cow<'_, str> {
        let units = b.chunks_exact(2).map(|c| unit([c[0], c[1]]));
        Cow::Owned(
            char::decode_utf16(units)
                .map(|c| c.unwrap_or(char::REPLACEMENT_CHARACTER))
                .collect(),
        )
    };
    if let Some(rest) = bytes.strip_prefix(b"\xff\xfe") {
        return utf16(rest, u16::from_le_bytes);
    }
    if let Some(rest) = bytes.strip_prefix(b"\xfe\xff") {
        return utf16(rest, u16::from_be_bytes);
    }
    let bytes = bytes.strip_prefix(b"\xef\xbb\xbf").unwrap_or(bytes);
    match std::str::from_utf8(bytes) {
        Ok(s) => Cow::Borrowed(s),
        Err(_) => Cow::Owned(bytes.iter().map(|&b| windows_1252(b)).collect()),
    }
}

/// The character a Windows-1252 byte stands for (the five unassigned bytes map to the C1
/// control of the same number, as browsers do).
fn windows_1252(b: u8) -> char {
    const HIGH: [char; 32] = [
        '€', '\u{81}', '‚', 'ƒ', '„', '…', '†', '‡', 'ˆ', '‰', 'Š', '‹', 'Œ', '\u{8d}', 'Ž',
        '\u{8f}', '\u{90}', '‘', '’', '“', '”', '•', '–', '—', '˜', '™', 'š', '›', 'œ', '\u{9d}',
        'ž', 'Ÿ',
    ];
    match b {
        0x80..=0x9f => HIGH[usize::from(b - 0x80)],
        _ => char::from(b),
    }
}

/// The blank lines among a section's data rows (lines with nothing, or only commas and
/// spaces). Those between two data rows are inside the data: skipped, and counted in a
/// note naming them. Those before the first data row or after the last are not.
#[derive(Debug, Default)]
pub(super) struct BlankLines {
    /// Blank lines since the last data row.
    pending: Vec<usize>,
    /// Blank lines inside the data, in order.
    inside: Vec<usize>,
    /// Each run of blank lines inside the data: its first line and the data row after it.
    runs: Vec<(usize, usize)>,
    /// Whether a data row has been taken.
    seen_data: bool,
}

impl BlankLines {
    /// Whether `row` is blank; if so it is remembered (and to be skipped).
    pub fn skip(&mut self, row: &Row) -> bool {
        let blank = row.is_blank();
        if blank {
            self.pending.push(row.line);
        }
        blank
    }

    /// Whether `row` is a data row, for a reader that takes every line that is not blank
    /// as one: a blank one is remembered ([`BlankLines::skip`]), a data row taken
    /// ([`BlankLines::data_row`]).
    pub fn is_data(&mut self, row: &Row) -> bool {
        if self.skip(row) {
            return false;
        }
        self.data_row(row.line);
        true
    }

    /// The first of the blank lines since the last data row, if any.
    pub fn pending(&self) -> Option<usize> {
        self.pending.first().copied()
    }

    /// A data row on `line` is taken: the blank lines just before it are inside the data,
    /// unless it is the first.
    pub fn data_row(&mut self, line: usize) {
        if let Some(&first) = self.pending.first()
            && self.seen_data
        {
            self.runs.push((first, line));
            self.inside.append(&mut self.pending);
        }
        self.pending.clear();
        self.seen_data = true;
    }

    /// The first of the blank lines skipped just before the data row on `line`, if any.
    pub fn run_before(&self, line: usize) -> Option<usize> {
        self.runs
            .binary_search_by_key(&line, |&(_, row)| row)
            .ok()
            .map(|i| self.runs[i].0)
    }

    /// The note for the blank lines inside `what` ("the data"), if there were any.
    pub fn note(&self, what: &str) -> Option<String> {
        blank_lines_note(&self.inside, what)
    }
}

/// What to add to an error about a data row that does not follow on from the row above
/// it: the first of the blank lines between them, if any ([`BlankLines::run_before`]).
pub(super) fn not_run_on(blank: Option<usize>) -> String {
    blank.map_or(String::new(), |b| {
        format!(" (the rows after the blank line {b} do not run on from those above it)")
    })
}

/// Split one line at commas. A cell in double quotes may hold commas; `""` inside quotes
/// is a quote. Cells are trimmed of spaces and tabs.
pub(super) fn split_cells(line: &str) -> Vec<Cow<'_, str>> {
    split_cells_on(line, Some(','))
}

/// Split one line at `sep`, or at runs of spaces and tabs when `sep` is `None` (then no
/// cell is empty and quotes are not special). With a separator, a cell in double quotes
/// may hold it; `""` inside quotes is a quote. Cells are trimmed of spaces and tabs.
pub(super) fn split_cells_on(line: &str, sep: Option<char>) -> Vec<Cow<'_, str>> {
    let line = line.strip_suffix('\r').unwrap_or(line);
    let Some(sep) = sep else {
        return line.split_whitespace().map(Cow::Borrowed).collect();
    };
    if !line.contains('"') {
        return line.split(sep).map(|c| Cow::Borrowed(c.trim())).collect();
    }
    let mut cells = Vec::new();
    let mut cur = String::new();
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match c {
            '"' if quoted && chars.peek() == Some(&'"') => {
                cur.push('"');
                chars.next();
            }
            '"' => quoted = !quoted,
            c if c == sep && !quoted => {
                cells.push(Cow::Owned(std::mem::take(&mut cur).trim().to_string()))
            }
            _ => cur.push(c),
        }
    }
    cells.push(Cow::Owned(cur.trim().to_string()));
    cells
}

/// "line L, column C" for a 0-based column index.
pub(super) fn place(line: usize, col: usize) -> String {
    format!("line {line}, column {}", col + 1)
}

/// Whether a cell reads as a number (with `.` as the decimal point).
pub(super) fn is_number(cell: &str) -> bool {
    cell.parse::<f64>().is_ok()
}

/// The note for blank `lines` skipped between the data rows of `what` ("the data"):
/// how many, and which (the first five).
fn blank_lines_note(lines: &[usize], what: &str) -> Option<String> {
    const SHOWN: usize = 5;
    let n = lines.len();
    if n == 0 {
        return None;
    }
    let mut list: Vec<String> = lines.iter().take(SHOWN).map(usize::to_string).collect();
    if n > SHOWN {
        list.push("…".to_string());
    }
    let (lines_word, was) = if n == 1 {
        ("line", "was")
    } else {
        ("lines", "were")
    };
    Some(format!(
        "{n} blank {lines_word} inside {what} {was} skipped ({lines_word} {}): the rows after \
         {} continue the frames above",
        list.join(", "),
        if n == 1 { "it" } else { "them" }
    ))
}

/// A cell as a number: `None` when it holds no value (empty, or `NaN` in any case); an
/// error message for anything else that is not a finite number. `decimal_comma`: the
/// cell may be written `1,25`.
pub(super) fn parse_number(cell: &str, decimal_comma: bool) -> Result<Option<f64>, String> {
    let cell = cell.trim();
    if cell.is_empty() || is_nan(cell) {
        return Ok(None);
    }
    let text = if decimal_comma {
        Cow::Owned(cell.replace(',', "."))
    } else {
        Cow::Borrowed(cell)
    };
    match text.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(Some(v)),
        Ok(_) => Err(format!("expected a finite number, found \"{cell}\"")),
        Err(_) => Err(format!("expected a number, found \"{}\"", shorten(cell))),
    }
}

/// Whether a cell says "not a number" (`NaN`, `nan`, `-nan`, …).
pub(super) fn is_nan(cell: &str) -> bool {
    cell.trim().parse::<f64>().is_ok_and(f64::is_nan)
}

/// Whether any of the cells `cols` of `row` says NaN.
pub(super) fn written_nan(row: &Row, cols: &[usize]) -> bool {
    cols.iter().any(|&c| is_nan(row.cell(c)))
}

/// The number in cell `col` of `row`: `None` for an empty (or absent) cell or `NaN`.
pub(super) fn number(path: &Path, row: &Row, col: usize) -> Result<Option<f64>, ImportError> {
    parse_number(row.cell(col), false)
        .map_err(|m| ImportError::format(path, place(row.line, col), m))
}

/// The number in cell `col` of `row`, which must hold one; `what` names it.
pub(super) fn required_number(
    path: &Path,
    row: &Row,
    col: usize,
    what: &str,
) -> Result<f64, ImportError> {
    number(path, row, col)?.ok_or_else(|| {
        let found = match row.cell(col) {
            "" => "an empty cell".to_string(),
            cell => format!("\"{}\"", shorten(cell)),
        };
        ImportError::format(
            path,
            place(row.line, col),
            format!("expected a number ({what}), found {found}"),
        )
    })
}

/// The position in cells `cols` (X, Y, Z) of `row`, times `scale` (metres per file
/// unit): `None` when all three are empty or any says NaN; an error when only some are
/// empty.
pub(super) fn position(
    path: &Path,
    row: &Row,
    cols: [usize; 3],
    scale: f64,
) -> Result<Option<DVec3>, ImportError> {
    let x = number(path, row, cols[0])?;
    let y = number(path, row, cols[1])?;
    let z = number(path, row, cols[2])?;
    if written_nan(row, &cols) {
        return Ok(None);
    }
    match (x, y, z) {
        (Some(x), Some(y), Some(z)) => Ok(Some(DVec3::new(x, y, z) * scale)),
        (None, None, None) => Ok(None),
        _ => {
            let empty = [x, y, z]
                .iter()
                .position(Option::is_none)
                .map_or(cols[0], |i| cols[i]);
            Err(ImportError::format(
                path,
                place(row.line, empty),
                "expected all three coordinates X, Y, Z or none, found this one empty \
                 while others of the same marker are given",
            ))
        }
    }
}

/// [`position`], a sample written as NaN counted in `gaps`.
pub(super) fn sample(
    path: &Path,
    row: &Row,
    cols: [usize; 3],
    scale: f64,
    gaps: &mut MarkedGaps,
) -> Result<Option<DVec3>, ImportError> {
    let p = position(path, row, cols, scale)?;
    if written_nan(row, &cols) {
        gaps.nan += 1;
    }
    Ok(p)
}

/// Check that a data row has the header's `width` cells: fewer means the row was cut
/// short; more is allowed only as empty cells (a trailing comma).
pub(super) fn check_width(path: &Path, row: &Row, width: usize) -> Result<(), ImportError> {
    let first = row.cell(0);
    if row.cells.len() < width && !first.is_empty() && first.parse::<f64>().is_err() {
        return Err(ImportError::format(
            path,
            format!("line {}", row.line),
            format!(
                "expected a data row, found one starting with \"{}\" ({} cells against the \
                 header's {width}): another export pasted after this one? Import each take \
                 from its own file",
                shorten(first),
                row.cells.len()
            ),
        ));
    }
    if row.cells.len() < width {
        return Err(ImportError::format(
            path,
            format!("line {}", row.line),
            format!(
                "expected {width} cells as in the header, found {} (row cut short: is the \
                 file truncated?)",
                row.cells.len()
            ),
        ));
    }
    if row.used_width() > width {
        return Err(ImportError::format(
            path,
            place(row.line, row.used_width() - 1),
            format!(
                "expected at most {width} cells as in the header, found a value past the last \
                 header column"
            ),
        ));
    }
    Ok(())
}

/// `s` cut to a readable length for an error message.
pub(super) fn shorten(s: &str) -> Cow<'_, str> {
    const MAX: usize = 40;
    match s.char_indices().nth(MAX) {
        Some((i, _)) => Cow::Owned(format!("{}…", &s[..i])),
        None => Cow::Borrowed(s),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn splits_quotes_crlf_and_trailing_commas() {
        let cells = split_cells("a, \"b,c\" ,\"d\"\"e\",\r");
        assert_eq!(cells, vec!["a", "b,c", "d\"e", ""]);
        let r = Row {
            line: 3,
            cells: split_cells("1,2,,"),
        };
        assert_eq!(r.used_width(), 2);
        assert!(check_width(Path::new("f"), &r, 3).is_ok());
        assert!(check_width(Path::new("f"), &r, 5).is_err());
        assert!(check_width(Path::new("f"), &r, 1).is_err());
        let pasted = Row {
            line: 56,
            cells: split_cells("Format Version,1.23,Take Name,roll"),
        };
        let e = check_width(Path::new("f"), &pasted, 63)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("line 56") && e.contains("another export pasted"),
            "{e}"
        );
        assert_eq!(shorten("abc"), "abc");
        assert_eq!(shorten(&"é".repeat(50)).chars().count(), 41);
    }

    #[test]
    fn splits_on_other_separators_and_decodes_any_encoding() {
        assert_eq!(
            split_cells_on("a\t\"b\tc\"\t", Some('\t')),
            vec!["a", "b\tc", ""]
        );
        assert_eq!(
            split_cells_on("1;2,5;;", Some(';')),
            vec!["1", "2,5", "", ""]
        );
        assert_eq!(split_cells_on("  1  2\t3 \r", None), vec!["1", "2", "3"]);
        let rows: Vec<_> = rows_on("a b\r\nc", None).collect();
        assert_eq!((rows[1].line, rows[1].cell(0)), (2, "c"));
        assert_eq!(decode_text(b"\xef\xbb\xbfx\xc2\xb0"), "x°");
        assert_eq!(decode_text(b"Winkel \xb0 \x80 \x9d"), "Winkel ° € \u{9d}");
        assert_eq!(decode_text(b"\xff\xfea\x00\xe9\x00"), "aé");
        assert_eq!(decode_text(b"\xfe\xff\x00a\x00\xe9"), "aé");
    }

    #[test]
    fn numbers_name_line_and_column() {
        let r = Row {
            line: 7,
            cells: split_cells("1.5,abc,,inf"),
        };
        let p = Path::new("t.csv");
        assert_eq!(number(p, &r, 0).unwrap(), Some(1.5));
        assert_eq!(number(p, &r, 2).unwrap(), None);
        assert_eq!(number(p, &r, 9).unwrap(), None);
        let e = number(p, &r, 1).unwrap_err().to_string();
        assert_eq!(
            e,
            "t.csv: line 7, column 2: expected a number, found \"abc\""
        );
        assert!(number(p, &r, 3).is_err());
        assert!(required_number(p, &r, 2, "time").is_err());
        assert!(position(p, &r, [0, 2, 2], 1.0).is_err());
        assert_eq!(position(p, &r, [2, 2, 2], 1.0).unwrap(), None);
    }

    #[test]
    fn blank_lines_between_data_rows_are_named_not_those_before_or_after() {
        let text = "\n1,2\n\n ,\t,\n3,4\n5,6\n,,\n";
        let mut blanks = BlankLines::default();
        let data: Vec<usize> = rows(text)
            .filter(|r| blanks.is_data(r))
            .map(|r| r.line)
            .collect();
        assert_eq!(data, [2, 5, 6]);
        assert_eq!(
            [2, 5, 6].map(|line| blanks.run_before(line)),
            [None, Some(3), None]
        );
        assert_eq!(blanks.pending(), Some(7), "the blank line at the end");
        assert_eq!(
            blanks.note("the data").unwrap(),
            "2 blank lines inside the data were skipped (lines 3, 4): the rows after them \
             continue the frames above"
        );
        let many = format!("1\n{}2\n", "\n".repeat(7));
        let mut blanks = BlankLines::default();
        assert_eq!(rows(&many).filter(|r| blanks.is_data(r)).count(), 2);
        assert_eq!(
            blanks.note("the data").unwrap(),
            "7 blank lines inside the data were skipped (lines 2, 3, 4, 5, 6, …): the rows \
             after them continue the frames above"
        );
        assert_eq!(BlankLines::default().note("the data"), None);
    }

    #[test]
    fn nan_cells_hold_no_value_and_make_the_position_a_gap() {
        let r = Row {
            line: 4,
            cells: split_cells("NaN,nan,-NaN,1.5,,x"),
        };
        let p = Path::new("t.csv");
        for col in 0..3 {
            assert!(is_nan(r.cell(col)));
            assert_eq!(number(p, &r, col).unwrap(), None);
        }
        assert!(!is_nan("") && !is_nan("1") && !is_nan("inf"));
        assert_eq!(
            required_number(p, &r, 0, "frame number")
                .unwrap_err()
                .to_string(),
            "t.csv: line 4, column 1: expected a number (frame number), found \"NaN\""
        );
        let mut gaps = MarkedGaps::default();
        assert_eq!(sample(p, &r, [0, 1, 2], 1.0, &mut gaps).unwrap(), None);
        // One NaN coordinate is a gap too; an empty one beside numbers is not.
        assert_eq!(sample(p, &r, [3, 3, 1], 1.0, &mut gaps).unwrap(), None);
        assert!(sample(p, &r, [3, 3, 4], 1.0, &mut gaps).is_err());
        assert_eq!(sample(p, &r, [4, 4, 4], 1.0, &mut gaps).unwrap(), None);
        assert_eq!(gaps.nan, 2);
        assert!(sample(p, &r, [0, 1, 5], 1.0, &mut gaps).is_err(), "x");
    }
}
