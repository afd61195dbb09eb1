//! The figures of a rendered performance, as `io::plot` figures for `render --plot` (PNG)
//! and the lesson pack (SVG): the stick tips' heights (target pale, simulated full) with
//! the scheduled strokes as guides, each contact's peak force (N) at its time, and the
//! spectrum of each drum's first stroke over the recorded note nearest its (1,1) (one
//! spectrum panel is also `sound analyse --plot`'s). Spectra are Hann-windowed FFTs
//! (`sound::analysis::note_spectrum_db`), in dB re their peak on a log10 frequency axis.

use super::performance::Performance;
use super::plot::{Figure, HAND_COLOURS, Panel, Series};
use crate::sound::analysis;
use plotters::style::RGBColor;

/// Span of a plotted spectrum from the note's onset, s, and its frequency range, Hz.
const SPECTRUM_SPAN_S: f64 = 0.5;
const SPECTRUM_HZ: (f64, f64) = (30.0, 10_000.0);
/// Points per plotted spectrum (the loudest bin of each log-frequency bucket).
const SPECTRUM_POINTS: usize = 1200;
/// A stroke's spectrum is taken from the mix from this long before its contact, s.
const SPECTRUM_LEAD_S: f64 = 0.01;

/// The colour of `hand` ("left" or "right").
fn hand_colour(hand: &str) -> RGBColor {
    HAND_COLOURS[usize::from(hand == "right")]
}

/// Both tips' heights z (m, performer frame) against score time: the targets pale, the
/// simulated tips full.
pub fn tip_heights_panel(p: &Performance) -> Panel {
    let pale = |c: RGBColor| RGBColor(c.0 / 2 + 127, c.1 / 2 + 127, c.2 / 2 + 127);
    let mut series = Vec::new();
    for (h, hand) in ["left", "right"].into_iter().enumerate() {
        let heights = |tips: &[glam::DVec3]| {
            tips.iter()
                .enumerate()
                .map(|(k, tip)| (p.time_of_sample(k), tip.z))
                .collect()
        };
        series.push(Series {
            label: format!("{hand} target"),
            colour: pale(HAND_COLOURS[h]),
            points: heights(&p.reference.tips[h]),
        });
        series.push(Series {
            label: format!("{hand} simulated"),
            colour: HAND_COLOURS[h],
            points: heights(&p.motion.tips[h]),
        });
    }
    Panel {
        y_label: "stick tip height z (m)".into(),
        series,
        markers: Vec::new(),
    }
}

/// Each contact's peak force (N) at its first touch, coloured by hand.
pub fn forces_panel(p: &Performance) -> Panel {
    Panel {
        y_label: "peak contact force (N)".into(),
        series: Vec::new(),
        markers: p
            .contacts
            .iter()
            .map(|c| {
                let colour = hand_colour(c.hit.hand());
                (c.hit.time_s, c.hit.peak_force_n, colour)
            })
            .collect(),
    }
}

/// The scheduled strokes' times, s: the figures' guide lines.
fn stroke_guides(p: &Performance) -> Vec<f64> {
    p.strokes.iter().map(|s| s.time_s).collect()
}

/// One figure of `panels` over score time, the strokes as guides.
fn over_time(p: &Performance, title: String, panels: Vec<Panel>, size: (u32, u32)) -> Figure {
    Figure {
        title,
        x_label: "time (s)".into(),
        panels,
        guides: stroke_guides(p),
        size,
    }
}

/// Tip heights above, each contact's peak force below (`render --plot`).
pub fn performance_figure(p: &Performance) -> Figure {
    let title = format!("{}: rendered performance", p.score.title);
    let panels = vec![tip_heights_panel(p), forces_panel(p)];
    over_time(p, title, panels, (1400, 800))
}

/// The tip heights alone, the scheduled strokes as guides (the lesson pack).
pub fn tip_heights_figure(p: &Performance) -> Figure {
    let title = format!(
        "{}: stick tip heights (vertical lines: the beats)",
        p.score.title
    );
    over_time(p, title, vec![tip_heights_panel(p)], (1200, 460))
}

/// The peak force of each contact alone (the lesson pack).
pub fn forces_figure(p: &Performance) -> Figure {
    let title = format!("{}: peak force per stroke", p.score.title);
    over_time(p, title, vec![forces_panel(p)], (1200, 380))
}

/// A figure of spectrum panels ([`spectrum_panel`]), one above the other.
pub fn spectra_figure(panels: Vec<Panel>) -> Figure {
    let count = panels.len() as u32;
    Figure {
        title: "Spectra (first 0.5 s) against recorded timpani".into(),
        x_label: "frequency: log10 Hz (2 = 100 Hz, 3 = 1 kHz)".into(),
        panels,
        guides: Vec::new(),
        size: (1200, 120 + 300 * count.max(1)),
    }
}

/// A note's spectrum (dB re its peak, floored at −90) on a log10 frequency axis, with the
/// recorded note nearest its (1,1) pitched to it.
pub fn spectrum_panel(name: &str, samples: &[f32], rate: u32) -> Panel {
    let bucketed = |points: Vec<(f64, f64)>| -> Vec<(f64, f64)> {
        let (lo, hi) = (SPECTRUM_HZ.0.log10(), SPECTRUM_HZ.1.log10());
        let mut buckets = vec![f64::NEG_INFINITY; SPECTRUM_POINTS];
        for (f, d) in points {
            let x = (f.max(1e-9).log10() - lo) / (hi - lo);
            if (0.0..1.0).contains(&x) {
                let b = &mut buckets[(x * SPECTRUM_POINTS as f64) as usize];
                *b = b.max(d.max(-90.0));
            }
        }
        buckets
            .into_iter()
            .enumerate()
            .filter(|(_, d)| d.is_finite())
            .map(|(k, d)| {
                (
                    lo + (k as f64 + 0.5) / SPECTRUM_POINTS as f64 * (hi - lo),
                    d,
                )
            })
            .collect()
    };
    let mut series = Vec::new();
    if let Some((label, points)) = analysis::profile(samples, rate)
        .and_then(|p| p.principal_hz)
        .and_then(|f| analysis::recorded_reference(f, SPECTRUM_SPAN_S))
    {
        series.push(Series {
            label,
            colour: RGBColor(120, 160, 220),
            points: bucketed(points),
        });
    }
    series.push(Series {
        label: "this note".into(),
        colour: RGBColor(200, 120, 30),
        points: bucketed(analysis::note_spectrum_db(samples, rate, SPECTRUM_SPAN_S)),
    });
    Panel {
        y_label: format!("{name}: dB re peak"),
        series,
        markers: Vec::new(),
    }
}

/// Per drum struck, its first scored stroke's spectrum (one second of the mix from 10 ms
/// before the contact: later strokes within it are heard too) over the recorded note
/// nearest its (1,1).
pub fn first_stroke_spectra(p: &Performance) -> Vec<Panel> {
    let mono = p.audio.mono();
    let rate = p.audio.rate_hz;
    let mut seen = Vec::new();
    p.contacts
        .iter()
        .filter(|c| c.beat.is_some())
        .filter(|c| {
            let new = !seen.contains(&c.hit.drum);
            seen.push(c.hit.drum);
            new
        })
        .filter_map(|c| {
            let t = c.hit.time_s;
            let from = ((t - SPECTRUM_LEAD_S).max(0.0) * f64::from(rate)) as usize;
            let name = p
                .kit
                .drums
                .get(c.hit.drum)
                .map_or("drum", |d| d.name.as_str());
            (from < mono.len()).then(|| {
                spectrum_panel(
                    &format!("{name} at {t:.2} s"),
                    &mono[from..(from + rate as usize).min(mono.len())],
                    rate,
                )
            })
        })
        .collect()
}
