//! `timpanist import-musicxml`: the timpani part of a MusicXML score (`.musicxml`, `.xml`
//! or compressed `.mxl`) as a score.

use super::midi::kit_reference;
use crate::io::musicxml::{self, ImportOptions};
use crate::kit::Kit;
use std::path::Path;

/// Import `input` with `kit` (default: the bundled standard kit) and save the score;
/// nothing is written unless the whole import succeeds.
pub fn import(
    input: &Path,
    output: &Path,
    part: Option<String>,
    kit_path: Option<&Path>,
    title: Option<String>,
) -> anyhow::Result<()> {
    let (kit, kit_ref) = match kit_path {
        Some(p) => (Kit::load(p)?, kit_reference(p, output)?),
        None => (Kit::standard(), "standard".to_string()),
    };
    let options = ImportOptions {
        part,
        kit_ref,
        title,
    };
    let (score, report) = musicxml::import_file(input, &kit, &options)?;
    if let Some(p) = score.problems(&kit).first() {
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
        report.source,
        report.duplicates_dropped,
        report.octave_moves
    );
    for n in &report.notices {
        eprintln!("note: {n}");
    }
    Ok(())
}
