//! One long-lived background thread that works on the latest request it was given: a
//! request replaces any still waiting (older ones are dropped unstarted), a job in progress
//! can see that a newer request arrived and stop early, and replies carry the request's
//! generation so the owner ignores stale ones. The editor's composing and rendering are
//! two of these; a job may send several replies (a rendering in steps), the last one
//! marked final.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Condvar, Mutex, OnceLock, mpsc};

/// Called after each reply, e.g. to wake the UI (set once, from any thread).
pub type Waker = Arc<OnceLock<Box<dyn Fn() + Send + Sync>>>;

struct Slot<Req> {
    request: Option<(u64, Req)>,
    quit: bool,
}

struct Shared<Req> {
    slot: Mutex<Slot<Req>>,
    wake: Condvar,
    /// The newest generation asked for or cancelled; a job older than this is stale.
    latest: AtomicU64,
    /// The newest generation asked for (a cancel bumps `latest` only).
    requested: AtomicU64,
}

/// A reply to request `generation`; `last` when the job has nothing more to send.
struct Reply<Out> {
    generation: u64,
    out: Out,
    last: bool,
}

/// The request side of a worker, cheap to clone and usable from other threads (the
/// composing worker forwards each composition to the rendering worker with one).
pub struct Requester<Req> {
    shared: Arc<Shared<Req>>,
}

impl<Req> Clone for Requester<Req> {
    fn clone(&self) -> Self {
        Requester {
            shared: Arc::clone(&self.shared),
        }
    }
}

impl<Req> Requester<Req> {
    /// Ask for `request`, replacing any request not yet started and making the job in
    /// progress stale.
    pub fn request(&self, request: Req) {
        let mut slot = self.shared.slot.lock().expect("worker lock");
        let generation = self.shared.latest.fetch_add(1, Ordering::SeqCst) + 1;
        self.shared.requested.store(generation, Ordering::SeqCst);
        slot.request = Some((generation, request));
        self.shared.wake.notify_one();
    }

    /// Make the job in progress stale and drop any request not yet started.
    pub fn cancel(&self) {
        let mut slot = self.shared.slot.lock().expect("worker lock");
        self.shared.latest.fetch_add(1, Ordering::SeqCst);
        slot.request = None;
    }
}

/// What a job is given besides its request: whether it is still wanted, and where its
/// replies go.
pub struct Job<'a, Out> {
    generation: u64,
    shared: &'a AtomicU64,
    replies: &'a mpsc::Sender<Reply<Out>>,
    waker: &'a Waker,
}

impl<Out> Job<'_, Out> {
    /// Whether no newer request (or cancel) has arrived since this job started.
    pub fn is_current(&self) -> bool {
        self.shared.load(Ordering::SeqCst) == self.generation
    }

    /// Send a reply (`last` when the job is done); false once the owner is gone.
    pub fn send(&self, out: Out, last: bool) -> bool {
        let reply = Reply {
            generation: self.generation,
            out,
            last,
        };
        let sent = self.replies.send(reply).is_ok();
        if let Some(wake) = self.waker.get() {
            wake();
        }
        sent
    }
}

/// A worker thread and the replies it sent.
pub struct Worker<Req, Out> {
    requester: Requester<Req>,
    replies: mpsc::Receiver<Reply<Out>>,
    /// The generation of the newest reply taken, and whether it was its job's last.
    taken: u64,
    finished: bool,
}

impl<Req: Send + 'static, Out: Send + 'static> Worker<Req, Out> {
    /// Start a thread called `name` that runs `job` on each request it takes.
    pub fn spawn(
        name: &str,
        waker: Waker,
        mut job: impl FnMut(Req, &Job<Out>) + Send + 'static,
    ) -> Worker<Req, Out> {
        let shared = Arc::new(Shared {
            slot: Mutex::new(Slot {
                request: None,
                quit: false,
            }),
            wake: Condvar::new(),
            latest: AtomicU64::new(0),
            requested: AtomicU64::new(0),
        });
        let (tx, replies) = mpsc::channel();
        let worker = Arc::clone(&shared);
        std::thread::Builder::new()
            .name(name.into())
            .spawn(move || {
                while let Some((generation, request)) = next_request(&worker) {
                    let context = Job {
                        generation,
                        shared: &worker.latest,
                        replies: &tx,
                        waker: &waker,
                    };
                    job(request, &context);
                }
            })
            .expect("spawn a worker thread");
        Worker {
            requester: Requester { shared },
            replies,
            taken: 0,
            finished: true,
        }
    }
}

impl<Req, Out> Worker<Req, Out> {
    /// The request side, to hand to another thread.
    pub fn requester(&self) -> Requester<Req> {
        self.requester.clone()
    }

    /// Ask for `request` (see [`Requester::request`]).
    pub fn request(&self, request: Req) {
        self.requester.request(request);
    }

    /// Make the job in progress stale (see [`Requester::cancel`]).
    pub fn cancel(&self) {
        self.requester.cancel();
    }

    /// The replies that arrived since the last poll, oldest first, without stale ones
    /// (a reply older than one already taken).
    pub fn poll(&mut self) -> Vec<Out> {
        let mut fresh = Vec::new();
        while let Ok(reply) = self.replies.try_recv() {
            if let Some(out) = self.take(reply) {
                fresh.push(out);
            }
        }
        fresh
    }

    /// Block until the newest request's job has sent its last reply (or the thread is
    /// gone); the replies that arrived meanwhile, as [`Worker::poll`].
    pub fn wait(&mut self) -> Vec<Out> {
        let mut fresh = Vec::new();
        while self.is_busy() {
            match self.replies.recv() {
                Ok(reply) => fresh.extend(self.take(reply)),
                Err(_) => break,
            }
        }
        fresh
    }

    fn take(&mut self, reply: Reply<Out>) -> Option<Out> {
        if reply.generation < self.taken {
            return None;
        }
        self.taken = reply.generation;
        self.finished = reply.last;
        Some(reply.out)
    }

    /// Whether a reply to the newest request is still to come (none is after a cancel:
    /// a job that finds itself stale stops without a last reply).
    pub fn is_busy(&self) -> bool {
        let shared = &self.requester.shared;
        let requested = shared.requested.load(Ordering::SeqCst);
        requested == shared.latest.load(Ordering::SeqCst)
            && (self.taken < requested || !self.finished)
    }
}

impl<Req, Out> Drop for Worker<Req, Out> {
    fn drop(&mut self) {
        let shared = &self.requester.shared;
        shared.latest.fetch_add(1, Ordering::SeqCst);
        if let Ok(mut slot) = shared.slot.lock() {
            slot.quit = true;
            shared.wake.notify_one();
        }
    }
}

/// Wait for the next request; `None` when the worker is dropped.
fn next_request<Req>(shared: &Shared<Req>) -> Option<(u64, Req)> {
    let mut slot = shared.slot.lock().expect("worker lock");
    loop {
        if slot.quit {
            return None;
        }
        if let Some(request) = slot.request.take() {
            return Some(request);
        }
        slot = shared.wake.wait(slot).expect("worker lock");
    }
}
