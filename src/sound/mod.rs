//! Sound from the simulated strikes, 48 kHz stereo, the same code offline and
//! live: three models — **modal** (a voice bank driven by the recorded contact force,
//! seed 000 §4), **sample** replay and **signal**-based partials (seed 002) — each with a
//! fixed calibration, mixed with a constant-power pan from each drum's placement x, heard
//! in a room if one is asked ([`room`]: a studio's or a hall's reverberation added), then
//! checked for NaN and held below −1 dBFS by scaling the whole render down if needed.

pub mod analysis;
pub mod calibration;
pub mod fit;
pub mod hands;
pub mod modal;
pub mod partials;
pub mod radiation;
pub mod recording;
pub mod room;
pub mod sample;
pub mod signal;
pub mod spectrum;
pub mod sympathy;
pub mod voices;
pub mod wav;

pub use spectrum::spectrum;
pub use wav::{WavFormat, write_wav, write_wav_as};

pub use crate::base::choices::{Room, SoundModel};
use crate::base::chunks::SharedChunks;
use crate::drum::DrumSet;
use crate::kit::Kit;
use std::f64::consts::FRAC_PI_4;
use std::path::PathBuf;

/// Audio sample rate, Hz.
pub const SAMPLE_RATE_HZ: u32 = 48_000;
/// Highest peak a render may reach, linear (−1 dBFS).
pub const PEAK_LIMIT: f64 = 0.891_250_938_133_745_5;
/// Placement x (m) that pans a drum fully to one side; nearer drums pan in proportion.
pub const PAN_SPAN_M: f64 = 1.2;
/// Impact speed of the reference strike the sample and signal models calibrate to, m/s:
/// the scripted ff's, [`crate::drum::strike::impact_speed_mps`] (a copied number went
/// stale when the strokes' speeds were rescaled, and every stroke from mf up then played
/// the sample model's unfiltered ff brightness).
pub fn reference_speed_mps() -> f64 {
    crate::drum::strike::impact_speed_mps(crate::score::Dynamic::Ff)
}
/// Peak level the sample and signal models give the reference strike (−6 dBFS); the
/// modal model's calibration puts a reference strike on the 26-inch drum there too.
pub const REFERENCE_LEVEL: f64 = 0.5;

/// A hand resting on a head to stop it ringing (a secco beat): drum `drum`, from `at_s`
/// for [`TOUCH_S`], during which every mode of the head decays with T60 [`TOUCH_T60_S`]
/// on top of its own decay (soft, lossy skin on the membrane).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Touch {
    pub drum: usize,
    /// s.
    pub at_s: f64,
}

/// How long a damping hand rests on the head, s.
pub const TOUCH_S: f64 = 0.25;
/// T60 the resting hand gives every mode, s.
pub const TOUCH_T60_S: f64 = 0.05;

/// The damping factor per sample at `rate_hz` while a hand rests on the head.
pub fn touch_factor(rate_hz: f64) -> f64 {
    (-(1000f64.ln()) / (TOUCH_T60_S * rate_hz)).exp()
}

/// Values per chunk of [`Samples`]: one second of stereo at [`SAMPLE_RATE_HZ`].
pub const AUDIO_CHUNK: usize = 2 * SAMPLE_RATE_HZ as usize;

/// Interleaved audio samples kept in shared chunks of [`AUDIO_CHUNK`] values: a
/// rendering hands its audio over by sharing them, and the next rendering, rewriting
/// what an edit changed, copies only the chunks it rewrites (the one-minute study's audio
/// is 24 MB; copying it whole for each step of a re-render took 15–30 ms). Reads as a
/// [`SharedChunks`] (`len`, `iter`, `samples[k]`, `to_vec_of(range)`).
#[derive(Clone, Debug, PartialEq)]
pub struct Samples(SharedChunks<f32>);

impl Default for Samples {
    fn default() -> Self {
        Samples(SharedChunks::new(AUDIO_CHUNK))
    }
}

impl From<Vec<f32>> for Samples {
    fn from(values: Vec<f32>) -> Self {
        Samples(SharedChunks::from_vec(values, AUDIO_CHUNK))
    }
}

impl std::ops::Deref for Samples {
    type Target = SharedChunks<f32>;

    fn deref(&self) -> &SharedChunks<f32> {
        &self.0
    }
}

impl std::ops::DerefMut for Samples {
    fn deref_mut(&mut self) -> &mut SharedChunks<f32> {
        &mut self.0
    }
}

/// Rendered sound.
#[derive(Clone, Debug, PartialEq)]
pub struct Audio {
    /// Samples per second per channel, Hz.
    pub rate_hz: u32,
    /// Channels (2: left, right).
    pub channels: u16,
    /// Interleaved samples in [−1, 1], shared (a rendering hands its mix over without a
    /// copy).
    pub samples: Samples,
    /// Scale applied on top of the model's fixed calibration to keep the peak at or below
    /// −1 dBFS (1 when none was needed).
    pub gain: f64,
}

impl Audio {
    /// Frames (samples per channel).
    pub fn frames(&self) -> usize {
        self.samples.len() / usize::from(self.channels.max(1))
    }

    /// One channel as its own signal.
    pub fn channel(&self, c: usize) -> Vec<f32> {
        self.samples
            .iter()
            .skip(c)
            .step_by(usize::from(self.channels.max(1)))
            .copied()
            .collect()
    }

    /// The mean of the channels.
    pub fn mono(&self) -> Vec<f32> {
        self.mono_of(0..self.frames())
    }

    /// The mean of the channels over `frames` (within the audio).
    pub fn mono_of(&self, frames: std::ops::Range<usize>) -> Vec<f32> {
        let ch = usize::from(self.channels.max(1));
        self.samples
            .to_vec_of(frames.start * ch..frames.end * ch)
            .chunks_exact(ch)
            .map(|f| f.iter().sum::<f32>() / ch as f32)
            .collect()
    }
}

/// Why sound could not be rendered or written.
#[derive(Debug, thiserror::Error)]
pub enum SoundError {
    #[error("duration {0} s is not a finite time ≥ 0 of at most 24 hours")]
    Duration(f64),
    #[error("the {model} model produced a non-finite sample at frame {frame}")]
    NonFinite { model: SoundModel, frame: usize },
    #[error("the drum set has {drums} heads but the kit {kit}")]
    KitMismatch { drums: usize, kit: usize },
    #[error("embedded sample {name}: {message}")]
    Sample { name: String, message: String },
    #[error("{}: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("{}: {source}", path.display())]
    Wav {
        path: PathBuf,
        #[source]
        source: hound::Error,
    },
}

/// Stereo gains (left, right) for a drum at placement x (m): constant power,
/// pan = clamp(x / PAN_SPAN_M, −1, 1), angle (pan + 1)·π/4.
pub fn pan_gains(x_m: f64) -> (f64, f64) {
    let pan = (x_m / PAN_SPAN_M).clamp(-1.0, 1.0);
    let angle = (pan + 1.0) * FRAC_PI_4;
    (angle.cos(), angle.sin())
}

/// What is heard: the sound model, and the room it is heard in. A bare [`SoundModel`] is
/// heard dry.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Voicing {
    pub model: SoundModel,
    pub room: Room,
}

impl From<SoundModel> for Voicing {
    fn from(model: SoundModel) -> Voicing {
        Voicing {
            model,
            room: Room::Dry,
        }
    }
}

/// Frames per block over which a rendering keeps the mix's peak (0.1 s).
const PEAK_BLOCK: usize = 4800;

/// What a rendering of sound keeps to re-synthesise only what changed: each drum's mono
/// output and synthesis state (modal model), the mix before normalisation and its peak
/// per [`PEAK_BLOCK`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SoundState {
    model: SoundModel,
    /// Per drum: mono output, synthesis state, whether anything touched it.
    drums: Vec<(Vec<f32>, modal::DrumSynth, bool)>,
    /// Per drum: what the others' sound makes it ring (modal model).
    sympathy: Vec<sympathy::SympathyState>,
    /// Interleaved stereo mix before the normalisation gain.
    mix: Vec<f32>,
    /// The mix heard in its room (nothing when dry).
    room: room::RoomState,
    /// Per block of what is heard (the mix, or the mix in its room).
    peaks: Vec<f32>,
    /// What is heard scaled by `gain`: the audio, shared with the renderings made of it.
    heard: Samples,
    /// The normalisation gain `heard` was scaled by ([`Audio::gain`]).
    gain: f64,
    /// Samples of `heard` that are `gain` times what is heard now (the synthesis made
    /// ahead beside a simulation rewrites what is heard but leaves the scaling to the
    /// rendering that hands the audio over).
    scaled: usize,
    /// Whether the next synthesis keeps `gain` while its peaks stay within the limit with
    /// it ([`SoundState::hold_gain`]).
    hold_gain: bool,
}

/// When hands rest on drum `j`'s head, from when to when (s), in time order: the
/// `touches` on it, each for [`TOUCH_S`], and before each of its pedal changes
/// (`drums.retunes()`) the player damping it up to the change — for [`TOUCH_S`], or from
/// half-way between the drum's last stroke and the change when they are closer.
fn touches_of(touches: &[Touch], drums: &DrumSet, j: usize) -> Vec<(f64, f64)> {
    let pedals = drums.retunes().iter().filter(|r| r.drum == j).map(|r| {
        let from = (r.at_s - TOUCH_S).max(r.after_s + 0.5 * (r.at_s - r.after_s).max(0.0));
        (from.min(r.at_s), r.at_s)
    });
    let mut own: Vec<(f64, f64)> = touches
        .iter()
        .filter(|t| t.drum == j)
        .map(|t| (t.at_s, t.at_s + TOUCH_S))
        .chain(pedals)
        .collect();
    own.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    own
}

/// Whether a hand rests on the head at time `t` (s) under `touches` (from, until; s).
fn resting(touches: &[(f64, f64)], t: f64) -> bool {
    touches.iter().any(|&(from, until)| from <= t && t < until)
}

/// Damp one replayed note (sample model), `note` starting at frame `start`: while a hand
/// rests on the head (`touches`: from, until; s) it decays with the touch's T60, and it
/// stays at the level it reached after (the hand has stopped it). Touches before the
/// note leave it alone.
fn damp_note(note: &mut [f32], start: usize, touches: &[(f64, f64)]) {
    let fs = f64::from(SAMPLE_RATE_HZ);
    let factor = touch_factor(fs);
    let frame = |t: f64| ((t * fs).round().max(0.0) as usize).saturating_sub(start);
    let mut gain = 1.0;
    let mut done = 0;
    for &(from, until) in touches {
        let (a, b) = (frame(from).max(done), frame(until).min(note.len()));
        if a >= b {
            continue;
        }
        for s in &mut note[done..a] {
            *s = (f64::from(*s) * gain) as f32;
        }
        for s in &mut note[a..b] {
            gain *= factor;
            *s = (f64::from(*s) * gain) as f32;
        }
        done = b;
    }
    for s in &mut note[done..] {
        *s = (f64::from(*s) * gain) as f32;
    }
}

/// A drum's radiated sound at frame `n` from what its synthesis keeps: the modal model
/// keeps Σ (gain_k/ω_k)·q̇_k and the pressure is its time derivative (a head radiates its
/// acceleration, so a mode's forced response below its resonance radiates less than at
/// it: [`partials`]); the other models keep the sound itself.
fn radiated(model: SoundModel, mono: &[f32], sympathy: Option<&[f32]>, n: usize) -> f32 {
    let at = |k: usize| mono[k] + sympathy.and_then(|s| s.get(k)).copied().unwrap_or(0.0);
    match model {
        SoundModel::Modal => {
            let before = if n == 0 { 0.0 } else { at(n - 1) };
            (at(n) - before) * SAMPLE_RATE_HZ as f32
        }
        SoundModel::Sample | SoundModel::Signal => at(n),
    }
}

/// Each drum's own sound, panned and scaled exactly as in the mix (stereo): what its
/// head radiates. The stems sum to the mix, to the rounding. One [`Audio`] per kit drum.
pub fn stems(
    kit: &Kit,
    (drums, touches): (&DrumSet, &[Touch]),
    duration_s: f64,
    voicing: impl Into<Voicing>,
) -> Result<Vec<Audio>, SoundError> {
    let voicing = voicing.into();
    let (mix, state) = render_touched(kit, drums, touches, duration_s, voicing, None)?;
    Ok(state
        .drums
        .iter()
        .zip(&kit.drums)
        .enumerate()
        .map(|(j, ((mono, _, _), drum))| {
            let sympathy = state.sympathy.get(j).map(|s| s.out.as_slice());
            stem(drum, voicing, (mono, sympathy), mix.gain)
        })
        .collect())
}

/// What one drum's synthesis (`mono`, plus its `sympathy` ringing) radiates, panned by its
/// placement and scaled by the mix's `gain`, heard in the `voicing`'s room: its stereo
/// share of the mix.
fn stem(
    drum: &crate::kit::Drum,
    voicing: Voicing,
    (mono, sympathy): (&[f32], Option<&[f32]>),
    gain: f64,
) -> Audio {
    let (l, r) = pan_gains(drum.placement.x_m);
    let mut samples: Vec<f32> = (0..mono.len())
        .flat_map(|n| {
            let s = f64::from(radiated(voicing.model, mono, sympathy, n)) * gain;
            [(s * l) as f32, (s * r) as f32]
        })
        .collect();
    room::reverberate(voicing.room, &mut samples);
    Audio {
        rate_hz: SAMPLE_RATE_HZ,
        channels: 2,
        samples: samples.into(),
        gain,
    }
}

/// Render `duration_s` of sound from what `drums` recorded (excitation, contacts).
pub fn render(
    kit: &Kit,
    drums: &DrumSet,
    duration_s: f64,
    voicing: impl Into<Voicing>,
) -> Result<Audio, SoundError> {
    render_resuming(kit, drums, duration_s, voicing, None).map(|(audio, _)| audio)
}

/// [`render`], re-synthesising only what changed when `previous` (a rendering's state of
/// the same kit and mode configuration) is given: each drum's record is compared with
/// the one it heard then, and synthesis resumes before the first difference. Bit for
/// bit a whole render. Only the modal model resumes; the others render whole.
pub fn render_resuming(
    kit: &Kit,
    drums: &DrumSet,
    duration_s: f64,
    voicing: impl Into<Voicing>,
    previous: Option<SoundState>,
) -> Result<(Audio, SoundState), SoundError> {
    render_touched(kit, drums, &[], duration_s, voicing, previous)
}

/// Build (or find) the modal model's sounding head of every drum of `kit`, and of each
/// drum as its pedal changes `retunes` tune it, frequencies from `source`, under the
/// shipped calibration: a render can do it on another core while it simulates, and its
/// sound then finds them built. Nothing for the other models.
pub fn prepare_heads(
    kit: &Kit,
    retunes: &[crate::kit::Retune],
    source: crate::drum::FrequencySource,
    model: SoundModel,
) {
    if model != SoundModel::Modal {
        return;
    }
    let calibration = calibration::Calibration::shipped();
    let retuned = retunes
        .iter()
        .filter_map(|r| Some(kit.drums.get(r.drum)?.retuned(r.pitch)));
    for drum in kit.drums.iter().cloned().chain(retuned) {
        modal::sound_head_of(&drum, source, calibration);
    }
}

/// [`render_resuming`] with hands damping heads at `touches`.
pub fn render_touched(
    kit: &Kit,
    drums: &DrumSet,
    touches: &[Touch],
    duration_s: f64,
    voicing: impl Into<Voicing>,
    previous: Option<SoundState>,
) -> Result<(Audio, SoundState), SoundError> {
    render_touched_on(
        kit,
        (drums, touches),
        duration_s,
        voicing,
        previous,
        Cores::All,
    )
}

/// [`render_resuming`] with the modal model under `calibration` (the fit tries its own).
pub fn render_calibrated(
    kit: &Kit,
    (drums, touches): (&DrumSet, &[Touch]),
    duration_s: f64,
    (model, calibration): (SoundModel, &calibration::Calibration),
    previous: Option<SoundState>,
) -> Result<(Audio, SoundState), SoundError> {
    render_on(
        kit,
        (drums, touches),
        duration_s,
        (model.into(), calibration),
        previous,
        Cores::All,
    )
}

/// How many cores a rendering of the sound may take.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Cores {
    /// Each drum on its own thread.
    All,
    /// The caller's thread only: for sound made beside a simulation that has the other core.
    One,
}

/// `f` of each item, on a thread each with [`Cores::All`], else one after another; in
/// order either way.
fn each<T: Send, R: Send>(items: Vec<T>, cores: Cores, f: impl Fn(T) -> R + Sync) -> Vec<R> {
    match cores {
        Cores::One => items.into_iter().map(f).collect(),
        Cores::All => crate::base::parallel::each(items, f),
    }
}

/// [`render_touched`] on `cores`.
pub fn render_touched_on(
    kit: &Kit,
    (drums, touches): (&DrumSet, &[Touch]),
    duration_s: f64,
    voicing: impl Into<Voicing>,
    previous: Option<SoundState>,
    cores: Cores,
) -> Result<(Audio, SoundState), SoundError> {
    render_on(
        kit,
        (drums, touches),
        duration_s,
        (voicing.into(), calibration::Calibration::shipped()),
        previous,
        cores,
    )
}

/// [`render_calibrated`] on `cores`.
fn render_on(
    kit: &Kit,
    sounding: (&DrumSet, &[Touch]),
    duration_s: f64,
    voicing: (Voicing, &calibration::Calibration),
    previous: Option<SoundState>,
    cores: Cores,
) -> Result<(Audio, SoundState), SoundError> {
    let state = synthesise_on(
        kit,
        sounding,
        duration_s,
        voicing,
        previous,
        (cores, Made::Audio),
    )?;
    Ok((state.audio(), state))
}

/// [`render_touched_on`] without its audio: only the state a later rendering resumes
/// (for sound made ahead while the body is still simulated, which nobody plays). What is
/// heard is made, not scaled by a normalisation gain: the rendering that hands the audio
/// over scales what changed since its audio was last scaled, once, with its own gain.
pub fn resynthesise_on(
    kit: &Kit,
    sounding: (&DrumSet, &[Touch]),
    duration_s: f64,
    voicing: impl Into<Voicing>,
    previous: Option<SoundState>,
    cores: Cores,
) -> Result<SoundState, SoundError> {
    let calibration = calibration::Calibration::shipped();
    synthesise_on(
        kit,
        sounding,
        duration_s,
        (voicing.into(), calibration),
        previous,
        (cores, Made::State),
    )
}

/// What a synthesis makes: the audio to hand over, or only the state to resume.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Made {
    Audio,
    State,
}

/// The sound of `drums` struck and `touches` damped up to `duration_s`, resuming
/// `previous` where its record first differs: each drum's voice, the sympathetic
/// ringing, the stereo mix and its block peaks.
fn synthesise_on(
    kit: &Kit,
    (drums, touches): (&DrumSet, &[Touch]),
    duration_s: f64,
    (voicing, calibration): (Voicing, &calibration::Calibration),
    previous: Option<SoundState>,
    (cores, made): (Cores, Made),
) -> Result<SoundState, SoundError> {
    let model = voicing.model;
    if !(duration_s.is_finite() && (0.0..=86_400.0).contains(&duration_s)) {
        return Err(SoundError::Duration(duration_s));
    }
    if drums.len() != kit.drums.len() {
        return Err(SoundError::KitMismatch {
            drums: drums.len(),
            kit: kit.drums.len(),
        });
    }
    let fs = f64::from(SAMPLE_RATE_HZ);
    let frames = (duration_s * fs).round() as usize;
    let mut state = match previous {
        Some(state)
            if model == SoundModel::Modal
                && state.model == model
                && state.drums.len() == kit.drums.len() =>
        {
            state
        }
        _ => SoundState {
            model,
            drums: vec![Default::default(); kit.drums.len()],
            ..SoundState::default()
        },
    };
    // The first frame any drum re-synthesises from.
    let mut start = state.mix.len() / 2;
    // Each drum on its own thread: they share nothing but what they read. The modal
    // model's threads also build (or find) their drum's sounding head, which the
    // sympathetic pass then reuses.
    type Synthesised = (Result<usize, SoundError>, modal::Tunings);
    let resting: Vec<Vec<(f64, f64)>> = (0..kit.drums.len())
        .map(|j| touches_of(touches, drums, j))
        .collect();
    let slots: Vec<_> = state.drums.iter_mut().zip(&resting).enumerate().collect();
    let results: Vec<Synthesised> = each(slots, cores, |(j, ((mono, synth, heard), own))| {
        let mut heads = Vec::new();
        let outcome = match model {
            SoundModel::Modal => {
                heads = modal::sound_heads(kit, drums, j, calibration);
                Ok(modal::resynthesise(
                    &heads,
                    (drums, own),
                    j,
                    (mono, None),
                    frames,
                    synth,
                ))
            }
            SoundModel::Sample => {
                *mono = vec![0.0; frames];
                sample::render_drum(kit, (drums, own), j, mono).map(|touched| (touched, 0))
            }
            SoundModel::Signal => {
                *mono = vec![0.0; frames];
                Ok((signal::render_drum((drums, own), j, mono), 0))
            }
        };
        let from = outcome.map(|(touched, from)| {
            *heard = touched;
            from
        });
        (from, heads)
    });
    let (froms, heads): (Vec<_>, modal::SoundHeads) = results.into_iter().unzip();
    let froms = froms.into_iter().collect::<Result<Vec<usize>, _>>()?;
    start = froms.iter().fold(start, |s, f| s.min(*f));
    if model == SoundModel::Modal {
        let monos: Vec<&[f32]> = state.drums.iter().map(|(m, _, _)| m.as_slice()).collect();
        state.sympathy.resize(kit.drums.len(), Default::default());
        let (heads, froms) = (&heads, &froms);
        let sympathy_froms: Vec<usize> = each(
            state
                .sympathy
                .iter_mut()
                .zip(&resting)
                .enumerate()
                .collect(),
            cores,
            |(j, (sym, own))| {
                sympathy::resynthesise(kit, (heads, own), j, (&monos, froms), frames, sym)
            },
        );
        start = sympathy_froms.iter().fold(start, |s, f| s.min(*f));
    } else {
        state.sympathy.clear();
    }
    let start = start.min(frames);
    let mix = &mut state.mix;
    mix.resize(2 * frames, 0.0);
    mix[2 * start..].fill(0.0);
    for (j, (drum, (mono, _, heard))) in kit.drums.iter().zip(&state.drums).enumerate() {
        let sympathy = state.sympathy.get(j).map(|s| s.out.as_slice());
        if !heard && sympathy.is_none_or(|s| s.iter().all(|v| *v == 0.0)) {
            continue;
        }
        let (l, r) = pan_gains(drum.placement.x_m);
        let (l, r) = (l as f32, r as f32);
        for (n, frame) in mix[2 * start..].chunks_exact_mut(2).enumerate() {
            let s = radiated(model, mono, sympathy, start + n);
            frame[0] += l * s;
            frame[1] += r * s;
        }
    }
    // What is heard: the mix, or the mix in its room (rewritten from the state the room's
    // network resumed at, never after `start`; all of it when the room changed). Peaks are
    // made again from the first block rewritten — all of them when a room is left, as
    // they were of the room's sound.
    let (heard, first_block) = if voicing.room.is_dry() {
        let from = if state.room.room().is_dry() { start } else { 0 };
        state.room = room::RoomState::default();
        (&state.mix, from / PEAK_BLOCK)
    } else {
        let from = state.room.update(voicing.room, mix, start);
        (&state.room.wet, from / PEAK_BLOCK)
    };
    state.peaks.truncate(first_block);
    for (b, block) in heard.chunks(2 * PEAK_BLOCK).enumerate().skip(first_block) {
        let mut peak = 0.0f32;
        for (i, s) in block.iter().enumerate() {
            if !s.is_finite() {
                return Err(SoundError::NonFinite {
                    model,
                    frame: b * PEAK_BLOCK + i / 2,
                });
            }
            peak = peak.max(s.abs());
        }
        state.peaks.push(peak);
    }
    // The audio: what is heard, scaled again from the first block rewritten or not scaled
    // since (all of it when the gain changed).
    let rewritten = 2 * first_block * PEAK_BLOCK;
    state.scaled = state.scaled.min(rewritten);
    if made == Made::State {
        return Ok(state);
    }
    let peak = state.peaks.iter().copied().fold(0.0f32, f32::max);
    let own = if f64::from(peak) > PEAK_LIMIT {
        PEAK_LIMIT / f64::from(peak)
    } else {
        1.0
    };
    let held = std::mem::take(&mut state.hold_gain) && state.gain > 0.0 && state.gain <= own;
    let gain = if held { state.gain } else { own };
    let from = if gain == state.gain { state.scaled } else { 0 };
    // Only the chunks rewritten are copied from the audio an earlier rendering shares.
    state.heard.resize(heard.len(), 0.0);
    let from = from.min(heard.len());
    state
        .heard
        .rewrite_from(from, heard, |s| (f64::from(*s) * gain) as f32);
    (state.gain, state.scaled) = (gain, heard.len());
    Ok(state)
}

impl SoundState {
    /// The mix as audio, scaled down as a whole if it would pass [`PEAK_LIMIT`]: shared,
    /// not copied.
    fn audio(&self) -> Audio {
        Audio {
            rate_hz: SAMPLE_RATE_HZ,
            channels: 2,
            samples: self.heard.clone(),
            gain: self.gain,
        }
    }

    /// Let the next synthesis keep this state's normalisation gain while its peaks stay
    /// within [`PEAK_LIMIT`] with it, instead of taking the gain of its own peaks: for a
    /// partial rendering, whose sound stops before the score ends (the rest, not made
    /// again yet, is as loud as before, so the level does not jump when it comes, and only
    /// what changed is scaled again). A whole rendering takes its own peaks' gain.
    pub fn hold_gain(&mut self) {
        self.hold_gain = true;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The standard kit's 26-inch drum struck once by a scripted stick at `speed_mps`.
    fn struck(kit: &Kit, speed_mps: f64) -> DrumSet {
        use crate::drum::{ModeConfig, strike};
        let (mallet, drum) = (&kit.mallets[0], &kit.drums[2]);
        let mut drums = DrumSet::new(kit, mallet, &ModeConfig::default(), 1e-4).unwrap();
        let point = drum.point_on_head(0.6, 0.0);
        let side = crate::kit::Side::Right;
        strike::scripted(&mut drums, drum, mallet, side, point, speed_mps, 0.5);
        drums
    }

    /// A rendering's audio is the sound state's own buffer, handed over without a copy;
    /// a synthesis resumed from that state while the audio is still played (a louder
    /// stroke instead: the gain changes, every sample is scaled again) leaves the audio
    /// handed over as it was, and gives what a whole render gives.
    #[test]
    fn audio_is_shared_and_a_resumed_synthesis_leaves_it_alone() {
        let kit = Kit::standard();
        let (soft, loud) = (struck(&kit, 1.0), struck(&kit, 20.0));
        let (first, state) = render_resuming(&kit, &soft, 1.5, SoundModel::Modal, None).unwrap();
        let whole = |a: &Samples, b: &Samples| a.shared_chunks(b) == a.chunks().count();
        assert!(
            whole(&first.samples, &state.heard),
            "handed over, not copied"
        );
        let kept = first.samples.to_vec();
        let (second, state) =
            render_resuming(&kit, &loud, 1.5, SoundModel::Modal, Some(state)).unwrap();
        assert!(whole(&second.samples, &state.heard));
        assert_eq!(
            first.samples.to_vec(),
            kept,
            "the audio handed over is unchanged"
        );
        assert_eq!(second, render(&kit, &loud, 1.5, SoundModel::Modal).unwrap());
        assert!(
            second.gain < first.gain,
            "{} vs {}",
            second.gain,
            first.gain
        );
    }

    /// A held gain: the next synthesis keeps the state's gain while its peaks stay within
    /// the limit with it (its samples are the mix at that gain), and only the next; the
    /// one after takes its own peaks' gain, as a whole render does.
    #[test]
    fn a_held_gain_lasts_one_synthesis() {
        let kit = Kit::standard();
        let (soft, loud) = (struck(&kit, 1.0), struck(&kit, 20.0));
        let (_, mut state) = render_resuming(&kit, &loud, 1.5, SoundModel::Modal, None).unwrap();
        let g = state.gain;
        assert!(g < 1.0, "{g}");
        state.hold_gain();
        let (held, state) =
            render_resuming(&kit, &soft, 1.5, SoundModel::Modal, Some(state)).unwrap();
        let whole = render(&kit, &soft, 1.5, SoundModel::Modal).unwrap();
        assert_eq!((held.gain, whole.gain), (g, 1.0));
        assert!(
            held.samples
                .iter()
                .zip(whole.samples.iter())
                .all(|(h, w)| *h == (f64::from(*w) * g) as f32)
        );
        let (again, _) = render_resuming(&kit, &soft, 1.5, SoundModel::Modal, Some(state)).unwrap();
        assert_eq!(again, whole);
    }

    /// Sound made ahead (the state alone) leaves the audio handed over as it was, neither
    /// rewritten nor scaled; the rendering that hands the next audio over scales what
    /// changed, once, and gives what a whole render gives.
    #[test]
    fn sound_made_ahead_is_scaled_by_the_rendering_that_hands_it_over() {
        let kit = Kit::standard();
        let (soft, loud) = (struck(&kit, 1.0), struck(&kit, 20.0));
        let (first, state) = render_resuming(&kit, &soft, 1.5, SoundModel::Modal, None).unwrap();
        let ahead = resynthesise_on(
            &kit,
            (&loud, &[]),
            1.5,
            SoundModel::Modal,
            Some(state),
            Cores::One,
        )
        .unwrap();
        let shared = first.samples.shared_chunks(&ahead.heard);
        assert_eq!(shared, first.samples.chunks().count(), "left alone");
        assert!(ahead.scaled < ahead.heard.len(), "marked as not scaled");
        let (audio, _) = render_resuming(&kit, &loud, 1.5, SoundModel::Modal, Some(ahead)).unwrap();
        assert_eq!(audio, render(&kit, &loud, 1.5, SoundModel::Modal).unwrap());
    }

    /// The 26-inch drum struck at once and, when `later`, the 29-inch drum first struck
    /// at 1.5 s (free sticks at 3 m/s, bouncing as they will).
    fn struck_then(kit: &Kit, later: bool) -> DrumSet {
        use crate::drum::strike::{self, ScriptedStick};
        let mallet = &kit.mallets[0];
        let config = crate::drum::ModeConfig::default();
        let mut drums = DrumSet::new(kit, mallet, &config, 1e-4).unwrap();
        let steps = (1.5 / drums.dt_s()).round() as usize;
        let above = |j: usize| {
            let drum = &kit.drums[j];
            ScriptedStick::above(drum, mallet, drum.point_on_head(0.6, 0.0), 3.0, 0.001)
        };
        let parked = ScriptedStick::parked(mallet);
        strike::run(&mut drums, &mut [parked, above(2)], 0.0, steps);
        let left = if later { above(1) } else { parked };
        strike::run(&mut drums, &mut [left, parked], 1.5, steps);
        drums
    }

    /// A drum first struck after the point a synthesis resumes from (which now starts it
    /// at the block of its first stroke, not at frame 0 with every head that hears it
    /// sympathetically) sounds as in a whole render.
    #[test]
    fn a_drum_first_struck_after_a_resume_sounds_as_in_a_whole_render() {
        let kit = Kit::standard();
        let (before, after) = (struck_then(&kit, false), struck_then(&kit, true));
        assert!(
            after
                .contacts()
                .iter()
                .any(|c| c.drum == 1 && c.start_s > 1.4)
        );
        let (_, state) = render_resuming(&kit, &before, 3.0, SoundModel::Modal, None).unwrap();
        let (resumed, _) =
            render_resuming(&kit, &after, 3.0, SoundModel::Modal, Some(state)).unwrap();
        assert_eq!(
            resumed,
            render(&kit, &after, 3.0, SoundModel::Modal).unwrap()
        );
    }

    /// A synthesis cut anywhere (the sound made ahead of a simulation, an editor's step)
    /// keeps a state at the start of its last block, so the next one resumes there — not
    /// up to 8192 frames before — and gives what a whole render gives.
    #[test]
    fn a_cut_synthesis_resumes_at_its_end() {
        let kit = Kit::standard();
        let drums = struck_then(&kit, true);
        let cut_s = 1.2345;
        let cut = resynthesise_on(
            &kit,
            (&drums, &[]),
            cut_s,
            SoundModel::Modal,
            None,
            Cores::One,
        )
        .unwrap();
        let frames = (cut_s * f64::from(SAMPLE_RATE_HZ)).round() as usize;
        let struck = &cut.drums[2].1;
        let saved = struck.latest_saved_frame().expect("a saved state");
        assert!(
            saved < frames && saved + modal::BLOCK >= frames,
            "saved at {saved}, cut at {frames}"
        );
        let (resumed, _) =
            render_resuming(&kit, &drums, 3.0, SoundModel::Modal, Some(cut)).unwrap();
        assert_eq!(
            resumed,
            render(&kit, &drums, 3.0, SoundModel::Modal).unwrap()
        );
    }

    /// A replayed note is untouched before a hand rests on the head, decays with the
    /// touch's T60 while it rests, and stays stopped after (a later stroke does not bring
    /// it back); a touch before the note leaves it alone.
    #[test]
    fn a_touch_stops_a_replayed_note_for_good() {
        let fs = f64::from(SAMPLE_RATE_HZ);
        let start = (1.0 * fs) as usize;
        let mut note = vec![1.0f32; (2.0 * fs) as usize];
        damp_note(&mut note, start, &[(0.2, 0.45), (1.5, 1.75)]);
        let at = |t: f64| note[((t - 1.0) * fs) as usize];
        assert_eq!(at(1.49), 1.0);
        // 0.05 s of a 0.05 s T60: 60 dB down.
        assert!(
            (f64::from(at(1.55)) / 1e-3 - 1.0).abs() < 0.01,
            "{}",
            at(1.55)
        );
        assert!(at(1.8) < 1e-12 && at(2.9) == at(1.8));
    }
}
