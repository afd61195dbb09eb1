//! The playback clock: plays the rendered audio through kira when a sound device exists,
//! and otherwise runs a silent clock on `std::time::Instant` (with a notice for the
//! window). The playhead, the 3D view and the plots read [`Playback::position_s`].
//! With no audio set, the clock still runs (the render pipeline supplies audio later via
//! [`Playback::set_audio`]).

use kira::sound::PlaybackState;
use kira::sound::static_sound::{StaticSoundData, StaticSoundHandle, StaticSoundSettings};
use kira::{AudioManager, AudioManagerSettings, DefaultBackend, Frame, Tween};
use std::sync::Arc;
use std::time::Instant;

/// Sample rate of the audio given to [`Playback::set_audio`], Hz.
pub const AUDIO_RATE_HZ: u32 = 48_000;

/// The notice shown when there is no sound device.
pub const SILENT_NOTICE: &str = "No sound device: silent playback";

/// Errors of the playback module.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PlaybackError {
    /// Interleaved stereo audio must have an even number of samples.
    #[error("stereo audio needs an even number of samples, got {0}")]
    OddSampleCount(usize),
}

/// Stereo interleaved samples at [`AUDIO_RATE_HZ`] as playback frames.
pub fn frames_of(interleaved: &[f32]) -> Result<Arc<[Frame]>, PlaybackError> {
    if !interleaved.len().is_multiple_of(2) {
        return Err(PlaybackError::OddSampleCount(interleaved.len()));
    }
    Ok(interleaved
        .chunks_exact(2)
        .map(|c| Frame {
            left: c[0],
            right: c[1],
        })
        .collect())
}

/// The playback clock and, when a device exists, the audio output.
pub struct Playback {
    manager: Option<AudioManager<DefaultBackend>>,
    notice: Option<String>,
    audio: Option<StaticSoundData>,
    sound: Option<StaticSoundHandle>,
    /// Position when the clock last started or stopped, s.
    anchor_s: f64,
    /// When the clock last started; `None` when paused.
    started: Option<Instant>,
}

impl Playback {
    /// Open the default sound device, or fall back to a silent clock if there is none.
    pub fn new() -> Playback {
        match AudioManager::<DefaultBackend>::new(AudioManagerSettings::default()) {
            Ok(manager) => Playback {
                manager: Some(manager),
                ..Playback::silent()
            },
            Err(e) => {
                let mut p = Playback::silent();
                p.notice = Some(format!("{SILENT_NOTICE} ({e})"));
                p
            }
        }
    }

    /// A silent clock without trying any device.
    pub fn silent() -> Playback {
        Playback {
            manager: None,
            notice: Some(SILENT_NOTICE.to_string()),
            audio: None,
            sound: None,
            anchor_s: 0.0,
            started: None,
        }
    }

    /// Why playback is silent, if it is.
    pub fn notice(&self) -> Option<&str> {
        self.notice.as_deref()
    }

    /// Whether a sound device is in use.
    pub fn has_device(&self) -> bool {
        self.manager.is_some()
    }

    /// Whether audio has been set.
    pub fn has_audio(&self) -> bool {
        self.audio.is_some()
    }

    /// Set the audio to play (stereo interleaved samples at [`AUDIO_RATE_HZ`]); if
    /// playing, it continues from the current position with the new audio.
    pub fn set_audio(&mut self, interleaved: &[f32]) -> Result<(), PlaybackError> {
        self.set_frames(frames_of(interleaved)?);
        Ok(())
    }

    /// [`set_audio`](Playback::set_audio) with the frames already made (e.g. on a worker
    /// thread, sparing the UI thread the copy).
    pub fn set_frames(&mut self, frames: Arc<[Frame]>) {
        self.audio = Some(StaticSoundData {
            sample_rate: AUDIO_RATE_HZ,
            frames,
            settings: StaticSoundSettings::default(),
            slice: None,
        });
        if self.is_playing() {
            let at = self.position_s();
            self.play_from(at);
        }
    }

    /// Start playing at `t_s` seconds.
    pub fn play_from(&mut self, t_s: f64) {
        self.stop_sound();
        self.anchor_s = t_s.max(0.0);
        self.started = Some(Instant::now());
        if let (Some(manager), Some(audio)) = (&mut self.manager, &self.audio) {
            let data = audio.start_position(self.anchor_s);
            match manager.play(data) {
                Ok(handle) => self.sound = Some(handle),
                Err(e) => self.notice = Some(format!("could not play the audio: {e}")),
            }
        }
    }

    /// Stop at the current position.
    pub fn pause(&mut self) {
        self.anchor_s = self.position_s();
        self.started = None;
        self.stop_sound();
    }

    /// Move the clock to `t_s`, keeping it playing or paused.
    pub fn seek(&mut self, t_s: f64) {
        if self.is_playing() {
            self.play_from(t_s);
        } else {
            self.anchor_s = t_s.max(0.0);
        }
    }

    /// Whether the clock runs.
    pub fn is_playing(&self) -> bool {
        self.started.is_some()
    }

    /// The current position, s: the audio's while it plays, else the wall clock's.
    pub fn position_s(&self) -> f64 {
        if let Some(sound) = &self.sound
            && matches!(sound.state(), PlaybackState::Playing)
        {
            return sound.position();
        }
        match self.started {
            Some(t0) => self.anchor_s + t0.elapsed().as_secs_f64(),
            None => self.anchor_s,
        }
    }

    fn stop_sound(&mut self) {
        if let Some(mut s) = self.sound.take() {
            s.stop(Tween::default());
        }
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

    /// Opening the default device never fails: with no sound card (as on the build
    /// machines) it falls back to the silent clock and says so, and the clock still runs
    /// with audio set.
    #[test]
    fn no_device_falls_back_to_silence() {
        let mut p = Playback::new();
        if !p.has_device() {
            assert!(p.notice().unwrap().starts_with(SILENT_NOTICE));
        }
        p.set_audio(&vec![0.0; 2 * 4800]).unwrap();
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
            p.set_audio(&[0.0; 3]),
            Err(PlaybackError::OddSampleCount(3))
        ));
    }
}
