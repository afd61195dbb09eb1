//! Modal synthesis speed: a bank of 64 voices rendering 1 s of audio at 48 kHz (free
//! ringing, and driven by a force input every sample), and one DrumSet step of the
//! standard kit with a tip held in contact (per 1000 steps). × real time = 1 s / time per iteration.
//! And the whole modal sound of the one-minute study (64 s of audio, 109 strokes on four
//! full-band heads; the performance is simulated once before timing).
//! `cargo bench --bench modal`.

use criterion::{Criterion, criterion_group, criterion_main};
use glam::DVec3;
use std::hint::black_box;
use timpanist::drum::strike::{PLAYING_SPOT_FRACTION, SIM_RATE_HZ, ScriptedStick};
use timpanist::drum::{DrumSet, ModeConfig};
use timpanist::kit::Kit;
use timpanist::mocap::db::MotionDb;
use timpanist::render::{RenderParams, render};
use timpanist::score::LoadedScore;
use timpanist::sound::SAMPLE_RATE_HZ;
use timpanist::sound::voices::{Voice, VoiceBank};
use timpanist::sound::{SoundModel, render as render_sound};

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
    thousand_steps(c, "4 drums, one tip in contact", &drums, tips, 0);
    // The same heads ringing after that contact with both sticks parked: nothing is near,
    // so the heads lag and are caught up once per membrane frame.
    let mut ringing = drums.clone();
    for k in 0..100 {
        ringing.step(k as f64 * 1e-4, tips);
    }
    let away = [(parked.position, parked.velocity); 2];
    thousand_steps(c, "4 drums ringing, no tip near", &ringing, away, 100);
}

/// 1000 steps (0.1 s) of `drums` with the tips held at `tips`, from step `first`.
fn thousand_steps(
    c: &mut Criterion,
    what: &str,
    drums: &DrumSet,
    tips: [(DVec3, DVec3); 2],
    first: usize,
) {
    c.bench_function(&format!("1000 DrumSet steps (0.1 s), {what}"), |b| {
        b.iter_batched_ref(
            || drums.clone(),
            |drums| {
                for k in first..first + 1000 {
                    black_box(drums.step(k as f64 * 1e-4, black_box(tips)));
                }
            },
            criterion::BatchSize::SmallInput,
        )
    });
}

fn minute_study(c: &mut Criterion) {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let db = MotionDb::load(&root.join("mocap")).expect("the shipped database");
    let loaded = LoadedScore::load(&root.join("scores/minute-study.ron")).expect("demo score");
    let r = render(&loaded, &db, &RenderParams::default(), &mut |_| true).expect("renders");
    let seconds = r.audio.frames() as f64 / f64::from(r.audio.rate_hz);
    // Build the heads once (a process does it on its first render).
    render_sound(&r.kit, &r.drums, 1.0, SoundModel::Modal).expect("sound");
    c.bench_function(
        "modal sound of the one-minute study (64 s, full band)",
        |b| b.iter(|| render_sound(&r.kit, &r.drums, seconds, SoundModel::Modal).expect("sound")),
    );
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20);
    targets = bench, minute_study
}
criterion_main!(benches);
