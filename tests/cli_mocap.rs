//! `timpanist mocap import` end to end: a Motive-style CSV export with one rigid body per
//! stick (Y up, metres, 250 Hz), written from a synthetic take whose impacts are known,
//! is cut into the right units; bad input, or a take with no strokes on the tracks
//! taken as sticks, leaves the database untouched; a file imported again replaces its
//! take.

use glam::{DQuat, DVec3};
use std::fmt::Write as _;
use std::path::Path;
use std::process::Command;
use timpanist::body::{Joint, Skeleton};
use timpanist::kit::Side;
use timpanist::mocap::db::{MotionDb, file_sha256};
use timpanist::mocap::synth::{SynthConfig, synthesize};
use timpanist::score::{Dynamic, Grip, ImpactLocation, PlayingMode};

fn timpanist(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_timpanist"))
        .args(args)
        .output()
        .unwrap()
}

/// A synthetic take of six French legato forte strokes of the right hand.
fn right_hand_legato() -> MotionDb {
    synthesize(&SynthConfig {
        grips: vec![Grip::French],
        modes: vec![PlayingMode::Legato],
        locations: vec![ImpactLocation::PlayingSpot],
        hands: vec![Side::Right],
        dynamics: vec![Dynamic::F],
        strokes_per_dynamic: 6,
        ..SynthConfig::default()
    })
}

/// Performer frame (Z up) to Motive's Y-up frame, for positions and rotations.
fn to_y_up(p: DVec3) -> DVec3 {
    DVec3::new(p.x, p.z, -p.y)
}

/// A Motive CSV export of `db`'s first take: rigid bodies StickL and StickR, pivot at the
/// grip, rotated with the stick, so the tip sits at (0, 0, −stick length) in the body.
fn motive_csv(db: &MotionDb) -> String {
    let skeleton = Skeleton::default();
    let poses = db.takes[0].joints.as_ref().unwrap();
    let n = poses.len();
    let to_y_up_rotation = DQuat::from_rotation_x(-std::f64::consts::FRAC_PI_2);
    let mut out = format!(
        "Format Version,1.23,Take Name,legato_spot,Take Notes,,Capture Frame Rate,250.000000,Export Frame Rate,250.000000,Capture Start Time,2024-05-14 03.12.45.120 PM,Capture Start Frame,0,Total Frames in Take,{n},Total Exported Frames,{n},Rotation Type,Quaternion,Length Units,Meters,Coordinate Space,Global\n\n"
    );
    out += ",Type,Rigid Body,Rigid Body,Rigid Body,Rigid Body,Rigid Body,Rigid Body,Rigid Body,Rigid Body,Rigid Body,Rigid Body,Rigid Body,Rigid Body,Rigid Body,Rigid Body,Rigid Body,Rigid Body\n";
    out += ",Name,StickL,StickL,StickL,StickL,StickL,StickL,StickL,StickL,StickR,StickR,StickR,StickR,StickR,StickR,StickR,StickR\n";
    out += ",ID,1,1,1,1,1,1,1,1,2,2,2,2,2,2,2,2\n";
    out += ",,Rotation,Rotation,Rotation,Rotation,Position,Position,Position,Mean Marker Error,Rotation,Rotation,Rotation,Rotation,Position,Position,Position,Mean Marker Error\n";
    out += "Frame,Time (Seconds),X,Y,Z,W,X,Y,Z,,X,Y,Z,W,X,Y,Z,\n";
    for (f, pose) in poses.iter().enumerate() {
        let frames = skeleton.forward(pose);
        write!(out, "{f},{:.6}", f as f64 / 250.0).unwrap();
        for grip in [Joint::GripL, Joint::GripR] {
            let q = to_y_up_rotation * frames.rotation[grip.index()];
            let p = to_y_up(frames.position[grip.index()]);
            write!(
                out,
                ",{:.7},{:.7},{:.7},{:.7},{:.7},{:.7},{:.7},0.000300",
                q.x, q.y, q.z, q.w, p.x, p.y, p.z
            )
            .unwrap();
        }
        out.push('\n');
    }
    out
}

/// The Motive export imports with rigid-body tips, Y up, labels from the file name, and
/// yields the units the synthetic take was cut into (impacts ±1 frame).
#[test]
fn motive_rigid_body_export_imports() {
    let source = right_hand_legato();
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("legato_spot_f_french.csv");
    std::fs::write(&csv, motive_csv(&source)).unwrap();
    let db_dir = dir.path().join("db");
    let stick = Skeleton::default().stick_length_m;
    let offset = format!("0,0,-{stick}");
    let out = timpanist(&[
        "mocap",
        "import",
        csv.to_str().unwrap(),
        "--format",
        "motive",
        "--tips",
        "StickL,StickR",
        "--tip-offset",
        &offset,
        "-o",
        db_dir.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let db = MotionDb::load(&db_dir).unwrap();
    let right: Vec<_> = db
        .index
        .units
        .iter()
        .filter(|u| u.hand == Side::Right)
        .collect();
    assert_eq!(right.len(), source.index.units.len());
    for (ours, theirs) in right.iter().zip(&source.index.units) {
        assert!(
            ours.impact.abs_diff(theirs.impact) <= 1,
            "{} vs {}",
            ours.impact,
            theirs.impact
        );
        assert_eq!(
            (ours.mode, ours.location, ours.dynamic, ours.grip),
            (
                PlayingMode::Legato,
                ImpactLocation::PlayingSpot,
                Dynamic::F,
                Grip::French
            )
        );
    }
    let tip = db.takes[0].tip(Side::Right)[right[0].impact].unwrap();
    assert!(
        (tip.z - 0.76).abs() < 0.012,
        "tip back in the performer frame: {tip}"
    );

    // Bodies named only by their hand ("L", "R") are the sticks when the take holds
    // nothing else.
    let plain = dir.path().join("legato_spot_f_french_plain.csv");
    let renamed = motive_csv(&source)
        .replace("StickL", "L")
        .replace("StickR", "R");
    std::fs::write(&plain, renamed).unwrap();
    let plain_db = dir.path().join("plain-db");
    let out = timpanist(&[
        "mocap",
        "import",
        plain.to_str().unwrap(),
        "--format",
        "motive",
        "--tip-offset",
        &offset,
        "-o",
        plain_db.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let plain_units = MotionDb::load(&plain_db).unwrap().index.units;
    assert_eq!(plain_units.len(), db.index.units.len());

    // A second file with an unknown label fails and leaves the database as it was.
    let before = std::fs::read_to_string(db_dir.join("index.ron")).unwrap();
    let out = timpanist(&[
        "mocap",
        "import",
        csv.to_str().unwrap(),
        "--tips",
        "StickL,Nope",
        "-o",
        db_dir.to_str().unwrap(),
    ]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("Nope"));
    assert_eq!(
        std::fs::read_to_string(db_dir.join("index.ron")).unwrap(),
        before
    );
}

/// The real C3D files hold no strokes: one read with the wrists taken for sticks is
/// refused naming the tracks, as is one whose only "right" label is a body's sternum
/// (`Daphnee:STER`), and nothing is written; a corrupt capture fails with one line
/// naming it.
#[test]
fn c3d_and_corrupt_files() {
    let dir = tempfile::tempdir().unwrap();
    let c3d = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/c3d/ezc3d_Vicon.c3d");
    let db_dir = dir.path().join("db");
    let import = |extra: &[&str]| {
        let mut args = vec!["mocap", "import", c3d.to_str().unwrap()];
        args.extend_from_slice(extra);
        args.extend_from_slice(&["--mode", "legato", "-o", db_dir.to_str().unwrap()]);
        timpanist(&args)
    };
    let out = import(&["--tips", "Daphnee:WRIST,Daphnee:INDEX"]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stdout).contains("580 frames at 100 Hz"));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("ezc3d_Vicon.c3d: no strokes found")
            && err.contains("Left \"Daphnee:WRIST\"")
            && err.contains("Right \"Daphnee:INDEX\""),
        "{err}"
    );
    assert!(!db_dir.exists());
    let out = import(&[]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("cannot tell which track is which stick") && err.contains("Daphnee:STER,"),
        "{err}"
    );
    assert!(!db_dir.exists());
    let bad = dir.path().join("bad.c3d");
    std::fs::write(&bad, &std::fs::read(&c3d).unwrap()[..700]).unwrap();
    let out = timpanist(&[
        "mocap",
        "import",
        bad.to_str().unwrap(),
        "--tips",
        "a,b",
        "--mode",
        "legato",
        "-o",
        dir.path().join("db2").to_str().unwrap(),
    ]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.starts_with("error: ") && err.contains("bad.c3d"),
        "{err}"
    );
    assert!(!dir.path().join("db2").exists());
}

/// Two tracks labelled alike: refused, naming both places, when the label is the stick
/// (named by --tips or picked by itself); only a note among tracks not taken.
#[test]
fn duplicate_labels_are_refused_when_used() {
    let source = right_hand_legato();
    let tip = &source.takes[0].tips[1];
    let dir = tempfile::tempdir().unwrap();
    // A Vicon CSV: the tip, then two more tracks labelled `second` and `third` (mm).
    let write = |name: &str, second: &str, third: &str| {
        let mut out = format!(
            "Trajectories\n{}\n,,StickR:Tip,,,{second},,,{third},,\nFrame,Sub Frame,X,Y,Z,X,Y,Z,X,Y,Z\n",
            source.takes[0].rate_hz
        );
        for (f, p) in tip.iter().enumerate() {
            let p = p.unwrap_or(DVec3::new(0.3, 0.2, 1.0)) * 1000.0;
            writeln!(
                out,
                "{},0,{},{},{},100,500,1200,200,500,1200",
                f + 1,
                p.x,
                p.y,
                p.z
            )
            .unwrap();
        }
        let path = dir.path().join(name);
        std::fs::write(&path, out).unwrap();
        path
    };
    let db_dir = dir.path().join("db");
    let import = |csv: &Path, extra: &[&str]| {
        let mut args = vec!["mocap", "import", csv.to_str().unwrap()];
        args.extend_from_slice(extra);
        args.extend_from_slice(&["--mode", "legato", "-o", db_dir.to_str().unwrap()]);
        timpanist(&args)
    };
    let arms = write("arms.csv", "Player:WristR", "Player:WristR");
    let out = import(&arms, &[]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains(
            "two tracks are named \"Player:WristR\" (tracks 2 and 3) (not taken as a stick)"
        ),
        "{err}"
    );
    std::fs::remove_dir_all(&db_dir).unwrap();
    let tips = write("tips.csv", "Player:WristR", "StickR:Tip");
    for extra in [&["--tips", ",StickR:Tip"][..], &[]] {
        let out = import(&tips, extra);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{extra:?}: {err}");
        assert!(
            err.contains(
                "tips.csv: labels: two tracks are named \"StickR:Tip\" (tracks 1 and 3): rename one"
            ),
            "{extra:?}: {err}"
        );
        assert!(!err.contains("twice"), "{err}");
        assert!(!db_dir.exists());
    }
}

/// A take that cannot be aligned (a QTM export cut short before the first stroke) fails
/// with an error that points at `--unit`, `--up` and `--tips`, after the take's own notes
/// (the cut, the vertical that could not be told), printed as every note is.
#[test]
fn an_unalignable_take_prints_its_notes_before_the_error() {
    let source = right_hand_legato();
    let take = &source.takes[0];
    let first_impact = source.index.units[0].impact;
    let rows = first_impact / 2;
    let mut tsv = format!(
        "NO_OF_FRAMES\t{}\nNO_OF_CAMERAS\t8\nNO_OF_MARKERS\t1\nFREQUENCY\t{}\nNO_OF_ANALOG\t0\n\
         ANALOG_FREQUENCY\t0\nDESCRIPTION\t--\nTIME_STAMP\t2024-05-14, 15:12:45.120\t81234.5\n\
         DATA_INCLUDED\t3D\nMARKER_NAMES\tStick R tip\nTRAJECTORY_TYPES\tMeasured\n\
         Frame\tTime\tStick R tip X\tStick R tip Y\tStick R tip Z\t\n",
        take.frames(),
        take.rate_hz
    );
    for (f, p) in take.tips[1].iter().take(rows).enumerate() {
        let p = p.unwrap() * 1000.0;
        writeln!(
            tsv,
            "{}\t{:.5}\t{:.3}\t{:.3}\t{:.3}",
            f + 1,
            f as f64 / take.rate_hz,
            p.x,
            p.y,
            p.z
        )
        .unwrap();
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("legato_cut.tsv");
    std::fs::write(&path, tsv).unwrap();
    let db_dir = dir.path().join("db");
    let out = timpanist(&[
        "mocap",
        "import",
        path.to_str().unwrap(),
        "--profile",
        "qualisys-3d",
        "--tips",
        ",Stick R tip",
        "--align",
        "auto",
        "-o",
        db_dir.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{err}");
    assert!(!db_dir.exists());
    let shown = path.display().to_string();
    let cut_note = format!(
        "note: {shown}: NO_OF_FRAMES (line 1) says {} frames, the file has {rows} rows",
        take.frames()
    );
    let error_at = err.find("error: ").expect("an error line");
    let note_at = err
        .find(&cut_note)
        .unwrap_or_else(|| panic!("{cut_note:?} in {err}"));
    assert!(note_at < error_at, "{err}");
    assert!(
        err[..error_at].contains(&format!("note: {shown}: the vertical")),
        "{err}"
    );
    let error = &err[error_at..];
    assert!(error.contains("no impacts to align"), "{err}");
    for flag in ["--unit", "--up", "--tips"] {
        assert!(error.contains(flag), "{flag} in {err}");
    }
}

/// Importing a take again into a database that holds it — the same file, or its copy in
/// another folder: same name, same bytes — replaces it, with a note, and the database
/// reads as after the first import; another file of the same name (other bytes: the
/// export with CRLF line endings) is added beside it under a sample file of its own, and
/// a copy under another name is another take. A pair of files is known again by both.
#[test]
fn importing_the_same_take_again_replaces_it() {
    let source = right_hand_legato();
    let dir = tempfile::tempdir().unwrap();
    let name = "legato_spot_f_french.csv";
    let text = motive_csv(&source);
    let put = |folder: &str, name: &str, text: &str| {
        let folder = dir.path().join(folder);
        std::fs::create_dir_all(&folder).unwrap();
        let path = folder.join(name);
        std::fs::write(&path, text).unwrap();
        path.to_str().unwrap().to_string()
    };
    let csv = put("session", name, &text);
    let offset = format!("0,0,-{}", Skeleton::default().stick_length_m);
    let import = |files: &[&str], extra: &[&str], db: &Path| {
        let mut args = vec!["mocap", "import"];
        args.extend_from_slice(files);
        args.extend_from_slice(extra);
        args.extend_from_slice(&["--format", "motive", "--tip-offset", &offset, "-o"]);
        args.push(db.to_str().unwrap());
        let out = timpanist(&args);
        let err = String::from_utf8_lossy(&out.stderr).to_string();
        assert!(out.status.success(), "{err}");
        err
    };
    let db_dir = dir.path().join("db");
    let both = ["--tips", "StickL,StickR"];
    let err = import(&[&csv], &both, &db_dir);
    assert!(!err.contains("already in the database"), "{err}");
    let first = MotionDb::load(&db_dir).unwrap();
    assert_eq!(first.index.takes.len(), 1);
    assert!(!first.index.units.is_empty());
    let sha = file_sha256(text.as_bytes());
    assert_eq!(
        first.index.takes[0].source_sha256.as_deref(),
        Some(sha.as_str())
    );
    let tmot = "takes/legato_spot_f_french.tmot";

    // The same file again, then its copy in another folder: replaced.
    let copy = put("backup", name, &text);
    for file in [&csv, &copy] {
        let err = import(&[file], &both, &db_dir);
        let note = format!(
            "note: {file}: take {tmot} already in the database (the same bytes, imported from \
             {csv}): replaced"
        );
        assert!(err.contains(&note), "{note:?} in {err}");
        let db = MotionDb::load(&db_dir).unwrap();
        assert_eq!(db.index.takes.len(), 1);
        assert_eq!(db.index.takes[0].file, tmot);
        assert_eq!(db.index.units, first.index.units);
        assert_eq!(db.takes, first.takes);
    }
    assert!(!db_dir.join("takes/legato_spot_f_french-2.tmot").exists());

    // Another file of that name, other bytes: kept beside it, and replaced in turn.
    let crlf = put("day2", name, &text.replace('\n', "\r\n"));
    let err = import(&[&crlf], &both, &db_dir);
    let note = format!(
        "note: {crlf}: another file named {name} is already in the database (take {tmot}, \
         from {copy}, with other bytes): this one is added beside it as take \
         takes/legato_spot_f_french-2.tmot"
    );
    assert!(err.contains(&note), "{note:?} in {err}");
    let err = import(&[&crlf], &both, &db_dir);
    assert!(
        err.contains("take takes/legato_spot_f_french-2.tmot already in the database"),
        "{err}"
    );
    let db = MotionDb::load(&db_dir).unwrap();
    assert_eq!(db.index.takes.len(), 2);
    assert_eq!(db.index.units.len(), 2 * first.index.units.len());
    assert_ne!(
        db.index.takes[0].source_sha256,
        db.index.takes[1].source_sha256
    );
    // The same bytes under another name: another take.
    let renamed = put("session", "legato_spot_f_french_again.csv", &text);
    let err = import(&[&renamed], &both, &db_dir);
    assert!(!err.contains("already in the database"), "{err}");
    assert_eq!(MotionDb::load(&db_dir).unwrap().index.takes.len(), 3);

    // A pair of files (left stick's, right stick's), imported twice: one take.
    let pair_db = dir.path().join("pair-db");
    let right = put("session", "legato_spot_f_french_right.csv", &text);
    for round in 0..2 {
        let err = import(
            &[&csv, &right],
            &["--pair", "--tips", "StickL,StickR"],
            &pair_db,
        );
        assert_eq!(err.contains("already in the database"), round == 1, "{err}");
    }
    let pair = MotionDb::load(&pair_db).unwrap();
    assert_eq!(pair.index.takes.len(), 1);
    assert_eq!(
        pair.index.takes[0].source_sha256,
        Some(format!("{sha}+{sha}"))
    );
}

/// The right tip of [`right_hand_legato`] as a plain CSV (`time_s,StickR_x,…`), each
/// position multiplied by `scale` (1000: millimetres written where metres belong), with
/// `spike` (frame, value) written in place of one x.
fn plain_tip_csv(scale: f64, spike: Option<(usize, f64)>) -> String {
    let db = right_hand_legato();
    let take = &db.takes[0];
    let mut csv = String::from("time_s,StickR_x,StickR_y,StickR_z\n");
    for (f, p) in take.tips[1].iter().enumerate() {
        let p = p.expect("the synthetic take has no gaps") * scale;
        let x = spike.filter(|s| s.0 == f).map_or(p.x, |s| s.1);
        writeln!(csv, "{:.6},{x},{},{}", f as f64 / take.rate_hz, p.y, p.z).unwrap();
    }
    csv
}

/// Millimetres in a file read as metres are refused, naming `--unit mm`, with nothing
/// written; one absurd coordinate (a corrupt sample, 10^15 m) is read as a gap with a
/// note, and the database written stays readable.
#[test]
fn a_wrong_unit_is_refused_and_an_absurd_sample_is_a_gap() {
    let dir = tempfile::tempdir().unwrap();
    let mm = dir.path().join("legato_mm.csv");
    std::fs::write(&mm, plain_tip_csv(1000.0, None)).unwrap();
    let db_dir = dir.path().join("db");
    let import = |file: &Path, extra: &[&str]| {
        let mut args = vec!["mocap", "import", file.to_str().unwrap()];
        args.extend_from_slice(extra);
        args.extend_from_slice(&["-o", db_dir.to_str().unwrap()]);
        timpanist(&args)
    };
    let out = import(&mm, &[]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        err.contains("legato_mm.csv") && err.contains("m/s") && err.contains("give --unit mm"),
        "{err}"
    );
    assert!(!db_dir.exists());
    let out = import(&mm, &["--unit", "mm"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );

    let spiked = dir.path().join("legato_spike.csv");
    std::fs::write(&spiked, plain_tip_csv(1.0, Some((400, 1e15)))).unwrap();
    let out = import(&spiked, &[]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("1 sample more than 1000 km from the capture's origin read as gaps")
            && err.contains("frame 401"),
        "{err}"
    );
    let db = MotionDb::load(&db_dir).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(db.takes.len(), 2);
    let out = timpanist(&["mocap", "stats", db_dir.to_str().unwrap()]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// `mocap columns` on a C3D file says it reads text captures (it said "expected a block of
/// data rows"), and a capture with no tracks is refused saying so.
#[test]
fn columns_of_a_c3d_and_a_capture_with_no_tracks() {
    let c3d = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/c3d/ezc3d_Vicon.c3d");
    let out = timpanist(&["mocap", "columns", c3d.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        err.contains("ezc3d_Vicon.c3d: a C3D file: `mocap columns` shows delimited text"),
        "{err}"
    );
    let dir = tempfile::tempdir().unwrap();
    let empty = dir.path().join("legato_empty.csv");
    std::fs::write(&empty, "time_s\n0.000\n0.004\n0.008\n").unwrap();
    let db_dir = dir.path().join("db");
    let out = timpanist(&[
        "mocap",
        "import",
        empty.to_str().unwrap(),
        "-o",
        db_dir.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        err.contains("legato_empty.csv") && err.contains("at least one track"),
        "{err}"
    );
    assert!(!db_dir.exists());
}
