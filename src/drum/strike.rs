//! A scripted stick for tests, benchmarks and the CLI: a point mass equal to the mallet's
//! effective mass, thrown down at a head with a given speed under gravity and stepped
//! through [`DrumSet::step`] (semi-implicit Euler), so the contact and the rebound come
//! from the two-way coupling alone. Also the dynamics → impact-speed map.
//!
//! The stick's mass is the mallet's effective mass at the tip ([`effective_mass_kg`]); the
//! body simulation supplies its own (arm-loaded) dynamics instead.

pub use super::contact::effective_mass_kg;
use super::set::DrumSet;
use crate::kit::{Drum, Mallet, Side};
use crate::score::Dynamic;
use glam::DVec3;

/// Gravity, m/s² (down).
pub const GRAVITY_MPS2: f64 = 9.81;
/// Simulation rate of the body and drum, Hz (seed 000 runs HIMC at 10 kHz).
pub const SIM_RATE_HZ: f64 = 10_000.0;
/// The usual playing spot as a fraction of the head radius from the centre: between "a
/// quarter of the diameter in from the rim" (0.5) and "a third of the radius in" (0.67)
/// (guide §5).
pub const PLAYING_SPOT_FRACTION: f64 = 0.6;
/// Downward tip speed at impact for velocity 1 (MIDI 127), m/s: impact speed =
/// `FULL_SPEED_MPS` × velocity, so pp 2.08, p 3.09, mp 4.03, mf 5.04, f 6.05, ff 7.06 m/s
/// (chosen so a free mf–ff stroke on the 26-inch drum peaks at 62–107 N as seed 000
/// reports, on the 100-mode head: its local compliance asks faster strokes than real
/// players' 1.5–3.7 m/s for those forces, see README "Strokes").
pub const FULL_SPEED_MPS: f64 = 8.0;

/// Peak contact force a stroke of MIDI velocity 0 aims at, N, and the increase to
/// velocity 127 (seed 000 measured 62–107 N strikes): pp 33 … ff 99 N. The renderer's
/// compensation adapts each stroke toward it, and the sound's reference strokes meet it.
pub const FORCE_AT_SILENCE_N: f64 = 5.0;
pub const FORCE_RANGE_N: f64 = 107.0;

/// The peak contact force aimed at for a stroke of `dynamic`, N.
pub fn aimed_force_n(dynamic: Dynamic) -> f64 {
    FORCE_AT_SILENCE_N + FORCE_RANGE_N * dynamic.velocity().clamp(0.0, 1.0)
}

/// Downward impact speed for a dynamic, m/s (linear in MIDI velocity, see [`FULL_SPEED_MPS`]).
pub fn impact_speed_mps(dynamic: Dynamic) -> f64 {
    FULL_SPEED_MPS * dynamic.velocity().clamp(0.0, 1.0)
}

/// A stick tip as a point mass.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScriptedStick {
    /// Effective mass at the tip, kg.
    pub mass_kg: f64,
    /// Tip (felt ball centre), performer frame, m.
    pub position: DVec3,
    /// m/s.
    pub velocity: DVec3,
    /// Constant downward push of the hand, N (0 for a free stroke).
    pub push_n: f64,
}

impl ScriptedStick {
    /// A stick held still 2.5 m up, 1 m behind the player: far from every head.
    pub fn parked(mallet: &Mallet) -> ScriptedStick {
        ScriptedStick {
            mass_kg: effective_mass_kg(mallet),
            position: DVec3::new(0.0, -1.0, 2.5),
            velocity: DVec3::ZERO,
            push_n: 0.0,
        }
    }

    /// A stick whose felt ball is `gap_m` above `point` on the resting head of `drum`,
    /// moving straight down at `speed_mps`.
    pub fn above(
        drum: &Drum,
        mallet: &Mallet,
        point: DVec3,
        speed_mps: f64,
        gap_m: f64,
    ) -> ScriptedStick {
        ScriptedStick {
            mass_kg: effective_mass_kg(mallet),
            position: DVec3::new(
                point.x,
                point.y,
                drum.placement.head_height_m + mallet.head_radius_m + gap_m,
            ),
            velocity: DVec3::new(0.0, 0.0, -speed_mps),
            push_n: 0.0,
        }
    }

    /// Advance by `dt_s` under gravity, the push and the contact `force` (semi-implicit Euler).
    pub fn advance(&mut self, force: DVec3, dt_s: f64) {
        let accel =
            (force + DVec3::new(0.0, 0.0, -self.push_n)) / self.mass_kg - DVec3::Z * GRAVITY_MPS2;
        self.velocity += accel * dt_s;
        self.position += self.velocity * dt_s;
    }

    pub(crate) fn tip(&self) -> (DVec3, DVec3) {
        (self.position, self.velocity)
    }
}

/// Step `drums` and both sticks for `steps` steps from `start_s`; returns the tip force
/// history of each stick (N, +up), one entry per step.
pub fn run(
    drums: &mut DrumSet,
    sticks: &mut [ScriptedStick; 2],
    start_s: f64,
    steps: usize,
) -> [Vec<f64>; 2] {
    let dt = drums.dt_s();
    let mut history = [Vec::with_capacity(steps), Vec::with_capacity(steps)];
    for k in 0..steps {
        let t = start_s + k as f64 * dt;
        let forces = drums.step(t, [sticks[0].tip(), sticks[1].tip()]);
        for i in 0..2 {
            sticks[i].advance(forces[i], dt);
            history[i].push(forces[i].z);
        }
    }
    history
}

/// The downward impact speed (m/s) at which a free stroke of `mallet` at `point` on the
/// single drum of `kit` peaks at `force_n` (within 0.5 %, secant on the speed from
/// [`FULL_SPEED_MPS`]-scaled guesses; each trial a fresh head at rest). Deterministic.
pub fn speed_for_force(kit: &crate::kit::Kit, config: &super::ModeConfig, force_n: f64) -> f64 {
    let (drum, mallet) = (&kit.drums[0], &kit.mallets[0]);
    let point = drum.point_on_head(PLAYING_SPOT_FRACTION, 0.0);
    let peak = |speed: f64| {
        let mut drums = DrumSet::new(kit, mallet, config, 1.0 / SIM_RATE_HZ)
            .expect("a kit that plays is valid");
        scripted(&mut drums, drum, mallet, Side::Right, point, speed, 0.02);
        drums
            .contacts()
            .iter()
            .map(|c| c.peak_force_n)
            .fold(0.0, f64::max)
    };
    let (mut v0, mut v1) = (0.04 * force_n, 0.06 * force_n);
    let (mut f0, mut f1) = (peak(v0), peak(v1));
    for _ in 0..20 {
        if (f1 / force_n - 1.0).abs() < 0.005 || (f1 - f0).abs() < 1e-9 {
            break;
        }
        let next = (v1 + (force_n - f1) * (v1 - v0) / (f1 - f0)).clamp(0.1, 30.0);
        (v0, f0) = (v1, f1);
        v1 = next;
        f1 = peak(v1);
    }
    v1
}

/// One free stroke by `side` at `point` on drum `drum` of the set, starting 1 mm above
/// the head at `speed_mps`, the other stick parked; runs `duration_s` from t = 0. As the
/// stick rises clear of the head after touching it the player takes it away (it is
/// parked), so it does not fall back for a second stroke. Returns the two sticks after the run.
pub fn scripted(
    drums: &mut DrumSet,
    drum: &Drum,
    mallet: &Mallet,
    side: Side,
    point: DVec3,
    speed_mps: f64,
    duration_s: f64,
) -> [ScriptedStick; 2] {
    let mut sticks = [ScriptedStick::parked(mallet), ScriptedStick::parked(mallet)];
    let i = match side {
        Side::Left => 0,
        Side::Right => 1,
    };
    sticks[i] = ScriptedStick::above(drum, mallet, point, speed_mps, 0.001);
    let steps = (duration_s / drums.dt_s()).round() as usize;
    let dt = drums.dt_s();
    let mut touched = false;
    for k in 0..steps {
        let t = k as f64 * dt;
        let forces = drums.step(t, [sticks[0].tip(), sticks[1].tip()]);
        for (stick, f) in sticks.iter_mut().zip(forces) {
            stick.advance(f, dt);
        }
        // Taken away once clearly leaving: moving up and 5 mm above the resting head
        // (a brief double touch while the head swings back still counts).
        let clear =
            sticks[i].position.z - mallet.head_radius_m > drum.placement.head_height_m + 0.005;
        if forces[i].z > 0.0 {
            touched = true;
        } else if touched && sticks[i].velocity.z > 0.0 && clear {
            sticks[i] = ScriptedStick::parked(mallet);
        }
    }
    sticks
}
