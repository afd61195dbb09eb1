//! The window around the views: the menu bar and the transport bar, the status bar
//! (what the workers and the writing jobs are doing, the last render error with a way to
//! the beat it names), the "unsaved changes" question, and the central layout of the 3D
//! view, the timeline, the tempo lane and the plots.

use super::command::Command;
use super::dialogs::{Purpose, Request};
use super::session::ConfirmAnswer;
use super::{
    Action, AfterConfirm, Camera, EditorApp, Export, plots, tempo_lane, timeline, viewport,
};
use crate::body::skeleton::Pose;
use crate::scene::marks::Rgba;
use crate::scene::stage;
use eframe::egui;

impl EditorApp {
    pub(super) fn menu_bar(&mut self, ui: &mut egui::Ui) {
        let can_undo = self.doc.as_ref().is_some_and(|d| d.history.can_undo());
        let can_redo = self.doc.as_ref().is_some_and(|d| d.history.can_redo());
        let undo_text = self.doc.as_ref().and_then(|d| d.history.undo_text());
        let redo_text = self.doc.as_ref().and_then(|d| d.history.redo_text());
        egui::MenuBar::new().ui(ui, |ui| {
            ui.menu_button("File", |ui| {
                let mut item = |ui: &mut egui::Ui, label: &str, action: Action| {
                    if ui.button(label).clicked() {
                        self.pending.push(Command::Do(action));
                    }
                };
                item(ui, "New  (Ctrl+N)", Action::New);
                item(ui, "Open...  (Ctrl+O)", Action::Open);
                ui.menu_button("Open Recent", |ui| {
                    if self.recent.paths().is_empty() {
                        ui.label("(none yet)");
                    }
                    for p in self.recent.paths().to_vec() {
                        if ui.button(p.display().to_string()).clicked() {
                            self.after_confirm(AfterConfirm::Open(p));
                        }
                    }
                });
                ui.menu_button("Demo scores", |ui| {
                    for (name, _) in crate::score::demos::DEMOS {
                        if ui.button(*name).clicked() {
                            self.after_confirm(AfterConfirm::OpenDemo(name));
                        }
                    }
                });
                let imports: [(&str, (&str, &[&str])); 3] = [
                    ("Import MIDI...", ("MIDI", &["mid", "midi"])),
                    (
                        "Import MusicXML...",
                        ("MusicXML", &["musicxml", "xml", "mxl"]),
                    ),
                    (
                        "Import audio (transcribe)...",
                        (
                            "recording (WAV, AIFF, FLAC, MP3, Ogg)",
                            &crate::sound::recording::EXTENSIONS,
                        ),
                    ),
                ];
                for (label, filter) in imports {
                    if ui.button(label).clicked() {
                        self.ask_and_act(Request {
                            purpose: Purpose::Open,
                            title: label.trim_end_matches('.'),
                            filter,
                            save: false,
                            file_name: None,
                            folder: None,
                        });
                    }
                }
                ui.separator();
                let mut item = |ui: &mut egui::Ui, label: &str, action: Action| {
                    if ui.button(label).clicked() {
                        self.pending.push(Command::Do(action));
                    }
                };
                item(ui, "Save  (Ctrl+S)", Action::Save);
                item(ui, "Save As...  (Ctrl+Shift+S)", Action::SaveAs);
                ui.separator();
                let blocked = self.export_blocked();
                for what in Export::ALL {
                    let blocked = blocked.as_ref().filter(|_| what.needs_rendering());
                    let button =
                        ui.add_enabled(blocked.is_none(), egui::Button::new(what.menu_label()));
                    let button = match &blocked {
                        Some(why) => button.on_disabled_hover_text(format!("Unavailable: {why}")),
                        None => button,
                    };
                    if button.clicked() {
                        self.export_dialog(what);
                    }
                }
                ui.separator();
                if ui.button("Quit").clicked() {
                    ui.ctx().send_viewport_cmd(egui::ViewportCommand::Close);
                }
            });
            ui.menu_button("Edit", |ui| {
                let undo = format!("Undo {}  (Ctrl+Z)", undo_text.unwrap_or_default());
                if ui.add_enabled(can_undo, egui::Button::new(undo)).clicked() {
                    self.pending.push(Command::Do(Action::Undo));
                }
                let redo = format!("Redo {}  (Ctrl+Shift+Z)", redo_text.unwrap_or_default());
                if ui.add_enabled(can_redo, egui::Button::new(redo)).clicked() {
                    self.pending.push(Command::Do(Action::Redo));
                }
                ui.separator();
                for (label, action) in [
                    ("Copy  (Ctrl+C)", Action::Copy),
                    ("Paste at playhead  (Ctrl+V)", Action::Paste),
                    ("Duplicate  (Ctrl+D)", Action::Duplicate),
                    ("Delete  (Del)", Action::Delete),
                    ("Select all  (Ctrl+A)", Action::SelectAll),
                ] {
                    if ui.button(label).clicked() {
                        self.pending.push(Command::Do(action));
                    }
                }
                ui.separator();
                if ui.button("Preferences...  (Ctrl+,)").clicked() {
                    self.pending.push(Command::Do(Action::TogglePreferences));
                }
            });
            ui.menu_button("View", |ui| {
                if ui.button("Fit the score in the timeline").clicked() {
                    self.views.timeline.fit();
                }
                if ui.button("Reset the 3D camera").clicked() {
                    self.views.viewport.hold();
                    self.views.viewport.camera = Camera::default();
                }
                for shortcut in super::keys::SHORTCUTS {
                    if let Action::CameraView(view) = shortcut.action
                        && ui
                            .button(format!("Camera: {}  ({})", view.name(), shortcut.label))
                            .clicked()
                    {
                        self.pending.push(Command::Do(shortcut.action));
                    }
                }
                for (label, action) in [
                    (
                        "Camera: follow the hand that strikes next  (F9)",
                        Action::FollowHand,
                    ),
                    ("Frame the selection  (F)", Action::FrameSelection),
                ] {
                    if ui.button(label).clicked() {
                        self.pending.push(Command::Do(action));
                    }
                }
                ui.checkbox(&mut self.views.timeline.snap, "Snap to grid");
                ui.checkbox(
                    &mut self.views.overlay_target,
                    "Overlay the target pose (composed tips through the IK)",
                );
                ui.checkbox(
                    &mut self.views.overlay_previous,
                    "Overlay the previous rendering (before the last edit)",
                );
                ui.checkbox(&mut self.views.flat_view, "Flat 3D view (no lighting)")
                    .on_hover_text(
                        "Draw the stage as flat shapes instead of lit, depth-buffered solids \
                         (the flat view is also what shows when the GPU cannot draw)",
                    );
                let viewport = &mut self.views.viewport;
                let mut windowed = viewport.trajectory_window_s.is_some();
                if ui
                    .checkbox(&mut windowed, "Trajectories near the playhead only")
                    .changed()
                {
                    viewport.trajectory_window_s = windowed.then_some(2.0);
                }
                if let Some(w) = &mut viewport.trajectory_window_s {
                    ui.add(
                        egui::Slider::new(w, 0.25..=viewport::MAX_WINDOW_S).text("s either side"),
                    );
                }
                for colour in crate::scene::trail::TrailColour::ALL {
                    ui.radio_value(
                        &mut viewport.trail_colour,
                        colour,
                        format!("Trajectories coloured {}", colour.name()),
                    );
                }
            });
            ui.menu_button("Help", |ui| {
                if ui.button("Keyboard and mouse  (F1)").clicked() {
                    self.views.show_help = true;
                }
            });
        });
    }

    pub(super) fn transport_bar(&mut self, ui: &mut egui::Ui) {
        ui.horizontal(|ui| {
            let playing = self.transport.playback.is_playing();
            if ui.button(if playing { "Pause" } else { "Play" }).clicked() {
                self.pending.push(Command::Do(Action::PlayPause));
            }
            if ui.button("To start").clicked() {
                self.pending.push(Command::Seek(0.0));
            }
            let position = self.doc.as_ref().map(|d| {
                let s = &d.loaded.score;
                let tick = s.tempo_map().tick_at(self.transport.playhead_s).max(0.0) as u64;
                s.meter_map().position(tick).to_string()
            });
            ui.monospace(format!(
                "{:7.2} s  {}",
                self.transport.playhead_s,
                position.unwrap_or_default()
            ));
            ui.separator();
            let speed = self.transport.playback.speed();
            egui::ComboBox::from_label("Speed")
                .width(64.0)
                .selected_text(super::actions::speed_label(speed))
                .show_ui(ui, |ui| {
                    for s in super::playback::SPEEDS {
                        if ui
                            .selectable_label(s == speed, super::actions::speed_label(s))
                            .clicked()
                        {
                            self.transport.playback.set_speed(s);
                        }
                    }
                })
                .response
                .on_hover_text("[ slower, ] faster; below 1 the audio is muted");
            ui.separator();
            ui.add_enabled(
                self.transport.loop_ticks.is_some(),
                egui::Checkbox::new(&mut self.transport.looping, "Loop"),
            )
            .on_hover_text("Shift+drag on the ruler sets the loop region");
            ui.checkbox(&mut self.views.timeline.snap, "Snap");
            if ui.button("Zoom in").clicked() {
                self.views.timeline.zoom(0.7);
            }
            if ui.button("Zoom out").clicked() {
                self.views.timeline.zoom(1.4);
            }
            if ui.button("Fit").clicked() {
                self.views.timeline.fit();
            }
            ui.separator();
            if ui.button("Help (F1)").clicked() {
                self.views.show_help = !self.views.show_help;
            }
        });
    }

    pub(super) fn status_bar(&mut self, ui: &mut egui::Ui) {
        let mut show = None;
        ui.horizontal(|ui| {
            if let Some(n) = self.transport.playback.notice() {
                ui.colored_label(ui.visuals().warn_fg_color, n);
                ui.separator();
            }
            if !self.transport.playback.is_real_time() {
                ui.colored_label(
                    ui.visuals().warn_fg_color,
                    super::playback::SLOW_MOTION_NOTICE,
                );
                ui.separator();
            }
            if self.pipeline.is_composing() {
                ui.spinner();
                ui.label("composing");
                ui.separator();
            } else if let Some(d) = self.pipeline.last_compose_time() {
                ui.label(format!("composed in {:.0} ms", d.as_secs_f64() * 1e3));
                ui.separator();
            }
            if self.pipeline.is_rendering() {
                ui.spinner();
                ui.label("rendering sound and motion");
                ui.separator();
            }
            for label in self.jobs.labels() {
                ui.spinner();
                ui.label(label);
                ui.separator();
            }
            if self.quitting && self.jobs.is_busy() {
                ui.label("closing once the files are written");
                ui.separator();
            }
            if self.is_dirty() {
                ui.label("unsaved changes");
                ui.separator();
            }
            ui.label(&self.messages.status);
            // Last, cut to the width left (in full on hover), after its button.
            if let Some(e) = self
                .pipeline
                .render_error()
                .filter(|_| !self.pipeline.is_rendering())
            {
                ui.separator();
                if let Some(b) = e.beat
                    && ui
                        .small_button(format!("Show beat {b}"))
                        .on_hover_text("Select the beat and move the playhead to it")
                        .clicked()
                {
                    show = Some(b);
                }
                let text = egui::RichText::new(&e.message).color(ui.visuals().error_fg_color);
                ui.add(egui::Label::new(text).truncate())
                    .on_hover_text(&e.message);
            }
        });
        if let Some(b) = show {
            self.show_beat(b);
        }
    }

    pub(super) fn confirm_dialog(&mut self, ctx: &egui::Context) {
        if self.confirm.is_none() {
            return;
        }
        let mut choice = None;
        egui::Modal::new(egui::Id::unique("unsaved-changes")).show(ctx, |ui| {
            ui.heading("Unsaved changes");
            ui.label("The score has changes that are not saved.");
            ui.horizontal(|ui| {
                if ui.button("Save").clicked() {
                    choice = Some(ConfirmAnswer::Save);
                }
                if ui.button("Discard changes").clicked() {
                    choice = Some(ConfirmAnswer::Discard);
                }
                if ui.button("Cancel").clicked() {
                    choice = Some(ConfirmAnswer::Cancel);
                }
            });
        });
        if let Some(answer) = choice {
            self.answer_confirm(answer);
        }
    }

    /// The offer to restore what the last session left unsaved.
    pub(super) fn restore_dialog(&mut self, ctx: &egui::Context) {
        let Some(offer) = &self.restore_offer else {
            return;
        };
        let from = offer
            .original
            .as_ref()
            .map_or("an untitled score".to_string(), |p| p.display().to_string());
        let mut choice = None;
        egui::Modal::new(egui::Id::unique("restore-autosave")).show(ctx, |ui| {
            ui.heading("Restore unsaved changes?");
            ui.label(format!(
                "timpanist did not close cleanly last time. Its autosave holds changes to \
                 {from} that were not saved."
            ));
            ui.horizontal(|ui| {
                if ui.button("Restore").clicked() {
                    choice = Some(true);
                }
                if ui.button("Discard").clicked() {
                    choice = Some(false);
                }
            });
        });
        if let Some(restore) = choice {
            self.answer_restore(restore);
        }
    }

    pub(super) fn central(&mut self, ui: &mut egui::Ui) {
        if let Some(err) = self.messages.error.clone() {
            ui.horizontal(|ui| {
                ui.colored_label(ui.visuals().error_fg_color, format!("Error: {err}"));
                if ui.small_button("Dismiss").clicked() {
                    self.messages.error = None;
                }
            });
        }
        let Some(doc) = &self.doc else {
            ui.label("No score open. Use File > Open or File > New.");
            return;
        };
        let loaded = &doc.loaded;
        let width = ui.available_width();
        let lanes_h = timeline::RULER_H + timeline::LANE_H * 3.0 + tempo_lane::TEMPO_H + 16.0;
        let plot_h = 215.0;
        let view_h = (ui.available_height() - lanes_h - plot_h).max(220.0);
        let (rect, _) = ui.allocate_exact_size(egui::vec2(width, view_h), egui::Sense::hover());
        let comp = self.pipeline.composition();
        let simulated_pose = (self.views.simulated.as_ref())
            .and_then(|s| s.pose_at(self.transport.playhead_s))
            .copied();
        let playhead = self.transport.playhead_s;
        let target_pose = comp.map(|c| {
            *self.views.ik.pose(
                &self.views.viewport.body().skeleton,
                c,
                self.pipeline.generation(),
                playhead,
            )
        });
        let pose = simulated_pose.or(target_pose);
        let mut ghosts: Vec<(Pose, Rgba)> = match (comp, self.views.simulated.as_ref()) {
            (Some(c), Some(sim)) => super::pose::ghosts(c, sim, &doc.selection.beats)
                .into_iter()
                .map(|g| (g, stage::GHOST))
                .collect(),
            _ => Vec::new(),
        };
        let mut overlays = Vec::new();
        if let (true, Some(_), Some(target)) =
            (self.views.overlay_target, simulated_pose, target_pose)
        {
            ghosts.push((target, stage::TARGET_POSE));
            overlays.push(("target pose (IK)", stage::TARGET_POSE));
        }
        let previous = (self.views.previous.as_ref()).and_then(|p| p.pose_at(playhead));
        if let (true, Some(previous)) = (self.views.overlay_previous, previous) {
            ghosts.push((*previous, stage::PREVIOUS_POSE));
            overlays.push(("previous rendering", stage::PREVIOUS_POSE));
        }
        self.views.viewport.show(
            ui,
            rect,
            &viewport::ViewportInput {
                doc: loaded,
                composition: comp,
                generation: self.pipeline.generation(),
                pose: pose.as_ref(),
                ghosts: &ghosts,
                overlays: &overlays,
                simulated: self.views.simulated.as_ref().map(|s| &s.motion().tips),
                drums: (self.views.simulated.as_ref())
                    .and_then(|s| s.rendering())
                    .map(|r| &r.drums),
                selection: &doc.selection,
                time_s: self.transport.playhead_s,
            },
            &mut self.pending,
        );
        ui.add_space(4.0);
        self.views.timeline.show(
            ui,
            &timeline::TimelineInput {
                doc: loaded,
                selection: &doc.selection,
                playhead_s: self.transport.playhead_s,
                loop_ticks: self.transport.loop_ticks,
            },
            &mut self.pending,
        );
        if let Some(axis) = self.views.timeline.axis() {
            let grid = if self.views.timeline.snap {
                self.views.timeline.grid_ticks(loaded)
            } else {
                1
            };
            self.views.tempo_lane.show(
                ui,
                axis,
                &loaded.score.tempo,
                loaded.score.ticks_per_quarter,
                grid,
                &mut self.pending,
            );
        }
        ui.add_space(4.0);
        let map = loaded.score.tempo_map();
        let window = self.views.timeline.geometry.map(|g| {
            let t = |x: f32| map.seconds_at(g.axis.tick_of(f64::from(x)).max(0.0));
            (t(g.lanes.left()), t(g.lanes.right()))
        });
        let busy = self.pipeline.is_busy();
        let note = match (self.pipeline.render_error(), busy, self.pipeline.renders()) {
            (Some(e), _, _) => Some(e.message.clone()),
            (None, true, _) => Some("rendering sound and motion...".to_string()),
            (None, false, false) => Some("rendering is turned off".to_string()),
            (None, false, true) => None,
        };
        let input = plots::PlotInput {
            composition: match (comp, self.pipeline.compose_error()) {
                (_, Some(e)) => Err(e),
                (Some(c), None) => Ok(Some((c, self.pipeline.generation()))),
                (None, None) => Ok(None),
            },
            rendering: self.pipeline.rendering().map(|(r, id)| (&**r, id)),
            rendering_current: self.pipeline.rendering_is_current(),
            rendering_busy: busy,
            rendering_note: note.as_deref(),
            link: plots::linked::TimeLink {
                window,
                playhead_s: self.transport.playhead_s,
            },
            selected_beats: &doc.selection.beats,
        };
        if let Some(t) = self.views.plots.show(ui, &input) {
            self.pending.push(Command::Seek(t));
        }
    }
}
