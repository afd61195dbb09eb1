//! The room a recording hears the drums in (opt-in: `render --room studio|hall`, the
//! score's settings): its late reverberation added to the drums' direct sound.
//!
//! **Model.** Past its first reflections a room's impulse response is noise decaying
//! exponentially, 60 dB over the room's reverberation time T60, each frequency at its own
//! rate (Polack's statistical model). A feedback delay network makes it (Jot & Chaigne
//! 1991): [`LINES`] delay lines of mutually prime lengths spread over the room's
//! [`Acoustics::delays_s`] (about its mean free path over the speed of sound), their
//! outputs mixed back through an orthogonal (Hadamard) matrix, so the network is lossless
//! but for each line's one-pole loss filter, which takes the T60 of the line's length at
//! 0 Hz ([`Acoustics::t60_low_s`]) and at the Nyquist frequency
//! ([`Acoustics::t60_high_s`]) — air and walls absorb the highs first. The left and right
//! channels enter and leave the lines by different rows of the matrix, so the two
//! reverberant channels are uncorrelated as a spaced pair's are.
//!
//! **Level.** Sabine's diffuse field against the direct sound at the microphones, a
//! distance r from the drums: DRR = Q·A/(16π·r²), with the absorption area A =
//! 0.161·V/T60 (m², T60 at 500 Hz) and the drums' directivity Q = 2 (a head radiates into
//! the half space above it). The network's output is scaled so its energy per unit of
//! direct energy is 1/DRR.
//!
//! **Resuming.** The network's state is saved every [`SAVE_EVERY_FRAMES`]; a rendering that
//! changes the mix from some frame on runs it again from the last state saved before that
//! frame, bit for bit as a whole render.
//!
//! Why a room: the recordings the sound is compared with were made in one. Their octave
//! bands are measured over a Hann window on the first second, which hides a dry stroke's
//! attack; a room carries the attack's low thump and brightness into that second (README,
//! "The room").

use super::SAMPLE_RATE_HZ;
pub use crate::base::choices::Room;
use std::sync::OnceLock;

/// Delay lines of the network.
pub const LINES: usize = 32;
/// Frames between saved network states (2 s).
pub const SAVE_EVERY_FRAMES: usize = 96_000;
/// Directivity of the drums' direct sound at the microphones (a head radiating into the
/// half space above it).
const DIRECTIVITY: f64 = 2.0;
/// Sabine's constant, s/m (T60 = 0.161·V/A).
const SABINE_S_PER_M: f64 = 0.161;
/// The frequency whose T60 sets the absorption area in Sabine's level, Hz.
const LEVEL_HZ: f64 = 500.0;

/// What a room preset is made of.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Acoustics {
    /// Volume, m³.
    pub volume_m3: f64,
    /// Reverberation time at 0 Hz, s.
    pub t60_low_s: f64,
    /// Reverberation time at the Nyquist frequency (24 kHz), s.
    pub t60_high_s: f64,
    /// Distance from the drums to the microphones, m.
    pub microphone_m: f64,
    /// The shortest and the longest delay line, s.
    pub delays_s: (f64, f64),
}

impl Acoustics {
    /// The acoustics of `room` (`None` for a dry render).
    pub fn of(room: Room) -> Option<Acoustics> {
        match room {
            Room::Dry => None,
            // A recording studio's live room, spot microphones 0.5 m over the heads.
            Room::Studio => Some(Acoustics {
                volume_m3: 400.0,
                t60_low_s: 0.52,
                t60_high_s: 0.15,
                microphone_m: 0.5,
                delays_s: (0.015, 0.050),
            }),
            // A concert hall, the microphones 3 m in front of the timpani.
            Room::Hall => Some(Acoustics {
                volume_m3: 12_000.0,
                t60_low_s: 2.2,
                t60_high_s: 0.5,
                microphone_m: 3.0,
                delays_s: (0.040, 0.130),
            }),
        }
    }

    /// The length of each delay line, frames: primes spread geometrically over
    /// [`Self::delays_s`].
    fn lengths(&self) -> [usize; LINES] {
        let fs = f64::from(SAMPLE_RATE_HZ);
        let (short, long) = self.delays_s;
        let mut lengths = [0; LINES];
        let mut last = 0;
        for (i, length) in lengths.iter_mut().enumerate() {
            let s = short * (long / short).powf(i as f64 / (LINES - 1) as f64);
            let mut n = ((s * fs).round() as usize).max(last + 1);
            while !is_prime(n) {
                n += 1;
            }
            *length = n;
            last = n;
        }
        lengths
    }

    /// The loss filter of a line `length` frames long, (b0, a1): y = b0·x + a1·y⁻¹, with
    /// the gain 10^(−3·length/(fs·T60)) at 0 Hz and at the Nyquist frequency.
    fn loss(&self, length: usize) -> (f64, f64) {
        let fs = f64::from(SAMPLE_RATE_HZ);
        let gain = |t60: f64| 10f64.powf(-3.0 * length as f64 / (fs * t60));
        let (g0, g1) = (gain(self.t60_low_s), gain(self.t60_high_s));
        let a1 = (g0 - g1) / (g0 + g1);
        (g0 * (1.0 - a1), a1)
    }

    /// The reverberation time at `hz` the network makes, s (over its mean line length).
    pub fn t60_at(&self, hz: f64) -> f64 {
        let lengths = self.lengths();
        let mean = lengths.iter().sum::<usize>() as f64 / LINES as f64;
        let (b0, a1) = self.loss(mean.round() as usize);
        let w = std::f64::consts::TAU * hz / f64::from(SAMPLE_RATE_HZ);
        let magnitude = b0 / (1.0 + a1 * a1 - 2.0 * a1 * w.cos()).sqrt();
        -3.0 * mean / (f64::from(SAMPLE_RATE_HZ) * magnitude.log10())
    }

    /// Direct-to-reverberant energy ratio at the microphones (Sabine; module docs).
    pub fn direct_to_reverberant(&self) -> f64 {
        let absorption_m2 = SABINE_S_PER_M * self.volume_m3 / self.t60_at(LEVEL_HZ);
        DIRECTIVITY * absorption_m2 / (16.0 * std::f64::consts::PI * self.microphone_m.powi(2))
    }
}

fn is_prime(n: usize) -> bool {
    n >= 2
        && (2..)
            .take_while(|d| d * d <= n)
            .all(|d| !n.is_multiple_of(d))
}

/// Row `r` of the [`LINES`]×[`LINES`] Sylvester–Hadamard matrix, ±1.
fn hadamard_row(r: usize) -> [f32; LINES] {
    std::array::from_fn(|c| {
        if (r & c).count_ones().is_multiple_of(2) {
            1.0
        } else {
            -1.0
        }
    })
}

/// One stage of the fast Walsh–Hadamard transform: the butterflies `H` apart (a constant,
/// so each stage unrolls into whole-register additions).
#[inline(always)]
fn butterflies<const H: usize>(x: &mut [f32; LINES]) {
    for group in x.chunks_exact_mut(2 * H) {
        let (a, b) = group.split_at_mut(H);
        for (a, b) in a.iter_mut().zip(b) {
            (*a, *b) = (*a + *b, *a - *b);
        }
    }
}

/// In place: the [`LINES`]-point Walsh–Hadamard transform scaled by 1/√[`LINES`]
/// (orthogonal). The stages act on different bits of the index, so their order is free.
#[inline]
fn hadamard(x: &mut [f32; LINES]) {
    const { assert!(LINES == 32) };
    butterflies::<16>(x);
    butterflies::<8>(x);
    butterflies::<4>(x);
    butterflies::<2>(x);
    butterflies::<1>(x);
    let scale = 1.0 / (LINES as f32).sqrt();
    for v in x {
        *v *= scale;
    }
}

/// Frames the network runs at a time: each line is read for the whole block before any
/// of it is written back, which holds while no line is shorter than a block.
const BLOCK: usize = 256;

/// One delay line: its samples (a ring) and where it is read and written.
#[derive(Clone, Debug, PartialEq)]
struct Line {
    ring: Vec<f32>,
    position: usize,
}

impl Line {
    /// The next `out.len()` samples out of the line; the position stays where they were
    /// read, for [`Line::write`].
    fn read(&self, out: &mut [f32]) {
        let first = out.len().min(self.ring.len() - self.position);
        let (head, tail) = out.split_at_mut(first);
        head.copy_from_slice(&self.ring[self.position..self.position + first]);
        tail.copy_from_slice(&self.ring[..tail.len()]);
    }

    /// Write `samples` into the line where the block was read, and move on.
    fn write(&mut self, samples: &[f32]) {
        let first = samples.len().min(self.ring.len() - self.position);
        let (head, tail) = samples.split_at(first);
        self.ring[self.position..self.position + first].copy_from_slice(head);
        self.ring[..tail.len()].copy_from_slice(tail);
        self.position = (self.position + samples.len()) % self.ring.len();
    }
}

/// The feedback delay network's coefficients and state.
#[derive(Clone, Debug, PartialEq)]
struct Network {
    lines: Vec<Line>,
    /// Per line: the loss filter y = b0·x + a1·y⁻¹, and its last output.
    b0: [f32; LINES],
    a1: [f32; LINES],
    filtered: [f32; LINES],
    /// How the left and right inputs enter the lines: rows 3 and 5 of the Hadamard
    /// matrix, scaled by 1/√[`LINES`].
    input: [[f32; LINES]; 2],
    /// The output scale: the left output is row 1 of the Hadamard matrix over the lines'
    /// filtered samples, the right row 2, each scaled by this and 1/√[`LINES`] — which
    /// are elements 1 and 2 of the feedback's transform, times this.
    wet: f32,
}

impl Network {
    /// A silent network for `acoustics`, its output scaled by `wet`.
    fn new(acoustics: &Acoustics, wet: f64) -> Network {
        let lengths = acoustics.lengths();
        let (mut b0, mut a1) = ([0.0; LINES], [0.0; LINES]);
        for (i, &length) in lengths.iter().enumerate() {
            debug_assert!(length >= BLOCK);
            let (b, a) = acoustics.loss(length);
            (b0[i], a1[i]) = (b as f32, a as f32);
        }
        let norm = 1.0 / (LINES as f64).sqrt();
        let scaled = |row: usize| hadamard_row(row).map(|v| v * norm as f32);
        Network {
            lines: lengths
                .iter()
                .map(|&length| Line {
                    ring: vec![0.0; length],
                    position: 0,
                })
                .collect(),
            b0,
            a1,
            filtered: [0.0; LINES],
            input: [scaled(3), scaled(5)],
            wet: wet as f32,
        }
    }

    /// Run the network over `stereo` (interleaved), adding its reverberation to it, a
    /// block at a time: each line's block read out whole, every frame's loss filters,
    /// feedback transform and inputs across the lines at once, the block written back.
    fn run(&mut self, stereo: &mut [f32]) {
        let mut blocks = vec![[0.0f32; BLOCK]; LINES];
        for block in stereo.chunks_mut(2 * BLOCK) {
            let n = block.len() / 2;
            for (line, out) in self.lines.iter().zip(blocks.iter_mut()) {
                line.read(&mut out[..n]);
            }
            for (k, io) in block.chunks_exact_mut(2).enumerate() {
                let (left, right) = (io[0], io[1]);
                let (b0, a1) = (&self.b0, &self.a1);
                for (i, f) in self.filtered.iter_mut().enumerate() {
                    *f = b0[i] * blocks[i][k] + a1[i] * *f;
                }
                let mut frame = self.filtered;
                hadamard(&mut frame);
                io[0] += self.wet * frame[1];
                io[1] += self.wet * frame[2];
                for (i, y) in frame.iter().enumerate() {
                    blocks[i][k] = y + self.input[0][i] * left + self.input[1][i] * right;
                }
            }
            for (line, samples) in self.lines.iter_mut().zip(&blocks) {
                line.write(&samples[..n]);
            }
        }
    }
}

/// The energy an unscaled network of `acoustics` gives back per unit of energy put in:
/// its response to a unit impulse, each channel in turn, summed over both outputs until it
/// has fallen 90 dB (mean of the two).
fn network_energy(acoustics: &Acoustics) -> f64 {
    let frames = (1.5 * acoustics.t60_low_s * f64::from(SAMPLE_RATE_HZ)) as usize;
    let mut total = 0.0;
    for channel in 0..2 {
        let mut stereo = vec![0.0f32; 2 * frames];
        stereo[channel] = 1.0;
        Network::new(acoustics, 1.0).run(&mut stereo);
        total += stereo[2..]
            .iter()
            .map(|v| f64::from(*v).powi(2))
            .sum::<f64>();
    }
    total / 2.0
}

/// The output scale that puts the reverberation 1/DRR of the direct energy (cached per
/// room).
fn wet_scale(room: Room, acoustics: &Acoustics) -> f64 {
    static SCALES: [OnceLock<f64>; 3] = [OnceLock::new(), OnceLock::new(), OnceLock::new()];
    *SCALES[room as usize].get_or_init(|| {
        (1.0 / (acoustics.direct_to_reverberant() * network_energy(acoustics))).sqrt()
    })
}

/// A room's reverberation of a mix, kept to resume: the mix with the room (interleaved
/// stereo) and the network's state every [`SAVE_EVERY_FRAMES`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RoomState {
    room: Room,
    /// The dry mix plus the room's reverberation of it.
    pub wet: Vec<f32>,
    saved: Vec<(usize, Network)>,
}

impl RoomState {
    /// The room it was last brought up to date in.
    pub fn room(&self) -> Room {
        self.room
    }

    /// Bring `wet` up to date with `dry` (interleaved stereo) in `room`, whose frames
    /// before `from` are those it was last given: the network runs again from its latest
    /// state saved at or before `from`. Returns the first frame of `wet` it rewrote (0 for
    /// a dry room: nothing is kept).
    pub fn update(&mut self, room: Room, dry: &[f32], from: usize) -> usize {
        let Some(acoustics) = Acoustics::of(room) else {
            *self = RoomState::default();
            return 0;
        };
        if self.room != room {
            *self = RoomState {
                room,
                ..RoomState::default()
            };
        }
        let frames = dry.len() / 2;
        self.saved.retain(|(frame, _)| *frame <= from.min(frames));
        let (begin, mut network) = match self.saved.last() {
            Some((frame, network)) => (*frame, network.clone()),
            None => (0, Network::new(&acoustics, wet_scale(room, &acoustics))),
        };
        self.wet.resize(dry.len(), 0.0);
        self.wet[2 * begin..].copy_from_slice(&dry[2 * begin..]);
        let mut at = begin;
        while at < frames {
            let next = ((at / SAVE_EVERY_FRAMES + 1) * SAVE_EVERY_FRAMES).min(frames);
            network.run(&mut self.wet[2 * at..2 * next]);
            if next < frames {
                self.saved.push((next, network.clone()));
            }
            at = next;
        }
        begin
    }
}

/// `stereo` (interleaved) heard in `room`: the direct sound plus the room's reverberation
/// of it, from silence (a stem; a mix that resumes keeps a [`RoomState`]).
pub fn reverberate(room: Room, stereo: &mut [f32]) {
    let Some(acoustics) = Acoustics::of(room) else {
        return;
    };
    Network::new(&acoustics, wet_scale(room, &acoustics)).run(stereo);
}

/// A mono signal heard in `room` by one of its two microphones: the direct sound plus
/// that channel's reverberation (the drum central, the same energy ratio as in stereo).
pub fn reverberate_mono(room: Room, mono: &mut [f32]) {
    let Some(acoustics) = Acoustics::of(room) else {
        return;
    };
    let half = std::f32::consts::FRAC_1_SQRT_2;
    let mut stereo: Vec<f32> = mono.iter().flat_map(|s| [s * half, s * half]).collect();
    Network::new(&acoustics, wet_scale(room, &acoustics)).run(&mut stereo);
    for (s, pair) in mono.iter_mut().zip(stereo.chunks_exact(2)) {
        *s += (pair[0] - *s * half) * std::f32::consts::SQRT_2;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::rng::Rng;

    fn noise(frames: usize, seed: u64) -> Vec<f32> {
        let mut rng = Rng::new(seed);
        (0..frames).map(|_| rng.uniform(-0.5, 0.5) as f32).collect()
    }

    /// The network's impulse response falls as the room's T60 says: the Schroeder
    /// (backward-integrated) energy decay of each channel, low-passed at 250 Hz (two
    /// one-pole filters) and fitted from −5 to −25 dB, gives the T60 at 125 Hz within
    /// 10 %.
    #[test]
    fn the_reverberation_decays_with_the_rooms_t60() {
        for room in [Room::Studio, Room::Hall] {
            let acoustics = Acoustics::of(room).unwrap();
            let frames = (2.0 * acoustics.t60_low_s * f64::from(SAMPLE_RATE_HZ)) as usize;
            let mut stereo = vec![0.0f32; 2 * frames];
            stereo[0] = 1.0;
            reverberate(room, &mut stereo);
            let alpha = 1.0 - (-std::f64::consts::TAU * 250.0 / f64::from(SAMPLE_RATE_HZ)).exp();
            for channel in 0..2 {
                let (mut y1, mut y2) = (0.0, 0.0);
                let energy: Vec<f64> = (1..frames)
                    .map(|n| {
                        y1 += alpha * (f64::from(stereo[2 * n + channel]) - y1);
                        y2 += alpha * (y1 - y2);
                        y2 * y2
                    })
                    .collect();
                let mut decay = vec![0.0; energy.len()];
                let mut sum = 0.0;
                for n in (0..energy.len()).rev() {
                    sum += energy[n];
                    decay[n] = sum;
                }
                let db = |n: usize| 10.0 * (decay[n] / decay[0]).log10();
                let at = |level: f64| (0..decay.len()).find(|&n| db(n) < level).unwrap();
                let (a, b) = (at(-5.0), at(-25.0));
                let t60 = 3.0 * (b - a) as f64 / f64::from(SAMPLE_RATE_HZ);
                let nominal = acoustics.t60_at(125.0);
                println!(
                    "{room}, channel {channel}: T60 {t60:.2} s (the network's {nominal:.2} s)"
                );
                assert!(
                    (t60 / nominal - 1.0).abs() < 0.1,
                    "{room}: T60 {t60:.2} s against {nominal:.2} s"
                );
            }
        }
    }

    /// In a steady noise the reverberant energy is 1/DRR of the direct (Sabine), within
    /// 0.5 dB, and the two channels' reverberation is uncorrelated (|r| < 0.1).
    #[test]
    fn the_reverberation_has_sabines_level_and_two_uncorrelated_channels() {
        for room in [Room::Studio, Room::Hall] {
            let acoustics = Acoustics::of(room).unwrap();
            let frames = 20 * SAMPLE_RATE_HZ as usize;
            let mono = noise(frames, 7);
            let dry: Vec<f32> = mono.iter().flat_map(|&x| [x, x]).collect();
            let mut wet = dry.clone();
            reverberate(room, &mut wet);
            // After the first T60, the reverberant field is steady.
            let skip = (acoustics.t60_low_s * f64::from(SAMPLE_RATE_HZ)) as usize;
            let (mut direct, mut reverb, mut lr) = (0.0, [0.0; 2], 0.0);
            for n in skip..frames {
                let r = [wet[2 * n] - dry[2 * n], wet[2 * n + 1] - dry[2 * n + 1]];
                direct += f64::from(dry[2 * n]).powi(2) + f64::from(dry[2 * n + 1]).powi(2);
                reverb[0] += f64::from(r[0]).powi(2);
                reverb[1] += f64::from(r[1]).powi(2);
                lr += f64::from(r[0]) * f64::from(r[1]);
            }
            let drr_db = 10.0 * (direct / (reverb[0] + reverb[1])).log10();
            let sabine_db = 10.0 * acoustics.direct_to_reverberant().log10();
            assert!(
                (drr_db - sabine_db).abs() < 0.5,
                "{room}: {drr_db:.2} dB against Sabine's {sabine_db:.2} dB"
            );
            let correlation = lr / (reverb[0] * reverb[1]).sqrt();
            println!("{room}: DRR {drr_db:.2} dB (Sabine {sabine_db:.2} dB), r = {correlation:.3}");
            assert!(correlation.abs() < 0.1, "{room}: r = {correlation:.3}");
        }
    }

    /// A mix changed from some frame on, brought up to date from the state saved before
    /// it, is the whole mix heard in the room bit for bit; a dry room keeps nothing.
    #[test]
    fn resuming_the_room_gives_the_whole_render_bit_for_bit() {
        let frames = 5 * SAVE_EVERY_FRAMES / 2;
        let first = noise(2 * frames, 1);
        let mut second = first.clone();
        let changed = 2 * SAVE_EVERY_FRAMES + 123;
        second[2 * changed..].copy_from_slice(&noise(2 * (frames - changed), 2));
        let mut resumed = RoomState::default();
        assert_eq!(resumed.update(Room::Hall, &first, 0), 0);
        let from = resumed.update(Room::Hall, &second, changed);
        assert_eq!(from, 2 * SAVE_EVERY_FRAMES);
        let mut whole = RoomState::default();
        whole.update(Room::Hall, &second, 0);
        assert!(resumed.wet == whole.wet);
        let mut alone = second.clone();
        reverberate(Room::Hall, &mut alone);
        assert!(alone == whole.wet);
        assert_ne!(whole.wet, second);
        assert_eq!(whole.update(Room::Dry, &second, 0), 0);
        assert_eq!(whole, RoomState::default());
    }
}
