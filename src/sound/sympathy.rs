//! Sympathetic resonance (modal model): a struck head's sound reaches the other heads of
//! the kit through the air and drives their modes, so partials they share ring faintly.
//!
//! The sound a drum radiates, as the mix has it, is taken as the pressure it makes
//! [`REFERENCE_DISTANCE_M`] away, full scale being [`FULL_SCALE_PA`] (an ff stroke, −6
//! dBFS, then peaks near 6.3 Pa ≈ 110 dB SPL at 1 m, the low end of what orchestral
//! timpani reach up close: an assumption, not a measurement of ours). At
//! another head, a distance d between centres, it arrives d/c later and (1 m)/d weaker;
//! across that head the wave is taken as plane, p(x) ≈ p − (x·ŝ)/c·ṗ (ŝ the direction it
//! travels). Its generalised force on the head's mode k is ∫ p Φ_k dA:
//!
//! * m = 0: p·A_k, A_k = ∫Φ_k dA = 2π a² J₁(j)/j (the uniform pressure);
//! * m = 1: −(ṗ/c)·B_k·(cos θ_s or sin θ_s), B_k = π a³ J₂(j)/j (the pressure gradient);
//!
//! and modes with m ≥ 2 see no net force from a plane wave at this order. Each receiving
//! head runs those modes (its m ≤ 1 voices, gains as in its own sound) driven by F/M_k,
//! and what they radiate is added to its own sound. One way only: the ringing of a
//! receiving head does not drive the source back (it is 20 dB and more below it). A hand
//! resting on a receiving head damps its ringing as it damps its own sound, and at a pedal
//! change the head starts again at rest at its new pitch.

use super::SAMPLE_RATE_HZ;
use super::modal::{BLOCK, FLUSH_FLOOR, SoundHeads, first_voice_change, periodic, tuning_at};
use super::partials::SoundHead;
use super::radiation::SOUND_SPEED_MPS;
use super::voices::{BankState, Voice, VoiceBank};
use crate::drum::bessel::bessel_j;
use crate::drum::modes::Orientation;
use crate::kit::Kit;
use std::f64::consts::PI;

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

/// One receiving head's coupling: its m ≤ 1 voices below [`MAX_HZ`], their forces per
/// unit pressure and pressure gradient, and the drums it hears.
#[derive(Clone, Debug)]
struct Receiver {
    bank: VoiceBank,
    voices: Vec<Voice>,
    inv_mass: Vec<f64>,
    /// Per voice: the force per unit pressure (m = 0: ∫Φ dA, m²) and per unit pressure
    /// gradient along local x and y (m = 1: −B_k cos/sin, m³).
    weights: Vec<[f64; 3]>,
    /// Per source drum i ≠ j: (i, delay in frames, pressure per output unit, the direction
    /// the wave travels in the head's local frame (cos θ_s, sin θ_s)).
    sources: Vec<(usize, usize, f64, [f64; 2])>,
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
        let picked: Vec<usize> = (0..head.voices.len())
            .filter(|&k| head.modes.modes()[k].m <= 1 && head.voices[k].freq_hz <= MAX_HZ)
            .collect();
        if picked.is_empty() {
            return None;
        }
        let voices: Vec<_> = picked
            .iter()
            .map(|&k| super::modal::calibrated_voice(&head.voices[k]))
            .collect();
        let inv_mass = picked
            .iter()
            .map(|&k| 1.0 / head.modes.modes()[k].modal_mass_kg)
            .collect();
        let centre = kit.drums[j].centre();
        let weights = picked
            .iter()
            .map(|&k| {
                let mode = &head.modes.modes()[k];
                let j_mn = mode.bessel_zero();
                if mode.m == 0 {
                    [2.0 * PI * a * a * bessel_j(1, j_mn) / j_mn, 0.0, 0.0]
                } else {
                    let b = PI * a.powi(3) * bessel_j(2, j_mn) / j_mn;
                    match mode.orientation {
                        Orientation::Cos => [0.0, -b, 0.0],
                        Orientation::Sin => [0.0, 0.0, -b],
                    }
                }
            })
            .collect();
        let sources = (0..kit.drums.len())
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
                let theta = dir.y.atan2(dir.x);
                (i, delay, scale, [theta.cos(), theta.sin()])
            })
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
        input.resize(steps * stride, 0.0);
        // Also at the start of the last block, where a cut synthesis resumes (see the
        // drums' own synthesis).
        if periodic(n0) || n0 + BLOCK >= frames {
            state.saved.push((n0, rx.bank.state(), last, images));
        }
        let n1 = (n0 + BLOCK).min(frames);
        let used = (n1 - n0).div_ceil(DECIMATION);
        input.fill(0.0);
        let mut driven = false;
        for (row, a) in input
            .chunks_exact_mut(stride)
            .zip((n0..n1).step_by(DECIMATION))
        {
            let z = (a + DECIMATION).min(n1);
            // The mean pressure at the head's centre and its gradient over the sub-step
            // (Pa, Pa/m; the gradient's mean telescopes to its ends).
            let mut field = [0.0f64; 3];
            for (i, delay, scale, [cos, sin]) in &rx.sources {
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
                let gradient =
                    scale * (at(z - 1) - before) * fs / ((z - a) as f64 * SOUND_SPEED_MPS);
                field[0] += scale * mean;
                field[1] += gradient * cos;
                field[2] += gradient * sin;
            }
            if field == [0.0; 3] {
                continue;
            }
            for ((r, w), im) in row.iter_mut().zip(&rx.weights).zip(&rx.inv_mass) {
                *r = ((w[0] * field[0] + w[1] * field[1] + w[2] * field[2]) * im) as f32;
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
