//! The playback clock: plays the rendered audio through kira when a sound device exists,
//! and otherwise runs a silent clock on `std::time::Instant` (with a notice for the
//! window). The playhead, the 3D view and the plots read [`Playback::position_s`].
//! With no audio set, the clock still runs (the render pipeline supplies audio later via
//! [`Playback::set_audio`]).
//!
//! With a device, one [tape](super::tape) sound is played for the whole session and
//! controlled through its handle: new audio is swapped in under the playhead without
//! restarting (a 5 ms crossfade), and play, pause and seek ramp over 5 ms.
//!
//! Slow motion ([`Playback::set_speed`] below 1): the clock runs on the wall clock
//! scaled by the speed and the tape stays paused — the mix cannot be heard slowed down
//! in sync, so it is muted, and each contact the playhead passes is played at full speed
//! instead ([`Playback::play_once`], `super::strike_sounds`; [`SLOW_MOTION_NOTICE`] says
//! so).
//!
//! A device that goes away while in use ([`Playback::check_device`], once per frame):
//! when the tape has not been asked for audio for [`STALL`](super::device_watch::STALL)
//! the silent clock takes over from where the sound stopped (the playhead keeps running)
//! with [`LOST_NOTICE`]; a background thread then tries to open the device again every
//! second, and once a new stream runs, the tape goes on on it from the clock's position
//! with the same audio. Nothing on the UI thread waits for a device.

use super::device_watch::{Retry, Stall};
use super::output::Output;
use super::tape::{Source, StereoSource, TapeHandle};
use std::sync::Arc;
use std::sync::mpsc::{Receiver, TryRecvError};
use std::time::Instant;

/// Sample rate of the audio given to [`Playback::set_audio`], Hz.
pub const AUDIO_RATE_HZ: u32 = super::tape::SOURCE_RATE_HZ;

/// The notice shown when there is no sound device.
pub const SILENT_NOTICE: &str = "No sound device: silent playback";

/// The start of the notice shown while the device in use has gone.
pub const LOST_NOTICE: &str = "Sound device lost: silent playback";

/// The notice shown while playing slower than real time.
pub const SLOW_MOTION_NOTICE: &str =
    "slow motion: the mix is muted, each strike sounds as it passes";

/// The playback speeds offered, fastest first (1 = real time).
pub const SPEEDS: [f64; 4] = [1.0, 0.5, 0.25, 0.1];

/// Errors of the playback module.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PlaybackError {
    /// Interleaved stereo audio must have an even number of samples.
    #[error("stereo audio needs an even number of samples, got {0}")]
    OddSampleCount(usize),
}

/// What happened to the device, for the status bar.
#[derive(Clone, Debug, PartialEq)]
pub enum DeviceEvent {
    /// The device in use went away (the notice says why): playback is silent.
    Lost(String),
    /// It is back: playback sounds again.
    Back,
}

impl DeviceEvent {
    /// A line for the status bar.
    pub fn message(&self) -> String {
        match self {
            DeviceEvent::Lost(_) => "sound device lost: playing silently until it returns".into(),
            DeviceEvent::Back => "sound device back: playing on it again".into(),
        }
    }
}

/// Opens the device again (on a background thread).
type Opener = Arc<dyn Fn() -> Result<Output, String> + Send + Sync>;

/// Finding the device again after it went.
struct Recovery {
    opener: Opener,
    retry: Retry,
    /// The attempt in flight.
    attempt: Option<Receiver<Result<Output, String>>>,
    /// An output that opened, kept until its stream runs (or stalls and is dropped).
    candidate: Option<(Output, Stall)>,
}

/// The playback clock and, when a device exists, the audio output.
pub struct Playback {
    /// The device with the tape on it (`None` without one).
    output: Option<Output>,
    /// Watches the output's heartbeat.
    stall: Option<Stall>,
    /// How to open the device again if it goes (`None` for the silent clock).
    opener: Option<Opener>,
    /// Set while the device has gone.
    recovery: Option<Recovery>,
    notice: Option<String>,
    /// The audio set, kept to give a reopened device.
    source: Option<Source>,
    /// Position when the clock last started or stopped, s.
    anchor_s: f64,
    /// When the clock last started; `None` when paused.
    started: Option<Instant>,
    /// Score seconds per wall-clock second (1: real time, with sound).
    speed: f64,
    /// Sounds given to [`Playback::play_once`] (played or, silent, only counted).
    played_once: usize,
}

impl Playback {
    /// Open the default sound device and start the tape on it (paused), or fall back to a
    /// silent clock if there is no device.
    pub fn new() -> Playback {
        Playback::open(None, None)
    }

    /// Open the output device named `device` (the default one when `None`, or when no
    /// device has that name any more, with a notice) with `buffer_frames` frames per
    /// buffer (the device's choice when `None`), and start the tape on it (paused); a
    /// silent clock if no device opens. Should the device go later, the same is opened
    /// again when it returns.
    pub fn open(device: Option<&str>, buffer_frames: Option<u32>) -> Playback {
        match Output::open(device, buffer_frames) {
            Ok((output, missing)) => {
                let notice = missing.map(|name| {
                    format!("audio device \"{name}\" not found: playing on the default device")
                });
                let device = device.map(str::to_string);
                let opener: Opener = Arc::new(move || {
                    Output::open(device.as_deref(), buffer_frames).map(|(output, _)| output)
                });
                Playback::on_output(output, notice, opener)
            }
            Err(e) => Playback {
                notice: Some(format!("{SILENT_NOTICE} ({e})")),
                ..Playback::silent()
            },
        }
    }

    /// Playback on `output`, showing `notice`, reopening with `opener` if it goes.
    fn on_output(output: Output, notice: Option<String>, opener: Opener) -> Playback {
        Playback {
            stall: Some(Stall::new(output.tape.frames_processed(), Instant::now())),
            output: Some(output),
            opener: Some(opener),
            notice,
            ..Playback::silent()
        }
    }

    /// A silent clock without trying any device.
    pub fn silent() -> Playback {
        Playback {
            output: None,
            stall: None,
            opener: None,
            recovery: None,
            notice: Some(SILENT_NOTICE.to_string()),
            source: None,
            anchor_s: 0.0,
            started: None,
            speed: 1.0,
            played_once: 0,
        }
    }

    /// Play `frames` (stereo at [`AUDIO_RATE_HZ`]) once on the device, over whatever the
    /// tape does (slow motion's strikes); counted, and only counted on the silent clock.
    pub fn play_once(&mut self, frames: &[[f32; 2]]) {
        self.played_once += 1;
        if let Some(output) = &mut self.output {
            output.play_once(frames, AUDIO_RATE_HZ);
        }
    }

    /// How many sounds [`Playback::play_once`] was given.
    pub fn played_once(&self) -> usize {
        self.played_once
    }

    /// Why playback is silent, if it is.
    pub fn notice(&self) -> Option<&str> {
        self.notice.as_deref()
    }

    /// Whether a sound device is in use.
    pub fn has_device(&self) -> bool {
        self.output.is_some()
    }

    /// Whether the device in use has been asked for audio for about a second since it
    /// opened (a stream that has just opened may wait before it runs; see
    /// [`device_watch`](super::device_watch)). Read by [`check_device`](Self::check_device).
    pub fn device_runs(&self) -> bool {
        self.stall.as_ref().is_some_and(Stall::is_running)
    }

    /// Whether the device in use went away and is being looked for.
    pub fn is_recovering(&self) -> bool {
        self.recovery.is_some()
    }

    /// Whether audio has been set.
    pub fn has_audio(&self) -> bool {
        self.source.is_some()
    }

    fn tape(&mut self) -> Option<&mut TapeHandle> {
        self.output.as_mut().map(|o| &mut o.tape)
    }

    /// Set the audio to play (stereo interleaved samples at [`AUDIO_RATE_HZ`], shared, not
    /// copied); if playing, it goes on from the current position with the new audio,
    /// crossfaded over 5 ms. The audio replaced is dropped on a later call, on this
    /// thread.
    pub fn set_audio(&mut self, audio: Arc<dyn StereoSource>) -> Result<(), PlaybackError> {
        let n = audio.sample_count();
        if !n.is_multiple_of(2) {
            return Err(PlaybackError::OddSampleCount(n));
        }
        if let Some(tape) = self.tape() {
            tape.set_source(Arc::clone(&audio));
        }
        self.source = Some(audio);
        Ok(())
    }

    /// Start playing at `t_s` seconds (the tape only at real time).
    pub fn play_from(&mut self, t_s: f64) {
        self.anchor_s = t_s.max(0.0);
        self.started = Some(Instant::now());
        let (real_time, at) = (self.is_real_time(), self.anchor_s);
        if let Some(tape) = self.tape() {
            if real_time {
                tape.play_from(at);
            } else {
                tape.pause();
                tape.seek(at);
            }
        }
    }

    /// Score seconds per wall-clock second.
    pub fn speed(&self) -> f64 {
        self.speed
    }

    /// Whether the clock runs at real time (and the audio is heard).
    pub fn is_real_time(&self) -> bool {
        self.speed == 1.0
    }

    /// Play at `speed` (clamped to 0.01–1) from where the clock is now, playing or
    /// paused; below 1 the audio is muted.
    pub fn set_speed(&mut self, speed: f64) {
        let at = self.position_s();
        self.speed = speed.clamp(0.01, 1.0);
        if self.is_playing() {
            self.play_from(at);
        }
    }

    /// Stop at the current position.
    pub fn pause(&mut self) {
        self.anchor_s = self.position_s();
        self.started = None;
        if let Some(tape) = self.tape() {
            tape.pause();
        }
    }

    /// Move the clock to `t_s`, keeping it playing or paused.
    pub fn seek(&mut self, t_s: f64) {
        if self.is_playing() {
            self.play_from(t_s);
        } else {
            self.anchor_s = t_s.max(0.0);
            let at = self.anchor_s;
            if let Some(tape) = self.tape() {
                tape.seek(at);
            }
        }
    }

    /// Whether the clock runs.
    pub fn is_playing(&self) -> bool {
        self.started.is_some()
    }

    /// The current position, s: the tape's while it plays on a device at real time,
    /// else the wall clock's times the speed.
    pub fn position_s(&self) -> f64 {
        match (self.started, &self.output) {
            (Some(_), Some(output)) if self.is_real_time() => output.tape.position_s(),
            (Some(t0), _) => self.anchor_s + t0.elapsed().as_secs_f64() * self.speed,
            (None, _) => self.anchor_s,
        }
    }

    /// Watch the device (call once per frame, and about once a second when idle): take
    /// the silent clock when it has gone, look for it again while it is gone, and go back
    /// to it when it has returned. What changed, if anything. Never waits.
    pub fn check_device(&mut self) -> Option<DeviceEvent> {
        let now = Instant::now();
        if let (Some(output), Some(stall)) = (&mut self.output, &mut self.stall) {
            let alive_at = stall.observe(output.tape.frames_processed(), now)?;
            let reason = output
                .last_error()
                .unwrap_or_else(|| "the device stopped asking for audio".into());
            return Some(self.lose(alive_at, &reason));
        }
        let recovery = self.recovery.as_mut()?;
        if let Some((output, stall)) = &mut recovery.candidate {
            let stalled = stall.observe(output.tape.frames_processed(), now);
            if stall.has_moved() {
                let (output, ..) = recovery.candidate.take()?;
                self.resume(output, now);
                return Some(DeviceEvent::Back);
            }
            if stalled.is_some() {
                // It opened but never ran: let it go (off this thread) and try again.
                let (dead, ..) = recovery.candidate.take()?;
                std::thread::spawn(move || drop(dead));
            }
            return None;
        }
        if let Some(rx) = &recovery.attempt {
            match rx.try_recv() {
                Ok(Ok(output)) => {
                    let stall = Stall::new(output.tape.frames_processed(), now);
                    recovery.candidate = Some((output, stall));
                    recovery.attempt = None;
                    return None;
                }
                Ok(Err(_)) | Err(TryRecvError::Disconnected) => recovery.attempt = None,
                Err(TryRecvError::Empty) => return None,
            }
        }
        if recovery.retry.due(now) {
            let (tx, rx) = std::sync::mpsc::channel();
            let opener = Arc::clone(&recovery.opener);
            std::thread::spawn(move || {
                // The receiver may be gone (playback dropped): then the output just drops.
                let _ = tx.send(opener());
            });
            recovery.attempt = Some(rx);
        }
        None
    }

    /// The device went (its heartbeat last moved at `alive_at`): the silent clock takes
    /// over from the tape's position then, and recovery starts.
    fn lose(&mut self, alive_at: Instant, reason: &str) -> DeviceEvent {
        let Some(output) = self.output.take() else {
            return DeviceEvent::Lost(self.notice.clone().unwrap_or_default());
        };
        self.stall = None;
        if self.is_playing() && self.is_real_time() {
            self.anchor_s = output.tape.position_s();
            self.started = Some(alive_at);
        }
        // Dropping kira's manager only flags its stream thread; still, never on this one.
        std::thread::spawn(move || drop(output));
        let notice = format!("{LOST_NOTICE} ({reason}); looking for it every second");
        self.notice = Some(notice.clone());
        self.recovery = self.opener.clone().map(|opener| Recovery {
            opener,
            retry: Retry::default(),
            attempt: None,
            candidate: None,
        });
        DeviceEvent::Lost(notice)
    }

    /// The device is back as `output` (its stream running): give it the audio and go on
    /// from the clock's position.
    fn resume(&mut self, mut output: Output, now: Instant) {
        if let Some(source) = &self.source {
            output.tape.set_source(Arc::clone(source));
        }
        let at = self.position_s();
        if self.is_playing() && self.is_real_time() {
            output.tape.play_from(at);
            self.anchor_s = at;
            self.started = Some(now);
        } else {
            output.tape.seek(at);
        }
        self.stall = Some(Stall::new(output.tape.frames_processed(), now));
        self.output = Some(output);
        self.recovery = None;
        self.notice = None;
    }
}

impl Default for Playback {
    fn default() -> Self {
        Playback::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use kira::Frame;
    use kira::info::MockInfoBuilder;
    use kira::sound::Sound;
    use std::sync::Mutex;
    use std::sync::atomic::{AtomicU32, Ordering};
    use std::sync::mpsc;
    use std::time::Duration;

    /// The silent clock runs from where it was started, pauses, and seeks.
    #[test]
    fn silent_clock_runs_and_pauses() {
        let mut p = Playback::silent();
        assert!(!p.is_playing());
        assert_eq!(p.position_s(), 0.0);
        p.play_from(2.0);
        std::thread::sleep(Duration::from_millis(60));
        let t = p.position_s();
        assert!((2.05..2.5).contains(&t), "{t}");
        p.pause();
        let held = p.position_s();
        std::thread::sleep(Duration::from_millis(20));
        assert_eq!(p.position_s(), held);
        p.seek(1.0);
        assert_eq!(p.position_s(), 1.0);
        assert!(!p.is_playing());
    }

    /// At a quarter speed the clock runs a quarter as fast, and changing the speed while
    /// playing keeps the position.
    #[test]
    fn slow_motion_clock() {
        let mut p = Playback::silent();
        p.set_speed(0.25);
        p.play_from(1.0);
        std::thread::sleep(Duration::from_millis(200));
        let t = p.position_s();
        assert!((1.04..1.1).contains(&t), "{t}");
        p.set_speed(1.0);
        let after = p.position_s();
        assert!(after >= t && after < t + 0.02, "{t} then {after}");
        assert!(p.is_real_time());
        p.set_speed(0.0);
        assert_eq!(p.speed(), 0.01);
    }

    /// Opening the default device never fails: with no sound card (as on the build
    /// machines) it falls back to the silent clock and says so, and the clock still runs
    /// with audio set.
    #[test]
    fn no_device_falls_back_to_silence() {
        let mut p = Playback::new();
        if !p.has_device() {
            assert!(p.notice().unwrap().starts_with(SILENT_NOTICE));
        }
        p.set_audio(Arc::new(vec![0.0; 2 * 4800])).unwrap();
        assert!(p.has_audio());
        p.play_from(0.0);
        assert!(p.is_playing());
        p.pause();
        assert!(p.position_s() >= 0.0);
    }

    /// Audio with an odd number of interleaved samples is refused.
    #[test]
    fn odd_audio_is_refused() {
        let mut p = Playback::silent();
        assert!(matches!(
            p.set_audio(Arc::new(vec![0.0; 3])),
            Err(PlaybackError::OddSampleCount(3))
        ));
    }

    /// 10 ms of output from `sound`, as a 48 kHz device asks; the frames.
    fn ten_ms(sound: &mut dyn Sound) -> Vec<Frame> {
        let mut out = vec![Frame::ZERO; 480];
        sound.process(&mut out, 1.0 / 48_000.0, &MockInfoBuilder::new().build());
        out
    }

    /// Call `check_device` every 20 ms until `done` says yes (at most `limit_s`).
    fn poll_until<T>(
        p: &mut Playback,
        limit_s: f64,
        mut done: impl FnMut(&mut Playback, Option<DeviceEvent>) -> Option<T>,
    ) -> T {
        let t0 = Instant::now();
        loop {
            let event = p.check_device();
            if let Some(v) = done(p, event) {
                return v;
            }
            assert!(
                t0.elapsed().as_secs_f64() < limit_s,
                "nothing after {limit_s} s"
            );
            std::thread::sleep(Duration::from_millis(20));
        }
    }

    /// The device going mid-play, with outputs on no device whose sounds the test plays
    /// by hand: the silent clock takes over from where the sound stopped (the playhead
    /// keeps running) with the notice; the device is looked for once a second, off this
    /// thread; an attempt that fails is let go; one that opens is back once its stream is
    /// asked for audio, gets the audio and plays on from the clock's position, and the
    /// notice goes.
    #[test]
    fn a_lost_device_falls_back_to_the_clock_and_comes_back() {
        let (output, mut sound) = Output::detached();
        let (tx, rx) = mpsc::channel::<Box<dyn Sound>>();
        let tx = Mutex::new(tx);
        let attempts = Arc::new(AtomicU32::new(0));
        let counted = Arc::clone(&attempts);
        let opener: Opener = Arc::new(move || {
            if counted.fetch_add(1, Ordering::SeqCst) == 0 {
                return Err("not there yet".into());
            }
            let (output, sound) = Output::detached();
            tx.lock().unwrap().send(sound).unwrap();
            Ok(output)
        });
        let mut p = Playback::on_output(output, None, opener);
        p.set_audio(Arc::new(vec![0.5; 2 * 48_000 * 20])).unwrap();
        p.play_from(1.0);
        let mut last = Vec::new();
        for _ in 0..120 {
            last = ten_ms(sound.as_mut());
            assert_eq!(p.check_device(), None);
            std::thread::sleep(Duration::from_millis(10));
        }
        assert!(last.iter().all(|f| f.left == 0.5), "the audio plays");
        assert!((p.position_s() - 2.2).abs() < 1e-9, "{}", p.position_s());
        assert!(p.device_runs());

        // The device stops asking for audio.
        let stopped = Instant::now();
        let notice = poll_until(&mut p, 2.0, |_, e| match e {
            Some(DeviceEvent::Lost(n)) => Some(n),
            _ => None,
        });
        let waited = stopped.elapsed().as_secs_f64();
        assert!(notice.starts_with(LOST_NOTICE), "{notice}");
        assert_eq!(p.notice(), Some(notice.as_str()));
        assert!(!p.has_device() && p.is_recovering() && p.is_playing());
        let t = p.position_s();
        assert!(
            t >= 2.2 + waited - 0.01 && t < 2.2 + waited + 0.05,
            "{t} after {waited} s"
        );

        // The first attempt fails; the second opens an output, back once it is asked for
        // audio.
        let mut comes_back = poll_until(&mut p, 3.0, |p, e| {
            assert_eq!(e, None);
            assert!(!p.has_device());
            rx.try_recv().ok()
        });
        assert_eq!(attempts.load(Ordering::SeqCst), 2);
        assert_eq!(p.check_device(), None, "not back until its stream runs");
        ten_ms(comes_back.as_mut());
        let resumed_at = p.position_s();
        assert_eq!(p.check_device(), Some(DeviceEvent::Back));
        assert!(p.has_device() && !p.is_recovering() && p.notice().is_none());
        for _ in 0..10 {
            last = ten_ms(comes_back.as_mut());
        }
        assert!(last.iter().all(|f| f.left == 0.5), "the audio plays again");
        let t = p.position_s();
        assert!(
            (t - (resumed_at + 0.1)).abs() < 0.02,
            "{t} vs {resumed_at} + 0.1"
        );
    }
}
