//! How the score was last looked at in the editor, saved with it: the 3D view's orbit
//! camera (the point looked at, m in the performer frame; yaw and pitch, rad; distance,
//! m). Plain numbers only — the editor converts them to and from its camera. Absent from
//! a file (as in every score written before it existed) means the editor's own camera.

use serde::{Deserialize, Serialize};

/// The editor's view of a score.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ViewSettings {
    /// The 3D view's camera when the score was saved.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub camera: Option<SavedCamera>,
}

/// An orbit camera as saved.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SavedCamera {
    /// The point orbited and looked at, m (performer frame: x right, y forward, z up).
    pub target_m: [f32; 3],
    /// Angle about the vertical through the target, rad (0: in front of the player).
    pub yaw_rad: f32,
    /// Elevation above the horizontal, rad.
    pub pitch_rad: f32,
    /// Distance from the target, m.
    pub distance_m: f32,
}

impl SavedCamera {
    /// Whether every number is finite and the distance positive (a camera that can be
    /// shown).
    pub fn is_usable(&self) -> bool {
        let numbers = [self.yaw_rad, self.pitch_rad, self.distance_m];
        self.target_m.iter().chain(&numbers).all(|v| v.is_finite()) && self.distance_m > 0.0
    }
}

#[cfg(test)]
mod tests {
    use crate::score::{Score, ViewSettings};
    use std::path::Path;

    /// A score with a saved camera writes it and reads it back unchanged; one without
    /// writes no `view` at all, and a file without one (as every older file) loads.
    #[test]
    fn camera_round_trips_and_is_optional() {
        let mut score = Score::new("t");
        let plain = score.to_ron();
        assert!(!plain.contains("view"), "{plain}");
        assert_eq!(Score::parse(Path::new("t.ron"), &plain).unwrap().view, None);
        let camera = super::SavedCamera {
            target_m: [0.1, 0.35, 0.95],
            yaw_rad: 2.7,
            pitch_rad: 0.85,
            distance_m: 1.9,
        };
        assert!(camera.is_usable());
        score.view = Some(ViewSettings {
            camera: Some(camera),
        });
        let text = score.to_ron();
        assert!(text.contains("yaw_rad"), "{text}");
        assert_eq!(Score::parse(Path::new("t.ron"), &text).unwrap(), score);
        let bad = super::SavedCamera {
            distance_m: f32::NAN,
            ..camera
        };
        assert!(!bad.is_usable());
    }
}
