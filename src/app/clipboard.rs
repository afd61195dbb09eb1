//! Copy, paste and duplicate of beats: the clipboard holds beats with ticks relative to
//! the earliest copied one, so a paste lands them at any tick with their spacing kept.

use crate::score::Beat;
use std::collections::BTreeSet;

/// Copied beats, ticks relative to the first.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Clipboard {
    beats: Vec<Beat>,
}

impl Clipboard {
    /// Copy the selected beats of `beats`.
    pub fn copy(beats: &[Beat], sel: &BTreeSet<usize>) -> Clipboard {
        let chosen: Vec<Beat> = sel.iter().filter_map(|&i| beats.get(i)).copied().collect();
        let first = chosen.iter().map(|b| b.tick).min().unwrap_or(0);
        Clipboard {
            beats: chosen
                .into_iter()
                .map(|b| Beat {
                    tick: b.tick - first,
                    ..b
                })
                .collect(),
        }
    }

    pub fn is_empty(&self) -> bool {
        self.beats.is_empty()
    }

    /// How many beats are held.
    pub fn len(&self) -> usize {
        self.beats.len()
    }

    /// The copied beats placed so the first lands at `tick`.
    pub fn placed_at(&self, tick: u64) -> Vec<Beat> {
        self.beats
            .iter()
            .map(|b| Beat {
                tick: b.tick + tick,
                ..*b
            })
            .collect()
    }
}

/// Where a duplicate of the selection goes: right after the selection's last stroke,
/// on the next multiple of `grid` ticks from its first beat (at least one grid step on).
pub fn duplicate_tick(beats: &[Beat], sel: &BTreeSet<usize>, grid: u64) -> Option<u64> {
    let chosen: Vec<&Beat> = sel.iter().filter_map(|&i| beats.get(i)).collect();
    let first = chosen.iter().map(|b| b.tick).min()?;
    let last = chosen.iter().map(|b| b.end_tick()).max()?;
    let grid = grid.max(1);
    let span = (last - first) / grid * grid + grid;
    Some(first + span)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Copy keeps relative spacing; paste places it at a tick; duplicate goes after.
    #[test]
    fn copy_paste_duplicate() {
        let beats = vec![
            Beat::plain(480, 0),
            Beat::plain(960, 1),
            Beat::plain(1200, 2),
        ];
        let sel = BTreeSet::from([0, 2]);
        let clip = Clipboard::copy(&beats, &sel);
        assert_eq!(clip.len(), 2);
        let placed = clip.placed_at(3840);
        assert_eq!(
            placed.iter().map(|b| b.tick).collect::<Vec<_>>(),
            [3840, 4560]
        );
        assert_eq!(placed[1].drum, 2);
        assert_eq!(duplicate_tick(&beats, &sel, 480), Some(480 + 960));
        assert_eq!(duplicate_tick(&beats, &BTreeSet::new(), 480), None);
        assert!(Clipboard::copy(&beats, &BTreeSet::new()).is_empty());
    }
}
