//! WAV output through hound — 16-bit or 24-bit PCM (rounded, not dithered: deterministic)
//! or 32-bit float (the rendered samples as they are) — written to a temporary file in the
//! target's folder and renamed over it, so a crash never leaves a half-written file.

use super::{Audio, SoundError};
use crate::base::ron_file::{FileError, write_atomic};
use std::io::Cursor;
use std::path::Path;

/// A WAV sample format.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum WavFormat {
    /// 16-bit integer PCM (full scale 32767).
    #[default]
    Pcm16,
    /// 24-bit integer PCM (full scale 8388607).
    Pcm24,
    /// 32-bit IEEE float (full scale 1.0).
    Float32,
}

impl WavFormat {
    /// Bits per sample.
    pub fn bits(self) -> u16 {
        match self {
            WavFormat::Pcm16 => 16,
            WavFormat::Pcm24 => 24,
            WavFormat::Float32 => 32,
        }
    }
}

/// Write `audio` as 16-bit PCM WAV at `path`, atomically (samples are rounded, not dithered,
/// so the file is deterministic).
pub fn write_wav(path: &Path, audio: &Audio) -> Result<(), SoundError> {
    write_wav_as(path, audio, WavFormat::Pcm16)
}

/// Write `audio` as a WAV of `format` at `path`, atomically. Integer formats clamp to
/// [−1, 1] and round to the nearest step.
pub fn write_wav_as(path: &Path, audio: &Audio, format: WavFormat) -> Result<(), SoundError> {
    let wav = |source| SoundError::Wav {
        path: path.to_path_buf(),
        source,
    };
    let spec = hound::WavSpec {
        channels: audio.channels,
        sample_rate: audio.rate_hz,
        bits_per_sample: format.bits(),
        sample_format: match format {
            WavFormat::Float32 => hound::SampleFormat::Float,
            WavFormat::Pcm16 | WavFormat::Pcm24 => hound::SampleFormat::Int,
        },
    };
    // Made in memory, then written as any other file (`write_atomic`: a temporary file
    // beside the target, synced and renamed, with the usual permissions).
    let mut bytes = Cursor::new(Vec::with_capacity(
        64 + audio.samples.len() * usize::from(format.bits() / 8),
    ));
    {
        let mut writer = hound::WavWriter::new(&mut bytes, spec).map_err(wav)?;
        let full_scale = f64::from((1u32 << (format.bits() - 1)) - 1);
        for &s in audio.samples.iter() {
            match format {
                WavFormat::Float32 => writer.write_sample(s),
                WavFormat::Pcm16 | WavFormat::Pcm24 => {
                    let v = (f64::from(s).clamp(-1.0, 1.0) * full_scale).round() as i32;
                    writer.write_sample(v)
                }
            }
            .map_err(wav)?;
        }
        writer.finalize().map_err(wav)?;
    }
    write_atomic(path, bytes.get_ref()).map_err(|e| match e {
        FileError::Io { path, source } => SoundError::Io { path, source },
        other => SoundError::Io {
            path: path.to_path_buf(),
            source: std::io::Error::other(other.to_string()),
        },
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A written WAV reads back with the same spec and samples (within 16-bit rounding),
    /// and no temporary file is left behind.
    #[test]
    fn wav_round_trip() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("x.wav");
        let audio = Audio {
            rate_hz: 48_000,
            channels: 2,
            samples: vec![0.0, 0.5, -0.5, 1.0, -1.0, 0.25].into(),
            gain: 1.0,
        };
        write_wav(&path, &audio).unwrap();
        let mut r = hound::WavReader::open(&path).unwrap();
        assert_eq!(r.spec().channels, 2);
        assert_eq!(r.spec().sample_rate, 48_000);
        let back: Vec<i16> = r.samples::<i16>().map(|s| s.unwrap()).collect();
        for (b, a) in back.iter().zip(audio.samples.iter()) {
            assert!((f64::from(*b) / 32767.0 - f64::from(*a)).abs() < 1e-4);
        }
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
        // Readable by others like every other file written (a bare temporary file was
        // private to its owner).
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            let mode = std::fs::metadata(&path).unwrap().permissions().mode();
            assert_eq!(mode & 0o644, 0o644, "{mode:o}");
        }
    }

    /// 24-bit and float files read back with their spec; the 24-bit steps are 256 times
    /// finer than the 16-bit ones and the float samples are exact.
    #[test]
    fn wav_formats_round_trip() {
        let dir = tempfile::tempdir().unwrap();
        let audio = Audio {
            rate_hz: 48_000,
            channels: 2,
            samples: vec![0.0, 0.123_456_79, -0.5, 1.0, -1.0, 1e-6].into(),
            gain: 1.0,
        };
        let p24 = dir.path().join("24.wav");
        write_wav_as(&p24, &audio, WavFormat::Pcm24).unwrap();
        let mut r = hound::WavReader::open(&p24).unwrap();
        assert_eq!(r.spec().bits_per_sample, 24);
        let back: Vec<i32> = r.samples::<i32>().map(|s| s.unwrap()).collect();
        for (b, a) in back.iter().zip(audio.samples.iter()) {
            assert!((f64::from(*b) / 8_388_607.0 - f64::from(*a)).abs() <= 0.5 / 8_388_607.0);
        }
        assert_eq!(back[3], 8_388_607);
        let pf = dir.path().join("f.wav");
        write_wav_as(&pf, &audio, WavFormat::Float32).unwrap();
        let mut r = hound::WavReader::open(&pf).unwrap();
        assert_eq!(r.spec().sample_format, hound::SampleFormat::Float);
        let back: Vec<f32> = r.samples::<f32>().map(|s| s.unwrap()).collect();
        assert_eq!(back, audio.samples.to_vec());
    }
}
