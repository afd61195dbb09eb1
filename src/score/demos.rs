//! The demo scores shipped in `scores/`, compiled into the program so an installed binary
//! has them with no source tree: `timpanist demos` lists them and writes them out, the
//! editor's File > Demo scores opens them. A demo taken out of `scores/` names its kit by
//! its bundled name ("standard", not "../kits/standard.ron"), so it loads anywhere.

use super::{LoadedScore, Score};
use crate::base::ron_file::FileError;
use std::path::{Path, PathBuf};

/// Each demo's name (its file stem in `scores/`) and text, in teaching order.
pub const DEMOS: &[(&str, &str)] = &[
    ("etude-modes", include_str!("../../scores/etude-modes.ron")),
    (
        "dynamics-ladder",
        include_str!("../../scores/dynamics-ladder.ron"),
    ),
    (
        "roll-exercise",
        include_str!("../../scores/roll-exercise.ron"),
    ),
    (
        "tempo-change",
        include_str!("../../scores/tempo-change.ron"),
    ),
    ("secco-study", include_str!("../../scores/secco-study.ron")),
    (
        "pedal-changes",
        include_str!("../../scores/pedal-changes.ron"),
    ),
    (
        "improvisation",
        include_str!("../../scores/improvisation.ron"),
    ),
    (
        "minute-study",
        include_str!("../../scores/minute-study.ron"),
    ),
];

/// How a demo is named in messages: `<built-in>/scores/NAME.ron`.
pub fn label(name: &str) -> PathBuf {
    Path::new("<built-in>/scores").join(format!("{name}.ron"))
}

/// The names of every demo, comma-separated (for messages).
pub fn names() -> String {
    DEMOS.iter().map(|(n, _)| *n).collect::<Vec<_>>().join(", ")
}

/// The text of the demo `name` as it is in `scores/`.
pub fn text(name: &str) -> Option<&'static str> {
    DEMOS.iter().find(|(n, _)| *n == name).map(|(_, t)| *t)
}

/// The demo `name` as a score standing alone: its kit named by its bundled name when the
/// kit file is a bundled kit.
pub fn score(name: &str) -> Result<Score, FileError> {
    let text = text(name).ok_or_else(|| {
        FileError::invalid(
            &label(name),
            "name",
            format!("no such demo score (demos: {})", names()),
        )
    })?;
    let mut score = Score::parse(&label(name), text)?;
    let stem = Path::new(&score.kit)
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or_default()
        .to_string();
    if crate::kit::Kit::bundled(&stem).is_some() {
        score.kit = stem;
    }
    Ok(score)
}

/// The demo `name` loaded with its kit and checked, as the editor opens it.
pub fn load(name: &str) -> Result<LoadedScore, FileError> {
    LoadedScore::from_score(&label(name), score(name)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every score in `scores/` is a demo, and every demo loads standing alone, with no
    /// notice (its kit is bundled) and at least one beat.
    #[test]
    fn every_shipped_score_is_a_demo_that_loads_alone() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scores");
        let mut on_disk: Vec<String> = std::fs::read_dir(&dir)
            .unwrap()
            .filter_map(|e| {
                let p = e.unwrap().path();
                (p.extension()? == "ron").then(|| p.file_stem()?.to_str().map(String::from))?
            })
            .collect();
        on_disk.sort();
        let mut listed: Vec<String> = DEMOS.iter().map(|(n, _)| n.to_string()).collect();
        listed.sort();
        assert_eq!(on_disk, listed, "scores/ and DEMOS differ");
        for (name, _) in DEMOS {
            let loaded = load(name).unwrap_or_else(|e| panic!("{name}: {e}"));
            assert!(loaded.notices.is_empty(), "{name}: {:?}", loaded.notices);
            assert!(!loaded.score.beats.is_empty(), "{name}");
            assert!(loaded.kit_source.starts_with("bundled kit"), "{name}");
        }
        let err = score("nonesuch").unwrap_err().to_string();
        assert!(err.contains("etude-modes"), "{err}");
    }
}
