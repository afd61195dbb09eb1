//! Bessel functions of the first kind J_m (integer order) and their zeros j_mn: the radial
//! part of the circular-membrane mode shapes J_m(j_mn·r/a) (seed 000 eq. 5's
//! modal shapes for a circular head).
//!
//! J_m(x) is evaluated by Miller's backward recurrence, J_{k−1} = (2k/x)·J_k − J_{k+1},
//! started well above max(m, x) and normalised by J₀ + 2·ΣJ_{2k} = 1 (stable for every
//! order; Numerical Recipes §6.5): some 60–400 multiply-adds where the integral
//! J_m(x) = (1/2π)∫₀^{2π} cos(mτ − x·sin τ) dτ by the trapezoidal rule (which a test keeps
//! as the reference) takes as many cosines — building a kit's heads went from 130 to
//! a few ms.
//!
//! High modes (zeros above [`EXACT_ZERO_LIMIT`], the dense part of a full-band head) use
//! Debye's asymptotic form instead: for x > m, J_m(x) ≈ √(2/(π w))·cos(φ(x) − π/4) with
//! w = √(x² − m²) and φ(x) = w − m·arccos(m/x), and J_m ≈ 0 for x ≤ m; the zeros solve
//! φ(j) = (n − ¼)π (within 0.3 % of the exact ones from j ≈ 14 up, better higher).

use std::collections::BTreeMap;
use std::sync::{Arc, Mutex, OnceLock};

/// J_m(x), the Bessel function of the first kind of integer order `m` (absolute error
/// below 1e-13 for x up to a few hundred).
pub fn bessel_j(m: u32, x: f64) -> f64 {
    if x == 0.0 {
        return if m == 0 { 1.0 } else { 0.0 };
    }
    // J_m(−x) = (−1)^m J_m(x).
    let (ax, sign) = (x.abs(), if x < 0.0 && m % 2 == 1 { -1.0 } else { 1.0 });
    // J_k(x) is negligible (below 1e-17 of its peak) from k ≈ x + 8·x^⅓ on: start above.
    let top = (ax.max(f64::from(m)) + 60.0 + 2.0 * ax.sqrt()) as u32;
    let top = top + top % 2;
    let two_over_x = 2.0 / ax;
    // (J_{k+1}, J_k) up to a common scale, from (0, tiny) at k = top.
    let (mut above, mut here) = (0.0f64, 1e-280f64);
    let (mut wanted, mut even_sum) = (0.0f64, 0.0f64);
    for k in (1..=top).rev() {
        let below = f64::from(k) * two_over_x * here - above;
        (above, here) = (here, below);
        // here is now J_{k−1}.
        if here.abs() > 1e250 {
            for v in [&mut above, &mut here, &mut wanted, &mut even_sum] {
                *v *= 1e-250;
            }
        }
        if k - 1 == m {
            wanted = here;
        }
        if k > 1 && (k - 1) % 2 == 0 {
            even_sum += 2.0 * here;
        }
    }
    sign * wanted / (even_sum + here)
}

/// The `n`-th positive zero j_mn of J_m (n from 1), to 1e-12.
pub fn bessel_zero(m: u32, n: u32) -> f64 {
    assert!(n >= 1, "zeros are counted from 1");
    if let Some(&z) = exact_zeros(m).get(n as usize - 1) {
        return z;
    }
    scan_zeros(m, f64::INFINITY, n as usize)
        .pop()
        .expect("J_m has infinitely many zeros")
}

/// All positive zeros of J_m below `x_max`, rising.
pub fn bessel_zeros_below(m: u32, x_max: f64) -> Vec<f64> {
    if x_max <= EXACT_ZERO_LIMIT {
        return exact_zeros(m)
            .iter()
            .copied()
            .take_while(|&z| z < x_max)
            .collect();
    }
    scan_zeros(m, x_max, usize::MAX)
}

/// The zeros of J_m below [`EXACT_ZERO_LIMIT`], found once per process and shared (every
/// head of a kit asks for the same ones).
fn exact_zeros(m: u32) -> Arc<Vec<f64>> {
    type Cache = Mutex<BTreeMap<u32, Arc<Vec<f64>>>>;
    static CACHE: OnceLock<Cache> = OnceLock::new();
    let cache = CACHE.get_or_init(|| Mutex::new(BTreeMap::new()));
    if let Some(z) = cache.lock().expect("cache lock").get(&m) {
        return Arc::clone(z);
    }
    let zeros = Arc::new(scan_zeros(m, EXACT_ZERO_LIMIT, usize::MAX));
    cache
        .lock()
        .expect("cache lock")
        .entry(m)
        .or_insert(zeros)
        .clone()
}

/// The first `count` positive zeros of J_m below `x_max`, rising: zeros lie above m and
/// are spaced by more than 2.5 (π asymptotically), so J_m is scanned in steps of 0.1 from
/// max(m, 0.5) and each sign change bisected (the same grid whatever the bounds, so a
/// zero is the same number however it was asked for).
fn scan_zeros(m: u32, x_max: f64, count: usize) -> Vec<f64> {
    let mut out = Vec::new();
    let mut lo = f64::from(m).max(0.5);
    let mut f_lo = bessel_j(m, lo);
    while lo < x_max && out.len() < count {
        let hi = lo + 0.1;
        let f_hi = bessel_j(m, hi);
        if f_lo == 0.0 || f_lo.signum() != f_hi.signum() {
            let z = bisect(m, lo, hi, f_lo);
            if z < x_max {
                out.push(z);
            }
        }
        lo = hi;
        f_lo = f_hi;
    }
    out
}

fn bisect(m: u32, mut lo: f64, mut hi: f64, mut f_lo: f64) -> f64 {
    if f_lo == 0.0 {
        return lo;
    }
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        let f_mid = bessel_j(m, mid);
        if f_mid.signum() == f_lo.signum() {
            lo = mid;
            f_lo = f_mid;
        } else {
            hi = mid;
        }
        if hi - lo < 1e-13 {
            break;
        }
    }
    0.5 * (lo + hi)
}

/// Intervals of the radial-profile tables over r/a ∈ [0, 1].
pub const RADIAL_INTERVALS: usize = 1024;

/// The radial profile of mode (m, n): J_m(j_mn·s) at s = i/RADIAL_INTERVALS, with its zero.
#[derive(Debug)]
pub struct RadialProfile {
    /// The zero j_mn.
    pub zero: f64,
    /// J_m(j_mn·s) at RADIAL_INTERVALS + 1 equally spaced s in [0, 1].
    pub table: Vec<f64>,
    /// J_{m+1}(j_mn), which gives the modal mass (∫ J_m(j r/a)² r dr = a²/2 · J_{m+1}(j)²).
    pub j_next_at_zero: f64,
}

impl RadialProfile {
    /// J_m(j_mn·s) for s = r/a in [0, 1] (linear interpolation in the table; error below
    /// 1e-5 for the modes used here). Outside the head (s > 1) the membrane is at rest: 0.
    pub fn at(&self, s: f64) -> f64 {
        if !(0.0..=1.0).contains(&s) {
            return 0.0;
        }
        let x = s * RADIAL_INTERVALS as f64;
        let i = (x as usize).min(RADIAL_INTERVALS - 1);
        let f = x - i as f64;
        self.table[i] + f * (self.table[i + 1] - self.table[i])
    }
}

/// The radial profile of mode (m, n), computed once per process and shared (it does not
/// depend on the drum).
pub fn radial_profile(m: u32, n: u32) -> Arc<RadialProfile> {
    type Cache = Mutex<BTreeMap<(u32, u32), Arc<RadialProfile>>>;
    static CACHE: OnceLock<Cache> = OnceLock::new();
    let cache = CACHE.get_or_init(|| Mutex::new(BTreeMap::new()));
    if let Some(p) = cache.lock().expect("cache lock").get(&(m, n)) {
        return Arc::clone(p);
    }
    let zero = bessel_zero(m, n);
    let table = (0..=RADIAL_INTERVALS)
        .map(|i| bessel_j(m, zero * i as f64 / RADIAL_INTERVALS as f64))
        .collect();
    let profile = Arc::new(RadialProfile {
        zero,
        table,
        j_next_at_zero: bessel_j(m + 1, zero),
    });
    cache
        .lock()
        .expect("cache lock")
        .entry((m, n))
        .or_insert(profile)
        .clone()
}

/// Zeros below this use exact Bessel functions and tables; above it, Debye's form.
pub const EXACT_ZERO_LIMIT: f64 = 20.0;

/// Debye's phase φ(x) = √(x² − m²) − m·arccos(m/x) for x > m (0 at and below m).
fn debye_phase(m: f64, x: f64) -> f64 {
    if x <= m {
        return 0.0;
    }
    (x * x - m * m).sqrt() - m * (m / x).acos()
}

/// The n-th zero of J_m by Debye's asymptotic form: φ(j) = (n − ¼)π solved by Newton
/// (φ' = w/x), bracketed above m.
pub fn debye_zero(m: u32, n: u32) -> f64 {
    let (mf, target) = (f64::from(m), (f64::from(n) - 0.25) * std::f64::consts::PI);
    // φ ≥ w − m·π/2 gives a start above the root; φ is increasing and concave there.
    let mut x = ((target + mf * std::f64::consts::FRAC_PI_2).powi(2) + mf * mf).sqrt();
    for _ in 0..60 {
        let w = (x * x - mf * mf).max(1e-300).sqrt();
        let next = (x - (debye_phase(mf, x) - target) * x / w).max(mf + 1e-9);
        if (next - x).abs() < 1e-12 * x {
            return next;
        }
        x = next;
    }
    x
}

/// J_m(x) by Debye's asymptotic form (see the module docs).
pub fn debye_j(m: u32, x: f64) -> f64 {
    let mf = f64::from(m);
    if x <= mf {
        return 0.0;
    }
    let w = (x * x - mf * mf).sqrt();
    (2.0 / (std::f64::consts::PI * w)).sqrt()
        * (debye_phase(mf, x) - std::f64::consts::FRAC_PI_4).cos()
}

/// The radial factor of a mode: an exact table, or Debye's form for a high mode.
#[derive(Clone, Debug)]
pub enum Radial {
    Table(Arc<RadialProfile>),
    Debye { m: u32, zero: f64 },
}

impl Radial {
    /// The radial factor of mode (m, n): exact when j_mn < [`EXACT_ZERO_LIMIT`].
    pub fn of(m: u32, n: u32, zero: f64) -> Radial {
        if zero < EXACT_ZERO_LIMIT {
            Radial::Table(radial_profile(m, n))
        } else {
            Radial::Debye { m, zero }
        }
    }

    /// The zero j_mn.
    pub fn zero(&self) -> f64 {
        match self {
            Radial::Table(p) => p.zero,
            Radial::Debye { zero, .. } => *zero,
        }
    }

    /// J_m(j_mn·s) for s = r/a in [0, 1]; 0 outside.
    pub fn at(&self, s: f64) -> f64 {
        match self {
            Radial::Table(p) => p.at(s),
            Radial::Debye { m, zero } if (0.0..=1.0).contains(&s) => debye_j(*m, zero * s),
            Radial::Debye { .. } => 0.0,
        }
    }

    /// J_{m+1}(j_mn)², which gives the modal mass; Debye: J'_m(j)² ≈ 2w/(π j²).
    pub fn j_next_squared(&self) -> f64 {
        match self {
            Radial::Table(p) => p.j_next_at_zero.powi(2),
            Radial::Debye { m, zero } => {
                let w = (zero * zero - f64::from(*m).powi(2)).max(0.0).sqrt();
                2.0 * w / (std::f64::consts::PI * zero * zero)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// J_m by the trapezoidal rule on its integral (exponentially convergent for this
    /// periodic analytic integrand; error of the order of J_{N−m}(x)).
    fn bessel_j_by_integral(m: u32, x: f64) -> f64 {
        let n = 2 * (x.abs().ceil() as usize + m as usize) + 48;
        let step = std::f64::consts::TAU / n as f64;
        let mf = f64::from(m);
        let sum: f64 = (0..n)
            .map(|j| {
                let t = j as f64 * step;
                (mf * t - x * t.sin()).cos()
            })
            .sum();
        sum / n as f64
    }

    /// The recurrence agrees with the integral to 1e-13 over orders 0–60 and arguments
    /// −30…400 (past every argument the heads and their radiation ask for).
    #[test]
    fn recurrence_matches_the_integral() {
        let mut worst = 0.0f64;
        for m in 0..=60 {
            for i in 0..=860 {
                let x = -30.0 + i as f64 * 0.5 + 0.0137 * f64::from(m);
                let (a, b) = (bessel_j(m, x), bessel_j_by_integral(m, x));
                worst = worst.max((a - b).abs());
                assert!((a - b).abs() < 1e-13, "J{m}({x}): {a} vs {b}");
            }
        }
        assert!(
            worst > 0.0,
            "two methods cannot agree to the bit everywhere"
        );
    }

    /// J_m agrees with tabulated values (Abramowitz & Stegun) to 1e-9.
    #[test]
    fn bessel_values() {
        let known = [
            (0, 0.0, 1.0),
            (0, 1.0, 0.765_197_686_557_966_6),
            (1, 1.0, 0.440_050_585_744_933_5),
            (2, 5.0, 0.046_565_116_277_752_2),
            (0, 10.0, -0.245_935_764_451_348_3),
            (1, 10.0, 0.043_472_746_168_861_4),
            (5, 3.0, 0.043_028_434_877_047_6),
        ];
        for (m, x, want) in known {
            let got = bessel_j(m, x);
            assert!((got - want).abs() < 1e-9, "J{m}({x}) = {got}, want {want}");
        }
    }

    /// The zeros j_mn agree with tabulated values to 1e-6.
    #[test]
    fn bessel_zeros() {
        let known = [
            (0, 1, 2.404_825_557_695_773),
            (1, 1, 3.831_705_970_207_512),
            (2, 1, 5.135_622_301_840_683),
            (0, 2, 5.520_078_110_286_311),
            (3, 1, 6.380_161_895_923_983),
            (1, 2, 7.015_586_669_815_619),
            (4, 1, 7.588_342_434_503_804),
            (2, 2, 8.417_244_140_399_865),
            (0, 3, 8.653_727_912_911_013),
            (5, 1, 8.771_483_815_959_954),
        ];
        for (m, n, want) in known {
            let got = bessel_zero(m, n);
            assert!((got - want).abs() < 1e-6, "j{m}{n} = {got}, want {want}");
        }
        assert!((bessel_zero(1, 1) - crate::kit::BESSEL_J11).abs() < 1e-10);
        let below = bessel_zeros_below(0, 9.0);
        assert_eq!(below.len(), 3);
        assert!((below[2] - 8.653_727_912_911_013).abs() < 1e-9);
    }

    /// Debye's zeros lie within 0.3 % of the exact ones near the limit (low n, high m the
    /// hardest), its J_m within 0.02 of the exact one there, and its modal-mass factor
    /// within 5 %.
    #[test]
    fn debye_form_near_the_limit() {
        for (m, n) in [(0, 9), (5, 6), (12, 3), (20, 1), (24, 1), (8, 7)] {
            let exact = bessel_zero(m, n);
            let debye = debye_zero(m, n);
            assert!(
                (debye / exact - 1.0).abs() < 3e-3,
                "j{m},{n}: {debye} vs {exact}"
            );
            for s in [0.3, 0.6, 0.9] {
                let (a, b) = (bessel_j(m, exact * s), debye_j(m, exact * s));
                assert!((a - b).abs() < 0.02, "J{m}({}): {b} vs {a}", exact * s);
            }
            let table = Radial::Table(radial_profile(m, n)).j_next_squared();
            let asym = Radial::Debye { m, zero: exact }.j_next_squared();
            assert!(
                (asym / table - 1.0).abs() < 0.05,
                "{m},{n}: {asym} vs {table}"
            );
        }
    }

    /// The tabulated profile interpolates J_m to 1e-5, is 0 at the rim and outside.
    #[test]
    fn radial_profile_interpolates() {
        let p = radial_profile(3, 2);
        for s in [0.0, 0.1234, 0.5, 0.777, 0.999] {
            let want = bessel_j(3, p.zero * s);
            assert!((p.at(s) - want).abs() < 1e-5, "s {s}");
        }
        assert!(p.at(1.0).abs() < 1e-9);
        assert_eq!(p.at(1.01), 0.0);
    }
}
