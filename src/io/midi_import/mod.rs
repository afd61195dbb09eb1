//! Standard MIDI File import: finds the timpani part of a type 0 or type 1 file and turns
//! its notes into a score that a timpanist can play on a given kit.
//!
//! The part is the track (or, in a type 0 file, the channel) with General MIDI program 48
//! "Timpani" (the notes it plays while on that program), else a track whose name or instrument name (meta event FF 04) names the
//! timpani (`crate::base::instrument_name`, shared with MusicXML), else the percussion channel 10;
//! `--track` overrides. Every distinct note becomes a beat on a drum whose range holds its
//! pitch, chosen as a timpanist would (a drum already tuned to the pitch, else the one idle
//! longest); exact duplicates are dropped (seed 003, footnote 1). Tempo and time signatures
//! come from every track. Notes written by [`super::midi_export`] carry their hand, mode,
//! drum, impact location and roll, which are restored. Channels and programs are counted
//! from 1 in messages, as General MIDI does.
//!
//! The file's tracks are read in [`chunks`] (damage reported with its track and byte,
//! what can be read kept), their events in [`file`], the part chosen in [`part`], its notes cleaned in
//! [`notes`] and given drums in [`drums`], its tempo and meter maps made in [`timing`].

use super::midi_export::{BeatData, GM_TIMPANI};
use crate::base::pitch::Pitch;
use crate::kit::Kit;
use crate::score::meter;
use crate::score::tempo::{self, BPM_RANGE};
use crate::score::{
    Beat, Dynamic, Hand, ImpactLocation, MeterChange, MeterMap, PlayingMode, Roll, Score,
    TempoPoint,
};
use midly::{Format, MetaMessage, MidiMessage, Timing, TrackEvent, TrackEventKind};
use std::cmp::Reverse;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::str::FromStr;

/// Ticks per quarter note of scores imported from files that count time in SMPTE frames.
const TIMECODE_TICKS_PER_QUARTER: u32 = 960;
/// Tempo assumed for SMPTE-timed files and files without tempo events, bpm.
const DEFAULT_BPM: f64 = 120.0;
/// The General MIDI percussion channel (10, counted from 1).
const PERCUSSION_CHANNEL: u8 = 9;
/// Drum index in timpanist data that lets the import choose the drum.
pub(super) const ANY_DRUM: usize = usize::MAX;
/// Fewest evenly spaced repeated notes taken as a roll by `detect_rolls`.
const MIN_ROLL_NOTES: usize = 6;

/// Which track holds the timpani part.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum TrackChoice {
    /// The track at this index (0 is the first track of the file).
    Index(usize),
    /// The first track whose name contains this text, ignoring case.
    Name(String),
}

impl FromStr for TrackChoice {
    type Err = std::convert::Infallible;

    /// A number is a track index, anything else part of a track name.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Ok(s.trim()
            .parse()
            .map_or_else(|_| TrackChoice::Name(s.to_string()), TrackChoice::Index))
    }
}

/// How to import.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ImportOptions {
    /// The track to read; `None` finds the timpani part.
    pub track: Option<TrackChoice>,
    /// What goes into `Score.kit`: a bundled kit name or a `.ron` path.
    pub kit_ref: String,
    /// The score title; `None` takes the conductor track's name, else the file stem.
    pub title: Option<String>,
    /// Collapse runs of fast repeated notes into rolls.
    pub detect_rolls: bool,
}

impl Default for ImportOptions {
    fn default() -> Self {
        ImportOptions {
            track: None,
            kit_ref: "standard".into(),
            title: None,
            detect_rolls: false,
        }
    }
}

/// What an import did.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ImportReport {
    /// Which track and channel were read, and why.
    pub source: String,
    /// Note-on events read from that source (before dropping duplicates).
    pub notes: usize,
    /// Notes dropped as duplicates (same channel, tick and key; the loudest is kept).
    pub duplicates_dropped: usize,
    /// Notes moved by octaves because no drum reaches their pitch.
    pub octave_moves: usize,
    /// Anything else the user should know.
    pub warnings: Vec<String>,
}

/// Why a MIDI file could not be imported; every message names the file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum MidiError {
    /// The file could not be read.
    #[error("{}: cannot read the file: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// The bytes are not a Standard MIDI File timpanist can read.
    #[error(
        "{}: not a readable Standard MIDI File ({message}); check that it is a .mid file and not truncated, or re-export it from your notation program",
        path.display()
    )]
    Malformed { path: PathBuf, message: String },
    /// A type 2 file holds several independent songs.
    #[error(
        "{}: a type 2 (sequential) MIDI file holds several separate songs, which timpanist cannot import; save it as a type 0 or type 1 file",
        path.display()
    )]
    Sequential { path: PathBuf },
    /// `--track N` beyond the last track.
    #[error(
        "{}: there is no track {index}; the file has {count} tracks (0 to {}):\n{tracks}",
        path.display(), count.saturating_sub(1)
    )]
    TrackIndex {
        path: PathBuf,
        index: usize,
        count: usize,
        tracks: String,
    },
    /// `--track NAME` matches no track name.
    #[error(
        "{}: no track name contains \"{name}\"; choose one of these with --track N or --track NAME:\n{tracks}",
        path.display()
    )]
    TrackName {
        path: PathBuf,
        name: String,
        tracks: String,
    },
    /// Nothing looks like a timpani part.
    #[error(
        "{}: no timpani part found (no General MIDI program 48 \"Timpani\", no track or instrument named {}, no notes on percussion channel 10); choose a track with --track N or --track NAME:\n{tracks}",
        path.display(), crate::base::instrument_name::TIMPANI_NAMES
    )]
    NoTimpani { path: PathBuf, tracks: String },
    /// A header and no track.
    #[error(
        "{}: the file holds no tracks (a MIDI header and nothing after it), so there is nothing to import",
        path.display()
    )]
    NoTracks { path: PathBuf },
    /// Damage cost the file its timpani part (or every track).
    #[error(
        "{}: {damage}; no timpani part found in what can be read: repair the file or export it again from your notation program{choices}",
        path.display()
    )]
    Damaged {
        path: PathBuf,
        /// Where the (first) damage that lost events is.
        damage: String,
        /// ", or choose a track …" with the readable tracks, or nothing if there are none.
        choices: String,
    },
}

/// Read and import a MIDI file.
pub fn import_file(
    path: &Path,
    kit: &Kit,
    options: &ImportOptions,
) -> Result<(Score, ImportReport), MidiError> {
    let bytes = crate::base::limits::read_at_most(
        path,
        crate::base::limits::MAX_MIDI_FILE_BYTES,
        "MIDI file",
    )
    .map_err(|source| MidiError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    import(path, &bytes, kit, options)
}

/// Import the MIDI file `bytes` (`path` names it in messages) as a score on `kit`.
/// The score has no problems against `kit`.
pub fn import(
    path: &Path,
    bytes: &[u8],
    kit: &Kit,
    options: &ImportOptions,
) -> Result<(Score, ImportReport), MidiError> {
    let (header, track_chunks) = midly::parse(bytes).map_err(|e| MidiError::Malformed {
        path: path.to_path_buf(),
        message: e.to_string(),
    })?;
    let malformed = |message: &str| MidiError::Malformed {
        path: path.to_path_buf(),
        message: message.into(),
    };
    if header.format == Format::Sequential {
        return Err(MidiError::Sequential {
            path: path.to_path_buf(),
        });
    }
    let clock = match header.timing {
        Timing::Metrical(t) if t.as_int() == 0 => return Err(malformed("0 ticks per quarter")),
        // Scores need at least 24 ticks per quarter: scale finer, exactly, if needed.
        Timing::Metrical(t) => Clock::Metrical {
            tpq: u32::from(t.as_int()),
            scale: 24u32.div_ceil(u32::from(t.as_int())),
        },
        Timing::Timecode(_, 0) => return Err(malformed("0 ticks per SMPTE frame")),
        Timing::Timecode(fps, sub) => Clock::Timecode {
            ticks_per_s: f64::from(fps.as_f32()) * f64::from(sub),
        },
    };
    let (tracks, damage) = read_tracks(bytes, track_chunks.unread());
    let file = read_file(&tracks, &clock);
    let (source, chosen) =
        choose(path, &file, options).map_err(|e| damaged_instead(path, &file, &damage, e))?;
    let mut warnings: Vec<String> = damage.iter().map(|d| damage_text(&file, d)).collect();
    let (notes, left_out) = part_notes(&file, &chosen);
    let note_count = notes.len();
    let tpq = clock.ticks_per_quarter();
    let mut notes = skip_roll_strokes(notes);
    let duplicates_dropped = drop_duplicates(&mut notes);
    if chosen.percussion {
        map_percussion(&mut notes, kit);
    }
    if options.detect_rolls {
        detect_rolls(&mut notes, tpq);
    }
    limit_to_two_hands(&mut notes, &mut warnings);
    let octave_moves = move_into_range(&mut notes, kit, &mut warnings);
    let beats = assign_drums(&notes, kit, &mut warnings);
    if matches!(clock, Clock::Timecode { .. }) {
        warnings.push(format!(
            "the file counts time in SMPTE frames; converted at a fixed {DEFAULT_BPM} bpm"
        ));
    }
    let mut score = Score::new("");
    let stem = path.file_stem().unwrap_or_default().to_string_lossy();
    let conductor = file.tracks.first().map(|t| t.name.as_str());
    score.title = [options.title.as_deref(), conductor, Some(&*stem)]
        .into_iter()
        .flatten()
        .find(|t| !t.is_empty())
        .unwrap_or_default()
        .to_string();
    score.kit = options.kit_ref.clone();
    score.ticks_per_quarter = tpq;
    score.meter = meter_changes(&file.meters, tpq, &mut warnings);
    let meter = MeterMap::new(&score.meter, tpq);
    score.tempo = tempo_points(&file.tempos, &clock, &meter, &mut warnings);
    if let Some(left_out) = left_out {
        warnings.push(left_out.warning(&file, &chosen, &meter));
    }
    score.beats = beats;
    score.sort_beats();
    trim_rolls(&mut score.beats);
    if score.beats.is_empty() {
        warnings.push(format!("{source} has no notes"));
    }
    let report = ImportReport {
        source,
        notes: note_count,
        duplicates_dropped,
        octave_moves,
        warnings,
    };
    Ok((score, report))
}

mod chunks;
mod drums;
mod file;
mod notes;
mod part;
#[cfg(test)]
mod tests;
mod timing;

use chunks::*;
pub(in crate::io) use drums::{assign_drums, move_into_range, trim_rolls};
pub(in crate::io) use file::Note;
pub use file::decode_text;
use file::*;
use notes::*;
pub(in crate::io) use notes::{drop_duplicates, limit_to_two_hands};
use part::*;
use timing::*;
