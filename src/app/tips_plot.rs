//! The composed stick tips against time (egui_plot): height and forward depth of both
//! tips side by side, impacts marked, the playhead as a vertical line. The time axis
//! follows the timeline's visible window (linked time axes), and a click seeks. Plot
//! points are built once per composition, not per frame.

use crate::kit::Side;
use crate::motion::compose::Composition;
use eframe::egui::{self, Color32};
use egui_plot::{Legend, Line, Plot, PlotPoint, Points, VLine};

/// Colour of each hand, as in the 3D view.
pub const HAND_COLOURS: [Color32; 2] = super::viewport::TARGET_COLOURS;

/// One plotted coordinate of the tips.
#[derive(Clone, Copy)]
enum Axis {
    Height,
    Depth,
}

/// Plot points of one composition: [height, depth] × [left, right].
#[derive(Default)]
pub struct TipsPlot {
    generation: Option<u64>,
    lines: [[Vec<PlotPoint>; 2]; 2],
    impacts: [[Vec<PlotPoint>; 2]; 2],
}

impl TipsPlot {
    fn rebuild(&mut self, comp: &Composition) {
        for (a, axis) in [Axis::Height, Axis::Depth].into_iter().enumerate() {
            let value = |p: &glam::DVec3| match axis {
                Axis::Height => p.z,
                Axis::Depth => p.y,
            };
            for (h, side) in [Side::Left, Side::Right].into_iter().enumerate() {
                self.lines[a][h] = comp
                    .tip(side)
                    .iter()
                    .enumerate()
                    .step_by(2)
                    .map(|(k, p)| PlotPoint::new(comp.time(k), value(p)))
                    .collect();
                self.impacts[a][h] = comp
                    .strokes
                    .iter()
                    .zip(&comp.impact_samples)
                    .filter(|(s, _)| s.hand == side)
                    .map(|(_, &k)| PlotPoint::new(comp.time(k), value(&comp.tip(side)[k])))
                    .collect();
            }
        }
    }

    /// Draw both plots with the playhead at `time_s` over the time `window` (s); returns
    /// a time to seek to when a plot was clicked.
    pub fn show(
        &mut self,
        ui: &mut egui::Ui,
        comp: &Composition,
        generation: u64,
        time_s: f64,
        window: Option<(f64, f64)>,
    ) -> Option<f64> {
        if self.generation != Some(generation) {
            self.generation = Some(generation);
            self.rebuild(comp);
        }
        let mut seek = None;
        let height = ui.available_height().max(100.0);
        ui.columns(2, |cols| {
            for (a, (id, label)) in [
                ("tip-height", "tip height (m)"),
                ("tip-depth", "tip forward (m)"),
            ]
            .into_iter()
            .enumerate()
            {
                let lines = &self.lines[a];
                let impacts = &self.impacts[a];
                let clicked = Plot::new(id)
                    .height(height)
                    .legend(Legend::default())
                    .x_axis_label("time (s)")
                    .y_axis_label(label)
                    .allow_drag(false)
                    .allow_zoom(false)
                    .allow_scroll(false)
                    .show(&mut cols[a], |plot| {
                        if let Some((t0, t1)) = window {
                            plot.set_plot_bounds_x(t0..=t1);
                            plot.set_auto_bounds([false, true]);
                        }
                        for (h, side) in [Side::Left, Side::Right].into_iter().enumerate() {
                            plot.line(
                                Line::new(format!("{side:?} tip"), &lines[h][..])
                                    .color(HAND_COLOURS[h])
                                    .width(1.5),
                            );
                            plot.points(
                                Points::new(format!("{side:?} impacts"), &impacts[h][..])
                                    .color(HAND_COLOURS[h])
                                    .radius(3.0),
                            );
                        }
                        plot.vline(
                            VLine::new("playhead", time_s).color(Color32::from_rgb(250, 80, 80)),
                        );
                        (plot.response().clicked())
                            .then(|| plot.pointer_coordinate())
                            .flatten()
                            .map(|p| p.x)
                    })
                    .inner;
                seek = seek.or(clicked);
            }
        });
        seek
    }
}
