//! The composed stick-tip trajectories in the editor: height of both tips against time,
//! impacts marked, the playhead as a vertical line (egui_plot). The plot points are built
//! once per composition, not per frame.

use crate::kit::Side;
use crate::motion::compose::Composition;
use eframe::egui::{self, Color32};
use egui_plot::{Legend, Line, Plot, PlotPoint, Points, VLine};

/// Colour of each hand, as in the exported figures.
pub const HAND_COLOURS: [Color32; 2] = super::viewport::TARGET_COLOURS;

/// Plot points of one composition.
#[derive(Default)]
pub struct TipsPlot {
    generation: Option<u64>,
    heights: [Vec<PlotPoint>; 2],
    impacts: [Vec<PlotPoint>; 2],
}

impl TipsPlot {
    /// Draw tip height against time for both hands, with the playhead at `time_s`.
    pub fn show(&mut self, ui: &mut egui::Ui, comp: &Composition, generation: u64, time_s: f64) {
        if self.generation != Some(generation) {
            self.generation = Some(generation);
            for (h, side) in [Side::Left, Side::Right].into_iter().enumerate() {
                self.heights[h] = comp
                    .tip(side)
                    .iter()
                    .enumerate()
                    .step_by(2)
                    .map(|(k, p)| PlotPoint::new(comp.time(k), p.z))
                    .collect();
                self.impacts[h] = comp
                    .strokes
                    .iter()
                    .zip(&comp.impact_samples)
                    .filter(|(s, _)| s.hand == side)
                    .map(|(_, &k)| PlotPoint::new(comp.time(k), comp.tip(side)[k].z))
                    .collect();
            }
        }
        Plot::new("tip-height")
            .height(ui.available_height().max(100.0))
            .legend(Legend::default())
            .x_axis_label("time (s)")
            .y_axis_label("tip height (m)")
            .show(ui, |plot| {
                for (h, side) in [Side::Left, Side::Right].into_iter().enumerate() {
                    plot.line(
                        Line::new(format!("{side:?} tip"), &self.heights[h][..])
                            .color(HAND_COLOURS[h])
                            .width(1.5),
                    );
                    plot.points(
                        Points::new(format!("{side:?} impacts"), &self.impacts[h][..])
                            .color(HAND_COLOURS[h])
                            .radius(3.0),
                    );
                }
                plot.vline(VLine::new("playhead", time_s).color(Color32::from_rgb(250, 80, 80)));
            });
    }
}
