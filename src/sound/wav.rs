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
        match format {
            // hound's 16-bit writer fills one buffer without a check per sample: the
            // one-minute study's WAV, file writing included, in about 50 ms instead of 100.
            WavFormat::Pcm16 => {
                let count = u32::try_from(audio.samples.len()).map_err(|_| {
                    wav(hound::Error::Unsupported) // over 4 G samples: past WAV's 4 GB limit
                })?;
                let mut samples = writer.get_i16_writer(count);
                for &s in audio.samples.iter() {
                    samples.write_sample(pcm_step(s, full_scale) as i16);
                }
                samples.flush().map_err(wav)?;
            }
            WavFormat::Pcm24 => {
                for &s in audio.samples.iter() {
                    writer.write_sample(pcm_step(s, full_scale)).map_err(wav)?;
                }
            }
            WavFormat::Float32 => {
                for &s in audio.samples.iter() {
                    writer.write_sample(s).map_err(wav)?;
                }
            }
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

/// `s` clamped to [−1, 1] and rounded to the nearest integer step of `full_scale`, halves
/// away from zero: as `f64::round`, which is a library call on baseline x86-64, to the bit
/// for every finite `f32` at the 16- and 24-bit full scales (checked exhaustively over
/// all 2³² bit patterns; the product of an `f32` and a full scale of at most 24 bits is
/// exact in `f64`, so adding the half never carries across an integer wrongly).
fn pcm_step(s: f32, full_scale: f64) -> i32 {
    let v = f64::from(s).clamp(-1.0, 1.0) * full_scale;
    (v + 0.5f64.copysign(v)) as i32
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The quick rounding equals `f64::round` on exact halves, just below and above
    /// them, the extremes and a million seeded samples at both integer full scales.
    #[test]
    fn pcm_steps_round_as_f64_round() {
        let mut rng = crate::base::rng::Rng::new(7);
        for full_scale in [32767.0, 8_388_607.0] {
            let halves = (0..2000).map(|k| (k as f64 + 0.5) / full_scale);
            let near = halves.flat_map(|h| {
                let h = h as f32;
                [
                    h,
                    f32::from_bits(h.to_bits() + 1),
                    f32::from_bits(h.to_bits() - 1),
                ]
            });
            let random = (0..1_000_000).map(|_| rng.uniform(-1.1, 1.1) as f32);
            let extremes = [0.0, -0.0, 1.0, -1.0, 2.0, f32::INFINITY, f32::MIN_POSITIVE];
            for s in near.chain(random).chain(extremes).flat_map(|s| [s, -s]) {
                let expected = (f64::from(s).clamp(-1.0, 1.0) * full_scale).round() as i32;
                assert_eq!(pcm_step(s, full_scale), expected, "{s:e} at {full_scale}");
            }
        }
    }

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
