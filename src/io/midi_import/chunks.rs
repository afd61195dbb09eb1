//! The file's tracks read chunk by chunk, keeping what a damaged file still holds and
//! saying where it is damaged. midly's own reader (without its `strict` feature) stops a
//! track silently at the first event it cannot read and skips chunks it cannot make out,
//! so a damaged track lost its notes without a word; here every track is read event by
//! event and each place reading stopped becomes a [`Damage`] naming the track and the byte
//! (counted from the start of the file).
//!
//! Readings chosen where the file is damaged but its meaning is clear: a track whose chunk
//! length runs past the end of the file ends at its End of Track event, and the chunks
//! after it are read on from there; a channel message without a status byte right after
//! a meta or system-exclusive event continues the running status from before it (the SMF
//! specification says those events cancel running status, but writers rely on it and
//! mido, among others, reads it so: the bytes can mean nothing else); a meta event whose
//! length is right but whose content midly will not read (a key signature of one byte)
//! is kept as an unknown meta event, skipped by its length, so the rest of its track
//! (often the whole tempo map) is not lost for it.

use midly::{EventIter, MetaMessage, TrackEvent, TrackEventKind};

/// Where and how a file is damaged.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(super) struct Damage {
    /// The track (from 0) it is in, if it is in one.
    pub(super) track: Option<usize>,
    /// Byte offset in the file.
    pub(super) byte: usize,
    pub(super) what: String,
    /// Events were lost (else the damage was read around).
    pub(super) lost: bool,
}

/// The tracks' events, and the damage found reading them.
pub(super) fn read_tracks<'a>(
    bytes: &'a [u8],
    chunks: &'a [u8],
) -> (Vec<Vec<TrackEvent<'a>>>, Vec<Damage>) {
    // `chunks` is the part of `bytes` after the header (inside a RIFF wrapper for RMID).
    let mut at = (chunks.as_ptr() as usize).saturating_sub(bytes.as_ptr() as usize);
    let mut rest = chunks;
    let mut tracks = Vec::new();
    let mut damage = Vec::new();
    // In a run of chunks that are no chunks (damage), only the first is reported.
    let mut in_damage = false;
    while !rest.is_empty() {
        let claimed = rest
            .get(4..8)
            .map(|len| u32::from_be_bytes(len.try_into().expect("4 bytes")) as usize);
        let Some(claimed) = claimed.filter(|c| *c <= rest.len() - 8 || rest[..4] == *b"MTrk")
        else {
            if !in_damage {
                damage.push(Damage {
                    track: None,
                    byte: at,
                    what: format!(
                        "no MIDI chunk starts here (the track before may be cut short); the {} bytes from here on are ignored",
                        rest.len()
                    ),
                    lost: true,
                });
            }
            break;
        };
        let body = &rest[8..8 + claimed.min(rest.len() - 8)];
        let id = &rest[..4];
        if id != b"MTrk" {
            // Chunks of other kinds are skipped, as the specification asks; one whose id
            // is no text is damage (a track whose "MTrk" was overwritten, say).
            if !id.iter().all(u8::is_ascii_graphic) && !in_damage {
                damage.push(Damage {
                    track: None,
                    byte: at,
                    what: "bytes that are no MIDI chunk (a damaged or cut-short track?); skipped up to the next track that can be read".into(),
                    lost: true,
                });
            }
            in_damage = !id.iter().all(u8::is_ascii_graphic);
            rest = &rest[8 + body.len()..];
            at += 8 + body.len();
            continue;
        }
        in_damage = false;
        let track = tracks.len();
        let read = read_events(body);
        let mut used = body.len();
        if let Some((offset, what)) = read.bad {
            damage.push(Damage {
                track: Some(track),
                byte: at + 8 + offset,
                what: format!("{what}; the track's events from there on are lost"),
                lost: true,
            });
        } else if claimed > body.len() {
            let (what, lost) = match read.end_of_track {
                Some(end) if end < body.len() => {
                    used = end;
                    (
                        format!(
                            "its chunk length ({claimed} bytes) runs past the end of the file; the track is taken to end at its End of Track (byte {}) and the file read on from there",
                            at + 8 + end
                        ),
                        false,
                    )
                }
                Some(_) => (
                    format!(
                        "its chunk length ({claimed} bytes) runs past the end of the file, which ends with the track's End of Track"
                    ),
                    false,
                ),
                None => (
                    "the file ends before the track's End of Track (it is cut short); the track's events after that are lost".to_string(),
                    true,
                ),
            };
            damage.push(Damage {
                track: Some(track),
                byte: at,
                what,
                lost,
            });
        }
        tracks.push(read.events);
        rest = &rest[8 + used..];
        at += 8 + used;
    }
    (tracks, damage)
}

/// A track's events as far as they can be read.
struct TrackRead<'a> {
    events: Vec<TrackEvent<'a>>,
    /// Where reading stopped (offset in the track's data) and why.
    bad: Option<(usize, &'static str)>,
    /// Offset just past the End of Track event, if there is one.
    end_of_track: Option<usize>,
}

/// The events of a track's data, up to its End of Track or the first it cannot read.
fn read_events(data: &[u8]) -> TrackRead<'_> {
    let mut read = TrackRead {
        events: Vec::new(),
        bad: None,
        end_of_track: None,
    };
    let mut iter = EventIter::new(data);
    // The status of the last channel message, for running status over a meta event.
    let mut channel_status = None;
    loop {
        let pos = data.len() - iter.unread().len();
        if pos == data.len() {
            return read;
        }
        if let Some(why) = bad_lengths(&data[pos..]) {
            read.bad = Some((pos, why));
            return read;
        }
        let running = iter.running_status().or(channel_status).is_some();
        let mut event = iter.next();
        if event.is_none() && iter.running_status().is_none() && channel_status.is_some() {
            let mut again = EventIter::new(&data[pos..]);
            *again.running_status_mut() = channel_status;
            event = again.next();
            if event.is_some() {
                iter = again;
            }
        }
        let event = match event {
            Some(Ok(event)) => event,
            _ => match odd_meta(&data[pos..]) {
                // A meta event midly will not read (a key signature of one byte, say),
                // whose length is right: kept as an unknown one, and reading goes on.
                Some((event, len)) => {
                    read.events.push(event);
                    iter = EventIter::new(&data[pos + len..]);
                    continue;
                }
                None => {
                    read.bad = Some((pos, unreadable(&data[pos..], running)));
                    return read;
                }
            },
        };
        if matches!(event.kind, TrackEventKind::Midi { .. }) {
            channel_status = iter.running_status();
        }
        let end = matches!(event.kind, TrackEventKind::Meta(MetaMessage::EndOfTrack));
        read.events.push(event);
        if end {
            read.end_of_track = Some(data.len() - iter.unread().len());
            return read;
        }
    }
}

/// What is wrong with the lengths of the event at the start of `rest`, which midly
/// (outside its `strict` mode) reads past: a delta time longer than four bytes or cut
/// short, a meta or system-exclusive event longer than the rest of its track.
fn bad_lengths(rest: &[u8]) -> Option<&'static str> {
    let Some((_, n)) = varlen(rest) else {
        return Some(if rest.len() < 4 {
            "the track ends inside an event's delta time"
        } else {
            "a delta time longer than four bytes"
        });
    };
    let rest = &rest[n..];
    let (skip, kind) = match rest.first() {
        None => return Some("the track ends after a delta time, before its event"),
        Some(0xFF) => (2, "a meta event"),
        Some(0xF0 | 0xF7) => (1, "a system-exclusive event"),
        Some(_) => return None,
    };
    match rest.get(skip..).and_then(varlen) {
        Some((len, n)) if rest.len() - skip - n >= len => None,
        Some(_) if kind == "a meta event" => Some("a meta event longer than the rest of its track"),
        Some(_) => Some("a system-exclusive event longer than the rest of its track"),
        None if kind == "a meta event" => Some("a meta event cut short"),
        None => Some("a system-exclusive event cut short"),
    }
}

/// The meta event at the start of `rest` (delta time, 0xFF, type, length, data; its
/// lengths already checked) as an unknown meta event, and the bytes it takes; `None` if
/// `rest` does not start with a meta event or it is End of Track.
fn odd_meta(rest: &[u8]) -> Option<(TrackEvent<'_>, usize)> {
    let (delta, n) = varlen(rest)?;
    let (&0xFF, &kind) = (rest.get(n)?, rest.get(n + 1)?) else {
        return None;
    };
    if kind == 0x2F {
        return None;
    }
    let (len, m) = varlen(rest.get(n + 2..)?)?;
    let start = n + 2 + m;
    let body = rest.get(start..start.checked_add(len)?)?;
    let event = TrackEvent {
        delta: u32::try_from(delta).ok()?.into(),
        kind: TrackEventKind::Meta(MetaMessage::Unknown(kind, body)),
    };
    Some((event, start + len))
}

/// Why midly could not read the event at the start of `rest`, whose lengths are right
/// (`running`: whether a running status could have stood for its status byte).
fn unreadable(rest: &[u8], running: bool) -> &'static str {
    let status = varlen(rest).and_then(|(_, n)| rest.get(n));
    match status {
        Some(b) if *b < 0x80 && !running => {
            "a data byte where a status byte should be (and no running status)"
        }
        _ => "an event cut short or with a bad data byte",
    }
}

/// A variable-length number (at most four bytes) and the bytes it takes.
fn varlen(bytes: &[u8]) -> Option<(usize, usize)> {
    let mut value = 0usize;
    for (i, b) in bytes.iter().take(4).enumerate() {
        value = (value << 7) | usize::from(b & 0x7F);
        if b & 0x80 == 0 {
            return Some((value, i + 1));
        }
    }
    None
}
