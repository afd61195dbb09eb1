//! Keyboard editing of the timeline driven headless: select a beat by clicking it, then
//! copy/duplicate, nudge with the arrow keys, move between lanes, delete — each one undo
//! step — and drag a beat along the timeline as one step.

mod common;

use eframe::egui;
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use std::path::Path;
use timpanist::app::EditorApp;
use timpanist::score::Hand;

fn harness(dir: &Path) -> Harness<'static, EditorApp> {
    let score = common::root().join("scores/etude-modes.ron");
    let mut h = common::editor(Some(score), dir, false);
    settle(&mut h);
    h
}

fn settle(h: &mut Harness<'static, EditorApp>) {
    h.step();
    h.state_mut().wait_for_composition();
    h.run();
}

fn press(h: &mut Harness<'static, EditorApp>, modifiers: egui::Modifiers, key: egui::Key) {
    h.key_press_modifiers(modifiers, key);
    settle(h);
}

fn ticks(h: &Harness<'static, EditorApp>) -> Vec<u64> {
    h.state()
        .loaded()
        .unwrap()
        .score
        .beats
        .iter()
        .map(|b| b.tick)
        .collect()
}

/// Click the second beat, duplicate it (Ctrl+D), nudge the copy right, move it to the
/// Right lane, delete it; every step undoes exactly.
#[test]
fn keyboard_editing() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = harness(dir.path());
    let original = ticks(&h);
    let at = h.state().timeline_point(960, Hand::Auto).unwrap();
    common::click(&mut h, at);
    assert_eq!(h.state().selection().beats.len(), 1);
    let none = egui::Modifiers::NONE;
    press(&mut h, egui::Modifiers::COMMAND, egui::Key::D);
    assert_eq!(ticks(&h).len(), original.len() + 1);
    let sel = *h.state().selection().beats.first().unwrap();
    let copy_tick = ticks(&h)[sel];
    assert!(copy_tick > 960, "the duplicate goes after the original");
    press(&mut h, none, egui::Key::ArrowRight);
    let sel = *h.state().selection().beats.first().unwrap();
    assert!(ticks(&h)[sel] > copy_tick);
    press(&mut h, none, egui::Key::ArrowUp);
    let sel = *h.state().selection().beats.first().unwrap();
    assert_eq!(
        h.state().loaded().unwrap().score.beats[sel].hand,
        Hand::Right
    );
    press(&mut h, none, egui::Key::Delete);
    assert_eq!(ticks(&h), original);
    assert_eq!(h.state().undo_steps(), 4);
    for _ in 0..4 {
        press(&mut h, egui::Modifiers::COMMAND, egui::Key::Z);
    }
    assert_eq!(ticks(&h), original);
    assert!(!h.state().is_dirty());
}

/// Dragging a beat along its lane moves it by whole grid steps, as one undo step.
#[test]
fn drag_beat_is_one_step() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = harness(dir.path());
    let from = h.state().timeline_point(960, Hand::Auto).unwrap();
    let to = h.state().timeline_point(960 + 240, Hand::Auto).unwrap();
    h.hover_at(from);
    settle(&mut h);
    h.drag_at(from);
    settle(&mut h);
    for k in 1..=5 {
        h.hover_at(from + (to - from) * (k as f32 / 5.0));
        settle(&mut h);
    }
    h.drop_at(to);
    settle(&mut h);
    let t = ticks(&h);
    assert!(t.contains(&1200), "{t:?}");
    assert!(!t.contains(&960));
    assert_eq!(h.state().undo_steps(), 1);
}

/// Dragging the tempo point up raises the tempo, as one undo step.
#[test]
fn drag_tempo_point() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = harness(dir.path());
    let lane = h.get_by_label("Tempo lane").rect();
    let point = egui::pos2(lane.left() + 1.0, lane.center().y);
    h.hover_at(point);
    settle(&mut h);
    h.drag_at(point);
    settle(&mut h);
    for k in 1..=4 {
        h.hover_at(point + egui::vec2(0.0, -4.0 * k as f32));
        settle(&mut h);
    }
    h.drop_at(point + egui::vec2(0.0, -16.0));
    settle(&mut h);
    let tempo = &h.state().loaded().unwrap().score.tempo;
    assert_eq!(tempo.len(), 1);
    assert_eq!(tempo[0].tick, 0);
    assert!(tempo[0].bpm > 90.0, "{}", tempo[0].bpm);
    assert_eq!(h.state().undo_steps(), 1);
}

/// Dragging a stroke's impact marker in the 3D view pins it on the head plane, as one
/// undo step; the pinned point keeps the impact's height.
#[test]
fn drag_impact_pins_it() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = harness(dir.path());
    let comp = h.state().composition().unwrap().clone();
    let s = 5;
    let side = comp.strokes[s].hand;
    let impact = comp.tip(side)[comp.impact_samples[s]];
    h.state_mut().seek(comp.strokes[s].time_s);
    settle(&mut h);
    let at = h.state().viewport_point(impact).unwrap();
    h.hover_at(at);
    settle(&mut h);
    h.drag_at(at);
    settle(&mut h);
    for k in 1..=4 {
        h.hover_at(at + egui::vec2(5.0 * k as f32, 0.0));
        settle(&mut h);
    }
    h.drop_at(at + egui::vec2(20.0, 0.0));
    settle(&mut h);
    let pins = &h.state().loaded().unwrap().score.pins;
    assert_eq!(pins.len(), 1, "{}", h.state().status());
    assert_eq!(pins[0].tick, comp.strokes[s].tick);
    assert!((pins[0].point_m[2] - impact.z).abs() < 1e-9);
    assert!((pins[0].point_m[0] - impact.x).abs() > 0.005);
    assert_eq!(h.state().undo_steps(), 1);
}

/// F7 moves the 3D camera to the side view over a few frames (between on the way, exactly
/// there at the end); the View menu's "Camera: top" item does the same for the top view.
#[test]
fn camera_views_from_keys_and_menu() {
    use timpanist::app::Camera;
    use timpanist::scene::camera::View;
    let dir = tempfile::tempdir().unwrap();
    let mut h = harness(dir.path());
    let start = h.state().camera();
    assert_eq!(start, Camera::default());
    h.key_press(egui::Key::F7);
    let side = Camera::of_view(View::Side);
    let mut seen = Vec::new();
    for _ in 0..4 {
        h.step();
        seen.push(h.state().camera());
    }
    assert!(
        seen.iter().any(|c| *c != start && *c != side),
        "the move was a jump: {seen:?}"
    );
    h.run();
    assert_eq!(h.state().camera(), side);
    h.get_by_label("View").click();
    h.run();
    h.get_by_label("Camera: top  (F8)").click();
    h.run();
    assert_eq!(h.state().camera(), Camera::of_view(View::Top));
}
