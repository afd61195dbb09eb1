//! A rendered performance as the writers take it: the plain parts of a rendering (the
//! score, the kit it was played on, the body's motion at the task rate and the targets it
//! followed, the skeleton, the 48 kHz audio, the scheduled strokes and every contact),
//! borrowed. `io` sits beside `render` and never names its `Rendering`; the one bridge is
//! `exports::performance`. Each teaching export is a method here, so `timpanist render`,
//! File > Export and the lesson pack (`io::pack`) write the same bytes from the same code.

use super::{bvh, glb, midi_performed, motion_c3d, motion_csv};
use crate::base::hit::Hit;
use crate::body::sim::{Motion, Reference};
use crate::body::skeleton::Skeleton;
use crate::kit::Kit;
use crate::motion::plan::PlannedStroke;
use crate::score::Score;
use crate::sound::Audio;

/// One stick–head contact with the numbers a lesson shows (times in score seconds).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Contact {
    /// Where, when and how hard (the OSC and performed-MIDI view of it).
    pub hit: Hit,
    /// The scored beat it plays (index into the score's beats); `None` for a rebound or
    /// re-contact.
    pub beat: Option<usize>,
    /// When its stroke was scheduled, s (`None` for a rebound).
    pub scheduled_s: Option<f64>,
    /// How long the felt touched the head, s.
    pub duration_s: f64,
}

impl Contact {
    /// Contact time minus scheduled time, s (positive: late); `None` for a rebound.
    pub fn timing_error_s(&self) -> Option<f64> {
        self.scheduled_s.map(|s| self.hit.time_s - s)
    }
}

/// The plain parts of one rendering of `score`.
pub struct Performance<'a> {
    pub score: &'a Score,
    /// The kit as played (the score's drum settings applied).
    pub kit: &'a Kit,
    /// What the body did, at the task rate (250 Hz), sample 0 at `start_s`.
    pub motion: &'a Motion,
    /// The targets the body followed, sampled as `motion`.
    pub reference: &'a Reference,
    /// Score time of motion sample 0, s (negative: the lead-in before the first beat).
    pub start_s: f64,
    /// The body that played it.
    pub skeleton: Skeleton,
    /// The mix, from score time 0.
    pub audio: &'a Audio,
    /// The scheduled strokes (each stroke of a roll its own), in time order.
    pub strokes: &'a [PlannedStroke],
    /// Every contact, in time order.
    pub contacts: Vec<Contact>,
    /// The render's force aims, for velocities from peak forces.
    pub force_scale: midi_performed::ForceScale,
}

impl Performance<'_> {
    /// Score time of motion sample `k`, s.
    pub fn time_of_sample(&self, k: usize) -> f64 {
        self.start_s + k as f64 / self.motion.rate_hz
    }

    /// Every contact as a performed hit (for OSC and performed MIDI).
    pub fn hits(&self) -> Vec<Hit> {
        self.contacts.iter().map(|c| c.hit).collect()
    }

    /// Length of the audio, s.
    pub fn duration_s(&self) -> f64 {
        self.audio.frames() as f64 / f64::from(self.audio.rate_hz)
    }

    /// Tips, targets and joint rotations per task sample as CSV (`io::motion_csv`).
    pub fn motion_csv(&self) -> String {
        motion_csv::to_csv(self.motion, self.reference, self.start_s)
    }

    /// Joints, tips and targets as C3D points (`io::motion_c3d`).
    pub fn c3d(&self) -> Vec<u8> {
        motion_c3d::to_c3d(self.motion, self.reference, &self.skeleton)
    }

    /// The performer as BVH (`io::bvh`).
    pub fn bvh(&self, options: &bvh::Options) -> Result<String, bvh::BvhError> {
        bvh::to_bvh(self.motion, &self.skeleton, options)
    }

    /// The scene as binary glTF (`io::glb`).
    pub fn glb(&self) -> Result<Vec<u8>, glb::GlbError> {
        glb::to_glb(self.motion, &self.skeleton, self.kit)
    }

    /// The performed hits as a Standard MIDI File (`io::midi_performed`).
    pub fn performed_midi(&self) -> Vec<u8> {
        midi_performed::export(self.score, self.kit, &self.hits(), &self.force_scale)
    }
}
