//! Snapshots of the editor's main window on the demo score, rendered headless with wgpu
//! (software rendering is enough: lavapipe or llvmpipe): the 3D view lit and
//! depth-buffered on the GPU, and the flat view it falls back to (View > Flat 3D view).
//! The status bar, which shows timings and the sound device's message, is masked. Update
//! with UPDATE_SNAPSHOTS=1.

mod common;

use eframe::egui;
use egui_kittest::Harness;
use timpanist::app::EditorApp;

fn window() -> (Harness<'static, EditorApp>, tempfile::TempDir) {
    let dir = tempfile::tempdir().unwrap();
    let score = common::root().join("scores/etude-modes.ron");
    let h = common::wgpu_editor(score, dir.path());
    (h, dir)
}

/// Snapshot the window as `name`, the status bar masked.
fn snapshot(h: &mut Harness<'static, EditorApp>, name: &str) {
    h.mask(egui::Rect::from_min_max(
        egui::pos2(0.0, 870.0),
        egui::pos2(1400.0, 900.0),
    ));
    h.snapshot(name);
}

/// The main window with every panel, the stage drawn lit on the GPU, matches the stored
/// snapshot.
#[test]
fn main_window_snapshot() {
    let (mut h, _dir) = window();
    snapshot(&mut h, "main_window");
}

/// With View > Flat 3D view the stage is drawn as flat marks, as when no GPU draws it.
#[test]
fn flat_view_snapshot() {
    let (mut h, _dir) = window();
    common::choose(&mut h, "View", "Flat 3D view (no lighting)");
    snapshot(&mut h, "main_window_flat");
}
