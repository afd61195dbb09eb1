//! The MIDI file's events as the import reads them: how it counts time ([`Clock`]), each
//! track's name, notes and program changes, the tempo and time-signature events of every track,
//! and timpanist data made fit for a score.

use super::*;

/// How the file counts time, and the conversion to score ticks.
pub(super) enum Clock {
    /// Ticks per quarter note; score ticks are file ticks × `scale`.
    Metrical { tpq: u32, scale: u32 },
    /// SMPTE ticks per second; scores get 960 ticks per quarter at 120 bpm.
    Timecode { ticks_per_s: f64 },
}

impl Clock {
    pub(super) fn ticks_per_quarter(&self) -> u32 {
        match *self {
            Clock::Metrical { tpq, scale } => tpq * scale,
            Clock::Timecode { .. } => TIMECODE_TICKS_PER_QUARTER,
        }
    }

    /// Score tick of a file tick.
    pub(super) fn tick(&self, file_tick: u64) -> u64 {
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
pub(in crate::io) struct Note {
    pub(in crate::io) tick: u64,
    pub(in crate::io) channel: u8,
    pub(in crate::io) key: u8,
    pub(in crate::io) vel: u8,
    /// timpanist data written just before this note (roll length in score ticks).
    pub(in crate::io) data: Option<BeatData>,
}

/// What a track holds.
#[derive(Default)]
pub(super) struct TrackInfo {
    pub(super) name: String,
    /// The first instrument name (meta event FF 04).
    pub(super) instrument: String,
    pub(super) notes: Vec<Note>,
    /// Every program change: (score tick, channel, program), in the track's order.
    pub(super) program_changes: Vec<(u64, u8, u8)>,
}

/// The parts of a file the import uses.
pub(super) struct FileInfo {
    pub(super) tracks: Vec<TrackInfo>,
    /// (score tick, µs per quarter) from every track.
    pub(super) tempos: Vec<(u64, u32)>,
    /// (score tick, numerator, denominator as a power of 2) from every track.
    pub(super) meters: Vec<(u64, u8, u8)>,
}

pub(super) fn read_file(tracks: &[Vec<TrackEvent<'_>>], clock: &Clock) -> FileInfo {
    let mut file = FileInfo {
        tracks: Vec::new(),
        tempos: Vec::new(),
        meters: Vec::new(),
    };
    for track in tracks {
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
                TrackEventKind::Meta(MetaMessage::InstrumentName(name))
                    if info.instrument.is_empty() =>
                {
                    info.instrument = decode_text(name).trim().to_string();
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
                        (info.program_changes).push((tick, channel.as_int(), program.as_int()));
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
/// if it decodes without errors, has Japanese letters (kana or kanji) and a byte
/// 0x80–0x9F (the lead byte of kana and common kanji: Latin-1 text, as timpanist's
/// export writes it, has none, and its accented letters pair up into rare kanji —
/// "Pièce" read "Pi鐵e"), else Latin-1 (Windows-1252); text with control characters in
/// it is taken as undecodable and read as empty (the title then falls back to the file
/// name).
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
    let shift_jis_lead = bytes.iter().any(|b| (0x80..=0x9f).contains(b));
    if shift_jis_lead
        && let Some(s) =
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
pub(super) fn sane(mut data: BeatData, clock: &Clock, file_tick: u64) -> BeatData {
    let tpq = clock.ticks_per_quarter();
    data.4 = data.4.and_then(|mut roll| {
        let end = file_tick.saturating_add(roll.length_ticks);
        roll.length_ticks = clock.tick(end) - clock.tick(file_tick);
        let spq = roll.strokes_per_quarter;
        ((1..=32).contains(&spq) && tpq.is_multiple_of(spq) && roll.length_ticks > 0)
            .then_some(roll)
    });
    // The damp counts ticks after the beat's end: held as the clock moves them.
    data.5 = data
        .5
        .map(|d| clock.tick(file_tick.saturating_add(d)) - clock.tick(file_tick));
    if let ImpactLocation::Point { radius, angle_deg } = data.3
        && !((0.0..=1.0).contains(&radius) && angle_deg.is_finite())
    {
        data.3 = ImpactLocation::PlayingSpot;
    }
    data
}
