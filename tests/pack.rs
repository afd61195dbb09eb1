//! `timpanist export-pack` as a user runs it, and the pack read back independently of the
//! writers: every file `index.html` names is in the pack and every file of the pack is
//! named, every `src`/`href` resolves, nothing is fetched from the network, the SVG plots
//! are well-formed XML with their lines and markers, the WAVs read with hound (each phrase
//! a stretch of the mix), the numbers agree with `render`'s own files (the same writers);
//! an occupied folder is refused, `--force` replaces it, and a failure leaves nothing.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// `timpanist ARGS` run from the repository.
fn timpanist(args: &[&std::ffi::OsStr]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_timpanist"))
        .current_dir(root())
        .args(args)
        .output()
        .unwrap()
}

fn export_pack(score: &str, dir: &Path, extra: &[&str]) -> Output {
    let mut args: Vec<&std::ffi::OsStr> = vec!["export-pack".as_ref(), score.as_ref()];
    args.extend(["-o".as_ref(), dir.as_os_str()]);
    args.extend(extra.iter().map(std::ffi::OsStr::new));
    timpanist(&args)
}

fn ok(out: &Output) {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Every file below `dir`, relative, with `/`.
fn files_below(dir: &Path) -> BTreeSet<String> {
    fn walk(base: &Path, dir: &Path, out: &mut BTreeSet<String>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                walk(base, &path, out);
            } else {
                let rel = path.strip_prefix(base).unwrap();
                out.insert(rel.to_string_lossy().replace('\\', "/"));
            }
        }
    }
    let mut out = BTreeSet::new();
    walk(dir, dir, &mut out);
    out
}

/// The values of every `name="…"` attribute in `html`, in order.
fn attributes(html: &str, name: &str) -> Vec<String> {
    let key = format!(" {name}=\"");
    html.match_indices(&key)
        .map(|(i, _)| {
            let rest = &html[i + key.len()..];
            rest[..rest.find('"').unwrap()].replace("&amp;", "&")
        })
        .collect()
}

/// The elements named `tag` in `svg`'s tree.
fn count(svg: &roxmltree::Document, tag: &str) -> usize {
    svg.descendants()
        .filter(|n| n.tag_name().name() == tag)
        .count()
}

/// Interleaved 16-bit samples, rate and channels of a WAV.
fn wav(path: &Path) -> (Vec<i16>, u32, u16) {
    let mut reader = hound::WavReader::open(path).unwrap();
    let spec = reader.spec();
    assert_eq!(spec.bits_per_sample, 16, "{}", path.display());
    let samples = reader.samples::<i16>().map(Result::unwrap).collect();
    (samples, spec.sample_rate, spec.channels)
}

/// The etude's pack (16 strokes, 6 bars of 3/4): every referenced file exists, every file
/// is referenced, nothing external, plots parse and show their data, the phrases cut the
/// mix, the contacts table matches the CSV, and the motion, MIDI and mix are byte for
/// byte what `timpanist render` writes for the same score.
#[test]
fn the_etude_pack_is_complete_and_self_contained() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("etude pack");
    let out = export_pack("scores/etude-modes.ron", &dir, &[]);
    ok(&out);
    let stderr = String::from_utf8_lossy(&out.stderr);
    for step in ["pack: writing the audio", "pack: drawing the plots"] {
        assert!(stderr.contains(step), "no progress line {step:?}: {stderr}");
    }
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("index.html"), "{stdout}");

    let html = std::fs::read_to_string(dir.join("index.html")).unwrap();
    let files = files_below(&dir);
    // Every src and href resolves: a file of the pack, or an id on the page.
    let srcs = attributes(&html, "src");
    let hrefs = attributes(&html, "href");
    let ids: BTreeSet<String> = attributes(&html, "id").into_iter().collect();
    let mut named = BTreeSet::new();
    for target in srcs.iter().chain(&hrefs) {
        if let Some(id) = target.strip_prefix('#') {
            assert!(ids.contains(id), "link to a missing section #{id}");
        } else {
            assert!(!target.contains(':'), "not a relative path: {target}");
            assert!(!target.starts_with('/'), "not a relative path: {target}");
            assert!(
                files.contains(target),
                "{target} is named but not in the pack"
            );
            named.insert(target.clone());
        }
    }
    let unnamed: Vec<_> = files
        .iter()
        .filter(|f| *f != "index.html" && !named.contains(*f))
        .collect();
    assert!(
        unnamed.is_empty(),
        "files the page does not name: {unnamed:?}"
    );
    for kind in [
        "motion/performer.bvh",
        "motion/scene.glb",
        "motion/motion.c3d",
    ] {
        assert!(files.contains(kind), "{kind} missing");
    }
    // Self-contained: no address with a scheme, no external style sheet or script.
    for bad in [
        "http://",
        "https://",
        "\"//",
        "<link",
        "<script src",
        "url(",
    ] {
        assert!(!html.contains(bad), "index.html holds {bad:?}");
    }

    // Plots: SVG images that parse as XML, with the data drawn in them.
    let imgs: Vec<_> = srcs.iter().filter(|s| s.ends_with(".svg")).collect();
    assert_eq!(imgs.len(), 3, "three plots: {imgs:?}");
    let contacts_csv = std::fs::read_to_string(dir.join("data/contacts.csv")).unwrap();
    let contacts = contacts_csv.lines().count() - 1;
    assert!(contacts >= 16, "{contacts} contacts for 16 strokes");
    for img in &imgs {
        let text = std::fs::read_to_string(dir.join(img)).unwrap();
        let svg = roxmltree::Document::parse(&text)
            .unwrap_or_else(|e| panic!("{img} is not well-formed XML: {e}"));
        assert_eq!(svg.root_element().tag_name().name(), "svg", "{img}");
        let without_namespace = text.replace("xmlns=\"http://www.w3.org/2000/svg\"", "");
        assert!(!without_namespace.contains("http"), "{img} refers outside");
        let lines = count(&svg, "polyline") + count(&svg, "path");
        match img.as_str() {
            "plots/forces.svg" => assert!(
                count(&svg, "circle") >= contacts,
                "{img}: a marker per contact"
            ),
            _ => assert!(lines >= 2, "{img}: {lines} lines"),
        }
    }
    assert!(
        count(
            &roxmltree::Document::parse(
                &std::fs::read_to_string(dir.join("plots/tip-heights.svg")).unwrap()
            )
            .unwrap(),
            "polyline"
        ) >= 4 + 16,
        "four tip lines and a guide per stroke"
    );

    // Audio: the mix and each phrase read back; a phrase is a stretch of the mix.
    let (mix, rate, channels) = wav(&dir.join("audio/performance.wav"));
    assert_eq!((rate, channels), (48_000, 2));
    let phrases: Vec<_> = srcs
        .iter()
        .filter(|s| s.starts_with("audio/phrase-"))
        .collect();
    assert_eq!(
        phrases.len(),
        2,
        "6 bars in phrases of at most 4: {phrases:?}"
    );
    let audio_players = html.matches("<audio controls").count();
    assert_eq!(audio_players, 3, "the mix and two phrases");
    let mut total = 0;
    for p in &phrases {
        let (samples, r, c) = wav(&dir.join(p));
        assert_eq!((r, c), (48_000, 2));
        assert!(samples.len() > 2 * 48_000, "{p}: seconds of sound");
        total += samples.len();
        // Away from its fades, the phrase is the mix at some offset.
        let probe = &samples[samples.len() / 2..samples.len() / 2 + 64];
        let found = mix.windows(64).any(|w| w == probe);
        assert!(found, "{p} is not a stretch of the mix");
    }
    assert!(total <= mix.len(), "phrases overlap");
    let first = wav(&dir.join("audio/phrase-01.wav")).0;
    assert_eq!(first[0], 0, "a phrase fades in");
    assert_eq!(*first.last().unwrap(), 0, "a phrase fades out");

    // The per-stroke table holds the CSV's contacts, with the numbers.
    let rows = html.split("<table id=\"contacts\">").nth(1).unwrap();
    let rows = &rows[..rows.find("</table>").unwrap()];
    assert_eq!(rows.matches("<tr").count() - 1, contacts);
    for column in [
        "timing error (ms)",
        "contact time (ms)",
        "peak force (N)",
        "impact speed (m/s)",
    ] {
        assert!(rows.contains(column), "no column {column}");
    }
    let score_rows = html.split("<table id=\"score-table\">").nth(1).unwrap();
    let score_rows = &score_rows[..score_rows.find("</table>").unwrap()];
    assert_eq!(score_rows.matches("<tr").count() - 1, 16, "a row per beat");
    assert!(score_rows.contains("<td>5:1</td>"), "bar:beat positions");

    // The same writers as `render`: identical bytes.
    let r = tmp.path().join("render");
    std::fs::create_dir(&r).unwrap();
    let arg = |name: &str| r.join(name).into_os_string();
    let rendered = timpanist(&[
        "render".as_ref(),
        "scores/etude-modes.ron".as_ref(),
        "--wav".as_ref(),
        &arg("mix.wav"),
        "--motion".as_ref(),
        &arg("motion.csv"),
        "--bvh".as_ref(),
        &arg("performer.bvh"),
        "--performed-midi".as_ref(),
        &arg("performed.mid"),
    ]);
    ok(&rendered);
    for (pack_file, render_file) in [
        ("audio/performance.wav", "mix.wav"),
        ("motion/motion.csv", "motion.csv"),
        ("motion/performer.bvh", "performer.bvh"),
        ("midi/performed.mid", "performed.mid"),
    ] {
        let a = std::fs::read(dir.join(pack_file)).unwrap();
        let b = std::fs::read(r.join(render_file)).unwrap();
        assert!(a == b, "{pack_file} differs from render's {render_file}");
    }
}

/// A folder holding anything is refused before rendering, naming it, and left as it was;
/// `--force` replaces it once the new pack is complete (nothing else left beside it); an
/// empty folder is filled.
#[test]
fn an_occupied_folder_is_refused_unless_forced() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("lesson");
    std::fs::create_dir(&dir).unwrap();
    std::fs::write(dir.join("notes.txt"), "mine").unwrap();
    let out = export_pack("scores/improvisation.ron", &dir, &[]);
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains(&dir.display().to_string()) && stderr.contains("not empty"),
        "{stderr}"
    );
    assert!(
        !stderr.contains("simulating"),
        "refused after rendering: {stderr}"
    );
    assert_eq!(files_below(&dir), BTreeSet::from(["notes.txt".to_string()]));
    assert_eq!(std::fs::read_dir(tmp.path()).unwrap().count(), 1);

    ok(&export_pack("scores/improvisation.ron", &dir, &["--force"]));
    let files = files_below(&dir);
    assert!(!files.contains("notes.txt") && files.contains("index.html"));
    let beside: Vec<PathBuf> = std::fs::read_dir(tmp.path())
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    assert_eq!(
        beside,
        std::slice::from_ref(&dir),
        "nothing left beside the pack"
    );

    let empty = tmp.path().join("empty");
    std::fs::create_dir(&empty).unwrap();
    ok(&export_pack("scores/improvisation.ron", &empty, &[]));
    assert!(empty.join("index.html").is_file());
    assert!(empty.join("audio/phrase-01.wav").is_file());
}

/// A score that cannot be rendered leaves no folder and nothing beside it.
#[test]
fn a_failed_render_leaves_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let score = tmp.path().join("empty.ron");
    let mut empty = timpanist::score::Score::new("Nothing");
    empty.beats.clear();
    empty.save(&score).unwrap();
    let dir = tmp.path().join("out").join("pack");
    let out = timpanist(&[
        "export-pack".as_ref(),
        score.as_os_str(),
        "-o".as_ref(),
        dir.as_os_str(),
    ]);
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("error:"), "{stderr}");
    assert!(!dir.exists(), "a pack was left behind");
    assert!(
        !dir.parent().unwrap().exists(),
        "its folder was made for nothing"
    );
    let left = files_below(tmp.path());
    assert_eq!(left, BTreeSet::from(["empty.ron".to_string()]), "{left:?}");
}

/// A failure midway through writing (the motion cannot be written: it has no samples,
/// after the audio was) leaves no folder and no staging folder.
#[test]
fn a_failure_midway_leaves_no_partial_pack() {
    use timpanist::body::sim::{Motion, Reference};
    use timpanist::io::midi_performed::ForceScale;
    use timpanist::io::pack::{self, PackError};
    use timpanist::io::performance::Performance;
    let score = timpanist::score::demos::score("etude-modes").unwrap();
    let kit = timpanist::kit::Kit::bundled("standard").unwrap();
    let motion = Motion::new(250.0, [Vec::new(), Vec::new()], Vec::new());
    let reference = Reference::following(250.0, [Vec::new(), Vec::new()]);
    let audio = timpanist::sound::Audio {
        rate_hz: 48_000,
        channels: 2,
        samples: vec![0.1; 2 * 48_000 * 3].into(),
        gain: 1.0,
    };
    let performance = Performance {
        score: &score,
        kit: &kit,
        motion: &motion,
        reference: &reference,
        start_s: 0.0,
        skeleton: timpanist::body::skeleton::Skeleton::new(1.75, 0.38),
        audio: &audio,
        strokes: &[],
        contacts: Vec::new(),
        force_scale: ForceScale {
            at_silence_n: 10.0,
            range_n: 100.0,
        },
    };
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("pack");
    let mut steps = Vec::new();
    let err = pack::write(&performance, &dir, &pack::Options::default(), &mut |s| {
        steps.push(s.to_string())
    })
    .unwrap_err();
    assert!(matches!(err, PackError::Bvh(_)), "{err}");
    assert!(
        steps.iter().any(|s| s.contains("audio")),
        "failed before writing anything: {steps:?}"
    );
    assert!(!dir.exists(), "a partial pack was left");
    assert_eq!(std::fs::read_dir(tmp.path()).unwrap().count(), 0);
}
