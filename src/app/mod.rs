//! The eframe editor. For now it opens a score with its kit, shows the score and a
//! read-only timeline, and saves it; editing, the 3D view and playback build on this.
//! The document (the score) is the only state that is saved; the UI reads it.

mod timeline;
mod tips_plot;

use crate::mocap::db::MotionDb;
use crate::motion::compose::{ComposeParams, Composition};
use crate::score::LoadedScore;
use eframe::egui;
use std::path::{Path, PathBuf};
use std::sync::mpsc;

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
    /// The composed trajectories of the open score, when ready.
    composition: Option<Composition>,
    /// A composition being made on a worker thread.
    composing: Option<mpsc::Receiver<Result<Composition, String>>>,
    /// Why there is no composition, if it failed.
    compose_error: Option<String>,
}

impl EditorApp {
    /// Open `path`, or the bundled demo score when `None`. Errors are shown in the window.
    pub fn new(path: Option<&Path>) -> EditorApp {
        let mut app = EditorApp {
            doc: None,
            error: None,
            status: String::new(),
            shown_title: String::new(),
            composition: None,
            composing: None,
            compose_error: None,
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
                self.start_composing(None);
            }
            Err(e) => self.error = Some(e.to_string()),
        }
    }

    /// Compose the open score on a worker thread (the UI never waits for it).
    fn start_composing(&mut self, ctx: Option<egui::Context>) {
        let Some(doc) = &self.doc else { return };
        let (score, kit) = (doc.loaded.score.clone(), doc.loaded.kit.clone());
        let (tx, rx) = mpsc::channel();
        self.composing = Some(rx);
        self.composition = None;
        self.compose_error = None;
        std::thread::spawn(move || {
            let db_dir = crate::mocap::db::default_dir();
            let result = MotionDb::load(&db_dir)
                .map_err(|e| format!("no motion database: {e}"))
                .and_then(|db| {
                    crate::motion::perform::trajectories(
                        &score,
                        &kit,
                        &db,
                        &Default::default(),
                        &ComposeParams::default(),
                    )
                });
            let _ = tx.send(result);
            if let Some(ctx) = ctx {
                ctx.request_repaint();
            }
        });
    }

    /// Take a finished composition, if one has arrived.
    fn poll_composition(&mut self) {
        if let Some(rx) = &self.composing
            && let Ok(result) = rx.try_recv()
        {
            self.composing = None;
            match result {
                Ok(c) => self.composition = Some(c),
                Err(e) => self.compose_error = Some(e),
            }
        }
    }

    /// Wait for the composition in progress (for tests and batch use).
    pub fn wait_for_composition(&mut self) -> Option<&Composition> {
        if let Some(rx) = self.composing.take() {
            match rx.recv() {
                Ok(Ok(c)) => self.composition = Some(c),
                Ok(Err(e)) => self.compose_error = Some(e),
                Err(_) => self.compose_error = Some("the composing thread stopped".into()),
            }
        }
        self.composition.as_ref()
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
                self.start_composing(None);
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
        self.poll_composition();
        if self.composing.is_some() {
            ctx.request_repaint_after(std::time::Duration::from_millis(50));
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
            ui.add_space(8.0);
            match (&self.composition, &self.compose_error) {
                (Some(c), _) => tips_plot::show(ui, c),
                (None, Some(e)) => {
                    ui.label(format!("Composed stick tips unavailable: {e}"));
                }
                (None, None) if self.composing.is_some() => {
                    ui.horizontal(|ui| {
                        ui.spinner();
                        ui.label("Composing stick-tip trajectories…");
                    });
                }
                _ => {}
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
