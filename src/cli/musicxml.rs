//! `timpanist import-musicxml`: the timpani part of a MusicXML score (`.musicxml`, `.xml`
//! or compressed `.mxl`) as a score.

use super::midi::{Imported, import_kit, save_imported};
use crate::io::musicxml::{self, ImportOptions};
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
    let (kit, kit_ref) = import_kit(kit_path, output)?;
    let options = ImportOptions {
        part,
        kit_ref,
        title,
    };
    let (score, report) = musicxml::import_file(input, &kit, &options)?;
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
    for n in &report.notices {
        eprintln!("note: {n}");
    }
    Ok(())
}
