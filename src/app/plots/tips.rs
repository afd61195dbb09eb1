//! Target against simulated stick tips of a rendering: height (z) and forward depth (y),
//! m, both hands, the targets (what the body followed: the felt ball's centre with the
//! strike-through dip and the timing compensation's warp) in the 3D view's target colours,
//! wide, under the simulated tips in its simulated colours. Rebuilt once per rendering.

use super::linked::{Outcome, Series, TimeLink, time_plot};
use super::{AXES, HAND_NAMES, SIMULATED_COLOURS, TARGET_COLOURS, two_columns};
use crate::render::Rendering;
use eframe::egui;
use egui_plot::Line;

/// Plot points of one rendering: [height, depth] × [left, right] × [target, simulated].
#[derive(Default)]
pub struct TipsPlot {
    rendering: Option<u64>,
    lines: [[[Series; 2]; 2]; 2],
}

impl TipsPlot {
    fn rebuild(&mut self, r: &Rendering) {
        let time = |k: usize| r.start_s + k as f64 / r.motion.rate_hz;
        for (a, axis) in AXES.iter().enumerate() {
            for h in 0..2 {
                for (kind, tips) in [&r.reference.tips[h], &r.motion.tips[h]]
                    .into_iter()
                    .enumerate()
                {
                    self.lines[a][h][kind] = Series::new(
                        tips.iter()
                            .enumerate()
                            .map(|(k, p)| [time(k), (axis.value)(p)])
                            .collect(),
                    );
                }
            }
        }
    }

    /// Both plots of rendering `r` (identified by `id`).
    pub fn show(&mut self, ui: &mut egui::Ui, r: &Rendering, id: u64, link: TimeLink) -> Outcome {
        if self.rendering != Some(id) {
            self.rendering = Some(id);
            self.rebuild(r);
        }
        two_columns(ui, |ui, a, height| {
            let [[lt, ls], [rt, rs]] = &mut self.lines[a];
            let lines = [
                [lt.view(link.window), ls.view(link.window)],
                [rt.view(link.window), rs.view(link.window)],
            ];
            let axis = &AXES[a];
            time_plot(
                ui,
                axis.simulated_id,
                axis.label,
                height,
                link,
                move |plot| {
                    for (h, [target, simulated]) in lines.into_iter().enumerate() {
                        plot.line(
                            Line::new(format!("{} target", HAND_NAMES[h]), target)
                                .color(TARGET_COLOURS[h])
                                .width(2.5),
                        );
                        plot.line(
                            Line::new(format!("{} simulated", HAND_NAMES[h]), simulated)
                                .color(SIMULATED_COLOURS[h])
                                .width(1.0),
                        );
                    }
                },
            )
        })
    }
}
