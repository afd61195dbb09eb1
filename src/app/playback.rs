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
//! in sync, so it is muted (and [`SLOW_MOTION_NOTICE`] says so).

use super::tape::{StereoSource, TapeData, TapeHandle};
use kira::backend::cpal::CpalBackendSettings;
use kira::backend::cpal::cpal::traits::{DeviceTrait, HostTrait};
use kira::backend::cpal::cpal::{self, BufferSize};
use kira::{AudioManager, AudioManagerSettings, DefaultBackend};
use std::sync::Arc;
use std::time::Instant;

/// Sample rate of the audio given to [`Playback::set_audio`], Hz.
pub const AUDIO_RATE_HZ: u32 = super::tape::SOURCE_RATE_HZ;

/// The notice shown when there is no sound device.
pub const SILENT_NOTICE: &str = "No sound device: silent playback";

/// The notice shown while playing slower than real time.
pub const SLOW_MOTION_NOTICE: &str = "slow motion: audio muted";

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

/// The playback clock and, when a device exists, the audio output.
pub struct Playback {
    /// The tape playing on the device (`None` without one).
    tape: Option<TapeHandle>,
    manager: Option<AudioManager<DefaultBackend>>,
    notice: Option<String>,
    has_audio: bool,
    /// Position when the clock last started or stopped, s.
    anchor_s: f64,
    /// When the clock last started; `None` when paused.
    started: Option<Instant>,
    /// Score seconds per wall-clock second (1: real time, with sound).
    speed: f64,
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
    /// silent clock if no device opens.
    pub fn open(device: Option<&str>, buffer_frames: Option<u32>) -> Playback {
        let mut p = Playback::silent();
        let (settings, missing) = backend_settings(device, buffer_frames);
        let settings = AudioManagerSettings {
            backend_settings: settings,
            ..AudioManagerSettings::default()
        };
        match AudioManager::<DefaultBackend>::new(settings) {
            Ok(mut manager) => match manager.play(TapeData::new()) {
                Ok(tape) => {
                    p.tape = Some(tape);
                    p.manager = Some(manager);
                    p.notice = missing.map(|name| {
                        format!("audio device \"{name}\" not found: playing on the default device")
                    });
                }
                Err(e) => p.notice = Some(format!("{SILENT_NOTICE} (could not play: {e})")),
            },
            Err(e) => p.notice = Some(format!("{SILENT_NOTICE} ({e})")),
        }
        p
    }

    /// A silent clock without trying any device.
    pub fn silent() -> Playback {
        Playback {
            tape: None,
            manager: None,
            notice: Some(SILENT_NOTICE.to_string()),
            has_audio: false,
            anchor_s: 0.0,
            started: None,
            speed: 1.0,
        }
    }

    /// Why playback is silent, if it is.
    pub fn notice(&self) -> Option<&str> {
        self.notice.as_deref()
    }

    /// Whether a sound device is in use.
    pub fn has_device(&self) -> bool {
        self.tape.is_some()
    }

    /// Whether audio has been set.
    pub fn has_audio(&self) -> bool {
        self.has_audio
    }

    /// Set the audio to play (stereo interleaved samples at [`AUDIO_RATE_HZ`], shared, not
    /// copied); if playing, it goes on from the current position with the new audio,
    /// crossfaded over 5 ms. The audio replaced is dropped on a later call, on this
    /// thread.
    pub fn set_audio(&mut self, audio: Arc<dyn StereoSource>) -> Result<(), PlaybackError> {
        let n = audio.interleaved().len();
        if !n.is_multiple_of(2) {
            return Err(PlaybackError::OddSampleCount(n));
        }
        if let Some(tape) = &mut self.tape {
            tape.set_source(audio);
        }
        self.has_audio = true;
        Ok(())
    }

    /// Start playing at `t_s` seconds (the tape only at real time).
    pub fn play_from(&mut self, t_s: f64) {
        self.anchor_s = t_s.max(0.0);
        self.started = Some(Instant::now());
        let real_time = self.is_real_time();
        if let Some(tape) = &mut self.tape {
            if real_time {
                tape.play_from(self.anchor_s);
            } else {
                tape.pause();
                tape.seek(self.anchor_s);
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
        if let Some(tape) = &mut self.tape {
            tape.pause();
        }
    }

    /// Move the clock to `t_s`, keeping it playing or paused.
    pub fn seek(&mut self, t_s: f64) {
        if self.is_playing() {
            self.play_from(t_s);
        } else {
            self.anchor_s = t_s.max(0.0);
            if let Some(tape) = &mut self.tape {
                tape.seek(self.anchor_s);
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
        match (self.started, &self.tape) {
            (Some(_), Some(tape)) if self.is_real_time() => tape.position_s(),
            (Some(t0), _) => self.anchor_s + t0.elapsed().as_secs_f64() * self.speed,
            (None, _) => self.anchor_s,
        }
    }
}

impl Default for Playback {
    fn default() -> Self {
        Playback::new()
    }
}

/// The names of the output devices the system has now (listed afresh each call, so a
/// device plugged in or out shows at the next call).
pub fn output_devices() -> Vec<String> {
    let host = cpal::default_host();
    host.output_devices()
        .map(|devices| devices.map(|d| d.to_string()).collect())
        .unwrap_or_default()
}

/// The backend settings for `device` and `buffer_frames`, and the name asked for when no
/// device has it.
fn backend_settings(
    device: Option<&str>,
    buffer_frames: Option<u32>,
) -> (CpalBackendSettings, Option<String>) {
    let host = cpal::default_host();
    let found = device.and_then(|name| host.output_devices().ok()?.find(|d| d.to_string() == name));
    let missing = device.filter(|_| found.is_none()).map(str::to_string);
    let config = buffer_frames.and_then(|frames| {
        let chosen = found.clone().or_else(|| host.default_output_device())?;
        let mut config = chosen.default_output_config().ok()?.config();
        config.buffer_size = BufferSize::Fixed(frames);
        Some(config)
    });
    let settings = CpalBackendSettings {
        device: found,
        config,
    };
    (settings, missing)
}

#[cfg(test)]
mod tests {
    use super::*;
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
}
