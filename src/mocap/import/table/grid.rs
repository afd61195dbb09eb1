//! Placing rows on a uniform frame grid by their time or frame number: dropped frames
//! become gaps, the rate comes from the times when the table does not state it.

use super::*;

/// Frames beyond this many times the rows (and 100 000) are refused as a broken time.
pub(super) const MAX_GAP_FACTOR: usize = 10;

/// Each row's frame on the uniform grid, and the rate.
pub(super) struct Grid {
    pub(super) index: Vec<usize>,
    pub(super) frames: usize,
    pub(super) rate_hz: f64,
}

impl Grid {
    /// Place the rows: by time at the stated rate (or the rate the times give), by frame
    /// number, or one frame per row. Dropped frames are noted.
    pub(super) fn place(
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
    pub(super) fn scatter(&self, tracks: Vec<Track>) -> Vec<Track> {
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
    pub(super) fn spread<T: Copy>(&self, samples: Vec<Option<T>>) -> Vec<Option<T>> {
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
pub(super) fn check_span(
    path: &Path,
    rows: &Rows,
    row: usize,
    frame: usize,
) -> Result<(), ImportError> {
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
pub(super) fn frame_numbers(path: &Path, rows: &Rows) -> Result<Vec<usize>, ImportError> {
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
pub(super) fn check_increasing(path: &Path, rows: &Rows, times: &[f64]) -> Result<(), ImportError> {
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
pub(super) fn time_steps(
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
pub(super) fn rate_from_times(
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
    let median = crate::base::stats::median(times.windows(2).map(|w| w[1] - w[0])).unwrap_or(0.0);
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
