//! The eframe editor. For now it opens a score with its kit, shows the score and a
//! read-only timeline, and saves it; editing, the 3D view and playback build on this.
//! The document (the score) is the only state that is saved; the UI reads it.

mod timeline;

use crate::score::LoadedScore;
use eframe::egui;
use std::path::{Path, PathBuf};

/// The demo score opened when no file is given (compiled in, so it opens anywhere).
pub const DEMO_SCORE_PATH: &str = "scores/etude-modes.ron";
const DEMO_SCORE_TEXT: &str = include_str!("../../scores/etude-modes.ron");

/// The open document.
struct Document {
    loaded: LoadedScore,
    /// Where it is saved; `None` for the compiled-in demo until saved.
    path: Option<PathBuf>,
}

/// The editor application state.
pub struct EditorApp {
    doc: Option<Document>,
    /// The last error, shown in the window until dismissed.
    error: Option<String>,
    /// A passing message for the status bar.
    status: String,
    /// The window title last sent, so it is only sent when it changes.
    shown_title: String,
}

impl EditorApp {
    /// Open `path`, or the bundled demo score when `None`. Errors are shown in the window.
    pub fn new(path: Option<&Path>) -> EditorApp {
        let mut app = EditorApp {
            doc: None,
            error: None,
            status: String::new(),
            shown_title: String::new(),
        };
        match path {
            Some(p) => app.open(p),
            None => app.open_demo(),
        }
        app
    }

    /// The loaded score, if any.
    pub fn loaded(&self) -> Option<&LoadedScore> {
        self.doc.as_ref().map(|d| &d.loaded)
    }

    /// The error shown in the window, if any.
    pub fn error(&self) -> Option<&str> {
        self.error.as_deref()
    }

    fn open_demo(&mut self) {
        let on_disk = Path::new(DEMO_SCORE_PATH);
        if on_disk.exists() {
            return self.open(on_disk);
        }
        match LoadedScore::parse(on_disk, DEMO_SCORE_TEXT) {
            Ok(loaded) => {
                self.status = "opened the bundled demo score".into();
                self.doc = Some(Document { loaded, path: None });
            }
            Err(e) => self.error = Some(e.to_string()),
        }
    }

    fn open(&mut self, path: &Path) {
        match LoadedScore::load(path) {
            Ok(loaded) => {
                self.status = format!("opened {}", path.display());
                if !loaded.notices.is_empty() {
                    self.status = loaded.notices.join("; ");
                }
                self.doc = Some(Document {
                    loaded,
                    path: Some(path.to_path_buf()),
                });
                self.error = None;
            }
            Err(e) => self.error = Some(e.to_string()),
        }
    }

    fn save(&mut self, ask: bool) {
        let Some(doc) = &mut self.doc else { return };
        let target = match (&doc.path, ask) {
            (Some(p), false) => Some(p.clone()),
            _ => rfd::FileDialog::new()
                .add_filter("timpanist score", &["ron"])
                .save_file(),
        };
        let Some(target) = target else { return };
        match doc.loaded.score.save(&target) {
            Ok(()) => {
                self.status = format!("saved {}", target.display());
                doc.path = Some(target);
            }
            Err(e) => self.error = Some(e.to_string()),
        }
    }

    fn open_dialog(&mut self) {
        if let Some(p) = rfd::FileDialog::new()
            .add_filter("timpanist score", &["ron"])
            .pick_file()
        {
            self.open(&p);
        }
    }

    fn window_title(&self) -> String {
        match &self.doc {
            Some(d) => format!(
                "timpanist — {} — {}",
                d.loaded.score.title,
                d.path
                    .as_ref()
                    .map_or("bundled demo".into(), |p| p.display().to_string())
            ),
            None => "timpanist".into(),
        }
    }

    fn menu_bar(&mut self, ui: &mut egui::Ui) {
        egui::MenuBar::new().ui(ui, |ui| {
            ui.menu_button("File", |ui| {
                if ui.button("Open…  (Ctrl+O)").clicked() {
                    self.open_dialog();
                }
                if ui.button("Save  (Ctrl+S)").clicked() {
                    self.save(false);
                }
                if ui.button("Save As…").clicked() {
                    self.save(true);
                }
                ui.separator();
                if ui.button("Quit").clicked() {
                    ui.ctx().send_viewport_cmd(egui::ViewportCommand::Close);
                }
            });
        });
    }

    fn score_panel(&self, ui: &mut egui::Ui) {
        let Some(doc) = &self.doc else {
            ui.label("No score open. Use File > Open.");
            return;
        };
        let s = &doc.loaded.score;
        ui.heading(&s.title);
        egui::Grid::new("score-info").num_columns(2).show(ui, |ui| {
            let rows = [
                ("Kit", doc.loaded.kit.name.clone()),
                ("Grip", format!("{:?}", s.grip)),
                ("Beats", s.beats.len().to_string()),
                ("Length", format!("{:.1} s", s.duration_s())),
                (
                    "Tempo",
                    s.tempo
                        .iter()
                        .map(|t| format!("{:.0}", t.bpm))
                        .collect::<Vec<_>>()
                        .join(" -> "),
                ),
                (
                    "Meter",
                    s.meter
                        .iter()
                        .map(|m| format!("{}/{}", m.numerator, m.denominator))
                        .collect::<Vec<_>>()
                        .join(", "),
                ),
            ];
            for (k, v) in rows {
                ui.label(k);
                ui.label(v);
                ui.end_row();
            }
        });
        ui.separator();
        ui.label("Drums");
        for (i, d) in doc.loaded.kit.drums.iter().enumerate() {
            ui.label(format!("{i}: {} in {}", d.name, d.tuning));
        }
    }
}

impl eframe::App for EditorApp {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        let ctx = ui.ctx().clone();
        let title = self.window_title();
        if title != self.shown_title {
            ctx.send_viewport_cmd(egui::ViewportCommand::Title(title.clone()));
            self.shown_title = title;
        }
        if ctx.input_mut(|i| i.consume_key(egui::Modifiers::COMMAND, egui::Key::S)) {
            self.save(false);
        }
        if ctx.input_mut(|i| i.consume_key(egui::Modifiers::COMMAND, egui::Key::O)) {
            self.open_dialog();
        }
        egui::Panel::top("menu").show(ui, |ui| self.menu_bar(ui));
        egui::Panel::bottom("status").show(ui, |ui| ui.label(&self.status));
        egui::Panel::left("score")
            .default_size(240.0)
            .show(ui, |ui| self.score_panel(ui));
        egui::CentralPanel::default_margins().show(ui, |ui| {
            if let Some(err) = self.error.clone() {
                ui.horizontal(|ui| {
                    ui.colored_label(ui.visuals().error_fg_color, format!("Error: {err}"));
                    if ui.small_button("Dismiss").clicked() {
                        self.error = None;
                    }
                });
            }
            if let Some(doc) = &self.doc {
                timeline::show(ui, &doc.loaded);
            }
        });
    }
}

/// Open the editor window on `score` (or the demo score) and run until it closes.
pub fn run(score: Option<PathBuf>) -> anyhow::Result<()> {
    let options = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_inner_size([1200.0, 720.0])
            .with_title("timpanist")
            .with_drag_and_drop(true),
        ..Default::default()
    };
    eframe::run_native(
        "timpanist",
        options,
        Box::new(move |_cc| Ok(Box::new(EditorApp::new(score.as_deref())))),
    )
    .map_err(|e| anyhow::anyhow!("could not open the editor window: {e}"))
}
