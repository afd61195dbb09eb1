//! The sound output: kira's audio manager on a cpal device with the [tape](super::tape)
//! playing on it (paused), as one value that [`playback`](super::playback) keeps while the
//! device works and drops when it goes; the output devices the system lists.

use super::tape::{TapeData, TapeHandle};
use kira::backend::cpal::CpalBackendSettings;
use kira::backend::cpal::cpal::traits::{DeviceTrait, HostTrait};
use kira::backend::cpal::cpal::{self, BufferSize};
use kira::{AudioManager, AudioManagerSettings, DefaultBackend};

/// A device with the tape on it.
pub struct Output {
    /// Keeps the device's stream running (`None` for a [detached](Output::detached)
    /// output, whose sound a test plays by hand).
    manager: Option<AudioManager<DefaultBackend>>,
    pub tape: TapeHandle,
}

impl Output {
    /// Open the output device named `device` (the default one when `None`, or when no
    /// device has that name any more) with `buffer_frames` frames per buffer (the
    /// device's choice when `None`), and start the tape on it, paused. With the output,
    /// the name asked for if no device has it; else why it did not open.
    pub fn open(
        device: Option<&str>,
        buffer_frames: Option<u32>,
    ) -> Result<(Output, Option<String>), String> {
        let (settings, missing) = backend_settings(device, buffer_frames);
        let settings = AudioManagerSettings {
            backend_settings: settings,
            ..AudioManagerSettings::default()
        };
        let mut manager =
            AudioManager::<DefaultBackend>::new(settings).map_err(|e| e.to_string())?;
        let tape = manager
            .play(TapeData::new())
            .map_err(|e| format!("could not play: {e}"))?;
        let output = Output {
            manager: Some(manager),
            tape,
        };
        Ok((output, missing))
    }

    /// An output on no device, and the tape's sound for the caller to play (tests).
    #[cfg(test)]
    pub fn detached() -> (Output, Box<dyn kira::sound::Sound>) {
        use kira::sound::SoundData;
        let Ok((sound, tape)) = TapeData::new().into_sound();
        let output = Output {
            manager: None,
            tape,
        };
        (output, sound)
    }

    /// Play `frames` (stereo at `rate_hz`) once, over the tape; false without a device.
    pub fn play_once(&mut self, frames: &[[f32; 2]], rate_hz: u32) -> bool {
        use kira::Frame;
        use kira::sound::static_sound::{StaticSoundData, StaticSoundSettings};
        let Some(manager) = self.manager.as_mut() else {
            return false;
        };
        let data = StaticSoundData {
            sample_rate: rate_hz,
            frames: frames
                .iter()
                .map(|&[left, right]| Frame { left, right })
                .collect(),
            settings: StaticSoundSettings::default(),
            slice: None,
        };
        manager.play(data).is_ok()
    }

    /// The last stream error the backend reported since the last call (the older ones
    /// are dropped), as text.
    pub fn last_error(&mut self) -> Option<String> {
        let backend = self.manager.as_mut()?.backend_mut();
        std::iter::from_fn(|| backend.pop_error())
            .last()
            .map(|e| e.to_string())
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
