//! The real binary's `sticking` command: every method fills in every Auto hand of the
//! demo scores, the result still checks, and a bad method name is refused.

use std::path::Path;
use std::process::Command;
use timpanist::score::{Hand, LoadedScore};

fn timpanist(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_timpanist"))
        .args(args)
        .output()
        .unwrap()
}

/// Each method, on each demo score, leaves no Auto hand and keeps fixed hands.
#[test]
fn every_method_fills_every_auto_hand() {
    let dir = tempfile::tempdir().unwrap();
    let scores = Path::new(env!("CARGO_MANIFEST_DIR")).join("scores");
    for entry in std::fs::read_dir(&scores).unwrap() {
        let path = entry.unwrap().path();
        let before = LoadedScore::load(&path).unwrap().score;
        for method in ["simple", "pairwise", "optimal"] {
            // Keep the kit reference valid by writing next to a copy of the kits folder layout.
            let out = dir.path().join("out.ron");
            let o = timpanist(&[
                "sticking",
                path.to_str().unwrap(),
                "--method",
                method,
                "-o",
                out.to_str().unwrap(),
            ]);
            assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
            let stdout = String::from_utf8_lossy(&o.stdout);
            assert!(stdout.contains("arm crossings"), "{stdout}");
            let text = std::fs::read_to_string(&out).unwrap();
            let after = timpanist::score::Score::parse(&out, &text).unwrap();
            assert_eq!(after.beats.len(), before.beats.len());
            for (a, b) in before.beats.iter().zip(&after.beats) {
                assert_ne!(b.hand, Hand::Auto, "{} {method}", path.display());
                if a.hand != Hand::Auto {
                    assert_eq!(a.hand, b.hand, "a fixed hand was changed");
                }
            }
        }
    }
}

/// An unknown method is a usage error with a non-zero exit.
#[test]
fn unknown_method_is_refused() {
    let score = Path::new(env!("CARGO_MANIFEST_DIR")).join("scores/etude-modes.ron");
    let o = timpanist(&["sticking", score.to_str().unwrap(), "--method", "random"]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("simple"));
}
