//! Capture importers end to end on real and realistic files: the three C3D samples from
//! ezc3d (Optotrak, Qualisys, Vicon; MIT licence in tests/fixtures/c3d/LICENSE-ezc3d),
//! hand-made Motive, Vicon Nexus and plain CSV exports of two timpani sticks, the C3D
//! writer's round trip, and a fuzz-style sweep that cuts and corrupts every fixture at
//! many offsets and checks that reading never panics.

use glam::{DQuat, DVec3};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use timpanist::io::c3d_write::write_c3d;
use timpanist::mocap::import::{self, Format, c3d, plain_csv};
use timpanist::mocap::{ImportError, Take, Track};

fn fixture(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures")
        .join(rel)
}

fn load(rel: &str) -> Take {
    let path = fixture(rel);
    import::read(&path, None).unwrap_or_else(|e| panic!("{e}"))
}

fn seen(t: &Track) -> usize {
    t.positions.iter().filter(|p| p.is_some()).count()
}

fn assert_near(a: DVec3, b: DVec3, tol: f64) {
    assert!(a.distance(b) < tol, "{a} vs {b}");
}

// ---------------------------------------------------------------- C3D: real files

#[test]
fn c3d_real_files_have_the_expected_markers_rate_and_frames() {
    // (file, markers, rate, frames read, frames the header declares)
    let expect = [
        ("c3d/ezc3d_Optotrak.c3d", 54, 30.0, 29, 1149),
        ("c3d/ezc3d_Qualisys.c3d", 55, 200.0, 340, 340),
        ("c3d/ezc3d_Vicon.c3d", 51, 100.0, 580, 580),
    ];
    for (rel, markers, rate, frames, declared) in expect {
        let take = load(rel);
        assert_eq!(take.tracks.len(), markers, "{rel}");
        assert_eq!(take.rate_hz, rate, "{rel}");
        assert_eq!(take.frames, declared, "{rel}");
        assert_eq!(take.file_unit, "mm", "{rel}");
        for t in &take.tracks {
            assert_eq!(t.positions.len(), declared, "{rel} {}", t.label);
            assert!(
                t.positions[frames..].iter().all(Option::is_none),
                "frames past the data are missing"
            );
            assert!(t.rotations.is_empty());
        }
        assert_eq!(
            take.notes.is_empty(),
            frames == declared,
            "{rel}: {:?}",
            take.notes
        );
        let bytes = std::fs::read(fixture(rel)).unwrap();
        let info = c3d::inspect(&fixture(rel), &bytes).unwrap();
        assert_eq!(info.declared_frames, declared, "{rel}");
        assert_eq!(info.frames, frames, "{rel}");
        assert_eq!(info.processor, c3d::Processor::Intel);
        assert!(info.float_data);
    }
    // The Optotrak sample is cut short: its header says frames 1..1149, but its data
    // section holds 29 whole frames (25056 bytes of 54 × 16), and nothing more.
    let info = c3d::inspect(
        &fixture("c3d/ezc3d_Optotrak.c3d"),
        &std::fs::read(fixture("c3d/ezc3d_Optotrak.c3d")).unwrap(),
    )
    .unwrap();
    assert_eq!(info.data_offset + 29 * 54 * 16, 28640);
    // Analog channels interleaved with the points are skipped.
    let q = c3d::inspect(
        &fixture("c3d/ezc3d_Qualisys.c3d"),
        &std::fs::read(fixture("c3d/ezc3d_Qualisys.c3d")).unwrap(),
    )
    .unwrap();
    assert_eq!(q.analog_values_per_frame, 69 * 10);
}

#[test]
fn c3d_labels_match_the_files() {
    let opto = load("c3d/ezc3d_Optotrak.c3d");
    let qual = load("c3d/ezc3d_Qualisys.c3d");
    let vicon = load("c3d/ezc3d_Vicon.c3d");
    for take in [&opto, &qual, &vicon] {
        println!("{}: {:?}", take.source.display(), &take.labels()[..6]);
        assert!(
            take.labels()
                .iter()
                .all(|l| !l.is_empty() && l.trim() == *l)
        );
    }
    assert_eq!(opto.labels()[0], "Marker_1");
    assert_eq!(opto.labels()[53], "Marker_54");
    assert_eq!(qual.labels()[..4], ["L_IAS", "L_IPS", "R_IPS", "R_IAS"]);
    assert_eq!(qual.labels()[54], "R_SAJ");
    assert_eq!(vicon.labels()[0], "boite:gauche_ext");
    assert_eq!(vicon.labels()[8], "Daphnee:ASISr");
    assert_eq!(vicon.labels()[50], "Daphnee:LATH");
    // Subject prefixes are found by Take::track.
    assert_eq!(vicon.track("ASISr").unwrap().label, "Daphnee:ASISr");
}

#[test]
fn c3d_positions_are_finite_plausible_and_missing_where_invalid() {
    for rel in [
        "c3d/ezc3d_Optotrak.c3d",
        "c3d/ezc3d_Qualisys.c3d",
        "c3d/ezc3d_Vicon.c3d",
    ] {
        let take = load(rel);
        for t in &take.tracks {
            for p in t.positions.iter().flatten() {
                assert!(p.is_finite(), "{rel} {}", t.label);
                assert!(p.length() < 3.0, "{rel} {} at {p}", t.label);
            }
        }
    }
    // Values read with a Python struct dump of the files (mm in the file, m here).
    let qual = load("c3d/ezc3d_Qualisys.c3d");
    let ias = qual.track("L_IAS").unwrap();
    assert_near(
        ias.positions[0].unwrap(),
        DVec3::new(-0.22012, 0.30642, 0.84634),
        1e-5,
    );
    assert_eq!(qual.tracks.iter().map(seen).sum::<usize>(), 55 * 340);

    let vicon = load("c3d/ezc3d_Vicon.c3d");
    let asis = vicon.track("Daphnee:ASISr").unwrap();
    assert_near(
        asis.positions[0].unwrap(),
        DVec3::new(0.66712, 0.30580, 0.17521),
        1e-5,
    );
    // 305 samples carry residual −1 (invalid) in this file.
    let missing: usize = vicon.tracks.iter().map(|t| vicon.frames - seen(t)).sum();
    assert_eq!(missing, 305);
    let gauche = vicon.track("boite:gauche_ext").unwrap();
    assert_eq!(seen(gauche), 574);

    let opto = load("c3d/ezc3d_Optotrak.c3d");
    assert_eq!(seen(opto.track("Marker_52").unwrap()), 0);
    assert_eq!(seen(opto.track("Marker_53").unwrap()), 0);
    assert_eq!(seen(opto.track("Marker_54").unwrap()), 28);
    assert_near(
        opto.track("Marker_1").unwrap().positions[0].unwrap(),
        DVec3::new(0.32631, 0.32863, -0.36617),
        1e-5,
    );
}

#[test]
fn c3d_unit_override_rescales() {
    let path = fixture("c3d/ezc3d_Qualisys.c3d");
    let mm = import::read(&path, Some(Format::C3d)).unwrap();
    let m = import::read_with_unit(&path, None, Some("m")).unwrap();
    assert_eq!(m.file_unit, "m");
    let a = mm.tracks[0].positions[0].unwrap();
    let b = m.tracks[0].positions[0].unwrap();
    assert_near(a * 1000.0, b, 1e-9);
    let e = import::read_with_unit(&path, None, Some("furlong")).unwrap_err();
    assert!(e.to_string().contains("unit override"), "{e}");
}

// ---------------------------------------------------------------- C3D: writer

#[test]
fn c3d_writer_round_trips_a_real_capture() {
    let take = load("c3d/ezc3d_Vicon.c3d");
    let bytes = write_c3d(&take);
    assert_eq!(bytes.len() % 512, 0);
    assert_eq!(
        Format::guess(Path::new("out.bin"), &bytes),
        Some(Format::C3d)
    );
    let back = import::read_bytes(Path::new("out.c3d"), &bytes, Format::C3d).unwrap();
    assert_eq!(back.labels(), take.labels());
    assert_eq!(back.rate_hz, take.rate_hz);
    assert_eq!(back.frames, take.frames);
    assert_eq!(back.file_unit, "mm");
    for (a, b) in take.tracks.iter().zip(&back.tracks) {
        for (pa, pb) in a.positions.iter().zip(&b.positions) {
            match (pa, pb) {
                (Some(x), Some(y)) => assert_near(*x, *y, 1e-6),
                (None, None) => {}
                _ => panic!("{}: {pa:?} became {pb:?}", a.label),
            }
        }
    }
}

#[test]
fn c3d_writer_round_trips_gaps_and_drops_rotations() {
    let take = Take {
        source: "ours.c3d".into(),
        rate_hz: 250.0,
        frames: 5,
        file_unit: "m".into(),
        tracks: vec![
            Track {
                label: "StickL".into(),
                positions: vec![
                    Some(DVec3::new(0.1, 0.2, 0.3)),
                    None,
                    None,
                    Some(DVec3::ONE),
                    Some(DVec3::NEG_ONE),
                ],
                rotations: vec![Some(DQuat::IDENTITY); 5],
            },
            Track {
                label: "StickR:Tip".into(),
                positions: vec![None; 5],
                rotations: vec![],
            },
        ],
        notes: Vec::new(),
    };
    let back = import::read_bytes(Path::new("x.c3d"), &write_c3d(&take), Format::C3d).unwrap();
    assert_eq!(back.labels(), ["StickL", "StickR:Tip"]);
    assert_eq!(back.frames, 5);
    assert_eq!(back.rate_hz, 250.0);
    assert_eq!(back.tracks[0].positions[1], None);
    assert_near(back.tracks[0].positions[4].unwrap(), DVec3::NEG_ONE, 1e-6);
    assert_eq!(back.tracks[1].positions, vec![None; 5]);
    assert!(back.tracks[0].rotations.is_empty());
}

/// A one-point take whose X (metres) is its frame number / 1000, so a frame read from
/// the wrong place shows.
fn counting_take(frames: usize) -> Take {
    Take {
        source: "count.c3d".into(),
        rate_hz: 200.0,
        frames,
        file_unit: "mm".into(),
        tracks: vec![Track {
            label: "Tip".into(),
            positions: (0..frames)
                .map(|f| Some(DVec3::new(f as f64 * 1e-3, 0.1, 0.8)))
                .collect(),
            rotations: vec![],
        }],
        notes: Vec::new(),
    }
}

/// Overwrite a 16-bit header word (1-based, Intel byte order).
fn set_header_word(bytes: &mut [u8], word: usize, v: u16) {
    bytes[2 * (word - 1)..2 * word].copy_from_slice(&v.to_le_bytes());
}

/// Byte position of a parameter record (its name length, group id, then `name`).
fn param_at(bytes: &[u8], name: &str) -> usize {
    let n = name.len();
    (0..bytes.len() - n - 2)
        .find(|&i| {
            usize::from(bytes[i]) == n
                && (bytes[i + 1] as i8) > 0
                && &bytes[i + 2..i + 2 + n] == name.as_bytes()
        })
        .unwrap_or_else(|| panic!("no parameter {name}"))
}

#[test]
fn c3d_data_start_parameter_overrules_a_wrong_header_pointer() {
    let take = counting_take(200);
    let good = write_c3d(&take);
    let info = c3d::inspect(Path::new("good.c3d"), &good).unwrap();
    assert!(info.notes.is_empty(), "{:?}", info.notes);
    let block = info.data_offset / 512 + 1;
    // Before the data (on the parameters) and past their start (inside the data).
    for wrong in [2, block + 2] {
        let mut bytes = good.clone();
        set_header_word(&mut bytes, 9, wrong as u16);
        let back = import::read_bytes(Path::new("moved.c3d"), &bytes, Format::C3d).unwrap();
        assert_eq!(back.frames, 200);
        for f in [0, 1, 199] {
            assert_near(
                back.tracks[0].positions[f].unwrap(),
                take.tracks[0].positions[f].unwrap(),
                1e-6,
            );
        }
        let note = back.notes.join("\n");
        assert!(
            note.contains(&format!(
                "data block {wrong} (word 9), POINT:DATA_START block {block}"
            )),
            "{note}"
        );
    }
    // A POINT:DATA_START past the end of the file leaves the header's pointer in charge.
    let mut bytes = good.clone();
    let at = param_at(&bytes, "DATA_START") + 2 + "DATA_START".len() + 4;
    bytes[at..at + 2].copy_from_slice(&9000u16.to_le_bytes());
    let back = import::read_bytes(Path::new("far.c3d"), &bytes, Format::C3d).unwrap();
    assert_near(
        back.tracks[0].positions[199].unwrap(),
        DVec3::new(0.199, 0.1, 0.8),
        1e-6,
    );
    assert!(
        back.notes.join(" ").contains("block 9000"),
        "{:?}",
        back.notes
    );
    // The real files' two pointers agree.
    for rel in [
        "c3d/ezc3d_Optotrak.c3d",
        "c3d/ezc3d_Qualisys.c3d",
        "c3d/ezc3d_Vicon.c3d",
    ] {
        let bytes = std::fs::read(fixture(rel)).unwrap();
        let info = c3d::inspect(&fixture(rel), &bytes).unwrap();
        assert!(
            info.notes.iter().all(|n| !n.contains("DATA_START")),
            "{rel}: {:?}",
            info.notes
        );
    }
}

#[test]
fn c3d_over_65535_frames_without_a_long_count_is_read_whole() {
    let take = counting_take(70_000);
    let mut bytes = write_c3d(&take);
    // Hide the writer's long counts (same-length names, so the records stay in place).
    for (name, hidden) in [
        ("LONG_FRAMES", "XONG_FRAMES"),
        ("ACTUAL_END_FIELD", "XCTUAL_END_FIELD"),
    ] {
        let at = param_at(&bytes, name) + 2;
        bytes[at..at + name.len()].copy_from_slice(hidden.as_bytes());
    }
    let frames_at = param_at(&bytes, "FRAMES") + 2 + "FRAMES".len() + 4;
    // Clamped: last frame 65535 (as written); wrapped: 70000 mod 65536; wrapped with a
    // trailing partial frame of junk after the data.
    let clamped = bytes.clone();
    let mut wrapped = bytes.clone();
    set_header_word(&mut wrapped, 5, 4464);
    wrapped[frames_at..frames_at + 2].copy_from_slice(&4464u16.to_le_bytes());
    let data_end = c3d::inspect(Path::new("w.c3d"), &wrapped)
        .unwrap()
        .data_offset
        + 70_000 * 16;
    let mut junk = wrapped.clone();
    junk.truncate(data_end);
    junk.extend_from_slice(&[0x11; 9]);
    for (case, bytes, why) in [
        ("clamped", clamped, "its last frame 65535"),
        ("wrapped", wrapped, "wraps past 65535"),
        ("junk", junk, "wraps past 65535"),
    ] {
        let back = import::read_bytes(Path::new("long.c3d"), &bytes, Format::C3d).unwrap();
        assert_eq!(back.frames, 70_000, "{case}");
        assert_eq!(back.tracks[0].positions.len(), 70_000, "{case}");
        assert_near(
            back.tracks[0].positions[69_999].unwrap(),
            DVec3::new(69.999, 0.1, 0.8),
            1e-4,
        );
        let note = back.notes.join(" ");
        assert!(
            note.contains(why) && note.contains("holds 70000 whole frames"),
            "{case}: {note}"
        );
    }
    // A short take's padding is no extra frame.
    let short = write_c3d(&counting_take(65_535));
    let back = import::read_bytes(Path::new("s.c3d"), &short, Format::C3d).unwrap();
    assert_eq!(back.frames, 65_535);
    assert!(back.notes.is_empty(), "{:?}", back.notes);
}

// ---------------------------------------------------------------- C3D: NaN and infinity

/// Overwrite point `point` of frame `frame` (0-based) of an Intel float C3D: its X, Y, Z
/// and, when given, its residual.
fn set_c3d_point(
    bytes: &mut [u8],
    frame: usize,
    point: usize,
    xyz: [f32; 3],
    residual: Option<f32>,
) {
    let info = c3d::inspect(Path::new("x.c3d"), bytes).unwrap();
    assert!(info.float_data && info.analog_values_per_frame == 0);
    let at = info.data_offset + (frame * info.points + point) * 16;
    for (i, v) in xyz.into_iter().chain(residual).enumerate() {
        bytes[at + 4 * i..at + 4 * i + 4].copy_from_slice(&v.to_le_bytes());
    }
}

/// A C3D point whose coordinates are NaN or ±infinity while its residual says it was
/// seen (as some exporters mark an unseen marker instead of a negative residual) is a
/// gap, counted in the gap note with the samples at exactly (0, 0, 0); a point the
/// residual already marks invalid is not counted, whatever its coordinates.
#[test]
fn c3d_nan_and_infinite_coordinates_are_counted_gaps() {
    let mut take = counting_take(40);
    take.tracks.push(Track {
        label: "Wrist".into(),
        ..take.tracks[0].clone()
    });
    take.tracks[0].positions[9] = Some(DVec3::ZERO);
    let mut bytes = write_c3d(&take);
    let (nan, inf) = (f32::NAN, f32::INFINITY);
    let negative_nan = f32::from_bits(0xffc0_0000);
    let marked = [
        (2, 0, [nan, nan, nan]),
        (3, 0, [12.0, negative_nan, 800.0]),
        (4, 1, [inf, inf, inf]),
        (5, 1, [12.0, 100.0, -inf]),
        (6, 1, [nan, inf, 0.0]),
    ];
    for (frame, point, xyz) in marked {
        set_c3d_point(&mut bytes, frame, point, xyz, None);
    }
    // Invalid by its residual, NaN as well: an ordinary gap.
    set_c3d_point(&mut bytes, 7, 0, [nan; 3], Some(-1.0));
    let note = "1 sample at exactly (0, 0, 0), 3 written as NaN and 2 written as ±infinity \
                read as gaps (the way Vicon, Cortex and many C3D writers mark an unseen marker)";
    for unit in [None, Some(import::LengthUnit::Metre)] {
        let back =
            import::read_bytes_with_unit(Path::new("nan.c3d"), &bytes, Format::C3d, unit).unwrap();
        assert_eq!(back.frames, 40);
        assert_eq!(back.notes, [note], "{unit:?}");
        let gaps: Vec<(usize, usize)> = (0..40)
            .flat_map(|f| (0..2).map(move |p| (f, p)))
            .filter(|&(f, p)| back.tracks[p].positions[f].is_none())
            .collect();
        assert_eq!(
            gaps,
            [(2, 0), (3, 0), (4, 1), (5, 1), (6, 1), (7, 0), (9, 0)]
        );
        let scale = if unit.is_some() { 1000.0 } else { 1.0 };
        assert_near(
            back.tracks[1].positions[3].unwrap(),
            DVec3::new(0.003, 0.1, 0.8) * scale,
            1e-6 * scale,
        );
    }
    // Without them, only the zero is noted, as before.
    let plain = write_c3d(&take);
    let back = import::read_bytes(Path::new("zero.c3d"), &plain, Format::C3d).unwrap();
    assert_eq!(
        back.notes,
        [
            "1 sample at exactly (0, 0, 0) read as gaps (the way Vicon, Cortex and many C3D \
          writers mark an unseen marker)"
        ]
    );
}

// ---------------------------------------------------------------- Motive

#[test]
fn motive_export_with_rigid_bodies_markers_and_gaps() {
    let take = load("motive/timpani_roll_250hz.csv");
    assert_eq!(take.rate_hz, 250.0);
    assert_eq!(take.frames, 48);
    assert_eq!(take.file_unit, "m");
    println!("{:?}", take.labels());
    assert_eq!(take.tracks.len(), 2 + 6 + 6 + 1);
    assert_eq!(take.labels()[..2], ["StickL", "StickL:Marker1 (solved)"]);
    assert!(take.labels().contains(&"StickR:Marker3"));
    assert!(take.labels().contains(&"Unlabeled 1000"));

    let left = take.track("StickL").unwrap();
    let right = take.track("StickR").unwrap();
    assert_eq!(left.rotations.len(), 48);
    assert_eq!(seen(left), 48);
    // StickR was lost for frames 10–14 (rigid body, its solved and measured markers).
    for f in 0..48 {
        let lost = (10..=14).contains(&f);
        assert_eq!(right.positions[f].is_none(), lost, "frame {f}");
        assert_eq!(right.rotations[f].is_none(), lost, "frame {f}");
        let m = take.track("StickR:Marker2").unwrap();
        assert_eq!(m.positions[f].is_none(), lost);
    }
    // A measured marker's own gap, and a marker that appears late.
    let m2 = take.track("StickL:Marker2").unwrap();
    assert_eq!(m2.positions[20..23], [None, None, None]);
    assert_eq!(seen(m2), 45);
    assert_eq!(seen(take.track("Unlabeled 1000").unwrap()), 18);

    // The quaternion is read as X, Y, Z, W: the solved tip marker is the body's position
    // plus its rotation applied to the marker's offset (0.02, 0, 0.30) in the body frame.
    let tip = take.track("StickL:Marker3 (solved)").unwrap();
    for f in 0..48 {
        let (p, q) = (left.positions[f].unwrap(), left.rotations[f].unwrap());
        assert!(q.is_normalized());
        assert_near(
            p + q * DVec3::new(0.02, 0.0, 0.30),
            tip.positions[f].unwrap(),
            5e-6,
        );
    }
    assert!(left.rotations[5].unwrap().angle_between(DQuat::IDENTITY) > 0.1);
}

#[test]
fn motive_units_and_truncation() {
    let path = fixture("motive/timpani_roll_250hz.csv");
    let text = std::fs::read_to_string(&path).unwrap();
    let mm = text.replacen("Length Units,Meters", "Length Units,Millimeters", 1);
    let take = import::read_bytes(&path, mm.as_bytes(), Format::Motive).unwrap();
    let metres = load("motive/timpani_roll_250hz.csv");
    assert_eq!(take.file_unit, "mm");
    assert_near(
        take.tracks[0].positions[0].unwrap() * 1000.0,
        metres.tracks[0].positions[0].unwrap(),
        1e-12,
    );
    // Rotations do not scale.
    assert_eq!(take.tracks[0].rotations, metres.tracks[0].rotations);
    // A cut export is caught by the frame count in line 1.
    let cut: String = text.lines().take(40).map(|l| format!("{l}\n")).collect();
    let e = import::read_bytes(&path, cut.as_bytes(), Format::Motive).unwrap_err();
    assert!(e.to_string().contains("Total Exported Frames"), "{e}");
}

// ---------------------------------------------------------------- Vicon

#[test]
fn vicon_export_skips_devices_and_stops_at_model_outputs() {
    let take = load("vicon/timpani_strokes_100hz.csv");
    assert_eq!(take.rate_hz, 100.0);
    assert_eq!(take.frames, 30);
    assert_eq!(take.file_unit, "mm");
    assert_eq!(take.tracks.len(), 8);
    assert_eq!(take.labels()[0], "Timpanist:RSHO");
    assert!(take.track("RElbowAngles").is_none());
    let tip = take.track("STICKR_TIP").unwrap();
    assert_eq!(tip.label, "Timpanist:STICKR_TIP");
    assert_near(
        tip.positions[0].unwrap(),
        DVec3::new(0.25, 0.982, 0.83),
        1e-9,
    );
    // Gaps: frames 12–15 (rows 11..15) of the right stick tip, the left finger from 28.
    assert_eq!(tip.positions[11..15], [None, None, None, None]);
    assert_eq!(seen(tip), 26);
    assert_eq!(seen(take.track("LFIN").unwrap()), 27);
    assert!(
        take.tracks
            .iter()
            .flat_map(|t| t.rotations.iter())
            .next()
            .is_none()
    );
}

// ---------------------------------------------------------------- plain CSV

#[test]
fn plain_csv_fixture_and_round_trip() {
    let take = load("csv/two_sticks_250hz.csv");
    assert!((take.rate_hz - 250.0).abs() < 1e-6);
    assert_eq!(take.frames, 20);
    assert_eq!(take.labels(), ["StickL:Tip", "StickL", "StickR:Tip"]);
    let body = take.track("StickL").unwrap();
    assert_eq!(body.rotations.len(), 20);
    assert!(take.track("StickL:Tip").unwrap().rotations.is_empty());
    assert_eq!(
        take.track("StickL:Tip").unwrap().positions[6..9],
        [None, None, None]
    );

    // Our exports: any take written as plain CSV reads back the same.
    let motive = load("motive/timpani_roll_250hz.csv");
    let text = plain_csv::write(&motive);
    let back = import::read_bytes(Path::new("x.csv"), text.as_bytes(), Format::Csv).unwrap();
    assert_eq!(back.labels(), motive.labels());
    assert_eq!(back.frames, motive.frames);
    assert!((back.rate_hz - motive.rate_hz).abs() < 1e-9);
    for (a, b) in motive.tracks.iter().zip(&back.tracks) {
        assert_eq!(a.positions, b.positions, "{}", a.label);
        assert_eq!(a.rotations.len(), b.rotations.len());
        for (qa, qb) in a.rotations.iter().zip(&b.rotations) {
            assert_eq!(qa.is_some(), qb.is_some());
            if let (Some(x), Some(y)) = (qa, qb) {
                assert!(x.abs_diff_eq(*y, 1e-12));
            }
        }
    }
}

// ---------------------------------------------------------------- guessing

#[test]
fn formats_are_guessed_from_content() {
    let cases = [
        ("c3d/ezc3d_Vicon.c3d", Format::C3d),
        ("motive/timpani_roll_250hz.csv", Format::Motive),
        ("vicon/timpani_strokes_100hz.csv", Format::Vicon),
        ("csv/two_sticks_250hz.csv", Format::Csv),
    ];
    for (rel, format) in cases {
        let bytes = std::fs::read(fixture(rel)).unwrap();
        assert_eq!(Format::guess(&fixture(rel), &bytes), Some(format), "{rel}");
    }
    let e = import::read_bytes(Path::new("x.csv"), b"hello", Format::Vicon).unwrap_err();
    assert!(e.to_string().contains("Trajectories"), "{e}");
    let missing = import::read(&fixture("nope.c3d"), None).unwrap_err();
    assert!(matches!(missing, ImportError::Io { .. }));
}

// ---------------------------------------------------------------- robustness

/// A small deterministic pseudo-random sequence (xorshift), for offsets.
struct Rng(u64);

impl Rng {
    fn below(&mut self, n: usize) -> usize {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 % n.max(1) as u64) as usize
    }
}

/// Read `bytes` as its own format and (a prefix of it) as every other; a panic fails
/// with the case named. Returns whether its own format gave an error; an error must name
/// a place.
fn read_all_formats(bytes: &[u8], own: Format, case: &str) -> bool {
    let mut own_failed = false;
    for format in [Format::C3d, Format::Motive, Format::Vicon, Format::Csv] {
        let input = if format == own {
            bytes
        } else {
            &bytes[..bytes.len().min(16 * 1024)]
        };
        let r = catch_unwind(AssertUnwindSafe(|| {
            import::read_bytes(Path::new("fuzz"), input, format)
        }));
        match r {
            Err(_) => panic!("{case}: reading as {format:?} panicked"),
            Ok(Err(ImportError::Format { place, message, .. })) => {
                assert!(!place.is_empty() && !message.is_empty(), "{case}");
                own_failed |= format == own;
            }
            Ok(Err(e)) => panic!("{case}: unexpected error {e}"),
            Ok(Ok(take)) => {
                for t in &take.tracks {
                    assert_eq!(t.positions.len(), take.frames, "{case}");
                    assert!(t.rotations.is_empty() || t.rotations.len() == take.frames);
                }
            }
        }
    }
    own_failed
}

#[test]
fn corrupt_and_truncated_files_never_panic() {
    let files = [
        ("c3d/ezc3d_Optotrak.c3d", Format::C3d),
        ("c3d/ezc3d_Qualisys.c3d", Format::C3d),
        ("c3d/ezc3d_Vicon.c3d", Format::C3d),
        ("motive/timpani_roll_250hz.csv", Format::Motive),
        ("vicon/timpani_strokes_100hz.csv", Format::Vicon),
        ("csv/two_sticks_250hz.csv", Format::Csv),
    ];
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    for (rel, format) in files {
        let original = std::fs::read(fixture(rel)).unwrap();
        let len = original.len();
        // Where the structure is: the header and parameters for C3D, else the whole file.
        // A C3D file cut after its first whole frames is still valid (it reads those
        // frames), so the many single-byte corruptions work on such a short copy.
        let (head, values): (usize, &[u8]) = match format {
            Format::C3d => (
                c3d::inspect(Path::new(rel), &original).unwrap().data_offset,
                &[0x00, 0xff, 0x80, 0x7f],
            ),
            _ => (len, &[0x00, 0xff, b',', b'\n']),
        };
        let short = &original[..len.min(head + 8192)];

        // Truncations: every byte of the first 600, then spread over the header part and
        // the data.
        let mut cuts: Vec<usize> = (0..600.min(len)).collect();
        cuts.extend((0..150).map(|_| rng.below(head)));
        for cut in cuts {
            let failed = read_all_formats(&original[..cut], format, &format!("{rel} cut at {cut}"));
            if format == Format::C3d {
                assert!(
                    failed,
                    "{rel} cut at {cut} (inside header/parameters) was accepted"
                );
            }
        }
        for _ in 0..20 {
            let cut = head + rng.below(len - head);
            read_all_formats(&original[..cut], format, &format!("{rel} cut at {cut}"));
        }

        // Corruptions: single bytes set to telling values, over the first 600 bytes and
        // spread over the rest.
        let mut bytes = short.to_vec();
        let mut spots: Vec<usize> = (0..600.min(bytes.len())).step_by(3).collect();
        spots.extend((0..250).map(|_| rng.below(bytes.len())));
        for at in spots {
            for &value in values {
                bytes[at] = value;
                read_all_formats(&bytes, format, &format!("{rel} byte {at} = {value:#x}"));
            }
            bytes[at] = short[at];
        }
        // Runs of garbage, including in the full file's data.
        let mut full = original.clone();
        for i in 0..40 {
            let (buf, orig) = if i % 4 == 0 {
                (&mut full, &original[..])
            } else {
                (&mut bytes, short)
            };
            let at = rng.below(buf.len());
            let end = (at + 1 + rng.below(64)).min(buf.len());
            for b in &mut buf[at..end] {
                *b = rng.below(256) as u8;
            }
            read_all_formats(buf, format, &format!("{rel} garbage at {at}..{end}"));
            buf[at..end].copy_from_slice(&orig[at..end]);
        }
    }
}

/// A sample written as exactly (0, 0, 0) — how Vicon, Cortex and many C3D writers mark
/// an unseen marker — is read as a gap, in C3D and in text, and the note counts them.
#[test]
fn zeros_are_read_as_gaps() {
    let frames = 50;
    let positions: Vec<Option<DVec3>> = (0..frames)
        .map(|f| Some(DVec3::new(0.1 * f as f64, 0.2, 0.8)))
        .collect();
    let mut zeroed = positions.clone();
    for f in [3, 4, 5, 30] {
        zeroed[f] = Some(DVec3::ZERO);
    }
    let take = Take {
        source: "zeros.c3d".into(),
        rate_hz: 100.0,
        frames,
        file_unit: "mm".into(),
        tracks: vec![Track {
            label: "TipR".into(),
            positions: zeroed,
            rotations: Vec::new(),
        }],
        notes: Vec::new(),
    };
    let read = import::read_bytes(Path::new("zeros.c3d"), &write_c3d(&take), Format::C3d).unwrap();
    assert_eq!(seen(&read.tracks[0]), frames - 4);
    assert!(read.tracks[0].positions[4].is_none());
    assert!(
        read.notes
            .iter()
            .any(|n| n.starts_with("4 samples at exactly (0, 0, 0)")),
        "{:?}",
        read.notes
    );
    let csv = "time_s,TipR_x,TipR_y,TipR_z\n0.00,0.1,0.2,0.8\n0.01,0,0,0\n0.02,0.1,0.0,0.8\n0.03,0.1,0.2,0.8\n";
    let read = import::read_bytes(Path::new("zeros.csv"), csv.as_bytes(), Format::Csv).unwrap();
    assert_eq!(seen(&read.tracks[0]), 3);
    assert!(read.tracks[0].positions[1].is_none());
    assert!(read.notes[0].starts_with("1 sample at"), "{:?}", read.notes);
}

// ---------------------------------------------------------------- sweep: Vicon blank lines

/// A Vicon Nexus CSV export at 100 Hz: a Devices block, then the Trajectories of a stick
/// tip and a wrist (mm) for `frames` frames, `inserts` put before the rows of the frames
/// they name (1-based), then `tail` (the next section, or nothing).
fn vicon_export(frames: usize, inserts: &[(usize, &str)], tail: &str) -> String {
    let mut out = String::from(
        "Devices\n1000\n,,Force Plate #1 - Force,,\nFrame,Sub Frame,Fx,Fy,Fz\n,,N,N,N\n\
         1,0,0.0,-0.2,701.5\n\nTrajectories\n100\n,,Player:StickR_Tip,,,Player:RWRA,,\n\
         Frame,Sub Frame,X,Y,Z,X,Y,Z\n,,mm,mm,mm,mm,mm,mm\n",
    );
    for f in 1..=frames {
        for (at, text) in inserts {
            if *at == f {
                out.push_str(text);
            }
        }
        let z = 800.0 + 120.0 * (f as f64 * 0.05).sin();
        out.push_str(&format!(
            "{f},0,250.000,950.000,{z:.3},310.000,700.000,1050.000\n"
        ));
    }
    out + tail
}

/// The 1-based line of the first line of `text` that starts with `prefix`.
fn line_of(text: &str, prefix: &str) -> usize {
    text.lines().position(|l| l.starts_with(prefix)).unwrap() + 1
}

/// A blank line inside the Trajectories data is skipped (with a note naming it) when the
/// frame numbers run on after it; a blank line before the next section ends the data
/// without a note; anything else after a blank line is noted or refused naming its line.
#[test]
fn vicon_blank_lines_inside_the_trajectories_are_skipped_with_a_note() {
    let path = Path::new("sweep.csv");
    let read = |text: &str| import::read_bytes(path, text.as_bytes(), Format::Vicon);
    // The sweep's file: a blank line after frame 895 of 3982, then a Model Outputs block.
    let tail = "\nModel Outputs\n100\n,,Player:RElbowAngles,,\nFrame,Sub Frame,X,Y,Z\n1,0,1,2,3\n";
    let text = vicon_export(3982, &[(896, "\n")], tail);
    let take = read(&text).unwrap();
    assert_eq!(take.frames, 3982);
    let tip = take.track("StickR_Tip").unwrap();
    assert_eq!(seen(tip), 3982);
    let blank = line_of(&text, "896,0,") - 1;
    let note = format!("1 blank line inside the Trajectories data was skipped (line {blank})");
    assert!(
        take.notes.iter().any(|n| n.starts_with(&note)),
        "{:?}",
        take.notes
    );
    // Read through the shipped `vicon` capture profile too.
    let vicon = import::CaptureProfile::shipped("vicon").unwrap();
    let take = import::table::read(path, text.as_bytes(), &vicon, None).unwrap();
    assert_eq!(take.frames, 3982);
    let note = format!("1 blank line inside the data was skipped (line {blank})");
    assert!(
        take.notes.iter().any(|n| n.starts_with(&note)),
        "{:?}",
        take.notes
    );
    // Two runs of blank lines, CRLF endings, a line of commas.
    let text = vicon_export(500, &[(100, "\n\n"), (300, ",,,,,,,\n")], tail).replace('\n', "\r\n");
    let take = read(&text).unwrap();
    assert_eq!(take.frames, 500);
    assert!(
        take.notes
            .iter()
            .any(|n| n.starts_with("3 blank lines inside the Trajectories data were skipped")),
        "{:?}",
        take.notes
    );
    // The blank line before the next section (or at the end) is the end: nothing noted.
    for tail in [
        tail,
        "",
        "\n\n",
        "\nEvents\nSubject,Context,Name,Time (s)\n",
    ] {
        let take = read(&vicon_export(50, &[], tail)).unwrap();
        assert_eq!(take.frames, 50, "{tail:?}");
        assert!(take.notes.is_empty(), "{tail:?}: {:?}", take.notes);
    }
    // A blank line before a block that is not a section Nexus writes: the data end there,
    // and the note names the line where the rest was left unread.
    let text = vicon_export(50, &[], "\nAnalog Gains\n1,2,3\n");
    let take = read(&text).unwrap();
    assert_eq!(take.frames, 50);
    let at = line_of(&text, "Analog Gains");
    assert!(
        take.notes.iter().any(|n| n.contains(&format!("line {at}"))
            && n.contains("Analog Gains")
            && n.contains("not read")),
        "{:?}",
        take.notes
    );
    // Frame numbers that do not run on after a blank line (a second block pasted on) and
    // a row cut short after one are refused naming the line.
    let text = vicon_export(50, &[], "\n1,0,1,2,3,4,5,6\n2,0,1,2,3,4,5,6\n");
    let e = read(&text).unwrap_err().to_string();
    let at = line_of(&text, "1,0,1,2");
    assert!(
        e.contains(&format!(
            "sweep.csv: line {at}, column 1: expected frame 51 after frame 50"
        )),
        "{e}"
    );
    let text = vicon_export(50, &[(40, "\n")], "").replace("45,0,250.000,950.000", "45,0,250.0");
    let e = read(&text).unwrap_err().to_string();
    assert!(
        e.contains(&format!(
            "sweep.csv: line {}: expected 8 cells",
            line_of(&text, "45,0,")
        )),
        "{e}"
    );
}

// ---------------------------------------------------------- sweep: blank lines, Motive, CSV

/// `text` with `inserts` put before the lines they name (1-based, in the original).
fn insert_lines(text: &str, inserts: &[(usize, &str)]) -> String {
    let mut out = String::new();
    for (i, line) in text.lines().enumerate() {
        for (at, insert) in inserts {
            if *at == i + 1 {
                out.push_str(insert);
            }
        }
        out.push_str(line);
        out.push('\n');
    }
    out
}

/// Whether `a` and `b` hold the same samples (rotations to 1e-12).
fn same_samples(a: &Take, b: &Take) -> bool {
    a.labels() == b.labels()
        && a.frames == b.frames
        && a.tracks.iter().zip(&b.tracks).all(|(ta, tb)| {
            ta.positions == tb.positions
                && ta.rotations.len() == tb.rotations.len()
                && ta
                    .rotations
                    .iter()
                    .zip(&tb.rotations)
                    .all(|(x, y)| match (x, y) {
                        (Some(x), Some(y)) => x.abs_diff_eq(*y, 1e-12),
                        _ => x == y,
                    })
        })
}

/// The take's note on blank lines inside the data, if any.
fn blank_note(take: &Take) -> Option<&str> {
    take.notes
        .iter()
        .map(String::as_str)
        .find(|n| n.contains("blank line"))
}

/// Check that `text` (LF line endings, blank lines inside its data) reads, with LF or
/// CRLF endings and with more blank lines at the end, as `want` with the blank-line
/// `note`.
fn reads_as_without_blank_lines(
    read: &dyn Fn(&str) -> Result<Take, ImportError>,
    text: &str,
    want: &Take,
    note: &str,
) {
    for (case, text) in [
        ("LF", text.to_string()),
        ("CRLF", text.replace('\n', "\r\n")),
        ("and at the end", format!("{text}\n,,,\r\n \n")),
    ] {
        let take = read(&text).unwrap_or_else(|e| panic!("{case}: {e}"));
        assert!(same_samples(&take, want), "{case}");
        assert_eq!(blank_note(&take), Some(note), "{case}");
    }
}

/// A blank line inside the data of a Motive or plain CSV export (hand-edited, or two
/// exports pasted together) is skipped with a note naming it, as in Vicon: the take is
/// the one without it. Lines of commas or spaces count as blank; CRLF endings and other
/// units read alike; blank lines at the end say nothing; rows after a blank line that do
/// not run on in time are refused naming the line and the blank line.
#[test]
fn blank_lines_inside_motive_and_plain_csv_data_are_skipped_with_a_note() {
    let path = fixture("motive/timpani_roll_250hz.csv");
    let motive = std::fs::read_to_string(&path).unwrap();
    let read_motive =
        |text: &str| import::read_bytes(Path::new("roll.csv"), text.as_bytes(), Format::Motive);
    let original = read_motive(&motive).unwrap();
    assert_eq!(blank_note(&original), None);
    // The first data row (frame 0) and the rows of frames 20 and 35.
    let row = |f: usize| line_of(&motive, &format!("{f},0."));
    let commas = ",".repeat(40) + "\n";
    let inserts = [
        (row(20), "\n"),
        (row(35), commas.as_str()),
        (row(35), " \t \n"),
    ];
    let blank = insert_lines(&motive, &inserts);
    let (b20, b35) = (row(20), row(35) + 1);
    let note = format!(
        "3 blank lines inside the data were skipped (lines {b20}, {b35}, {}): the rows after \
         them continue the frames above",
        b35 + 1
    );
    reads_as_without_blank_lines(&read_motive, &blank, &original, &note);
    // In millimetres.
    let mm = |t: &str| t.replacen("Length Units,Meters", "Length Units,Millimeters", 1);
    let take = read_motive(&mm(&blank)).unwrap();
    assert_eq!(take.file_unit, "mm");
    assert!(same_samples(&take, &read_motive(&mm(&motive)).unwrap()));
    assert_eq!(blank_note(&take), Some(note.as_str()));
    // A blank line at the end only, or between the header and the data, says nothing.
    for text in [
        motive.clone() + "\n\n",
        insert_lines(&motive, &[(row(0), "\n")]),
    ] {
        let take = read_motive(&text).unwrap();
        assert!(same_samples(&take, &original));
        assert_eq!(blank_note(&take), None);
    }
    // A second export pasted after a blank line: its times start again.
    let frames: Vec<&str> = motive.lines().skip(row(0) - 1).collect();
    let pasted = format!("{motive}\n{}\n", frames[..10].join("\n"));
    let e = read_motive(&pasted).unwrap_err().to_string();
    let at = motive.lines().count() + 2;
    assert!(
        e.contains(&format!(
            "roll.csv: line {at}, column 2: expected a time step of 0.004000 s"
        )) && e.contains(&format!(
            "(the rows after the blank line {} do not run on from those above it)",
            at - 1
        )),
        "{e}"
    );

    // Plain CSV: our own export of the same take, blank lines put in by hand.
    let csv = plain_csv::write(&original);
    let read_csv =
        |text: &str| import::read_bytes(Path::new("roll.csv"), text.as_bytes(), Format::Csv);
    let written = read_csv(&csv).unwrap();
    let blank = insert_lines(&csv, &[(12, "\n\n"), (40, ",,,,\n")]);
    reads_as_without_blank_lines(
        &read_csv,
        &blank,
        &written,
        "3 blank lines inside the data were skipped (lines 12, 13, 42): the rows after them \
         continue the frames above",
    );
    // Centimetres, and a take split in two files pasted together with a blank line
    // between (its times running on).
    let cm = "time_s,StickR:Tip_x,StickR:Tip_y,StickR:Tip_z\n\
              0.000,31.2,-4.0,88.4\n0.005,31.3,-4.1,87.9\n0.010,31.3,-4.1,87.1\n\
              \n0.015,31.4,-4.2,86.0\n0.020,31.4,-4.2,84.6\n";
    let cm_unit = Some(import::LengthUnit::Centimetre);
    let take =
        import::read_bytes_with_unit(Path::new("cm.csv"), cm.as_bytes(), Format::Csv, cm_unit)
            .unwrap();
    assert_eq!(take.frames, 5);
    assert!((take.rate_hz - 200.0).abs() < 1e-9);
    assert_near(
        take.tracks[0].positions[3].unwrap(),
        DVec3::new(0.314, -0.042, 0.86),
        1e-12,
    );
    assert!(
        blank_note(&take)
            .is_some_and(|n| n.starts_with("1 blank line inside the data was skipped (line 5)")),
        "{:?}",
        take.notes
    );
    // The second file's times start again, or frames are missing across the blank line.
    for (tail, want) in [
        (
            "\n0.000,31.2,-4.0,88.4\n0.005,31.3,-4.1,87.9\n",
            "line 6, column 1: expected a time after the previous row's 0.01 s, found 0 s",
        ),
        (
            "\n0.100,31.2,-4.0,88.4\n0.105,31.3,-4.1,87.9\n",
            "line 6, column 1: expected a uniform time step of 0.005",
        ),
    ] {
        let text = format!(
            "time_s,StickR:Tip_x,StickR:Tip_y,StickR:Tip_z\n\
             0.000,31.2,-4.0,88.4\n0.005,31.3,-4.1,87.9\n0.010,31.3,-4.1,87.1\n{tail}"
        );
        let e = read_csv(&text).unwrap_err().to_string();
        assert!(
            e.contains(want)
                && e.ends_with(
                    "(the rows after the blank line 5 do not run on from those above it)"
                ),
            "{e}"
        );
    }
}

// ---------------------------------------------------------------- sweep: Qualisys truncated

/// A QTM 3D TSV export at 200 Hz whose header says `stated` frames, holding `rows` rows of
/// one stick tip (mm); `cell` writes the tip of frame `f` (1-based).
fn qualisys_tsv(stated: usize, rows: usize, cell: &dyn Fn(usize) -> String) -> String {
    let mut out = format!(
        "NO_OF_FRAMES\t{stated}\nNO_OF_CAMERAS\t8\nNO_OF_MARKERS\t1\nFREQUENCY\t200\n\
         NO_OF_ANALOG\t0\nANALOG_FREQUENCY\t0\nDESCRIPTION\t--\n\
         TIME_STAMP\t2024-05-14, 15:12:45.120\t81234.56789012\nDATA_INCLUDED\t3D\n\
         MARKER_NAMES\tStick R tip\nTRAJECTORY_TYPES\tMeasured\n\
         Frame\tTime\tStick R tip X\tStick R tip Y\tStick R tip Z\t\n"
    );
    for f in 1..=rows {
        out.push_str(&format!(
            "{f}\t{:.5}\t{}\n",
            (f - 1) as f64 / 200.0,
            cell(f)
        ));
    }
    out
}

fn tip_cells(f: usize) -> String {
    format!(
        "250.000\t950.000\t{:.3}",
        800.0 + 100.0 * (f as f64 * 0.05).sin()
    )
}

/// A QTM export cut short (fewer rows than NO_OF_FRAMES) is read with a note giving the
/// header's count and the rows found; a complete one has no such note.
#[test]
fn qualisys_tsv_shorter_than_no_of_frames_is_noted() {
    let profile = import::CaptureProfile::shipped("qualisys-3d").unwrap();
    let path = Path::new("cut.tsv");
    let read = |text: &str| import::table::read(path, text.as_bytes(), &profile, None).unwrap();
    let noted = |take: &Take, want: &str| {
        assert!(
            take.notes.iter().any(|n| n == want),
            "{want:?} in {:?}",
            take.notes
        );
    };
    // Eleven metadata lines and the column row: frame f is on line 12 + f.
    let take = read(&qualisys_tsv(3982, 895, &tip_cells));
    assert_eq!(take.frames, 895);
    assert_eq!(seen(&take.tracks[0]), 895);
    noted(
        &take,
        "NO_OF_FRAMES (line 1) says 3982 frames, the file has 895 rows, the last on line 907: \
         it is truncated (the rows present are read)",
    );
    let take = read(&qualisys_tsv(895, 895, &tip_cells));
    assert!(
        take.notes.iter().all(|n| !n.contains("NO_OF_FRAMES")),
        "{:?}",
        take.notes
    );
    // A row dropped inside (the grid fills it) and a header that says too few.
    let dropped = qualisys_tsv(895, 895, &tip_cells).replace("\n400\t", "\nX");
    let dropped: String = dropped
        .lines()
        .filter(|l| !l.starts_with('X'))
        .map(|l| format!("{l}\n"))
        .collect();
    let take = read(&dropped);
    assert_eq!(take.frames, 895);
    noted(
        &take,
        "NO_OF_FRAMES (line 1) says 895 frames, the file has 894 rows: the missing rows are \
         frames dropped inside it",
    );
    let take = read(&qualisys_tsv(800, 895, &tip_cells));
    noted(
        &take,
        "NO_OF_FRAMES (line 1) says 800 frames, the file has 895 rows: the header is out of date",
    );
    let odd =
        qualisys_tsv(895, 895, &tip_cells).replacen("NO_OF_FRAMES\t895", "NO_OF_FRAMES\tmany", 1);
    let e = import::table::read(path, odd.as_bytes(), &profile, None)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("cut.tsv: line 1, \"NO_OF_FRAMES\": expected a whole number"),
        "{e}"
    );
    // The 6DOF export too.
    let six_d = import::CaptureProfile::shipped("qualisys-6d").unwrap();
    let text = std::fs::read_to_string(fixture("capture/qualisys_6d_100hz.tsv")).unwrap();
    let cut = text.replacen("NO_OF_FRAMES\t7", "NO_OF_FRAMES\t700", 1);
    assert_ne!(cut, text);
    let take = import::table::read(path, cut.as_bytes(), &six_d, None).unwrap();
    assert!(
        take.notes
            .iter()
            .any(|n| n.contains("NO_OF_FRAMES") && n.contains("700") && n.contains("7 rows")),
        "{:?}",
        take.notes
    );
}

// ---------------------------------------------------------------- sweep: NaN

/// A coordinate written as NaN (any case) is a gap in every text format, as an empty
/// cell is, and the gap note counts them.
#[test]
fn nan_is_a_gap_in_every_text_format() {
    let nan_note = |take: &Take, n: usize| {
        let want = format!(
            "{n} sample{} written as NaN read as gaps",
            if n == 1 { "" } else { "s" }
        );
        assert!(
            take.notes.iter().any(|note| note.contains(&want)),
            "{:?}",
            take.notes
        );
    };
    // Vicon: NaN, nan, a single NaN coordinate, and empty cells (not counted as NaN).
    let mut text = String::from(
        "Trajectories\n100\n,,Player:StickR_Tip,,,Player:RWRA,,\n\
         Frame,Sub Frame,X,Y,Z,X,Y,Z\n,,mm,mm,mm,mm,mm,mm\n",
    );
    for f in 1..=60 {
        let tip = match f {
            10 => "NaN,NaN,NaN".to_string(),
            11 => "nan,nan,nan".to_string(),
            12 => "250.0,NaN,812.0".to_string(),
            13 => ",,".to_string(),
            _ => format!("250.0,950.0,{:.3}", 800.0 + f as f64),
        };
        text.push_str(&format!("{f},0,{tip},310.0,700.0,1050.0\n"));
    }
    let take = import::read_bytes(Path::new("nan.csv"), text.as_bytes(), Format::Vicon).unwrap();
    let tip = take.track("StickR_Tip").unwrap();
    assert_eq!(tip.positions[9..13], [None, None, None, None]);
    assert_eq!(seen(tip), 56);
    nan_note(&take, 3);
    // Plain CSV: a NaN position and a NaN rigid body (position and quaternion).
    let csv = "time_s,TipR_x,TipR_y,TipR_z,B_x,B_y,B_z,B_qx,B_qy,B_qz,B_qw\n\
               0.00,0.1,0.2,0.8,0.1,0.2,0.8,0,0,0,1\n\
               0.01,NaN,NaN,NaN,nan,nan,nan,nan,nan,nan,nan\n\
               0.02,0.1,0.2,0.8,0.1,0.2,0.8,0,0,0,1\n\
               0.03,,,,0.1,0.2,0.8,NaN,NaN,NaN,NaN\n";
    let take = import::read_bytes(Path::new("nan.csv"), csv.as_bytes(), Format::Csv).unwrap();
    assert_eq!(take.tracks[0].positions[1], None);
    assert_eq!(take.tracks[0].positions[3], None);
    assert_eq!(
        (take.tracks[1].positions[1], take.tracks[1].rotations[1]),
        (None, None)
    );
    assert!(take.tracks[1].positions[3].is_some());
    assert_eq!(take.tracks[1].rotations[3], None);
    nan_note(&take, 2);
    // Motive: the left stick lost (NaN) for one frame.
    let path = fixture("motive/timpani_roll_250hz.csv");
    let motive = std::fs::read_to_string(&path).unwrap();
    let lost = motive
        .lines()
        .map(|l| match l.strip_prefix("3,0.012000,") {
            Some(rest) => {
                let cells: Vec<&str> = rest.split(',').collect();
                let nans = ["NaN"; 7];
                format!("3,0.012000,{},{}", nans.join(","), cells[7..].join(","))
            }
            None => l.to_string(),
        })
        .collect::<Vec<_>>()
        .join("\n");
    let take = import::read_bytes(&path, lost.as_bytes(), Format::Motive).unwrap();
    let left = take.track("StickL").unwrap();
    assert_eq!((left.positions[3], left.rotations[3]), (None, None));
    nan_note(&take, 1);
    // TRC (through the table reader): its NaN marker is counted too.
    let take = load("capture/opensim_walk.trc");
    assert_eq!(take.tracks[1].positions[3], None);
    nan_note(&take, 1);
    // Qualisys (a profile): NaN and empty cells are gaps, the NaN counted.
    let profile = import::CaptureProfile::shipped("qualisys-3d").unwrap();
    let tsv = qualisys_tsv(40, 40, &|f| match f {
        5 => "NaN\tNaN\tNaN".to_string(),
        6 => "\t\t".to_string(),
        _ => tip_cells(f),
    });
    let take = import::table::read(Path::new("nan.tsv"), tsv.as_bytes(), &profile, None).unwrap();
    assert_eq!(take.tracks[0].positions[4..6], [None, None]);
    nan_note(&take, 1);
}

/// A spreadsheet set to a European locale saves "CSV" with semicolons between cells and
/// decimal commas: the Motive, Vicon and plain CSV fixtures so rewritten (CRLF line ends
/// for one) read the same tracks and samples as the originals, with a note saying how they
/// were read.
#[test]
fn european_csv_reads_as_the_same_export() {
    let dir = std::env::temp_dir().join(format!("timpanist-euro-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (rel, crlf) in [
        ("motive/timpani_roll_250hz.csv", false),
        ("vicon/timpani_strokes_100hz.csv", true),
        ("csv/two_sticks_250hz.csv", false),
    ] {
        let original = load(rel);
        let text = std::fs::read_to_string(fixture(rel)).unwrap();
        let mut euro = text.replace(',', ";").replace('.', ",");
        if crlf {
            euro = euro.replace("\r\n", "\n").replace('\n', "\r\n");
        }
        let path = dir.join(Path::new(rel).file_name().unwrap());
        std::fs::write(&path, euro).unwrap();
        let read = import::read(&path, None).unwrap_or_else(|e| panic!("{rel}: {e}"));
        assert_eq!(read.rate_hz, original.rate_hz, "{rel}");
        assert_eq!(read.tracks.len(), original.tracks.len(), "{rel}");
        for (a, b) in read.tracks.iter().zip(&original.tracks) {
            assert_eq!(a.label, b.label, "{rel}");
            assert_eq!(a.positions, b.positions, "{rel}: {}", a.label);
            assert_eq!(a.rotations, b.rotations, "{rel}: {}", a.label);
        }
        assert!(
            read.notes.iter().any(|n| n.contains("semicolons")),
            "{rel}: {:?}",
            read.notes
        );
        assert!(!original.notes.iter().any(|n| n.contains("semicolons")));
    }
    std::fs::remove_dir_all(&dir).ok();
}

/// Corrupt parameter records are refused, naming the place, not read past: a parameter
/// whose dimensions make more data than its record holds (it would take the next
/// records' bytes as its own), and an offset to the next record that points past the
/// parameter section (a negative offset read unsigned, which would drop every parameter
/// after it).
#[test]
fn c3d_corrupt_parameter_records_are_refused() {
    let good = write_c3d(&counting_take(50));
    let read = |bytes: &[u8]| {
        import::read_bytes(Path::new("corrupt.c3d"), bytes, Format::C3d)
            .map(|_| ())
            .unwrap_err()
            .to_string()
    };
    // POINT:SCALE: name, offset to the next record (2 bytes), type, dimension count.
    let scale = param_at(&good, "SCALE") + 2 + "SCALE".len();
    let mut bytes = good.clone();
    bytes[scale + 3] = 1;
    bytes[scale + 4] = 60;
    let err = read(&bytes);
    assert!(
        err.contains("corrupt.c3d")
            && err.contains("(parameter SCALE)")
            && err.contains("run past"),
        "{err}"
    );
    let mut bytes = good.clone();
    bytes[scale..scale + 2].copy_from_slice(&(-6i16).to_le_bytes());
    let err = read(&bytes);
    assert!(
        err.contains(&format!("byte {scale}")) && err.contains("points past the parameter section"),
        "{err}"
    );
}

/// Whatever the file says, a take's frame rate is one a capture can have, and a sample
/// absurdly far from the origin (a corrupt value) is a gap with a note.
#[test]
fn an_absurd_rate_is_refused_and_an_absurd_sample_is_a_gap() {
    let rows = |step: f64, x: &dyn Fn(usize) -> f64| {
        let mut text = String::from("time_s,Tip_x,Tip_y,Tip_z\n");
        for f in 0..20 {
            text += &format!("{},{},0.1,0.8\n", f as f64 * step, x(f));
        }
        text
    };
    let fast = rows(1e-25, &|_| 0.2);
    let err = import::read_bytes(Path::new("fast.csv"), fast.as_bytes(), Format::Csv)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("fast.csv: frame rate:") && err.contains("at most 100 kHz"),
        "{err}"
    );
    let far = rows(0.004, &|f| if f == 7 { 3e7 } else { 0.2 });
    let take = import::read_bytes(Path::new("far.csv"), far.as_bytes(), Format::Csv).unwrap();
    assert_eq!(take.tracks[0].positions[7], None);
    assert_eq!(take.tracks[0].positions[8], Some(DVec3::new(0.2, 0.1, 0.8)));
    assert!(
        take.notes
            .iter()
            .any(|n| n.contains("1 sample more than 1000 km") && n.contains("frame 8")),
        "{:?}",
        take.notes
    );
}
