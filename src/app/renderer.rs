//! The rendering half of the editor's pipeline: each composition the composing worker
//! makes is rendered (body + drums + sound, `crate::render::render_composition`) on a
//! [`Worker`](super::worker::Worker) of its own; a newer request cancels the render in
//! progress. Each rendering resumes the previous one's performance from its latest saved
//! state before the edit and first renders only a little past it, so the edited part plays
//! at once; the rest follows in steps. What a rendering gives the editor: its audio to
//! playback (played in place), the simulated poses and membranes to the 3D view, all of
//! it to the plots and File > Export.

use super::pose::Simulated;
use super::tape::StereoSource;
use super::worker::Job;
use crate::motion::compose::Composition;
use crate::render::{
    FIRST_STEP_S, RESUME_STEP_GROWTH, RESUME_STEP_S, RenderError, RenderParams, Rendering, Resume,
    render_composition,
};
use crate::score::LoadedScore;
use std::sync::Arc;
use std::time::{Duration, Instant};

/// A finished render, ready for playback, the view, the plots and export.
pub struct Rendered {
    /// Everything the pipeline produced (shared with the plots and export).
    pub rendering: Arc<Rendering>,
    pub simulated: Simulated,
    /// One line for the status bar.
    pub summary: String,
    /// Whether the whole score is rendered (else the audio is final up to a time the
    /// summary names, and the rest follows).
    pub complete: bool,
}

impl Rendered {
    /// The parts of `rendering` the editor uses.
    pub fn new(rendering: Arc<Rendering>) -> Rendered {
        let origin = (rendering.stats.resumed_from_s, rendering.stats.wall());
        Rendered::of_request(rendering, origin)
    }

    /// [`Rendered::new`] for the last of the steps that rendered one request: the status
    /// names where the first step resumed from (`None`: rendered whole) and the wall time
    /// of all the steps.
    fn of_request(rendering: Arc<Rendering>, (from, wall): (Option<f64>, Duration)) -> Rendered {
        let r = &rendering;
        let t = &r.timing;
        let summary = if !r.complete {
            format!("rendered up to {:.1} s; rendering the rest", r.ready_s)
        } else {
            format!(
                "rendered: {} strokes, timing median {:.1} ms, worst {:.1} ms{}; {}",
                t.strokes,
                t.median_abs_s * 1e3,
                t.worst_abs_s * 1e3,
                if t.missed > 0 {
                    format!(", {} missed", t.missed)
                } else {
                    String::new()
                },
                match from {
                    Some(from) => format!(
                        "re-simulated from {from:.1} s in {:.2} s",
                        wall.as_secs_f64()
                    ),
                    None => format!("in {:.2} s", wall.as_secs_f64()),
                }
            )
        };
        let simulated = Simulated::of_rendering(Arc::clone(r));
        Rendered {
            complete: r.complete,
            rendering,
            simulated,
            summary,
        }
    }
}

/// Playback plays the rendering's audio in place (`Arc<Rendering>`, no copy).
impl StereoSource for Rendering {
    fn sample_count(&self) -> usize {
        self.audio.samples.len()
    }

    fn frame(&self, i: usize) -> Option<[f32; 2]> {
        let s = &self.audio.samples;
        Some([*s.get(2 * i)?, *s.get(2 * i + 1)?])
    }
}

/// Why a render failed: the message for the window, and the beat it names, if any (the
/// one being played when the simulation stopped, or the one out of reach).
#[derive(Clone, Debug, PartialEq)]
pub struct Failure {
    pub message: String,
    pub beat: Option<usize>,
}

impl Failure {
    /// A failure that names no beat.
    pub fn of(message: impl Into<String>) -> Failure {
        Failure {
            message: message.into(),
            beat: None,
        }
    }
}

impl From<RenderError> for Failure {
    fn from(e: RenderError) -> Failure {
        let beat = match &e {
            RenderError::Diverged { beat, .. } => *beat,
            RenderError::OutOfReach(r) => Some(r.beat),
            _ => None,
        };
        Failure {
            message: e.to_string(),
            beat,
        }
    }
}

/// What the rendering worker is asked: a score and the composition of it the view
/// already shows (the render does not compose again).
pub struct Request {
    /// The score and its kit (before the score's settings change the kit).
    pub loaded: LoadedScore,
    pub composition: Arc<Composition>,
}

/// One reply of the rendering worker: a rendering (partial ones first) or why it failed.
pub type Reply = Result<Rendered, Failure>;

/// The rendering worker's job: render each request's composition, first the edited part
/// (quick, to play at once) and then the rest in steps, each resuming the performance the
/// renderings so far left (kept here across requests).
pub fn job() -> impl FnMut(Request, &Job<Reply>) + Send + 'static {
    let mut resume: Option<Resume> = None;
    move |request, job| {
        let params = RenderParams::for_score(&request.loaded.score.settings);
        let began = Instant::now();
        // Where the first step resumed from.
        let mut origin: Option<Option<f64>> = None;
        let mut step_s = RESUME_STEP_S;
        loop {
            let stop_after_s = if origin.is_none() {
                FIRST_STEP_S
            } else {
                let next = RESUME_STEP_GROWTH * step_s;
                std::mem::replace(&mut step_s, next)
            };
            let result = render_composition(
                &mut resume,
                Some(stop_after_s),
                &request.loaded,
                std::sync::Arc::clone(&request.composition),
                &params,
                &mut |_| job.is_current(),
            );
            let reply = match result {
                Err(RenderError::Cancelled) => return,
                Err(e) => Err(Failure::from(e)),
                Ok(r) => {
                    let from = *origin.get_or_insert(r.stats.resumed_from_s);
                    Ok(Rendered::of_request(Arc::new(r), (from, began.elapsed())))
                }
            };
            let complete = reply.as_ref().map_or(true, |r| r.complete);
            if !job.send(reply, complete) || complete {
                return;
            }
        }
    }
}
