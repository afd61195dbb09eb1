//! MIDI export and import through the library API: round trips of hand-built scores,
//! track selection in constructed files, errors, and a real orchestral file made by
//! music21 from a Bach score with a timpani part.

use midly::num::{u4, u7, u15, u24, u28};
use midly::{Format, Header, MetaMessage, MidiMessage, Smf, Timing, TrackEvent, TrackEventKind};
use std::path::Path;
use timpanist::base::pitch::Pitch;
use timpanist::io::midi_export::export;
use timpanist::io::midi_import::{
    ImportOptions, ImportReport, MidiError, TrackChoice, import, import_file,
};
use timpanist::kit::Kit;
use timpanist::score::{
    Beat, Dynamic, Hand, ImpactLocation, MeterChange, PlayingMode, Roll, Score, TempoChange,
    TempoPoint,
};

fn beat(tick: u64, drum: usize) -> Beat {
    Beat::plain(tick, drum)
}

/// Import `bytes` as "test.mid" on the standard kit, checking the score has no problems.
fn import_ok(bytes: &[u8], options: &ImportOptions) -> (Score, ImportReport) {
    let kit = Kit::standard();
    let (score, report) = import(Path::new("test.mid"), bytes, &kit, options).unwrap();
    assert_eq!(score.problems(&kit), vec![], "{report:?}");
    (score, report)
}

/// The score's title as `export` writes it (the conductor track's name, its bytes) and as
/// the import reads it back.
fn title_written_and_read(title: &str) -> (Vec<u8>, String) {
    let mut score = rich_score();
    score.title = title.into();
    let bytes = export(&score, &Kit::standard());
    let smf = Smf::parse(&bytes).unwrap();
    let written = (smf.tracks[0].iter())
        .find_map(|e| match e.kind {
            TrackEventKind::Meta(MetaMessage::TrackName(name)) => Some(name.to_vec()),
            _ => None,
        })
        .unwrap();
    (
        written,
        import_ok(&bytes, &ImportOptions::default()).0.title,
    )
}

/// A title whose every character is Latin-1 is written in Latin-1 (one byte each, as
/// mido and other readers decode MIDI text), any other transliterated to ASCII; both
/// read back (the Latin-1 ones as written: "Pièce" is not taken for Shift-JIS).
#[test]
fn titles_are_written_in_latin1_or_ascii() {
    let cases: [(&str, &[u8], &str); 4] = [
        ("Ouvertüre", b"Ouvert\xfcre", "Ouvertüre"),
        ("Pièce", b"Pi\xe8ce", "Pièce"),
        ("àé ½", b"\xe0\xe9 \xbd", "àé ½"),
        (
            "Pauken – Tympani ♯",
            b"Pauken - Tympani #",
            "Pauken - Tympani #",
        ),
    ];
    for (title, bytes, back) in cases {
        assert_eq!(
            title_written_and_read(title),
            (bytes.to_vec(), back.to_string()),
            "{title}"
        );
    }
}

/// A score using every kind of beat data, two time signature changes and two beats at once.
fn rich_score() -> Score {
    let mut score = Score::new("Rich");
    score.meter.push(MeterChange {
        bar: 3,
        numerator: 3,
        denominator: 4,
    });
    score.meter.push(MeterChange {
        bar: 5,
        numerator: 6,
        denominator: 8,
    });
    let mut beats = vec![beat(0, 0), beat(0, 3), beat(480, 1), beat(960, 2)];
    beats[0].hand = Hand::Left;
    beats[1].hand = Hand::Right;
    beats[1].dynamic = Dynamic::Velocity(0.3);
    beats[2].pitch = Some("A2".parse().unwrap());
    beats[2].mode = PlayingMode::Staccato;
    beats[2].location = ImpactLocation::Point {
        radius: 0.55,
        angle_deg: -20.5,
    };
    beats[3].roll = Some(Roll {
        length_ticks: 1920,
        strokes_per_quarter: 8,
    });
    beats[3].dynamic = Dynamic::Pp;
    let mut more = vec![beat(2880, 1), beat(7680 + 960, 1), beat(13440, 3)];
    more[0].mode = PlayingMode::VerticalAccent;
    more[0].location = ImpactLocation::Rim;
    more[1].location = ImpactLocation::Centre;
    more[1].hand = Hand::Right;
    more[2].pitch = Some("E3".parse().unwrap());
    more[2].dynamic = Dynamic::Ff;
    more[2].damp = Some(480);
    beats.extend(more);
    score.beats = beats;
    score
}

/// Every beat survives export and import: tick, drum, sounding pitch, MIDI velocity, hand,
/// mode, location, roll and damp; and title and time signatures too.
#[test]
fn round_trip_keeps_every_beat() {
    let kit = Kit::standard();
    let score = rich_score();
    assert_eq!(score.problems(&kit), vec![]);
    let (back, report) = import_ok(&export(&score, &kit), &ImportOptions::default());
    assert!(report.source.contains("Timpani"), "{}", report.source);
    assert_eq!(report.duplicates_dropped, 0);
    assert_eq!(back.title, "Rich");
    assert_eq!(back.meter, score.meter);
    assert_eq!(back.ticks_per_quarter, score.ticks_per_quarter);
    assert_eq!(back.beats.len(), score.beats.len());
    // A beat naming no pitch sounds its drum's pitch then (the drum starts at the first
    // pitch its beats name).
    let sounding = score.sounding_pitches(&kit);
    let heard = back.sounding_pitches(&kit);
    for (((a, b), pitch), back_pitch) in
        score.beats.iter().zip(&back.beats).zip(sounding).zip(heard)
    {
        assert!(a.tick.abs_diff(b.tick) <= 1, "{a:?} {b:?}");
        assert_eq!(a.drum, b.drum, "{a:?} {b:?}");
        assert_eq!(pitch, back_pitch, "{a:?} {b:?}");
        assert_eq!(a.dynamic.midi_velocity(), b.dynamic.midi_velocity());
        assert_eq!(
            (a.hand, a.mode, a.location, a.roll, a.damp),
            (b.hand, b.mode, b.location, b.roll, b.damp)
        );
    }
}

/// A score with an accelerando ramp and a step comes back with every beat at the same
/// time in seconds within 1 ms.
#[test]
fn round_trip_tempo_ramp() {
    let kit = Kit::standard();
    let mut score = Score::new("Accelerando");
    score.tempo = vec![
        TempoPoint {
            tick: 0,
            bpm: 60.0,
            change: TempoChange::Step,
        },
        TempoPoint {
            tick: 8 * 960,
            bpm: 150.0,
            change: TempoChange::Ramp,
        },
        TempoPoint {
            tick: 12 * 960,
            bpm: 90.0,
            change: TempoChange::Step,
        },
    ];
    score.beats = (0..32)
        .map(|i| beat(i * 480 + i % 3 * 7, (i % 4) as usize))
        .collect();
    let (back, _) = import_ok(&export(&score, &kit), &ImportOptions::default());
    assert!(back.tempo.len() > 30, "the ramp is written as steps");
    for (a, b) in score.beat_times().iter().zip(back.beat_times()) {
        assert!((a - b).abs() < 1e-3, "{a} s vs {b} s");
    }
    assert!((score.duration_s() - back.duration_s()).abs() < 1e-3);
}

/// Remove timpanist's sequencer-specific events from a file, as another program might.
fn without_timpanist_data(bytes: &[u8]) -> Vec<u8> {
    let mut smf = Smf::parse(bytes).unwrap();
    for track in &mut smf.tracks {
        let mut carry = 0;
        track.retain_mut(|e| {
            if matches!(
                e.kind,
                TrackEventKind::Meta(MetaMessage::SequencerSpecific(_))
            ) {
                carry += e.delta.as_int();
                return false;
            }
            e.delta = u28::new(e.delta.as_int() + carry);
            carry = 0;
            true
        });
    }
    let mut out = Vec::new();
    smf.write_std(&mut out).unwrap();
    out
}

/// Without timpanist's data a roll's strokes are separate beats (none thinned); with
/// detect_rolls they become the roll again, and pitch and velocity always survive.
#[test]
fn plain_midi_and_roll_detection() {
    let kit = Kit::standard();
    let score = rich_score();
    let plain = without_timpanist_data(&export(&score, &kit));
    let (back, report) = import_ok(&plain, &ImportOptions::default());
    assert_eq!(back.beats.len(), score.beats.len() - 1 + 16);
    assert_eq!(report.notes, back.beats.len());
    assert!(
        back.beats
            .iter()
            .all(|b| b.roll.is_none() && b.hand == Hand::Auto)
    );
    let options = ImportOptions {
        detect_rolls: true,
        ..ImportOptions::default()
    };
    let (rolled, _) = import_ok(&plain, &options);
    assert_eq!(rolled.beats.len(), score.beats.len());
    let sounding = score.sounding_pitches(&kit);
    let heard = rolled.sounding_pitches(&kit);
    for (((a, b), pitch), back_pitch) in (score.beats.iter().zip(&rolled.beats))
        .zip(sounding)
        .zip(heard)
    {
        assert_eq!(a.tick, b.tick);
        assert_eq!(a.roll, b.roll);
        assert_eq!(pitch, back_pitch, "{a:?} {b:?}");
        assert_eq!(a.dynamic.midi_velocity(), b.dynamic.midi_velocity());
    }
}

// ---- constructed files ----

type Events = Vec<(u64, TrackEventKind<'static>)>;

fn on(channel: u8, key: u8, vel: u8) -> TrackEventKind<'static> {
    TrackEventKind::Midi {
        channel: u4::new(channel),
        message: MidiMessage::NoteOn {
            key: u7::new(key),
            vel: u7::new(vel),
        },
    }
}

fn program(channel: u8, program: u8) -> TrackEventKind<'static> {
    TrackEventKind::Midi {
        channel: u4::new(channel),
        message: MidiMessage::ProgramChange {
            program: u7::new(program),
        },
    }
}

fn name(text: &'static str) -> TrackEventKind<'static> {
    TrackEventKind::Meta(MetaMessage::TrackName(text.as_bytes()))
}

/// `count` quarter notes of `key` on `channel`, starting at `start`.
fn notes(channel: u8, key: u8, start: u64, count: u64) -> Events {
    (0..count)
        .map(|i| (start + i * 480, on(channel, key, 90)))
        .collect()
}

/// A Standard MIDI File at 480 ticks per quarter from tracks of (absolute tick, event).
fn smf(format: Format, tracks: Vec<Events>) -> Vec<u8> {
    let tracks = tracks
        .into_iter()
        .map(|mut events| {
            events.sort_by_key(|e| e.0);
            let mut last = 0;
            let mut track: Vec<TrackEvent> = events
                .into_iter()
                .map(|(tick, kind)| {
                    let delta = u28::new((tick - last) as u32);
                    last = tick;
                    TrackEvent { delta, kind }
                })
                .collect();
            track.push(TrackEvent {
                delta: u28::new(0),
                kind: TrackEventKind::Meta(MetaMessage::EndOfTrack),
            });
            track
        })
        .collect();
    let smf = Smf {
        header: Header::new(format, Timing::Metrical(u15::new(480))),
        tracks,
    };
    let mut out = Vec::new();
    smf.write_std(&mut out).unwrap();
    out
}

/// A conductor track with a title and 100 bpm.
fn conductor() -> Events {
    vec![
        (0, name("Symphony")),
        (
            0,
            TrackEventKind::Meta(MetaMessage::Tempo(u24::new(600_000))),
        ),
    ]
}

/// Exact duplicates (and a louder copy) are dropped and counted; repeated fast notes
/// that are not duplicates all stay.
#[test]
fn duplicates_are_dropped() {
    let mut timp = vec![(0, name("Timpani")), (0, program(2, 47))];
    timp.extend(notes(2, 45, 0, 4));
    timp.extend(notes(2, 45, 0, 4));
    timp.push((480, on(2, 45, 120)));
    timp.extend((0..8).map(|i| (2400 + i * 30, on(2, 50, 70))));
    let bytes = smf(Format::Parallel, vec![conductor(), timp]);
    let (score, report) = import_ok(&bytes, &ImportOptions::default());
    assert_eq!(report.notes, 17);
    assert_eq!(report.duplicates_dropped, 5);
    assert_eq!(score.beats.len(), 12);
    assert_eq!(score.beats[1].dynamic.midi_velocity(), 120);
    assert_eq!(score.title, "Symphony");
    assert_eq!(score.ticks_per_quarter, 480);
    assert_eq!(score.tempo[0].bpm, 100.0);
}

/// In a type 0 file the channel with program 48 "Timpani" is chosen over busier
/// channels, including percussion.
#[test]
fn type_0_picks_the_timpani_channel() {
    let mut all = vec![(0, program(0, 0)), (0, program(3, 47))];
    all.extend(notes(0, 72, 0, 20));
    all.extend(notes(9, 38, 0, 20));
    all.extend(notes(3, 38, 240, 3));
    let (score, report) = import_ok(
        &smf(Format::SingleTrack, vec![all]),
        &ImportOptions::default(),
    );
    assert!(report.source.contains("channel 4"), "{}", report.source);
    assert_eq!(score.beats.len(), 3);
    let kit = Kit::standard();
    assert!(
        score
            .beats
            .iter()
            .all(|b| b.sounding_pitch(&kit) == Pitch(38))
    );
}

/// A channel that changes program mid-track is the timpani part only while it is on
/// program 48: the notes it plays on another program are left out and reported (how
/// many, on which program, where the first is), in a type 0 file and in a type 1 file
/// whose program changes are in another track than the notes; a channel that only
/// switches to the timpani later is found too; `--track` keeps every note.
#[test]
fn programs_changed_mid_track() {
    // Channel 4: timpani for bars 1-2 (8 quarters), a piano for bar 3 (4 notes), the
    // timpani again for bar 4 (2 notes); channel 1 a busier piano throughout.
    let mut all = vec![(0, program(0, 0)), (0, program(3, 47))];
    all.extend(notes(0, 72, 0, 20));
    all.extend(notes(3, 38, 0, 8));
    all.push((3840, program(3, 0)));
    all.extend(notes(3, 60, 3840, 4));
    all.push((5760, program(3, 47)));
    all.extend(notes(3, 45, 5760, 2));
    let (score, report) = import_ok(
        &smf(Format::SingleTrack, vec![all.clone()]),
        &ImportOptions::default(),
    );
    assert!(
        report.source.contains("channel 4") && report.source.contains("for 10 of its 14 notes"),
        "{}",
        report.source
    );
    assert_eq!((report.notes, score.beats.len()), (10, 10));
    let left_out = report
        .warnings
        .iter()
        .find(|w| w.contains("left out"))
        .unwrap_or_else(|| panic!("{:?}", report.warnings));
    for part in [
        "4 notes of track 0 (no name), channel 4 were played on program 1",
        "(the first at bar 3 beat 1)",
        "--track 0 imports them too, with every other channel of the track",
    ] {
        assert!(left_out.contains(part), "{left_out}");
    }
    let kit = Kit::standard();
    let pitches: Vec<u8> = (score.beats.iter())
        .map(|b| b.sounding_pitch(&kit).0)
        .collect();
    assert_eq!(pitches, [vec![38; 8], vec![45; 2]].concat());

    // The program changes in the conductor track, the notes in their own track.
    let (changes, played): (Events, Events) = all.iter().cloned().partition(|(_, e)| {
        matches!(
            e,
            TrackEventKind::Midi {
                message: MidiMessage::ProgramChange { .. },
                ..
            }
        )
    });
    let mut conductor = conductor();
    conductor.extend(changes);
    let (score, report) = import_ok(
        &smf(Format::Parallel, vec![conductor, played]),
        &ImportOptions::default(),
    );
    assert_eq!(score.beats.len(), 10, "{report:?}");
    assert!(report.source.contains("track 1"), "{}", report.source);

    // A channel on a piano that switches to the timpani at bar 2 is the part from there.
    let mut late = vec![(0, program(2, 0))];
    late.extend(notes(2, 60, 0, 4));
    late.push((1920, program(2, 47)));
    late.extend(notes(2, 43, 1920, 6));
    let (score, report) = import_ok(
        &smf(Format::SingleTrack, vec![late]),
        &ImportOptions::default(),
    );
    assert!(report.source.contains("channel 3"), "{}", report.source);
    assert_eq!(score.beats.len(), 6);
    assert!(
        report.warnings.iter().any(|w| w.contains("4 notes")
            && w.contains("bar 1 beat 1")
            && w.ends_with("--track 0 imports them too")),
        "{:?}",
        report.warnings
    );

    // --track reads the whole track, every program.
    let options = ImportOptions {
        track: Some(TrackChoice::Index(0)),
        ..ImportOptions::default()
    };
    let (_, report) = import_ok(&smf(Format::SingleTrack, vec![all]), &options);
    assert_eq!(report.notes, 34);
    assert!(!report.warnings.iter().any(|w| w.contains("left out")));
}

/// With no timpani program or name, percussion keys on channel 10 are spread over the
/// drums: the lower key on the lowest drum's tuning, the higher on the highest's.
#[test]
fn percussion_channel_fallback() {
    let mut drums = vec![(0, name("Drums"))];
    drums.extend(notes(9, 36, 0, 4));
    drums.extend(notes(9, 38, 240, 4));
    let mut piano = vec![(0, name("Piano"))];
    piano.extend(notes(0, 60, 0, 8));
    let bytes = smf(Format::Parallel, vec![conductor(), piano, drums]);
    let (score, report) = import_ok(&bytes, &ImportOptions::default());
    assert!(report.source.contains("channel 10"), "{}", report.source);
    let kit = Kit::standard();
    let pitches: Vec<Pitch> = score.beats.iter().map(|b| b.sounding_pitch(&kit)).collect();
    let (low, high) = (kit.drums[0].tuning, kit.drums[3].tuning);
    assert_eq!(pitches, [low, high].repeat(4));
}

/// Three instrument tracks without any timpani marking.
fn band() -> Vec<u8> {
    let mut flute = vec![(0, name("Flute")), (0, program(1, 73))];
    flute.extend(notes(1, 79, 0, 5));
    let mut brass = vec![(0, name("Low Brass")), (0, program(2, 57))];
    brass.extend(notes(2, 31, 0, 6));
    smf(Format::Parallel, vec![conductor(), flute, brass])
}

/// --track by name (any case, part of the name) and by index choose that track, and
/// pitches out of every drum's range are moved by octaves.
#[test]
fn track_by_name_and_index() {
    for choice in [TrackChoice::Name("BRASS".into()), TrackChoice::Index(2)] {
        let options = ImportOptions {
            track: Some(choice),
            ..ImportOptions::default()
        };
        let (score, report) = import_ok(&band(), &options);
        assert!(report.source.contains("Low Brass"), "{}", report.source);
        assert_eq!(score.beats.len(), 6);
        assert_eq!(report.octave_moves, 6);
        assert_eq!(report.warnings.len(), 1, "{:?}", report.warnings);
    }
}

/// Without a timpani part, or with a track that does not exist, the error names the file
/// and lists the tracks with index, name, channel, program and note count.
#[test]
fn errors_list_the_tracks() {
    let kit = Kit::standard();
    let path = Path::new("music/band.mid");
    let err = import(path, &band(), &kit, &ImportOptions::default()).unwrap_err();
    assert!(matches!(err, MidiError::NoTimpani { .. }));
    let message = err.to_string();
    for part in [
        "music/band.mid",
        "--track",
        "track 0 \"Symphony\": no notes",
        "track 1 \"Flute\": 5 notes on channel 2 (program 74)",
        "track 2 \"Low Brass\": 6 notes on channel 3 (program 58)",
    ] {
        assert!(message.contains(part), "{part} not in {message}");
    }
    for choice in [TrackChoice::Index(3), TrackChoice::Name("timpani".into())] {
        let options = ImportOptions {
            track: Some(choice),
            ..ImportOptions::default()
        };
        let message = import(path, &band(), &kit, &options)
            .unwrap_err()
            .to_string();
        assert!(
            message.contains("music/band.mid") && message.contains("Flute"),
            "{message}"
        );
    }
}

/// Bytes that are not MIDI, a type 2 file and a missing file give errors naming the file.
#[test]
fn bad_files_name_the_file() {
    let kit = Kit::standard();
    let options = ImportOptions::default();
    let path = Path::new("broken.mid");
    for bytes in [
        &b"not a midi file at all"[..],
        b"MThd\0\0\0\x06\0\x01\0\x02\x01",
    ] {
        let err = import(path, bytes, &kit, &options).unwrap_err();
        assert!(matches!(err, MidiError::Malformed { .. }), "{err}");
        assert!(err.to_string().starts_with("broken.mid: "), "{err}");
    }
    let type_2 = smf(Format::Sequential, vec![conductor()]);
    let err = import(path, &type_2, &kit, &options).unwrap_err();
    assert!(matches!(err, MidiError::Sequential { .. }), "{err}");
    let missing = Path::new("/no/such/file.mid");
    let err = import_file(missing, &kit, &options).unwrap_err();
    assert!(err.to_string().contains("/no/such/file.mid"), "{err}");
}

/// The options' title and kit reference go into the score.
#[test]
fn title_and_kit_options() {
    let kit = Kit::standard();
    let options = ImportOptions {
        title: Some("Mine".into()),
        kit_ref: "kits/my.ron".into(),
        track: Some(TrackChoice::Index(1)),
        ..ImportOptions::default()
    };
    let (score, _) = import(Path::new("x.mid"), &band(), &kit, &options).unwrap();
    assert_eq!(
        (score.title.as_str(), score.kit.as_str()),
        ("Mine", "kits/my.ron")
    );
}

// ---- a real orchestral file ----

const FIXTURES: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures");

/// Bach, BWV 248/64, converted to MIDI by music21 (15 tracks, 10080 ticks per quarter):
/// the timpani track is found without --track, and its 112 notes come at the offsets and
/// pitches music21 reads from the MusicXML score.
#[test]
fn bach_timpani_part() {
    let kit = Kit::standard();
    let path = Path::new(FIXTURES).join("bwv248-64-6.mid");
    let (score, report) = import_file(&path, &kit, &ImportOptions::default()).unwrap();
    assert_eq!(score.problems(&kit), vec![]);
    assert!(report.source.contains("\"Timpani\""), "{}", report.source);
    assert!(report.source.contains("program 48"), "{}", report.source);
    assert_eq!(report.duplicates_dropped, 0);
    assert_eq!(report.octave_moves, 0);
    assert_eq!(score.title, "bwv248-64-6");
    assert_eq!(score.tempo[0].bpm, 72.0);
    let expected_text =
        std::fs::read_to_string(Path::new(FIXTURES).join("bwv248-64-6.timpani.txt")).unwrap();
    let expected: Vec<(f64, u8)> = expected_text
        .lines()
        .filter(|l| !l.starts_with('#'))
        .map(|l| {
            let (offset, pitch) = l.split_once(' ').unwrap();
            (offset.parse().unwrap(), pitch.parse().unwrap())
        })
        .collect();
    assert_eq!(expected.len(), 112);
    assert_eq!(score.beats.len(), expected.len());
    let tpq = f64::from(score.ticks_per_quarter);
    for (b, &(offset, pitch)) in score.beats.iter().zip(&expected) {
        assert!(
            (b.tick as f64 - offset * tpq).abs() <= 1.0,
            "{b:?} vs {offset}"
        );
        assert_eq!(b.sounding_pitch(&kit), Pitch(pitch), "{b:?}");
    }
    // A2 and D3 alternate: each settles on one drum instead of retuning every stroke.
    let drums: std::collections::BTreeSet<usize> = score.beats.iter().map(|b| b.drum).collect();
    assert_eq!(drums.len(), 2, "{drums:?}");
}
