//! The plot area under the timeline, one tab at a time: the composed tips;
//! then, from the rendering, target against simulated tips, contact force per strike, the
//! output waveform with the spectrum of one strike, and the simulated joint angles. Every
//! time axis follows the timeline's visible window, shows the playhead and seeks on a
//! click ([`linked`]); each tab builds its points once per composition or rendering and
//! hands egui_plot at most [`linked::MAX_POINTS`] per line ([`decimate`]).

mod composed;
pub mod decimate;
mod force;
mod joints;
pub mod linked;
mod sound;
mod tips;

use super::viewport::{SIMULATED_COLOURS, TARGET_COLOURS};
use crate::motion::compose::Composition;
use crate::render::Rendering;
use eframe::egui;
use egui_plot::PlotTransform;
use glam::DVec3;
use linked::{Outcome, Shown, TimeLink};
use std::collections::BTreeSet;

/// Hand names in plot legends, [left, right].
const HAND_NAMES: [&str; 2] = ["Left", "Right"];

/// A coordinate of the stick tips plotted against time.
struct TipAxis {
    value: fn(&DVec3) -> f64,
    label: &'static str,
    composed_id: &'static str,
    simulated_id: &'static str,
}

/// Height (z) and forward depth (y) of a tip, m (performer frame).
const AXES: [TipAxis; 2] = [
    TipAxis {
        value: |p| p.z,
        label: "tip height (m)",
        composed_id: "tip-height",
        simulated_id: "sim-tip-height",
    },
    TipAxis {
        value: |p| p.y,
        label: "tip forward (m)",
        composed_id: "tip-depth",
        simulated_id: "sim-tip-depth",
    },
];

/// The tabs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Tab {
    /// Composed tips (needs only a composition).
    #[default]
    Composed,
    /// Target against simulated tips.
    Tips,
    /// Contact force per strike.
    Force,
    /// Waveform and the spectrum of one strike.
    Sound,
    /// Joint angles of the simulated body.
    Joints,
}

impl Tab {
    /// Every tab with its title, in order.
    pub const ALL: [(Tab, &'static str); 5] = [
        (Tab::Composed, "Composed tips"),
        (Tab::Tips, "Simulated tips"),
        (Tab::Force, "Contact force"),
        (Tab::Sound, "Sound"),
        (Tab::Joints, "Joint angles"),
    ];
}

/// What the plots show this frame.
pub struct PlotInput<'a> {
    /// The latest composition and its generation, or why there is none.
    pub composition: Result<Option<(&'a Composition, u64)>, &'a str>,
    /// The rendering shown and its identity (a counter of renderings received).
    pub rendering: Option<(&'a Rendering, u64)>,
    /// Whether `rendering` is of the score as it is now.
    pub rendering_current: bool,
    /// Whether a render is running.
    pub rendering_busy: bool,
    /// Why there is no (current) rendering, when there is none.
    pub rendering_note: Option<&'a str>,
    pub link: TimeLink,
    /// Selected beats (the sound tab analyses the first selected beat's strike).
    pub selected_beats: &'a BTreeSet<usize>,
}

/// The plot area's state: the open tab and each tab's cached points.
#[derive(Default)]
pub struct Plots {
    pub tab: Tab,
    composed: composed::ComposedPlot,
    tips: tips::TipsPlot,
    force: force::ForcePlot,
    sound: sound::SoundPlot,
    joints: joints::JointsPlot,
    /// Last frame's mapping of the open tab's first time plot.
    transform: Option<PlotTransform>,
}

impl Plots {
    /// Screen position of time `t_s` half-way up the open tab's first time plot, as drawn
    /// last frame.
    pub fn screen_of(&self, t_s: f64) -> Option<egui::Pos2> {
        let t = self.transform.as_ref()?;
        Some(egui::pos2(
            t.position_from_point_x(t_s),
            t.frame().center().y,
        ))
    }

    /// The time window (s) of the open tab's first time plot, as drawn last frame.
    pub fn time_window(&self) -> Option<(f64, f64)> {
        let b = self.transform.as_ref()?.bounds();
        Some((b.min()[0], b.max()[0]))
    }

    /// Draw the tab bar and the open tab; returns a time to seek to when a plot was clicked.
    pub fn show(&mut self, ui: &mut egui::Ui, input: &PlotInput) -> Option<f64> {
        ui.horizontal(|ui| {
            for (tab, title) in Tab::ALL {
                ui.selectable_value(&mut self.tab, tab, title);
            }
            if self.tab != Tab::Composed && input.rendering.is_some() && !input.rendering_current {
                ui.separator();
                ui.weak(match input.rendering_note {
                    Some(n) => format!("showing the previous rendering ({n})"),
                    None => "showing the previous rendering".to_string(),
                });
            }
        });
        self.transform = None;
        let link = input.link;
        let outcome = match (self.tab, input.rendering) {
            (Tab::Composed, _) => match input.composition {
                Err(e) => message(ui, false, &format!("Composed stick tips unavailable: {e}")),
                Ok(None) => message(ui, true, "Composing stick-tip trajectories..."),
                Ok(Some((c, generation))) => self.composed.show(ui, c, generation, link),
            },
            (_, None) => {
                let busy = input.rendering_busy;
                let why = match input.rendering_note {
                    Some(n) => format!("No rendering to plot: {n}"),
                    None => "No rendering to plot yet.".to_string(),
                };
                message(ui, busy, &why)
            }
            (Tab::Tips, Some((r, id))) => self.tips.show(ui, r, id, link),
            (Tab::Force, Some((r, id))) => self.force.show(ui, r, id, link),
            (Tab::Sound, Some((r, id))) => self.sound.show(ui, r, id, link, input.selected_beats),
            (Tab::Joints, Some((r, id))) => self.joints.show(ui, r, id, link),
        };
        self.transform = outcome.transform;
        outcome.seek
    }
}

/// A line of text in place of the plots (with a spinner while work is under way).
fn message(ui: &mut egui::Ui, busy: bool, text: &str) -> Outcome {
    ui.horizontal(|ui| {
        if busy {
            ui.spinner();
        }
        ui.label(text);
    });
    Outcome::default()
}

/// Two plots side by side filling the space left; `plot(ui, column, height)` draws one.
fn two_columns(
    ui: &mut egui::Ui,
    mut plot: impl FnMut(&mut egui::Ui, usize, f32) -> Shown,
) -> Outcome {
    let height = ui.available_height().max(100.0);
    let mut outcome = Outcome::default();
    ui.columns(2, |cols| {
        for (a, col) in cols.iter_mut().enumerate() {
            outcome.add(plot(col, a, height));
        }
    });
    outcome
}
