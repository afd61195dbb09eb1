//! The document's life in the window: opening (files, drops, the demo, new scores),
//! saving and exporting through background jobs, asking before unsaved changes are lost,
//! and quitting only once every file being written is written. Also where the pipeline's
//! and the jobs' results are taken in, once per frame.

use super::dialogs::{Asked, Purpose, Request};
use super::document::Document;
use super::export::{self, Export};
use super::files::{self, FileKind, kind_of};
use super::jobs::{Done, Finished};
use super::renderer::Rendered;
use super::{AfterConfirm, DEMO_SCORE_PATH, EditorApp, viewport};
use crate::kit::Kit;
use crate::score::{LoadedScore, Score, ViewSettings};
use eframe::egui;
use std::path::{Path, PathBuf};

impl EditorApp {
    pub(super) fn open_demo(&mut self) {
        let on_disk = Path::new(DEMO_SCORE_PATH);
        if on_disk.exists() {
            return self.open_path(on_disk);
        }
        let text = crate::score::demos::text("etude-modes").expect("etude-modes is a demo");
        match LoadedScore::parse(on_disk, text) {
            Ok(loaded) => {
                self.set_document(loaded, None);
                self.messages.status = "opened the bundled demo score".into();
            }
            Err(e) => self.messages.error = Some(e.to_string()),
        }
    }

    fn set_document(&mut self, loaded: LoadedScore, path: Option<PathBuf>) {
        let saved = (loaded.score.view.as_ref())
            .and_then(|v| v.camera.as_ref())
            .and_then(viewport::camera_of_saved);
        if let Some(camera) = saved {
            self.views.viewport.hold();
            self.views.viewport.camera = camera;
        }
        self.doc = Some(Document::new(loaded, path));
        self.recovery.restart();
        self.transport.reset();
        self.views.timeline.fit();
        self.views.simulated = None;
        self.views.previous = None;
        self.views.shown_complete = false;
        self.messages.error = None;
        self.pipeline.forget_rendering();
        self.recompose();
    }

    /// Ask the pipeline for the score as it is now.
    pub(super) fn recompose(&mut self) {
        match &self.doc {
            Some(d) => self.pipeline.request(&d.loaded),
            None => self.pipeline.clear(),
        }
    }

    /// Take what the pipeline and the writing jobs finished.
    pub(super) fn take_results(&mut self) {
        if let Some(r) = self.pipeline.poll() {
            self.show_rendering(r);
        }
        for finished in self.jobs.poll() {
            self.job_finished(finished);
        }
        if let Some(outcome) = self.opening.as_ref().and_then(|o| o.poll()) {
            self.take_opened(outcome);
        }
    }

    /// Show a rendering the pipeline took: its body in the view, its summary in the status
    /// bar, its audio to playback. Swaps are seamless (a crossfade under the playhead), so
    /// every rendering is heard at once, a new version or more of the one playing.
    pub(super) fn show_rendering(&mut self, r: Rendered) {
        // A complete rendering replaced by a new one is the score before the edit: kept
        // for View > Overlay the previous rendering (the steps of one rendering are not).
        if self.views.shown_complete {
            self.views.previous = self.views.simulated.take();
        }
        self.views.shown_complete = r.complete;
        self.views.simulated = Some(r.simulated);
        self.messages.status = r.summary;
        if let Err(e) = self.transport.load(&r.rendering) {
            self.pipeline.playback_failed(format!("playback: {e}"));
        }
    }

    pub(super) fn job_finished(&mut self, Finished { done, result }: Finished) {
        match result {
            Ok(status) => self.messages.status = status,
            Err(e) => {
                self.messages.error = Some(e.to_string());
                self.after_save = None;
                self.quitting = false;
                return;
            }
        }
        if let Done::Saved { path, revision } = done {
            if let Some(doc) = &mut self.doc {
                doc.mark_saved(revision, path.clone());
            }
            if let Err(e) = self.recent.add(&path) {
                self.messages.status = e.to_string();
            }
            if let Some(what) = self.after_save.take() {
                self.run_confirmed(what);
            }
        }
    }

    /// Open a score (`.ron`) or import a MIDI (`.mid`), MusicXML or recording file;
    /// errors go to the window. A recording is transcribed on a thread while a dialog
    /// shows ([`super::opening`]); the rest open at once. Unsaved changes are dropped (the
    /// UI asks first).
    pub fn open_path(&mut self, path: &Path) {
        if let Some(busy) = &self.opening {
            self.messages.error = Some(format!(
                "{}: wait until {} is read, or cancel it",
                path.display(),
                busy.path().display()
            ));
            return;
        }
        if kind_of(path) == FileKind::Audio {
            let wake = self
                .ctx
                .clone()
                .map(|ctx| Box::new(move || ctx.request_repaint()) as Box<dyn Fn() + Send>);
            self.opening = Some(super::opening::Opening::start(path, wake));
            return;
        }
        match files::read(path) {
            Ok(opened) => self.open_document(opened),
            Err(e) => self.messages.error = Some(e.to_string()),
        }
    }

    /// Take the recording read on its thread, if it is read: as the document, or its
    /// error in the window.
    fn take_opened(&mut self, outcome: super::opening::Outcome) {
        self.opening = None;
        match outcome {
            Ok(opened) => self.open_document(opened),
            Err(e) => self.messages.error = Some(e),
        }
    }

    /// Block until a recording being read is read and open it (tests and batch use).
    pub(super) fn wait_for_opening(&mut self) {
        if let Some(opening) = self.opening.take() {
            self.take_opened(opening.wait());
        }
    }

    /// The dialog shown while a recording is read: its name, the time so far, Cancel
    /// (the document on screen stays; the thread's result is dropped).
    pub(super) fn opening_dialog(&mut self, ctx: &egui::Context) {
        let Some(opening) = &self.opening else {
            return;
        };
        let name = opening.path().file_name().map_or_else(
            || opening.path().display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        );
        let seconds = opening.elapsed().as_secs_f64();
        let mut cancel = false;
        egui::Modal::new(egui::Id::unique("opening-recording")).show(ctx, |ui| {
            ui.heading("Transcribing a recording");
            ui.horizontal(|ui| {
                ui.spinner();
                ui.label(format!("{name}: {seconds:.0} s"));
            });
            ui.label("Finding the strokes, their drums, pitches and dynamics, and the beat.");
            if ui.button("Cancel").clicked() || ui.input(|i| i.key_pressed(egui::Key::Escape)) {
                cancel = true;
            }
        });
        if cancel {
            self.messages.status = format!("cancelled reading {name}");
            self.opening = None;
        } else {
            ctx.request_repaint_after(std::time::Duration::from_millis(250));
        }
    }

    /// Show a document read (or imported) already.
    pub fn open_document(&mut self, opened: files::Opened) {
        self.set_document(opened.loaded, opened.path.clone());
        self.messages.status = opened.message;
        if let Some(p) = &opened.path
            && let Err(e) = self.recent.add(p)
        {
            self.messages.status = e.to_string();
        }
    }

    /// Handle a file dropped on the window: scores open, MIDI files import, anything else
    /// is an error shown in the window. Asks first if there are unsaved changes.
    pub fn handle_dropped(&mut self, path: &Path) {
        match kind_of(path) {
            FileKind::Other => {
                self.messages.error = Some(format!(
                    "{}: drop a score (.ron), a MIDI file (.mid), a MusicXML file (.musicxml, .xml, .mxl) or a recording (.wav, .aiff, .flac, .mp3, .ogg)",
                    path.display()
                ))
            }
            _ => self.after_confirm(AfterConfirm::Open(path.to_path_buf())),
        }
    }

    /// Save the score to `path` (Save As without a dialog) on a background job; the
    /// outcome goes to the status bar, or the error to the window. The 3D camera is saved
    /// with the score (`view`).
    pub fn save_to(&mut self, path: &Path) {
        let camera = viewport::saved_camera(&self.views.viewport.camera);
        let Some(doc) = &mut self.doc else { return };
        // The camera is saved as it is, not as an edit (no undo step, nothing unsaved).
        doc.loaded.score.view = Some(ViewSettings {
            camera: Some(camera),
        });
        let text = doc.loaded.score.to_ron();
        let target = path.to_path_buf();
        let done = Done::Saved {
            path: target.clone(),
            revision: doc.revision(),
        };
        self.jobs
            .spawn(format!("saving {}", path.display()), done, move || {
                crate::base::ron_file::write_atomic(&target, text.as_bytes())
                    .map(|()| format!("saved {}", target.display()))
            });
    }

    /// Save where the score is saved, or ask where (always with `ask`); false if the user
    /// cancelled the dialog.
    pub(super) fn save(&mut self, ask: bool) -> bool {
        let Some(doc) = &self.doc else { return false };
        if let (Some(p), false) = (&doc.path, ask) {
            let p = p.clone();
            self.save_to(&p);
            return true;
        }
        let request = Request {
            purpose: Purpose::SaveScore,
            title: "Save score as",
            filter: ("timpanist score", &["ron"]),
            save: true,
            file_name: Some(format!("{}.ron", file_stem(doc))),
            folder: doc
                .path
                .as_deref()
                .and_then(Path::parent)
                .map(Path::to_path_buf),
        };
        match self.ask_file(request) {
            Asked::Chosen(_, p) => {
                self.save_to(&p);
                true
            }
            Asked::Cancelled(_) => false,
            Asked::InWindow => true,
        }
    }

    /// Ask for a file with the system's dialog or the in-window one; the answer, when the
    /// system's gave one.
    pub(super) fn ask_file(&mut self, request: Request) -> Asked {
        let asked = self.dialogs.ask(request, self.recent.paths());
        if let Some(notice) = self.dialogs.take_notice() {
            self.messages.status = notice;
        }
        asked
    }

    /// Ask for a file and act on the answer when it comes (open, save or export).
    pub(super) fn ask_and_act(&mut self, request: Request) {
        let asked = self.ask_file(request);
        self.act_on_file(asked);
    }

    /// Draw the in-window file browser, if open, and act on its answer.
    pub(super) fn file_dialog(&mut self, ctx: &egui::Context) {
        if let Some(asked) = self.dialogs.show(ctx) {
            self.act_on_file(asked);
        }
    }

    fn act_on_file(&mut self, asked: Asked) {
        match asked {
            Asked::Chosen(Purpose::Open, p) => self.after_confirm(AfterConfirm::Open(p)),
            Asked::Chosen(Purpose::SaveScore, p) => self.save_to(&p),
            Asked::Chosen(Purpose::Export(what), p) => self.export_to(what, &p),
            // A save asked for before going on (quit, new, open): ask again.
            Asked::Cancelled(Purpose::SaveScore) => {
                if let Some(what) = self.after_save.take() {
                    self.confirm = Some(what);
                }
            }
            Asked::Cancelled(_) | Asked::InWindow => {}
        }
    }

    /// Export `what` to `path` on a background job (File > Export without the dialog);
    /// refused with the reason when there is nothing current to export.
    pub fn export_to(&mut self, what: Export, path: &Path) {
        let Some(doc) = &self.doc else {
            self.messages.error = Some("cannot export: no score is open".into());
            return;
        };
        if let Some(why) = what
            .needs_rendering()
            .then(|| self.export_blocked())
            .flatten()
        {
            self.messages.error = Some(format!("cannot export: {why}"));
            return;
        }
        let score = doc.loaded.score.clone();
        let kit = score.kit(&doc.loaded.kit).into_owned();
        let rendering = self.pipeline.rendering().map(|(r, _)| r.clone());
        let target = path.to_path_buf();
        let label = format!("exporting {}", path.display());
        let camera = self.views.viewport.camera;
        self.jobs.spawn(label, Done::Exported, move || {
            export::write(what, (&score, &kit), rendering.as_deref(), &target, camera)
        });
    }

    /// Ask where to export, then export.
    pub(super) fn export_dialog(&mut self, what: Export) {
        let Some(doc) = &self.doc else { return };
        let mut request = export::request(what, doc.path.as_deref(), &file_stem(doc));
        if let Some(folder) = &self.settings.prefs.export_folder {
            request.folder = Some(folder.clone());
        }
        self.ask_and_act(request);
    }

    fn new_document(&mut self) {
        let name = self.settings.prefs.default_kit.clone();
        let kit = Kit::bundled(&name)
            .or_else(|| Kit::bundled("standard"))
            .expect("the standard kit is bundled");
        let loaded = LoadedScore {
            score: Score {
                kit: name.clone(),
                ..Score::new("Untitled")
            },
            kit,
            kit_source: format!("bundled kit \"{name}\""),
            notices: Vec::new(),
        };
        self.set_document(loaded, None);
        self.messages.status = "new score".into();
    }

    /// Ask to quit: true if the editor may close now. With unsaved changes it asks first;
    /// while files are being written it waits for them, then closes.
    pub fn request_quit(&mut self) -> bool {
        if self.jobs.is_busy() {
            self.quitting = true;
            false
        } else if self.is_dirty() {
            self.quitting = false;
            self.confirm = Some(AfterConfirm::Quit);
            false
        } else {
            self.forget_autosave();
            true
        }
    }

    /// Nothing is left to recover (a clean quit): remove the autosave.
    fn forget_autosave(&mut self) {
        if let Err(e) = self.recovery.remove() {
            self.messages.status = format!("autosave: {e}");
        }
    }

    /// At start: offer back a score the last session left unsaved (a crash, a kill, a
    /// power cut). An autosave that cannot be read is reported and kept.
    pub(super) fn find_left_behind(&mut self) {
        match self.recovery.left_behind() {
            Some(Ok(recovered)) => {
                let from = recovered
                    .original
                    .as_ref()
                    .map_or("an untitled score".to_string(), |p| p.display().to_string());
                eprintln!("timpanist: the autosave holds unsaved changes to {from}: offered back");
                self.restore_offer = Some(recovered);
            }
            Some(Err(e)) => {
                self.messages.error = Some(format!("the autosave could not be read: {e}"))
            }
            None => {}
        }
    }

    /// Write the score to the autosave once it has been left alone a moment after a
    /// change, and wake the window to do it.
    pub(super) fn autosave(&mut self, ctx: &egui::Context) {
        let now = ctx.input(|i| i.time);
        match self.recovery.tick(self.doc.as_ref(), now) {
            Ok(true) => self.messages.status = "changes autosaved".into(),
            Ok(false) => {}
            Err(e) => self.messages.status = format!("autosave failed: {e}"),
        }
        if self.recovery.waiting(self.doc.as_ref()) {
            ctx.request_repaint_after(std::time::Duration::from_millis(500));
        }
    }

    /// Whether a score left unsaved by the last session is being offered back.
    pub fn restore_offered(&self) -> bool {
        self.restore_offer.is_some()
    }

    /// Answer the offer: restore the score the last session left (it opens with its
    /// changes unsaved, under its own file name), or discard it.
    pub fn answer_restore(&mut self, restore: bool) {
        let Some(recovered) = self.restore_offer.take() else {
            return;
        };
        if restore {
            let from = recovered
                .original
                .as_ref()
                .map_or("an untitled score".to_string(), |p| p.display().to_string());
            self.set_document(recovered.loaded, recovered.original);
            self.recovery.adopt();
            if let Some(doc) = &mut self.doc {
                doc.history.mark_unsaved();
            }
            self.messages.status = format!("restored the unsaved changes to {from}");
        } else {
            self.forget_autosave();
            self.messages.status = "discarded the autosaved changes".into();
        }
    }

    /// Run `what` now, or ask first when there are unsaved changes.
    pub(super) fn after_confirm(&mut self, what: AfterConfirm) {
        if self.is_dirty() {
            self.confirm = Some(what);
        } else {
            self.run_confirmed(what);
        }
    }

    fn run_confirmed(&mut self, what: AfterConfirm) {
        match what {
            AfterConfirm::Quit => {
                self.quitting = true;
                self.forget_autosave();
                if let Some(ctx) = &self.ctx
                    && !self.jobs.is_busy()
                {
                    ctx.send_viewport_cmd(egui::ViewportCommand::Close);
                }
            }
            AfterConfirm::New => self.new_document(),
            AfterConfirm::Open(p) => self.open_path(&p),
            AfterConfirm::OpenDemo(name) => match crate::score::demos::load(name) {
                Ok(loaded) => {
                    self.set_document(loaded, None);
                    self.messages.status = format!("opened the demo score {name} (unsaved)");
                }
                Err(e) => self.messages.error = Some(e.to_string()),
            },
            AfterConfirm::OpenDialog => self.ask_and_act(Request {
                purpose: Purpose::Open,
                title: "Open a score, MIDI, MusicXML or recording",
                filter: (
                    "score, MIDI, MusicXML or recording",
                    &crate::io::open::OPENABLE_EXTENSIONS,
                ),
                save: false,
                file_name: None,
                folder: self
                    .doc
                    .as_ref()
                    .and_then(|d| d.path.as_deref()?.parent())
                    .map(Path::to_path_buf),
            }),
        }
    }

    /// The "unsaved changes" answer: save first (then go on once saved), discard, or
    /// cancel.
    pub(super) fn answer_confirm(&mut self, answer: ConfirmAnswer) {
        let Some(what) = self.confirm.take() else {
            return;
        };
        match answer {
            ConfirmAnswer::Save => {
                if self.save(false) {
                    self.after_save = Some(what);
                } else {
                    self.confirm = Some(what);
                }
            }
            ConfirmAnswer::Discard => {
                if let Some(d) = &mut self.doc {
                    d.history.set_saved();
                }
                self.run_confirmed(what);
            }
            ConfirmAnswer::Cancel => {}
        }
    }
}

/// The answers to "unsaved changes".
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ConfirmAnswer {
    Save,
    Discard,
    Cancel,
}

/// The name files made from `doc` start with: its file's stem, else its title.
fn file_stem(doc: &Document) -> String {
    doc.path
        .as_deref()
        .and_then(Path::file_stem)
        .and_then(|s| s.to_str())
        .unwrap_or(&doc.loaded.score.title)
        .to_string()
}
