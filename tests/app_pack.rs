//! File > Export lesson pack... driven headless through egui_kittest: on a rendering of
//! the improvisation score, the menu item asks for a new folder in the in-window browser
//! (folders only, the suggested name `NAME-lesson`), Save writes the pack there on a
//! background job and the status bar says so; a second export to the same folder is
//! refused with the reason and leaves the first pack as it was; without a rendering the
//! item is disabled.

mod common;

use common::settle;
use egui_kittest::kittest::Queryable;

#[test]
fn file_menu_exports_a_lesson_pack_into_a_new_folder() {
    let dir = tempfile::tempdir().unwrap();
    let (mut h, score) = common::editor_on_improvisation(dir.path());
    // Without a rendering the item is there but disabled.
    assert!(
        common::file_item_disabled(&mut h, "Export lesson pack..."),
        "exportable with no rendering"
    );
    common::give_rendering(&mut h, &score);

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
