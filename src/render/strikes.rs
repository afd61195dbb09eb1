//! Which simulated contact is which scored stroke, and the per-contact event records
//! (`timpanist render --events`): a stroke's contact is the first strong touch of its
//! hand on its drum near its scheduled time; other touches (rebounds, double bounces) are
//! events with no beat, and the strong ones after a stroke's contact count as its
//! *re-contacts* (the stick falling back onto the head: heard as a buzz or a flam).
//! Also the per-dynamic force report of `timpanist render --stats`.

use crate::drum::ContactEvent;
use crate::kit::Side;
use crate::motion::plan::PlannedStroke;
use serde::Serialize;

/// Farthest a contact may be from its stroke's time to count as that stroke's, s (also
/// never more than half the gap to the hand's neighbouring strokes).
pub const MATCH_WINDOW_S: f64 = 0.06;

/// A stroke's contact is the first touch in its window whose peak force is at least this fraction
/// of the strongest there (a weaker earlier one is a graze; later ones are bounces).
const MAIN_FRACTION: f64 = 0.2;

/// A touch after a stroke's contact counts as a re-contact from this peak force, N.
pub const RECONTACT_MIN_N: f64 = 5.0;

/// One contact of a stick with a head, as written by `--events` (times in score seconds).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct StrikeEvent {
    /// The scored beat it plays (index into the score's beats), `null` for a rebound.
    pub beat: Option<usize>,
    pub hand: &'static str,
    /// Drum index in the kit.
    pub drum: usize,
    /// When the stroke was scored, s (`null` for a rebound).
    pub scheduled_s: Option<f64>,
    /// When the felt first touched, s.
    pub contact_s: f64,
    pub duration_ms: f64,
    pub peak_force_n: f64,
    /// Downward tip speed at first touch, m/s.
    pub impact_speed_mps: f64,
    /// Where it first touched, performer frame, m.
    pub x_m: f64,
    pub y_m: f64,
    /// For a stroke's contact: the touches of at least [`RECONTACT_MIN_N`] by the same
    /// stick on the same drum after it and before the hand's next stroke (0 for a clean
    /// stroke; always 0 for a rebound's own event).
    pub recontacts: usize,
    /// The stroke's playing mode and nearest dynamic marking (`null` for a rebound).
    pub mode: Option<&'static str>,
    pub dynamic: Option<&'static str>,
}

/// For each stroke, the index of its contact in `contacts` (whose times are in score
/// seconds), or `None` if the stick never touched its drum near its time.
pub fn match_strokes(strokes: &[PlannedStroke], contacts: &[ContactEvent]) -> Vec<Option<usize>> {
    match_range(strokes, 0..strokes.len(), contacts, 0)
}

/// [`match_strokes`] for the strokes `which` only, among the contacts from index `from`
/// on (returned indices are into all of `contacts`); the other strokes still narrow the
/// windows.
pub fn match_range(
    strokes: &[PlannedStroke],
    which: std::ops::Range<usize>,
    contacts: &[ContactEvent],
    from: usize,
) -> Vec<Option<usize>> {
    let mut claimed = vec![false; contacts.len()];
    strokes[which.clone()]
        .iter()
        .zip(which)
        .map(|(s, i)| {
            let neighbour_gap = strokes
                .iter()
                .enumerate()
                .filter(|&(j, o)| j != i && o.hand == s.hand)
                .map(|(_, o)| (o.time_s - s.time_s).abs())
                .fold(f64::INFINITY, f64::min);
            let window = MATCH_WINDOW_S.min(0.5 * neighbour_gap);
            let near: Vec<usize> = (from.min(contacts.len())..contacts.len())
                .filter(|&c| {
                    let e = &contacts[c];
                    !claimed[c]
                        && e.side == s.hand
                        && e.drum == s.drum
                        && (e.start_s - s.time_s).abs() <= window
                })
                .collect();
            let strongest = near
                .iter()
                .map(|&c| contacts[c].peak_force_n)
                .fold(0.0, f64::max);
            let found = near
                .into_iter()
                .find(|&c| contacts[c].peak_force_n >= MAIN_FRACTION * strongest);
            if let Some(c) = found {
                claimed[c] = true;
            }
            found
        })
        .collect()
}

impl StrikeEvent {
    /// The contact as the hit writers take it (`io::midi_performed`, `io::osc`): primary
    /// when it is a scored stroke's own contact.
    pub fn hit(&self) -> crate::base::hit::Hit {
        crate::base::hit::Hit {
            time_s: self.contact_s,
            drum: self.drum,
            side: if self.hand == "left" {
                Side::Left
            } else {
                Side::Right
            },
            x_m: self.x_m,
            y_m: self.y_m,
            peak_force_n: self.peak_force_n,
            impact_speed_mps: self.impact_speed_mps,
            primary: self.beat.is_some(),
        }
    }
}

/// Every contact as an event, in time order, with its stroke's beat and schedule if it
/// is one.
pub fn events(
    strokes: &[PlannedStroke],
    contacts: &[ContactEvent],
    matches: &[Option<usize>],
) -> Vec<StrikeEvent> {
    let mut stroke_of = vec![None; contacts.len()];
    for (i, m) in matches.iter().enumerate() {
        if let Some(c) = m {
            stroke_of[*c] = Some(i);
        }
    }
    let mut out: Vec<StrikeEvent> = contacts
        .iter()
        .zip(&stroke_of)
        .map(|(c, s)| StrikeEvent {
            beat: s.map(|i| strokes[i].beat),
            hand: match c.side {
                Side::Left => "left",
                Side::Right => "right",
            },
            drum: c.drum,
            scheduled_s: s.map(|i| strokes[i].time_s),
            contact_s: c.start_s,
            duration_ms: c.duration_s() * 1e3,
            peak_force_n: c.peak_force_n,
            impact_speed_mps: c.impact_speed_mps,
            x_m: c.point.x,
            y_m: c.point.y,
            recontacts: 0,
            mode: s.map(|i| strokes[i].mode.name()),
            dynamic: s.map(|i| strokes[i].dynamic.nearest_mark()),
        })
        .collect();
    out.sort_by(|a, b| a.contact_s.total_cmp(&b.contact_s));
    count_recontacts(&mut out);
    out
}

/// Set each stroke event's [`StrikeEvent::recontacts`] (`events` in time order).
fn count_recontacts(events: &mut [StrikeEvent]) {
    for i in 0..events.len() {
        if events[i].beat.is_none() {
            continue;
        }
        let (hand, drum) = (events[i].hand, events[i].drum);
        events[i].recontacts = events[i + 1..]
            .iter()
            .filter(|e| e.hand == hand)
            .take_while(|e| e.beat.is_none())
            .filter(|e| e.drum == drum && e.peak_force_n >= RECONTACT_MIN_N)
            .count();
    }
}

/// The peak forces of the strokes of one dynamic marking.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct DynamicForces {
    /// The nearest marking, e.g. "mf".
    pub dynamic: &'static str,
    pub strokes: usize,
    /// Median peak force of the strokes' contacts, N.
    pub median_n: f64,
    /// The lowest and highest peak force as a fraction of the median (0.8 = 20 % below).
    pub low: f64,
    pub high: f64,
    /// Shortest and longest contact, ms.
    pub shortest_ms: f64,
    pub longest_ms: f64,
    /// Re-contacts after these strokes (see [`StrikeEvent::recontacts`]).
    pub recontacts: usize,
}

/// Per dynamic marking, soft to loud, the force of the strokes that sounded in `events`.
pub fn forces_by_dynamic(events: &[StrikeEvent]) -> Vec<DynamicForces> {
    crate::score::Dynamic::MARKS
        .iter()
        .filter_map(|&(_, _, mark)| {
            let of: Vec<&StrikeEvent> = events.iter().filter(|e| e.dynamic == Some(mark)).collect();
            let mut forces: Vec<f64> = of.iter().map(|e| e.peak_force_n).collect();
            forces.sort_by(f64::total_cmp);
            let median = *forces.get(forces.len() / 2)?;
            let durations = of.iter().map(|e| e.duration_ms);
            Some(DynamicForces {
                dynamic: mark,
                strokes: of.len(),
                median_n: median,
                low: forces[0] / median,
                high: forces[forces.len() - 1] / median,
                shortest_ms: durations.clone().fold(f64::INFINITY, f64::min),
                longest_ms: durations.fold(0.0, f64::max),
                recontacts: of.iter().map(|e| e.recontacts).sum(),
            })
        })
        .collect()
}

/// The beats of the strokes `matches` found no contact for, in the strokes' order, each
/// once (a roll's strokes share their beat).
pub fn missed_beats(strokes: &[PlannedStroke], matches: &[Option<usize>]) -> Vec<usize> {
    let mut beats: Vec<usize> = Vec::new();
    for (stroke, _) in strokes.iter().zip(matches).filter(|(_, m)| m.is_none()) {
        if !beats.contains(&stroke.beat) {
            beats.push(stroke.beat);
        }
    }
    beats
}

/// How well contacts kept time.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Timing {
    pub strokes: usize,
    /// Strokes with no contact.
    pub missed: usize,
    /// Median and worst |contact − scheduled| over the strokes that sounded, s.
    pub median_abs_s: f64,
    pub worst_abs_s: f64,
}

/// Timing of `matches` (contact − scheduled per stroke).
pub fn timing(errors: &[Option<f64>]) -> Timing {
    let mut abs: Vec<f64> = errors.iter().flatten().map(|e| e.abs()).collect();
    abs.sort_by(f64::total_cmp);
    Timing {
        strokes: errors.len(),
        missed: errors.iter().filter(|e| e.is_none()).count(),
        median_abs_s: if abs.is_empty() {
            0.0
        } else if abs.len() % 2 == 1 {
            abs[abs.len() / 2]
        } else {
            0.5 * (abs[abs.len() / 2 - 1] + abs[abs.len() / 2])
        },
        worst_abs_s: abs.last().copied().unwrap_or(0.0),
    }
}

/// contact − scheduled for each stroke, s.
pub fn errors(
    strokes: &[PlannedStroke],
    contacts: &[ContactEvent],
    matches: &[Option<usize>],
) -> Vec<Option<f64>> {
    strokes
        .iter()
        .zip(matches)
        .map(|(s, m)| m.map(|c| contacts[c].start_s - s.time_s))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::score::{Dynamic, PlayingMode};
    use glam::DVec3;

    fn stroke(time_s: f64, hand: Side) -> PlannedStroke {
        PlannedStroke {
            beat: (time_s * 10.0) as usize,
            tick: 0,
            hand,
            time_s,
            target: DVec3::ZERO,
            toward_player: DVec3::NEG_Y,
            drum: 0,
            mode: PlayingMode::Legato,
            dynamic: Dynamic::Mf,
            unit: 0,
        }
    }

    fn contact(start_s: f64, side: Side, peak: f64) -> ContactEvent {
        ContactEvent {
            side,
            drum: 0,
            start_s,
            end_s: start_s + 0.004,
            peak_force_n: peak,
            impact_speed_mps: 2.0,
            point: DVec3::ZERO,
        }
    }

    /// The strong touch near a stroke is its contact; a weak rebound after it and a touch
    /// by the other hand are not; a stroke with nothing near it is missed.
    #[test]
    fn matches_main_contacts_only() {
        let strokes = [
            stroke(1.0, Side::Right),
            stroke(2.0, Side::Right),
            stroke(3.0, Side::Left),
        ];
        let contacts = [
            contact(1.002, Side::Right, 80.0),
            contact(1.030, Side::Right, 10.0),
            contact(2.001, Side::Left, 80.0),
            contact(2.003, Side::Right, 60.0),
        ];
        let m = match_strokes(&strokes, &contacts);
        assert_eq!(m, vec![Some(0), Some(3), None]);
        let e = events(&strokes, &contacts, &m);
        assert_eq!(e.len(), 4);
        assert_eq!(e[1].beat, None);
        assert_eq!(e[0].recontacts, 1, "the 10 N bounce after the first stroke");
        assert_eq!(e[3].recontacts, 0);
        assert_eq!((e[0].mode, e[0].dynamic), (Some("legato"), Some("mf")));
        assert_eq!(e[3].scheduled_s, Some(2.0));
        let t = timing(&errors(&strokes, &contacts, &m));
        assert_eq!((t.strokes, t.missed), (3, 1));
        assert_eq!(missed_beats(&strokes, &m), vec![30]);
        assert!((t.worst_abs_s - 0.003).abs() < 1e-9 && (t.median_abs_s - 0.0025).abs() < 1e-9);
    }
}
