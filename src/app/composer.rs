//! Composition off the UI thread: one long-lived worker composes the latest score it was
//! given (older requests still waiting are dropped; results of stale requests are
//! ignored), loading the motion database once. The UI polls once per frame and keeps
//! showing the previous composition until the new one arrives.

use crate::kit::Kit;
use crate::mocap::db::MotionDb;
use crate::motion::compose::{ComposeParams, Composition};
use crate::score::Score;
use eframe::egui;
use std::sync::{Arc, Condvar, Mutex, mpsc};
use std::time::{Duration, Instant};

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

type Reply = (u64, Result<Composition, String>, Duration);

/// The composing worker and its latest result.
pub struct Composer {
    shared: Arc<(Mutex<Slot>, Condvar)>,
    replies: mpsc::Receiver<Reply>,
    generation: u64,
    done: u64,
    composition: Option<Composition>,
    error: Option<String>,
    /// How long the last finished composition took on the worker.
    pub last_duration: Option<Duration>,
}

impl Composer {
    /// Start the worker.
    pub fn new() -> Composer {
        let shared = Arc::new((Mutex::new(Slot::default()), Condvar::new()));
        let (tx, replies) = mpsc::channel();
        let worker = Arc::clone(&shared);
        std::thread::Builder::new()
            .name("compose".into())
            .spawn(move || work(&worker, &tx))
            .expect("spawn the composing thread");
        Composer {
            shared,
            replies,
            generation: 0,
            done: 0,
            composition: None,
            error: None,
            last_duration: None,
        }
    }

    /// Compose `score` on `kit` (replacing any request not yet started); `ctx` is asked to
    /// repaint when it is done.
    pub fn request(&mut self, score: &Score, kit: &Kit, ctx: Option<egui::Context>) {
        self.generation += 1;
        let (lock, cv) = &*self.shared;
        let mut slot = lock.lock().expect("composer lock");
        slot.request = Some(Request {
            generation: self.generation,
            score: score.clone(),
            kit: score.settings.kit(kit).into_owned(),
            ctx,
        });
        cv.notify_one();
    }

    /// Forget the composition (e.g. when the document is closed).
    pub fn clear(&mut self) {
        self.generation += 1;
        self.done = self.generation;
        self.composition = None;
        self.error = None;
    }

    /// Take finished results; true if the composition changed.
    pub fn poll(&mut self) -> bool {
        let mut changed = false;
        while let Ok(reply) = self.replies.try_recv() {
            changed |= self.accept(reply);
        }
        changed
    }

    /// Block until the latest request is composed (tests and batch use).
    pub fn wait(&mut self) -> Option<&Composition> {
        while self.done < self.generation {
            match self.replies.recv() {
                Ok(reply) => {
                    self.accept(reply);
                }
                Err(_) => {
                    self.error = Some("the composing thread stopped".into());
                    break;
                }
            }
        }
        self.composition.as_ref()
    }

    fn accept(&mut self, (generation, result, took): Reply) -> bool {
        if generation < self.done {
            return false;
        }
        self.done = generation;
        self.last_duration = Some(took);
        match result {
            Ok(c) => {
                self.composition = Some(c);
                self.error = None;
            }
            Err(e) => self.error = Some(e),
        }
        true
    }

    /// Whether a newer composition is on its way.
    pub fn is_busy(&self) -> bool {
        self.done < self.generation
    }

    /// The latest composition (possibly of an older version of the score while busy).
    pub fn composition(&self) -> Option<&Composition> {
        self.composition.as_ref()
    }

    /// Why the latest composition failed.
    pub fn error(&self) -> Option<&str> {
        self.error.as_deref()
    }
}

impl Default for Composer {
    fn default() -> Self {
        Composer::new()
    }
}

impl Drop for Composer {
    fn drop(&mut self) {
        let (lock, cv) = &*self.shared;
        if let Ok(mut slot) = lock.lock() {
            slot.quit = true;
            cv.notify_one();
        }
    }
}

fn work(shared: &(Mutex<Slot>, Condvar), tx: &mpsc::Sender<Reply>) {
    let mut db: Option<Result<MotionDb, String>> = None;
    loop {
        let request = {
            let (lock, cv) = shared;
            let mut slot = lock.lock().expect("composer lock");
            loop {
                if slot.quit {
                    return;
                }
                if let Some(r) = slot.request.take() {
                    break r;
                }
                slot = cv.wait(slot).expect("composer lock");
            }
        };
        let t0 = Instant::now();
        let db = db.get_or_insert_with(|| {
            MotionDb::load(&crate::mocap::db::default_dir())
                .map_err(|e| format!("no motion database: {e}"))
        });
        let result = match db {
            Ok(db) => crate::motion::perform::trajectories(
                &request.score,
                &request.kit,
                db,
                &Default::default(),
                &ComposeParams::default(),
            ),
            Err(e) => Err(e.clone()),
        };
        if tx.send((request.generation, result, t0.elapsed())).is_err() {
            return;
        }
        if let Some(ctx) = request.ctx {
            ctx.request_repaint();
        }
    }
}
