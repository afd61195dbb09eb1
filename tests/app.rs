//! The editor driven headless through egui_kittest: it opens scores, adds beats by
//! clicking, sets modes by key and inspector, undoes and redoes, drags a 3D handle, saves
//! and reopens, asks before losing changes, reports bad files in the window, handles
//! dropped files and keeps a recent-files list — all in temp dirs, never the real home.

mod common;
use common::settle;

use eframe::egui;
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use std::path::{Path, PathBuf};
use timpanist::app::EditorApp;
use timpanist::score::{Hand, PlayingMode};

use common::root;

/// An editor on `score` with its recent list in `dir`, composed and idle.
fn harness(score: Option<PathBuf>, dir: &Path) -> Harness<'static, EditorApp> {
    let mut h = common::editor(score, dir, false);
    settle(&mut h);
    h
}

fn demo() -> PathBuf {
    root().join("scores/etude-modes.ron")
}

/// The editor opens the bundled demo score, shows its title, the kit and every panel.
#[test]
fn opens_demo_score_with_every_panel() {
    let dir = tempfile::tempdir().unwrap();
    let h = harness(Some(demo()), dir.path());
    let app = h.state();
    assert!(app.error().is_none(), "{:?}", app.error());
    assert_eq!(app.loaded().unwrap().score.beats.len(), 16);
    h.get_by_label("Etude in five modes and three spots");
    h.get_by_label("Standard set (32/29/26/23 inch)");
    for panel in [
        "3D view",
        "Timeline",
        "Ruler",
        "Tempo lane",
        "Inspector",
        "File",
        "Edit",
        "Play",
    ] {
        h.get_by_label(panel);
    }
    assert_eq!(
        h.get_all_by_label("Right tip").count(),
        2,
        "height and depth plots"
    );
    h.get_by_label_contains("No sound device: silent playback");
}

/// The editor composes the open score's stick-tip trajectories in the background.
#[test]
fn composes_in_the_background() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = harness(Some(root().join("scores/improvisation.ron")), dir.path());
    let strokes = h
        .state_mut()
        .wait_for_composition()
        .map(|c| c.strokes.len());
    assert_eq!(strokes, Some(5));
}

/// A score that fails to load is reported in the window instead of crashing.
#[test]
fn load_error_is_shown() {
    let dir = tempfile::tempdir().unwrap();
    let h = harness(Some(PathBuf::from("/no/such/score.ron")), dir.path());
    assert!(h.state().error().unwrap().contains("/no/such/score.ron"));
    h.get_by_label_contains("Error: ");
}

/// Clicking an empty spot of a lane adds a beat there (snapped, in that hand's lane) and
/// selects it; keys 1-5 set its mode; Ctrl+Z and Ctrl+Shift+Z undo and redo each step.
#[test]
fn add_beat_set_mode_undo_redo() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = harness(Some(demo()), dir.path());
    let before = h.state().loaded().unwrap().score.beats.clone();
    // Half-way between two beats of the demo, in the Left lane.
    let tick = 960 * 4 * 2 + 480;
    assert!(before.iter().all(|b| b.tick != tick));
    let at = common::steady_timeline_point(&mut h, tick, Hand::Left);
    common::click(&mut h, at);
    let app = h.state();
    let beats = &app.loaded().unwrap().score.beats;
    assert_eq!(beats.len(), before.len() + 1, "{}", app.status());
    let added: Vec<_> = beats.iter().filter(|b| !before.contains(b)).collect();
    assert_eq!(added.len(), 1);
    assert_eq!((added[0].tick, added[0].hand), (tick, Hand::Left));
    assert!(app.is_dirty());
    let sel: Vec<usize> = app.selection().beats.iter().copied().collect();
    assert_eq!(beats[sel[0]].tick, tick);

    h.key_press(egui::Key::Num5);
    settle(&mut h);
    let mode_of_added = |h: &Harness<'static, EditorApp>| {
        let s = &h.state().loaded().unwrap().score;
        s.beats
            .iter()
            .find(|b| b.tick == tick && b.hand == Hand::Left)
            .map(|b| b.mode)
    };
    assert_eq!(mode_of_added(&h), Some(PlayingMode::Staccato));
    assert_eq!(h.state().undo_steps(), 2);

    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    settle(&mut h);
    assert_eq!(mode_of_added(&h), Some(before_mode(&h, tick)));
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    settle(&mut h);
    assert_eq!(h.state().loaded().unwrap().score.beats, before);
    assert!(!h.state().is_dirty());
    h.key_press_modifiers(
        egui::Modifiers::COMMAND | egui::Modifiers::SHIFT,
        egui::Key::Z,
    );
    settle(&mut h);
    h.key_press_modifiers(
        egui::Modifiers::COMMAND | egui::Modifiers::SHIFT,
        egui::Key::Z,
    );
    settle(&mut h);
    assert_eq!(mode_of_added(&h), Some(PlayingMode::Staccato));
}

/// The mode a new beat takes from the template (the demo's plain beat): legato.
fn before_mode(_h: &Harness<'static, EditorApp>, _tick: u64) -> PlayingMode {
    PlayingMode::Legato
}

/// The inspector sets the mode of all selected beats at once, as one undo step.
#[test]
fn inspector_sets_mode_of_selection() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = harness(Some(demo()), dir.path());
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::A);
    settle(&mut h);
    h.get_by_label("16 beat(s) selected");
    h.get_by_label("Mode").click();
    settle(&mut h);
    h.get_by_label("4 vertical accent").click();
    settle(&mut h);
    let s = &h.state().loaded().unwrap().score;
    assert!(
        s.beats
            .iter()
            .all(|b| b.mode == PlayingMode::VerticalAccent)
    );
    assert_eq!(h.state().undo_steps(), 1);
}

/// The inspector's Damping field makes the selected beats secco (the hand touches the
/// head an 8th after the stroke), saved in the score as one undo step.
#[test]
fn inspector_sets_secco() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = harness(Some(demo()), dir.path());
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::A);
    settle(&mut h);
    h.get_by_label("Damping").click();
    settle(&mut h);
    h.get_by_label("secco: touch an 8th after").click();
    settle(&mut h);
    let s = &h.state().loaded().unwrap().score;
    let eighth = u64::from(s.ticks_per_quarter) / 2;
    assert!(s.beats.iter().all(|b| b.damp == Some(eighth)));
    assert!(s.to_ron().contains(&format!("damp: Some({eighth})")));
    assert_eq!(h.state().undo_steps(), 1);
}

/// Dragging on a composed trajectory in the 3D view adds a handle and moves it: one undo
/// step; undo removes it.
#[test]
fn drag_handle_in_3d_is_one_step() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = harness(Some(demo()), dir.path());
    let comp = h.state().composition().unwrap().clone();
    // A point of the right tip mid-way between two impacts, high above the head.
    let k = comp.impact_samples[2] + (comp.impact_samples[3] - comp.impact_samples[2]) / 2;
    let side = comp.strokes[2].hand;
    let world = comp.tip(side)[k];
    let start = h.state().viewport_point(world).expect("visible");
    h.hover_at(start);
    settle(&mut h);
    h.drag_at(start);
    settle(&mut h);
    for step in 1..=6 {
        h.hover_at(start + egui::vec2(0.0, -8.0 * step as f32));
        settle(&mut h);
    }
    h.drop_at(start + egui::vec2(0.0, -48.0));
    settle(&mut h);
    h.state_mut().wait_for_composition();
    let s = &h.state().loaded().unwrap().score;
    assert_eq!(s.handles.len(), 1, "{}", h.state().status());
    let offset = s.handles[0].offset_m;
    assert!(offset[2] > 0.01, "the handle moved up: {offset:?}");
    assert_eq!(h.state().undo_steps(), 1);
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    settle(&mut h);
    assert!(h.state().loaded().unwrap().score.handles.is_empty());
}

/// With the trajectories shown only near the playhead (View menu), a part of a trajectory
/// far from it is not drawn and cannot be grabbed: dragging there orbits and adds no
/// handle; the menu's checkbox turns the window on and off.
#[test]
fn trajectory_window_hides_far_parts() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = harness(Some(demo()), dir.path());
    h.get_by_label("View").click();
    settle(&mut h);
    h.get_by_label("Trajectories near the playhead only")
        .click();
    settle(&mut h);
    assert_eq!(h.state().trajectory_window(), Some(2.0));
    h.state_mut().set_trajectory_window(Some(0.25));
    let comp = h.state().composition().unwrap().clone();
    let k = comp.impact_samples[2] + (comp.impact_samples[3] - comp.impact_samples[2]) / 2;
    assert!(
        comp.time(k) > 0.5,
        "the point is far from the playhead at 0"
    );
    let world = comp.tip(comp.strokes[2].hand)[k];
    let start = h.state().viewport_point(world).expect("visible");
    let camera = h.state().camera();
    h.hover_at(start);
    settle(&mut h);
    h.drag_at(start);
    settle(&mut h);
    h.hover_at(start + egui::vec2(0.0, -24.0));
    settle(&mut h);
    h.drop_at(start + egui::vec2(0.0, -24.0));
    settle(&mut h);
    assert!(h.state().loaded().unwrap().score.handles.is_empty());
    assert_ne!(h.state().camera(), camera, "the drag orbits instead");
    h.get_by_label("View").click();
    settle(&mut h);
    h.get_by_label("Trajectories near the playhead only")
        .click();
    settle(&mut h);
    assert_eq!(h.state().trajectory_window(), None);
}

/// Save As into a temp dir, reopen: the same score, recorded in the recent list (kept in
/// the injected location, which persists it).
#[test]
fn save_and_reopen() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = harness(Some(demo()), dir.path());
    let at = common::steady_timeline_point(&mut h, 960 * 3, Hand::Right);
    common::click(&mut h, at);
    let beats = h.state().loaded().unwrap().score.beats.clone();
    let target = dir.path().join("saved.ron");
    h.state_mut().save_to(&target);
    h.state_mut().wait_for_files();
    assert!(h.state().error().is_none(), "{:?}", h.state().error());
    assert!(!h.state().is_dirty());
    // What was saved: the edited beats, and the 3D camera with them.
    let edited = h.state().loaded().unwrap().score.clone();
    assert_eq!(edited.beats, beats);
    assert!(edited.view.is_some());
    let again = harness(Some(target.clone()), dir.path());
    assert_eq!(again.state().loaded().unwrap().score, edited);
    assert_eq!(again.state().recent_files()[0], target);
    let listed = std::fs::read_to_string(dir.path().join("recent.txt")).unwrap();
    assert!(listed.contains("saved.ron"));
}

/// Quitting with unsaved changes asks first; Cancel keeps the editor and the changes.
#[test]
fn quit_with_unsaved_changes_asks() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = harness(Some(demo()), dir.path());
    assert!(h.state_mut().request_quit(), "nothing to lose yet");
    let at = common::steady_timeline_point(&mut h, 960 * 3, Hand::Right);
    common::click(&mut h, at);
    assert!(!h.state_mut().request_quit());
    settle(&mut h);
    h.get_by_label("Unsaved changes");
    h.get_by_label("Cancel").click();
    settle(&mut h);
    assert!(!h.state().is_asking_to_discard());
    assert!(h.state().is_dirty());
}

/// A 32 kHz WAV of the shipped recorded notes `names` (e.g. "2L"), each cut or padded with
/// silence to `samples_each`.
fn write_recorded_notes(wav: &Path, names: &[&str], samples_each: usize) {
    let spec = hound::WavSpec {
        channels: 1,
        sample_rate: 32_000,
        bits_per_sample: 16,
        sample_format: hound::SampleFormat::Int,
    };
    let mut w = hound::WavWriter::create(wav, spec).unwrap();
    for name in names {
        let path = root().join(format!("kits/samples/Timpani_{name}.wav"));
        let mut r = hound::WavReader::open(path).unwrap();
        let note: Vec<i16> = r.samples::<i16>().map(Result::unwrap).collect();
        for i in 0..samples_each {
            w.write_sample(note.get(i).copied().unwrap_or(0)).unwrap();
        }
    }
    w.finalize().unwrap();
}

/// Dropped files: a MIDI file imports as a new unsaved score, a recording is transcribed
/// into one, a broken score shows an error in the window, another kind of file is refused
/// with a message.
#[test]
fn dropped_files() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = harness(Some(demo()), dir.path());
    let bad = dir.path().join("broken.ron");
    std::fs::write(&bad, "Score(version: 2, title: ").unwrap();
    h.state_mut().handle_dropped(&bad);
    settle(&mut h);
    assert!(h.state().error().unwrap().contains("broken.ron"));
    h.get_by_label_contains("Error: ");
    h.state_mut().handle_dropped(Path::new("notes.txt"));
    assert!(h.state().error().unwrap().contains("notes.txt"));

    let mid = dir.path().join("export.mid");
    let loaded = timpanist::score::LoadedScore::load(&demo()).unwrap();
    std::fs::write(
        &mid,
        timpanist::io::midi_export::export(&loaded.score, &loaded.kit),
    )
    .unwrap();
    h.state_mut().handle_dropped(&mid);
    h.state_mut().wait_for_composition();
    settle(&mut h);
    let app = h.state();
    assert!(app.error().is_none(), "{:?}", app.error());
    assert_eq!(app.loaded().unwrap().score.beats.len(), 16);
    assert!(app.path().is_none(), "an import is not saved yet");

    // A recording is transcribed: three recorded notes 0.8 s apart, three strokes.
    let wav = dir.path().join("three notes.wav");
    write_recorded_notes(&wav, &["2L", "3R", "2R"], 25_600);
    h.state_mut().handle_dropped(&wav);
    h.state_mut().wait_for_composition();
    settle(&mut h);
    let app = h.state();
    assert!(app.error().is_none(), "{:?}", app.error());
    assert_eq!(app.loaded().unwrap().score.beats.len(), 3);
    assert!(app.path().is_none(), "a transcription is not saved yet");
}

/// A recording is transcribed on a thread while a dialog says so: the window keeps
/// drawing, its shortcuts wait, a second file is refused until it is read, and Cancel
/// keeps the score on screen. Read to the end, the transcription opens; an MP3 too.
#[test]
fn a_recording_opens_behind_a_dialog_that_can_cancel() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = harness(Some(demo()), dir.path());
    // Twenty seconds of recorded notes, a second apart: long enough to be caught reading.
    let wav = dir.path().join("twenty notes.wav");
    write_recorded_notes(&wav, &["3R"; 20], 32_000);

    h.state_mut().handle_dropped(&wav);
    // A new window shows from its second frame (the first measures it).
    h.step();
    h.step();
    h.get_by_label("Transcribing a recording");
    h.get_by_label_contains("twenty notes.wav");
    h.state_mut().handle_dropped(&demo());
    let refused = h.state().error().unwrap().to_string();
    assert!(refused.contains("wait until"), "{refused}");
    h.get_by_label("Cancel").click();
    h.step();
    h.step();
    assert!(h.query_by_label("Transcribing a recording").is_none());
    assert_eq!(
        h.state().loaded().unwrap().score.beats.len(),
        16,
        "the demo stays"
    );
    assert!(
        h.state()
            .status()
            .contains("cancelled reading twenty notes.wav")
    );

    h.state_mut().handle_dropped(&wav);
    h.step();
    settle(&mut h);
    let app = h.state();
    assert_eq!(app.loaded().unwrap().score.beats.len(), 20);
    assert!(app.path().is_none(), "a transcription is not saved yet");
    assert!(h.query_by_label("Transcribing a recording").is_none());

    h.state_mut()
        .handle_dropped(&root().join("tests/fixtures/recordings/d2-note.mp3"));
    settle(&mut h);
    assert_eq!(h.state().loaded().unwrap().score.beats.len(), 1);
}

/// Space plays from the playhead on the silent clock and pauses again; F1 shows help.
#[test]
fn space_plays_on_the_silent_clock() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = harness(Some(demo()), dir.path());
    h.key_press(egui::Key::Space);
    h.step();
    assert!(h.state().playback().is_playing());
    std::thread::sleep(std::time::Duration::from_millis(50));
    h.step();
    h.key_press(egui::Key::Space);
    h.step();
    assert!(!h.state().playback().is_playing());
    assert!(h.state().playhead_s() > 0.04, "{}", h.state().playhead_s());
    h.key_press(egui::Key::F1);
    settle(&mut h);
    h.get_by_label("Keyboard and mouse");
}

/// The inspector's physics and sound settings: picking a concert hall, the ID pipeline,
/// the sample model and the reference body step are undoable edits of the score's
/// settings; undo and redo restore them; they are saved with the score and read back.
#[test]
fn inspector_edits_settings_undoably_and_saves_them() {
    use timpanist::body::sim::{BodyStep, Pipeline};
    use timpanist::sound::{Room, SoundModel};
    let dir = tempfile::tempdir().unwrap();
    let mut h = harness(Some(demo()), dir.path());
    h.get_by_label("Physics and sound").click();
    settle(&mut h);
    h.get_by_label("Room").click();
    settle(&mut h);
    h.get_by_label("concert hall (T60 2.2 s)").click();
    settle(&mut h);
    assert_eq!(h.state().loaded().unwrap().score.settings.room, Room::Hall);
    h.get_by_label("Control").click();
    settle(&mut h);
    h.get_by_label("ID (PD + inverse dynamics)").click();
    settle(&mut h);
    h.get_by_label("Sound model").click();
    settle(&mut h);
    h.get_by_label("sample replay").click();
    settle(&mut h);
    h.get_by_label("Body step").click();
    settle(&mut h);
    h.get_by_label("reference (10 kHz)").click();
    settle(&mut h);
    let s = &h.state().loaded().unwrap().score.settings;
    assert_eq!((s.control, s.sound), (Pipeline::Id, SoundModel::Sample));
    assert_eq!(s.body_step, BodyStep::Reference);
    assert_eq!(h.state().undo_steps(), 4);
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    settle(&mut h);
    assert_eq!(
        h.state().loaded().unwrap().score.settings.body_step,
        BodyStep::Fast
    );
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::Z);
    settle(&mut h);
    let s = &h.state().loaded().unwrap().score.settings;
    assert_eq!((s.control, s.sound), (Pipeline::Id, SoundModel::Modal));
    h.key_press_modifiers(
        egui::Modifiers::COMMAND | egui::Modifiers::SHIFT,
        egui::Key::Z,
    );
    settle(&mut h);
    assert_eq!(
        h.state().loaded().unwrap().score.settings.sound,
        SoundModel::Sample
    );
    let path = dir.path().join("with-settings.ron");
    h.state_mut().save_to(&path);
    h.state_mut().wait_for_files();
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(
        text.contains("settings") && text.contains("Sample") && text.contains("room: Hall"),
        "{text}"
    );
    assert!(!text.contains("body_step"), "{text}");
    let mut again = harness(Some(path), dir.path());
    settle(&mut again);
    let s = &again.state().loaded().unwrap().score.settings;
    assert_eq!(
        (s.control, s.sound, s.room),
        (Pipeline::Id, SoundModel::Sample, Room::Hall)
    );
}

/// With nothing selected, a beat added in a hand's lane goes on the first drum that hand
/// prefers (the 26-inch for the right hand on the standard kit, the 32-inch for the left):
/// never on a far drum across the body.
#[test]
fn a_new_beat_goes_on_a_drum_of_its_hand() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = harness(Some(demo()), dir.path());
    let kit = h.state().loaded().unwrap().kit.clone();
    for (tick, hand) in [
        (960 * 4 * 2 + 480, Hand::Right),
        (960 * 4 * 3 + 480, Hand::Left),
    ] {
        h.key_press(egui::Key::Escape);
        settle(&mut h);
        assert!(h.state().selection().beats.is_empty());
        let before = h.state().loaded().unwrap().score.beats.clone();
        let at = common::steady_timeline_point(&mut h, tick, hand);
        common::click(&mut h, at);
        let beats = &h.state().loaded().unwrap().score.beats;
        let added: Vec<_> = beats.iter().filter(|b| !before.contains(b)).collect();
        assert_eq!(added.len(), 1, "{hand:?} at {at:?}");
        let drum = &kit.drums[added[0].drum];
        assert_eq!(
            Some(drum.preferred_hand),
            hand.side(),
            "{hand:?}: {}",
            drum.name
        );
    }
}

/// The inspector's Pitch field tunes the selected beats' drum (one undo step), and a beat
/// asking its drum for another pitch than the one before it shows the pedal change.
#[test]
fn inspector_sets_pitch_and_names_a_pedal_change() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = harness(Some(demo()), dir.path());
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::A);
    settle(&mut h);
    h.get_by_label("Pitch").click();
    settle(&mut h);
    // The 26-inch drum's range is B♭2–F3; the demo leaves it at its D3.
    h.get_by_label("as tuned (D3)");
    h.get_by_label("C3").click();
    settle(&mut h);
    let doc = h.state().loaded().unwrap();
    assert!(
        doc.score
            .beats
            .iter()
            .all(|b| b.pitch == Some("C3".parse().unwrap()))
    );
    assert_eq!(doc.score.kit(&doc.kit).drums[2].tuning.to_string(), "C3");
    assert_eq!(h.state().undo_steps(), 1);
    // The drums' table shows the pitch the drum plays the score at.
    h.get_by_label("Drums and membranes").click();
    settle(&mut h);
    h.get_by_label("C3 (kit D3)");
    // The second beat alone asks for E3: a pedal change from C3, made in the time since
    // the drum's first stroke.
    let at = common::steady_timeline_point(&mut h, 960, Hand::Auto);
    common::click(&mut h, at);
    assert_eq!(h.state().selection().beats.len(), 1);
    common::choose(&mut h, "Pitch", "E3");
    h.get_by_label_contains("pedal change from C3 to E3");
    let doc = h.state().loaded().unwrap();
    // To E3 for that beat, and back to C3 for the next.
    let changes = doc.score.pedal_changes(&doc.kit);
    let pitches: Vec<String> = changes
        .iter()
        .map(|c| format!("{}-{}", c.from, c.to))
        .collect();
    assert_eq!(pitches, ["C3-E3", "E3-C3"], "{changes:?}");
    assert_eq!(doc.score.retunes(&doc.kit).len(), 2);
}
