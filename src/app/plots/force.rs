//! Contact force per strike: every contact of a rendering as a stem at its first touch up
//! to its peak force (N), coloured by hand (the simulated sticks' colours), and the
//! force–time curve each stick put on the heads (the drums' recorded excitation, one
//! point per 0.1 ms simulation step in contact, back to zero between contacts) — the
//! stems read at the score's scale, the curves once the timeline is zoomed to a stroke.
//! Neither line lets egui_plot merge dense points into a band: between sparse pulses the
//! band would fill the gap from one peak to the next.

use super::linked::{Outcome, Series, TimeLink, time_plot};
use super::{HAND_NAMES, SIMULATED_COLOURS};
use crate::drum::Excitation;
use crate::kit::Side;
use crate::render::Rendering;
use crate::render::strikes::StrikeEvent;
use eframe::egui;
use egui_plot::{Line, PlotPoint, Points};

const SIDES: [Side; 2] = [Side::Left, Side::Right];

/// Plot points of one rendering, per hand [left, right].
#[derive(Default)]
pub struct ForcePlot {
    rendering: Option<u64>,
    stems: [Series; 2],
    peaks: [Vec<PlotPoint>; 2],
    curves: [Series; 2],
}

/// One hand's stems: (t, 0) → (t, F) → (t, 0) per contact, s and N.
pub fn stems(events: &[StrikeEvent], hand: &str) -> Vec<[f64; 2]> {
    events
        .iter()
        .filter(|e| e.hand == hand)
        .flat_map(|e| {
            [
                [e.contact_s, 0.0],
                [e.contact_s, e.peak_force_n],
                [e.contact_s, 0.0],
            ]
        })
        .collect()
}

/// One side's force against time, N: each step's force at its start time, with a zero a
/// step before and after every run of consecutive steps (so contacts are separate pulses).
pub fn force_curve(excitation: &[Excitation], side: Side, dt_s: f64) -> Vec<[f64; 2]> {
    let mut out: Vec<[f64; 2]> = Vec::new();
    let mut last: Option<u64> = None;
    for e in excitation.iter().filter(|e| e.side == side) {
        if last.is_none_or(|s| e.step > s + 1) {
            // Two steps apart the zeros after one run and before the next meet; rounding
            // of the step times must not put them out of order.
            let mut lead = e.time_s - dt_s;
            if let Some(&[t, _]) = out.last() {
                let trail = t + dt_s;
                lead = lead.max(trail);
                out.push([trail, 0.0]);
            }
            out.push([lead, 0.0]);
        }
        out.push([e.time_s, e.force_n]);
        last = Some(e.step);
    }
    if let Some(&[t, _]) = out.last() {
        out.push([t + dt_s, 0.0]);
    }
    out
}

impl ForcePlot {
    fn rebuild(&mut self, r: &Rendering) {
        for (h, side) in SIDES.into_iter().enumerate() {
            let hand = HAND_NAMES[h].to_ascii_lowercase();
            let stems = stems(&r.events, &hand);
            self.peaks[h] = stems
                .iter()
                .skip(1)
                .step_by(3)
                .map(|&[t, f]| PlotPoint::new(t, f))
                .collect();
            self.stems[h] = Series::new(stems);
            self.curves[h] = Series::new(force_curve(r.drums.excitation(), side, r.drums.dt_s()));
        }
    }

    /// The plot of rendering `r` (identified by `id`).
    pub fn show(&mut self, ui: &mut egui::Ui, r: &Rendering, id: u64, link: TimeLink) -> Outcome {
        if self.rendering != Some(id) {
            self.rendering = Some(id);
            self.rebuild(r);
        }
        let height = ui.available_height().max(100.0);
        let [ls, rs] = &mut self.stems;
        let stems = [ls.view(link.window), rs.view(link.window)];
        let [lc, rc] = &mut self.curves;
        let curves = [lc.view(link.window), rc.view(link.window)];
        let peaks = &self.peaks;
        let mut outcome = Outcome::default();
        outcome.add(time_plot(
            ui,
            "contact-force",
            "contact force (N)",
            height,
            link,
            move |plot| {
                for h in 0..2 {
                    let colour = SIMULATED_COLOURS[h];
                    plot.line(
                        Line::new(format!("{} force", HAND_NAMES[h]), curves[h])
                            .color(colour.gamma_multiply(0.6))
                            .width(1.0)
                            .allow_band(false),
                    );
                    plot.line(
                        Line::new(format!("{} peaks", HAND_NAMES[h]), stems[h])
                            .color(colour)
                            .width(1.5)
                            .allow_band(false),
                    );
                    plot.points(
                        Points::new(format!("{} peaks", HAND_NAMES[h]), &peaks[h][..])
                            .color(colour)
                            .radius(3.0),
                    );
                }
            },
        ));
        outcome
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec2;

    /// Stems rise to each contact's peak at its time; the force curve is zero between
    /// contacts and follows each step's force within one.
    #[test]
    fn stems_and_curve() {
        let event = |hand: &'static str, t: f64, f: f64| StrikeEvent {
            beat: None,
            hand,
            drum: 0,
            scheduled_s: None,
            contact_s: t,
            duration_ms: 4.0,
            peak_force_n: f,
            impact_speed_mps: 3.0,
            x_m: 0.0,
            y_m: 0.5,
            recontacts: 0,
            mode: None,
            dynamic: None,
        };
        let events = [
            event("left", 1.0, 50.0),
            event("right", 1.2, 70.0),
            event("left", 2.0, 30.0),
        ];
        assert_eq!(
            stems(&events, "left"),
            vec![
                [1.0, 0.0],
                [1.0, 50.0],
                [1.0, 0.0],
                [2.0, 0.0],
                [2.0, 30.0],
                [2.0, 0.0]
            ]
        );
        let dt = 1e-4;
        let step = |step: u64, side: Side, f: f64| Excitation {
            step,
            time_s: step as f64 * dt,
            drum: 1,
            side,
            point: DVec2::ZERO,
            force_n: f,
        };
        let exc = [
            step(10, Side::Left, 5.0),
            step(11, Side::Left, 9.0),
            step(11, Side::Right, 40.0),
            step(12, Side::Left, 4.0),
            step(50, Side::Left, 7.0),
        ];
        let curve = force_curve(&exc, Side::Left, dt);
        let want = [
            [9.0, 0.0],
            [10.0, 5.0],
            [11.0, 9.0],
            [12.0, 4.0],
            [13.0, 0.0],
            [49.0, 0.0],
            [50.0, 7.0],
            [51.0, 0.0],
        ];
        assert_eq!(curve.len(), want.len());
        for (c, w) in curve.iter().zip(want) {
            assert!(
                (c[0] - w[0] * dt).abs() < 1e-12 && c[1] == w[1],
                "{c:?} vs {w:?}"
            );
        }
        assert!(force_curve(&[], Side::Right, dt).is_empty());
        // Regression (seen on the 60-second score of tests/app_timing.rs): runs two steps
        // apart whose step times are rounded closer than two steps still give a curve in
        // time order.
        let close = [
            step(10, Side::Left, 1.0),
            Excitation {
                time_s: 10.0 * dt + 2.0 * dt - 1e-15,
                ..step(12, Side::Left, 2.0)
            },
        ];
        let curve = force_curve(&close, Side::Left, dt);
        assert_eq!(curve.len(), 6);
        assert!(curve.windows(2).all(|w| w[0][0] <= w[1][0]));
    }
}
