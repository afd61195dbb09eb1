//! The in-window file browser the editor falls back to where the system's dialog cannot
//! open (no desktop portal): Ctrl+O shows it, a click on a score and on Open loads that
//! score; Save As writes where it is told; Cancel leaves everything as it was; File >
//! Export MusicXML needs no rendering and writes a score that imports back.

mod common;

use common::{editor, root, settle};
use eframe::egui;
use egui_kittest::kittest::{NodeT, Queryable};
use std::path::Path;

/// The editor on the demo score `name` from `scores/`, settled (no rendering).
fn settled(dir: &Path, name: &str) -> egui_kittest::Harness<'static, timpanist::app::EditorApp> {
    let mut h = editor(Some(root().join(format!("scores/{name}.ron"))), dir, false);
    settle(&mut h);
    h
}

/// Save As by its shortcut, settled.
fn save_as(h: &mut egui_kittest::Harness<'static, timpanist::app::EditorApp>) {
    h.key_press_modifiers(
        egui::Modifiers::COMMAND | egui::Modifiers::SHIFT,
        egui::Key::S,
    );
    settle(h);
}

#[test]
fn ctrl_o_opens_the_in_window_browser_and_it_opens_a_score() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = settled(dir.path(), "etude-modes");
    assert!(!h.state().is_file_browser_open());
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::O);
    settle(&mut h);
    assert!(h.state().is_file_browser_open(), "Ctrl+O showed no dialog");
    // The browser starts in the score's folder, showing the other demo scores.
    h.get_by_label("improvisation.ron").click();
    settle(&mut h);
    h.get_by_label("Open").click();
    settle(&mut h);
    assert!(!h.state().is_file_browser_open());
    let path = h.state().path().map(Path::to_path_buf);
    assert_eq!(
        path.as_deref().and_then(|p| p.file_name()),
        Some(std::ffi::OsStr::new("improvisation.ron")),
        "error: {:?}",
        h.state().error()
    );
}

#[test]
fn save_as_writes_where_the_browser_is_told_and_cancel_changes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = settled(dir.path(), "improvisation");
    // Cancel: nothing saved, the score still where it was.
    save_as(&mut h);
    assert!(h.state().is_file_browser_open(), "Save As showed no dialog");
    h.get_by_label("Cancel").click();
    settle(&mut h);
    assert!(!h.state().is_file_browser_open());
    // Escape closes it too (the editor's own Escape shortcut waits while it shows).
    save_as(&mut h);
    assert!(h.state().is_file_browser_open());
    h.key_press(egui::Key::Escape);
    settle(&mut h);
    assert!(
        !h.state().is_file_browser_open(),
        "Escape left the browser open"
    );
    assert!(
        h.state()
            .path()
            .unwrap()
            .ends_with("scores/improvisation.ron")
    );

    // The Places list offers the recent files' folder; go there and save.
    let target_dir = dir.path().join("lessons");
    std::fs::create_dir_all(&target_dir).unwrap();
    let other = target_dir.join("other.ron");
    std::fs::copy(root().join("scores/roll-exercise.ron"), &other).unwrap();
    h.state_mut().open_path(&other);
    h.state_mut()
        .open_path(&root().join("scores/improvisation.ron"));
    settle(&mut h);
    save_as(&mut h);
    h.get_by_label("lessons").click();
    settle(&mut h);
    h.get_by_label("Save").click();
    settle(&mut h);
    h.state_mut().wait_for_files();
    settle(&mut h);
    let saved = target_dir.join("improvisation.ron");
    assert!(saved.is_file(), "not saved: {:?}", h.state().error());
    assert_eq!(h.state().path(), Some(saved.as_path()));
    timpanist::score::LoadedScore::load(&saved).expect("the saved score loads");
}

/// File > Demo scores opens a built-in demo as a new, unsaved score.
#[test]
fn the_demo_scores_menu_opens_a_built_in_demo() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = settled(dir.path(), "improvisation");
    h.get_by_label("File").click();
    settle(&mut h);
    h.get_by_label("Demo scores").click();
    settle(&mut h);
    h.get_by_label("roll-exercise").click();
    settle(&mut h);
    let want = timpanist::score::demos::score("roll-exercise").unwrap();
    let loaded = h.state().loaded().expect("a score is open");
    assert_eq!(loaded.score.title, want.title);
    assert_eq!(loaded.score.beats.len(), want.beats.len());
    assert_eq!(h.state().path(), None, "a demo opens unsaved");
}

/// File > Export MusicXML... needs no rendering: it is enabled while rendering is off
/// and asks where to write; the export (here without the dialog) writes MusicXML that
/// imports back with the score's beats at the same ticks and pitches, and `.mxl` a zip.
#[test]
fn export_musicxml_from_the_file_menu() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = settled(dir.path(), "roll-exercise");
    h.get_by_label("File").click();
    settle(&mut h);
    let item = h.get_by_label("Export MusicXML...");
    assert!(!item.accesskit_node().is_disabled());
    assert!(
        h.get_by_label("Export WAV...")
            .accesskit_node()
            .is_disabled()
    );
    h.get_by_label("Export MusicXML...").click();
    settle(&mut h);
    assert!(h.state().is_file_browser_open(), "no dialog");
    h.get_by_label("Cancel").click();
    settle(&mut h);

    let loaded =
        timpanist::score::LoadedScore::load(&root().join("scores/roll-exercise.ron")).unwrap();
    for name in ["roll.musicxml", "roll.mxl"] {
        let path = dir.path().join(name);
        h.state_mut().export_musicxml_to(&path);
        h.state_mut().wait_for_files();
        assert!(h.state().error().is_none(), "{:?}", h.state().error());
        let (back, _) = timpanist::io::musicxml::import_file(
            &path,
            &loaded.kit,
            &timpanist::io::musicxml::ImportOptions::default(),
        )
        .unwrap();
        let notes = |s: &timpanist::score::Score| -> Vec<(u64, u8)> {
            s.beats
                .iter()
                .map(|b| (b.tick, b.sounding_pitch(&loaded.kit).0))
                .collect()
        };
        assert_eq!(notes(&back), notes(&loaded.score), "{name}");
    }
    let mxl = std::fs::read(dir.path().join("roll.mxl")).unwrap();
    assert!(mxl.starts_with(b"PK\x03\x04"));
}
