//! The choices a score's settings make and the layers above carry out: the control
//! pipeline (IK, ID or HIMC, seed 000 §3), the IK method, where membrane mode frequencies
//! come from, how many modes a head has, and the sound model. Named here, below the
//! score, so the score can save them without importing the physics or the sound.

use std::fmt;
use std::str::FromStr;

/// A name that names none of the choices (e.g. `--sound loud`).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown {what} `{name}` (expected {expected})")]
pub struct UnknownName {
    /// What kind of choice was asked for, e.g. "sound model".
    pub what: &'static str,
    pub name: String,
    /// The names that would do, e.g. "modal, sample or signal".
    pub expected: &'static str,
}

/// A control pipeline.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Pipeline {
    Ik,
    Id,
    Himc,
}

impl Pipeline {
    /// Lower-case name.
    pub fn name(self) -> &'static str {
        match self {
            Pipeline::Ik => "ik",
            Pipeline::Id => "id",
            Pipeline::Himc => "himc",
        }
    }
}

/// How each iteration turns the tip error into joint steps.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum IkMethod {
    /// Δθ = α·Jᵀe (α chosen by the optimal step along Jᵀe).
    Transpose,
    /// Δθ = Jᵀ(JJᵀ)⁻¹e.
    PseudoInverse,
    /// Δθ = Jᵀ(JJᵀ + λ²I)⁻¹e.
    DampedLeastSquares,
}

/// Default number of mode orientations per head in the mechanics (the stick meets them;
/// the sound is full-band regardless). A point force on a head excites every mode, and a
/// truncated set leaves its highest modes to carry the local response: with 24 the 32-inch
/// head (top mode ≈ 500 Hz) threw a free mallet back and caught it again every 2 ms, with
/// 48 a free ff stroke still came back at 19 N, with 100 at most 3 N.
pub const DEFAULT_MODE_COUNT: usize = 100;
/// Largest number of mode orientations per head.
pub const MAX_MODE_COUNT: usize = 200;

/// Where mode frequencies come from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum FrequencySource {
    /// The kit's measured ratios to the (1,1) for the modes it lists (kettledrum
    /// 1.50, 1.98, 2.44, 2.94 by default), the in-vacuo membrane for the others.
    #[default]
    Measured,
    /// The ideal membrane, f_mn = air_loading · j_mn/(2πa) · √(T/σ), for every mode.
    Membrane,
}

/// Which sound model renders.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize,
)]
pub enum SoundModel {
    /// Modal voices driven by the simulated contact force.
    #[default]
    Modal,
    /// A recorded note per drum, pitched and scaled by impact speed.
    Sample,
    /// Decaying partials at the kit's modes plus a noise burst.
    Signal,
}

impl SoundModel {
    /// Every model with its command-line name.
    pub const ALL: [(SoundModel, &'static str); 3] = [
        (SoundModel::Modal, "modal"),
        (SoundModel::Sample, "sample"),
        (SoundModel::Signal, "signal"),
    ];
}

/// The name `all` gives `value` ("?" for none).
fn name_in<T: PartialEq>(all: &[(T, &'static str)], value: &T) -> &'static str {
    all.iter().find(|(v, _)| v == value).map_or("?", |(_, n)| n)
}

/// The choice of `all` named `name` (any case), else which names would do.
fn parse_in<T: Copy>(
    all: &[(T, &'static str)],
    name: &str,
    (what, expected): (&'static str, &'static str),
) -> Result<T, UnknownName> {
    all.iter()
        .find(|(_, n)| n.eq_ignore_ascii_case(name.trim()))
        .map(|(v, _)| *v)
        .ok_or_else(|| UnknownName {
            what,
            name: name.to_string(),
            expected,
        })
}

impl fmt::Display for SoundModel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(name_in(&Self::ALL, self))
    }
}

impl FromStr for SoundModel {
    type Err = UnknownName;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        parse_in(&Self::ALL, s, ("sound model", "modal, sample or signal"))
    }
}

/// How finely the body's dynamics are stepped. The drums and the stick–head contact step
/// at 10 kHz either way, and the body steps with them while a stick is on a head; between
/// contacts the fast step moves the body every 0.2 ms, and every 0.4 ms with its fast PD
/// loops implicit while it is calm, away from strokes and hand placements (README
/// "Physics (HIMC)", "a coarser body step" and "calm stretches": 0.38 mm RMS from the
/// reference's tip paths on the demo scores).
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize,
)]
pub enum BodyStep {
    /// 5 kHz between contacts, 2.5 kHz while calm (the default).
    #[default]
    Fast,
    /// 10 kHz throughout: the reference the fast step is measured against.
    Reference,
}

impl BodyStep {
    /// Whether this is the default (a score file then leaves it out).
    pub fn is_default(&self) -> bool {
        *self == BodyStep::default()
    }

    /// Contact steps (10 kHz) per body step between contacts.
    pub fn contact_substeps(self) -> usize {
        match self {
            BodyStep::Fast => 2,
            BodyStep::Reference => 1,
        }
    }

    /// Contact steps (10 kHz) per body step while the body is calm, its PD loops stepped
    /// implicitly (0: no coarser step).
    pub fn calm_substeps(self) -> usize {
        match self {
            BodyStep::Fast => 4,
            BodyStep::Reference => 0,
        }
    }
}

/// The room the drums are heard in: none (the direct sound alone, as the heads radiate
/// it), or a room's reverberation added (`sound::room`).
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize,
)]
pub enum Room {
    /// The direct sound alone.
    #[default]
    Dry,
    /// A recording studio (T60 0.52 s at low frequencies), spot microphones 0.5 m from
    /// the heads.
    Studio,
    /// A concert hall (T60 2.2 s at low frequencies), microphones at 3 m.
    Hall,
}

impl Room {
    /// Every room with its command-line name.
    pub const ALL: [(Room, &'static str); 3] = [
        (Room::Dry, "dry"),
        (Room::Studio, "studio"),
        (Room::Hall, "hall"),
    ];

    /// Whether this is the dry default (a score file then leaves it out).
    pub fn is_dry(&self) -> bool {
        *self == Room::Dry
    }
}

impl fmt::Display for Room {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(name_in(&Self::ALL, self))
    }
}

impl FromStr for Room {
    type Err = UnknownName;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        parse_in(&Self::ALL, s, ("room", "dry, studio or hall"))
    }
}
