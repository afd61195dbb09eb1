//! The modes a head sounds with: every mode orientation below [`SOUND_MAX_HZ`] (the top of
//! the 4 kHz octave band, with margin), weighted by its far-field radiation toward the
//! listener ([`super::radiation`]) and the calibration's correction, with the calibrated
//! T60; the kit's listed partials take the kit's gain relative to the (1,1)'s Rayleigh
//! weight instead (their balance is what a timpani's pitch is heard from, guide §5: the
//! (2,1) is often as strong as the (1,1)). Modes more than [`AUDIBLE_FLOOR_DB`] below the head's loudest are left out, and
//! above [`DENSE_FROM_HZ`], where modes crowd (their number grows with f²), each
//! 1/[`BINS_PER_OCTAVE`]-octave bin keeps its [`KEEP_PER_BIN`] strongest radiators, scaled
//! up so the bin radiates the same energy (√(Σ w²/Σ kept w²)).
//!
//! Each voice also carries its glide weight: a stroke stretches the head film, and the
//! mean tension rises by ΔT = E·h/(2(1 − ν)·A) · ∫|∇u|² dA (Kirchhoff–Carrier; Avanzini &
//! Marogna 2010), raising every frequency by δ = ΔT/(2T); with u = Σ q_k Φ_k,
//! ∫|∇u|² dA = Σ q_k² (j_k/a)² ∫Φ_k² dA, averaged over a cycle.

use super::calibration::Calibration;
use super::radiation;
use super::voices::Voice;
use crate::drum::{DrumError, FrequencySource, HeadModes, Orientation};
use crate::kit::Drum;
use glam::DVec2;

/// The head film for the pitch glide: polyester (Mylar) 0.19 mm (7.5 mil) thick,
/// Young's modulus 4.5 GPa, Poisson's ratio 0.38.
pub const HEAD_YOUNG_PA: f64 = 4.5e9;
pub const HEAD_THICKNESS_M: f64 = 1.9e-4;
pub const HEAD_POISSON: f64 = 0.38;
/// The share of the stretch that tensions the playing area: the film is not clamped at
/// the rim but wraps a flesh hoop over the kettle's bearing edge, and the collar and hoop
/// take up the rest. An estimate, not a measurement: chosen so an ff stroke on the 26-inch
/// drum in D3 (3890 N/m) glides ≈ 0.7 % and a p stroke ≈ 0.15 % (`timpanist sound analyse`,
/// 10–70 ms against 0.5–0.6 s; a clamped film, share 1, glided several %).
pub const HEAD_STRETCH_SHARE: f64 = 0.45;

/// Highest mode frequency that sounds, Hz.
pub const SOUND_MAX_HZ: f64 = 6000.0;
/// Radiation below the head's loudest mode by more than this is left out, dB.
pub const AUDIBLE_FLOOR_DB: f64 = 50.0;
/// Above this frequency modes are thinned per bin, Hz.
pub const DENSE_FROM_HZ: f64 = 800.0;
/// Thinning bins per octave.
pub const BINS_PER_OCTAVE: f64 = 6.0;
/// Modes kept per thinning bin.
pub const KEEP_PER_BIN: usize = 6;

/// A head's sounding modes and their voices (gains in output units per m/s of modal
/// velocity, before the model's overall calibration).
#[derive(Clone, Debug)]
pub struct SoundHead {
    /// The sounding modes only, in voice order.
    pub modes: HeadModes,
    pub voices: Vec<Voice>,
}

impl SoundHead {
    /// The sounding modes of `drum` (frequencies from `source`) under `calibration`.
    pub fn new(
        drum: &Drum,
        source: FrequencySource,
        calibration: &Calibration,
    ) -> Result<SoundHead, DrumError> {
        let mut modes = HeadModes::below_hz(drum, source, SOUND_MAX_HZ)?;
        let mut weights = radiation::weights(&modes);
        let w11 = modes
            .modes()
            .iter()
            .zip(&weights)
            .find(|(k, _)| (k.m, k.n, k.orientation) == (1, 1, Orientation::Cos))
            .map_or(1.0, |(_, w)| w.abs());
        for (mode, w) in modes.modes().iter().zip(weights.iter_mut()) {
            if mode.listed {
                *w = w11 * mode.gain * radiation::directivity(mode);
            }
        }
        let loudest = weights.iter().fold(0.0f64, |m, w| m.max(w.abs()));
        let floor = loudest * 10f64.powf(-AUDIBLE_FLOOR_DB / 20.0);
        // (mode index, weight, energy scale) of the modes that sound.
        let mut chosen: Vec<(usize, f64, f64)> = Vec::new();
        let bin_of = |hz: f64| ((hz / DENSE_FROM_HZ).log2() * BINS_PER_OCTAVE).floor() as i64;
        let mut dense: std::collections::BTreeMap<i64, Vec<(usize, f64)>> = Default::default();
        for (k, (mode, &w)) in modes.modes().iter().zip(&weights).enumerate() {
            if w.abs() < floor || w == 0.0 {
                continue;
            }
            if mode.freq_hz < DENSE_FROM_HZ {
                chosen.push((k, w, 1.0));
            } else {
                dense.entry(bin_of(mode.freq_hz)).or_default().push((k, w));
            }
        }
        for (_, mut bin) in dense {
            let total: f64 = bin.iter().map(|(_, w)| w * w).sum();
            bin.sort_by(|a, b| b.1.abs().total_cmp(&a.1.abs()).then(a.0.cmp(&b.0)));
            bin.truncate(KEEP_PER_BIN);
            let kept: f64 = bin.iter().map(|(_, w)| w * w).sum();
            let scale = (total / kept).sqrt();
            chosen.extend(bin.into_iter().map(|(k, w)| (k, w, scale)));
        }
        chosen.sort_by_key(|c| c.0);
        // Tension modulation (module docs): δ = κ·Σ (j_k/a)²·N_k·⟨q_k²⟩ with
        // ⟨q²⟩ = (x1² + x2²)/(2ω²) and N_k = ∫Φ_k² dA.
        let (a, mem) = (drum.radius_m(), &drum.membrane);
        let kappa = HEAD_STRETCH_SHARE * HEAD_YOUNG_PA * HEAD_THICKNESS_M
            / (4.0 * (1.0 - HEAD_POISSON) * std::f64::consts::PI * a * a * mem.tension_n_per_m);
        let stretch = |mode: &crate::drum::HeadMode| {
            let omega = std::f64::consts::TAU * mode.freq_hz;
            (mode.bessel_zero() / a).powi(2) * mode.area_m2 / (2.0 * omega * omega)
        };
        let f11 = drum.tuning.hz();
        let voices = chosen
            .iter()
            .map(|&(k, w, scale)| {
                let mode = &modes.modes()[k];
                let axisymmetric = mode.m == 0 && !mode.listed;
                let t60_s = calibration.t60_s(mode.m, mode.n, mode.freq_hz);
                let radiated = if mode.listed {
                    w
                } else {
                    let own = if axisymmetric {
                        calibration.axisymmetric_gain()
                    } else {
                        1.0
                    };
                    w * scale * calibration.radiation_gain(mode.freq_hz / f11) * own
                };
                Voice {
                    freq_hz: mode.freq_hz,
                    // An axisymmetric mode dies at least as fast as its own radiation
                    // damps it.
                    t60_s: if axisymmetric {
                        t60_s.min(mode.t60_s)
                    } else {
                        t60_s
                    },
                    glide: kappa * stretch(mode),
                    // Over ω_k: the mix differentiates (the head radiates its
                    // acceleration), giving w at the mode's own frequency.
                    gain: radiated / (std::f64::consts::TAU * mode.freq_hz),
                }
            })
            .collect();
        let keep: Vec<usize> = chosen.iter().map(|c| c.0).collect();
        modes.retain_indices(&keep);
        Ok(SoundHead { modes, voices })
    }

    /// Each sounding mode's shape at a head-local point, into `out` (voice order).
    pub fn shapes_at(&self, local: DVec2, out: &mut [f64]) {
        self.modes.shapes_at(local, out);
    }
}
