//! The tempo map (`<sound tempo>` and `<metronome>` marks of every part, quarter notes per
//! minute) and the meter map (each bar as long as its measure) of the part.

use super::*;

/// Tempo points from the tempo marks of every part: at one tick the chosen part's mark
/// wins over another part's and a `<sound tempo>` over a metronome mark (the same mark
/// written in several parts is one); 120 bpm until the first; steps; clamped into the
/// score's range. Marks taken from other parts are reported with the first one's place.
pub(super) fn tempo_points(tempos: &[TempoMark], notices: &mut Notices) -> Vec<TempoPoint> {
    let mut sorted = tempos.to_vec();
    sorted.sort_by_key(|m| (m.tick, m.precedence()));
    // The played mark of each tick: the last of its tick.
    sorted.reverse();
    sorted.dedup_by_key(|m| m.tick);
    sorted.reverse();
    for m in &sorted {
        if let Some(place) = &m.other_part {
            notices.add(
                "tempo mark written in another part: played (tempo is the whole score's)",
                place,
            );
        }
    }
    tempo::steps(
        DEFAULT_BPM,
        sorted.into_iter().map(|TempoMark { tick, bpm, .. }| {
            let clamped = bpm.clamp(*BPM_RANGE.start(), *BPM_RANGE.end());
            if clamped != bpm {
                notices.add(
                    format!(
                        "tempo outside {}–{} bpm: clamped",
                        BPM_RANGE.start(),
                        BPM_RANGE.end()
                    ),
                    &format!("score tick {tick}"),
                );
            }
            (tick, clamped)
        }),
    )
}

/// `length` ticks as a time signature (numerator 1–64 over 1–32), preferring `den`.
pub(super) fn signature_of(length: u64, tpq: u64, den: u32) -> Option<(u32, u32)> {
    std::iter::once(den)
        .chain([4, 8, 16, 32, 2, 1])
        .find_map(|d| {
            let whole = 4 * tpq;
            let num = length * u64::from(d);
            num.is_multiple_of(whole)
                .then(|| num / whole)
                .filter(|n| (1..=64).contains(n))
                .map(|n| (n as u32, d))
        })
}

/// Time signatures from the measures: each bar as long as its measure (a pickup or an
/// incomplete measure gets its own signature, so later bars fall where the file's do).
pub(super) fn meter_changes(
    measures: &[Measure],
    tpq: u64,
    notices: &mut Notices,
) -> Vec<MeterChange> {
    let mut changes: Vec<MeterChange> = Vec::new();
    let tpq32 = u32::try_from(tpq).expect("ticks per quarter fit in u32");
    for (i, m) in measures.iter().enumerate() {
        let written = m.signature.unwrap_or((4, 4));
        let nominal = u64::from(written.0) * 4 * tpq / u64::from(written.1);
        let sig = if m.length == nominal {
            Some(written)
        } else {
            let s = signature_of(m.length, tpq, written.1);
            match (s, m.implicit || i == 0) {
                (Some(s), true) => notices.add(
                    format!("pickup measure: its bar is {}/{}", s.0, s.1),
                    &format!("measure {}", m.number),
                ),
                (Some(s), false) if m.signature.is_some() => notices.add(
                    format!(
                        "a measure shorter or longer than its time signature: its bar is {}/{}",
                        s.0, s.1
                    ),
                    &format!("measure {}", m.number),
                ),
                (None, _) => notices.add(
                    "a measure whose length is no time signature: later bar lines are shifted",
                    &format!("measure {}", m.number),
                ),
                _ => {}
            }
            s
        };
        let Some((numerator, denominator)) = sig else {
            continue;
        };
        if changes
            .last()
            .is_none_or(|c| (c.numerator, c.denominator) != (numerator, denominator))
        {
            changes.push(MeterChange {
                bar: u32::try_from(i + 1).unwrap_or(u32::MAX),
                numerator,
                denominator,
            });
        }
    }
    if changes.first().is_none_or(|c| c.bar != 1) {
        changes.insert(
            0,
            MeterChange {
                bar: 1,
                numerator: 4,
                denominator: 4,
            },
        );
    }
    if !meter::validate_changes(&changes, tpq32).is_empty() {
        notices
            .push_text("the measures' time signatures do not fit a score; the meter is 4/4".into());
        changes.truncate(1);
        changes[0] = MeterChange {
            bar: 1,
            numerator: 4,
            denominator: 4,
        };
    }
    changes
}
