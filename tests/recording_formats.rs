//! Recordings as other programs write them: the first 1.2 s of the shipped FluidR3 D2 note
//! (`kits/samples/Timpani_2R.wav`) as ffmpeg wrote it in FLAC, AIFF, MP3 (LAME, 64 kb/s),
//! Ogg Vorbis (q3), IMA ADPCM and A-law WAV (`tests/fixtures/recordings/`, MIT as the
//! samples), and a 64-bit float WAV written here. Each reads back to the note: the
//! lossless ones sample for sample, the others with the same (1,1) and octave bands; an
//! MP3 is transcribed as one stroke on the WAV's pitch. Files no decoder reads are refused
//! naming the file and the formats that are read.

use std::path::{Path, PathBuf};
use timpanist::sound::analysis;
use timpanist::sound::recording::{read_mono, read_mono_bytes};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn fixture(name: &str) -> PathBuf {
    root().join("tests/fixtures/recordings").join(name)
}

/// The WAV note the fixtures were made from, cut to their 1.2 s.
fn the_wav() -> (Vec<f32>, u32) {
    let (samples, rate) = read_mono(&root().join("kits/samples/Timpani_2R.wav")).unwrap();
    let n = (1.2 * f64::from(rate)) as usize;
    (samples[..n].to_vec(), rate)
}

/// A WAV of 64-bit float samples (format 3), as DAWs write on request.
fn f64_wav(samples: &[f32], rate: u32) -> Vec<u8> {
    let data = samples.len() as u32 * 8;
    let mut b = Vec::new();
    b.extend_from_slice(b"RIFF");
    b.extend_from_slice(&(36 + data).to_le_bytes());
    b.extend_from_slice(b"WAVEfmt ");
    b.extend_from_slice(&16u32.to_le_bytes());
    b.extend_from_slice(&3u16.to_le_bytes()); // IEEE float
    b.extend_from_slice(&1u16.to_le_bytes()); // mono
    b.extend_from_slice(&rate.to_le_bytes());
    b.extend_from_slice(&(rate * 8).to_le_bytes());
    b.extend_from_slice(&8u16.to_le_bytes());
    b.extend_from_slice(&64u16.to_le_bytes());
    b.extend_from_slice(b"data");
    b.extend_from_slice(&data.to_le_bytes());
    for &s in samples {
        b.extend_from_slice(&f64::from(s).to_le_bytes());
    }
    b
}

#[test]
fn lossless_formats_read_sample_for_sample() {
    let (wav, rate) = the_wav();
    let f64_bytes = f64_wav(&wav, rate);
    let cases = [
        ("d2-note.flac", read_mono(&fixture("d2-note.flac")).unwrap()),
        ("d2-note.aiff", read_mono(&fixture("d2-note.aiff")).unwrap()),
        (
            "64-bit float WAV",
            read_mono_bytes(Path::new("note.wav"), &f64_bytes)
                .map(|(samples, rate, _)| (samples, rate))
                .unwrap(),
        ),
    ];
    for (name, (samples, r)) in cases {
        assert_eq!(r, rate, "{name}: rate");
        assert_eq!(samples.len(), wav.len(), "{name}: length");
        assert_eq!(samples, wav, "{name}: samples");
    }
}

#[test]
fn lossy_and_companded_formats_keep_the_note() {
    let (wav, rate) = the_wav();
    let want = analysis::profile(&wav, rate).unwrap();
    let want_hz = want.principal_hz.unwrap();
    // A-law and ADPCM keep 8 and 4 bits a sample, MP3 at 64 kb/s and Vorbis q3 drop
    // what masking hides: the note's pitch and its strong bands stay; the quiet top
    // bands (4 kHz sits 45 dB under the whole) may move by more.
    for (name, band_tolerance_db) in [
        ("d2-note-alaw.wav", 1.0),
        ("d2-note-ima-adpcm.wav", 1.0),
        ("d2-note.mp3", 1.5),
        ("d2-note.ogg", 1.5),
    ] {
        let (samples, r) = read_mono(&fixture(name)).unwrap();
        assert_eq!(r, rate, "{name}: rate");
        // MP3 and Vorbis are read gapless (the encoder's delay and padding removed).
        let extra = samples.len().abs_diff(wav.len());
        assert!(
            extra <= 1152,
            "{name}: {} samples against {}",
            samples.len(),
            wav.len()
        );
        let got = analysis::profile(&samples, r).unwrap();
        assert!(
            (got.onset_s - want.onset_s).abs() < 0.002,
            "{name}: onset {} s against {} s",
            got.onset_s,
            want.onset_s
        );
        let hz = got.principal_hz.unwrap();
        assert!(
            (hz / want_hz - 1.0).abs() < 0.002,
            "{name}: (1,1) {hz} Hz against {want_hz} Hz"
        );
        for (k, (g, w)) in got.bands_db.iter().zip(want.bands_db).enumerate() {
            let tolerance = if w > -40.0 { band_tolerance_db } else { 6.0 };
            assert!(
                (g - w).abs() < tolerance,
                "{name}: band {} Hz {g:.1} dB against {w:.1} dB",
                analysis::OCTAVE_CENTRES_HZ[k]
            );
        }
    }
}

#[test]
fn an_mp3_is_transcribed_as_its_wav() {
    let dir = tempfile::tempdir().unwrap();
    let run = |input: &Path, out: &str| {
        let out = dir.path().join(out);
        let status = std::process::Command::new(env!("CARGO_BIN_EXE_timpanist"))
            .arg("transcribe")
            .arg(input)
            .arg("-o")
            .arg(&out)
            .output()
            .unwrap();
        assert!(
            status.status.success(),
            "{}: {}",
            input.display(),
            String::from_utf8_lossy(&status.stderr)
        );
        timpanist::score::LoadedScore::load(&out).unwrap()
    };
    let from_wav = run(&root().join("kits/samples/Timpani_2R.wav"), "wav.ron");
    let from_mp3 = run(&fixture("d2-note.mp3"), "mp3.ron");
    assert_eq!(from_wav.score.beats.len(), 1, "one stroke in the WAV");
    assert_eq!(from_mp3.score.beats.len(), 1, "one stroke in the MP3");
    assert_eq!(from_mp3.score.beats[0].tick, from_wav.score.beats[0].tick);
    assert_eq!(from_mp3.score.beats[0].drum, from_wav.score.beats[0].drum);
    assert_eq!(from_mp3.kit, from_wav.kit, "the same drums tuned alike");
    // One stroke shows no beat: one tempo, the transcriber's default.
    for loaded in [&from_wav, &from_mp3] {
        assert_eq!(loaded.score.tempo.len(), 1, "{:?}", loaded.score.tempo);
        assert_eq!(loaded.score.tempo[0].bpm, 100.0);
    }
}

#[test]
fn unreadable_files_are_refused_by_name() {
    let refused = |name: &str, bytes: &[u8]| -> String {
        let e = read_mono_bytes(Path::new(name), bytes)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with(name), "{e}");
        e
    };
    // An MPEG-4 (AAC) file: no decoder here reads it.
    let mut m4a = vec![0, 0, 0, 0x20];
    m4a.extend_from_slice(b"ftypM4A \0\0\0\0M4A mp42isom\0\0\0\0");
    m4a.resize(4096, 0);
    let e = refused("take.m4a", &m4a);
    assert!(e.contains("WAV, AIFF, FLAC, MP3 or Ogg Vorbis"), "{e}");
    assert!(refused("empty.wav", b"").contains("empty"));
    let text = b"These are notes about the session, not a recording.\n".repeat(40);
    refused("notes.wav", &text);
    // A FLAC cut after its header and a few frames: what was written is read, or a clear
    // error; never a panic.
    let flac = std::fs::read(fixture("d2-note.flac")).unwrap();
    for cut in [4, 42, 100, 2000, flac.len() / 2] {
        if let Ok((samples, rate, notes)) = read_mono_bytes(Path::new("cut.flac"), &flac[..cut]) {
            assert_eq!(rate, 32_000);
            assert!(
                samples.len() < 38_400,
                "cut at {cut}: {} samples",
                samples.len()
            );
            assert!(
                notes.iter().any(|n| n.contains("cut short")),
                "cut at {cut}: {notes:?}"
            );
        }
    }
    // A FLAC with damaged bytes mid-file: the frames failing their checksum are skipped
    // by the reader, read as silence with a note saying when and how long, so the note
    // keeps its length and what follows its time.
    let (whole, _, notes) = read_mono_bytes(Path::new("d2-note.flac"), &flac).unwrap();
    assert!(notes.is_empty(), "{notes:?}");
    let mut damaged = flac.clone();
    let at = flac.len() / 2;
    for b in &mut damaged[at..at + 300] {
        *b ^= 0xA5;
    }
    let (read, _, notes) = read_mono_bytes(Path::new("damaged.flac"), &damaged).unwrap();
    assert_eq!(read.len(), whole.len());
    assert!(
        notes.len() == 1 && notes[0].contains("damaged") && notes[0].contains("silence"),
        "{notes:?}"
    );
}
