//! A snapshot of the editor's main window on the demo score, rendered headless with wgpu
//! (software rendering is enough: lavapipe or llvmpipe). The status bar, which shows
//! timings and the sound device's message, is masked. Update with UPDATE_SNAPSHOTS=1.

mod common;

use eframe::egui;
use timpanist::app::EditorApp;

/// The main window with every panel, as rendered, matches the stored snapshot.
#[test]
fn main_window_snapshot() {
    let dir = tempfile::tempdir().unwrap();
    let score = common::root().join("scores/etude-modes.ron");
    let options = common::options(Some(score), dir.path(), false);
    let mut h = common::builder()
        .wgpu()
        .build_eframe(move |_cc| EditorApp::with_options(options));
    common::settle(&mut h);
    h.mask(egui::Rect::from_min_max(
        egui::pos2(0.0, 870.0),
        egui::pos2(1400.0, 900.0),
    ));
    h.snapshot("main_window");
}
