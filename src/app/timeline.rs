//! A read-only timeline: one lane per hand (and one for beats still on Auto), bar and beat
//! grid, beats drawn by playing mode (colour and shape), dynamic (size) and drum (label).

use crate::score::{Hand, LoadedScore, PlayingMode};
use eframe::egui::{self, Color32, Pos2, Rect, Sense, Shape, Stroke, Vec2};

/// Colour of each playing mode.
pub fn mode_colour(mode: PlayingMode) -> Color32 {
    match mode {
        PlayingMode::Legato => Color32::from_rgb(90, 170, 255),
        PlayingMode::Tenuto => Color32::from_rgb(120, 210, 140),
        PlayingMode::Accent => Color32::from_rgb(255, 170, 60),
        PlayingMode::VerticalAccent => Color32::from_rgb(240, 90, 90),
        PlayingMode::Staccato => Color32::from_rgb(200, 130, 240),
    }
}

const LANES: [(Hand, &str); 3] = [
    (Hand::Right, "Right"),
    (Hand::Auto, "Auto"),
    (Hand::Left, "Left"),
];

/// Draw the timeline of `doc` filling the available width.
pub fn show(ui: &mut egui::Ui, doc: &LoadedScore) {
    let score = &doc.score;
    let end_tick = score.beats.iter().map(|b| b.end_tick()).max().unwrap_or(0);
    let meter = score.meter_map();
    let last_bar = meter.position(end_tick).bar + 1;
    let total_ticks = meter.bar_start(last_bar).max(1) as f32;
    let lane_h = 56.0;
    let label_w = 56.0;
    let (rect, response) = ui.allocate_exact_size(
        Vec2::new(ui.available_width(), lane_h * LANES.len() as f32 + 20.0),
        Sense::hover(),
    );
    let painter = ui.painter_at(rect);
    painter.rect_filled(rect, 4.0, ui.visuals().extreme_bg_color);
    let x_of = |tick: f64| {
        rect.left() + label_w + (tick as f32 / total_ticks) * (rect.width() - label_w - 8.0)
    };
    let grid = ui.visuals().widgets.noninteractive.bg_stroke.color;
    for bar in 1..=last_bar {
        let start = meter.bar_start(bar);
        let sig = meter.signature_at(start);
        let x = x_of(start as f64);
        painter.line_segment(
            [Pos2::new(x, rect.top()), Pos2::new(x, rect.bottom())],
            Stroke::new(1.5, grid),
        );
        painter.text(
            Pos2::new(x + 3.0, rect.bottom() - 2.0),
            egui::Align2::LEFT_BOTTOM,
            bar.to_string(),
            egui::FontId::monospace(10.0),
            grid,
        );
        if bar < last_bar {
            for beat in 1..sig.numerator {
                let bx = x_of(
                    (start + u64::from(beat) * sig.beat_ticks(score.ticks_per_quarter)) as f64,
                );
                painter.line_segment(
                    [
                        Pos2::new(bx, rect.top()),
                        Pos2::new(bx, rect.bottom() - 14.0),
                    ],
                    Stroke::new(0.5, grid),
                );
            }
        }
    }
    let text_colour = ui.visuals().text_color();
    for (lane, (_, name)) in LANES.iter().enumerate() {
        let y = rect.top() + lane_h * (lane as f32 + 0.5);
        painter.text(
            Pos2::new(rect.left() + 6.0, y),
            egui::Align2::LEFT_CENTER,
            *name,
            egui::FontId::proportional(12.0),
            text_colour,
        );
    }
    let hover = response.hover_pos();
    for beat in &score.beats {
        let lane = LANES.iter().position(|(h, _)| *h == beat.hand).unwrap_or(1);
        let centre = Pos2::new(
            x_of(beat.tick as f64),
            rect.top() + lane_h * (lane as f32 + 0.5),
        );
        let radius = 4.0 + 10.0 * beat.dynamic.velocity() as f32;
        let colour = mode_colour(beat.mode);
        if let Some(roll) = beat.roll {
            let end = x_of((beat.tick + roll.length_ticks) as f64);
            painter.rect_filled(
                Rect::from_min_max(centre - Vec2::new(0.0, 3.0), Pos2::new(end, centre.y + 3.0)),
                2.0,
                colour.gamma_multiply(0.6),
            );
        }
        painter.add(beat_shape(beat.mode, centre, radius, colour));
        painter.text(
            centre + Vec2::new(0.0, radius + 7.0),
            egui::Align2::CENTER_CENTER,
            beat.drum.to_string(),
            egui::FontId::monospace(9.0),
            text_colour,
        );
        if hover.is_some_and(|p| p.distance(centre) <= radius + 2.0) {
            let drum = &doc.kit.drums[beat.drum];
            response.clone().on_hover_text(format!(
                "{}\n{} {}, {} on the {} ({}), {}",
                meter.position(beat.tick),
                beat.dynamic.nearest_mark(),
                beat.mode.name(),
                format!("{:?}", beat.hand).to_lowercase(),
                drum.name,
                beat.sounding_pitch(&doc.kit),
                beat.location.name()
            ));
        }
    }
}

/// Legato circle, tenuto square, accent triangle, vertical accent inverted triangle,
/// staccato diamond.
fn beat_shape(mode: PlayingMode, c: Pos2, r: f32, fill: Color32) -> Shape {
    let stroke = Stroke::new(1.0, Color32::BLACK);
    let poly = |pts: Vec<Pos2>| Shape::convex_polygon(pts, fill, stroke);
    match mode {
        PlayingMode::Legato => Shape::circle_filled(c, r, fill),
        PlayingMode::Tenuto => {
            Shape::rect_filled(Rect::from_center_size(c, Vec2::splat(1.7 * r)), 2.0, fill)
        }
        PlayingMode::Accent => poly(vec![
            c + Vec2::new(-r, r),
            c + Vec2::new(r, r),
            c + Vec2::new(0.0, -r),
        ]),
        PlayingMode::VerticalAccent => poly(vec![
            c + Vec2::new(-r, -r),
            c + Vec2::new(0.0, r),
            c + Vec2::new(r, -r),
        ]),
        PlayingMode::Staccato => poly(vec![
            c + Vec2::new(0.0, -r),
            c + Vec2::new(r, 0.0),
            c + Vec2::new(0.0, r),
            c + Vec2::new(-r, 0.0),
        ]),
    }
}
