//! What the panels ask of the editor: each frame the UI pushes [`Command`]s and the app
//! drains them once, applying score changes through the undo history.

use super::keys::Action;
use super::selection::Selection;
use crate::score::edit::ScoreEdit;

/// One request from the UI.
#[derive(Clone, Debug)]
pub enum Command {
    /// Start a new undo step (a click, key press or drag begins).
    Gesture,
    /// Change the score, as part of the current gesture.
    Edit(ScoreEdit),
    /// Replace the selection.
    Select(Selection),
    /// A keyboard or menu action.
    Do(Action),
    /// Move the playhead to this time, s.
    Seek(f64),
    /// Set or clear the loop region, ticks.
    SetLoop(Option<(u64, u64)>),
}
