//! The timeline strip under a video frame: one lane per drum, the score's bars and beats,
//! each scheduled stroke as a disc in its hand's colour (larger when louder), each contact
//! as a bar rising with its peak force (re-contacts in red), and the playhead. The strip
//! scrolls: it shows [`WINDOW_S`] around the playhead, which stays a third of the way in.

use super::marks::{Anchor, HAND_COLOURS, Mark, Rgba};
use crate::base::hit::Hit;
use crate::kit::Side;
use crate::motion::plan::PlannedStroke;
use crate::score::{MeterMap, TempoMap};
use glam::DVec2;

/// Seconds of score the strip shows.
pub const WINDOW_S: f64 = 6.0;
/// Where the playhead sits across the strip (0 left, 1 right).
const PLAYHEAD_AT: f64 = 1.0 / 3.0;
/// A contact of this peak force fills its lane's height, N.
const FULL_FORCE_N: f64 = 120.0;
/// Width of the lane names at the left, px.
const GUTTER_PX: f64 = 84.0;
/// Height of the header line (time, bar and beat), px.
const HEADER_PX: f64 = 22.0;

/// What the strip shows.
pub struct StripInput<'a> {
    /// The drums' names, lane by lane (drum 0 at the top).
    pub drum_names: Vec<&'a str>,
    /// The scheduled strokes.
    pub strokes: &'a [PlannedStroke],
    /// Every contact.
    pub hits: &'a [Hit],
    pub tempo: &'a TempoMap,
    pub meter: &'a MeterMap,
    /// The playhead, score seconds.
    pub time_s: f64,
}

/// The strip drawn into the rectangle at `min` of `size` px.
pub fn strip(input: &StripInput, min: DVec2, size: DVec2, out: &mut Vec<Mark>) {
    out.push(Mark::rect(min, min + size, Rgba::rgb(22, 23, 28)));
    let lanes = input.drum_names.len().max(1);
    let top = min.y + HEADER_PX;
    let lane_h = (size.y - HEADER_PX) / lanes as f64;
    let left = min.x + GUTTER_PX;
    let width = (size.x - GUTTER_PX).max(1.0);
    let t0 = input.time_s - PLAYHEAD_AT * WINDOW_S;
    let x_of = |t: f64| left + (t - t0) / WINDOW_S * width;
    let visible = |t: f64| (t0..=t0 + WINDOW_S).contains(&t);
    for (i, name) in input.drum_names.iter().enumerate() {
        let y = top + lane_h * i as f64;
        let shade = if i % 2 == 0 { 30 } else { 26 };
        out.push(Mark::rect(
            DVec2::new(left, y),
            DVec2::new(min.x + size.x, y + lane_h),
            Rgba::rgb(shade, shade + 2, shade + 8),
        ));
        out.push(Mark::Label {
            at: DVec2::new(min.x + 6.0, y + 0.5 * lane_h),
            anchor: Anchor::LeftCentre,
            text: (*name).to_string(),
            size: 13.0,
            colour: Rgba::grey(170),
        });
    }
    grid(input, t0, &x_of, top, min.y + size.y, out);
    let lane_base = |drum: usize| top + lane_h * (drum.min(lanes - 1) + 1) as f64 - 3.0;
    for hit in input.hits.iter().filter(|h| visible(h.time_s)) {
        let x = x_of(hit.time_s);
        let base = lane_base(hit.drum);
        let rise = (hit.peak_force_n / FULL_FORCE_N).clamp(0.02, 1.0) * (lane_h - 8.0);
        let colour = if hit.primary {
            hand_colour(hit.side).with_alpha(200)
        } else {
            Rgba::rgb(230, 60, 60)
        };
        out.push(Mark::segment(
            DVec2::new(x, base),
            DVec2::new(x, base - rise),
            3.0,
            colour,
        ));
    }
    for s in input.strokes.iter().filter(|s| visible(s.time_s)) {
        let y = top + lane_h * (s.drum.min(lanes - 1) as f64 + 0.5);
        let radius = 3.0 + 4.0 * s.dynamic.velocity().clamp(0.0, 1.0) as f32;
        out.push(Mark::Disc {
            centre: DVec2::new(x_of(s.time_s), y),
            radius: radius + 1.0,
            colour: Rgba::grey(15),
        });
        out.push(Mark::Disc {
            centre: DVec2::new(x_of(s.time_s), y),
            radius,
            colour: hand_colour(s.hand),
        });
    }
    let x = x_of(input.time_s);
    out.push(Mark::segment(
        DVec2::new(x, min.y + 2.0),
        DVec2::new(x, min.y + size.y),
        2.0,
        Rgba::grey(240),
    ));
    let tick = input.tempo.tick_at(input.time_s.max(0.0)).max(0.0) as u64;
    out.push(Mark::Label {
        at: DVec2::new(x + 6.0, min.y + 4.0),
        anchor: Anchor::LeftTop,
        text: {
            let at = input.meter.position(tick);
            format!("{:.2} s   bar {} beat {}", input.time_s, at.bar, at.beat)
        },
        size: 13.0,
        colour: Rgba::grey(235),
    });
}

/// The colour of a hand's strokes and trajectory.
pub fn hand_colour(side: Side) -> Rgba {
    match side {
        Side::Left => HAND_COLOURS[0],
        Side::Right => HAND_COLOURS[1],
    }
}

/// Beat lines (faint) and bar lines with their numbers, inside the window from `t0`.
fn grid(
    input: &StripInput,
    t0: f64,
    x_of: &dyn Fn(f64) -> f64,
    top: f64,
    bottom: f64,
    out: &mut Vec<Mark>,
) {
    let t1 = t0 + WINDOW_S;
    let first_tick = input.tempo.tick_at(t0.max(0.0)).max(0.0) as u64;
    let mut bar = input.meter.position(first_tick).bar;
    // A bar is at least one tick long, so this ends; stop at a sane count regardless.
    for _ in 0..10_000 {
        let start = input.meter.bar_start(bar);
        let start_s = input.tempo.seconds_at(start as f64);
        if start_s > t1 {
            break;
        }
        let sig = input.meter.signature_at(start);
        let beat_ticks = sig.beat_ticks(input.meter.ticks_per_quarter()).max(1);
        for beat in 0..u64::from(sig.numerator) {
            let t = input.tempo.seconds_at((start + beat * beat_ticks) as f64);
            if !(t0..=t1).contains(&t) {
                continue;
            }
            let x = x_of(t);
            let (width, colour) = if beat == 0 {
                (1.5, Rgba::grey(95))
            } else {
                (1.0, Rgba::grey(50))
            };
            out.push(Mark::segment(
                DVec2::new(x, top),
                DVec2::new(x, bottom),
                width,
                colour,
            ));
            if beat == 0 {
                out.push(Mark::Label {
                    at: DVec2::new(x + 3.0, top - 18.0),
                    anchor: Anchor::LeftTop,
                    text: bar.to_string(),
                    size: 11.0,
                    colour: Rgba::grey(120),
                });
            }
        }
        bar += 1;
    }
}
