//! The performer on screen (issue 21) driven headless: slow motion and stepping the
//! playhead by frames and contacts.

mod common;

use eframe::egui;
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use std::path::Path;
use std::time::{Duration, Instant};
use timpanist::app::EditorApp;
use timpanist::app::playback::SLOW_MOTION_NOTICE as SLOW;

fn harness(dir: &Path) -> Harness<'static, EditorApp> {
    harness_on(dir, "etude-modes")
}

/// The editor on the bundled score `name` (the etude is played by the right hand alone;
/// the dynamics ladder alternates hands).
fn harness_on(dir: &Path, name: &str) -> Harness<'static, EditorApp> {
    let score = common::root().join(format!("scores/{name}.ron"));
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
    assert!(h.query_by_label(SLOW).is_none());
    for expected in [0.5, 0.25, 0.1, 0.1] {
        press(&mut h, none, egui::Key::OpenBracket);
        assert_eq!(h.state().playback().speed(), expected);
    }
    h.get_by_label(SLOW);
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
    assert!(h.query_by_label(SLOW).is_none());
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

/// View > Camera: follow the hand moves the camera's target after the tip of the hand
/// that strikes next — gliding, not jumping, when the playhead moves to the other hand's
/// stroke — and a named view (F6) stops it.
#[test]
fn camera_follows_the_next_hand() {
    use timpanist::kit::Side;
    let dir = tempfile::tempdir().unwrap();
    let mut h = harness_on(dir.path(), "dynamics-ladder");
    let comp = h.state().composition().unwrap().clone();
    // A stroke of each hand right after one of the other hand's.
    let after_other = |hand: Side| {
        comp.strokes
            .windows(2)
            .find(|w| w[1].hand == hand && w[0].hand != hand && w[1].time_s - w[0].time_s > 0.05)
            .map(|w| w[1].time_s - 0.02)
            .unwrap()
    };
    let tip = |t: f64, hand: Side| {
        let k = ((t - comp.start_s) * comp.rate_hz).round() as usize;
        comp.tip(hand)[k]
    };
    h.get_by_label("View").click();
    h.run();
    h.get_by_label("Camera: follow the hand that strikes next  (F9)")
        .click();
    common::settle(&mut h);
    assert!(h.state().is_following_hand());
    let t_right = after_other(Side::Right);
    h.state_mut().seek(t_right);
    h.run();
    let goal = tip(t_right, Side::Right);
    let target = h.state().camera().target;
    assert!(target.distance(goal) < 0.005, "{target} vs {goal}");
    let t_left = after_other(Side::Left);
    h.state_mut().seek(t_left);
    let goal = tip(t_left, Side::Left);
    let start = target.distance(goal);
    assert!(start > 0.05, "the hands' tips are apart: {start}");
    h.step();
    let between = h.state().camera().target.distance(goal);
    assert!(
        between > 0.05 * start && between < 0.95 * start,
        "{between} of {start}"
    );
    h.run();
    assert!(h.state().camera().target.distance(goal) < 0.005);
    h.key_press(egui::Key::F6);
    h.run();
    assert!(!h.state().is_following_hand());
}

/// F frames the selected beat's impact (centred, closer than the default camera), and
/// with nothing selected the whole kit (every head's centre inside the view).
#[test]
fn frame_the_selection() {
    use timpanist::app::Camera;
    let dir = tempfile::tempdir().unwrap();
    let mut h = harness(dir.path());
    let b = 3;
    h.state_mut().show_beat(b);
    common::settle(&mut h);
    h.key_press(egui::Key::F);
    h.run();
    let comp = h.state().composition().unwrap().clone();
    let (stroke, k) = comp
        .strokes
        .iter()
        .zip(&comp.impact_samples)
        .find(|(s, _)| s.beat == b)
        .unwrap();
    let impact = comp.tip(stroke.hand)[*k];
    let rect = h.state().viewport_rect().unwrap();
    let at = h.state().viewport_point(impact).unwrap();
    assert!((at - rect.center()).length() < 2.0, "{at:?} in {rect:?}");
    let close = h.state().camera().distance;
    assert!(close < Camera::default().distance, "{close}");
    h.key_press(egui::Key::Escape);
    h.key_press(egui::Key::F);
    h.run();
    assert!(h.state().selection().beats.is_empty());
    assert!(h.state().camera().distance > close);
    let kit = h.state().loaded().unwrap().kit.clone();
    for drum in &kit.drums {
        let at = h.state().viewport_point(drum.centre()).unwrap();
        assert!(
            rect.contains(at),
            "{} at {at:?} outside {rect:?}",
            drum.name
        );
    }
}

/// Saving writes the 3D camera into the score (`view: (camera: …)`) without the camera
/// alone marking the score changed; opening the saved score brings the camera back.
#[test]
fn camera_is_saved_with_the_score() {
    use timpanist::app::Camera;
    use timpanist::scene::camera::View;
    use timpanist::score::LoadedScore;
    let dir = tempfile::tempdir().unwrap();
    let mut h = harness(dir.path());
    h.key_press(egui::Key::F6);
    h.run();
    let front = Camera::of_view(View::Front);
    assert_eq!(h.state().camera(), front);
    assert!(!h.state().is_dirty(), "moving the camera is not an edit");
    let path = dir.path().join("saved.ron");
    h.state_mut().save_to(&path);
    h.state_mut().wait_for_files();
    let saved = LoadedScore::load(&path).unwrap().score;
    let camera = saved.view.unwrap().camera.unwrap();
    assert!((f64::from(camera.yaw_rad) - front.yaw).abs() < 1e-6);
    assert!((f64::from(camera.distance_m) - front.distance).abs() < 1e-6);
    let mut reopened = common::editor(Some(path), dir.path(), false);
    common::settle(&mut reopened);
    let back = reopened.state().camera();
    assert!(back.target.distance(front.target) < 1e-6, "{back:?}");
    assert!((back.pitch - front.pitch).abs() < 1e-6 && (back.yaw - front.yaw).abs() < 1e-6);
    assert!((back.distance - front.distance).abs() < 1e-6);
}

/// View > Trajectories coloured by speed shows the speed ramp's legend, by phase the four
/// phases' names, plain the hands' names again.
#[test]
fn trajectories_coloured_by_speed_or_phase() {
    use timpanist::scene::trail::TrailColour;
    let dir = tempfile::tempdir().unwrap();
    let mut h = harness(dir.path());
    assert_eq!(h.state().trajectory_colour(), TrailColour::Plain);
    h.get_by_label("left target");
    assert!(h.query_by_label("tip speed, m/s").is_none());
    let choose = |h: &mut Harness<'static, EditorApp>, item: &str| common::choose(h, "View", item);
    choose(&mut h, "Trajectories coloured by speed");
    assert_eq!(h.state().trajectory_colour(), TrailColour::Speed);
    h.get_by_label("tip speed, m/s");
    assert!(h.query_by_label("left target").is_none());
    choose(&mut h, "Trajectories coloured by phase");
    assert_eq!(h.state().trajectory_colour(), TrailColour::Phase);
    for phase in ["preparation", "downstroke", "contact", "rebound"] {
        h.get_by_label(phase);
    }
    assert!(h.query_by_label("tip speed, m/s").is_none());
    choose(&mut h, "Trajectories coloured plain (by hand)");
    assert_eq!(h.state().trajectory_colour(), TrailColour::Plain);
    h.get_by_label("right target");
}

/// View > Overlay the target pose shows the IK pose of the composed tips over the
/// simulated body, and View > Overlay the previous rendering shows the body of the
/// rendering before the last one (a score with a louder second beat here) — each named
/// in the view's legend while shown, and only once there is something to show.
#[test]
fn target_and_previous_rendering_overlaid() {
    use std::sync::Arc;
    let dir = tempfile::tempdir().unwrap();
    let mut h = harness_on(dir.path(), "improvisation");
    let loaded = h.state().loaded().unwrap().clone();
    let before = common::render_once(&loaded);
    let mut louder = loaded;
    louder.score.beats[1].dynamic = timpanist::score::Dynamic::Ff;
    let after = common::render_once(&louder);
    let toggle = |h: &mut Harness<'static, EditorApp>, item: &str| common::choose(h, "View", item);
    toggle(
        &mut h,
        "Overlay the target pose (composed tips through the IK)",
    );
    toggle(
        &mut h,
        "Overlay the previous rendering (before the last edit)",
    );
    // No rendering yet: the body shown is the target pose itself, nothing to overlay.
    assert!(h.query_by_label("target pose (IK)").is_none());
    h.state_mut().set_rendering(Arc::new(before));
    common::settle(&mut h);
    assert!(h.query_by_label("target pose (IK)").is_some());
    assert!(h.query_by_label("previous rendering").is_none());
    h.state_mut().set_rendering(Arc::new(after));
    common::settle(&mut h);
    assert!(h.query_by_label("previous rendering").is_some());
    toggle(
        &mut h,
        "Overlay the previous rendering (before the last edit)",
    );
    assert!(h.query_by_label("previous rendering").is_none());
    assert!(h.query_by_label("target pose (IK)").is_some());
}

/// In slow motion each contact the playhead passes is played once, at full speed (the
/// mix itself is muted); at real time none is (the mix plays). The first contact after
/// 0.5 s is played over.
#[test]
fn strikes_sound_in_slow_motion() {
    use std::sync::Arc;
    let dir = tempfile::tempdir().unwrap();
    let mut h = harness_on(dir.path(), "improvisation");
    let rendering = common::render_once(h.state().loaded().unwrap());
    let first = (rendering.drums.contacts().iter())
        .map(|c| c.start_s)
        .find(|t| *t > 0.5)
        .unwrap();
    h.state_mut().set_rendering(Arc::new(rendering));
    common::settle(&mut h);
    let none = egui::Modifiers::NONE;
    let play_over_first_contact = |h: &mut Harness<'static, EditorApp>| {
        h.state_mut().seek(first - 0.03);
        h.key_press(egui::Key::Space);
        let t = Instant::now();
        while h.state().playback().played_once() == 0 && t.elapsed() < Duration::from_secs(3) {
            h.step();
            std::thread::sleep(Duration::from_millis(20));
        }
        h.key_press(egui::Key::Space);
        h.step();
    };
    play_over_first_contact(&mut h);
    assert_eq!(
        h.state().playback().played_once(),
        0,
        "real time plays the mix"
    );
    press(&mut h, none, egui::Key::OpenBracket);
    press(&mut h, none, egui::Key::OpenBracket);
    assert_eq!(h.state().playback().speed(), 0.25);
    play_over_first_contact(&mut h);
    assert_eq!(h.state().playback().played_once(), 1);
}
