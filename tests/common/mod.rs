//! Set-up shared by the editor's tests: an editor on a score with its recent-files list
//! in a temporary folder and the silent clock, in a window large enough for every panel.
// Each test crate uses only some of these.
#![allow(dead_code)]

use eframe::egui;
use egui_kittest::{Harness, HarnessBuilder};
use std::path::{Path, PathBuf};
use timpanist::app::{EditorApp, EditorOptions};
use timpanist::mocap::db::MotionDb;
use timpanist::render::{RenderParams, render};
use timpanist::score::LoadedScore;

/// The repository (the tests run from it: the motion database is found there).
pub fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The editor's options for `score`, its recent list, autosave and preferences in `dir`, no sound device,
/// rendering if `render`, the in-window file browser (a system dialog would block the
/// test); moves into the repository.
pub fn options(score: Option<PathBuf>, dir: &Path, render: bool) -> EditorOptions {
    std::env::set_current_dir(root()).unwrap();
    EditorOptions {
        score,
        recent_store: Some(dir.join("recent.txt")),
        recovery_file: Some(dir.join("recovery.ron")),
        audio_device: false,
        render,
        in_window_dialogs: true,
        preferences_file: Some(dir.join("preferences.ron")),
    }
}

/// A 1400 × 900 window, at most 64 steps a run.
pub fn builder() -> HarnessBuilder<EditorApp> {
    Harness::builder()
        .with_size(egui::vec2(1400.0, 900.0))
        .with_max_steps(64)
}

/// The editor on `score` (see [`options`]).
pub fn editor(score: Option<PathBuf>, dir: &Path, render: bool) -> Harness<'static, EditorApp> {
    let options = options(score, dir, render);
    builder().build_eframe(move |_cc| EditorApp::with_options(options))
}

/// Let the file jobs (saving, exporting, importing) and then the composing worker
/// finish, then run the UI until it is idle. (Without waiting for the files, a save
/// still writing under a loaded machine kept the status bar's spinner turning past the
/// harness's 64 frames.)
pub fn settle(h: &mut Harness<'static, EditorApp>) {
    h.step();
    h.state_mut().wait_for_files();
    h.state_mut().wait_for_composition();
    h.run();
}

/// Click at `pos`: hover, then press and release one frame apart. The harness advances
/// 0.25 s a frame and egui takes a press held over 0.8 s for a long press, not a click:
/// settling between press and release (as many frames as the workers keep the UI busy,
/// more under load) once made a click add no beat.
pub fn click(h: &mut Harness<'static, EditorApp>, pos: egui::Pos2) {
    click_settled_by(h, pos, settle);
}

/// [`click`], letting the UI settle between its frames with `settle`.
pub fn click_settled_by(
    h: &mut Harness<'static, EditorApp>,
    pos: egui::Pos2,
    settle: impl Fn(&mut Harness<'static, EditorApp>),
) {
    h.hover_at(pos);
    settle(h);
    h.drag_at(pos);
    h.step();
    h.drop_at(pos);
    settle(h);
}

/// Where `tick` lies in `hand`'s lane once the layout has stopped moving (a panel that
/// opens or closes animates over a few frames, and a click aimed at the first frame's
/// geometry can land beside its lane): the point two settled frames agree on.
pub fn steady_timeline_point(
    h: &mut Harness<'static, EditorApp>,
    tick: u64,
    hand: timpanist::score::Hand,
) -> egui::Pos2 {
    let mut point = h.state().timeline_point(tick, hand);
    for _ in 0..30 {
        settle(h);
        let now = h.state().timeline_point(tick, hand);
        if now == point {
            break;
        }
        point = now;
    }
    point.expect("the timeline has been drawn")
}

/// The editor on a copy of the improvisation score in `dir` (so the file browser starts
/// there), not rendering by itself, and that copy's path.
pub fn editor_on_improvisation(dir: &Path) -> (Harness<'static, EditorApp>, PathBuf) {
    let score = dir.join("improvisation.ron");
    std::fs::copy(root().join("scores/improvisation.ron"), &score).unwrap();
    let mut h = editor(Some(score.clone()), dir, false);
    settle(&mut h);
    (h, score)
}

/// Render `score` with the defaults and hand the rendering to the editor.
pub fn give_rendering(h: &mut Harness<'static, EditorApp>, score: &Path) {
    let loaded = LoadedScore::load(score).unwrap();
    let db = MotionDb::load(&root().join("mocap")).unwrap();
    let rendering = render(&loaded, &db, &RenderParams::default(), &mut |_| true).unwrap();
    h.state_mut().set_rendering(std::sync::Arc::new(rendering));
    settle(h);
}

/// `loaded` rendered in one simulation pass (no timing compensation: quick, and enough
/// for what the views show), with the built-in motion database.
#[allow(dead_code)]
pub fn render_once(loaded: &LoadedScore) -> timpanist::render::Rendering {
    let db = timpanist::mocap::shipped::built_in().unwrap();
    let params = RenderParams {
        max_attempts: 1,
        ..RenderParams::default()
    };
    render(loaded, &db, &params, &mut |_| true).unwrap()
}

/// The editor on `score` drawn with wgpu (a software GPU is enough), settled.
#[allow(dead_code)]
pub fn wgpu_editor(score: PathBuf, dir: &Path) -> Harness<'static, EditorApp> {
    let options = options(Some(score), dir, false);
    let mut h = builder()
        .wgpu()
        .build_eframe(move |_cc| EditorApp::with_options(options));
    settle(&mut h);
    h
}

/// Open the menu `menu`, click its item `item`, and close the menu if the item left it
/// open (a checkbox does).
#[allow(dead_code)]
pub fn choose(h: &mut Harness<'static, EditorApp>, menu: &str, item: &str) {
    use egui_kittest::kittest::Queryable;
    h.get_by_label(menu).click();
    h.run();
    h.get_by_label(item).click();
    settle(h);
    if h.query_by_label(item).is_some() {
        h.key_press(egui::Key::Escape);
        settle(h);
    }
}

/// Whether the File menu item `label` is disabled (opens and closes the menu).
pub fn file_item_disabled(h: &mut Harness<'static, EditorApp>, label: &str) -> bool {
    use egui_kittest::kittest::{NodeT, Queryable};
    h.get_by_label("File").click();
    settle(h);
    let disabled = h.get_by_label(label).accesskit_node().is_disabled();
    h.get_by_label("File").click();
    settle(h);
    disabled
}
