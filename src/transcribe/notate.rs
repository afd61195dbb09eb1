//! Heard strokes as beats of a score: each principal partial rounded to a pitch (after the
//! recording's own tuning offset), the pitch given to the drum tuned to it or the nearest
//! drum whose range holds it (which is then retuned), times quantised to the coarsest
//! musical grid that keeps them within 8 ms, fast even runs on one drum written as rolls,
//! and each stroke's added energy mapped to the nearest dynamic marking.

use crate::base::pitch::Pitch;
use crate::kit::Kit;
use crate::score::{Beat, Dynamic, Hand, ImpactLocation, PlayingMode, Roll, TempoMap};

/// Grids tried, coarsest first, as divisions of a quarter note.
const GRIDS: [u32; 10] = [1, 2, 4, 3, 8, 6, 16, 12, 32, 24];
/// A quantised stroke may move at most this far, s.
pub const QUANTISE_TOLERANCE_S: f64 = 0.008;
/// A roll: at least this many strokes…
const ROLL_MIN_STROKES: usize = 6;
/// …each at most this long after the previous, s…
const ROLL_MAX_GAP_S: f64 = 0.13;
/// …each within this share of a gap from an even grid.
const ROLL_EVENNESS: f64 = 0.35;
/// A close run that is not even as a whole may still hold a roll with this many strokes
/// left out at either end.
const ROLL_TRIM: usize = 2;
/// A roll's last stroke at least this much louder than the roll's other strokes (their
/// median) is the note the roll resolves to, dB: an accent or a chord the roll is tied to,
/// struck at the roll's own pace.
const RESOLUTION_DB: f64 = 6.0;

/// One stroke as heard: when, which pitches (two for a chord), how much energy it added.
#[derive(Clone, Debug, PartialEq)]
pub struct Stroke {
    pub time_s: f64,
    /// The principal (1,1) frequency heard, Hz.
    pub principal_hz: Option<f64>,
    /// Added energy, dB re a full-scale sine.
    pub level_db: f64,
}

/// A stroke placed on a drum: its tick and pitch, its drum, and its dynamic.
#[derive(Clone, Debug, PartialEq)]
pub struct Placed {
    pub time_s: f64,
    pub tick: u64,
    /// (drum, pitch) per drum struck.
    pub drums: Vec<(usize, Pitch)>,
    pub dynamic: Dynamic,
    /// Added energy, dB re a full-scale sine (the stroke's [`Stroke::level_db`]).
    pub level_db: f64,
}

/// What notation decided that the user should hear about.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Notes {
    /// Strokes whose pitch no drum reaches, moved by octaves into a drum's range.
    pub octave_moves: usize,
    /// Strokes whose pitch was not heard (no kettledrum pattern): put on the drum of the
    /// previous stroke.
    pub unpitched: usize,
}

/// The fractional MIDI note of `hz` (A4 = 440 Hz).
pub fn midi_of(hz: f64) -> f64 {
    69.0 + 12.0 * (hz / 440.0).log2()
}

/// The recording's tuning offset, cents: the median deviation of the principal partials
/// from equal temperament (A4 = 440 Hz).
pub fn tuning_offset_cents(strokes: &[Stroke]) -> f64 {
    let mut devs: Vec<f64> = strokes
        .iter()
        .filter_map(|s| s.principal_hz)
        .map(|f| {
            let m = midi_of(f);
            100.0 * (m - m.round())
        })
        .collect();
    if devs.is_empty() {
        return 0.0;
    }
    devs.sort_by(f64::total_cmp);
    devs[devs.len() / 2]
}

/// Which drum plays `pitch`: one tuned to it now, else the one in range whose present
/// tuning is nearest (it is retuned), else, moved by octaves, the nearest such. Not
/// `exclude` (the other drum of a chord). Returns the drum, the pitch it plays, and
/// whether an octave move was needed; `None` for a kit without drums.
fn drum_for(
    kit: &Kit,
    tunings: &mut [Pitch],
    pitch: Pitch,
    exclude: Option<usize>,
) -> Option<(usize, Pitch, bool)> {
    let usable = |i: &usize| Some(*i) != exclude;
    if let Some(i) = (0..kit.drums.len())
        .filter(usable)
        .find(|&i| tunings[i] == pitch)
    {
        return Some((i, pitch, false));
    }
    let nearest_in_range = |p: Pitch, tunings: &[Pitch]| {
        (0..kit.drums.len())
            .filter(usable)
            .filter(|&i| kit.drums[i].in_range(p))
            .min_by_key(|&i| (i32::from(tunings[i].0) - i32::from(p.0)).abs())
    };
    if let Some(i) = nearest_in_range(pitch, tunings) {
        tunings[i] = pitch;
        return Some((i, pitch, false));
    }
    for octaves in 1..=4 {
        for p in [
            pitch.transposed(-12 * octaves),
            pitch.transposed(12 * octaves),
        ]
        .into_iter()
        .flatten()
        {
            if let Some(i) = nearest_in_range(p, tunings) {
                tunings[i] = p;
                return Some((i, p, true));
            }
        }
    }
    (0..kit.drums.len())
        .find(usable)
        .map(|i| (i, tunings[i], true))
}

/// The nearest dynamic marking to `level_db`, given each marking's level (pp…ff).
fn dynamic_for(level_db: f64, marks_db: &[f64; 6]) -> Dynamic {
    let i = (0..6)
        .min_by(|&a, &b| {
            (marks_db[a] - level_db)
                .abs()
                .total_cmp(&(marks_db[b] - level_db).abs())
        })
        .unwrap_or(3);
    Dynamic::MARKS[i].0
}

/// The tick of `time_s` on the coarsest grid of [`GRIDS`] that keeps it within
/// [`QUANTISE_TOLERANCE_S`], else the nearest tick; never at or before `after`.
pub fn quantise(map: &TempoMap, tpq: u32, time_s: f64, after: Option<u64>) -> u64 {
    let exact = map.tick_at(time_s).max(0.0);
    let fits = |t: u64| {
        (map.seconds_at(t as f64) - time_s).abs() <= QUANTISE_TOLERANCE_S
            && after.is_none_or(|a| t > a)
    };
    GRIDS
        .iter()
        .filter(|&&g| tpq.is_multiple_of(g))
        .map(|&g| {
            let step = f64::from(tpq / g);
            ((exact / step).round() * step) as u64
        })
        .find(|&t| fits(t))
        .unwrap_or_else(|| {
            let t = exact.round() as u64;
            after.map_or(t, |a| t.max(a + 1))
        })
}

/// Place every stroke: pitch, drum, tick, dynamic. `marks_db(pitch)` gives the levels of
/// the six markings on a drum tuned to `pitch`.
pub fn place(
    strokes: &[Stroke],
    kit: &Kit,
    map: &TempoMap,
    tpq: u32,
    marks_db: &mut dyn FnMut(Pitch) -> [f64; 6],
) -> (Vec<Placed>, Notes) {
    let offset = tuning_offset_cents(strokes) / 100.0;
    let mut tunings: Vec<Pitch> = kit.drums.iter().map(|d| d.tuning).collect();
    let mut notes = Notes::default();
    let mut placed: Vec<Placed> = Vec::new();
    for s in strokes {
        let mut drums: Vec<(usize, Pitch)> = Vec::new();
        if let Some(f) = s.principal_hz {
            let p = Pitch((midi_of(f) - offset).round().clamp(0.0, 127.0) as u8);
            if let Some((i, p, moved)) = drum_for(kit, &mut tunings, p, None) {
                notes.octave_moves += usize::from(moved);
                drums.push((i, p));
            }
        }
        if drums.is_empty() {
            notes.unpitched += 1;
            let i = placed.last().map_or(0, |p: &Placed| p.drums[0].0);
            if i < kit.drums.len() {
                drums.push((i, tunings[i]));
            }
        }
        let Some(&(_, pitch)) = drums.first() else {
            continue;
        };
        let tick = quantise(map, tpq, s.time_s, placed.last().map(|p| p.tick));
        placed.push(Placed {
            time_s: s.time_s,
            tick,
            drums,
            dynamic: dynamic_for(s.level_db, &marks_db(pitch)),
            level_db: s.level_db,
        });
    }
    (placed, notes)
}

/// Runs of strokes to write as rolls: (first, last) index, inclusive ([`roll_spans`] of
/// their times and levels, a chord ending a run, a beat every `tpq` ticks).
pub fn roll_runs(placed: &[Placed], tpq: u32) -> Vec<(usize, usize)> {
    let times: Vec<f64> = placed.iter().map(|p| p.time_s).collect();
    let levels: Vec<f64> = placed.iter().map(|p| p.level_db).collect();
    roll_spans(&times, &levels, &|k| placed[k].drums.len() > 1, &|k| {
        placed[k].tick.is_multiple_of(u64::from(tpq))
    })
}

/// Which strokes at `times` (s, sorted; their added energies `levels`, dB) are rolls:
/// (first, last) index, inclusive, a stroke for which `chord` holds ending a run. Judged
/// by timing — inside a roll each stroke adds little to a head already ringing, so its
/// own pitch is unreliable — a roll is written on one drum, at the pitch heard over the
/// whole roll. Two runs one missed stroke apart (at the pace of both) are one roll: a
/// roll's soft strokes can fall under the onset detector, and each half would otherwise
/// be written on the drum its own first stroke was heard on. A roll's last stroke that is
/// the note it resolves to ([`resolves`]; `on_beat` says which strokes fall on a beat)
/// is left out of it: a half-note roll tied to an accent, its strokes at the roll's own
/// pace, was written one stroke longer and the accent lost, and a final chord with it.
pub fn roll_spans(
    times: &[f64],
    levels: &[f64],
    chord: &dyn Fn(usize) -> bool,
    on_beat: &dyn Fn(usize) -> bool,
) -> Vec<(usize, usize)> {
    let mut runs: Vec<(usize, usize)> = Vec::new();
    let mut i = 0;
    while i < times.len() {
        let mut j = i;
        while j + 1 < times.len() && !chord(j) && times[j + 1] - times[j] <= ROLL_MAX_GAP_S {
            j += 1;
        }
        if let Some((a, b)) = roll_core(&times[i..=j]).map(|(a, b)| (i + a, i + b)) {
            match runs.last_mut() {
                Some(last) if last.1 + 1 == a && one_stroke_missed(times, *last, (a, b)) => {
                    last.1 = b;
                }
                _ => runs.push((a, b)),
            }
        }
        i = j + 1;
    }
    for r in 0..runs.len() {
        let floor = if r == 0 { 0 } else { runs[r - 1].1 + 1 };
        runs[r].0 = extended_back(times, runs[r], floor, chord);
        if resolves(levels, runs[r], on_beat(runs[r].1)) {
            runs[r].1 -= 1;
        }
    }
    runs
}

/// Whether the last stroke of the roll `run` is the note it resolves to, the roll keeping
/// [`ROLL_MIN_STROKES`] without it: struck on a beat (`on_beat`) no softer than the roll's
/// strokes (their median added energy, from `levels`), or anywhere [`RESOLUTION_DB`]
/// louder. A roll's strokes fill its length up to, not at, the beat it ends on; a stroke
/// on that beat is the tied note, an accent added to a ringing head by less than its own
/// dynamic says (a rendered f accent after a p roll: +3 dB).
fn resolves(levels: &[f64], (a, b): (usize, usize), on_beat: bool) -> bool {
    if b - a < ROLL_MIN_STROKES {
        return false;
    }
    let mut roll = levels[a..b].to_vec();
    roll.sort_by(f64::total_cmp);
    let median = roll[roll.len() / 2];
    let margin = if on_beat { 0.0 } else { RESOLUTION_DB };
    levels[b] >= median + margin
}

/// Where the roll `run` of `times` starts once the strokes before it that keep its pace
/// are taken in (each one or two of its steps before the next, within [`ROLL_EVENNESS`]
/// of a step: a soft roll's first strokes, heard unevenly in a hall and one of them
/// missed, were too few to be a roll of their own), not reaching back past `floor` or a
/// chord.
fn extended_back(
    times: &[f64],
    run: (usize, usize),
    floor: usize,
    chord: &dyn Fn(usize) -> bool,
) -> usize {
    let (_, step) = even_line(&times[run.0..=run.1]);
    let mut a = run.0;
    while a > floor && !chord(a - 1) {
        let steps = (times[a] - times[a - 1]) / step;
        if !(0.5..2.5).contains(&steps) || (steps - steps.round()).abs() > ROLL_EVENNESS {
            break;
        }
        a -= 1;
    }
    a
}

/// The longest part of strokes at `times` (s, sorted; a run of close strokes) that is a
/// roll ([`is_roll`]), leaving out at most [`ROLL_TRIM`] strokes at each end (a stray
/// onset just before or after a roll — a loud note's beating, a stroke of the next beat
/// — made the whole run uneven, and each stroke of the roll was written on its own):
/// (first, last) index, inclusive; `None` when no such part is one.
fn roll_core(times: &[f64]) -> Option<(usize, usize)> {
    let n = times.len();
    (0..=2 * ROLL_TRIM)
        .flat_map(|dropped| (0..=dropped).map(move |front| (front, dropped - front)))
        .filter(|&(front, back)| front <= ROLL_TRIM && back <= ROLL_TRIM && front + back < n)
        .map(|(front, back)| (front, n - 1 - back))
        .find(|&(a, b)| is_roll(&times[a..=b]))
}

/// Mean gap between the strokes at `times` (at least two), s.
fn mean_gap(times: &[f64]) -> f64 {
    (times[times.len() - 1] - times[0]) / (times.len() - 1) as f64
}

/// Whether the runs `a` and `b` of `times` (next to each other) keep one pace, within
/// [`ROLL_EVENNESS`] of a gap, with one stroke missing between them.
fn one_stroke_missed(times: &[f64], a: (usize, usize), b: (usize, usize)) -> bool {
    let (ga, gb) = (mean_gap(&times[a.0..=a.1]), mean_gap(&times[b.0..=b.1]));
    let gap = 0.5 * (ga + gb);
    let between = times[b.0] - times[a.1];
    (ga - gb).abs() <= ROLL_EVENNESS * gap && (between - 2.0 * gap).abs() <= ROLL_EVENNESS * gap
}

/// Whether strokes at `times` (s, sorted) lie on an even grid: every one within
/// [`ROLL_EVENNESS`] of a gap from the least-squares line through them.
fn even(times: &[f64]) -> bool {
    let (first, gap) = even_line(times);
    gap > 0.0
        && times
            .iter()
            .enumerate()
            .all(|(k, t)| (first + gap * k as f64 - t).abs() <= ROLL_EVENNESS * gap)
}

/// The least-squares line through `values` (at least two) against their index: its
/// value at index 0 and its step.
fn even_line(values: &[f64]) -> (f64, f64) {
    let index: Vec<f64> = (0..values.len()).map(|k| k as f64).collect();
    line_through(&index, values)
}

/// The least-squares line through the points (`xs`, `ys`) (at least two distinct `xs`):
/// its value at x = 0 and its slope.
fn line_through(xs: &[f64], ys: &[f64]) -> (f64, f64) {
    let n = xs.len() as f64;
    let (mean_x, mean_y) = (xs.iter().sum::<f64>() / n, ys.iter().sum::<f64>() / n);
    let (mut num, mut den) = (0.0, 0.0);
    for (x, y) in xs.iter().zip(ys) {
        num += (x - mean_x) * (y - mean_y);
        den += (x - mean_x).powi(2);
    }
    let slope = num / den;
    (mean_y - slope * mean_x, slope)
}

/// Whether strokes at `times` (s, sorted) are one roll by their timing, as [`roll_runs`]
/// judges it: at least [`ROLL_MIN_STROKES`], each at most [`ROLL_MAX_GAP_S`] after the
/// previous, on an even grid.
fn is_roll(times: &[f64]) -> bool {
    times.len() >= ROLL_MIN_STROKES
        && times.windows(2).all(|w| w[1] - w[0] <= ROLL_MAX_GAP_S)
        && even(times)
}

/// A roll over `run`: where it starts (tick) and its strokes per quarter, the divisor of
/// `tpq` (1–32) nearest the run's rate, with one stroke-step of length per stroke (a
/// roll's strokes run up to, not at, its end; see [`crate::score::Beat::stroke_ticks`]).
/// The run's strokes are fitted by one even line of ticks, and the roll starts on the
/// step of that line's start nearest it: one stroke's own onset can be 20 ms off in a
/// reverberant recording (a hall's roll was written from an onset a third of a step late,
/// and every one of its strokes missed the performance by as much).
pub fn roll_of(run: &[Placed], tpq: u32) -> (u64, Roll) {
    let ticks: Vec<f64> = run.iter().map(|p| p.tick as f64).collect();
    // Each stroke's step on the roll's grid, counting a stroke the onsets missed (a gap
    // of two steps) as a step of its own.
    let mut gaps: Vec<f64> = ticks.windows(2).map(|w| w[1] - w[0]).collect();
    gaps.sort_by(f64::total_cmp);
    let typical = gaps[gaps.len() / 2].max(1.0);
    let mut steps = vec![0.0];
    for w in ticks.windows(2) {
        let last = steps[steps.len() - 1];
        steps.push(last + ((w[1] - w[0]) / typical).round().max(1.0));
    }
    let (first, gap_ticks) = line_through(&steps, &ticks);
    let per_quarter = (1..=32u32)
        .filter(|d| tpq.is_multiple_of(*d))
        .min_by(|&a, &b| {
            let err = |d: u32| (f64::from(tpq) / f64::from(d) / gap_ticks).ln().abs();
            err(a).total_cmp(&err(b))
        })
        .unwrap_or(8);
    let step = f64::from(tpq / per_quarter);
    let start = ((first / step).round() * step).max(0.0);
    let last = first + gap_ticks * steps[steps.len() - 1];
    let strokes = ((last - start) / step).round().max(0.0) as u64 + 1;
    (
        start as u64,
        Roll {
            length_ticks: strokes * step as u64,
            strokes_per_quarter: per_quarter,
        },
    )
}

/// The beats of the placed strokes: rolls where [`roll_runs`] finds them, a beat per drum
/// of each other stroke; the pitch written on the beats of a drum retuned somewhere
/// (`tuning::drop_needless_pitches`).
pub fn beats(placed: &[Placed], kit: &Kit, tpq: u32) -> (Vec<Beat>, usize) {
    let runs = roll_runs(placed, tpq);
    let mut beats = Vec::new();
    let mut i = 0;
    let mut run = runs.iter().peekable();
    while i < placed.len() {
        let p = &placed[i];
        let beat = |(drum, pitch): (usize, Pitch)| Beat {
            tick: p.tick,
            hand: Hand::Auto,
            mode: PlayingMode::Legato,
            dynamic: p.dynamic,
            drum,
            pitch: Some(pitch),
            location: ImpactLocation::PlayingSpot,
            roll: None,
            damp: None,
        };
        if let Some(&&(a, b)) = run.peek()
            && a == i
        {
            let mut b0 = beat(p.drums[0]);
            let (tick, roll) = roll_of(&placed[a..=b], tpq);
            b0.tick = tick;
            b0.roll = Some(roll);
            beats.push(b0);
            run.next();
            i = b + 1;
            continue;
        }
        beats.extend(p.drums.iter().map(|&d| beat(d)));
        i += 1;
    }
    crate::score::tuning::drop_needless_pitches(&mut beats, kit);
    (beats, runs.len())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::score::{TempoChange, TempoPoint};

    fn map(bpm: f64) -> TempoMap {
        TempoMap::new(
            &[TempoPoint {
                tick: 0,
                bpm,
                change: TempoChange::Step,
            }],
            960,
        )
    }

    /// A stroke at `t` s on `drum` (drum, pitch), its tick on the map `m` at 960 per quarter.
    fn stroke_at(m: &TempoMap, t: f64, drum: (usize, Pitch), dynamic: Dynamic) -> Placed {
        Placed {
            time_s: t,
            tick: quantise(m, 960, t, None),
            drums: vec![drum],
            dynamic,
            level_db: -30.0,
        }
    }

    /// On the beat, an eighth, a triplet and a late stroke land on their grids; a stroke
    /// between grids keeps its exact tick.
    #[test]
    fn quantises_to_the_coarsest_grid() {
        let m = map(60.0);
        assert_eq!(quantise(&m, 960, 1.003, None), 960);
        assert_eq!(quantise(&m, 960, 1.5, None), 1440);
        assert_eq!(quantise(&m, 960, 1.0 / 3.0, None), 320);
        assert_eq!(quantise(&m, 960, 2.1143, None), 2030);
        assert_eq!(quantise(&m, 960, 1.0, Some(960)), 961);
    }

    /// A pitch goes to the drum tuned to it; a chord to two drums; an unreachable pitch
    /// is moved by octaves; a new pitch retunes the nearest drum in range.
    #[test]
    fn drums_for_pitches() {
        let kit = Kit::standard();
        let mut tunings: Vec<Pitch> = kit.drums.iter().map(|d| d.tuning).collect();
        let t = tunings.clone();
        for (i, &p) in t.iter().enumerate() {
            assert_eq!(drum_for(&kit, &mut tunings, p, None), Some((i, p, false)));
        }
        let (d, _, _) = drum_for(&kit, &mut tunings, t[2], Some(2)).unwrap();
        assert_ne!(d, 2);
        let high = Pitch(t[3].0 + 24);
        let (_, moved, octave) = drum_for(&kit, &mut tunings, high, None).unwrap();
        assert!(octave && (i32::from(high.0) - i32::from(moved.0)) % 12 == 0);
        let new = Pitch(t[2].0 + 1);
        let (d, p, _) = drum_for(&kit, &mut tunings, new, None).unwrap();
        assert_eq!((p, tunings[d]), (new, new));
    }

    /// Ten even strokes 62.5 ms apart at 60 bpm become one roll of 16 strokes per quarter
    /// and ten strokes' length; one stroke 30 ms late breaks the evenness.
    #[test]
    fn even_fast_runs_are_rolls() {
        let m = map(60.0);
        let placed: Vec<Placed> = (0..10)
            .map(|k| stroke_at(&m, 1.0 + f64::from(k) * 0.0625, (1, Pitch(45)), Dynamic::P))
            .collect();
        assert_eq!(roll_runs(&placed, 960), vec![(0, 9)]);
        let (tick, roll) = roll_of(&placed, 960);
        assert_eq!(tick, 960);
        assert_eq!(roll.strokes_per_quarter, 16);
        assert_eq!(roll.length_ticks, 10 * 60);
        let (beats, rolls) = beats(&placed, &Kit::standard(), 960);
        assert_eq!((beats.len(), rolls), (1, 1));
        assert_eq!(beats[0].tick, 960);
        let uneven: Vec<Placed> = placed
            .iter()
            .enumerate()
            .map(|(k, p)| Placed {
                time_s: p.time_s + if k == 5 { 0.03 } else { 0.0 },
                ..p.clone()
            })
            .collect();
        assert!(roll_runs(&uneven, 960).is_empty());
    }

    /// A roll of 30 strokes, eighths of a quarter at 96 bpm, whose 12th stroke the onsets
    /// missed, its second part heard on another drum: one roll of 30 strokes on the first
    /// part's drum. A second roll after a rest of two strokes stays apart.
    #[test]
    fn a_roll_missing_one_stroke_is_one_roll() {
        let m = map(96.0);
        let stroke = |k: u32| {
            let t = 1.0 + f64::from(k) * 0.078125;
            Placed {
                time_s: t,
                tick: quantise(&m, 960, t, None),
                drums: vec![if k < 11 {
                    (0, Pitch(45))
                } else {
                    (1, Pitch(52))
                }],
                dynamic: Dynamic::Pp,
                level_db: -40.0,
            }
        };
        let placed: Vec<Placed> = (0..30).filter(|&k| k != 11).map(stroke).collect();
        assert_eq!(roll_runs(&placed, 960), vec![(0, 28)]);
        let (beats, rolls) = beats(&placed, &Kit::standard(), 960);
        assert_eq!((beats.len(), rolls), (1, 1));
        assert_eq!(beats[0].drum, 0);
        let roll = beats[0].roll.expect("written as a roll");
        assert_eq!(
            roll.length_ticks / u64::from(960 / roll.strokes_per_quarter),
            30
        );
        let rest: Vec<Placed> = (0..30)
            .filter(|&k| k != 11 && k != 12)
            .map(stroke)
            .collect();
        assert_eq!(roll_runs(&rest, 960), vec![(0, 10), (11, 27)]);
    }

    /// Twelve strokes a tenth of a second apart (sixths of a quarter at 100 bpm) with a
    /// stray onset 50 ms after the last (a loud low note's beating): the twelve are one
    /// roll and the stray one a beat of its own. With the first onset a third of a step
    /// late, as a hall can place it, the roll still starts on its step.
    #[test]
    fn a_roll_leaves_out_a_stray_onset_and_starts_on_its_line() {
        let m = map(100.0);
        let at = |t: f64| stroke_at(&m, t, (1, Pitch(45)), Dynamic::P);
        let mut placed: Vec<Placed> = (0..12).map(|k| at(0.6 + f64::from(k) * 0.1)).collect();
        placed.push(at(0.6 + 1.1 + 0.05));
        assert_eq!(roll_runs(&placed, 960), vec![(0, 11)]);
        let (beats, rolls) = beats(&placed, &Kit::standard(), 960);
        assert_eq!((beats.len(), rolls), (2, 1));
        assert!(beats[1].roll.is_none());
        placed.pop();
        placed[0] = at(0.6 + 0.1 / 3.0);
        let (tick, roll) = roll_of(&placed, 960);
        assert_eq!((tick, roll.strokes_per_quarter), (960, 6));
        assert_eq!(roll.length_ticks, 12 * 160);
    }

    /// A soft roll heard unevenly: three strokes, one missed, then eleven (eighths of a
    /// quarter at 96 bpm). The three are too few to be a roll of their own, but they keep
    /// its pace: one roll from the first stroke, on its grid, 15 steps long.
    #[test]
    fn a_roll_takes_in_the_strokes_before_it_that_keep_its_pace() {
        let m = map(96.0);
        let placed: Vec<Placed> = (0..15)
            .filter(|&k| k != 3)
            .map(|k| {
                stroke_at(
                    &m,
                    1.25 + f64::from(k) * 0.078125,
                    (0, Pitch(45)),
                    Dynamic::Pp,
                )
            })
            .collect();
        assert_eq!(roll_runs(&placed, 960), vec![(0, 13)]);
        let (tick, roll) = roll_of(&placed, 960);
        assert_eq!((tick, roll.strokes_per_quarter), (1920, 8));
        assert_eq!(roll.length_ticks, 15 * 120);
    }

    /// A half-note roll at 96 bpm (16 strokes, eighths of a quarter) tied to a note on the
    /// next beat at the roll's own pace: the roll ends before it and the note is a beat of
    /// its own when it is no softer than the roll (an accent over a ringing head added 3
    /// dB), or 6 dB louder off the beat; a stroke dying away on the beat, or 3 dB louder
    /// off it, stays in the roll.
    #[test]
    fn a_roll_ends_before_the_note_it_resolves_to() {
        let m = map(96.0);
        let roll_with_last = |last_db: f64, late_s: f64| -> Vec<Placed> {
            (0..17)
                .map(|k| {
                    let t = 1.25 + f64::from(k) * 0.078125 + if k == 16 { late_s } else { 0.0 };
                    Placed {
                        level_db: if k == 16 {
                            last_db
                        } else {
                            -24.0 + f64::from(k % 3)
                        },
                        ..stroke_at(&m, t, (1, Pitch(50)), Dynamic::P)
                    }
                })
                .collect()
        };
        let on_beat = roll_with_last(-20.0, 0.0);
        assert_eq!(on_beat[16].tick, 4 * 960);
        assert_eq!(roll_runs(&on_beat, 960), vec![(0, 15)]);
        let (beats, rolls) = beats(&on_beat, &Kit::standard(), 960);
        assert_eq!((beats.len(), rolls), (2, 1));
        assert_eq!(beats[0].roll.map(|r| r.length_ticks), Some(1920));
        assert_eq!((beats[1].tick, beats[1].roll), (4 * 960, None));
        assert_eq!(roll_runs(&roll_with_last(-27.0, 0.0), 960), vec![(0, 16)]);
        // The same strokes a third of a step late: off the beat.
        let off = roll_with_last(-20.0, 0.026);
        assert_ne!(off[16].tick % 960, 0);
        assert_eq!(roll_runs(&off, 960), vec![(0, 16)]);
        assert_eq!(roll_runs(&roll_with_last(-16.0, 0.026), 960), vec![(0, 15)]);
    }
}
