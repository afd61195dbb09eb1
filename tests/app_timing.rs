//! Measured, not asserted: on a 60-second score, how long a one-beat edit takes to become
//! a new composition (the part of edit-to-audio the editor owns), and how long the
//! editor's frames take while playing (CPU side of `ui`, no GPU). Run with
//! `cargo test --test app_timing -- --nocapture` to see the figures.

use eframe::egui;
use egui_kittest::Harness;
use std::path::Path;
use std::time::Instant;
use timpanist::app::{EditorApp, EditorOptions};
use timpanist::score::{Beat, Hand, Score};

/// A 60-second score: eighth notes at 100 bpm over all four drums.
fn sixty_seconds(dir: &Path) -> std::path::PathBuf {
    let mut s = Score::new("sixty seconds");
    s.beats = (0..200u64)
        .map(|k| Beat::plain(k * 480, (k % 4) as usize))
        .collect();
    assert!((s.duration_s() - 59.7).abs() < 0.1, "{}", s.duration_s());
    let path = dir.join("sixty.ron");
    s.save(&path).unwrap();
    path
}

/// One click adds a beat and a new composition arrives; frames stay cheap while playing.
#[test]
fn edit_to_composition_and_frame_times() {
    let dir = tempfile::tempdir().unwrap();
    std::env::set_current_dir(env!("CARGO_MANIFEST_DIR")).unwrap();
    let options = EditorOptions {
        score: Some(sixty_seconds(dir.path())),
        recent_store: Some(dir.path().join("recent.txt")),
        audio_device: false,
        render: false,
    };
    let mut h = Harness::builder()
        .with_size(egui::vec2(1400.0, 900.0))
        .with_max_steps(64)
        .build_eframe(move |_cc| EditorApp::with_options(options));
    h.step();
    assert!(h.state_mut().wait_for_composition().is_some());
    h.run();
    let first = h.state().last_compose_time().unwrap();

    let at = h
        .state()
        .timeline_point(480 * 101 + 240, Hand::Right)
        .unwrap();
    h.hover_at(at);
    h.step();
    h.drag_at(at);
    h.step();
    h.drop_at(at);
    let t0 = Instant::now();
    h.step();
    let strokes = h.state_mut().wait_for_composition().unwrap().strokes.len();
    let edit_to_composition = t0.elapsed();
    assert_eq!(strokes, 201, "the new beat is composed");
    let worker = h.state().last_compose_time().unwrap();

    h.key_press(egui::Key::Space);
    let mut frames = Vec::new();
    for _ in 0..60 {
        let t = Instant::now();
        h.step();
        frames.push(t.elapsed().as_secs_f64() * 1e3);
    }
    frames.sort_by(f64::total_cmp);
    println!(
        "60 s score, 200 beats: first composition (with database load) {:.0} ms; \
         one-beat edit to new composition {:.0} ms (worker {:.0} ms); \
         frames while playing: median {:.1} ms, max {:.1} ms",
        first.as_secs_f64() * 1e3,
        edit_to_composition.as_secs_f64() * 1e3,
        worker.as_secs_f64() * 1e3,
        frames[frames.len() / 2],
        frames[frames.len() - 1]
    );
}
