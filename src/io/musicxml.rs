//! MusicXML import: finds the timpani part of a partwise MusicXML file (`.musicxml`,
//! `.xml`, or the compressed `.mxl` zip with its `META-INF/container.xml`) and turns its
//! notes into a score a timpanist can play on a given kit.
//!
//! The part is the one named by `--part` (its id, or part of its name), else one whose
//! instrument sound is `drum.timpani…` or whose MIDI program is 48 (General MIDI
//! "Timpani"), else one named like "Timpani", "Timp.", "Pk.", "Pauken" or "Timbales".
//! Musical time is exact: the score's ticks per quarter are the least common multiple of
//! 960 and every `<divisions>` of the part. Each sounding note (a tie's later notes extend
//! the first; grace and cue notes are skipped and reported) becomes a beat on a drum chosen
//! as [`super::midi_import`] does (a drum tuned to the pitch, else the one idle longest;
//! out-of-range pitches move by octaves). Measures play in performed order, repeats and
//! volta endings expanded ([`super::musicxml_repeats`]). Tremolo marks become rolls (a
//! two-note tremolo: strokes alternating between its two notes), dynamics and hairpins
//! per-beat dynamics, articulations playing modes, `<stopped/>` damping when the note
//! ends, `<other-technical>` R/L the hand, `<sound tempo>` and `<metronome>` the tempo
//! map (quarter notes per minute), time signatures and measure lengths the meter map.
//! Whatever is read but not performed (fermatas, jumps, ornaments, texts…) is listed in
//! [`ImportReport::notices`]; notation that only concerns the page (clefs, keys, beams,
//! stems, layout, lyrics, chord symbols) is left out silently.

use super::midi_import::{self as midi, ANY_DRUM, Note};
use super::musicxml_repeats as repeats;
use crate::kit::Kit;
use crate::score::meter;
use crate::score::tempo::BPM_RANGE;
use crate::score::{
    Dynamic, Hand, ImpactLocation, MeterChange, PlayingMode, Roll, Score, TempoChange, TempoPoint,
};
use roxmltree::{Document, Node};
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::io::Read as _;
use std::path::{Path, PathBuf};

/// Ticks per quarter note that every import's resolution is a multiple of.
const BASE_TICKS_PER_QUARTER: u64 = 960;
/// The finest resolution taken (ticks per quarter); beyond it durations are rounded.
const MAX_TICKS_PER_QUARTER: u64 = 960 * 3 * 5 * 7 * 11 * 13;
/// Tempo until the first tempo mark, quarter notes per minute (MusicXML's default).
const DEFAULT_BPM: f64 = 120.0;
/// Dynamic before the first marking (MIDI velocity of mf).
const DEFAULT_VELOCITY: f64 = 80.0;
/// Strokes per quarter note of an unmeasured tremolo (a free roll), as three marks.
const UNMEASURED_STROKES_PER_QUARTER: u32 = 8;
/// Largest file read out of an `.mxl` archive, bytes.
const MAX_ENTRY_BYTES: u64 = 512 << 20;
/// General MIDI program of the timpani, counted from 1 as MusicXML does.
const GM_TIMPANI_1: u32 = 48;

/// How to import.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ImportOptions {
    /// The part to read, by id or by (part of) its name; `None` finds the timpani part.
    pub part: Option<String>,
    /// What goes into `Score.kit`: a bundled kit name or a `.ron` path.
    pub kit_ref: String,
    /// The score title; `None` takes the movement or work title, else the file stem.
    pub title: Option<String>,
}

impl Default for ImportOptions {
    fn default() -> Self {
        ImportOptions {
            part: None,
            kit_ref: "standard".into(),
            title: None,
        }
    }
}

/// What an import did.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ImportReport {
    /// Which part was read, and why.
    pub source: String,
    /// Sounding notes read (after joining ties, before dropping duplicates).
    pub notes: usize,
    /// Notes dropped as duplicates (same time and pitch in two voices).
    pub duplicates_dropped: usize,
    /// Notes moved by octaves because no drum reaches their pitch.
    pub octave_moves: usize,
    /// What was read but not performed, or changed to fit the score, with its place.
    pub notices: Vec<String>,
}

/// Why a MusicXML file could not be imported; every message names the file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum MusicXmlError {
    /// The file could not be read.
    #[error("{}: cannot read the file: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// A `.mxl` that is not a readable zip, or lacks its score.
    #[error("{}: not a readable compressed MusicXML (.mxl) file: {message}", path.display())]
    Archive { path: PathBuf, message: String },
    /// The text is not well-formed XML (or not in its declared encoding).
    #[error("{}:{line}:{column}: malformed XML: {message}", path.display())]
    Xml {
        path: PathBuf,
        line: u32,
        column: u32,
        message: String,
    },
    /// Well-formed XML, but not a score timpanist can read.
    #[error("{}: {message}", path.display())]
    NotMusicXml { path: PathBuf, message: String },
    /// A value the music depends on is missing or wrong.
    #[error("{}:{line}: measure {measure}: {message}", path.display())]
    Invalid {
        path: PathBuf,
        line: u32,
        measure: String,
        message: String,
    },
    /// `--part` matches no part.
    #[error(
        "{}: no part has the id or a name containing \"{part}\"; choose one of these with --part ID or --part NAME:\n{parts}",
        path.display()
    )]
    PartNotFound {
        path: PathBuf,
        part: String,
        parts: String,
    },
    /// Nothing looks like a timpani part.
    #[error(
        "{}: no timpani part found (no instrument sound \"drum.timpani\", no MIDI program 48, no part named \"Timp…\", \"Pk.\", \"Pauken\" or \"Timbales\"); choose one with --part ID or --part NAME:\n{parts}",
        path.display()
    )]
    NoTimpani { path: PathBuf, parts: String },
}

/// Read and import a MusicXML file (`.musicxml`, `.xml` or `.mxl`).
pub fn import_file(
    path: &Path,
    kit: &Kit,
    options: &ImportOptions,
) -> Result<(Score, ImportReport), MusicXmlError> {
    let bytes = crate::base::limits::read_at_most(
        path,
        crate::base::limits::MAX_MUSICXML_FILE_BYTES,
        "MusicXML file",
    )
    .map_err(|source| MusicXmlError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    import(path, &bytes, kit, options)
}

/// Import the MusicXML file `bytes` (`path` names it in messages; a zip is read as `.mxl`
/// whatever its name) as a score on `kit`. The score has no problems against `kit`.
pub fn import(
    path: &Path,
    bytes: &[u8],
    kit: &Kit,
    options: &ImportOptions,
) -> Result<(Score, ImportReport), MusicXmlError> {
    let mut notices = Notices::default();
    let text = score_text(path, bytes, &mut notices)?;
    let opts = roxmltree::ParsingOptions {
        allow_dtd: true,
        ..Default::default()
    };
    let doc = Document::parse_with_options(&text, opts).map_err(|e| xml_error(path, &text, &e))?;
    let root = doc.root_element();
    match root.tag_name().name() {
        "score-partwise" => {}
        "score-timewise" => {
            return Err(MusicXmlError::NotMusicXml {
                path: path.to_path_buf(),
                message: "a timewise MusicXML score (<score-timewise>), which timpanist cannot read; export it as a partwise score (the usual kind)".into(),
            });
        }
        other => {
            return Err(MusicXmlError::NotMusicXml {
                path: path.to_path_buf(),
                message: format!(
                    "not a MusicXML score: the root element is <{other}>, not <score-partwise>"
                ),
            });
        }
    }
    let parts = part_list(root);
    let (source, chosen, instrument) = choose(path, &parts, options)?;
    let part_node = root
        .children()
        .filter(|n| n.has_tag_name("part"))
        .find(|n| n.attribute("id").unwrap_or("") == parts[chosen].id)
        .or_else(|| {
            // A part without an id (41g): the part at the same position.
            root.children()
                .filter(|n| n.has_tag_name("part"))
                .nth(parts[chosen].index)
        })
        .ok_or_else(|| MusicXmlError::NotMusicXml {
            path: path.to_path_buf(),
            message: format!(
                "the part list names {} but there is no such <part>",
                parts[chosen].label()
            ),
        })?;
    let tpq = ticks_per_quarter(part_node, &mut notices);
    let mut reader = PartReader::new(path, &doc, tpq, instrument);
    reader.notices = notices;
    reader.read(part_node)?;
    let PartReader {
        notes: xnotes,
        measures,
        tempos,
        dynamics,
        mut notices,
        ..
    } = reader;

    let note_count = xnotes.len();
    let levels = Levels::new(&dynamics, tpq);
    let mut xnotes = one_roll_per_chord(xnotes, &mut notices);
    xnotes.sort_by_key(|n| (n.tick, n.pitch));
    let mut exact: BTreeMap<(u64, u8), (Dynamic, PlayingMode, Option<u64>)> = BTreeMap::new();
    let mut notes: Vec<Note> = Vec::with_capacity(xnotes.len());
    for n in &xnotes {
        let (vel, accent) = levels.at(n.tick);
        let mode = if accent && n.mode == PlayingMode::Legato {
            PlayingMode::Accent
        } else {
            n.mode
        };
        let dynamic = dynamic_of(vel);
        let entry = exact
            .entry((n.tick, n.pitch))
            .or_insert((dynamic, mode, n.damp));
        if vel > entry.0.velocity() * 127.0 {
            *entry = (dynamic, mode, n.damp);
        }
        notes.push(Note {
            tick: n.tick,
            channel: 0,
            key: n.pitch,
            vel: vel.round().clamp(1.0, 127.0) as u8,
            data: Some(midi_data(n.hand, mode, n.roll)),
        });
    }
    let duplicates_dropped = midi::drop_duplicates(&mut notes);
    let mut warnings = Vec::new();
    midi::limit_to_two_hands(&mut notes, &mut warnings);
    let dynamics_of: Vec<(Dynamic, PlayingMode, Option<u64>)> =
        notes.iter().map(|n| exact[&(n.tick, n.key)]).collect();
    let octave_moves = midi::move_into_range(&mut notes, kit, &mut warnings);
    let mut beats = midi::assign_drums(&notes, kit, &mut warnings);
    for (b, (dynamic, mode, damp)) in beats.iter_mut().zip(dynamics_of) {
        b.dynamic = dynamic;
        b.mode = mode;
        b.damp = damp;
    }
    for w in warnings {
        notices.push_text(w.replace("tick", "score tick"));
    }

    let mut score = Score::new("");
    score.title = [options.title.clone(), title_of(root)]
        .into_iter()
        .flatten()
        .chain(std::iter::once(
            path.file_stem()
                .unwrap_or_default()
                .to_string_lossy()
                .into_owned(),
        ))
        .find(|t| !t.trim().is_empty())
        .unwrap_or_default()
        .trim()
        .to_string();
    score.kit = options.kit_ref.clone();
    score.ticks_per_quarter = u32::try_from(tpq).expect("ticks per quarter fit in u32");
    score.tempo = tempo_points(&tempos, &mut notices);
    score.meter = meter_changes(&measures, tpq, &mut notices);
    score.beats = beats;
    score.sort_beats();
    midi::trim_rolls(&mut score.beats);
    if score.beats.is_empty() {
        notices.push_text(format!("{source} has no notes"));
    }
    let report = ImportReport {
        source,
        notes: note_count,
        duplicates_dropped,
        octave_moves,
        notices: notices.into_list(),
    };
    Ok((score, report))
}

/// The hand, mode and roll of a note in the MIDI import's terms (the drum left to choose).
fn midi_data(hand: Hand, mode: PlayingMode, roll: Option<Roll>) -> super::midi_export::BeatData {
    super::midi_export::BeatData(hand, mode, ANY_DRUM, ImpactLocation::PlayingSpot, roll)
}

/// The marking of a MIDI velocity if it is exactly one, else the velocity (0–1).
fn dynamic_of(vel: f64) -> Dynamic {
    Dynamic::MARKS
        .iter()
        .find(|(_, v, _)| f64::from(*v) == vel)
        .map(|(m, _, _)| *m)
        .unwrap_or(Dynamic::Velocity((vel / 127.0).clamp(0.0, 1.0)))
}

// ---------------------------------------------------------------------------------------
// Reading the file: zip, encoding.

/// The score's XML text: the root file of a `.mxl` zip, or the file itself, decoded from
/// its byte-order mark or declared encoding (UTF-8 by default).
pub fn score_text(
    path: &Path,
    bytes: &[u8],
    notices: &mut Notices,
) -> Result<String, MusicXmlError> {
    if bytes.starts_with(b"PK\x03\x04") || bytes.starts_with(b"PK\x05\x06") {
        let (name, inner) = unzip_root(path, bytes, notices)?;
        let shown = PathBuf::from(format!("{}:{name}", path.display()));
        return decode(&shown, &inner);
    }
    let is_mxl = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("mxl"));
    if is_mxl {
        return Err(MusicXmlError::Archive {
            path: path.to_path_buf(),
            message: "the file is not a zip archive".into(),
        });
    }
    decode(path, bytes)
}

/// The root score of a `.mxl` archive: (its name in the archive, its bytes).
fn unzip_root(
    path: &Path,
    bytes: &[u8],
    notices: &mut Notices,
) -> Result<(String, Vec<u8>), MusicXmlError> {
    let archive_err = |message: String| MusicXmlError::Archive {
        path: path.to_path_buf(),
        message,
    };
    let mut zip = zip::ZipArchive::new(std::io::Cursor::new(bytes))
        .map_err(|e| archive_err(format!("corrupt zip: {e}")))?;
    let read_entry = |zip: &mut zip::ZipArchive<_>, name: &str| -> Result<Vec<u8>, MusicXmlError> {
        let entry = zip
            .by_name(name)
            .map_err(|e| archive_err(format!("cannot open {name}: {e}")))?;
        if entry.size() > MAX_ENTRY_BYTES {
            return Err(archive_err(format!(
                "{name} is {} bytes unpacked, more than the {MAX_ENTRY_BYTES} read",
                entry.size()
            )));
        }
        let mut out = Vec::new();
        entry
            .take(MAX_ENTRY_BYTES)
            .read_to_end(&mut out)
            .map_err(|e| archive_err(format!("corrupt entry {name}: {e}")))?;
        Ok(out)
    };
    let names: Vec<String> = zip
        .file_names()
        .map(|n| n.map(|n| n.into_owned()))
        .collect::<Result<_, _>>()
        .map_err(|e| archive_err(format!("unreadable file name: {e}")))?;
    const CONTAINER: &str = "META-INF/container.xml";
    if names.iter().any(|n| n == CONTAINER) {
        let container = read_entry(&mut zip, CONTAINER)?;
        let shown = PathBuf::from(format!("{}:{CONTAINER}", path.display()));
        let text = decode(&shown, &container)?;
        let doc = Document::parse(&text).map_err(|e| xml_error(&shown, &text, &e))?;
        let root_file = doc
            .descendants()
            .filter(|n| n.has_tag_name("rootfile"))
            .filter(|n| {
                n.attribute("media-type")
                    .is_none_or(|m| m.contains("musicxml"))
            })
            .find_map(|n| n.attribute("full-path"))
            .ok_or_else(|| {
                archive_err(format!(
                    "{CONTAINER} names no MusicXML <rootfile full-path=…>"
                ))
            })?
            .to_string();
        let inner = read_entry(&mut zip, &root_file)?;
        return Ok((root_file, inner));
    }
    let fallback = names
        .iter()
        .find(|n| !n.starts_with("META-INF/") && (n.ends_with(".xml") || n.ends_with(".musicxml")))
        .cloned()
        .ok_or_else(|| {
            archive_err(format!(
                "no {CONTAINER} and no .xml or .musicxml file inside"
            ))
        })?;
    notices.push_text(format!(
        "the archive has no {CONTAINER}; read {fallback}, its first MusicXML file"
    ));
    let inner = read_entry(&mut zip, &fallback)?;
    Ok((fallback, inner))
}

/// A parse error with its place (said once: roxmltree's text ends with it too).
/// A file that stops early is placed at its end.
fn xml_error(path: &Path, xml: &str, e: &roxmltree::Error) -> MusicXmlError {
    let pos = e.pos();
    let text = e.to_string();
    let message = text
        .strip_suffix(&format!(" at {}:{}", pos.row, pos.col))
        .unwrap_or(&text)
        .to_string();
    let (line, column) = if matches!(e, roxmltree::Error::UnexpectedEndOfStream) {
        let line = xml.lines().count().max(1);
        let column = xml.lines().last().map_or(0, |l| l.chars().count()) + 1;
        (
            u32::try_from(line).unwrap_or(u32::MAX),
            u32::try_from(column).unwrap_or(u32::MAX),
        )
    } else {
        (pos.row, pos.col)
    };
    MusicXmlError::Xml {
        path: path.to_path_buf(),
        line,
        column,
        message,
    }
}

/// Decode XML bytes: a byte-order mark, else the declaration's `encoding`, else UTF-8.
fn decode(path: &Path, bytes: &[u8]) -> Result<String, MusicXmlError> {
    let (encoding, skip) = encoding_rs::Encoding::for_bom(bytes).unwrap_or_else(|| {
        let head = &bytes[..bytes.len().min(200)];
        let declared = std::str::from_utf8(head)
            .ok()
            .or_else(|| {
                std::str::from_utf8(&head[..head.iter().rposition(|&b| b < 0x80).unwrap_or(0)]).ok()
            })
            .and_then(declared_encoding)
            .and_then(|label| encoding_rs::Encoding::for_label(label.as_bytes()))
            .unwrap_or(encoding_rs::UTF_8);
        (declared, 0)
    });
    let (text, had_errors) = encoding.decode_without_bom_handling(&bytes[skip..]);
    if had_errors {
        let good = match std::str::from_utf8(&bytes[skip..]) {
            Err(e) if encoding == encoding_rs::UTF_8 => e.valid_up_to(),
            _ => 0,
        };
        let line = 1 + bytes[skip..skip + good]
            .iter()
            .filter(|&&b| b == b'\n')
            .count();
        return Err(MusicXmlError::Xml {
            path: path.to_path_buf(),
            line: u32::try_from(line).unwrap_or(u32::MAX),
            column: 1,
            message: format!("the text is not valid {}", encoding.name()),
        });
    }
    Ok(text.into_owned())
}

/// The `encoding` of an XML declaration at the start of `head`.
fn declared_encoding(head: &str) -> Option<String> {
    let decl = head.strip_prefix("<?xml")?;
    let decl = &decl[..decl.find("?>")?];
    let at = decl.find("encoding")?;
    let rest = decl[at + "encoding".len()..]
        .trim_start()
        .strip_prefix('=')?
        .trim_start();
    let quote = rest.chars().next().filter(|c| *c == '"' || *c == '\'')?;
    let rest = &rest[1..];
    Some(rest[..rest.find(quote)?].to_string())
}

// ---------------------------------------------------------------------------------------
// Notices.

/// What the import reports, merged by kind: each kind once, with a count and where it
/// first happened.
#[derive(Default)]
pub struct Notices {
    /// kind → (count, first place, order of first appearance)
    kinds: BTreeMap<String, (usize, String, usize)>,
    /// Free-standing notices, in order.
    texts: Vec<String>,
    seen: usize,
}

impl Notices {
    /// Count one `kind` (e.g. "fermata: not performed") at `place` ("measure 12").
    fn add(&mut self, kind: impl Into<String>, place: &str) {
        let seen = self.seen;
        let entry = self
            .kinds
            .entry(kind.into())
            .or_insert_with(|| (0, place.to_string(), seen));
        entry.0 += 1;
        self.seen += 1;
    }

    fn push_text(&mut self, text: String) {
        self.texts.push(text);
    }

    /// The notices: the merged kinds in the order first seen, then the others.
    fn into_list(self) -> Vec<String> {
        let mut kinds: Vec<(String, (usize, String, usize))> = self.kinds.into_iter().collect();
        kinds.sort_by_key(|(_, (_, _, order))| *order);
        kinds
            .into_iter()
            .map(|(kind, (n, place, _))| match n {
                1 => format!("{kind} ({place})"),
                n => format!("{kind} ×{n} (the first in {place})"),
            })
            .chain(self.texts)
            .collect()
    }
}

// ---------------------------------------------------------------------------------------
// Parts.

/// A `<score-part>` of the part list.
#[derive(Clone, Debug)]
struct PartInfo {
    index: usize,
    id: String,
    name: String,
    abbreviation: String,
    /// (instrument id, name, sound) of each `<score-instrument>`.
    instruments: Vec<(String, String, String)>,
    /// MIDI programs (1–128) per instrument id ("" when the midi-instrument names none).
    programs: Vec<(String, u32)>,
    /// Pitched notes in the part.
    notes: usize,
}

impl PartInfo {
    fn label(&self) -> String {
        match self.name.trim() {
            "" => format!("part {}", self.id),
            name => format!("part {} \"{}\"", self.id, name),
        }
    }
}

fn text_of(node: Node, tag: &str) -> String {
    node.children()
        .find(|n| n.has_tag_name(tag))
        .and_then(|n| n.text())
        .unwrap_or("")
        .trim()
        .to_string()
}

fn part_list(root: Node) -> Vec<PartInfo> {
    let part_nodes: Vec<Node> = root.children().filter(|n| n.has_tag_name("part")).collect();
    let list = root.children().find(|n| n.has_tag_name("part-list"));
    let score_parts: Vec<Node> = list
        .map(|l| {
            l.children()
                .filter(|n| n.has_tag_name("score-part"))
                .collect()
        })
        .unwrap_or_default();
    let count = score_parts.len().max(part_nodes.len());
    (0..count)
        .map(|index| {
            let sp = score_parts.get(index);
            let id = sp
                .and_then(|n| n.attribute("id"))
                .or_else(|| part_nodes.get(index).and_then(|n| n.attribute("id")))
                .unwrap_or("")
                .to_string();
            let part = part_nodes
                .iter()
                .find(|n| n.attribute("id") == Some(id.as_str()) && !id.is_empty())
                .or(part_nodes.get(index));
            let notes = part.map_or(0, |p| {
                p.descendants()
                    .filter(|n| n.has_tag_name("note"))
                    .filter(|n| {
                        n.children()
                            .any(|c| c.has_tag_name("pitch") || c.has_tag_name("unpitched"))
                    })
                    .count()
            });
            let instruments = sp.map_or_else(Vec::new, |sp| {
                sp.children()
                    .filter(|n| n.has_tag_name("score-instrument"))
                    .map(|n| {
                        (
                            n.attribute("id").unwrap_or("").to_string(),
                            text_of(n, "instrument-name"),
                            text_of(n, "instrument-sound"),
                        )
                    })
                    .collect()
            });
            let programs = sp.map_or_else(Vec::new, |sp| {
                sp.children()
                    .filter(|n| n.has_tag_name("midi-instrument"))
                    .filter_map(|n| {
                        let p = text_of(n, "midi-program").parse().ok()?;
                        Some((n.attribute("id").unwrap_or("").to_string(), p))
                    })
                    .collect()
            });
            PartInfo {
                index,
                id,
                name: sp.map(|n| text_of(*n, "part-name")).unwrap_or_default(),
                abbreviation: sp
                    .map(|n| text_of(*n, "part-abbreviation"))
                    .unwrap_or_default(),
                instruments,
                programs,
                notes,
            }
        })
        .collect()
}

/// One line per part: id, name, instruments, notes.
fn part_listing(parts: &[PartInfo]) -> String {
    let mut out = String::new();
    for p in parts {
        let _ = write!(out, "  {}", p.label());
        let sounds: Vec<String> = p
            .instruments
            .iter()
            .map(|(_, name, sound)| match (name.as_str(), sound.as_str()) {
                (n, "") => n.to_string(),
                (n, s) => format!("{n} [{s}]"),
            })
            .filter(|s| !s.is_empty())
            .collect();
        if !sounds.is_empty() {
            let _ = write!(out, " ({})", sounds.join(", "));
        }
        let _ = writeln!(out, ": {} notes", p.notes);
    }
    out.pop();
    out
}

/// A word of a name that marks a timpani part: "Timpani", "Timp.", "Pk.", "Pauken",
/// "Timbales" (any case).
fn timpani_name(name: &str) -> bool {
    let lower = name.to_lowercase();
    lower.contains("timp")
        || lower.contains("pauk")
        || lower.contains("timbal")
        || lower
            .split(|c: char| !c.is_alphanumeric())
            .any(|w| w == "pk" || w == "pkn")
}

/// A way to recognise the timpani part: (the instrument id if one matched, why).
type Rule = dyn Fn(&PartInfo) -> Option<(String, String)>;

/// Choose the part and say which and why.
fn choose(
    path: &Path,
    parts: &[PartInfo],
    options: &ImportOptions,
) -> Result<(String, usize, Option<String>), MusicXmlError> {
    if let Some(want) = &options.part {
        let lower = want.to_lowercase();
        let found = parts.iter().position(|p| p.id == *want).or_else(|| {
            parts.iter().position(|p| {
                p.name.to_lowercase().contains(&lower) || p.abbreviation.to_lowercase() == lower
            })
        });
        return match found {
            Some(i) => Ok((
                format!("{} (chosen with --part \"{want}\")", parts[i].label()),
                i,
                None,
            )),
            None => Err(MusicXmlError::PartNotFound {
                path: path.to_path_buf(),
                part: want.clone(),
                parts: part_listing(parts),
            }),
        };
    }
    let by_sound = |p: &PartInfo| {
        p.instruments
            .iter()
            .find(|(_, _, s)| s.starts_with("drum.timpani"))
            .map(|(id, _, s)| (id.clone(), format!("instrument sound {s}")))
            .or_else(|| {
                p.programs
                    .iter()
                    .find(|(_, prog)| *prog == GM_TIMPANI_1)
                    .map(|(id, _)| (id.clone(), "MIDI program 48 \"Timpani\"".to_string()))
            })
    };
    let by_name = |p: &PartInfo| {
        let named = [p.name.as_str(), p.abbreviation.as_str()]
            .into_iter()
            .chain(p.instruments.iter().map(|(_, n, _)| n.as_str()))
            .find(|n| timpani_name(n))?;
        Some((String::new(), format!("named \"{named}\"")))
    };
    let rules: [&Rule; 2] = [&by_sound, &by_name];
    for rule in rules {
        let candidates: Vec<(usize, String, String)> = parts
            .iter()
            .filter(|p| p.notes > 0)
            .filter_map(|p| rule(p).map(|(inst, why)| (p.index, inst, why)))
            .collect();
        let Some(best) = candidates
            .iter()
            .max_by_key(|(i, _, _)| (parts[*i].notes, std::cmp::Reverse(*i)))
        else {
            continue;
        };
        let (i, inst, why) = best.clone();
        let instrument = (parts[i].instruments.len() > 1 && !inst.is_empty()).then_some(inst);
        let mut text = format!("{}: {why}; {} notes", parts[i].label(), parts[i].notes);
        if candidates.len() > 1 {
            let _ = write!(text, ", the most of {} candidates", candidates.len());
        }
        return Ok((text, i, instrument));
    }
    Err(MusicXmlError::NoTimpani {
        path: path.to_path_buf(),
        parts: part_listing(parts),
    })
}

/// Ticks per quarter: the least common multiple of 960 and the part's divisions (when it
/// stays at most [`MAX_TICKS_PER_QUARTER`]; else 960, and durations are rounded).
fn ticks_per_quarter(part: Node, notices: &mut Notices) -> u64 {
    let mut tpq = BASE_TICKS_PER_QUARTER;
    for d in part.descendants().filter(|n| n.has_tag_name("divisions")) {
        let Some(div) = d
            .text()
            .and_then(|t| t.trim().parse::<f64>().ok())
            .filter(|v| *v >= 1.0 && v.fract() == 0.0 && *v < 1e9)
        else {
            continue;
        };
        let div = div as u64;
        let lcm = tpq / gcd(tpq, div) * div;
        if lcm <= MAX_TICKS_PER_QUARTER {
            tpq = lcm;
        } else {
            notices.add(
                format!("{div} divisions per quarter cannot be held exactly; durations rounded to 1/{tpq} quarter"),
                "the part",
            );
        }
    }
    tpq
}

fn gcd(a: u64, b: u64) -> u64 {
    if b == 0 { a } else { gcd(b, a % b) }
}

// ---------------------------------------------------------------------------------------
// Reading a part.

/// A sounding note (ties joined), in score ticks.
#[derive(Clone, Debug)]
struct XNote {
    tick: u64,
    end: u64,
    pitch: u8,
    mode: PlayingMode,
    /// The sticking written as `<other-technical>` "R" or "L".
    hand: Hand,
    /// Strokes per quarter of a tremolo; the roll's length is the note's.
    strokes: Option<u32>,
    /// The end of the last tied note that carries the tremolo (a damped roll's tremolo
    /// may stop before its tied notes do).
    roll_end: u64,
    /// Marked `<stopped/>`: the hand damps the head when the (tied) note ends.
    damped: bool,
    /// Half of a two-note tremolo.
    two_note: Option<TwoNote>,
    roll: Option<Roll>,
    /// Ticks from the last stroke to the damping touch.
    damp: Option<u64>,
}

/// A note's part in a two-note tremolo.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum TwoNote {
    /// The first note; strokes per quarter of the alternation.
    Start(u32),
    Stop,
}

/// What a note's notations say about how it is played.
struct NoteMarks {
    mode: PlayingMode,
    strokes: Option<u32>,
    hand: Hand,
    damped: bool,
    two_note: Option<TwoNote>,
}

/// A measure as read: where it starts, how long it is, its written time signature.
#[derive(Clone, Debug)]
struct Measure {
    length: u64,
    signature: Option<(u32, u32)>,
    number: String,
    implicit: bool,
}

/// A dynamic instruction at a tick.
#[derive(Clone, Copy, Debug, PartialEq)]
enum DynEvent {
    /// A new level (MIDI velocity).
    Level(f64),
    /// One stroke at this velocity (accented for sf, sfz, fz…), then the level `then`
    /// (or back to the level before).
    Single {
        vel: f64,
        then: Option<f64>,
        accent: bool,
    },
    /// A hairpin starts (true: crescendo) with this number.
    Wedge { up: bool, number: u32 },
    /// The hairpin with this number ends.
    WedgeStop { number: u32 },
}

struct PartReader<'a, 'd> {
    path: &'a Path,
    doc: &'a Document<'d>,
    tpq: u64,
    /// Only notes of this instrument (a part with several).
    instrument: Option<String>,
    divisions: f64,
    /// Sounding pitch minus written pitch, semitones.
    transpose: i32,
    notes: Vec<XNote>,
    measures: Vec<Measure>,
    /// (tick, bpm, from `<sound tempo>`).
    tempos: Vec<(u64, f64, bool)>,
    dynamics: Vec<(u64, DynEvent)>,
    notices: Notices,
    /// Open ties: (pitch, note index).
    ties: Vec<(u8, usize)>,
    rounded: bool,
    /// The time signature in force.
    signature: Option<(u32, u32)>,
}

/// Velocities of the dynamic levels, softest to loudest.
const LEVELS: [(&str, f64); 12] = [
    ("pppppp", 3.0),
    ("ppppp", 6.0),
    ("pppp", 10.0),
    ("ppp", 16.0),
    ("pp", 33.0),
    ("p", 49.0),
    ("mp", 64.0),
    ("mf", 80.0),
    ("f", 96.0),
    ("ff", 112.0),
    ("fff", 120.0),
    ("ffff", 127.0),
];

fn level(name: &str) -> Option<f64> {
    match name {
        "fffff" | "ffffff" => Some(127.0),
        _ => LEVELS.iter().find(|(n, _)| *n == name).map(|(_, v)| *v),
    }
}

/// Elements that only concern how the page looks or analyses the music: read silently.
const PAGE_ONLY: &[&str] = &[
    "print",
    "key",
    "clef",
    "staves",
    "staff-details",
    "part-symbol",
    "instruments",
    "measure-style",
    "footnote",
    "level",
    "harmony",
    "figured-bass",
    "bookmark",
    "link",
    "grouping",
    "listening",
    "for-part",
];

impl<'a, 'd> PartReader<'a, 'd> {
    fn new(path: &'a Path, doc: &'a Document<'d>, tpq: u64, instrument: Option<String>) -> Self {
        PartReader {
            path,
            doc,
            tpq,
            instrument,
            divisions: 1.0,
            transpose: 0,
            notes: Vec::new(),
            measures: Vec::new(),
            tempos: Vec::new(),
            dynamics: Vec::new(),
            notices: Notices::default(),
            ties: Vec::new(),
            rounded: false,
            signature: None,
        }
    }

    fn line(&self, node: Node) -> u32 {
        self.doc.text_pos_at(node.range().start).row
    }

    fn invalid(&self, node: Node, measure: &str, message: String) -> MusicXmlError {
        MusicXmlError::Invalid {
            path: self.path.to_path_buf(),
            line: self.line(node),
            measure: measure.to_string(),
            message,
        }
    }

    /// A duration element's value in ticks.
    fn ticks(&mut self, node: Node, measure: &str) -> Result<u64, MusicXmlError> {
        let text = node.text().unwrap_or("").trim();
        let value: f64 = text
            .parse()
            .ok()
            .filter(|v: &f64| v.is_finite() && *v >= 0.0 && *v < 1e12)
            .ok_or_else(|| {
                self.invalid(
                    node,
                    measure,
                    format!(
                        "<{}> \"{text}\" is not a duration (a number of divisions ≥ 0)",
                        node.tag_name().name()
                    ),
                )
            })?;
        let exact = value * self.tpq as f64 / self.divisions;
        if exact > 1e12 {
            return Err(self.invalid(
                node,
                measure,
                format!(
                    "<{}> {text} at {} divisions per quarter is longer than a score can hold",
                    node.tag_name().name(),
                    self.divisions
                ),
            ));
        }
        let ticks = exact.round();
        if (ticks - exact).abs() > 1e-6 && !self.rounded {
            self.rounded = true;
            self.notices.add(
                "a duration is not a whole number of score ticks; rounded",
                &format!("measure {measure}"),
            );
        }
        Ok(ticks as u64)
    }

    fn read(&mut self, part: Node) -> Result<(), MusicXmlError> {
        let written: Vec<Node> = part
            .children()
            .filter(|n| n.has_tag_name("measure"))
            .collect();
        let order = match repeats::performed_order(&written) {
            Some((order, notes)) => {
                for note in notes {
                    self.notices.push_text(note);
                }
                order
            }
            None => {
                self.notices.push_text(
                    "the repeats and endings do not resolve into an order of measures; the music is played once, as written".into(),
                );
                (0..written.len()).collect()
            }
        };
        if order.len() != written.len() {
            self.notices.push_text(format!(
                "repeats expanded: the {} written measures are played as {}",
                written.len(),
                order.len()
            ));
        }
        for m in order.into_iter().map(|i| written[i]) {
            let number = m.attribute("number").unwrap_or("?").to_string();
            let start = self.measures.iter().map(|m| m.length).sum::<u64>();
            let length = self.read_measure(m, start, &number)?;
            let nominal = self
                .signature
                .map(|(n, d)| u64::from(n) * 4 * self.tpq / u64::from(d));
            // A measure with nothing in it lasts its time signature.
            let length = if length == 0 {
                nominal.unwrap_or(0)
            } else {
                length
            };
            self.measures.push(Measure {
                length,
                signature: self.signature,
                number,
                implicit: m.attribute("implicit") == Some("yes"),
            });
        }
        self.notes = two_note_tremolos(std::mem::take(&mut self.notes), self.tpq);
        let max_damp = crate::score::validate::MAX_DAMP_QUARTERS * self.tpq;
        for n in &mut self.notes {
            // A damped roll's tremolo may stop before its tied notes do.
            let roll_end = if n.damped { n.roll_end } else { n.end };
            n.roll = n.strokes.and_then(|spq| {
                (roll_end > n.tick).then_some(Roll {
                    length_ticks: roll_end - n.tick,
                    strokes_per_quarter: spq,
                })
            });
            let last_stroke = n.tick + n.roll.map_or(0, |r| r.length_ticks);
            n.damp = n
                .damped
                .then(|| n.end.saturating_sub(last_stroke).clamp(1, max_damp));
        }
        Ok(())
    }

    /// Read one measure starting at score tick `start`; returns its length in ticks.
    fn read_measure(&mut self, m: Node, start: u64, number: &str) -> Result<u64, MusicXmlError> {
        let place = format!("measure {number}");
        let mut pos: i64 = 0;
        let mut longest: i64 = 0;
        let mut last_start: i64 = 0;
        for el in m.children().filter(Node::is_element) {
            let at = |p: i64| start.saturating_add_signed(p.max(-(start as i64)));
            match el.tag_name().name() {
                "attributes" => self.attributes(el, number)?,
                "note" => {
                    let chord = el.children().any(|c| c.has_tag_name("chord"));
                    let grace = el.children().any(|c| c.has_tag_name("grace"));
                    let duration = match el.children().find(|c| c.has_tag_name("duration")) {
                        Some(d) => self.ticks(d, number)? as i64,
                        None => 0,
                    };
                    let note_start = if chord { last_start } else { pos };
                    if grace {
                        self.notices
                            .add("grace note: skipped (grace notes take no time)", &place);
                        continue;
                    }
                    if !chord {
                        last_start = pos;
                        pos += duration;
                        longest = longest.max(pos);
                    }
                    self.note(el, at(note_start), duration as u64, number)?;
                }
                "backup" => {
                    let d = el.children().find(|c| c.has_tag_name("duration"));
                    let d = match d {
                        Some(d) => self.ticks(d, number)? as i64,
                        None => 0,
                    };
                    pos -= d;
                    if pos < 0 {
                        self.notices.add(
                            "<backup> goes back past the start of its measure; clamped",
                            &place,
                        );
                        pos = 0;
                    }
                }
                "forward" => {
                    let d = el.children().find(|c| c.has_tag_name("duration"));
                    if let Some(d) = d {
                        pos += self.ticks(d, number)? as i64;
                        longest = longest.max(pos);
                    }
                }
                "direction" => {
                    let offset = match el.children().find(|c| c.has_tag_name("offset")) {
                        Some(o) => self.signed_ticks(o, number)?,
                        None => 0,
                    };
                    self.direction(el, at(pos + offset), number);
                }
                "sound" => {
                    let offset = match el.children().find(|c| c.has_tag_name("offset")) {
                        Some(o) => self.signed_ticks(o, number)?,
                        None => 0,
                    };
                    self.sound(el, at(pos + offset), number);
                }
                "barline" => self.barline(el, number),
                name if PAGE_ONLY.contains(&name) => {}
                other => self.notices.add(format!("<{other}>: not read"), &place),
            }
        }
        Ok(longest.max(0) as u64)
    }

    /// An `<offset>` (may be negative) in ticks.
    fn signed_ticks(&mut self, node: Node, measure: &str) -> Result<i64, MusicXmlError> {
        let text = node.text().unwrap_or("").trim();
        let negative = text.starts_with('-');
        let value: f64 = text.trim_start_matches('-').parse().map_err(|_| {
            self.invalid(
                node,
                measure,
                format!("<offset> \"{text}\" is not a number of divisions"),
            )
        })?;
        let ticks = (value * self.tpq as f64 / self.divisions).round() as i64;
        Ok(if negative { -ticks } else { ticks })
    }

    fn attributes(&mut self, el: Node, number: &str) -> Result<(), MusicXmlError> {
        let place = format!("measure {number}");
        for a in el.children().filter(Node::is_element) {
            match a.tag_name().name() {
                "divisions" => {
                    let text = a.text().unwrap_or("").trim();
                    self.divisions = text
                        .parse::<f64>()
                        .ok()
                        .filter(|d| d.is_finite() && *d > 0.0)
                        .ok_or_else(|| {
                            self.invalid(
                                a,
                                number,
                                format!("<divisions> \"{text}\" is not a positive number"),
                            )
                        })?;
                }
                "time" => self.time(a, &place),
                "transpose" => {
                    let chromatic: i32 = text_of(a, "chromatic").parse().unwrap_or(0);
                    let octaves: i32 = text_of(a, "octave-change").parse().unwrap_or(0);
                    self.transpose = chromatic + 12 * octaves;
                }
                "directive" => self.notices.add(
                    format!(
                        "directive \"{}\": not performed",
                        a.text().unwrap_or("").trim()
                    ),
                    &place,
                ),
                name if PAGE_ONLY.contains(&name) => {}
                other => self.notices.add(format!("<{other}>: not read"), &place),
            }
        }
        Ok(())
    }

    /// A `<time>`: the sum of its beats/beat-type pairs ("3+2" beats add up).
    fn time(&mut self, t: Node, place: &str) {
        if t.children().any(|c| c.has_tag_name("senza-misura")) {
            self.notices.add(
                "senza misura (no time signature): bars follow the written measures",
                place,
            );
            self.signature = None;
            return;
        }
        let beats: Vec<u32> = t
            .children()
            .filter(|c| c.has_tag_name("beats"))
            .map(|c| {
                c.text()
                    .unwrap_or("")
                    .split('+')
                    .map(|x| x.trim().parse::<u32>().unwrap_or(0))
                    .sum()
            })
            .collect();
        let types: Vec<u32> = t
            .children()
            .filter(|c| c.has_tag_name("beat-type"))
            .map(|c| c.text().unwrap_or("").trim().parse().unwrap_or(0))
            .collect();
        let ok = !beats.is_empty()
            && beats.len() == types.len()
            && types.iter().all(|d| d.is_power_of_two() && *d <= 32)
            && beats.iter().all(|b| *b > 0);
        if !ok {
            self.notices.add(
                "a time signature timpanist cannot hold (beat types other than 1–32, or none): bars follow the written measures",
                place,
            );
            return;
        }
        let den = *types.iter().max().expect("not empty");
        let num: u32 = beats.iter().zip(&types).map(|(b, d)| b * (den / d)).sum();
        if beats.len() > 1 {
            self.notices.add(
                format!("compound time signature read as {num}/{den}"),
                place,
            );
        }
        self.signature = Some((num, den));
    }

    /// A `<note>` at score tick `tick`, lasting `duration` ticks.
    fn note(
        &mut self,
        el: Node,
        tick: u64,
        duration: u64,
        number: &str,
    ) -> Result<(), MusicXmlError> {
        let place = format!("measure {number}");
        if el.children().any(|c| c.has_tag_name("rest")) {
            return Ok(());
        }
        if el.children().any(|c| c.has_tag_name("cue")) {
            self.notices
                .add("cue note (another part's music): skipped", &place);
            return Ok(());
        }
        if let Some(want) = &self.instrument {
            let inst = el
                .children()
                .find(|c| c.has_tag_name("instrument"))
                .and_then(|c| c.attribute("id"));
            if inst.is_some_and(|i| i != want) {
                return Ok(());
            }
        }
        let Some(pitch) = self.pitch(el, number)? else {
            return Ok(());
        };
        for c in el.children().filter(Node::is_element) {
            match c.tag_name().name() {
                "grace" | "cue" | "chord" | "pitch" | "unpitched" | "rest" | "duration" | "tie"
                | "instrument" | "footnote" | "level" | "voice" | "type" | "dot" | "accidental"
                | "time-modification" | "stem" | "notehead" | "notehead-text" | "staff"
                | "beam" | "notations" | "lyric" | "play" | "listen" => {}
                other => self
                    .notices
                    .add(format!("<{other}> in a note: not read"), &place),
            }
        }
        let tie_types: Vec<&str> = el
            .children()
            .filter(|c| c.has_tag_name("tie"))
            .chain(
                el.children()
                    .filter(|c| c.has_tag_name("notations"))
                    .flat_map(|n| n.children().filter(|c| c.has_tag_name("tied"))),
            )
            .filter_map(|t| t.attribute("type"))
            .collect();
        let tie_stop = tie_types.iter().any(|t| *t == "stop" || *t == "continue");
        let tie_start = tie_types.iter().any(|t| *t == "start" || *t == "continue");
        if tie_stop {
            let open = self
                .ties
                .iter()
                .position(|&(p, i)| p == pitch && self.notes[i].end == tick)
                .or_else(|| self.ties.iter().position(|&(p, _)| p == pitch));
            if let Some(k) = open {
                let i = self.ties[k].1;
                self.notes[i].end = self.notes[i].end.max(tick + duration);
                let rolled = has_mark(el, "ornaments", "tremolo");
                if rolled && self.notes[i].strokes.is_some() {
                    self.notes[i].roll_end = self.notes[i].end;
                }
                self.notes[i].damped |= has_mark(el, "technical", "stopped");
                if !tie_start {
                    self.ties.remove(k);
                }
                return Ok(());
            }
            self.notices.add(
                "a tie ends on a note no tie starts on: played as a new stroke",
                &place,
            );
        }
        self.ties.retain(|&(p, _)| p != pitch);
        let marks = self.notations(el, tick, &place);
        self.notes.push(XNote {
            tick,
            end: tick + duration,
            pitch,
            mode: marks.mode,
            hand: marks.hand,
            strokes: marks.strokes,
            roll_end: tick + duration,
            damped: marks.damped,
            two_note: marks.two_note,
            roll: None,
            damp: None,
        });
        if tie_start {
            self.ties.push((pitch, self.notes.len() - 1));
        }
        Ok(())
    }

    /// The sounding MIDI pitch of a note (`None`: outside MIDI's range, reported).
    fn pitch(&mut self, el: Node, number: &str) -> Result<Option<u8>, MusicXmlError> {
        let place = format!("measure {number}");
        let (node, step_tag, octave_tag) =
            if let Some(p) = el.children().find(|c| c.has_tag_name("pitch")) {
                (p, "step", "octave")
            } else if let Some(p) = el.children().find(|c| c.has_tag_name("unpitched")) {
                self.notices.add(
                    "unpitched (percussion staff) note: read at its written staff position",
                    &place,
                );
                (p, "display-step", "display-octave")
            } else {
                return Err(self.invalid(
                    el,
                    number,
                    "a <note> with neither <pitch>, <unpitched> nor <rest>".into(),
                ));
            };
        if node.has_tag_name("unpitched")
            && !node.children().any(|c| c.has_tag_name("display-step"))
        {
            // No staff position: the middle line of a treble staff.
            return Ok(Some(71));
        }
        let step = match text_of(node, step_tag).as_str() {
            "C" => 0,
            "D" => 2,
            "E" => 4,
            "F" => 5,
            "G" => 7,
            "A" => 9,
            "B" => 11,
            other => {
                return Err(self.invalid(
                    node,
                    number,
                    format!("<{step_tag}> \"{other}\" is not A–G"),
                ));
            }
        };
        let octave_text = text_of(node, octave_tag);
        let octave: i32 = octave_text.parse().map_err(|_| {
            self.invalid(
                node,
                number,
                format!("<{octave_tag}> \"{octave_text}\" is not an octave number"),
            )
        })?;
        let alter_text = text_of(node, "alter");
        let alter: f64 = if alter_text.is_empty() {
            0.0
        } else {
            alter_text.parse().map_err(|_| {
                self.invalid(
                    node,
                    number,
                    format!("<alter> \"{alter_text}\" is not a number of semitones"),
                )
            })?
        };
        if alter.fract() != 0.0 {
            self.notices.add(
                "microtonal alteration: rounded to the nearest semitone",
                &place,
            );
        }
        let midi = (octave + 1) * 12 + step + alter.round() as i32 + self.transpose;
        match u8::try_from(midi).ok().filter(|m| *m <= 127) {
            Some(m) => Ok(Some(m)),
            None => {
                self.notices
                    .add("a note outside MIDI's pitch range: skipped", &place);
                Ok(None)
            }
        }
    }

    /// A note's playing mode, tremolo, sticking and damping from its notations; its
    /// dynamics and what is not performed go to the dynamics and the notices.
    fn notations(&mut self, el: Node, tick: u64, place: &str) -> NoteMarks {
        let mut marks: Vec<PlayingMode> = Vec::new();
        let mut strokes = None;
        let mut two_note = None;
        let (mut hand, mut damped) = (Hand::Auto, false);
        for notations in el.children().filter(|c| c.has_tag_name("notations")) {
            for n in notations.children().filter(Node::is_element) {
                match n.tag_name().name() {
                    "tied" | "slur" | "tuplet" | "accidental-mark" | "footnote" | "level" => {}
                    "articulations" => {
                        for a in n.children().filter(Node::is_element) {
                            match a.tag_name().name() {
                                "accent" => marks.push(PlayingMode::Accent),
                                "strong-accent" => marks.push(PlayingMode::VerticalAccent),
                                "staccato" | "staccatissimo" | "spiccato" => {
                                    marks.push(PlayingMode::Staccato);
                                }
                                "tenuto" | "detached-legato" => marks.push(PlayingMode::Tenuto),
                                other => self
                                    .notices
                                    .add(format!("articulation <{other}>: not performed"), place),
                            }
                        }
                    }
                    "ornaments" => {
                        for o in n.children().filter(Node::is_element) {
                            if o.has_tag_name("tremolo") {
                                match o.attribute("type") {
                                    Some("start") => {
                                        two_note = Some(TwoNote::Start(two_note_strokes(el, o)));
                                    }
                                    Some("stop") => two_note = Some(TwoNote::Stop),
                                    _ => strokes = self.tremolo(o, place).or(strokes),
                                }
                            } else if !o.has_tag_name("accidental-mark") {
                                self.notices.add(
                                    format!("ornament <{}>: not performed", o.tag_name().name()),
                                    place,
                                );
                            }
                        }
                    }
                    "dynamics" => self.dynamics(n, tick, place),
                    "technical" => {
                        for t in n.children().filter(Node::is_element) {
                            match (t.tag_name().name(), t.text().map(str::trim)) {
                                ("stopped", _) => damped = true,
                                ("other-technical", Some("R")) => hand = Hand::Right,
                                ("other-technical", Some("L")) => hand = Hand::Left,
                                (other, _) => self
                                    .notices
                                    .add(format!("technical mark <{other}>: not performed"), place),
                            }
                        }
                    }
                    "fermata" => self.notices.add(
                        "fermata: not performed (the note keeps its written length)",
                        place,
                    ),
                    other => self
                        .notices
                        .add(format!("notation <{other}>: not performed"), place),
                }
            }
        }
        // Several marks: the strongest (marcato, accent, staccato, tenuto).
        let rank = |m: &PlayingMode| match m {
            PlayingMode::VerticalAccent => 0,
            PlayingMode::Accent => 1,
            PlayingMode::Staccato => 2,
            PlayingMode::Tenuto => 3,
            PlayingMode::Legato => 4,
        };
        let mode = marks
            .into_iter()
            .min_by_key(rank)
            .unwrap_or(PlayingMode::Legato);
        NoteMarks {
            mode,
            strokes,
            hand,
            damped,
            two_note,
        }
    }

    /// A `<tremolo>`: single with n marks is 2^n strokes per quarter (1 mark eighths, 3
    /// thirty-seconds); unmeasured is a free roll; two-note tremolos are reported.
    fn tremolo(&mut self, t: Node, place: &str) -> Option<u32> {
        match t.attribute("type").unwrap_or("single") {
            "single" => {
                let marks: u32 = t.text().unwrap_or("").trim().parse().unwrap_or(3);
                if !(1..=5).contains(&marks) {
                    self.notices.add(
                        format!("tremolo with {marks} marks: read as an unmeasured roll"),
                        place,
                    );
                    return Some(UNMEASURED_STROKES_PER_QUARTER);
                }
                Some(1 << marks)
            }
            "unmeasured" => Some(UNMEASURED_STROKES_PER_QUARTER),
            _ => None,
        }
    }

    /// `<dynamics>` at `tick`.
    fn dynamics(&mut self, d: Node, tick: u64, place: &str) {
        for m in d.children().filter(Node::is_element) {
            let name = m.tag_name().name();
            let event = match name {
                "sf" | "sfz" | "fz" | "rf" | "rfz" => Some(DynEvent::Single {
                    vel: 96.0,
                    then: None,
                    accent: true,
                }),
                "sffz" => Some(DynEvent::Single {
                    vel: 112.0,
                    then: None,
                    accent: true,
                }),
                "fp" => Some(DynEvent::Single {
                    vel: 96.0,
                    then: Some(49.0),
                    accent: false,
                }),
                "sfp" | "sfzp" => Some(DynEvent::Single {
                    vel: 96.0,
                    then: Some(49.0),
                    accent: true,
                }),
                "sfpp" => Some(DynEvent::Single {
                    vel: 96.0,
                    then: Some(33.0),
                    accent: true,
                }),
                "pf" => Some(DynEvent::Single {
                    vel: 49.0,
                    then: Some(96.0),
                    accent: false,
                }),
                other => level(other).map(DynEvent::Level),
            };
            match event {
                Some(e) => self.dynamics.push((tick, e)),
                None => self
                    .notices
                    .add(format!("dynamic <{name}>: not read"), place),
            }
        }
    }

    /// A `<direction>` whose time is `tick`.
    fn direction(&mut self, el: Node, tick: u64, number: &str) {
        let place = format!("measure {number}");
        let has_sound_tempo = el
            .children()
            .any(|c| c.has_tag_name("sound") && c.attribute("tempo").is_some());
        for c in el.children().filter(Node::is_element) {
            match c.tag_name().name() {
                "direction-type" => {
                    for t in c.children().filter(Node::is_element) {
                        self.direction_type(t, tick, &place, has_sound_tempo);
                    }
                }
                "sound" => self.sound(c, tick, number),
                "offset" | "voice" | "staff" | "footnote" | "level" | "listening" => {}
                other => self
                    .notices
                    .add(format!("<{other}> in a direction: not read"), &place),
            }
        }
    }

    fn direction_type(&mut self, t: Node, tick: u64, place: &str, has_sound_tempo: bool) {
        match t.tag_name().name() {
            "dynamics" => self.dynamics(t, tick, place),
            "wedge" => {
                let number = t
                    .attribute("number")
                    .and_then(|n| n.parse().ok())
                    .unwrap_or(1);
                match t.attribute("type") {
                    Some("crescendo") => self
                        .dynamics
                        .push((tick, DynEvent::Wedge { up: true, number })),
                    Some("diminuendo") => {
                        self.dynamics
                            .push((tick, DynEvent::Wedge { up: false, number }));
                    }
                    Some("stop") => self.dynamics.push((tick, DynEvent::WedgeStop { number })),
                    _ => {}
                }
            }
            "metronome" => {
                // <sound tempo> in the same direction is what is played.
                if has_sound_tempo {
                    return;
                }
                match metronome_bpm(t) {
                    Some(bpm) => self.tempos.push((tick, bpm, false)),
                    None => self.notices.add(
                        "metronome mark other than \"note = number\" (e.g. a metric modulation): not read",
                        place,
                    ),
                }
            }
            "words" => {
                let text: String = t.text().unwrap_or("").trim().chars().take(40).collect();
                if !text.is_empty() && !repeats::is_jump_mark(&text) {
                    self.notices
                        .add(format!("text \"{text}\": not performed"), place);
                }
            }
            "rehearsal" | "dashes" | "bracket" | "octave-shift" | "image" => {}
            // Followed by `musicxml_repeats`.
            "segno" | "coda" => {}
            other => self
                .notices
                .add(format!("direction <{other}>: not performed"), place),
        }
    }

    /// A `<sound>`: its tempo (quarter notes per minute); jumps are reported.
    fn sound(&mut self, s: Node, tick: u64, number: &str) {
        let place = format!("measure {number}");
        if let Some(tempo) = s.attribute("tempo") {
            match tempo
                .trim()
                .parse::<f64>()
                .ok()
                .filter(|t| t.is_finite() && *t > 0.0)
            {
                Some(bpm) => self.tempos.push((tick, bpm, true)),
                None => self
                    .notices
                    .add(format!("<sound tempo=\"{tempo}\">: not a tempo"), &place),
            }
        }
        // Jumps (dacapo, dalsegno, tocoda, fine, segno, coda) are followed by
        // `musicxml_repeats`; a forward repeat is read from the bar line.
    }

    fn barline(&mut self, b: Node, number: &str) {
        let place = format!("measure {number}");
        for c in b.children().filter(Node::is_element) {
            match c.tag_name().name() {
                "segno" | "coda" => self.notices.add(
                    format!(
                        "{} on a bar line: not followed (write it as a direction)",
                        c.tag_name().name()
                    ),
                    &place,
                ),
                "fermata" => self
                    .notices
                    .add("fermata on a barline: not performed", &place),
                _ => {}
            }
        }
    }
}

/// Whether `note` has the notation `<notations><group><name>` (e.g. technical, stopped).
fn has_mark(note: Node, group: &str, name: &str) -> bool {
    note.children()
        .filter(|c| c.has_tag_name("notations"))
        .flat_map(|n| n.children().filter(|c| c.has_tag_name(group)))
        .any(|g| g.children().any(|c| c.has_tag_name(name)))
}

/// Strokes per quarter of a two-note tremolo starting at `note` with mark `tremolo`: its
/// marks add to the beams of the notes' written type (three marks between half notes
/// are thirty-seconds: 8 per quarter), 1 (eighths) to 5 in all.
fn two_note_strokes(note: Node, tremolo: Node) -> u32 {
    let marks: u32 = tremolo.text().unwrap_or("").trim().parse().unwrap_or(3);
    let beams = match text_of(note, "type").as_str() {
        "eighth" => 1,
        "16th" => 2,
        "32nd" => 3,
        "64th" => 4,
        _ => 0,
    };
    1 << (marks + beams).clamp(1, 5)
}

/// Two-note tremolos as their strokes: from the first note's start to the second's end,
/// alternating between the two pitches at the tremolo's rate (each a note of its own;
/// the first stroke on each pitch keeps its note's mode and hand). A half without its
/// other half is played as written.
fn two_note_tremolos(notes: Vec<XNote>, tpq: u64) -> Vec<XNote> {
    let mut out = Vec::with_capacity(notes.len());
    let mut open: std::collections::VecDeque<(XNote, u32)> = Default::default();
    for n in notes {
        match n.two_note {
            Some(TwoNote::Start(spq)) => open.push_back((n, spq)),
            Some(TwoNote::Stop) => match open.pop_front() {
                Some((first, spq)) => out.extend(alternate(&first, &n, spq, tpq)),
                None => out.push(n),
            },
            None => out.push(n),
        }
    }
    out.extend(open.into_iter().map(|(n, _)| n));
    out
}

/// The strokes of a two-note tremolo from `a` to `b` at `spq` strokes per quarter.
fn alternate(a: &XNote, b: &XNote, spq: u32, tpq: u64) -> Vec<XNote> {
    let spacing = (tpq / u64::from(spq.max(1))).max(1);
    let end = a.end.max(b.end);
    (a.tick..end)
        .step_by(spacing as usize)
        .enumerate()
        .map(|(k, tick)| {
            let from = if k % 2 == 0 { a } else { b };
            let first = k < 2;
            XNote {
                tick,
                end: (tick + spacing).min(end),
                pitch: from.pitch,
                mode: if first {
                    from.mode
                } else {
                    PlayingMode::Legato
                },
                hand: if first { from.hand } else { Hand::Auto },
                strokes: None,
                roll_end: tick,
                damped: false,
                two_note: None,
                roll: None,
                damp: None,
            }
        })
        .collect()
}

/// Quarter notes per minute of a `<metronome>` "beat-unit [dots] = per-minute".
fn metronome_bpm(m: Node) -> Option<f64> {
    let units: Vec<Node> = m
        .children()
        .filter(|c| c.has_tag_name("beat-unit"))
        .collect();
    let [unit] = units[..] else { return None };
    let quarters = match unit.text()?.trim() {
        "maxima" => 32.0,
        "long" => 16.0,
        "breve" => 8.0,
        "whole" => 4.0,
        "half" => 2.0,
        "quarter" => 1.0,
        "eighth" => 0.5,
        "16th" => 0.25,
        "32nd" => 0.125,
        "64th" => 0.0625,
        _ => return None,
    };
    let dots = m
        .children()
        .filter(|c| c.has_tag_name("beat-unit-dot"))
        .count();
    let dotted = quarters * (2.0 - 0.5f64.powi(i32::try_from(dots).ok()?));
    let text = text_of(m, "per-minute");
    // "120", "c. 120", "120-132": the first number.
    let start = text.find(|c: char| c.is_ascii_digit())?;
    let rest = &text[start..];
    let end = rest
        .find(|c: char| !(c.is_ascii_digit() || c == '.'))
        .unwrap_or(rest.len());
    let per_minute: f64 = rest[..end].trim_end_matches('.').parse().ok()?;
    (per_minute > 0.0).then_some(per_minute * dotted)
}

/// The movement title, else the work title.
fn title_of(root: Node) -> Option<String> {
    let movement = text_of(root, "movement-title");
    if !movement.is_empty() {
        return Some(movement);
    }
    let work = root.children().find(|n| n.has_tag_name("work"))?;
    Some(text_of(work, "work-title")).filter(|t| !t.is_empty())
}

/// A roll takes both hands: of notes starting together with a rolled one, keep the
/// rolled one (the lowest if several).
fn one_roll_per_chord(mut notes: Vec<XNote>, notices: &mut Notices) -> Vec<XNote> {
    notes.sort_by_key(|n| (n.tick, n.roll.is_none(), n.pitch));
    let mut kept: Vec<XNote> = Vec::with_capacity(notes.len());
    for n in notes {
        match kept.last() {
            Some(k) if k.tick == n.tick && k.roll.is_some() => {
                notices.add(
                    "a rolled chord: rolled on its lowest (rolled) note only, as a roll takes both hands",
                    &format!("score tick {}", n.tick),
                );
            }
            _ => kept.push(n),
        }
    }
    kept
}

// ---------------------------------------------------------------------------------------
// Dynamics over time.

/// The dynamic level over time: markings, single accented strokes, hairpins.
struct Levels {
    /// (tick, velocity) level changes, in time order.
    marks: Vec<(u64, f64)>,
    /// (tick, velocity, accented) single strokes.
    singles: Vec<(u64, f64, bool)>,
    /// (start, end, from, to) hairpins, linear in MIDI velocity.
    ramps: Vec<(u64, u64, f64, f64)>,
}

impl Levels {
    fn new(events: &[(u64, DynEvent)], tpq: u64) -> Self {
        let mut events = events.to_vec();
        events.sort_by_key(|e| e.0);
        let mut marks = Vec::new();
        let mut singles = Vec::new();
        let mut open: Vec<(u32, u64, bool)> = Vec::new();
        let mut wedges: Vec<(u64, u64, bool)> = Vec::new();
        for &(tick, e) in &events {
            match e {
                DynEvent::Level(v) => marks.push((tick, v)),
                DynEvent::Single { vel, then, accent } => {
                    singles.push((tick, vel, accent));
                    if let Some(t) = then {
                        marks.push((tick, t));
                    }
                }
                DynEvent::Wedge { up, number } => {
                    open.retain(|w| w.0 != number);
                    open.push((number, tick, up));
                }
                DynEvent::WedgeStop { number } => {
                    if let Some(k) = open.iter().position(|w| w.0 == number) {
                        let (_, start, up) = open.remove(k);
                        wedges.push((start, tick, up));
                    }
                }
            }
        }
        let mut levels = Levels {
            marks,
            singles,
            ramps: Vec::new(),
        };
        for (start, stop, up) in wedges {
            let from = levels.mark_at(start);
            // The marking that closes the hairpin: at its end or within a quarter after.
            let closing = levels
                .marks
                .iter()
                .find(|(t, _)| *t >= stop && *t <= stop + tpq)
                .copied();
            let (end, to) = closing.unwrap_or_else(|| (stop, step(from, up)));
            if closing.is_none() {
                let at = levels.marks.partition_point(|(t, _)| *t <= stop);
                levels.marks.insert(at, (stop, to));
            }
            if end > start {
                levels.ramps.push((start, end, from, to));
            }
        }
        levels
    }

    /// The level of the last marking at or before `tick` (mf before any).
    fn mark_at(&self, tick: u64) -> f64 {
        self.marks
            .iter()
            .rev()
            .find(|(t, _)| *t <= tick)
            .map_or(DEFAULT_VELOCITY, |m| m.1)
    }

    /// The MIDI velocity at `tick` (fractional inside hairpins) and whether the stroke
    /// there is accented (sf, sfz…).
    fn at(&self, tick: u64) -> (f64, bool) {
        if let Some(&(_, v, accent)) = self.singles.iter().rev().find(|s| s.0 == tick) {
            return (v, accent);
        }
        for &(start, end, from, to) in self.ramps.iter().rev() {
            if tick > start && tick < end {
                let x = (tick - start) as f64 / (end - start) as f64;
                return ((from + (to - from) * x).clamp(1.0, 127.0), false);
            }
        }
        (self.mark_at(tick), false)
    }
}

/// The next marking up (or down) from velocity `v` among pp … ff, else `v` ± 16.
fn step(v: f64, up: bool) -> f64 {
    let marks = Dynamic::MARKS.map(|(_, m, _)| f64::from(m));
    let next = if up {
        marks.iter().copied().find(|m| *m > v)
    } else {
        marks.iter().rev().copied().find(|m| *m < v)
    };
    next.unwrap_or(if up { v + 16.0 } else { v - 16.0 })
        .clamp(1.0, 127.0)
}

// ---------------------------------------------------------------------------------------
// Tempo and meter.

/// Tempo points from (tick, bpm, from `<sound>`): a `<sound tempo>` wins over a metronome
/// mark at the same tick; 120 bpm until the first; steps; clamped into the score's range.
fn tempo_points(tempos: &[(u64, f64, bool)], notices: &mut Notices) -> Vec<TempoPoint> {
    let step = |tick, bpm| TempoPoint {
        tick,
        bpm,
        change: TempoChange::Step,
    };
    let mut sorted = tempos.to_vec();
    sorted.sort_by_key(|a| (a.0, a.2));
    let mut points = vec![step(0, DEFAULT_BPM)];
    for (tick, bpm, _) in sorted {
        let clamped = bpm.clamp(*BPM_RANGE.start(), *BPM_RANGE.end());
        if clamped != bpm {
            notices.add(
                format!(
                    "tempo outside {}–{} bpm: clamped",
                    BPM_RANGE.start(),
                    BPM_RANGE.end()
                ),
                &format!("score tick {tick}"),
            );
        }
        let last = points.last_mut().expect("points start with one");
        if last.tick == tick {
            last.bpm = clamped;
        } else if last.bpm != clamped {
            points.push(step(tick, clamped));
        }
    }
    points.dedup_by(|b, a| a.bpm == b.bpm);
    points
}

/// `length` ticks as a time signature (numerator 1–64 over 1–32), preferring `den`.
fn signature_of(length: u64, tpq: u64, den: u32) -> Option<(u32, u32)> {
    std::iter::once(den)
        .chain([4, 8, 16, 32, 2, 1])
        .find_map(|d| {
            let whole = 4 * tpq;
            let num = length * u64::from(d);
            num.is_multiple_of(whole)
                .then(|| num / whole)
                .filter(|n| (1..=64).contains(n))
                .map(|n| (n as u32, d))
        })
}

/// Time signatures from the measures: each bar as long as its measure (a pickup or an
/// incomplete measure gets its own signature, so later bars fall where the file's do).
fn meter_changes(measures: &[Measure], tpq: u64, notices: &mut Notices) -> Vec<MeterChange> {
    let mut changes: Vec<MeterChange> = Vec::new();
    let tpq32 = u32::try_from(tpq).expect("ticks per quarter fit in u32");
    for (i, m) in measures.iter().enumerate() {
        let written = m.signature.unwrap_or((4, 4));
        let nominal = u64::from(written.0) * 4 * tpq / u64::from(written.1);
        let sig = if m.length == nominal {
            Some(written)
        } else {
            let s = signature_of(m.length, tpq, written.1);
            match (s, m.implicit || i == 0) {
                (Some(s), true) => notices.add(
                    format!("pickup measure: its bar is {}/{}", s.0, s.1),
                    &format!("measure {}", m.number),
                ),
                (Some(s), false) if m.signature.is_some() => notices.add(
                    format!(
                        "a measure shorter or longer than its time signature: its bar is {}/{}",
                        s.0, s.1
                    ),
                    &format!("measure {}", m.number),
                ),
                (None, _) => notices.add(
                    "a measure whose length is no time signature: later bar lines are shifted",
                    &format!("measure {}", m.number),
                ),
                _ => {}
            }
            s
        };
        let Some((numerator, denominator)) = sig else {
            continue;
        };
        if changes
            .last()
            .is_none_or(|c| (c.numerator, c.denominator) != (numerator, denominator))
        {
            changes.push(MeterChange {
                bar: u32::try_from(i + 1).unwrap_or(u32::MAX),
                numerator,
                denominator,
            });
        }
    }
    if changes.first().is_none_or(|c| c.bar != 1) {
        changes.insert(
            0,
            MeterChange {
                bar: 1,
                numerator: 4,
                denominator: 4,
            },
        );
    }
    if !meter::validate_changes(&changes, tpq32).is_empty() {
        notices
            .push_text("the measures' time signatures do not fit a score; the meter is 4/4".into());
        changes.truncate(1);
        changes[0] = MeterChange {
            bar: 1,
            numerator: 4,
            denominator: 4,
        };
    }
    changes
}
