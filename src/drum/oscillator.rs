//! The exact (zero-order-hold) discretisation of one damped mode, q̈ + 2σq̇ + ω₀²q = u:
//! the step matrix e^{A·dt} and the held-input vector, shared by the membrane simulation
//! (10 kHz) and the modal voices (48 kHz). Its poles are exp((−σ ± iω_d)·dt), i.e. the
//! impulse-invariant two-pole resonator r = exp(−dt/τ), so it is stable for any frequency
//! and any step (seed 000 eq. 5, one decoupled mode).

use std::f64::consts::TAU;

/// One mode's step over dt in scaled coordinates x = (ω₀·q, q̇) (both m/s, so f32 storage
/// keeps its precision at any frequency): x' = A·x + B·u, u held over the step (m/s²).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModeStep {
    /// Row-major step matrix on (ω₀q, q̇).
    pub a: [[f64; 2]; 2],
    /// Response of (ω₀q, q̇) to a unit input held for one step, s.
    pub b: [f64; 2],
    /// Undamped angular frequency ω₀, rad/s (to convert ω₀q back to q).
    pub omega0: f64,
}

/// Amplitude decay time constant τ from a T60 (time to fall by 60 dB): τ = T60 / ln 1000, s.
pub fn tau_from_t60(t60_s: f64) -> f64 {
    t60_s / 1000f64.ln()
}

impl ModeStep {
    /// The exact step of a mode ringing at `freq_hz` (damped frequency) with a 60 dB decay
    /// time `t60_s`, over `dt_s`.
    pub fn new(freq_hz: f64, t60_s: f64, dt_s: f64) -> ModeStep {
        let sigma = 1.0 / tau_from_t60(t60_s);
        let wd = TAU * freq_hz;
        let w0 = (wd * wd + sigma * sigma).sqrt();
        let e = (-sigma * dt_s).exp();
        let (s, c) = (wd * dt_s).sin_cos();
        // e^{A dt} on (q, q̇): [[c + σ/ωd s, s/ωd], [−ω0²/ωd s, c − σ/ωd s]]·e.
        let a11 = e * (c + sigma / wd * s);
        let a12 = e * s / wd;
        let a21 = -e * w0 * w0 / wd * s;
        let a22 = e * (c - sigma / wd * s);
        // Held unit input: q = (1 − a11)/ω0², q̇ = a12 (the step response and its derivative).
        let b1 = (1.0 - a11) / (w0 * w0);
        let b2 = a12;
        ModeStep {
            a: [[a11, w0 * a12], [a21 / w0, a22]],
            b: [w0 * b1, b2],
            omega0: w0,
        }
    }

    /// Advance the scaled state by one step with input `u` held, m/s².
    pub fn advance(&self, x: [f64; 2], u: f64) -> [f64; 2] {
        [
            self.a[0][0] * x[0] + self.a[0][1] * x[1] + self.b[0] * u,
            self.a[1][0] * x[0] + self.a[1][1] * x[1] + self.b[1] * u,
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Free ringing decays by 60 dB in T60 and crosses zero at the given frequency.
    #[test]
    fn exact_decay_and_frequency() {
        let (f, t60, dt) = (147.0, 1.6, 1e-4);
        let step = ModeStep::new(f, t60, dt);
        // Start from a velocity kick; the envelope is e^{−t/τ}.
        let mut x = [0.0, 1.0];
        let n = (t60 / dt).round() as usize;
        let mut crossings = 0;
        let mut last = x[1];
        let mut peak_late: f64 = 0.0;
        for k in 0..n {
            x = step.advance(x, 0.0);
            if last < 0.0 && x[1] >= 0.0 {
                crossings += 1;
            }
            last = x[1];
            if k > n - (1.0 / f / dt) as usize * 2 {
                peak_late = peak_late.max(x[1].abs());
            }
        }
        let expected = f * t60;
        assert!(
            (f64::from(crossings) - expected).abs() <= 1.0,
            "{crossings}"
        );
        // The window holds the last two periods: its peak is the envelope at its start.
        let envelope = 1e-3 * (2.0 / f / tau_from_t60(t60)).exp();
        assert!(
            (peak_late / envelope - 1.0).abs() < 0.02,
            "{peak_late} vs {envelope}"
        );
    }

    /// A held unit input settles at q = 1/ω0² (the static deflection), even for a mode far
    /// above the step's Nyquist frequency (stable for any frequency).
    #[test]
    fn static_response_and_stability() {
        for f in [50.0, 4000.0, 37_000.0] {
            let step = ModeStep::new(f, 0.05, 1e-4);
            let mut x = [0.0, 0.0];
            for _ in 0..20_000 {
                x = step.advance(x, 1.0);
                assert!(x[0].is_finite() && x[1].abs() < 1.0);
            }
            let q = x[0] / step.omega0;
            assert!((q * step.omega0.powi(2) - 1.0).abs() < 1e-6, "{f}: {q}");
        }
    }
}
