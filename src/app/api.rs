//! What tests and batch use see of the editor and drive without the mouse: the document,
//! the pipeline's results, the transport, where things were drawn last frame, and the
//! seams that hand the editor a rendering or audio as the pipeline would.

use super::command::Command;
use super::export::{self, Export};
use super::playback::{Playback, PlaybackError};
use super::renderer::Rendered;
use super::selection::{self, Selection};
use super::{Camera, EditorApp, PlotTab, Simulated, tape, viewport};
use crate::motion::compose::Composition;
use crate::render::Rendering;
use crate::score::{Hand, LoadedScore};
use eframe::egui;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// The selection when no document is open.
static NOTHING_SELECTED: Selection = Selection {
    beats: std::collections::BTreeSet::new(),
    handle: None,
};

impl EditorApp {
    /// The loaded score, if any.
    pub fn loaded(&self) -> Option<&LoadedScore> {
        self.doc.as_ref().map(|d| &d.loaded)
    }

    /// Whether the editor's own in-window file browser is showing.
    pub fn is_file_browser_open(&self) -> bool {
        self.dialogs.is_open()
    }

    /// Where the open score is saved, if anywhere.
    pub fn path(&self) -> Option<&Path> {
        self.doc.as_ref().and_then(|d| d.path.as_deref())
    }

    /// Why the latest rendering failed, if it did.
    pub fn render_error(&self) -> Option<&str> {
        self.pipeline.render_error().map(|f| f.message.as_str())
    }

    /// The beat the latest render error names, if any.
    pub fn render_error_beat(&self) -> Option<usize> {
        self.pipeline.render_error().and_then(|f| f.beat)
    }

    /// The error shown in the window, if any.
    pub fn error(&self) -> Option<&str> {
        self.messages.error.as_deref()
    }

    /// The status bar message.
    pub fn status(&self) -> &str {
        &self.messages.status
    }

    /// Whether the score has changes not saved.
    pub fn is_dirty(&self) -> bool {
        self.doc.as_ref().is_some_and(|d| d.is_dirty())
    }

    /// Number of undo steps recorded.
    pub fn undo_steps(&self) -> usize {
        self.doc.as_ref().map_or(0, |d| d.history.steps())
    }

    /// The current selection.
    pub fn selection(&self) -> &Selection {
        self.doc
            .as_ref()
            .map_or(&NOTHING_SELECTED, |d| &d.selection)
    }

    /// The recent files, most recent first.
    pub fn recent_files(&self) -> &[PathBuf] {
        self.recent.paths()
    }

    /// The playback clock.
    pub fn playback(&self) -> &Playback {
        &self.transport.playback
    }

    /// The playhead, s.
    pub fn playhead_s(&self) -> f64 {
        self.transport.playhead_s
    }

    /// Whether Space was pressed where the audio is not ready yet (playback starts once
    /// it is).
    pub fn is_waiting_to_play(&self) -> bool {
        self.transport.is_waiting_to_play()
    }

    /// Whether the "unsaved changes" question is showing.
    pub fn is_asking_to_discard(&self) -> bool {
        self.confirm.is_some()
    }

    /// The latest composition (possibly of an older version while recomposing).
    pub fn composition(&self) -> Option<&Composition> {
        self.pipeline.composition()
    }

    /// How long the last composition took on the worker thread.
    pub fn last_compose_time(&self) -> Option<std::time::Duration> {
        self.pipeline.last_compose_time()
    }

    /// How many compositions the pipeline has made since the editor started (each
    /// version of the score is composed once, for the view and the rendering alike).
    pub fn compositions_made(&self) -> u64 {
        self.pipeline.compositions_made()
    }

    /// Wait for a recording being opened, then for the composition in progress (for
    /// tests and batch use).
    pub fn wait_for_composition(&mut self) -> Option<&Composition> {
        self.wait_for_opening();
        self.pipeline.wait_for_composition()
    }

    /// Wait until every file being saved or exported is written, and take the outcomes
    /// (for tests and batch use).
    pub fn wait_for_files(&mut self) {
        for finished in self.jobs.wait() {
            self.job_finished(finished);
        }
    }

    /// Whether a file is being saved or exported.
    pub fn is_writing(&self) -> bool {
        self.jobs.is_busy()
    }

    /// Screen position of `tick` in the lane of `hand` on last frame's timeline.
    pub fn timeline_point(&self, tick: u64, hand: Hand) -> Option<egui::Pos2> {
        let g = self.views.timeline.geometry?;
        Some(g.point(tick as f64, selection::lane_of(hand)))
    }

    /// Screen position of world point `p` (m, performer frame) in last frame's 3D view.
    pub fn viewport_point(&self, p: glam::DVec3) -> Option<egui::Pos2> {
        self.views.viewport.screen_of(p)
    }

    /// Set the audio that playback plays (stereo interleaved, 48 kHz, e.g. an
    /// `Arc<Vec<f32>>`): the seam for the render pipeline.
    pub fn set_audio(&mut self, audio: Arc<dyn tape::StereoSource>) -> Result<(), PlaybackError> {
        self.transport.playback.set_audio(audio)
    }

    /// Move the playhead to `t_s` seconds.
    pub fn seek(&mut self, t_s: f64) {
        self.pending.push(Command::Seek(t_s));
        self.drain();
    }

    /// Show a simulated performance (poses and tips) instead of the IK pose: the seam for
    /// the render pipeline. `None` goes back to the IK pose of the composed targets.
    pub fn set_simulation(&mut self, simulated: Option<Simulated>) {
        self.views.simulated = simulated;
    }

    /// Take `rendering` as the rendering of the score as it is now, as if the render
    /// pipeline had just delivered it: its audio to playback, its body to the 3D view, all
    /// of it to the plots and File > Export (the seam for tests and batch use).
    pub fn set_rendering(&mut self, rendering: Arc<Rendering>) {
        let r = Rendered::new(rendering);
        self.pipeline.accept_rendering(&r, true);
        self.show_rendering(r);
    }

    /// The latest rendering received, if any (possibly of an older version of the score).
    pub fn rendering(&self) -> Option<&Arc<Rendering>> {
        self.pipeline.rendering().map(|(r, _)| r)
    }

    /// Why File > Export is unavailable now, or `None` when the current rendering can be
    /// exported.
    pub fn export_blocked(&self) -> Option<String> {
        if self.doc.is_none() {
            return Some("no score is open".into());
        }
        export::RenderState {
            rendering: self.rendering().map(|r| &**r),
            current: self.pipeline.rendering_is_current(),
            busy: self.pipeline.is_busy(),
            enabled: self.pipeline.renders(),
            error: self.render_error(),
        }
        .blocked()
    }

    /// Export the current rendering's sound as a WAV at `path` (File > Export WAV without
    /// the dialog), in the background (see [`EditorApp::wait_for_files`]).
    pub fn export_wav_to(&mut self, path: &Path) {
        self.export_to(Export::Wav, path);
    }

    /// Export the current rendering's motion as CSV at `path` (File > Export motion CSV).
    pub fn export_motion_to(&mut self, path: &Path) {
        self.export_to(Export::Motion, path);
    }

    /// Export the score as a Standard MIDI File at `path` (File > Export MIDI).
    pub fn export_midi_to(&mut self, path: &Path) {
        self.export_to(Export::Midi, path);
    }

    /// Export the score as MusicXML at `path` (File > Export MusicXML; `.mxl`
    /// compressed).
    pub fn export_musicxml_to(&mut self, path: &Path) {
        self.export_to(Export::MusicXml, path);
    }

    /// Export the current rendering's motion as C3D at `path` (File > Export motion C3D).
    pub fn export_c3d_to(&mut self, path: &Path) {
        self.export_to(Export::MotionC3d, path);
    }

    /// Export the current rendering's motion as BVH at `path` (File > Export motion BVH).
    pub fn export_bvh_to(&mut self, path: &Path) {
        self.export_to(Export::Bvh, path);
    }

    /// Export the current rendering as a glTF scene at `path` (File > Export scene glTF).
    pub fn export_glb_to(&mut self, path: &Path) {
        self.export_to(Export::Glb, path);
    }

    /// How far either side of the playhead the 3D view shows the composed trajectories,
    /// s (`None`: all of them; View > Trajectories near the playhead only).
    pub fn trajectory_window(&self) -> Option<f64> {
        self.views.viewport.trajectory_window_s
    }

    /// Set [`EditorApp::trajectory_window`].
    pub fn set_trajectory_window(&mut self, window_s: Option<f64>) {
        self.views.viewport.trajectory_window_s =
            window_s.map(|w| w.clamp(0.25, viewport::MAX_WINDOW_S));
    }

    /// What the composed trajectories' colour shows (View > Trajectories coloured …).
    pub fn trajectory_colour(&self) -> crate::scene::trail::TrailColour {
        self.views.viewport.trail_colour
    }

    /// The 3D view's camera as it is now.
    pub fn camera(&self) -> Camera {
        self.views.viewport.camera
    }

    /// Whether the 3D camera follows the hand that strikes next (F9).
    pub fn is_following_hand(&self) -> bool {
        self.views.viewport.is_following()
    }

    /// Where the 3D view was drawn last frame.
    pub fn viewport_rect(&self) -> Option<egui::Rect> {
        self.views.viewport.rect
    }

    /// Film the current rendering into the video `path` (File > Export video): the 3D
    /// view from the viewport's camera over the timeline, with the mix, through ffmpeg.
    pub fn export_video_to(&mut self, path: &Path) {
        self.export_to(Export::Video, path);
    }

    /// The video's frames as PNGs with the mix into the new folder `path` (File > Export
    /// video frames).
    pub fn export_video_frames_to(&mut self, path: &Path) {
        self.export_to(Export::VideoFrames, path);
    }

    /// Export the current rendering as a lesson pack into the new folder `path` (File >
    /// Export lesson pack).
    pub fn export_pack_to(&mut self, path: &Path) {
        self.export_to(Export::Pack, path);
    }

    /// Aim the live OSC output at `host`:`port` (the inspector's "Live OSC output" fields;
    /// its checkbox turns it on).
    pub fn set_osc_target(&mut self, host: &str, port: u16) {
        self.osc.settings.host = host.to_string();
        self.osc.settings.port = port;
    }

    /// Hits the live OSC output sent since it was turned on, and its latest error.
    pub fn osc_sent(&self) -> (usize, Option<&str>) {
        (self.osc.sent, self.osc.error.as_deref())
    }

    /// The open plot tab.
    pub fn plot_tab(&self) -> PlotTab {
        self.views.plots.tab
    }

    /// Screen position of score time `t_s` on the open plot tab's first time plot, as drawn
    /// last frame (none when the tab shows no time plot).
    pub fn plot_point(&self, t_s: f64) -> Option<egui::Pos2> {
        self.views.plots.screen_of(t_s)
    }

    /// The time window (s) of the open plot tab's first time plot, as drawn last frame: the
    /// timeline's visible window (none when the tab shows no time plot).
    pub fn plot_time_window(&self) -> Option<(f64, f64)> {
        self.views.plots.time_window()
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
}
