//! The composed stick-tip trajectories in the editor: height of both tips against time,
//! impacts marked (egui_plot).

use crate::kit::Side;
use crate::motion::compose::Composition;
use eframe::egui::{self, Color32};
use egui_plot::{Legend, Line, Plot, Points};

/// Colour of each hand, as in the exported figures.
pub const HAND_COLOURS: [Color32; 2] = [
    Color32::from_rgb(31, 119, 180),
    Color32::from_rgb(230, 120, 20),
];

/// Draw tip height against time for both hands.
pub fn show(ui: &mut egui::Ui, comp: &Composition) {
    Plot::new("tip-height")
        .height(ui.available_height().clamp(160.0, 360.0))
        .legend(Legend::default())
        .x_axis_label("time (s)")
        .y_axis_label("tip height (m)")
        .show(ui, |plot| {
            for (h, side) in [Side::Left, Side::Right].into_iter().enumerate() {
                let points: Vec<[f64; 2]> = comp
                    .tip(side)
                    .iter()
                    .enumerate()
                    .step_by(2)
                    .map(|(k, p)| [comp.time(k), p.z])
                    .collect();
                plot.line(
                    Line::new(format!("{side:?} tip"), points)
                        .color(HAND_COLOURS[h])
                        .width(1.5),
                );
                let impacts: Vec<[f64; 2]> = comp
                    .strokes
                    .iter()
                    .zip(&comp.impact_samples)
                    .filter(|(s, _)| s.hand == side)
                    .map(|(_, &k)| [comp.time(k), comp.tip(side)[k].z])
                    .collect();
                plot.points(
                    Points::new(format!("{side:?} impacts"), impacts)
                        .color(HAND_COLOURS[h])
                        .radius(3.0),
                );
            }
        });
}
