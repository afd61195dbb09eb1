//! Reading older score formats: each older version is its own strict struct, converted
//! to the current [`Score`] on load.

use super::{Beat, Grip, MeterChange, SCORE_FORMAT_VERSION, Score, TempoPoint};
use serde::Deserialize;

/// Format 1: as format 2 without trajectory handles and impact pins.
#[derive(Deserialize)]
#[serde(rename = "Score", deny_unknown_fields)]
pub(super) struct ScoreV1 {
    #[allow(dead_code)]
    version: u32,
    title: String,
    kit: String,
    grip: Grip,
    ticks_per_quarter: u32,
    tempo: Vec<TempoPoint>,
    meter: Vec<MeterChange>,
    beats: Vec<Beat>,
}

/// Bring a format 1 score to the current format.
pub(super) fn from_v1(v1: ScoreV1) -> Score {
    Score {
        version: SCORE_FORMAT_VERSION,
        title: v1.title,
        kit: v1.kit,
        grip: v1.grip,
        ticks_per_quarter: v1.ticks_per_quarter,
        tempo: v1.tempo,
        meter: v1.meter,
        beats: v1.beats,
        handles: Vec::new(),
        pins: Vec::new(),
        settings: super::Settings::default(),
        view: None,
    }
}

#[cfg(test)]
mod tests {
    use crate::score::Score;
    use std::path::Path;

    /// A format 1 file loads as the current format with no handles or pins, and a typo in
    /// it is still reported with its line and column.
    #[test]
    fn version_1_migrates() {
        let v1 = "Score(version: 1, title: \"t\", kit: \"standard\", grip: French, ticks_per_quarter: 960,\n tempo: [(tick: 0, bpm: 90.0, change: Step)], meter: [(bar: 1, numerator: 4, denominator: 4)],\n beats: [])";
        let s = Score::parse(Path::new("v1.ron"), v1).unwrap();
        assert_eq!(s.version, super::SCORE_FORMAT_VERSION);
        assert!(s.handles.is_empty() && s.pins.is_empty());
        let bad = v1.replace("beats: []", "beats: [], handles: []");
        let err = Score::parse(Path::new("v1.ron"), &bad)
            .unwrap_err()
            .to_string();
        assert!(
            err.starts_with("v1.ron:3:") && err.contains("handles"),
            "{err}"
        );
    }
}
