//! A seeded mutation fuzzer for every parser, on stable Rust: each parser gets inputs made
//! from its real fixtures by byte mutations (bit flips, interesting values, inserted,
//! deleted, duplicated and spliced runs, truncation) and, for text formats, token
//! mutations (numbers replaced by huge, negative, NaN or empty values, lines dropped or
//! repeated). A parser may refuse an input with an error; it must never panic. A panic
//! fails the test with the seed and the input saved under `target/fuzz-crashes/`, to
//! become a regression test named after what it was.
//!
//! CI runs a short share (`TIMPANIST_FUZZ_RUNS`, default 300 inputs per parser); the long
//! run is `TIMPANIST_FUZZ_RUNS=1000000 cargo test --release --test fuzz -- --nocapture`
//! (README "Fuzzing"), which prints the inputs run per parser. `TIMPANIST_FUZZ_SEED`
//! starts another sequence; `TIMPANIST_FUZZ_ONLY=midi,c3d` runs only the parsers named.

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::Path;
use timpanist::base::rng::Rng;
use timpanist::kit::Kit;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn env_u64(name: &str, default: u64) -> u64 {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// Run a parser on bytes: whether it accepted them.
type Parser = Box<dyn Fn(&[u8]) -> bool>;

/// One parser: its name, seed inputs and how to run it.
struct Target {
    name: &'static str,
    seeds: Vec<Vec<u8>>,
    text: bool,
    run: Parser,
}

fn read(rel: &str) -> Vec<u8> {
    std::fs::read(root().join(rel)).unwrap_or_else(|e| panic!("{rel}: {e}"))
}

fn targets() -> Vec<Target> {
    let kit = Kit::standard();
    let path = Path::new("fuzz-input");
    let mut targets = Vec::new();
    let mut add = |name, seeds: Vec<Vec<u8>>, text, run: Parser| {
        targets.push(Target {
            name,
            seeds,
            text,
            run,
        })
    };
    let scores = ["etude-modes", "tempo-change", "roll-exercise"]
        .map(|n| read(&format!("scores/{n}.ron")))
        .to_vec();
    add(
        "score",
        scores,
        true,
        Box::new(move |b| {
            let text = String::from_utf8_lossy(b);
            let Ok(loaded) = timpanist::score::LoadedScore::parse(path, &text) else {
                return false;
            };
            // A score that loads must also survive what is built on it.
            let _ = loaded.score.duration_s();
            let _ = loaded.score.problems(&loaded.kit);
            use timpanist::motion::sticking::{Method, Params, assign};
            let _ = assign(
                &loaded.score,
                &loaded.kit,
                Method::Optimal,
                &Params::default(),
            );
            true
        }),
    );
    add(
        "kit",
        ["kits/standard.ron", "kits/pair.ron"].map(read).to_vec(),
        true,
        Box::new(move |b| Kit::parse(path, &String::from_utf8_lossy(b)).is_ok()),
    );
    let midi_kit = kit.clone();
    add(
        "midi",
        vec![read("tests/fixtures/bwv248-64-6.mid")],
        false,
        Box::new(move |b| {
            let options = timpanist::io::midi_import::ImportOptions::default();
            timpanist::io::midi_import::import(path, b, &midi_kit, &options).is_ok()
        }),
    );
    let xml_kit = kit.clone();
    // The Bach movement's MusicXML, unpacked (mutating the zip would only test its CRC).
    let mxl = std::fs::File::open(root().join("tests/data/bwv248.64-6.mxl")).unwrap();
    let mut archive = zip::ZipArchive::new(mxl).unwrap();
    let mut xml = Vec::new();
    std::io::Read::read_to_end(&mut archive.by_name("bwv248.64-6.xml").unwrap(), &mut xml).unwrap();
    // With small documents of the MusicXML test suite (repeat endings, ties, chords,
    // backups, pickups, mixed meters, tempo marks): quick to parse, so the long runs
    // reach millions, and each reaches other paths than the Bach.
    let mut xml_seeds = vec![xml];
    for name in [
        "45b-RepeatWithAlternatives.xml",
        "33b-Spanners-Tie.xml",
        "21a-Chord-Basic.xml",
        "03b-Rhythm-Backup.xml",
        "46d-PickupMeasure-ImplicitMeasures.xml",
        "11e-TimeSignatures-CompoundMixed.xml",
        "31c-MetronomeMarks.xml",
    ] {
        // Their parts named as a timpani part, so the import takes them.
        let text = String::from_utf8(read(&format!(
            "tests/data/musicxml-testsuite/xmlFiles/{name}"
        )))
        .unwrap();
        let named = named_timpani(&text);
        xml_seeds.push(named.into_bytes());
    }
    add(
        "musicxml",
        xml_seeds,
        false,
        Box::new(move |b| {
            let options = timpanist::io::musicxml::ImportOptions::default();
            timpanist::io::musicxml::import(path, b, &xml_kit, &options).is_ok()
        }),
    );
    use timpanist::mocap::import::{Format, read_bytes};
    let capture = |name, format: Format, seeds: Vec<Vec<u8>>, text| {
        (
            name,
            seeds,
            text,
            Box::new(move |b: &[u8]| read_bytes(path, b, format).is_ok()) as Parser,
        )
    };
    for (name, seeds, text, run) in [
        capture(
            "c3d",
            Format::C3d,
            vec![read("tests/fixtures/c3d/ezc3d_Optotrak.c3d")],
            false,
        ),
        capture(
            "motive",
            Format::Motive,
            vec![read("tests/fixtures/motive/timpani_roll_250hz.csv")],
            true,
        ),
        capture(
            "vicon",
            Format::Vicon,
            vec![read("tests/fixtures/vicon/timpani_strokes_100hz.csv")],
            true,
        ),
        capture(
            "plain-csv",
            Format::Csv,
            vec![read("tests/fixtures/csv/two_sticks_250hz.csv")],
            true,
        ),
        capture(
            "trc",
            Format::Trc,
            vec![read("tests/fixtures/capture/opensim_walk.trc")],
            true,
        ),
    ] {
        add(name, seeds, text, run);
    }
    use timpanist::mocap::import::profile::CaptureProfile;
    let six_d = CaptureProfile::shipped("qualisys-6d").expect("a shipped profile");
    add(
        "capture-table",
        vec![read("tests/fixtures/capture/qualisys_6d_100hz.tsv")],
        true,
        Box::new(move |b| timpanist::mocap::import::table::read(path, b, &six_d, None).is_ok()),
    );
    add(
        "capture-profile",
        vec![
            read("mocap/profiles/qualisys-6d.ron"),
            read("mocap/profiles/vicon.ron"),
        ],
        true,
        Box::new(move |b| CaptureProfile::parse(&String::from_utf8_lossy(b), path).is_ok()),
    );
    // Recordings: a small WAV, and the D2 note as FLAC, AIFF, MP3 and Ogg Vorbis
    // (tests/fixtures/recordings; all but the Ogg, which is read whole or not at all, cut
    // to their first packets so mutations reach the decoders, not only the headers).
    add(
        "recording",
        vec![
            small_wav(),
            recording_head("d2-note.flac", 16_000),
            recording_head("d2-note.aiff", 4000),
            recording_head("d2-note.mp3", 1500),
            recording_head("d2-note.ogg", usize::MAX),
        ],
        false,
        Box::new(move |b| timpanist::sound::recording::read_mono_bytes(path, b).is_ok()),
    );
    // A motion-database take, its zlib stream unpacked: inputs are the 24-byte header
    // and the raw varint channels, packed again before decoding, so the mutations reach
    // the channel decoding rather than the zlib checksum. The seed is the first take's
    // first 64 frames (decoded, cut and encoded again): every channel and the joints are
    // there, and an input is packed and unpacked ~10x faster than the whole take's.
    let take = std::fs::read_dir(root().join("mocap/takes"))
        .unwrap()
        .filter_map(Result::ok)
        .map(|e| e.path())
        .min()
        .unwrap();
    let mut excerpt =
        timpanist::mocap::db::decode_take(&take, &std::fs::read(&take).unwrap()).unwrap();
    const EXCERPT_FRAMES: usize = 64;
    assert!(excerpt.frames() > EXCERPT_FRAMES && excerpt.joints.is_some());
    for tip in &mut excerpt.tips {
        tip.truncate(EXCERPT_FRAMES);
    }
    if let Some(joints) = &mut excerpt.joints {
        joints.truncate(EXCERPT_FRAMES);
    }
    let packed = timpanist::mocap::db::encode_take(&excerpt);
    let mut raw = packed[..24].to_vec();
    std::io::Read::read_to_end(&mut flate2::read::ZlibDecoder::new(&packed[24..]), &mut raw)
        .unwrap();
    add(
        "tmot-take",
        vec![raw],
        false,
        Box::new(move |b| {
            let mut file = b[..b.len().min(24)].to_vec();
            if b.len() > 24 {
                let mut z = flate2::write::ZlibEncoder::new(file, flate2::Compression::fast());
                std::io::Write::write_all(&mut z, &b[24..]).unwrap();
                file = z.finish().unwrap();
            }
            timpanist::mocap::db::decode_take(path, &file).is_ok()
        }),
    );
    targets
}

/// `text` with the name of its first part (a MusicXML `<part-name>`, possibly empty or
/// self-closed) replaced by "Timpani".
fn named_timpani(text: &str) -> String {
    if let Some(start) = text.find("<part-name") {
        let end = match text[start..].find("/>") {
            Some(e) if !text[start..start + e].contains('>') => start + e + 2,
            _ => {
                start
                    + text[start..]
                        .find("</part-name>")
                        .expect("a closed part-name")
                    + 12
            }
        };
        return format!(
            "{}<part-name>Timpani</part-name>{}",
            &text[..start],
            &text[end..]
        );
    }
    text.to_string()
}

/// The first `bytes` of a recording fixture (readable: its decoders stop at the cut).
fn recording_head(name: &str, bytes: usize) -> Vec<u8> {
    let mut b = read(&format!("tests/fixtures/recordings/{name}"));
    b.truncate(bytes);
    b
}

/// A 20 ms stereo 16-bit WAV of a decaying 147 Hz tone.
fn small_wav() -> Vec<u8> {
    let spec = hound::WavSpec {
        channels: 2,
        sample_rate: 48_000,
        bits_per_sample: 16,
        sample_format: hound::SampleFormat::Int,
    };
    let mut bytes = std::io::Cursor::new(Vec::new());
    let mut w = hound::WavWriter::new(&mut bytes, spec).unwrap();
    for k in 0..960 {
        let t = f64::from(k) / 48_000.0;
        let v = (8000.0 * (-30.0 * t).exp() * (std::f64::consts::TAU * 147.0 * t).sin()) as i16;
        w.write_sample(v).unwrap();
        w.write_sample(v).unwrap();
    }
    w.finalize().unwrap();
    bytes.into_inner()
}

/// Numbers a text mutation puts in place of a number.
const ODD_NUMBERS: &[&str] = &[
    "0",
    "-1",
    "1e308",
    "-1e308",
    "NaN",
    "inf",
    "4294967296",
    "18446744073709551616",
    "",
    "0.0",
    "-0",
    "1e-320",
    "99999999999",
];

/// Bytes a mutation likes to write.
const ODD_BYTES: &[u8] = &[0x00, 0xFF, 0x7F, 0x80, 0x01, b'\n', b',', b'"', b'(', b')'];

fn pick(rng: &mut Rng, n: usize) -> usize {
    (rng.next_u64() % n.max(1) as u64) as usize
}

/// One mutation of `input` (with `other`, another seed, for splicing).
fn mutate(rng: &mut Rng, input: &mut Vec<u8>, other: &[u8], text: bool) {
    let len = input.len();
    let at = pick(rng, len + 1);
    match pick(rng, if text { 10 } else { 8 }) {
        0 if len > 0 => {
            let i = pick(rng, len);
            input[i] ^= 1 << pick(rng, 8);
        }
        1 if len > 0 => {
            let i = pick(rng, len);
            input[i] = ODD_BYTES[pick(rng, ODD_BYTES.len())];
        }
        2 => {
            let n = 1 + pick(rng, 8);
            for _ in 0..n {
                input.insert(at.min(input.len()), rng.next_u64() as u8);
            }
        }
        3 if len > 0 => {
            let end = (at + 1 + pick(rng, 64)).min(len);
            input.drain(at.min(len - 1)..end);
        }
        4 if len > 0 => {
            let start = pick(rng, len);
            let end = (start + 1 + pick(rng, 256)).min(len);
            let chunk = input[start..end].to_vec();
            let at = at.min(input.len());
            input.splice(at..at, chunk);
        }
        5 => input.truncate(at),
        6 if !other.is_empty() => {
            let start = pick(rng, other.len());
            let end = (start + 1 + pick(rng, 512)).min(other.len());
            let at = at.min(input.len());
            let cut = (at + pick(rng, 512)).min(input.len());
            input.splice(at..cut, other[start..end].iter().copied());
        }
        7 if len >= 4 => {
            // An integer field set to an extreme (little-endian, as C3D and .tmot are).
            let i = pick(rng, len - 3);
            let v: u32 = [0, u32::MAX, i32::MAX as u32, 0x8000_0000][pick(rng, 4)];
            input[i..i + 4].copy_from_slice(&v.to_le_bytes());
        }
        8 => mutate_number(rng, input),
        9 => mutate_line(rng, input),
        _ => input.push(ODD_BYTES[pick(rng, ODD_BYTES.len())]),
    }
}

/// Replace one run of digits (with its sign, point and exponent) by an odd number.
fn mutate_number(rng: &mut Rng, input: &mut Vec<u8>) {
    let starts: Vec<usize> = (0..input.len())
        .filter(|&i| input[i].is_ascii_digit() && (i == 0 || !input[i - 1].is_ascii_digit()))
        .collect();
    if starts.is_empty() {
        return;
    }
    let start = starts[pick(rng, starts.len())];
    let end = (start..input.len())
        .find(|&i| !(input[i].is_ascii_digit() || b".eE-+".contains(&input[i])))
        .unwrap_or(input.len());
    let odd = ODD_NUMBERS[pick(rng, ODD_NUMBERS.len())].as_bytes();
    input.splice(start..end, odd.iter().copied());
}

/// Drop or repeat one line.
fn mutate_line(rng: &mut Rng, input: &mut Vec<u8>) {
    let breaks: Vec<usize> = (0..input.len()).filter(|&i| input[i] == b'\n').collect();
    if breaks.len() < 2 {
        return;
    }
    let k = pick(rng, breaks.len() - 1);
    let (start, end) = (breaks[k] + 1, breaks[k + 1] + 1);
    if rng.next_u64().is_multiple_of(2) {
        input.drain(start..end);
    } else {
        let line = input[start..end].to_vec();
        input.splice(start..start, line);
    }
}

/// Every seed is accepted as it is, so the mutations start from inputs that reach deep.
#[test]
fn every_seed_is_accepted() {
    let mut refused = Vec::new();
    for target in targets() {
        for (k, seed) in target.seeds.iter().enumerate() {
            if !(target.run)(seed) {
                refused.push(format!("{} seed {k}", target.name));
            }
        }
    }
    assert!(refused.is_empty(), "refused: {}", refused.join(", "));
}

#[test]
fn no_parser_panics_on_mutated_inputs() {
    let runs = env_u64("TIMPANIST_FUZZ_RUNS", 300);
    let seed = env_u64("TIMPANIST_FUZZ_SEED", 1);
    let only = std::env::var("TIMPANIST_FUZZ_ONLY").ok();
    let chosen = |name: &str| {
        only.as_ref()
            .is_none_or(|o| o.split(',').any(|n| n.trim() == name))
    };
    let targets = targets();
    let names: Vec<&str> = targets.iter().map(|t| t.name).collect();
    assert!(
        names.iter().any(|n| chosen(n)),
        "TIMPANIST_FUZZ_ONLY names none of the parsers: {}",
        names.join(", ")
    );
    // Panics are expected to be caught here; keep their messages off the output.
    let quiet = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let mut crashes = Vec::new();
    for (t, target) in targets.iter().enumerate() {
        if !chosen(target.name) {
            continue;
        }
        let mut rng = Rng::new(seed).fork(t as u64);
        let started = std::time::Instant::now();
        let mut accepted = 0u64;
        for run in 0..runs {
            let s = pick(&mut rng, target.seeds.len());
            let mut input = target.seeds[s].clone();
            let other = &target.seeds[pick(&mut rng, target.seeds.len())];
            for _ in 0..1 + pick(&mut rng, 4) {
                mutate(&mut rng, &mut input, other, target.text);
            }
            let outcome = catch_unwind(AssertUnwindSafe(|| (target.run)(&input)));
            accepted += u64::from(matches!(outcome, Ok(true)));
            if outcome.is_err() {
                let dir = root().join("target/fuzz-crashes");
                std::fs::create_dir_all(&dir).unwrap();
                let file = dir.join(format!("{}-seed{seed}-run{run}.bin", target.name));
                std::fs::write(&file, &input).unwrap();
                crashes.push(format!(
                    "{}: run {run} panicked; input in {}",
                    target.name,
                    file.display()
                ));
                if crashes.len() > 20 {
                    break;
                }
            }
        }
        println!(
            "fuzz {:<16} {runs} inputs in {:.1} s, {:.0} % accepted",
            target.name,
            started.elapsed().as_secs_f64(),
            100.0 * accepted as f64 / runs.max(1) as f64
        );
        // The mutations must reach past the first check and also break things: a fuzzer
        // whose inputs all fail at once (or all pass) tests nothing.
        if target.name == "score" {
            assert!(
                accepted * 50 > runs && accepted * 10 < runs * 9,
                "score: {accepted} of {runs} mutated scores accepted"
            );
        }
    }
    std::panic::set_hook(quiet);
    assert!(
        crashes.is_empty(),
        "parsers panicked:\n{}",
        crashes.join("\n")
    );
}
