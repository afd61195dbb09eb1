//! Undoable changes to a score, as `undo::Edit`s: the editor pushes these into an
//! `undo::Record` so every change can be undone and redone; consecutive moves of the same
//! handle or beat merge, so one drag is one undo step.

use super::{Beat, Handle, ImpactPin, Score, Settings, TempoPoint};

/// One change to a score.
#[derive(Clone, Debug, PartialEq)]
pub enum ScoreEdit {
    /// Insert a beat in time order (after any beat at the same tick).
    AddBeat { beat: Beat, at: Option<usize> },
    /// Remove the beat at `index`.
    RemoveBeat { index: usize, removed: Option<Beat> },
    /// Replace the beat at `index` (re-sorted by tick afterwards).
    SetBeat {
        index: usize,
        before: Option<Beat>,
        after: Beat,
        now_at: Option<usize>,
    },
    /// Add a trajectory handle.
    AddHandle(Handle),
    /// Change handle `index` from `from` to `to`.
    MoveHandle {
        index: usize,
        from: Handle,
        to: Handle,
    },
    /// Remove handle `index`.
    RemoveHandle {
        index: usize,
        removed: Option<Handle>,
    },
    /// Pin (or, with `None`, unpin) the impact of the stroke at (hand, tick).
    SetPin {
        hand: crate::kit::Side,
        tick: u64,
        pin: Option<ImpactPin>,
        before: Option<Option<ImpactPin>>,
    },
    /// Replace the tempo map.
    SetTempo {
        before: Vec<TempoPoint>,
        after: Vec<TempoPoint>,
    },
    /// Replace all beats at once (`after` in time order): a change of several beats
    /// (move, delete, paste, set mode of a selection) as one step.
    SetBeats { before: Vec<Beat>, after: Vec<Beat> },
    /// Replace the performance and sound settings.
    SetSettings { before: Settings, after: Settings },
}

impl ScoreEdit {
    /// A short description for menus ("Undo add handle").
    pub fn describe(&self) -> &'static str {
        match self {
            ScoreEdit::AddBeat { .. } => "add beat",
            ScoreEdit::RemoveBeat { .. } => "delete beat",
            ScoreEdit::SetBeat { .. } => "change beat",
            ScoreEdit::AddHandle(_) => "add handle",
            ScoreEdit::MoveHandle { .. } => "move handle",
            ScoreEdit::RemoveHandle { .. } => "remove handle",
            ScoreEdit::SetPin { .. } => "pin impact",
            ScoreEdit::SetTempo { .. } => "change tempo",
            ScoreEdit::SetBeats { .. } => "change beats",
            ScoreEdit::SetSettings { .. } => "change settings",
        }
    }
}

impl std::fmt::Display for ScoreEdit {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.describe())
    }
}

fn insert_sorted(score: &mut Score, beat: Beat) -> usize {
    let at = score.beats.partition_point(|b| b.tick <= beat.tick);
    score.beats.insert(at, beat);
    at
}

impl undo::Edit for ScoreEdit {
    type Target = Score;
    type Output = ();

    fn edit(&mut self, score: &mut Score) {
        match self {
            ScoreEdit::AddBeat { beat, at } => *at = Some(insert_sorted(score, *beat)),
            ScoreEdit::RemoveBeat { index, removed } => *removed = Some(score.beats.remove(*index)),
            ScoreEdit::SetBeat {
                index,
                before,
                after,
                now_at,
            } => {
                *before = Some(score.beats.remove(*index));
                *now_at = Some(insert_sorted(score, *after));
            }
            ScoreEdit::AddHandle(h) => score.handles.push(*h),
            ScoreEdit::MoveHandle { index, to, .. } => score.handles[*index] = *to,
            ScoreEdit::RemoveHandle { index, removed } => {
                *removed = Some(score.handles.remove(*index))
            }
            ScoreEdit::SetPin {
                hand,
                tick,
                pin,
                before,
            } => {
                let existing = score
                    .pins
                    .iter()
                    .position(|p| p.hand == *hand && p.tick == *tick);
                *before = Some(existing.map(|i| score.pins.remove(i)));
                score.pins.extend(*pin);
            }
            ScoreEdit::SetTempo { after, .. } => score.tempo = after.clone(),
            ScoreEdit::SetBeats { after, .. } => score.beats = after.clone(),
            ScoreEdit::SetSettings { after, .. } => score.settings = after.clone(),
        }
    }

    fn undo(&mut self, score: &mut Score) {
        match self {
            ScoreEdit::AddBeat { at, .. } => {
                if let Some(i) = at.take() {
                    score.beats.remove(i);
                }
            }
            ScoreEdit::RemoveBeat { index, removed } => {
                if let Some(b) = removed.take() {
                    score.beats.insert(*index, b);
                }
            }
            ScoreEdit::SetBeat {
                index,
                before,
                now_at,
                ..
            } => {
                if let (Some(b), Some(i)) = (before.take(), now_at.take()) {
                    score.beats.remove(i);
                    score.beats.insert(*index, b);
                }
            }
            ScoreEdit::AddHandle(_) => {
                score.handles.pop();
            }
            ScoreEdit::MoveHandle { index, from, .. } => score.handles[*index] = *from,
            ScoreEdit::RemoveHandle { index, removed } => {
                if let Some(h) = removed.take() {
                    score.handles.insert(*index, h);
                }
            }
            ScoreEdit::SetPin {
                hand, tick, before, ..
            } => {
                score.pins.retain(|p| !(p.hand == *hand && p.tick == *tick));
                if let Some(Some(old)) = before.take() {
                    score.pins.push(old);
                }
            }
            ScoreEdit::SetTempo { before, .. } => score.tempo = before.clone(),
            ScoreEdit::SetBeats { before, .. } => score.beats = before.clone(),
            ScoreEdit::SetSettings { before, .. } => score.settings = before.clone(),
        }
    }

    /// Consecutive moves of one handle, or changes of one beat that stays in place, or
    /// successive replacements of the beats or the tempo map (each starting where the last
    /// ended), become one step.
    /// (The editor groups edits by gesture on top of this, so two drags stay two steps.)
    fn merge(&mut self, other: Self) -> undo::Merged<Self> {
        match (self, other) {
            (
                ScoreEdit::MoveHandle { index, to, .. },
                ScoreEdit::MoveHandle {
                    index: j,
                    to: new_to,
                    ..
                },
            ) if *index == j => {
                *to = new_to;
                undo::Merged::Yes
            }
            (
                ScoreEdit::SetBeat {
                    now_at: Some(at),
                    after,
                    ..
                },
                ScoreEdit::SetBeat {
                    index,
                    after: new_after,
                    ..
                },
            ) if *at == index && after.tick == new_after.tick => {
                *after = new_after;
                undo::Merged::Yes
            }
            (
                ScoreEdit::SetTempo { after, .. },
                ScoreEdit::SetTempo {
                    before: new_before,
                    after: new_after,
                },
            ) if *after == new_before => {
                *after = new_after;
                undo::Merged::Yes
            }
            (
                ScoreEdit::SetSettings { after, .. },
                ScoreEdit::SetSettings {
                    before: new_before,
                    after: new_after,
                },
            ) if *after == new_before => {
                *after = new_after;
                undo::Merged::Yes
            }
            (
                ScoreEdit::SetBeats { after, .. },
                ScoreEdit::SetBeats {
                    before: new_before,
                    after: new_after,
                },
            ) if *after == new_before => {
                *after = new_after;
                undo::Merged::Yes
            }
            (_, other) => undo::Merged::No(other),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kit::Side;
    use crate::score::{Dynamic, Hand, ImpactLocation, PlayingMode};
    use undo::Record;

    fn beat(tick: u64) -> Beat {
        Beat {
            tick,
            hand: Hand::Auto,
            mode: PlayingMode::Legato,
            dynamic: Dynamic::Mf,
            drum: 0,
            pitch: None,
            location: ImpactLocation::PlayingSpot,
            roll: None,
            damp: None,
        }
    }

    fn handle(z: f64) -> Handle {
        Handle {
            hand: Side::Right,
            tick: 960,
            reach_ticks: 240,
            offset_m: [0.0, 0.0, z],
        }
    }

    /// Add, move (a drag of many small moves) and remove a handle; each is one undo step
    /// and redo restores it.
    #[test]
    fn handle_edits_undo_and_redo() {
        let mut score = Score::new("t");
        let mut record = Record::new();
        record.edit(&mut score, ScoreEdit::AddHandle(handle(0.0)));
        for k in 1..=10 {
            let from = score.handles[0];
            record.edit(
                &mut score,
                ScoreEdit::MoveHandle {
                    index: 0,
                    from,
                    to: handle(0.01 * k as f64),
                },
            );
        }
        assert_eq!(score.handles[0], handle(0.1));
        record.edit(
            &mut score,
            ScoreEdit::RemoveHandle {
                index: 0,
                removed: None,
            },
        );
        assert!(score.handles.is_empty());
        record.undo(&mut score);
        assert_eq!(score.handles, vec![handle(0.1)]);
        record.undo(&mut score);
        assert_eq!(
            score.handles,
            vec![handle(0.0)],
            "the whole drag is one step"
        );
        record.undo(&mut score);
        assert!(score.handles.is_empty());
        record.redo(&mut score);
        record.redo(&mut score);
        assert_eq!(score.handles, vec![handle(0.1)]);
    }

    /// Beat edits keep time order and undo exactly.
    #[test]
    fn beat_edits_keep_order() {
        let mut score = Score::new("t");
        score.beats = vec![beat(0), beat(960), beat(1920)];
        let original = score.clone();
        let mut record = Record::new();
        record.edit(
            &mut score,
            ScoreEdit::AddBeat {
                beat: beat(480),
                at: None,
            },
        );
        assert_eq!(
            score.beats.iter().map(|b| b.tick).collect::<Vec<_>>(),
            [0, 480, 960, 1920]
        );
        let mut later = beat(0);
        later.tick = 3000;
        record.edit(
            &mut score,
            ScoreEdit::SetBeat {
                index: 0,
                before: None,
                after: later,
                now_at: None,
            },
        );
        assert_eq!(
            score.beats.iter().map(|b| b.tick).collect::<Vec<_>>(),
            [480, 960, 1920, 3000]
        );
        record.edit(
            &mut score,
            ScoreEdit::RemoveBeat {
                index: 1,
                removed: None,
            },
        );
        while record.can_undo() {
            record.undo(&mut score);
        }
        assert_eq!(score, original);
    }

    /// Replacing all beats is one step however often it is repeated in a row, and undo
    /// restores the beats from before the first replacement.
    #[test]
    fn set_beats_merge_and_undo() {
        let mut score = Score::new("t");
        score.beats = vec![beat(0), beat(960)];
        let original = score.beats.clone();
        let mut record = Record::new();
        for shift in [10u64, 20, 30] {
            let after: Vec<Beat> = original
                .iter()
                .map(|b| Beat {
                    tick: b.tick + shift,
                    ..*b
                })
                .collect();
            let before = score.beats.clone();
            record.edit(&mut score, ScoreEdit::SetBeats { before, after });
        }
        assert_eq!(score.beats[1].tick, 990);
        assert_eq!(record.len(), 1);
        record.undo(&mut score);
        assert_eq!(score.beats, original);
        record.redo(&mut score);
        assert_eq!(score.beats[0].tick, 30);
    }

    /// Pinning replaces an earlier pin of the same stroke, and undo brings it back.
    #[test]
    fn pins_replace_and_restore() {
        let mut score = Score::new("t");
        let pin = |x: f64| ImpactPin {
            hand: Side::Left,
            tick: 0,
            point_m: [x, 0.5, 0.76],
        };
        let mut record = Record::new();
        record.edit(
            &mut score,
            ScoreEdit::SetPin {
                hand: Side::Left,
                tick: 0,
                pin: Some(pin(0.1)),
                before: None,
            },
        );
        record.edit(
            &mut score,
            ScoreEdit::SetPin {
                hand: Side::Left,
                tick: 0,
                pin: Some(pin(0.2)),
                before: None,
            },
        );
        assert_eq!(score.pins, vec![pin(0.2)]);
        record.undo(&mut score);
        assert_eq!(score.pins, vec![pin(0.1)]);
    }
}
