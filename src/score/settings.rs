//! How a score is performed and heard, saved with it: the control pipeline, the IK
//! method, the PD gains, the body's step, the sound model and room, the membrane modes,
//! and per-drum changes of the kit (head diameter, tension). Absent from a file means the
//! defaults; a score with default settings is written without them.

use crate::base::choices::{
    BodyStep, DEFAULT_MODE_COUNT, FrequencySource, IkMethod, MAX_MODE_COUNT, Pipeline, Room,
    SoundModel,
};
use crate::base::problem::Problem;
use crate::kit::Kit;
use serde::{Deserialize, Serialize};
use std::borrow::Cow;

/// A change to one drum of the kit.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DrumChange {
    /// Index of the drum in the kit.
    pub drum: usize,
    /// Head diameter, m.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub diameter_m: Option<f64>,
    /// Membrane tension, N/m.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tension_n_per_m: Option<f64>,
}

/// Range of the PD gain scale.
pub const GAIN_SCALE_RANGE: std::ops::RangeInclusive<f64> = 0.25..=4.0;
/// Range of membrane modes per head.
pub const MODE_COUNT_RANGE: std::ops::RangeInclusive<usize> = 1..=MAX_MODE_COUNT;
/// Range of head diameters, m.
pub const DIAMETER_RANGE_M: std::ops::RangeInclusive<f64> = 0.4..=0.9;
/// Range of membrane tensions, N/m.
pub const TENSION_RANGE_N_PER_M: std::ops::RangeInclusive<f64> = 500.0..=20_000.0;

/// The performance and sound settings of a score.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Settings {
    pub control: Pipeline,
    pub ik: IkMethod,
    /// Every PD gain multiplied by this (1 = nominal).
    pub gain_scale: f64,
    /// How finely the body is stepped between contacts (fast by default).
    #[serde(skip_serializing_if = "BodyStep::is_default")]
    pub body_step: BodyStep,
    pub sound: SoundModel,
    /// The room the drums are heard in (dry by default).
    #[serde(skip_serializing_if = "Room::is_dry")]
    pub room: Room,
    /// Membrane modes per head (both orientations of a pair count).
    pub modes: usize,
    pub frequencies: FrequencySource,
    /// Changes to the kit's drums, at most one per drum.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub drums: Vec<DrumChange>,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            control: Pipeline::Himc,
            ik: IkMethod::DampedLeastSquares,
            gain_scale: 1.0,
            body_step: BodyStep::Fast,
            sound: SoundModel::Modal,
            room: Room::Dry,
            modes: DEFAULT_MODE_COUNT,
            frequencies: FrequencySource::Measured,
            drums: Vec::new(),
        }
    }
}

impl Settings {
    /// Whether these are the defaults (then a score file leaves them out).
    pub fn is_default(&self) -> bool {
        *self == Settings::default()
    }

    /// The change to drum `drum`, if any.
    pub fn drum(&self, drum: usize) -> Option<&DrumChange> {
        self.drums.iter().find(|c| c.drum == drum)
    }

    /// Set drum `drum`'s change (removed when it changes nothing).
    pub fn set_drum(&mut self, change: DrumChange) {
        self.drums.retain(|c| c.drum != change.drum);
        if change.diameter_m.is_some() || change.tension_n_per_m.is_some() {
            self.drums.push(change);
            self.drums.sort_by_key(|c| c.drum);
        }
    }

    /// `kit` with the drum changes applied (borrowed as it is when there are none: the
    /// 3D view asks every frame).
    pub fn kit<'k>(&self, kit: &'k Kit) -> Cow<'k, Kit> {
        if self.drums.is_empty() {
            return Cow::Borrowed(kit);
        }
        let mut kit = kit.clone();
        for change in &self.drums {
            if let Some(drum) = kit.drums.get_mut(change.drum) {
                if let Some(d) = change.diameter_m {
                    drum.diameter_m = d;
                }
                if let Some(t) = change.tension_n_per_m {
                    drum.membrane.tension_n_per_m = t;
                }
            }
        }
        Cow::Owned(kit)
    }

    /// Every problem with these settings for `kit`, named by their place in the file.
    pub fn problems(&self, kit: &Kit) -> Vec<Problem> {
        let mut out = Vec::new();
        if !GAIN_SCALE_RANGE.contains(&self.gain_scale) {
            out.push(Problem::new(
                "settings.gain_scale",
                format!("{} is not between 0.25 and 4", self.gain_scale),
            ));
        }
        if !MODE_COUNT_RANGE.contains(&self.modes) {
            out.push(Problem::new(
                "settings.modes",
                format!("{} is not between 1 and 200", self.modes),
            ));
        }
        for (i, c) in self.drums.iter().enumerate() {
            let place = format!("settings.drums[{i}]");
            if c.drum >= kit.drums.len() {
                out.push(Problem::new(
                    &place,
                    format!("drum {} does not exist in kit \"{}\"", c.drum, kit.name),
                ));
            }
            if self.drums[..i].iter().any(|o| o.drum == c.drum) {
                out.push(Problem::new(
                    &place,
                    format!("drum {} changed twice", c.drum),
                ));
            }
            if let Some(d) = c.diameter_m.filter(|d| !DIAMETER_RANGE_M.contains(d)) {
                out.push(Problem::new(
                    &place,
                    format!("diameter {d} m is not between 0.4 and 0.9 m"),
                ));
            }
            if let Some(t) = c
                .tension_n_per_m
                .filter(|t| !TENSION_RANGE_N_PER_M.contains(t))
            {
                out.push(Problem::new(
                    &place,
                    format!("tension {t} N/m is not between 500 and 20000 N/m"),
                ));
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Drum changes apply to a copy of the kit; a change that changes nothing is dropped.
    #[test]
    fn drum_changes_apply_and_drop() {
        let kit = Kit::standard();
        let mut s = Settings::default();
        assert!(s.is_default());
        s.set_drum(DrumChange {
            drum: 1,
            diameter_m: Some(0.7),
            tension_n_per_m: None,
        });
        let changed = s.kit(&kit);
        assert_eq!(changed.drums[1].diameter_m, 0.7);
        assert_eq!(changed.drums[0], kit.drums[0]);
        assert!(!s.is_default() && s.problems(&kit).is_empty());
        s.set_drum(DrumChange {
            drum: 1,
            diameter_m: None,
            tension_n_per_m: None,
        });
        assert!(s.is_default());
    }

    /// The body step is saved only when it is not the fast default, and read back; a
    /// misspelt one is refused naming the choices.
    #[test]
    fn the_body_step_is_saved_when_it_is_the_reference() {
        let fast = ron::to_string(&Settings::default()).unwrap();
        assert!(!fast.contains("body_step"), "{fast}");
        let reference = Settings {
            body_step: BodyStep::Reference,
            ..Settings::default()
        };
        let text = ron::to_string(&reference).unwrap();
        assert!(text.contains("body_step:Reference"), "{text}");
        assert_eq!(ron::from_str::<Settings>(&text).unwrap(), reference);
        assert_eq!(
            (
                BodyStep::Fast.contact_substeps(),
                BodyStep::Reference.contact_substeps()
            ),
            (2, 1)
        );
        let wrong = ron::from_str::<Settings>("(body_step: Slow)").unwrap_err();
        assert!(wrong.to_string().contains("Fast"), "{wrong}");
    }

    /// Out-of-range values are named by their place.
    #[test]
    fn problems_name_the_field() {
        let kit = Kit::standard();
        let s = Settings {
            gain_scale: 9.0,
            modes: 0,
            drums: vec![DrumChange {
                drum: 99,
                diameter_m: Some(2.0),
                tension_n_per_m: None,
            }],
            ..Settings::default()
        };
        let text: Vec<String> = s.problems(&kit).iter().map(|p| p.to_string()).collect();
        assert_eq!(text.len(), 4, "{text:?}");
        assert!(text[0].contains("settings.gain_scale"), "{text:?}");
        assert!(text[1].contains("settings.modes"), "{text:?}");
        assert!(text[2].contains("settings.drums[0]") && text[2].contains("99"));
        assert!(text[3].contains("diameter 2 m"), "{text:?}");
    }
}
