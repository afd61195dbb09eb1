//! Where the beats of a score read from a file stand in that file. A score keeps its beats
//! in time order ([`Score::sort_beats`](super::Score::sort_beats)), but a file may list
//! them in any order: messages name a beat as the file does — its number in the file's
//! `beats` list, counted from 0 — and, for a score read from text, give the line and
//! column where its entry starts. timpanist writes beats in time order, so for the files
//! it saves the two numberings are the same.

use super::Beat;
use ron::error::Position;
use ron::value::RawValue;
use serde::Deserialize;

/// Where each beat of a score, in time order, stands in the file it was read from.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct BeatPlaces {
    /// For each beat in time order, its number in the file; empty when they are the same.
    numbers: Vec<usize>,
    /// For each beat in time order, where its entry starts in the file's text; empty when
    /// not known.
    at: Vec<Position>,
}

impl BeatPlaces {
    /// The places of a score's beats as it holds them: beat `i` is the file's beat `i`,
    /// at no known line (a score made or changed in memory, or saved as it is held).
    pub fn in_order() -> BeatPlaces {
        BeatPlaces::default()
    }

    /// Put `beats`, listed as in the file whose text is `text`, in time order (stable:
    /// beats at one tick keep the file's order), keeping where each stood.
    pub(super) fn sort(beats: &mut Vec<Beat>, text: &str) -> BeatPlaces {
        let mut numbers: Vec<usize> = (0..beats.len()).collect();
        numbers.sort_by_key(|&n| beats[n].tick);
        *beats = numbers.iter().map(|&n| beats[n]).collect();
        let in_file = entry_positions(text);
        let at = if in_file.len() == numbers.len() {
            numbers.iter().map(|&n| in_file[n]).collect()
        } else {
            Vec::new()
        };
        BeatPlaces { numbers, at }
    }

    /// The number in the file of the score's beat `i` (in time order).
    pub fn number(&self, i: usize) -> usize {
        self.numbers.get(i).copied().unwrap_or(i)
    }

    /// Where the entry of the score's beat `i` (in time order) starts in the file's text.
    pub fn position(&self, i: usize) -> Option<Position> {
        self.at.get(i).copied()
    }

    /// Whether the file lists its beats in time order (its numbers are the score's own).
    pub fn in_time_order(&self) -> bool {
        self.numbers.iter().enumerate().all(|(i, &n)| i == n)
    }
}

/// Where each entry of the `beats` list of the score text `text` starts (past any comment
/// before it), in the file's order; empty if the text is not a score.
fn entry_positions(text: &str) -> Vec<Position> {
    /// A score's `beats` list, each entry as its own text (a slice of the file's).
    #[derive(Deserialize)]
    #[serde(rename = "Score")]
    struct Entries<'a> {
        #[serde(borrow)]
        beats: Vec<&'a RawValue>,
    }
    let Ok(entries) = ron::from_str::<Entries>(text) else {
        return Vec::new();
    };
    let offsets: Vec<usize> = (entries.beats.iter())
        .map(|raw| raw.trim().get_ron().as_ptr() as usize - text.as_ptr() as usize)
        .collect();
    positions(text, &offsets)
}

/// The line and column (both from 1, the column in characters, as RON's parse errors
/// count them) of each byte offset of `text`, given in increasing order; empty if they
/// are not.
fn positions(text: &str, offsets: &[usize]) -> Vec<Position> {
    let (mut line, mut line_start, mut from) = (1, 0, 0);
    let mut out = Vec::with_capacity(offsets.len());
    for &offset in offsets {
        let Some(between) = text.get(from..offset) else {
            return Vec::new();
        };
        for (i, _) in between.match_indices('\n') {
            line += 1;
            line_start = from + i + 1;
        }
        from = offset;
        let col = text[line_start..offset].chars().count() + 1;
        out.push(Position { line, col });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Positions count lines from 1 and columns in characters from 1.
    #[test]
    fn positions_count_lines_and_characters() {
        let text = "ab\n«é»x\n\nz";
        let at = |offset: usize| positions(text, &[offset])[0];
        assert_eq!(at(0), Position { line: 1, col: 1 });
        assert_eq!(at(3), Position { line: 2, col: 1 });
        assert_eq!(at(text.find('x').unwrap()), Position { line: 2, col: 4 });
        assert_eq!(at(text.find('z').unwrap()), Position { line: 4, col: 1 });
        assert!(positions(text, &[5, 3]).is_empty());
    }

    /// Beats listed out of time order are sorted (ties keeping the file's order), each
    /// keeping its number in the file and the line and column of its entry, past a
    /// comment before it; a score made in memory numbers beats as it holds them.
    #[test]
    fn sorting_keeps_where_each_beat_stood() {
        let mut score = super::super::Score::new("t");
        score.beats = vec![
            Beat::plain(960, 0),
            Beat::plain(0, 1),
            Beat::plain(960, 2),
            Beat::plain(480, 3),
        ];
        let text = score.to_ron().replace(
            "        Beat(tick: 0,",
            "        // first\n        Beat(tick: 0,",
        );
        let line_of = |needle: &str| text[..text.find(needle).unwrap()].matches('\n').count() + 1;
        let mut beats = score.beats.clone();
        let places = BeatPlaces::sort(&mut beats, &text);
        assert_eq!(
            beats.iter().map(|b| b.drum).collect::<Vec<_>>(),
            [1, 3, 0, 2]
        );
        assert_eq!(
            (0..4).map(|i| places.number(i)).collect::<Vec<_>>(),
            [1, 3, 0, 2]
        );
        assert!(!places.in_time_order());
        let first = places.position(0).unwrap();
        assert_eq!((first.line, first.col), (line_of("Beat(tick: 0,"), 9));
        assert_eq!(places.position(2).unwrap().line, line_of("Beat(tick: 960,"));
        let fresh = BeatPlaces::in_order();
        assert_eq!((fresh.number(3), fresh.position(3)), (3, None));
        assert!(fresh.in_time_order());
    }
}
