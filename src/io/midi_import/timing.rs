//! The tempo map (µs per quarter to bpm, SMPTE-timed files at a fixed tempo) and the
//! meter map (time signatures at the bars where they fall).

use super::*;

/// The tempo of `us` µs per quarter note in bpm: the whole number or number with three
/// decimals that MIDI writes as `us` if there is one (833333 µs is 72 bpm), else exact.
pub(super) fn bpm_of(us: u32) -> f64 {
    let exact = 60e6 / f64::from(us.max(1));
    [1.0, 1000.0]
        .iter()
        .map(|scale| (exact * scale).round() / scale)
        .find(|bpm| (60e6 / bpm).round() == f64::from(us))
        .unwrap_or(exact)
}

/// Tempo points from (tick, µs per quarter) events: steps, repeats merged, 120 bpm until
/// the first; SMPTE-timed files get 120 bpm throughout. Tempi outside the score's range
/// are clamped, the warning naming the first one's tick and bar on `meter`.
pub(super) fn tempo_points(
    tempos: &[(u64, u32)],
    clock: &Clock,
    meter: &MeterMap,
    warnings: &mut Vec<String>,
) -> Vec<TempoPoint> {
    if matches!(clock, Clock::Timecode { .. }) {
        return tempo::steps(DEFAULT_BPM, []);
    }
    let mut sorted = tempos.to_vec();
    sorted.sort_by_key(|t| t.0);
    let mut clamped = 0;
    let mut first = None;
    let points = tempo::steps(
        DEFAULT_BPM,
        sorted.iter().map(|&(tick, us)| {
            let exact = bpm_of(us);
            let bpm = exact.clamp(*BPM_RANGE.start(), *BPM_RANGE.end());
            if bpm != exact {
                clamped += 1;
                first.get_or_insert((tick, exact));
            }
            (tick, bpm)
        }),
    );
    if let Some((tick, exact)) = first {
        warnings.push(format!(
            "{clamped} tempo events outside {}–{} bpm were clamped into that range (the first, {} bpm, at tick {tick}, {})",
            BPM_RANGE.start(),
            BPM_RANGE.end(),
            (exact * 100.0).round() / 100.0,
            meter.position(tick)
        ));
    }
    points
}

/// Time signatures at the bars where they fall (a signature off a bar line starts at the
/// next one, with a warning); 4/4 if there are none. Repeats are merged and a later
/// signature for the same bar replaces the earlier.
pub(super) fn meter_changes(
    meters: &[(u64, u8, u8)],
    tpq: u32,
    warnings: &mut Vec<String>,
) -> Vec<MeterChange> {
    let mut changes = vec![MeterChange {
        bar: 1,
        numerator: 4,
        denominator: 4,
    }];
    let mut sorted = meters.to_vec();
    sorted.sort_by_key(|m| m.0);
    for (tick, num, pow) in sorted {
        let (numerator, denominator) = (u32::from(num), 1u32.checked_shl(pow.into()).unwrap_or(0));
        let map = MeterMap::new(&changes, tpq);
        let now = map.signature_at(tick);
        if (now.numerator, now.denominator) == (numerator, denominator) {
            continue;
        }
        let at = map.position(tick);
        let on_line = map.is_bar_line(tick);
        let bar = u32::try_from(at.bar + u64::from(!on_line)).unwrap_or(u32::MAX);
        let mut candidate = changes.clone();
        if candidate.last().is_some_and(|c| c.bar == bar) {
            candidate.pop();
        }
        if candidate
            .last()
            .is_none_or(|c| (c.numerator, c.denominator) != (numerator, denominator))
        {
            candidate.push(MeterChange {
                bar,
                numerator,
                denominator,
            });
        }
        if !meter::validate_changes(&candidate, tpq).is_empty() {
            warnings.push(format!(
                "ignored the impossible time signature {numerator}/{denominator} at tick {tick}"
            ));
            continue;
        }
        if !on_line {
            warnings.push(format!(
                "the time signature {numerator}/{denominator} at tick {tick} ({at}) is not on a bar line; it starts at bar {bar}"
            ));
        }
        changes = candidate;
    }
    changes
}
