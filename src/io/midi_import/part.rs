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
}

/// Notes per channel of a track.
pub(super) fn channel_counts(track: &TrackInfo) -> BTreeMap<u8, usize> {
    let mut counts = BTreeMap::new();
    for n in &track.notes {
        *counts.entry(n.channel).or_insert(0) += 1;
    }
    counts
}

/// The program of `channel` in `track`, else the first set for it in any track.
pub(super) fn program(file: &FileInfo, track: usize, channel: u8) -> Option<u8> {
    let ch = usize::from(channel);
    file.tracks[track].programs[ch].or_else(|| file.tracks.iter().find_map(|t| t.programs[ch]))
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
pub(super) fn choose(
    path: &Path,
    file: &FileInfo,
    options: &ImportOptions,
) -> Result<(String, Chosen), MidiError> {
    let whole = |track: usize| Chosen {
        track,
        channel: None,
        percussion: false,
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
