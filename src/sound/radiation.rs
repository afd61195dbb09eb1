//! How strongly each mode of a head is heard: the far-field pressure per unit modal
//! velocity from the Rayleigh integral of a baffled circular membrane (the kettle closes
//! the head's back), toward a listener at polar angle ψ from the head's normal, averaged
//! over azimuth (see [`directivity`]):
//!
//! P_k ∝ ω_k · ∫ Φ_k(r, θ) e^{i k r sin ψ cos(θ − φ)} dA
//!     = ω_k · 2π · A_m(φ) · ∫₀^a J_m(α r) J_m(β r) r dr,  α = j_mn/a, β = k sin ψ,
//!
//! with A_m the azimuthal factor (1 for m = 0, 1/√2 otherwise), and the radial integral in closed form
//! (Lommel, J_m(αa) = 0): −a·α·J_{m−1}(j_mn)·J_m(βa) / (α² − β²). A timpani head is
//! subsonic (membrane waves ≈ 90 m/s against 343 m/s in air, so β < α always): the
//! axisymmetric modes radiate as monopoles (the low thump of the (0,1)), the others as
//! multipoles whose strength falls as (βa)^m, and modes with many nodal diameters are
//! nearly silent. The i^m phase of each multipole is folded to a sign
//! (−1)^⌊m/2⌋, a real gain per mode.

use crate::drum::HeadModes;
use crate::drum::bessel::{EXACT_ZERO_LIMIT, bessel_j};
use crate::drum::modes::{HeadMode, SOUND_SPEED_MPS};
use std::f64::consts::{PI, TAU};

/// The listener's polar angle from the head's normal: a close microphone 45° above the
/// plane of the head, rad.
pub const LISTENER_POLAR_RAD: f64 = PI / 4.0;

/// A mode's azimuthal factor as heard: 1 for m = 0, else the RMS of cos(mφ) over the
/// listener's azimuth, 1/√2 — recordings hear a head through several microphones and a
/// room, not from one point on a nodal pattern (one point put the (2,1) and (3,1) of a
/// playing-spot stroke 8–14 dB down by geometry alone).
pub fn directivity(mode: &HeadMode) -> f64 {
    if mode.m == 0 {
        1.0
    } else {
        std::f64::consts::FRAC_1_SQRT_2
    }
}

/// J_{m−1}(j_mn): exact below [`EXACT_ZERO_LIMIT`], else Debye's J'_m(j) ≈ (−1)^n √(2w/π)/j
/// (J_{m−1} = J'_m at a zero of J_m).
fn j_prev_at_zero(mode: &HeadMode) -> f64 {
    let (m, j) = (mode.m, mode.bessel_zero());
    if j < EXACT_ZERO_LIMIT {
        return if m == 0 {
            -bessel_j(1, j)
        } else {
            bessel_j(m - 1, j)
        };
    }
    let w = (j * j - f64::from(m).powi(2)).max(0.0).sqrt();
    let sign = if mode.n.is_multiple_of(2) { 1.0 } else { -1.0 };
    sign * (2.0 * w / PI).sqrt() / j
}

/// ∫₀^a J_m(α r) J_m(β r) r dr for `mode` of a head of radius `a` (α = j_mn/a) and an
/// in-plane wavenumber `beta` (1/m): Lommel's closed form, −a·α·J_{m−1}(j_mn)·J_m(βa) /
/// (α² − β²), m². A timpani head is subsonic (β < α), so the denominator never vanishes.
pub fn radial_overlap(mode: &HeadMode, a: f64, beta: f64) -> f64 {
    let alpha = mode.bessel_zero() / a;
    -a * alpha * j_prev_at_zero(mode) * bessel_j(mode.m, beta * a)
        / (alpha * alpha - beta * beta).max(1e-9 * alpha * alpha)
}

/// (−1)^⌊m/2⌋: the sign a multipole's phase (±i)^m folds to — of the real weight for m
/// even, of the quarter-period-shifted one for m odd.
pub fn multipole_sign(m: u32) -> f64 {
    if (m / 2).is_multiple_of(2) { 1.0 } else { -1.0 }
}

/// Far-field pressure per unit modal velocity of each mode of `head` toward the listener
/// (arbitrary common unit: the calibration sets the level).
pub fn weights(head: &HeadModes) -> Vec<f64> {
    let a = head.radius_m();
    head.modes()
        .iter()
        .map(|mode| {
            let m = mode.m;
            let omega = TAU * mode.freq_hz;
            let beta = omega / SOUND_SPEED_MPS * LISTENER_POLAR_RAD.sin();
            let angular = directivity(mode);
            // J_m(x) for m > x + 25 is below 1e-7 of its peak: silent.
            if f64::from(m) > beta * a + 25.0 {
                return 0.0;
            }
            let radial = radial_overlap(mode, a, beta);
            omega * TAU * angular * radial * multipole_sign(m)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drum::FrequencySource;
    use crate::kit::Kit;

    /// The closed-form radial integral equals a quadrature of ∫J_m(αr)J_m(βr)r dr; the
    /// (0,1) radiates more than the (1,1) per unit velocity at the same frequency scale;
    /// high-m modes are nearly silent.
    #[test]
    fn rayleigh_weights() {
        let drum = &Kit::standard().drums[2];
        let head = HeadModes::below_hz(drum, FrequencySource::Measured, 3000.0).unwrap();
        let a = head.radius_m();
        for mode in head
            .modes()
            .iter()
            .filter(|k| k.bessel_zero() < 20.0)
            .take(12)
        {
            let (m, alpha) = (mode.m, mode.bessel_zero() / a);
            let beta = TAU * mode.freq_hz / SOUND_SPEED_MPS * LISTENER_POLAR_RAD.sin();
            let n = 4000;
            let quad: f64 = (0..n)
                .map(|i| {
                    let r = (i as f64 + 0.5) / n as f64 * a;
                    bessel_j(m, alpha * r) * bessel_j(m, beta * r) * r * a / n as f64
                })
                .sum();
            let closed = -a * alpha * j_prev_at_zero(mode) * bessel_j(m, beta * a)
                / (alpha * alpha - beta * beta);
            assert!(
                (quad - closed).abs() < 1e-6 * a * a,
                "({m},{}): {quad} vs {closed}",
                mode.n
            );
        }
        let w = weights(&head);
        let of = |m: u32, n: u32| {
            head.modes()
                .iter()
                .zip(&w)
                .filter(|(k, _)| (k.m, k.n) == (m, n))
                .map(|(k, w)| w.abs() / k.freq_hz)
                .fold(0.0, f64::max)
        };
        assert!(of(0, 1) > 3.0 * of(1, 1), "{} vs {}", of(0, 1), of(1, 1));
        let top = w.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let high_m = head
            .modes()
            .iter()
            .zip(&w)
            .filter(|(k, _)| k.m >= 30)
            .fold(0.0f64, |m, (_, x)| m.max(x.abs()));
        assert!(high_m < 1e-6 * top, "{high_m} vs {top}");
    }
}
