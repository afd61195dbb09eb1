//! Keyboard shortcuts: one table from key chords to editor actions, read both by the
//! frame's input handling and by the help overlay (so the overlay never lies).

use crate::scene::camera::View;
use crate::score::PlayingMode;
use eframe::egui::{self, Key, Modifiers};

/// Something the user can ask for from the keyboard.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Action {
    PlayPause,
    New,
    Open,
    Save,
    SaveAs,
    Undo,
    Redo,
    Delete,
    Copy,
    Paste,
    Duplicate,
    SelectAll,
    /// Move the selection by this many grid steps in time.
    Nudge(i64),
    /// Move the selection to the other hand lane (-1 up toward Right, +1 down).
    NudgeLane(i64),
    SetMode(PlayingMode),
    ToggleHelp,
    TogglePreferences,
    ClearSelection,
    /// Move the 3D camera to a named view.
    CameraView(View),
    /// Make the 3D camera follow the stick tip of the hand that strikes next.
    FollowHand,
    /// Move the 3D camera so the selected beats' impacts (or the kit) fill the view.
    FrameSelection,
    /// Change the playback speed this many steps (positive: faster).
    Speed(i64),
    /// Pause and move the playhead this many video frames.
    StepFrames(i64),
    /// Pause and move the playhead to the next (true) or previous contact.
    StepContact(bool),
}

/// A key chord and what it does; `label` is how the help overlay shows it.
pub struct Shortcut {
    pub modifiers: Modifiers,
    pub key: Key,
    pub action: Action,
    pub label: &'static str,
    pub what: &'static str,
}

const fn chord(
    modifiers: Modifiers,
    key: Key,
    action: Action,
    label: &'static str,
    what: &'static str,
) -> Shortcut {
    Shortcut {
        modifiers,
        key,
        action,
        label,
        what,
    }
}

const CMD: Modifiers = Modifiers::COMMAND;
const CMD_SHIFT: Modifiers = Modifiers::COMMAND.plus(Modifiers::SHIFT);
const NONE: Modifiers = Modifiers::NONE;
const SHIFT: Modifiers = Modifiers::SHIFT;

/// Every shortcut. More specific chords (with Shift) come before their plain forms.
pub const SHORTCUTS: &[Shortcut] = &[
    chord(
        NONE,
        Key::F5,
        Action::CameraView(View::Player),
        "F5",
        "3D view: over the player's shoulder",
    ),
    chord(
        NONE,
        Key::F6,
        Action::CameraView(View::Front),
        "F6",
        "3D view: from the front",
    ),
    chord(
        NONE,
        Key::F7,
        Action::CameraView(View::Side),
        "F7",
        "3D view: from the side",
    ),
    chord(
        NONE,
        Key::F8,
        Action::CameraView(View::Top),
        "F8",
        "3D view: from above",
    ),
    chord(
        NONE,
        Key::F9,
        Action::FollowHand,
        "F9",
        "3D view: follow the hand that strikes next",
    ),
    chord(
        NONE,
        Key::F,
        Action::FrameSelection,
        "F",
        "3D view: frame the selected beats' impacts (or the kit)",
    ),
    chord(
        NONE,
        Key::OpenBracket,
        Action::Speed(-1),
        "[",
        "slower playback (1, 1/2, 1/4, 1/10; below 1 each strike sounds as it passes)",
    ),
    chord(
        NONE,
        Key::CloseBracket,
        Action::Speed(1),
        "]",
        "faster playback",
    ),
    chord(
        SHIFT,
        Key::Comma,
        Action::StepContact(false),
        "Shift+,",
        "pause, playhead to the previous contact",
    ),
    chord(
        SHIFT,
        Key::Period,
        Action::StepContact(true),
        "Shift+.",
        "pause, playhead to the next contact",
    ),
    chord(
        NONE,
        Key::Space,
        Action::PlayPause,
        "Space",
        "play / pause from the playhead",
    ),
    chord(CMD, Key::N, Action::New, "Ctrl+N", "new score"),
    chord(CMD, Key::O, Action::Open, "Ctrl+O", "open a score"),
    chord(
        CMD,
        Key::Comma,
        Action::TogglePreferences,
        "Ctrl+,",
        "preferences",
    ),
    chord(
        NONE,
        Key::Comma,
        Action::StepFrames(-1),
        ",",
        "pause, playhead back one video frame (1/60 s)",
    ),
    chord(
        NONE,
        Key::Period,
        Action::StepFrames(1),
        ".",
        "pause, playhead on one video frame (1/60 s)",
    ),
    chord(CMD_SHIFT, Key::S, Action::SaveAs, "Ctrl+Shift+S", "save as"),
    chord(CMD, Key::S, Action::Save, "Ctrl+S", "save"),
    chord(CMD_SHIFT, Key::Z, Action::Redo, "Ctrl+Shift+Z", "redo"),
    chord(CMD, Key::Y, Action::Redo, "Ctrl+Y", "redo"),
    chord(CMD, Key::Z, Action::Undo, "Ctrl+Z", "undo"),
    chord(
        NONE,
        Key::Delete,
        Action::Delete,
        "Delete",
        "delete the selection",
    ),
    chord(
        NONE,
        Key::Backspace,
        Action::Delete,
        "Backspace",
        "delete the selection",
    ),
    chord(
        CMD,
        Key::C,
        Action::Copy,
        "Ctrl+C",
        "copy the selected beats",
    ),
    chord(
        CMD,
        Key::V,
        Action::Paste,
        "Ctrl+V",
        "paste at the playhead",
    ),
    chord(
        CMD,
        Key::D,
        Action::Duplicate,
        "Ctrl+D",
        "duplicate the selection after itself",
    ),
    chord(CMD, Key::A, Action::SelectAll, "Ctrl+A", "select all beats"),
    chord(
        NONE,
        Key::ArrowLeft,
        Action::Nudge(-1),
        "Left",
        "nudge earlier by one grid step",
    ),
    chord(
        NONE,
        Key::ArrowRight,
        Action::Nudge(1),
        "Right",
        "nudge later by one grid step",
    ),
    chord(
        NONE,
        Key::ArrowUp,
        Action::NudgeLane(-1),
        "Up",
        "move to the lane above",
    ),
    chord(
        NONE,
        Key::ArrowDown,
        Action::NudgeLane(1),
        "Down",
        "move to the lane below",
    ),
    chord(
        NONE,
        Key::Num1,
        Action::SetMode(PlayingMode::Legato),
        "1",
        "legato",
    ),
    chord(
        NONE,
        Key::Num2,
        Action::SetMode(PlayingMode::Tenuto),
        "2",
        "tenuto",
    ),
    chord(
        NONE,
        Key::Num3,
        Action::SetMode(PlayingMode::Accent),
        "3",
        "accent",
    ),
    chord(
        NONE,
        Key::Num4,
        Action::SetMode(PlayingMode::VerticalAccent),
        "4",
        "vertical accent",
    ),
    chord(
        NONE,
        Key::Num5,
        Action::SetMode(PlayingMode::Staccato),
        "5",
        "staccato",
    ),
    chord(
        NONE,
        Key::F1,
        Action::ToggleHelp,
        "F1",
        "show / hide this help",
    ),
    chord(
        NONE,
        Key::Escape,
        Action::ClearSelection,
        "Escape",
        "clear the selection, close help",
    ),
];

/// The actions asked for by this frame's key presses (consumed from the input), unless a
/// text field has the keyboard focus.
pub fn take_actions(ctx: &egui::Context) -> Vec<Action> {
    if ctx.memory(|m| m.focused().is_some()) && ctx.egui_wants_keyboard_input() {
        return Vec::new();
    }
    let mut out = Vec::new();
    ctx.input_mut(|i| {
        for s in SHORTCUTS {
            if i.consume_key(s.modifiers, s.key) {
                out.push(s.action);
            }
        }
    });
    out
}

/// The help overlay listing every shortcut and mouse control; returns false when closed.
pub fn help_window(ctx: &egui::Context, open: &mut bool) {
    egui::Window::new("Keyboard and mouse")
        .open(open)
        .collapsible(false)
        .resizable(false)
        .anchor(egui::Align2::CENTER_CENTER, egui::Vec2::ZERO)
        .show(ctx, |ui| {
            egui::Grid::new("help-keys").striped(true).show(ui, |ui| {
                for s in SHORTCUTS {
                    ui.monospace(s.label);
                    ui.label(s.what);
                    ui.end_row();
                }
                for (k, what) in MOUSE_HELP {
                    ui.monospace(*k);
                    ui.label(*what);
                    ui.end_row();
                }
            });
        });
}

/// Mouse controls, for the help overlay.
pub const MOUSE_HELP: &[(&str, &str)] = &[
    ("Timeline: click lane", "add a beat (snapped to the grid)"),
    (
        "Timeline: click beat",
        "select it (Shift/Ctrl: add to the selection)",
    ),
    ("Timeline: drag beat", "move the selection in time"),
    ("Timeline: drag empty", "box-select"),
    ("Timeline: wheel", "scroll; Ctrl+wheel zooms"),
    (
        "Ruler: click/drag",
        "move the playhead; Shift+drag sets the loop",
    ),
    (
        "Tempo lane: drag point",
        "change its tempo; double-click adds a point",
    ),
    (
        "3D: left drag",
        "orbit; Shift+left or middle drag pans; wheel zooms",
    ),
    (
        "3D: drag on a trajectory",
        "add a handle and drag it (hold X, Y or Z for an axis)",
    ),
    ("3D: drag a handle", "move it; right-click removes it"),
    ("3D: drag an impact", "pin it on the head"),
];

#[cfg(test)]
mod tests {
    use super::*;

    /// No two shortcuts share a chord, and every playing mode has a number key.
    #[test]
    fn chords_are_unique() {
        for (i, a) in SHORTCUTS.iter().enumerate() {
            for b in &SHORTCUTS[i + 1..] {
                assert!(
                    !(a.key == b.key && a.modifiers == b.modifiers),
                    "{} twice",
                    a.label
                );
            }
        }
        for mode in PlayingMode::ALL {
            assert!(SHORTCUTS.iter().any(|s| s.action == Action::SetMode(mode)));
        }
    }
}
