//! Standard MIDI File import: finds the timpani part of a type 0 or type 1 file and turns
//! its notes into a score that a timpanist can play on a given kit.
//!
//! The part is the track (or, in a type 0 file, the channel) with General MIDI program 48
//! "Timpani", else a track named like "Timpani"/"Pauken", else the percussion channel 10;
//! `--track` overrides. Every distinct note becomes a beat on a drum whose range holds its
//! pitch, chosen as a timpanist would (a drum already tuned to the pitch, else the one idle
//! longest); exact duplicates are dropped (seed 003, footnote 1). Tempo and time signatures
//! come from every track. Notes written by [`super::midi_export`] carry their hand, mode,
//! drum, impact location and roll, which are restored. Channels and programs are counted
//! from 1 in messages, as General MIDI does.

use super::midi_export::{BeatData, GM_TIMPANI};
use crate::base::pitch::Pitch;
use crate::kit::Kit;
use crate::score::meter;
use crate::score::tempo::BPM_RANGE;
use crate::score::{
    Beat, Dynamic, Hand, ImpactLocation, MeterChange, MeterMap, PlayingMode, Roll, Score,
    TempoChange, TempoPoint,
};
use midly::{Format, MetaMessage, MidiMessage, Smf, Timing, TrackEventKind};
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
        "{}: no timpani part found (no General MIDI program 48 \"Timpani\", no track named \"Timp…\" or \"Pauk…\", no notes on percussion channel 10); choose a track with --track N or --track NAME:\n{tracks}",
        path.display()
    )]
    NoTimpani { path: PathBuf, tracks: String },
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
    let smf = Smf::parse(bytes).map_err(|e| MidiError::Malformed {
        path: path.to_path_buf(),
        message: e.to_string(),
    })?;
    let malformed = |message: &str| MidiError::Malformed {
        path: path.to_path_buf(),
        message: message.into(),
    };
    if smf.header.format == Format::Sequential {
        return Err(MidiError::Sequential {
            path: path.to_path_buf(),
        });
    }
    let clock = match smf.header.timing {
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
    let file = read_file(&smf, &clock);
    let mut warnings = Vec::new();
    let (source, chosen) = choose(path, &file, options)?;
    let notes: Vec<Note> = file.tracks[chosen.track]
        .notes
        .iter()
        .filter(|n| chosen.channel.is_none_or(|c| n.channel == c))
        .cloned()
        .collect();
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
    score.tempo = tempo_points(&file.tempos, &clock, &mut warnings);
    score.meter = meter_changes(&file.meters, tpq, &mut warnings);
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

/// How the file counts time, and the conversion to score ticks.
enum Clock {
    /// Ticks per quarter note; score ticks are file ticks × `scale`.
    Metrical { tpq: u32, scale: u32 },
    /// SMPTE ticks per second; scores get 960 ticks per quarter at 120 bpm.
    Timecode { ticks_per_s: f64 },
}

impl Clock {
    fn ticks_per_quarter(&self) -> u32 {
        match *self {
            Clock::Metrical { tpq, scale } => tpq * scale,
            Clock::Timecode { .. } => TIMECODE_TICKS_PER_QUARTER,
        }
    }

    /// Score tick of a file tick.
    fn tick(&self, file_tick: u64) -> u64 {
        match *self {
            Clock::Metrical { scale, .. } => file_tick * u64::from(scale),
            Clock::Timecode { ticks_per_s } => {
                let quarters_per_s = DEFAULT_BPM / 60.0;
                (file_tick as f64 / ticks_per_s
                    * quarters_per_s
                    * f64::from(TIMECODE_TICKS_PER_QUARTER))
                .round() as u64
            }
        }
    }
}

/// A note-on, in score ticks.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Note {
    pub(super) tick: u64,
    pub(super) channel: u8,
    pub(super) key: u8,
    pub(super) vel: u8,
    /// timpanist data written just before this note (roll length in score ticks).
    pub(super) data: Option<BeatData>,
}

/// What a track holds.
#[derive(Default)]
struct TrackInfo {
    name: String,
    notes: Vec<Note>,
    /// The first program change on each channel.
    programs: [Option<u8>; 16],
}

/// The parts of a file the import uses.
struct FileInfo {
    tracks: Vec<TrackInfo>,
    /// (score tick, µs per quarter) from every track.
    tempos: Vec<(u64, u32)>,
    /// (score tick, numerator, denominator as a power of 2) from every track.
    meters: Vec<(u64, u8, u8)>,
}

fn read_file(smf: &Smf<'_>, clock: &Clock) -> FileInfo {
    let mut file = FileInfo {
        tracks: Vec::new(),
        tempos: Vec::new(),
        meters: Vec::new(),
    };
    for track in &smf.tracks {
        let mut info = TrackInfo::default();
        let mut file_tick = 0u64;
        let mut pending: Option<(u64, BeatData)> = None;
        for event in track {
            file_tick += u64::from(event.delta.as_int());
            let tick = clock.tick(file_tick);
            match event.kind {
                TrackEventKind::Meta(MetaMessage::TrackName(name)) if info.name.is_empty() => {
                    info.name = decode_text(name).trim().to_string();
                }
                TrackEventKind::Meta(MetaMessage::Tempo(us)) => {
                    file.tempos.push((tick, us.as_int()));
                }
                TrackEventKind::Meta(MetaMessage::TimeSignature(num, pow, _, _)) => {
                    file.meters.push((tick, num, pow));
                }
                TrackEventKind::Meta(MetaMessage::SequencerSpecific(bytes)) => {
                    pending = BeatData::from_payload(bytes)
                        .map(|data| (tick, sane(data, clock, file_tick)));
                }
                TrackEventKind::Midi { channel, message } => match message {
                    MidiMessage::NoteOn { key, vel } if vel.as_int() > 0 => {
                        info.notes.push(Note {
                            tick,
                            channel: channel.as_int(),
                            key: key.as_int(),
                            vel: vel.as_int(),
                            data: pending.take().filter(|p| p.0 == tick).map(|p| p.1),
                        });
                    }
                    MidiMessage::ProgramChange { program } => {
                        let slot = &mut info.programs[usize::from(channel.as_int())];
                        slot.get_or_insert(program.as_int());
                    }
                    _ => {}
                },
                _ => {}
            }
        }
        file.tracks.push(info);
    }
    file
}

/// MIDI text (a track name, the title) as a string: valid UTF-8 as it is, else Shift-JIS
/// if it decodes without errors and has Japanese letters (kana or kanji), else Latin-1
/// (Windows-1252); text with control characters in it is taken as undecodable and read as
/// empty (the title then falls back to the file name).
pub fn decode_text(bytes: &[u8]) -> String {
    let readable = |s: &str| !s.chars().any(|c| c.is_control() && c != '\t');
    if let Ok(s) = std::str::from_utf8(bytes) {
        return if readable(s) {
            s.to_string()
        } else {
            String::new()
        };
    }
    let japanese = |c: char| {
        // Hiragana, katakana, kanji; not the half-width katakana alone, which Latin-1
        // capitals and accented letters also decode to.
        matches!(c, '\u{3040}'..='\u{30ff}' | '\u{4e00}'..='\u{9fff}')
    };
    if let Some(s) =
        encoding_rs::SHIFT_JIS.decode_without_bom_handling_and_without_replacement(bytes)
        && s.chars().any(japanese)
        && readable(&s)
    {
        return s.into_owned();
    }
    let (latin, _) = encoding_rs::WINDOWS_1252.decode_without_bom_handling(bytes);
    if readable(&latin) {
        latin.into_owned()
    } else {
        String::new()
    }
}

/// Timpani data made fit for a score: roll length in score ticks, and a roll or location
/// a score cannot hold (from a foreign or damaged file) replaced by none or the playing spot.
fn sane(mut data: BeatData, clock: &Clock, file_tick: u64) -> BeatData {
    let tpq = clock.ticks_per_quarter();
    data.4 = data.4.and_then(|mut roll| {
        let end = file_tick.saturating_add(roll.length_ticks);
        roll.length_ticks = clock.tick(end) - clock.tick(file_tick);
        let spq = roll.strokes_per_quarter;
        ((1..=32).contains(&spq) && tpq.is_multiple_of(spq) && roll.length_ticks > 0)
            .then_some(roll)
    });
    if let ImpactLocation::Point { radius, angle_deg } = data.3
        && !((0.0..=1.0).contains(&radius) && angle_deg.is_finite())
    {
        data.3 = ImpactLocation::PlayingSpot;
    }
    data
}

/// The notes to import: a track, optionally one channel of it.
struct Chosen {
    track: usize,
    channel: Option<u8>,
    /// Percussion keys (channel 10) rather than pitches.
    percussion: bool,
}

/// Notes per channel of a track.
fn channel_counts(track: &TrackInfo) -> BTreeMap<u8, usize> {
    let mut counts = BTreeMap::new();
    for n in &track.notes {
        *counts.entry(n.channel).or_insert(0) += 1;
    }
    counts
}

/// The program of `channel` in `track`, else the first set for it in any track.
fn program(file: &FileInfo, track: usize, channel: u8) -> Option<u8> {
    let ch = usize::from(channel);
    file.tracks[track].programs[ch].or_else(|| file.tracks.iter().find_map(|t| t.programs[ch]))
}

/// "track 3 \"Timpani\"", or "track 0 (no name)".
fn track_label(file: &FileInfo, track: usize) -> String {
    match file.tracks[track].name.as_str() {
        "" => format!("track {track} (no name)"),
        name => format!("track {track} \"{name}\""),
    }
}

/// One line per track: index, name, channels with programs, note counts.
fn track_listing(file: &FileInfo) -> String {
    let mut out = String::new();
    for (i, t) in file.tracks.iter().enumerate() {
        let counts = channel_counts(t);
        let _ = write!(out, "  {}: ", track_label(file, i));
        if counts.is_empty() {
            out.push_str("no notes");
        }
        let parts: Vec<String> = counts
            .iter()
            .map(|(&ch, &n)| {
                let prog = program(file, i, ch)
                    .map_or_else(|| "no program".into(), |p| format!("program {}", p + 1));
                format!("{n} notes on channel {} ({prog})", ch + 1)
            })
            .collect();
        out.push_str(&parts.join(", "));
        out.push('\n');
    }
    out.pop();
    out
}

/// Choose the notes to import and say which and why.
fn choose(
    path: &Path,
    file: &FileInfo,
    options: &ImportOptions,
) -> Result<(String, Chosen), MidiError> {
    let whole = |track: usize| Chosen {
        track,
        channel: None,
        percussion: false,
    };
    match &options.track {
        Some(TrackChoice::Index(i)) if *i < file.tracks.len() => {
            return Ok((
                format!("{} (chosen with --track {i})", track_label(file, *i)),
                whole(*i),
            ));
        }
        Some(TrackChoice::Index(i)) => {
            return Err(MidiError::TrackIndex {
                path: path.to_path_buf(),
                index: *i,
                count: file.tracks.len(),
                tracks: track_listing(file),
            });
        }
        Some(TrackChoice::Name(name)) => {
            let lower = name.to_lowercase();
            return match file
                .tracks
                .iter()
                .position(|t| t.name.to_lowercase().contains(&lower))
            {
                Some(i) => Ok((
                    format!("{} (chosen with --track \"{name}\")", track_label(file, i)),
                    whole(i),
                )),
                None => Err(MidiError::TrackName {
                    path: path.to_path_buf(),
                    name: name.clone(),
                    tracks: track_listing(file),
                }),
            };
        }
        None => {}
    }
    // Candidates of the first rule that has any: (notes, description, choice).
    let mut by_program = Vec::new();
    let mut by_name = Vec::new();
    let mut percussion = Vec::new();
    for (i, t) in file.tracks.iter().enumerate() {
        for (&ch, &n) in &channel_counts(t) {
            let label = format!("{}, channel {}", track_label(file, i), ch + 1);
            let on = |percussion| Chosen {
                track: i,
                channel: Some(ch),
                percussion,
            };
            if ch == PERCUSSION_CHANNEL {
                let why = format!(
                    "{label}: no timpani part, so the percussion keys are spread over the drums from low to high"
                );
                percussion.push((n, why, on(true)));
            } else if program(file, i, ch) == Some(GM_TIMPANI) {
                let why = format!("{label}: General MIDI program 48 \"Timpani\"");
                by_program.push((n, why, on(false)));
            }
        }
        let name = t.name.to_lowercase();
        if !t.notes.is_empty() && (name.contains("timp") || name.contains("pauk")) {
            let why = format!("{}: named like a timpani part", track_label(file, i));
            by_name.push((t.notes.len(), why, whole(i)));
        }
    }
    let candidates = [by_program, by_name, percussion]
        .into_iter()
        .find(|c| !c.is_empty())
        .ok_or_else(|| MidiError::NoTimpani {
            path: path.to_path_buf(),
            tracks: track_listing(file),
        })?;
    let others = candidates.len() - 1;
    let (n, mut why, chosen) = candidates
        .into_iter()
        .enumerate()
        .max_by_key(|(i, c)| (c.0, Reverse(*i)))
        .map(|(_, c)| c)
        .expect("candidates is not empty");
    let _ = write!(why, "; {n} notes");
    if others > 0 {
        let _ = write!(why, ", the most of {} candidates", others + 1);
    }
    Ok((why, chosen))
}

/// Drop the repeated strokes of rolls described by timpanist data (notes of the same
/// channel and key inside the roll that carry no data of their own).
fn skip_roll_strokes(notes: Vec<Note>) -> Vec<Note> {
    let rolls: Vec<(u8, u8, u64, u64)> = notes
        .iter()
        .filter_map(|n| {
            let roll = n.data?.4?;
            Some((n.channel, n.key, n.tick, n.tick + roll.length_ticks))
        })
        .collect();
    notes
        .into_iter()
        .filter(|n| {
            n.data.is_some()
                || !rolls.iter().any(|&(ch, key, start, end)| {
                    n.channel == ch && n.key == key && (start..end).contains(&n.tick)
                })
        })
        .collect()
}

/// Drop duplicate notes (same channel, tick and key; notes carrying timpanist data for
/// different drums are not duplicates), keeping the loudest; sort the rest by time.
/// Returns how many were dropped.
pub(super) fn drop_duplicates(notes: &mut Vec<Note>) -> usize {
    let before = notes.len();
    let drum = |n: &Note| n.data.map(|d| d.2);
    notes.sort_by_key(|n| (n.tick, n.channel, n.key, drum(n), Reverse(n.vel)));
    notes.dedup_by(|b, a| {
        (a.tick, a.channel, a.key, drum(a)) == (b.tick, b.channel, b.key, drum(b))
    });
    before - notes.len()
}

/// Drums by index, from the lowest kit tuning to the highest.
fn drums_low_to_high(kit: &Kit) -> Vec<usize> {
    let mut drums: Vec<usize> = (0..kit.drums.len()).collect();
    drums.sort_by_key(|&d| kit.drums[d].tuning);
    drums
}

/// Turn percussion keys into pitches: the distinct keys, in ascending order, are spread
/// evenly over the drums from low to high, each taking its drum's kit tuning.
fn map_percussion(notes: &mut [Note], kit: &Kit) {
    let drums = drums_low_to_high(kit);
    let mut keys: Vec<u8> = notes.iter().map(|n| n.key).collect();
    keys.sort_unstable();
    keys.dedup();
    let (m, d) = (keys.len(), drums.len());
    for n in notes.iter_mut() {
        let j = keys.binary_search(&n.key).expect("every key is listed");
        let slot = if m > 1 {
            (j * (d - 1) + (m - 1) / 2) / (m - 1)
        } else {
            (d - 1) / 2
        };
        n.key = kit.drums[drums[slot]].tuning.0;
    }
}

/// Collapse runs of at least [`MIN_ROLL_NOTES`] notes of one key, evenly spaced (every gap
/// within 1 tick of the first) at most a sixteenth note apart, into their first note with
/// a roll, when the mean spacing is within 1 tick of a whole division of the quarter note
/// into 4–32 strokes and no other note falls inside the roll.
fn detect_rolls(notes: &mut Vec<Note>, tpq: u32) {
    let q = u64::from(tpq);
    let ticks: Vec<u64> = notes.iter().map(|n| n.tick).collect();
    let mut by_key: BTreeMap<(u8, u8), Vec<usize>> = BTreeMap::new();
    for (i, n) in notes.iter().enumerate().filter(|(_, n)| n.data.is_none()) {
        by_key.entry((n.channel, n.key)).or_default().push(i);
    }
    let mut remove = vec![false; notes.len()];
    for run_of in by_key.values() {
        let mut start = 0;
        while start + 1 < run_of.len() {
            let gap = |k: usize| ticks[run_of[k + 1]] - ticks[run_of[k]];
            let first_gap = gap(start);
            let mut end = start + 1; // last index of the run in `run_of`
            while end + 1 < run_of.len() && gap(end).abs_diff(first_gap) <= 1 {
                end += 1;
            }
            let (first, last) = (ticks[run_of[start]], ticks[run_of[end]]);
            let count = end - start + 1;
            let mean = (last - first) as f64 / (count - 1) as f64;
            let strokes = (q as f64 / mean).round() as u64;
            let spacing = q / strokes.max(1);
            let inside = ticks.partition_point(|&t| t < last + spacing)
                - ticks.partition_point(|&t| t <= first);
            if count >= MIN_ROLL_NOTES
                && (1..=32).contains(&strokes)
                && q.is_multiple_of(strokes)
                && (spacing as f64 - mean).abs() <= 1.0
                && spacing <= q / 4
                && inside == count - 1
            {
                let head = &mut notes[run_of[start]];
                let roll = Roll {
                    length_ticks: last - first + spacing,
                    strokes_per_quarter: strokes as u32,
                };
                head.data = Some(BeatData(
                    Hand::Auto,
                    PlayingMode::Legato,
                    ANY_DRUM,
                    ImpactLocation::PlayingSpot,
                    Some(roll),
                ));
                for &k in &run_of[start + 1..=end] {
                    remove[k] = true;
                }
                start = end + 1;
            } else {
                start = end; // the run's last note may start the next run
            }
        }
    }
    let mut keep = remove.iter().map(|r| !r);
    notes.retain(|_| keep.next().expect("one flag per note"));
}

/// Keep at most the two loudest notes at each tick (a timpanist has two hands), and give
/// two simultaneous strokes different hands if their data names the same one.
pub(super) fn limit_to_two_hands(notes: &mut Vec<Note>, warnings: &mut Vec<String>) {
    let mut kept = Vec::with_capacity(notes.len());
    let mut crowded = Vec::new();
    for group in notes.chunk_by(|a, b| a.tick == b.tick) {
        let mut group = group.to_vec();
        if group.len() > 2 {
            crowded.push(group[0].tick);
            group.sort_by_key(|n| Reverse(n.vel));
            group.truncate(2);
            group.sort_by_key(|n| (n.channel, n.key));
        }
        if let [a, b] = &mut group[..]
            && let (Some(da), Some(db)) = (&a.data, &mut b.data)
            && da.0 == db.0
            && da.0 != Hand::Auto
        {
            db.0 = Hand::Auto;
        }
        kept.extend(group);
    }
    if let Some(first) = crowded.first() {
        warnings.push(format!(
            "{} times had more than two notes at once (the first at tick {first}); kept the two loudest of each",
            crowded.len()
        ));
    }
    *notes = kept;
}

/// The pitch fewest octaves from `pitch` (downward on a tie) that `fits`, if any.
fn nearest_octave(pitch: Pitch, fits: impl Fn(&Pitch) -> bool) -> Option<Pitch> {
    (1..=10)
        .flat_map(|k| [-12 * k, 12 * k])
        .filter_map(|s| pitch.transposed(s))
        .find(|p| fits(p))
}

/// The pitch nearest by octaves to `pitch` that some drum reaches (fewest octaves,
/// downward on a tie), else the nearest pitch any drum reaches.
fn reachable(pitch: Pitch, kit: &Kit) -> Pitch {
    let fits = |p: &Pitch| kit.drums_for(*p).next().is_some();
    nearest_octave(pitch, fits).unwrap_or_else(|| {
        (0..=127)
            .map(Pitch)
            .filter(fits)
            .min_by_key(|p| p.0.abs_diff(pitch.0))
            .expect("a valid kit has a drum")
    })
}

/// Move notes no drum can reach by octaves into a drum's range; one warning sums them up.
/// Returns how many moved.
pub(super) fn move_into_range(notes: &mut [Note], kit: &Kit, warnings: &mut Vec<String>) -> usize {
    let mut moves: BTreeMap<(Pitch, Pitch), usize> = BTreeMap::new();
    for n in notes.iter_mut() {
        let pitch = Pitch(n.key);
        if kit.drums_for(pitch).next().is_none() {
            let to = reachable(pitch, kit);
            *moves.entry((pitch, to)).or_insert(0) += 1;
            n.key = to.0;
        }
    }
    let total = moves.values().sum();
    if total > 0 {
        let list: Vec<String> = moves
            .iter()
            .map(|((from, to), n)| format!("{from} → {to} ×{n}"))
            .collect();
        warnings.push(format!(
            "{total} notes were outside every drum's range and were moved by octaves: {}",
            list.join(", ")
        ));
    }
    total
}

/// Give every note a drum as a timpanist would and make it a beat. Walking in time, each
/// drum keeps its current tuning; a note goes to the drum its data names if that drum
/// reaches it, else, among the drums that reach it (not already struck at this tick if
/// possible; for a roll, which takes both hands, one both hands reach if possible), to one
/// tuned to it, else to the one idle longest (it is retuned), ties to the nearest kit
/// tuning. The notes of one tick choose in order of how few drums reach them, so a chord
/// of F3 and A3 on the standard kit takes the 26- and the 23-inch drum (in score order
/// the F3 took the 23-inch drum, tuned to it, and left the A3, which only the 23-inch
/// drum reaches, on the same drum at the same time). A chord note whose drums are all
/// struck at that tick moves by the fewest octaves to a drum that is free (counted in one
/// warning), as a timpanist would rewrite it.
pub(super) fn assign_drums(notes: &[Note], kit: &Kit, warnings: &mut Vec<String>) -> Vec<Beat> {
    let mut tuning: Vec<Pitch> = kit.drums.iter().map(|d| d.tuning).collect();
    let mut last_used: Vec<Option<u64>> = vec![None; kit.drums.len()];
    let mut drums: Vec<usize> = vec![0; notes.len()];
    let mut keys: Vec<u8> = notes.iter().map(|n| n.key).collect();
    let both_hands_reach = both_hands_reach(kit);
    let mut moves: BTreeMap<(Pitch, Pitch), usize> = BTreeMap::new();
    let mut start = 0;
    while start < notes.len() {
        let tick = notes[start].tick;
        let end = start + notes[start..].iter().take_while(|n| n.tick == tick).count();
        let named = |n: &Note| {
            n.data.map(|d| d.2).filter(|&d| {
                kit.drums
                    .get(d)
                    .is_some_and(|drum| drum.in_range(Pitch(n.key)))
            })
        };
        let mut order: Vec<usize> = (start..end).collect();
        order.sort_by_key(|&i| {
            let n = &notes[i];
            let choices = if named(n).is_some() {
                0
            } else {
                kit.drums_for(Pitch(n.key)).count()
            };
            (choices, i)
        });
        let mut taken: Vec<usize> = Vec::new();
        for i in order {
            let n = &notes[i];
            let mut pitch = Pitch(n.key);
            let free = |p: &Pitch| kit.drums_for(*p).any(|d| !taken.contains(&d));
            let named_drum = named(n);
            if named_drum.is_none()
                && !free(&pitch)
                && let Some(to) = nearest_octave(pitch, free)
            {
                *moves.entry((pitch, to)).or_insert(0) += 1;
                pitch = to;
            }
            let roll = n.data.is_some_and(|d| d.4.is_some());
            let drum = named_drum.unwrap_or_else(|| {
                kit.drums_for(pitch)
                    .min_by_key(|&d| {
                        (
                            taken.contains(&d),
                            roll && !both_hands_reach[d],
                            tuning[d] != pitch,
                            last_used[d],
                            kit.drums[d].tuning.0.abs_diff(pitch.0),
                        )
                    })
                    .expect("notes were moved into a drum's range")
            });
            tuning[drum] = pitch;
            last_used[drum] = Some(tick);
            taken.push(drum);
            (drums[i], keys[i]) = (drum, pitch.0);
        }
        start = end;
    }
    if !moves.is_empty() {
        let list: Vec<String> = moves
            .iter()
            .map(|((from, to), n)| format!("{from} → {to} ×{n}"))
            .collect();
        warnings.push(format!(
            "{} chord notes had no free drum that reaches them at once and were moved by \
             octaves: {}",
            moves.values().sum::<usize>(),
            list.join(", ")
        ));
    }
    let mut beats: Vec<Beat> = notes
        .iter()
        .zip(drums.into_iter().zip(keys))
        .map(|(n, (drum, key))| {
            let data = n.data.unwrap_or(BeatData(
                Hand::Auto,
                PlayingMode::Legato,
                drum,
                ImpactLocation::PlayingSpot,
                None,
            ));
            Beat {
                tick: n.tick,
                hand: data.0,
                mode: data.1,
                dynamic: Dynamic::from_midi_velocity(n.vel),
                drum,
                pitch: Some(Pitch(key)),
                location: data.3,
                roll: data.4,
                // A MIDI note's length says nothing reliable about damping: let it ring.
                damp: None,
            }
        })
        .collect();
    crate::score::tuning::drop_needless_pitches(&mut beats, kit);
    beats
}

/// Per drum, whether the default player reaches its playing spot with either hand upright
/// (the stretched arm and stick from the shoulder, as the sticking judges it; the renderer
/// also lets the trunk lean toward a far stroke, but a roll is played on a drum both hands
/// reach upright when one holds its pitch).
fn both_hands_reach(kit: &Kit) -> Vec<bool> {
    use crate::kit::Side;
    let body = crate::body::skeleton::Skeleton::holding_mallets_of(kit);
    let (r, angle) = ImpactLocation::PlayingSpot.polar();
    kit.drums
        .iter()
        .map(|d| {
            let spot = d.point_on_head(r, angle);
            [Side::Left, Side::Right]
                .into_iter()
                .all(|h| body.reaches(h, spot))
        })
        .collect()
}

/// Shorten rolls that another beat starts inside (a roll takes both hands).
pub(super) fn trim_rolls(beats: &mut [Beat]) {
    for i in 0..beats.len() {
        let tick = beats[i].tick;
        let next = beats[i + 1..].iter().map(|b| b.tick).find(|&t| t > tick);
        if let (Some(roll), Some(next)) = (&mut beats[i].roll, next) {
            roll.length_ticks = roll.length_ticks.min(next - tick);
        }
    }
}

/// The tempo of `us` µs per quarter note in bpm: the whole number or number with three
/// decimals that MIDI writes as `us` if there is one (833333 µs is 72 bpm), else exact.
fn bpm_of(us: u32) -> f64 {
    let exact = 60e6 / f64::from(us.max(1));
    [1.0, 1000.0]
        .iter()
        .map(|scale| (exact * scale).round() / scale)
        .find(|bpm| (60e6 / bpm).round() == f64::from(us))
        .unwrap_or(exact)
}

/// Tempo points from (tick, µs per quarter) events: steps, repeats merged, 120 bpm until
/// the first; SMPTE-timed files get 120 bpm throughout.
fn tempo_points(
    tempos: &[(u64, u32)],
    clock: &Clock,
    warnings: &mut Vec<String>,
) -> Vec<TempoPoint> {
    let step = |tick, bpm| TempoPoint {
        tick,
        bpm,
        change: TempoChange::Step,
    };
    let mut points = vec![step(0, DEFAULT_BPM)];
    if matches!(clock, Clock::Timecode { .. }) {
        return points;
    }
    let mut sorted = tempos.to_vec();
    sorted.sort_by_key(|t| t.0);
    let mut clamped = 0;
    for &(tick, us) in &sorted {
        let exact = bpm_of(us);
        let bpm = exact.clamp(*BPM_RANGE.start(), *BPM_RANGE.end());
        clamped += usize::from(bpm != exact);
        let last = points.last_mut().expect("points start with one");
        if last.tick == tick {
            last.bpm = bpm;
        } else if last.bpm != bpm {
            points.push(step(tick, bpm));
        }
    }
    // A later event at the same tick may have made a point repeat the one before.
    points.dedup_by(|b, a| a.bpm == b.bpm);
    if clamped > 0 {
        warnings.push(format!(
            "{clamped} tempo events outside {}–{} bpm were clamped into that range",
            BPM_RANGE.start(),
            BPM_RANGE.end()
        ));
    }
    points
}

/// Time signatures at the bars where they fall (a signature off a bar line starts at the
/// next one, with a warning); 4/4 if there are none. Repeats are merged and a later
/// signature for the same bar replaces the earlier.
fn meter_changes(
    meters: &[(u64, u8, u8)],
    tpq: u32,
    warnings: &mut Vec<String>,
) -> Vec<MeterChange> {
    let mut changes = vec![MeterChange {
        bar: 1,
        numerator: 4,
        denominator: 4,
    }];
    let mut sorted = meters.to_vec();
    sorted.sort_by_key(|m| m.0);
    for (tick, num, pow) in sorted {
        let (numerator, denominator) = (u32::from(num), 1u32.checked_shl(pow.into()).unwrap_or(0));
        let map = MeterMap::new(&changes, tpq);
        let now = map.signature_at(tick);
        if (now.numerator, now.denominator) == (numerator, denominator) {
            continue;
        }
        let at = map.position(tick);
        let on_line = map.is_bar_line(tick);
        let bar = u32::try_from(at.bar + u64::from(!on_line)).unwrap_or(u32::MAX);
        let mut candidate = changes.clone();
        if candidate.last().is_some_and(|c| c.bar == bar) {
            candidate.pop();
        }
        if candidate
            .last()
            .is_none_or(|c| (c.numerator, c.denominator) != (numerator, denominator))
        {
            candidate.push(MeterChange {
                bar,
                numerator,
                denominator,
            });
        }
        if !meter::validate_changes(&candidate, tpq).is_empty() {
            warnings.push(format!(
                "ignored the impossible time signature {numerator}/{denominator} at tick {tick}"
            ));
            continue;
        }
        if !on_line {
            warnings.push(format!(
                "the time signature {numerator}/{denominator} at tick {tick} ({at}) is not on a bar line; it starts at bar {bar}"
            ));
        }
        changes = candidate;
    }
    changes
}

#[cfg(test)]
mod tests {
    use super::*;

    fn note(tick: u64, key: u8) -> Note {
        Note {
            tick,
            channel: 0,
            key,
            vel: 80,
            data: None,
        }
    }

    fn pitch(name: &str) -> u8 {
        name.parse::<Pitch>().unwrap().0
    }

    /// Alternating D3 and A2 go to the drum tuned to D3 and to the drum nearest A2 (retuned
    /// once, then kept), with the pitch kept only on a drum retuned somewhere.
    #[test]
    fn drums_as_a_timpanist_would() {
        let kit = Kit::standard();
        let (d3, a2) = (pitch("D3"), pitch("A2"));
        let notes: Vec<Note> = [d3, a2, d3, a2, a2]
            .iter()
            .enumerate()
            .map(|(i, &k)| note(i as u64 * 480, k))
            .collect();
        let beats = assign_drums(&notes, &kit, &mut Vec::new());
        let drums: Vec<usize> = beats.iter().map(|b| b.drum).collect();
        assert_eq!(drums, vec![2, 1, 2, 1, 1]);
        assert_eq!(beats[0].pitch, None);
        assert_eq!(beats[1].pitch, Some(Pitch(a2)));
        assert!(
            beats
                .iter()
                .all(|b| b.hand == Hand::Auto && b.roll.is_none())
        );
    }

    /// A line with more pitches than drums retunes drums within the piece; every note,
    /// the ones at a drum's kit tuning included, still sounds its own pitch (a beat naming
    /// none would sound the drum's pitch then, so a retuned drum's beats all name theirs).
    #[test]
    fn a_line_with_more_pitches_than_drums_sounds_every_note() {
        let kit = Kit::standard();
        let line = [
            "G2", "A2", "B2", "C3", "D3", "E3", "F3", "G3", "D3", "A2", "G2",
        ];
        let notes: Vec<Note> = (line.iter().enumerate())
            .map(|(i, p)| note(i as u64 * 480, pitch(p)))
            .collect();
        let mut score = crate::score::Score::new("line");
        score.beats = assign_drums(&notes, &kit, &mut Vec::new());
        let sounding: Vec<String> = (score.sounding_pitches(&kit).iter())
            .map(ToString::to_string)
            .collect();
        assert_eq!(sounding, line);
        assert!(!score.pedal_changes(&kit).is_empty());
    }

    /// Two notes at the same tick that the same drum could play go to different drums,
    /// and an idle drum is retuned rather than the one just played.
    #[test]
    fn simultaneous_notes_use_two_drums() {
        let kit = Kit::standard();
        let notes = [note(0, pitch("Bb2")), note(0, pitch("C3"))];
        let beats = assign_drums(&notes, &kit, &mut Vec::new());
        assert_eq!((beats[0].drum, beats[1].drum), (1, 2));
        let notes = [note(0, pitch("Bb2")), note(10, pitch("C3"))];
        let beats = assign_drums(&notes, &kit, &mut Vec::new());
        assert_eq!(beats[1].drum, 2);
        // F3 reaches the 26- and the 23-inch drum (tuned to F3), A3 only the 23-inch:
        // the A3 chooses first, so the F3 takes the 26-inch, in either order.
        for (a, b) in [("F3", "A3"), ("A3", "F3")] {
            let notes = [note(0, pitch(a)), note(0, pitch(b))];
            let beats = assign_drums(&notes, &kit, &mut Vec::new());
            let on = |p: &str| beats[usize::from(b == p)].drum;
            assert_eq!((on("F3"), on("A3")), (2, 3), "{a} then {b}");
        }
    }

    /// A chord of two notes only the 23-inch drum reaches (G3, A3) cannot sound on one
    /// drum: the note choosing second moves by an octave to a free drum, in one warning.
    #[test]
    fn a_chord_one_drum_cannot_play_moves_a_note_by_an_octave() {
        let kit = Kit::standard();
        let mut warnings = Vec::new();
        let notes = [note(0, pitch("A3")), note(0, pitch("G3"))];
        let beats = assign_drums(&notes, &kit, &mut warnings);
        assert_ne!(beats[0].drum, beats[1].drum);
        assert_eq!(beats[0].pitch, Some(Pitch(pitch("A3"))));
        assert_eq!(beats[1].pitch, Some(Pitch(pitch("G2"))));
        assert_eq!(warnings.len(), 1, "{warnings:?}");
        assert!(warnings[0].contains("G3 → G2 ×1"), "{warnings:?}");
    }

    /// A roll takes both hands: an F3 roll goes to the 26-inch drum, which both hands
    /// reach, not to the 23-inch drum beside the player (tuned to F3), which the left
    /// hand does not; a single F3 stroke still goes to the drum tuned to it.
    #[test]
    fn a_roll_goes_to_a_drum_both_hands_reach() {
        let kit = Kit::standard();
        let reach = both_hands_reach(&kit);
        assert_eq!(reach, [false, true, true, false]);
        let rolled = Note {
            data: Some(BeatData(
                Hand::Auto,
                PlayingMode::Legato,
                usize::MAX,
                ImpactLocation::PlayingSpot,
                Some(Roll {
                    length_ticks: 960,
                    strokes_per_quarter: 4,
                }),
            )),
            ..note(0, pitch("F3"))
        };
        let beats = assign_drums(&[rolled], &kit, &mut Vec::new());
        assert_eq!(beats[0].drum, 2);
        let beats = assign_drums(&[note(0, pitch("F3"))], &kit, &mut Vec::new());
        assert_eq!(beats[0].drum, 3);
    }

    /// Pitches no drum reaches move by the fewest octaves into some drum's range, counted
    /// and summed up in one warning.
    #[test]
    fn octave_moves() {
        let kit = Kit::standard();
        let mut notes = vec![
            note(0, pitch("C5")),
            note(1, pitch("C1")),
            note(2, pitch("E2")),
        ];
        let mut warnings = Vec::new();
        assert_eq!(move_into_range(&mut notes, &kit, &mut warnings), 2);
        let keys: Vec<u8> = notes.iter().map(|n| n.key).collect();
        assert_eq!(keys, vec![pitch("C3"), pitch("C3"), pitch("E2")]);
        assert_eq!(warnings.len(), 1);
        assert!(warnings[0].contains("C5 → C3 ×1"), "{}", warnings[0]);
    }

    /// Eight even 32nd notes become one rolled beat; five do not, nor a run with another
    /// note inside it.
    #[test]
    fn detects_rolls() {
        // Gaps of 120 and 121 ticks, as when 8.0 strokes per quarter are rounded to ticks.
        let run = |n: u64, start: u64| (0..n).map(move |i| note(start + i * 120 + i / 2, 45));
        let mut notes: Vec<Note> = run(8, 0).chain(run(5, 4800)).collect();
        detect_rolls(&mut notes, 960);
        assert_eq!(notes.len(), 1 + 5);
        let roll = notes[0].data.unwrap().4.unwrap();
        assert_eq!(
            roll,
            Roll {
                length_ticks: 963,
                strokes_per_quarter: 8
            }
        );
        let mut crowded: Vec<Note> = run(8, 0).collect();
        crowded.insert(3, note(300, 50));
        detect_rolls(&mut crowded, 960);
        assert_eq!(crowded.len(), 9);
    }

    /// Three percussion keys spread over the lowest, third and highest drums' tunings.
    #[test]
    fn percussion_spread() {
        let kit = Kit::standard();
        let mut notes = vec![note(0, 42), note(1, 35), note(2, 38), note(3, 42)];
        map_percussion(&mut notes, &kit);
        let keys: Vec<u8> = notes.iter().map(|n| n.key).collect();
        let t = |d: usize| kit.drums[d].tuning.0;
        assert_eq!(keys, vec![t(3), t(0), t(2), t(3)]);
    }

    /// Duplicates keep the loudest; more than two notes at once keep the two loudest.
    #[test]
    fn duplicates_and_crowds() {
        let mut notes = vec![
            note(0, 45),
            note(0, 45),
            note(0, 50),
            note(0, 38),
            note(5, 45),
        ];
        notes[1].vel = 100;
        notes[3].vel = 10;
        assert_eq!(drop_duplicates(&mut notes), 1);
        assert_eq!(notes.iter().find(|n| n.key == 45).unwrap().vel, 100);
        let mut warnings = Vec::new();
        limit_to_two_hands(&mut notes, &mut warnings);
        let keys: Vec<(u64, u8)> = notes.iter().map(|n| (n.tick, n.key)).collect();
        assert_eq!(keys, vec![(0, 45), (0, 50), (5, 45)]);
        assert_eq!(warnings.len(), 1);
    }

    /// A 3/4 signature off a bar line starts at the next bar with a warning; repeated
    /// signatures and tempos merge; missing ones default to 4/4 and 120 bpm.
    #[test]
    fn meter_and_tempo() {
        let mut warnings = Vec::new();
        let meter = meter_changes(&[(0, 4, 2), (4800, 3, 2), (9600, 3, 2)], 960, &mut warnings);
        let bars: Vec<(u32, u32)> = meter.iter().map(|m| (m.bar, m.numerator)).collect();
        assert_eq!(bars, vec![(1, 4), (3, 3)]);
        assert_eq!(warnings.len(), 1);
        assert!(warnings[0].contains("bar 3"), "{}", warnings[0]);
        assert_eq!(meter_changes(&[], 960, &mut warnings)[0].numerator, 4);
        let clock = Clock::Metrical { tpq: 960, scale: 1 };
        let tempo = tempo_points(
            &[(0, 500_000), (960, 600_000), (1920, 600_000)],
            &clock,
            &mut warnings,
        );
        let bpms: Vec<(u64, f64)> = tempo.iter().map(|p| (p.tick, p.bpm)).collect();
        assert_eq!(bpms, vec![(0, 120.0), (960, 100.0)]);
        assert_eq!(tempo_points(&[], &clock, &mut warnings)[0].bpm, 120.0);
    }

    /// Tempos read as the round numbers MIDI rounded to µs, else exactly.
    #[test]
    fn round_tempos() {
        assert_eq!(bpm_of(833_333), 72.0);
        assert_eq!(bpm_of(600_000), 100.0);
        assert_eq!(bpm_of(461_538), 130.0);
        assert_eq!(bpm_of(1_000_001), 60e6 / 1_000_001.0);
    }

    /// `--track` text: a number is an index, anything else a name.
    #[test]
    fn track_choice_parses() {
        assert_eq!("3".parse(), Ok(TrackChoice::Index(3)));
        assert_eq!("Timp".parse(), Ok(TrackChoice::Name("Timp".into())));
    }

    /// SMPTE time (25 fps × 40 subframes = 1000 ticks/s) becomes 960 ticks per quarter at
    /// 120 bpm: one second is two quarters.
    #[test]
    fn timecode_clock() {
        let clock = Clock::Timecode {
            ticks_per_s: 1000.0,
        };
        assert_eq!(clock.tick(1000), 1920);
        assert_eq!(clock.ticks_per_quarter(), 960);
    }
}
