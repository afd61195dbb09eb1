//! File > Export video... and Export video frames... driven headless through
//! egui_kittest: on a rendering of the improvisation score the menu item asks where in the
//! in-window browser (suggesting `NAME.mp4`), Save films it on a background job from the
//! viewport's camera, and the file probes as H.264 with AAC; the frames item writes the PNG
//! folder; with no ffmpeg the error says so and names the frames export; without a
//! rendering both items are disabled. Needs ffmpeg (README).

mod common;

use common::settle;
use egui_kittest::kittest::Queryable;
use std::path::Path;
use std::process::Command;

fn streams(path: &Path) -> String {
    let out = Command::new("ffprobe")
        .args(["-v", "error", "-show_entries", "stream=codec_name"])
        .args(["-of", "csv=p=0"])
        .arg(path)
        .output()
        .expect("ffprobe runs (install ffmpeg)");
    String::from_utf8(out.stdout).unwrap()
}

#[test]
fn file_menu_exports_a_video_and_its_frames() {
    let dir = tempfile::tempdir().unwrap();
    let (mut h, score) = common::editor_on_improvisation(dir.path());
    for item in ["Export video...", "Export video frames (PNG + WAV)..."] {
        assert!(
            common::file_item_disabled(&mut h, item),
            "{item} with no rendering"
        );
    }
    common::give_rendering(&mut h, &score);

    h.get_by_label("File").click();
    settle(&mut h);
    h.get_by_label("Export video...").click();
    settle(&mut h);
    assert!(h.state().is_file_browser_open(), "no dialog for the video");
    h.get_by_label("Save").click();
    h.step();
    h.state_mut().wait_for_files();
    settle(&mut h);
    let video = dir.path().join("improvisation.mp4");
    assert!(video.is_file(), "no video: {:?}", h.state().error());
    assert_eq!(streams(&video), "h264\naac\n");
    assert!(h.state().status().contains("fps"), "{}", h.state().status());

    let frames = dir.path().join("frames");
    h.state_mut().export_video_frames_to(&frames);
    h.state_mut().wait_for_files();
    settle(&mut h);
    assert!(
        frames.join("frames/frame-000001.png").is_file(),
        "{:?}",
        h.state().error()
    );
    assert!(frames.join("audio.wav").is_file());

    // No ffmpeg: the error says so and names the frames export; nothing is written.
    // SAFETY: this test binary runs this one test; nothing else reads the environment.
    unsafe { std::env::set_var("TIMPANIST_FFMPEG", dir.path().join("none")) };
    let missing = dir.path().join("missing.mp4");
    h.state_mut().export_video_to(&missing);
    h.state_mut().wait_for_files();
    settle(&mut h);
    let error = h.state().error().unwrap_or_default().to_string();
    assert!(error.contains("ffmpeg was not found"), "{error}");
    assert!(error.contains("Export video frames"), "{error}");
    assert!(!missing.exists());
}
