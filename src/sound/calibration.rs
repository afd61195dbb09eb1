//! The modal sound's calibration on recorded timpani (`kits/sound/modal.ron`, written by
//! `timpanist sound fit`, see [`super::fit`]): a correction of the Rayleigh radiation
//! weights (dB) per octave of a mode's *order*, its frequency over the head's (1,1)
//! ([`ORDER_CENTRES`]: what the model misses in the excitation and radiation of a head's
//! higher modes scales with their place in its spectrum, not with absolute frequency, so
//! one correction serves the low and the high drums), the T60 of the modes the kit does
//! not list per octave band (s), the T60 of the listed (m, n) partials, and the fit's
//! residuals. Values between centres are interpolated linearly in log frequency and held
//! flat beyond the ends.
//! The shipped file is embedded in the program.

use super::analysis::OCTAVE_CENTRES_HZ;
use crate::base::ron_file::{self, FileError};
use serde::{Deserialize, Serialize};
use std::path::Path;
use std::sync::OnceLock;

/// Centres of the radiation correction's octaves of mode order f/f11.
pub const ORDER_CENTRES: [f64; 7] = [0.5, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0];

/// The shipped calibration's text.
pub const SHIPPED: &str = include_str!("../../kits/sound/modal.ron");

/// A listed partial's decay.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PartialDecay {
    pub m: u32,
    pub n: u32,
    /// s.
    pub t60_s: f64,
}

/// One recording's fit residual: model minus recording per octave band, dB.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Residual {
    pub recording: String,
    pub bands_db: [f64; 7],
}

/// See the module docs.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Calibration {
    pub version: u32,
    /// The recordings it was fitted to.
    pub fitted_from: Vec<String>,
    /// Correction of the radiation weights per octave of mode order f/f11
    /// ([`ORDER_CENTRES`]), dB.
    pub radiation_by_order_db: [f64; 7],
    /// T60 of unlisted modes per octave band, s.
    pub t60_s: [f64; 7],
    /// T60 of axisymmetric (m = 0) modes as a share of the others' (radiation damps them).
    pub axisymmetric_t60_share: f64,
    /// Correction of the unlisted axisymmetric modes' radiation (the (0,1)'s low thump
    /// below the (1,1)), dB (calibrations written before it read 0).
    #[serde(default)]
    pub axisymmetric_db: f64,
    /// T60 of the listed partials.
    pub partials: Vec<PartialDecay>,
    /// The fit's residuals.
    pub residuals: Vec<Residual>,
}

impl Calibration {
    /// The shipped calibration.
    pub fn shipped() -> &'static Calibration {
        static CAL: OnceLock<Calibration> = OnceLock::new();
        CAL.get_or_init(|| ron::from_str(SHIPPED).expect("kits/sound/modal.ron is valid"))
    }

    /// Write it atomically.
    pub fn save(&self, path: &Path) -> Result<(), FileError> {
        let text = format!(
            "// The modal sound's calibration on recorded timpani, written by `timpanist sound fit`\n\
             // (README \"Sound calibration\"). Radiation correction (dB) per octave of mode order f/f11\n\
             // (0.5 ... 32); per octave band 63 Hz - 4 kHz the T60 of unlisted modes (s); listed\n\
             // partials' T60; residual = model - recording per octave band (dB).\n{}",
            ron_file::to_pretty(self)
        );
        ron_file::write_atomic(path, text.as_bytes())
    }

    /// Radiation correction of the unlisted axisymmetric modes, linear gain.
    pub fn axisymmetric_gain(&self) -> f64 {
        10f64.powf(self.axisymmetric_db / 20.0)
    }

    /// Radiation correction of a mode of order `f_over_f11` (its frequency over the
    /// head's (1,1)), linear gain.
    pub fn radiation_gain(&self, f_over_f11: f64) -> f64 {
        let at = f_over_f11 / ORDER_CENTRES[0] * OCTAVE_CENTRES_HZ[0];
        10f64.powf(interpolate(&self.radiation_by_order_db, at) / 20.0)
    }

    /// Where a fit starts: no radiation correction, the guide's recorded decay (−20 dB in
    /// about 0.7 s, T60 ≈ 2 s) in every band, axisymmetric modes at a tenth of that
    /// (the (0,1) radiates as a monopole and dies fast), no listed partials.
    pub fn initial() -> Calibration {
        Calibration {
            version: 1,
            fitted_from: Vec::new(),
            radiation_by_order_db: [0.0; 7],
            t60_s: [2.0; 7],
            axisymmetric_t60_share: 0.1,
            axisymmetric_db: 0.0,
            partials: Vec::new(),
            residuals: Vec::new(),
        }
    }

    /// The listed partial (m, n), if the calibration has it.
    pub fn partial(&self, m: u32, n: u32) -> Option<&PartialDecay> {
        self.partials.iter().find(|p| (p.m, p.n) == (m, n))
    }

    /// T60 of a mode (m, n) at `hz`: the listed partial's when the calibration has it,
    /// else the band law (× the axisymmetric share for m = 0), s.
    pub fn t60_s(&self, m: u32, n: u32, hz: f64) -> f64 {
        if let Some(p) = self.partial(m, n) {
            return p.t60_s;
        }
        let t = interpolate(&self.t60_s, hz);
        if m == 0 {
            t * self.axisymmetric_t60_share
        } else {
            t
        }
    }
}

/// Piecewise-linear interpolation in log2 frequency over the octave-band centres.
pub fn interpolate(values: &[f64; 7], hz: f64) -> f64 {
    let x = (hz.max(1.0) / OCTAVE_CENTRES_HZ[0]).log2();
    let i = x.floor();
    if i < 0.0 {
        return values[0];
    }
    let i = i as usize;
    if i >= values.len() - 1 {
        return values[values.len() - 1];
    }
    let f = x - i as f64;
    values[i] + f * (values[i + 1] - values[i])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The shipped file parses, has positive decays, and interpolates between centres.
    #[test]
    fn shipped_calibration_is_sane() {
        let c = Calibration::shipped();
        assert!(c.t60_s.iter().all(|t| *t > 0.0 && t.is_finite()));
        assert!(c.partials.iter().all(|p| p.t60_s > 0.0));
        let v = [0.0, 6.0, 6.0, 6.0, 6.0, 6.0, 12.0];
        assert_eq!(interpolate(&v, 10.0), 0.0);
        assert!((interpolate(&v, 63.0 * 2f64.sqrt()) - 3.0).abs() < 1e-9);
        assert_eq!(interpolate(&v, 20_000.0), 12.0);
    }
}
