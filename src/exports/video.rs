//! A rendering filmed: each frame is the 3D view (the editor's stage: floor, drums with
//! their membranes moving, the simulated body and sticks, each tip's last second as a
//! trail, each contact as an arrow as long as its force for a moment) over the timeline
//! strip (lanes per drum, bars, strokes, contacts, playhead),
//! drawn by `scene` and rasterised without a GPU, from score time 0 to the end of the mix.
//! `io::video` encodes the frames with the mix through ffmpeg, or writes them as PNGs.

use crate::body::model::BodyModel;
use crate::io::video::{self, VideoError, VideoSpec};
use crate::render::Rendering;
use crate::scene::camera::Camera;
use crate::scene::marks::{Anchor, HAND_COLOURS, Mark, Rgba};
use crate::scene::raster::Canvas;
use crate::scene::stage;
use crate::scene::strip::{self, StripInput};
use crate::score::{MeterMap, Score, TempoMap};
use glam::{DVec2, DVec3};
use std::path::{Path, PathBuf};

/// The look of a video.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VideoOptions {
    /// Frame size, px.
    pub width: u32,
    pub height: u32,
    /// Frames per second (30 or 60).
    pub fps: u32,
    /// The 3D view's camera.
    pub camera: Camera,
}

impl Default for VideoOptions {
    /// 1280 × 720 at 30 fps, from the editor's default camera.
    fn default() -> Self {
        VideoOptions {
            width: 1280,
            height: 720,
            fps: 30,
            camera: Camera::default(),
        }
    }
}

/// Share of the frame's height the timeline strip takes.
const STRIP_SHARE: f64 = 0.24;
/// Length of the tip trails, s.
const TRAIL_S: f64 = 1.0;

/// The frames of a rendering.
pub struct Filmer<'a> {
    rendering: &'a Rendering,
    score: &'a Score,
    options: VideoOptions,
    model: BodyModel,
    tempo: TempoMap,
    meter: MeterMap,
    hits: Vec<crate::base::hit::Hit>,
    canvas: Canvas,
    marks: Vec<Mark>,
}

impl<'a> Filmer<'a> {
    /// Frames of `rendering` (of `score`) as `options` ask.
    pub fn new(
        rendering: &'a Rendering,
        score: &'a Score,
        options: VideoOptions,
    ) -> Result<Filmer<'a>, VideoError> {
        let canvas = Canvas::new(options.width, options.height, stage::BACKGROUND)
            .map_err(|_| VideoError::Size(options.width, options.height))?;
        let mallet = rendering.kit.mallets.get(rendering.params.mallet);
        Ok(Filmer {
            rendering,
            score,
            options,
            model: BodyModel::new(rendering.skeleton(), rendering.params.mass_kg)
                .holding_mallets(mallet.map_or(0.0, |m| m.mass_kg)),
            tempo: score.tempo_map(),
            meter: score.meter_map(),
            hits: rendering.events.iter().map(|e| e.hit()).collect(),
            canvas,
            marks: Vec::new(),
        })
    }

    /// The frames: from score time 0 to the end of the mix.
    pub fn spec(&self) -> VideoSpec {
        let audio = &self.rendering.audio;
        let frames_per_channel = audio.samples.len() / usize::from(audio.channels.max(1));
        let duration_s = frames_per_channel as f64 / f64::from(audio.rate_hz.max(1));
        VideoSpec {
            width: self.options.width,
            height: self.options.height,
            fps: self.options.fps,
            frames: (duration_s * f64::from(self.options.fps)).ceil() as u64,
        }
    }

    /// Score time of frame `k`, s.
    pub fn time_of(&self, k: u64) -> f64 {
        k as f64 / f64::from(self.options.fps)
    }

    /// Draw frame `k` on the canvas.
    pub fn draw(&mut self, k: u64) -> &Canvas {
        let t = self.time_of(k);
        let r = self.rendering;
        let (w, h) = (
            f64::from(self.options.width),
            f64::from(self.options.height),
        );
        let strip_h = (STRIP_SHARE * h).round();
        let view = DVec2::new(w, h - strip_h);
        let proj = self.options.camera.projector(view);
        let marks = &mut self.marks;
        marks.clear();
        stage::floor(&proj, marks);
        for (index, drum) in r.kit.drums.iter().enumerate() {
            let membrane = |p: DVec3| r.drums.recorded_displacement(index, t, p);
            stage::drum(&proj, drum, &membrane, marks);
        }
        let motion = &r.motion;
        if let Some(last) = motion.poses.len().checked_sub(1) {
            let at =
                |t: f64| (((t - r.start_s) * motion.rate_hz).round().max(0.0) as usize).min(last);
            let (from, now) = (at(t - TRAIL_S), at(t));
            for (hand, tips) in motion.tips.iter().enumerate() {
                if let Some(trail) = tips.get(from..=now.min(tips.len().saturating_sub(1))) {
                    stage::path(&proj, trail, 2.0, HAND_COLOURS[hand].with_alpha(200), marks);
                }
            }
            stage::body(&proj, &self.model, &motion.poses[now], marks);
        }
        stage::contacts(&proj, r.drums.contacts(), t, marks);
        marks.push(Mark::Label {
            at: DVec2::new(12.0, 10.0),
            anchor: Anchor::LeftTop,
            text: self.score.title.clone(),
            size: 18.0,
            colour: Rgba::grey(225),
        });
        for (hand, name) in ["left hand", "right hand"].into_iter().enumerate() {
            marks.push(Mark::Label {
                at: DVec2::new(w - 12.0, 10.0 + 18.0 * hand as f64),
                anchor: Anchor::RightTop,
                text: name.to_string(),
                size: 14.0,
                colour: HAND_COLOURS[hand],
            });
        }
        let input = StripInput {
            drum_names: r.kit.drums.iter().map(|d| d.name.as_str()).collect(),
            strokes: &r.composition.strokes,
            hits: &self.hits,
            tempo: &self.tempo,
            meter: &self.meter,
            time_s: t,
        };
        strip::strip(
            &input,
            DVec2::new(0.0, h - strip_h),
            DVec2::new(w, strip_h),
            marks,
        );
        self.canvas.clear(stage::BACKGROUND);
        self.canvas.draw(&self.marks);
        &self.canvas
    }
}

/// Film `rendering` (of `score`) into the video `out` through ffmpeg (see `io::video`).
/// `progress(done, total)` after each frame; false stops, leaving nothing.
pub fn write_video(
    rendering: &Rendering,
    score: &Score,
    options: VideoOptions,
    out: &Path,
    progress: &mut dyn FnMut(u64, u64) -> bool,
) -> Result<VideoSpec, VideoError> {
    let mut filmer = Filmer::new(rendering, score, options)?;
    let spec = filmer.spec();
    video::encode(
        out,
        &spec,
        &rendering.audio,
        &mut |k| Ok(filmer.draw(k).rgba().to_vec()),
        &mut |done| progress(done, spec.frames),
    )?;
    Ok(spec)
}

/// The frames of `rendering` as PNGs in the new folder `dir`, with the mix and the
/// command that joins them (see `io::video::write_frames`).
pub fn write_frames(
    rendering: &Rendering,
    score: &Score,
    options: VideoOptions,
    dir: &Path,
    replace: bool,
    progress: &mut dyn FnMut(u64, u64) -> bool,
) -> Result<(PathBuf, VideoSpec), VideoError> {
    let mut filmer = Filmer::new(rendering, score, options)?;
    let spec = filmer.spec();
    let written = video::write_frames(
        dir,
        replace,
        &spec,
        &rendering.audio,
        &mut |k| {
            filmer.draw(k).png().map_err(|e| VideoError::Frame {
                index: k,
                message: e.to_string(),
            })
        },
        &mut |done| progress(done, spec.frames),
    )?;
    Ok((written, spec))
}
