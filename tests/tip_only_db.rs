//! A database as a lab import gives it: stick tips only (no joint angles), one stick per
//! take (the other tip never seen), 200 Hz, a few short marker dropouts, only some playing
//! modes, hands and locations, and one dynamic — built here from the shipped synthetic
//! database. `evaluate` runs every mode it has (HIMC below ID) and reports the rest as
//! skipped; a demo score renders with it, completed by the synthetic database for the
//! modes it lacks, every stroke sounding, the substituted beats told; nothing loses control.

use glam::DVec3;
use std::path::Path;
use std::process::Command;
use timpanist::kit::Side;
use timpanist::mocap::db::{MotionDb, TakeData, UnitEntry, side_index};
use timpanist::motion::plan;
use timpanist::render::evaluate::{self, EvalParams};
use timpanist::render::{RenderParams, render};
use timpanist::score::{Dynamic, Grip, ImpactLocation, LoadedScore, PlayingMode};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn shipped() -> MotionDb {
    MotionDb::load(&root().join("mocap")).unwrap()
}

/// The lab's rate, Hz.
const LAB_RATE_HZ: f64 = 200.0;

/// What the lab captured: French grip, mf only, and per mode one hand at one location —
/// legato with the right hand at the playing spot, accent with the left hand only,
/// staccato with the right hand at the rim. No tenuto, no vertical accent, no German grip.
const CAPTURED: [(PlayingMode, Side, ImpactLocation); 3] = [
    (
        PlayingMode::Legato,
        Side::Right,
        ImpactLocation::PlayingSpot,
    ),
    (PlayingMode::Accent, Side::Left, ImpactLocation::PlayingSpot),
    (PlayingMode::Staccato, Side::Right, ImpactLocation::Rim),
];

/// A tip track resampled from `from_hz` to `to_hz` by linear interpolation (a sample
/// next to a missing one is missing).
fn resample(track: &[Option<DVec3>], from_hz: f64, to_hz: f64) -> Vec<Option<DVec3>> {
    let n = ((track.len() - 1) as f64 * to_hz / from_hz).floor() as usize + 1;
    (0..n)
        .map(|k| {
            let f = k as f64 * from_hz / to_hz;
            let i = f.floor() as usize;
            let (a, b) = (track[i], track[(i + 1).min(track.len() - 1)]);
            Some(a?.lerp(b?, f - i as f64))
        })
        .collect()
}

/// `db`'s take `t` as the lab has it: only `hand`'s tip, at `rate_hz`, with a two-sample
/// dropout every 173 samples; no joints.
fn lab_take(db: &MotionDb, t: usize, hand: Side, rate_hz: f64) -> TakeData {
    let take = &db.takes[t];
    let mut tip = resample(take.tip(hand), take.rate_hz, rate_hz);
    for k in (40..tip.len().saturating_sub(2)).step_by(173) {
        tip[k] = None;
        tip[k + 1] = None;
    }
    let mut tips = [vec![None; tip.len()], vec![None; tip.len()]];
    tips[side_index(hand)] = tip;
    TakeData {
        rate_hz,
        tips,
        joints: None,
    }
}

/// Unit `u` of a take at `from_hz` cut from its resampled take `data`: frames scaled,
/// the impact moved to the lowest sample next to it.
fn lab_unit(u: &UnitEntry, from_hz: f64, take: usize, data: &TakeData) -> UnitEntry {
    let at = |f: usize| (f as f64 * data.rate_hz / from_hz).round() as usize;
    let tip = data.tip(u.hand);
    let height = |f: usize| tip[f].map_or(f64::INFINITY, |p| p.z);
    let impact = (at(u.impact) - 1..=at(u.impact) + 1)
        .min_by(|&a, &b| height(a).total_cmp(&height(b)))
        .unwrap();
    UnitEntry {
        take,
        start: at(u.start),
        impact,
        end: at(u.end),
        ..u.clone()
    }
}

/// The lab's database ([`CAPTURED`], mf, at `rate_hz`), cut from the shipped synthetic
/// one.
fn lab_db(shipped: &MotionDb, rate_hz: f64) -> MotionDb {
    let mut db = MotionDb::empty("tip-only lab capture (test)");
    db.index.joints.clear();
    for (t, entry) in shipped.index.takes.iter().enumerate() {
        let units: Vec<&UnitEntry> = (shipped.index.units.iter())
            .filter(|u| u.take == t)
            .collect();
        let Some(first) = units.first() else { continue };
        let labels = (first.mode, first.hand, first.location);
        if first.grip != Grip::French || !CAPTURED.contains(&labels) {
            continue;
        }
        let data = lab_take(shipped, t, first.hand, rate_hz);
        let take = db.takes.len();
        for u in units.iter().filter(|u| u.dynamic == Dynamic::Mf) {
            let unit = lab_unit(u, entry.rate_hz, take, &data);
            assert!(unit.start < unit.impact && unit.impact < unit.end);
            db.index.units.push(unit);
        }
        db.index.takes.push(timpanist::mocap::db::TakeEntry {
            file: format!("takes/lab-{t}.tmot"),
            frames: data.frames(),
            rate_hz,
            performer: "lab".into(),
            source: entry.file.clone(),
            source_sha256: None,
        });
        db.takes.push(data);
    }
    db
}

/// The lab's database written to disk and read back, as an import leaves it.
fn saved_lab_db(dir: &Path) -> MotionDb {
    lab_db(&shipped(), LAB_RATE_HZ).save(dir).unwrap();
    MotionDb::load(dir).unwrap()
}

/// The modes of a report, in order.
fn modes(report: &evaluate::Report) -> Vec<&str> {
    report.modes.iter().map(|m| m.mode.as_str()).collect()
}

/// (a) `evaluate` on the lab's database (written and read back) runs every mode it has
/// with no error, HIMC's tip error below ID's for each (ID replaying the joint angles
/// solved from the tips on the capture skeleton); the labels used are said where they are
/// not right hand, playing spot, mf; tenuto and vertical accent are reported as skipped.
#[test]
fn evaluate_runs_every_captured_mode_himc_below_id() {
    let dir = tempfile::tempdir().unwrap();
    let db = saved_lab_db(dir.path());
    let params = EvalParams {
        trials: 2,
        ..EvalParams::default()
    };
    let report = evaluate::evaluate(&db, &evaluate::simulated_body(), &params).unwrap();
    assert_eq!(modes(&report), ["legato", "accent", "staccato"]);
    for m in &report.modes {
        println!(
            "{}: IK {:.2} mm, ID {:.2} ± {:.2} mm, HIMC {:.2} ± {:.2} mm",
            m.mode,
            m.ik.rms_e_m * 1e3,
            m.id.rms_e_m * 1e3,
            m.id.rms_sd_m * 1e3,
            m.himc.rms_e_m * 1e3,
            m.himc.rms_sd_m * 1e3
        );
        assert!(m.himc.rms_e_m < m.id.rms_e_m, "{m:?}");
        assert!(m.joints_from_ik && m.skipped_units.is_empty(), "{m:?}");
        assert_eq!(m.labels.iter().map(|l| l.units).sum::<usize>(), 2);
    }
    let described = |mode: usize| report.modes[mode].labels[0].describe();
    assert!(!report.modes[0].substituted());
    assert_eq!(described(1), "left, playing spot, mf, French");
    assert_eq!(described(2), "right, rim, mf, French");
    let skipped: Vec<(&str, &str)> = (report.skipped.iter())
        .map(|s| (s.mode.as_str(), s.reason.as_str()))
        .collect();
    assert_eq!(
        skipped,
        [
            ("tenuto", "the database has no tenuto unit"),
            (
                "vertical accent",
                "the database has no vertical accent unit"
            )
        ]
    );
}

/// The simulator follows tip-only references at the take's rate from 100 to 250 Hz,
/// HIMC below ID at each.
#[test]
fn captures_from_100_to_250_hz_are_followed() {
    let shipped = shipped();
    let params = EvalParams {
        trials: 1,
        strokes_per_mode: 1,
        ..EvalParams::default()
    };
    for rate in [100.0, 120.0, 250.0] {
        let db = lab_db(&shipped, rate);
        let report = evaluate::evaluate(&db, &evaluate::simulated_body(), &params).unwrap();
        assert_eq!(report.modes.len(), 3, "{rate} Hz");
        for m in &report.modes {
            assert!(m.himc.rms_e_m < m.id.rms_e_m, "{rate} Hz: {m:?}");
        }
    }
}

/// On the shipped database the JSON report keeps its form: no labels, joints or skipped
/// entries (every mode is evaluated on right-hand playing-spot mf French units with
/// captured joints).
#[test]
fn the_shipped_report_keeps_its_form() {
    let params = EvalParams {
        trials: 1,
        strokes_per_mode: 1,
        ..EvalParams::default()
    };
    let report = evaluate::evaluate(&shipped(), &evaluate::simulated_body(), &params).unwrap();
    let json = serde_json::to_value(&report).unwrap();
    let keys = |v: &serde_json::Value| v.as_object().unwrap().keys().cloned().collect::<Vec<_>>();
    assert_eq!(keys(&json), ["modes"]);
    for m in json["modes"].as_array().unwrap() {
        assert_eq!(keys(m), ["amplitude_m", "himc", "id", "ik", "mode"]);
    }
}

/// `timpanist evaluate --db` on the lab's database: every captured mode in the table,
/// HIMC below ID in the JSON, the labels used and the skipped modes said, and what ID
/// replayed; no loss of control.
#[test]
fn cli_evaluate_on_a_tip_only_database() {
    let dir = tempfile::tempdir().unwrap();
    saved_lab_db(dir.path());
    let json = dir.path().join("report.json");
    let out = Command::new(env!("CARGO_BIN_EXE_timpanist"))
        .args(["evaluate", "--trials", "1", "--db"])
        .arg(dir.path())
        .arg("--json")
        .arg(&json)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    println!("{stdout}");
    for line in [
        "accent: evaluated 2 × left, playing spot, mf, French (no unit of right, playing spot, mf, French)",
        "staccato: evaluated 2 × right, rim, mf, French",
        "tenuto: skipped (the database has no tenuto unit)",
        "vertical accent: skipped",
        "no captured joint angles; ID replays",
    ] {
        assert!(stdout.contains(line), "{line:?} not in\n{stdout}");
    }
    assert!(!stdout.contains("legato: evaluated"), "{stdout}");
    assert!(!format!("{stdout}{stderr}").contains("lost control"));
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let modes = report["modes"].as_array().unwrap();
    assert_eq!(modes.len(), 3);
    for m in modes {
        assert!(
            m["himc"]["rms_e_m"].as_f64() < m["id"]["rms_e_m"].as_f64(),
            "{m}"
        );
    }
    assert_eq!(report["skipped"].as_array().unwrap().len(), 2);
}

/// `with_fallback` adds the synthetic database's units of exactly the (grip, mode) pairs
/// the lab's lacks, after the lab's own (kept as they are), with the takes they come from.
#[test]
fn the_fallback_adds_only_the_modes_lacking() {
    let shipped = shipped();
    let lab = lab_db(&shipped, LAB_RATE_HZ);
    let lacking = lab.modes_lacking(&shipped);
    assert_eq!(
        lacking.len(),
        2 + 5,
        "French tenuto and vertical accent, all German"
    );
    assert!(lacking.contains(&(Grip::French, PlayingMode::Tenuto)));
    let db = lab.with_fallback(&shipped);
    assert!(db.modes_lacking(&shipped).is_empty());
    let own = lab.index.units.len();
    assert_eq!(db.index.units[..own], lab.index.units[..]);
    let added = &db.index.units[own..];
    assert_eq!(
        added.len(),
        (shipped.index.units.iter())
            .filter(|u| lacking.contains(&(u.grip, u.mode)))
            .count()
    );
    for u in added {
        assert!(lacking.contains(&(u.grip, u.mode)));
        assert!(u.take >= lab.takes.len() && db.takes[u.take].joints.is_some());
        assert!(db.index.takes[u.take].file.starts_with("fallback/"));
    }
    assert_eq!(shipped.with_fallback(&shipped), shipped);
}

/// (b, c) The improvisation (five strokes, every mode) rendered with the lab's database
/// completed by the synthetic one: every stroke has its contact, on time; tenuto and
/// vertical accent are played from the synthetic units, and the beats played with units
/// of other labels are listed (the right-hand ff accent from a left-hand mf accent).
#[test]
fn a_score_renders_with_the_completed_database() {
    let shipped = shipped();
    let lab = lab_db(&shipped, LAB_RATE_HZ);
    let db = lab.with_fallback(&shipped);
    let loaded = LoadedScore::load(&root().join("scores/improvisation.ron")).unwrap();
    let r = render(&loaded, &db, &RenderParams::default(), &mut |_| true).unwrap();
    assert_eq!(
        (r.timing.strokes, r.timing.missed),
        (5, 0),
        "{:?}",
        r.timing
    );
    let beats: Vec<usize> = r.events.iter().filter_map(|e| e.beat).collect();
    assert_eq!(beats, [0, 1, 2, 3, 4]);
    assert!(r.timing.worst_abs_s < 0.005, "{:?}", r.timing);
    for s in &r.composition.strokes {
        let synthetic = db.index.units[s.unit].take >= lab.takes.len();
        let lacking = [PlayingMode::Tenuto, PlayingMode::VerticalAccent].contains(&s.mode);
        assert_eq!(synthetic, lacking, "{s:?}");
    }
    let notes: Vec<String> = plan::substitutions(&r.composition.strokes, &loaded.score, &db)
        .iter()
        .map(ToString::to_string)
        .collect();
    assert_eq!(
        notes,
        [
            "beat 0 (legato, right, p): no such unit; used legato, right, mf",
            "beat 2 (accent, right, ff): no such unit; used accent, left, mf",
        ]
    );
}

/// `timpanist render --db` with the lab's database says which modes came from the
/// synthetic database and which beats were substituted, and every beat has its contact
/// in the events; `compose --db` says the same.
#[test]
fn cli_render_and_compose_tell_the_fallback_and_substitutions() {
    let dir = tempfile::tempdir().unwrap();
    saved_lab_db(dir.path());
    let events = dir.path().join("events.json");
    let run = |args: &[&str]| {
        let out = Command::new(env!("CARGO_BIN_EXE_timpanist"))
            .current_dir(root())
            .args(args)
            .arg("--db")
            .arg(dir.path())
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
        assert!(out.status.success(), "{stderr}");
        stderr
    };
    let (wav, csv) = (dir.path().join("out.wav"), dir.path().join("tips.csv"));
    let rendered = run(&[
        "render",
        "scores/improvisation.ron",
        "--wav",
        wav.to_str().unwrap(),
        "--events",
        events.to_str().unwrap(),
    ]);
    let composed = run(&[
        "compose",
        "scores/improvisation.ron",
        "-o",
        csv.to_str().unwrap(),
    ]);
    for stderr in [&rendered, &composed] {
        for note in [
            "has no unit of tenuto (French), vertical accent (French), legato (German)",
            "those come from the built-in synthetic database",
            "note: beat 2 (accent, right, ff): no such unit; used accent, left, mf",
        ] {
            assert!(stderr.contains(note), "{note:?} not in\n{stderr}");
        }
        assert!(!stderr.contains("lost control"), "{stderr}");
    }
    let events: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&events).unwrap()).unwrap();
    let beats: Vec<u64> = (events.as_array().unwrap().iter())
        .filter_map(|e| e["beat"].as_u64())
        .collect();
    assert_eq!(beats, [0, 1, 2, 3, 4]);
}

/// A left-hand unit serving a right-hand stroke is mirrored across the stroke's vertical
/// plane: its sideways motion goes the way the right hand's own unit's does (the
/// synthetic left and right accents are mirror images, so the two paths nearly agree).
#[test]
fn a_left_hand_unit_serves_a_right_hand_stroke_mirrored() {
    use timpanist::motion::compose::{ComposeParams, compose};
    let shipped = shipped();
    let loaded = LoadedScore::load(&root().join("scores/improvisation.ron")).unwrap();
    let strokes = plan::plan(
        &loaded.score,
        &loaded.kit,
        &shipped,
        &plan::PlanParams::default(),
    )
    .unwrap();
    let stroke = (strokes.iter())
        .find(|s| s.hand == Side::Right && s.mode == PlayingMode::Accent)
        .unwrap();
    let own = plan::Labels::of(&shipped.index.units[stroke.unit]);
    let mirror_of = plan::Labels {
        hand: Side::Left,
        ..own
    };
    let left = (shipped.index.units.iter())
        .position(|u| plan::Labels::of(u) == mirror_of)
        .unwrap();
    let sideways = DVec3::Z.cross(stroke.toward_player);
    let path = |unit: usize| {
        let one = plan::PlannedStroke {
            unit,
            time_s: 1.0,
            ..stroke.clone()
        };
        let c = compose(
            std::slice::from_ref(&one),
            &shipped,
            &ComposeParams::default(),
        );
        let (tip, impact) = (c.tip(Side::Right), c.impact_samples[0]);
        (impact - 60..impact + 40)
            .map(|k| (tip[k] - tip[impact]).dot(sideways))
            .collect::<Vec<f64>>()
    };
    let (right, mirrored) = (path(stroke.unit), path(left));
    let rms = |xs: &mut dyn Iterator<Item = f64>| {
        let v: Vec<f64> = xs.collect();
        (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt()
    };
    let size = rms(&mut right.iter().copied());
    let apart = rms(&mut right.iter().zip(&mirrored).map(|(a, b)| a - b));
    println!("sideways: {size:.4} m, apart {apart:.4} m");
    assert!(size > 0.03, "the accent moves sideways: {size} m");
    assert!(apart < 0.2 * size, "{apart} m apart for {size} m");
}
