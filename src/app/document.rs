//! The open document: the score with its kit, where it is saved, its undo history and the
//! selection — the only state the editor saves. Every change goes through the history
//! (one gesture, one undo step); the keyboard's and menus' editing actions (undo, delete,
//! copy and paste, nudge, set mode) live here, apart from the views and the pipeline.

use super::clipboard::{self, Clipboard};
use super::history::History;
use super::keys::Action;
use super::selection::{self, Selection};
use super::time_axis::snap;
use crate::score::edit::ScoreEdit;
use crate::score::{Beat, LoadedScore};
use std::collections::BTreeSet;
use std::path::PathBuf;

/// A score open in the editor.
pub struct Document {
    pub loaded: LoadedScore,
    /// Where it is saved; `None` for the compiled-in demo, new scores and imports.
    pub path: Option<PathBuf>,
    pub history: History,
    pub selection: Selection,
    /// Counts changes to the score (edits, undo, redo): a save is of one revision.
    revision: u64,
}

/// What an editing action did.
#[derive(Debug, Default, PartialEq)]
pub struct Outcome {
    /// Whether the score changed (it must be composed again).
    pub changed: bool,
    /// A message for the status bar.
    pub status: Option<String>,
}

impl Outcome {
    fn changed(changed: bool) -> Outcome {
        Outcome {
            changed,
            status: None,
        }
    }

    fn say(status: impl Into<String>) -> Outcome {
        Outcome {
            changed: false,
            status: Some(status.into()),
        }
    }
}

impl Document {
    /// `loaded`, saved at `path` (if anywhere), with an empty history.
    pub fn new(loaded: LoadedScore, path: Option<PathBuf>) -> Document {
        Document {
            loaded,
            path,
            history: History::new(),
            selection: Selection::default(),
            revision: 0,
        }
    }

    /// The revision of the score now (see [`Document::mark_saved`]).
    pub fn revision(&self) -> u64 {
        self.revision
    }

    /// Whether the score has changes not saved.
    pub fn is_dirty(&self) -> bool {
        !self.history.is_saved()
    }

    /// The score of `revision` was saved at `path`: mark it saved if it is still the
    /// score now (else the changes made meanwhile stay unsaved).
    pub fn mark_saved(&mut self, revision: u64, path: PathBuf) {
        self.path = Some(path);
        if revision == self.revision {
            self.history.set_saved();
        }
    }

    /// Start a new undo step.
    pub fn begin_gesture(&mut self) {
        self.history.begin_gesture();
    }

    /// Apply `edit` as part of the current gesture.
    pub fn apply(&mut self, edit: ScoreEdit) {
        self.history.apply(&mut self.loaded.score, edit);
        self.revision += 1;
    }

    /// Keep the selection within the score after a change.
    pub fn clamp_selection(&mut self) {
        let score = &self.loaded.score;
        self.selection.clamp(score.beats.len(), score.handles.len());
    }

    /// Do an editing `action` on a grid of `grid` ticks with the playhead at `playhead_s`
    /// (paste goes there); other actions do nothing here.
    pub fn act(
        &mut self,
        action: Action,
        grid: u64,
        playhead_s: f64,
        clipboard: &mut Clipboard,
    ) -> Outcome {
        use Action::*;
        let beats = self.loaded.score.beats.clone();
        let sel = self.selection.beats.clone();
        match action {
            Undo | Redo => self.undo_redo(action == Undo),
            Delete => self.delete(&beats, &sel),
            Copy => {
                *clipboard = Clipboard::copy(&beats, &sel);
                Outcome::say(format!("copied {} beat(s)", clipboard.len()))
            }
            Paste if clipboard.is_empty() => {
                Outcome::say("nothing to paste: copy beats first (Ctrl+C)")
            }
            Paste => {
                let tick = snap(self.loaded.score.tempo_map().tick_at(playhead_s), grid);
                let (after, new_sel) = selection::inserted(&beats, &clipboard.placed_at(tick));
                self.push_beats(after, new_sel)
            }
            Duplicate => match clipboard::duplicate_tick(&beats, &sel, grid) {
                Some(tick) => {
                    let copy = Clipboard::copy(&beats, &sel).placed_at(tick);
                    let (after, new_sel) = selection::inserted(&beats, &copy);
                    self.push_beats(after, new_sel)
                }
                None => Outcome::default(),
            },
            SelectAll => {
                self.selection = Selection {
                    beats: (0..beats.len()).collect(),
                    handle: None,
                };
                Outcome::default()
            }
            Nudge(n) => {
                let (after, s) = selection::moved(&beats, &sel, n * grid as i64, 0);
                self.push_beats(after, s)
            }
            NudgeLane(n) => {
                let (after, s) = selection::moved(&beats, &sel, 0, n);
                self.push_beats(after, s)
            }
            SetMode(m) => {
                let (after, s) = selection::modify(&beats, &sel, |b| b.mode = m);
                self.push_beats(after, s)
            }
            _ => Outcome::default(),
        }
    }

    fn undo_redo(&mut self, undo: bool) -> Outcome {
        let done = if undo {
            self.history.undo(&mut self.loaded.score)
        } else {
            self.history.redo(&mut self.loaded.score)
        };
        if done {
            self.revision += 1;
        }
        self.selection = Selection::default();
        Outcome {
            changed: done,
            status: Some(
                match (done, undo) {
                    (true, true) => "undone",
                    (true, false) => "redone",
                    (false, true) => "nothing to undo",
                    (false, false) => "nothing to redo",
                }
                .into(),
            ),
        }
    }

    fn delete(&mut self, beats: &[Beat], sel: &BTreeSet<usize>) -> Outcome {
        if !sel.is_empty() {
            return self.push_beats(selection::deleted(beats, sel), BTreeSet::new());
        }
        let Some(h) = self.selection.handle else {
            return Outcome::default();
        };
        self.begin_gesture();
        self.apply(ScoreEdit::RemoveHandle {
            index: h,
            removed: None,
        });
        self.selection = Selection::default();
        Outcome::changed(true)
    }

    /// Replace all beats with `after` and select `sel`, as one gesture (nothing when the
    /// beats stay the same).
    fn push_beats(&mut self, after: Vec<Beat>, sel: BTreeSet<usize>) -> Outcome {
        if after == self.loaded.score.beats {
            return Outcome::default();
        }
        self.begin_gesture();
        let before = self.loaded.score.beats.clone();
        self.apply(ScoreEdit::SetBeats { before, after });
        self.selection = Selection {
            beats: sel,
            handle: None,
        };
        Outcome::changed(true)
    }

    /// The window title: the score's title, a star when unsaved, and where it is saved.
    pub fn title(&self) -> String {
        format!(
            "timpanist - {}{} - {}",
            self.loaded.score.title,
            if self.is_dirty() { " *" } else { "" },
            self.path
                .as_ref()
                .map_or("not saved".into(), |p| p.display().to_string())
        )
    }
}
