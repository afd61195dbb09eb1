//! What each drum is tuned to for a score: the pitch its beats name (`Beat::pitch`; a
//! beat naming none plays the drum as it is tuned then). A drum starts at the pitch of
//! its earliest beat that names one — its head's tension set by `Drum::retuned` (f ∝ √T),
//! so the simulated membrane, the contact and every sound model play it; a drum no beat
//! names a pitch for keeps the kit tuning. A later beat naming another pitch is a pedal
//! change ([`pedal_changes`]): the player damps the head after the drum's last stroke at
//! the old pitch and retunes it [`RETUNE_LEAD_S`] before the beat (half-way between them
//! when they are closer), a [`Retune`] the mechanics and the sound carry out.

use super::Score;
use crate::base::pitch::Pitch;
use crate::kit::{Kit, Retune};
use std::borrow::Cow;

/// The new pitch holds this long before the first beat asking for it, s.
pub const RETUNE_LEAD_S: f64 = 0.1;
/// ... and at least this long, however close the strokes (a stroke's contact may come a
/// few milliseconds early), s.
pub const RETUNE_MARGIN_S: f64 = 0.01;
/// A pedal change with less time than this after the drum's last stroke is flagged as
/// quick: the head must be damped and the pedal moved in between, s.
pub const QUICK_PEDAL_S: f64 = 0.5;

/// A beat asking its drum for another pitch than it plays just before: a pedal change.
#[derive(Clone, Debug, PartialEq)]
pub struct PedalChange {
    /// Index of the beat in the score.
    pub beat: usize,
    pub drum: usize,
    /// The pitch the drum played before.
    pub from: Pitch,
    /// What the beat asks.
    pub to: Pitch,
    /// Score time of the drum's previous stroke (a roll's last), s.
    pub after_s: f64,
    /// Score time of the beat, s.
    pub before_s: f64,
}

impl PedalChange {
    /// Time the player has for the change, s.
    pub fn gap_s(&self) -> f64 {
        self.before_s - self.after_s
    }

    /// Whether the change has less than [`QUICK_PEDAL_S`].
    pub fn is_quick(&self) -> bool {
        self.gap_s() < QUICK_PEDAL_S
    }

    /// The retuning the performance carries out for it.
    pub fn retune(&self) -> Retune {
        let gap = self.gap_s().max(0.0);
        Retune {
            drum: self.drum,
            at_s: (self.before_s - RETUNE_LEAD_S)
                .max(self.after_s + 0.5 * gap)
                .min(self.before_s - RETUNE_MARGIN_S),
            after_s: self.after_s,
            pitch: self.to,
        }
    }
}

impl std::fmt::Display for PedalChange {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "beat {}: drum {} is retuned from {} to {} in the {:.2} s before it",
            self.beat,
            self.drum,
            self.from,
            self.to,
            self.gap_s()
        )?;
        if self.is_quick() {
            write!(
                f,
                " (a quick change: under {QUICK_PEDAL_S} s to damp the head and move the pedal)"
            )?;
        }
        Ok(())
    }
}

/// Per drum of `kit`, the pitch it starts `score` at: that of its earliest beat naming
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

/// `kit` with each drum retuned to the pitch it starts `score` at (borrowed as it is when
/// every drum keeps its kit tuning).
pub fn tuned<'k>(score: &Score, kit: Cow<'k, Kit>) -> Cow<'k, Kit> {
    let pitches = drum_pitches(score, &kit);
    if pitches.iter().zip(&kit.drums).all(|(p, d)| *p == d.tuning) {
        return kit;
    }
    let mut kit = kit.into_owned();
    for (drum, pitch) in kit.drums.iter_mut().zip(pitches) {
        *drum = drum.retuned(pitch);
    }
    Cow::Owned(kit)
}

/// The pedal changes `score` asks of `kit` (as it plays the score: [`tuned`], which is
/// done here when it is not already), in time order: each beat naming another pitch than
/// its drum plays just before it.
pub fn pedal_changes(score: &Score, kit: &Kit) -> Vec<PedalChange> {
    walk(score, kit).0
}

/// The pitch each beat of `score` sounds on `kit` (tuned to it as [`pedal_changes`]
/// does): its own, else the one its drum is tuned to then (the kit tuning for a beat on a
/// drum the kit lacks).
pub fn sounding_pitches(score: &Score, kit: &Kit) -> Vec<Pitch> {
    walk(score, kit).1
}

/// The beats of `score` in time order on `kit` (tuned as [`pedal_changes`] does), each
/// drum's pitch followed through them: the pedal changes and the pitch each beat sounds
/// ([`pedal_changes`] and [`sounding_pitches`] in one pass).
pub fn walk(score: &Score, kit: &Kit) -> (Vec<PedalChange>, Vec<Pitch>) {
    let kit = tuned(score, Cow::Borrowed(kit));
    let map = score.tempo_map();
    let mut order: Vec<usize> = (0..score.beats.len()).collect();
    order.sort_by_key(|&i| score.beats[i].tick);
    // Per drum: the pitch it plays and when its latest stroke is (s).
    let mut now: Vec<(Pitch, Option<f64>)> = kit.drums.iter().map(|d| (d.tuning, None)).collect();
    let mut changes = Vec::new();
    let mut sounding: Vec<Pitch> = score
        .beats
        .iter()
        .map(|b| {
            b.pitch
                .unwrap_or_else(|| kit.drums.get(b.drum).map_or(Pitch(0), |d| d.tuning))
        })
        .collect();
    for i in order {
        let beat = &score.beats[i];
        let Some((pitch, last_end)) = now.get_mut(beat.drum) else {
            continue;
        };
        let before_s = map.seconds_at(beat.tick as f64);
        if let (Some(asked), Some(after_s)) = (beat.pitch, *last_end)
            && asked != *pitch
        {
            changes.push(PedalChange {
                beat: i,
                drum: beat.drum,
                from: *pitch,
                to: asked,
                after_s,
                before_s,
            });
        }
        *pitch = beat.pitch.unwrap_or(*pitch);
        sounding[i] = *pitch;
        let last_tick = (beat.stroke_ticks(score.ticks_per_quarter).last()).unwrap_or(beat.tick);
        let last_s = map.seconds_at(last_tick as f64);
        *last_end = Some(last_end.map_or(last_s, |e| e.max(last_s)));
    }
    (changes, sounding)
}

/// Leave out the pitches of `beats` (each naming the pitch it sounds) that say nothing:
/// those on a drum all of whose beats sound its `kit` tuning. A drum retuned anywhere
/// keeps every beat's pitch, since a beat naming none sounds the drum's pitch then.
pub fn drop_needless_pitches(beats: &mut [super::Beat], kit: &Kit) {
    for (d, drum) in kit.drums.iter().enumerate() {
        let on = |b: &&mut super::Beat| b.drum == d;
        if beats
            .iter_mut()
            .filter(on)
            .all(|b| b.pitch.is_none_or(|p| p == drum.tuning))
        {
            beats.iter_mut().filter(on).for_each(|b| b.pitch = None);
        }
    }
}

/// The retunings that carry out `score`'s pedal changes on `kit` (as [`pedal_changes`]),
/// in time order.
pub fn retunes(score: &Score, kit: &Kit) -> Vec<Retune> {
    let mut retunes: Vec<Retune> = pedal_changes(score, kit)
        .iter()
        .map(PedalChange::retune)
        .collect();
    retunes.sort_by(|a, b| a.at_s.total_cmp(&b.at_s));
    retunes
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
    fn a_pedal_change_retunes_the_drum_between_its_strokes() {
        let kit = Kit::standard();
        // Listed out of time order: the earliest beat naming a pitch (tick 480) sets the
        // start; the beat at tick 0 names none and plays the drum as it starts. At 100 bpm
        // and 480 ticks per quarter a quarter is 0.6 s.
        let mut s = score(&[
            (1920, 1, Some("C3")),
            (480, 1, Some("A2")),
            (0, 1, None),
            (960, 1, Some("A2")),
            (2400, 1, None),
            (2880, 1, Some("A2")),
        ]);
        s.ticks_per_quarter = 480;
        let quarter = 60.0 / s.tempo_map().bpm_at(0.0);
        let a2: Pitch = "A2".parse().unwrap();
        let c3: Pitch = "C3".parse().unwrap();
        assert_eq!(drum_pitches(&s, &kit)[1], a2);
        let tuned = tuned(&s, Cow::Borrowed(&kit));
        let changes = pedal_changes(&s, &tuned);
        let got: Vec<(usize, Pitch, Pitch)> =
            changes.iter().map(|c| (c.beat, c.from, c.to)).collect();
        // C3 at tick 1920, kept by the beat naming none, then back to A2.
        assert_eq!(got, [(0, a2, c3), (5, c3, a2)]);
        let first = &changes[0];
        assert!((first.after_s - 2.0 * quarter).abs() < 1e-9, "{first:?}");
        assert!((first.before_s - 4.0 * quarter).abs() < 1e-9, "{first:?}");
        assert!(!first.is_quick());
        let retunes = retunes(&s, &tuned);
        assert_eq!(retunes.len(), 2);
        assert!((retunes[0].at_s - (4.0 * quarter - RETUNE_LEAD_S)).abs() < 1e-9);
        assert_eq!((retunes[0].drum, retunes[0].pitch), (1, c3));
        assert!(first.to_string().contains("from A2 to C3"), "{first}");
        // The kit as it is, untuned, gives the same.
        assert_eq!(pedal_changes(&s, &kit), changes);
    }

    #[test]
    fn a_quick_pedal_change_is_flagged_and_retuned_half_way() {
        let kit = Kit::standard();
        // Two sixteenths apart at 100 bpm: 0.15 s.
        let mut s = score(&[(0, 2, Some("D3")), (120, 2, Some("E3"))]);
        s.ticks_per_quarter = 480;
        let changes = pedal_changes(&s, &kit);
        assert_eq!(changes.len(), 1);
        assert!(changes[0].is_quick());
        assert!(changes[0].to_string().contains("quick"));
        let r = changes[0].retune();
        assert!((r.at_s - 0.5 * changes[0].before_s).abs() < 1e-9, "{r:?}");
    }
}
