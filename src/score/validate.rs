//! Checks a score against its kit: format version, tempo and meter maps, and every beat
//! (drum exists, pitch in the drum's range, velocity 0–1, location on the head, rolls,
//! no more simultaneous strokes than hands). A beat is named by its number in the file
//! and its bar and beat, and placed at its line in the file when read from text
//! ([`BeatPlaces`]).

use super::{BeatPlaces, Dynamic, Hand, ImpactLocation, SCORE_FORMAT_VERSION, Score, meter, tempo};
use crate::base::problem::Problem;
use crate::kit::Kit;

/// Every problem in `score` played on `kit`, in file order, its beats named as `places`
/// says they stand in the file.
pub fn problems(score: &Score, kit: &Kit, places: &BeatPlaces) -> Vec<Problem> {
    let mut out = Vec::new();
    if score.version != SCORE_FORMAT_VERSION {
        out.push(Problem::new(
            "version",
            format!("expected {SCORE_FORMAT_VERSION}"),
        ));
    }
    out.extend(score.settings.problems(kit));
    if !(24..=32767).contains(&score.ticks_per_quarter) {
        out.push(Problem::new(
            "ticks_per_quarter",
            format!("{} is not between 24 and 32767", score.ticks_per_quarter),
        ));
        return out; // Every position below depends on it.
    }
    let tempo_problems = tempo::validate_points(&score.tempo);
    let tempo_ok = tempo_problems.is_empty();
    for (i, m) in tempo_problems {
        out.push(Problem::new(format!("tempo point {i}"), m));
    }
    let meter_problems = meter::validate_changes(&score.meter, score.ticks_per_quarter);
    let meter_ok = meter_problems.is_empty();
    for (i, m) in meter_problems {
        out.push(Problem::new(format!("time signature {i}"), m));
    }
    if score.beats.len() > crate::base::limits::MAX_BEATS {
        out.push(Problem::new(
            "beats",
            format!(
                "{} beats are more than the {} a score may hold; split it into movements",
                score.beats.len(),
                crate::base::limits::MAX_BEATS
            ),
        ));
        return out;
    }
    if tempo_ok {
        let length_s = score.duration_s();
        if length_s > crate::base::limits::MAX_SCORE_S {
            out.push(Problem::new(
                "length",
                format!(
                    "{} (min:s) is longer than the {} a score may last (a render holds the \
                     whole performance in memory); split it into movements",
                    minutes_and_seconds(length_s),
                    minutes_and_seconds(crate::base::limits::MAX_SCORE_S)
                ),
            ));
        }
    }
    let bars = meter_ok.then(|| score.meter_map());
    // A problem of beat `i` (in time order), named and placed as in the file.
    let of_beat = |i: usize, message: String| {
        let tick = score.beats[i].tick;
        let when = match &bars {
            Some(map) => map.position(tick).to_string(),
            None => format!("tick {tick}"),
        };
        Problem::new(format!("beat {} ({when})", places.number(i)), message).at(places.position(i))
    };
    for (i, beat) in score.beats.iter().enumerate() {
        let mut bad = |message: String| out.push(of_beat(i, message));
        match kit.drums.get(beat.drum) {
            None => bad(format!(
                "drum {} does not exist: kit \"{}\" has drums 0 to {}",
                beat.drum,
                kit.name,
                kit.drums.len().saturating_sub(1)
            )),
            Some(drum) => {
                if let Some(p) = beat.pitch.filter(|&p| !drum.in_range(p)) {
                    bad(format!(
                        "pitch {p} is outside the {} drum's range {}–{}",
                        drum.name, drum.lowest, drum.highest
                    ));
                }
            }
        }
        if let Dynamic::Velocity(v) = beat.dynamic
            && !(0.0..=1.0).contains(&v)
        {
            bad(format!("velocity {v} is not between 0 and 1"));
        }
        if let ImpactLocation::Point { radius, angle_deg } = beat.location {
            point_problems(radius, angle_deg).for_each(&mut bad);
        }
        if let Some(roll) = beat.roll {
            let per_quarter_ok = (1..=32).contains(&roll.strokes_per_quarter)
                && score
                    .ticks_per_quarter
                    .is_multiple_of(roll.strokes_per_quarter);
            if roll.length_ticks == 0 || !per_quarter_ok {
                bad(format!(
                    "a roll needs a positive length and 1–32 strokes per quarter dividing {} ticks",
                    score.ticks_per_quarter
                ));
            }
            if let Some(j) = (i + 1..score.beats.len())
                .find(|&j| score.beats[j].tick > beat.tick && score.beats[j].tick < beat.end_tick())
            {
                bad(format!(
                    "beat {} falls inside this roll, which takes both hands",
                    places.number(j)
                ));
            }
        }
        if let Some(d) = beat.damp
            && (d == 0 || d > MAX_DAMP_QUARTERS * u64::from(score.ticks_per_quarter))
        {
            bad(format!(
                "damp {d} ticks: the hand touches the head 1 tick to {MAX_DAMP_QUARTERS} quarter notes after the stroke"
            ));
        }
    }
    for (i, h) in score.handles.iter().enumerate() {
        let size = h.offset_m.iter().map(|v| v * v).sum::<f64>().sqrt();
        if h.reach_ticks == 0 || !(size.is_finite() && size <= 0.5) {
            out.push(Problem::new(
                format!("handle {i}"),
                "a handle needs a positive reach and a finite offset of at most 0.5 m",
            ));
        }
    }
    for (i, p) in score.pins.iter().enumerate() {
        if !p.point_m.iter().all(|v| v.is_finite() && v.abs() <= 3.0) {
            out.push(Problem::new(
                format!("pin {i}"),
                "a pinned impact point must be finite and within 3 m of the player",
            ));
        }
    }
    let mut i = 0;
    while i < score.beats.len() {
        let tick = score.beats[i].tick;
        let together: Vec<usize> = (i..score.beats.len())
            .take_while(|&j| score.beats[j].tick == tick)
            .collect();
        let hands: Vec<Hand> = together.iter().map(|&j| score.beats[j].hand).collect();
        if together.len() > 2 {
            out.push(of_beat(
                i,
                format!(
                    "{} strokes at once, but a timpanist has two hands",
                    together.len()
                ),
            ));
        } else if together.len() == 2 && hands[0] == hands[1] && hands[0] != Hand::Auto {
            out.push(of_beat(
                together[1],
                format!("two strokes at once with the same hand ({:?})", hands[0]),
            ));
        }
        i += together.len();
    }
    out
}

/// What is wrong with an impact point `Point(radius: …, angle_deg: …)`, each naming its
/// field: a radius outside 0–1 of the head's radius, an angle that is not a finite
/// number of degrees (NaN or infinite).
fn point_problems(radius: f64, angle_deg: f64) -> impl Iterator<Item = String> {
    let radius_bad = !(0.0..=1.0).contains(&radius);
    let angle_bad = !angle_deg.is_finite();
    let radius = radius_bad
        .then(|| format!("impact point radius {radius} must be a fraction 0–1 of the head radius"));
    let angle = angle_bad
        .then(|| format!("impact point angle_deg {angle_deg} must be a finite angle, degrees"));
    radius.into_iter().chain(angle)
}

/// Longest wait before a damping touch, quarter notes (after that the drum has died away).
pub const MAX_DAMP_QUARTERS: u64 = 16;

/// `s` seconds as minutes and whole seconds, rounded up ("30:07"), so a length just over a
/// limit never reads as the limit itself.
fn minutes_and_seconds(s: f64) -> String {
    let whole = s.max(0.0).ceil() as u64;
    format!("{}:{:02}", whole / 60, whole % 60)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::score::{Beat, Roll};

    fn beat(tick: u64, drum: usize) -> Beat {
        Beat::plain(tick, drum)
    }

    fn first_problem(score: &Score) -> String {
        problems(score, &Kit::standard(), &BeatPlaces::in_order())
            .first()
            .map(ToString::to_string)
            .unwrap_or_default()
    }

    /// A sensible score has no problems.
    #[test]
    fn valid_score() {
        let mut s = Score::new("t");
        s.beats = vec![beat(0, 0), beat(960, 3)];
        assert!(s.problems(&Kit::standard()).is_empty());
    }

    /// Each kind of mistake is found and named with its bar and beat.
    #[test]
    fn finds_mistakes() {
        let mut s = Score::new("t");
        s.beats = vec![beat(0, 0), beat(960, 9)];
        assert!(first_problem(&s).contains("beat 1 (bar 1 beat 2): drum 9 does not exist"));

        s.beats = vec![beat(0, 0)];
        s.beats[0].pitch = Some("C4".parse().unwrap());
        assert!(first_problem(&s).contains("outside the 32-inch drum's range D2–A2"));

        s.beats = vec![beat(0, 0)];
        s.beats[0].dynamic = Dynamic::Velocity(1.5);
        assert!(first_problem(&s).contains("velocity"));

        s.beats = vec![beat(0, 0), beat(0, 1), beat(0, 2)];
        assert!(first_problem(&s).contains("3 strokes at once"));

        s.beats = vec![beat(0, 0), beat(0, 1)];
        s.beats[0].hand = Hand::Left;
        s.beats[1].hand = Hand::Left;
        assert!(first_problem(&s).contains("same hand"));

        s.beats = vec![beat(0, 0), beat(480, 1), beat(1920, 1)];
        s.beats[0].roll = Some(Roll {
            length_ticks: 1920,
            strokes_per_quarter: 8,
        });
        assert!(first_problem(&s).contains("beat 1 falls inside this roll"));

        s.beats = vec![beat(0, 0)];
        s.beats[0].damp = Some(0);
        assert!(first_problem(&s).contains("damp 0 ticks"));
        s.beats[0].damp = Some(960);
        assert!(first_problem(&s).is_empty());

        s.beats = vec![beat(0, 0)];
        s.beats[0].location = ImpactLocation::Point {
            radius: 0.5,
            angle_deg: f64::NAN,
        };
        assert_eq!(
            first_problem(&s),
            "beat 0 (bar 1 beat 1): impact point angle_deg NaN must be a finite angle, degrees"
        );
        s.beats[0].location = ImpactLocation::Point {
            radius: 1.5,
            angle_deg: 0.0,
        };
        assert_eq!(
            first_problem(&s),
            "beat 0 (bar 1 beat 1): impact point radius 1.5 must be a fraction 0–1 of the head radius"
        );

        s.beats = vec![beat(0, 0)];
        s.tempo[0].bpm = 2000.0;
        assert!(first_problem(&s).contains("tempo point 0: tempo 2000 bpm is impossible"));
    }

    /// A score past the limits is refused with what they are: too many beats, too long.
    #[test]
    fn limits_hold() {
        use crate::base::limits::{MAX_BEATS, MAX_SCORE_S};
        let mut s = Score::new("t");
        s.beats = (0..=MAX_BEATS as u64).map(|k| beat(k * 480, 0)).collect();
        let p = first_problem(&s);
        assert!(
            p.contains("beats: 50001 beats are more than the 50000"),
            "{p}"
        );
        // One beat 31 minutes in, then one just inside the limit.
        let tick_at = |t: f64| s.tempo_map().tick_at(t) as u64;
        let (late, last) = (tick_at(31.0 * 60.0), tick_at(MAX_SCORE_S - 10.0));
        s.beats = vec![beat(0, 0), beat(late, 1)];
        let p = first_problem(&s);
        assert!(
            p.contains("length: 31:0")
                && p.contains("(min:s) is longer than the 30:00 a score may"),
            "{p}"
        );
        s.beats = vec![beat(0, 0), beat(last, 1)];
        let p = first_problem(&s);
        assert!(p.is_empty(), "{p}");
    }
}
