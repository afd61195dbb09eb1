//! The Hertz law of the felt mallet on the head (seed 000 eq. 6) with the felt's
//! hysteresis: F = k·c^α·(1 + λ·ċ) for a compression c > 0 between the felt ball and the
//! (displaced) head surface, 0 otherwise (Hunt & Crossley 1975: the loss λ, s/m, makes the
//! felt push harder while it is compressed than while it recovers, and the force still
//! starts and ends at zero; never negative, the felt does not pull). Felt is a stiffening,
//! lossy spring (guide §5; Stulov's hereditary model for piano hammers behaves so over a
//! stroke). The compression is capped at the felt ball's radius (beyond it the stick's core
//! would meet the head), so a tip driven far below the head gets a large but finite force.
//!
//! Effective mass at the tip ([`effective_mass_kg`]): the mallet pivots about the grip; with
//! a third of its mass in the felt head at the tip and two thirds in a uniform shaft
//! (I/L² = m_shaft/3), m_eff = m/3 + (2m/3)/3 = 5m/9.

use super::DrumError;
use crate::kit::Mallet;

/// Effective mass of a mallet at its tip when it pivots about the grip, kg (5/9 of its mass).
pub fn effective_mass_kg(mallet: &Mallet) -> f64 {
    mallet.mass_kg * 5.0 / 9.0
}

/// One mallet's contact law.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HertzContact {
    /// k, N/m^α.
    pub stiffness: f64,
    /// α.
    pub exponent: f64,
    /// Felt ball radius, m (the stick tip is the ball's centre).
    pub ball_radius_m: f64,
    /// Hunt–Crossley loss λ of the felt, s/m (0: elastic).
    pub loss_s_per_m: f64,
}

impl HertzContact {
    /// The law of a kit mallet.
    pub fn of(mallet: &Mallet) -> Result<HertzContact, DrumError> {
        let ok = mallet.felt_stiffness.is_finite()
            && mallet.felt_stiffness > 0.0
            && mallet.head_radius_m > 0.0
            && mallet.mass_kg > 0.0
            && (1.0..=4.0).contains(&mallet.contact_exponent)
            && (0.0..=10.0).contains(&mallet.felt_loss_s_per_m);
        if !ok {
            return Err(DrumError::InvalidMallet(mallet.name.clone()));
        }
        Ok(HertzContact {
            stiffness: mallet.felt_stiffness,
            exponent: mallet.contact_exponent,
            ball_radius_m: mallet.head_radius_m,
            loss_s_per_m: mallet.felt_loss_s_per_m,
        })
    }

    /// Force for compression `c` (m; ≤ 0 or NaN means apart), N, ≥ 0.
    pub fn force(&self, c: f64) -> f64 {
        if c > 0.0 {
            self.stiffness * c.min(self.ball_radius_m).powf(self.exponent)
        } else {
            0.0
        }
    }
}

impl HertzContact {
    /// The force F ≥ 0 held over one step of `dt_s` that satisfies
    /// F = k·c^α·max(0, 1 + λ·ċ) with the mid-step compression c = c0 − compliance·F and
    /// its rate ċ = 2·(c − c_start)/dt (the compression at the step's start `c_start`, m):
    /// the contact force when the compression itself yields under it (m, m/N). 0 when
    /// c0 ≤ 0. With λ = 0 it is the elastic F = k·c^α.
    pub fn solve(&self, c0: f64, compliance: f64, c_start: f64, dt_s: f64) -> f64 {
        if c0.is_nan() || c0 <= 0.0 {
            return 0.0;
        }
        let rate_gain = 2.0 * self.loss_s_per_m / dt_s;
        // The force for a mid-step compression c, and its slope dF/dc.
        let law = |c: f64| -> (f64, f64) {
            if c <= 0.0 {
                return (0.0, 0.0);
            }
            let capped = c.min(self.ball_radius_m);
            let elastic = self.stiffness * capped.powf(self.exponent);
            let loss = 1.0 + rate_gain * (c - c_start);
            if loss <= 0.0 {
                return (0.0, 0.0);
            }
            let elastic_slope = if c < self.ball_radius_m {
                self.exponent * elastic / c
            } else {
                0.0
            };
            (elastic * loss, elastic_slope * loss + elastic * rate_gain)
        };
        let residual = |f: f64| f - law(c0 - compliance * f).0;
        // The compression cannot go below 0, so F ≤ c0/compliance.
        let (mut lo, mut hi) = (0.0, law(c0).0);
        if compliance.is_nan() || compliance <= 0.0 || hi <= 0.0 {
            return hi.max(0.0);
        }
        hi = hi.min(c0 / compliance);
        // residual is increasing in F: Newton steps kept inside a shrinking bracket
        // (bisection when Newton leaves it), to a relative 1e-12.
        let mut f = 0.5 * (lo + hi);
        for _ in 0..100 {
            let r = residual(f);
            if r > 0.0 {
                hi = f;
            } else {
                lo = f;
            }
            let slope = 1.0 + compliance * law(c0 - compliance * f).1;
            let mut next = f - r / slope;
            if !(next > lo && next < hi) {
                next = 0.5 * (lo + hi);
            }
            if (next - f).abs() <= 1e-12 * f.abs().max(1e-9) || hi - lo <= 1e-12 * hi {
                return next;
            }
            f = next;
        }
        f
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kit::Kit;

    /// F = k·c^α for small c, zero when apart or NaN, finite and capped when driven deep.
    #[test]
    fn hertz_law() {
        let law = HertzContact::of(&Kit::standard().mallets[0]).unwrap();
        let c = 0.002;
        assert!((law.force(c) - law.stiffness * c.powf(law.exponent)).abs() < 1e-9);
        assert_eq!(law.force(0.0), 0.0);
        assert_eq!(law.force(-0.01), 0.0);
        assert_eq!(law.force(f64::NAN), 0.0);
        assert_eq!(law.force(10.0), law.force(law.ball_radius_m));
        assert!(law.force(2.0 * c) > law.force(c));
        // The yielding solution satisfies its equation and is below the rigid force.
        let elastic = HertzContact {
            loss_s_per_m: 0.0,
            ..law
        };
        let (c0, s, dt) = (0.004, 2e-5, 1e-4);
        let f = elastic.solve(c0, s, c0, dt);
        assert!((f - law.force(c0 - s * f)).abs() < 1e-6 * f, "{f}");
        assert!(f > 0.0 && f < law.force(c0));
        assert_eq!(law.solve(-1e-3, s, 0.0, dt), 0.0);
        assert_eq!(law.solve(f64::NAN, s, 0.0, dt), 0.0);
        // Hysteresis: compressing (the step started 0.1 mm shallower) pushes harder than
        // the elastic law, recovering (0.1 mm deeper) less, and the equation holds.
        let s = 1e-8;
        let f = elastic.solve(c0, s, c0, dt);
        let loading = law.solve(c0, s, c0 - 1e-4, dt);
        let unloading = law.solve(c0, s, c0 + 1e-4, dt);
        assert!(loading > f && unloading < f, "{loading} {f} {unloading}");
        let c = c0 - s * loading;
        let rate = 2.0 * (c - (c0 - 1e-4)) / dt;
        let want = law.force(c) * (1.0 + law.loss_s_per_m * rate);
        assert!((loading - want).abs() < 1e-6 * want, "{loading} {want}");
        // A felt recovering faster than λ allows pushes not at all (it never pulls).
        assert_eq!(law.solve(c0, s, c0 + 0.1, dt), 0.0);
    }
}
