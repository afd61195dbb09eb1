//! `timpanist render` and `timpanist edit` as a user runs them: the render writes WAV,
//! motion (CSV, C3D), events and a plot, and refuses bad scores cleanly. These also run
//! against the headless build (`--no-default-features`), whose `edit` says how to get the
//! editor instead of opening it.

use std::path::Path;
use std::process::Command;
use timpanist::score::{Beat, Hand, ImpactLocation, Score};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The standard output of a run that must have succeeded (else its standard error).
fn succeeded(out: &std::process::Output) -> String {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// `timpanist render` writes a WAV, the motion CSV and C3D, the events JSON with the
/// issue's fields and a PNG plot, and prints its statistics.
#[test]
fn cli_render_writes_wav_motion_and_events() {
    let dir = tempfile::tempdir().unwrap();
    let (wav, csv, json, png) = (
        dir.path().join("out.wav"),
        dir.path().join("motion.csv"),
        dir.path().join("events.json"),
        dir.path().join("plot.png"),
    );
    let out = Command::new(env!("CARGO_BIN_EXE_timpanist"))
        .current_dir(root())
        .args(["render", "scores/improvisation.ron", "--stats", "--wav"])
        .arg(&wav)
        .arg("--motion")
        .arg(&csv)
        .arg("--c3d")
        .arg(dir.path().join("motion.c3d"))
        .arg("--events")
        .arg(&json)
        .arg("--plot")
        .arg(&png)
        .arg("--stems")
        .arg(dir.path().join("stems"))
        .output()
        .unwrap();
    let stdout = succeeded(&out);
    assert!(
        stdout.contains("real time") && stdout.contains("drums"),
        "{stdout}"
    );
    // The attempts per cluster add up to the clusters.
    let per_cluster = stdout
        .lines()
        .find_map(|l| l.strip_prefix("attempts per cluster: "))
        .expect("attempts per cluster");
    let settled: usize = per_cluster
        .trim_end_matches(" clusters")
        .split(", ")
        .map(|p| p.split(" for ").nth(1).unwrap().parse::<usize>().unwrap())
        .sum();
    assert!(
        stdout.contains(&format!("in {settled} clusters")),
        "{stdout}"
    );
    let mut reader = hound::WavReader::open(&wav).unwrap();
    assert_eq!(
        (reader.spec().sample_rate, reader.spec().channels),
        (48_000, 2)
    );
    // One stereo stem per drum, panned as in the mix (the solo kit has one drum), and
    // one per hand (tests/exports.rs): the stems sum to the mix.
    let mut stems: Vec<_> = std::fs::read_dir(dir.path().join("stems"))
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    stems.sort();
    assert_eq!(stems, ["1-23-inch.wav", "left.wav", "right.wav"]);
    let mut stem = hound::WavReader::open(dir.path().join("stems/1-23-inch.wav")).unwrap();
    assert_eq!(stem.spec().channels, 2);
    let stem: Vec<i16> = stem.samples::<i16>().map(Result::unwrap).collect();
    let mix: Vec<i16> = reader.samples::<i16>().map(Result::unwrap).collect();
    assert_eq!(mix.len(), stem.len());
    assert!(stem.iter().any(|s| s.abs() > 1000));
    assert!(mix.iter().zip(&stem).all(|(m, s)| (m - s).abs() <= 1));
    let events: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let first = &events.as_array().unwrap()[0];
    for key in [
        "beat",
        "hand",
        "drum",
        "scheduled_s",
        "contact_s",
        "duration_ms",
        "peak_force_n",
        "impact_speed_mps",
        "x_m",
        "y_m",
    ] {
        assert!(first.get(key).is_some(), "{key} missing in {first}");
    }
    let motion = std::fs::read_to_string(&csv).unwrap();
    assert!(motion.starts_with("time_s,left_tip_x_m"));
    assert!(motion.lines().count() > 250);
    let c3d = dir.path().join("motion.c3d");
    let take =
        timpanist::mocap::import::c3d::read(&c3d, &std::fs::read(&c3d).unwrap(), None).unwrap();
    assert_eq!(
        take.frames,
        motion.lines().count() - 1,
        "a frame per CSV row"
    );
    assert!(take.track("LTIP_TARGET").is_some() && take.track("ELBOW_R").is_some());
    assert!(std::fs::read(&png).unwrap().starts_with(b"\x89PNG"));
    // --plot's second figure: the first stroke's spectrum against a recorded note.
    let spectra = dir.path().join("plot-spectra.png");
    assert!(std::fs::read(&spectra).unwrap().starts_with(b"\x89PNG"));
}

/// `--body-hz 5000` steps the body at 5 kHz with the drums and the contact at 10 kHz,
/// and at 2.5 kHz while calm (and says so); `--body-hz 10000` at 10 kHz throughout; a
/// rate it does not offer is refused.
#[test]
fn cli_render_steps_the_body_at_the_rate_asked() {
    let dir = tempfile::tempdir().unwrap();
    let wav = dir.path().join("out.wav");
    let run = |hz: &str| {
        Command::new(env!("CARGO_BIN_EXE_timpanist"))
            .current_dir(root())
            .args(["render", "scores/improvisation.ron", "--stats", "--wav"])
            .arg(&wav)
            .args(["--body-hz", hz])
            .output()
            .unwrap()
    };
    let out = run("5000");
    let stdout = succeeded(&out);
    assert!(
        stdout.contains("at 5000 Hz (body; 2500 Hz while calm), 10000 Hz (drums and contact)"),
        "{stdout}"
    );
    let reference = succeeded(&run("10000"));
    assert!(
        reference.contains("at 10000 Hz (body), 10000 Hz (drums and contact)"),
        "{reference}"
    );
    let refused = run("3000");
    assert!(!refused.status.success());
    assert!(String::from_utf8_lossy(&refused.stderr).contains("--body-hz"));
}

/// `--room hall` hears the performance in a concert hall: the same length, the drums
/// ringing on longer after the last stroke (the reverberation) than dry.
#[test]
fn cli_render_hears_the_drums_in_a_hall() {
    let dir = tempfile::tempdir().unwrap();
    let run = |room: &str| {
        let wav = dir.path().join(format!("{room}.wav"));
        let out = Command::new(env!("CARGO_BIN_EXE_timpanist"))
            .current_dir(root())
            .args(["render", "scores/improvisation.ron", "--wav"])
            .arg(&wav)
            .args(["--room", room])
            .output()
            .unwrap();
        succeeded(&out);
        let mut reader = hound::WavReader::open(&wav).unwrap();
        let samples: Vec<f64> = reader
            .samples::<i16>()
            .map(|s| f64::from(s.unwrap()))
            .collect();
        samples
    };
    let (dry, hall) = (run("dry"), run("hall"));
    assert_eq!(dry.len(), hall.len());
    let last = dry.len() - 48_000; // the last half second (stereo)
    let energy = |s: &[f64]| s.iter().map(|v| v * v).sum::<f64>();
    let more_db = 10.0 * (energy(&hall[last..]) / energy(&dry[last..])).log10();
    eprintln!("the hall's last half second: {more_db:.1} dB over dry");
    assert!(more_db > 1.0, "{more_db:.1} dB");
}

/// A malformed score, or one with a stroke out of reach, fails with its name and the
/// place or beat, a non-zero exit, and no WAV.
#[test]
fn cli_render_refuses_bad_scores_cleanly() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.ron");
    std::fs::write(&bad, "Score(version: 2, title: \"x\", beats: [oops])").unwrap();
    let wav = dir.path().join("out.wav");
    // Renders `score`: it must fail, write no WAV, and say why (returned).
    let refused = |score: &Path| {
        let out = Command::new(env!("CARGO_BIN_EXE_timpanist"))
            .current_dir(root())
            .arg("render")
            .arg(score)
            .arg("--wav")
            .arg(&wav)
            .output()
            .unwrap();
        assert!(!out.status.success());
        assert!(!wav.exists());
        String::from_utf8_lossy(&out.stderr).into_owned()
    };
    let stderr = refused(&bad);
    assert!(stderr.contains("bad.ron:1:"), "{stderr}");

    // A stroke the body cannot reach: the right hand on the far-left drum's centre.
    let mut score = Score::new("reach");
    let mut beat = Beat::plain(960, 0);
    beat.hand = Hand::Right;
    beat.location = ImpactLocation::Centre;
    score.beats.push(beat);
    let far = dir.path().join("far.ron");
    score.save(&far).unwrap();
    let stderr = refused(&far);
    assert!(
        stderr.contains("far.ron: beat 0 is out of the right hand's reach"),
        "{stderr}"
    );

    // Past the limits: a file larger than a score may be (refused unread), and a score
    // longer than 30 minutes.
    let huge = dir.path().join("huge.ron");
    let mut text = std::fs::read_to_string(&far).unwrap();
    text.push_str(&" ".repeat(33 << 20));
    std::fs::write(&huge, text).unwrap();
    let stderr = refused(&huge);
    assert!(
        stderr.contains("huge.ron: 33.0 MB is larger than the 32.0 MB a text file may be"),
        "{stderr}"
    );
    let mut score = Score::new("long");
    score.beats = vec![Beat::plain(0, 1), Beat::plain(960 * 4000, 1)];
    let long = dir.path().join("long.ron");
    score.save(&long).unwrap();
    let stderr = refused(&long);
    assert!(
        stderr.contains("long.ron: length:") && stderr.contains("split it into movements"),
        "{stderr}"
    );
}

/// The standard error of `timpanist ARGS`, which must fail.
fn failed(args: &[&std::ffi::OsStr]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_timpanist"))
        .current_dir(root())
        .args(args)
        .output()
        .unwrap();
    assert!(!out.status.success());
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// `render` names a beat by its place in the file's `beats` list, as `check` does
/// (`tests/files.rs`), when the file lists them out of time order: the stroke out of
/// reach, at 960 ticks, is the file's beat 1 (the score's first in time).
#[test]
fn cli_render_names_beats_as_the_file_does() {
    let dir = tempfile::tempdir().unwrap();
    let wav = dir.path().join("out.wav");
    let mut score = Score::new("reach");
    let mut far = Beat::plain(960, 0);
    far.hand = Hand::Right;
    far.location = ImpactLocation::Centre;
    score.beats = vec![Beat::plain(1920, 1), far];
    let path = dir.path().join("far.ron");
    score.save(&path).unwrap();
    let stderr = failed(&[
        "render".as_ref(),
        path.as_ref(),
        "--wav".as_ref(),
        wav.as_ref(),
    ]);
    assert!(
        stderr.contains("far.ron: beat 1 is out of the right hand's reach"),
        "{stderr}"
    );
    assert!(!wav.exists());
}

/// A score with no beats is refused by `check` (exit 1) as `render` refuses it, in the
/// same words.
#[test]
fn check_refuses_an_empty_score_as_render_does() {
    let dir = tempfile::tempdir().unwrap();
    let wav = dir.path().join("out.wav");
    let empty = dir.path().join("empty.ron");
    Score::new("empty").save(&empty).unwrap();
    let refusal = format!("{}: the score is empty: nothing to render", empty.display());
    let stderr = failed(&[
        "render".as_ref(),
        empty.as_ref(),
        "--wav".as_ref(),
        wav.as_ref(),
    ]);
    assert!(stderr.contains(&format!("error: {refusal}")), "{stderr}");
    let stderr = failed(&["check".as_ref(), empty.as_ref()]);
    assert_eq!(
        stderr.lines().collect::<Vec<_>>(),
        [refusal.as_str(), "error: 1 of 1 files have problems"],
        "{stderr}"
    );
}

/// Without the `editor` feature, `timpanist edit` fails at once and says how to get the
/// editor (with it, the editor would open a window: not run here).
#[cfg(not(feature = "editor"))]
#[test]
fn headless_edit_says_how_to_get_the_editor() {
    let out = Command::new(env!("CARGO_BIN_EXE_timpanist"))
        .args(["edit", "scores/etude-modes.ron"])
        .current_dir(root())
        .output()
        .unwrap();
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("built without the editor") && stderr.contains("cargo"),
        "{stderr}"
    );
}

/// A score asking a drum for a second pitch renders, retuning the drum between the two
/// beats, and says so, naming the beat as the file lists it.
#[test]
fn cli_render_names_the_pedal_changes() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(root().join("scores/improvisation.ron"))
        .unwrap()
        .replace("../kits/", &format!("{}/kits/", root().display()));
    // The solo kit's one drum (F3): its first beat asks D3, its second E3.
    let mut beats = 0;
    let text: String = text
        .lines()
        .map(|l| {
            let line = if l.trim_start().starts_with("Beat(") && beats < 2 {
                beats += 1;
                let pitch = if beats == 1 { "D3" } else { "E3" };
                l.replacen(
                    "location:",
                    &format!("pitch: Some(\"{pitch}\"), location:"),
                    1,
                )
            } else {
                l.to_string()
            };
            line + "\n"
        })
        .collect();
    // The first beat (D3, tick 0) listed last: the change, at tick 960, is the file's
    // beat 0 — `render` and `check` name it so.
    let mut lines: Vec<&str> = text.lines().collect();
    let first = lines
        .iter()
        .position(|l| l.contains("Beat(tick: 0,"))
        .unwrap();
    let last = lines
        .iter()
        .rposition(|l| l.trim_start().starts_with("Beat("))
        .unwrap();
    let moved = lines.remove(first);
    lines.insert(last, moved);
    let score = dir.path().join("pedal.ron");
    std::fs::write(&score, lines.join("\n")).unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_timpanist"))
        .args(["render"])
        .arg(&score)
        .arg("--wav")
        .arg(dir.path().join("pedal.wav"))
        .output()
        .unwrap();
    succeeded(&out);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("beat 0: drum 0 is retuned from D3 to E3 in the"),
        "{stderr}"
    );
    // `check` finds the score valid and says the same.
    let out = Command::new(env!("CARGO_BIN_EXE_timpanist"))
        .arg("check")
        .arg(&score)
        .output()
        .unwrap();
    let stdout = succeeded(&out);
    assert!(
        stdout.contains("(note: 1 pedal change(s), ") && stdout.contains("; beat 0: drum 0"),
        "{stdout}"
    );
}
