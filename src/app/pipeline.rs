//! The editor's pipeline, apart from the document and the views: a composing
//! [`Worker`] turns each version of the score into two tip trajectories (the motion
//! database loaded once, on first use, and shared by reference) and hands each composition
//! both to the view and, unchanged, to the rendering worker ([`super::renderer`]), so an
//! edit composes once. The UI polls once per frame and keeps showing the previous
//! composition and rendering until newer ones arrive.

use super::renderer::{self, Failure, Rendered};
use super::worker::{Job, Requester, Waker, Worker};
use crate::base::ron_file::FileError;
use crate::mocap::db::MotionDb;
use crate::mocap::shipped::DbSource;
use crate::motion::compose::Composition;
use crate::render::{RenderError, RenderParams, Rendering};
use crate::score::LoadedScore;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, OnceLock};
use std::time::{Duration, Instant};

/// Why the composing worker has no composition.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ComposeFailure {
    /// The database failed to load (once; every composition reports it).
    #[error("no motion database: {0}")]
    NoDatabase(Arc<FileError>),
    #[error(transparent)]
    Compose(#[from] RenderError),
}

/// A composition (or why there is none) and how long it took on the worker.
struct Composed {
    result: Result<Arc<Composition>, ComposeFailure>,
    took: Duration,
}

/// The workers and their latest results.
pub struct Pipeline {
    composer: Worker<LoadedScore, Composed>,
    renderer: Option<Worker<renderer::Request, renderer::Reply>>,
    waker: Waker,
    /// Compositions made by the composing worker since the start.
    compositions_made: Arc<AtomicU64>,
    composition: Option<Arc<Composition>>,
    compose_error: Option<String>,
    last_compose_time: Option<Duration>,
    /// Counts compositions received (for the views' caches).
    generation: u64,
    rendering: Option<Arc<Rendering>>,
    /// Counts renderings received (for the plots' caches).
    rendering_id: u64,
    /// Whether `rendering` is of the score as it is now.
    rendering_current: bool,
    render_error: Option<Failure>,
}

impl Pipeline {
    /// Start the workers (the rendering one only if `render`), composing with the motion
    /// database from `db` (read on first use).
    pub fn new(render: bool, db: DbSource) -> Pipeline {
        let waker: Waker = Arc::default();
        let renderer = render.then(|| Worker::spawn("render", waker.clone(), renderer::job()));
        let forward = renderer.as_ref().map(Worker::requester);
        let compositions_made = Arc::new(AtomicU64::new(0));
        let job = compose_job(forward, Arc::clone(&compositions_made), db);
        Pipeline {
            composer: Worker::spawn("compose", waker.clone(), job),
            renderer,
            waker,
            compositions_made,
            composition: None,
            compose_error: None,
            last_compose_time: None,
            generation: 0,
            rendering: None,
            rendering_id: 0,
            rendering_current: false,
            render_error: None,
        }
    }

    /// Call `wake` after every reply of either worker (set once: the UI's repaint).
    pub fn set_waker(&self, wake: impl Fn() + Send + Sync + 'static) {
        let _ = self.waker.set(Box::new(wake));
    }

    /// Compose and then render `loaded`, dropping work on older versions.
    pub fn request(&mut self, loaded: &LoadedScore) {
        self.rendering_current = false;
        if let Some(r) = &self.renderer {
            r.cancel();
        }
        self.composer.request(loaded.clone());
    }

    /// Forget every result (no document is open).
    pub fn clear(&mut self) {
        self.composer.cancel();
        if let Some(r) = &self.renderer {
            r.cancel();
        }
        self.composition = None;
        self.compose_error = None;
        self.forget_rendering();
    }

    /// Forget the rendering (a new document).
    pub fn forget_rendering(&mut self) {
        self.rendering = None;
        self.rendering_current = false;
        self.render_error = None;
    }

    /// Take what the workers sent: the newest rendering that arrived, if any (for
    /// playback and the status bar).
    pub fn poll(&mut self) -> Option<Rendered> {
        for composed in self.composer.poll() {
            self.accept_composition(composed);
        }
        let replies = self.renderer.as_mut().map(Worker::poll).unwrap_or_default();
        // A newer request still on its way means these are of an older version.
        let current = !self.is_busy();
        let mut newest = None;
        for reply in replies {
            match reply {
                Ok(r) => {
                    self.accept_rendering(&r, current);
                    newest = Some(r);
                }
                Err(e) => {
                    self.render_error = Some(Failure {
                        message: format!("render: {}", e.message),
                        ..e
                    })
                }
            }
        }
        newest
    }

    /// Block until the composition in progress arrives (tests and batch use).
    pub fn wait_for_composition(&mut self) -> Option<&Composition> {
        for composed in self.composer.wait() {
            self.accept_composition(composed);
        }
        self.composition()
    }

    fn accept_composition(&mut self, composed: Composed) {
        self.generation += 1;
        self.last_compose_time = Some(composed.took);
        match composed.result {
            Ok(c) => {
                self.composition = Some(c);
                self.compose_error = None;
            }
            Err(e) => {
                if self.renderer.is_some() {
                    self.render_error = Some(Failure::of(format!("render: {e}")));
                }
                self.compose_error = Some(e.to_string());
            }
        }
    }

    /// Take `r` as the newest rendering (`current`: of the score as it is now).
    pub fn accept_rendering(&mut self, r: &Rendered, current: bool) {
        self.render_error = None;
        self.rendering = Some(Arc::clone(&r.rendering));
        self.rendering_id += 1;
        self.rendering_current = current;
    }

    /// Playback of the rendering failed: say so where render errors go.
    pub fn playback_failed(&mut self, message: String) {
        self.render_error = Some(Failure::of(message));
    }

    /// Whether a composition is on its way.
    pub fn is_composing(&self) -> bool {
        self.composer.is_busy()
    }

    /// Whether a rendering of the newest version is still to come (or its rest).
    pub fn is_rendering(&self) -> bool {
        self.renderer.as_ref().is_some_and(Worker::is_busy)
    }

    /// Whether anything of the newest version is still to come.
    pub fn is_busy(&self) -> bool {
        self.is_composing() || self.is_rendering()
    }

    /// Whether the editor renders at all.
    pub fn renders(&self) -> bool {
        self.renderer.is_some()
    }

    /// The latest composition (possibly of an older version while recomposing).
    pub fn composition(&self) -> Option<&Composition> {
        self.composition.as_deref()
    }

    /// Why the latest composition failed.
    pub fn compose_error(&self) -> Option<&str> {
        self.compose_error.as_deref()
    }

    /// How long the last composition took on the worker.
    pub fn last_compose_time(&self) -> Option<Duration> {
        self.last_compose_time
    }

    /// How many compositions the composing worker has made.
    pub fn compositions_made(&self) -> u64 {
        self.compositions_made.load(Ordering::SeqCst)
    }

    /// Counts compositions received.
    pub fn generation(&self) -> u64 {
        self.generation
    }

    /// The latest rendering (possibly of an older version) and its count.
    pub fn rendering(&self) -> Option<(&Arc<Rendering>, u64)> {
        self.rendering.as_ref().map(|r| (r, self.rendering_id))
    }

    /// Whether the rendering is of the score as it is now.
    pub fn rendering_is_current(&self) -> bool {
        self.rendering_current
    }

    /// Why the latest render (or its playback) failed.
    pub fn render_error(&self) -> Option<&Failure> {
        self.render_error.as_ref()
    }
}

/// The composing worker's job: compose each score (loading the motion database once) and
/// forward the composition to the rendering worker, if any.
fn compose_job(
    forward: Option<Requester<renderer::Request>>,
    made: Arc<AtomicU64>,
    source: DbSource,
) -> impl FnMut(LoadedScore, &Job<Composed>) + Send + 'static {
    let db: OnceLock<Result<MotionDb, Arc<FileError>>> = OnceLock::new();
    move |loaded, job| {
        let began = Instant::now();
        let db = db.get_or_init(|| source.load().map_err(Arc::new));
        let params = RenderParams::for_score(&loaded.score.settings);
        let result = match db {
            Ok(db) => crate::render::compose(&loaded, db, &params)
                .map(Arc::new)
                .map_err(ComposeFailure::from),
            Err(e) => Err(ComposeFailure::NoDatabase(Arc::clone(e))),
        };
        made.fetch_add(1, Ordering::SeqCst);
        let took = began.elapsed();
        if let (Ok(composition), Some(render)) = (&result, &forward)
            && job.is_current()
        {
            render.request(renderer::Request {
                loaded,
                composition: Arc::clone(composition),
            });
        }
        job.send(Composed { result, took }, true);
    }
}
