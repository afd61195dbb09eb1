//! Choosing the timpani part: the track (or channel of a type 0 file) named by `--track`,
//! else the one with General MIDI program 48, else one whose track or instrument name
//! names the timpani (`crate::base::instrument_name`), else the
//! percussion channel 10; the reason for the choice is reported.

use super::*;
use crate::base::instrument_name::is_timpani_name;

/// The notes to import: a track, optionally one channel of it.
pub(super) struct Chosen {
    pub(super) track: usize,
    pub(super) channel: Option<u8>,
    /// Percussion keys (channel 10) rather than pitches.
    pub(super) percussion: bool,
    /// Chosen for its program 48 "Timpani": only the notes played while the channel is
    /// on that program are the part.
    pub(super) timpani_program: bool,
}

/// Notes per channel of a track.
pub(super) fn channel_counts(track: &TrackInfo) -> BTreeMap<u8, usize> {
    let mut counts = BTreeMap::new();
    for n in &track.notes {
        *counts.entry(n.channel).or_insert(0) += 1;
    }
    counts
}

/// When `channel` plays which program, as `track` hears it: (score tick, program) of each
/// program change on that channel in `track`, else in every track (a file's tracks share
/// its sixteen channels), in time order.
pub(super) fn program_timeline(file: &FileInfo, track: usize, channel: u8) -> Vec<(u64, u8)> {
    let on = |t: &TrackInfo| -> Vec<(u64, u8)> {
        (t.program_changes.iter())
            .filter(|c| c.1 == channel)
            .map(|c| (c.0, c.2))
            .collect()
    };
    let own = on(&file.tracks[track]);
    if !own.is_empty() {
        return own;
    }
    let mut all: Vec<(u64, u8)> = file.tracks.iter().flat_map(on).collect();
    all.sort_by_key(|c| c.0);
    all
}

/// The program a note at score `tick` plays on a channel with this `timeline`: the last
/// change at or before it (one at the note's own tick is meant for it), else the first
/// (files often set their programs just after their first notes); none if never set.
pub(super) fn program_at(timeline: &[(u64, u8)], tick: u64) -> Option<u8> {
    let i = timeline.partition_point(|c| c.0 <= tick);
    timeline.get(i.saturating_sub(1)).map(|c| c.1)
}

/// "program 48", or "programs 48, 1" for a channel that changes (counted from 1), or "no
/// program".
fn programs_text(timeline: &[(u64, u8)]) -> String {
    let mut programs: Vec<u8> = Vec::new();
    for &(_, p) in timeline {
        if programs.last() != Some(&p) {
            programs.push(p);
        }
    }
    let listed: Vec<String> = programs.iter().map(|p| (p + 1).to_string()).collect();
    match listed.len() {
        0 => "no program".into(),
        1 => format!("program {}", listed[0]),
        _ => format!("programs {}", listed.join(", ")),
    }
}

/// "track 3 \"Timpani\"", or "track 0 (no name)".
pub(super) fn track_label(file: &FileInfo, track: usize) -> String {
    match file.tracks[track].name.as_str() {
        "" => format!("track {track} (no name)"),
        name => format!("track {track} \"{name}\""),
    }
}

/// One line per track: index, name, channels with programs, note counts.
pub(super) fn track_listing(file: &FileInfo) -> String {
    let mut out = String::new();
    for (i, t) in file.tracks.iter().enumerate() {
        let counts = channel_counts(t);
        let _ = write!(out, "  {}", track_label(file, i));
        if !t.instrument.is_empty() {
            let _ = write!(out, " (instrument \"{}\")", t.instrument);
        }
        out.push_str(": ");
        if counts.is_empty() {
            out.push_str("no notes");
        }
        let parts: Vec<String> = counts
            .iter()
            .map(|(&ch, &n)| {
                let prog = programs_text(&program_timeline(file, i, ch));
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
pub(super) fn choose(
    path: &Path,
    file: &FileInfo,
    options: &ImportOptions,
) -> Result<(String, Chosen), MidiError> {
    let whole = |track: usize| Chosen {
        track,
        channel: None,
        percussion: false,
        timpani_program: false,
    };
    if file.tracks.is_empty() {
        return Err(MidiError::NoTracks {
            path: path.to_path_buf(),
        });
    }
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
            let on = |percussion, timpani_program| Chosen {
                track: i,
                channel: Some(ch),
                percussion,
                timpani_program,
            };
            if ch == PERCUSSION_CHANNEL {
                let why = format!(
                    "{label}: no timpani part, so the percussion keys are spread over the drums from low to high"
                );
                percussion.push((n, why, on(true, false)));
                continue;
            }
            let timeline = program_timeline(file, i, ch);
            let timpani = (t.notes.iter())
                .filter(|note| note.channel == ch)
                .filter(|note| program_at(&timeline, note.tick) == Some(GM_TIMPANI))
                .count();
            if timpani == n {
                let why = format!("{label}: General MIDI program 48 \"Timpani\"");
                by_program.push((n, why, on(false, true)));
            } else if timpani > 0 {
                let why = format!(
                    "{label}: General MIDI program 48 \"Timpani\" for {timpani} of its {n} notes \
                     (the channel changes program)"
                );
                by_program.push((timpani, why, on(false, true)));
            }
        }
        let named = [&t.name, &t.instrument]
            .into_iter()
            .find(|n| is_timpani_name(n));
        if let Some(named) = named.filter(|_| !t.notes.is_empty()) {
            let why = format!("{}: named \"{named}\"", track_label(file, i));
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

/// "track 2 \"Perc\" is damaged at byte 97: …", or "the file is damaged at byte 97: …".
pub(super) fn damage_text(file: &FileInfo, d: &Damage) -> String {
    let whose = match d.track {
        Some(t) if t < file.tracks.len() => track_label(file, t),
        _ => "the file".into(),
    };
    format!("{whose} is damaged at byte {}: {}", d.byte, d.what)
}

/// A file with damage that lost events and no timpani part (or no track, or not the
/// track asked for) is reported as damaged, not as lacking a timpani part.
pub(super) fn damaged_instead(
    path: &Path,
    file: &FileInfo,
    damage: &[Damage],
    error: MidiError,
) -> MidiError {
    let Some(first) = damage.iter().find(|d| d.lost) else {
        return error;
    };
    if !matches!(
        error,
        MidiError::NoTimpani { .. } | MidiError::NoTracks { .. } | MidiError::TrackIndex { .. }
    ) {
        return error;
    }
    let choices = match track_listing(file) {
        listing if listing.is_empty() => String::new(),
        listing => format!(", or choose a track with --track N or --track NAME:\n{listing}"),
    };
    MidiError::Damaged {
        path: path.to_path_buf(),
        damage: damage_text(file, first),
        choices,
    }
}

/// Notes of the chosen channel played while it was on another program than 48
/// "Timpani", left out of a part chosen for that program.
pub(super) struct LeftOut {
    count: usize,
    /// Score tick of the first.
    first_tick: u64,
    /// The programs they were played on, counted from 0, in order of first use.
    programs: Vec<u8>,
}

impl LeftOut {
    /// "12 notes of track 2 \"Perc\", channel 3 were played on program 10, not 48
    /// \"Timpani\", and are left out (the first at bar 5 beat 1); --track 2 imports them
    /// too" (", with every other channel of the track" when it has notes on others).
    pub(super) fn warning(&self, file: &FileInfo, chosen: &Chosen, meter: &MeterMap) -> String {
        let programs: Vec<String> = self.programs.iter().map(|p| (p + 1).to_string()).collect();
        let channel = chosen
            .channel
            .map_or(String::new(), |c| format!(", channel {}", c + 1));
        let others = channel_counts(&file.tracks[chosen.track]).len() > 1;
        format!(
            "{} note{} of {}{channel} {} played on program {}, not 48 \"Timpani\", and {} left \
             out (the first at {}); --track {} imports them too{}",
            self.count,
            if self.count == 1 { "" } else { "s" },
            track_label(file, chosen.track),
            if self.count == 1 { "was" } else { "were" },
            programs.join(", "),
            if self.count == 1 { "is" } else { "are" },
            meter.position(self.first_tick),
            chosen.track,
            if others {
                ", with every other channel of the track"
            } else {
                ""
            },
        )
    }
}

/// The chosen part's notes, and those of its channel left out because they were played
/// on another program (a part chosen for its program 48 "Timpani" only).
pub(super) fn part_notes(file: &FileInfo, chosen: &Chosen) -> (Vec<Note>, Option<LeftOut>) {
    let track = &file.tracks[chosen.track];
    let of_part = track
        .notes
        .iter()
        .filter(|n| chosen.channel.is_none_or(|c| n.channel == c));
    let (Some(channel), true) = (chosen.channel, chosen.timpani_program) else {
        return (of_part.cloned().collect(), None);
    };
    let timeline = program_timeline(file, chosen.track, channel);
    let mut left_out: Option<LeftOut> = None;
    let mut notes = Vec::new();
    for n in of_part {
        // Never unset: the channel was chosen for a program change to 48.
        match program_at(&timeline, n.tick) {
            Some(GM_TIMPANI) | None => notes.push(n.clone()),
            Some(program) => {
                let out = left_out.get_or_insert(LeftOut {
                    count: 0,
                    first_tick: n.tick,
                    programs: Vec::new(),
                });
                out.count += 1;
                if !out.programs.contains(&program) {
                    out.programs.push(program);
                }
            }
        }
    }
    (notes, left_out)
}
