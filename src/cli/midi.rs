//! `timpanist import-midi` and `timpanist export-midi`: Standard MIDI Files in and out
//! (and the score-export plumbing `export-musicxml` shares).

use crate::base::ron_file;
use crate::io::midi_export;
use crate::io::midi_import::{self, ImportOptions, TrackChoice};
use crate::kit::Kit;
use crate::score::LoadedScore;
use anyhow::Context;
use std::path::{Component, Path, PathBuf};

/// Import `input` with `kit` (default: the bundled standard kit) and save the score.
pub fn import(
    input: &Path,
    output: &Path,
    track: Option<String>,
    kit_path: Option<&Path>,
    title: Option<String>,
    detect_rolls: bool,
) -> anyhow::Result<()> {
    let (kit, kit_ref) = import_kit(kit_path, output)?;
    let options = ImportOptions {
        track: track.map(|t| t.parse::<TrackChoice>().unwrap_or(TrackChoice::Name(t))),
        kit_ref,
        title,
        detect_rolls,
    };
    let (score, report) = midi_import::import_file(input, &kit, &options)?;
    save_imported(
        (input, output),
        &score,
        &kit,
        &Imported {
            source: &report.source,
            duplicates_dropped: report.duplicates_dropped,
            octave_moves: report.octave_moves,
        },
    )?;
    for w in &report.warnings {
        eprintln!("warning: {w}");
    }
    Ok(())
}

/// The kit an import plays on (`kit_path`, else the bundled standard kit) and how the
/// score written to `output` names it.
pub(super) fn import_kit(kit_path: Option<&Path>, output: &Path) -> anyhow::Result<(Kit, String)> {
    Ok(match kit_path {
        Some(p) => (Kit::load(p)?, kit_reference(p, output)?),
        None => (Kit::standard(), "standard".to_string()),
    })
}

/// What an import says about itself on its summary line.
pub(super) struct Imported<'a> {
    pub source: &'a str,
    pub duplicates_dropped: usize,
    pub octave_moves: usize,
}

/// Save an imported `score` from `input` to `output` once it is playable on `kit`
/// (else nothing is written), and print the summary line.
pub(super) fn save_imported(
    (input, output): (&Path, &Path),
    score: &crate::score::Score,
    kit: &Kit,
    imported: &Imported,
) -> anyhow::Result<()> {
    if let Some(p) = score.problems(kit).first() {
        anyhow::bail!(
            "{}: the imported score is not playable: {p}",
            input.display()
        );
    }
    score.save(output)?;
    println!(
        "{} -> {}: {} beats from {}; {} duplicates dropped; {} notes moved by octaves",
        input.display(),
        output.display(),
        score.beats.len(),
        imported.source,
        imported.duplicates_dropped,
        imported.octave_moves
    );
    Ok(())
}

/// Export the score at `input` to a type 1 Standard MIDI File at `output`.
pub fn export(input: &Path, output: &Path) -> anyhow::Result<()> {
    export_score(input, output, &|_, score, kit| {
        midi_export::export(score, kit)
    })
}

/// Load the score at `input`, turn it into bytes with `encode` (given `output`, the
/// score and its kit) and write them atomically to `output`; print the summary line.
pub(super) fn export_score(
    input: &Path,
    output: &Path,
    encode: &dyn Fn(&Path, &crate::score::Score, &Kit) -> Vec<u8>,
) -> anyhow::Result<()> {
    let loaded = LoadedScore::load(input)?;
    for n in &loaded.notices {
        eprintln!("note: {n}");
    }
    let bytes = encode(output, &loaded.score, &loaded.score.kit(&loaded.kit));
    ron_file::write_atomic(output, &bytes)?;
    println!(
        "{} -> {}: {} beats, {:.1} s",
        input.display(),
        output.display(),
        loaded.score.beats.len(),
        loaded.score.duration_s()
    );
    Ok(())
}

/// How a score saved at `score` should name the kit file `kit`: relative to the score's
/// folder when both are on the same tree.
pub(super) fn kit_reference(kit: &Path, score: &Path) -> anyhow::Result<String> {
    let kit = kit
        .canonicalize()
        .with_context(|| format!("{}: cannot resolve the kit path", kit.display()))?;
    let dir = score
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let dir = dir
        .canonicalize()
        .with_context(|| format!("{}: the output folder does not exist", dir.display()))?;
    Ok(relative_path(&kit, &dir).display().to_string())
}

/// `target` as seen from the folder `base` (both absolute).
fn relative_path(target: &Path, base: &Path) -> PathBuf {
    let t: Vec<Component> = target.components().collect();
    let b: Vec<Component> = base.components().collect();
    let common = t.iter().zip(&b).take_while(|(x, y)| x == y).count();
    let mut out = PathBuf::new();
    for _ in common..b.len() {
        out.push("..");
    }
    for c in &t[common..] {
        out.push(c);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Relative paths climb out of the base and down into the target.
    #[test]
    fn relative_paths() {
        assert_eq!(
            relative_path(Path::new("/a/kits/k.ron"), Path::new("/a/scores")),
            PathBuf::from("../kits/k.ron")
        );
        assert_eq!(
            relative_path(Path::new("/a/k.ron"), Path::new("/a")),
            PathBuf::from("k.ron")
        );
    }
}
