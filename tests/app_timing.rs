//! Measured, not asserted: on a 60-second score, how long a one-beat edit takes to become
//! a new composition (the part of edit-to-audio the editor owns), and how long the
//! editor's frames take while playing (CPU side of `ui`, no GPU), on each plot tab with a
//! rendering of the score. Run with `cargo test --test app_timing -- --nocapture` to see
//! the figures.

use eframe::egui;
use egui_kittest::Harness;
use egui_kittest::kittest::{NodeT, Queryable};
use std::path::Path;
use std::time::Instant;
use timpanist::app::{EditorApp, EditorOptions};
use timpanist::mocap::db::MotionDb;
use timpanist::render::{RenderParams, render};
use timpanist::score::{Beat, Hand, Score};

/// Median and maximum of `n` frame times while playing, ms.
fn frame_times(h: &mut Harness<'static, EditorApp>, n: usize) -> (f64, f64) {
    let mut frames = Vec::with_capacity(n);
    for _ in 0..n {
        let t = Instant::now();
        h.step();
        frames.push(t.elapsed().as_secs_f64() * 1e3);
    }
    frames.sort_by(f64::total_cmp);
    (frames[n / 2], frames[n - 1])
}

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
    let (median, max) = frame_times(&mut h, 60);
    println!(
        "60 s score, 200 beats: first composition (with database load) {:.0} ms; \
         one-beat edit to new composition {:.0} ms (worker {:.0} ms); \
         frames while playing: median {median:.1} ms, max {max:.1} ms",
        first.as_secs_f64() * 1e3,
        edit_to_composition.as_secs_f64() * 1e3,
        worker.as_secs_f64() * 1e3,
    );

    // The score as edited, rendered in one simulation pass (the plots' cost does not
    // depend on how many passes made the rendering) and handed to the editor.
    let loaded = h.state().loaded().unwrap().clone();
    let db = MotionDb::load(&timpanist::mocap::db::default_dir()).unwrap();
    let params = RenderParams {
        max_attempts: 1,
        ..RenderParams::default()
    };
    let rendering = render(&loaded, &db, &params, &mut |_| true).unwrap();
    let contacts = rendering.events.len();
    h.state_mut().set_rendering(std::sync::Arc::new(rendering));
    h.step();
    assert!(h.state().playback().is_playing());
    for tab in [
        "Composed tips",
        "Simulated tips",
        "Contact force",
        "Sound",
        "Joint angles",
    ] {
        h.get_by_label(tab).click();
        // The first frame on a tab builds its points for this rendering.
        let t = Instant::now();
        h.step();
        let build = t.elapsed().as_secs_f64() * 1e3;
        let (median, max) = frame_times(&mut h, 60);
        println!(
            "plot tab {tab:15} ({contacts} contacts): first frame {build:.1} ms, \
             frames while playing: median {median:.1} ms, max {max:.1} ms"
        );
        if tab == "Sound" {
            // Jump to another strike: the frame analyses its spectrum.
            h.state_mut().seek(30.0);
            let t = Instant::now();
            h.step();
            let spent = t.elapsed().as_secs_f64() * 1e3;
            let label = h
                .get_by_label_contains("Spectrum of the strike at")
                .accesskit_node()
                .value()
                .unwrap_or_default();
            assert!(
                label.contains(" at 29.") || label.contains(" at 30."),
                "{label}"
            );
            println!("plot tab Sound: a frame analysing a new strike {spent:.1} ms");
        }
    }
}
