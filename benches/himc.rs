//! HIMC speed: following one captured legato stroke (≈ 0.75 s, both arms, 10 kHz
//! physics, 250 Hz task) with IK nested in PD. Divide the stroke's length by the time per
//! iteration for the real-time factor. `cargo bench --bench himc`.

use criterion::{Criterion, criterion_group, criterion_main};
use std::path::Path;
use timpanist::body::sim::{Pipeline, SimParams, simulate};
use timpanist::body::skeleton::JOINT_COUNT;
use timpanist::mocap::db::MotionDb;
use timpanist::render::evaluate::{reference_of, simulated_body, units_for};
use timpanist::score::PlayingMode;

fn bench(c: &mut Criterion) {
    let db = MotionDb::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("mocap"))
        .expect("the shipped database");
    let unit = units_for(&db, PlayingMode::Legato, 1)[0];
    let reference = reference_of(&db, unit);
    let seconds = (reference.tips[0].len() - 1) as f64 / reference.rate_hz;
    let model = simulated_body();
    let start = reference.poses.as_ref().expect("joints")[0];
    let params = SimParams::default();
    println!("one stroke = {seconds:.3} s of motion");
    for pipeline in [Pipeline::Himc, Pipeline::Id] {
        c.bench_function(
            &format!("{} one stroke ({seconds:.3} s)", pipeline.name()),
            |b| {
                b.iter(|| {
                    simulate(
                        &model,
                        &reference,
                        pipeline,
                        &params,
                        &start,
                        &[1.0; JOINT_COUNT],
                    )
                    .expect("stable")
                })
            },
        );
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10);
    targets = bench
}
criterion_main!(benches);
