//! MusicXML export: a score's timpani part as a partwise MusicXML 4.0 document (plain
//! text, or the compressed `.mxl` zip with its `META-INF/container.xml`), for notation
//! programs (MuseScore, Finale, Dorico, music21) and back into [`super::musicxml`].
//!
//! One part "Timpani" (instrument sound `drum.timpani`, General MIDI program 48 on the
//! first channel) on a bass staff; `<divisions>` are the score's ticks per quarter
//! reduced by every time written. Measures follow the meter map (a `<time>` where the signature changes).
//! Each beat is a note at its sounding pitch; beats at the same tick are a `<chord/>`. A
//! note lasts to the next beat or the end of its bar, whichever comes first (a roll: its
//! length; a damped beat: until the damping touch, marked `<stopped/>`), rests fill the
//! rest, and a note crossing a bar line is split with ties. Durations are written as
//! plain or dotted note values; a length that is none of them keeps its exact
//! `<duration>` with the nearest `<type>`. Playing modes are articulations (accent,
//! strong-accent marcato, staccato, tenuto; legato none), a roll a single-note tremolo
//! (log2 of its strokes per quarter as marks, 3 for thirty-seconds) on each of its tied
//! notes, a fixed hand the sticking "R"/"L" as `<other-technical>`. Dynamics are
//! `<dynamics>` directions where the nearest marking changes, with the exact velocity as
//! `<sound dynamics>` (percent of forte = MIDI velocity 90). Tempo points are metronome
//! marks with `<sound tempo>` (quarter notes per minute); a linear ramp is marked
//! "accel." or "rit." and played as the MIDI export's steps every sixteenth note, each an
//! invisible `<sound tempo>` at its `<offset>`, so the seconds match the score's.
//! Each note names its drum in a processing instruction, `<?timpanist drum="N"?>`, which
//! other programs leave alone and the import reads back. The impact location does not
//! survive.

use crate::base::pitch::Pitch;
use crate::kit::Kit;
use crate::score::{Beat, Dynamic, Hand, PlayingMode, Score, TempoChange};
use std::fmt::Write as _;
use std::io::Write as _;

/// The document type line of a partwise MusicXML 4.0 file.
const DOCTYPE: &str = r#"<!DOCTYPE score-partwise PUBLIC "-//Recordare//DTD MusicXML 4.0 Partwise//EN" "http://www.musicxml.org/dtds/partwise.dtd">"#;
/// MIDI velocity MusicXML's `<sound dynamics>` counts as 100 percent (forte).
const FORTE_VELOCITY: f64 = 90.0;
/// Name of the score inside a `.mxl` archive.
const MXL_ROOT: &str = "score.musicxml";

/// The score as MusicXML text (UTF-8). The same score and kit always give the same text.
pub fn export(score: &Score, kit: &Kit) -> String {
    Writer::new(score, kit).document()
}

/// The score as a compressed MusicXML (`.mxl`) archive: `mimetype`, the container naming
/// the root file, and the score.
pub fn export_mxl(score: &Score, kit: &Kit) -> Vec<u8> {
    let container = format!(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<container>\n  <rootfiles>\n    <rootfile full-path=\"{MXL_ROOT}\" media-type=\"application/vnd.recordare.musicxml+xml\"/>\n  </rootfiles>\n</container>\n"
    );
    let stored =
        zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Stored);
    let deflated = stored.compression_method(zip::CompressionMethod::Deflated);
    let text = export(score, kit);
    let entries: [(&str, &[u8], _); 3] = [
        ("mimetype", b"application/vnd.recordare.musicxml", stored),
        ("META-INF/container.xml", container.as_bytes(), deflated),
        (MXL_ROOT, text.as_bytes(), deflated),
    ];
    let mut zip = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    for (name, bytes, options) in entries {
        zip.start_file(name, options)
            .and_then(|()| zip.write_all(bytes).map_err(Into::into))
            .expect("writing a zip to memory cannot fail");
    }
    zip.finish()
        .expect("writing a zip to memory cannot fail")
        .into_inner()
}

/// The bytes for a file at `path`: a `.mxl` archive when it ends in `.mxl`, else text.
pub fn export_for(path: &std::path::Path, score: &Score, kit: &Kit) -> Vec<u8> {
    let mxl = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("mxl"));
    if mxl {
        export_mxl(score, kit)
    } else {
        export(score, kit).into_bytes()
    }
}

/// A note value: its length in 128th notes, its `<type>` and dots.
type Value = (u64, &'static str, u8);

/// Plain and dotted note values from the longest, in 128th notes.
const VALUES: [Value; 16] = [
    (384, "breve", 1),
    (256, "breve", 0),
    (192, "whole", 1),
    (128, "whole", 0),
    (96, "half", 1),
    (64, "half", 0),
    (48, "quarter", 1),
    (32, "quarter", 0),
    (24, "eighth", 1),
    (16, "eighth", 0),
    (12, "16th", 1),
    (8, "16th", 0),
    (6, "32nd", 1),
    (4, "32nd", 0),
    (2, "64th", 0),
    (1, "128th", 0),
];

/// Beats sounding from the same tick, written as one chord.
struct Group<'a> {
    tick: u64,
    /// Where its written notes end (the next group's tick at the latest).
    end: u64,
    /// Where a damped roll's tremolo stops (its notes are split there).
    splits: Vec<u64>,
    beats: Vec<&'a Beat>,
    /// The pitch each of `beats` sounds (its own, else its drum's then).
    pitches: Vec<crate::base::pitch::Pitch>,
}

/// A direction or a bare `<sound>` at a tick.
struct Mark {
    tick: u64,
    /// `<direction …>` and its direction types, or `None` for a bare `<sound>`.
    direction: Option<String>,
    /// The `<sound>` attributes.
    sound: String,
}

impl Mark {
    /// One line of XML, `offset` divisions after its place in the measure.
    fn xml(&self, offset: u64) -> String {
        let offset = match offset {
            0 => String::new(),
            o => format!("<offset>{o}</offset>"),
        };
        match &self.direction {
            Some(d) => format!("      {d}{offset}<sound {}/></direction>\n", self.sound),
            None if offset.is_empty() => format!("      <sound {}/>\n", self.sound),
            None => format!("      <sound {}>{offset}</sound>\n", self.sound),
        }
    }
}

/// One written note or chord (a piece of a group between bar lines) or a rest.
#[derive(Clone, Copy)]
struct Piece {
    start: u64,
    ticks: u64,
    /// The group sounding, `None` for a rest.
    group: Option<usize>,
}

struct Writer<'a> {
    score: &'a Score,
    tpq: u64,
    /// Ticks per division.
    unit: u64,
    groups: Vec<Group<'a>>,
    /// Bar start ticks, one past the last bar included.
    bars: Vec<u64>,
    /// Every direction and sound, in time order.
    marks: Vec<Mark>,
}

impl<'a> Writer<'a> {
    fn new(score: &'a Score, kit: &'a Kit) -> Self {
        let tpq = u64::from(score.ticks_per_quarter.max(1));
        let groups = groups(score, kit, tpq);
        let mut marks = tempo_marks(score);
        marks.extend(dynamic_marks(&groups));
        marks.sort_by_key(|d| d.tick);
        let last = groups
            .last()
            .map_or(0, |g| g.end)
            .max(marks.last().map_or(0, |m| m.tick + 1));
        let meter = score.meter_map();
        let mut bars = vec![0];
        while *bars.last().expect("not empty") < last || bars.len() < 2 {
            bars.push(meter.bar_start(bars.len() as u64 + 1));
        }
        let times = groups
            .iter()
            .flat_map(|g| [g.tick, g.end].into_iter().chain(g.splits.iter().copied()))
            .chain(bars.iter().copied())
            .chain(marks.iter().map(|d| d.tick));
        let unit = times.fold(tpq, gcd);
        Writer {
            score,
            tpq,
            unit,
            groups,
            bars,
            marks,
        }
    }

    fn document(&self) -> String {
        let mut out = String::new();
        let _ = writeln!(out, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n{DOCTYPE}");
        let _ = writeln!(out, "<score-partwise version=\"4.0\">");
        let _ = writeln!(
            out,
            "  <work><work-title>{}</work-title></work>",
            escape(&self.score.title)
        );
        let _ = writeln!(
            out,
            "  <identification><encoding><software>timpanist {}</software></encoding></identification>",
            env!("CARGO_PKG_VERSION")
        );
        out.push_str(concat!(
            "  <part-list>\n    <score-part id=\"P1\">\n      <part-name>Timpani</part-name>\n",
            "      <part-abbreviation>Timp.</part-abbreviation>\n",
            "      <score-instrument id=\"P1-I1\"><instrument-name>Timpani</instrument-name>",
            "<instrument-sound>drum.timpani</instrument-sound></score-instrument>\n",
            "      <midi-instrument id=\"P1-I1\"><midi-channel>1</midi-channel>",
            "<midi-program>48</midi-program></midi-instrument>\n",
            "    </score-part>\n  </part-list>\n  <part id=\"P1\">\n"
        ));
        for bar in 0..self.bars.len() - 1 {
            self.measure(&mut out, bar);
        }
        out.push_str("  </part>\n</score-partwise>\n");
        out
    }

    /// Measure `bar` (from 0): attributes where the time signature changes, then its
    /// notes and rests with the directions that fall in each.
    fn measure(&self, out: &mut String, bar: usize) {
        let (start, end) = (self.bars[bar], self.bars[bar + 1]);
        let _ = writeln!(out, "    <measure number=\"{}\">", bar + 1);
        let meter = self.score.meter_map();
        let sig = meter.signature_at(start);
        let time = format!(
            "<time><beats>{}</beats><beat-type>{}</beat-type></time>",
            sig.numerator, sig.denominator
        );
        if bar == 0 {
            let _ = writeln!(
                out,
                "      <attributes><divisions>{}</divisions><key><fifths>0</fifths></key>{time}<clef><sign>F</sign><line>4</line></clef></attributes>",
                self.tpq / self.unit
            );
        } else if meter.signature_at(self.bars[bar - 1]) != sig {
            let _ = writeln!(out, "      <attributes>{time}</attributes>");
        }
        let pieces = self.pieces(start, end);
        let whole_rest = matches!(pieces[..], [Piece { group: None, .. }]);
        for p in pieces {
            for m in self
                .marks
                .iter()
                .filter(|m| m.tick >= p.start && m.tick < p.start + p.ticks)
            {
                out.push_str(&m.xml((m.tick - p.start) / self.unit));
            }
            match p.group {
                None if whole_rest => {
                    let _ = writeln!(
                        out,
                        "      <note><rest measure=\"yes\"/><duration>{}</duration><voice>1</voice></note>",
                        p.ticks / self.unit
                    );
                }
                None => self.rest(out, p),
                Some(g) => self.chord(out, p, &self.groups[g]),
            }
        }
        let _ = writeln!(out, "    </measure>");
    }

    /// The written pieces of `start..end`: rests and the groups' notes, each cut at the
    /// bar's ends.
    fn pieces(&self, start: u64, end: u64) -> Vec<Piece> {
        let mut out = Vec::new();
        let mut at = start;
        let first = self.groups.partition_point(|g| g.end <= start);
        for (i, g) in self.groups.iter().enumerate().skip(first) {
            if g.tick >= end {
                break;
            }
            if g.tick > at {
                out.push(Piece {
                    start: at,
                    ticks: g.tick - at,
                    group: None,
                });
            }
            let from = g.tick.max(start);
            let to = g.end.min(end);
            let cuts = g.splits.iter().copied().filter(|&c| c > from && c < to);
            let mut cut_at = from;
            for c in cuts.chain([to]) {
                out.push(Piece {
                    start: cut_at,
                    ticks: c - cut_at,
                    group: Some(i),
                });
                cut_at = c;
            }
            at = to;
        }
        if at < end {
            out.push(Piece {
                start: at,
                ticks: end - at,
                group: None,
            });
        }
        out
    }

    /// A rest of `p.ticks`, as note values.
    fn rest(&self, out: &mut String, p: Piece) {
        for (ticks, kind, dots) in self.values(p.ticks) {
            let _ = writeln!(
                out,
                "      <note><rest/><duration>{}</duration><voice>1</voice>{}</note>",
                ticks / self.unit,
                type_xml(kind, dots)
            );
        }
    }

    /// The notes of `group` within piece `p`, as tied note values.
    fn chord(&self, out: &mut String, p: Piece, group: &Group) {
        let values = self.values(p.ticks);
        let mut at = p.start;
        for &(ticks, kind, dots) in &values {
            let first = at == group.tick;
            let last = at + ticks == group.end;
            for (n, beat) in group.beats.iter().enumerate() {
                let mut note = String::from("      <note>");
                let pi = super::musicxml::DRUM_PI_TARGET;
                let _ = write!(note, "<?{pi} drum=\"{}\"?>", beat.drum);
                if n > 0 {
                    note.push_str("<chord/>");
                }
                note.push_str(&pitch_xml(group.pitches[n]));
                let _ = write!(note, "<duration>{}</duration>", ticks / self.unit);
                let (tie_stop, tie_start) = (!first, !last);
                for (on, kind) in [(tie_stop, "stop"), (tie_start, "start")] {
                    if on {
                        let _ = write!(note, "<tie type=\"{kind}\"/>");
                    }
                }
                note.push_str("<voice>1</voice>");
                note.push_str(&type_xml(kind, dots));
                let notations = self.notations(beat, (at, at + ticks), (tie_stop, tie_start));
                if !notations.is_empty() {
                    let _ = write!(note, "<notations>{notations}</notations>");
                }
                note.push_str("</note>\n");
                out.push_str(&note);
            }
            at += ticks;
        }
    }

    /// The notations of `beat`'s written note from `span.0` to `span.1`.
    fn notations(&self, beat: &Beat, span: (u64, u64), ties: (bool, bool)) -> String {
        let mut x = String::new();
        for (on, kind) in [(ties.0, "stop"), (ties.1, "start")] {
            if on {
                let _ = write!(x, "<tied type=\"{kind}\"/>");
            }
        }
        let first = span.0 == beat.tick;
        if first && let Some(a) = articulation(beat.mode) {
            let _ = write!(x, "<articulations>{a}</articulations>");
        }
        if let Some(r) = beat.roll.filter(|r| span.0 < beat.tick + r.length_ticks) {
            let _ = write!(
                x,
                "<ornaments><tremolo type=\"single\">{}</tremolo></ornaments>",
                tremolo_marks(r.strokes_per_quarter)
            );
        }
        let mut technical = String::new();
        if first && let Some(hand) = hand_letter(beat.hand) {
            let _ = write!(technical, "<other-technical>{hand}</other-technical>");
        }
        if beat.damp.is_some() && !ties.1 {
            technical.push_str("<stopped/>");
        }
        if !technical.is_empty() {
            let _ = write!(x, "<technical>{technical}</technical>");
        }
        x
    }

    /// `ticks` as note values (ticks, type, dots), longest first; a length that is no sum
    /// of them ends with its exact remainder under the nearest type.
    fn values(&self, ticks: u64) -> Vec<(u64, &'static str, u8)> {
        let mut out = Vec::new();
        let mut rem = ticks;
        while rem > 0 {
            // A value's ticks: 128ths × ticks per quarter / 32, when whole.
            let exact = |v: &&Value| (v.0 * self.tpq).is_multiple_of(32);
            let fits = VALUES
                .iter()
                .filter(exact)
                .map(|v| (v.0 * self.tpq / 32, v.1, v.2))
                .find(|v| v.0 <= rem && self.dyadic(rem - v.0));
            match fits {
                Some(v) => {
                    out.push(v);
                    rem -= v.0;
                }
                None => {
                    out.push(self.nearest(rem));
                    rem = 0;
                }
            }
        }
        out
    }

    /// Whether `ticks` is a whole number of 128th notes.
    fn dyadic(&self, ticks: u64) -> bool {
        (ticks * 32).is_multiple_of(self.tpq)
    }

    /// `ticks` under the undotted type nearest in length.
    fn nearest(&self, ticks: u64) -> (u64, &'static str, u8) {
        let quarters = ticks as f64 / self.tpq as f64;
        let (_, kind, _) = VALUES
            .iter()
            .filter(|v| v.2 == 0)
            .min_by(|a, b| {
                let d = |v: &Value| ((v.0 as f64 / 32.0) / quarters).ln().abs();
                d(a).total_cmp(&d(b))
            })
            .expect("VALUES is not empty");
        (ticks, kind, 0)
    }
}

/// Metronome marks and `<sound tempo>` at the tempo points, "accel."/"rit." where a
/// ramp starts, and bare `<sound tempo>` steps inside ramps (the MIDI export's steps).
fn tempo_marks(score: &Score) -> Vec<Mark> {
    let points = &score.tempo;
    let steps = super::midi_export::tempo_steps(score);
    let bpm = |us: u32| number(60e6 / f64::from(us), 3);
    let step_at = |tick: u64| steps.iter().rev().find(|s| s.0 <= tick).map(|s| s.1);
    let mut out = Vec::new();
    for (i, p) in points.iter().enumerate() {
        let ramp = points
            .get(i + 1)
            .filter(|n| n.change == TempoChange::Ramp && n.bpm != p.bpm);
        let words = match ramp {
            Some(n) if n.bpm > p.bpm => "<direction-type><words>accel.</words></direction-type>",
            Some(_) => "<direction-type><words>rit.</words></direction-type>",
            None => "",
        };
        out.push(Mark {
            tick: p.tick,
            direction: Some(format!(
                "<direction placement=\"above\"><direction-type><metronome><beat-unit>quarter</beat-unit><per-minute>{}</per-minute></metronome></direction-type>{words}",
                number(p.bpm, 1)
            )),
            sound: format!(
                "tempo=\"{}\"",
                step_at(p.tick).map_or_else(|| number(p.bpm, 3), bpm)
            ),
        });
    }
    let at_point = |t: u64| points.iter().any(|p| p.tick == t);
    out.extend(
        steps
            .iter()
            .filter(|s| !at_point(s.0))
            .map(|&(tick, us)| Mark {
                tick,
                direction: None,
                sound: format!("tempo=\"{}\"", bpm(us)),
            }),
    );
    out
}

/// The dynamic of each chord (its loudest beat) where it changes: a `<dynamics>`
/// direction where the nearest marking changes, else a bare `<sound>`, each with the
/// exact velocity as `<sound dynamics>`.
fn dynamic_marks(groups: &[Group]) -> Vec<Mark> {
    let mut out = Vec::new();
    let mut last: Option<Dynamic> = None;
    for g in groups {
        let loudest = g
            .beats
            .iter()
            .map(|b| b.dynamic)
            .max_by(|a, b| a.velocity().total_cmp(&b.velocity()))
            .unwrap_or(Dynamic::Mf);
        if last == Some(loudest) {
            continue;
        }
        let mark = loudest.nearest_mark();
        let visible = last.is_none_or(|l| l.nearest_mark() != mark);
        last = Some(loudest);
        let percent = loudest.velocity() * 127.0 / FORTE_VELOCITY * 100.0;
        out.push(Mark {
            tick: g.tick,
            direction: visible.then(|| format!(
                "<direction placement=\"below\"><direction-type><dynamics><{mark}/></dynamics></direction-type>"
            )),
            sound: format!("dynamics=\"{}\"", number(percent, 2)),
        });
    }
    out
}

/// The beats grouped by tick, each group ending at the next group's tick or the end of
/// its bar (a roll: its length; a damped beat: its damping touch), whichever first; the
/// last without a roll or damp lasts a quarter note at most.
fn groups<'s>(score: &'s Score, kit: &Kit, tpq: u64) -> Vec<Group<'s>> {
    let meter = score.meter_map();
    let sounding = crate::score::tuning::sounding_pitches(score, kit);
    let mut groups: Vec<Group> = Vec::new();
    for (b, &pitch) in score.beats.iter().zip(&sounding) {
        match groups.last_mut() {
            Some(g) if g.tick == b.tick => {
                g.beats.push(b);
                g.pitches.push(pitch);
            }
            _ => groups.push(Group {
                tick: b.tick,
                end: 0,
                splits: Vec::new(),
                beats: vec![b],
                pitches: vec![pitch],
            }),
        }
    }
    let ticks: Vec<u64> = groups.iter().map(|g| g.tick).collect();
    for (i, g) in groups.iter_mut().enumerate() {
        let next = ticks.get(i + 1).copied();
        let held = g
            .beats
            .iter()
            .filter_map(|b| b.damp_tick().or(b.roll.map(|r| b.tick + r.length_ticks)))
            .max();
        let bar = meter.position(g.tick).bar;
        let bar_end = meter.bar_start(bar + 1);
        let free = match next {
            Some(n) => n.min(bar_end),
            None => (g.tick + tpq).min(bar_end),
        };
        let want = held.unwrap_or(free);
        g.end = next.map_or(want, |n| want.min(n)).max(g.tick + 1);
        g.splits = g
            .beats
            .iter()
            .filter(|b| b.damp.is_some())
            .filter_map(|b| b.roll.map(|r| b.tick + r.length_ticks))
            .collect();
    }
    groups
}

/// `<pitch>` of a MIDI pitch, spelled as the score files name it (C#, Eb, F#, Ab, Bb).
fn pitch_xml(pitch: Pitch) -> String {
    let name = pitch.to_string();
    let step = &name[..1];
    let alter = match name.as_bytes().get(1) {
        Some(b'#') => "<alter>1</alter>",
        Some(b'b') => "<alter>-1</alter>",
        _ => "",
    };
    let octave = i32::from(pitch.0) / 12 - 1;
    format!("<pitch><step>{step}</step>{alter}<octave>{octave}</octave></pitch>")
}

fn type_xml(kind: &str, dots: u8) -> String {
    format!("<type>{kind}</type>{}", "<dot/>".repeat(usize::from(dots)))
}

/// The articulation of a playing mode (legato has none).
fn articulation(mode: PlayingMode) -> Option<&'static str> {
    match mode {
        PlayingMode::Legato => None,
        PlayingMode::Tenuto => Some("<tenuto/>"),
        PlayingMode::Accent => Some("<accent/>"),
        PlayingMode::VerticalAccent => Some("<strong-accent type=\"up\"/>"),
        PlayingMode::Staccato => Some("<staccato/>"),
    }
}

fn hand_letter(hand: Hand) -> Option<&'static str> {
    match hand {
        Hand::Left => Some("L"),
        Hand::Right => Some("R"),
        Hand::Auto => None,
    }
}

/// Tremolo marks for a roll of `strokes` per quarter: log2, 1 (eighths) to 5; the nearest.
fn tremolo_marks(strokes: u32) -> u32 {
    (f64::from(strokes.max(1)).log2().round() as u32).clamp(1, 5)
}

/// `v` with at most `decimals` decimals, without trailing zeros.
fn number(v: f64, decimals: usize) -> String {
    let s = format!("{v:.decimals$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

fn gcd(a: u64, b: u64) -> u64 {
    if b == 0 { a } else { gcd(b, a % b) }
}
