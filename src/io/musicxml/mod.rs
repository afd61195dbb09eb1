//! MusicXML import: finds the timpani part of a partwise MusicXML file (`.musicxml`,
//! `.xml`, or the compressed `.mxl` zip with its `META-INF/container.xml`) and turns its
//! notes into a score a timpanist can play on a given kit.
//!
//! The part is the one named by `--part` (its id, or part of its name), else one whose
//! instrument sound is `drum.timpani…` or whose MIDI program is 48 (General MIDI
//! "Timpani"), else one named like "Timpani", "Timp.", "Kettledrums", "Pk.", "Pauken" or
//! "Timbales" (whole words: `crate::base::instrument_name`, shared with the MIDI import).
//! Musical time is exact: the score's ticks per quarter are the least common multiple of
//! 960 and every `<divisions>` of the part. Each sounding note (a tie's later notes extend
//! the first; grace and cue notes are skipped and reported) becomes a beat on a drum chosen
//! as [`super::midi_import`] does (a drum tuned to the pitch, else the one idle longest;
//! out-of-range pitches move by octaves). Measures play in performed order, repeats and
//! volta endings expanded ([`repeats`]). Tremolo marks become rolls (a
//! two-note tremolo: strokes alternating between its two notes), and so do trill marks
//! (at an unmeasured tremolo's rate, over the notes up to their wavy line's stop),
//! dynamics and hairpins
//! per-beat dynamics, articulations playing modes, `<stopped/>` damping when the note
//! ends, `<other-technical>` R/L the hand, `<sound tempo>` and `<metronome>` — of every
//! part, since tempo is the whole score's — the tempo map (quarter notes per minute),
//! time signatures and measure lengths the meter map.
//! Whatever is read but not performed (fermatas, jumps, ornaments, texts…) is listed in
//! [`ImportReport::notices`]; notation that only concerns the page (clefs, keys, beams,
//! stems, layout, lyrics, chord symbols) is left out silently.
//!
//! The file's text is read in [`file`], the part chosen in [`parts`] and read in
//! [`reader`] (its measures put in performed order by [`repeats`]), its dynamics over
//! time kept in [`levels`], the tempo marks of every part found in [`score_tempo`], its
//! tempo and meter maps made in [`timing`].

use super::midi_import::{self as midi, ANY_DRUM, Note};
use crate::kit::Kit;
use crate::score::meter;
use crate::score::tempo::{self, BPM_RANGE};
use crate::score::{
    Dynamic, Hand, ImpactLocation, MeterChange, PlayingMode, Roll, Score, TempoPoint,
};
use roxmltree::{Document, Node};
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::io::Read as _;
use std::path::{Path, PathBuf};

mod file;
mod levels;
mod parts;
mod reader;
mod repeats;
mod score_tempo;
mod timing;

use file::*;
use levels::*;
use parts::*;
use reader::*;
use score_tempo::*;
use timing::*;

/// Ticks per quarter note that every import's resolution is a multiple of.
const BASE_TICKS_PER_QUARTER: u64 = 960;
/// The finest resolution taken (ticks per quarter); beyond it durations are rounded.
const MAX_TICKS_PER_QUARTER: u64 = 960 * 3 * 5 * 7 * 11 * 13;
/// Tempo until the first tempo mark, quarter notes per minute (MusicXML's default).
const DEFAULT_BPM: f64 = 120.0;
/// Dynamic before the first marking (MIDI velocity of mf).
const DEFAULT_VELOCITY: f64 = 80.0;
/// Strokes per quarter note of an unmeasured tremolo or a trill (a free roll), as three
/// marks.
const UNMEASURED_STROKES_PER_QUARTER: u32 = 8;
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
    /// A file inside a `.mxl` that unpacks to more than
    /// [`MAX_MXL_ENTRY_BYTES`](crate::base::limits::MAX_MXL_ENTRY_BYTES) (a zip bomb).
    #[error(
        "{}: {entry} expands past {} MiB: not a score?",
        path.display(), crate::base::limits::MAX_MXL_ENTRY_BYTES >> 20
    )]
    EntryTooLarge { path: PathBuf, entry: String },
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
        "{}: no timpani part found (no instrument sound \"drum.timpani\", no MIDI program 48, no part named {}); choose one with --part ID or --part NAME:\n{parts}",
        path.display(), crate::base::instrument_name::TIMPANI_NAMES
    )]
    NoTimpani { path: PathBuf, parts: String },
    /// The timpani part holds rests only.
    #[error(
        "{}: the timpani part ({part}) has no notes (rests only), so there is nothing to import",
        path.display()
    )]
    TimpaniWithoutNotes { path: PathBuf, part: String },
    /// A score with no part at all.
    #[error(
        "{}: the score holds no parts (its part list and its <part> elements are empty), so there is nothing to import",
        path.display()
    )]
    NoParts { path: PathBuf },
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
    reader.score_tempos = score_tempo::other_parts(root, part_node, &parts);
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
            data: Some(midi_data(n.hand, mode, n.roll, n.drum)),
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

/// The target of the processing instruction `<?timpanist drum="N"?>` that timpanist's
/// export puts in each note to name its drum (notation programs leave it alone), so a
/// pitch two drums can play comes back on its own.
pub(crate) const DRUM_PI_TARGET: &str = "timpanist";

/// The hand, mode, roll and drum of a note in the MIDI import's terms (the drum left to
/// choose unless named; one that cannot play the note is chosen again).
fn midi_data(
    hand: Hand,
    mode: PlayingMode,
    roll: Option<Roll>,
    drum: Option<usize>,
) -> super::midi_export::BeatData {
    let drum = drum.unwrap_or(ANY_DRUM);
    super::midi_export::BeatData(hand, mode, drum, ImpactLocation::PlayingSpot, roll, None)
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
