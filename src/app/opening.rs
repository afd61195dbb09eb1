//! Opening a recording off the UI thread: it is decoded and transcribed, which takes
//! seconds for minutes of audio (a 5-minute MP3 about 5 s here), so a thread reads it
//! while the window keeps drawing a dialog that says what is being read, for how long,
//! and offers Cancel. Scores, MIDI and MusicXML files read in milliseconds and open at
//! once, on the UI thread.

use super::files::{self, Opened};
use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::{Duration, Instant};

/// What the reading thread gives back: the document, or why it did not open.
pub type Outcome = Result<Opened, String>;

/// A file being read on a thread of its own.
pub struct Opening {
    path: PathBuf,
    started: Instant,
    reply: mpsc::Receiver<Outcome>,
}

impl Opening {
    /// Start reading `path` ([`files::read`]); `wake` is called when it is read.
    pub fn start(path: &Path, wake: Option<Box<dyn Fn() + Send>>) -> Opening {
        let (tx, reply) = mpsc::channel();
        let target = path.to_path_buf();
        std::thread::Builder::new()
            .name("open".into())
            .spawn(move || {
                let _ = tx.send(files::read(&target).map_err(|e| e.to_string()));
                if let Some(wake) = wake {
                    wake();
                }
            })
            .expect("spawn a reading thread");
        Opening {
            path: path.to_path_buf(),
            started: Instant::now(),
            reply,
        }
    }

    /// The outcome once the file is read; `None` while it is being read.
    pub fn poll(&self) -> Option<Outcome> {
        match self.reply.try_recv() {
            Ok(outcome) => Some(outcome),
            Err(mpsc::TryRecvError::Empty) => None,
            Err(mpsc::TryRecvError::Disconnected) => Some(Err(self.stopped())),
        }
    }

    /// Block until the file is read.
    pub fn wait(self) -> Outcome {
        self.reply.recv().unwrap_or_else(|_| Err(self.stopped()))
    }

    /// The file being read.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// How long it has been read for.
    pub fn elapsed(&self) -> Duration {
        self.started.elapsed()
    }

    /// The outcome of a thread that ended without one (it panicked).
    fn stopped(&self) -> String {
        format!("{}: the reading thread stopped", self.path.display())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A recording is read on the thread and comes back as a document; a missing file
    /// comes back as its error.
    #[test]
    fn reads_on_a_thread() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let note = root.join("tests/fixtures/recordings/d2-note.flac");
        let opened = Opening::start(&note, None).wait().unwrap();
        assert_eq!(opened.loaded.score.beats.len(), 1);
        assert!(opened.path.is_none(), "a transcription is not saved yet");
        let missing = Opening::start(Path::new("/no/such/take.mp3"), None);
        assert_eq!(missing.path(), Path::new("/no/such/take.mp3"));
        let error = missing.wait().unwrap_err();
        assert!(error.contains("/no/such/take.mp3"), "{error}");
    }
}
