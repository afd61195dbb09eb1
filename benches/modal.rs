//! Modal synthesis speed: a bank of 64 voices rendering 1 s of audio at 48 kHz (free
//! ringing, and driven by a force input every sample), and one DrumSet step of the
//! standard kit with a tip held in contact (per 1000 steps). × real time = 1 s / time per iteration.
//! `cargo bench --bench modal`.

use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use timpanist::drum::strike::{PLAYING_SPOT_FRACTION, SIM_RATE_HZ, ScriptedStick};
use timpanist::drum::{DrumSet, ModeConfig};
use timpanist::kit::Kit;
use timpanist::sound::SAMPLE_RATE_HZ;
use timpanist::sound::voices::{Voice, VoiceBank};

fn bank(n: usize) -> VoiceBank {
    let voices: Vec<Voice> = (0..n)
        .map(|k| Voice {
            freq_hz: 100.0 + 37.0 * k as f64,
            t60_s: 2.0 - 0.02 * k as f64,
            gain: 1.0 / (1.0 + k as f64),
            glide: 0.0,
        })
        .collect();
    let mut b = VoiceBank::new(&voices, f64::from(SAMPLE_RATE_HZ));
    b.kick(&vec![1.0; n]);
    b
}

fn bench(c: &mut Criterion) {
    let second = SAMPLE_RATE_HZ as usize;
    c.bench_function("64 modes, 1 s free ringing", |b| {
        let mut out = vec![0.0f32; second];
        b.iter_batched_ref(
            || bank(64),
            |bank| {
                out.fill(0.0);
                bank.render_free(&mut out);
                black_box(out[second - 1])
            },
            criterion::BatchSize::LargeInput,
        )
    });
    c.bench_function("64 modes, 1 s driven every sample", |b| {
        let mut out = vec![0.0f32; second];
        let proto = bank(64);
        let input = vec![1e-3f32; 4096 * proto.stride()];
        b.iter_batched_ref(
            || proto.clone(),
            |bank| {
                out.fill(0.0);
                for chunk in out.chunks_mut(4096) {
                    bank.render_driven(&input[..chunk.len() * bank.stride()], chunk);
                }
                black_box(out[second - 1])
            },
            criterion::BatchSize::LargeInput,
        )
    });
    let kit = Kit::standard();
    let mallet = &kit.mallets[0];
    let drum = &kit.drums[2];
    let drums = DrumSet::new(&kit, mallet, &ModeConfig::default(), 1.0 / SIM_RATE_HZ)
        .expect("standard kit");
    let tip = ScriptedStick::above(
        drum,
        mallet,
        drum.point_on_head(PLAYING_SPOT_FRACTION, 0.0),
        0.0,
        -0.002,
    );
    let parked = ScriptedStick::parked(mallet);
    let tips = [
        (parked.position, parked.velocity),
        (tip.position, tip.velocity),
    ];
    c.bench_function(
        "1000 DrumSet steps (0.1 s), 4 drums × 24 modes, one tip in contact",
        |b| {
            b.iter_batched_ref(
                || drums.clone(),
                |drums| {
                    for k in 0..1000 {
                        black_box(drums.step(k as f64 * 1e-4, black_box(tips)));
                    }
                },
                criterion::BatchSize::SmallInput,
            )
        },
    );
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20);
    targets = bench
}
criterion_main!(benches);
