//! `timpanist render --video` and `--video-frames` as a user runs them: the video probes
//! (ffprobe) as H.264 at the asked frame rate and size with an AAC stream, as long as the
//! mix; the frames folder holds one PNG per frame that shows the performance moving and
//! the playhead; without ffmpeg the command says so, points at the frames folder and
//! writes nothing; a container it cannot write is refused before rendering.
//!
//! Needs `ffmpeg` and `ffprobe` on PATH (README lists the package; `.ci/run` installs it).

use std::path::Path;
use std::process::Command;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn timpanist() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_timpanist"));
    c.current_dir(root());
    c
}

/// Seconds of audio in a WAV.
fn wav_seconds(path: &Path) -> f64 {
    let r = hound::WavReader::open(path).unwrap();
    f64::from(r.duration()) / f64::from(r.spec().sample_rate)
}

/// ffprobe's `key=value` lines for the streams and format of `path`.
fn probe(path: &Path) -> String {
    let out = Command::new("ffprobe")
        .args(["-v", "error", "-show_entries"])
        .arg("stream=codec_type,codec_name,width,height,r_frame_rate,nb_frames:format=duration")
        .args(["-of", "default=noprint_wrappers=1"])
        .arg(path)
        .output()
        .expect("ffprobe runs (install ffmpeg: README, Quick start)");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

fn field<'a>(probe: &'a str, key: &str) -> Vec<&'a str> {
    probe
        .lines()
        .filter_map(|l| l.strip_prefix(key)?.strip_prefix('='))
        .collect()
}

#[test]
fn render_video_probes_with_rate_size_duration_and_audio() {
    let dir = tempfile::tempdir().unwrap();
    let (wav, mp4) = (dir.path().join("mix.wav"), dir.path().join("etude.mp4"));
    for (fps, size, camera) in [("30", "640x360", "editor"), ("60", "320x180", "side")] {
        let out = timpanist()
            .args(["render", "scores/improvisation.ron", "--wav"])
            .arg(&wav)
            .arg("--video")
            .arg(&mp4)
            .args([
                "--video-fps",
                fps,
                "--video-size",
                size,
                "--video-camera",
                camera,
            ])
            .output()
            .unwrap();
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert!(
            out.status.success(),
            "{stdout}{}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(stdout.contains(&format!("at {fps} fps")), "{stdout}");
        let p = probe(&mp4);
        assert_eq!(field(&p, "codec_name"), ["h264", "aac"], "{p}");
        assert_eq!(field(&p, "codec_type"), ["video", "audio"], "{p}");
        assert_eq!(field(&p, "r_frame_rate")[0], format!("{fps}/1"), "{p}");
        let (w, h) = size.split_once('x').unwrap();
        assert_eq!(field(&p, "width"), [w], "{p}");
        assert_eq!(field(&p, "height"), [h], "{p}");
        let duration: f64 = field(&p, "duration").last().unwrap().parse().unwrap();
        let mix = wav_seconds(&wav);
        let frame = 1.0 / fps.parse::<f64>().unwrap();
        assert!(
            (duration - mix).abs() <= 2.0 * frame + 0.03,
            "video {duration} s, mix {mix} s"
        );
        let frames: u64 = field(&p, "nb_frames")[0].parse().unwrap();
        assert_eq!(frames, (mix / frame).ceil() as u64, "{p}");
    }
    // Only the video and the mix are left: no staging files beside them.
    let mut names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    names.sort();
    assert_eq!(names, ["etude.mp4", "mix.wav"]);
}

/// The PNG frames: one per frame of the mix, the size asked, the body moving between
/// frames, the playhead drawn in every frame at a third of the strip.
#[test]
fn render_video_frames_show_motion_and_playhead() {
    let dir = tempfile::tempdir().unwrap();
    let (wav, frames) = (dir.path().join("mix.wav"), dir.path().join("frames"));
    let out = timpanist()
        .args(["render", "scores/improvisation.ron", "--wav"])
        .arg(&wav)
        .arg("--video-frames")
        .arg(&frames)
        .args(["--video-size", "320x180"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let count = std::fs::read_dir(frames.join("frames")).unwrap().count() as u64;
    assert_eq!(count, (wav_seconds(&wav) * 30.0).ceil() as u64);
    assert!(frames.join("audio.wav").is_file());
    assert!(
        std::fs::read_to_string(frames.join("join.sh"))
            .unwrap()
            .contains("ffmpeg")
    );
    let load = |k: u64| {
        let path = frames.join(format!("frames/frame-{k:06}.png"));
        tiny_skia::Pixmap::load_png(&path).unwrap()
    };
    // The strokes of the improvisation fall between 1 and 4 s: its body moves.
    let (a, b) = (load(31), load(61));
    assert_eq!((a.width(), a.height()), (320, 180));
    let view_rows = 0..130usize;
    let moved = view_rows
        .flat_map(|y| (0..320usize).map(move |x| 4 * (y * 320 + x)))
        .filter(|&i| a.data()[i..i + 3] != b.data()[i..i + 3])
        .count();
    assert!(
        moved > 200,
        "only {moved} pixels of the view changed in 1 s"
    );
    // The playhead: a bright column a third of the way across the strip (after the lane
    // names), in the first and the last frame.
    for frame in [load(1), load(count)] {
        let x = (84.0 + (320.0 - 84.0) / 3.0) as usize;
        let bright = (150..180usize)
            .filter(|&y| (x - 1..=x + 1).any(|x| frame.data()[4 * (y * 320 + x)] > 200))
            .count();
        assert!(bright >= 25, "playhead lit {bright} of 30 rows");
    }
}

/// Without ffmpeg: a clear error naming the way out, a non-zero exit, nothing written
/// (checked before the render). A container it cannot write: refused the same way.
#[test]
fn render_video_refusals_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let wav = dir.path().join("mix.wav");
    let out = timpanist()
        .env("TIMPANIST_FFMPEG", dir.path().join("no-ffmpeg-here"))
        .args(["render", "scores/improvisation.ron", "--wav"])
        .arg(&wav)
        .arg("--video")
        .arg(dir.path().join("v.mp4"))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(stderr.contains("ffmpeg was not found"), "{stderr}");
    assert!(stderr.contains("--video-frames"), "{stderr}");
    let out = timpanist()
        .args(["render", "scores/improvisation.ron", "--wav"])
        .arg(&wav)
        .arg("--video")
        .arg(dir.path().join("v.avi"))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        stderr.contains("v.avi") && stderr.contains(".mp4"),
        "{stderr}"
    );
    let out = timpanist()
        .args(["render", "scores/improvisation.ron", "--wav"])
        .arg(&wav)
        .args(["--video-frames", "x", "--video-size", "641x360"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("even"));
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        0,
        "something was written"
    );
}
