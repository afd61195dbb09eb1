//! Telling that the sound device has gone, and when to look for it again: pure logic for
//! [`playback`](super::playback), on a heartbeat (the count of frames the audio thread has
//! filled, which stops when the device stops asking for audio) and the wall clock; no
//! audio or UI here.
//!
//! A device that goes away does not always say so: cpal reports some losses as errors,
//! kira restarts its stream on some of them, and a stream can also just stop being called.
//! The one sign common to all is that the tape is no longer asked for frames, so
//! [`Stall`] watches for that; [`Retry`] paces the attempts to open the device again.
//!
//! A stream that has just opened may wait before it is first asked for audio (through
//! PulseAudio's ALSA plugin on a busy machine, 2–4 s was seen, after which it ran
//! normally), so until it has been asked for [`WARM_FRAMES`] it has [`START_GRACE`] rather
//! than [`STALL`].

use std::time::{Duration, Instant};

/// Once running, the heartbeat must move at least this often, or the device is taken as
/// gone. Far longer than any buffer (4096 frames at 44.1 kHz are 93 ms).
pub const STALL: Duration = Duration::from_millis(500);

/// How long a stream that has not yet run may keep still.
pub const START_GRACE: Duration = Duration::from_secs(6);

/// A stream runs once it has been asked for this many frames (about a second).
pub const WARM_FRAMES: u64 = 44_100;

/// While the device is gone, try to open it again this often.
pub const RETRY: Duration = Duration::from_secs(1);

/// Watches a heartbeat for a stall.
#[derive(Clone, Debug)]
pub struct Stall {
    /// The heartbeat when the watch started.
    first: u64,
    beat: u64,
    /// When the heartbeat was last seen moving (or the watch started).
    alive_at: Instant,
}

impl Stall {
    /// Start watching at `now`, with the heartbeat at `beat`.
    pub fn new(beat: u64, now: Instant) -> Stall {
        Stall {
            first: beat,
            beat,
            alive_at: now,
        }
    }

    /// The heartbeat read at `now`: `Some(when it was last seen moving)` once it has not
    /// moved for [`STALL`] ([`START_GRACE`] before the stream [runs](Stall::is_running)),
    /// else `None`.
    pub fn observe(&mut self, beat: u64, now: Instant) -> Option<Instant> {
        if beat != self.beat {
            self.beat = beat;
            self.alive_at = now;
            return None;
        }
        let limit = if self.is_running() {
            STALL
        } else {
            START_GRACE
        };
        (now.saturating_duration_since(self.alive_at) >= limit).then_some(self.alive_at)
    }

    /// Whether the heartbeat has moved since the watch started.
    pub fn has_moved(&self) -> bool {
        self.beat != self.first
    }

    /// Whether the stream runs: it has been asked for [`WARM_FRAMES`] since the watch
    /// started.
    pub fn is_running(&self) -> bool {
        self.beat.wrapping_sub(self.first) >= WARM_FRAMES
    }
}

/// Paces attempts: the first is due at once, the next [`RETRY`] after the one before.
#[derive(Clone, Debug, Default)]
pub struct Retry {
    last: Option<Instant>,
    /// Attempts made.
    pub attempts: u32,
}

impl Retry {
    /// Whether an attempt is due at `now` (and if so, count it as made).
    pub fn due(&mut self, now: Instant) -> bool {
        let due = self
            .last
            .is_none_or(|t| now.saturating_duration_since(t) >= RETRY);
        if due {
            self.last = Some(now);
            self.attempts += 1;
        }
        due
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A running heartbeat never stalls; a still one stalls after [`STALL`], naming when
    /// it last moved; moving again clears it.
    #[test]
    fn stall_after_the_heartbeat_stops() {
        let t0 = Instant::now();
        let ms = |n: u64| t0 + Duration::from_millis(n);
        let mut s = Stall::new(0, t0);
        for i in 1..=20u64 {
            assert_eq!(s.observe(i * 4800, ms(100 * (i - 1))), None);
        }
        assert!(s.is_running() && s.has_moved());
        let last = ms(1900);
        assert_eq!(s.observe(20 * 4800, ms(2000)), None);
        assert_eq!(s.observe(20 * 4800, ms(2399)), None);
        assert_eq!(s.observe(20 * 4800, ms(2400)), Some(last));
        assert_eq!(s.observe(20 * 4800, ms(5000)), Some(last));
        assert_eq!(s.observe(21 * 4800, ms(5010)), None);
        assert!(!Stall::new(7, t0).has_moved());
    }

    /// A stream that has not run yet — never asked for audio, or asked for a few buffers
    /// and then waiting — has [`START_GRACE`]; once it has run, [`STALL`].
    #[test]
    fn a_starting_stream_has_a_grace() {
        let t0 = Instant::now();
        let mut s = Stall::new(0, t0);
        assert_eq!(s.observe(0, t0 + STALL * 2), None);
        assert_eq!(s.observe(0, t0 + START_GRACE), Some(t0));
        let mut s = Stall::new(100, t0);
        let moved = t0 + Duration::from_millis(10);
        assert_eq!(s.observe(4196, moved), None);
        assert!(s.has_moved() && !s.is_running());
        assert_eq!(s.observe(4196, moved + Duration::from_secs(3)), None);
        assert_eq!(s.observe(4196, moved + START_GRACE), Some(moved));
        let mut s = Stall::new(100, t0);
        assert_eq!(s.observe(100 + WARM_FRAMES, moved), None);
        assert_eq!(s.observe(100 + WARM_FRAMES, moved + STALL), Some(moved));
    }

    /// Attempts are due at once, then once per [`RETRY`] however often asked.
    #[test]
    fn retries_once_a_second() {
        let t0 = Instant::now();
        let mut r = Retry::default();
        let due: Vec<bool> = (0..25)
            .map(|i| r.due(t0 + Duration::from_millis(100 * i)))
            .collect();
        let at: Vec<usize> = due
            .iter()
            .enumerate()
            .filter(|p| *p.1)
            .map(|p| p.0)
            .collect();
        assert_eq!(at, [0, 10, 20]);
        assert_eq!(r.attempts, 3);
    }
}
