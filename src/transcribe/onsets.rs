//! Where strokes begin in a recording. A log-magnitude spectral flux over a logarithmic
//! filterbank against a maximum-filtered, lagged reference frame (SuperFlux, Böck &
//! Widmer 2013) gives an onset strength every 5 ms; adaptive peak picking (Böck, Krebs &
//! Schedl 2012: a local maximum above the local mean plus a threshold, at least 30 ms
//! apart) finds the strokes; each is
//! then placed to the half millisecond on the steepest rise of the high-passed signal's
//! energy, where the stick's click starts.

use crate::sound::spectrum::{fft, hann};

/// Spacing of the onset-strength frames, s.
pub const HOP_S: f64 = 0.005;
/// Length of each analysis frame, s (rounded to the nearest power of two of samples, on a
/// log scale: 1024 at 32 kHz, 2048 at 44.1 and 48 kHz).
const FRAME_S: f64 = 0.04;
/// Frequencies the flux sums over, Hz.
const FLUX_BAND_HZ: (f64, f64) = (30.0, 12_000.0);
/// Bands of the flux's logarithmic filterbank per octave.
const BANDS_PER_OCTAVE: f64 = 48.0;
/// Log compression: ln(1 + γ·|X|), |X| relative to a full-scale sinusoid.
const LOG_GAMMA: f64 = 1000.0;
/// The reference frame lies this many frames back (SuperFlux's μ).
const LAG_FRAMES: usize = 2;
/// Peak picking: the maximum over −30…+30 ms, the mean over −60…+70 ms (over −100 ms,
/// Böck's, the mean held a roll's first stroke — struck from silence, its flux 5–7 times
/// a later stroke's — when the second came 67–83 ms after it, and the second was lost;
/// a hall's echo 45 ms after a stroke still has the stroke in its mean).
const PRE_MAX_S: f64 = 0.03;
const POST_MAX_S: f64 = 0.03;
const PRE_AVG_S: f64 = 0.06;
const POST_AVG_S: f64 = 0.07;
/// Two onsets are at least this far apart, s.
pub const MIN_GAP_S: f64 = 0.03;
/// Threshold above the local mean, as a share of the strongest onsets' strength…
const DELTA_OF_TOP: f64 = 0.06;
/// …and at least this many times the median frame (the noise floor).
const DELTA_OF_MEDIAN: f64 = 1.5;
/// …and never under this: a stroke's strength is 6–250 (the quietest of the rendered roll
/// exercise's strokes 6.0, the loudest 252; a note's the same at 0 and −60 dBFS), the
/// frame-to-frame wiggle of a held tone's spectral leakage ≈ 0.02, which a file holding
/// nothing else would otherwise pick.
const MIN_STRENGTH: f64 = 1.0;
/// A recording's first frames count as onsets only if they reach this share of its peak.
const START_SHARE: f32 = 0.05;
/// An onset must reach this share of the strongest onset strength of the last
/// [`MASKED_S`]: the decay of a loud note (its partials beating) is not a stroke. The
/// beats of the recorded C2 and D2 notes reach 3–4 % of their strokes' strength, the
/// strokes of a roll after its first 13–35 %.
const MASKED_SHARE: f64 = 0.08;
const MASKED_S: f64 = 3.0;
/// An onset is placed within this of its frame's centre, s (half a frame at 32 kHz; the
/// 2048-sample frames at 44.1 and 48 kHz reach ±21–23 ms, into a fast roll's neighbours).
const PLACE_WITHIN_S: f64 = 0.016;
/// Energy blocks of the high-passed signal for placing an onset, s.
const BLOCK_S: f64 = 0.0005;
/// The rise is measured against the mean energy of this span before, s.
const RISE_BEFORE_S: f64 = 0.025;

/// The onset strength of a signal: one value per frame, frame `n` centred at `n`·hop.
#[derive(Clone, Debug, PartialEq)]
pub struct Strength {
    /// Frame spacing, s.
    pub hop_s: f64,
    /// Analysis frame length, s.
    pub frame_s: f64,
    /// Half-wave rectified log spectral flux per frame (dimensionless).
    pub values: Vec<f64>,
}

impl Strength {
    /// Time of frame `n`, s.
    pub fn time_s(&self, n: usize) -> f64 {
        n as f64 * self.hop_s
    }

    fn frames(&self, seconds: f64) -> usize {
        (seconds / self.hop_s).round() as usize
    }
}

/// A stroke's beginning.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Onset {
    /// When the stroke begins, s from the start of the signal.
    pub time_s: f64,
    /// Its onset strength (the flux peak).
    pub strength: f64,
}

/// The onset strength of mono `samples` at `rate_hz`.
pub fn strength(samples: &[f32], rate_hz: u32) -> Strength {
    let rate = f64::from(rate_hz);
    let n = (1usize << (FRAME_S * rate).log2().round().max(6.0) as u32).max(64);
    let hop = ((HOP_S * rate).round() as usize).max(1);
    let peak = samples.iter().fold(0.0f32, |m, s| m.max(s.abs()));
    let scale = if peak > 0.0 {
        1.0 / f64::from(peak)
    } else {
        1.0
    };
    let window: Vec<f64> = (0..n).map(|i| hann(i, n)).collect();
    let full_scale = window.iter().sum::<f64>() / 2.0;
    let bin_hz = rate / n as f64;
    let lo = (FLUX_BAND_HZ.0 / bin_hz).ceil() as usize;
    let hi = ((FLUX_BAND_HZ.1 / bin_hz).floor() as usize).min(n / 2);
    let bands = log_bands(lo, hi, bin_hz);
    let frames = samples.len().div_ceil(hop) + 1;
    let head = &samples[..samples.len().min(n / 2)];
    let loud_start = head.iter().fold(0.0f32, |m, s| m.max(s.abs())) >= START_SHARE * peak;
    let mut history: Vec<Vec<f64>> = Vec::with_capacity(LAG_FRAMES + 1);
    let mut values = Vec::with_capacity(frames);
    let (mut re, mut im) = (vec![0.0; n], vec![0.0; n]);
    for f in 0..frames {
        let start = (f * hop) as isize - (n / 2) as isize;
        for i in 0..n {
            let j = start + i as isize;
            re[i] = if j >= 0 && (j as usize) < samples.len() {
                f64::from(samples[j as usize]) * scale * window[i]
            } else {
                0.0
            };
            im[i] = 0.0;
        }
        fft(&mut re, &mut im);
        let log: Vec<f64> = bands
            .iter()
            .map(|band| {
                let m = band
                    .clone()
                    .map(|k| (re[k] * re[k] + im[k] * im[k]).sqrt())
                    .sum::<f64>();
                (1.0 + LOG_GAMMA * m / full_scale).ln()
            })
            .collect();
        let flux = match history.first() {
            // A noise floor that starts with the recording fills the first windows, and a
            // recording cut off while ringing ends in a step: neither is a stroke.
            _ if start < 0 && !loud_start => 0.0,
            _ if start + n as isize > samples.len() as isize => 0.0,
            Some(reference) if history.len() > LAG_FRAMES - 1 => {
                let reference = max_filtered(reference);
                log.iter()
                    .zip(&reference)
                    .map(|(l, r)| (l - r).max(0.0))
                    .sum()
            }
            // Before the first reference frame the signal is measured against silence, so
            // a stroke at the very start counts.
            _ => log.iter().sum(),
        };
        values.push(flux);
        history.push(log);
        if history.len() > LAG_FRAMES {
            history.remove(0);
        }
    }
    Strength {
        hop_s: hop as f64 / rate,
        frame_s: n as f64 / rate,
        values,
    }
}

/// The FFT bins `lo..=hi` grouped into bands of [`BANDS_PER_OCTAVE`] (a bin of its own
/// where the bands are narrower than a bin, below 2–3 kHz): SuperFlux's logarithmic
/// filterbank. Summed bin by bin, the octaves above 3 kHz held three quarters of the
/// flux's terms, and a recording's hiss fluctuated in each of them: soft roll strokes
/// under white noise 50 dB below the peak were lost (the demos' roll exercise, damaged:
/// 50 of 68 found; 64 with the bands, 65 once a roll also took in its uneven start).
fn log_bands(lo: usize, hi: usize, bin_hz: f64) -> Vec<std::ops::Range<usize>> {
    let mut bands = Vec::new();
    let mut start = lo;
    while start <= hi {
        let f = start.max(1) as f64 * bin_hz;
        let next = f * 2f64.powf(1.0 / BANDS_PER_OCTAVE);
        let end = ((next / bin_hz).ceil() as usize).clamp(start + 1, hi + 1);
        bands.push(start..end);
        start = end;
    }
    bands
}

/// Each bin replaced by the largest of itself and its two neighbours.
fn max_filtered(bins: &[f64]) -> Vec<f64> {
    (0..bins.len())
        .map(|k| {
            let a = bins[k.saturating_sub(1)];
            let c = bins[(k + 1).min(bins.len() - 1)];
            bins[k].max(a).max(c)
        })
        .collect()
}

/// The frames that are onsets: local maxima of the strength above the local mean plus
/// the threshold and not masked by a much stronger onset just before, at least
/// [`MIN_GAP_S`] apart.
pub fn pick(strength: &Strength) -> Vec<usize> {
    let v = &strength.values;
    if v.is_empty() {
        return Vec::new();
    }
    let delta = threshold(v);
    let (pre_max, post_max) = (strength.frames(PRE_MAX_S), strength.frames(POST_MAX_S));
    let (pre_avg, post_avg) = (strength.frames(PRE_AVG_S), strength.frames(POST_AVG_S));
    let gap = strength.frames(MIN_GAP_S);
    let masked = strength.frames(MASKED_S);
    let mut prefix = vec![0.0; v.len() + 1];
    for (i, x) in v.iter().enumerate() {
        prefix[i + 1] = prefix[i] + x;
    }
    let mut picked: Vec<usize> = Vec::new();
    for n in 0..v.len() {
        let (a, b) = (n.saturating_sub(pre_max), (n + post_max).min(v.len() - 1));
        if v[a..=b].iter().any(|&x| x > v[n]) {
            continue;
        }
        let (a, b) = (n.saturating_sub(pre_avg), (n + post_avg).min(v.len() - 1));
        let mean = (prefix[b + 1] - prefix[a]) / (b + 1 - a) as f64;
        if v[n] <= 0.0 || v[n] < mean + delta {
            continue;
        }
        let recent = v[n.saturating_sub(masked)..n]
            .iter()
            .copied()
            .fold(0.0, f64::max);
        if v[n] < MASKED_SHARE * recent {
            continue;
        }
        if picked.last().is_some_and(|&last| n - last < gap) {
            continue;
        }
        picked.push(n);
    }
    picked
}

/// The threshold above the local mean: a share of the strong onsets' strength, and well
/// above the noise floor.
fn threshold(v: &[f64]) -> f64 {
    let mut sorted = v.to_vec();
    sorted.sort_by(f64::total_cmp);
    let at = |q: f64| sorted[((sorted.len() - 1) as f64 * q) as usize];
    (DELTA_OF_TOP * at(0.995))
        .max(DELTA_OF_MEDIAN * at(0.5))
        .max(MIN_STRENGTH)
}

/// Where within frame `frame`'s window (at most [`PLACE_WITHIN_S`] either side of its
/// centre) the stroke begins, s: the first block of the
/// high-passed signal rising at least half as much as the block that rises most above the
/// largest block of the [`RISE_BEFORE_S`] before it (a drum still ringing stays near its
/// own largest block; a stroke's click does not).
pub fn place(samples: &[f32], rate_hz: u32, strength: &Strength, frame: usize) -> f64 {
    let rate = f64::from(rate_hz);
    let block = ((BLOCK_S * rate).round() as usize).max(1);
    let before = ((RISE_BEFORE_S / BLOCK_S).round() as usize).max(1);
    let centre = strength.time_s(frame) * rate;
    let half = (strength.frame_s / 2.0).min(PLACE_WITHIN_S) * rate;
    let first = ((centre - half).max(0.0) as usize) / block;
    let last = ((centre + half) as usize).min(samples.len()) / block;
    let energy = |b: usize| -> f64 {
        let (s, e) = ((b * block).max(1), ((b + 1) * block).min(samples.len()));
        (s..e)
            .map(|i| {
                let d = f64::from(samples[i]) - f64::from(samples[i - 1]);
                d * d
            })
            .sum::<f64>()
    };
    let span: Vec<f64> = (first.saturating_sub(before)..=last).map(energy).collect();
    let top = span.iter().copied().fold(0.0, f64::max);
    if top <= 0.0 {
        return strength.time_s(frame);
    }
    let floor = 1e-4 * top;
    let offset = first - first.saturating_sub(before);
    let rise = |i: usize| -> f64 {
        let prior = span[i.saturating_sub(before)..i]
            .iter()
            .copied()
            .fold(0.0, f64::max);
        span[i] / (prior + floor)
    };
    let best = (offset..span.len())
        .filter(|&i| span[i] >= 0.02 * top)
        .max_by(|&a, &b| rise(a).total_cmp(&rise(b)))
        .unwrap_or(offset);
    let half_rise = 1.0 + 0.5 * (rise(best) - 1.0);
    let start = (offset..=best)
        .find(|&i| span[i] >= 0.02 * top && rise(i) >= half_rise)
        .unwrap_or(best);
    (first - offset + start) as f64 * block as f64 / rate
}

/// The onsets of mono `samples`, in time order.
pub fn detect(samples: &[f32], rate_hz: u32) -> Vec<Onset> {
    let strength = strength(samples, rate_hz);
    let mut onsets: Vec<Onset> = pick(&strength)
        .into_iter()
        .map(|f| Onset {
            time_s: place(samples, rate_hz, &strength, f),
            strength: strength.values[f],
        })
        .collect();
    onsets.sort_by(|a, b| a.time_s.total_cmp(&b.time_s));
    onsets.dedup_by(|b, a| b.time_s - a.time_s < MIN_GAP_S / 2.0);
    onsets
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A decaying two-partial "drum" struck at known times, with a click.
    pub(crate) fn strikes(times: &[(f64, f64, f64)], seconds: f64, rate: u32) -> Vec<f32> {
        let n = (seconds * f64::from(rate)) as usize;
        let mut out = vec![0.0f32; n];
        for &(t0, hz, amp) in times {
            let start = (t0 * f64::from(rate)) as usize;
            for (i, s) in out.iter_mut().enumerate().skip(start) {
                let t = (i - start) as f64 / f64::from(rate);
                let click = if t < 0.001 {
                    0.3 * (1.0 - t / 0.001)
                } else {
                    0.0
                };
                let v = (-t / 0.4).exp()
                    * ((std::f64::consts::TAU * hz * t).sin()
                        + 0.5 * (std::f64::consts::TAU * 1.5 * hz * t).sin())
                    + click * (((i * 7919) % 13) as f64 / 6.5 - 1.0);
                *s += (amp * v) as f32;
            }
        }
        out
    }

    /// Strokes a quarter of a second apart, loud and soft, over a ringing drum: every one
    /// is found within 3 ms, and nothing else.
    #[test]
    fn finds_each_stroke() {
        let truth = [
            (0.2, 110.0, 0.8),
            (0.45, 146.8, 0.2),
            (0.7, 110.0, 0.5),
            (0.95, 146.8, 0.1),
            (1.6, 110.0, 0.9),
        ];
        for rate in [32_000, 44_100, 48_000] {
            let onsets = detect(&strikes(&truth, 2.5, rate), rate);
            let times: Vec<f64> = onsets.iter().map(|o| o.time_s).collect();
            assert_eq!(times.len(), truth.len(), "{rate} Hz: {times:?}");
            for (got, want) in times.iter().zip(&truth) {
                assert!(
                    (got - want.0).abs() < 0.003,
                    "{rate} Hz: {got} vs {}",
                    want.0
                );
            }
        }
    }

    /// Silence and an empty signal have no onsets; a stroke at the very start is found.
    #[test]
    fn edges() {
        assert!(detect(&[], 48_000).is_empty());
        assert!(detect(&vec![0.0; 48_000], 48_000).is_empty());
        let onsets = detect(&strikes(&[(0.0, 98.0, 0.7)], 1.0, 48_000), 48_000);
        assert_eq!(onsets.len(), 1);
        assert!(onsets[0].time_s < 0.002, "{:?}", onsets[0]);
    }

    /// The filterbank's bands tile the flux's bins without gap or overlap, one bin each
    /// where bins are wider than a 48th of an octave, and hold many bins an octave near
    /// the top (a 2048-point frame at 48 kHz: 23.4 Hz bins).
    #[test]
    fn log_bands_tile_the_bins() {
        let bin_hz = 48_000.0 / 2048.0;
        let (lo, hi) = (2, 512);
        let bands = log_bands(lo, hi, bin_hz);
        assert_eq!(bands[0].start, lo);
        assert_eq!(bands.last().unwrap().end, hi + 1);
        assert!(bands.windows(2).all(|w| w[0].end == w[1].start));
        assert!(bands.iter().all(|b| !b.is_empty()));
        let at = |hz: f64| {
            bands
                .iter()
                .find(|b| b.contains(&((hz / bin_hz) as usize)))
                .unwrap()
                .len()
        };
        assert_eq!(at(500.0), 1);
        assert!(at(11_000.0) >= 6, "{}", at(11_000.0));
        // An octave near the top (6–12 kHz) holds about 48 bands' worth, not its 256 bins.
        let top = bands
            .iter()
            .filter(|b| b.start as f64 * bin_hz >= 6_000.0)
            .count();
        assert!((40..=56).contains(&top), "{top}");
    }
}
