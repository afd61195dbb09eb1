//! The length unit, the time or frame column, the rate and the frame count a table
//! states.

use super::*;

/// The time column and how to read it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Clock {
    /// Seconds per file unit.
    Time(f64),
    Frame,
}

/// The time column's index and kind, if the profile has one.
pub(super) fn clock_column(
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
pub(super) struct Scales {
    pub(super) per_track: Vec<[f64; 3]>,
    pub(super) file_unit: String,
}

impl Scales {
    /// The unit is the override, else the profile's `unit`, else its `unit_key` value,
    /// else the unit row (per column), else metres.
    pub(super) fn new(
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

    pub(super) fn uniform(u: LengthUnit, n: usize) -> Scales {
        Scales {
            per_track: vec![[u.metres(); 3]; n],
            file_unit: u.symbol().to_string(),
        }
    }
}

/// The unit `unit_key` gives: `None` (with a note) when the key is absent; an error
/// naming the cell when its value is not a unit.
pub(super) fn keyed_unit(
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
pub(super) fn stated_rate(
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

/// The note when the data rows differ from the frame count the profile's `frames_key`
/// entry states: a file cut short (`frames`, the rows on the grid, short of the count
/// too; its rows are still read), rows dropped inside it, or a header out of date.
pub(super) fn frame_count_note(
    path: &Path,
    profile: &CaptureProfile,
    meta: &[MetaEntry],
    rows: &Rows,
    frames: usize,
) -> Result<Option<String>, ImportError> {
    let Some(key) = &profile.frames_key else {
        return Ok(None);
    };
    let Some((e, stated)) = stated_count(path, meta, key)? else {
        return Ok(None);
    };
    let found = rows.lines.len();
    let last = rows.lines.last().copied().unwrap_or(e.line);
    let says = format!(
        "{} (line {}) says {stated} frames, the file has {found} rows",
        e.key, e.line
    );
    Ok(if found == stated {
        None
    } else if found > stated {
        Some(format!("{says}: the header is out of date"))
    } else if frames < stated {
        Some(format!(
            "{says}, the last on line {last}: it is truncated (the rows present are read)"
        ))
    } else {
        Some(format!(
            "{says}: the missing rows are frames dropped inside it"
        ))
    })
}

/// A whole-number metadata value (`NumMarkers`, `NO_OF_FRAMES`), if the file has the
/// key; an error naming its line when the value is not a whole number.
pub(in crate::mocap::import) fn stated_count<'m>(
    path: &Path,
    meta: &'m [MetaEntry],
    key: &str,
) -> Result<Option<(&'m MetaEntry, usize)>, ImportError> {
    let Some(e) = lookup(meta, key) else {
        return Ok(None);
    };
    let n = e.value.trim().parse::<usize>().map_err(|_| {
        ImportError::format(
            path,
            format!("line {}, \"{}\"", e.line, e.key),
            format!(
                "expected a whole number below {}, found \"{}\"",
                e.key,
                csv_text::shorten(&e.value)
            ),
        )
    })?;
    Ok(Some((e, n)))
}

/// A cell as a number: `None` for a missing value (empty, `NaN` or `-`); an error message
/// for anything else that is not a finite number.
pub(super) fn parse_number(cell: &str, decimal_comma: bool) -> Result<Option<f64>, String> {
    if cell.trim() == "-" {
        return Ok(None);
    }
    csv_text::parse_number(cell, decimal_comma)
}
