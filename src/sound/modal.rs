//! The modal sound model (seed 000 §4): per head, a [`VoiceBank`] of its sounding modes
//! ([`SoundHead`]: full band, radiation-weighted, calibrated) driven by the contact force
//! the simulation recorded. The force, held over each simulation step, is resampled to
//! 48 kHz by a triangle kernel one step wide each side (linear interpolation, impulse
//! preserved); mode k receives F·Φ_k(x)/M_k (its shape at the contact point over its
//! modal mass, m/s²) and the drum's synthesis is `MODAL_CALIBRATION` × Σ (gain_k/ω_k) ×
//! q̇_k, which the mix differentiates. Hands resting on the head (touches) damp it, and
//! the glide retunes the bank, block by block.

use super::SAMPLE_RATE_HZ;
use super::calibration::Calibration;
use super::partials::SoundHead;
use super::voices::{BankState, Voice, VoiceBank};
use crate::drum::{DrumSet, FrequencySource};
use crate::kit::Drum;
use glam::DVec2;
use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};

/// Output per unit of Σ gain × modal velocity (gains: [`super::partials`]): an ff strike at the
/// playing spot of the standard 26-inch drum peaks near −6 dBFS.
pub const MODAL_CALIBRATION: f64 = 0.006;
/// Samples per processing block (a pedal change takes effect at a block's start).
pub const BLOCK: usize = 128;
/// States below this (m/s; with gains ≤ 0.2 per m/s, under −150 dBFS) are flushed to zero,
/// and a chunk of voices that is all zero is skipped.
pub const FLUSH_FLOOR: f32 = 1e-7;

/// The sounding modes of `drum` under `calibration`, frequencies from `source`, built once
/// per process per drum definition, frequency source and calibration (a full-band head
/// takes a while to build).
pub fn sound_head_of(
    drum: &Drum,
    source: FrequencySource,
    calibration: &Calibration,
) -> Option<Arc<SoundHead>> {
    type Cache = Mutex<HashMap<String, Arc<SoundHead>>>;
    static CACHE: OnceLock<Cache> = OnceLock::new();
    let key = format!("{drum:?}{source:?}{calibration:?}");
    let cache = CACHE.get_or_init(Default::default);
    if let Some(h) = cache.lock().expect("cache lock").get(&key) {
        return Some(Arc::clone(h));
    }
    let head = Arc::new(SoundHead::new(drum, source, calibration).ok()?);
    cache
        .lock()
        .expect("cache lock")
        .insert(key, Arc::clone(&head));
    Some(head)
}

/// A drum's sounding heads over a performance: from each first frame on (48 kHz, a
/// multiple of [`BLOCK`]), the head as its pedal tunes it then (None where it could not
/// be built); the first from frame 0.
pub type Tunings = Vec<(usize, Option<Arc<SoundHead>>)>;

/// Each kit drum's sounding heads.
pub type SoundHeads = Vec<Tunings>;

/// The first frame of the block in which a pedal change at score time `at_s` (s) takes
/// effect.
pub fn change_frame(at_s: f64) -> usize {
    ((at_s * f64::from(SAMPLE_RATE_HZ)).floor().max(0.0) as usize) / BLOCK * BLOCK
}

/// Drum `j` of `kit`'s sounding heads over the performance `drums` recorded: the kit's
/// drum from the start, then the drum retuned at each of its pedal changes.
pub fn sound_heads(
    kit: &crate::kit::Kit,
    drums: &DrumSet,
    j: usize,
    calibration: &Calibration,
) -> Tunings {
    let Some(drum) = kit.drums.get(j) else {
        return Vec::new();
    };
    let source = drums.config().source;
    std::iter::once((0, sound_head_of(drum, source, calibration)))
        .chain(drums.retunes().iter().filter(|r| r.drum == j).map(|r| {
            (
                change_frame(r.at_s),
                sound_head_of(&drum.retuned(r.pitch), source, calibration),
            )
        }))
        .collect()
}

/// Which of `tunings` (first frames rising) holds at frame `n`.
pub fn tuning_at<T>(tunings: &[(usize, T)], n: usize) -> usize {
    tunings.iter().rposition(|(f, _)| *f <= n).unwrap_or(0)
}

/// The first frame from which two drums' voices over a performance (per tuning: its first
/// frame and voices) differ; None when they are the same.
pub fn first_voice_change(
    now: &[(usize, Vec<Voice>)],
    before: &[(usize, Vec<Voice>)],
) -> Option<usize> {
    first_change(now, before, |(f, _)| *f as f64).map(|f| f as usize)
}

/// A sounding head's voice with the model's calibration applied.
pub fn calibrated_voice(v: &Voice) -> Voice {
    Voice {
        gain: v.gain * MODAL_CALIBRATION,
        ..*v
    }
}

/// The voices of a sounding head with the model's calibration applied.
fn calibrated(head: &SoundHead) -> Vec<Voice> {
    head.voices.iter().map(calibrated_voice).collect()
}

/// Index of a hand's share: 0 left, 1 right.
pub fn side_index(side: crate::kit::Side) -> usize {
    usize::from(side == crate::kit::Side::Right)
}

/// Contact points are taken to the centre of a square cell this wide for their mode
/// shapes, m (the felt ball is ≈ 36 mm across).
const SHAPE_GRID_M: f64 = 5e-4;

/// Blocks between saved synthesis states (8192 frames, 0.17 s).
const SAVE_EVERY_BLOCKS: usize = 64;

/// A drum's synthesis state at the start of a block: where re-synthesis can resume.
#[derive(Clone, Debug, PartialEq)]
pub struct Saved {
    /// First frame of the block.
    pub frame: usize,
    bank: BankState,
    silent: bool,
}

/// Whether a state is saved at frame `n` whatever the synthesis's length (the drums'
/// synthesis and the sympathetic heads' alike).
pub(super) fn periodic(n: usize) -> bool {
    n.is_multiple_of(SAVE_EVERY_BLOCKS * BLOCK)
}

/// The frame synthesis resumes from with states `saved`, for a change at frame `from`.
fn resume_frame(saved: &[Saved], from: usize) -> usize {
    saved
        .iter()
        .rev()
        .find(|s| s.frame <= from)
        .map_or(0, |s| s.frame)
}

/// What a drum's synthesis keeps to re-synthesise only what a changed record changes:
/// the states saved as it went and what it was rendered from.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DrumSynth {
    saved: Vec<Saved>,
    /// The drum's excitation it heard, in time order: time (s), contact point (m), force
    /// (N).
    heard: Vec<(f64, DVec2, f64)>,
    /// The damping touches it heard: from when to when a hand rested on the head, s.
    touches: Vec<(f64, f64)>,
    /// The voices of each of its tunings, from its first frame.
    voices: Vec<(usize, Vec<Voice>)>,
}

impl DrumSynth {
    /// The frame of the latest saved state: where a synthesis of a record unchanged up to
    /// its end resumes.
    #[cfg(test)]
    pub(crate) fn latest_saved_frame(&self) -> Option<usize> {
        self.saved.last().map(|s| s.frame)
    }
}

/// The time (s, by `time`) of the first entry where two time-ordered records differ: the
/// earlier of the two entries there (one may be missing). None when they are equal.
fn first_change<T: PartialEq>(now: &[T], before: &[T], time: impl Fn(&T) -> f64) -> Option<f64> {
    (0..now.len().max(before.len()))
        .find(|&d| now.get(d) != before.get(d))
        .map(|d| {
            [now.get(d), before.get(d)]
                .into_iter()
                .flatten()
                .map(&time)
                .fold(f64::INFINITY, f64::min)
        })
}

/// Render drum `j`'s sound (mono, 48 kHz, from t = 0), `frames` long, into `out` that
/// holds the output `synth` was rendered with (empty, with a default `synth`, the first
/// time): the record is compared with the one heard then, and synthesis resumes from the
/// latest saved state before the first frame a changed entry (or the end of the previous
/// output) reaches; the output before it is kept. Bit for bit a whole render. Returns
/// whether anything touched the drum and the first frame rewritten.
///
/// With `hands`, each hand's share of the sound is rendered too, into `hands[side]`
/// (`frames` long, from frame 0: pass a fresh `synth`): a bank per hand driven by that
/// hand's contacts only, damped and retuned with the whole head's glide (the head's
/// tension is set by everything on it), so the bank is linear in each step and the two
/// shares sum to the drum's sound to the float rounding.
pub fn resynthesise(
    heads: &[(usize, Option<Arc<SoundHead>>)],
    (drums, touches): (&DrumSet, &[(f64, f64)]),
    j: usize,
    (out, mut hands): (&mut Vec<f32>, Option<&mut [Vec<f32>; 2]>),
    frames: usize,
    synth: &mut DrumSynth,
) -> (bool, usize) {
    let fs = f64::from(SAMPLE_RATE_HZ);
    let dt = drums.dt_s();
    // Sample span of an entry's kernel: centre c = t + dt/2, support (c − dt, c + dt).
    let span = |t: f64| {
        let c = (t + 0.5 * dt) * fs;
        let lo = ((c - dt * fs).floor() + 1.0).max(0.0) as usize;
        let hi = (c + dt * fs).ceil().max(0.0) as usize; // exclusive
        (c, lo, hi)
    };
    let mut entries: Vec<_> = drums.excitation().iter().filter(|e| e.drum == j).collect();
    entries.sort_by(|a, b| a.time_s.total_cmp(&b.time_s));
    let heard: Vec<(f64, DVec2, f64)> = entries
        .iter()
        .map(|e| (e.time_s, e.point, e.force_n))
        .collect();
    let voices: Vec<(usize, Vec<Voice>)> = heads
        .iter()
        .map(|(f, h)| (*f, h.as_deref().map_or(Vec::new(), calibrated)))
        .collect();
    // The first frame a difference reaches: none before the end of the previous output
    // when the drum is silent now and was then, or heard the same entries with the same
    // voices.
    let first_difference = first_change(&heard, &synth.heard, |e| e.0).map(|t| span(t).1);
    let mut touches = touches.to_vec();
    touches.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    let first_touch_difference =
        first_change(&touches, &synth.touches, |t| t.0).map(|t| (t * fs).floor().max(0.0) as usize);
    let silent_both = heard.is_empty() && synth.heard.is_empty();
    let voice_difference = first_voice_change(&voices, &synth.voices).filter(|_| !silent_both);
    let from = first_difference
        .into_iter()
        .chain(first_touch_difference)
        .chain(voice_difference)
        .fold(usize::MAX, usize::min)
        .min(out.len());
    let touched = !entries.is_empty();
    let was_silent = synth.heard.is_empty() && synth.saved.is_empty();
    // A silent drum's output is zero: only what it held since `from` is cleared. One
    // struck for the first time is at rest and silent until the block of its first
    // entry, so it starts there (not at frame 0, which would make every head that hears
    // it sympathetically ring again from the start too).
    let start = match entries.first() {
        None => from,
        Some(e) if was_silent => span(e.time_s).1 / BLOCK * BLOCK,
        Some(_) => resume_frame(&synth.saved, from),
    }
    .min(frames);
    // The periodic states, and the one resumed from (a cut's: see below).
    synth
        .saved
        .retain(|s| s.frame <= start && (periodic(s.frame) || s.frame == start));
    synth.heard = heard;
    synth.touches = touches;
    synth.voices = voices;
    out.resize(frames, 0.0);
    out[start..].fill(0.0);
    if let Some(hands) = hands.as_deref_mut() {
        for h in hands.iter_mut() {
            *h = vec![0.0; frames];
        }
    }
    if !touched || heads.iter().all(|(_, h)| h.is_none()) {
        synth.saved.clear();
        return (false, start);
    }
    let damping = super::touch_factor(fs) as f32;
    let saved = &mut synth.saved;
    let mut tuned = Tuned::new(
        heads,
        &synth.voices,
        tuning_at(heads, start),
        hands.is_some(),
    );
    let mut silent = true;
    if let Some(s) = saved.pop() {
        tuned.bank.restore(&s.bank);
        silent = s.silent;
    }
    let mut first = 0;
    for n0 in (start..out.len()).step_by(BLOCK) {
        let now = tuning_at(heads, n0);
        if now != tuned.index {
            // A pedal change: the head (damped before it) starts at rest at its new pitch.
            tuned = Tuned::new(heads, &synth.voices, now, hands.is_some());
            silent = true;
        }
        let Tuned {
            bank,
            hand_banks,
            head,
            inv_mass,
            shapes,
            shapes_cell,
            row,
            input,
            ..
        } = &mut tuned;
        let stride = bank.stride();
        // Also at the start of the last block: a synthesis cut here (the sound made
        // ahead of a simulation, the editor's steps) is resumed from its end, not from
        // up to SAVE_EVERY_BLOCKS blocks before it.
        if periodic(n0) || n0 + BLOCK >= out.len() {
            saved.push(Saved {
                frame: n0,
                bank: bank.state(),
                silent,
            });
        }
        let n1 = (n0 + BLOCK).min(out.len());
        while first < entries.len() && span(entries[first].time_s).2 <= n0 {
            first += 1;
        }
        let mut driven = false;
        for e in entries[first..]
            .iter()
            .take_while(|e| span(e.time_s).1 < n1)
        {
            let (c, lo, hi) = span(e.time_s);
            let (lo, hi) = (lo.max(n0), hi.min(n1));
            let Some(head) = head.as_deref().filter(|_| lo < hi) else {
                continue;
            };
            let cell = (e.point / SHAPE_GRID_M).round();
            if *shapes_cell != Some(cell) {
                head.shapes_at(cell * SHAPE_GRID_M, shapes);
                *shapes_cell = Some(cell);
            }
            for ((r, s), im) in row.iter_mut().zip(shapes.iter()).zip(inv_mass.iter()) {
                *r = (e.force_n * s * im) as f32;
            }
            for n in lo..hi {
                let w = (1.0 - (n as f64 - c).abs() / (dt * fs)).max(0.0) as f32;
                let at = (n - n0) * stride..(n - n0 + 1) * stride;
                let hand = hand_banks.get_mut(side_index(e.side));
                for input in [Some(&mut *input), hand.map(|h| &mut h.1)]
                    .into_iter()
                    .flatten()
                {
                    for (d, r) in input[at.clone()].iter_mut().zip(row.iter()) {
                        *d += w * r;
                    }
                }
            }
            driven = true;
        }
        if driven || !silent {
            let t = n0 as f64 / fs;
            let resting = super::resting(&synth.touches, t);
            let glide = bank.glide();
            for b in std::iter::once(&mut *bank).chain(hand_banks.iter_mut().map(|h| &mut h.0)) {
                b.damp(if resting { damping } else { 1.0 });
                b.retune(glide);
            }
        }
        if let Some(hands) = hands.as_deref_mut() {
            for ((b, input), h) in hand_banks.iter_mut().zip(hands.iter_mut()) {
                if driven {
                    b.render_driven(&input[..(n1 - n0) * stride], &mut h[n0..n1]);
                    input.fill(0.0);
                } else if !silent {
                    b.render_free(&mut h[n0..n1]);
                    b.flush(FLUSH_FLOOR);
                }
            }
        }
        if driven {
            bank.render_driven(&input[..(n1 - n0) * stride], &mut out[n0..n1]);
            input.fill(0.0);
            silent = false;
        } else if !silent {
            bank.render_free(&mut out[n0..n1]);
            silent = bank.flush(FLUSH_FLOOR);
        }
    }
    (true, start)
}

/// A drum's synthesis at one of its tunings: the bank (and each hand's, with input),
/// the head, and the scratch to drive it.
struct Tuned {
    index: usize,
    bank: VoiceBank,
    hand_banks: Vec<(VoiceBank, Vec<f32>)>,
    head: Option<Arc<SoundHead>>,
    inv_mass: Vec<f64>,
    shapes: Vec<f64>,
    /// The grid cell the shapes were last evaluated at: a contact moves little, so its
    /// entries share them (a function of the entry alone, so resuming changes nothing).
    shapes_cell: Option<DVec2>,
    row: Vec<f32>,
    input: Vec<f32>,
}

impl Tuned {
    /// Tuning `index` of `heads` (voices `voices[index]`) at rest, with a bank per hand
    /// when `hands`.
    fn new(
        heads: &[(usize, Option<Arc<SoundHead>>)],
        voices: &[(usize, Vec<Voice>)],
        index: usize,
        hands: bool,
    ) -> Tuned {
        let head = heads.get(index).and_then(|(_, h)| h.clone());
        let bank = VoiceBank::new(
            voices.get(index).map_or(&[][..], |v| &v.1),
            f64::from(SAMPLE_RATE_HZ),
        );
        let inv_mass: Vec<f64> = head.as_deref().map_or(Vec::new(), |h| {
            h.modes
                .modes()
                .iter()
                .map(|m| 1.0 / m.modal_mass_kg)
                .collect()
        });
        let stride = bank.stride();
        let hand_banks = if hands {
            (0..2)
                .map(|_| (bank.clone(), vec![0.0f32; BLOCK * stride]))
                .collect()
        } else {
            Vec::new()
        };
        Tuned {
            index,
            shapes: vec![0.0; inv_mass.len()],
            shapes_cell: None,
            row: vec![0.0f32; stride],
            input: vec![0.0f32; BLOCK * stride],
            bank,
            hand_banks,
            head,
            inv_mass,
        }
    }
}
