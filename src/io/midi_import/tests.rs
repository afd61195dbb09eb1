//! The MIDI import's unit tests: part choice, drums, rolls, tempo and meter maps.

use super::drums::*;
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

/// A note at `tick` of pitch `name` rolled for `length_ticks`, its drum left to choose.
fn rolled(tick: u64, name: &str, length_ticks: u64, strokes_per_quarter: u32) -> Note {
    Note {
        data: Some(BeatData(
            Hand::Auto,
            PlayingMode::Legato,
            usize::MAX,
            ImpactLocation::PlayingSpot,
            Some(Roll {
                length_ticks,
                strokes_per_quarter,
            }),
            None,
        )),
        ..note(tick, pitch(name))
    }
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
    let beats = assign_drums(&[rolled(0, "F3", 960, 4)], &kit, &mut Vec::new());
    assert_eq!(beats[0].drum, 2);
    let beats = assign_drums(&[note(0, pitch("F3"))], &kit, &mut Vec::new());
    assert_eq!(beats[0].drum, 3);
}

/// A roll that starts as another roll on the drum ends does not take that drum when it
/// would have to be retuned with no time to do it: after G2, C3 and D3 rolls back to back,
/// the D3 roll goes to the 23-inch drum (retuned from F3 while idle), although only one
/// hand reaches it upright, where it had gone to the 26-inch drum the C3 roll had just
/// released, retuned in no time.
#[test]
fn a_roll_does_not_take_a_drum_still_rolling_at_another_pitch() {
    let kit = Kit::standard();
    let drums = |d3_at: u64| -> Vec<usize> {
        let notes = [
            rolled(0, "G2", 1920, 8),
            rolled(1920, "C3", 1920, 8),
            rolled(d3_at, "D3", 1920, 8),
        ];
        let beats = assign_drums(&notes, &kit, &mut Vec::new());
        beats.iter().map(|b| b.drum).collect()
    };
    assert_eq!(drums(3840), [1, 2, 3]);
    // With two beats' rest before it the 26-inch drum has time and takes it.
    assert_eq!(drums(5760), [1, 2, 2]);
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
    let map = MeterMap::new(&meter, 960);
    let tempo = tempo_points(
        &[(0, 500_000), (960, 600_000), (1920, 600_000)],
        &clock,
        &map,
        &mut warnings,
    );
    let bpms: Vec<(u64, f64)> = tempo.iter().map(|p| (p.tick, p.bpm)).collect();
    assert_eq!(bpms, vec![(0, 120.0), (960, 100.0)]);
    assert_eq!(tempo_points(&[], &clock, &map, &mut warnings)[0].bpm, 120.0);
}

/// A tempo outside 10–400 bpm is clamped, and the warning names where the first was:
/// 1000 bpm (60 000 µs) at tick 4800, which is bar 2 beat 2 in 4/4 at 960 per quarter.
#[test]
fn clamped_tempo_warning_names_its_place() {
    let mut warnings = Vec::new();
    let clock = Clock::Metrical { tpq: 960, scale: 1 };
    let meter = meter_changes(&[], 960, &mut warnings);
    let map = MeterMap::new(&meter, 960);
    let tempo = tempo_points(
        &[(4800, 60_000), (9600, 60_000_000)],
        &clock,
        &map,
        &mut warnings,
    );
    assert_eq!(tempo[1].bpm, 400.0);
    assert_eq!(tempo[2].bpm, 10.0);
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(
        warnings[0].starts_with("2 tempo events")
            && warnings[0].contains("the first, 1000 bpm, at tick 4800, bar 2 beat 2"),
        "{}",
        warnings[0]
    );
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
