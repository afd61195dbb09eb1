//! The signal-based sound model (seed 002): each contact starts decaying sinusoidal
//! partials at the head's mode frequencies, decays and gains (the voices of
//! [`voices_for`]), each weighted by its mode shape at the impact point, plus a
//! short noise burst (deterministic, seeded by drum and contact), all in proportion to
//! the impact speed: a strike at [`reference_speed_mps`] gives partials of total amplitude
//! ≈ `REFERENCE_LEVEL` at the playing spot.

use super::modal::FLUSH_FLOOR;
use super::voices::{Voice, VoiceBank};
use super::{REFERENCE_LEVEL, SAMPLE_RATE_HZ, reference_speed_mps};
use crate::base::rng::Rng;
use crate::drum::{DrumSet, HeadModes, Orientation};

/// The partials of a head: the indices in `head.modes()` and the voices (gains × `scale`)
/// of the simulated head's modes below 0.45 × 48 kHz heard on its axis through the
/// player (θ = 0), where the cos orientations radiate with the kit's gain and the sin
/// orientations, with a nodal line there, are silent.
fn voices_for(head: &HeadModes, scale: f64) -> (Vec<usize>, Vec<Voice>) {
    let nyquist_margin = 0.45 * f64::from(SAMPLE_RATE_HZ);
    head.modes()
        .iter()
        .enumerate()
        .filter(|(_, m)| {
            m.orientation == Orientation::Cos && m.freq_hz < nyquist_margin && m.gain > 0.0
        })
        .map(|(k, m)| {
            (
                k,
                Voice {
                    freq_hz: m.freq_hz,
                    t60_s: m.t60_s,
                    gain: m.gain * scale,
                    glide: 0.0,
                },
            )
        })
        .unzip()
}

/// Scale of the partials: with the kit's gains and the shapes at the playing spot, a
/// reference strike peaks near `REFERENCE_LEVEL` (measured: 0.22 at scale 2 → 4.4).
const SIGNAL_SCALE: f64 = 4.4;
/// Noise burst: amplitude relative to the partials' scale, decay time constant (s),
/// length (s), and one-pole low-pass coefficient (≈ 3 kHz at 48 kHz).
const NOISE_LEVEL: f64 = 0.15;
const NOISE_TAU_S: f64 = 0.002;
const NOISE_LEN_S: f64 = 0.012;
const NOISE_POLE: f64 = 0.67;

/// Render drum `j`'s contacts into `out`, the partials damped while a hand rests on the
/// head (`touches`: from, until; s); returns whether any contact was on it.
pub fn render_drum((drums, touches): (&DrumSet, &[(f64, f64)]), j: usize, out: &mut [f32]) -> bool {
    if drums.head(j).is_none() {
        return false;
    }
    let contacts: Vec<(usize, &crate::drum::ContactEvent)> = drums
        .contacts()
        .iter()
        .enumerate()
        .filter(|(_, c)| c.drum == j)
        .collect();
    if contacts.is_empty() {
        return false;
    }
    let fs = f64::from(SAMPLE_RATE_HZ);
    let damping = super::touch_factor(fs) as f32;
    // Ring `p` over out[from..to], damped where a hand rests (its edges split the span).
    let ring = |p: &mut Partials, out: &mut [f32], from: usize, to: usize| {
        let edges = (touches.iter())
            .flat_map(|&(a, b)| [a, b])
            .map(|t| (t * fs).round().max(0.0) as usize)
            .filter(|&e| e > from && e < to);
        let mut edges: Vec<usize> = edges.chain([to]).collect();
        edges.sort_unstable();
        let mut at = from;
        for edge in edges {
            let resting = super::resting(touches, at as f64 / fs);
            p.bank.damp(if resting { damping } else { 1.0 });
            p.bank.ring(&mut out[at..edge], FLUSH_FLOOR);
            at = edge;
        }
    };
    // The tuning the partials ring at (`DrumSet::head_at`) and them.
    let mut partials: Option<(usize, Partials)> = None;
    let mut cursor = 0;
    for (ci, c) in &contacts {
        let start = ((c.start_s * fs).round().max(0.0) as usize).min(out.len());
        let Some((tuning, head)) = drums.head_at(j, c.start_s) else {
            continue;
        };
        // At a pedal change (the head damped before it) the partials start again at rest
        // at the new pitch.
        if partials.as_ref().is_none_or(|(t, _)| *t != tuning) {
            if let Some((_, p)) = partials.as_mut() {
                ring(p, out, cursor, start);
                cursor = start;
            }
            partials = Some((tuning, Partials::of(head)));
        }
        let Some((_, p)) = partials.as_mut() else {
            continue;
        };
        ring(p, out, cursor, start);
        cursor = start;
        let amp = REFERENCE_LEVEL * c.impact_speed_mps / reference_speed_mps();
        head.shapes_at(head.local(c.point), &mut p.shapes);
        for (d, &k) in p.kick.iter_mut().zip(&p.index) {
            *d = (amp / p.total_gain * SIGNAL_SCALE * p.shapes[k]) as f32;
        }
        p.bank.kick(&p.kick);
        // The noise burst, added directly.
        let mut rng = Rng::new(0x5EED_0000 ^ ((j as u64) << 32) ^ *ci as u64);
        let mut lp = 0.0;
        let len = (NOISE_LEN_S * fs) as usize;
        for (i, o) in out[start..].iter_mut().take(len).enumerate() {
            lp = NOISE_POLE * lp + (1.0 - NOISE_POLE) * rng.uniform(-1.0, 1.0);
            let env = (-(i as f64) / (NOISE_TAU_S * fs)).exp();
            *o += (NOISE_LEVEL * amp * env * lp) as f32;
        }
    }
    if let Some((_, p)) = partials.as_mut() {
        ring(p, out, cursor, out.len());
    }
    true
}

/// A head's partials ringing, and the scratch to kick them.
struct Partials {
    /// Indices of the partials' modes in the head's modes.
    index: Vec<usize>,
    /// The kicks are scaled by the total gain so kits with more or louder modes stay level.
    total_gain: f64,
    bank: VoiceBank,
    shapes: Vec<f64>,
    kick: Vec<f32>,
}

impl Partials {
    /// `head`'s partials at rest.
    fn of(head: &HeadModes) -> Partials {
        let (index, voices) = voices_for(head, 1.0);
        Partials {
            total_gain: voices.iter().map(|v| v.gain).sum::<f64>().max(1e-12),
            bank: VoiceBank::new(&voices, f64::from(SAMPLE_RATE_HZ)),
            shapes: vec![0.0; head.modes().len()],
            kick: vec![0.0f32; index.len()],
            index,
        }
    }
}
