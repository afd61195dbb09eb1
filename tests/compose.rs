//! Composition of the demo scores from the shipped database, checked as the issue asks:
//! impacts exactly on time and target, on the membrane with a downward velocity; no jumps
//! in position, velocity or acceleration; a tempo ramp followed; handles local; tips
//! above the heads and within reach.

use glam::DVec3;
use std::path::Path;
use timpanist::body::{Joint, Skeleton};
use timpanist::kit::Side;
use timpanist::mocap::db::MotionDb;
use timpanist::motion::compose::{ComposeParams, Composition};
use timpanist::motion::perform;
use timpanist::motion::plan::PlanParams;
use timpanist::score::{Handle, LoadedScore};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn demos() -> Vec<LoadedScore> {
    let mut paths: Vec<_> = std::fs::read_dir(root().join("scores"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    paths.sort();
    paths
        .iter()
        .map(|p| LoadedScore::load(p).unwrap())
        .collect()
}

fn db() -> MotionDb {
    MotionDb::load(&root().join("mocap")).unwrap()
}

fn compose(s: &LoadedScore, db: &MotionDb) -> Composition {
    perform::trajectories(
        &s.score,
        &s.kit,
        db,
        &PlanParams::default(),
        &ComposeParams::default(),
    )
    .unwrap()
}

/// Largest |acceleration| (m/s²) and largest change of acceleration between samples
/// (m/s² per sample), by central finite differences, ignoring ±3 samples around impacts
/// (the stick's velocity reverses there, as it does on a real drum).
fn smoothness(comp: &Composition, side: Side) -> (f64, f64, f64) {
    let x = comp.tip(side);
    let r = comp.rate_hz;
    let near_impact = |k: usize| {
        comp.strokes
            .iter()
            .zip(&comp.impact_samples)
            .any(|(s, &i)| s.hand == side && k.abs_diff(i) <= 3)
    };
    let (mut max_step, mut max_acc, mut max_jerk) = (0.0f64, 0.0f64, 0.0f64);
    let acc = |k: usize| (x[k + 1] - 2.0 * x[k] + x[k - 1]) * r * r;
    for k in 2..x.len() - 2 {
        max_step = max_step.max((x[k + 1] - x[k]).length());
        if near_impact(k) || near_impact(k + 1) {
            continue;
        }
        max_acc = max_acc.max(acc(k).length());
        max_jerk = max_jerk.max((acc(k + 1) - acc(k)).length());
    }
    (max_step * r, max_acc, max_jerk)
}

/// Stated bounds: tip speed below 10 m/s between samples, acceleration below 400 m/s²
/// and its change below 100 m/s² per 4 ms sample away from impacts.
const MAX_SPEED: f64 = 10.0;
const MAX_ACC: f64 = 400.0;
const MAX_ACC_STEP: f64 = 100.0;

/// Every impact lands on its scored time (±1 sample) and target (±1 mm), at the
/// membrane's height, reached from above with a downward velocity.
#[test]
fn impacts_on_time_and_target() {
    let db = db();
    for s in demos() {
        let comp = compose(&s, &db);
        for (stroke, &k) in comp.strokes.iter().zip(&comp.impact_samples) {
            assert!(
                (comp.time(k) - stroke.time_s).abs() <= 1.0 / comp.rate_hz,
                "{}: time",
                s.score.title
            );
            let tip = comp.tip(stroke.hand);
            assert!(
                tip[k].distance(stroke.target) < 1e-3,
                "{}: {} vs {}",
                s.score.title,
                tip[k],
                stroke.target
            );
            assert!((tip[k].z - s.kit.drums[stroke.drum].placement.head_height_m).abs() < 1e-3);
            assert!(
                tip[k - 1].z > tip[k].z,
                "{}: not coming down into beat {}",
                s.score.title,
                stroke.beat
            );
        }
    }
}

/// No jumps: speed, acceleration and its change stay within the stated bounds on every
/// demo score.
#[test]
fn no_jumps() {
    let db = db();
    for s in demos() {
        let comp = compose(&s, &db);
        for side in [Side::Left, Side::Right] {
            let (v, a, j) = smoothness(&comp, side);
            println!(
                "{} {side:?}: speed {v:.2} m/s, acc {a:.0} m/s², acc step {j:.1}",
                s.score.title
            );
            assert!(
                v < MAX_SPEED && a < MAX_ACC && j < MAX_ACC_STEP,
                "{} {side:?}: {v} {a} {j}",
                s.score.title
            );
        }
    }
}

/// The bounds are tight enough to catch a hard cut: composing with (almost) no blending
/// breaks them.
#[test]
fn hard_cuts_would_be_caught() {
    let db = db();
    let s = &demos()[3];
    let comp = perform::trajectories(
        &s.score,
        &s.kit,
        &db,
        &PlanParams::default(),
        &ComposeParams {
            blend_fraction: 0.01,
            ..ComposeParams::default()
        },
    )
    .unwrap();
    let (_, a, j) = [Side::Left, Side::Right]
        .iter()
        .map(|&h| smoothness(&comp, h))
        .fold((0.0, 0.0f64, 0.0f64), |m, v| {
            (0.0, m.1.max(v.1), m.2.max(v.2))
        });
    assert!(a > MAX_ACC || j > MAX_ACC_STEP, "{a} {j}");
}

/// Under the accelerando, inter-impact times follow the tempo map to ±1 sample.
#[test]
fn tempo_ramp_is_followed() {
    let db = db();
    let s = demos()
        .into_iter()
        .find(|s| s.score.title.contains("accelerando"))
        .unwrap();
    let comp = compose(&s, &db);
    let map = s.score.tempo_map();
    let mut impacts: Vec<(u64, f64)> = comp
        .strokes
        .iter()
        .zip(&comp.impact_samples)
        .map(|(st, &k)| (st.tick, comp.time(k)))
        .collect();
    impacts.sort_by_key(|p| p.0);
    for w in impacts.windows(2) {
        let scored = map.seconds_at(w[1].0 as f64) - map.seconds_at(w[0].0 as f64);
        assert!(((w[1].1 - w[0].1) - scored).abs() <= 1.0 / comp.rate_hz + 1e-9);
    }
    let first_gap = map.seconds_at(960.0) - map.seconds_at(0.0);
    let ramp_gap = map.seconds_at(4.0 * 960.0 * 4.0 + 960.0) - map.seconds_at(4.0 * 960.0 * 4.0);
    assert!(ramp_gap < first_gap * 0.8, "the ramp speeds up");
}

/// Moving one handle changes samples only inside its support: every other sample is
/// bit-identical; inside, the displacement reaches the handle's offset at its centre.
#[test]
fn handles_are_local() {
    let db = db();
    let mut s = demos()
        .into_iter()
        .find(|s| s.score.title.contains("accelerando"))
        .unwrap();
    let before = compose(&s, &db);
    let handle = Handle {
        hand: Side::Right,
        tick: 5 * 960 + 480,
        reach_ticks: 360,
        offset_m: [0.0, -0.03, 0.05],
    };
    s.score.handles.push(handle);
    let after = compose(&s, &db);
    let (centre, half) = timpanist::motion::handles::support_s(&s.score, &handle);
    let mut changed = 0;
    for k in 0..before.len() {
        let t = before.time(k);
        let same = before.tips[0][k] == after.tips[0][k] && before.tips[1][k] == after.tips[1][k];
        if (t - centre).abs() >= half {
            assert!(same, "sample {k} at {t} s outside the support changed");
        } else {
            changed += usize::from(!same);
        }
    }
    assert!(changed > 10);
    let k = ((centre - before.start_s) * before.rate_hz).round() as usize;
    let moved = after.tips[1][k] - before.tips[1][k];
    assert!(
        moved.distance(DVec3::new(0.0, -0.03, 0.05)) < 0.01,
        "{moved}"
    );
    for (stroke, &i) in after.strokes.iter().zip(&after.impact_samples) {
        assert_eq!(
            after.tip(stroke.hand)[i],
            before.tip(stroke.hand)[i],
            "impacts never move"
        );
    }
}

/// Tips never pass through a drum head between strokes, and stay within reach of the arm
/// model (shoulder to tip at most arm + stick length, with the trunk leaning 10 cm).
#[test]
fn above_the_heads_and_in_reach() {
    let db = db();
    let skeleton = Skeleton::default();
    let rest = skeleton.forward(&timpanist::body::skeleton::REST);
    let reach = 0.30 + 0.26 + 0.08 + skeleton.stick_length_m + 0.10;
    for s in demos() {
        let comp = compose(&s, &db);
        for side in [Side::Left, Side::Right] {
            let shoulder = rest.position[Joint::arm(side)[0].index()];
            for p in comp.tip(side) {
                for d in &s.kit.drums {
                    let over = p.truncate().distance(d.centre().truncate()) < d.radius_m();
                    assert!(
                        !over || p.z > d.placement.head_height_m - 1e-3,
                        "{}: {side:?} tip through the {} head at {p}",
                        s.score.title,
                        d.name
                    );
                }
                assert!(
                    p.distance(shoulder) < reach,
                    "{}: {side:?} out of reach at {p}",
                    s.score.title
                );
            }
        }
    }
}

/// Scores the editor still composes while they have problems — beats pasted over beats
/// (two strokes of one hand at once, three strokes at once) and beats a few ticks apart —
/// compose to finite trajectories (a NaN tip once reached the plots after a paste).
#[test]
fn scores_with_problems_compose_to_finite_tips() {
    let db = db();
    let base = LoadedScore::load(&root().join("scores/minute-study.ron")).unwrap();
    type Edit = fn(&mut Vec<timpanist::score::Beat>);
    let variants: [(&str, Edit); 3] = [
        ("pasted over itself", |beats| {
            let copy = beats.clone();
            beats.extend(copy);
        }),
        ("pasted a tick later", |beats| {
            let copy: Vec<_> = beats
                .iter()
                .map(|b| timpanist::score::Beat {
                    tick: b.tick + 1,
                    ..*b
                })
                .collect();
            beats.extend(copy);
        }),
        ("pasted three times over itself", |beats| {
            let copy = beats.clone();
            beats.extend(copy.clone());
            beats.extend(copy);
        }),
    ];
    for (name, edit) in variants {
        let mut s = base.clone();
        edit(&mut s.score.beats);
        s.score.beats.sort_by_key(|b| b.tick);
        let comp = compose(&s, &db);
        for h in [Side::Left, Side::Right] {
            let bad = comp.tip(h).iter().position(|p| !p.is_finite());
            assert!(
                bad.is_none(),
                "{name}: {h:?} tip not finite at {:.3} s",
                comp.time(bad.unwrap())
            );
        }
    }
}
