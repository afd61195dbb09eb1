//! Edit > Preferences (Ctrl+,): the window over [`Preferences`] and how each choice takes
//! effect. The look (theme, UI scale) applies at once; the audio device and buffer size
//! reopen playback at once, keeping the audio and the playhead; the kit of a new score
//! and the export folder apply to the next New and Export; the motion database is read at
//! the next start. The device list is read again every 2 s while the window is open, so
//! a device plugged in or out shows without restarting. Every change is saved at once.

use super::EditorApp;
use super::playback::{self, Playback};
use super::preferences::{BUFFER_FRAMES, Preferences, Theme, UI_SCALE_RANGE};
use eframe::egui;
use std::path::PathBuf;
use std::time::{Duration, Instant};

/// How often the device list is read while the window is open.
const DEVICE_POLL: Duration = Duration::from_secs(2);

/// The preferences, where they are kept, and the window's state.
pub struct Settings {
    pub prefs: Preferences,
    file: Option<PathBuf>,
    /// Whether this editor plays on a device at all (tests and `--silent` do not).
    use_device: bool,
    pub window_open: bool,
    /// Why the preferences file could not be read, until shown.
    pub load_error: Option<String>,
    devices: Vec<String>,
    listed_at: Option<Instant>,
    /// The database and export folder fields as typed.
    database_text: String,
    export_text: String,
}

impl Settings {
    pub fn new(prefs: Preferences, file: Option<PathBuf>, use_device: bool) -> Settings {
        let text = |p: &Option<PathBuf>| {
            p.as_ref()
                .map_or(String::new(), |p| p.display().to_string())
        };
        Settings {
            database_text: text(&prefs.database),
            export_text: text(&prefs.export_folder),
            prefs,
            file,
            use_device,
            window_open: false,
            load_error: None,
            devices: Vec::new(),
            listed_at: None,
        }
    }

    /// The same, remembering why the file could not be read.
    pub fn with_load_error(self, load_error: Option<String>) -> Settings {
        Settings { load_error, ..self }
    }

    /// Theme and UI scale onto `ctx`.
    pub fn apply_look(&self, ctx: &egui::Context) {
        ctx.set_theme(match self.prefs.theme {
            Theme::System => egui::ThemePreference::System,
            Theme::Dark => egui::ThemePreference::Dark,
            Theme::Light => egui::ThemePreference::Light,
        });
        ctx.set_zoom_factor(self.prefs.ui_scale);
    }

    /// Save, if kept in a file; the error to show otherwise.
    fn save(&self) -> Option<String> {
        let file = self.file.as_deref()?;
        self.prefs.save(file).err().map(|e| e.to_string())
    }
}

/// What changed in one frame of the window.
#[derive(Default)]
struct Changed {
    look: bool,
    audio: bool,
    any: bool,
}

impl EditorApp {
    /// Draw the preferences window when open, and apply and save what changed.
    pub(super) fn preferences_window(&mut self, ctx: &egui::Context) {
        if !self.settings.window_open {
            return;
        }
        let s = &mut self.settings;
        if s.use_device && s.listed_at.is_none_or(|t| t.elapsed() >= DEVICE_POLL) {
            s.devices = super::output::output_devices();
            s.listed_at = Some(Instant::now());
        }
        ctx.request_repaint_after(DEVICE_POLL);
        let notice = self.transport.playback.notice().map(str::to_string);
        let mut open = true;
        let mut changed = Changed::default();
        egui::Window::new("Preferences")
            .open(&mut open)
            .resizable(false)
            .collapsible(false)
            .show(ctx, |ui| {
                changed = preferences_ui(ui, s, notice.as_deref());
            });
        self.settings.window_open = open;
        if changed.look {
            self.settings.apply_look(ctx);
        }
        if changed.audio && self.settings.use_device {
            self.reopen_audio();
        }
        if changed.any
            && let Some(e) = self.settings.save()
        {
            self.messages.error = Some(format!("preferences not saved: {e}"));
        }
    }

    /// Reopen playback on the chosen device, keeping the audio and the playhead.
    fn reopen_audio(&mut self) {
        let prefs = &self.settings.prefs;
        self.transport.playback.pause();
        self.transport.playback =
            Playback::open(prefs.audio_device.as_deref(), prefs.buffer_frames);
        let playhead = self.transport.playhead_s;
        self.transport.seek(playhead);
        if let Some((rendering, _)) = self.pipeline.rendering()
            && let Err(e) = self.transport.load(&std::sync::Arc::clone(rendering))
        {
            self.messages.error = Some(format!("playback: {e}"));
        }
        self.messages.status = match self.transport.playback.notice() {
            Some(n) => n.to_string(),
            None => format!(
                "playing on {}",
                prefs
                    .audio_device
                    .as_deref()
                    .unwrap_or("the default device")
            ),
        };
    }
}

/// The window's contents; what the user changed.
fn preferences_ui(ui: &mut egui::Ui, s: &mut Settings, notice: Option<&str>) -> Changed {
    let mut changed = Changed::default();
    let before = s.prefs.clone();
    egui::Grid::new("preferences")
        .num_columns(2)
        .spacing([12.0, 8.0])
        .show(ui, |ui| {
            let label = ui.label("Audio output");
            ui.vertical(|ui| {
                let shown = s
                    .prefs
                    .audio_device
                    .clone()
                    .unwrap_or("system default".into());
                egui::ComboBox::from_id_salt("audio-device")
                    .selected_text(shown)
                    .width(260.0)
                    .show_ui(ui, |ui| {
                        ui.selectable_value(&mut s.prefs.audio_device, None, "system default");
                        for d in &s.devices {
                            ui.selectable_value(&mut s.prefs.audio_device, Some(d.clone()), d);
                        }
                    })
                    .response
                    .labelled_by(label.id);
                if !s.use_device {
                    ui.weak("(this editor was started without a sound device)");
                } else if let Some(n) = notice {
                    ui.colored_label(ui.visuals().warn_fg_color, n);
                }
            });
            ui.end_row();

            let label = ui.label("Buffer size");
            let frames_text = |f: Option<u32>| match f {
                None => "the device's choice".to_string(),
                Some(f) => format!(
                    "{f} frames ({:.1} ms)",
                    f64::from(f) * 1e3 / f64::from(playback::AUDIO_RATE_HZ)
                ),
            };
            egui::ComboBox::from_id_salt("buffer-size")
                .selected_text(frames_text(s.prefs.buffer_frames))
                .show_ui(ui, |ui| {
                    ui.selectable_value(&mut s.prefs.buffer_frames, None, frames_text(None));
                    for f in BUFFER_FRAMES {
                        ui.selectable_value(
                            &mut s.prefs.buffer_frames,
                            Some(f),
                            frames_text(Some(f)),
                        );
                    }
                })
                .response
                .labelled_by(label.id);
            ui.end_row();

            let label = ui.label("Kit of a new score");
            egui::ComboBox::from_id_salt("default-kit")
                .selected_text(s.prefs.default_kit.clone())
                .show_ui(ui, |ui| {
                    for (name, _) in crate::kit::BUNDLED_KITS {
                        ui.selectable_value(&mut s.prefs.default_kit, name.to_string(), *name);
                    }
                })
                .response
                .labelled_by(label.id);
            ui.end_row();

            let label = ui.label("Motion database");
            ui.vertical(|ui| {
                let field = ui
                    .add(
                        egui::TextEdit::singleline(&mut s.database_text)
                            .hint_text("searched: ./mocap, then the installed, then the built-in"),
                    )
                    .labelled_by(label.id);
                if field.lost_focus() {
                    s.prefs.database = folder(&s.database_text);
                }
                ui.weak("read when the editor starts");
            });
            ui.end_row();

            ui.label("Theme");
            ui.horizontal(|ui| {
                for theme in Theme::ALL {
                    ui.radio_value(&mut s.prefs.theme, theme, theme.label());
                }
            });
            ui.end_row();

            let label = ui.label("UI scale");
            ui.add(egui::Slider::new(&mut s.prefs.ui_scale, UI_SCALE_RANGE).step_by(0.05))
                .labelled_by(label.id);
            ui.end_row();

            let label = ui.label("Export to");
            let field = ui
                .add(egui::TextEdit::singleline(&mut s.export_text).hint_text("beside the score"))
                .labelled_by(label.id);
            if field.lost_focus() {
                s.prefs.export_folder = folder(&s.export_text);
            }
            ui.end_row();
        });
    if ui.button("Restore the defaults").clicked() {
        *s = Settings::new(Preferences::default(), s.file.clone(), s.use_device);
        s.window_open = true;
    }
    let after = &s.prefs;
    changed.look = after.theme != before.theme || after.ui_scale != before.ui_scale;
    changed.audio =
        after.audio_device != before.audio_device || after.buffer_frames != before.buffer_frames;
    changed.any = *after != before;
    changed
}

/// A typed folder: `None` when blank.
fn folder(text: &str) -> Option<PathBuf> {
    let t = text.trim();
    (!t.is_empty()).then(|| PathBuf::from(t))
}
