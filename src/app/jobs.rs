//! Saving and exporting off the UI thread: each file the editor writes is written by a job
//! on a thread of its own (atomically, by the writers it calls), while the window shows
//! what is being written; the job's outcome comes back as a status line or an error for
//! the window. The editor does not close while a job runs: it waits for them.

use std::path::PathBuf;
use std::sync::mpsc;

/// What a finished job wrote, for the editor to act on.
#[derive(Clone, Debug, PartialEq)]
pub enum Done {
    /// The score of document revision `revision` was saved at `path`.
    Saved { path: PathBuf, revision: u64 },
    /// An export was written; the status line says what.
    Exported,
}

/// Why a job wrote nothing.
pub type JobError = Box<dyn std::error::Error + Send + Sync>;

/// A finished job: what it was, and a status line or why it failed.
pub struct Finished {
    pub done: Done,
    pub result: Result<String, JobError>,
}

/// A writing thread that ended without saying how (it panicked).
#[derive(Debug, thiserror::Error)]
#[error("{0}: the writing thread stopped")]
struct Stopped(String);

struct Running {
    label: String,
    replies: mpsc::Receiver<Finished>,
}

impl Running {
    /// The outcome of a job whose thread ended without one (it panicked).
    fn stopped(&self) -> Finished {
        Finished {
            done: Done::Exported,
            result: Err(Box::new(Stopped(self.label.clone()))),
        }
    }
}

/// The jobs running now.
#[derive(Default)]
pub struct Jobs {
    running: Vec<Running>,
    wake: Option<std::sync::Arc<dyn Fn() + Send + Sync>>,
}

impl Jobs {
    /// Call `wake` when a job finishes (the UI's repaint).
    pub fn set_waker(&mut self, wake: impl Fn() + Send + Sync + 'static) {
        self.wake = Some(std::sync::Arc::new(wake));
    }

    /// Run `write` on a new thread, shown as `label` while it runs; `done` says what it
    /// was when it finishes.
    pub fn spawn<E: std::error::Error + Send + Sync + 'static>(
        &mut self,
        label: String,
        done: Done,
        write: impl FnOnce() -> Result<String, E> + Send + 'static,
    ) {
        let (tx, replies) = mpsc::channel();
        let wake = self.wake.clone();
        std::thread::Builder::new()
            .name("write".into())
            .spawn(move || {
                let result = write().map_err(|e| Box::new(e) as JobError);
                let _ = tx.send(Finished { done, result });
                if let Some(wake) = wake {
                    wake();
                }
            })
            .expect("spawn a writing thread");
        self.running.push(Running { label, replies });
    }

    /// The jobs that finished since the last poll, in the order they were started.
    pub fn poll(&mut self) -> Vec<Finished> {
        let mut finished = Vec::new();
        self.running.retain(|job| match job.replies.try_recv() {
            Ok(f) => {
                finished.push(f);
                false
            }
            Err(mpsc::TryRecvError::Empty) => true,
            Err(mpsc::TryRecvError::Disconnected) => {
                finished.push(job.stopped());
                false
            }
        });
        finished
    }

    /// Block until every job has finished; what they did, as [`Jobs::poll`].
    pub fn wait(&mut self) -> Vec<Finished> {
        self.running
            .drain(..)
            .map(|job| job.replies.recv().unwrap_or_else(|_| job.stopped()))
            .collect()
    }

    /// What is being written now, e.g. "saving etude.ron".
    pub fn labels(&self) -> impl Iterator<Item = &str> {
        self.running.iter().map(|j| j.label.as_str())
    }

    /// Whether any job runs.
    pub fn is_busy(&self) -> bool {
        !self.running.is_empty()
    }
}
