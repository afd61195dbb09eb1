//! The editor's pipeline and background writing, driven headless with the real workers:
//! an edit is composed once, and the rendering plays exactly the composition the view
//! shows; saving runs off the UI thread and quitting waits for it.

mod common;

use eframe::egui;
use egui_kittest::Harness;
use std::time::{Duration, Instant};
use timpanist::app::EditorApp;

/// Step the editor until it holds a complete rendering of the score as it is now.
fn until_rendered(h: &mut Harness<'static, EditorApp>) {
    let began = Instant::now();
    loop {
        h.step();
        let done = h.state().rendering().is_some_and(|r| r.complete)
            && h.state().export_blocked().is_none();
        if done {
            return;
        }
        assert!(
            began.elapsed() < Duration::from_secs(120),
            "no rendering: {} / {:?}",
            h.state().status(),
            h.state().render_error()
        );
        std::thread::sleep(Duration::from_millis(5));
    }
}

/// The editor (not rendering) on the etude with every beat made an accent: unsaved.
fn edited_etude(dir: &std::path::Path) -> Harness<'static, EditorApp> {
    let score = common::root().join("scores/etude-modes.ron");
    let mut h = common::editor(Some(score), dir, false);
    common::settle(&mut h);
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::A);
    h.key_press(egui::Key::Num3);
    h.step();
    h
}

/// One edit, one composition: the view's composition is handed to the render, which
/// composes nothing itself and performs exactly those trajectories.
#[test]
fn an_edit_is_composed_once_for_the_view_and_the_rendering() {
    let dir = tempfile::tempdir().unwrap();
    let score = common::root().join("scores/roll-exercise.ron");
    let mut h = common::editor(Some(score), dir.path(), true);
    until_rendered(&mut h);
    assert_eq!(h.state().compositions_made(), 1, "opening composes once");

    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::A);
    h.key_press(egui::Key::Num2);
    h.step();
    assert!(h.state().is_dirty(), "the edit was made");
    until_rendered(&mut h);
    assert_eq!(h.state().compositions_made(), 2, "the edit composes once");

    let rendering = h.state().rendering().unwrap().clone();
    assert_eq!(
        rendering.stats.compose,
        Duration::ZERO,
        "the render composed"
    );
    assert_eq!(Some(&*rendering.composition), h.state().composition());
    assert!(
        (rendering.composition.strokes.iter())
            .all(|s| s.mode == timpanist::score::PlayingMode::Tenuto),
        "the rendering is of the edited score"
    );
}

/// Save writes on a background job: the file is complete once the job is taken in, the
/// score is then clean, and a quit asked meanwhile waits for it instead of closing.
#[test]
fn saving_runs_in_the_background_and_quitting_waits_for_it() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = edited_etude(dir.path());
    assert!(h.state().is_dirty());

    let target = dir.path().join("background.ron");
    h.state_mut().save_to(&target);
    // Until the job is taken in, a quit waits (and does not ask about the changes).
    assert!(h.state().is_writing());
    assert!(!h.state_mut().request_quit(), "quit waits for the save");
    assert!(!h.state().is_asking_to_discard());
    h.state_mut().wait_for_files();
    assert!(!h.state().is_writing());
    assert!(!h.state().is_dirty(), "{}", h.state().status());
    assert!(
        h.state().status().contains("saved"),
        "{}",
        h.state().status()
    );
    let saved = timpanist::score::LoadedScore::load(&target).unwrap();
    assert_eq!(&saved.score, &h.state().loaded().unwrap().score);
    assert!(h.state_mut().request_quit(), "nothing left to wait for");
}

/// A save that fails reports the error in the window and leaves the score unsaved.
#[test]
fn a_failed_background_save_keeps_the_changes() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = edited_etude(dir.path());
    h.state_mut()
        .save_to(std::path::Path::new("/no/such/dir/score.ron"));
    h.state_mut().wait_for_files();
    assert!(h.state().is_dirty());
    let error = h.state().error().unwrap_or_default();
    assert!(error.contains("/no/such/dir/score.ron"), "{error}");
}
