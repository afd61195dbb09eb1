//! File > Export lesson pack... driven headless through egui_kittest: on a rendering of
//! the improvisation score, the menu item asks for a new folder in the in-window browser
//! (folders only, the suggested name `NAME-lesson`), Save writes the pack there on a
//! background job and the status bar says so; a second export to the same folder is
//! refused with the reason and leaves the first pack as it was; without a rendering the
//! item is disabled.

mod common;

use common::{root, settle};
use egui_kittest::kittest::{NodeT, Queryable};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use timpanist::mocap::db::MotionDb;
use timpanist::render::{RenderParams, render};
use timpanist::score::LoadedScore;

/// A copy of the improvisation score in `dir` (so the browser starts there, not in the
/// repository).
fn score_in(dir: &Path) -> PathBuf {
    let path = dir.join("improvisation.ron");
    std::fs::copy(root().join("scores/improvisation.ron"), &path).unwrap();
    path
}

#[test]
fn file_menu_exports_a_lesson_pack_into_a_new_folder() {
    let dir = tempfile::tempdir().unwrap();
    let score = score_in(dir.path());
    let mut h = common::editor(Some(score.clone()), dir.path(), false);
    settle(&mut h);
    // Without a rendering the item is there but disabled.
    h.get_by_label("File").click();
    settle(&mut h);
    assert!(
        h.get_by_label("Export lesson pack...")
            .accesskit_node()
            .is_disabled(),
        "exportable with no rendering"
    );
    h.get_by_label("File").click();
    settle(&mut h);

    let loaded = LoadedScore::load(&score).unwrap();
    let db = MotionDb::load(&root().join("mocap")).unwrap();
    let rendering = render(&loaded, &db, &RenderParams::default(), &mut |_| true).unwrap();
    h.state_mut().set_rendering(Arc::new(rendering));
    settle(&mut h);

    h.get_by_label("File").click();
    settle(&mut h);
    h.get_by_label("Export lesson pack...").click();
    settle(&mut h);
    assert!(h.state().is_file_browser_open(), "no dialog for the folder");
    h.get_by_label("Save").click();
    // The export runs as a job (a spinner shows meanwhile): one frame to start it.
    h.step();
    h.state_mut().wait_for_files();
    settle(&mut h);
    let pack = dir.path().join("improvisation-lesson");
    assert!(
        pack.join("index.html").is_file(),
        "no pack: {:?}",
        h.state().error()
    );
    assert!(pack.join("audio/phrase-01.wav").is_file());
    assert!(pack.join("plots/tip-heights.svg").is_file());
    assert!(pack.join("motion/scene.glb").is_file());
    assert!(
        h.state().status().contains("lesson pack"),
        "{}",
        h.state().status()
    );
    let html = std::fs::read_to_string(pack.join("index.html")).unwrap();
    assert!(html.contains("Improvisation"), "the score's title");

    // The same folder again: refused, naming it; the first pack is untouched.
    let before = std::fs::read(pack.join("index.html")).unwrap();
    h.state_mut().export_pack_to(&pack);
    h.state_mut().wait_for_files();
    settle(&mut h);
    let error = h.state().error().unwrap_or_default().to_string();
    assert!(
        error.contains("not empty") && error.contains("improvisation-lesson"),
        "{error}"
    );
    assert_eq!(std::fs::read(pack.join("index.html")).unwrap(), before);
}
