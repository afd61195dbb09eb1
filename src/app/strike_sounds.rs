//! Strikes heard in slow motion: the mix cannot be slowed down in sync and is muted below
//! real time, but each contact the playhead passes sounds at full speed — the rendered
//! mix's [`SNIPPET_S`] from just before the contact, pitch and timbre untouched — so a
//! teacher showing one stroke's anatomy at 1/10 speed still hears where it lands.

use crate::render::Rendering;
use std::sync::Arc;

/// Length of a strike's sound, s.
pub const SNIPPET_S: f64 = 0.3;
/// It starts this long before the contact, s.
const LEAD_S: f64 = 0.005;
/// Fade-out at its end, s.
const FADE_S: f64 = 0.03;

/// The contacts of the rendering being played and its audio.
#[derive(Default)]
pub struct StrikeSounds {
    rendering: Option<Arc<Rendering>>,
    /// Contact start times, s, sorted.
    starts_s: Vec<f64>,
}

impl StrikeSounds {
    /// Take `rendering`'s contacts and audio.
    pub fn set(&mut self, rendering: &Arc<Rendering>) {
        let mut starts: Vec<f64> = (rendering.drums.contacts().iter())
            .map(|c| c.start_s)
            .filter(|t| t.is_finite())
            .collect();
        starts.sort_by(f64::total_cmp);
        self.starts_s = starts;
        self.rendering = Some(Arc::clone(rendering));
    }

    /// Forget them (a new document).
    pub fn clear(&mut self) {
        *self = StrikeSounds::default();
    }

    /// The contacts that start after `from_s` and by `to_s`, s (none when the playhead
    /// went back, e.g. at a loop's end).
    pub fn crossed(&self, from_s: f64, to_s: f64) -> &[f64] {
        if to_s <= from_s {
            return &[];
        }
        let a = self.starts_s.partition_point(|t| *t <= from_s);
        let b = self.starts_s.partition_point(|t| *t <= to_s);
        &self.starts_s[a..b]
    }

    /// The mix around the contact at `at_s`: stereo frames from [`LEAD_S`] before it,
    /// [`SNIPPET_S`] long (less at the audio's end), fading out over its last [`FADE_S`];
    /// empty without a rendering.
    pub fn snippet(&self, at_s: f64) -> Vec<[f32; 2]> {
        let Some(r) = &self.rendering else {
            return Vec::new();
        };
        let audio = &r.audio;
        let rate = f64::from(audio.rate_hz);
        let frames = audio.samples.len() / 2;
        let first = (((at_s - LEAD_S) * rate).round().max(0.0) as usize).min(frames);
        let last = (first + (SNIPPET_S * rate) as usize).min(frames);
        let fade = (FADE_S * rate) as usize;
        (first..last)
            .map(|k| {
                let gain = ((last - k) as f32 / fade.max(1) as f32).min(1.0);
                [audio.samples[2 * k] * gain, audio.samples[2 * k + 1] * gain]
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Contacts are found between two playhead positions (the later bound included),
    /// never when the playhead went back.
    #[test]
    fn contacts_crossed() {
        let s = StrikeSounds {
            rendering: None,
            starts_s: vec![1.0, 1.5, 2.0],
        };
        assert_eq!(s.crossed(0.9, 1.0), &[1.0]);
        assert_eq!(s.crossed(1.0, 1.9), &[1.5]);
        assert_eq!(s.crossed(0.0, 5.0), &[1.0, 1.5, 2.0]);
        assert!(s.crossed(2.0, 1.0).is_empty());
        assert!(s.crossed(1.6, 1.9).is_empty());
        assert!(s.snippet(1.0).is_empty());
    }
}
