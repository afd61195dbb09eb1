//! Magnitude spectra for tests and the editor: a Hann-windowed, zero-padded radix-2 FFT,
//! and peak helpers (parabolic interpolation between bins, a kettledrum-pattern
//! fundamental finder used to measure the recorded samples' (1,1) pitch).

use std::f64::consts::{PI, TAU};

/// In-place iterative radix-2 FFT of (re, im); the length must be a power of two.
pub fn fft(re: &mut [f64], im: &mut [f64]) {
    let n = re.len();
    assert!(
        n.is_power_of_two() && im.len() == n,
        "FFT length must be a power of two"
    );
    let mut j = 0;
    for i in 1..n {
        let mut bit = n >> 1;
        while j & bit != 0 {
            j ^= bit;
            bit >>= 1;
        }
        j |= bit;
        if i < j {
            re.swap(i, j);
            im.swap(i, j);
        }
    }
    let mut len = 2;
    while len <= n {
        let (ws, wc) = (-TAU / len as f64).sin_cos();
        for start in (0..n).step_by(len) {
            let (mut cr, mut ci) = (1.0, 0.0);
            for k in 0..len / 2 {
                let (a, b) = (start + k, start + k + len / 2);
                let tr = re[b] * cr - im[b] * ci;
                let ti = re[b] * ci + im[b] * cr;
                re[b] = re[a] - tr;
                im[b] = im[a] - ti;
                re[a] += tr;
                im[a] += ti;
                let next = cr * wc - ci * ws;
                ci = cr * ws + ci * wc;
                cr = next;
            }
        }
        len <<= 1;
    }
}

/// Hann-windowed magnitude spectrum of mono `samples`: (frequency Hz, amplitude) for bins
/// 0..=N/2, N the next power of two ≥ 4 × the length (zero padding for fine bins). A
/// sinusoid of amplitude A reads ≈ A at its peak (the window's gain is divided out).
pub fn spectrum(samples: &[f32], rate_hz: u32) -> Vec<(f64, f64)> {
    if samples.is_empty() {
        return Vec::new();
    }
    let len = samples.len();
    let n = (4 * len).next_power_of_two();
    let mut re = vec![0.0; n];
    let mut im = vec![0.0; n];
    let mut wsum = 0.0;
    for (i, &s) in samples.iter().enumerate() {
        let w = 0.5 - 0.5 * (TAU * i as f64 / len as f64).cos();
        re[i] = f64::from(s) * w;
        wsum += w;
    }
    fft(&mut re, &mut im);
    let scale = 2.0 / wsum;
    (0..=n / 2)
        .map(|k| {
            (
                k as f64 * f64::from(rate_hz) / n as f64,
                (re[k] * re[k] + im[k] * im[k]).sqrt() * scale,
            )
        })
        .collect()
}

/// The largest peak within [lo, hi] Hz, refined by parabolic interpolation of the log
/// magnitude: (frequency Hz, amplitude). None if the band holds no bin.
pub fn peak_in(spec: &[(f64, f64)], lo: f64, hi: f64) -> Option<(f64, f64)> {
    let within = bins_within(spec, lo, hi);
    let (k, &(_, a)) = spec[within.clone()]
        .iter()
        .enumerate()
        .map(|(i, p)| (within.start + i, p))
        .max_by(|x, y| x.1.1.total_cmp(&y.1.1))?;
    if k == 0 || k + 1 >= spec.len() || a <= 0.0 {
        return Some(spec[k]);
    }
    let (l, c, r) = (
        spec[k - 1].1.max(1e-30).ln(),
        a.ln(),
        spec[k + 1].1.max(1e-30).ln(),
    );
    let denom = l - 2.0 * c + r;
    let shift = if denom < 0.0 {
        (0.5 * (l - r) / denom).clamp(-0.5, 0.5)
    } else {
        0.0
    };
    let bin = spec[1].0 - spec[0].0;
    Some((spec[k].0 + shift * bin, (c - 0.25 * (l - r) * shift).exp()))
}

/// The bins of `spec` (rising in frequency) within [lo, hi] Hz, found by bisection: the
/// transcriber asks for a few bins around each of thousands of partials per stroke, and
/// scanning the whole spectrum for each took most of its time.
pub fn bins_within(spec: &[(f64, f64)], lo: f64, hi: f64) -> std::ops::Range<usize> {
    let start = spec.partition_point(|(f, _)| *f < lo);
    let end = spec.partition_point(|(f, _)| *f <= hi);
    start..end.max(start)
}

/// Local maxima above `floor` × the largest amplitude in [lo, hi] Hz, rising in frequency.
pub fn peaks(spec: &[(f64, f64)], lo: f64, hi: f64, floor: f64) -> Vec<(f64, f64)> {
    let within = bins_within(spec, lo, hi);
    let band: Vec<usize> =
        (within.start.max(1)..within.end.min(spec.len().saturating_sub(1))).collect();
    let top = band.iter().map(|&k| spec[k].1).fold(0.0, f64::max);
    band.into_iter()
        .filter(|&k| {
            spec[k].1 >= floor * top && spec[k].1 > spec[k - 1].1 && spec[k].1 >= spec[k + 1].1
        })
        .map(|k| spec[k])
        .collect()
}

/// The principal (1,1) frequency of a kettledrum sound: among the peaks in [lo, hi] Hz
/// within 20 dB of the strongest, the one whose own amplitude plus the largest peak within
/// ±2 % of each further multiple in `ratios` (after the leading 1) is largest, refined by
/// interpolation.
pub fn principal_hz(spec: &[(f64, f64)], lo: f64, hi: f64, ratios: &[f64]) -> Option<f64> {
    let candidates = peaks(spec, lo, hi, 0.1);
    let score = |(f, a): (f64, f64)| -> f64 {
        a + ratios
            .iter()
            .skip(1)
            .map(|r| peak_in(spec, r * f * 0.98, r * f * 1.02).map_or(0.0, |p| p.1))
            .sum::<f64>()
    };
    let best = candidates
        .iter()
        .map(|&p| (p.0, score(p)))
        .max_by(|x, y| x.1.total_cmp(&y.1).then(y.0.total_cmp(&x.0)))?;
    peak_in(spec, best.0 * 0.995, best.0 * 1.005).map(|p| p.0)
}

/// Hann window value w(i) of an `n`-point window.
pub fn hann(i: usize, n: usize) -> f64 {
    0.5 - 0.5 * (2.0 * PI * i as f64 / n as f64).cos()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The FFT equals a direct DFT (1e-9), and a sinusoid's spectral peak lands on its
    /// frequency (0.05 %) with its amplitude (1 %).
    #[test]
    fn fft_and_spectrum() {
        let n = 64;
        let x: Vec<f64> = (0..n).map(|i| ((i * 7 % 13) as f64 - 6.0) / 3.0).collect();
        let (mut re, mut im) = (x.clone(), vec![0.0; n]);
        fft(&mut re, &mut im);
        for k in [0, 1, 5, 31, 63] {
            let (dr, di) = x.iter().enumerate().fold((0.0, 0.0), |(r, i), (t, v)| {
                let a = -TAU * (k * t) as f64 / n as f64;
                (r + v * a.cos(), i + v * a.sin())
            });
            assert!((re[k] - dr).abs() < 1e-9 && (im[k] - di).abs() < 1e-9);
        }
        let rate = 48_000;
        let s: Vec<f32> = (0..24_000)
            .map(|i| (0.5 * (TAU * 146.83 * i as f64 / 48_000.0).sin()) as f32)
            .collect();
        let spec = spectrum(&s, rate);
        let (f, a) = peak_in(&spec, 100.0, 200.0).unwrap();
        assert!((f / 146.83 - 1.0).abs() < 5e-4, "{f}");
        assert!((a / 0.5 - 1.0).abs() < 0.01, "{a}");
        assert!(hann(0, 8) == 0.0 && (hann(4, 8) - 1.0).abs() < 1e-12);
    }

    /// The principal finder picks the (1,1) of a synthetic kettledrum even when the (2,1)
    /// is louder, not its octave below or the (2,1).
    #[test]
    fn principal_of_kettledrum_pattern() {
        let rate = 48_000;
        let parts = [(1.0, 0.3), (1.5, 1.0), (1.98, 0.6), (2.44, 0.4)];
        let s: Vec<f32> = (0..48_000)
            .map(|i| {
                let t = i as f64 / 48_000.0;
                parts
                    .iter()
                    .map(|(r, a)| a * (TAU * 100.0 * r * t).sin())
                    .sum::<f64>() as f32
            })
            .collect();
        let spec = spectrum(&s, rate);
        let f = principal_hz(&spec, 40.0, 400.0, &[1.0, 1.5, 1.98, 2.44, 2.94]).unwrap();
        assert!((f / 100.0 - 1.0).abs() < 1e-3, "{f}");
    }

    /// The bins within a band, by bisection: the same bins a scan keeps, edges included.
    #[test]
    fn bins_within_a_band() {
        let spec: Vec<(f64, f64)> = (0..100).map(|k| (k as f64 * 2.5, 1.0)).collect();
        assert_eq!(bins_within(&spec, 10.0, 20.0), 4..9);
        assert_eq!(bins_within(&spec, 10.1, 19.9), 5..8);
        assert_eq!(bins_within(&spec, 300.0, 400.0), 100..100);
        assert_eq!(bins_within(&spec, 20.0, 10.0).len(), 0);
        assert_eq!(bins_within(&[], 1.0, 2.0).len(), 0);
        for (lo, hi) in [(0.0, 7.5), (33.3, 97.1), (-5.0, 1000.0)] {
            let scanned: Vec<usize> = (0..spec.len())
                .filter(|&k| (lo..=hi).contains(&spec[k].0))
                .collect();
            assert_eq!(bins_within(&spec, lo, hi).collect::<Vec<_>>(), scanned);
        }
    }
}
