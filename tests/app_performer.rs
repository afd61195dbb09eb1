//! The performer on screen (issue 21) driven headless: slow motion and stepping the
//! playhead by frames and contacts.

mod common;

use eframe::egui;
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use std::path::Path;
use std::time::{Duration, Instant};
use timpanist::app::EditorApp;

fn harness(dir: &Path) -> Harness<'static, EditorApp> {
    let score = common::root().join("scores/etude-modes.ron");
    let mut h = common::editor(Some(score), dir, false);
    common::settle(&mut h);
    h
}

fn press(h: &mut Harness<'static, EditorApp>, modifiers: egui::Modifiers, key: egui::Key) {
    h.key_press_modifiers(modifiers, key);
    common::settle(h);
}

/// `[` slows playback to 1/2, 1/4, 1/10 (and no further) with the audio muted and a notice
/// saying so; at 1/4 the playhead moves a quarter as fast as the wall clock; `]` goes back
/// to real time and the notice goes.
#[test]
fn slow_motion() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = harness(dir.path());
    let none = egui::Modifiers::NONE;
    assert_eq!(h.state().playback().speed(), 1.0);
    assert!(h.query_by_label("slow motion: audio muted").is_none());
    for expected in [0.5, 0.25, 0.1, 0.1] {
        press(&mut h, none, egui::Key::OpenBracket);
        assert_eq!(h.state().playback().speed(), expected);
    }
    h.get_by_label("slow motion: audio muted");
    press(&mut h, none, egui::Key::CloseBracket);
    assert_eq!(h.state().playback().speed(), 0.25);
    press(&mut h, none, egui::Key::Space);
    assert!(h.state().playback().is_playing());
    let (t0, wall0) = (h.state().playhead_s(), Instant::now());
    std::thread::sleep(Duration::from_millis(400));
    h.step();
    let (t1, wall) = (h.state().playhead_s(), wall0.elapsed().as_secs_f64());
    let rate = (t1 - t0) / wall;
    assert!((0.2..0.3).contains(&rate), "{rate} score s per s");
    press(&mut h, none, egui::Key::Space);
    for _ in 0..2 {
        press(&mut h, none, egui::Key::CloseBracket);
    }
    assert!(h.state().playback().is_real_time());
    assert!(h.query_by_label("slow motion: audio muted").is_none());
}

/// `.` and `,` step the playhead by video frames (1/60 s, pausing playback);
/// Shift+`.` and Shift+`,` go to the next and previous contact.
#[test]
fn frame_and_contact_steps() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = harness(dir.path());
    let none = egui::Modifiers::NONE;
    let strokes: Vec<f64> = (h.state().composition().unwrap().strokes.iter())
        .map(|s| s.time_s)
        .collect();
    press(&mut h, none, egui::Key::Space);
    std::thread::sleep(Duration::from_millis(100));
    press(&mut h, none, egui::Key::Period);
    assert!(!h.state().playback().is_playing(), "a step pauses");
    let frame = (h.state().playhead_s() * 60.0).round();
    assert!(frame >= 1.0);
    assert!((h.state().playhead_s() - frame / 60.0).abs() < 1e-9);
    for _ in 0..3 {
        press(&mut h, none, egui::Key::Period);
    }
    press(&mut h, none, egui::Key::Comma);
    assert!((h.state().playhead_s() - (frame + 2.0) / 60.0).abs() < 1e-9);
    let here = h.state().playhead_s();
    let next = strokes.iter().copied().find(|t| *t > here).unwrap();
    press(&mut h, egui::Modifiers::SHIFT, egui::Key::Period);
    assert_eq!(h.state().playhead_s(), next);
    press(&mut h, egui::Modifiers::SHIFT, egui::Key::Period);
    let second = h.state().playhead_s();
    assert!(second > next);
    press(&mut h, egui::Modifiers::SHIFT, egui::Key::Comma);
    assert_eq!(h.state().playhead_s(), next);
}
