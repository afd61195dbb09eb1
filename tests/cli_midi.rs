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

// ---- damaged and unusual files, built byte by byte ----

/// A Standard MIDI File of `tracks` (each a track chunk's bytes after its header,
/// its length given by `lengths` where `Some`) at 480 ticks per quarter.
fn smf(tracks: &[&[u8]], lengths: &[Option<u32>]) -> Vec<u8> {
    let mut out = b"MThd\0\0\0\x06\0\x01".to_vec();
    out.extend((tracks.len() as u16).to_be_bytes());
    out.extend(480u16.to_be_bytes());
    for (i, t) in tracks.iter().enumerate() {
        out.extend(b"MTrk");
        let len = lengths.get(i).copied().flatten();
        out.extend(len.unwrap_or(t.len() as u32).to_be_bytes());
        out.extend(*t);
    }
    out
}

/// A track of four quarter notes D3 on channel 1, program 48 (47 counted from 0), with
/// running status: its note-offs and later note-ons have no status byte.
const TIMPANI: &[u8] = b"\x00\xc0\x2f\x00\x90\x32\x5a\x83\x60\x32\x00\x00\x32\x5a\x83\x60\x32\x00\x00\x32\x5a\x83\x60\x32\x00\x00\x32\x5a\x83\x60\x32\x00\x00\xff\x2f\x00";
const CONDUCTOR: &[u8] = b"\x00\xff\x51\x03\x07\xa1\x20\x00\xff\x2f\x00";

/// Import `bytes` written to NAME in a scratch folder: (success, stderr, beats written).
fn import_bytes(name: &str, bytes: &[u8], extra: &[&str]) -> (bool, String, usize) {
    let dir = tempfile::tempdir().unwrap();
    let mid = dir.path().join(name);
    std::fs::write(&mid, bytes).unwrap();
    let out_path = dir.path().join("out.ron");
    let mut args = vec![
        "import-midi",
        mid.to_str().unwrap(),
        "-o",
        out_path.to_str().unwrap(),
    ];
    args.extend(extra);
    let out = timpanist(&args);
    let beats = if out_path.exists() {
        LoadedScore::load(&out_path).unwrap().score.beats.len()
    } else {
        0
    };
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
        beats,
    )
}

/// A track cut short inside an event (its chunk length too small) is imported as far as
/// it can be read, with a warning naming the track and the byte; a file cut short in its
/// only track with notes is refused naming the damage, not as having no timpani part; a
/// delta time longer than four bytes and a meta event longer than its track are damage
/// too (midly's lenient reader read past both without a word).
#[test]
fn damaged_tracks_are_reported_with_track_and_byte() {
    // The timpani track's chunk says 20 bytes: it ends inside the third note's delta time.
    let cut = smf(&[CONDUCTOR, TIMPANI], &[None, Some(20)]);
    let (ok, err, beats) = import_bytes("cut.mid", &cut, &[]);
    assert!(ok, "{err}");
    assert_eq!(beats, 2, "{err}");
    // 14 header + 8 + 11 conductor + 8 = byte 41 starts the timpani track's data; its
    // 20 bytes end with a delta time and one data byte of the third note.
    assert!(
        err.contains("warning: track 1 (no name) is damaged at byte 59: an event cut short"),
        "{err}"
    );
    let mut truncated = smf(&[CONDUCTOR, TIMPANI], &[]);
    truncated.truncate(14 + 8 + CONDUCTOR.len() + 8 + 4);
    let (ok, err, _) = import_bytes("truncated.mid", &truncated, &[]);
    assert!(!ok);
    assert!(
        err.starts_with("error: ") && err.contains("truncated.mid: track 1 (no name) is damaged at byte 44: the track ends after a delta time")
            && !err.contains("no timpani part found (no General"),
        "{err}"
    );
    let bad_vlq = smf(
        &[b"\x00\xc0\x2f\xff\xff\xff\xff\xff\x00\x90\x32\x5a\x00\xff\x2f\x00"],
        &[],
    );
    let (ok, err, _) = import_bytes("vlq.mid", &bad_vlq, &[]);
    assert!(
        !ok && err.contains("damaged at byte 25: a delta time longer than four bytes"),
        "{err}"
    );
    let long_meta = smf(
        &[b"\x00\xff\x03\x8f\xff\xff\x7fabc\x00\xc0\x2f\x00\x90\x32\x5a\x00\xff\x2f\x00"],
        &[],
    );
    let (ok, err, _) = import_bytes("meta.mid", &long_meta, &[]);
    assert!(
        !ok && err.contains("damaged at byte 22: a meta event longer than the rest of its track"),
        "{err}"
    );
}

/// A first track whose chunk length runs past the end of the file ends at its End of
/// Track, and the timpani track after it is read in full (with a warning).
#[test]
fn a_chunk_length_past_the_end_is_read_around() {
    let bytes = smf(&[CONDUCTOR, TIMPANI], &[Some(u32::MAX)]);
    let (ok, err, beats) = import_bytes("huge.mid", &bytes, &[]);
    assert!(ok, "{err}");
    assert_eq!(beats, 4, "{err}");
    assert!(
        err.contains("track 0 (no name) is damaged at byte 14: its chunk length"),
        "{err}"
    );
}

/// Running status continued after a meta event (which the SMF specification says cancels
/// it; writers rely on it anyway): the notes after the meta event are read, silently.
#[test]
fn running_status_after_a_meta_event() {
    let track: &[u8] = b"\x00\xc0\x2f\x00\x90\x32\x5a\x83\x60\x32\x00\x00\xff\x01\x03abc\x00\x2d\x5a\x83\x60\x2d\x00\x00\xff\x2f\x00";
    let (ok, err, beats) = import_bytes("running.mid", &smf(&[track], &[]), &[]);
    assert!(ok, "{err}");
    assert_eq!(beats, 2, "{err}");
    assert!(!err.contains("warning"), "{err}");
}

/// Tracks named "Timbales", "Pk." or "Kettledrums", or whose instrument name (FF 04) is
/// "Timpani", are the timpani part; "Paukenschlag Violin" is not.
#[test]
fn timpani_track_and_instrument_names() {
    // Four notes on channel 2 with no program: only the name can tell.
    let notes: &[u8] =
        b"\x00\x91\x32\x5a\x83\x60\x32\x00\x00\x32\x5a\x83\x60\x32\x00\x00\xff\x2f\x00";
    let named = |meta: u8, name: &str| {
        let mut t = vec![0, 0xff, meta, name.len() as u8];
        t.extend(name.as_bytes());
        t.extend(notes);
        smf(&[&t], &[])
    };
    for name in ["Timbales", "Pk.", "Kettledrums"] {
        let (ok, err, beats) = import_bytes("named.mid", &named(0x03, name), &[]);
        assert!(ok && beats == 2, "{name}: {err}");
    }
    let (ok, err, _) = import_bytes("inst.mid", &named(0x04, "Timpani"), &[]);
    assert!(ok, "{err}");
    let (ok, err, _) = import_bytes("violin.mid", &named(0x03, "Paukenschlag Violin"), &[]);
    assert!(!ok && err.contains("no timpani part found"), "{err}");
}

/// A file with a header and no track says so (the message ended in an empty track list).
#[test]
fn no_tracks_says_so() {
    let (ok, err, _) = import_bytes("empty.mid", &smf(&[], &[]), &[]);
    assert!(!ok);
    assert!(
        err.starts_with("error: ")
            && err.trim_end().ends_with(
                "empty.mid: the file holds no tracks (a MIDI header and nothing after it), so there is nothing to import"
            ),
        "{err}"
    );
}

/// A meta event of the right length whose content is odd (a key signature of one byte
/// where two belong) is skipped by its length: the tempo change after it in the
/// conductor track is kept, with no damage reported.
#[test]
fn an_odd_meta_event_keeps_the_rest_of_its_track() {
    // 100 bpm (600 000 µs), a one-byte key signature, then 60 bpm at tick 960.
    let conductor: &[u8] =
        b"\x00\xff\x51\x03\x09\x27\xc0\x00\xff\x59\x01\x00\x87\x40\xff\x51\x03\x0f\x42\x40\x00\xff\x2f\x00";
    let dir = tempfile::tempdir().unwrap();
    let mid = dir.path().join("keysig.mid");
    std::fs::write(&mid, smf(&[conductor, TIMPANI], &[])).unwrap();
    let out_path = dir.path().join("out.ron");
    let out = timpanist(&[
        "import-midi",
        mid.to_str().unwrap(),
        "-o",
        out_path.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(!err.contains("damaged"), "{err}");
    let score = LoadedScore::load(&out_path).unwrap().score;
    let bpm: Vec<f64> = score.tempo.iter().map(|t| t.bpm).collect();
    assert_eq!(bpm.len(), 2, "{:?}", score.tempo);
    assert!(
        (bpm[0] - 100.0).abs() < 0.01 && (bpm[1] - 60.0).abs() < 0.01,
        "{bpm:?}"
    );
}
