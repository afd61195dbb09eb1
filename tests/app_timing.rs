//! Measured, not asserted: on a 60-second score, how long a one-beat edit takes to become
//! a new composition (the part of edit-to-audio the editor owns), and how long the
//! editor's frames take while playing (CPU side of `ui`, no GPU), on each plot tab with a
//! rendering of the score. Run with `cargo test --test app_timing -- --nocapture` to see
//! the figures.

mod common;

use eframe::egui;
use egui_kittest::Harness;
use egui_kittest::kittest::{NodeT, Queryable};
use std::path::Path;
use std::time::Instant;
use timpanist::app::EditorApp;
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

/// The editor on `score` (recent files in `dir`, no sound device), rendering if
/// `render`.
fn editor(score: std::path::PathBuf, dir: &Path, render: bool) -> Harness<'static, EditorApp> {
    common::editor(Some(score), dir, render)
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
    let score = sixty_seconds(dir.path());
    let mut h = editor(score, dir.path(), false);
    h.step();
    assert!(h.state_mut().wait_for_composition().is_some());
    h.run();
    let first = h.state().last_compose_time().unwrap();

    // Select a beat on the 26-inch drum (the template of new beats), then add one in the
    // right hand's lane: the grid at this zoom is a bar, so it lands with a bar's first
    // beat (on the 32-inch drum), which automatic sticking then gives the left hand.
    h.state_mut().show_beat(102);
    h.step();
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
    let rendering = common::render_once(h.state().loaded().unwrap());
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

/// The 3D view drawn lit on the GPU (wgpu; here a software rasteriser, llvmpipe or
/// lavapipe) on the one-minute demo study with its rendering, playing: the CPU side of a
/// frame (the UI, which builds the stage's triangles and the heads' motion) and a whole
/// frame with the GPU's drawing and the image read back. Measured, not asserted.
#[test]
fn gpu_view_frame_times() {
    let dir = tempfile::tempdir().unwrap();
    let score = common::root().join("scores/minute-study.ron");
    let mut h = common::wgpu_editor(score, dir.path());
    let rendering = common::render_once(h.state().loaded().unwrap());
    h.key_press(egui::Key::Space);
    h.state_mut().set_rendering(std::sync::Arc::new(rendering));
    h.state_mut().seek(10.0);
    h.step();
    assert!(h.state().playback().is_playing());
    let (median, max) = frame_times(&mut h, 60);
    let mut whole = Vec::new();
    for _ in 0..20 {
        let t = Instant::now();
        h.step();
        h.render().unwrap();
        whole.push(t.elapsed().as_secs_f64() * 1e3);
    }
    println!(
        "GPU 3D view, one-minute study playing: CPU side of a frame median {median:.1} ms, \
         max {max:.1} ms; with the GPU drawing and read-back median {:.1} ms, max {:.1} ms",
        percentile(&mut whole, 0.5),
        percentile(&mut whole, 1.0)
    );
}

/// Percentile `p` (0–1) of `values` (sorted in place).
fn percentile(values: &mut [f64], p: f64) -> f64 {
    values.sort_by(f64::total_cmp);
    values[((values.len() - 1) as f64 * p).round() as usize]
}

/// Step the editor until it holds a rendering other than `old` (complete if `complete`),
/// recording each frame's time, ms. Panics after `limit_s`.
fn step_until_rendering(
    h: &mut Harness<'static, EditorApp>,
    old: Option<*const timpanist::render::Rendering>,
    complete: bool,
    frames: &mut Vec<f64>,
    limit_s: f64,
) {
    let began = Instant::now();
    loop {
        let t = Instant::now();
        h.step();
        frames.push(t.elapsed().as_secs_f64() * 1e3);
        if let Some(r) = h.state().rendering()
            && Some(std::sync::Arc::as_ptr(r)) != old
            && (r.complete || !complete)
        {
            return;
        }
        assert!(
            began.elapsed().as_secs_f64() < limit_s,
            "no rendering after {limit_s} s: {} / {:?}",
            h.state().status(),
            h.state().render_error()
        );
        std::thread::sleep(std::time::Duration::from_millis(2));
    }
}

/// With the real render worker on the one-minute demo study: the editor's frames while
/// the whole score renders, and after a one-beat edit near 30 s the time until audio
/// past the edit is ready (the worker resumes from its saved state before the edit and
/// first renders one second past it) and until the whole score is rendered again.
#[test]
fn render_worker_frames_and_edit_to_ready_audio() {
    let dir = tempfile::tempdir().unwrap();
    let score = Path::new(env!("CARGO_MANIFEST_DIR")).join("scores/minute-study.ron");
    let mut h = editor(score, dir.path(), true);
    let mut during_render = Vec::new();
    let began = Instant::now();
    step_until_rendering(&mut h, None, true, &mut during_render, 120.0);
    let first = began.elapsed().as_secs_f64();
    let frames = during_render.len();
    let (median, p99, max) = (
        percentile(&mut during_render, 0.5),
        percentile(&mut during_render, 0.99),
        percentile(&mut during_render, 1.0),
    );
    println!(
        "one-minute study with the render worker: first whole rendering after {first:.1} s; \
         {frames} frames meanwhile: median {median:.1} ms, 99th percentile {p99:.1} ms, \
         max {max:.1} ms"
    );
    let before = h.state().rendering().map(std::sync::Arc::as_ptr);
    // The beat at tick 46080 (30.625 s) becomes a tenuto: select it, press 2.
    let at = h.state().timeline_point(46080, Hand::Auto).unwrap();
    h.hover_at(at);
    h.step();
    h.drag_at(at);
    h.step();
    h.drop_at(at);
    h.step();
    assert_eq!(h.state().selection().beats.len(), 1, "the beat is selected");
    h.key_press(egui::Key::Num2);
    let edited = Instant::now();
    let mut after_edit = Vec::new();
    step_until_rendering(&mut h, before, false, &mut after_edit, 120.0);
    let ready = edited.elapsed().as_secs_f64() * 1e3;
    let partial = h.state().rendering().unwrap().clone();
    let quick = !partial.complete;
    let from = partial.stats.resumed_from_s;
    let ready_s = partial.ready_s;
    println!(
        "the first step after the edit: simulating {:.1} ms, its sound {:.1} ms",
        partial.stats.simulate.as_secs_f64() * 1e3,
        partial.stats.sound.as_secs_f64() * 1e3
    );
    let before = h.state().rendering().map(std::sync::Arc::as_ptr);
    if quick {
        step_until_rendering(&mut h, before, true, &mut after_edit, 120.0);
    }
    let whole = edited.elapsed().as_secs_f64() * 1e3;
    let rest = h.state().rendering().unwrap();
    assert!(from.is_some(), "the edit resumes from a saved state");
    assert!(rest.complete && rest.stats.resumed_from_s.is_some());
    assert!(
        h.state().status().contains("re-simulated from"),
        "{}",
        h.state().status()
    );
    let max_frame = percentile(&mut after_edit, 1.0);
    println!(
        "one-beat edit at 30.6 s (mode changed): audio ready to {ready_s:.1} s (resumed at {:.2} s, \
         {:.2} s simulated in {} attempts) after {ready:.0} ms; whole score rendered again after \
         {whole:.0} ms; longest frame meanwhile {max_frame:.1} ms",
        from.unwrap_or(0.0),
        partial.stats.simulated_s,
        partial.stats.attempts
    );
}
