//! Composition speed: planning and composing a five-minute score (quarter notes at
//! 120 bpm alternating between two drums, mixed modes and dynamics, a roll every eight
//! bars) from the shipped motion database. `cargo bench --bench compose`.

use criterion::{Criterion, criterion_group, criterion_main};
use std::path::Path;
use timpanist::kit::Kit;
use timpanist::mocap::db::MotionDb;
use timpanist::motion::compose::ComposeParams;
use timpanist::motion::perform;
use timpanist::motion::plan::PlanParams;
use timpanist::score::{
    Beat, Dynamic, Hand, ImpactLocation, PlayingMode, Roll, Score, TempoChange, TempoPoint,
};

/// Five minutes of music at 120 bpm: 600 quarter-note beats.
fn five_minute_score() -> Score {
    let mut score = Score::new("five minutes");
    score.tempo = vec![TempoPoint {
        tick: 0,
        bpm: 120.0,
        change: TempoChange::Step,
    }];
    let dynamics = [Dynamic::P, Dynamic::Mf, Dynamic::F];
    for q in 0..600u64 {
        let in_roll_bar = q % 32 >= 28;
        if in_roll_bar && q % 32 != 28 {
            continue;
        }
        score.beats.push(Beat {
            tick: q * 960,
            hand: Hand::Auto,
            mode: PlayingMode::ALL[(q / 4 % 5) as usize],
            dynamic: dynamics[(q % 3) as usize],
            drum: 1 + (q % 2) as usize,
            pitch: None,
            location: ImpactLocation::PlayingSpot,
            roll: in_roll_bar.then_some(Roll {
                length_ticks: 3 * 960,
                strokes_per_quarter: 8,
            }),
            damp: None,
        });
    }
    score
}

fn bench(c: &mut Criterion) {
    let db = MotionDb::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("mocap"))
        .expect("the shipped database");
    let kit = Kit::standard();
    let score = five_minute_score();
    assert!(score.problems(&kit).is_empty());
    c.bench_function("compose a 5-minute score", |b| {
        b.iter(|| {
            perform::trajectories(
                &score,
                &kit,
                &db,
                &PlanParams::default(),
                &ComposeParams::default(),
            )
            .expect("composes")
        })
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20);
    targets = bench
}
criterion_main!(benches);
