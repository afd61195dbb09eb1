//! Joint angles of the simulated body against time: each joint's rotation away from the
//! rest pose as one angle, θ = 2·acos|w| of q_rest⁻¹·q (degrees, 0 at rest, whatever the
//! axis), for the joints ticked above the plot (elbows and wrists at first; left arm in
//! blues, right arm in oranges like the hands). Rebuilt once per rendering.

use super::linked::{Outcome, Series, TimeLink, time_plot};
use crate::body::skeleton::{JOINT_COUNT, Joint, REST};
use crate::render::Rendering;
use eframe::egui::{self, Color32};
use egui_plot::Line;
use glam::DQuat;

/// Colour of each joint, in [`Joint::ALL`] order.
const COLOURS: [Color32; JOINT_COUNT] = [
    Color32::from_rgb(170, 170, 170), // trunk
    Color32::from_rgb(130, 200, 130), // neck
    Color32::from_rgb(200, 130, 200), // head
    Color32::from_rgb(90, 120, 250),  // shoulder_l
    Color32::from_rgb(60, 170, 240),  // elbow_l
    Color32::from_rgb(120, 230, 230), // wrist_l
    Color32::from_rgb(170, 200, 255), // grip_l
    Color32::from_rgb(230, 100, 60),  // shoulder_r
    Color32::from_rgb(240, 150, 40),  // elbow_r
    Color32::from_rgb(250, 220, 90),  // wrist_r
    Color32::from_rgb(255, 200, 170), // grip_r
];

/// The rotation angle of `q` away from `rest`, degrees in [0, 180].
pub fn angle_deg(rest: DQuat, q: DQuat) -> f64 {
    let d = (rest.inverse() * q).normalize();
    (2.0 * d.w.abs().min(1.0).acos()).to_degrees()
}

/// Plot points of one rendering per joint, and which joints are shown.
pub struct JointsPlot {
    rendering: Option<u64>,
    lines: [Series; JOINT_COUNT],
    shown: [bool; JOINT_COUNT],
}

impl Default for JointsPlot {
    fn default() -> Self {
        let shown = Joint::ALL.map(|j| {
            matches!(
                j,
                Joint::ElbowL | Joint::WristL | Joint::ElbowR | Joint::WristR
            )
        });
        JointsPlot {
            rendering: None,
            lines: Default::default(),
            shown,
        }
    }
}

impl JointsPlot {
    fn rebuild(&mut self, r: &Rendering) {
        let time = |k: usize| r.start_s + k as f64 / r.motion.rate_hz;
        for (j, line) in self.lines.iter_mut().enumerate() {
            *line = Series::new(
                r.motion
                    .poses
                    .iter()
                    .enumerate()
                    .map(|(k, pose)| [time(k), angle_deg(REST[j], pose[j])])
                    .collect(),
            );
        }
    }

    /// The joint choice and the plot of rendering `r` (identified by `id`).
    pub fn show(&mut self, ui: &mut egui::Ui, r: &Rendering, id: u64, link: TimeLink) -> Outcome {
        if self.rendering != Some(id) {
            self.rendering = Some(id);
            self.rebuild(r);
        }
        ui.horizontal_wrapped(|ui| {
            for (j, joint) in Joint::ALL.into_iter().enumerate() {
                ui.checkbox(&mut self.shown[j], joint.name());
            }
        });
        let height = ui.available_height().max(100.0);
        let lines: Vec<_> = self
            .lines
            .iter_mut()
            .zip(Joint::ALL.into_iter().zip(COLOURS))
            .zip(self.shown)
            .filter(|(_, shown)| *shown)
            .map(|((line, (joint, colour)), _)| (joint.name(), colour, line.view(link.window)))
            .collect();
        let mut outcome = Outcome::default();
        outcome.add(time_plot(
            ui,
            "joint-angles",
            "angle from rest (deg)",
            height,
            link,
            move |plot| {
                for (name, colour, points) in lines {
                    plot.line(Line::new(name, points).color(colour).width(1.5));
                }
            },
        ));
        outcome
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The angle is the rotation's magnitude about any axis, sign-free, 0 at rest.
    #[test]
    fn rotation_angles() {
        assert_eq!(angle_deg(DQuat::IDENTITY, DQuat::IDENTITY), 0.0);
        let q = DQuat::from_rotation_x(0.7);
        assert!((angle_deg(DQuat::IDENTITY, q) - 0.7f64.to_degrees()).abs() < 1e-9);
        let axis = glam::DVec3::new(1.0, -2.0, 0.5).normalize();
        let q = DQuat::from_axis_angle(axis, -1.2);
        assert!((angle_deg(DQuat::IDENTITY, q) - 1.2f64.to_degrees()).abs() < 1e-9);
        assert!((angle_deg(DQuat::IDENTITY, -q) - 1.2f64.to_degrees()).abs() < 1e-9);
        let rest = DQuat::from_rotation_z(0.3);
        assert!(
            (angle_deg(rest, rest * DQuat::from_rotation_y(0.5)) - 0.5f64.to_degrees()).abs()
                < 1e-9
        );
    }
}
