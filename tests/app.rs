//! The editor driven headless through egui_kittest: it opens the demo score and shows it.

use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use std::path::Path;
use timpanist::app::EditorApp;

/// The editor opens the bundled demo score, shows its title and the kit, and no error.
#[test]
fn opens_demo_score() {
    let demo = Path::new(env!("CARGO_MANIFEST_DIR")).join("scores/etude-modes.ron");
    let mut harness = Harness::new_eframe(|_cc| EditorApp::new(Some(&demo)));
    harness.state_mut().wait_for_composition();
    harness.run();
    let app = harness.state();
    assert!(app.error().is_none(), "{:?}", app.error());
    assert_eq!(app.loaded().unwrap().score.beats.len(), 16);
    harness.get_by_label("Etude in five modes and three spots");
    harness.get_by_label("Standard set (32/29/26/23 inch)");
}

/// The editor composes the open score's stick-tip trajectories in the background and
/// shows them once they arrive.
#[test]
fn composes_in_the_background() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    std::env::set_current_dir(root).unwrap();
    let demo = root.join("scores/improvisation.ron");
    let mut harness = Harness::new_eframe(|_cc| EditorApp::new(Some(&demo)));
    let strokes = harness
        .state_mut()
        .wait_for_composition()
        .map(|c| c.strokes.len());
    assert_eq!(strokes, Some(5));
    harness.run();
    harness.get_by_label("Right tip");
}

/// A score that fails to load is reported in the window instead of crashing.
#[test]
fn load_error_is_shown() {
    let mut harness =
        Harness::new_eframe(|_cc| EditorApp::new(Some(Path::new("/no/such/score.ron"))));
    harness.run();
    assert!(
        harness
            .state()
            .error()
            .unwrap()
            .contains("/no/such/score.ron")
    );
    harness.get_by_label_contains("Error: ");
}
