//! A snapshot of the editor's main window on the demo score, rendered headless with wgpu
//! (software rendering is enough: lavapipe or llvmpipe). The status bar, which shows
//! timings and the sound device's message, is masked. Update with UPDATE_SNAPSHOTS=1.

use eframe::egui;
use egui_kittest::Harness;
use std::path::Path;
use timpanist::app::{EditorApp, EditorOptions};

/// The main window with every panel, as rendered, matches the stored snapshot.
#[test]
fn main_window_snapshot() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    std::env::set_current_dir(root).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let options = EditorOptions {
        score: Some(root.join("scores/etude-modes.ron")),
        recent_store: Some(dir.path().join("recent.txt")),
        audio_device: false,
        render: false,
    };
    let mut h = Harness::builder()
        .with_size(egui::vec2(1400.0, 900.0))
        .with_max_steps(64)
        .wgpu()
        .build_eframe(move |_cc| EditorApp::with_options(options));
    h.step();
    h.state_mut().wait_for_composition();
    h.run();
    h.mask(egui::Rect::from_min_max(
        egui::pos2(0.0, 870.0),
        egui::pos2(1400.0, 900.0),
    ));
    h.snapshot("main_window");
}
