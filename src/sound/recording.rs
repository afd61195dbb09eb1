//! Reading a recording to mono samples, whatever program wrote it: WAV in any encoding
//! (8–32-bit integer, 32- and 64-bit float, A-law, μ-law, IMA and Microsoft ADPCM, the
//! extensible header), AIFF and AIFF-C, FLAC, MP3 and Ogg Vorbis, decoded by Symphonia;
//! the format is recognised from the bytes (the extension only hints). Several channels
//! are averaged to one, or the loudest is kept where averaging would cancel (see
//! [`downmix`]). Used by `sound analyse`, `sound fit` and the transcriber.

use std::io::Cursor;
use std::path::{Path, PathBuf};
use symphonia::core::codecs::CodecParameters;
use symphonia::core::errors::Error as DecodeError;
use symphonia::core::formats::TrackType;
use symphonia::core::formats::probe::Hint;
use symphonia::core::io::{MediaSourceStream, ReadOnlySource};

/// A stereo (or wider) file whose channels summed keep less than this share of their mean
/// energy is read from its loudest channel instead: spaced microphones out of phase cancel.
const MIN_MIX_SHARE: f64 = 0.5;

/// A mean above this share of the recording's RMS level (about −12 dB) is an offset to
/// remove ([`remove_offset`]); the embedded notes' means are 0.01–0.03 of it.
const MAX_OFFSET_SHARE: f64 = 0.25;

/// The formats read, as a user would name them (for messages).
pub const FORMATS: &str = "WAV, AIFF, FLAC, MP3 or Ogg Vorbis";

/// The file extensions of the formats read (lower case).
pub const EXTENSIONS: [&str; 9] = [
    "wav", "wave", "aif", "aiff", "aifc", "flac", "mp3", "ogg", "oga",
];

/// Why a recording could not be read.
#[derive(Debug, thiserror::Error)]
#[error("{}: {message}", path.display())]
pub struct ReadError {
    pub path: PathBuf,
    pub message: String,
}

/// A recording's channels averaged to mono (samples in −1…1), with its rate, Hz. What
/// [`read_mono_noted`] would note is dropped: the commands and the transcriber call that.
pub fn read_mono(path: &Path) -> Result<(Vec<f32>, u32), ReadError> {
    read_mono_noted(path).map(|(samples, rate, _)| (samples, rate))
}

/// [`read_mono`], with notes on what was read round (a WAV header left unfinished by a
/// recorder that stopped: [`finish_wav_sizes`]).
pub fn read_mono_noted(path: &Path) -> Result<(Vec<f32>, u32, Vec<String>), ReadError> {
    let mut bytes = crate::base::limits::read_at_most(
        path,
        crate::base::limits::MAX_CAPTURE_FILE_BYTES,
        "recording",
    )
    .map_err(|e| ReadError {
        path: path.to_path_buf(),
        message: e.to_string(),
    })?;
    let finished = finish_wav_sizes(&mut bytes);
    let (samples, rate, read) = read_mono_bytes(path, &bytes)?;
    let notes = finished
        .into_iter()
        .chain(read)
        .map(|n| format!("{}: {n}", path.display()))
        .collect();
    Ok((samples, rate, notes))
}

/// The size a recorder writes in a WAV header it means to finish when it stops: a crash
/// leaves 0 or 0xFFFFFFFF (streaming writers' "unknown").
const UNFINISHED_SIZES: [u32; 2] = [0, u32::MAX];

/// A RIFF/WAVE file whose RIFF size or `data` chunk size was left unfinished
/// ([`UNFINISHED_SIZES`]) or runs past the file's end (a recorder that crashed or lost
/// power before closing the file; ffmpeg and Audacity read such files) is given the sizes
/// of what the file holds, in place. Returns what was changed, for a note.
fn finish_wav_sizes(bytes: &mut [u8]) -> Option<String> {
    if bytes.len() < 12 || &bytes[..4] != b"RIFF" || &bytes[8..12] != b"WAVE" {
        return None;
    }
    let len = bytes.len();
    let size_at =
        |b: &[u8], at: usize| u32::from_le_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]]);
    let (mut at, mut data) = (12, None);
    while at + 8 <= len {
        let size = size_at(bytes, at + 4);
        if &bytes[at..at + 4] == b"data" {
            data = Some((at, size));
            break;
        }
        at += 8 + size as usize + (size as usize & 1);
    }
    let (at, size) = data?;
    let held = u32::try_from(len - (at + 8)).ok()?;
    let riff = size_at(bytes, 4);
    let riff_held = u32::try_from(len - 8).ok()?;
    let unset = |s: u32| UNFINISHED_SIZES.contains(&s);
    let data_unset = unset(size) && held > 0;
    let cut_short = !unset(size) && size > held;
    let data_wrong = data_unset || size > held;
    let riff_wrong = unset(riff) || riff > riff_held;
    if !data_wrong && !riff_wrong {
        return None;
    }
    bytes[4..8].copy_from_slice(&riff_held.to_le_bytes());
    if data_wrong {
        bytes[at + 4..at + 8].copy_from_slice(&held.to_le_bytes());
    }
    let unfinished = |what: &str, said: u32| {
        format!(
            "its header was not finished (it gives the {what} as {said} bytes: a recorder \
             that stopped before closing the file?): read the {held} bytes of sound it holds"
        )
    };
    Some(if cut_short {
        format!(
            "the file is cut short: its header gives {size} bytes of sound, it holds {held} \
             (read those)"
        )
    } else if data_wrong {
        unfinished("sound data", size)
    } else {
        unfinished("file size", riff)
    })
}

/// The highest sample rate read, Hz (a header claiming more is damaged).
pub const MAX_RATE_HZ: u32 = 768_000;

/// [`read_mono`] of a recording held in memory (`path` names it in errors; its extension,
/// if any, is a hint to the format, which is recognised from the bytes), with notes on
/// what was read round: damaged stretches a decoder skipped (read as silence, so what
/// follows keeps its time) and a stream cut short.
pub fn read_mono_bytes(
    path: &Path,
    bytes: &[u8],
) -> Result<(Vec<f32>, u32, Vec<String>), ReadError> {
    let bad = |message: String| ReadError {
        path: path.to_path_buf(),
        message,
    };
    if bytes.is_empty() {
        return Err(bad("the file is empty".into()));
    }
    if bytes.starts_with(b"RF64") || bytes.starts_with(b"BW64") {
        return Err(bad(
            "an RF64/BW64 WAV (the format for files over 4 GB) is not read: save the note \
             as a plain WAV"
                .into(),
        ));
    }
    let mut hint = Hint::new();
    if let Some(ext) = path.extension().and_then(|e| e.to_str()) {
        hint.with_extension(ext);
    }
    // Read as a stream, front to back, never seeking: a file cut short (a recorder stopped
    // mid-write) then gives what was written instead of failing a length check.
    let source = ReadOnlySource::new(Cursor::new(bytes));
    let stream = MediaSourceStream::new(Box::new(source), Default::default());
    let mut reader = symphonia::default::get_probe()
        .probe(&hint, stream, Default::default(), Default::default())
        .map_err(|e| {
            bad(match e {
                DecodeError::Unsupported(_) => {
                    format!("not a recording timpanist can read (it reads {FORMATS})")
                }
                DecodeError::IoError(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => {
                    "the file ends before its first sound (is it cut short?)".into()
                }
                e => format!("not a readable {FORMATS} file ({e})"),
            })
        })?;
    let track = reader
        .default_track(TrackType::Audio)
        .ok_or_else(|| bad("the file holds no audio track".into()))?;
    let track_id = track.id;
    let Some(CodecParameters::Audio(params)) = track.codec_params.clone() else {
        return Err(bad("the file holds no audio track".into()));
    };
    let rate = params
        .sample_rate
        .filter(|&r| r > 0)
        .ok_or_else(|| bad("the file does not say its sample rate".into()))?;
    if rate > MAX_RATE_HZ {
        return Err(bad(format!(
            "its header gives a sample rate of {rate} Hz, more than any recording's (at most \
             {} kHz): is the file damaged?",
            MAX_RATE_HZ / 1000
        )));
    }
    let time_base = track.time_base;
    let mut decoder = symphonia::default::get_codecs()
        .make_audio_decoder(&params, &Default::default())
        .map_err(|e| bad(format!("its audio encoding is not read ({e})")))?;
    let max_frames = (crate::base::limits::MAX_SCORE_S * f64::from(rate)) as usize;
    let mut raw: Vec<f32> = Vec::new();
    let mut packet_samples: Vec<f32> = Vec::new();
    let mut channels = 0usize;
    let seconds = |frames: usize| frames as f64 / f64::from(rate);
    let mut notes = Vec::new();
    // Where the next packet should start (time-base units): a later one follows a
    // stretch the reader skipped (a FLAC frame failing its checksum). FLAC only: the
    // other formats' readers skip nothing (an Ogg Vorbis stream's first packets overlap).
    let flac = bytes.starts_with(b"fLaC");
    let mut next_pts: Option<i64> = None;
    loop {
        let packet = match reader.next_packet() {
            Ok(Some(packet)) => packet,
            Ok(None) => break,
            // A file cut short (a recorder stopped mid-write): what was written is read.
            Err(DecodeError::IoError(e))
                if e.kind() == std::io::ErrorKind::UnexpectedEof && !raw.is_empty() =>
            {
                if !bytes.starts_with(b"RIFF") {
                    notes.push(format!(
                        "the stream ends unfinished at {:.3} s (is the file cut short?): \
                         what it holds is read",
                        seconds(raw.len() / channels.max(1))
                    ));
                }
                break;
            }
            Err(e) => {
                let at = seconds(raw.len() / channels.max(1));
                return Err(bad(format!("unreadable at {at:.3} s: {e}")));
            }
        };
        if packet.track_id != track_id {
            continue;
        }
        if let (Some(tb), Some(expected)) = (time_base, next_pts)
            && channels > 0
        {
            let missing_s = (packet.pts.get() - expected) as f64 * f64::from(tb.numer.get())
                / f64::from(tb.denom.get());
            let frames = (missing_s * f64::from(rate)).round();
            if frames >= 1.0 && frames <= max_frames as f64 {
                let at = seconds(raw.len() / channels);
                notes.push(format!(
                    "{missing_s:.3} s at {at:.3} s could not be read (damaged) and is read \
                     as silence"
                ));
                raw.resize(raw.len() + frames as usize * channels, 0.0);
            }
        }
        next_pts = flac.then(|| packet.pts.get() + packet.dur.get() as i64);
        let decoded = decoder.decode(&packet).map_err(|e| {
            let at = seconds(raw.len() / channels.max(1));
            bad(format!("unreadable at {at:.3} s: {e}"))
        })?;
        let ch = decoded.spec().channels().count().max(1);
        if channels != 0 && ch != channels {
            return Err(bad(format!(
                "its channel count changes from {channels} to {ch} at {:.3} s",
                seconds(raw.len() / channels)
            )));
        }
        channels = ch;
        decoded.copy_to_vec_interleaved(&mut packet_samples);
        raw.extend_from_slice(&packet_samples);
        if raw.len() / channels > max_frames {
            return Err(bad(format!(
                "longer than {:.0} minutes, the longest recording read",
                crate::base::limits::MAX_SCORE_S / 60.0
            )));
        }
    }
    if raw.is_empty() {
        return Err(bad("the file holds no samples".into()));
    }
    if let Some(i) = raw.iter().position(|s| !s.is_finite()) {
        let frame = i / channels.max(1);
        return Err(bad(format!(
            "it holds samples that are not numbers (NaN or infinite), the first at {:.6} s \
             (frame {frame})",
            seconds(frame)
        )));
    }
    let mut mono = downmix(&raw, channels);
    remove_offset(&mut mono);
    Ok((mono, rate, notes))
}

/// A constant offset standing within [`MAX_OFFSET_SHARE`] of the sound's own RMS level
/// (an interface's DC, not the slight asymmetry of a struck note, whose mean over the file
/// is 1–2 % of its RMS) is subtracted: it would read as a step at the file's start and
/// raise every window's level, hiding the strokes above it.
fn remove_offset(mono: &mut [f32]) {
    let n = mono.len().max(1) as f64;
    let mean = mono.iter().map(|&x| f64::from(x)).sum::<f64>() / n;
    let power = mono.iter().map(|&x| f64::from(x).powi(2)).sum::<f64>() / n;
    let ac_rms = (power - mean * mean).max(0.0).sqrt();
    if mean.abs() > MAX_OFFSET_SHARE * ac_rms {
        for x in mono.iter_mut() {
            *x = (f64::from(*x) - mean) as f32;
        }
    }
}

/// Interleaved frames of `ch` channels to mono: their mean, or the loudest channel when the
/// mean keeps less than [`MIN_MIX_SHARE`] of the channels' mean energy (a spaced pair
/// whose microphones hear the head out of phase would cancel its low partials).
fn downmix(raw: &[f32], ch: usize) -> Vec<f32> {
    let mean: Vec<f32> = raw
        .chunks_exact(ch)
        .map(|f| f.iter().sum::<f32>() / ch as f32)
        .collect();
    if ch < 2 {
        return mean;
    }
    let energy = |xs: &mut dyn Iterator<Item = f32>| xs.map(|x| f64::from(x).powi(2)).sum::<f64>();
    let per_channel: Vec<f64> = (0..ch)
        .map(|c| energy(&mut raw.iter().skip(c).step_by(ch).copied()))
        .collect();
    let channels_mean = per_channel.iter().sum::<f64>() / ch as f64;
    if energy(&mut mean.iter().copied()) >= MIN_MIX_SHARE * channels_mean {
        return mean;
    }
    let loudest = (0..ch)
        .max_by(|&a, &b| per_channel[a].total_cmp(&per_channel[b]))
        .unwrap_or(0);
    raw.iter().skip(loudest).step_by(ch).copied().collect()
}

#[cfg(test)]
mod tests {

    /// A WAV whose recorder stopped before finishing its header (RIFF and data sizes 0 or
    /// 0xFFFFFFFF, as crashed or streaming recorders leave them) or was cut short reads
    /// the samples the file holds, the same as the whole file, with a note saying so.
    #[test]
    fn unfinished_wav_headers_read_what_the_file_holds() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("kits/samples/Timpani_2R.wav");
        let whole = std::fs::read(&path).unwrap();
        let (samples, rate, notes) = read_mono_bytes(&path, &whole).unwrap();
        assert!(notes.is_empty(), "{notes:?}");
        let data = whole.windows(4).position(|w| w == b"data").unwrap();
        let set =
            |b: &mut Vec<u8>, at: usize, v: u32| b[at..at + 4].copy_from_slice(&v.to_le_bytes());
        let max = Some(u32::MAX);
        let cases = [
            (Some(0), Some(0)),
            (max, max),
            (None, Some(0)),
            (None, max),
            (Some(0), None),
            (max, None),
        ];
        for (riff, size) in cases {
            let mut bytes = whole.clone();
            if let Some(r) = riff {
                set(&mut bytes, 4, r);
            }
            if let Some(s) = size {
                set(&mut bytes, data + 4, s);
            }
            let note = finish_wav_sizes(&mut bytes).expect("a note");
            assert!(note.contains("not finished"), "{note}");
            assert_eq!(bytes, whole, "riff {riff:?} data {size:?}");
            assert_eq!(
                read_mono_bytes(&path, &bytes).unwrap(),
                (samples.clone(), rate, vec![])
            );
        }
        // Cut short: the first half of the sound.
        let mut cut = whole[..data + 8 + (whole.len() - data - 8) / 2].to_vec();
        let note = finish_wav_sizes(&mut cut).expect("a note");
        assert!(note.contains("cut short"), "{note}");
        let (half, _, _) = read_mono_bytes(&path, &cut).unwrap();
        assert!(half.len() + 2 >= samples.len() / 2 && half.len() <= samples.len() / 2 + 2);
        // A finished file is left alone.
        let mut same = whole.clone();
        assert_eq!(finish_wav_sizes(&mut same), None);
    }

    /// A 32-bit float WAV of `samples` (mono) at `rate`.
    fn float_wav(samples: &[f32], rate: u32) -> Vec<u8> {
        let mut b = Vec::new();
        let data = (4 * samples.len()) as u32;
        b.extend_from_slice(b"RIFF");
        b.extend_from_slice(&(36 + data).to_le_bytes());
        b.extend_from_slice(b"WAVEfmt ");
        b.extend_from_slice(&16u32.to_le_bytes());
        b.extend_from_slice(&3u16.to_le_bytes());
        b.extend_from_slice(&1u16.to_le_bytes());
        b.extend_from_slice(&rate.to_le_bytes());
        b.extend_from_slice(&rate.wrapping_mul(4).to_le_bytes());
        b.extend_from_slice(&4u16.to_le_bytes());
        b.extend_from_slice(&32u16.to_le_bytes());
        b.extend_from_slice(b"data");
        b.extend_from_slice(&data.to_le_bytes());
        for x in samples {
            b.extend_from_slice(&x.to_le_bytes());
        }
        b
    }

    /// A header claiming a rate no recorder writes is refused at once (it had the onset
    /// detector's frames grow with it, to gigabytes); a NaN is named by its time and frame.
    #[test]
    fn an_absurd_rate_and_a_nan_are_refused_saying_where() {
        let path = Path::new("note.wav");
        let tone: Vec<f32> = (0..4800).map(|i| (0.01 * i as f32).sin() * 0.5).collect();
        let e = read_mono_bytes(path, &float_wav(&tone, 4_000_000_000)).unwrap_err();
        assert!(e.to_string().contains("4000000000 Hz"), "{e}");
        assert!(read_mono_bytes(path, &float_wav(&tone, MAX_RATE_HZ)).is_ok());
        let mut bad = tone.clone();
        bad[2400] = f32::NAN;
        let e = read_mono_bytes(path, &float_wav(&bad, 48_000)).unwrap_err();
        assert!(e.to_string().contains("0.050000 s (frame 2400)"), "{e}");
    }
    use super::*;
    use std::f64::consts::TAU;

    /// An interface's offset is removed; a note's own slight mean is kept bit for bit.
    #[test]
    fn a_dc_offset_is_removed_a_notes_own_mean_kept() {
        let note: Vec<f32> = (0..48_000)
            .map(|i| {
                let t = i as f64 / 48_000.0;
                ((TAU * 100.0 * t).sin() * (-3.0 * t).exp() * 0.5 + 0.004 * (-20.0 * t).exp())
                    as f32
            })
            .collect();
        let mut kept = note.clone();
        remove_offset(&mut kept);
        assert_eq!(kept, note);
        let mut offset: Vec<f32> = note.iter().map(|&x| x + 0.2).collect();
        remove_offset(&mut offset);
        let mean = offset.iter().map(|&x| f64::from(x)).sum::<f64>() / offset.len() as f64;
        assert!(mean.abs() < 1e-6, "{mean}");
    }

    /// Two channels hearing the head out of phase are read from the louder, not cancelled;
    /// two in phase are averaged.
    #[test]
    fn a_stereo_pair_out_of_phase_is_not_cancelled() {
        let note: Vec<f32> = (0..4800)
            .map(|i| (TAU * 100.0 * i as f64 / 48_000.0).sin() as f32)
            .collect();
        let interleave =
            |l: f32, r: f32| -> Vec<f32> { note.iter().flat_map(|&x| [l * x, r * x]).collect() };
        assert_eq!(downmix(&interleave(1.0, -0.9), 2), note);
        let mean: Vec<f32> = note.iter().map(|&x| (x + 0.5 * x) / 2.0).collect();
        assert_eq!(downmix(&interleave(1.0, 0.5), 2), mean);
        assert_eq!(downmix(&note, 1), note);
    }
}
