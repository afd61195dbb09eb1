//! A long editing session on the one-minute study driven headless with random keys and
//! clicks — select, nudge, change modes, duplicate, copy and paste, delete, undo, redo,
//! play, pause, step frames and seek — checking after every action that undo and redo
//! restore exactly the document each step left, that nothing panics, and that memory
//! stays bounded. 400 actions by default; `TIMPANIST_SOAK_ACTIONS=3000 cargo test
//! --release --test app_soak -- --nocapture` runs a longer session, and
//! `TIMPANIST_SOAK_RENDER=1` renders (and re-renders after every edit) meanwhile.

mod common;

use eframe::egui::{Key, Modifiers};
use egui_kittest::Harness;
use timpanist::app::EditorApp;
use timpanist::base::rng::Rng;
use timpanist::score::Score;

fn score(h: &Harness<'static, EditorApp>) -> Score {
    h.state().loaded().unwrap().score.clone()
}

/// Let the composition arrive and the UI settle; while a render runs its spinner keeps
/// the UI repainting, so then a few frames instead of waiting for stillness.
fn settle(h: &mut Harness<'static, EditorApp>, rendering: bool) {
    if rendering {
        h.step();
        h.state_mut().wait_for_composition();
        h.run_steps(4);
    } else {
        common::settle(h);
    }
}

/// Resident memory of this process, bytes (Linux; 0 elsewhere).
fn resident_bytes() -> u64 {
    std::fs::read_to_string("/proc/self/statm")
        .ok()
        .and_then(|s| s.split_whitespace().nth(1)?.parse::<u64>().ok())
        .map_or(0, |pages| pages * 4096)
}

/// What one step of the session does.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Act {
    ClickBeat,
    SelectAll,
    Clear,
    Key(Modifiers, Key),
    Undo,
    Redo,
    Seek,
}

/// A whole number in 0..n.
fn below(rng: &mut Rng, n: usize) -> usize {
    (rng.next_u64() % n as u64) as usize
}

fn pick(rng: &mut Rng) -> Act {
    let keys = [
        (Modifiers::NONE, Key::ArrowLeft),
        (Modifiers::NONE, Key::ArrowRight),
        (Modifiers::NONE, Key::ArrowUp),
        (Modifiers::NONE, Key::ArrowDown),
        (Modifiers::NONE, Key::Num1),
        (Modifiers::NONE, Key::Num3),
        (Modifiers::NONE, Key::Num5),
        (Modifiers::COMMAND, Key::D),
        (Modifiers::COMMAND, Key::C),
        (Modifiers::COMMAND, Key::V),
        (Modifiers::NONE, Key::Delete),
        (Modifiers::NONE, Key::Space),
        (Modifiers::NONE, Key::Period),
        (Modifiers::NONE, Key::Comma),
    ];
    match below(rng, 20) {
        0..=3 => Act::ClickBeat,
        4 => Act::SelectAll,
        5 => Act::Clear,
        6..=8 => Act::Undo,
        9 => Act::Redo,
        10 => Act::Seek,
        _ => {
            let (m, k) = keys[below(rng, keys.len())];
            Act::Key(m, k)
        }
    }
}

#[test]
fn long_random_session_keeps_undo_exact() {
    let actions: usize = std::env::var("TIMPANIST_SOAK_ACTIONS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(400);
    let dir = tempfile::tempdir().unwrap();
    let study = common::root().join("scores/minute-study.ron");
    let render = std::env::var_os("TIMPANIST_SOAK_RENDER").is_some();
    let mut h = common::editor(Some(study), dir.path(), render);
    settle(&mut h, render);
    let original = score(&h);
    // The documents each undo step returns to, and those each redo step goes forward to.
    let mut undo: Vec<Score> = Vec::new();
    let mut redo: Vec<Score> = Vec::new();
    let mut rng = Rng::new(0x50a4);
    let mut memory_after_warm_up = 0;
    let mut edits = 0;
    for step in 0..actions {
        if step == actions / 5 {
            memory_after_warm_up = resident_bytes();
        }
        let before = score(&h);
        let act = pick(&mut rng);
        match act {
            Act::ClickBeat => {
                let beats = &before.beats;
                if !beats.is_empty() {
                    let b = &beats[below(&mut rng, beats.len())];
                    if let Some(at) = h.state().timeline_point(b.tick, b.hand)
                        && at.x > 0.0
                        && at.x < 1400.0
                        && at.y > 0.0
                        && at.y < 900.0
                    {
                        common::click_settled_by(&mut h, at, |h| settle(h, render));
                    }
                }
            }
            Act::SelectAll => h.key_press_modifiers(Modifiers::COMMAND, Key::A),
            Act::Clear => h.key_press(Key::Escape),
            Act::Key(m, k) => h.key_press_modifiers(m, k),
            Act::Undo => h.key_press_modifiers(Modifiers::COMMAND, Key::Z),
            Act::Redo => h.key_press_modifiers(Modifiers::COMMAND | Modifiers::SHIFT, Key::Z),
            Act::Seek => {
                let t = rng.uniform(0.0, 60.0);
                h.state_mut().seek(t);
            }
        }
        settle(&mut h, render);
        let after = score(&h);
        match act {
            Act::Undo => {
                if let Some(previous) = undo.pop() {
                    assert_eq!(
                        after, previous,
                        "step {step}: undo did not restore the document"
                    );
                    redo.push(before);
                } else {
                    assert_eq!(after, before, "step {step}: undo with nothing to undo");
                }
            }
            Act::Redo => {
                if let Some(next) = redo.pop() {
                    assert_eq!(
                        after, next,
                        "step {step}: redo did not restore the document"
                    );
                    undo.push(before);
                } else {
                    assert_eq!(after, before, "step {step}: redo with nothing to redo");
                }
            }
            _ if after != before => {
                edits += 1;
                undo.push(before);
                redo.clear();
            }
            _ => {}
        }
        // The history holds the steps to undo and those to redo.
        let held = undo.len() + redo.len();
        assert_eq!(h.state().undo_steps(), held, "step {step} ({act:?})");
        assert!(
            h.state().error().is_none(),
            "step {step}: {:?}",
            h.state().error()
        );
    }
    let last = score(&h);
    let grown_mb = resident_bytes().saturating_sub(memory_after_warm_up) as f64 / 1e6;
    println!(
        "{actions} actions, {edits} edits, {} undo steps held; memory grew {grown_mb:.1} MB after the first fifth",
        undo.len()
    );
    assert!(edits > actions / 10, "the session hardly edited: {edits}");
    assert!(grown_mb < 200.0, "memory grew {grown_mb:.1} MB");
    // Undo everything: the study as opened; redo everything: the session's last document,
    // the same as the edits that stayed, replayed without their undos.
    let steps = undo.len();
    for _ in 0..steps {
        h.key_press_modifiers(Modifiers::COMMAND, Key::Z);
        settle(&mut h, render);
    }
    assert_eq!(score(&h), original);
    for _ in 0..steps {
        h.key_press_modifiers(Modifiers::COMMAND | Modifiers::SHIFT, Key::Z);
        settle(&mut h, render);
    }
    assert_eq!(score(&h), last);
}
