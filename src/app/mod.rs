//! The eframe editor (issue #7): a timeline with a tempo lane, a 3D viewport with
//! trajectory handles, an inspector and tabs of plots over one document, the score.
//! Panels read the score and push [`Command`]s; the app drains them once per frame,
//! applying every change through the undo history (one gesture, one step) and asking the
//! composing and rendering workers for fresh trajectories, sound and motion. Files,
//! recent files, drag and drop, the keyboard, the playback clock, the plots and export
//! live in their own modules.

mod camera;
mod clipboard;
mod command;
mod composer;
mod export;
mod files;
mod history;
mod inspector;
mod keys;
pub mod picking;
pub mod playback;
mod plots;
mod pose;
mod recent;
mod renderer;
mod selection;
mod settings_panel;
pub mod tape;
mod tempo_lane;
mod time_axis;
mod timeline;
mod viewport;

pub use camera::Camera;
pub use export::Export;
pub use files::{FileKind, kind_of};
pub use keys::Action;
pub use plots::Tab as PlotTab;
pub use pose::Simulated;
pub use recent::RecentFiles;
pub use selection::Selection;
pub use time_axis::{TimeAxis, snap};
pub use viewport::head_displacement;

use crate::kit::Kit;
use crate::motion::compose::Composition;
use crate::render::Rendering;
use crate::score::edit::ScoreEdit;
use crate::score::{Hand, LoadedScore, Score};
use clipboard::Clipboard;
use command::Command;
use composer::Composer;
use eframe::egui;
use history::History;
use playback::Playback;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// The demo score opened when no file is given (compiled in, so it opens anywhere).
pub const DEMO_SCORE_PATH: &str = "scores/etude-modes.ron";
const DEMO_SCORE_TEXT: &str = include_str!("../../scores/etude-modes.ron");

/// How the editor starts.
#[derive(Clone, Debug)]
pub struct EditorOptions {
    /// The score to open; `None` opens the bundled demo.
    pub score: Option<PathBuf>,
    /// Where the recent-files list is kept; `None` keeps it in memory only.
    pub recent_store: Option<PathBuf>,
    /// Try to open the sound device (otherwise the silent clock is used).
    pub audio_device: bool,
    /// Render each version of the score (simulation and sound) on a worker thread for
    /// playback and the simulated body.
    pub render: bool,
}

impl Default for EditorOptions {
    fn default() -> Self {
        EditorOptions {
            score: None,
            recent_store: recent::default_store(),
            audio_device: true,
            render: true,
        }
    }
}

/// The open document.
struct Document {
    loaded: LoadedScore,
    /// Where it is saved; `None` for the compiled-in demo, new scores and imports.
    path: Option<PathBuf>,
    history: History,
}

/// What to do once the user has agreed to lose unsaved changes.
#[derive(Clone, Debug, PartialEq)]
enum AfterConfirm {
    Quit,
    New,
    OpenDialog,
    Open(PathBuf),
}

/// Space plays at once only if this much audio past the playhead is ready, s.
const PLAY_AHEAD_S: f64 = 0.3;

/// The editor application state.
pub struct EditorApp {
    doc: Option<Document>,
    /// The last error, shown in the window until dismissed.
    error: Option<String>,
    /// A passing message for the status bar.
    status: String,
    /// The window title last sent, so it is only sent when it changes.
    shown_title: String,
    composer: Composer,
    /// Renders each version of the score for playback (`None` when disabled).
    renderer: Option<renderer::Renderer>,
    /// Why the latest render failed.
    /// Why the latest render or playback failed, and the beat it names (the status bar
    /// offers to show it).
    render_error: Option<renderer::Failure>,
    /// Counts compositions received (for caches).
    generation: u64,
    selection: Selection,
    clipboard: Clipboard,
    playback: Playback,
    /// The playhead, s.
    playhead_s: f64,
    /// The loop region, ticks.
    loop_ticks: Option<(u64, u64)>,
    looping: bool,
    timeline: timeline::TimelineView,
    tempo_lane: tempo_lane::TempoLane,
    viewport: viewport::Viewport,
    ik: pose::IkPose,
    /// The simulated performance, once the render pipeline provides one.
    simulated: Option<Simulated>,
    /// The latest rendering received (possibly of an older version while re-rendering).
    rendering: Option<Arc<Rendering>>,
    /// Counts renderings received (for the plots' caches).
    rendering_id: u64,
    /// Whether `rendering` is of the score as it is now (what File > Export needs).
    rendering_current: bool,
    /// Score time up to which the audio given to playback is final, s (infinite once a
    /// whole rendering, or none, is in).
    audio_ready_s: f64,
    /// Space was pressed where the audio is not ready yet: play once it is.
    waiting_to_play: bool,
    plots: plots::Plots,
    recent: RecentFiles,
    show_help: bool,
    confirm: Option<AfterConfirm>,
    allow_close: bool,
    pending: Vec<Command>,
    ctx: Option<egui::Context>,
}

impl EditorApp {
    /// Open `path`, or the bundled demo score when `None`, with the default options.
    pub fn new(path: Option<&Path>) -> EditorApp {
        EditorApp::with_options(EditorOptions {
            score: path.map(Path::to_path_buf),
            ..EditorOptions::default()
        })
    }

    /// Start the editor with `options`. Errors are shown in the window.
    pub fn with_options(options: EditorOptions) -> EditorApp {
        let mut app = EditorApp {
            doc: None,
            error: None,
            status: String::new(),
            shown_title: String::new(),
            composer: Composer::new(),
            renderer: options.render.then(renderer::Renderer::new),
            render_error: None,
            generation: 0,
            selection: Selection::default(),
            clipboard: Clipboard::default(),
            playback: if options.audio_device {
                Playback::new()
            } else {
                Playback::silent()
            },
            playhead_s: 0.0,
            loop_ticks: None,
            looping: false,
            timeline: timeline::TimelineView::new(),
            tempo_lane: tempo_lane::TempoLane::default(),
            viewport: viewport::Viewport::default(),
            ik: pose::IkPose::default(),
            simulated: None,
            rendering: None,
            rendering_id: 0,
            rendering_current: false,
            audio_ready_s: f64::INFINITY,
            waiting_to_play: false,
            plots: plots::Plots::default(),
            recent: RecentFiles::load(options.recent_store),
            show_help: false,
            confirm: None,
            allow_close: false,
            pending: Vec::new(),
            ctx: None,
        };
        match &options.score {
            Some(p) => app.open_path(p),
            None => app.open_demo(),
        }
        app
    }

    /// The loaded score, if any.
    pub fn loaded(&self) -> Option<&LoadedScore> {
        self.doc.as_ref().map(|d| &d.loaded)
    }

    /// Where the open score is saved, if anywhere.
    pub fn path(&self) -> Option<&Path> {
        self.doc.as_ref().and_then(|d| d.path.as_deref())
    }

    /// Why the latest rendering failed, if it did.
    pub fn render_error(&self) -> Option<&str> {
        self.render_error.as_ref().map(|f| f.message.as_str())
    }

    /// The error shown in the window, if any.
    pub fn error(&self) -> Option<&str> {
        self.error.as_deref()
    }

    /// The status bar message.
    pub fn status(&self) -> &str {
        &self.status
    }

    /// Whether the score has changes not saved.
    pub fn is_dirty(&self) -> bool {
        self.doc.as_ref().is_some_and(|d| !d.history.is_saved())
    }

    /// Number of undo steps recorded.
    pub fn undo_steps(&self) -> usize {
        self.doc.as_ref().map_or(0, |d| d.history.steps())
    }

    /// The current selection.
    pub fn selection(&self) -> &Selection {
        &self.selection
    }

    /// The recent files, most recent first.
    pub fn recent_files(&self) -> &[PathBuf] {
        self.recent.paths()
    }

    /// The playback clock.
    pub fn playback(&self) -> &Playback {
        &self.playback
    }

    /// The playhead, s.
    pub fn playhead_s(&self) -> f64 {
        self.playhead_s
    }

    /// Whether the "unsaved changes" question is showing.
    pub fn is_asking_to_discard(&self) -> bool {
        self.confirm.is_some()
    }

    /// The latest composition (possibly of an older version while recomposing).
    pub fn composition(&self) -> Option<&Composition> {
        self.composer.composition()
    }

    /// How long the last composition took on the worker thread.
    pub fn last_compose_time(&self) -> Option<std::time::Duration> {
        self.composer.last_duration
    }

    /// Wait for the composition in progress (for tests and batch use).
    pub fn wait_for_composition(&mut self) -> Option<&Composition> {
        if self.composer.is_busy() {
            self.composer.wait();
            self.generation += 1;
        }
        self.composer.composition()
    }

    /// Screen position of `tick` in the lane of `hand` on last frame's timeline.
    pub fn timeline_point(&self, tick: u64, hand: Hand) -> Option<egui::Pos2> {
        let g = self.timeline.geometry?;
        Some(g.point(tick as f64, selection::lane_of(hand)))
    }

    /// Screen position of world point `p` (m, performer frame) in last frame's 3D view.
    pub fn viewport_point(&self, p: glam::DVec3) -> Option<egui::Pos2> {
        self.viewport.screen_of(p)
    }

    /// Set the audio that playback plays (stereo interleaved, 48 kHz, e.g. an
    /// `Arc<Vec<f32>>`): the seam for the render pipeline.
    pub fn set_audio(
        &mut self,
        audio: Arc<dyn tape::StereoSource>,
    ) -> Result<(), playback::PlaybackError> {
        self.playback.set_audio(audio)
    }

    /// Move the playhead to `t_s` seconds.
    pub fn seek(&mut self, t_s: f64) {
        self.pending.push(Command::Seek(t_s));
        self.drain();
    }

    /// Show a simulated performance (poses and tips) instead of the IK pose: the seam for
    /// the render pipeline. `None` goes back to the IK pose of the composed targets.
    pub fn set_simulation(&mut self, simulated: Option<Simulated>) {
        self.simulated = simulated;
    }

    /// Take `rendering` as the rendering of the score as it is now, as if the render
    /// pipeline had just delivered it: its audio to playback, its body to the 3D view, all
    /// of it to the plots and File > Export (the seam for tests and batch use).
    pub fn set_rendering(&mut self, rendering: Arc<Rendering>) {
        self.accept_rendering(renderer::Rendered::new(rendering), true);
    }

    /// The latest rendering received, if any (possibly of an older version of the score).
    pub fn rendering(&self) -> Option<&Arc<Rendering>> {
        self.rendering.as_ref()
    }

    /// Why File > Export is unavailable now, or `None` when the current rendering can be
    /// exported.
    pub fn export_blocked(&self) -> Option<String> {
        if self.doc.is_none() {
            return Some("no score is open".into());
        }
        export::RenderState {
            rendering: self.rendering.as_deref(),
            current: self.rendering_current,
            busy: self.renderer.as_ref().is_some_and(|r| r.is_busy()),
            enabled: self.renderer.is_some(),
            error: self.render_error(),
        }
        .blocked()
    }

    /// Export the current rendering's sound as a WAV at `path` (File > Export WAV without
    /// the dialog); the outcome goes to the status bar, or the error to the window.
    pub fn export_wav_to(&mut self, path: &Path) {
        self.export_to(Export::Wav, path);
    }

    /// Export the current rendering's motion as CSV at `path` (File > Export motion CSV
    /// without the dialog); the outcome goes to the status bar, or the error to the window.
    pub fn export_motion_to(&mut self, path: &Path) {
        self.export_to(Export::Motion, path);
    }

    /// Export the score as a Standard MIDI File at `path` (File > Export MIDI without the
    /// dialog).
    pub fn export_midi_to(&mut self, path: &Path) {
        self.export_to(Export::Midi, path);
    }

    /// Export the current rendering's motion as C3D at `path` (File > Export motion C3D
    /// without the dialog).
    pub fn export_c3d_to(&mut self, path: &Path) {
        self.export_to(Export::MotionC3d, path);
    }

    fn export_to(&mut self, what: Export, path: &Path) {
        let blocked = match (&self.doc, what.needs_rendering()) {
            (None, _) => Some("no score is open".to_string()),
            (Some(_), true) => self.export_blocked(),
            (Some(_), false) => None,
        };
        if let Some(why) = blocked {
            self.error = Some(format!("cannot export: {why}"));
            return;
        }
        let Some(doc) = &self.doc else { return };
        let kit = doc.loaded.score.settings.kit(&doc.loaded.kit);
        let score = (&doc.loaded.score, kit.as_ref());
        match export::write(what, score, self.rendering.as_deref(), path) {
            Ok(done) => self.status = done,
            Err(e) => self.error = Some(e),
        }
    }

    /// Ask where to export, then export.
    fn export_dialog(&mut self, what: Export) {
        let Some(doc) = &self.doc else { return };
        if let Some(p) = export::ask_path(what, doc.path.as_deref(), &doc.loaded.score.title) {
            self.export_to(what, &p);
        }
    }

    /// The open plot tab.
    pub fn plot_tab(&self) -> PlotTab {
        self.plots.tab
    }

    /// Screen position of score time `t_s` on the open plot tab's first time plot, as drawn
    /// last frame (none when the tab shows no time plot).
    pub fn plot_point(&self, t_s: f64) -> Option<egui::Pos2> {
        self.plots.screen_of(t_s)
    }

    /// The time window (s) of the open plot tab's first time plot, as drawn last frame: the
    /// timeline's visible window (none when the tab shows no time plot).
    pub fn plot_time_window(&self) -> Option<(f64, f64)> {
        self.plots.time_window()
    }

    fn open_demo(&mut self) {
        let on_disk = Path::new(DEMO_SCORE_PATH);
        if on_disk.exists() {
            return self.open_path(on_disk);
        }
        match LoadedScore::parse(on_disk, DEMO_SCORE_TEXT) {
            Ok(loaded) => {
                self.set_document(loaded, None);
                self.status = "opened the bundled demo score".into();
            }
            Err(e) => self.error = Some(e.to_string()),
        }
    }

    fn set_document(&mut self, loaded: LoadedScore, path: Option<PathBuf>) {
        self.doc = Some(Document {
            loaded,
            path,
            history: History::new(),
        });
        self.selection = Selection::default();
        self.playback.pause();
        self.playback.seek(0.0);
        self.playhead_s = 0.0;
        self.loop_ticks = None;
        self.timeline.fit();
        self.error = None;
        self.simulated = None;
        self.rendering = None;
        self.render_error = None;
        self.waiting_to_play = false;
        self.recompose();
    }

    fn recompose(&mut self) {
        self.rendering_current = false;
        match &self.doc {
            Some(d) => {
                self.composer
                    .request(&d.loaded.score, &d.loaded.kit, self.ctx.clone());
                if let Some(r) = &mut self.renderer {
                    r.request(&d.loaded.score, &d.loaded.kit, self.ctx.clone());
                }
            }
            None => self.composer.clear(),
        }
    }

    /// Take a finished render: its audio to playback, its body to the view, all of it to
    /// the plots and export.
    fn take_render(&mut self) {
        let Some(renderer) = self.renderer.as_mut() else {
            return;
        };
        let Some(done) = renderer.poll() else {
            return;
        };
        // A newer request still running means this render is of an older version.
        let current = !renderer.is_busy();
        match done {
            Ok(r) => self.accept_rendering(r, current),
            Err(e) => {
                self.render_error = Some(renderer::Failure {
                    message: format!("render: {}", e.message),
                    ..e
                })
            }
        }
    }

    fn accept_rendering(&mut self, r: renderer::Rendered, current: bool) {
        self.render_error = None;
        self.simulated = Some(r.simulated);
        self.rendering = Some(r.rendering);
        self.rendering_id += 1;
        self.rendering_current = current;
        self.status = r.summary;
        // Swaps are seamless (a crossfade under the playhead), so every rendering is
        // heard at once, a new version or more of the one playing.
        self.load_audio();
    }

    /// Give playback the current rendering's audio (shared, not copied), and start
    /// playing if Space waits for audio that is now ready.
    fn load_audio(&mut self) {
        let Some(r) = &self.rendering else {
            return;
        };
        let ready_s = if r.complete { f64::INFINITY } else { r.ready_s };
        if let Err(e) = self
            .playback
            .set_audio(Arc::clone(r) as Arc<dyn tape::StereoSource>)
        {
            self.render_error = Some(renderer::Failure::of(format!("playback: {e}")));
            return;
        }
        self.audio_ready_s = ready_s;
        if self.waiting_to_play && self.playhead_s + PLAY_AHEAD_S <= self.audio_ready_s {
            self.waiting_to_play = false;
            self.playback.play_from(self.playhead_s);
        }
    }

    /// Select beat `b` and move the playhead just before it (the status bar's "Show beat"
    /// after a render error naming it).
    pub fn show_beat(&mut self, b: usize) {
        let Some(doc) = &self.doc else { return };
        let Some(beat) = doc.loaded.score.beats.get(b) else {
            return;
        };
        let t = doc.loaded.score.tempo_map().seconds_at(beat.tick as f64);
        self.pending.push(Command::Select(Selection::only(b)));
        self.pending.push(Command::Seek((t - 0.5).max(0.0)));
        self.drain();
    }

    fn is_rendering(&self) -> bool {
        self.renderer.as_ref().is_some_and(|r| r.is_busy())
    }

    /// The beat the latest render error names, if any.
    pub fn render_error_beat(&self) -> Option<usize> {
        self.render_error.as_ref().and_then(|f| f.beat)
    }

    /// Whether Space was pressed where the audio is not ready yet (playback starts once
    /// it is).
    pub fn is_waiting_to_play(&self) -> bool {
        self.waiting_to_play
    }

    /// Open a score (`.ron`) or import a MIDI file (`.mid`); errors go to the window.
    /// Unsaved changes are dropped (the UI asks first).
    pub fn open_path(&mut self, path: &Path) {
        match files::read(path) {
            Ok(opened) => {
                self.set_document(opened.loaded, opened.path.clone());
                self.status = opened.message;
                if let Some(p) = &opened.path
                    && let Err(e) = self.recent.add(p)
                {
                    self.status = e;
                }
            }
            Err(e) => self.error = Some(e),
        }
    }

    /// Handle a file dropped on the window: scores open, MIDI files import, anything else
    /// is an error shown in the window. Asks first if there are unsaved changes.
    pub fn handle_dropped(&mut self, path: &Path) {
        match kind_of(path) {
            FileKind::Other => {
                self.error = Some(format!(
                    "{}: drop a score (.ron) or a MIDI file (.mid)",
                    path.display()
                ))
            }
            _ => self.after_confirm(AfterConfirm::Open(path.to_path_buf())),
        }
    }

    /// Save the score to `path` (Save As without a dialog); errors go to the window.
    pub fn save_to(&mut self, path: &Path) {
        let Some(doc) = &mut self.doc else { return };
        match doc.loaded.score.save(path) {
            Ok(()) => {
                self.status = format!("saved {}", path.display());
                doc.path = Some(path.to_path_buf());
                doc.history.set_saved();
                if let Err(e) = self.recent.add(path) {
                    self.status = e;
                }
            }
            Err(e) => self.error = Some(e.to_string()),
        }
    }

    fn save(&mut self, ask: bool) {
        let Some(doc) = &self.doc else { return };
        let target = match (&doc.path, ask) {
            (Some(p), false) => Some(p.clone()),
            _ => rfd::FileDialog::new()
                .add_filter("timpanist score", &["ron"])
                .save_file(),
        };
        if let Some(t) = target {
            self.save_to(&t);
        }
    }

    fn new_document(&mut self) {
        let kit = Kit::bundled("standard").expect("the standard kit is bundled");
        let loaded = LoadedScore {
            score: Score::new("Untitled"),
            kit,
            kit_source: "bundled kit \"standard\"".into(),
            notices: Vec::new(),
        };
        self.set_document(loaded, None);
        self.status = "new score".into();
    }

    /// Ask to quit: true if the editor may close now; with unsaved changes it asks first.
    pub fn request_quit(&mut self) -> bool {
        if self.is_dirty() && !self.allow_close {
            self.confirm = Some(AfterConfirm::Quit);
            false
        } else {
            true
        }
    }

    /// Run `what` now, or ask first when there are unsaved changes.
    fn after_confirm(&mut self, what: AfterConfirm) {
        if self.is_dirty() {
            self.confirm = Some(what);
        } else {
            self.run_confirmed(what);
        }
    }

    fn run_confirmed(&mut self, what: AfterConfirm) {
        match what {
            AfterConfirm::Quit => {
                self.allow_close = true;
                if let Some(ctx) = &self.ctx {
                    ctx.send_viewport_cmd(egui::ViewportCommand::Close);
                }
            }
            AfterConfirm::New => self.new_document(),
            AfterConfirm::Open(p) => self.open_path(&p),
            AfterConfirm::OpenDialog => {
                if let Some(p) = rfd::FileDialog::new()
                    .add_filter("score or MIDI", &["ron", "mid", "midi"])
                    .pick_file()
                {
                    self.open_path(&p);
                }
            }
        }
    }

    fn window_title(&self) -> String {
        match &self.doc {
            Some(d) => format!(
                "timpanist - {}{} - {}",
                d.loaded.score.title,
                if d.history.is_saved() { "" } else { " *" },
                d.path
                    .as_ref()
                    .map_or("not saved".into(), |p| p.display().to_string())
            ),
            None => "timpanist".into(),
        }
    }

    /// Apply the queued commands (once per frame).
    fn drain(&mut self) {
        let mut edited = false;
        for cmd in std::mem::take(&mut self.pending) {
            match cmd {
                Command::Gesture => {
                    if let Some(d) = &mut self.doc {
                        d.history.begin_gesture();
                    }
                }
                Command::Edit(e) => {
                    if let Some(d) = &mut self.doc {
                        d.history.apply(&mut d.loaded.score, e);
                        edited = true;
                    }
                }
                Command::Select(s) => self.selection = s,
                Command::Do(a) => edited |= self.act(a),
                Command::Seek(t) => {
                    self.playhead_s = t.max(0.0);
                    self.playback.seek(self.playhead_s);
                }
                Command::SetLoop(r) => {
                    self.loop_ticks = r;
                    self.looping = r.is_some();
                }
            }
        }
        if edited {
            if let Some(d) = &self.doc {
                self.selection
                    .clamp(d.loaded.score.beats.len(), d.loaded.score.handles.len());
            }
            self.recompose();
        }
    }

    /// Push a change of all beats with a new selection, as one gesture.
    fn push_beats(
        &mut self,
        after: Vec<crate::score::Beat>,
        sel: std::collections::BTreeSet<usize>,
    ) {
        let Some(d) = &mut self.doc else { return };
        if after == d.loaded.score.beats {
            return;
        }
        d.history.begin_gesture();
        let before = d.loaded.score.beats.clone();
        d.history
            .apply(&mut d.loaded.score, ScoreEdit::SetBeats { before, after });
        self.selection = Selection {
            beats: sel,
            handle: None,
        };
    }

    /// Do `action`; true if the score changed.
    fn act(&mut self, action: Action) -> bool {
        use Action::*;
        match action {
            PlayPause => {
                if self.playback.is_playing() {
                    self.playback.pause();
                    self.playhead_s = self.playback.position_s();
                } else if self.waiting_to_play {
                    self.waiting_to_play = false;
                    self.status = "playback cancelled".into();
                } else if self.playhead_s + PLAY_AHEAD_S > self.audio_ready_s {
                    self.waiting_to_play = true;
                    self.status = format!(
                        "waiting for the audio at {:.1} s (ready to {:.1} s)",
                        self.playhead_s, self.audio_ready_s
                    );
                } else {
                    self.playback.play_from(self.playhead_s);
                }
                return false;
            }
            New => self.after_confirm(AfterConfirm::New),
            Open => self.after_confirm(AfterConfirm::OpenDialog),
            Save => self.save(false),
            SaveAs => self.save(true),
            ToggleHelp => self.show_help = !self.show_help,
            ClearSelection => {
                self.selection = Selection::default();
                self.show_help = false;
            }
            _ => {}
        }
        if matches!(
            action,
            PlayPause | New | Open | Save | SaveAs | ToggleHelp | ClearSelection
        ) {
            // New and Open recompose themselves.
            return false;
        }
        let grid = match &self.doc {
            Some(d) => self.timeline.grid_ticks(&d.loaded),
            None => return false,
        };
        let Some(d) = &mut self.doc else { return false };
        let beats = d.loaded.score.beats.clone();
        let sel = self.selection.beats.clone();
        match action {
            Undo | Redo => {
                let done = if action == Undo {
                    d.history.undo(&mut d.loaded.score)
                } else {
                    d.history.redo(&mut d.loaded.score)
                };
                self.status = match (done, action == Undo) {
                    (true, true) => "undone".into(),
                    (true, false) => "redone".into(),
                    (false, true) => "nothing to undo".into(),
                    (false, false) => "nothing to redo".into(),
                };
                self.selection = Selection::default();
                return done;
            }
            Delete => {
                if !sel.is_empty() {
                    self.push_beats(selection::deleted(&beats, &sel), Default::default());
                } else if let Some(h) = self.selection.handle {
                    d.history.begin_gesture();
                    d.history.apply(
                        &mut d.loaded.score,
                        ScoreEdit::RemoveHandle {
                            index: h,
                            removed: None,
                        },
                    );
                    self.selection = Selection::default();
                }
            }
            Copy => {
                self.clipboard = Clipboard::copy(&beats, &sel);
                self.status = format!("copied {} beat(s)", self.clipboard.len());
                return false;
            }
            Paste if self.clipboard.is_empty() => {
                self.status = "nothing to paste: copy beats first (Ctrl+C)".into();
                return false;
            }
            Paste => {
                let tick = snap(d.loaded.score.tempo_map().tick_at(self.playhead_s), grid);
                let (after, new_sel) = selection::inserted(&beats, &self.clipboard.placed_at(tick));
                self.push_beats(after, new_sel);
            }
            Duplicate => {
                if let Some(tick) = clipboard::duplicate_tick(&beats, &sel, grid) {
                    let copy = Clipboard::copy(&beats, &sel).placed_at(tick);
                    let (after, new_sel) = selection::inserted(&beats, &copy);
                    self.push_beats(after, new_sel);
                }
            }
            SelectAll => {
                self.selection = Selection {
                    beats: (0..beats.len()).collect(),
                    handle: None,
                };
                return false;
            }
            Nudge(n) => {
                let (after, s) = selection::moved(&beats, &sel, n * grid as i64, 0);
                self.push_beats(after, s);
            }
            NudgeLane(n) => {
                let (after, s) = selection::moved(&beats, &sel, 0, n);
                self.push_beats(after, s);
            }
            SetMode(m) => {
                let (after, s) = selection::modify(&beats, &sel, |b| b.mode = m);
                self.push_beats(after, s);
            }
            _ => return false,
        }
        true
    }

    fn menu_bar(&mut self, ui: &mut egui::Ui) {
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
                if ui.button("Import MIDI...").clicked()
                    && let Some(p) = rfd::FileDialog::new()
                        .add_filter("MIDI", &["mid", "midi"])
                        .pick_file()
                {
                    self.after_confirm(AfterConfirm::Open(p));
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
            });
            ui.menu_button("View", |ui| {
                if ui.button("Fit the score in the timeline").clicked() {
                    self.timeline.fit();
                }
                if ui.button("Reset the 3D camera").clicked() {
                    self.viewport.camera = Camera::default();
                }
                ui.checkbox(&mut self.timeline.snap, "Snap to grid");
            });
            ui.menu_button("Help", |ui| {
                if ui.button("Keyboard and mouse  (F1)").clicked() {
                    self.show_help = true;
                }
            });
        });
    }

    fn transport(&mut self, ui: &mut egui::Ui) {
        ui.horizontal(|ui| {
            let playing = self.playback.is_playing();
            if ui.button(if playing { "Pause" } else { "Play" }).clicked() {
                self.pending.push(Command::Do(Action::PlayPause));
            }
            if ui.button("To start").clicked() {
                self.pending.push(Command::Seek(0.0));
            }
            let position = self.doc.as_ref().map(|d| {
                let s = &d.loaded.score;
                let tick = s.tempo_map().tick_at(self.playhead_s).max(0.0) as u64;
                s.meter_map().position(tick).to_string()
            });
            ui.monospace(format!(
                "{:7.2} s  {}",
                self.playhead_s,
                position.unwrap_or_default()
            ));
            ui.separator();
            ui.add_enabled(
                self.loop_ticks.is_some(),
                egui::Checkbox::new(&mut self.looping, "Loop"),
            )
            .on_hover_text("Shift+drag on the ruler sets the loop region");
            ui.checkbox(&mut self.timeline.snap, "Snap");
            if ui.button("Zoom in").clicked() {
                self.timeline.zoom(0.7);
            }
            if ui.button("Zoom out").clicked() {
                self.timeline.zoom(1.4);
            }
            if ui.button("Fit").clicked() {
                self.timeline.fit();
            }
            ui.separator();
            if ui.button("Help (F1)").clicked() {
                self.show_help = !self.show_help;
            }
        });
    }

    fn status_bar(&mut self, ui: &mut egui::Ui) {
        let mut show = None;
        ui.horizontal(|ui| {
            if let Some(n) = self.playback.notice() {
                ui.colored_label(ui.visuals().warn_fg_color, n);
                ui.separator();
            }
            if self.composer.is_busy() {
                ui.spinner();
                ui.label("composing");
                ui.separator();
            } else if let Some(d) = self.composer.last_duration {
                ui.label(format!("composed in {:.0} ms", d.as_secs_f64() * 1e3));
                ui.separator();
            }
            if self.is_rendering() {
                ui.spinner();
                ui.label("rendering sound and motion");
                ui.separator();
            }
            if self.is_dirty() {
                ui.label("unsaved changes");
                ui.separator();
            }
            ui.label(&self.status);
            // Last, cut to the width left (in full on hover), after its button.
            if let Some(e) = self.render_error.as_ref().filter(|_| !self.is_rendering()) {
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

    /// Follow the playback clock: move the playhead, wrap at the loop end, stop at the end.
    fn follow_playback(&mut self, ctx: &egui::Context) {
        if !self.playback.is_playing() {
            return;
        }
        self.playhead_s = self.playback.position_s();
        if let Some(d) = &self.doc {
            let map = d.loaded.score.tempo_map();
            if self.looping
                && let Some((a, b)) = self.loop_ticks
                && self.playhead_s >= map.seconds_at(b as f64)
            {
                let start = map.seconds_at(a as f64);
                self.playback.play_from(start);
                self.playhead_s = start;
            } else if self.playhead_s > d.loaded.score.duration_s() + 1.0 {
                self.playback.pause();
            }
            self.timeline.follow(map.tick_at(self.playhead_s));
        }
        ctx.request_repaint();
    }

    fn confirm_dialog(&mut self, ctx: &egui::Context) {
        let Some(what) = self.confirm.clone() else {
            return;
        };
        let mut choice = None;
        egui::Modal::new(egui::Id::unique("unsaved-changes")).show(ctx, |ui| {
            ui.heading("Unsaved changes");
            ui.label("The score has changes that are not saved.");
            ui.horizontal(|ui| {
                if ui.button("Save").clicked() {
                    choice = Some(0);
                }
                if ui.button("Discard changes").clicked() {
                    choice = Some(1);
                }
                if ui.button("Cancel").clicked() {
                    choice = Some(2);
                }
            });
        });
        match choice {
            Some(0) => {
                self.save(false);
                if !self.is_dirty() {
                    self.confirm = None;
                    self.run_confirmed(what);
                }
            }
            Some(1) => {
                self.confirm = None;
                if let Some(d) = &mut self.doc {
                    d.history.set_saved();
                }
                self.run_confirmed(what);
            }
            Some(2) => self.confirm = None,
            _ => {}
        }
    }

    fn central(&mut self, ui: &mut egui::Ui) {
        if let Some(err) = self.error.clone() {
            ui.horizontal(|ui| {
                ui.colored_label(ui.visuals().error_fg_color, format!("Error: {err}"));
                if ui.small_button("Dismiss").clicked() {
                    self.error = None;
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
        let comp = self.composer.composition();
        let simulated_pose = self
            .simulated
            .as_ref()
            .and_then(|s| s.pose_at(self.playhead_s))
            .copied();
        let pose = simulated_pose.or_else(|| {
            comp.map(|c| {
                *self.ik.pose(
                    &self.viewport.body().skeleton,
                    c,
                    self.generation,
                    self.playhead_s,
                )
            })
        });
        self.viewport.show(
            ui,
            rect,
            &viewport::ViewportInput {
                doc: loaded,
                composition: comp,
                generation: self.generation,
                pose: pose.as_ref(),
                simulated: self.simulated.as_ref().map(|s| &s.motion().tips),
                drums: (self.simulated.as_ref())
                    .and_then(|s| s.rendering())
                    .map(|r| &r.drums),
                selection: &self.selection,
                time_s: self.playhead_s,
            },
            &mut self.pending,
        );
        ui.add_space(4.0);
        self.timeline.show(
            ui,
            &timeline::TimelineInput {
                doc: loaded,
                selection: &self.selection,
                playhead_s: self.playhead_s,
                loop_ticks: self.loop_ticks,
            },
            &mut self.pending,
        );
        if let Some(axis) = self.timeline.axis() {
            let grid = if self.timeline.snap {
                self.timeline.grid_ticks(loaded)
            } else {
                1
            };
            self.tempo_lane.show(
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
        let window = self.timeline.geometry.map(|g| {
            let t = |x: f32| map.seconds_at(g.axis.tick_of(f64::from(x)).max(0.0));
            (t(g.lanes.left()), t(g.lanes.right()))
        });
        let busy = self.renderer.as_ref().is_some_and(|r| r.is_busy());
        let note = match (self.render_error(), busy, &self.renderer) {
            (Some(e), _, _) => Some(e.to_string()),
            (None, true, _) => Some("rendering sound and motion...".to_string()),
            (None, false, None) => Some("rendering is turned off".to_string()),
            (None, false, Some(_)) => None,
        };
        let input = plots::PlotInput {
            composition: match (comp, self.composer.error()) {
                (_, Some(e)) => Err(e),
                (Some(c), None) => Ok(Some((c, self.generation))),
                (None, None) => Ok(None),
            },
            rendering: self.rendering.as_deref().map(|r| (r, self.rendering_id)),
            rendering_current: self.rendering_current,
            rendering_busy: busy,
            rendering_note: note.as_deref(),
            link: plots::linked::TimeLink {
                window,
                playhead_s: self.playhead_s,
            },
            selected_beats: &self.selection.beats,
        };
        if let Some(t) = self.plots.show(ui, &input) {
            self.pending.push(Command::Seek(t));
        }
    }
}

impl eframe::App for EditorApp {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        let ctx = ui.ctx().clone();
        if self.ctx.is_none() {
            self.ctx = Some(ctx.clone());
        }
        if self.composer.poll() {
            self.generation += 1;
        }
        self.take_render();
        if self.composer.is_busy() {
            ctx.request_repaint_after(std::time::Duration::from_millis(30));
        }
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
        if self.confirm.is_none() {
            for a in keys::take_actions(&ctx) {
                self.pending.push(Command::Do(a));
            }
        }
        let title = self.window_title();
        if title != self.shown_title {
            ctx.send_viewport_cmd(egui::ViewportCommand::Title(title.clone()));
            self.shown_title = title;
        }
        self.follow_playback(&ctx);

        egui::Panel::top("menu").show(ui, |ui| {
            self.menu_bar(ui);
            self.transport(ui);
        });
        egui::Panel::bottom("status").show(ui, |ui| self.status_bar(ui));
        egui::Panel::right("inspector")
            .default_size(300.0)
            .show(ui, |ui| {
                egui::ScrollArea::vertical().show(ui, |ui| {
                    if let Some(d) = &self.doc {
                        inspector::show(ui, &d.loaded, &self.selection, &mut self.pending);
                    }
                });
            });
        egui::CentralPanel::default_margins().show(ui, |ui| self.central(ui));

        self.drain();
        self.confirm_dialog(&ctx);
        keys::help_window(&ctx, &mut self.show_help);
    }
}

/// Open the editor window on `score` (or the demo score) and run until it closes.
pub fn run(score: Option<PathBuf>) -> anyhow::Result<()> {
    let options = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_inner_size([1400.0, 900.0])
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
