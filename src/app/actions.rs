//! Carrying out what the panels and the keyboard asked this frame: the queued
//! [`Command`]s are drained once, score changes go through the document's history, and a
//! changed score is sent to the pipeline once, however many edits the frame made.

use super::command::Command;
use super::keys::Action;
use super::selection::Selection;
use super::{AfterConfirm, EditorApp};
use crate::mocap::db::side_index;
use glam::DVec3;

impl EditorApp {
    /// Apply the queued commands (once per frame).
    pub(super) fn drain(&mut self) {
        let mut edited = false;
        for cmd in std::mem::take(&mut self.pending) {
            match cmd {
                Command::Gesture => {
                    if let Some(d) = &mut self.doc {
                        d.begin_gesture();
                    }
                }
                Command::Edit(e) => {
                    if let Some(d) = &mut self.doc {
                        d.apply(e);
                        edited = true;
                    }
                }
                Command::Select(s) => {
                    if let Some(d) = &mut self.doc {
                        d.selection = s;
                    }
                }
                Command::Do(a) => edited |= self.act(a),
                Command::Seek(t) => self.transport.seek(t),
                Command::SetLoop(r) => self.transport.set_loop(r),
            }
        }
        if edited {
            if let Some(d) = &mut self.doc {
                d.clamp_selection();
            }
            self.recompose();
        }
    }

    /// Do `action`; true if the score changed.
    fn act(&mut self, action: Action) -> bool {
        match action {
            Action::PlayPause => {
                if let Some(status) = self.transport.play_pause() {
                    self.messages.status = status;
                }
            }
            Action::New => self.after_confirm(AfterConfirm::New),
            Action::Open => self.after_confirm(AfterConfirm::OpenDialog),
            Action::Save => {
                self.save(false);
            }
            Action::SaveAs => {
                self.save(true);
            }
            Action::ToggleHelp => self.views.show_help = !self.views.show_help,
            Action::CameraView(view) => {
                let now = self.now();
                self.views.viewport.go_to(view, now);
            }
            Action::FollowHand => {
                let now = self.now();
                self.views.viewport.follow_hand(now);
            }
            Action::FrameSelection => self.frame_selection(),
            Action::Speed(steps) => {
                let speed = self.transport.change_speed(steps);
                self.messages.status = format!("playback speed {}", speed_label(speed));
            }
            Action::StepFrames(frames) => self.transport.step_frames(frames),
            Action::StepContact(forward) => {
                let times = self
                    .pipeline
                    .composition()
                    .map(|c| c.strokes.iter().map(|s| s.time_s).collect::<Vec<_>>())
                    .unwrap_or_default();
                if !self.transport.step_to_contact(times, forward) {
                    self.messages.status =
                        format!("no contact {}", if forward { "after" } else { "before" });
                }
            }
            Action::TogglePreferences => self.settings.window_open = !self.settings.window_open,
            Action::ClearSelection => {
                if let Some(d) = &mut self.doc {
                    d.selection = Selection::default();
                }
                self.views.show_help = false;
            }
            edit => return self.edit(edit),
        }
        false
    }

    /// The window's clock (egui time), s; 0 before the first frame.
    fn now(&self) -> f64 {
        self.ctx.as_ref().map_or(0.0, |c| c.input(|i| i.time))
    }

    /// Move the camera so the selected beats' composed impact points fill the 3D view,
    /// or the whole kit (each head's centre and rim) when no beat is selected.
    fn frame_selection(&mut self) {
        let Some(doc) = &self.doc else { return };
        let selected = &doc.selection.beats;
        let mut points: Vec<DVec3> = (self.pipeline.composition())
            .map(|c| {
                c.strokes
                    .iter()
                    .zip(&c.impact_samples)
                    .filter(|(s, _)| selected.contains(&s.beat))
                    .map(|(s, &k)| c.tips[side_index(s.hand)][k])
                    .collect()
            })
            .unwrap_or_default();
        if points.is_empty() {
            let kit = doc.loaded.score.settings.kit(&doc.loaded.kit);
            for drum in &kit.drums {
                let (c, r) = (drum.centre(), 0.5 * drum.diameter_m);
                points.extend([c, c + DVec3::X * r, c - DVec3::X * r]);
                points.extend([c + DVec3::Y * r, c - DVec3::Y * r]);
            }
        }
        let viewport = &mut self.views.viewport;
        let aspect = viewport.size().map_or(1.5, |s| s.x / s.y.max(1.0));
        if let Some(to) = viewport.camera.framing(&points, aspect) {
            let now = self.now();
            self.views.viewport.move_to(to, now);
        }
    }

    /// Do an editing action on the document; true if the score changed.
    fn edit(&mut self, action: Action) -> bool {
        let Some(doc) = &mut self.doc else {
            return false;
        };
        let grid = self.views.timeline.grid_ticks(&doc.loaded);
        let outcome = doc.act(action, grid, self.transport.playhead_s, &mut self.clipboard);
        if let Some(status) = outcome.status {
            self.messages.status = status;
        }
        outcome.changed
    }
}

/// A playback speed as the transport bar shows it: "1×", "1/2×", "1/10×".
pub(super) fn speed_label(speed: f64) -> String {
    if speed >= 1.0 {
        "1×".into()
    } else {
        format!("1/{}×", (1.0 / speed).round())
    }
}
