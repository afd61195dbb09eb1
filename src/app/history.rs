//! The undo history of the open score: every change is a [`ScoreEdit`] pushed into an
//! `undo::Record` as part of a *gesture* (one click, one key press, one drag). Edits of the
//! same gesture merge into one undo step; a new gesture always starts a new step, so two
//! drags of the same handle stay two steps.

use crate::score::Score;
use crate::score::edit::ScoreEdit;

/// One undo step: the edits of one gesture, applied in order.
#[derive(Clone, Debug)]
pub struct Step {
    gesture: u64,
    edits: Vec<ScoreEdit>,
}

impl std::fmt::Display for Step {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.edits.first() {
            Some(e) => write!(f, "{e}"),
            None => f.write_str("nothing"),
        }
    }
}

impl undo::Edit for Step {
    type Target = Score;
    type Output = ();

    fn edit(&mut self, score: &mut Score) {
        for e in &mut self.edits {
            e.edit(score);
        }
    }

    fn undo(&mut self, score: &mut Score) {
        for e in self.edits.iter_mut().rev() {
            e.undo(score);
        }
    }

    fn merge(&mut self, other: Self) -> undo::Merged<Self> {
        if other.gesture != self.gesture {
            return undo::Merged::No(other);
        }
        for e in other.edits {
            match self.edits.pop() {
                Some(mut last) => match last.merge(e) {
                    undo::Merged::Yes => self.edits.push(last),
                    undo::Merged::No(e) => {
                        self.edits.push(last);
                        self.edits.push(e);
                    }
                    undo::Merged::Annul => {}
                },
                None => self.edits.push(e),
            }
        }
        undo::Merged::Yes
    }
}

/// The score's undo record and the gesture counter.
pub struct History {
    record: undo::Record<Step>,
    gesture: u64,
}

impl Default for History {
    fn default() -> Self {
        History::new()
    }
}

impl History {
    /// An empty history, marked saved.
    pub fn new() -> History {
        let mut record = undo::Record::new();
        record.set_saved();
        History { record, gesture: 0 }
    }

    /// Start a new gesture: later edits no longer merge with earlier ones.
    pub fn begin_gesture(&mut self) {
        self.gesture += 1;
    }

    /// Apply `edit` to `score` as part of the current gesture.
    pub fn apply(&mut self, score: &mut Score, edit: ScoreEdit) {
        self.record.edit(
            score,
            Step {
                gesture: self.gesture,
                edits: vec![edit],
            },
        );
    }

    /// Undo the last step; false if there was none.
    pub fn undo(&mut self, score: &mut Score) -> bool {
        self.begin_gesture();
        self.record.undo(score).is_some()
    }

    /// Redo the next step; false if there was none.
    pub fn redo(&mut self, score: &mut Score) -> bool {
        self.begin_gesture();
        self.record.redo(score).is_some()
    }

    pub fn can_undo(&self) -> bool {
        self.record.can_undo()
    }

    pub fn can_redo(&self) -> bool {
        self.record.can_redo()
    }

    /// Number of undo steps recorded.
    pub fn steps(&self) -> usize {
        self.record.len()
    }

    /// Whether the score is as last saved.
    pub fn is_saved(&self) -> bool {
        self.record.is_saved()
    }

    /// Mark the current state as saved.
    pub fn set_saved(&mut self) {
        self.begin_gesture();
        self.record.set_saved();
    }

    /// Mark the score as not saved (e.g. restored from the autosave).
    pub fn mark_unsaved(&mut self) {
        self.begin_gesture();
        self.record.clear_saved();
    }

    /// What Undo would undo, e.g. "move handle".
    pub fn undo_text(&self) -> Option<String> {
        self.record
            .head()
            .checked_sub(1)
            .and_then(|i| self.record.get_entry(i))
            .map(|e| e.as_ref().to_string())
    }

    /// What Redo would redo.
    pub fn redo_text(&self) -> Option<String> {
        self.record
            .get_entry(self.record.head())
            .map(|e| e.as_ref().to_string())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kit::Side;
    use crate::score::Handle;

    fn handle(z: f64) -> Handle {
        Handle {
            hand: Side::Left,
            tick: 480,
            reach_ticks: 240,
            offset_m: [0.0, 0.0, z],
        }
    }

    fn drag(history: &mut History, score: &mut Score, to: [f64; 3]) {
        history.begin_gesture();
        for k in 1..=5 {
            let from = score.handles[0];
            let mut h = from;
            h.offset_m = to.map(|v| v * k as f64 / 5.0);
            history.apply(
                score,
                ScoreEdit::MoveHandle {
                    index: 0,
                    from,
                    to: h,
                },
            );
        }
    }

    /// Two drags of one handle are two undo steps; a drag starting with the handle's
    /// creation is one; undo and redo walk them exactly.
    #[test]
    fn gestures_are_steps() {
        let mut score = Score::new("t");
        let mut history = History::new();
        assert!(history.is_saved());
        history.begin_gesture();
        history.apply(&mut score, ScoreEdit::AddHandle(handle(0.0)));
        for k in 1..=5 {
            let from = score.handles[0];
            history.apply(
                &mut score,
                ScoreEdit::MoveHandle {
                    index: 0,
                    from,
                    to: handle(0.01 * k as f64),
                },
            );
        }
        drag(&mut history, &mut score, [0.1, 0.0, 0.0]);
        assert_eq!(history.steps(), 2);
        assert!(!history.is_saved());
        assert_eq!(history.undo_text().as_deref(), Some("move handle"));
        assert!(history.undo(&mut score));
        assert_eq!(score.handles, vec![handle(0.05)]);
        assert!(history.undo(&mut score));
        assert!(score.handles.is_empty());
        assert!(history.is_saved());
        assert!(!history.undo(&mut score));
        assert!(history.redo(&mut score));
        assert!(history.redo(&mut score));
        assert_eq!(score.handles[0].offset_m, [0.1, 0.0, 0.0]);
    }
}
