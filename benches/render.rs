//! Whole-score rendering speed: the one-minute demo study (60 s of music, 109 strokes)
//! composed, simulated with HIMC and the modal drums at 10 kHz with timing compensation,
//! and synthesised to 48 kHz stereo. Each iteration is one full `timpanist render`
//! (≈ 10–15 s), so this takes a few minutes. `cargo bench --bench render`.

use criterion::{Criterion, criterion_group, criterion_main};
use std::path::Path;
use timpanist::mocap::db::MotionDb;
use timpanist::render::{RenderParams, render};
use timpanist::score::LoadedScore;

fn bench(c: &mut Criterion) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let db = MotionDb::load(&root.join("mocap")).expect("the shipped database");
    let loaded = LoadedScore::load(&root.join("scores/minute-study.ron")).expect("demo score");
    c.bench_function("render the one-minute study (HIMC, modal)", |b| {
        b.iter(|| render(&loaded, &db, &RenderParams::default(), &mut |_| true).expect("renders"))
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10).warm_up_time(std::time::Duration::from_millis(1));
    targets = bench
}
criterion_main!(benches);
