//! Simulation speed: one semi-implicit Euler step (articulated-body algorithm) of the full
//! 11-segment body at dt = 1e-4 s, with joint torques and a drum force on a stick tip.
//! `cargo bench --bench dynamics`.

use criterion::{Criterion, black_box, criterion_group, criterion_main};
use glam::{DQuat, DVec3};
use timpanist::body::dynamics::{Dynamics, ExternalForce, State};
use timpanist::body::model::BodyModel;
use timpanist::body::{JOINT_COUNT, Joint};
use timpanist::kit::Side;

fn bench(c: &mut Criterion) {
    let mut dynamics = Dynamics::new(BodyModel::default());
    let mut state = State::rest();
    for i in 0..JOINT_COUNT {
        let k = i as f64;
        state.q[i] = DQuat::from_scaled_axis(DVec3::new(0.3, -0.2 * k.sin(), 0.1 * k.cos()));
        state.w[i] = DVec3::new(0.5 * k.cos(), 0.4, -0.3 * k.sin());
    }
    let tau = [DVec3::new(0.5, -0.2, 0.1); JOINT_COUNT];
    let (tip, _) = dynamics.tip(&state, Side::Right);
    let drum = [ExternalForce {
        segment: Joint::GripR.index(),
        point_world: tip,
        force_world: DVec3::new(0.0, 0.0, 20.0),
    }];
    c.bench_function("dynamics step (11 segments, dt = 1e-4 s)", |b| {
        b.iter(|| {
            let mut s = state.clone();
            dynamics.step(&mut s, black_box(&tau), black_box(&drum), 1e-4);
            black_box(s)
        })
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
