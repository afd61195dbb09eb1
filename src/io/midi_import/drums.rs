//! Notes to drums: pitches no drum reaches moved by octaves, each note given a drum as a
//! timpanist would choose it (one tuned to the pitch, else the one idle longest), rolls
//! kept on drums both hands reach and shortened where another beat starts inside them.

use super::*;

/// The pitch fewest octaves from `pitch` (downward on a tie) that `fits`, if any.
pub(super) fn nearest_octave(pitch: Pitch, fits: impl Fn(&Pitch) -> bool) -> Option<Pitch> {
    (1..=10)
        .flat_map(|k| [-12 * k, 12 * k])
        .filter_map(|s| pitch.transposed(s))
        .find(|p| fits(p))
}

/// The pitch nearest by octaves to `pitch` that some drum reaches (fewest octaves,
/// downward on a tie), else the nearest pitch any drum reaches.
pub(super) fn reachable(pitch: Pitch, kit: &Kit) -> Pitch {
    let fits = |p: &Pitch| kit.drums_for(*p).next().is_some();
    nearest_octave(pitch, fits).unwrap_or_else(|| {
        (0..=127)
            .map(Pitch)
            .filter(fits)
            .min_by_key(|p| p.0.abs_diff(pitch.0))
            .expect("a valid kit has a drum")
    })
}

/// Move notes no drum can reach by octaves into a drum's range; one warning sums them up.
/// Returns how many moved.
pub(in crate::io) fn move_into_range(
    notes: &mut [Note],
    kit: &Kit,
    warnings: &mut Vec<String>,
) -> usize {
    let mut moves: BTreeMap<(Pitch, Pitch), usize> = BTreeMap::new();
    for n in notes.iter_mut() {
        let pitch = Pitch(n.key);
        if kit.drums_for(pitch).next().is_none() {
            let to = reachable(pitch, kit);
            *moves.entry((pitch, to)).or_insert(0) += 1;
            n.key = to.0;
        }
    }
    let total = moves.values().sum();
    if total > 0 {
        let list: Vec<String> = moves
            .iter()
            .map(|((from, to), n)| format!("{from} → {to} ×{n}"))
            .collect();
        warnings.push(format!(
            "{total} notes were outside every drum's range and were moved by octaves: {}",
            list.join(", ")
        ));
    }
    total
}

/// Give every note a drum as a timpanist would and make it a beat. Walking in time, each
/// drum keeps its current tuning; a note goes to the drum its data names if that drum
/// reaches it, else, among the drums that reach it (not already struck at this tick if
/// possible; not one whose roll lasts up to this tick when it would have to be retuned;
/// for a roll, which takes both hands, one both hands reach if possible), to one tuned
/// to it, else to the one idle longest since its last note or roll ended (it is
/// retuned), ties to the nearest kit
/// tuning. The notes of one tick choose in order of how few drums reach them, so a chord
/// of F3 and A3 on the standard kit takes the 26- and the 23-inch drum (in score order
/// the F3 took the 23-inch drum, tuned to it, and left the A3, which only the 23-inch
/// drum reaches, on the same drum at the same time). A chord note whose drums are all
/// struck at that tick moves by the fewest octaves to a drum that is free (counted in one
/// warning), as a timpanist would rewrite it.
pub(in crate::io) fn assign_drums(
    notes: &[Note],
    kit: &Kit,
    warnings: &mut Vec<String>,
) -> Vec<Beat> {
    let mut tuning: Vec<Pitch> = kit.drums.iter().map(|d| d.tuning).collect();
    // Per drum, the tick its last note or roll ends.
    let mut busy_until: Vec<Option<u64>> = vec![None; kit.drums.len()];
    let mut drums: Vec<usize> = vec![0; notes.len()];
    let mut keys: Vec<u8> = notes.iter().map(|n| n.key).collect();
    let both_hands_reach = both_hands_reach(kit);
    let mut moves: BTreeMap<(Pitch, Pitch), usize> = BTreeMap::new();
    let mut start = 0;
    while start < notes.len() {
        let tick = notes[start].tick;
        let end = start + notes[start..].iter().take_while(|n| n.tick == tick).count();
        let named = |n: &Note| {
            n.data.map(|d| d.2).filter(|&d| {
                kit.drums
                    .get(d)
                    .is_some_and(|drum| drum.in_range(Pitch(n.key)))
            })
        };
        let mut order: Vec<usize> = (start..end).collect();
        order.sort_by_key(|&i| {
            let n = &notes[i];
            let choices = if named(n).is_some() {
                0
            } else {
                kit.drums_for(Pitch(n.key)).count()
            };
            (choices, i)
        });
        let mut taken: Vec<usize> = Vec::new();
        for i in order {
            let n = &notes[i];
            let mut pitch = Pitch(n.key);
            let free = |p: &Pitch| kit.drums_for(*p).any(|d| !taken.contains(&d));
            let named_drum = named(n);
            if named_drum.is_none()
                && !free(&pitch)
                && let Some(to) = nearest_octave(pitch, free)
            {
                *moves.entry((pitch, to)).or_insert(0) += 1;
                pitch = to;
            }
            let roll = n.data.and_then(|d| d.4);
            // A drum still sounding a roll up to this tick cannot be retuned for it.
            let no_time_to_retune =
                |d: usize| tuning[d] != pitch && busy_until[d].is_some_and(|end| end >= tick);
            let drum = named_drum.unwrap_or_else(|| {
                kit.drums_for(pitch)
                    .min_by_key(|&d| {
                        (
                            taken.contains(&d),
                            no_time_to_retune(d),
                            roll.is_some() && !both_hands_reach[d],
                            tuning[d] != pitch,
                            busy_until[d],
                            kit.drums[d].tuning.0.abs_diff(pitch.0),
                        )
                    })
                    .expect("notes were moved into a drum's range")
            });
            tuning[drum] = pitch;
            busy_until[drum] = Some(tick + roll.map_or(0, |r| r.length_ticks));
            taken.push(drum);
            (drums[i], keys[i]) = (drum, pitch.0);
        }
        start = end;
    }
    if !moves.is_empty() {
        let list: Vec<String> = moves
            .iter()
            .map(|((from, to), n)| format!("{from} → {to} ×{n}"))
            .collect();
        warnings.push(format!(
            "{} chord notes had no free drum that reaches them at once and were moved by \
             octaves: {}",
            moves.values().sum::<usize>(),
            list.join(", ")
        ));
    }
    let mut beats: Vec<Beat> = notes
        .iter()
        .zip(drums.into_iter().zip(keys))
        .map(|(n, (drum, key))| {
            let data = n.data.unwrap_or(BeatData(
                Hand::Auto,
                PlayingMode::Legato,
                drum,
                ImpactLocation::PlayingSpot,
                None,
                None,
            ));
            Beat {
                tick: n.tick,
                hand: data.0,
                mode: data.1,
                dynamic: Dynamic::from_midi_velocity(n.vel),
                drum,
                pitch: Some(Pitch(key)),
                location: data.3,
                roll: data.4,
                // A MIDI note's length says nothing reliable about damping: it rings
                // unless timpanist's own data says when the hand stops it.
                damp: data.5,
            }
        })
        .collect();
    crate::score::tuning::drop_needless_pitches(&mut beats, kit);
    beats
}

/// Per drum, whether the default player reaches its playing spot with either hand upright
/// (the stretched arm and stick from the shoulder, as the sticking judges it; the renderer
/// also lets the trunk lean toward a far stroke, but a roll is played on a drum both hands
/// reach upright when one holds its pitch).
pub(super) fn both_hands_reach(kit: &Kit) -> Vec<bool> {
    use crate::kit::Side;
    let body = crate::body::skeleton::Skeleton::holding_mallets_of(kit);
    let (r, angle) = ImpactLocation::PlayingSpot.polar();
    kit.drums
        .iter()
        .map(|d| {
            let spot = d.point_on_head(r, angle);
            [Side::Left, Side::Right]
                .into_iter()
                .all(|h| body.reaches(h, spot))
        })
        .collect()
}

/// Shorten rolls that another beat starts inside (a roll takes both hands).
pub(in crate::io) fn trim_rolls(beats: &mut [Beat]) {
    for i in 0..beats.len() {
        let tick = beats[i].tick;
        let next = beats[i + 1..].iter().map(|b| b.tick).find(|&t| t > tick);
        if let (Some(roll), Some(next)) = (&mut beats[i].roll, next) {
            roll.length_ticks = roll.length_ticks.min(next - tick);
        }
    }
}
