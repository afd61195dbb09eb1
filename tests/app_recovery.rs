//! Autosave and recovery, driven headless: an edit is written to the recovery file once the
//! score has been left alone a moment; an editor started afterwards (as after a crash: the
//! first one is dropped without quitting) offers it back, and restoring gives the edited
//! score, unsaved, under its own file name; discarding removes the file; a clean quit
//! leaves nothing to recover.

mod common;

use eframe::egui;
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use std::path::{Path, PathBuf};
use timpanist::app::EditorApp;
use timpanist::score::Hand;

/// A copy of the etude in `dir` (its kit path made absolute so the copy loads there).
fn etude_copy(dir: &Path) -> PathBuf {
    let text = std::fs::read_to_string(common::root().join("scores/etude-modes.ron")).unwrap();
    let kit = common::root().join("kits/standard.ron");
    let text = text.replace(
        "\"../kits/standard.ron\"",
        &format!("{:?}", kit.display().to_string()),
    );
    let path = dir.join("etude.ron");
    std::fs::write(&path, text).unwrap();
    path
}

fn editor(score: &Path, dir: &Path) -> Harness<'static, EditorApp> {
    let mut h = common::editor(Some(score.to_path_buf()), dir, false);
    common::settle(&mut h);
    h
}

fn beats(h: &Harness<'static, EditorApp>) -> usize {
    h.state().loaded().unwrap().score.beats.len()
}

/// Delete the beat at tick 960.
fn delete_a_beat(h: &mut Harness<'static, EditorApp>) {
    let at = h.state().timeline_point(960, Hand::Auto).unwrap();
    common::click(h, at);
    h.key_press(egui::Key::Delete);
    common::settle(h);
}

/// Run frames until `done` or about `seconds` of the harness's clock (0.25 s a frame).
fn run_for(h: &mut Harness<'static, EditorApp>, seconds: f64, done: impl Fn(&EditorApp) -> bool) {
    for _ in 0..(seconds / 0.25).ceil() as usize {
        if done(h.state()) {
            return;
        }
        h.step();
    }
}

#[test]
fn an_edit_survives_a_crash_and_is_offered_back() {
    let dir = tempfile::tempdir().unwrap();
    let score = etude_copy(dir.path());
    let recovery = dir.path().join("recovery.ron");
    let mut h = editor(&score, dir.path());
    let before = beats(&h);
    assert!(!recovery.exists(), "nothing to recover before an edit");
    delete_a_beat(&mut h);
    assert_eq!(beats(&h), before - 1);
    assert!(h.state().is_dirty());
    run_for(&mut h, 4.0, |_| recovery.exists());
    assert!(
        recovery.exists(),
        "the edit is autosaved within a few seconds"
    );
    assert!(
        h.state().status().contains("autosaved"),
        "{}",
        h.state().status()
    );
    // The "crash": the editor goes away without quitting.
    drop(h);

    let mut again = editor(&score, dir.path());
    assert!(again.state().restore_offered());
    assert_eq!(beats(&again), before, "the file on disk is as it was");
    again.get_by_label("Restore").click();
    common::settle(&mut again);
    assert!(!again.state().restore_offered());
    assert_eq!(beats(&again), before - 1, "the edit is back");
    assert!(
        again.state().is_dirty(),
        "restored changes are not saved yet"
    );
    assert_eq!(again.state().path(), Some(score.as_path()));
    // Saving makes the autosave unnecessary: it goes.
    again.state_mut().save_to(&score);
    again.state_mut().wait_for_files();
    common::settle(&mut again);
    run_for(&mut again, 2.0, |_| !recovery.exists());
    assert!(!recovery.exists(), "a save removes the autosave");
}

#[test]
fn discarding_the_offer_removes_the_autosave_and_a_clean_quit_leaves_none() {
    let dir = tempfile::tempdir().unwrap();
    let score = etude_copy(dir.path());
    let recovery = dir.path().join("recovery.ron");
    let mut h = editor(&score, dir.path());
    let before = beats(&h);
    delete_a_beat(&mut h);
    run_for(&mut h, 4.0, |_| recovery.exists());
    assert!(recovery.exists());
    drop(h);

    let mut again = editor(&score, dir.path());
    assert!(again.state().restore_offered());
    again.get_by_label("Discard").click();
    common::settle(&mut again);
    assert!(!recovery.exists());
    assert_eq!(beats(&again), before);
    drop(again);
    let third = editor(&score, dir.path());
    assert!(!third.state().restore_offered(), "nothing is offered twice");

    // Edit, autosave, then quit cleanly discarding the changes: nothing is left.
    let mut h = third;
    delete_a_beat(&mut h);
    run_for(&mut h, 4.0, |_| recovery.exists());
    assert!(recovery.exists());
    assert!(
        !h.state_mut().request_quit(),
        "it asks about the unsaved change first"
    );
    common::settle(&mut h);
    h.get_by_label("Discard changes").click();
    // The window is closing (the harness keeps running it): no more autosaves either.
    for _ in 0..16 {
        h.step();
    }
    assert!(!recovery.exists(), "a clean quit leaves nothing to recover");
}

/// A recovery file that cannot be read is reported by name, kept, and nothing is offered.
#[test]
fn an_unreadable_autosave_is_reported_and_kept() {
    let dir = tempfile::tempdir().unwrap();
    let score = etude_copy(dir.path());
    let recovery = dir.path().join("recovery.ron");
    std::fs::write(&recovery, "Recovery(version: 1, original: None, score: Sc").unwrap();
    let h = editor(&score, dir.path());
    assert!(!h.state().restore_offered());
    let error = h.state().error().unwrap_or_default().to_string();
    assert!(
        error.contains("autosave") && error.contains("recovery.ron"),
        "{error}"
    );
    assert!(recovery.exists());
}
