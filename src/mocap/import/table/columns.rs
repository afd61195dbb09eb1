//! Column names (header rows joined, upper rows carried over empty cells), finding a
//! column by name or number, and the metadata key/values above the header.

use super::*;

/// A header name as displayed: trimmed, whitespace runs collapsed to one space.
pub(super) fn display_name(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// A header name as matched: [`display_name`], lower case.
pub(super) fn key_of(s: &str) -> String {
    display_name(s).to_lowercase()
}

/// The table's column names and their lookup.
pub(super) struct Columns {
    pub(super) names: Vec<String>,
    /// Matching key → first column with it.
    pub(super) keys: HashMap<String, usize>,
}

impl Columns {
    pub(super) fn new(sheet: &Sheet, found: &Located) -> Columns {
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
    pub(super) fn find(&self, r: &str, anchor: Option<usize>) -> Result<usize, String> {
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
    pub(super) fn nearest(&self, name: &str) -> String {
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
pub(super) fn forward_fill<'r>(row: &'r Row, width: usize, fill: bool) -> Vec<&'r str> {
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
pub(super) fn edit_distance(a: &[char], b: &[char]) -> usize {
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
pub(super) fn metadata(rows: &[Row]) -> Vec<MetaEntry> {
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
pub(super) fn meta_numeric(c: &str) -> bool {
    !c.is_empty() && c.replace(',', ".").parse::<f64>().is_ok()
}

/// The number of non-empty cells.
pub(super) fn filled_cells(row: &Row) -> usize {
    row.cells.iter().filter(|c| !c.is_empty()).count()
}

/// Whether `row` is two or more keys (no numbers) and `next` their values: as many
/// cells, the first a number, at least half of them numbers (TRC lines 2 and 3).
pub(super) fn keys_over_values(row: &Row, next: &Row) -> bool {
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
pub(super) fn alternating(row: &Row) -> bool {
    row.cells.len() >= 4
        && !row.cell(0).is_empty()
        && row.cells.iter().step_by(2).all(|c| !meta_numeric(c))
        && row.cells.iter().skip(1).step_by(2).any(|c| meta_numeric(c))
}

/// The value of metadata key `key` (matched like column names), with its entry.
pub(in crate::mocap::import) fn lookup<'m>(
    meta: &'m [MetaEntry],
    key: &str,
) -> Option<&'m MetaEntry> {
    let want = key_of(key);
    meta.iter().find(|e| key_of(&e.key) == want)
}
