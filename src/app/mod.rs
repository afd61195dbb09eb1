//! The eframe editor: a timeline with a tempo lane, a 3D viewport with trajectory handles,
//! an inspector and tabs of plots over one document, the score. Three parts, wired here:
//! the [`document`] (score, history, selection, file), the [`pipeline`] (composing and
//! rendering workers) and the views (timeline, viewport, inspector, plots, menus). Panels
//! read the document and push [`Command`]s; the app drains them once per frame, applies
//! each change through the undo history (one gesture, one step) and asks the pipeline for
//! a fresh composition, sound and motion. Files and the window's menus, the transport,
//! background saving and the read-only API for tests live in their own modules.

mod actions;
mod api;
mod chrome;
mod clipboard;
mod command;
mod device_watch;
mod dialogs;
mod document;
mod export;
mod file_browser;
mod files;
mod gpu_view;
mod history;
mod inspector;
mod jobs;
mod keys;
mod opening;
mod osc_out;
mod output;
pub mod picking;
mod pipeline;
pub mod playback;
mod plots;
mod pose;
mod preferences;
mod preferences_window;
mod recent;
mod recovery;
mod renderer;
mod selection;
mod session;
mod settings_panel;
mod solid_frame;
mod strike_sounds;
pub mod tape;
mod tempo_lane;
mod time_axis;
mod timeline;
mod transport;
mod viewport;
mod worker;

pub use crate::scene::camera::Camera;
pub use export::Export;
pub use files::{FileKind, kind_of};
pub use keys::Action;
pub use plots::Tab as PlotTab;
pub use pose::Simulated;
pub use recent::RecentFiles;
pub use selection::Selection;
pub use time_axis::{TimeAxis, snap};

use clipboard::Clipboard;
use command::Command;
use document::Document;
use eframe::egui;
use jobs::Jobs;
use pipeline::Pipeline;
use playback::Playback;
use std::path::{Path, PathBuf};
use transport::Transport;

/// The demo score opened when no file is given (compiled in, so it opens anywhere).
pub const DEMO_SCORE_PATH: &str = "scores/etude-modes.ron";

/// How the editor starts.
#[derive(Clone, Debug)]
pub struct EditorOptions {
    /// The score to open; `None` opens the bundled demo.
    pub score: Option<PathBuf>,
    /// Where the recent-files list is kept; `None` keeps it in memory only.
    pub recent_store: Option<PathBuf>,
    /// The autosave file (see `recovery`); `None` autosaves nowhere.
    pub recovery_file: Option<PathBuf>,
    /// Try to open the sound device (otherwise the silent clock is used).
    pub audio_device: bool,
    /// Render each version of the score (simulation and sound) on a worker thread for
    /// playback and the simulated body.
    pub render: bool,
    /// Use the in-window file browser rather than the system's dialogs (which are used,
    /// by default, while they open; see `dialogs`).
    pub in_window_dialogs: bool,
    /// The preferences file (see `preferences`); `None` keeps them in memory only.
    pub preferences_file: Option<PathBuf>,
}

impl Default for EditorOptions {
    fn default() -> Self {
        EditorOptions {
            score: None,
            recent_store: recent::default_store(),
            recovery_file: recovery::default_file(),
            audio_device: true,
            render: true,
            in_window_dialogs: false,
            preferences_file: preferences::default_file(),
        }
    }
}

/// What to do once the user has agreed to lose unsaved changes.
#[derive(Clone, Debug, PartialEq)]
enum AfterConfirm {
    Quit,
    New,
    OpenDialog,
    Open(PathBuf),
    /// A demo score built into the program, by name (`score::demos`).
    OpenDemo(&'static str),
}

/// The views' own state (nothing here is saved with the score).
struct Views {
    timeline: timeline::TimelineView,
    tempo_lane: tempo_lane::TempoLane,
    viewport: viewport::Viewport,
    ik: pose::IkPose,
    /// The simulated performance shown instead of the IK pose, once rendered.
    simulated: Option<Simulated>,
    plots: plots::Plots,
    show_help: bool,
    /// Draw the 3D view flat (2D marks) even when the GPU can draw it lit.
    flat_view: bool,
    /// Overlay the target pose (the composed tips through the IK) on the simulated one.
    overlay_target: bool,
    /// Overlay the previous rendering's pose (the score before the last edit).
    overlay_previous: bool,
    /// The last complete rendering before the one shown, once a newer one arrived.
    previous: Option<Simulated>,
    /// Whether the rendering shown is complete (the next one then makes it `previous`).
    shown_complete: bool,
}

/// What the window says: the last error (until dismissed) and a passing status line.
#[derive(Default)]
struct Messages {
    error: Option<String>,
    status: String,
}

/// The editor application state.
pub struct EditorApp {
    doc: Option<Document>,
    pipeline: Pipeline,
    transport: Transport,
    /// Live OSC output of the hits during playback.
    osc: osc_out::OscOut,
    views: Views,
    jobs: Jobs,
    recent: RecentFiles,
    recovery: recovery::Recovery,
    /// A score the last session left unsaved, offered back until the user answers.
    restore_offer: Option<recovery::Recovered>,
    clipboard: Clipboard,
    messages: Messages,
    /// The question asked before losing unsaved changes, while it shows.
    confirm: Option<AfterConfirm>,
    /// What to do once the save started from that question has finished.
    after_save: Option<AfterConfirm>,
    /// The user agreed to quit: close once the writing jobs are done.
    quitting: bool,
    /// A recording being read (transcribed) for a new document, while its dialog shows.
    opening: Option<opening::Opening>,
    pending: Vec<Command>,
    ctx: Option<egui::Context>,
    /// The window title last sent, so it is only sent when it changes.
    shown_title: String,
    dialogs: dialogs::Dialogs,
    /// The preferences and their window.
    settings: preferences_window::Settings,
}

impl EditorApp {
    /// Open `path`, or the bundled demo score when `None`, with the default options.
    pub fn new(path: Option<&Path>) -> EditorApp {
        EditorApp::with_options(EditorOptions {
            score: path.map(Path::to_path_buf),
            ..EditorOptions::default()
        })
    }

    /// Start the editor with `options` on a document read already (`timpanist FILE`
    /// imports before the window opens); `options.score` is not read.
    pub fn with_document(options: EditorOptions, opened: files::Opened) -> EditorApp {
        let mut app = EditorApp::start(&options);
        app.open_document(opened);
        app.find_left_behind();
        app.report_preferences_error();
        app
    }

    /// Start the editor with `options`. Errors are shown in the window.
    pub fn with_options(options: EditorOptions) -> EditorApp {
        let mut app = EditorApp::start(&options);
        match &options.score {
            Some(p) => app.open_path(p),
            None => app.open_demo(),
        }
        app.find_left_behind();
        app.report_preferences_error();
        app
    }

    /// Show why the preferences file could not be read (after the document, whose
    /// opening clears the error line).
    fn report_preferences_error(&mut self) {
        if let Some(e) = self.settings.load_error.take() {
            self.messages.error = Some(format!("{e} (using the default preferences)"));
        }
    }

    /// The editor with no document yet.
    fn start(options: &EditorOptions) -> EditorApp {
        let (prefs, prefs_error) =
            match preferences::Preferences::load(options.preferences_file.as_deref()) {
                Ok(p) => (p, None),
                Err(e) => (preferences::Preferences::default(), Some(e.to_string())),
            };
        let playback = if options.audio_device {
            Playback::open(prefs.audio_device.as_deref(), prefs.buffer_frames)
        } else {
            Playback::silent()
        };
        let db = crate::mocap::shipped::DbSource::named_or_located(prefs.database.clone());
        EditorApp {
            doc: None,
            pipeline: Pipeline::new(options.render, db),
            transport: Transport::new(playback),
            osc: osc_out::OscOut::default(),
            views: Views {
                timeline: timeline::TimelineView::new(),
                tempo_lane: tempo_lane::TempoLane::default(),
                viewport: viewport::Viewport::default(),
                ik: pose::IkPose::default(),
                simulated: None,
                plots: plots::Plots::default(),
                show_help: false,
                flat_view: std::env::var_os("TIMPANIST_FLAT_VIEW").is_some(),
                overlay_target: false,
                overlay_previous: false,
                previous: None,
                shown_complete: false,
            },
            jobs: Jobs::default(),
            recent: RecentFiles::load(options.recent_store.clone()),
            recovery: recovery::Recovery::new(options.recovery_file.clone()),
            restore_offer: None,
            clipboard: Clipboard::default(),
            messages: Messages::default(),
            confirm: None,
            after_save: None,
            quitting: false,
            opening: None,
            pending: Vec::new(),
            ctx: None,
            shown_title: String::new(),
            settings: preferences_window::Settings::new(
                prefs,
                options.preferences_file.clone(),
                options.audio_device,
            )
            .with_load_error(prefs_error),
            dialogs: if options.in_window_dialogs {
                dialogs::Dialogs::new(dialogs::Kind::InWindow)
            } else {
                dialogs::Dialogs::from_environment()
            },
        }
    }

    /// Once per frame, before the panels: take the workers' results, dropped files, the
    /// close button and the keyboard.
    fn take_inputs(&mut self, ctx: &egui::Context) {
        if self.ctx.is_none() {
            self.ctx = Some(ctx.clone());
            self.settings.apply_look(ctx);
            let (a, b) = (ctx.clone(), ctx.clone());
            self.pipeline.set_waker(move || a.request_repaint());
            self.jobs.set_waker(move || b.request_repaint());
        }
        self.take_results();
        let dropped: Vec<PathBuf> = ctx.input(|i| {
            i.raw
                .dropped_files
                .iter()
                .map(|f| f.path().to_path_buf())
                .filter(|p| !p.as_os_str().is_empty())
                .collect()
        });
        for p in dropped {
            self.handle_dropped(&p);
        }
        if ctx.input(|i| i.viewport().close_requested()) && !self.request_quit() {
            ctx.send_viewport_cmd(egui::ViewportCommand::CancelClose);
        }
        if self.quitting && !self.jobs.is_busy() {
            ctx.send_viewport_cmd(egui::ViewportCommand::Close);
        }
        if self.restore_offer.is_none() && !self.quitting {
            self.autosave(ctx);
        }
        // Shortcuts wait while a modal asks something (its own keys, Escape and Enter, are
        // its own).
        if self.confirm.is_none()
            && self.restore_offer.is_none()
            && self.opening.is_none()
            && !self.dialogs.is_open()
        {
            for a in keys::take_actions(ctx) {
                self.pending.push(Command::Do(a));
            }
            // Done before the frame is drawn: an edit by key is composed (and rendered)
            // while the UI draws, instead of after it, and the frame shows it.
            self.drain();
        }
        let title = self
            .doc
            .as_ref()
            .map_or("timpanist".into(), Document::title);
        if title != self.shown_title {
            ctx.send_viewport_cmd(egui::ViewportCommand::Title(title.clone()));
            self.shown_title = title;
        }
        if let Some(event) = self.transport.playback.check_device() {
            self.messages.status = event.message();
        }
        let tick = self
            .transport
            .follow(self.doc.as_ref().map(|d| &d.loaded.score));
        if let Some(tick) = tick {
            self.views.timeline.follow(tick);
        }
        self.osc.tick(
            self.transport.playback.is_playing(),
            self.transport.playhead_s,
            self.pipeline.rendering().map(|(r, _)| r),
        );
        if self.transport.playback.is_playing() || self.pipeline.is_composing() {
            ctx.request_repaint_after(std::time::Duration::from_millis(30));
        } else if self.transport.playback.is_recovering() {
            // A lost device is looked for every second, and taken once its stream runs.
            ctx.request_repaint_after(device_watch::RETRY / 4);
        } else if self.transport.playback.has_device() {
            // Watch the device while idle too.
            ctx.request_repaint_after(device_watch::RETRY);
        }
    }
}

impl eframe::App for EditorApp {
    fn ui(&mut self, ui: &mut egui::Ui, frame: &mut eframe::Frame) {
        let ctx = ui.ctx().clone();
        self.views.viewport.gpu = frame
            .wgpu_render_state()
            .filter(|_| !self.views.flat_view)
            .map(|rs| rs.target_format);
        self.take_inputs(&ctx);
        egui::Panel::top("menu").show(ui, |ui| {
            self.menu_bar(ui);
            self.transport_bar(ui);
        });
        egui::Panel::bottom("status").show(ui, |ui| self.status_bar(ui));
        egui::Panel::right("inspector")
            .default_size(300.0)
            .show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| {
                    if let Some(d) = &self.doc {
                        inspector::show(ui, &d.loaded, &d.selection, &mut self.pending);
                    }
                    self.osc.ui(ui);
                });
            });
        egui::CentralPanel::default_margins().show(ui, |ui| self.central(ui));
        self.drain();
        self.confirm_dialog(&ctx);
        self.restore_dialog(&ctx);
        self.opening_dialog(&ctx);
        self.file_dialog(&ctx);
        keys::help_window(&ctx, &mut self.views.show_help);
        self.preferences_window(&ctx);
    }

    /// A clean quit: nothing is left to recover.
    fn on_exit(&mut self) {
        let _ = self.recovery.remove();
    }
}

/// Open the editor window on `score` (or the demo score) and run until it closes.
pub fn run(score: Option<PathBuf>) -> anyhow::Result<()> {
    open_window(move || EditorApp::new(score.as_deref()))
}

/// Open the editor window on a document read or imported already (`timpanist FILE.mid`).
pub fn run_document(opened: files::Opened) -> anyhow::Result<()> {
    open_window(move || EditorApp::with_document(EditorOptions::default(), opened))
}

/// Open the editor window on the editor `make` builds and run until it closes.
fn open_window(make: impl FnOnce() -> EditorApp + 'static) -> anyhow::Result<()> {
    let mut viewport = egui::ViewportBuilder::default()
        .with_inner_size([1400.0, 900.0])
        .with_title("timpanist")
        .with_app_id("timpanist")
        .with_drag_and_drop(true);
    // The icon the desktop entry names (src/app/assets, installed by the Debian package).
    if let Ok(icon) = eframe::icon_data::from_png_bytes(include_bytes!("assets/timpanist.png")) {
        viewport = viewport.with_icon(icon);
    }
    let options = eframe::NativeOptions {
        viewport,
        ..Default::default()
    };
    eframe::run_native(
        "timpanist",
        options,
        Box::new(move |_cc| Ok(Box::new(make()))),
    )
    .map_err(|e| anyhow::anyhow!("could not open the editor window: {e}"))
}
