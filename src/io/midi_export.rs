//! Standard MIDI File export: a type 1 file with a conductor track (title, tempo, time
//! signatures) and one timpani track (General MIDI program 48 "Timpani" on channel 1).
//!
//! Every beat becomes a note (key = sounding pitch, velocity = dynamic) and a roll becomes
//! its repeated strokes. What MIDI cannot say (hand, playing mode, drum, impact location
//! and roll) goes into a sequencer-specific meta event just before the beat's first note:
//! `timpanist:` followed by a compact RON tuple, which other programs ignore and
//! [`super::midi_import`] reads back. Linear tempo ramps become tempo steps every sixteenth
//! note, each lasting exactly as long in seconds as the ramp takes over that step.
//! The title (the conductor track's name) is written in Latin-1, or transliterated to
//! ASCII when it does not fit ([`super::midi_text`]), as MIDI readers expect.

use crate::kit::Kit;
use crate::score::{Hand, ImpactLocation, PlayingMode, Roll, Score, TempoChange};
use midly::num::{u4, u7, u15, u24, u28};
use midly::{
    Format, Header, MetaMessage, MidiMessage, Smf, Timing, Track, TrackEvent, TrackEventKind,
};
use serde::{Deserialize, Serialize};

/// General MIDI program "Timpani" (48 counted from 1).
pub const GM_TIMPANI: u8 = 47;

/// The manufacturer ID a sequencer-specific meta event's data starts with (SMF 1.0):
/// 0x7D, the one set aside for non-commercial use.
const NON_COMMERCIAL_ID: u8 = 0x7D;

/// Prefix, after [`NON_COMMERCIAL_ID`], of the sequencer-specific payload that carries a
/// beat's timpanist data.
pub(crate) const PAYLOAD_PREFIX: &[u8] = b"timpanist:";

/// What MIDI cannot say about a beat: (hand, mode, drum index, location, roll, damp),
/// written as RON after [`PAYLOAD_PREFIX`].
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub(crate) struct BeatData(
    pub Hand,
    pub PlayingMode,
    pub usize,
    pub ImpactLocation,
    pub Option<Roll>,
    pub Option<u64>,
);

/// [`BeatData`] as files written before 2026-12-07 carry it: without the damp, and
/// without the manufacturer ID.
#[derive(Deserialize)]
struct BeatDataWithoutDamp(Hand, PlayingMode, usize, ImpactLocation, Option<Roll>);

impl BeatData {
    /// The payload bytes for a sequencer-specific meta event.
    fn to_payload(self) -> Vec<u8> {
        let ron = ron::to_string(&self).expect("beat data always serialises to RON");
        [&[NON_COMMERCIAL_ID], PAYLOAD_PREFIX, ron.as_bytes()].concat()
    }

    /// Read a payload written by [`BeatData::to_payload`] (or by an earlier version);
    /// `None` for anything else.
    pub(crate) fn from_payload(bytes: &[u8]) -> Option<BeatData> {
        let bytes = bytes.strip_prefix(&[NON_COMMERCIAL_ID]).unwrap_or(bytes);
        let text = std::str::from_utf8(bytes.strip_prefix(PAYLOAD_PREFIX)?).ok()?;
        ron::from_str(text).ok().or_else(|| {
            let BeatDataWithoutDamp(hand, mode, drum, location, roll) = ron::from_str(text).ok()?;
            Some(BeatData(hand, mode, drum, location, roll, None))
        })
    }
}

/// The score as the bytes of a type 1 Standard MIDI File at the score's ticks per quarter.
/// The same score and kit always give the same bytes.
pub fn export(score: &Score, kit: &Kit) -> Vec<u8> {
    let tpq = score.ticks_per_quarter;
    let payloads: Vec<Vec<u8>> = score
        .beats
        .iter()
        .map(|b| BeatData(b.hand, b.mode, b.drum, b.location, b.roll, b.damp).to_payload())
        .collect();
    let title = super::midi_text::encode(&score.title);
    let smf = Smf {
        header: Header::new(
            Format::Parallel,
            Timing::Metrical(u15::new(tpq.min(0x7fff) as u16)),
        ),
        tracks: vec![
            to_track(conductor_events(score, &title)),
            to_track(timpani_events(score, kit, &payloads)),
        ],
    };
    let mut bytes = Vec::new();
    smf.write_std(&mut bytes)
        .expect("writing a MIDI file to memory cannot fail");
    bytes
}

/// An event at an absolute tick; at the same tick, lower `order` comes first (note offs
/// before everything else), and events of equal order keep the order they were made in.
pub(crate) type Timed<'a> = (u64, u8, TrackEventKind<'a>);

fn meta(message: MetaMessage<'_>) -> TrackEventKind<'_> {
    TrackEventKind::Meta(message)
}

fn midi<'a>(message: MidiMessage) -> TrackEventKind<'a> {
    TrackEventKind::Midi {
        channel: u4::new(0),
        message,
    }
}

/// Sort events by time, turn absolute ticks into deltas and end the track.
pub(crate) fn to_track<'a>(mut events: Vec<Timed<'a>>) -> Track<'a> {
    events.sort_by_key(|&(tick, order, _)| (tick, order));
    let end = events.last().map_or(0, |e| e.0);
    let mut last = 0;
    events
        .into_iter()
        .chain([(end, u8::MAX, meta(MetaMessage::EndOfTrack))])
        .map(|(tick, _, kind)| {
            let delta = (tick - last).min(u64::from(u28::max_value().as_int())) as u32;
            last = tick;
            TrackEvent {
                delta: u28::new(delta),
                kind,
            }
        })
        .collect()
}

/// Title (`title`: the score's, as [`super::midi_text::encode`] writes it), tempo and time
/// signatures.
pub(crate) fn conductor_events<'a>(score: &Score, title: &'a [u8]) -> Vec<Timed<'a>> {
    let mut events = vec![(0, 1, meta(MetaMessage::TrackName(title)))];
    events.extend(
        tempo_steps(score)
            .into_iter()
            .map(|(tick, us)| (tick, 1, meta(MetaMessage::Tempo(u24::new(us))))),
    );
    let bars = score.meter_map();
    events.extend(score.meter.iter().map(|m| {
        let signature = MetaMessage::TimeSignature(
            m.numerator.min(255) as u8,
            m.denominator.trailing_zeros() as u8,
            24,
            8,
        );
        (bars.bar_start(u64::from(m.bar)), 1, meta(signature))
    }));
    events
}

/// The tempo as (tick, µs per quarter note) changes. A ramp is cut into steps of a
/// sixteenth note; each step's constant tempo makes the written file reach the step's end
/// at the ramp's time (rounding errors are carried into the next step, not accumulated).
pub(crate) fn tempo_steps(score: &Score) -> Vec<(u64, u32)> {
    let map = score.tempo_map();
    let q = f64::from(score.ticks_per_quarter);
    let step = (u64::from(score.ticks_per_quarter) / 4).max(1) as usize;
    let mut starts: Vec<u64> = Vec::new();
    for (i, p) in score.tempo.iter().enumerate() {
        match score.tempo.get(i + 1) {
            Some(n) if n.change == TempoChange::Ramp => {
                starts.extend((p.tick..n.tick).step_by(step));
            }
            _ => starts.push(p.tick),
        }
    }
    let mut written_s = 0.0;
    let mut out: Vec<(u64, u32)> = Vec::new();
    for (k, &start) in starts.iter().enumerate() {
        let exact_us = match starts.get(k + 1) {
            Some(&end) => (map.seconds_at(end as f64) - written_s) * 1e6 * q / (end - start) as f64,
            None => 60e6 / map.bpm_at(start as f64),
        };
        let us = exact_us
            .round()
            .clamp(1.0, f64::from(u24::max_value().as_int()));
        if let Some(&end) = starts.get(k + 1) {
            written_s += us * (end - start) as f64 / (q * 1e6);
        }
        if out.last().map(|&(_, u)| f64::from(u)) != Some(us) {
            out.push((start, us as u32));
        }
    }
    out
}

/// Track name, program, and the notes of every beat, each beat's first note preceded by
/// its sequencer-specific data.
fn timpani_events<'a>(score: &Score, kit: &Kit, payloads: &'a [Vec<u8>]) -> Vec<Timed<'a>> {
    let tpq = u64::from(score.ticks_per_quarter);
    // (tick, key, velocity, beat index, first stroke of the beat)
    let mut strokes: Vec<(u64, u8, u8, usize, bool)> = Vec::new();
    let sounding = crate::score::tuning::sounding_pitches(score, kit);
    for (i, (beat, pitch)) in score.beats.iter().zip(&sounding).enumerate() {
        let key = pitch.0;
        let vel = beat.dynamic.midi_velocity();
        strokes.extend(
            beat.stroke_ticks(score.ticks_per_quarter)
                .map(|t| (t, key, vel, i, t == beat.tick)),
        );
    }
    strokes.sort_by_key(|s| s.0);
    let notes: Vec<(u64, u8, u8)> = strokes.iter().map(|s| (s.0, s.1, s.2)).collect();
    let mut events = track_start(b"Timpani");
    events.extend(note_events(&notes, tpq, |n| {
        let (_, _, _, beat, first) = strokes[n];
        first.then(|| meta(MetaMessage::SequencerSpecific(&payloads[beat])))
    }));
    events
}

/// A timpani track's name and its General MIDI program, at tick 0 on channel 1.
pub(crate) fn track_start(name: &[u8]) -> Vec<Timed<'_>> {
    vec![
        (0, 1, meta(MetaMessage::TrackName(name))),
        (
            0,
            1,
            midi(MidiMessage::ProgramChange {
                program: u7::new(GM_TIMPANI),
            }),
        ),
    ]
}

/// Note on and off events (channel 1) for `notes` (tick, key, velocity) sorted by tick:
/// each lasts half a quarter (`tpq` ticks per quarter) or until the next note of its key.
/// `before(n)` may put an event just before note `n`'s note on.
pub(crate) fn note_events<'a>(
    notes: &[(u64, u8, u8)],
    tpq: u64,
    before: impl Fn(usize) -> Option<TrackEventKind<'a>>,
) -> Vec<Timed<'a>> {
    let mut events = Vec::new();
    for (n, &(tick, key, vel)) in notes.iter().enumerate() {
        let next_same_key = notes[n + 1..]
            .iter()
            .find(|s| s.1 == key && s.0 > tick)
            .map_or(u64::MAX, |s| s.0 - tick);
        let length = (tpq / 2).min(next_same_key).max(1);
        if let Some(event) = before(n) {
            events.push((tick, 2, event));
        }
        let (key, vel) = (u7::new(key), u7::new(vel));
        events.push((tick, 2, midi(MidiMessage::NoteOn { key, vel })));
        let off = MidiMessage::NoteOff {
            key,
            vel: u7::new(0),
        };
        events.push((tick + length, 0, midi(off)));
    }
    events
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::score::{Beat, TempoPoint};

    fn beat(tick: u64, drum: usize) -> Beat {
        Beat::plain(tick, drum)
    }

    /// Absolute ticks and kinds of a track's events.
    fn absolute<'a>(track: &Track<'a>) -> Vec<(u64, TrackEventKind<'a>)> {
        let mut tick = 0;
        track
            .iter()
            .map(|e| {
                tick += u64::from(e.delta.as_int());
                (tick, e.kind)
            })
            .collect()
    }

    /// Beat data survives the payload round trip, including a roll, an exact point and a
    /// damp; a payload of an earlier version (no damp, no manufacturer ID) still reads.
    #[test]
    fn payload_round_trip() {
        let data = BeatData(
            Hand::Left,
            PlayingMode::VerticalAccent,
            3,
            ImpactLocation::Point {
                radius: 0.1 + 0.2,
                angle_deg: -33.3,
            },
            Some(Roll {
                length_ticks: 1920,
                strokes_per_quarter: 8,
            }),
            Some(240),
        );
        let payload = data.to_payload();
        assert!(payload.starts_with(b"\x7Dtimpanist:("));
        assert_eq!(BeatData::from_payload(&payload), Some(data));
        assert_eq!(BeatData::from_payload(b"other:(Auto)"), None);
        // As files written before the damp and the manufacturer ID carry it.
        let old = b"timpanist:(Left,Tenuto,2,PlayingSpot,None)";
        assert_eq!(
            BeatData::from_payload(old),
            Some(BeatData(
                Hand::Left,
                PlayingMode::Tenuto,
                2,
                ImpactLocation::PlayingSpot,
                None,
                None
            ))
        );
    }

    /// A ramp's tempo steps reach every step boundary at the ramp's time to 1 µs, and the
    /// tempo after the ramp is the final tempo.
    #[test]
    fn ramp_steps_keep_time() {
        let mut score = Score::new("ramp");
        score.tempo = vec![
            TempoPoint {
                tick: 0,
                bpm: 60.0,
                change: TempoChange::Step,
            },
            TempoPoint {
                tick: 3840,
                bpm: 120.0,
                change: TempoChange::Ramp,
            },
        ];
        let steps = tempo_steps(&score);
        assert_eq!(steps.len(), 17);
        let map = score.tempo_map();
        let mut t = 0.0;
        for w in steps.windows(2) {
            t += f64::from(w[0].1) * 1e-6 * (w[1].0 - w[0].0) as f64 / 960.0;
            assert!((t - map.seconds_at(w[1].0 as f64)).abs() < 1e-6, "{w:?}");
        }
        assert_eq!(steps.last(), Some(&(3840, 500_000)));
    }

    /// Notes are in time order with the data just before each beat's first note, note
    /// offs before note ons at the same tick, roll strokes every 1/8 quarter, and the
    /// same score gives the same bytes.
    #[test]
    fn timpani_track_layout() {
        let kit = Kit::standard();
        let mut score = Score::new("t");
        let mut roll = beat(960, 2);
        roll.roll = Some(Roll {
            length_ticks: 480,
            strokes_per_quarter: 8,
        });
        score.beats = vec![beat(0, 0), beat(100, 0), roll, beat(1440, 2)];
        let bytes = export(&score, &kit);
        assert_eq!(bytes, export(&score, &kit));
        let smf = Smf::parse(&bytes).unwrap();
        assert_eq!(smf.tracks.len(), 2);
        let events = absolute(&smf.tracks[1]);
        let ons: Vec<(u64, u8)> = events
            .iter()
            .filter_map(|(t, k)| match k {
                TrackEventKind::Midi {
                    message: MidiMessage::NoteOn { key, .. },
                    ..
                } => Some((*t, key.as_int())),
                _ => None,
            })
            .collect();
        let f2 = kit.drums[0].tuning.0;
        let d3 = kit.drums[2].tuning.0;
        assert_eq!(
            ons,
            vec![
                (0, f2),
                (100, f2),
                (960, d3),
                (1080, d3),
                (1200, d3),
                (1320, d3),
                (1440, d3)
            ]
        );
        // The first F2 ends when the second starts; each payload precedes a note on.
        let first_off = events.iter().position(|(t, k)| {
            *t == 100
                && matches!(
                    k,
                    TrackEventKind::Midi {
                        message: MidiMessage::NoteOff { .. },
                        ..
                    }
                )
        });
        let second_on = events.iter().position(|(t, k)| {
            *t == 100
                && matches!(
                    k,
                    TrackEventKind::Midi {
                        message: MidiMessage::NoteOn { .. },
                        ..
                    }
                )
        });
        assert!(first_off < second_on && first_off.is_some());
        let payloads: Vec<usize> = events
            .iter()
            .enumerate()
            .filter(|(_, (_, k))| {
                matches!(k, TrackEventKind::Meta(MetaMessage::SequencerSpecific(_)))
            })
            .map(|(i, _)| i)
            .collect();
        assert_eq!(payloads.len(), 4);
        for i in payloads {
            assert!(matches!(
                events[i + 1].1,
                TrackEventKind::Midi {
                    message: MidiMessage::NoteOn { .. },
                    ..
                }
            ));
        }
        assert!(matches!(
            events.last().unwrap().1,
            TrackEventKind::Meta(MetaMessage::EndOfTrack)
        ));
    }
}
