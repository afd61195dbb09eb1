//! The Hertz law of the felt mallet on the head (seed 000 eq. 6): F = k·c^α for a
//! compression c > 0 between the felt ball and the (displaced) head surface, 0 otherwise.
//! The compression is capped at the felt ball's radius (beyond it the stick's core would
//! meet the head), so a tip driven far below the head gets a large but finite force.
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
}

impl HertzContact {
    /// The law of a kit mallet.
    pub fn of(mallet: &Mallet) -> Result<HertzContact, DrumError> {
        let ok = mallet.felt_stiffness.is_finite()
            && mallet.felt_stiffness > 0.0
            && mallet.head_radius_m > 0.0
            && mallet.mass_kg > 0.0
            && (1.0..=4.0).contains(&mallet.contact_exponent);
        if !ok {
            return Err(DrumError::InvalidMallet(mallet.name.clone()));
        }
        Ok(HertzContact {
            stiffness: mallet.felt_stiffness,
            exponent: mallet.contact_exponent,
            ball_radius_m: mallet.head_radius_m,
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
    /// The force F ≥ 0 that satisfies F = k·c^α with c = c0 − compliance·F (m, m/N): the
    /// contact force when the compression itself yields under it. 0 when c0 ≤ 0.
    pub fn solve(&self, c0: f64, compliance: f64) -> f64 {
        if c0.is_nan() || c0 <= 0.0 {
            return 0.0;
        }
        let residual = |f: f64| f - self.force(c0 - compliance * f);
        // The compression cannot go below 0, so F ≤ c0/compliance.
        let (mut lo, mut hi) = (0.0, self.force(c0));
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
            let c = c0 - compliance * f;
            let slope = if c > 0.0 && c < self.ball_radius_m {
                1.0 + compliance * self.exponent * self.stiffness * c.powf(self.exponent - 1.0)
            } else {
                1.0
            };
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
        let (c0, s) = (0.004, 2e-5);
        let f = law.solve(c0, s);
        assert!((f - law.force(c0 - s * f)).abs() < 1e-6 * f, "{f}");
        assert!(f > 0.0 && f < law.force(c0));
        assert_eq!(law.solve(-1e-3, s), 0.0);
        assert_eq!(law.solve(f64::NAN, s), 0.0);
    }
}
