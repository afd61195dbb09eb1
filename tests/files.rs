//! Score and kit files end to end: the shipped content is valid, round-trips through
//! save and load, and bad files are refused by the real `timpanist check` binary with
//! the file, line and column and what was expected.

use std::path::{Path, PathBuf};
use std::process::Command;
use timpanist::kit::Kit;
use timpanist::score::{LoadedScore, Score};

fn shipped(dir: &str) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> =
        std::fs::read_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join(dir))
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|x| x == "ron"))
            .collect();
    files.sort();
    files
}

fn check(files: &[&Path]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_timpanist"))
        .arg("check")
        .args(files)
        .output()
        .unwrap()
}

/// Write `text` to a temporary score file next to a copy of the standard kit path layout.
fn temp_score(dir: &Path, text: &str) -> PathBuf {
    let path = dir.join("bad.ron");
    std::fs::write(
        &path,
        text.replace("../kits/standard.ron", "standard")
            .replace("../kits/solo.ron", "solo"),
    )
    .unwrap();
    path
}

fn demo_text() -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("scores/improvisation.ron"))
        .unwrap()
}

/// `timpanist check scores/*.ron kits/*.ron` accepts everything we ship (at least four
/// scores and two kits).
#[test]
fn shipped_content_checks() {
    let scores = shipped("scores");
    let kits = shipped("kits");
    assert!(scores.len() >= 4 && kits.len() >= 2);
    let all: Vec<&Path> = scores.iter().chain(&kits).map(PathBuf::as_path).collect();
    let out = check(&all);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(
        String::from_utf8_lossy(&out.stdout)
            .lines()
            .filter(|l| l.starts_with("ok"))
            .count(),
        all.len()
    );
}

/// Every shipped score survives load → save → load unchanged, and so does every kit.
#[test]
fn shipped_content_round_trips() {
    let dir = tempfile::tempdir().unwrap();
    for path in shipped("scores") {
        let first = LoadedScore::load(&path).unwrap().score;
        let copy = dir.path().join("copy.ron");
        first.save(&copy).unwrap();
        let second = Score::parse(&copy, &std::fs::read_to_string(&copy).unwrap()).unwrap();
        assert_eq!(first, second, "{}", path.display());
        assert_eq!(first.to_ron(), second.to_ron());
    }
    for path in shipped("kits") {
        let kit = Kit::load(&path).unwrap();
        let copy = dir.path().join("kit.ron");
        kit.save(&copy).unwrap();
        assert_eq!(Kit::load(&copy).unwrap(), kit);
    }
}

/// A misspelt field fails with `path:line:col` and the list of expected fields.
#[test]
fn typo_reports_line_column_and_expectation() {
    let dir = tempfile::tempdir().unwrap();
    let path = temp_score(
        dir.path(),
        &demo_text().replace("grip: French", "gripp: French"),
    );
    let out = check(&[&path]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    let line = demo_text()
        .lines()
        .position(|l| l.contains("grip: French"))
        .unwrap()
        + 1;
    assert!(
        err.contains(&format!("{}:{line}:5:", path.display())),
        "{err}"
    );
    assert!(
        err.contains("`gripp`") && err.contains("expected one of"),
        "{err}"
    );
}

/// A misspelt playing mode names the enum's variants; a missing field is an error.
#[test]
fn bad_variant_and_missing_field() {
    let dir = tempfile::tempdir().unwrap();
    let path = temp_score(
        dir.path(),
        &demo_text().replace("mode: Staccato", "mode: Stacato"),
    );
    let err = String::from_utf8_lossy(&check(&[&path]).stderr).to_string();
    assert!(
        err.contains("`Stacato`") && err.contains("`VerticalAccent`"),
        "{err}"
    );
    let path = temp_score(dir.path(), &demo_text().replace("grip: French,", ""));
    let out = check(&[&path]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("`grip`"));
}

/// Content errors name the beat with its bar and beat; an impossible tempo is refused.
#[test]
fn content_errors_name_the_place() {
    let dir = tempfile::tempdir().unwrap();
    let path = temp_score(
        dir.path(),
        &demo_text().replace("drum: 0, location: Rim", "drum: 7, location: Rim"),
    );
    let err = String::from_utf8_lossy(&check(&[&path]).stderr).to_string();
    assert!(
        err.contains("beat 4 (bar 2 beat 1): drum 7 does not exist"),
        "{err}"
    );
    let path = temp_score(dir.path(), &demo_text().replace("bpm: 72.0", "bpm: 0.0"));
    let err = String::from_utf8_lossy(&check(&[&path]).stderr).to_string();
    assert!(
        err.contains("tempo point 0") && err.contains("impossible"),
        "{err}"
    );
}

/// A beat's problem names it by its place in the file's `beats` list and gives the line
/// and column of its entry, whatever order the file lists the beats in; an impact angle
/// that is no number is named as the angle, not the radius.
#[test]
fn beat_problems_name_the_file_number_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let mut score = Score::new("out of order");
    let mut nan = timpanist::score::Beat::plain(960, 0);
    nan.location = timpanist::score::ImpactLocation::Point {
        radius: 0.5,
        angle_deg: f64::NAN,
    };
    // Listed in the file as ticks 1920, 0 (no such drum), 960 (angle NaN).
    score.beats = vec![
        timpanist::score::Beat::plain(1920, 0),
        timpanist::score::Beat::plain(0, 7),
        nan,
    ];
    let path = dir.path().join("order.ron");
    score.save(&path).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    let line_of = |needle: &str| text.lines().position(|l| l.contains(needle)).unwrap() + 1;
    let out = check(&[&path]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    let lines: Vec<&str> = err.lines().collect();
    assert_eq!(
        lines[..2],
        [
            format!(
                "{}:{}:9: beat 1 (bar 1 beat 1): drum 7 does not exist: kit \"Standard set (32/29/26/23 inch)\" has drums 0 to 3",
                path.display(),
                line_of("drum: 7")
            ),
            format!(
                "{}:{}:9: beat 2 (bar 1 beat 2): impact point angle_deg NaN must be a finite angle, degrees",
                path.display(),
                line_of("NaN")
            ),
        ],
        "{err}"
    );
}

/// Opening a score that lists its beats out of time order (as the editor and
/// `timpanist FILE` do) notes that the editor numbers them in time order; a score in
/// time order opens without that note.
#[test]
fn opening_beats_out_of_order_says_how_they_are_numbered() {
    let dir = tempfile::tempdir().unwrap();
    let mut score = Score::new("t");
    score.beats = vec![
        timpanist::score::Beat::plain(960, 0),
        timpanist::score::Beat::plain(0, 1),
    ];
    let path = dir.path().join("order.ron");
    score.save(&path).unwrap();
    let opened = timpanist::io::open::read(&path).unwrap();
    assert_eq!(opened.loaded.score.beats[0].tick, 0);
    assert!(
        opened
            .notices
            .iter()
            .any(|n| n.contains("listed out of time order")),
        "{:?}",
        opened.notices
    );
    score.sort_beats();
    score.save(&path).unwrap();
    assert!(timpanist::io::open::read(&path).unwrap().notices.is_empty());
}

/// A file from a newer timpanist is refused with a clear message, not misread.
#[test]
fn newer_format_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let path = temp_score(
        dir.path(),
        &demo_text().replace(
            &format!("version: {}", timpanist::score::SCORE_FORMAT_VERSION),
            "version: 9",
        ),
    );
    let err = String::from_utf8_lossy(&check(&[&path]).stderr).to_string();
    assert!(err.contains("format version 9 is newer"), "{err}");
}

/// A kit file with a tuning outside its range is refused, naming the drum.
#[test]
fn bad_kit_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("kits/pair.ron"))
        .unwrap();
    let path = dir.path().join("kit.ron");
    std::fs::write(&path, text.replacen("tuning: \"A2\"", "tuning: \"A3\"", 1)).unwrap();
    let out = check(&[&path]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("drum 0 (29-inch): tuning A3 is outside its range F2–C3"),
        "{err}"
    );
}
