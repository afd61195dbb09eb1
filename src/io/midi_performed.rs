//! Standard MIDI File of the *performed* hits, so a DAW lines the simulated performance
//! up with the score: a type 1 file with the score's conductor track (title, tempo map,
//! time signatures — as `midi_export` writes them) and one track with a note per primary
//! contact (a scored stroke's own contact, each roll stroke included) at the tick where
//! the file's tempo map puts the simulated contact time.
//!
//! Re-contacts and rebounds (touches that are no stroke's contact) get no note: they
//! sound as part of the stroke's note (a buzz, a flam), and a note for each would double
//! the stroke in a DAW. Key: the pitch the struck drum is tuned to at the contact (the
//! pitch it sounds, pedal changes included). Channel 1, General MIDI program 48 "Timpani" (not
//! channel 10: General MIDI percussion has no timpani key). Velocity: the render's own
//! force aim inverted, v = round(127 · (F − F₀) / ΔF) clamped to 1–127 (F peak force, N;
//! F₀ and ΔF the aims at velocity 0 and the rise to 127), so a stroke that met its aim
//! gets its dynamic's velocity back and velocity never falls as force rises.

use super::midi_export::{conductor_events, note_events, tempo_steps, to_track, track_start};
use crate::base::hit::Hit;
use crate::kit::Kit;
use crate::score::Score;
use midly::num::u15;
use midly::{Format, Header, Smf, Timing};

/// How peak force maps to velocity: the render's force aims.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ForceScale {
    /// Peak force aimed at for velocity 0, N.
    pub at_silence_n: f64,
    /// Rise of the aim from velocity 0 to 127, N.
    pub range_n: f64,
}

impl ForceScale {
    /// The MIDI velocity (1–127) of a contact of peak force `force_n`.
    pub fn velocity(&self, force_n: f64) -> u8 {
        let v = 127.0 * (force_n - self.at_silence_n) / self.range_n.max(1e-9);
        v.round().clamp(1.0, 127.0) as u8
    }
}

/// The primary `hits` as the bytes of a type 1 Standard MIDI File at the score's ticks
/// per quarter, under the score's tempo map. The same input always gives the same bytes.
pub fn export(score: &Score, kit: &Kit, hits: &[Hit], scale: &ForceScale) -> Vec<u8> {
    let tpq = score.ticks_per_quarter;
    let steps = tempo_steps(score);
    let retunes = crate::score::tuning::retunes(score, kit);
    let mut notes: Vec<(u64, u8, u8)> = hits
        .iter()
        .filter(|h| h.primary)
        .filter_map(|h| {
            let key = crate::kit::pitch_at(kit, &retunes, h.drum, h.time_s)?.0;
            let tick = tick_at(&steps, tpq, h.time_s).round() as u64;
            Some((tick, key, scale.velocity(h.peak_force_n)))
        })
        .collect();
    notes.sort_by_key(|n| n.0);
    let mut track = track_start(b"Timpani (performed)");
    let title = super::midi_text::encode(&score.title);
    track.extend(note_events(&notes, u64::from(tpq), |_| None));
    let smf = Smf {
        header: Header::new(
            Format::Parallel,
            Timing::Metrical(u15::new(tpq.min(0x7fff) as u16)),
        ),
        tracks: vec![to_track(conductor_events(score, &title)), to_track(track)],
    };
    let mut bytes = Vec::new();
    smf.write_std(&mut bytes)
        .expect("writing a MIDI file to memory cannot fail");
    bytes
}

/// The tick (fractional) at `seconds` (≥ 0; earlier is tick 0) under tempo `steps`
/// ((tick, µs per quarter) from tick 0), as a sequencer playing the file counts it.
fn tick_at(steps: &[(u64, u32)], tpq: u32, seconds: f64) -> f64 {
    let q = f64::from(tpq);
    let mut at_s = 0.0;
    for (k, &(tick, us)) in steps.iter().enumerate() {
        let per_tick_s = f64::from(us) * 1e-6 / q;
        let end_s = steps
            .get(k + 1)
            .map_or(f64::INFINITY, |n| at_s + (n.0 - tick) as f64 * per_tick_s);
        if seconds < end_s {
            return tick as f64 + (seconds - at_s).max(0.0) / per_tick_s;
        }
        at_s = end_s;
    }
    seconds.max(0.0) * 2.0 * q // no tempo at all: MIDI's default 120 bpm
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kit::Side;
    use crate::score::{TempoChange, TempoPoint};
    use midly::{MidiMessage, TrackEventKind};

    fn hit(time_s: f64, drum: usize, force: f64, primary: bool) -> Hit {
        Hit {
            time_s,
            drum,
            side: Side::Right,
            x_m: 0.0,
            y_m: 0.0,
            peak_force_n: force,
            impact_speed_mps: 1.0,
            primary,
        }
    }

    /// A note per primary hit (a rebound gets none) at the tick the tempo map gives its
    /// time — across a step from 60 to 120 bpm — keyed by the drum's tuning, velocities
    /// rising with force and clamped to 1–127.
    #[test]
    fn notes_of_primary_hits() {
        let kit = Kit::standard();
        let mut score = Score::new("p");
        score.tempo = [(0, 60.0), (1920, 120.0)]
            .map(|(tick, bpm)| TempoPoint {
                tick,
                bpm,
                change: TempoChange::Step,
            })
            .to_vec();
        let scale = ForceScale {
            at_silence_n: 20.0,
            range_n: 100.0,
        };
        let hits = [
            hit(0.5, 0, 10.0, true),
            hit(0.52, 0, 30.0, false),
            hit(1.0, 1, 70.0, true),
            hit(2.25, 2, 500.0, true),
        ];
        let bytes = export(&score, &kit, &hits, &scale);
        assert_eq!(bytes, export(&score, &kit, &hits, &scale));
        let smf = Smf::parse(&bytes).unwrap();
        let mut tick = 0;
        let mut ons = Vec::new();
        for e in &smf.tracks[1] {
            tick += u64::from(e.delta.as_int());
            if let TrackEventKind::Midi {
                message: MidiMessage::NoteOn { key, vel },
                ..
            } = e.kind
            {
                ons.push((tick, key.as_int(), vel.as_int()));
            }
        }
        let key = |d: usize| kit.drums[d].tuning.0;
        // 0.5 s and 1 s at 60 bpm (960 ticks a second); 2.25 s is 2 s (1920) + 0.25 s at
        // 120 bpm (480 ticks).
        assert_eq!(
            ons,
            vec![(480, key(0), 1), (960, key(1), 64), (2400, key(2), 127)]
        );
        // The 26-inch drum's beats name D3 at 1 s and E3 at 2.25 s: a pedal change, and
        // the hit after it is keyed E3.
        score.beats = [(960, "D3"), (2400, "E3")]
            .map(|(tick, p)| crate::score::Beat {
                pitch: Some(p.parse().unwrap()),
                ..crate::score::Beat::plain(tick, 2)
            })
            .to_vec();
        let smf_bytes = export(&score, &kit, &hits, &scale);
        let smf = Smf::parse(&smf_bytes).unwrap();
        let keys: Vec<u8> = (smf.tracks[1].iter())
            .filter_map(|e| match e.kind {
                TrackEventKind::Midi {
                    message: MidiMessage::NoteOn { key, .. },
                    ..
                } => Some(key.as_int()),
                _ => None,
            })
            .collect();
        let e3: crate::base::pitch::Pitch = "E3".parse().unwrap();
        assert_eq!(keys, [key(0), key(1), e3.0]);
    }
}
