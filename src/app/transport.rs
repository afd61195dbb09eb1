//! The transport: the playhead, the loop region and the playback clock it follows, and
//! Space's rule — play at once if the audio past the playhead is rendered, else wait for
//! it (the rendering worker delivers the edited part first, then the rest). Also slow
//! motion (the speeds of [`SPEEDS`]; below 1 the mix is muted and each contact passed
//! sounds at full speed, `super::strike_sounds`) and stepping the playhead by a
//! video frame ([`FRAME_S`]) or to the previous or next contact.

use super::playback::{Playback, PlaybackError, SPEEDS};
use super::strike_sounds::StrikeSounds;
use super::tape::StereoSource;
use crate::render::Rendering;
use crate::score::Score;
use std::sync::Arc;

/// Space plays at once only if this much audio past the playhead is ready, s.
const PLAY_AHEAD_S: f64 = 0.3;

/// One video frame, the step of `,` and `.`, s (60 frames per second).
pub const FRAME_S: f64 = 1.0 / 60.0;

/// Where playback is and what it plays.
pub struct Transport {
    pub playback: Playback,
    /// The playhead, s.
    pub playhead_s: f64,
    /// The loop region, ticks.
    pub loop_ticks: Option<(u64, u64)>,
    pub looping: bool,
    /// Score time up to which the audio given to playback is final, s (infinite once a
    /// whole rendering, or none, is in).
    audio_ready_s: f64,
    /// Space was pressed where the audio is not ready yet: play once it is.
    waiting_to_play: bool,
    /// The contacts heard one by one in slow motion.
    strikes: StrikeSounds,
}

impl Transport {
    /// Stopped at 0 s on `playback`.
    pub fn new(playback: Playback) -> Transport {
        Transport {
            playback,
            playhead_s: 0.0,
            loop_ticks: None,
            looping: false,
            audio_ready_s: f64::INFINITY,
            waiting_to_play: false,
            strikes: StrikeSounds::default(),
        }
    }

    /// Stop and go back to the start, with no loop (a new document).
    pub fn reset(&mut self) {
        self.playback.pause();
        self.playback.seek(0.0);
        self.playhead_s = 0.0;
        self.loop_ticks = None;
        self.waiting_to_play = false;
        self.strikes.clear();
    }

    /// Move the playhead to `t_s` (clamped at 0), s.
    pub fn seek(&mut self, t_s: f64) {
        self.playhead_s = t_s.max(0.0);
        self.playback.seek(self.playhead_s);
    }

    /// Set or clear the loop region, ticks.
    pub fn set_loop(&mut self, region: Option<(u64, u64)>) {
        self.loop_ticks = region;
        self.looping = region.is_some();
    }

    /// Space: pause, cancel a wait, wait for audio not yet rendered, or play. Returns a
    /// message for the status bar, if any.
    pub fn play_pause(&mut self) -> Option<String> {
        if self.playback.is_playing() {
            self.pause();
            None
        } else if self.waiting_to_play {
            self.waiting_to_play = false;
            Some("playback cancelled".into())
        } else if self.playhead_s + PLAY_AHEAD_S > self.audio_ready_s {
            self.waiting_to_play = true;
            Some(format!(
                "waiting for the audio at {:.1} s (ready to {:.1} s)",
                self.playhead_s, self.audio_ready_s
            ))
        } else {
            self.playback.play_from(self.playhead_s);
            None
        }
    }

    /// Play `rendering`'s audio (shared, not copied), and start playing if Space waits
    /// for audio that is now ready.
    pub fn load(&mut self, rendering: &Arc<Rendering>) -> Result<(), PlaybackError> {
        let ready_s = if rendering.complete {
            f64::INFINITY
        } else {
            rendering.ready_s
        };
        self.playback
            .set_audio(Arc::clone(rendering) as Arc<dyn StereoSource>)?;
        self.strikes.set(rendering);
        self.audio_ready_s = ready_s;
        if self.waiting_to_play && self.playhead_s + PLAY_AHEAD_S <= self.audio_ready_s {
            self.waiting_to_play = false;
            self.playback.play_from(self.playhead_s);
        }
        Ok(())
    }

    /// Move `steps` places along [`SPEEDS`] (positive: faster), keeping the playhead;
    /// the new speed.
    pub fn change_speed(&mut self, steps: i64) -> f64 {
        let now = SPEEDS
            .iter()
            .position(|s| *s <= self.playback.speed())
            .unwrap_or(SPEEDS.len() - 1) as i64;
        let to = (now - steps).clamp(0, SPEEDS.len() as i64 - 1) as usize;
        self.playback.set_speed(SPEEDS[to]);
        SPEEDS[to]
    }

    /// Pause and move the playhead `frames` video frames (of [`FRAME_S`]) from the
    /// frame nearest it.
    pub fn step_frames(&mut self, frames: i64) {
        self.pause();
        let frame = (self.playhead_s / FRAME_S).round() + frames as f64;
        self.seek(frame * FRAME_S);
    }

    /// Pause and move the playhead to the first of `contacts_s` (times, s) after it
    /// (`forward`) or the last before it; false, staying put, when there is none.
    pub fn step_to_contact(
        &mut self,
        contacts_s: impl IntoIterator<Item = f64>,
        forward: bool,
    ) -> bool {
        self.pause();
        let here = self.playhead_s;
        let times = contacts_s.into_iter();
        let found = if forward {
            times.filter(|t| *t > here + 1e-6).min_by(f64::total_cmp)
        } else {
            times.filter(|t| *t < here - 1e-6).max_by(f64::total_cmp)
        };
        found.inspect(|t| self.seek(*t)).is_some()
    }

    /// Stop at the current position (and stop waiting to play).
    fn pause(&mut self) {
        if self.playback.is_playing() {
            self.playback.pause();
            self.playhead_s = self.playback.position_s();
        }
        self.waiting_to_play = false;
    }

    /// Whether Space waits for audio not yet rendered.
    pub fn is_waiting_to_play(&self) -> bool {
        self.waiting_to_play
    }

    /// Follow the playback clock through `score`: move the playhead, wrap at the loop end,
    /// stop past the end. The tick at the playhead while playing (for the timeline).
    pub fn follow(&mut self, score: Option<&Score>) -> Option<f64> {
        if !self.playback.is_playing() {
            return None;
        }
        let before = self.playhead_s;
        self.playhead_s = self.playback.position_s();
        if self.playback.speed() < 1.0 {
            let passed = self.strikes.crossed(before, self.playhead_s).to_vec();
            for t in passed {
                let sound = self.strikes.snippet(t);
                self.playback.play_once(&sound);
            }
        }
        let score = score?;
        let map = score.tempo_map();
        if self.looping
            && let Some((a, b)) = self.loop_ticks
            && self.playhead_s >= map.seconds_at(b as f64)
        {
            let start = map.seconds_at(a as f64);
            self.playback.play_from(start);
            self.playhead_s = start;
        } else if self.playhead_s > score.duration_s() + 1.0 {
            self.playback.pause();
        }
        Some(map.tick_at(self.playhead_s))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `[` and `]` walk the speeds and stop at the ends; frame steps land on the 60 Hz
    /// grid; contact steps find the neighbours and stay put past the last.
    #[test]
    fn speeds_and_steps() {
        let mut t = Transport::new(Playback::silent());
        assert_eq!(t.change_speed(-1), 0.5);
        assert_eq!(t.change_speed(-5), 0.1);
        assert_eq!(t.change_speed(1), 0.25);
        assert_eq!(t.change_speed(9), 1.0);
        t.seek(0.101);
        t.step_frames(1);
        assert!(
            (t.playhead_s - 7.0 / 60.0).abs() < 1e-12,
            "{}",
            t.playhead_s
        );
        t.step_frames(-2);
        assert!((t.playhead_s - 5.0 / 60.0).abs() < 1e-12);
        let contacts = [0.5, 1.0, 1.5];
        assert!(t.step_to_contact(contacts, true));
        assert_eq!(t.playhead_s, 0.5);
        assert!(t.step_to_contact(contacts, true));
        assert_eq!(t.playhead_s, 1.0);
        assert!(t.step_to_contact(contacts, false));
        assert_eq!(t.playhead_s, 0.5);
        assert!(!t.step_to_contact(contacts, false));
        assert_eq!(t.playhead_s, 0.5);
        assert_eq!(t.playback.position_s(), 0.5);
    }
}
