//! MusicXML import: the real Bach chorale movement checked note by note, hand-written
//! snippets for each element read, malformed input, the whole MusicXML test suite (no
//! file may crash the importer), `import-musicxml` and `export-musicxml` through the
//! binary, `timpanist FILE` dispatch, and MIDI text in Shift-JIS and Latin-1.

use std::path::{Path, PathBuf};
use std::process::Command;
use timpanist::base::pitch::Pitch;
use timpanist::io::musicxml::{ImportOptions, ImportReport, MusicXmlError, import, import_file};
use timpanist::io::open::{self, FileKind, OpenAction, OpenError};
use timpanist::kit::Kit;
use timpanist::score::{Dynamic, Hand, PlayingMode, Roll, Score};

const DATA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data");
const FIXTURES: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures");

fn p(name: &str) -> Pitch {
    name.parse().unwrap()
}

/// A one-part partwise score named "Timpani" holding `measures` (the inner XML of each
/// `<measure>`, numbered from 1).
fn doc(measures: &[&str]) -> String {
    let body: String = measures
        .iter()
        .enumerate()
        .map(|(i, m)| format!("<measure number=\"{}\">{m}</measure>\n", i + 1))
        .collect();
    format!(
        r#"<?xml version="1.0" encoding="UTF-8"?>
<!DOCTYPE score-partwise PUBLIC "-//Recordare//DTD MusicXML 4.0 Partwise//EN" "http://www.musicxml.org/dtds/partwise.dtd">
<score-partwise version="4.0">
<part-list><score-part id="P1"><part-name>Timpani</part-name></score-part></part-list>
<part id="P1">
{body}</part>
</score-partwise>"#
    )
}

/// `<attributes>` with divisions and 4/4.
fn attrs(divisions: u32) -> String {
    format!(
        "<attributes><divisions>{divisions}</divisions><time><beats>4</beats><beat-type>4</beat-type></time></attributes>"
    )
}

/// A note: step+octave like "D3" or "Bb2", a duration in divisions, extra inner XML.
fn note(pitch: &str, duration: u32, extra: &str) -> String {
    let (step, rest) = pitch.split_at(1);
    let (alter, octave) = match rest.strip_prefix('b') {
        Some(o) => ("<alter>-1</alter>", o),
        None => match rest.strip_prefix('#') {
            Some(o) => ("<alter>1</alter>", o),
            None => ("", rest),
        },
    };
    format!(
        "<note><pitch><step>{step}</step>{alter}<octave>{octave}</octave></pitch><duration>{duration}</duration>{extra}</note>"
    )
}

fn rest(duration: u32) -> String {
    format!("<note><rest/><duration>{duration}</duration></note>")
}

fn run(xml: &str) -> (Score, ImportReport) {
    let kit = Kit::standard();
    let (score, report) = import(
        Path::new("snippet.musicxml"),
        xml.as_bytes(),
        &kit,
        &ImportOptions::default(),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    assert!(
        score.problems(&kit).is_empty(),
        "{:?}",
        score.problems(&kit)
    );
    (score, report)
}

/// Every timpani part in music21's own corpus (sixteen Bach movements in music21 9), when
/// python3 has music21: each imports with every note at music21's offset and pitch, repeats
/// expanded as music21 expands them (`tests/scripts/music21_corpus_timpani.py` lists them as
/// music21 reads them); skipped with a message without music21.
#[test]
fn music21_corpus_timpani_parts() {
    let script =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/scripts/music21_corpus_timpani.py");
    let Ok(o) = Command::new("python3").arg(&script).output() else {
        println!("skipped: no python3");
        return;
    };
    let stdout = String::from_utf8_lossy(&o.stdout);
    if !o.status.success()
        && String::from_utf8_lossy(&o.stderr).contains("No module named 'music21'")
    {
        println!("skipped: python3 with music21 is not installed (pip install music21)");
        return;
    }
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let kit = Kit::standard();
    let mut parts = 0;
    for line in stdout.lines() {
        let v: serde_json::Value = serde_json::from_str(line).unwrap();
        let path = PathBuf::from(v["path"].as_str().unwrap());
        let mut want: Vec<(i64, u8)> = (v["notes"].as_array().unwrap().iter())
            .map(|n| {
                let offset = n[0].as_f64().unwrap();
                (
                    (offset * 960.0).round() as i64,
                    n[1].as_u64().unwrap() as u8,
                )
            })
            .collect();
        let (score, _) =
            import_file(&path, &kit, &ImportOptions::default()).unwrap_or_else(|e| panic!("{e}"));
        let tpq = i64::from(score.ticks_per_quarter);
        let mut got: Vec<(i64, u8)> = (score.beats.iter())
            .map(|b| (b.tick as i64 * 960 / tpq, b.sounding_pitch(&kit).0))
            .collect();
        want.sort_unstable();
        got.sort_unstable();
        assert_eq!(got, want, "{}", path.display());
        println!(
            "{}: {} notes as music21 reads them",
            path.display(),
            got.len()
        );
        parts += 1;
    }
    assert!(
        parts >= 10,
        "only {parts} timpani parts in music21's corpus"
    );
}

/// (tick, sounding pitch) of every beat.
fn timeline(score: &Score) -> Vec<(u64, Pitch)> {
    let kit = Kit::standard();
    score
        .beats
        .iter()
        .map(|b| (b.tick, b.sounding_pitch(&kit)))
        .collect()
}

// ---- the Bach movement ----

/// Every timpani note of BWV 248/64 (the .mxl of the music21 corpus) at its time and
/// pitch: the 112 notes music21 reads (tests/fixtures), here from the MusicXML itself.
/// By hand from the XML: divisions 4; measure 0 is a one-quarter pickup (forward 2, rest
/// 2), measure 1 a whole rest, measure 2 starts at quarter 5 with an eighth rest, then
/// D3 A2 D3 A2 A2 in eighths: quarters 5.5, 6, 6.5, 7, 7.5. A2 goes to the 29-inch drum
/// (tuned Bb2, retuned to A2 and kept), D3 to the 26-inch drum (tuned D3).
#[test]
fn bach_timpani_part_note_by_note() {
    let kit = Kit::standard();
    let (score, report) = import_file(
        &Path::new(DATA).join("bwv248.64-6.mxl"),
        &kit,
        &ImportOptions::default(),
    )
    .unwrap();
    assert!(score.problems(&kit).is_empty());
    assert!(
        report.source.starts_with("part P4 \"Timpani\""),
        "{}",
        report.source
    );
    assert_eq!(report.notes, 112);
    assert_eq!((report.duplicates_dropped, report.octave_moves), (0, 0));
    assert_eq!(score.title, "bwv248.64-6");
    assert_eq!(score.ticks_per_quarter, 960);
    let tempo: Vec<(u64, f64)> = score.tempo.iter().map(|t| (t.tick, t.bpm)).collect();
    assert_eq!(tempo, vec![(0, 72.0)]);
    let meter: Vec<(u32, u32, u32)> = score
        .meter
        .iter()
        .map(|m| (m.bar, m.numerator, m.denominator))
        .collect();
    assert_eq!(meter, vec![(1, 1, 4), (2, 4, 4)], "the pickup is a 1/4 bar");
    assert!(
        report.notices.iter().any(|n| n.contains("pickup")),
        "{:?}",
        report.notices
    );
    let expected: Vec<(f64, u8)> =
        std::fs::read_to_string(Path::new(FIXTURES).join("bwv248-64-6.timpani.txt"))
            .unwrap()
            .lines()
            .filter(|l| !l.starts_with('#'))
            .map(|l| {
                let (o, m) = l.split_once(' ').unwrap();
                (o.parse().unwrap(), m.parse().unwrap())
            })
            .collect();
    assert_eq!(score.beats.len(), 112);
    for (b, &(offset, midi)) in score.beats.iter().zip(&expected) {
        assert_eq!(b.tick as f64, offset * 960.0, "{b:?}");
        assert_eq!(b.sounding_pitch(&kit), Pitch(midi), "{b:?}");
        let (drum, pitch) = if midi == 45 {
            (1, Some(p("A2")))
        } else {
            (2, None)
        };
        assert_eq!((b.drum, b.pitch), (drum, pitch), "{b:?}");
        assert_eq!(b.dynamic, Dynamic::Mf);
        assert_eq!(b.mode, PlayingMode::Legato);
        assert!(b.roll.is_none());
    }
    let first: Vec<(u64, Pitch)> = timeline(&score).into_iter().take(5).collect();
    assert_eq!(
        first,
        vec![
            (5280, p("D3")),
            (5760, p("A2")),
            (6240, p("D3")),
            (6720, p("A2")),
            (7200, p("A2"))
        ]
    );
}

// ---- snippets ----

/// A chord is two drums at once; a tie's later notes are no new strokes (across a bar
/// line too); the same pitch after the tie is.
#[test]
fn chords_and_ties() {
    let xml = doc(&[
        &format!(
            "{}{}{}{}{}",
            attrs(2),
            note("A2", 2, ""),
            note("D3", 2, "<chord/>"),
            note(
                "F3",
                4,
                "<tie type=\"start\"/><notations><tied type=\"start\"/></notations>"
            ),
            rest(2)
        ),
        &format!(
            "{}{}{}",
            note(
                "F3",
                2,
                "<tie type=\"stop\"/><notations><tied type=\"stop\"/></notations>"
            ),
            note("F3", 2, ""),
            rest(4)
        ),
    ]);
    let (score, report) = run(&xml);
    assert_eq!(
        timeline(&score),
        vec![(0, p("A2")), (0, p("D3")), (960, p("F3")), (4800, p("F3"))]
    );
    assert_ne!(score.beats[0].drum, score.beats[1].drum);
    assert_eq!(report.notes, 4);
}

/// Single-note tremolos roll with their stroke count (2 marks: 16ths, 3 marks: 32nds)
/// for the note's length; an unmeasured tremolo is a roll of 32nds, tied notes lengthen it.
#[test]
fn tremolos_are_rolls() {
    let trem = |t: &str, marks: u32| {
        format!(
            "<notations><ornaments><tremolo type=\"{t}\">{marks}</tremolo></ornaments></notations>"
        )
    };
    let xml = doc(&[
        &format!(
            "{}{}{}{}",
            attrs(1),
            note("D3", 2, &trem("single", 3)),
            note("D3", 1, &trem("single", 2)),
            rest(1)
        ),
        &note(
            "A2",
            4,
            &format!(
                "<tie type=\"start\"/>{}",
                trem("unmeasured", 0).replace("<notations>", "<notations><tied type=\"start\"/>")
            ),
        ),
        &note("A2", 2, "<tie type=\"stop\"/>"),
    ]);
    let (score, _) = run(&xml);
    let rolls: Vec<(u64, Option<Roll>)> = score.beats.iter().map(|b| (b.tick, b.roll)).collect();
    let roll = |length_ticks, strokes_per_quarter| {
        Some(Roll {
            length_ticks,
            strokes_per_quarter,
        })
    };
    assert_eq!(
        rolls,
        vec![
            (0, roll(1920, 8)),
            (1920, roll(960, 4)),
            (3840, roll(5760, 8))
        ]
    );
}

/// Dynamics are levels from where they stand; a crescendo hairpin rises linearly (in MIDI
/// velocity) to the marking that closes it; a diminuendo without one falls a step; sfz
/// accents one stroke and the level comes back.
#[test]
fn dynamics_and_hairpins() {
    let dir =
        |inner: &str| format!("<direction><direction-type>{inner}</direction-type></direction>");
    let xml = doc(&[
        &format!(
            "{}{}{}{}{}{}{}{}",
            attrs(1),
            dir("<dynamics><p/></dynamics>"),
            note("D3", 1, ""),
            dir("<wedge type=\"crescendo\"/>"),
            note("D3", 1, ""),
            note("D3", 1, ""),
            note("D3", 1, ""),
            dir("<wedge type=\"stop\"/>"),
        ),
        &format!(
            "{}{}{}{}{}{}{}",
            dir("<dynamics><f/></dynamics>"),
            note("D3", 1, ""),
            note(
                "D3",
                1,
                "<notations><dynamics><sfz/></dynamics></notations>"
            ),
            dir("<wedge type=\"diminuendo\"/>"),
            note("D3", 1, ""),
            dir("<wedge type=\"stop\"/>"),
            note("D3", 1, ""),
        ),
    ]);
    let (score, _) = run(&xml);
    let dynamics: Vec<Dynamic> = score.beats.iter().map(|b| b.dynamic).collect();
    let v = |x: f64| Dynamic::Velocity(x / 127.0);
    assert_eq!(
        dynamics,
        vec![
            Dynamic::P,
            Dynamic::P,
            v(49.0 + 47.0 / 3.0),
            v(49.0 + 2.0 * 47.0 / 3.0),
            Dynamic::F,
            Dynamic::F,  // sfz
            Dynamic::F,  // the diminuendo's start
            Dynamic::Mf  // a step down from f where it stops
        ]
    );
    assert_eq!(score.beats[5].mode, PlayingMode::Accent);
    assert_eq!(score.beats[4].mode, PlayingMode::Legato);
}

/// Accent, marcato (strong accent), staccato, tenuto; none is legato; the strongest of
/// several wins.
#[test]
fn articulations_are_modes() {
    let art = |a: &str| format!("<notations><articulations>{a}</articulations></notations>");
    let xml = doc(&[&format!(
        "{}{}{}{}{}{}{}{}{}",
        attrs(2),
        note("D3", 1, &art("<accent/>")),
        note("D3", 1, &art("<strong-accent type=\"up\"/>")),
        note("D3", 1, &art("<staccato/>")),
        note("D3", 1, &art("<tenuto/>")),
        note("D3", 1, ""),
        note("D3", 1, &art("<staccato/><accent/>")),
        note("D3", 1, &art("<staccatissimo/>")),
        note("D3", 1, &art("<breath-mark/>")),
    )]);
    let (score, report) = run(&xml);
    let modes: Vec<PlayingMode> = score.beats.iter().map(|b| b.mode).collect();
    use PlayingMode::*;
    assert_eq!(
        modes,
        vec![
            Accent,
            VerticalAccent,
            Staccato,
            Tenuto,
            Legato,
            Accent,
            Staccato,
            Legato
        ]
    );
    assert!(
        report.notices.iter().any(|n| n.contains("breath-mark")),
        "{:?}",
        report.notices
    );
}

/// `<sound tempo>` wins over the metronome mark beside it; a metronome alone counts in
/// its beat unit (dotted half = 40 is 120 quarters a minute); 120 bpm before any mark.
#[test]
fn tempo_marks() {
    let metro = |unit: &str, dots: usize, pm: &str| {
        format!(
            "<metronome><beat-unit>{unit}</beat-unit>{}<per-minute>{pm}</per-minute></metronome>",
            "<beat-unit-dot/>".repeat(dots)
        )
    };
    let xml = doc(&[
        &format!(
            "{}{}<direction><direction-type>{}</direction-type><sound tempo=\"60\"/></direction>",
            attrs(1),
            note("D3", 2, ""),
            metro("quarter", 0, "66")
        ),
        &format!("{}{}", note("D3", 2, ""), rest(2)),
        &format!(
            "<direction><direction-type>{}</direction-type></direction>{}",
            metro("half", 1, "c. 40"),
            rest(4)
        ),
        &format!("<sound tempo=\"90\"/>{}", rest(4)),
    ]);
    let (score, _) = run(&xml);
    let tempo: Vec<(u64, f64)> = score.tempo.iter().map(|t| (t.tick, t.bpm)).collect();
    // Measure 1 holds a half note (a 2/4 bar), measures 2 and 3 a whole bar each.
    assert_eq!(
        tempo,
        vec![(0, 120.0), (1920, 60.0), (5760, 120.0), (9600, 90.0)]
    );
}

/// Divisions may change between measures: 1, then 4 (eighths), then 3 (triplet eighths);
/// a part in 7 divisions gets 960 × 7 ticks per quarter, exactly.
#[test]
fn divisions_change() {
    let xml = doc(&[
        &format!("{}{}{}", attrs(1), note("D3", 2, ""), note("D3", 2, "")),
        &format!(
            "<attributes><divisions>4</divisions></attributes>{}{}{}",
            note("D3", 2, ""),
            note("D3", 2, ""),
            rest(12)
        ),
        &format!(
            "<attributes><divisions>3</divisions></attributes>{}{}{}{}",
            note("D3", 1, ""),
            note("D3", 1, ""),
            note("D3", 1, ""),
            rest(9)
        ),
    ]);
    let (score, _) = run(&xml);
    let ticks: Vec<u64> = score.beats.iter().map(|b| b.tick).collect();
    assert_eq!(ticks, vec![0, 1920, 3840, 4320, 7680, 8000, 8320]);
    let xml = doc(&[&format!(
        "{}{}{}",
        attrs(7),
        note("D3", 3, ""),
        note("D3", 25, "")
    )]);
    let (score, report) = run(&xml);
    assert_eq!(score.ticks_per_quarter, 6720);
    assert_eq!(score.beats[1].tick, 3 * 960);
    assert!(
        !report.notices.iter().any(|n| n.contains("<divisions>")),
        "{:?}",
        report.notices
    );
    // No <divisions> at all: read at one per quarter, and said, naming where.
    let xml = doc(&[&format!(
        "<attributes><time><beats>4</beats><beat-type>4</beat-type></time></attributes>{}{}",
        note("D3", 2, ""),
        note("D3", 2, "")
    )]);
    let (score, report) = run(&xml);
    assert_eq!(score.beats[1].tick, 2 * 960);
    assert!(
        report
            .notices
            .iter()
            .any(|n| n.contains("before any <divisions>") && n.contains("measure 1")),
        "{:?}",
        report.notices
    );
}

/// Two voices through `<backup>` and `<forward>`: both are read; a unison written in
/// both voices is one stroke.
#[test]
fn backup_forward_and_voices() {
    let v = |n: u32| format!("<voice>{n}</voice>");
    let xml = doc(&[&format!(
        "{}{}{}<backup><duration>8</duration></backup><forward><duration>2</duration></forward>{}{}<forward><duration>2</duration></forward>",
        attrs(2),
        note("D3", 4, &v(1)),
        note("D3", 4, &v(1)),
        note("A2", 2, &v(2)),
        note("D3", 2, &v(2)),
    )]);
    let (score, report) = run(&xml);
    assert_eq!(
        timeline(&score),
        vec![(0, p("D3")), (960, p("A2")), (1920, p("D3"))]
    );
    assert_eq!(report.duplicates_dropped, 1);
}

/// Grace notes are skipped and fermatas reported, each with its measure; the repeat
/// is played twice and said so.
#[test]
fn reported_not_performed() {
    let xml = doc(&[
        &format!(
            "{}<barline location=\"left\"><repeat direction=\"forward\"/></barline>{}{}{}",
            attrs(1),
            "<note><grace/><pitch><step>A</step><octave>2</octave></pitch></note>",
            note("D3", 2, "<notations><fermata/></notations>"),
            rest(2)
        ),
        &format!(
            "{}<barline location=\"right\"><repeat direction=\"backward\"/></barline>",
            rest(4)
        ),
    ]);
    let (score, report) = run(&xml);
    assert_eq!(timeline(&score), vec![(0, p("D3")), (7680, p("D3"))]);
    let all = report.notices.join("\n");
    assert!(
        all.contains("grace note: skipped (grace notes take no time) ×2 (the first in measure 1)"),
        "{all}"
    );
    assert!(all.contains("fermata"), "{all}");
    assert!(
        all.contains("repeats expanded: the 2 written measures are played as 4"),
        "{all}"
    );
}

/// A bar line (left or right) holding `inner`.
fn barline(location: &str, inner: &str) -> String {
    format!("<barline location=\"{location}\">{inner}</barline>")
}

/// Repeats and volta endings play in performed order: bar 1, |: bar 2 [1. bar 3 :|]
/// [2. bar 4] bar 5 |: bar 6 :| ×3 is bars 1 2 3 2 4 5 6 6 6, each a quarter note of its
/// own pitch in 1/4 (so a bar is 960 ticks); the 45a–45d files of the test suite expand
/// to the measure counts music21 gives them.
#[test]
fn repeats_and_endings_expand() {
    let one = "<attributes><divisions>1</divisions><time><beats>1</beats><beat-type>4</beat-type></time></attributes>";
    let pitches = ["C3", "D3", "E3", "F3", "G3", "A2"];
    let fwd = barline("left", "<repeat direction=\"forward\"/>");
    let measures = [
        format!("{one}{}", note(pitches[0], 1, "")),
        format!("{fwd}{}", note(pitches[1], 1, "")),
        format!(
            "{}{}{}",
            barline("left", "<ending number=\"1\" type=\"start\"/>"),
            note(pitches[2], 1, ""),
            barline(
                "right",
                "<ending number=\"1\" type=\"stop\"/><repeat direction=\"backward\"/>"
            )
        ),
        format!(
            "{}{}{}",
            barline("left", "<ending number=\"2\" type=\"start\"/>"),
            note(pitches[3], 1, ""),
            barline("right", "<ending number=\"2\" type=\"discontinue\"/>")
        ),
        note(pitches[4], 1, ""),
        format!(
            "{fwd}{}{}",
            note(pitches[5], 1, ""),
            barline("right", "<repeat direction=\"backward\" times=\"3\"/>")
        ),
    ];
    let refs: Vec<&str> = measures.iter().map(String::as_str).collect();
    let (score, report) = run(&doc(&refs));
    let want: Vec<(u64, Pitch)> = [0, 1, 2, 1, 3, 4, 5, 5, 5]
        .iter()
        .enumerate()
        .map(|(k, &m)| (960 * k as u64, p(pitches[m])))
        .collect();
    assert_eq!(timeline(&score), want);
    assert!(
        report
            .notices
            .iter()
            .any(|n| n == "repeats expanded: the 6 written measures are played as 9"),
        "{:?}",
        report.notices
    );
    assert!(!report.notices.iter().any(|n| n.contains("repeat sign")));

    // The test suite's repeat files: written and performed measures, as music21 10.5's
    // expandRepeats counts them (45c nests a times="5" repeat in a times="3" one).
    let kit = Kit::standard();
    let dir = Path::new(DATA).join("musicxml-testsuite/xmlFiles");
    for (name, written, played) in [
        ("45a-SimpleRepeat.xml", 2, 6),
        ("45b-RepeatWithAlternatives.xml", 4, 5),
        ("45c-RepeatMultipleTimes.xml", 8, 46),
        ("45d-Repeats-Nested-Alternatives.xml", 12, 16),
    ] {
        let opts = ImportOptions {
            part: Some("P1".into()),
            ..ImportOptions::default()
        };
        let (_, report) = import_file(&dir.join(name), &kit, &opts).unwrap();
        let expanded = format!("the {written} written measures are played as {played}");
        assert!(
            report.notices.iter().any(|n| n.contains(&expanded)),
            "{name}: {:?}",
            report.notices
        );
    }
}

/// Jumps are followed as music21 10.5's `expandRepeats` follows them (its notes for these
/// two documents, checked with it): D.C. al Fine written as words only plays bars 1 2 3 4
/// 1 2; a D.S. al Coda (sound attributes) after a repeat plays the repeat first, then goes
/// to the segno without repeating, takes the To Coda to the coda: 1 2 3 4 2 3 4 2 3 5 6.
/// Neither leaves a "not performed" notice for the jump marks.
#[test]
fn jumps_are_followed() {
    let one = "<attributes><divisions>1</divisions><time><beats>1</beats><beat-type>4</beat-type></time></attributes>";
    let words = |t: &str, sound: &str| {
        format!("<direction><direction-type><words>{t}</words></direction-type>{sound}</direction>")
    };
    let q = |pitch: &str| note(pitch, 1, "");
    let played = |xml: &str| -> Vec<Pitch> {
        let (score, report) = run(xml);
        let all = report.notices.join("\n");
        assert!(
            !all.contains("not performed") && !all.contains("not followed"),
            "{all}"
        );
        let ticks: Vec<u64> = score.beats.iter().map(|b| b.tick).collect();
        assert_eq!(
            ticks,
            (0..ticks.len() as u64).map(|k| k * 960).collect::<Vec<_>>()
        );
        timeline(&score).into_iter().map(|(_, p)| p).collect()
    };
    let dc = doc(&[
        &format!("{one}{}", q("D3")),
        &format!("{}{}", q("E3"), words("Fine", "")),
        &q("F3"),
        &format!("{}{}", q("G3"), words("D.C. al Fine", "")),
    ]);
    let want: Vec<Pitch> = ["D3", "E3", "F3", "G3", "D3", "E3"].map(p).to_vec();
    assert_eq!(played(&dc), want);

    let segno =
        "<direction><direction-type><segno/></direction-type><sound segno=\"s\"/></direction>";
    let coda = "<direction><direction-type><coda/></direction-type><sound coda=\"c\"/></direction>";
    let ds = doc(&[
        &format!("{one}{}", q("D3")),
        &format!(
            "{}{segno}{}",
            barline("left", "<repeat direction=\"forward\"/>"),
            q("E3")
        ),
        &format!("{}{}", q("F3"), words("To Coda", "<sound tocoda=\"c\"/>")),
        &format!(
            "{}{}{}",
            q("G3"),
            words("D.S. al Coda", "<sound dalsegno=\"s\"/>"),
            barline("right", "<repeat direction=\"backward\"/>")
        ),
        &format!("{coda}{}", q("A2")),
        &q("Bb2"),
    ]);
    let want: Vec<Pitch> = [
        "D3", "E3", "F3", "G3", "E3", "F3", "G3", "E3", "F3", "A2", "Bb2",
    ]
    .map(p)
    .to_vec();
    assert_eq!(played(&ds), want);
}

/// A two-note tremolo alternates its two drums at the rate of its marks plus the notes'
/// beams: two half notes (each written a whole, 2:1) with 3 marks fill a whole note with
/// 32 thirty-seconds, D3 first; two quarters typed eighths with 2 marks, 1 beam are 32nds
/// too; the first stroke on each drum keeps its note's accent.
#[test]
fn two_note_tremolos_alternate() {
    let trem = |t: &str, marks: u32| {
        format!(
            "<notations><ornaments><tremolo type=\"{t}\">{marks}</tremolo></ornaments></notations>"
        )
    };
    let half = "<type>whole</type><time-modification><actual-notes>2</actual-notes><normal-notes>1</normal-notes></time-modification>";
    let xml = doc(&[
        &format!(
            "{}{}{}",
            attrs(2),
            note("D3", 4, &format!("{half}{}", trem("start", 3))),
            note("A2", 4, &format!("{half}{}", trem("stop", 3))),
        ),
        &format!(
            "{}{}{}",
            note(
                "D3",
                1,
                &format!(
                    "<type>eighth</type>{}",
                    trem("start", 2).replace(
                        "</ornaments>",
                        "</ornaments><articulations><accent/></articulations>"
                    )
                )
            ),
            note("A2", 1, &format!("<type>eighth</type>{}", trem("stop", 2))),
            rest(6)
        ),
    ]);
    let (score, report) = run(&xml);
    let mut want: Vec<(u64, Pitch)> = (0..32)
        .map(|k| (120 * k, p(if k % 2 == 0 { "D3" } else { "A2" })))
        .collect();
    want.extend((0..8).map(|k| (3840 + 120 * k, p(if k % 2 == 0 { "D3" } else { "A2" }))));
    assert_eq!(timeline(&score), want);
    let modes: Vec<PlayingMode> = score.beats[32..35].iter().map(|b| b.mode).collect();
    assert_eq!(
        modes,
        [
            PlayingMode::Accent,
            PlayingMode::Legato,
            PlayingMode::Legato
        ]
    );
    assert!(
        !report.notices.iter().any(|n| n.contains("tremolo")),
        "{:?}",
        report.notices
    );
}

/// `<stopped/>` damps a note when it (with its tied notes) ends, a damped roll's
/// tremolo stops where its tied notes stop carrying the marks, and `<other-technical>`
/// R and L are the hands.
#[test]
fn stopped_and_stickings() {
    let tech = |inner: &str| format!("<notations><technical>{inner}</technical></notations>");
    let tied_trem = |tie: &str, tremolo: bool, extra: &str| {
        let trem = if tremolo {
            "<ornaments><tremolo type=\"single\">3</tremolo></ornaments>"
        } else {
            ""
        };
        let ties: String = tie
            .split(',')
            .map(|t| format!("<tied type=\"{t}\"/>"))
            .collect();
        let tie_el: String = tie
            .split(',')
            .map(|t| format!("<tie type=\"{t}\"/>"))
            .collect();
        format!("{tie_el}<notations>{ties}{trem}{extra}</notations>")
    };
    let xml = doc(&[
        &format!(
            "{}{}{}{}",
            attrs(2),
            note(
                "D3",
                1,
                &tech("<other-technical>L</other-technical><stopped/>")
            ),
            rest(1),
            note(
                "A2",
                6,
                &tied_trem(
                    "start",
                    true,
                    "<technical><other-technical>R</other-technical></technical>"
                )
            ),
        ),
        &format!(
            "{}{}{}",
            note("A2", 2, &tied_trem("stop,start", true, "")),
            note(
                "A2",
                2,
                &tied_trem("stop", false, "<technical><stopped/></technical>")
            ),
            rest(4)
        ),
    ]);
    let (score, _) = run(&xml);
    let got: Vec<(u64, Hand, Option<Roll>, Option<u64>)> = score
        .beats
        .iter()
        .map(|b| (b.tick, b.hand, b.roll, b.damp))
        .collect();
    assert_eq!(
        got,
        vec![
            (0, Hand::Left, None, Some(480)),
            (
                960,
                Hand::Right,
                Some(Roll {
                    length_ticks: 3840,
                    strokes_per_quarter: 8
                }),
                Some(960)
            ),
        ]
    );
}

// ---- trills ----

/// A beat's tick, roll and damping.
type Stroke = (u64, Option<Roll>, Option<u64>);

/// The (tick, roll, damping) of every beat of `measures` and the import's notices.
fn trills(measures: &[&str]) -> (Vec<Stroke>, Vec<String>) {
    let (score, report) = run(&doc(measures));
    let beats = (score.beats.iter())
        .map(|b| (b.tick, b.roll, b.damp))
        .collect();
    (beats, report.notices)
}

/// A roll of 8 strokes per quarter (the unmeasured tremolo's) lasting `length_ticks`.
fn free_roll(length_ticks: u64) -> Option<Roll> {
    Some(Roll {
        length_ticks,
        strokes_per_quarter: 8,
    })
}

/// `<tie>` and `<tied>` of these types, then `<type>` and the `<notations>` holding
/// `ornaments` and `more`, in the order notation programs write them.
fn tied(ties: &str, kind: &str, ornaments: &str, more: &str) -> String {
    let tie: String = (ties.split(',').filter(|t| !t.is_empty()))
        .map(|t| format!("<tie type=\"{t}\"/>"))
        .collect();
    let tied: String = (ties.split(',').filter(|t| !t.is_empty()))
        .map(|t| format!("<tied type=\"{t}\"/>"))
        .collect();
    let ornaments = if ornaments.is_empty() {
        String::new()
    } else {
        format!("<ornaments>{ornaments}</ornaments>")
    };
    format!(
        "{tie}<voice>1</voice><type>{kind}</type><notations>{tied}{ornaments}{more}</notations>"
    )
}

/// A `<wavy-line>` of this type, number 1.
fn wavy(kind: &str) -> String {
    format!("<wavy-line type=\"{kind}\" number=\"1\"/>")
}

/// A first measure (in 4/4, 2 divisions) holding a whole D3 with `ornaments`, tied on.
fn trilled_whole_d3(ornaments: &str) -> String {
    format!(
        "{}{}",
        attrs(2),
        note("D3", 8, &tied("start", "whole", ornaments, ""))
    )
}

/// A trill mark is a roll at the unmeasured tremolo's rate for the note's tied length:
/// with its wavy line starting on a whole note and stopping on the half note it is tied
/// to over the bar line; alone on the first of three tied notes; with an accidental mark
/// (the trill's upper note, nothing to a timpanist) on a quarter; alone on a quarter, and
/// with its wavy line starting and stopping on that one quarter.
#[test]
fn trill_marks_are_rolls() {
    let start = format!("<trill-mark placement=\"above\"/>{}", wavy("start"));
    // Over the bar line: a whole note tied to a half, the line stopping on the half.
    let (beats, notices) = trills(&[
        &trilled_whole_d3(&start),
        &format!(
            "{}{}",
            note("D3", 4, &tied("stop", "half", &wavy("stop"), "")),
            rest(4)
        ),
    ]);
    assert_eq!(beats, vec![(0, free_roll(5760), None)]);
    assert!(
        !notices
            .iter()
            .any(|n| n.contains("trill") || n.contains("wavy")),
        "{notices:?}"
    );
    // The mark on the first note only, no line: the roll lasts all three tied notes.
    let (beats, _) = trills(&[
        &format!(
            "{}{}{}",
            attrs(2),
            rest(4),
            note("A2", 4, &tied("start", "half", "<trill-mark/>", ""))
        ),
        &note("A2", 8, &tied("stop,start", "whole", "", "")),
        &format!(
            "{}{}",
            note("A2", 2, &tied("stop", "quarter", "", "")),
            rest(6)
        ),
    ]);
    assert_eq!(beats, vec![(1920, free_roll(6720), None)]);
    // A trill with an accidental mark, a trill alone, a trill with its line on one
    // quarter, then a plain quarter: three one-quarter rolls and a stroke.
    let (beats, notices) = trills(&[&format!(
        "{}{}{}{}{}",
        attrs(2),
        note(
            "F3",
            2,
            &tied(
                "",
                "quarter",
                "<trill-mark/><accidental-mark>flat</accidental-mark>",
                ""
            )
        ),
        note("D3", 2, &tied("", "quarter", "<trill-mark/>", "")),
        note(
            "A2",
            2,
            &tied("", "quarter", &format!("{start}{}", wavy("stop")), "")
        ),
        note("D3", 2, "<voice>1</voice><type>quarter</type>"),
    )]);
    assert_eq!(
        beats,
        vec![
            (0, free_roll(960), None),
            (960, free_roll(960), None),
            (1920, free_roll(960), None),
            (2880, None, None)
        ]
    );
    assert!(
        !notices
            .iter()
            .any(|n| n.contains("trill") || n.contains("wavy")),
        "{notices:?}"
    );
}

/// A wavy line stopping on the middle of three tied notes ends the roll there (the last
/// note rings on, here damped when it ends); a line stopping on the next note after the
/// roll is the roll's end, silently; one running on over later notes rolls them too (of the
/// trilled note's voice), each re-struck, up to the note it stops on.
#[test]
fn trill_wavy_lines_stop() {
    let start = format!("<trill-mark/>{}", wavy("start"));
    let (beats, notices) = trills(&[
        &trilled_whole_d3(&start),
        &note("D3", 8, &tied("stop,start", "whole", &wavy("stop"), "")),
        &format!(
            "{}{}",
            note(
                "D3",
                4,
                &tied("stop", "half", "", "<technical><stopped/></technical>")
            ),
            rest(4)
        ),
    ]);
    assert_eq!(beats, vec![(0, free_roll(7680), Some(1920))]);
    assert!(!notices.iter().any(|n| n.contains("wavy")), "{notices:?}");
    let (beats, notices) = trills(&[&format!(
        "{}{}{}{}{}",
        attrs(2),
        note("A2", 2, &tied("", "quarter", &start, "")),
        note("D3", 2, &tied("", "quarter", &wavy("stop"), "")),
        note("A2", 2, &tied("", "quarter", &start, "")),
        note("D3", 4, &tied("", "half", &wavy("stop"), "")),
    )]);
    assert_eq!(
        beats,
        vec![
            (0, free_roll(960), None),
            (960, None, None),
            (1920, free_roll(960), None),
            (2880, None, None)
        ]
    );
    assert!(!notices.iter().any(|n| n.contains("wavy")), "{notices:?}");
    let (beats, notices) = trills(&[&format!(
        "{}{}{}{}",
        attrs(2),
        note("A2", 2, &tied("", "quarter", &start, "")),
        note("D3", 2, "<voice>1</voice><type>quarter</type>"),
        note("F3", 4, &tied("", "half", &wavy("stop"), "")),
    )]);
    assert_eq!(
        beats,
        vec![
            (0, free_roll(960), None),
            (960, free_roll(960), None),
            (1920, None, None)
        ]
    );
    assert!(!notices.iter().any(|n| n.contains("wavy")), "{notices:?}");
    // A note of another voice under the line is not the trill's.
    let (beats, _) = trills(&[&format!(
        "{}{}{}{}",
        attrs(2),
        note("A2", 2, &tied("", "quarter", &start, "")),
        note("D3", 2, "<voice>2</voice><type>quarter</type>"),
        note("F3", 4, &tied("", "half", &wavy("stop"), "")),
    )]);
    let rolled: Vec<bool> = beats.iter().map(|b| b.1.is_some()).collect();
    assert_eq!(rolled, [true, false, false]);
}

/// A wavy line whose stop never comes: the roll lasts the trilled note's tied notes, and
/// a note says so.
#[test]
fn trill_wavy_line_never_stopping() {
    let start = "<trill-mark/><wavy-line type=\"start\" number=\"1\"/>";
    let (beats, notices) = trills(&[
        &format!(
            "{}{}{}",
            attrs(2),
            rest(4),
            note("F3", 4, &tied("start", "half", start, ""))
        ),
        &format!(
            "{}{}{}",
            note("F3", 2, &tied("stop", "quarter", "", "")),
            note("F3", 2, "<voice>1</voice><type>quarter</type>"),
            rest(4)
        ),
    ]);
    assert_eq!(
        beats,
        vec![(1920, free_roll(2880), None), (4800, None, None)]
    );
    let all = notices.join("\n");
    assert!(
        all.contains(
            "a trill's wavy line never stops: the roll ends with the notes tied to its trilled note (measure 1)"
        ),
        "{all}"
    );
}

/// The test suite's trills: 32aa's `tr` on a quarter (its unmeasured tremolo a roll as
/// before); 33a's trill on a quarter whose wavy line runs on over two more, untied, of the
/// same pitch and stops on the second (the first rolled too, re-struck; the second where
/// the line ends); 33f's on a sixteenth whose line runs on over a dotted quarter (rolled
/// too) to a grace note after it.
#[test]
fn test_suite_trills() {
    let kit = Kit::standard();
    let dir = Path::new(DATA).join("musicxml-testsuite/xmlFiles");
    let rolls = |name: &str| {
        let opts = ImportOptions {
            part: Some("P1".into()),
            ..ImportOptions::default()
        };
        let (score, report) = import_file(&dir.join(name), &kit, &opts).unwrap();
        assert!(score.problems(&kit).is_empty(), "{name}");
        let tpq = u64::from(score.ticks_per_quarter);
        let rolls: Vec<(u64, u64, u32)> = (score.beats.iter())
            .filter_map(|b| {
                let r = b.roll?;
                Some((
                    b.tick * 960 / tpq,
                    r.length_ticks * 960 / tpq,
                    r.strokes_per_quarter,
                ))
            })
            .collect();
        (rolls, report.notices.join("\n"))
    };
    let (got, notices) = rolls("32aa-Notations2_Ornaments.xml");
    assert_eq!(got, vec![(0, 960, 8), (10560, 960, 8)], "{notices}");
    assert!(!notices.contains("trill-mark"), "{notices}");
    let (got, notices) = rolls("33a-Spanners.xml");
    assert_eq!(got, vec![(14400, 960, 8), (15360, 960, 8)], "{notices}");
    assert!(
        !notices.contains("runs on past") && !notices.contains("trill-mark"),
        "{notices}"
    );
    let (got, notices) = rolls("33f-Trill-EndingOnGraceNote.xml");
    assert_eq!(got, vec![(1200, 240, 8), (1440, 1440, 8)], "{notices}");
    assert!(!notices.contains("runs on past"), "{notices}");
}

// ---- choosing the part ----

fn two_parts(first: &str, second: &str) -> String {
    let m = format!(
        "<measure number=\"1\">{}{}</measure>",
        attrs(1),
        note("D3", 4, "")
    );
    format!(
        r#"<score-partwise><part-list>
<score-part id="P1">{first}</score-part><score-part id="P2">{second}</score-part>
</part-list><part id="P1">{m}</part><part id="P2">{m}</part></score-partwise>"#
    )
}

/// The timpani part by its instrument sound, by MIDI program 48, by a name ("Pk."); else
/// the error lists the parts; `--part` by id or name.
#[test]
fn choosing_the_part() {
    let kit = Kit::standard();
    let go = |xml: &str, part: Option<&str>| {
        import(
            Path::new("parts.musicxml"),
            xml.as_bytes(),
            &kit,
            &ImportOptions {
                part: part.map(str::to_string),
                ..ImportOptions::default()
            },
        )
    };
    let violin = "<part-name>Violin</part-name>";
    let sound = "<part-name>Percussion 1</part-name><score-instrument id=\"I1\"><instrument-name>Kettledrums</instrument-name><instrument-sound>drum.timpani</instrument-sound></score-instrument>";
    let (_, r) = go(&two_parts(violin, sound), None).unwrap();
    assert!(
        r.source
            .starts_with("part P2 \"Percussion 1\": instrument sound drum.timpani"),
        "{}",
        r.source
    );
    let program = "<part-name>Kettle</part-name><midi-instrument id=\"I2\"><midi-program>48</midi-program></midi-instrument>";
    let (_, r) = go(&two_parts(program, violin), None).unwrap();
    assert!(
        r.source.contains("P1") && r.source.contains("program 48"),
        "{}",
        r.source
    );
    let (_, r) = go(&two_parts(violin, "<part-name>Pk.</part-name>"), None).unwrap();
    assert!(r.source.starts_with("part P2 \"Pk.\""), "{}", r.source);
    let err = go(&two_parts(violin, "<part-name>Viola</part-name>"), None).unwrap_err();
    assert!(matches!(err, MusicXmlError::NoTimpani { .. }));
    let text = err.to_string();
    assert!(
        text.starts_with("parts.musicxml: no timpani part found"),
        "{text}"
    );
    assert!(
        text.contains("part P1 \"Violin\": 1 notes") && text.contains("part P2 \"Viola\""),
        "{text}"
    );
    let (_, r) = go(
        &two_parts(violin, "<part-name>Viola</part-name>"),
        Some("P2"),
    )
    .unwrap();
    assert!(r.source.contains("--part \"P2\""), "{}", r.source);
    let (_, r) = go(
        &two_parts(violin, "<part-name>Viola</part-name>"),
        Some("viol"),
    )
    .unwrap();
    assert!(r.source.starts_with("part P1"), "{}", r.source);
    let err = go(&two_parts(violin, violin), Some("Tuba")).unwrap_err();
    assert!(err.to_string().contains("\"Tuba\""), "{err}");
}

/// Timpani parts named in other languages and abbreviations are found ("Kettledrums",
/// "Kettle Drums", "Tympani", "Tymp."), by whole words only: "Paukenschlag Violin" is no
/// timpani part. A score with no part at all says so instead of listing nothing.
#[test]
fn timpani_names_and_no_parts() {
    let kit = Kit::standard();
    let go = |xml: &str| {
        import(
            Path::new("names.musicxml"),
            xml.as_bytes(),
            &kit,
            &ImportOptions::default(),
        )
    };
    let violin = "<part-name>Violin</part-name>";
    for name in ["Kettledrums", "Kettle Drums", "Tympani", "Tymp."] {
        let (_, r) = go(&two_parts(
            violin,
            &format!("<part-name>{name}</part-name>"),
        ))
        .unwrap();
        assert!(
            r.source.starts_with(&format!("part P2 \"{name}\"")),
            "{}",
            r.source
        );
    }
    let err = go(&two_parts(
        violin,
        "<part-name>Paukenschlag Violin</part-name>",
    ))
    .unwrap_err();
    assert!(matches!(err, MusicXmlError::NoTimpani { .. }), "{err}");
    let empty = "<score-partwise version=\"4.0\"><part-list/></score-partwise>";
    let err = go(empty).unwrap_err().to_string();
    assert_eq!(
        err,
        "names.musicxml: the score holds no parts (its part list and its <part> elements are empty), so there is nothing to import"
    );
}

/// Tempo is the whole score's: marks written only in the top part (a `<sound tempo>` with
/// its metronome mark at bar 1, a bare metronome mark at an offset in bar 3) set the
/// timpani part's tempo; a mark of the timpani part's own (bar 2) still counts, and the
/// same mark written in both parts is one; the import says where the marks came from.
#[test]
fn tempo_marks_of_other_parts() {
    let metronome = |bpm: u32| {
        format!(
            "<direction-type><metronome><beat-unit>quarter</beat-unit><per-minute>{bpm}</per-minute></metronome></direction-type>"
        )
    };
    let bar = |dirs: &str, pitch: &str| format!("{dirs}{}", note(pitch, 4, ""));
    let top = [
        format!(
            "{}{}",
            attrs(1),
            bar(
                &format!(
                    "<direction>{}<sound tempo=\"66\"/></direction>",
                    metronome(66)
                ),
                "C5"
            )
        ),
        bar("<direction><sound tempo=\"90\"/></direction>", "C5"),
        format!(
            "<note><pitch><step>C</step><octave>5</octave></pitch><duration>2</duration></note><direction>{}</direction><note><pitch><step>C</step><octave>5</octave></pitch><duration>2</duration></note>",
            metronome(132)
        ),
    ];
    let timp = [
        format!("{}{}", attrs(1), bar("", "D3")),
        bar(&format!("<direction>{}</direction>", metronome(90)), "A2"),
        bar("", "D3"),
    ];
    let part = |id: &str, ms: &[String]| {
        let body: String = ms
            .iter()
            .enumerate()
            .map(|(i, m)| format!("<measure number=\"{}\">{m}</measure>", i + 1))
            .collect();
        format!("<part id=\"{id}\">{body}</part>")
    };
    let xml = format!(
        r#"<score-partwise version="4.0"><part-list>
<score-part id="P1"><part-name>Violin</part-name></score-part><score-part id="P2"><part-name>Timpani</part-name></score-part>
</part-list>{}{}</score-partwise>"#,
        part("P1", &top),
        part("P2", &timp)
    );
    let (score, report) = run(&xml);
    let tpq = u64::from(score.ticks_per_quarter);
    let tempo: Vec<(u64, f64)> = score.tempo.iter().map(|t| (t.tick, t.bpm)).collect();
    assert_eq!(tempo, vec![(0, 66.0), (4 * tpq, 90.0), (10 * tpq, 132.0)]);
    assert!(
        report
            .notices
            .iter()
            .any(|n| n.starts_with("tempo mark written in another part")
                && n.contains("part P1 \"Violin\", measure 1")),
        "{:?}",
        report.notices
    );
}

// ---- bad input ----

/// Malformed XML names the file, line and column; a bad value names the line and
/// measure; an .mxl that is no zip, a corrupt zip and a missing file name the file.
#[test]
fn malformed_input_errors() {
    let kit = Kit::standard();
    let opts = ImportOptions::default();
    let err = |name: &str, bytes: &[u8]| {
        import(Path::new(name), bytes, &kit, &opts)
            .unwrap_err()
            .to_string()
    };
    let truncated = doc(&[&note("D3", 1, "")]);
    let truncated = &truncated[..truncated.len() - 30];
    let e = err("cut.musicxml", truncated.as_bytes());
    assert!(
        e.starts_with("cut.musicxml:6:") && e.contains("malformed XML"),
        "{e}"
    );
    let bad_duration = doc(&[&format!(
        "{}{}",
        attrs(1),
        note("D3", 1, "").replace(">1<", ">one<")
    )]);
    let e = err("dur.musicxml", bad_duration.as_bytes());
    assert!(
        e.starts_with("dur.musicxml:6: measure 1: <duration> \"one\""),
        "{e}"
    );
    let e = err("x.musicxml", b"<html><body/></html>");
    assert!(
        e.contains("not a MusicXML score") && e.contains("<html>"),
        "{e}"
    );
    // Uncompressed XML under an .mxl name is read as XML (here an empty score).
    let e = err("plain.mxl", b"<score-partwise/>");
    assert!(e.starts_with("plain.mxl: the score holds no parts"), "{e}");
    let e = err("not-zip.mxl", b"\x00\x01 neither");
    assert!(
        e.starts_with("not-zip.mxl: not a readable compressed MusicXML"),
        "{e}"
    );
    let mxl = std::fs::read(Path::new(DATA).join("bwv248.64-6.mxl")).unwrap();
    let e = err("cut.mxl", &mxl[..mxl.len() / 2]);
    assert!(
        e.starts_with("cut.mxl: not a readable compressed MusicXML"),
        "{e}"
    );
    let e = import_file(Path::new("/nonexistent/score.mxl"), &kit, &opts)
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("/nonexistent/score.mxl: cannot read the file"),
        "{e}"
    );
}

/// A compressed MusicXML archive holding `xml` as `name`, named by its container.
fn mxl_of(name: &str, xml: &[u8]) -> Vec<u8> {
    use std::io::Write as _;
    let container = format!(
        r#"<?xml version="1.0" encoding="UTF-8"?><container><rootfiles><rootfile full-path="{name}"/></rootfiles></container>"#
    );
    let deflated = zip::write::SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Deflated);
    let mut zip = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    for (entry, bytes) in [
        ("META-INF/container.xml", container.as_bytes()),
        (name, xml),
    ] {
        zip.start_file(entry, deflated).unwrap();
        zip.write_all(bytes).unwrap();
    }
    zip.finish().unwrap().into_inner()
}

/// A zip bomb is refused: a score padded (inside an XML comment) to one byte past the
/// 64 MiB an `.mxl` entry may unpack to names the file and the entry, the archive itself
/// being a few hundred kB; the same score padded to exactly 64 MiB imports.
#[test]
fn mxl_entries_past_64_mib_are_refused() {
    const LIMIT: usize = 64 << 20;
    let kit = Kit::standard();
    let opts = ImportOptions::default();
    let score = doc(&[&format!("{}{}", attrs(1), note("D3", 4, ""))]);
    let padded = |len: usize| {
        let pad = len - score.len() - "<!---->".len();
        format!("{score}<!--{}-->", " ".repeat(pad)).into_bytes()
    };
    let bomb = mxl_of("score.musicxml", &padded(LIMIT + 1));
    assert!(bomb.len() < 1 << 20, "{} bytes", bomb.len());
    let e = import(Path::new("bomb.mxl"), &bomb, &kit, &opts).unwrap_err();
    assert!(matches!(e, MusicXmlError::EntryTooLarge { .. }), "{e:?}");
    assert_eq!(
        e.to_string(),
        "bomb.mxl: score.musicxml expands past 64 MiB: not a score?"
    );
    let full = mxl_of("score.musicxml", &padded(LIMIT));
    let (score, _) = import(Path::new("full.mxl"), &full, &kit, &opts).unwrap();
    assert_eq!(score.beats.len(), 1);
}

/// Every file of the MusicXML test suite either imports into a playable score or fails
/// with an error naming it; none panics. Files without a timpani part are read with
/// `--part` set to their first part.
#[test]
fn whole_test_suite_never_crashes() {
    let kit = Kit::standard();
    let dir = Path::new(DATA).join("musicxml-testsuite/xmlFiles");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    files.sort();
    assert_eq!(files.len(), 150);
    let (mut imported, mut errors) = (Vec::new(), Vec::new());
    for f in &files {
        let mut result = import_file(f, &kit, &ImportOptions::default());
        if let Err(MusicXmlError::NoTimpani { parts, .. }) = &result {
            let first = parts.lines().next().unwrap().trim();
            let id = first
                .strip_prefix("part ")
                .unwrap()
                .split([' ', ':'])
                .next()
                .unwrap();
            let opts = ImportOptions {
                part: Some(id.to_string()),
                ..ImportOptions::default()
            };
            result = import_file(f, &kit, &opts);
        }
        match result {
            Ok((score, _)) => {
                assert!(
                    score.problems(&kit).is_empty(),
                    "{}: {:?}",
                    f.display(),
                    score.problems(&kit)
                );
                imported.push(f);
            }
            Err(e) => {
                let name = f.file_name().unwrap().to_string_lossy();
                assert!(e.to_string().contains(&*name), "{e}");
                errors.push(e.to_string());
            }
        }
    }
    println!(
        "{} imported, {} clean errors: {errors:#?}",
        imported.len(),
        errors.len()
    );
    // The one malformed file of the suite (a </part> closes an open <measure>).
    assert_eq!(errors.len(), 1, "{errors:#?}");
    assert!(errors[0].contains("32ad-Notations5.musicxml:141:3: malformed XML"));
}

/// Snippets of the test suite read as a timpanist would: 21a (a chord of three notes:
/// the two loudest — here the first two — kept), 03c (divisions changes), 90a (.mxl).
#[test]
fn test_suite_files() {
    let kit = Kit::standard();
    let dir = Path::new(DATA).join("musicxml-testsuite/xmlFiles");
    let read = |name: &str, part: &str| {
        let opts = ImportOptions {
            part: Some(part.into()),
            ..ImportOptions::default()
        };
        import_file(&dir.join(name), &kit, &opts).unwrap()
    };
    let (score, report) = read("90a-Compressed-MusicXML.mxl", "P1");
    assert_eq!(score.beats.len(), 4, "{report:?}");
    let (score, _) = read("03c-Rhythm-DivisionChange.xml", "P1");
    assert!(score.beats.windows(2).all(|w| w[0].tick < w[1].tick));
}

// ---- the binary ----

fn timpanist(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_timpanist"))
        .args(args)
        .output()
        .unwrap()
}

/// `import-musicxml` writes a score that checks; a file without a timpani part fails
/// with the parts listed and writes nothing.
#[test]
fn cli_import_musicxml() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("bach.ron");
    let bach = Path::new(DATA).join("bwv248.64-6.mxl");
    let o = timpanist(&[
        "import-musicxml",
        bach.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(stdout.contains("112 beats from part P4"), "{stdout}");
    assert!(String::from_utf8_lossy(&o.stderr).contains("note: pickup measure"));
    let loaded = timpanist::score::LoadedScore::load(&out).unwrap();
    assert_eq!(loaded.score.beats.len(), 112);
    let no_timp = Path::new(DATA).join("musicxml-testsuite/xmlFiles/21a-Chord-Basic.xml");
    let out2 = tmp.path().join("none.ron");
    let o = timpanist(&[
        "import-musicxml",
        no_timp.to_str().unwrap(),
        "-o",
        out2.to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        stderr.contains("no timpani part found") && stderr.contains("part P0"),
        "{stderr}"
    );
    assert!(!out2.exists());
    let o = timpanist(&[
        "import-musicxml",
        no_timp.to_str().unwrap(),
        "-o",
        out2.to_str().unwrap(),
        "--part",
        "P0",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// `export-musicxml` writes plain text or a `.mxl` archive with its container; a
/// missing score or an unwritable target fails naming the file and leaves nothing.
#[test]
fn cli_export_musicxml() {
    let tmp = tempfile::tempdir().unwrap();
    let score = Path::new(env!("CARGO_MANIFEST_DIR")).join("scores/roll-exercise.ron");
    let plain = tmp.path().join("roll.musicxml");
    let o = timpanist(&[
        "export-musicxml",
        score.to_str().unwrap(),
        "-o",
        plain.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stdout).contains("22 beats"));
    let loaded = timpanist::score::LoadedScore::load(&score).unwrap();
    assert_eq!(
        std::fs::read_to_string(&plain).unwrap(),
        timpanist::io::musicxml_export::export(&loaded.score, &loaded.kit)
    );
    let mxl = tmp.path().join("roll.mxl");
    let o = timpanist(&[
        "export-musicxml",
        score.to_str().unwrap(),
        "-o",
        mxl.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let bytes = std::fs::read(&mxl).unwrap();
    let mut zip = zip::ZipArchive::new(std::io::Cursor::new(&bytes)).unwrap();
    let names: Vec<String> = zip.file_names().map(|n| n.unwrap().into_owned()).collect();
    assert_eq!(
        names,
        ["mimetype", "META-INF/container.xml", "score.musicxml"]
    );
    let mut container = String::new();
    std::io::Read::read_to_string(
        &mut zip.by_name("META-INF/container.xml").unwrap(),
        &mut container,
    )
    .unwrap();
    assert!(container.contains("full-path=\"score.musicxml\""));
    let (back, _) = import(
        Path::new("roll.mxl"),
        &bytes,
        &loaded.kit,
        &ImportOptions::default(),
    )
    .unwrap();
    assert_eq!(back.beats.len(), 22);

    let missing = tmp.path().join("none.ron");
    let out = tmp.path().join("none.musicxml");
    let o = timpanist(&[
        "export-musicxml",
        missing.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("none.ron"));
    assert!(!out.exists());
    let o = timpanist(&[
        "export-musicxml",
        score.to_str().unwrap(),
        "-o",
        "/no/such/dir/x.musicxml",
    ]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("/no/such/dir/x.musicxml"));
    let left: Vec<_> = std::fs::read_dir(tmp.path()).unwrap().collect();
    assert_eq!(left.len(), 2, "no temporary files: {left:?}");
}

// ---- timpanist FILE ----

/// `timpanist FILE`: a score is edited, MIDI and MusicXML files are imported; a missing
/// or unknown file is refused naming it. Reading an import gives an unsaved document.
#[test]
fn file_dispatch() {
    let mid = Path::new(FIXTURES).join("bwv248-64-6.mid");
    let mxl = Path::new(DATA).join("bwv248.64-6.mxl");
    let ron = Path::new(env!("CARGO_MANIFEST_DIR")).join("scores/etude-modes.ron");
    assert_eq!(
        open::action_for(&ron).unwrap(),
        OpenAction::Edit(ron.clone())
    );
    assert_eq!(
        open::action_for(&mid).unwrap(),
        OpenAction::Import(mid.clone(), FileKind::Midi)
    );
    assert_eq!(
        open::action_for(&mxl).unwrap(),
        OpenAction::Import(mxl.clone(), FileKind::MusicXml)
    );
    assert!(matches!(
        open::action_for(Path::new("/nope/a.mid")),
        Err(OpenError::Missing(_))
    ));
    assert!(matches!(
        open::action_for(&Path::new(DATA).join("LICENSE-music21-corpus.txt")),
        Err(OpenError::NotAScore(_))
    ));
    for file in [&mid, &mxl] {
        let opened = open::read(file).unwrap();
        assert_eq!(opened.path, None, "an import is unsaved");
        assert_eq!(opened.loaded.score.beats.len(), 112);
    }
    let o = timpanist(&["/nope/a.mid"]);
    assert!(!o.status.success());
    assert_eq!(
        String::from_utf8_lossy(&o.stderr).trim(),
        "error: /nope/a.mid: no such file"
    );
    let tmp = tempfile::tempdir().unwrap();
    let bad = tmp.path().join("bad.musicxml");
    std::fs::write(&bad, "<score-partwise><part-list>").unwrap();
    let o = timpanist(&[bad.to_str().unwrap()]);
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("bad.musicxml:1:"));
}

// ---- MIDI text encodings ----

fn midi_titled(title: &[u8]) -> Vec<u8> {
    use midly::num::{u4, u7, u15, u28};
    use midly::{
        Format, Header, MetaMessage, MidiMessage, Smf, Timing, TrackEvent, TrackEventKind,
    };
    let ev = |kind| TrackEvent {
        delta: u28::new(0),
        kind,
    };
    let end = ev(TrackEventKind::Meta(MetaMessage::EndOfTrack));
    let smf = Smf {
        header: Header::new(Format::Parallel, Timing::Metrical(u15::new(480))),
        tracks: vec![
            vec![ev(TrackEventKind::Meta(MetaMessage::TrackName(title))), end],
            vec![
                ev(TrackEventKind::Midi {
                    channel: u4::new(0),
                    message: MidiMessage::ProgramChange {
                        program: u7::new(47),
                    },
                }),
                ev(TrackEventKind::Midi {
                    channel: u4::new(0),
                    message: MidiMessage::NoteOn {
                        key: u7::new(50),
                        vel: u7::new(80),
                    },
                }),
                end,
            ],
        ],
    };
    let mut out = Vec::new();
    smf.write_std(&mut out).unwrap();
    out
}

/// Titles in UTF-8, Shift-JIS and Latin-1 read as written; undecodable text gives the
/// file name.
#[test]
fn midi_titles_in_legacy_encodings() {
    use timpanist::io::midi_import;
    let kit = Kit::standard();
    let title = |bytes: &[u8]| {
        let midi = midi_titled(bytes);
        let (score, _) = midi_import::import(
            Path::new("dir/song.mid"),
            &midi,
            &kit,
            &midi_import::ImportOptions::default(),
        )
        .unwrap();
        score.title
    };
    let (sjis, _, bad) = encoding_rs::SHIFT_JIS.encode("ティンパニ協奏曲 第1番");
    assert!(!bad && std::str::from_utf8(&sjis).is_err());
    assert_eq!(title(&sjis), "ティンパニ協奏曲 第1番");
    assert_eq!(
        title(b"Pi\xe8ce pour timbales \xe0 Fran\xe7ois"),
        "Pièce pour timbales à François"
    );
    assert_eq!(title("Ouvertüre".as_bytes()), "Ouvertüre");
    // Bytes that are Shift-JIS without any Japanese letter are Latin-1: "Åbo".
    assert_eq!(title(b"\xc5bo"), "Åbo");
    assert_eq!(title(b"\x01\x02\x03"), "song");
    assert_eq!(midi_import::decode_text(b"caf\xe9"), "café");
}

/// A timpani part of rests only is said to have no notes (it was "no timpani part found
/// … no part named Timpani", listing the part named Timpani); uncompressed MusicXML saved
/// under an `.mxl` name is read as what it is, with a notice.
#[test]
fn a_rests_only_part_and_plain_xml_named_mxl() {
    let kit = Kit::standard();
    let rests = doc(&[&format!("{}{}", attrs(1), rest(4))]);
    let err = import(
        Path::new("rests.musicxml"),
        rests.as_bytes(),
        &kit,
        &ImportOptions::default(),
    )
    .map(|_| ())
    .unwrap_err()
    .to_string();
    assert!(
        err.contains("rests.musicxml: the timpani part (")
            && err.contains("has no notes (rests only)"),
        "{err}"
    );
    let xml = doc(&[&format!(
        "{}{}{}",
        attrs(1),
        note("D3", 2, ""),
        note("A2", 2, "")
    )]);
    let (score, report) = import(
        Path::new("plain.mxl"),
        xml.as_bytes(),
        &kit,
        &ImportOptions::default(),
    )
    .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(score.beats.len(), 2);
    assert!(
        report
            .notices
            .iter()
            .any(|n| n.contains("holds uncompressed MusicXML")),
        "{:?}",
        report.notices
    );
    let err = import(
        Path::new("junk.mxl"),
        b"not xml, not zip",
        &kit,
        &ImportOptions::default(),
    )
    .map(|_| ())
    .unwrap_err()
    .to_string();
    assert!(err.contains("not a zip archive"), "{err}");
}
