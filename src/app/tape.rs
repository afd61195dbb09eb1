//! The tape: one long-lived kira sound that plays interleaved stereo audio at
//! [`SOURCE_RATE_HZ`] from a shared source that can be swapped while it plays.
//!
//! [`TapeData`] is played once ([`kira::AudioManager::play`]) and then controlled through
//! its [`TapeHandle`]: play from a position, pause, seek, and swap the source. Commands go
//! to the audio thread over a lock-free ring buffer (`rtrb`); the sound publishes its
//! position (seconds, as the bits of an `f64` in an `AtomicU64`) for the handle to read.
//!
//! Nothing restarts: a swap keeps the position and crossfades linearly from the old
//! source to the new one over [`FADE_S`] (5 ms, 240 frames at 48 kHz), so it is
//! click-free even where the new audio differs at the playhead; a seek while playing
//! crossfades from the old position to the new one the same way; play and pause ramp the
//! level over 5 ms, and once paused and silent the position stops. The output rate may
//! differ from the source's: each output frame of `dt` seconds advances `dt · 48000`
//! source frames, interpolating linearly between them. Past the end of the source the
//! tape plays silence while the position keeps running.
//!
//! The audio thread never allocates or frees: a source it lets go of is sent back to the
//! handle over a second ring buffer and dropped there, on the next call to the handle.
//! The sound is finished once the handle is dropped.

use kira::Frame;
use kira::info::Info;
use kira::sound::{Sound, SoundData};
use rtrb::{Consumer, Producer, PushError, RingBuffer};
use std::collections::VecDeque;
use std::convert::Infallible;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::Instant;

/// Sample rate of every source, Hz (frames per second per channel).
pub const SOURCE_RATE_HZ: u32 = 48_000;

/// Length of every fade (play, pause, swap, seek while playing), s.
pub const FADE_S: f64 = 0.005;

/// Commands that fit in the ring to the audio thread (more wait on the handle).
const COMMAND_CAPACITY: usize = 64;
/// Sources that fit in the ring back from the audio thread (when it is full the sound
/// holds on to what it would return and takes no further commands until there is room).
const RETURN_CAPACITY: usize = 16;

/// Interleaved stereo samples (left, right, left, …) at [`SOURCE_RATE_HZ`], in [−1, 1].
/// A trailing odd sample is ignored.
pub trait StereoSource: Send + Sync {
    /// Samples (twice the frames, plus a trailing odd one if any).
    fn sample_count(&self) -> usize;
    /// Frame `i` (left, right), if the source holds it whole.
    fn frame(&self, i: usize) -> Option<[f32; 2]>;
}

impl StereoSource for Vec<f32> {
    fn sample_count(&self) -> usize {
        self.len()
    }

    fn frame(&self, i: usize) -> Option<[f32; 2]> {
        self.get(2 * i..2 * i + 2).map(|lr| [lr[0], lr[1]])
    }
}

/// A source shared between the UI and the audio thread.
pub type Source = Arc<dyn StereoSource>;

enum Command {
    /// Play from this position, s.
    Play(f64),
    Pause,
    /// Move to this position, s, playing or not.
    Seek(f64),
    Swap(Source),
}

struct Sequenced {
    /// Counts the commands sent, from 1.
    seq: u64,
    command: Command,
}

/// What the sound publishes and the handle reads.
struct Shared {
    /// The position, s, as `f64` bits.
    position: AtomicU64,
    /// The `seq` of the last command the sound has applied.
    applied: AtomicU64,
    /// Cleared when the handle is dropped: the sound is then finished.
    handle_alive: AtomicBool,
    /// Output frames processed so far: the heartbeat of the audio thread, which stops
    /// when the device does.
    frames: AtomicU64,
}

/// The tape before it plays: give it to [`kira::AudioManager::play`] (once) to get its
/// [`TapeHandle`].
pub struct TapeData {
    sound: TapeSound,
    handle: TapeHandle,
}

impl TapeData {
    /// A paused tape at 0 s with no source.
    pub fn new() -> TapeData {
        let (commands_tx, commands_rx) = RingBuffer::new(COMMAND_CAPACITY);
        let (returns_tx, returns_rx) = RingBuffer::new(RETURN_CAPACITY);
        let shared = Arc::new(Shared {
            position: AtomicU64::new(0.0f64.to_bits()),
            applied: AtomicU64::new(0),
            handle_alive: AtomicBool::new(true),
            frames: AtomicU64::new(0),
        });
        TapeData {
            sound: TapeSound {
                commands: commands_rx,
                returns: returns_tx,
                shared: Arc::clone(&shared),
                now: Voice::default(),
                fading: None,
                mix: 1.0,
                level: 0.0,
                playing: false,
                applied: 0,
            },
            handle: TapeHandle {
                commands: commands_tx,
                returns: returns_rx,
                shared,
                backlog: VecDeque::new(),
                seq: 0,
                playing: false,
                moved_seq: 0,
                asked_s: 0.0,
                asked_at: None,
            },
        }
    }
}

impl Default for TapeData {
    fn default() -> Self {
        TapeData::new()
    }
}

impl SoundData for TapeData {
    type Error = Infallible;
    type Handle = TapeHandle;

    fn into_sound(self) -> Result<(Box<dyn Sound>, TapeHandle), Infallible> {
        Ok((Box::new(self.sound), self.handle))
    }
}

/// Controls a playing tape from the UI thread. Every call first drops the sources the
/// audio thread has let go of.
pub struct TapeHandle {
    commands: Producer<Sequenced>,
    returns: Consumer<Source>,
    shared: Arc<Shared>,
    /// Commands not yet in the ring (only when it was full).
    backlog: VecDeque<Sequenced>,
    /// The `seq` of the last command sent.
    seq: u64,
    playing: bool,
    /// The `seq` of the last play, pause or seek: until the sound has applied it,
    /// [`position_s`](TapeHandle::position_s) is estimated from what it asked.
    moved_seq: u64,
    /// The position the last play, pause or seek asked for, s.
    asked_s: f64,
    /// When the last play asked (`None` when paused).
    asked_at: Option<Instant>,
}

impl TapeHandle {
    /// Play from `t_s` seconds (ramping in; a crossfade from the old position if already
    /// playing).
    pub fn play_from(&mut self, t_s: f64) {
        let t_s = t_s.max(0.0);
        self.playing = true;
        self.asked(t_s, Some(Instant::now()));
        self.send(Command::Play(t_s));
    }

    /// Pause (ramping out over [`FADE_S`], after which the position stops).
    pub fn pause(&mut self) {
        let at = self.position_s();
        self.playing = false;
        self.asked(at, None);
        self.send(Command::Pause);
    }

    /// Move to `t_s` seconds, playing or not (a crossfade when playing).
    pub fn seek(&mut self, t_s: f64) {
        let t_s = t_s.max(0.0);
        self.asked(t_s, self.playing.then(Instant::now));
        self.send(Command::Seek(t_s));
    }

    /// Play `source` from now on, at the same position (a crossfade when playing).
    pub fn set_source(&mut self, source: Source) {
        self.send(Command::Swap(source));
    }

    /// Whether the tape was last told to play.
    pub fn is_playing(&self) -> bool {
        self.playing
    }

    /// The position, s: the sound's once it has applied the last play, pause or seek,
    /// else estimated from what that asked and the wall clock since.
    pub fn position_s(&self) -> f64 {
        if self.shared.applied.load(Ordering::Acquire) >= self.moved_seq {
            f64::from_bits(self.shared.position.load(Ordering::Relaxed))
        } else {
            self.asked_s + self.asked_at.map_or(0.0, |t| t.elapsed().as_secs_f64())
        }
    }

    /// The output frames the audio thread has processed so far (paused or not): it stops
    /// counting when the device stops asking for audio.
    pub fn frames_processed(&self) -> u64 {
        self.shared.frames.load(Ordering::Relaxed)
    }

    /// Drop the sources the audio thread has let go of, and send commands that did not
    /// fit in the ring before.
    pub fn collect(&mut self) {
        while let Ok(source) = self.returns.pop() {
            drop(source);
        }
        while let Some(c) = self.backlog.pop_front() {
            if let Err(PushError::Full(c)) = self.commands.push(c) {
                self.backlog.push_front(c);
                break;
            }
        }
    }

    fn asked(&mut self, t_s: f64, at: Option<Instant>) {
        self.moved_seq = self.seq + 1;
        self.asked_s = t_s;
        self.asked_at = at;
    }

    fn send(&mut self, command: Command) {
        self.collect();
        self.seq += 1;
        self.backlog.push_back(Sequenced {
            seq: self.seq,
            command,
        });
        self.collect();
    }
}

impl Drop for TapeHandle {
    fn drop(&mut self) {
        self.shared.handle_alive.store(false, Ordering::Release);
        while let Ok(source) = self.returns.pop() {
            drop(source);
        }
    }
}

/// A source and a position in it.
#[derive(Default)]
struct Voice {
    source: Option<Source>,
    /// Position, source frames.
    pos: f64,
}

impl Voice {
    /// The frame at `pos`, interpolated linearly; silence past the end.
    fn sample(&self) -> Frame {
        let Some(source) = &self.source else {
            return Frame::ZERO;
        };
        let at = |i: usize| match source.frame(i) {
            Some([l, r]) => Frame::new(l, r),
            None => Frame::ZERO,
        };
        let i = self.pos.floor();
        let f = (self.pos - i) as f32;
        let i = i as usize;
        if f == 0.0 {
            at(i)
        } else {
            at(i) * (1.0 - f) + at(i + 1) * f
        }
    }
}

/// The tape on the audio thread.
struct TapeSound {
    commands: Consumer<Sequenced>,
    returns: Producer<Source>,
    shared: Arc<Shared>,
    /// What plays (fading in while `fading` fades out).
    now: Voice,
    /// What a swap or a seek left, fading out; kept (silent) until it can be returned.
    fading: Option<Voice>,
    /// The gain of `now` against `fading`, 0 to 1.
    mix: f64,
    /// The output gain, ramping towards 1 when playing and 0 when paused.
    level: f64,
    playing: bool,
    /// The `seq` of the last command applied.
    applied: u64,
}

/// Ramps closer than this to their end are taken as finished (rounding).
const RAMP_EPS: f64 = 1e-9;

impl TapeSound {
    /// Apply the waiting commands, while no crossfade runs and a source can be returned.
    fn take_commands(&mut self) {
        while self.fading.is_none() && self.returns.slots() > 0 {
            let Ok(c) = self.commands.pop() else {
                break;
            };
            self.apply(c.command);
            self.applied = c.seq;
        }
    }

    fn apply(&mut self, command: Command) {
        match command {
            Command::Play(t_s) => {
                self.move_to(t_s);
                self.playing = true;
            }
            Command::Pause => self.playing = false,
            Command::Seek(t_s) => self.move_to(t_s),
            Command::Swap(source) => {
                if self.level > 0.0 {
                    let pos = self.now.pos;
                    self.crossfade_to(Voice {
                        source: Some(source),
                        pos,
                    });
                } else if let Some(old) = self.now.source.replace(source) {
                    // `take_commands` made sure there is room.
                    self.give_back(old);
                }
            }
        }
    }

    fn move_to(&mut self, t_s: f64) {
        let pos = t_s.max(0.0) * f64::from(SOURCE_RATE_HZ);
        if self.level > 0.0 {
            let source = self.now.source.clone();
            self.crossfade_to(Voice { source, pos });
        } else {
            self.now.pos = pos;
        }
    }

    fn crossfade_to(&mut self, voice: Voice) {
        self.fading = Some(std::mem::replace(&mut self.now, voice));
        self.mix = 0.0;
    }

    /// Return the faded-out voice's source if there is room (else try again next frame).
    fn retire_fading(&mut self) {
        let Some(voice) = self.fading.take() else {
            return;
        };
        if let Some(source) = voice.source
            && let Err(PushError::Full(source)) = self.returns.push(source)
        {
            self.fading = Some(Voice {
                source: Some(source),
                pos: voice.pos,
            });
        }
    }

    fn give_back(&mut self, source: Source) {
        if let Err(PushError::Full(source)) = self.returns.push(source) {
            // Not reached (see `take_commands`); never free on the audio thread.
            std::mem::forget(source);
        }
    }
}

impl Sound for TapeSound {
    fn process(&mut self, out: &mut [Frame], dt: f64, _info: &Info) {
        let mut step = dt * f64::from(SOURCE_RATE_HZ);
        if (step - 1.0).abs() < RAMP_EPS {
            step = 1.0;
        }
        let ramp = (dt / FADE_S).min(1.0);
        self.shared
            .frames
            .fetch_add(out.len() as u64, Ordering::Relaxed);
        for frame in out {
            if self.fading.is_none() {
                self.take_commands();
            }
            let mut f = self.now.sample();
            if let Some(old) = &self.fading {
                let m = self.mix as f32;
                f = old.sample() * (1.0 - m) + f * m;
            }
            *frame = f * self.level as f32;
            if self.playing || self.level > 0.0 {
                self.now.pos += step;
                if let Some(old) = &mut self.fading {
                    old.pos += step;
                }
            }
            self.level = if self.playing {
                let l = self.level + ramp;
                if l >= 1.0 - RAMP_EPS { 1.0 } else { l }
            } else {
                let l = self.level - ramp;
                if l <= RAMP_EPS { 0.0 } else { l }
            };
            if self.fading.is_some() {
                self.mix += ramp;
                if self.mix >= 1.0 - RAMP_EPS {
                    self.mix = 1.0;
                    self.retire_fading();
                }
            }
        }
        if self.fading.is_none() {
            self.take_commands();
        }
        let t_s = self.now.pos / f64::from(SOURCE_RATE_HZ);
        self.shared.position.store(t_s.to_bits(), Ordering::Relaxed);
        self.shared.applied.store(self.applied, Ordering::Release);
    }

    fn finished(&self) -> bool {
        !self.shared.handle_alive.load(Ordering::Acquire)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use kira::info::MockInfoBuilder;

    const DT: f64 = 1.0 / 48_000.0;
    /// Frames per fade at 48 kHz.
    const FADE: usize = 240;

    fn tape() -> (Box<dyn Sound>, TapeHandle) {
        let Ok(pair) = TapeData::new().into_sound();
        pair
    }

    /// `n` frames of output at `dt`.
    fn run(sound: &mut dyn Sound, n: usize, dt: f64) -> Vec<Frame> {
        let info = MockInfoBuilder::new().build();
        let mut out = vec![Frame::new(f32::NAN, f32::NAN); n];
        // In blocks, as a device asks.
        for block in out.chunks_mut(128) {
            sound.process(block, dt, &info);
        }
        out
    }

    /// Left = frame index / 1e5 and right = −left: each frame tells where it came from.
    fn ramp_source(frames: usize) -> Arc<Vec<f32>> {
        Arc::new(
            (0..frames)
                .flat_map(|i| [i as f32 * 1e-5, -(i as f32) * 1e-5])
                .collect(),
        )
    }

    fn constant(value: f32, frames: usize) -> Arc<Vec<f32>> {
        Arc::new(vec![value; 2 * frames])
    }

    fn max_jump(out: &[Frame]) -> f32 {
        out.windows(2)
            .map(|w| (w[1].left - w[0].left).abs())
            .fold(0.0, f32::max)
    }

    /// At a 48 kHz output the source comes out frame for frame from the asked position:
    /// ramped in over the first 5 ms, then sample-exact; the position is published.
    #[test]
    fn plays_the_source_sample_exact() {
        let (mut sound, mut h) = tape();
        h.set_source(ramp_source(48_000));
        h.play_from(0.25);
        let out = run(sound.as_mut(), 4800, DT);
        let first = 12_000;
        for (k, f) in out.iter().enumerate() {
            let want = (first + k) as f32 * 1e-5;
            if k >= FADE {
                assert_eq!((f.left, f.right), (want, -want), "frame {k}");
            } else {
                let gain = k as f32 / FADE as f32;
                assert!((f.left - want * gain).abs() < 1e-6, "frame {k}: {}", f.left);
            }
        }
        assert!((h.position_s() - 0.35).abs() < 1e-12, "{}", h.position_s());
        assert!(h.is_playing());
    }

    /// A swap while playing keeps the position and crossfades: between two different
    /// constant signals no step is larger than 1/240 of their difference, and after
    /// 5 ms only the new one plays.
    #[test]
    fn swap_crossfades_and_keeps_the_position() {
        let (mut sound, mut h) = tape();
        h.set_source(constant(0.5, 96_000));
        h.play_from(0.0);
        run(sound.as_mut(), 1000, DT);
        let before = h.position_s();
        assert!((before - 1000.0 / 48_000.0).abs() < 1e-12);
        h.set_source(constant(-0.3, 96_000));
        let out = run(sound.as_mut(), 1000, DT);
        assert_eq!(out[0].left, 0.5, "the swap starts from the old audio");
        let bound = 0.8 / FADE as f32 + 1e-6;
        assert!(max_jump(&out) <= bound, "{} > {bound}", max_jump(&out));
        assert!(
            out[FADE + 1..]
                .iter()
                .all(|f| f.left == -0.3 && f.right == -0.3)
        );
        assert!((h.position_s() - before - 1000.0 / 48_000.0).abs() < 1e-12);
    }

    /// Pause ramps the level to silence over 5 ms (no step larger than 1/240 of the
    /// signal), and then the position stops; play ramps back in from there.
    #[test]
    fn pause_ramps_to_silence_and_stops() {
        let (mut sound, mut h) = tape();
        h.set_source(constant(0.8, 96_000));
        h.play_from(0.0);
        let out = run(sound.as_mut(), 1000, DT);
        assert_eq!(out[999].left, 0.8);
        h.pause();
        assert!(!h.is_playing());
        let out = run(sound.as_mut(), 1000, DT);
        assert!(max_jump(&out) <= 0.8 / FADE as f32 + 1e-6);
        assert!(out[FADE..].iter().all(|f| f.left == 0.0 && f.right == 0.0));
        let held = h.position_s();
        let ramp_out = held * 48_000.0 - 1000.0;
        assert!(
            (FADE as f64 - 1.0..=FADE as f64 + 1.0).contains(&ramp_out),
            "{ramp_out}"
        );
        run(sound.as_mut(), 4800, DT);
        assert_eq!(
            h.position_s(),
            held,
            "paused and silent: the position holds"
        );
        h.play_from(held);
        let out = run(sound.as_mut(), 1000, DT);
        assert_eq!(out[0].left, 0.0);
        assert!(max_jump(&out) <= 0.8 / FADE as f32 + 1e-6);
        assert_eq!(out[999].left, 0.8);
    }

    /// A seek while playing crossfades from the old position to the new one (no click
    /// between two different constant parts) and the position is the new one at once.
    #[test]
    fn seek_while_playing_crossfades() {
        let (mut sound, mut h) = tape();
        let mut two = vec![0.6f32; 2 * 48_000];
        two.extend(vec![-0.6f32; 2 * 48_000]);
        h.set_source(Arc::new(two));
        h.play_from(0.1);
        run(sound.as_mut(), 1000, DT);
        h.seek(1.5);
        let asked = h.position_s();
        assert!(
            (1.5..1.6).contains(&asked),
            "asked, not yet applied: {asked}"
        );
        let out = run(sound.as_mut(), 1000, DT);
        assert!(max_jump(&out) <= 1.2 / FADE as f32 + 1e-6);
        assert_eq!(out[999].left, -0.6);
        assert!((h.position_s() - (1.5 + 1000.0 / 48_000.0)).abs() < 1e-12);
    }

    /// At a 44.1 kHz output each frame advances 48000/44100 source frames, interpolated
    /// linearly, and a second of output is a second of position.
    #[test]
    fn resamples_to_the_output_rate() {
        let (mut sound, mut h) = tape();
        h.set_source(ramp_source(96_000));
        h.play_from(0.0);
        let out = run(sound.as_mut(), 44_100, 1.0 / 44_100.0);
        assert!((h.position_s() - 1.0).abs() < 1e-9, "{}", h.position_s());
        for k in [300, 1234, 44_099] {
            let want = (k as f64 * 48_000.0 / 44_100.0 * 1e-5) as f32;
            assert!((out[k].left - want).abs() < 1e-6, "{k}: {}", out[k].left);
            assert!((out[k].right + want).abs() < 1e-6);
        }
    }

    /// Past the end of the source the tape is silent and the clock keeps running; with
    /// no source at all, too.
    #[test]
    fn past_the_end_is_silence_and_time_runs() {
        let (mut sound, mut h) = tape();
        h.play_from(0.0);
        let out = run(sound.as_mut(), 500, DT);
        assert!(out.iter().all(|f| f.left == 0.0 && f.right == 0.0));
        h.set_source(constant(0.5, 300));
        let out = run(sound.as_mut(), 1000, DT);
        assert!(out.iter().all(|f| f.left == 0.0), "the source ends at 300");
        h.play_from(0.0);
        let out = run(sound.as_mut(), 1000, DT);
        assert_eq!(out[299].left, 0.5);
        assert!(out[301..].iter().all(|f| f.left == 0.0 && f.right == 0.0));
        assert!((h.position_s() - 1000.0 / 48_000.0).abs() < 1e-12);
    }

    /// Replaced sources come back to the handle and are dropped there, on its next call:
    /// after `process` the audio thread holds no reference, the return ring does.
    #[test]
    fn replaced_sources_are_returned_not_dropped() {
        let (mut sound, mut h) = tape();
        let a = constant(0.1, 48_000);
        let b = constant(0.2, 48_000);
        let c = constant(0.3, 48_000);
        h.set_source(a.clone());
        run(sound.as_mut(), 10, DT);
        // Paused: the swap is immediate.
        h.set_source(b.clone());
        run(sound.as_mut(), 10, DT);
        assert_eq!(Arc::strong_count(&a), 2, "in the return ring");
        h.play_from(0.0);
        assert_eq!(Arc::strong_count(&a), 1, "dropped by the handle");
        run(sound.as_mut(), 1000, DT);
        // Playing: a crossfade, after which `b` is returned.
        h.set_source(c.clone());
        run(sound.as_mut(), 100, DT);
        assert_eq!(Arc::strong_count(&b), 2, "still fading out");
        run(sound.as_mut(), 1000, DT);
        assert_eq!(Arc::strong_count(&b), 2, "returned, not dropped");
        h.collect();
        assert_eq!(Arc::strong_count(&b), 1);
        assert_eq!(Arc::strong_count(&c), 2, "playing");
        assert!(!sound.finished());
        drop(h);
        assert!(sound.finished());
    }

    /// Many swaps while playing, more than the return ring holds, with the handle not
    /// called in between: the sound waits for room instead of dropping anything (every
    /// source is still held somewhere), and once the handle collects, the swaps go on,
    /// each a crossfade, until the last source plays.
    #[test]
    fn a_full_return_ring_holds_commands_back() {
        let (mut sound, mut h) = tape();
        let sources: Vec<_> = (0..40).map(|i| constant(i as f32 * 0.01, 48_000)).collect();
        h.play_from(0.0);
        run(sound.as_mut(), 300, DT);
        for s in &sources {
            h.set_source(s.clone());
        }
        let mut out = run(sound.as_mut(), 6000, DT);
        assert!(
            sources.iter().all(|s| Arc::strong_count(s) == 2),
            "nothing was dropped in process"
        );
        assert_eq!(out.last().unwrap().left, 0.16, "stuck at the 17th");
        for _ in 0..3 {
            h.collect();
            out.extend(run(sound.as_mut(), 6000, DT));
        }
        h.collect();
        assert!(max_jump(&out) <= 0.01 / FADE as f32 + 1e-6);
        assert_eq!(out.last().unwrap().left, 0.39);
        for s in &sources[..39] {
            assert_eq!(Arc::strong_count(s), 1);
        }
        assert_eq!(Arc::strong_count(&sources[39]), 2);
    }

    /// Through a real audio manager (kira's mock backend at 48 kHz): the tape is accepted
    /// as a sound, processed, and its position read back.
    #[test]
    fn plays_through_an_audio_manager() {
        use kira::backend::mock::{MockBackend, MockBackendSettings};
        use kira::{AudioManager, AudioManagerSettings};
        let mut manager = AudioManager::<MockBackend>::new(AudioManagerSettings {
            backend_settings: MockBackendSettings {
                sample_rate: 48_000,
            },
            ..AudioManagerSettings::default()
        })
        .unwrap();
        let mut h = manager.play(TapeData::new()).unwrap();
        h.set_source(constant(0.5, 48_000));
        h.play_from(0.5);
        for _ in 0..10 {
            manager.backend_mut().on_start_processing();
            manager.backend_mut().process();
        }
        let t = h.position_s();
        assert!(t > 0.5 && t < 0.6, "{t}");
    }

    /// The heartbeat counts every frame asked for, paused or playing, and only those.
    #[test]
    fn the_heartbeat_counts_frames_asked_for() {
        let (mut sound, mut h) = tape();
        assert_eq!(h.frames_processed(), 0);
        run(sound.as_mut(), 1000, DT);
        assert_eq!(h.frames_processed(), 1000);
        h.set_source(constant(0.5, 48_000));
        h.play_from(0.0);
        run(sound.as_mut(), 500, DT);
        assert_eq!(h.frames_processed(), 1500);
        assert_eq!(h.frames_processed(), 1500, "no frames asked, no beats");
    }
}
