//! WAV output: 16-bit PCM through hound, written to a temporary file in the target's folder
//! and renamed over it, so a crash never leaves a half-written file.

use super::{Audio, SoundError};
use std::io::BufWriter;
use std::path::Path;

/// Write `audio` as 16-bit PCM WAV at `path`, atomically (samples are rounded, not dithered,
/// so the file is deterministic).
pub fn write_wav(path: &Path, audio: &Audio) -> Result<(), SoundError> {
    let io = |source| SoundError::Io {
        path: path.to_path_buf(),
        source,
    };
    let wav = |source| SoundError::Wav {
        path: path.to_path_buf(),
        source,
    };
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let mut tmp = tempfile::Builder::new()
        .prefix(".timpanist-")
        .suffix(".wav")
        .tempfile_in(dir)
        .map_err(io)?;
    let spec = hound::WavSpec {
        channels: audio.channels,
        sample_rate: audio.rate_hz,
        bits_per_sample: 16,
        sample_format: hound::SampleFormat::Int,
    };
    {
        let mut writer =
            hound::WavWriter::new(BufWriter::new(tmp.as_file_mut()), spec).map_err(wav)?;
        for &s in &audio.samples {
            let v = (f64::from(s).clamp(-1.0, 1.0) * 32767.0).round() as i16;
            writer.write_sample(v).map_err(wav)?;
        }
        writer.finalize().map_err(wav)?;
    }
    tmp.as_file().sync_all().map_err(io)?;
    tmp.persist(path).map_err(|e| io(e.error))?;
    Ok(())
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
            samples: vec![0.0, 0.5, -0.5, 1.0, -1.0, 0.25],
            gain: 1.0,
        };
        write_wav(&path, &audio).unwrap();
        let mut r = hound::WavReader::open(&path).unwrap();
        assert_eq!(r.spec().channels, 2);
        assert_eq!(r.spec().sample_rate, 48_000);
        let back: Vec<i16> = r.samples::<i16>().map(|s| s.unwrap()).collect();
        for (b, a) in back.iter().zip(&audio.samples) {
            assert!((f64::from(*b) / 32767.0 - f64::from(*a)).abs() < 1e-4);
        }
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }
}
