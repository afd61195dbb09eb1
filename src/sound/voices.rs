//! The modal voice bank: one exact two-pole resonator per mode at the audio
//! rate — the ZOH step of [`ModeStep`](crate::drum::oscillator::ModeStep), whose poles are
//! the impulse-invariant r·e^{±iω_d/fs}, r = exp(−1/(τ·fs)), τ = T60/ln 1000 — laid out as
//! a struct of arrays in lanes of 8 f32 so the per-sample update *and* the sum over modes
//! (per-lane partial sums) vectorise (guide §5). Output = Σ gain_k × modal velocity_k.
//! On an x86-64 with AVX2 the same loops run compiled for it (a chunk in one register
//! instead of two; no fused multiply-adds, so the output is bit-identical to the portable
//! build's), chosen at run time.
//!
//! Pitch glide (tension modulation, Avanzini & Marogna, IEEE TASLP 2010): a loud stroke
//! stretches the head, raising its tension and every mode's frequency by the same factor
//! 1 + δ with δ = Σ_k c_k·(x1_k² + x2_k²) (the voices' `glide` weights, from the head's
//! stretching; see [`crate::sound::partials`]). [`VoiceBank::retune`] sets δ for the next
//! block by turning each voice's step by the extra angle ε = ω_k·δ·dt (a small rotation
//! applied after the step: exact to O(ε²) for the damped step, ε < 1e-3 here).

use crate::drum::oscillator::ModeStep;

/// Largest relative frequency rise of a glide (5 %).
pub const MAX_GLIDE: f32 = 0.05;

/// The glide is applied in steps of this size (1e-6: 0.0017 cents).
pub const GLIDE_STEP: f32 = 1e-6;

/// Modes per SIMD chunk.
pub const LANES: usize = 8;
type Lane = [f32; LANES];

/// How this CPU runs the banks: eight lanes in one AVX2 register, with AVX-512's 32
/// registers as well, or portable code.
#[cfg(target_arch = "x86_64")]
#[derive(Clone, Copy, PartialEq, Eq)]
enum Width {
    Portable,
    Avx2,
    Avx512,
}

/// This CPU's [`Width`], detected once.
#[cfg(target_arch = "x86_64")]
fn width() -> Width {
    static WIDTH: std::sync::OnceLock<Width> = std::sync::OnceLock::new();
    *WIDTH.get_or_init(|| {
        if std::arch::is_x86_feature_detected!("avx512f")
            && std::arch::is_x86_feature_detected!("avx512vl")
        {
            Width::Avx512
        } else if std::arch::is_x86_feature_detected!("avx2") {
            Width::Avx2
        } else {
            Width::Portable
        }
    })
}

/// One resonator's parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Voice {
    /// Ringing frequency, Hz.
    pub freq_hz: f64,
    /// Time to decay by 60 dB, s.
    pub t60_s: f64,
    /// Output weight of the modal velocity (output units per m/s).
    pub gain: f64,
    /// Glide weight c: this voice's share of the relative frequency rise per (m/s)² of
    /// its state, s²/m² (0: no glide).
    pub glide: f64,
}

/// The state of a [`VoiceBank`]'s voices.
#[derive(Clone, Debug, PartialEq)]
pub struct BankState {
    x1: Vec<Lane>,
    x2: Vec<Lane>,
}

/// A bank of resonators with state (ω₀q, q̇) per voice; padding lanes stay at zero.
#[derive(Clone, Debug)]
pub struct VoiceBank {
    len: usize,
    a11: Vec<Lane>,
    a12: Vec<Lane>,
    a21: Vec<Lane>,
    a22: Vec<Lane>,
    b1: Vec<Lane>,
    b2: Vec<Lane>,
    gain: Vec<Lane>,
    x1: Vec<Lane>,
    x2: Vec<Lane>,
    /// The untuned step matrices, the glide weights and ω·dt per voice.
    base: [Vec<Lane>; 4],
    glide: Vec<Lane>,
    omega_dt: Vec<Lane>,
    /// Whether any voice glides, and the glide the step matrices hold now (NaN: unknown,
    /// after a restore).
    glides: bool,
    tuned: f32,
    /// Extra decay factor per sample (1: none).
    damping: f32,
    /// Per chunk: whether any of its voices is ringing (all-zero chunks are skipped).
    active: Vec<bool>,
}

impl VoiceBank {
    /// A bank at rest, sampled at `rate_hz`.
    pub fn new(voices: &[Voice], rate_hz: f64) -> VoiceBank {
        let chunks = voices.len().div_ceil(LANES);
        let zero = vec![[0.0f32; LANES]; chunks];
        let mut bank = VoiceBank {
            len: voices.len(),
            a11: zero.clone(),
            a12: zero.clone(),
            a21: zero.clone(),
            a22: zero.clone(),
            b1: zero.clone(),
            b2: zero.clone(),
            gain: zero.clone(),
            x1: zero.clone(),
            x2: zero.clone(),
            base: [zero.clone(), zero.clone(), zero.clone(), zero.clone()],
            glide: zero.clone(),
            omega_dt: zero,
            glides: voices.iter().any(|v| v.glide > 0.0),
            tuned: 0.0,
            damping: 1.0,
            active: vec![false; chunks],
        };
        for (k, v) in voices.iter().enumerate() {
            let s = ModeStep::new(v.freq_hz, v.t60_s, 1.0 / rate_hz);
            let (c, l) = (k / LANES, k % LANES);
            bank.a11[c][l] = s.a[0][0] as f32;
            bank.a12[c][l] = s.a[0][1] as f32;
            bank.a21[c][l] = s.a[1][0] as f32;
            bank.a22[c][l] = s.a[1][1] as f32;
            bank.b1[c][l] = s.b[0] as f32;
            bank.b2[c][l] = s.b[1] as f32;
            bank.gain[c][l] = v.gain as f32;
            bank.glide[c][l] = v.glide as f32;
            bank.omega_dt[c][l] = (std::f64::consts::TAU * v.freq_hz / rate_hz) as f32;
        }
        bank.base = [
            bank.a11.clone(),
            bank.a12.clone(),
            bank.a21.clone(),
            bank.a22.clone(),
        ];
        bank
    }

    /// The relative frequency rise δ = Σ c_k·(x1_k² + x2_k²) the voices' state calls for.
    pub fn glide(&self) -> f32 {
        if !self.glides {
            return 0.0;
        }
        let mut acc = [0.0f32; LANES];
        for ((c, x1), x2) in self.glide.iter().zip(&self.x1).zip(&self.x2) {
            for l in 0..LANES {
                acc[l] += c[l] * (x1[l] * x1[l] + x2[l] * x2[l]);
            }
        }
        acc.iter().sum()
    }

    /// Ring every voice `1 + delta` times its own frequency from now on (see the module
    /// docs; δ is held within ±[`MAX_GLIDE`]: the stretching law is a small-strain one);
    /// `retune(0.0)` restores the voices. The extra turn is an exact rotation, so a
    /// retuned voice never gains energy.
    pub fn retune(&mut self, delta: f32) {
        if !self.glides {
            return;
        }
        // Quantised, so the matrices are a function of the state alone (resuming from a
        // saved state retunes exactly as the whole run did) and are rebuilt only when the
        // glide moves by a step.
        let delta = ((delta.clamp(-MAX_GLIDE, MAX_GLIDE) / GLIDE_STEP).round()) * GLIDE_STEP;
        if delta != self.tuned {
            self.tuned = delta;
            self.rebuild();
        }
    }

    /// Damp every voice by the extra factor `per_sample` (≤ 1) each sample from now on
    /// (a hand resting on the head); 1 lifts it.
    pub fn damp(&mut self, per_sample: f32) {
        if per_sample != self.damping {
            self.damping = per_sample;
            self.rebuild();
        }
    }

    /// The step matrices from the plain ones, the glide and the damping.
    fn rebuild(&mut self) {
        let delta = if self.tuned.is_nan() { 0.0 } else { self.tuned };
        let d = self.damping;
        let [b11, b12, b21, b22] = &self.base;
        for c in 0..self.a11.len() {
            for l in 0..LANES {
                let (s, k) = (self.omega_dt[c][l] * delta).sin_cos();
                let (s, k) = (s * d, k * d);
                self.a11[c][l] = b11[c][l] * k - b12[c][l] * s;
                self.a12[c][l] = b11[c][l] * s + b12[c][l] * k;
                self.a21[c][l] = b21[c][l] * k - b22[c][l] * s;
                self.a22[c][l] = b21[c][l] * s + b22[c][l] * k;
            }
        }
    }

    /// The voices' state, to [`restore`](VoiceBank::restore) later.
    pub fn state(&self) -> BankState {
        BankState {
            x1: self.x1.clone(),
            x2: self.x2.clone(),
        }
    }

    /// Go back to a state saved from a bank of the same voices.
    pub fn restore(&mut self, state: &BankState) {
        self.x1.clone_from(&state.x1);
        self.x2.clone_from(&state.x2);
        self.tuned = f32::NAN;
        for (a, (x1, x2)) in self.active.iter_mut().zip(self.x1.iter().zip(&self.x2)) {
            *a = x1.iter().chain(x2).any(|v| *v != 0.0);
        }
    }

    /// Number of voices.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether the bank has no voices.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Length of one sample's input row: voices padded to whole lanes.
    pub fn stride(&self) -> usize {
        self.a11.len() * LANES
    }

    /// Ring freely for `out.len()` samples, adding the output to `out`. Works in blocks of
    /// samples with each chunk of voices held in registers through the block (the same
    /// sums in the same order as one sample at a time, so the output is identical).
    pub fn render_free(&mut self, out: &mut [f32]) {
        #[cfg(target_arch = "x86_64")]
        match width() {
            // SAFETY: the CPU has AVX-512F and VL (checked by `width`).
            Width::Avx512 => return unsafe { self.render_free_avx512(out) },
            // SAFETY: the CPU has AVX2 (checked by `width`).
            Width::Avx2 => return unsafe { self.render_free_avx2(out) },
            Width::Portable => {}
        }
        self.render_free_lanes::<2>(out);
    }

    /// [`render_free`](Self::render_free) compiled for AVX2: a chunk's eight lanes in one
    /// register instead of two. No fused multiply-adds: the same operations in the same
    /// order as the portable code, so the output is bit-identical on every x86-64.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn render_free_avx2(&mut self, out: &mut [f32]) {
        self.render_free_lanes::<2>(out);
    }

    /// [`render_free`](Self::render_free) with AVX-512's 32 vector registers: four
    /// chunks' recurrences interleaved instead of two (2.4× the portable code's speed
    /// against 1.6× with AVX2 alone; on 256-bit vectors, so the same lanes and sums).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,avx512f,avx512vl")]
    unsafe fn render_free_avx512(&mut self, out: &mut [f32]) {
        self.render_free_lanes::<4>(out);
    }

    #[inline(always)]
    fn render_free_lanes<const G: usize>(&mut self, out: &mut [f32]) {
        const BLOCK: usize = 64;
        let chunks = self.x1.len();
        for block in out.chunks_mut(BLOCK) {
            let mut acc = [[0.0f32; LANES]; BLOCK];
            let acc_block = &mut acc[..block.len()];
            // Active chunks G at a time: a chunk's recurrence is a chain of dependent
            // multiply-adds (latency-bound), G independent chains fill the pipeline. Each
            // sample's sum still takes the chunks in order, so the output is the same.
            let mut group = [0usize; G];
            let mut held = 0;
            for c in 0..chunks {
                if !self.active[c] {
                    continue;
                }
                group[held] = c;
                held += 1;
                if held == G {
                    self.ring_group(group, acc_block);
                    held = 0;
                }
            }
            for &c in &group[..held] {
                self.ring_group([c], acc_block);
            }
            for (o, a) in block.iter_mut().zip(&acc) {
                *o += a.iter().sum::<f32>();
            }
        }
    }

    /// The chunks `cs` (in increasing order) ring freely over `acc.len()` samples,
    /// interleaved sample by sample, each sample adding their outputs to `acc` in order
    /// (as one chunk after the other would).
    #[inline(always)]
    fn ring_group<const N: usize>(&mut self, cs: [usize; N], acc: &mut [Lane]) {
        let (a11, a12) = (cs.map(|c| self.a11[c]), cs.map(|c| self.a12[c]));
        let (a21, a22) = (cs.map(|c| self.a21[c]), cs.map(|c| self.a22[c]));
        let g = cs.map(|c| self.gain[c]);
        let (mut x1, mut x2) = (cs.map(|c| self.x1[c]), cs.map(|c| self.x2[c]));
        for acc in acc.iter_mut() {
            for k in 0..N {
                for l in 0..LANES {
                    let n1 = a11[k][l] * x1[k][l] + a12[k][l] * x2[k][l];
                    let n2 = a21[k][l] * x1[k][l] + a22[k][l] * x2[k][l];
                    x1[k][l] = n1;
                    x2[k][l] = n2;
                    acc[l] += g[k][l] * n2;
                }
            }
        }
        for (k, &c) in cs.iter().enumerate() {
            (self.x1[c], self.x2[c]) = (x1[k], x2[k]);
        }
    }

    /// Ring for `out.len()` samples driven by `input` (per sample one row of
    /// [`stride`](Self::stride) accelerations, m/s², held over the sample), adding to `out`.
    pub fn render_driven(&mut self, input: &[f32], out: &mut [f32]) {
        if self.stride() == 0 {
            // No voices (every mode of the head above the band): nothing sounds.
            return;
        }
        #[cfg(target_arch = "x86_64")]
        if width() != Width::Portable {
            // SAFETY: the CPU has AVX2 (checked by `width`).
            return unsafe { self.render_driven_avx2(input, out) };
        }
        self.render_driven_lanes(input, out);
    }

    /// [`render_driven`](Self::render_driven) compiled for AVX2 (see
    /// [`render_free_avx2`](Self::render_free_avx2)).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn render_driven_avx2(&mut self, input: &[f32], out: &mut [f32]) {
        self.render_driven_lanes(input, out);
    }

    #[inline(always)]
    fn render_driven_lanes(&mut self, input: &[f32], out: &mut [f32]) {
        let stride = self.stride();
        assert!(input.len() >= out.len() * stride, "input too short");
        self.active.fill(true);
        let chunks = self.x1.len();
        for (o, row) in out.iter_mut().zip(input.chunks_exact(stride)) {
            let mut acc = [0.0f32; LANES];
            // Each chunk's lanes taken by value and put back, as in `render_free_lanes`:
            // held in registers, the eight lanes run as one vector (through references
            // into the arrays they ran one by one).
            for (c, u) in row.chunks_exact(LANES).enumerate().take(chunks) {
                let u: Lane = u.try_into().expect("a chunk of lanes");
                let (a11, a12, a21, a22, b1, b2, g) = (
                    self.a11[c],
                    self.a12[c],
                    self.a21[c],
                    self.a22[c],
                    self.b1[c],
                    self.b2[c],
                    self.gain[c],
                );
                let (mut x1, mut x2) = (self.x1[c], self.x2[c]);
                for l in 0..LANES {
                    let n1 = a11[l] * x1[l] + a12[l] * x2[l] + b1[l] * u[l];
                    let n2 = a21[l] * x1[l] + a22[l] * x2[l] + b2[l] * u[l];
                    x1[l] = n1;
                    x2[l] = n2;
                    acc[l] += g[l] * n2;
                }
                (self.x1[c], self.x2[c]) = (x1, x2);
            }
            *o += acc.iter().sum::<f32>();
        }
    }

    /// Ring freely over `out` in chunks, flushing states below `floor` (m/s) between
    /// chunks and stopping once the bank is silent (long tails stay out of subnormals).
    pub fn ring(&mut self, out: &mut [f32], floor: f32) {
        for chunk in out.chunks_mut(2048) {
            if self.flush(floor) {
                return;
            }
            self.render_free(chunk);
        }
    }

    /// Add `dv[k]` to voice k's modal velocity (an impulse), m/s.
    pub fn kick(&mut self, dv: &[f32]) {
        for (k, d) in dv.iter().enumerate().take(self.len) {
            self.x2[k / LANES][k % LANES] += d;
            self.active[k / LANES] |= *d != 0.0;
        }
    }

    /// Set states below `floor` (m/s) to exactly zero — keeps long tails out of subnormal
    /// arithmetic — and say whether the whole bank is now silent.
    pub fn flush(&mut self, floor: f32) -> bool {
        let mut silent = true;
        for ((x1, x2), active) in self
            .x1
            .iter_mut()
            .zip(self.x2.iter_mut())
            .zip(self.active.iter_mut())
        {
            let mut ringing = false;
            for v in x1.iter_mut().chain(x2.iter_mut()) {
                if v.abs() < floor {
                    *v = 0.0;
                } else {
                    ringing = true;
                }
            }
            *active = ringing;
            silent &= !ringing;
        }
        silent
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A gliding voice kicked hard rings sharp by δ = c·|x|² and settles as it decays;
    /// retune(0) restores the voice exactly.
    #[test]
    fn glide_follows_the_state() {
        let rate = 48_000.0;
        let v = Voice {
            freq_hz: 200.0,
            t60_s: 0.3,
            gain: 1.0,
            glide: 1e-4,
        };
        let mut bank = VoiceBank::new(&[v], rate);
        let plain = bank.clone();
        bank.kick(&[10.0]);
        assert!((bank.glide() - 1e-2).abs() < 1e-6, "{}", bank.glide());
        bank.retune(bank.glide());
        assert_ne!(bank.a11, plain.a11);
        // Its fifth upward zero crossing comes ≥ 4 samples (≈ 0.4 %) before a plain
        // voice's (δ starts at 1 % and falls with the energy, T60 0.3 s).
        let run = |b: &mut VoiceBank, glide: bool| {
            let mut out = vec![0.0f32; 2400];
            for chunk in out.chunks_mut(128) {
                if glide {
                    b.retune(b.glide());
                }
                b.render_free(chunk);
            }
            out.windows(2)
                .enumerate()
                .filter(|(_, w)| w[0] < 0.0 && w[1] >= 0.0)
                .nth(4)
                .unwrap()
                .0
        };
        let mut reference = plain.clone();
        reference.kick(&[10.0]);
        let (sharp, flat) = (run(&mut bank, true), run(&mut reference, false));
        assert!(sharp + 4 <= flat && flat - sharp < 20, "{sharp} vs {flat}");
        bank.retune(0.0);
        assert_eq!((bank.a11.clone(), bank.a22.clone()), (plain.a11, plain.a22));
    }

    /// The bank as this CPU runs it (AVX2 or AVX-512, chunks interleaved two or four at a
    /// time) gives the portable code's output, one chunk after another, to the bit — with
    /// every chunk ringing, and with one silent (skipped) among them.
    #[test]
    fn wide_and_portable_lanes_agree_bit_for_bit() {
        for silent in [None, Some(1)] {
            lanes_agree(silent);
        }
    }

    fn lanes_agree(silent_chunk: Option<usize>) {
        let voices: Vec<Voice> = (0..37)
            .map(|k| Voice {
                freq_hz: 100.0 + 97.0 * k as f64,
                t60_s: 0.3 + 0.05 * k as f64,
                gain: 1.0 / (1.0 + k as f64),
                glide: 0.0,
            })
            .collect();
        let mut bank = VoiceBank::new(&voices, 48_000.0);
        let kicks: Vec<f32> = (0..37)
            .map(|k| match silent_chunk {
                Some(c) if k / LANES == c => 0.0,
                _ => 1.0 - k as f32 / 40.0,
            })
            .collect();
        bank.kick(&kicks);
        let mut twin = bank.clone();
        let (mut a, mut b) = (vec![0.0f32; 4000], vec![0.0f32; 4000]);
        bank.render_free(&mut a[..300]);
        twin.render_free_lanes::<1>(&mut b[..300]);
        assert_eq!(a, b);
        let input: Vec<f32> = (0..300 * bank.stride()).map(|i| (i % 7) as f32).collect();
        let (mut a, mut b) = (vec![0.0f32; 4000], vec![0.0f32; 4000]);
        bank.render_driven(&input, &mut a[..300]);
        twin.render_driven_lanes(&input, &mut b[..300]);
        bank.render_free(&mut a[300..]);
        twin.render_free_lanes::<1>(&mut b[300..]);
        assert_eq!(a, b);
        assert!(a.iter().any(|v| *v != 0.0));
    }

    /// A kicked voice rings at its frequency and its envelope falls 60 dB in T60 (2 %),
    /// and padding lanes stay silent; driven and free rendering agree for zero input.
    #[test]
    fn voices_ring_and_decay() {
        let rate = 48_000.0;
        let voices = [
            Voice {
                freq_hz: 220.0,
                t60_s: 0.5,
                gain: 1.0,
                glide: 0.0,
            },
            Voice {
                freq_hz: 1000.0,
                t60_s: 0.2,
                gain: 0.0,
                glide: 0.0,
            },
        ];
        let mut bank = VoiceBank::new(&voices, rate);
        assert_eq!((bank.len(), bank.stride()), (2, 8));
        let mut twin = bank.clone();
        bank.kick(&[1.0, 1.0]);
        twin.kick(&[1.0, 1.0]);
        let n = 30_000;
        let mut out = vec![0.0f32; n];
        bank.render_free(&mut out);
        let mut out2 = vec![0.0f32; n];
        twin.render_driven(&vec![0.0; n * 8], &mut out2);
        assert_eq!(out, out2);
        let crossings = out.windows(2).filter(|w| w[0] < 0.0 && w[1] >= 0.0).count();
        assert!(
            (crossings as f64 - 220.0 * n as f64 / rate).abs() <= 1.0,
            "{crossings}"
        );
        let env = |t: f64| {
            let i = (t * rate) as usize;
            out[i..i + 220].iter().fold(0.0f32, |m, v| m.max(v.abs()))
        };
        let db = 20.0 * (env(0.5) / env(0.0)).log10();
        assert!((db + 60.0).abs() < 1.2, "{db} dB");
        assert!(!bank.flush(1e-9));
    }
}
