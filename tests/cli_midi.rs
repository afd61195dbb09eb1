//! The real binary's `export-midi` and `import-midi`: every demo score survives
//! score → MIDI → score with each beat's tick, drum and velocity, and failures leave no
//! output file behind.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use timpanist::score::LoadedScore;

fn timpanist(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_timpanist"))
        .args(args)
        .output()
        .unwrap()
}

fn demo_scores() -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scores");
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    v.sort();
    v
}

/// Every demo score → MIDI → score keeps each beat's tick (±1), drum and MIDI velocity.
#[test]
fn demo_scores_round_trip_through_midi() {
    let dir = tempfile::tempdir().unwrap();
    for score_path in demo_scores() {
        let original = LoadedScore::load(&score_path).unwrap();
        let mid = dir.path().join("x.mid");
        let back = dir.path().join("x.ron");
        let kit = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("kits")
            .join(Path::new(&original.score.kit).file_name().unwrap());
        let out = timpanist(&[
            "export-midi",
            score_path.to_str().unwrap(),
            "-o",
            mid.to_str().unwrap(),
        ]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let out = timpanist(&[
            "import-midi",
            mid.to_str().unwrap(),
            "-o",
            back.to_str().unwrap(),
            "--kit",
            kit.to_str().unwrap(),
        ]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let imported = LoadedScore::load(&back).unwrap();
        let (a, b) = (&original.score, &imported.score);
        assert_eq!(a.beats.len(), b.beats.len(), "{}", score_path.display());
        for (x, y) in a.beats.iter().zip(&b.beats) {
            let tx = x.tick * u64::from(b.ticks_per_quarter);
            let ty = y.tick * u64::from(a.ticks_per_quarter);
            assert!(
                tx.abs_diff(ty) <= u64::from(a.ticks_per_quarter),
                "{}: tick {} vs {}",
                score_path.display(),
                x.tick,
                y.tick
            );
            assert_eq!(x.drum, y.drum);
            assert_eq!(x.dynamic.midi_velocity(), y.dynamic.midi_velocity());
        }
    }
}

/// A file that is not MIDI fails with one line naming it, and writes nothing.
#[test]
fn bad_midi_leaves_no_output() {
    let dir = tempfile::tempdir().unwrap();
    let bogus = dir.path().join("bogus.mid");
    std::fs::write(&bogus, b"MThd\0\0\0\x06\0\x01").unwrap();
    let out_path = dir.path().join("out.ron");
    let out = timpanist(&[
        "import-midi",
        bogus.to_str().unwrap(),
        "-o",
        out_path.to_str().unwrap(),
    ]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.starts_with("error: ") && err.contains("bogus.mid"),
        "{err}"
    );
    assert!(!out_path.exists());
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        1,
        "a temporary file was left behind"
    );
}

/// Exporting a broken score fails and leaves no MIDI file.
#[test]
fn bad_score_exports_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let score = dir.path().join("s.ron");
    std::fs::write(&score, "Score(version: 1)").unwrap();
    let mid = dir.path().join("s.mid");
    let out = timpanist(&[
        "export-midi",
        score.to_str().unwrap(),
        "-o",
        mid.to_str().unwrap(),
    ]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("s.ron:1:"));
    assert!(!mid.exists());
}

/// The real Bach MIDI file imports through the CLI with its 112 timpani notes.
#[test]
fn bach_imports_through_cli() {
    let dir = tempfile::tempdir().unwrap();
    let mid = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/bwv248-64-6.mid");
    let out_path = dir.path().join("bach.ron");
    let out = timpanist(&[
        "import-midi",
        mid.to_str().unwrap(),
        "-o",
        out_path.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(LoadedScore::load(&out_path).unwrap().score.beats.len(), 112);
}
