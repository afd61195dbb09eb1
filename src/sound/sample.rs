//! The sample-replay sound model (seed 002): every contact replays the recorded timpani
//! note whose measured (1,1) pitch is nearest the drum's tuning (in semitones), resampled
//! (cubic Hermite interpolation) so its (1,1) lands on the tuning, at an amplitude
//! proportional to the impact speed: peak = `REFERENCE_LEVEL` × v / `REFERENCE_SPEED_MPS`
//! (each recording is first normalised to peak 1).
//!
//! The recordings are the FluidR3 GM timpani (MIT, `kits/samples/COPYRIGHT-fluid-soundfont`),
//! embedded in the program. Their (1,1) pitches are measured once, with this module's
//! spectrum code ([`principal_hz`] over the kettledrum ratios): about 64.0, 73.3 and 99.1 Hz.
//! Pitching a note up also raises its top octave; content shifted above 24 kHz aliases
//! (the recordings hold little energy there).

use super::spectrum::{principal_hz, spectrum};
use super::{REFERENCE_LEVEL, REFERENCE_SPEED_MPS, SAMPLE_RATE_HZ, SoundError};
use crate::drum::DrumSet;
use crate::kit::Drum;
use std::io::Cursor;
use std::sync::OnceLock;

/// The embedded recordings: (file name, WAV bytes).
pub const RECORDINGS: [(&str, &[u8]); 3] = [
    (
        "Timpani_1L.wav",
        include_bytes!("../../kits/samples/Timpani_1L.wav"),
    ),
    (
        "Timpani_2L.wav",
        include_bytes!("../../kits/samples/Timpani_2L.wav"),
    ),
    (
        "Timpani_3L.wav",
        include_bytes!("../../kits/samples/Timpani_3L.wav"),
    ),
];

/// Kettledrum mode ratios used to recognise the (1,1) in a recording.
const KETTLEDRUM_RATIOS: [f64; 5] = [1.0, 1.5, 1.98, 2.44, 2.94];

/// One decoded recording.
#[derive(Clone, Debug)]
pub struct Recording {
    pub name: &'static str,
    /// Hz.
    pub rate_hz: u32,
    /// Mono samples normalised to peak 1.
    pub samples: Vec<f32>,
    /// Measured (1,1) frequency, Hz.
    pub principal_hz: f64,
}

fn decode(name: &'static str, bytes: &[u8]) -> Result<Recording, SoundError> {
    let bad = |message: String| SoundError::Sample {
        name: name.to_string(),
        message,
    };
    let mut reader = hound::WavReader::new(Cursor::new(bytes)).map_err(|e| bad(e.to_string()))?;
    let spec = reader.spec();
    if spec.sample_format != hound::SampleFormat::Int || spec.bits_per_sample != 16 {
        return Err(bad("expected 16-bit PCM".into()));
    }
    let ch = usize::from(spec.channels.max(1));
    let raw: Vec<i16> = reader
        .samples::<i16>()
        .collect::<Result<_, _>>()
        .map_err(|e| bad(e.to_string()))?;
    let mono: Vec<f32> = raw
        .chunks_exact(ch)
        .map(|f| f.iter().map(|&s| f32::from(s)).sum::<f32>() / ch as f32)
        .collect();
    let peak = mono.iter().fold(0.0f32, |m, s| m.max(s.abs()));
    if peak <= 0.0 {
        return Err(bad("the recording is silent".into()));
    }
    let samples: Vec<f32> = mono.iter().map(|s| s / peak).collect();
    let spec_mag = spectrum(&samples, spec.sample_rate);
    let principal_hz = principal_hz(&spec_mag, 40.0, 400.0, &KETTLEDRUM_RATIOS)
        .ok_or_else(|| bad("no (1,1) peak found".into()))?;
    Ok(Recording {
        name,
        rate_hz: spec.sample_rate,
        samples,
        principal_hz,
    })
}

/// The decoded recordings with their measured pitches (decoded once per process).
pub fn recordings() -> Result<&'static [Recording], SoundError> {
    static CELL: OnceLock<Result<Vec<Recording>, String>> = OnceLock::new();
    let decoded = CELL.get_or_init(|| {
        RECORDINGS
            .iter()
            .map(|(n, b)| decode(n, b))
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| e.to_string())
    });
    match decoded {
        Ok(v) => Ok(v),
        Err(message) => Err(SoundError::Sample {
            name: "recordings".into(),
            message: message.clone(),
        }),
    }
}

/// The recording whose (1,1) is nearest `hz` in log frequency.
pub fn nearest(recordings: &[Recording], hz: f64) -> Option<&Recording> {
    recordings.iter().min_by(|a, b| {
        (a.principal_hz / hz)
            .ln()
            .abs()
            .total_cmp(&(b.principal_hz / hz).ln().abs())
    })
}

/// Cubic Hermite (Catmull–Rom) interpolation of `x` at fractional index `pos` (0 outside).
fn interpolate(x: &[f32], pos: f64) -> f64 {
    let i = pos.floor() as isize;
    let t = pos - i as f64;
    let at = |k: isize| {
        usize::try_from(k)
            .ok()
            .and_then(|k| x.get(k))
            .map_or(0.0, |&v| f64::from(v))
    };
    let (p0, p1, p2, p3) = (at(i - 1), at(i), at(i + 1), at(i + 2));
    p1 + 0.5
        * t
        * (p2 - p0 + t * (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3 + t * (3.0 * (p1 - p2) + p3 - p0)))
}

/// Render drum `j`'s contacts into `out`; returns whether any contact was on it.
pub fn render_drum(
    drum: &Drum,
    drums: &DrumSet,
    j: usize,
    out: &mut [f32],
) -> Result<bool, SoundError> {
    let contacts: Vec<_> = drums.contacts().iter().filter(|c| c.drum == j).collect();
    if contacts.is_empty() {
        return Ok(false);
    }
    let recs = recordings()?;
    let rec = nearest(recs, drum.tuning.hz()).expect("three recordings are embedded");
    let fs = f64::from(SAMPLE_RATE_HZ);
    // Recording samples per output sample.
    let step = drum.tuning.hz() / rec.principal_hz * f64::from(rec.rate_hz) / fs;
    let len = ((rec.samples.len() as f64 - 1.0) / step).floor() as usize;
    for c in contacts {
        let amp = REFERENCE_LEVEL * c.impact_speed_mps / REFERENCE_SPEED_MPS;
        let start = (c.start_s * fs).round().max(0.0) as usize;
        for (i, o) in out.iter_mut().skip(start).take(len).enumerate() {
            *o += (amp * interpolate(&rec.samples, i as f64 * step)) as f32;
        }
    }
    Ok(true)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The embedded recordings decode and their measured (1,1) pitches are the stated
    /// 64.0, 73.3 and 99.1 Hz (within 1 %).
    #[test]
    fn recorded_pitches() {
        let recs = recordings().unwrap();
        let got: Vec<f64> = recs.iter().map(|r| r.principal_hz).collect();
        for (g, want) in got.iter().zip([64.0, 73.3, 99.1]) {
            assert!((g / want - 1.0).abs() < 0.005, "{got:?}");
        }
        assert_eq!(nearest(recs, 146.8).unwrap().name, "Timpani_3L.wav");
        assert_eq!(nearest(recs, 68.0).unwrap().name, "Timpani_1L.wav");
    }

    /// Interpolation passes through the samples and is 0 outside.
    #[test]
    fn interpolation_hits_samples() {
        let x = [0.0, 1.0, 4.0, 9.0, 16.0];
        assert_eq!(interpolate(&x, 2.0), 4.0);
        assert!((interpolate(&x, 2.5) - 6.25).abs() < 0.2);
        assert_eq!(interpolate(&x, 10.0), 0.0);
    }
}
