//! Sympathetic resonance (modal model): a struck head's sound reaches the other heads of
//! the kit through the air and drives their modes, so partials they share ring faintly.
//!
//! The sound a drum radiates, as the mix has it, is taken as the pressure it makes
//! [`REFERENCE_DISTANCE_M`] away, full scale being [`FULL_SCALE_PA`] (an ff stroke, −6
//! dBFS, then peaks near 6.3 Pa ≈ 110 dB SPL at 1 m, the low end of what orchestral
//! timpani reach up close: an assumption, not a measurement of ours). At
//! another head, a distance d between centres, it arrives d/c later and (1 m)/d weaker;
//! across that head it is a plane wave grazing the head, p(x, t) = p(t − x·ŝ/c) (ŝ the
//! direction it travels, at θ_s in the head's frame). Its generalised force on the head's
//! mode k (shape J_m(j r/a)·cos or sin mθ) is ∫ p Φ_k dA; at the mode's own frequency
//! ω_k, wavenumber k = ω_k/c (a mode answers only near its resonance), the plane wave's
//! overlap with the shape is exact (Jacobi–Anger and Lommel, the reciprocal of the
//! radiation's [`radiation::radial_overlap`]):
//!
//! ∫ Φ_k e^{−i k x·ŝ} dA = 2π (−i)^m I_m (cos or sin mθ_s),  I_m = ∫₀^a J_m(j r/a) J_m(k r) r dr,
//!
//! so a mode with m even is driven by the pressure, (−1)^{m/2}·2π I_m·p, and one with m
//! odd by its rate, −(−1)^{(m−1)/2}·2π I_m·ṗ/ω_k (a quarter period later), each times its
//! angular factor. For ka ≪ 1 this is the uniform pressure on the axisymmetric modes
//! (2π a² J₁(j)/j · p) and the pressure gradient on the m = 1 modes (π a³ J₂(j)/j · ṗ/c),
//! as first modelled; at the heads' ka of 1–7 below 1 kHz the gradient alone
//! overstated the m = 1 modes with nodal circles (a 29-inch head's (1,3) at 392 Hz, ka
//! 2.6, by 8.5 dB) and left out m ≥ 2. Each receiving head runs its voices below
//! [`MAX_HZ`] (gains as in its own sound) driven by F/M_k, and what they radiate is added
//! to its own sound. One way only: the ringing of a
//! receiving head does not drive the source back (it is 20 dB and more below it). A hand
//! resting on a receiving head damps its ringing as it damps its own sound, and at a pedal
//! change the head starts again at rest at its new pitch.

use super::SAMPLE_RATE_HZ;
use super::modal::{BLOCK, FLUSH_FLOOR, SoundHeads, first_voice_change, periodic, tuning_at};
use super::partials::SoundHead;
use super::radiation;
use super::voices::{BankState, Voice, VoiceBank};
use crate::drum::modes::{HeadMode, Orientation, SOUND_SPEED_MPS};
use crate::kit::Kit;
use std::f64::consts::{PI, TAU};

/// Pressure of a full-scale output at the reference distance, Pa.
pub const FULL_SCALE_PA: f64 = 12.6;
/// Distance at which the output is taken as the radiated pressure, m.
pub const REFERENCE_DISTANCE_M: f64 = 1.0;
/// The receiving heads run at the audio rate over this (6 kHz: their modes are below
/// [`MAX_HZ`]); their output is brought back by linear interpolation.
const DECIMATION: usize = 8;
/// Cut-off of the low-pass that takes the sub-step rate's images out of the output, Hz
/// (see [`ImageFilter`]).
const IMAGE_CUTOFF_HZ: f64 = 1500.0;

/// One receiving head's coupling: its voices below [`MAX_HZ`], their forces per unit
/// pressure and pressure rate from each drum it hears, and those drums.
#[derive(Clone, Debug)]
struct Receiver {
    bank: VoiceBank,
    voices: Vec<Voice>,
    inv_mass: Vec<f64>,
    /// Per source (in the order of `sources`), per voice: the force per unit pressure (m
    /// even) and per unit ṗ/c (m odd), m² and m³ (see the module docs) — source by
    /// source, so the sum over the voices runs along contiguous lanes.
    weights: Vec<[Vec<f64>; 2]>,
    /// Per source drum i ≠ j: (i, delay in frames, pressure per output unit).
    sources: Vec<(usize, usize, f64)>,
}

/// The force on `mode` of a head of radius `a` per unit pressure and per unit ṗ/c of a
/// plane wave grazing it at θ_s (`theta`, rad, head frame): the module docs' overlap at the
/// mode's own wavenumber.
fn plane_wave_coupling(mode: &HeadMode, a: f64, theta: f64) -> [f64; 2] {
    let k = TAU * mode.freq_hz / SOUND_SPEED_MPS;
    let m = mode.m;
    let angle = f64::from(m) * theta;
    let angular = match mode.orientation {
        Orientation::Cos => angle.cos(),
        Orientation::Sin => angle.sin(),
    };
    let overlap = TAU * radiation::radial_overlap(mode, a, k) * angular;
    let sign = radiation::multipole_sign(m);
    if m.is_multiple_of(2) {
        [sign * overlap, 0.0]
    } else {
        [0.0, -sign * overlap / k]
    }
}

/// A receiving drum's sympathetic output (the same units as its own synthesis: summed
/// gain/ω × modal velocity) and the states to resume it.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SympathyState {
    pub out: Vec<f32>,
    /// Saved: (frame, bank state, the last sub-step's output, the image filter).
    saved: Vec<(usize, BankState, f32, ImageFilter)>,
    /// The voices it rang with per tuning, from its first frame (a change restarts it
    /// there).
    voices: Vec<(usize, Vec<Voice>)>,
}

/// The receiving heads run at the sub-step rate (6 kHz) and come back to 48 kHz by
/// linear interpolation, which leaves images of every partial f at 6 kHz ± f only
/// 30–40 dB down: faint inharmonic tones near 5–7 kHz on every head that rings
/// sympathetically (a 570 Hz partial's image at 5.43 kHz carried more of the mix's 4 kHz
/// octave band than the struck head's own modes). A fourth-order Butterworth low-pass at
/// [`IMAGE_CUTOFF_HZ`] (two biquad sections, transposed direct form II) takes them out:
/// −0.2 dB at 1 kHz, where the sympathetic partials stop ([`MAX_HZ`]), −45 dB at 5.4 kHz.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct ImageFilter([[f64; 2]; 2]);

impl ImageFilter {
    /// Each section's (b0, b1, b2, a1, a2) at the audio rate (bilinear transform, the
    /// cut-off pre-warped; the Butterworth pair's Q = 1/(2 cos(π/8)), 1/(2 cos(3π/8))).
    fn sections() -> [[f64; 5]; 2] {
        let k = (PI * IMAGE_CUTOFF_HZ / f64::from(SAMPLE_RATE_HZ)).tan();
        [PI / 8.0, 3.0 * PI / 8.0].map(|angle| {
            let q = 0.5 / angle.cos();
            let norm = 1.0 / (1.0 + k / q + k * k);
            let b0 = k * k * norm;
            [
                b0,
                2.0 * b0,
                b0,
                2.0 * (k * k - 1.0) * norm,
                (1.0 - k / q + k * k) * norm,
            ]
        })
    }

    /// One sample through both sections.
    fn run(&mut self, sections: &[[f64; 5]; 2], x: f32) -> f32 {
        let mut v = f64::from(x);
        for (s, [b0, b1, b2, a1, a2]) in self.0.iter_mut().zip(sections) {
            let y = b0 * v + s[0];
            s[0] = b1 * v - a1 * y + s[1];
            s[1] = b2 * v - a2 * y;
            v = y;
        }
        v as f32
    }

    /// Whether its state has died away (below [`FLUSH_FLOOR`]).
    fn is_silent(&self) -> bool {
        self.0
            .iter()
            .flatten()
            .all(|s| s.abs() < f64::from(FLUSH_FLOOR))
    }
}

impl Receiver {
    /// Drum `j`'s receiver when its head is `head`; `heads` say which drums sound.
    fn new(kit: &Kit, heads: &SoundHeads, j: usize, head: &SoundHead) -> Option<Receiver> {
        let a = head.modes.radius_m();
        let centre = kit.drums[j].centre();
        let heard: Vec<(usize, usize, f64, f64)> = (0..kit.drums.len())
            .filter(|&i| {
                i != j
                    && heads
                        .get(i)
                        .is_some_and(|t| t.iter().any(|(_, h)| h.is_some()))
            })
            .map(|i| {
                let from = kit.drums[i].centre();
                let d = (centre - from).length().max(0.05);
                let delay = (d / SOUND_SPEED_MPS * f64::from(SAMPLE_RATE_HZ)).round() as usize;
                let scale = FULL_SCALE_PA * REFERENCE_DISTANCE_M / d;
                let dir = head.modes.local(centre + (centre - from));
                (i, delay, scale, dir.y.atan2(dir.x))
            })
            .collect();
        // Each voice below MAX_HZ with its couplings, and how loud it can ring: driven at
        // resonance its output goes as the force per pascal (the rate's weight times k)
        // over its modal mass, times its decay and its gain.
        let candidates: Vec<(usize, Vec<[f64; 2]>, f64)> = (0..head.voices.len())
            .filter(|&k| head.voices[k].freq_hz <= MAX_HZ)
            .map(|k| {
                let (mode, voice) = (&head.modes.modes()[k], &head.voices[k]);
                let weights: Vec<[f64; 2]> = heard
                    .iter()
                    .map(|&(.., theta)| plane_wave_coupling(mode, a, theta))
                    .collect();
                let wavenumber = TAU * mode.freq_hz / SOUND_SPEED_MPS;
                let force = weights
                    .iter()
                    .map(|[p, rate]| p.abs() + rate.abs() * wavenumber)
                    .fold(0.0, f64::max);
                let strength = force / mode.modal_mass_kg * voice.t60_s * voice.gain.abs();
                (k, weights, strength)
            })
            .collect();
        let loudest = candidates.iter().map(|c| c.2).fold(0.0, f64::max);
        let floor = loudest * 10f64.powf(-RECEIVER_FLOOR_DB / 20.0);
        let picked: Vec<(usize, Vec<[f64; 2]>, f64)> =
            candidates.into_iter().filter(|c| c.2 > floor).collect();
        if picked.is_empty() {
            return None;
        }
        let voices: Vec<_> = picked
            .iter()
            .map(|(k, ..)| super::modal::calibrated_voice(&head.voices[*k]))
            .collect();
        let inv_mass = picked
            .iter()
            .map(|(k, ..)| 1.0 / head.modes.modes()[*k].modal_mass_kg)
            .collect();
        let weights = (0..heard.len())
            .map(|s| [0, 1].map(|c| picked.iter().map(|(_, w, _)| w[s][c]).collect()))
            .collect();
        let sources = heard
            .iter()
            .map(|&(i, delay, scale, _)| (i, delay, scale))
            .collect();
        Some(Receiver {
            bank: VoiceBank::new(&voices, f64::from(SAMPLE_RATE_HZ) / DECIMATION as f64),
            voices,
            inv_mass,
            weights,
            sources,
        })
    }
}

/// Highest mode frequency that rings sympathetically, Hz (the shared low partials; the
/// coupling of higher modes is far below audibility and not worth the time).
pub const MAX_HZ: f64 = 1000.0;
/// A receiving head leaves out the modes that could ring this far below its loudest, dB
/// (the many with several nodal diameters, which a plane wave barely drives and which
/// radiate little).
const RECEIVER_FLOOR_DB: f64 = 40.0;

/// Drum `j`'s sympathetic output, `frames` long, from the other drums' radiated sound
/// (the time derivative of their synthesis `monos[i]`, as the mix radiates it), its head
/// as `heads[j]` tunes it over the performance and damped while a hand rests on it (from
/// each of `touches`, from when to when, s), resuming `state` from the
/// first frame a source's sound changed (`changed[i]`, per drum). Returns the first frame
/// rewritten. Bit for bit a whole render.
pub fn resynthesise(
    kit: &Kit,
    (heads, touches): (&SoundHeads, &[(f64, f64)]),
    j: usize,
    (monos, changed): (&[&[f32]], &[usize]),
    frames: usize,
    state: &mut SympathyState,
) -> usize {
    let tunings = heads.get(j).map_or(&[][..], Vec::as_slice);
    let receivers: Vec<Option<Receiver>> = tunings
        .iter()
        .map(|(_, h)| Receiver::new(kit, heads, j, h.as_deref()?))
        .collect();
    let Some(sources) = receivers.iter().flatten().next().map(|r| r.sources.clone()) else {
        // Nothing rings here: silent, and unchanged if it was silent already.
        let unchanged =
            state.voices.iter().all(|(_, v)| v.is_empty()) && state.out.iter().all(|v| *v == 0.0);
        let from = if unchanged { state.out.len() } else { 0 };
        *state = SympathyState {
            out: vec![0.0; frames],
            ..SympathyState::default()
        };
        return from;
    };
    let voices: Vec<(usize, Vec<Voice>)> = tunings
        .iter()
        .zip(&receivers)
        .map(|((f, _), rx)| (*f, rx.as_ref().map_or(Vec::new(), |r| r.voices.clone())))
        .collect();
    // From the first frame a source's sound changes here, or the head's own synthesis
    // changed (its voices may have: a new tuning or size).
    let from = sources
        .iter()
        .map(|(i, delay, ..)| changed[*i].saturating_add(*delay))
        .chain([changed[j]])
        .chain(first_voice_change(&voices, &state.voices))
        .min()
        .unwrap_or(usize::MAX)
        .min(state.out.len());
    state.voices = voices;
    let resume = state.saved.iter().rposition(|(f, ..)| *f <= from);
    let start = resume.map_or(0, |k| state.saved[k].0).min(frames);
    let mut index = tuning_at(tunings, start);
    let mut receiver = receivers[index].clone();
    let mut last = 0.0f32;
    let mut images = ImageFilter::default();
    if let Some(k) = resume.filter(|_| start > 0) {
        if let Some(rx) = receiver.as_mut() {
            rx.bank.restore(&state.saved[k].1);
        }
        (last, images) = (state.saved[k].2, state.saved[k].3);
    }
    let sections = ImageFilter::sections();
    state.saved.retain(|(f, ..)| *f < start && periodic(*f));
    state.out.resize(frames, 0.0);
    state.out[start..].fill(0.0);
    let steps = BLOCK / DECIMATION;
    let mut sub = [0.0f32; BLOCK / DECIMATION];
    let fs = f64::from(SAMPLE_RATE_HZ);
    let damping = super::touch_factor(fs / DECIMATION as f64) as f32;
    let mut ringing = start > 0;
    let mut input = Vec::new();
    // The (stride, voices) `input`'s rows are laid out for.
    let mut layout = (0, 0);
    let mut fields: Vec<[f64; 2]> = Vec::new();
    let mut forces: Vec<f64> = Vec::new();
    for n0 in (start..frames).step_by(BLOCK) {
        let now = tuning_at(tunings, n0);
        if now != index {
            // A pedal change: the head, damped before it, starts again at rest.
            index = now;
            receiver = receivers[index].clone();
            ringing = false;
        }
        let Some(rx) = receiver.as_mut() else {
            (last, images) = (0.0, ImageFilter::default());
            continue;
        };
        let stride = rx.bank.stride();
        if layout != (stride, rx.voices.len()) {
            // Rows are written voice by voice below: their padding lanes stay zero.
            layout = (stride, rx.voices.len());
            input = vec![0.0; steps * stride];
        }
        // Also at the start of the last block, where a cut synthesis resumes (see the
        // drums' own synthesis).
        if periodic(n0) || n0 + BLOCK >= frames {
            state.saved.push((n0, rx.bank.state(), last, images));
        }
        let n1 = (n0 + BLOCK).min(frames);
        let used = (n1 - n0).div_ceil(DECIMATION);
        let mut driven = false;
        for (row, a) in input
            .chunks_exact_mut(stride)
            .zip((n0..n1).step_by(DECIMATION))
        {
            let z = (a + DECIMATION).min(n1);
            // Per source, the mean pressure at the head's centre and its rate over c over
            // the sub-step (Pa, Pa/m; the rate's mean telescopes to its ends).
            fields.clear();
            for (i, delay, scale) in &rx.sources {
                let mono = monos[*i];
                // The source's output as heard here at frame n (delayed; 0 before it).
                let heard = |n: usize| {
                    n.checked_sub(*delay)
                        .and_then(|m| mono.get(m))
                        .map_or(0.0, |v| f64::from(*v))
                };
                let heard_before = |n: usize| if n == 0 { 0.0 } else { heard(n - 1) };
                // The radiated sound at frame n here: the source's derivative, delayed.
                let at = |n: usize| (heard(n) - heard_before(n)) * fs;
                // Its mean over the sub-step telescopes to the ends.
                let mean = (heard(z - 1) - heard_before(a)) * fs / (z - a) as f64;
                let before = if a == 0 { 0.0 } else { at(a - 1) };
                let rate = scale * (at(z - 1) - before) * fs / ((z - a) as f64 * SOUND_SPEED_MPS);
                fields.push([scale * mean, rate]);
            }
            if fields.iter().all(|f| *f == [0.0; 2]) {
                row.fill(0.0);
                continue;
            }
            // Per voice, the sources' forces summed in their order (as `Sum` would: the
            // first source's force, then each other's added).
            forces.clear();
            let [pressure, rate] = &rx.weights[0];
            let [mean, slope] = fields[0];
            forces.extend(
                pressure
                    .iter()
                    .zip(rate)
                    .map(|(w0, w1)| w0 * mean + w1 * slope),
            );
            for ([pressure, rate], [mean, slope]) in rx.weights.iter().zip(&fields).skip(1) {
                for ((force, w0), w1) in forces.iter_mut().zip(pressure).zip(rate) {
                    *force += w0 * mean + w1 * slope;
                }
            }
            for ((r, force), im) in row.iter_mut().zip(&forces).zip(&rx.inv_mass) {
                *r = (force * im) as f32;
            }
            driven = true;
        }
        sub.fill(0.0);
        if driven || ringing {
            let t = n0 as f64 / fs;
            let resting = super::resting(touches, t);
            rx.bank.damp(if resting { damping } else { 1.0 });
        }
        if driven {
            rx.bank
                .render_driven(&input[..used * stride], &mut sub[..used]);
            ringing = true;
        } else if ringing {
            rx.bank.render_free(&mut sub[..used]);
            ringing = !rx.bank.flush(FLUSH_FLOOR);
        } else if last == 0.0 && images.is_silent() {
            continue;
        }
        // Back to the audio rate: linear between the sub-steps' outputs, the images of
        // the sub-step rate filtered out.
        for (k, o) in state.out[n0..n1].iter_mut().enumerate() {
            let (step, phase) = (k / DECIMATION, (k % DECIMATION + 1) as f32);
            let from = if step == 0 { last } else { sub[step - 1] };
            *o = images.run(
                &sections,
                from + (sub[step] - from) * phase / DECIMATION as f32,
            );
        }
        last = sub[used - 1];
    }
    start
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The image filter's gain on a steady sine after its start has died away, dB.
    fn gain_db(hz: f64) -> f64 {
        let (sections, mut filter) = (ImageFilter::sections(), ImageFilter::default());
        let fs = f64::from(SAMPLE_RATE_HZ);
        let (mut peak_in, mut peak_out) = (0.0f64, 0.0f64);
        for n in 0..48_000 {
            let x = (std::f64::consts::TAU * hz * n as f64 / fs).sin() as f32;
            let y = filter.run(&sections, x);
            if n > 24_000 {
                peak_in = peak_in.max(f64::from(x.abs()));
                peak_out = peak_out.max(f64::from(y.abs()));
            }
        }
        20.0 * (peak_out / peak_in).log10()
    }

    /// The coupling of a grazing plane wave to a mode is its overlap with the mode's
    /// shape, ∫ Φ e^{−i k x·ŝ} dA, by quadrature: real for m even (the pressure's
    /// weight), imaginary for m odd (k times the weight of ṗ/c), for modes up to m = 4
    /// and n = 3 of the 29-inch head; and at small ka it is the first-order expansion's
    /// uniform pressure (m = 0) and gradient (m = 1).
    #[test]
    fn plane_wave_coupling_is_the_overlap_with_the_shape() {
        use crate::drum::bessel::bessel_j;
        use crate::drum::{FrequencySource, HeadModes};
        let drum = &Kit::standard().drums[1];
        let head = HeadModes::below_hz(drum, FrequencySource::Measured, MAX_HZ).unwrap();
        let a = head.radius_m();
        let theta_s = 0.7;
        let mut checked = 0;
        for mode in head.modes().iter().filter(|k| k.m <= 4 && k.n <= 3) {
            let k = TAU * mode.freq_hz / SOUND_SPEED_MPS;
            let (nr, nt) = (600, 256);
            let (mut re, mut im) = (0.0, 0.0);
            for i in 0..nr {
                let r = (i as f64 + 0.5) / nr as f64 * a;
                let radial = bessel_j(mode.m, mode.bessel_zero() * r / a) * r * a / nr as f64;
                for t in 0..nt {
                    let th = t as f64 / nt as f64 * TAU;
                    let angular = match mode.orientation {
                        Orientation::Cos => (f64::from(mode.m) * th).cos(),
                        Orientation::Sin => (f64::from(mode.m) * th).sin(),
                    };
                    let phase = -k * r * (th - theta_s).cos();
                    let w = radial * angular * TAU / nt as f64;
                    re += w * phase.cos();
                    im += w * phase.sin();
                }
            }
            let [per_p, per_rate] = plane_wave_coupling(mode, a, theta_s);
            let scale = a * a * 1e-4;
            let (m, n) = (mode.m, mode.n);
            if mode.m.is_multiple_of(2) {
                assert!(
                    (re - per_p).abs() < scale && im.abs() < scale,
                    "({m},{n}): {re} {im} vs {per_p}"
                );
            } else {
                assert!(
                    (im / k - per_rate).abs() < scale / k && re.abs() < scale,
                    "({m},{n}): {re} {im} vs {per_rate}"
                );
            }
            checked += 1;
        }
        assert!(checked >= 12, "{checked}");
        // At 5 Hz (ka 0.03) the first order: p·2πa²J₁(j)/j and −(ṗ/c)·πa³J₂(j)/j·cos θ_s.
        let low = |m: u32| {
            let mut mode = head
                .modes()
                .iter()
                .find(|k| (k.m, k.n, k.orientation) == (m, 1, Orientation::Cos))
                .unwrap()
                .clone();
            mode.freq_hz = 5.0;
            (plane_wave_coupling(&mode, a, theta_s), mode.bessel_zero())
        };
        let ([p0, _], j0) = low(0);
        let first = TAU * a * a * bessel_j(1, j0) / j0;
        assert!((p0 / first - 1.0).abs() < 1e-3, "{p0} vs {first}");
        let ([_, d1], j1) = low(1);
        let first = -PI * a.powi(3) * bessel_j(2, j1) / j1 * theta_s.cos();
        assert!((d1 / first - 1.0).abs() < 1e-3, "{d1} vs {first}");
    }

    /// Flat where the sympathetic partials ring (up to 1 kHz: within 0.3 dB), and the
    /// images of the 6 kHz sub-step rate (5–7 kHz) at least 40 dB down.
    #[test]
    fn the_image_filter_passes_the_partials_and_stops_the_images() {
        for hz in [100.0, 500.0, MAX_HZ] {
            assert!(gain_db(hz).abs() < 0.3, "{hz} Hz: {:.2} dB", gain_db(hz));
        }
        for hz in [5000.0, 5430.0, 6600.0] {
            assert!(gain_db(hz) < -40.0, "{hz} Hz: {:.1} dB", gain_db(hz));
        }
    }
}
