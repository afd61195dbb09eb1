//! The editor's plot tabs and File > Export driven headless through egui_kittest, on a
//! rendering of the improvisation score made once (synchronously, the editor's own
//! pipeline) and handed to the app as the render worker would: every tab shows its plots
//! and says so when there is no rendering, a click on a plot seeks, and export writes a
//! WAV and a motion CSV of the current rendering or refuses with the reason.

mod common;
mod readers;

use eframe::egui;
use egui_kittest::Harness;
use egui_kittest::kittest::{NodeT, Queryable};
use std::path::{Path, PathBuf};
use std::sync::{Arc, OnceLock};
use timpanist::app::{EditorApp, PlotTab};
use timpanist::mocap::db::MotionDb;
use timpanist::render::{RenderParams, Rendering, render};
use timpanist::score::{Hand, LoadedScore};

use common::root;

fn score_path() -> PathBuf {
    root().join("scores/improvisation.ron")
}

/// The improvisation score rendered with the default parameters, once per test run.
fn rendering() -> Arc<Rendering> {
    static RENDERING: OnceLock<Arc<Rendering>> = OnceLock::new();
    Arc::clone(RENDERING.get_or_init(|| {
        let loaded = LoadedScore::load(&score_path()).unwrap();
        let db = MotionDb::load(&root().join("mocap")).unwrap();
        Arc::new(render(&loaded, &db, &RenderParams::default(), &mut |_| true).unwrap())
    }))
}

/// An editor on the improvisation score with the silent clock and `render` as given, in
/// a window large enough for every panel; with `rendered`, the rendering is handed over.
/// With the render worker on, a spinner keeps repainting: the UI runs a few frames only.
fn harness(dir: &Path, render: bool, rendered: bool) -> Harness<'static, EditorApp> {
    let mut h = common::editor(Some(score_path()), dir, render);
    if rendered {
        h.state_mut().set_rendering(rendering());
    }
    if render {
        h.step();
        h.state_mut().wait_for_composition();
        h.run_steps(4);
    } else {
        settle(&mut h);
    }
    h
}

/// Let the composing worker finish, then run the UI until it is idle.
use common::settle;

/// Open the plot tab titled `title`.
fn open_tab(h: &mut Harness<'static, EditorApp>, title: &str) {
    h.get_by_label(title).click();
    settle(h);
}

/// Click at `pos` (press and release without moving).
fn click(h: &mut Harness<'static, EditorApp>, pos: egui::Pos2) {
    h.hover_at(pos);
    h.step();
    h.drag_at(pos);
    h.step();
    h.drop_at(pos);
    settle(h);
}

/// Every tab shows its plots with the expected legends and labels, over the rendering's
/// whole time, and the joints chosen above the joint plot are the ones drawn.
#[test]
fn every_tab_shows_its_plots() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = harness(dir.path(), false, true);
    assert_eq!(h.state().plot_tab(), PlotTab::Composed);
    assert_eq!(
        h.get_all_by_label("Right tip").count(),
        2,
        "height and depth"
    );
    assert_eq!(h.get_all_by_label("Left impacts").count(), 2);

    open_tab(&mut h, "Simulated tips");
    assert_eq!(h.state().plot_tab(), PlotTab::Tips);
    for line in [
        "Left target",
        "Left simulated",
        "Right target",
        "Right simulated",
    ] {
        assert_eq!(h.get_all_by_label(line).count(), 2, "{line} in both plots");
    }

    open_tab(&mut h, "Contact force");
    h.get_by_label("Left peaks");
    h.get_by_label("Right force");

    open_tab(&mut h, "Sound");
    h.get_by_label("waveform");
    h.get_by_label("simulated stroke");
    h.get_by_label_contains("recorded Timpani_");
    h.get_by_label("analysed strike");
    // The playhead is at 0: the first strike is analysed.
    let first = &rendering().events[0];
    h.get_by_label_contains(&format!(
        "Spectrum of the strike at {:.3} s",
        first.contact_s
    ));

    open_tab(&mut h, "Joint angles");
    assert_eq!(
        h.get_all_by_label("elbow_r").count(),
        2,
        "checkbox and legend"
    );
    assert_eq!(h.get_all_by_label("trunk").count(), 1, "checkbox only");
    h.get_by_label("trunk").click();
    settle(&mut h);
    assert_eq!(h.get_all_by_label("trunk").count(), 2, "now drawn too");
}

const TABS: [&str; 5] = [
    "Composed tips",
    "Simulated tips",
    "Contact force",
    "Sound",
    "Joint angles",
];

/// Every tab's time axis shows the timeline's visible window: the same on all tabs, and
/// narrower on all of them after the timeline zooms in.
#[test]
fn time_axes_follow_the_timeline() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = harness(dir.path(), false, true);
    let windows = |h: &mut Harness<'static, EditorApp>| -> (f64, f64) {
        let all: Vec<(f64, f64)> = TABS
            .iter()
            .map(|tab| {
                open_tab(h, tab);
                h.state().plot_time_window().expect(tab)
            })
            .collect();
        for (w, tab) in all.iter().zip(TABS) {
            assert!(
                (w.0 - all[0].0).abs() < 1e-9 && (w.1 - all[0].1).abs() < 1e-9,
                "{tab}: {w:?} vs {:?}",
                all[0]
            );
        }
        all[0]
    };
    let fit = windows(&mut h);
    assert!(fit.0 <= 0.0 && fit.1 >= 3.0, "the whole score: {fit:?}");
    h.get_by_label("Zoom in").click();
    settle(&mut h);
    let zoomed = windows(&mut h);
    let ratio = (zoomed.1 - zoomed.0) / (fit.1 - fit.0);
    assert!((ratio - 0.7).abs() < 0.01, "{fit:?} -> {zoomed:?}");
}

/// A click on a plot moves the playhead to the time under the pointer (within a pixel),
/// on every tab; on the sound tab the strike analysed follows.
#[test]
fn click_on_a_plot_seeks() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = harness(dir.path(), false, true);
    let events = rendering().events.clone();
    for (i, tab) in TABS.into_iter().enumerate() {
        open_tab(&mut h, tab);
        let target = 0.5 + 0.6 * i as f64;
        let at = h.state().plot_point(target).expect(tab);
        let px_per_s = f64::from(h.state().plot_point(target + 1.0).unwrap().x - at.x);
        click(&mut h, at);
        let playhead = h.state().playhead_s();
        assert!(
            (playhead - target).abs() <= 1.0 / px_per_s,
            "{tab}: clicked at {target} s, playhead {playhead} s"
        );
    }
    // The sound tab analyses the strike nearest the playhead.
    open_tab(&mut h, "Sound");
    let last = events.iter().rfind(|e| e.beat.is_some()).unwrap();
    let at = h.state().plot_point(last.contact_s + 0.01).unwrap();
    click(&mut h, at);
    h.get_by_label_contains(&format!(
        "Spectrum of the strike at {:.3} s",
        last.contact_s
    ));
}

/// Before any rendering the rendering tabs say why there is nothing to plot, while the
/// composed tips still show; with the render worker on, they say it is rendering.
#[test]
fn tabs_say_when_there_is_no_rendering() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = harness(dir.path(), false, false);
    for tab in ["Simulated tips", "Contact force", "Sound", "Joint angles"] {
        open_tab(&mut h, tab);
        h.get_by_label("No rendering to plot: rendering is turned off");
        assert!(h.state().plot_point(1.0).is_none());
    }
    open_tab(&mut h, "Composed tips");
    assert_eq!(h.get_all_by_label("Right tip").count(), 2);

    let mut h = harness(dir.path(), true, false);
    h.get_by_label("Contact force").click();
    h.run_steps(2);
    h.get_by_label("No rendering to plot: rendering sound and motion...");
}

/// Export writes the current rendering: a 48 kHz stereo 16-bit WAV with every sample of
/// the rendered audio, and a CSV with its header and one row per motion sample; no
/// temporary file is left behind.
#[test]
fn export_writes_wav_and_motion() {
    let dir = tempfile::tempdir().unwrap();
    let out = tempfile::tempdir().unwrap();
    let mut h = harness(dir.path(), false, true);
    assert_eq!(h.state().export_blocked(), None);
    let r = rendering();

    let wav = out.path().join("improvisation.wav");
    h.state_mut().export_wav_to(&wav);
    h.state_mut().wait_for_files();
    assert!(h.state().error().is_none(), "{:?}", h.state().error());
    assert!(
        h.state().status().contains("exported"),
        "{}",
        h.state().status()
    );
    let mut reader = hound::WavReader::open(&wav).unwrap();
    let spec = reader.spec();
    assert_eq!(
        (spec.sample_rate, spec.channels, spec.bits_per_sample),
        (48_000, 2, 16)
    );
    let samples: Vec<i16> = reader.samples::<i16>().map(Result::unwrap).collect();
    assert_eq!(samples.len(), r.audio.samples.len());
    assert!(samples.len() > 2 * 48_000, "seconds of sound");
    let worst = samples
        .iter()
        .zip(r.audio.samples.iter())
        .map(|(&s, &a)| (f64::from(s) / 32767.0 - f64::from(a)).abs())
        .fold(0.0, f64::max);
    assert!(worst < 1e-4, "16-bit rounding only: {worst}");
    assert!(samples.iter().any(|&s| s.abs() > 1000), "not silent");

    let csv = out.path().join("improvisation-motion.csv");
    h.state_mut().export_motion_to(&csv);
    h.state_mut().wait_for_files();
    assert!(h.state().error().is_none(), "{:?}", h.state().error());
    let text = std::fs::read_to_string(&csv).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert!(lines[0].starts_with("time_s,left_tip_x_m,left_tip_y_m,left_tip_z_m"));
    let columns = lines[0].split(',').count();
    assert_eq!(columns, 1 + 2 * 2 * 3 + 11 * 4);
    assert_eq!(lines.len(), 1 + r.motion.poses.len());
    let first: Vec<f64> = lines[1].split(',').map(|v| v.parse().unwrap()).collect();
    assert_eq!(first.len(), columns);
    assert!((first[0] - r.start_s).abs() < 1e-4);
    assert!(
        (first[3] - r.motion.tips[0][0].z).abs() < 1e-6,
        "left tip z"
    );
    // The motion as C3D: every joint and tip, read back by the C3D reader.
    let c3d = out.path().join("improvisation-motion.c3d");
    h.state_mut().export_c3d_to(&c3d);
    h.state_mut().wait_for_files();
    assert!(h.state().error().is_none(), "{:?}", h.state().error());
    let take =
        timpanist::mocap::import::c3d::read(&c3d, &std::fs::read(&c3d).unwrap(), None).unwrap();
    assert_eq!(take.frames, r.motion.poses.len());
    assert_eq!(take.rate_hz, r.motion.rate_hz);
    assert_eq!(take.tracks.len(), 11 + 4, "{:?}", take.labels());
    let tip = take.track("RTIP").unwrap().positions[0].unwrap();
    assert!((tip - r.motion.tips[1][0]).length() < 1e-6, "{tip}");

    // The motion as BVH: read by the independent parser, a frame per sample at 250 Hz,
    // the right stick's end site at the simulated tip (Y up, the performer facing +Z).
    let bvh = out.path().join("improvisation.bvh");
    h.state_mut().export_bvh_to(&bvh);
    h.state_mut().wait_for_files();
    assert!(h.state().error().is_none(), "{:?}", h.state().error());
    let parsed = readers::Bvh::parse(&std::fs::read_to_string(&bvh).unwrap());
    assert_eq!(parsed.frames.len(), r.motion.poses.len());
    assert!((parsed.frame_time_s - 1.0 / r.motion.rate_hz).abs() < 1e-9);
    let tip = parsed.positions(0)[parsed.index("grip_r_end")];
    let want = r.motion.tips[1][0];
    let d = glam::DVec3::from(tip).distance(glam::DVec3::new(-want.x, want.z, want.y));
    assert!(d < 1e-3, "right tip {d} m off");

    // The scene as glTF: read by the gltf crate, a rotation key per sample for each of
    // the 11 joints.
    let glb = out.path().join("improvisation.glb");
    h.state_mut().export_glb_to(&glb);
    h.state_mut().wait_for_files();
    assert!(h.state().error().is_none(), "{:?}", h.state().error());
    let scene = gltf::Gltf::from_slice(&std::fs::read(&glb).unwrap()).unwrap();
    let animation = scene.animations().next().unwrap();
    assert_eq!(animation.channels().count(), 11);
    for c in animation.channels() {
        assert_eq!(c.sampler().output().count(), r.motion.poses.len());
    }

    // The score as MIDI: imported again, the same beats at the same ticks.
    let mid = out.path().join("improvisation.mid");
    h.state_mut().export_midi_to(&mid);
    h.state_mut().wait_for_files();
    assert!(h.state().error().is_none(), "{:?}", h.state().error());
    let loaded = LoadedScore::load(&score_path()).unwrap();
    let (back, _) =
        timpanist::io::midi_import::import_file(&mid, &loaded.kit, &Default::default()).unwrap();
    let ticks = |beats: &[timpanist::score::Beat]| beats.iter().map(|b| b.tick).collect::<Vec<_>>();
    let score = loaded.score;
    assert_eq!(back.beats.len(), score.beats.len());
    assert_eq!(ticks(&back.beats), ticks(&score.beats));

    let names: Vec<_> = std::fs::read_dir(out.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names.len(), 6, "no temporary files: {names:?}");

    // A failing write is an error in the window, not a panic.
    h.state_mut().export_wav_to(Path::new("/no/such/dir/x.wav"));
    h.state_mut().wait_for_files();
    assert!(h.state().error().unwrap().contains("/no/such/dir/x.wav"));
    h.run();
    h.get_by_label_contains("Error: cannot export to /no/such/dir/x.wav");
}

/// Export is refused with the reason while there is no rendering of the score as it is
/// now — none yet, or the score edited since — and nothing is written; the File menu's
/// export items are disabled meanwhile.
#[test]
fn export_is_refused_without_a_current_rendering() {
    let dir = tempfile::tempdir().unwrap();
    let out = tempfile::tempdir().unwrap();
    let wav = out.path().join("x.wav");

    let mut h = harness(dir.path(), false, false);
    h.get_by_label("File").click();
    settle(&mut h);
    assert!(
        h.get_by_label("Export WAV...")
            .accesskit_node()
            .is_disabled()
    );
    assert!(
        h.get_by_label("Export motion CSV...")
            .accesskit_node()
            .is_disabled()
    );
    h.state_mut().export_wav_to(&wav);
    h.state_mut().wait_for_files();
    let error = h.state().error().unwrap().to_string();
    assert!(
        error.contains("cannot export: rendering is turned off"),
        "{error}"
    );
    assert!(!wav.exists());

    let mut h = harness(dir.path(), false, true);
    h.get_by_label("File").click();
    settle(&mut h);
    assert!(
        !h.get_by_label("Export WAV...")
            .accesskit_node()
            .is_disabled()
    );
    h.key_press(egui::Key::Escape);
    settle(&mut h);
    // An edit: the rendering no longer matches the score.
    let at = h
        .state()
        .timeline_point(960 * 2 + 480, Hand::Right)
        .unwrap();
    h.hover_at(at);
    h.step();
    h.drag_at(at);
    h.step();
    h.drop_at(at);
    settle(&mut h);
    assert!(h.state().is_dirty());
    h.state_mut().export_motion_to(&out.path().join("m.csv"));
    h.state_mut().wait_for_files();
    let error = h.state().error().unwrap().to_string();
    assert!(error.contains("changed since it was rendered"), "{error}");
    assert_eq!(std::fs::read_dir(out.path()).unwrap().count(), 0);
    // The plots still show the previous rendering, and say so.
    open_tab(&mut h, "Contact force");
    h.get_by_label("Left peaks");
    h.get_by_label_contains("showing the previous rendering");
}

/// Space where only part of the audio is ready (a rendering that stopped early, as the
/// worker hands over right after an edit) waits and says so; playback starts by itself
/// when a rendering with the audio there arrives. Where the audio is ready it plays at
/// once.
#[test]
fn space_waits_for_audio_that_is_not_ready() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = harness(dir.path(), false, false);
    let whole = rendering();
    let mut partial = (*whole).clone();
    partial.complete = false;
    partial.ready_s = 2.0;
    h.state_mut().set_rendering(Arc::new(partial));
    h.state_mut().seek(3.0);
    h.key_press(egui::Key::Space);
    h.step();
    assert!(!h.state().playback().is_playing());
    assert!(h.state().is_waiting_to_play());
    assert!(
        h.state().status().contains("waiting for the audio"),
        "{}",
        h.state().status()
    );
    h.state_mut().set_rendering(whole);
    h.step();
    assert!(h.state().playback().is_playing() && !h.state().is_waiting_to_play());
    // Before the ready point a partial rendering plays at once.
    h.key_press(egui::Key::Space);
    h.step();
    let mut partial = (*rendering()).clone();
    partial.complete = false;
    partial.ready_s = 2.0;
    h.state_mut().set_rendering(Arc::new(partial));
    h.state_mut().seek(1.0);
    h.key_press(egui::Key::Space);
    h.step();
    assert!(h.state().playback().is_playing());
}

/// A score with a stroke out of reach (the right hand on the far-left drum's centre): the
/// real render worker refuses it, the status bar says why and offers "Show beat 1", which
/// selects that beat and moves the playhead to just before it.
#[test]
fn a_render_error_shows_its_beat() {
    use timpanist::score::{Beat, ImpactLocation, Score};
    let dir = tempfile::tempdir().unwrap();
    let mut score = Score::new("reach");
    score.beats.push(Beat::plain(0, 1));
    let mut far = Beat::plain(1920, 0);
    far.hand = Hand::Right;
    far.location = ImpactLocation::Centre;
    score.beats.push(far);
    let path = dir.path().join("reach.ron");
    score.save(&path).unwrap();
    let beat_s = score.tempo_map().seconds_at(1920.0);
    let mut h = common::editor(Some(path), dir.path(), true);
    let began = std::time::Instant::now();
    while h.state().render_error().is_none() {
        assert!(began.elapsed().as_secs() < 60, "no render error");
        h.step();
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    let error = h.state().render_error().unwrap().to_string();
    assert!(
        error.contains("beat 1 is out of the right hand's reach"),
        "{error}"
    );
    assert_eq!(h.state().render_error_beat(), Some(1));
    h.state_mut().wait_for_composition();
    h.run();
    h.get_by_label("Show beat 1").click();
    h.run();
    assert_eq!(
        h.state()
            .selection()
            .beats
            .iter()
            .copied()
            .collect::<Vec<_>>(),
        vec![1]
    );
    let t = h.state().playhead_s();
    assert!((t - (beat_s - 0.5)).abs() < 1e-9, "{t} vs {beat_s}");
}

/// The live OSC output, turned on in the inspector and aimed at a UDP receiver on
/// loopback, sends each contact of the rendering once as the silent playback clock
/// passes it, from the first, and nothing beyond the playhead; every message decodes
/// (rosc) to its event's drum, hand and time. (A contact a moment before score time 0 is
/// `osc_out`'s unit test's case.)
#[test]
fn live_osc_sends_the_hits_as_they_sound() {
    let rx = std::net::UdpSocket::bind("127.0.0.1:0").unwrap();
    rx.set_read_timeout(Some(std::time::Duration::from_millis(500)))
        .unwrap();
    let dir = tempfile::tempdir().unwrap();
    let mut h = harness(dir.path(), false, true);
    let r = rendering();
    h.state_mut()
        .set_osc_target("127.0.0.1", rx.local_addr().unwrap().port());
    h.get_by_label("Live OSC output").click();
    settle(&mut h);
    h.get_by_label("Send hits during playback").click();
    settle(&mut h);
    h.state_mut().seek(0.0);
    h.key_press(egui::Key::Space);
    h.step();
    let until_s = r.events[2].contact_s + 0.1;
    let started = std::time::Instant::now();
    while h.state().playhead_s() < until_s {
        assert!(started.elapsed().as_secs() < 30, "playback stalled");
        std::thread::sleep(std::time::Duration::from_millis(20));
        h.step();
    }
    h.key_press(egui::Key::Space);
    h.step();
    let stopped_s = h.state().playhead_s();
    let want: Vec<_> = r
        .events
        .iter()
        .filter(|e| e.contact_s <= stopped_s)
        .collect();
    assert!(want.len() >= 3, "{want:?}");
    let mut buf = [0u8; 1536];
    let mut got = Vec::new();
    while let Ok(n) = rx.recv(&mut buf) {
        let (_, packet) = rosc::decoder::decode_udp(&buf[..n]).unwrap();
        let rosc::OscPacket::Message(m) = packet else {
            panic!("not a message")
        };
        got.push(m);
    }
    assert_eq!(got.len(), want.len(), "{:?}", h.state().osc_sent());
    for (m, e) in got.iter().zip(want) {
        assert_eq!(m.addr, "/timpanist/hit");
        assert_eq!(m.args[0].clone().int().unwrap() as usize, e.drum);
        assert_eq!(m.args[1].clone().string().unwrap(), e.hand);
        assert_eq!(m.args[6].clone().float().unwrap(), e.contact_s as f32);
    }
}
