//! What each drum is tuned to for a score: the pitch its beats name (`Beat::pitch`; a
//! beat naming none plays the drum as it is tuned). A drum is retuned to the pitch of its
//! earliest beat that names one, for the whole performance — its head's tension set to
//! `Drum::tension_for` that pitch (f ∝ √T), so the simulated membrane, the contact and
//! every sound model play it; a drum no beat names a pitch for keeps the kit tuning. A
//! drum named several pitches (a pedal change within the score) keeps the first: pedal
//! changes are not simulated, and [`pedal_changes`] names the beats that then sound at
//! another pitch than written.

use super::Score;
use crate::base::pitch::Pitch;
use crate::kit::Kit;
use std::borrow::Cow;

/// A beat that asks its drum for another pitch than the one the drum plays the score at.
#[derive(Clone, Debug, PartialEq)]
pub struct PedalChange {
    /// Index of the beat in the score.
    pub beat: usize,
    pub drum: usize,
    /// What the beat asks.
    pub asked: Pitch,
    /// What the drum is tuned to (its first beat's pitch).
    pub played: Pitch,
}

impl std::fmt::Display for PedalChange {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "beat {} asks drum {} for {} but the drum plays the score at {} (its first \
             beat's pitch: pedal changes within a score are not simulated)",
            self.beat, self.drum, self.asked, self.played
        )
    }
}

/// Per drum of `kit`, the pitch it plays `score` at: that of its earliest beat naming
/// one, else the kit tuning.
pub fn drum_pitches(score: &Score, kit: &Kit) -> Vec<Pitch> {
    let mut first: Vec<Option<(u64, Pitch)>> = vec![None; kit.drums.len()];
    for beat in score.beats.iter().filter(|b| b.drum < kit.drums.len()) {
        let (Some(pitch), slot) = (beat.pitch, &mut first[beat.drum]) else {
            continue;
        };
        if slot.is_none_or(|(t, _)| beat.tick < t) {
            *slot = Some((beat.tick, pitch));
        }
    }
    first
        .iter()
        .zip(&kit.drums)
        .map(|(f, d)| f.map_or(d.tuning, |(_, p)| p))
        .collect()
}

/// `kit` with each drum retuned to the pitch it plays `score` at (borrowed as it is when
/// every drum keeps its kit tuning).
pub fn tuned<'k>(score: &Score, kit: Cow<'k, Kit>) -> Cow<'k, Kit> {
    let pitches = drum_pitches(score, &kit);
    if pitches.iter().zip(&kit.drums).all(|(p, d)| *p == d.tuning) {
        return kit;
    }
    let mut kit = kit.into_owned();
    for (drum, pitch) in kit.drums.iter_mut().zip(pitches) {
        if pitch != drum.tuning {
            drum.membrane.tension_n_per_m = drum.tension_for(pitch);
            drum.tuning = pitch;
        }
    }
    Cow::Owned(kit)
}

/// The beats of `score` asking their drum for another pitch than the one it plays the
/// score at (`kit` as the score names it, before [`tuned`]).
pub fn pedal_changes(score: &Score, kit: &Kit) -> Vec<PedalChange> {
    let pitches = drum_pitches(score, kit);
    score
        .beats
        .iter()
        .enumerate()
        .filter(|(_, b)| b.drum < kit.drums.len())
        .filter_map(|(i, b)| {
            let asked = b.pitch?;
            (asked != pitches[b.drum]).then_some(PedalChange {
                beat: i,
                drum: b.drum,
                asked,
                played: pitches[b.drum],
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::score::Beat;

    fn score(beats: &[(u64, usize, Option<&str>)]) -> Score {
        let mut s = Score::new("tuning");
        s.beats = beats
            .iter()
            .map(|&(tick, drum, pitch)| Beat {
                pitch: pitch.map(|p| p.parse().unwrap()),
                ..Beat::plain(tick, drum)
            })
            .collect();
        s
    }

    #[test]
    fn a_drum_takes_the_pitch_its_beats_ask() {
        let kit = Kit::standard();
        // The 32-inch drum (F2 in the kit) asked for D2, the 26-inch left at its D3.
        let s = score(&[(0, 0, Some("D2")), (960, 2, None), (1920, 0, Some("D2"))]);
        let tuned = tuned(&s, Cow::Borrowed(&kit));
        let d2: Pitch = "D2".parse().unwrap();
        assert_eq!(tuned.drums[0].tuning, d2);
        let ratio = tuned.drums[0].membrane.tension_n_per_m / kit.drums[0].membrane.tension_n_per_m;
        let expected = (d2.hz() / kit.drums[0].tuning.hz()).powi(2);
        assert!((ratio - expected).abs() < 1e-12, "{ratio} vs {expected}");
        // The retuned head's membrane predicts its new pitch as the kit's did the old.
        let before = kit.drums[0].membrane_f11_hz() / kit.drums[0].tuning.hz();
        let after = tuned.drums[0].membrane_f11_hz() / d2.hz();
        assert!((before - after).abs() < 1e-9);
        assert_eq!(tuned.drums[1..], kit.drums[1..]);
        assert!(pedal_changes(&s, &kit).is_empty());
    }

    #[test]
    fn a_score_in_the_kit_tuning_borrows_the_kit() {
        let kit = Kit::standard();
        let s = score(&[(0, 1, None), (960, 2, Some("D3"))]);
        assert_eq!(kit.drums[2].tuning.to_string(), "D3");
        assert!(matches!(tuned(&s, Cow::Borrowed(&kit)), Cow::Borrowed(_)));
    }

    #[test]
    fn a_pedal_change_keeps_the_first_pitch_and_names_the_other_beats() {
        let kit = Kit::standard();
        // Listed out of time order: the earliest beat naming a pitch (tick 480) decides; the
        // beat at tick 0 names none and plays the drum as tuned.
        let s = score(&[
            (1920, 1, Some("C3")),
            (480, 1, Some("A2")),
            (0, 1, None),
            (960, 1, Some("A2")),
        ]);
        let a2: Pitch = "A2".parse().unwrap();
        assert_eq!(drum_pitches(&s, &kit)[1], a2);
        let changes = pedal_changes(&s, &kit);
        let asked: Vec<(usize, String)> = changes
            .iter()
            .map(|c| (c.beat, c.asked.to_string()))
            .collect();
        assert_eq!(asked, [(0, "C3".to_string())]);
        assert!(changes.iter().all(|c| c.played == a2 && c.drum == 1));
        assert!(changes[0].to_string().contains("pedal changes"));
    }
}
