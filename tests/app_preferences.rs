//! Edit > Preferences as a user meets them: the preferences file's theme, UI scale and kit
//! of a new score apply when the editor starts; Ctrl+, opens the window; a change there
//! applies at once and is saved to the file; a broken file is reported and not
//! overwritten until a change is made.

mod common;

use common::{builder, options, root, settle};
use eframe::egui;
use egui_kittest::kittest::Queryable;
use timpanist::app::EditorApp;

fn start(dir: &std::path::Path) -> egui_kittest::Harness<'static, EditorApp> {
    let opts = options(Some(root().join("scores/improvisation.ron")), dir, false);
    builder().build_eframe(move |_cc| EditorApp::with_options(opts))
}

#[test]
fn preferences_apply_at_start_and_changes_are_saved() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("preferences.ron");
    std::fs::write(
        &file,
        "(theme: Light, ui_scale: 1.25, default_kit: \"pair\")",
    )
    .unwrap();
    let mut h = start(dir.path());
    settle(&mut h);
    assert_eq!(h.ctx.zoom_factor(), 1.25);
    assert_eq!(h.ctx.theme(), egui::Theme::Light);

    // A new score takes the preferred kit.
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::N);
    settle(&mut h);
    let loaded = h.state().loaded().unwrap();
    assert_eq!(loaded.score.kit, "pair");
    assert_eq!(loaded.kit.drums.len(), 2);

    // Ctrl+, opens the window; choosing the dark theme applies and saves it.
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Comma);
    settle(&mut h);
    h.get_by_label("dark").click();
    settle(&mut h);
    assert_eq!(h.ctx.theme(), egui::Theme::Dark);
    let saved = std::fs::read_to_string(&file).unwrap();
    assert!(saved.contains("theme: Dark"), "{saved}");
    assert!(saved.contains("default_kit: \"pair\""), "{saved}");
}

#[test]
fn a_broken_preferences_file_is_reported_and_kept() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("preferences.ron");
    std::fs::write(&file, "(theme: Purple)").unwrap();
    let mut h = start(dir.path());
    settle(&mut h);
    let error = h.state().error().unwrap_or_default().to_string();
    assert!(error.contains("preferences.ron"), "{error}");
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "(theme: Purple)");
}
