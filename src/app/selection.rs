//! The selection (beats by index, or one trajectory handle) and the pure operations on a
//! selection of beats — move in time or between hand lanes, delete, modify — each giving
//! the new beat list (in time order) and where the selected beats ended up, ready to
//! push as one `ScoreEdit::SetBeats`.

use crate::score::{Beat, Hand};
use std::collections::BTreeSet;

/// The hand lanes of the timeline, top to bottom.
pub const LANES: [Hand; 3] = [Hand::Right, Hand::Auto, Hand::Left];

/// Lane index of a hand.
pub fn lane_of(hand: Hand) -> usize {
    LANES.iter().position(|h| *h == hand).unwrap_or(1)
}

/// What is selected.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Selection {
    /// Selected beats, by index into `Score::beats`.
    pub beats: BTreeSet<usize>,
    /// The selected trajectory handle, by index into `Score::handles`.
    pub handle: Option<usize>,
}

impl Selection {
    /// Select just beat `i`.
    pub fn only(i: usize) -> Selection {
        Selection {
            beats: BTreeSet::from([i]),
            handle: None,
        }
    }

    pub fn is_empty(&self) -> bool {
        self.beats.is_empty() && self.handle.is_none()
    }

    /// Toggle beat `i` in the selection.
    pub fn toggle(&mut self, i: usize) {
        if !self.beats.remove(&i) {
            self.beats.insert(i);
        }
    }

    /// Drop indices that no longer exist.
    pub fn clamp(&mut self, beats: usize, handles: usize) {
        self.beats.retain(|&i| i < beats);
        self.handle = self.handle.filter(|&h| h < handles);
    }
}

/// Put `(beat, selected)` pairs in time order (stable) and split them into the beat list
/// and the selected indices.
pub fn rebuild(mut tagged: Vec<(Beat, bool)>) -> (Vec<Beat>, BTreeSet<usize>) {
    tagged.sort_by_key(|(b, _)| b.tick);
    let selected = tagged
        .iter()
        .enumerate()
        .filter(|(_, (_, s))| *s)
        .map(|(i, _)| i)
        .collect();
    (tagged.into_iter().map(|(b, _)| b).collect(), selected)
}

/// Apply `f` to each selected beat.
pub fn modify(
    beats: &[Beat],
    sel: &BTreeSet<usize>,
    mut f: impl FnMut(&mut Beat),
) -> (Vec<Beat>, BTreeSet<usize>) {
    rebuild(
        beats
            .iter()
            .enumerate()
            .map(|(i, b)| {
                let mut b = *b;
                let s = sel.contains(&i);
                if s {
                    f(&mut b);
                }
                (b, s)
            })
            .collect(),
    )
}

/// Move the selected beats by `dtick` ticks (the whole group stops at tick 0) and by
/// `dlane` hand lanes (each beat stops at the top or bottom lane).
pub fn moved(
    beats: &[Beat],
    sel: &BTreeSet<usize>,
    dtick: i64,
    dlane: i64,
) -> (Vec<Beat>, BTreeSet<usize>) {
    let earliest = sel
        .iter()
        .filter_map(|&i| beats.get(i))
        .map(|b| b.tick as i64)
        .min()
        .unwrap_or(0);
    let dtick = dtick.max(-earliest);
    modify(beats, sel, |b| {
        b.tick = (b.tick as i64 + dtick) as u64;
        let lane = (lane_of(b.hand) as i64 + dlane).clamp(0, LANES.len() as i64 - 1);
        b.hand = LANES[lane as usize];
    })
}

/// Remove the selected beats.
pub fn deleted(beats: &[Beat], sel: &BTreeSet<usize>) -> Vec<Beat> {
    beats
        .iter()
        .enumerate()
        .filter(|(i, _)| !sel.contains(i))
        .map(|(_, b)| *b)
        .collect()
}

/// Insert `new` beats (kept selected) among `beats` (deselected).
pub fn inserted(beats: &[Beat], new: &[Beat]) -> (Vec<Beat>, BTreeSet<usize>) {
    rebuild(
        beats
            .iter()
            .map(|b| (*b, false))
            .chain(new.iter().map(|b| (*b, true)))
            .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::score::PlayingMode;

    fn beats() -> Vec<Beat> {
        vec![Beat::plain(0, 0), Beat::plain(480, 1), Beat::plain(960, 2)]
    }

    /// Moving the first beat past the others keeps time order and follows it in the
    /// selection; a move before 0 stops at 0; lanes clamp.
    #[test]
    fn move_keeps_order_and_selection() {
        let (b, sel) = moved(&beats(), &BTreeSet::from([0]), 1000, -5);
        assert_eq!(
            b.iter().map(|b| b.tick).collect::<Vec<_>>(),
            [480, 960, 1000]
        );
        assert_eq!(sel, BTreeSet::from([2]));
        assert_eq!(b[2].hand, Hand::Right);
        let (b, _) = moved(&beats(), &BTreeSet::from([1, 2]), -2000, 1);
        assert_eq!(b.iter().map(|b| b.tick).collect::<Vec<_>>(), [0, 0, 480]);
        assert_eq!(b[2].hand, Hand::Left);
    }

    /// Modify touches only the selection; delete removes only it; insert selects the new.
    #[test]
    fn modify_delete_insert() {
        let (b, _) = modify(&beats(), &BTreeSet::from([1]), |b| {
            b.mode = PlayingMode::Staccato
        });
        assert_eq!(
            b.iter().map(|b| b.mode).collect::<Vec<_>>(),
            [
                PlayingMode::Legato,
                PlayingMode::Staccato,
                PlayingMode::Legato
            ]
        );
        assert_eq!(deleted(&beats(), &BTreeSet::from([0, 2])), vec![beats()[1]]);
        let (b, sel) = inserted(&beats(), &[Beat::plain(700, 3)]);
        assert_eq!(b[2].tick, 700);
        assert_eq!(sel, BTreeSet::from([2]));
    }
}
