//! The composed stick tips against time: height (z) and forward depth (y) of both tips
//! side by side, m, impacts marked. Available as soon as a composition is, before any
//! rendering. Points are rebuilt once per composition.

use super::linked::{Outcome, Series, TimeLink, time_plot};
use super::{AXES, HAND_NAMES, TARGET_COLOURS, two_columns};
use crate::kit::Side;
use crate::motion::compose::Composition;
use eframe::egui;
use egui_plot::{Line, PlotPoint, Points};

/// Plot points of one composition: [height, depth] × [left, right].
#[derive(Default)]
pub struct ComposedPlot {
    generation: Option<u64>,
    lines: [[Series; 2]; 2],
    impacts: [[Vec<PlotPoint>; 2]; 2],
}

impl ComposedPlot {
    fn rebuild(&mut self, comp: &Composition) {
        for (a, axis) in AXES.iter().enumerate() {
            for (h, side) in [Side::Left, Side::Right].into_iter().enumerate() {
                let tip = comp.tip(side);
                self.lines[a][h] = Series::new(
                    tip.iter()
                        .enumerate()
                        .map(|(k, p)| [comp.time(k), (axis.value)(p)])
                        .collect(),
                );
                self.impacts[a][h] = comp
                    .strokes
                    .iter()
                    .zip(&comp.impact_samples)
                    .filter(|(s, _)| s.hand == side)
                    .map(|(_, &k)| PlotPoint::new(comp.time(k), (axis.value)(&tip[k])))
                    .collect();
            }
        }
    }

    /// Both plots of `comp` (identified by `generation`).
    pub fn show(
        &mut self,
        ui: &mut egui::Ui,
        comp: &Composition,
        generation: u64,
        link: TimeLink,
    ) -> Outcome {
        if self.generation != Some(generation) {
            self.generation = Some(generation);
            self.rebuild(comp);
        }
        two_columns(ui, |ui, a, height| {
            let [left, right] = &mut self.lines[a];
            let lines = [left.view(link.window), right.view(link.window)];
            let impacts = &self.impacts[a];
            let axis = &AXES[a];
            time_plot(
                ui,
                axis.composed_id,
                axis.label,
                height,
                link,
                move |plot| {
                    for h in 0..2 {
                        plot.line(
                            Line::new(format!("{} tip", HAND_NAMES[h]), lines[h])
                                .color(TARGET_COLOURS[h])
                                .width(1.5),
                        );
                        plot.points(
                            Points::new(format!("{} impacts", HAND_NAMES[h]), &impacts[h][..])
                                .color(TARGET_COLOURS[h])
                                .radius(3.0),
                        );
                    }
                },
            )
        })
    }
}
