//! Audio → score on data with a known answer: every demo score rendered, then transcribed
//! back, its strokes matched to the rendering's contacts (F-measure at ±20 ms, the drum of
//! each match); the same after realistic damage (another rate, a gain, noise, a delay);
//! the shipped recorded notes joined into a phrase (every note and its pitch); and bad
//! input refused with the file named.

use std::path::{Path, PathBuf};
use timpanist::base::pitch::Pitch;
use timpanist::kit::Kit;
use timpanist::mocap::db::MotionDb;
use timpanist::render::{RenderParams, render};
use timpanist::score::{LoadedScore, Score};
use timpanist::sound::Room;
use timpanist::transcribe::{Options, TranscribeError, transcribe, transcribe_file};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// Match tolerance, s.
const TOLERANCE_S: f64 = 0.020;

/// Every stroke of a score: (time s, drum).
fn strokes_of(score: &Score) -> Vec<(f64, usize)> {
    let map = score.tempo_map();
    let mut v: Vec<(f64, usize)> = score
        .beats
        .iter()
        .flat_map(|b| {
            b.stroke_ticks(score.ticks_per_quarter)
                .map(move |t| (t, b.drum))
        })
        .map(|(t, d)| (map.seconds_at(t as f64), d))
        .collect();
    v.sort_by(|a, b| a.0.total_cmp(&b.0));
    v
}

/// Greedy one-to-one matching in time order within the tolerance: (F-measure, matched,
/// matched with the right drum).
fn score_against(truth: &[(f64, usize)], found: &[(f64, usize)]) -> (f64, usize, usize) {
    let mut used = vec![false; found.len()];
    let (mut hits, mut drums) = (0, 0);
    for &(t, d) in truth {
        let best = (0..found.len())
            .filter(|&j| !used[j] && (found[j].0 - t).abs() <= TOLERANCE_S)
            .min_by(|&a, &b| {
                (found[a].1 != d)
                    .cmp(&(found[b].1 != d))
                    .then((found[a].0 - t).abs().total_cmp(&(found[b].0 - t).abs()))
            });
        if let Some(j) = best {
            used[j] = true;
            hits += 1;
            drums += usize::from(found[j].1 == d);
        }
    }
    let precision = hits as f64 / found.len().max(1) as f64;
    let recall = hits as f64 / truth.len().max(1) as f64;
    let f = if hits == 0 {
        0.0
    } else {
        2.0 * precision * recall / (precision + recall)
    };
    (f, hits, drums)
}

struct Rendered {
    name: String,
    kit: Kit,
    /// Primary contacts: (time s, drum).
    truth: Vec<(f64, usize)>,
    /// Where the score's beats stand, in quarter notes after its first.
    positions: Vec<f64>,
    mono: Vec<f32>,
    rate: u32,
}

fn rendered_demos() -> Vec<Rendered> {
    let db = MotionDb::load(&root().join("mocap")).unwrap();
    let mut paths: Vec<PathBuf> = std::fs::read_dir(root().join("scores"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    paths.sort();
    paths
        .iter()
        .map(|p| {
            let loaded = LoadedScore::load(p).unwrap();
            let r = render(&loaded, &db, &RenderParams::default(), &mut |_| true).unwrap();
            Rendered {
                name: p.file_stem().unwrap().to_string_lossy().into_owned(),
                kit: loaded.kit.clone(),
                truth: r
                    .events
                    .iter()
                    .filter(|e| e.beat.is_some())
                    .map(|e| (e.contact_s, e.drum))
                    .collect(),
                mono: r.audio.mono(),
                rate: r.audio.rate_hz,
                positions: positions(&loaded.score),
            }
        })
        .collect()
}

/// Where `score`'s beats stand, in quarter notes after its first beat, each once.
fn positions(score: &Score) -> Vec<f64> {
    let tpq = f64::from(score.ticks_per_quarter);
    let first = score.beats.first().map_or(0, |b| b.tick);
    let mut p: Vec<f64> = (score.beats.iter())
        .map(|b| (b.tick - first) as f64 / tpq)
        .collect();
    p.dedup();
    p
}

/// How many of `want` (quarter notes after the first beat) `got` writes too (within a
/// 128th: both are on ticks).
fn positions_kept(want: &[f64], got: &[f64]) -> usize {
    want.iter()
        .filter(|w| got.iter().any(|g| (g - *w).abs() < 1.0 / 32.0))
        .count()
}

/// Transcribe `mono` onto `kit` and score it against `truth` shifted by `delay_s`;
/// also checks the score is playable on the kit. Returns (F, hits, right drums, truth,
/// the sounding pitch of each roll written, the positions of its beats as [`positions`]).
fn check(
    name: &str,
    mono: &[f32],
    rate: u32,
    kit: &Kit,
    truth: &[(f64, usize)],
    delay_s: f64,
) -> (f64, usize, usize, usize, Vec<Pitch>, Vec<f64>) {
    let (score, report) = transcribe(mono, rate, kit, name, &Options::default())
        .unwrap_or_else(|e| panic!("{name}: {e}"));
    assert!(
        score.problems(kit).is_empty(),
        "{name}: {:?}",
        score.problems(kit)
    );
    let shifted: Vec<(f64, usize)> = truth.iter().map(|&(t, d)| (t + delay_s, d)).collect();
    let found = strokes_of(&score);
    let (f, hits, drums) = score_against(&shifted, &found);
    println!(
        "{name}: {} contacts, {} strokes written ({} heard, {} rolls, {:.0} bpm); F {:.3}, right drum {}/{}",
        truth.len(),
        found.len(),
        report.strokes,
        report.rolls,
        report.bpm,
        f,
        drums,
        hits
    );
    let rolls = score
        .beats
        .iter()
        .filter(|b| b.roll.is_some())
        .map(|b| b.sounding_pitch(kit))
        .collect();
    (f, hits, drums, truth.len(), rolls, positions(&score))
}

/// The eight demo scores, rendered and transcribed, clean and after the damage a user's
/// file has (−12 dB gain, white noise 50 dB below the peak, 0.35 s of silence in front).
/// Clean (as the issue asks): F ≥ 0.95 at ±20 ms on every score and the right drum for
/// 97 % of the matched strokes (measured 2026-12-07: 317 of 319 found, 312 on the right
/// drum, 295 before a roll after another drum took the pitch its strokes hear; earlier
/// 316 of 319 found, 310 on the right drum. A roll
/// whose soft strokes the onsets miss one of is still one roll, written on its first
/// stroke's drum: before, the roll exercise's A2 roll came apart there and its second
/// half, heard by its (2,1) — an even roll of eighths of a quarter at 96 bpm meets the
/// (1,1) in opposite phase stroke after stroke — was written on the D3 drum: 287 of 315).
/// Damaged: 85 % of the strokes found, F ≥ 0.6 on every score, the right drum for 90 %
/// (measured 2026-12-07: 313 found, 293 on the right drum, 281 before the same change;
/// 2026-12-06: 315 of 319 found, F 0.977 on the roll exercise, and 308 of 315
/// on the right drum; 314, 0.970 and 307 before a roll took in the uneven strokes at its
/// start; 300, 0.840 and 274 before the flux summed a logarithmic filterbank,
/// whose top octaves no longer let the hiss drown soft strokes; 295, 0.789 and 270 before
/// the onsets' local mean looked back 60 ms instead of 100). Heard in a concert hall
/// (`sound::room`, one microphone: recordings are made in rooms): 93 % found, F ≥ 0.75,
/// the right drum for 78 % (measured: 315 of 319 found, F 0.993 on the roll exercise and
/// 0.952 on the secco study, 301 of 315 on the right drum — 272 of 313 before a roll's
/// every stroke took the roll's pitch and a roll took in the uneven strokes at its start,
/// its two rolls written a semitone and a fifth off; 311, 0.962 and 270 before the
/// filterbank; the hall carries the strokes before into each stroke's pitch. Before a
/// roll started on the step of the
/// even line through its strokes rather than at its first onset, which the hall put a
/// third of a step late, 298 found and F 0.763 there; before the 60 ms look-back, 306
/// found, F 0.892, the A2 roll in pieces). A damping is no stroke: the secco
/// study's hand stopping the 29-inch drum was heard as a pp stroke (F 0.909) until
/// `notes::is_damping`. Notation: the share of each score's beat positions (quarter
/// notes after its first beat) the transcription writes too, at least 98 % clean and
/// damaged, 96 % in the hall (measured 2026-12-07: 268, 266 and 266 of 271, a roll now
/// ending before the accent or chord it is tied to; 2026-12-06: 266, 268 and 261; 265, 265 and
/// 258 before the strokes' own even pace set the local beat, `beats::follow_strokes`:
/// the tempo-change study's 120 bpm stretch was written a beat short, 29, 27 and 24 of
/// 33, now 30, 30 and 27; clean 256 before `beats::plainest_period_s`, the improvisation
/// at 72 bpm written at 48 in triplets, 2 of 5, and the secco study at 76 at 114 in
/// dotted notes, 4 of 10).
#[test]
fn rendered_demo_scores_transcribe_back() {
    let demos = rendered_demos();
    let damaged = |mono: &[f32], rate: u32| -> Vec<f32> {
        let mut rng = timpanist::base::rng::Rng::new(7);
        let peak = mono.iter().fold(0.0f32, |m, s| m.max(s.abs()));
        let noise = peak * 10f32.powf(-50.0 / 20.0);
        let lead = (0.35 * f64::from(rate)) as usize;
        std::iter::repeat_n(0.0, lead)
            .chain(mono.iter().copied())
            .map(|s| 0.25 * s + 0.25 * noise * rng.uniform(-1.732, 1.732) as f32)
            .collect()
    };
    // (variant, delay s, least recall over all strokes, least F per score, least share
    // of right drums, least share of the scores' beat positions written as they are).
    // Clean right drums 0.97 (2026-12-07): a roll after another drum takes the pitch its
    // strokes hear (`notes::roll_pitch`) and a roll ends before the note it is tied to
    // (`notate::roll_spans`) — 312 of 317, was 295 with the clean roll exercise's D3 roll
    // read on the A2 drum ringing under it.
    for (variant, delay, least_recall, least_f, least_drums, least_positions) in [
        ("clean", 0.0, 0.95, 0.95, 0.97, 0.98),
        ("damaged", 0.35, 0.85, 0.6, 0.9, 0.98),
        ("hall", 0.0, 0.93, 0.75, 0.78, 0.96),
    ] {
        let (mut hits, mut drums, mut truth, mut per_score) = (0, 0, 0, Vec::new());
        let (mut kept, mut written_positions) = (0, 0);
        for d in &demos {
            let mono = match variant {
                "damaged" => damaged(&d.mono, d.rate),
                "hall" => {
                    let mut wet = d.mono.clone();
                    timpanist::sound::room::reverberate_mono(Room::Hall, &mut wet);
                    wet
                }
                _ => d.mono.clone(),
            };
            let name = format!("{} ({variant})", d.name);
            let (f, h, dr, t, rolls, got) = check(&name, &mono, d.rate, &d.kit, &d.truth, delay);
            let k = positions_kept(&d.positions, &got);
            println!(
                "  {name}: {k} of the score's {} beat positions written",
                d.positions.len()
            );
            kept += k;
            written_positions += d.positions.len();
            if variant == "clean" && d.name == "roll-exercise" {
                // Its D3 roll and its A2 roll, both at their pitch (the A2 roll was written
                // on B♭2 while a roll's first stroke set its pitch; the D3 roll on A2, the
                // drum struck just before it and ringing under it, from 2026-12-07 until
                // its strokes' own pitch could overrule the whole roll's: README "Audio
                // transcription").
                assert_eq!(
                    rolls,
                    vec![Pitch(50), Pitch(45)],
                    "{name}: rolls at {rolls:?}"
                );
            }
            per_score.push((name, f));
            hits += h;
            drums += dr;
            truth += t;
        }
        let written: usize = per_score.len();
        println!(
            "{variant}: {hits} of {truth} contacts matched over {written} scores, right drum {drums}; {kept} of {written_positions} beat positions as the scores write them"
        );
        let recall = hits as f64 / truth as f64;
        assert!(recall >= least_recall, "{variant}: recall {recall:.3}");
        for (name, f) in &per_score {
            assert!(*f >= least_f, "{name}: F {f:.3}");
        }
        assert!(
            drums as f64 >= least_drums * hits as f64,
            "{variant}: right drum {drums} of {hits}"
        );
        assert!(
            kept as f64 >= least_positions * written_positions as f64,
            "{variant}: {kept} of {written_positions} beat positions"
        );
    }
}

/// A recorded note's onset (s) and its principal (1,1) frequency over its first half
/// second (Hz).
fn onset_and_principal(note: &[f32], rate: u32) -> (f64, f64) {
    let onset = timpanist::sound::analysis::onset(note, rate).unwrap() as f64 / f64::from(rate);
    let spec =
        timpanist::sound::spectrum::spectrum(&note[..(rate as usize / 2).min(note.len())], rate);
    let hz = timpanist::sound::spectrum::principal_hz(
        &spec,
        40.0,
        400.0,
        &timpanist::sound::analysis::KETTLEDRUM_RATIOS,
    )
    .unwrap();
    (onset, hz)
}

/// The shipped recorded notes (FluidR3 timpani, 32 kHz, three pitches, each hand) joined
/// into a phrase, played `semitones` higher (resampled: shorter and higher, as a tape sped
/// up), and each note's onset (s) and principal (1,1) frequency (Hz). Each note is cut
/// after 0.9 s and the next follows; `ringing` instead lets every note ring out under the
/// next ones, 0.6 s apart.
fn recorded_phrase(semitones: i32, ringing: bool) -> (Vec<f32>, u32, Vec<(f64, f64)>) {
    let dir = root().join("kits/samples");
    let speed = 2f64.powf(f64::from(semitones) / 12.0);
    let mut phrase: Vec<f32> = Vec::new();
    let mut truth: Vec<(f64, f64)> = Vec::new();
    let mut rate = 0;
    let mut next_at = 0.0;
    for name in ["1L", "2R", "3L", "1R", "3R", "2L"] {
        let (original, r) =
            timpanist::sound::recording::read_mono(&dir.join(format!("Timpani_{name}.wav")))
                .unwrap();
        rate = r;
        let s: Vec<f32> = (0..((original.len() - 1) as f64 / speed) as usize)
            .map(|i| {
                let x = i as f64 * speed;
                let (k, u) = (x.floor() as usize, (x - x.floor()) as f32);
                original[k] + (original[k + 1] - original[k]) * u
            })
            .collect();
        let (onset, hz) = onset_and_principal(&s, r);
        truth.push((next_at + onset, hz));
        let keep = if ringing {
            s.len()
        } else {
            (0.9 * f64::from(r)) as usize
        };
        let start = (next_at * f64::from(r)) as usize;
        phrase.resize(phrase.len().max(start + keep), 0.0);
        for (out, x) in phrase[start..].iter_mut().zip(s.iter().take(keep)) {
            *out += x;
        }
        next_at += if ringing { 0.6 } else { 0.9 };
    }
    (phrase, rate, truth)
}

/// The recorded phrase as recorded and moved up or down by up to a minor seventh, with
/// each note cut or ringing under the next: every note is found within 20 ms with its
/// pitch (a pitch no drum of the standard kit reaches counts when its pitch class is
/// right: it is moved by octaves into a drum's range, as MIDI import does).
#[test]
fn recorded_notes_joined_into_a_phrase() {
    let kit = Kit::standard();
    let variants = [0, -2, 1, 3, 5, 7, 10].map(|s| (s, false));
    for (semitones, ringing) in variants.into_iter().chain([(0, true), (5, true)]) {
        let (phrase, rate, truth) = recorded_phrase(semitones, ringing);
        let (score, report) =
            transcribe(&phrase, rate, &kit, "phrase", &Options::default()).unwrap();
        let found = strokes_of(&score);
        println!(
            "recorded phrase {semitones:+} semitones (ringing {ringing}): truth {truth:.3?}; heard {:.3?}; tuning {:+.0} cents",
            report.onsets_s, report.tuning_cents
        );
        assert_eq!(found.len(), truth.len(), "{semitones:+}: {found:?}");
        let unplayable = truth
            .iter()
            .filter(|(_, hz)| {
                let want = Pitch((69.0 + 12.0 * (hz / 440.0).log2()).round() as u8);
                !kit.drums.iter().any(|d| d.in_range(want))
            })
            .count();
        assert_eq!(report.octave_moves, unplayable, "{semitones:+}");
        for ((t, hz), (beat, (at, _))) in truth.iter().zip(score.beats.iter().zip(&found)) {
            assert!((at - t).abs() <= TOLERANCE_S, "{semitones:+}: {at} vs {t}");
            let want = Pitch((69.0 + 12.0 * (hz / 440.0).log2()).round() as u8);
            let got = beat.sounding_pitch(&kit);
            let playable = kit.drums.iter().any(|d| d.in_range(want));
            println!("  recorded {hz:.1} Hz ({want}): transcribed {got}");
            assert!(
                got == want || (!playable && got.0 % 12 == want.0 % 12),
                "{semitones:+}: recorded {hz:.1} Hz ({want}) transcribed {got}"
            );
        }
    }
}

/// Strokes far apart show no beat in their onset strength: three recorded notes 3 s,
/// 2.4 s and 2 s apart are written on whole beats nearest 100 bpm (100, 100 and 90 bpm),
/// with one tempo after the lead-in; one note alone at 100 bpm with one tempo.
#[test]
fn sparse_strokes_are_written_on_whole_beats() {
    let kit = Kit::standard();
    let (note, rate) =
        timpanist::sound::recording::read_mono(&root().join("kits/samples/Timpani_2R.wav"))
            .unwrap();
    for (gap_s, beats_apart) in [(3.0, 5u64), (2.4, 4), (2.0, 3)] {
        let gap = (gap_s * f64::from(rate)) as usize;
        let mut phrase = vec![0.0f32; rate as usize + 3 * gap];
        for k in 0..3 {
            let at = rate as usize + k * gap;
            let n = note.len().min(gap);
            for (o, s) in phrase[at..at + n].iter_mut().zip(&note[..n]) {
                *o += s;
            }
        }
        let (score, _) = transcribe(&phrase, rate, &kit, "sparse", &Options::default()).unwrap();
        let ticks: Vec<u64> = score.beats.iter().map(|b| b.tick).collect();
        let tpq = u64::from(score.ticks_per_quarter);
        assert_eq!(ticks.len(), 3, "{gap_s} s: {ticks:?}");
        assert!(
            ticks.windows(2).all(|w| w[1] - w[0] == beats_apart * tpq),
            "{gap_s} s: {ticks:?}"
        );
        let after_lead_in: Vec<f64> = (score.tempo.iter())
            .filter(|p| p.tick >= ticks[0])
            .map(|p| p.bpm)
            .collect();
        assert_eq!(after_lead_in.len(), 1, "{gap_s} s: {:?}", score.tempo);
        let want_bpm = 60.0 * beats_apart as f64 / gap_s;
        assert!(
            (after_lead_in[0] / want_bpm - 1.0).abs() < 0.01,
            "{:?}",
            score.tempo
        );
    }
    let (score, _) = transcribe(&note, rate, &kit, "one note", &Options::default()).unwrap();
    assert_eq!(score.beats.len(), 1);
    assert_eq!(score.tempo.len(), 1, "{:?}", score.tempo);
    assert_eq!(score.tempo[0].bpm, 100.0);
}

/// `x` at `from` Hz played at `to` Hz (`to` > `from`): band-limited interpolation, a
/// Hann-windowed sinc of 24 samples either side (as a recording made at 44.1 or 48 kHz).
fn upsampled(x: &[f32], from: u32, to: u32) -> Vec<f32> {
    const HALF: i64 = 24;
    let n = (x.len() as f64 * f64::from(to) / f64::from(from)) as usize;
    (0..n)
        .map(|i| {
            let t = i as f64 * f64::from(from) / f64::from(to);
            let c = t.floor() as i64;
            let taps = (c - HALF + 1).max(0)..=(c + HALF).min(x.len() as i64 - 1);
            taps.map(|m| {
                let d = std::f64::consts::PI * (t - m as f64);
                let sinc = if d.abs() < 1e-12 { 1.0 } else { d.sin() / d };
                let window = 0.5 + 0.5 * (d / HALF as f64).cos();
                f64::from(x[m as usize]) * sinc * window
            })
            .sum::<f64>() as f32
        })
        .collect()
}

/// A roll built from a shipped recorded note (`name`, 32 kHz) at `rate_hz`: 16 strokes
/// at `per_s` per second, each up to `jitter` of a gap early or late and at 55–75 % of
/// the note's level, each ringing under the next (the head struck again while it rings,
/// as in a real roll). Returns the samples, the strokes' onsets (s) and the note's pitch.
fn recorded_roll(
    name: &str,
    rate_hz: u32,
    per_s: f64,
    jitter: f64,
    seed: u64,
) -> (Vec<f32>, Vec<f64>, Pitch) {
    let path = root().join(format!("kits/samples/Timpani_{name}.wav"));
    let (note, r) = timpanist::sound::recording::read_mono(&path).unwrap();
    let note = if r == rate_hz {
        note
    } else {
        upsampled(&note, r, rate_hz)
    };
    let (onset, hz) = onset_and_principal(&note, rate_hz);
    let pitch = Pitch((69.0 + 12.0 * (hz / 440.0).log2()).round() as u8);
    let mut state = seed;
    let mut uniform = || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let strokes = 16;
    let rate = f64::from(rate_hz);
    let mut out = vec![0.0f32; ((0.5 + strokes as f64 / per_s + 3.0) * rate) as usize];
    let mut truth = Vec::new();
    for k in 0..strokes {
        let t = 0.5 + (k as f64 + (2.0 * uniform() - 1.0) * jitter) / per_s;
        let level = (0.55 + 0.2 * uniform()) as f32;
        let at = (t * rate) as usize;
        for (o, x) in out[at..].iter_mut().zip(&note) {
            *o += level * x;
        }
        truth.push(t + onset);
    }
    let peak = out.iter().fold(0.0f32, |m, x| m.max(x.abs()));
    out.iter_mut().for_each(|x| *x *= 0.8 / peak);
    (out, truth, pitch)
}

/// Rolls on the recorded notes (C2, D2 and G2, each hand's sample; 10, 12 and 15 strokes
/// per second; ±3 % and ±8 % timing jitter: 36 rolls of 16 strokes), at 32 kHz as
/// recorded and upsampled to 44.1 and 48 kHz: nearly every stroke is heard within 15 ms,
/// nearly every roll is written as one roll of at least 12 strokes (a stray stroke
/// beside it allowed), and most at the note's pitch (C2, which no drum of the standard
/// kit reaches, an octave up). Measured 2026-12-06 (32 / 44.1 / 48 kHz): 563 / 558 / 565
/// of 576 strokes heard, 33 / 34 / 34 rolls, 30 / 30 / 30 at the pitch (30 / 29 / 29
/// before every stroke of a roll as notation writes it took the roll's pitch; 564 / 560 / 569,
/// 34 / 35 / 35 and 30 / 30 / 31 before the flux summed a logarithmic filterbank rather
/// than every bin, which hears soft strokes under hiss far better). Before the local
/// mean of the onset strength looked back 100 ms (it held a roll's first stroke, struck
/// from silence and many times stronger, when the second came 67–83 ms later) and a
/// roll could leave out a stray onset at its ends: 559 / 550 / 562, 33 / 30 / 30,
/// 29 / 26 / 29. Before the onset frames at 32 kHz were sized to the nearest power of
/// two, a late weak flux peak was masked by 8 % of a loud one and a roll's pitch was taken
/// from the whole run: 480 strokes, 12 single rolls, 12 at the pitch (32 kHz).
#[test]
fn recorded_rolls_are_heard_as_rolls() {
    let kit = Kit::standard();
    for rate_hz in [32_000, 44_100, 48_000] {
        let (mut strokes, mut heard, mut single, mut right, mut rolls) = (0, 0, 0, 0, 0);
        for name in ["1L", "1R", "2L", "2R", "3L", "3R"] {
            for per_s in [10.0, 12.0, 15.0] {
                for jitter in [0.03, 0.08] {
                    let (samples, truth, want) = recorded_roll(name, rate_hz, per_s, jitter, 7);
                    let (score, report) =
                        transcribe(&samples, rate_hz, &kit, "roll", &Options::default()).unwrap();
                    let found = truth
                        .iter()
                        .filter(|t| report.onsets_s.iter().any(|o| (o - *t).abs() <= 0.015))
                        .count();
                    let reachable = kit.drums.iter().any(|d| d.in_range(want));
                    let at_pitch = |b: &timpanist::score::Beat| {
                        let p = b.sounding_pitch(&kit);
                        p == want || (!reachable && p.0 % 12 == want.0 % 12)
                    };
                    let rolled: Vec<_> = score.beats.iter().filter(|b| b.roll.is_some()).collect();
                    let one = rolled.len() == 1
                        && rolled[0].roll.is_some_and(|r| {
                            r.length_ticks
                                >= 12 * u64::from(score.ticks_per_quarter / r.strokes_per_quarter)
                        });
                    let good = if one {
                        at_pitch(rolled[0])
                    } else {
                        2 * score.beats.iter().filter(|b| at_pitch(b)).count() > score.beats.len()
                    };
                    println!(
                        "{rate_hz} Hz {name} ({want}) {per_s}/s ±{jitter}: {found}/16 strokes heard, {} beats{}{}",
                        score.beats.len(),
                        if one { ", one roll" } else { "" },
                        if good { ", at the pitch" } else { "" }
                    );
                    strokes += truth.len();
                    heard += found;
                    single += usize::from(one);
                    right += usize::from(good);
                    rolls += 1;
                }
            }
        }
        println!(
            "{rate_hz} Hz: {heard} of {strokes} strokes heard; {single} of {rolls} rolls written as one roll, {right} at the pitch"
        );
        assert!(
            heard * 100 >= strokes * 96,
            "{rate_hz} Hz: {heard} of {strokes}"
        );
        assert!(
            single * 100 >= rolls * 88,
            "{rate_hz} Hz: {single} of {rolls}"
        );
        assert!(
            right * 100 >= rolls * 78,
            "{rate_hz} Hz: {right} of {rolls}"
        );
    }
}

/// Bad input: a file that is not a WAV, and silence, are refused naming the file.
#[test]
fn bad_input_is_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("notes.wav");
    std::fs::write(&bad, b"RIFF....WAVEfmt garbage").unwrap();
    let kit = Kit::standard();
    let e = transcribe_file(&bad, &kit, &Options::default()).unwrap_err();
    assert!(e.to_string().contains("notes.wav"), "{e}");
    let silent = transcribe(
        &vec![0.0; 48_000],
        48_000,
        &kit,
        "quiet.wav",
        &Options::default(),
    )
    .unwrap_err();
    assert!(matches!(silent, TranscribeError::Silent { .. }), "{silent}");
    assert!(silent.to_string().contains("quiet.wav"));
    let nan = transcribe(
        &[0.0, f32::NAN],
        48_000,
        &kit,
        "nan.wav",
        &Options::default(),
    )
    .unwrap_err();
    assert!(nan.to_string().contains("nan.wav") && nan.to_string().contains("sample 1"));
}

/// Sounds that are no playing: pink noise (5 and 30 s), white noise and a held tone, each
/// starting at once — their only "stroke" is where they begin — are refused by name with
/// how little their start stands out; a single struck note from silence is not.
#[test]
fn noise_and_held_tones_are_not_strokes() {
    let kit = Kit::standard();
    let fs = 48_000u32;
    let mut rng = timpanist::base::rng::Rng::new(5);
    // Pink noise by the Voss–McCartney sum of 16 held white rows.
    let pink = |seconds: usize, rng: &mut timpanist::base::rng::Rng| -> Vec<f32> {
        let mut rows = [0.0f64; 16];
        (0..seconds * fs as usize)
            .map(|n| {
                let row = (n + 1).trailing_zeros().min(15) as usize;
                rows[row] = rng.uniform(-1.0, 1.0);
                (0.03 * rows.iter().sum::<f64>()) as f32
            })
            .collect()
    };
    let white: Vec<f32> = (0..5 * fs)
        .map(|_| 0.3 * rng.uniform(-1.0, 1.0) as f32)
        .collect();
    let tone: Vec<f32> = (0..5 * fs)
        .map(|n| {
            (0.3 * (std::f64::consts::TAU * 147.0 * f64::from(n) / f64::from(fs)).sin()) as f32
        })
        .collect();
    let cases = [
        ("pink5.wav", pink(5, &mut rng)),
        ("pink30.wav", pink(30, &mut rng)),
        ("white.wav", white),
        ("tone.wav", tone),
    ];
    for (name, samples) in cases {
        let e = transcribe(&samples, fs, &kit, name, &Options::default()).unwrap_err();
        assert!(matches!(e, TranscribeError::NoStrike { .. }), "{name}: {e}");
        assert!(
            e.to_string().contains(name) && e.to_string().contains("dB"),
            "{e}"
        );
    }
    let mut note = vec![0.0f32; fs as usize / 2];
    note.extend((0..3 * fs).map(|n| {
        let t = f64::from(n) / f64::from(fs);
        (0.5 * (-t * 2.3).exp() * (std::f64::consts::TAU * 147.0 * t).sin()) as f32
    }));
    let (score, _) = transcribe(&note, fs, &kit, "note.wav", &Options::default()).unwrap();
    assert_eq!(score.beats.len(), 1);
}

/// A recorded note cut to 0.3–0.75 s (the note fills the file, so it is most of its own
/// median level) is still a stroke, while as short a stretch of white noise or a held tone
/// is still refused; faint clicks (single samples 54 dB down, every 0.5 s) ringing on
/// after the note are left out, with a notice, instead of becoming pp strokes.
#[test]
fn short_notes_are_heard_and_faint_clicks_are_not() {
    let kit = Kit::standard();
    let (note, fs) =
        timpanist::sound::recording::read_mono(&root().join("kits/samples/Timpani_2L.wav"))
            .unwrap();
    let mut rng = timpanist::base::rng::Rng::new(11);
    for seconds in [0.3, 0.5, 0.75] {
        let n = (seconds * f64::from(fs)) as usize;
        let (score, _) = transcribe(&note[..n], fs, &kit, "cut.wav", &Options::default()).unwrap();
        assert_eq!(score.beats.len(), 1, "{seconds} s");
        let white: Vec<f32> = (0..n)
            .map(|_| 0.3 * rng.uniform(-1.0, 1.0) as f32)
            .collect();
        let tone: Vec<f32> = (0..n)
            .map(|k| (0.3 * (0.02 * k as f64).sin()) as f32)
            .collect();
        for (name, samples) in [("white.wav", white), ("tone.wav", tone)] {
            let e = transcribe(&samples, fs, &kit, name, &Options::default()).unwrap_err();
            assert!(
                matches!(e, TranscribeError::NoStrike { .. }),
                "{seconds} s {name}: {e}"
            );
        }
    }
    let mut clicked = note.clone();
    clicked.resize(8 * fs as usize, 0.0);
    let peak = note.iter().fold(0.0f32, |m, x| m.max(x.abs()));
    for k in 1..15 {
        clicked[k * fs as usize / 2 + 100] += peak * 10f32.powf(-54.0 / 20.0);
    }
    let (score, report) =
        transcribe(&clicked, fs, &kit, "clicks.wav", &Options::default()).unwrap();
    assert_eq!(score.beats.len(), 1, "{:?}", report.notices);
    assert!(
        report
            .notices
            .iter()
            .any(|n| n.contains("clicks were left out")),
        "{:?}",
        report.notices
    );
}

/// `timpanist transcribe`: a recording becomes a score file that loads; a bad file exits
/// non-zero naming it and writes nothing.
#[test]
fn cli_transcribe() {
    let dir = tempfile::tempdir().unwrap();
    let transcribe = |wav: &Path, out: &Path| {
        std::process::Command::new(env!("CARGO_BIN_EXE_timpanist"))
            .args([
                "transcribe",
                wav.to_str().unwrap(),
                "-o",
                out.to_str().unwrap(),
            ])
            .output()
            .unwrap()
    };
    let wav = root().join("kits/samples/Timpani_2L.wav");
    let out = dir.path().join("note.ron");
    let run = transcribe(&wav, &out);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let loaded = LoadedScore::load(&out).unwrap();
    assert_eq!(loaded.score.beats.len(), 1);
    assert_eq!(loaded.score.title, "Timpani_2L");
    assert!(String::from_utf8_lossy(&run.stdout).contains("0 notes moved by octaves"));

    // The C2 note: no drum of the standard kit reaches it, and the summary says so.
    let low = root().join("kits/samples/Timpani_1L.wav");
    let run = transcribe(&low, &out);
    assert!(run.status.success());
    let said = String::from_utf8_lossy(&run.stdout);
    assert!(said.contains("1 notes moved by octaves"), "{said}");

    let bad = dir.path().join("broken.wav");
    std::fs::write(&bad, b"RIFF").unwrap();
    let never = dir.path().join("never.ron");
    let run = transcribe(&bad, &never);
    assert!(!run.status.success());
    assert!(String::from_utf8_lossy(&run.stderr).contains("broken.wav"));
    assert!(!never.exists());
}
