//! The lesson pack's phrases: the score cut into groups of bars, each with its stretch of
//! the mix to listen to on its own.
//!
//! A phrase is a run of consecutive bars that hold strokes, at most `bars_per_phrase`
//! long (bars counted from bar 1 under the meter map); a bar with no stroke (a whole bar
//! of rest, and no roll running through it) ends the phrase before it and belongs to
//! none. So a 4-bar phrasing of a score in 4-bar sentences separated by a bar's rest
//! gives one phrase per sentence, and a score with no rests is cut every 4 bars.
//!
//! A phrase's audio runs from [`LEAD_S`] before its first bar line (a stroke on the bar
//! line touches a little early, and the listener hears the phrase start) to [`LEAD_S`]
//! before the next phrase's first bar line, or [`RING_S`] after its own last bar if that
//! comes first; the last phrase runs to the end of the mix. It fades in over [`FADE_IN_S`]
//! and out over [`FADE_OUT_S`], so a cut never clicks.

use crate::score::Score;
use crate::sound::Audio;
use std::ops::RangeInclusive;

/// Audio before a phrase's first bar line, s.
pub const LEAD_S: f64 = 0.1;
/// Longest ring kept after a phrase's last bar when the next phrase starts later, s.
pub const RING_S: f64 = 2.5;
/// Fade at the start and at the end of a phrase's audio, s.
pub const FADE_IN_S: f64 = 0.005;
pub const FADE_OUT_S: f64 = 0.08;

/// One phrase of the score.
#[derive(Clone, Debug, PartialEq)]
pub struct Phrase {
    /// Its bars (counting from 1), both ends included.
    pub bars: RangeInclusive<u64>,
    /// The beats starting in it (indices into the score's beats).
    pub beats: Vec<usize>,
    /// Score time of its first bar line, s.
    pub start_s: f64,
    /// Score time of the bar line after its last bar, s.
    pub end_s: f64,
}

/// The phrases of `score`, `bars_per_phrase` bars at most each (at least 1).
pub fn phrases(score: &Score, bars_per_phrase: u32) -> Vec<Phrase> {
    let meter = score.meter_map();
    let tempo = score.tempo_map();
    let most = u64::from(bars_per_phrase.max(1));
    // For each beat, the bar it starts in and the bar its last stroke (a roll's) is in.
    let spans: Vec<(u64, u64)> = score
        .beats
        .iter()
        .map(|b| (meter.position(b.tick).bar, meter.position(b.end_tick()).bar))
        .collect();
    let Some(last_bar) = spans.iter().map(|s| s.1).max() else {
        return Vec::new();
    };
    let occupied = |bar: u64| spans.iter().any(|&(a, b)| (a..=b).contains(&bar));
    let seconds_at_bar = |bar: u64| tempo.seconds_at(meter.bar_start(bar) as f64);
    let mut out = Vec::new();
    let mut bar = 1;
    while bar <= last_bar {
        if !occupied(bar) {
            bar += 1;
            continue;
        }
        let first = bar;
        while bar <= last_bar && bar - first < most && occupied(bar) {
            bar += 1;
        }
        let bars = first..=bar - 1;
        out.push(Phrase {
            beats: (spans.iter().enumerate())
                .filter(|(_, s)| bars.contains(&s.0))
                .map(|(i, _)| i)
                .collect(),
            start_s: seconds_at_bar(first),
            end_s: seconds_at_bar(bar),
            bars,
        });
    }
    out
}

/// The stretch of the mix (score seconds, from, to) heard as each of `phrases`, for audio
/// of `duration_s`.
pub fn spans(phrases: &[Phrase], duration_s: f64) -> Vec<(f64, f64)> {
    phrases
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let from = (p.start_s - LEAD_S).clamp(0.0, duration_s.max(0.0));
            let to = match phrases.get(i + 1) {
                Some(next) => (next.start_s - LEAD_S).min(p.end_s + RING_S),
                None => duration_s,
            };
            (from, to.min(duration_s).max(from))
        })
        .collect()
}

/// `audio` from `from_s` to `to_s` (score seconds; the mix starts at 0), faded in and out.
pub fn slice(audio: &Audio, from_s: f64, to_s: f64) -> Audio {
    let channels = usize::from(audio.channels.max(1));
    let rate = f64::from(audio.rate_hz);
    let frame = |t: f64| ((t.max(0.0) * rate).round() as usize).min(audio.frames());
    let (a, b) = (frame(from_s), frame(to_s.max(from_s)));
    let mut samples = audio.samples.to_vec_of(a * channels..b * channels);
    let frames = b - a;
    let fade_in = ((FADE_IN_S * rate) as usize).min(frames / 2);
    let fade_out = ((FADE_OUT_S * rate) as usize).min(frames / 2);
    for (k, frame) in samples.chunks_exact_mut(channels).enumerate() {
        let mut g = 1.0f32;
        if k < fade_in {
            g = k as f32 / fade_in as f32;
        }
        let left = frames - 1 - k;
        if left < fade_out {
            g = g.min(left as f32 / fade_out as f32);
        }
        if g < 1.0 {
            frame.iter_mut().for_each(|s| *s *= g);
        }
    }
    Audio {
        rate_hz: audio.rate_hz,
        channels: audio.channels,
        samples: samples.into(),
        gain: audio.gain,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::score::{Beat, MeterChange, Roll};

    /// A 4/4 score at 60 bpm (a bar is 4 s) with beats at the given quarter notes.
    fn score(quarters: &[u64]) -> Score {
        let mut s = Score::new("t");
        s.meter = vec![MeterChange {
            bar: 1,
            numerator: 4,
            denominator: 4,
        }];
        s.tempo[0].bpm = 60.0;
        let tpq = u64::from(s.ticks_per_quarter);
        s.beats = quarters.iter().map(|q| Beat::plain(q * tpq, 0)).collect();
        s
    }

    /// Runs of bars with strokes are cut every N bars; an empty bar ends a phrase and
    /// belongs to none; times are the bar lines.
    #[test]
    fn groups_bars_and_splits_at_rests() {
        // Bars 1-5 filled, bar 6 empty, bars 7-8 filled.
        let quarters: Vec<u64> = (0..20).chain(24..32).collect();
        let p = phrases(&score(&quarters), 4);
        let bars: Vec<_> = p.iter().map(|p| p.bars.clone()).collect();
        assert_eq!(bars, [1..=4, 5..=5, 7..=8]);
        assert_eq!(p[0].beats, (0..16).collect::<Vec<_>>());
        assert_eq!(p[1].beats, (16..20).collect::<Vec<_>>());
        assert_eq!((p[2].start_s, p[2].end_s), (24.0, 32.0));
        assert!(phrases(&score(&[]), 4).is_empty());
    }

    /// A roll running through a bar keeps the bar in its phrase.
    #[test]
    fn a_roll_fills_its_bars() {
        let mut s = score(&[0, 12]);
        s.beats[0].roll = Some(Roll {
            length_ticks: 8 * u64::from(s.ticks_per_quarter),
            strokes_per_quarter: 4,
        });
        let p = phrases(&s, 8);
        assert_eq!(p.len(), 1);
        assert_eq!(p[0].bars, 1..=4);
    }

    /// A phrase's audio stops before the next phrase's first bar line, or after its ring
    /// when the next starts later; the last runs to the end; slices fade to silence.
    #[test]
    fn spans_and_fades() {
        let p = phrases(&score(&[0, 4, 24]), 1);
        let s = spans(&p, 40.0);
        assert_eq!(s.len(), 3);
        assert!((s[0].0 - 0.0).abs() < 1e-9 && (s[0].1 - (4.0 - LEAD_S)).abs() < 1e-9);
        assert!((s[1].1 - (8.0 + RING_S)).abs() < 1e-9);
        assert!((s[2].0 - (24.0 - LEAD_S)).abs() < 1e-9 && s[2].1 == 40.0);
        // Audio shorter than the score (a partial rendering): empty spans at its end.
        let short = spans(&p, 6.0);
        assert_eq!(short[2], (6.0, 6.0));
        assert!(short.iter().all(|(a, b)| a <= b && *b <= 6.0));
        let audio = Audio {
            rate_hz: 1000,
            channels: 2,
            samples: vec![0.5; 2 * 3000].into(),
            gain: 1.0,
        };
        let cut = slice(&audio, 1.0, 2.0);
        assert_eq!(cut.frames(), 1000);
        assert_eq!(cut.samples[0], 0.0);
        assert_eq!(cut.samples[cut.samples.len() - 1], 0.0);
        assert_eq!(cut.samples[1000], 0.5);
    }
}
