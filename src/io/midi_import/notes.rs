//! Cleaning the chosen notes: rolls written out by timpanist data or as runs of even
//! notes, exact duplicates, percussion keys spread over the drums, and at most two notes
//! at a time (a timpanist has two hands).

use super::*;

/// Drop the repeated strokes of rolls described by timpanist data (notes of the same
/// channel and key inside the roll that carry no data of their own).
pub(super) fn skip_roll_strokes(notes: Vec<Note>) -> Vec<Note> {
    let rolls: Vec<(u8, u8, u64, u64)> = notes
        .iter()
        .filter_map(|n| {
            let roll = n.data?.4?;
            Some((n.channel, n.key, n.tick, n.tick + roll.length_ticks))
        })
        .collect();
    notes
        .into_iter()
        .filter(|n| {
            n.data.is_some()
                || !rolls.iter().any(|&(ch, key, start, end)| {
                    n.channel == ch && n.key == key && (start..end).contains(&n.tick)
                })
        })
        .collect()
}

/// Drop duplicate notes (same channel, tick and key; notes carrying timpanist data for
/// different drums are not duplicates), keeping the loudest; sort the rest by time.
/// Returns how many were dropped.
pub(in crate::io) fn drop_duplicates(notes: &mut Vec<Note>) -> usize {
    let before = notes.len();
    let drum = |n: &Note| n.data.map(|d| d.2);
    notes.sort_by_key(|n| (n.tick, n.channel, n.key, drum(n), Reverse(n.vel)));
    notes.dedup_by(|b, a| {
        (a.tick, a.channel, a.key, drum(a)) == (b.tick, b.channel, b.key, drum(b))
    });
    before - notes.len()
}

/// Drums by index, from the lowest kit tuning to the highest.
pub(super) fn drums_low_to_high(kit: &Kit) -> Vec<usize> {
    let mut drums: Vec<usize> = (0..kit.drums.len()).collect();
    drums.sort_by_key(|&d| kit.drums[d].tuning);
    drums
}

/// Turn percussion keys into pitches: the distinct keys, in ascending order, are spread
/// evenly over the drums from low to high, each taking its drum's kit tuning.
pub(super) fn map_percussion(notes: &mut [Note], kit: &Kit) {
    let drums = drums_low_to_high(kit);
    let mut keys: Vec<u8> = notes.iter().map(|n| n.key).collect();
    keys.sort_unstable();
    keys.dedup();
    let (m, d) = (keys.len(), drums.len());
    for n in notes.iter_mut() {
        let j = keys.binary_search(&n.key).expect("every key is listed");
        let slot = if m > 1 {
            (j * (d - 1) + (m - 1) / 2) / (m - 1)
        } else {
            (d - 1) / 2
        };
        n.key = kit.drums[drums[slot]].tuning.0;
    }
}

/// Collapse runs of at least [`MIN_ROLL_NOTES`] notes of one key, evenly spaced (every gap
/// within 1 tick of the first) at most a sixteenth note apart, into their first note with
/// a roll, when the mean spacing is within 1 tick of a whole division of the quarter note
/// into 4–32 strokes and no other note falls inside the roll.
pub(super) fn detect_rolls(notes: &mut Vec<Note>, tpq: u32) {
    let q = u64::from(tpq);
    let ticks: Vec<u64> = notes.iter().map(|n| n.tick).collect();
    let mut by_key: BTreeMap<(u8, u8), Vec<usize>> = BTreeMap::new();
    for (i, n) in notes.iter().enumerate().filter(|(_, n)| n.data.is_none()) {
        by_key.entry((n.channel, n.key)).or_default().push(i);
    }
    let mut remove = vec![false; notes.len()];
    for run_of in by_key.values() {
        let mut start = 0;
        while start + 1 < run_of.len() {
            let gap = |k: usize| ticks[run_of[k + 1]] - ticks[run_of[k]];
            let first_gap = gap(start);
            let mut end = start + 1; // last index of the run in `run_of`
            while end + 1 < run_of.len() && gap(end).abs_diff(first_gap) <= 1 {
                end += 1;
            }
            let (first, last) = (ticks[run_of[start]], ticks[run_of[end]]);
            let count = end - start + 1;
            let mean = (last - first) as f64 / (count - 1) as f64;
            let strokes = (q as f64 / mean).round() as u64;
            let spacing = q / strokes.max(1);
            let inside = ticks.partition_point(|&t| t < last + spacing)
                - ticks.partition_point(|&t| t <= first);
            if count >= MIN_ROLL_NOTES
                && (1..=32).contains(&strokes)
                && q.is_multiple_of(strokes)
                && (spacing as f64 - mean).abs() <= 1.0
                && spacing <= q / 4
                && inside == count - 1
            {
                let head = &mut notes[run_of[start]];
                let roll = Roll {
                    length_ticks: last - first + spacing,
                    strokes_per_quarter: strokes as u32,
                };
                head.data = Some(BeatData(
                    Hand::Auto,
                    PlayingMode::Legato,
                    ANY_DRUM,
                    ImpactLocation::PlayingSpot,
                    Some(roll),
                    None,
                ));
                for &k in &run_of[start + 1..=end] {
                    remove[k] = true;
                }
                start = end + 1;
            } else {
                start = end; // the run's last note may start the next run
            }
        }
    }
    let mut keep = remove.iter().map(|r| !r);
    notes.retain(|_| keep.next().expect("one flag per note"));
}

/// Keep at most the two loudest notes at each tick (a timpanist has two hands), and give
/// two simultaneous strokes different hands if their data names the same one.
pub(in crate::io) fn limit_to_two_hands(notes: &mut Vec<Note>, warnings: &mut Vec<String>) {
    let mut kept = Vec::with_capacity(notes.len());
    let mut crowded = Vec::new();
    for group in notes.chunk_by(|a, b| a.tick == b.tick) {
        let mut group = group.to_vec();
        if group.len() > 2 {
            crowded.push(group[0].tick);
            group.sort_by_key(|n| Reverse(n.vel));
            group.truncate(2);
            group.sort_by_key(|n| (n.channel, n.key));
        }
        if let [a, b] = &mut group[..]
            && let (Some(da), Some(db)) = (&a.data, &mut b.data)
            && da.0 == db.0
            && da.0 != Hand::Auto
        {
            db.0 = Hand::Auto;
        }
        kept.extend(group);
    }
    if let Some(first) = crowded.first() {
        warnings.push(format!(
            "{} times had more than two notes at once (the first at tick {first}); kept the two loudest of each",
            crowded.len()
        ));
    }
    *notes = kept;
}
