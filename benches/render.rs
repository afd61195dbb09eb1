//! Whole-score rendering speed and the editor's edit-to-ready-audio on the one-minute demo
//! study (60 s of music, 109 strokes), HIMC with the modal drums at 10 kHz and timing
//! compensation, synthesised to 48 kHz stereo:
//!
//! * a full `timpanist render` at the default, fast body step (5 kHz between contacts,
//!   the drums and contact at 10 kHz; ≈ 1.4 s per iteration, so this takes a few
//!   minutes), and the same at the 10 kHz reference (`BodyStep::Reference`, `render
//!   --body-hz 10000`);
//! * after a one-beat edit near 30 s (its dynamic changed), the rendering that resumes
//!   the previous performance from its saved state before the edit and stops
//!   `FIRST_STEP_S` (0.25 s) past the edited stroke (what the editor plays at once: its audio is final up
//!   to there), and the resumed rendering of the whole rest.
//!
//! * what handing a compensation attempt to the other core would copy first, at the
//!   study's end: the performance's simulator (its motion and targets so far), drums and
//!   targets (README "Where the speed issue stands": a retry costs about as much wall
//!   time as the copy).
//!
//! `cargo bench --bench render`.

use criterion::{BatchSize, Criterion, criterion_group, criterion_main};
use std::path::Path;
use timpanist::body::sim::{BodyStep, SimParams};
use timpanist::mocap::db::MotionDb;
use timpanist::render::{FIRST_STEP_S, RenderParams, render, render_after};
use timpanist::score::{Dynamic, LoadedScore};

fn bench(c: &mut Criterion) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let db = MotionDb::load(&root.join("mocap")).expect("the shipped database");
    let loaded = LoadedScore::load(&root.join("scores/minute-study.ron")).expect("demo score");
    let params = RenderParams::default();
    c.bench_function("render the one-minute study (HIMC, modal)", |b| {
        b.iter(|| render(&loaded, &db, &params, &mut |_| true).expect("renders"))
    });
    let reference = RenderParams {
        sim: SimParams {
            contact_substeps: BodyStep::Reference.contact_substeps(),
            ..params.sim.clone()
        },
        ..params.clone()
    };
    c.bench_function(
        "render the one-minute study, body at the 10 kHz reference",
        |b| b.iter(|| render(&loaded, &db, &reference, &mut |_| true).expect("renders")),
    );
    let mut resume = None;
    let before =
        render_after(&mut resume, None, &loaded, &db, &params, &mut |_| true).expect("renders");
    let performance = resume.as_ref().expect("a resumable state").performance();
    c.bench_function(
        "copy the simulator, drums and targets at the study's end",
        |b| {
            b.iter(|| {
                (
                    performance.sim.clone(),
                    performance.drums.clone(),
                    performance.reference.clone(),
                )
            })
        },
    );
    let mut edited = loaded.clone();
    let beat = before
        .composition
        .strokes
        .iter()
        .find(|s| s.time_s >= 30.0)
        .expect("a stroke after 30 s")
        .beat;
    let b = &mut edited.score.beats[beat];
    b.dynamic = if b.dynamic == Dynamic::Ff {
        Dynamic::Mp
    } else {
        Dynamic::Ff
    };
    for (name, stop_after_s) in [
        (
            "one-beat edit at 30 s: audio ready past the edited stroke",
            Some(FIRST_STEP_S),
        ),
        ("one-beat edit at 30 s: the whole rest re-rendered", None),
    ] {
        c.bench_function(name, |b| {
            b.iter_batched(
                || resume.clone(),
                |mut resume| {
                    let r = render_after(
                        &mut resume,
                        stop_after_s,
                        &edited,
                        &db,
                        &params,
                        &mut |_| true,
                    )
                    .expect("renders");
                    assert!(r.stats.resumed_from_s.is_some(), "the edit resumes");
                    r
                },
                BatchSize::LargeInput,
            )
        });
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10).warm_up_time(std::time::Duration::from_millis(1));
    targets = bench
}
criterion_main!(benches);
