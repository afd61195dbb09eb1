//! Measuring a struck note the way the guide's reference numbers were measured (guide §5,
//! "Recorded timpani"): the onset, then over the first second after it the energy in
//! the octave bands 63 Hz – 4 kHz as a share of the whole (dB) and the spectral centroid,
//! both under one Hann window spanning that second (as the reference figures
//! were measured: see `power_spectrum`), the (1,1) frequency over time (pitch glide) and the decay of a partial. Used by the
//! calibration fit, `timpanist sound analyse`, the tests and the plots; the same code
//! measures recordings and our own renders.

use super::spectrum::{fft, hann, peak_in, principal_hz, spectrum};

/// Nominal octave-band centres, Hz (band edges at centre/√2 and centre·√2).
pub const OCTAVE_CENTRES_HZ: [f64; 7] = [63.0, 125.0, 250.0, 500.0, 1000.0, 2000.0, 4000.0];
/// Span after the onset that the band energies and the centroid cover, s.
pub const ANALYSIS_SPAN_S: f64 = 1.0;
/// Onset: the first sample whose magnitude reaches this share of the note's peak.
const ONSET_SHARE: f32 = 0.05;
/// The onset is moved this long earlier so the attack's first rise is inside the span, s.
const ONSET_LEAD_S: f64 = 0.002;

/// A decay is measured only where the level falls at least this much over the span, dB.
pub const MIN_DECAY_DB: f64 = 3.0;
/// A struck note's loudest 10 ms stand at least this far above the median 10 ms of its
/// file (or `--at` span), dB: pink noise stands 2–3 dB above, a timpani note 20–60.
pub const MIN_STRIKE_CONTRAST_DB: f64 = 10.0;
/// In a file under 2 s a note cut short may have decayed only a little by its end, so
/// there its loudest 10 ms need stand only this far above its resting level
/// ([`reference_level`]), dB: over such a span noise stands 1–3 dB above its last quarter,
/// a held tone less, a D2 note cut to 0.3 s 7.4 dB.
pub const MIN_SHORT_STRIKE_CONTRAST_DB: f64 = 6.0;
/// Shorter than this after the onset, a note is not measured at all, s.
pub const MIN_NOTE_S: f64 = 0.2;
/// Shorter than this after the onset, a note is measured over what there is, with a
/// warning, s.
pub const SHORT_NOTE_S: f64 = 0.5;

/// Kettledrum ratios (1,1)…(5,1) used to recognise the (1,1) (guide §5, Fletcher & Rossing).
pub const KETTLEDRUM_RATIOS: [f64; 5] = [1.0, 1.5, 1.98, 2.44, 2.94];

/// What [`profile`] measures of one note.
#[derive(Clone, Debug, PartialEq)]
pub struct Profile {
    /// Onset, s from the start of the signal.
    pub onset_s: f64,
    /// Energy per octave band of [`OCTAVE_CENTRES_HZ`] over the total energy, dB.
    pub bands_db: [f64; 7],
    /// Power-weighted mean frequency, Hz.
    pub centroid_hz: f64,
    /// The principal (1,1) frequency, Hz, when the kettledrum pattern is found (40–400 Hz).
    pub principal_hz: Option<f64>,
}

/// The first frame of the note: where the magnitude first reaches 5 % of its peak, less
/// 2 ms. None for a silent signal.
pub fn onset(samples: &[f32], rate_hz: u32) -> Option<usize> {
    let peak = samples.iter().fold(0.0f32, |m, s| m.max(s.abs()));
    if peak.is_nan() || peak <= 0.0 {
        return None;
    }
    let first = samples.iter().position(|s| s.abs() >= ONSET_SHARE * peak)?;
    Some(first.saturating_sub((ONSET_LEAD_S * f64::from(rate_hz)) as usize))
}

/// Why `samples` (at `rate_hz`) cannot be measured as a struck note, if they cannot:
/// silent, less than [`MIN_NOTE_S`] after its onset, or no strike standing
/// [`MIN_STRIKE_CONTRAST_DB`] above the file's median level in 10 ms windows (noise, a
/// sustained tone).
pub fn not_a_note(samples: &[f32], rate_hz: u32) -> Option<String> {
    let Some(start) = onset(samples, rate_hz) else {
        return Some("silent".into());
    };
    let after_s = (samples.len() - start) as f64 / f64::from(rate_hz);
    if after_s < MIN_NOTE_S {
        return Some(format!(
            "only {after_s:.3} s of sound after the onset: too short to measure (at least \
             {MIN_NOTE_S} s)"
        ));
    }
    // Never missing: 0.2 s after the onset is twenty 10 ms windows at any audio rate.
    let contrast_db = strike_contrast_db(samples, rate_hz)?;
    let needed_db = min_strike_contrast_db(samples.len(), rate_hz);
    (contrast_db < needed_db).then(|| {
        format!(
            "no struck note: its loudest 10 ms stand only {contrast_db:.1} dB above its resting \
             level (at least {needed_db} dB: is it noise or a sustained sound?)"
        )
    })
}

/// How far a strike must stand above the resting level ([`reference_level`]) of a file of
/// `frames` at `rate_hz`, dB: [`MIN_STRIKE_CONTRAST_DB`], or in a file under 2 s
/// [`MIN_SHORT_STRIKE_CONTRAST_DB`].
pub fn min_strike_contrast_db(frames: usize, rate_hz: u32) -> f64 {
    if frames / window_frames(rate_hz) < SHORT_FILE_WINDOWS {
        MIN_SHORT_STRIKE_CONTRAST_DB
    } else {
        MIN_STRIKE_CONTRAST_DB
    }
}

/// Frames in a 10 ms window at `rate_hz` (at least one).
fn window_frames(rate_hz: u32) -> usize {
    ((0.01 * f64::from(rate_hz)) as usize).max(1)
}

/// Mean square of each whole 10 ms window of `samples`, in time order.
fn window_levels(samples: &[f32], rate_hz: u32) -> (usize, Vec<f64>) {
    let window = window_frames(rate_hz);
    let levels = samples
        .chunks(window)
        .filter(|w| w.len() == window)
        .map(|w| w.iter().map(|&x| f64::from(x) * f64::from(x)).sum::<f64>() / window as f64)
        .collect();
    (window, levels)
}

/// The median of `levels` (not empty).
fn median_of(levels: &[f64]) -> f64 {
    let mut sorted = levels.to_vec();
    sorted.sort_by(f64::total_cmp);
    sorted[sorted.len() / 2]
}

/// Below this many 10 ms windows (2 s) a file may be one note from end to end, s.
const SHORT_FILE_WINDOWS: usize = 200;

/// The level a strike is measured against: the median 10 ms window, or in a file under
/// 2 s, where a note cut short fills most of it and is its own median, the median of its
/// last quarter if quieter (a struck note has decayed there; noise and held tones have
/// not). Not empty.
fn reference_level(levels: &[f64]) -> f64 {
    let median = median_of(levels);
    if levels.len() >= SHORT_FILE_WINDOWS {
        return median;
    }
    let tail = &levels[levels.len() - levels.len().div_ceil(4)..];
    median.min(median_of(tail))
}

/// How far the loudest 10 ms window of `samples` stands above their median 10 ms
/// window (in a file under 2 s, the quieter of it and its last quarter's: see
/// [`reference_level`]), dB (`None` with no whole window): a struck note stands 20–60 dB above, room
/// tone, noise and sustained tones 2–5 dB (seconds of pink noise up to ~10 dB).
pub fn strike_contrast_db(samples: &[f32], rate_hz: u32) -> Option<f64> {
    let (_, levels) = window_levels(samples, rate_hz);
    let loudest = levels.iter().copied().reduce(f64::max)?;
    Some(10.0 * (loudest / reference_level(&levels).max(1e-30)).log10())
}

/// How far the loudest 10 ms window within `span_s` after each of `times_s` stands above
/// the median 10 ms window of `samples`, dB, the best of them (`None` with no whole
/// window): a stroke's attack stands 20–60 dB above a recording's median level, the start
/// of a noise a few dB.
pub fn attack_contrast_db(
    samples: &[f32],
    rate_hz: u32,
    times_s: &[f64],
    span_s: f64,
) -> Option<f64> {
    let (window, levels) = window_levels(samples, rate_hz);
    if levels.is_empty() {
        return None;
    }
    let resting = reference_level(&levels).max(1e-30);
    let index =
        |t: f64| ((t.max(0.0) * f64::from(rate_hz)) as usize / window).min(levels.len() - 1);
    times_s
        .iter()
        .map(|&t| {
            let (a, b) = (index(t), index(t + span_s));
            let loudest = levels[a..=b].iter().copied().fold(0.0, f64::max);
            10.0 * (loudest / resting).log10()
        })
        .reduce(f64::max)
}

/// Power spectrum of `samples` under one Hann window spanning them, zero-padded to a power
/// of two: (bin width Hz, power per bin for bins 0..=N/2). The window matters: cutting a
/// note that still rings at the span's end with no taper spreads its (1,1) over every
/// band (−6 dB per octave), which put a D3 note's 63 Hz band near −27 dB where the
/// issue's Hann measurement of the same render reads −91 dB.
fn power_spectrum(samples: &[f32], rate_hz: u32) -> (f64, Vec<f64>) {
    let n = samples.len().max(2).next_power_of_two();
    let len = samples.len();
    let mut re: Vec<f64> = samples
        .iter()
        .enumerate()
        .map(|(i, &s)| f64::from(s) * hann(i, len))
        .collect();
    re.resize(n, 0.0);
    let mut im = vec![0.0; n];
    fft(&mut re, &mut im);
    let power = (0..=n / 2).map(|k| re[k] * re[k] + im[k] * im[k]).collect();
    (f64::from(rate_hz) / n as f64, power)
}

/// The upper edge of octave band `i` of [`OCTAVE_CENTRES_HZ`] (its centre times √2), Hz.
pub fn band_top_hz(i: usize) -> f64 {
    OCTAVE_CENTRES_HZ[i] * 2f64.sqrt()
}

/// The energy of a power spectrum (bin width `bin_hz`) in the octave band centred on
/// `centre_hz`, from centre/√2 (included) to centre·√2. DC never falls in a band.
fn octave_energy(bin_hz: f64, power: &[f64], centre_hz: f64) -> f64 {
    let (lo, hi) = (centre_hz / 2f64.sqrt(), centre_hz * 2f64.sqrt());
    power
        .iter()
        .enumerate()
        .filter(|(k, _)| (lo..hi).contains(&(*k as f64 * bin_hz)))
        .map(|(_, p)| p)
        .sum()
}

/// Octave-band shares (dB) and power-weighted centroid (Hz) of a power spectrum; DC left out.
fn bands_and_centroid(bin_hz: f64, power: &[f64]) -> ([f64; 7], f64) {
    let total: f64 = power.iter().skip(1).sum::<f64>().max(1e-300);
    let mut bands = [0.0; 7];
    for (band, &centre) in bands.iter_mut().zip(&OCTAVE_CENTRES_HZ) {
        let energy = octave_energy(bin_hz, power, centre);
        *band = 10.0 * (energy / total).max(1e-30).log10();
    }
    let moment: f64 = power
        .iter()
        .enumerate()
        .skip(1)
        .map(|(k, p)| k as f64 * bin_hz * p)
        .sum();
    (bands, moment / total)
}

/// Measure one note (mono `samples` at `rate_hz`): the onset and, over the first second
/// after it (or what there is), the octave-band shares, the centroid and the (1,1).
/// None for a silent signal.
pub fn profile(samples: &[f32], rate_hz: u32) -> Option<Profile> {
    let start = onset(samples, rate_hz)?;
    let len = ((ANALYSIS_SPAN_S * f64::from(rate_hz)) as usize).min(samples.len() - start);
    let span = &samples[start..start + len];
    let (bin_hz, power) = power_spectrum(span, rate_hz);
    let (bands_db, centroid_hz) = bands_and_centroid(bin_hz, &power);
    let principal = principal_hz(&spectrum(span, rate_hz), 40.0, 400.0, &KETTLEDRUM_RATIOS);
    Some(Profile {
        onset_s: start as f64 / f64::from(rate_hz),
        bands_db,
        centroid_hz,
        principal_hz: principal,
    })
}

/// Share (dB of the total) of the first second after the onset that lies between `lo_hz`
/// and `hi_hz`, e.g. the low thump below the (1,1). None for a silent signal.
pub fn share_between_db(samples: &[f32], rate_hz: u32, lo_hz: f64, hi_hz: f64) -> Option<f64> {
    let start = onset(samples, rate_hz)?;
    let len = ((ANALYSIS_SPAN_S * f64::from(rate_hz)) as usize).min(samples.len() - start);
    let (bin_hz, power) = power_spectrum(&samples[start..start + len], rate_hz);
    let total: f64 = power.iter().skip(1).sum::<f64>().max(1e-300);
    let inside: f64 = power
        .iter()
        .enumerate()
        .filter(|(k, _)| (lo_hz..hi_hz).contains(&(*k as f64 * bin_hz)))
        .map(|(_, p)| p)
        .sum();
    Some(10.0 * (inside / total).max(1e-30).log10())
}

/// The frequency of the partial near `near_hz` (searched within ±4 %) in a Hann window of
/// `window_s` seconds starting `at_s` after the signal's start, by the peak of a zero-padded
/// spectrum (×16) refined by parabolic interpolation. None when the window runs off the end.
pub fn partial_at(
    samples: &[f32],
    rate_hz: u32,
    at_s: f64,
    window_s: f64,
    near_hz: f64,
) -> Option<f64> {
    let fs = f64::from(rate_hz);
    let (a, len) = (
        (at_s * fs).round() as usize,
        (window_s * fs).round() as usize,
    );
    if len < 16 || a + len > samples.len() {
        return None;
    }
    let n = (16 * len).next_power_of_two();
    let mut re = vec![0.0; n];
    let mut im = vec![0.0; n];
    for (i, (r, &s)) in re.iter_mut().zip(&samples[a..a + len]).enumerate() {
        *r = f64::from(s) * hann(i, len);
    }
    fft(&mut re, &mut im);
    let spec: Vec<(f64, f64)> = (0..=n / 2)
        .map(|k| {
            (
                k as f64 * fs / n as f64,
                (re[k] * re[k] + im[k] * im[k]).sqrt(),
            )
        })
        .collect();
    peak_in(&spec, near_hz * 0.96, near_hz * 1.04).map(|p| p.0)
}

/// Pitch glide of the partial near `near_hz`, %: its frequency 10–70 ms after the onset
/// against 0.5–0.6 s (a 60 ms window resolves the (1,1) from the (0,1) and (2,1) that a
/// 30 ms one smears together). None when the note is shorter.
pub fn glide_percent(samples: &[f32], rate_hz: u32, near_hz: f64) -> Option<f64> {
    let t0 = onset(samples, rate_hz)? as f64 / f64::from(rate_hz);
    let early = partial_at(samples, rate_hz, t0 + 0.01, 0.06, near_hz)?;
    let late = partial_at(samples, rate_hz, t0 + 0.5, 0.1, near_hz)?;
    Some(100.0 * (early / late - 1.0))
}

/// Level (dB, arbitrary reference) of the partial near `near_hz` in successive Hann
/// windows of `window_s` seconds from `from_s` to `to_s` after the signal's start, and
/// the least-squares T60 (s) of that decay: 60 dB over the fitted slope. None when the
/// span is too short or the partial falls less than `min_fall_db` ([`t60_of`]).
pub fn partial_t60(
    samples: &[f32],
    rate_hz: u32,
    near_hz: f64,
    (span_s, window_s): ((f64, f64), f64),
    min_fall_db: f64,
) -> Option<f64> {
    let points = levels(samples, rate_hz, (0, span_s), window_s, |w| {
        let (_, amp) = peak_in(&spectrum(w, rate_hz), near_hz * 0.97, near_hz * 1.03)?;
        Some(20.0 * amp.max(1e-12).log10())
    });
    t60_of(&points, min_fall_db)
}

/// Energy of an octave band (centre `centre_hz`) in successive windows: the band's T60 (s)
/// from a least-squares line through its level from `from_s` to `to_s` after the onset, in
/// windows of `window_s` seconds. None when the band falls less than `min_fall_db`
/// ([`t60_of`]).
pub fn band_t60(
    samples: &[f32],
    rate_hz: u32,
    centre_hz: f64,
    (span_s, window_s): ((f64, f64), f64),
    min_fall_db: f64,
) -> Option<f64> {
    let start = onset(samples, rate_hz)?;
    let points = levels(samples, rate_hz, (start, span_s), window_s, |w| {
        let (bin, power) = power_spectrum(w, rate_hz);
        let energy = octave_energy(bin, &power, centre_hz);
        (energy > 0.0).then(|| 10.0 * energy.log10())
    });
    t60_of(&points, min_fall_db)
}

/// A level (dB, by `level`) of successive windows of `window_s` seconds, half overlapping,
/// from `from_s` to `to_s` after frame `start`: (window start s, dB) where it has one.
fn levels(
    samples: &[f32],
    rate_hz: u32,
    (start, (from_s, to_s)): (usize, (f64, f64)),
    window_s: f64,
    level: impl Fn(&[f32]) -> Option<f64>,
) -> Vec<(f64, f64)> {
    let fs = f64::from(rate_hz);
    let len = (window_s * fs).round() as usize;
    let mut points = Vec::new();
    let mut t = from_s;
    while t + window_s <= to_s {
        let a = start + (t * fs).round() as usize;
        if a + len > samples.len() {
            break;
        }
        if let Some(db) = level(&samples[a..a + len]) {
            points.push((t, db));
        }
        t += 0.5 * window_s;
    }
    points
}

/// T60 (s) of levels (time s, dB) from their least-squares slope; None for fewer than three
/// points or a line that falls by less than `min_fall_db` over them (with
/// [`MIN_DECAY_DB`]: noise or a sustained sound, whose T60 of minutes read off a flat line
/// means nothing; 0 keeps every falling line).
fn t60_of(points: &[(f64, f64)], min_fall_db: f64) -> Option<f64> {
    if points.len() < 3 {
        return None;
    }
    let slope = crate::base::stats::least_squares_line(points).slope;
    let span_s = points[points.len() - 1].0 - points[0].0;
    (slope < 0.0 && slope * span_s <= -min_fall_db).then(|| -60.0 / slope)
}

/// The magnitude spectrum of a note over `window_s` from its onset (Hann, zero-padded),
/// as (frequency Hz, level dB re the strongest bin). Empty for a silent signal.
pub fn note_spectrum_db(samples: &[f32], rate_hz: u32, window_s: f64) -> Vec<(f64, f64)> {
    let Some(start) = onset(samples, rate_hz) else {
        return Vec::new();
    };
    let len = (window_s * f64::from(rate_hz)) as usize;
    let spec = spectrum(&samples[start..(start + len).min(samples.len())], rate_hz);
    let db = |amp: f64| 20.0 * amp.max(1e-12).log10();
    let top = spec
        .iter()
        .map(|&(_, m)| db(m))
        .fold(f64::NEG_INFINITY, f64::max);
    spec.into_iter().map(|(f, m)| (f, db(m) - top)).collect()
}

/// The embedded recorded timpani note nearest `tuning_hz` (FluidR3, the sample model's),
/// its spectrum over `window_s` from the onset with frequencies × tuning/(its (1,1)): how
/// that note would look pitched to the tuning. With a name for a legend.
pub fn recorded_reference(tuning_hz: f64, window_s: f64) -> Option<(String, Vec<(f64, f64)>)> {
    let recordings = super::sample::recordings().ok()?;
    let rec = super::sample::nearest(recordings, tuning_hz)?;
    let scale = tuning_hz / rec.principal_hz;
    let points = note_spectrum_db(&rec.samples, rec.rate_hz, window_s)
        .into_iter()
        .map(|(f, d)| (f * scale, d))
        .collect();
    Some((
        format!("recorded {} at {:.0} Hz", rec.name, tuning_hz),
        points,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::TAU;

    /// A decaying sinusoid: its octave band holds almost all the energy, the centroid sits
    /// on its frequency, the T60 is read back (5 %) and a gliding partial is tracked.
    #[test]
    fn measures_a_known_signal() {
        let rate = 48_000;
        let (f0, t60) = (250.0, 0.8);
        let tau = t60 / 1000f64.ln();
        let mut s = vec![0.0f32; 4800];
        s.extend((0..96_000).map(|i| {
            let t = i as f64 / 48_000.0;
            ((TAU * f0 * t).sin() * (-t / tau).exp()) as f32
        }));
        let p = profile(&s, rate).unwrap();
        assert!((p.onset_s - 0.1).abs() < 0.003, "{}", p.onset_s);
        assert!(p.bands_db[2] > -0.5, "{:?}", p.bands_db);
        assert!(
            p.bands_db[0] < -20.0 && p.bands_db[6] < -40.0,
            "{:?}",
            p.bands_db
        );
        assert!((p.centroid_hz / f0 - 1.0).abs() < 0.1, "{}", p.centroid_hz);
        let onset = p.onset_s;
        let est = partial_t60(
            &s,
            rate,
            f0,
            ((onset + 0.05, onset + 0.9), 0.1),
            MIN_DECAY_DB,
        )
        .unwrap();
        assert!((est / t60 - 1.0).abs() < 0.05, "{est}");
        let band = band_t60(&s, rate, 250.0, ((0.05, 0.9), 0.1), MIN_DECAY_DB).unwrap();
        assert!((band / t60 - 1.0).abs() < 0.05, "{band}");
        let f = partial_at(&s, rate, 0.2, 0.05, 245.0).unwrap();
        assert!((f / f0 - 1.0).abs() < 2e-3, "{f}");
        assert!(super::onset(&[0.0; 10], rate).is_none());
        assert_eq!(not_a_note(&s, rate), None);
    }

    /// Noise, a flat tone, silence and a scrap of a note are refused with the reason; a
    /// level that does not fall has no T60.
    #[test]
    fn refuses_what_is_not_a_struck_note() {
        let rate = 48_000;
        let mut rng = crate::base::rng::Rng::new(3);
        let noise: Vec<f32> = (0..96_000).map(|_| rng.uniform(-0.1, 0.1) as f32).collect();
        let why = not_a_note(&noise, rate).unwrap();
        assert!(why.contains("no struck note"), "{why}");
        let tone: Vec<f32> = (0..96_000)
            .map(|i| (TAU * 200.0 * i as f64 / 48_000.0).sin() as f32)
            .collect();
        assert!(not_a_note(&tone, rate).unwrap().contains("no struck note"));
        assert_eq!(not_a_note(&[0.0; 96_000], rate).unwrap(), "silent");
        let scrap: Vec<f32> = tone[..2400].to_vec();
        assert!(not_a_note(&scrap, rate).unwrap().contains("too short"));
        let span = ((0.05, 0.9), 0.1);
        assert_eq!(band_t60(&tone, rate, 250.0, span, MIN_DECAY_DB), None);
        assert_eq!(partial_t60(&tone, rate, 200.0, span, MIN_DECAY_DB), None);
    }
}
