//! `timpanist import-musicxml`: the timpani part of a MusicXML score (`.musicxml`, `.xml`
//! or compressed `.mxl`) as a score; `timpanist export-musicxml`: a score as MusicXML
//! (compressed when the output ends in `.mxl`).

use super::midi::{Imported, export_score, import_kit, save_imported};
use crate::io::musicxml::{self, ImportOptions};
use crate::io::musicxml_export;
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

/// Export the score at `input` as MusicXML at `output` (a `.mxl` archive when `output`
/// ends in `.mxl`), written atomically.
pub fn export(input: &Path, output: &Path) -> anyhow::Result<()> {
    export_score(input, output, &musicxml_export::export_for)
}
