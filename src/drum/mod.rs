//! The timpani heads as modal membranes struck through a Hertz felt contact (seed
//! 000 §4, eqs. 4–6): mode tables per head ([`modes`]), the exact per-mode time
//! step ([`oscillator`]), the contact law ([`contact`]), the whole kit stepped at the
//! simulation rate with both stick tips ([`set`]), and a scripted stick for tests and
//! benchmarks ([`strike`]).

pub mod bessel;
pub mod contact;
pub mod modes;
pub mod oscillator;
pub mod set;
pub mod strike;

pub use crate::base::choices::{DEFAULT_MODE_COUNT, FrequencySource, MAX_MODE_COUNT};
pub use contact::HertzContact;
pub use modes::{HeadMode, HeadModes, Orientation};
pub use set::{ContactEvent, DrumCheckpoint, DrumSet, Excitation};

/// How many modes each head has and where their frequencies come from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ModeConfig {
    /// Mode orientations per head (both orientations of a degenerate pair count), 1–200.
    pub count: usize,
    pub source: FrequencySource,
}

impl Default for ModeConfig {
    fn default() -> Self {
        ModeConfig {
            count: DEFAULT_MODE_COUNT,
            source: FrequencySource::Measured,
        }
    }
}

impl ModeConfig {
    /// Whether the configuration is usable.
    pub fn check(&self) -> Result<(), DrumError> {
        if (1..=MAX_MODE_COUNT).contains(&self.count) {
            Ok(())
        } else {
            Err(DrumError::ModeCount(self.count))
        }
    }
}

/// Why a drum could not be set up.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DrumError {
    #[error("mode count {0} is outside 1–{MAX_MODE_COUNT}")]
    ModeCount(usize),
    #[error("drum `{0}` has a non-positive size, tension or density, or no modes")]
    InvalidDrum(String),
    #[error("mallet `{0}` needs positive stiffness, head radius and mass and an exponent 1–4")]
    InvalidMallet(String),
    #[error("simulation step {0} s is not a positive finite time")]
    TimeStep(f64),
    #[error("drum index {index} is out of range (the kit has {count})")]
    NoSuchDrum { index: usize, count: usize },
}
