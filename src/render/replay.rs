//! A rendering's followed targets played again open loop — no timing compensation, fresh
//! drums — with other simulation settings: what the body's step changes in the motion and
//! the contacts for the very same targets (a sub-stepped contact,
//! [`SimParams::contact_substeps`], against the 10 kHz reference). With the rendering's
//! own settings it gives back the rendering's motion and contacts bit for bit.

use super::{RenderError, Rendering, held_within, performer};
use crate::body::sim::{Environment, Motion, SimParams};
use crate::drum::DrumSet;
use glam::DVec3;

/// What the body did and the drums it struck.
#[derive(Clone, Debug)]
pub struct Replay {
    pub motion: Motion,
    pub drums: DrumSet,
}

/// The drums in score time.
struct Heads<'a> {
    drums: &'a mut DrumSet,
    start_s: f64,
}

impl Environment for Heads<'_> {
    fn tip_forces(&mut self, time_s: f64, tips: [(DVec3, DVec3); 2]) -> [DVec3; 2] {
        self.drums.step(self.start_s + time_s, tips)
    }
}

/// Follow `rendering`'s targets (`Rendering::reference`) with the simulation settings
/// `sim` (its joint limits replaced by the composition's when the rendering held them),
/// from the posture the rendering started in, on fresh drums of its kit.
pub fn replay(rendering: &Rendering, sim: &SimParams) -> Result<Replay, RenderError> {
    let params = &rendering.params;
    let mallet = rendering
        .kit
        .mallets
        .get(params.mallet)
        .ok_or(RenderError::NoMallet(params.mallet))?;
    let sim = held_within(sim, params, rendering.composition.limits);
    let reference = &rendering.reference;
    let (mut simulator, mut drums) = performer(
        (&rendering.kit, rendering.drums.retunes(), mallet),
        params,
        &sim,
        rendering.skeleton(),
        reference,
        rendering.start_s,
    )?;
    let mut heads = Heads {
        drums: &mut drums,
        start_s: rendering.start_s,
    };
    simulator
        .advance(&mut heads, reference, reference.tips[0].len())
        .map_err(|e| RenderError::of_simulation(e, rendering.start_s))?;
    Ok(Replay {
        motion: simulator.into_motion(),
        drums,
    })
}
