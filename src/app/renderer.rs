//! The render pipeline off the UI thread: after each composition request the latest score
//! is rendered (body + drums + sound, `crate::render`) on one long-lived worker; a newer
//! request cancels the render in progress. Each rendering resumes the previous one's
//! performance from its latest saved state before the edit (`render::render_after`) and
//! first renders only a second past it, so the edited part plays at once; the rest
//! follows. The UI polls once per frame and hands the rendering to playback (which plays
//! its audio in place), the simulated
//! poses and membranes to the 3D view and the whole rendering to the plots and to
//! File > Export.

use super::pose::Simulated;
use super::tape::StereoSource;
use crate::kit::Kit;
use crate::mocap::db::MotionDb;
use crate::render::{
    FIRST_STEP_S, RESUME_STEP_S, RenderError, RenderParams, Rendering, Resume, render_after,
};
use crate::score::{LoadedScore, Score};
use eframe::egui;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Condvar, Mutex, mpsc};
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
    fn interleaved(&self) -> &[f32] {
        &self.audio.samples
    }
}

struct Request {
    generation: u64,
    score: Score,
    kit: Kit,
    ctx: Option<egui::Context>,
}

#[derive(Default)]
struct Slot {
    request: Option<Request>,
    quit: bool,
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

type Reply = (u64, Result<Rendered, Failure>);

/// The rendering worker.
pub struct Renderer {
    shared: Arc<(Mutex<Slot>, Condvar)>,
    /// The newest generation requested; the worker stops a render that is older.
    latest: Arc<AtomicU64>,
    replies: mpsc::Receiver<Reply>,
    done: u64,
    /// Whether the newest reply was a whole rendering.
    complete: bool,
}

impl Renderer {
    /// Start the worker.
    pub fn new() -> Renderer {
        let shared = Arc::new((Mutex::new(Slot::default()), Condvar::new()));
        let latest = Arc::new(AtomicU64::new(0));
        let (tx, replies) = mpsc::channel();
        let (worker, newest) = (Arc::clone(&shared), Arc::clone(&latest));
        std::thread::Builder::new()
            .name("render".into())
            .spawn(move || work(&worker, &newest, &tx))
            .expect("spawn the rendering thread");
        Renderer {
            shared,
            latest,
            replies,
            done: 0,
            complete: true,
        }
    }

    /// Render `score` on `kit`, cancelling any render in progress.
    pub fn request(&mut self, score: &Score, kit: &Kit, ctx: Option<egui::Context>) {
        let generation = self.latest.fetch_add(1, Ordering::SeqCst) + 1;
        let (lock, cv) = &*self.shared;
        let mut slot = lock.lock().expect("renderer lock");
        slot.request = Some(Request {
            generation,
            score: score.clone(),
            kit: kit.clone(),
            ctx,
        });
        cv.notify_one();
    }

    /// The newest finished render, if one arrived since the last poll.
    pub fn poll(&mut self) -> Option<Result<Rendered, Failure>> {
        let mut newest = None;
        while let Ok((generation, result)) = self.replies.try_recv() {
            if generation >= self.done {
                self.done = generation;
                self.complete = result.as_ref().map_or(true, |r| r.complete);
                newest = Some(result);
            }
        }
        newest
    }

    /// Whether a render of the latest request is still to come (or its rest).
    pub fn is_busy(&self) -> bool {
        self.done < self.latest.load(Ordering::SeqCst) || !self.complete
    }
}

impl Default for Renderer {
    fn default() -> Self {
        Renderer::new()
    }
}

impl Drop for Renderer {
    fn drop(&mut self) {
        self.latest.fetch_add(1, Ordering::SeqCst);
        let (lock, cv) = &*self.shared;
        if let Ok(mut slot) = lock.lock() {
            slot.quit = true;
            cv.notify_one();
        }
    }
}

fn work(shared: &(Mutex<Slot>, Condvar), latest: &AtomicU64, tx: &mpsc::Sender<Reply>) {
    let mut db: Option<Result<MotionDb, String>> = None;
    // What the renderings so far left: the next one resumes from it where it can.
    let mut resume: Option<Resume> = None;
    loop {
        let request = {
            let (lock, cv) = shared;
            let mut slot = lock.lock().expect("renderer lock");
            loop {
                if slot.quit {
                    return;
                }
                if let Some(r) = slot.request.take() {
                    break r;
                }
                slot = cv.wait(slot).expect("renderer lock");
            }
        };
        let db = db.get_or_insert_with(|| {
            MotionDb::load(&crate::mocap::db::default_dir())
                .map_err(|e| format!("no motion database: {e}"))
        });
        let Ok(db) = db else {
            let e = db.as_ref().err().cloned().unwrap_or_default();
            if tx.send((request.generation, Err(Failure::of(e)))).is_err() {
                return;
            }
            continue;
        };
        // First the edited part (quick, to play at once), then the rest in steps.
        let mut complete = false;
        let began = Instant::now();
        // Where the first step resumed from.
        let mut origin: Option<Option<f64>> = None;
        while !complete {
            let stop_after_s = if origin.is_none() {
                FIRST_STEP_S
            } else {
                RESUME_STEP_S
            };
            let result = match run(&request, db, latest, &mut resume, stop_after_s) {
                Err(RenderError::Cancelled) => break,
                Err(e) => Err(Failure::from(e)),
                Ok(r) => {
                    let from = *origin.get_or_insert(r.stats.resumed_from_s);
                    Ok(Rendered::of_request(Arc::new(r), (from, began.elapsed())))
                }
            };
            complete = result.as_ref().map_or(true, |r| r.complete);
            if tx.send((request.generation, result)).is_err() {
                return;
            }
            if let Some(ctx) = &request.ctx {
                ctx.request_repaint();
            }
        }
    }
}

fn run(
    request: &Request,
    db: &MotionDb,
    latest: &AtomicU64,
    resume: &mut Option<Resume>,
    stop_after_s: f64,
) -> Result<Rendering, RenderError> {
    let loaded = LoadedScore {
        score: request.score.clone(),
        kit: request.kit.clone(),
        kit_source: String::new(),
        notices: Vec::new(),
    };
    let params = RenderParams::for_score(&loaded.score.settings);
    render_after(
        resume,
        Some(stop_after_s),
        &loaded,
        db,
        &params,
        &mut |_| latest.load(Ordering::SeqCst) == request.generation,
    )
}
