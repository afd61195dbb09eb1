//! `timpanist transcribe`: a timpani recording (WAV, AIFF, FLAC, MP3, Ogg Vorbis) as a score ([`crate::transcribe`]).

use super::midi::{Imported, import_kit, save_imported};
use crate::transcribe::{self, Levels, Options};
use std::path::Path;

/// Transcribe `input` onto `kit` (default: the bundled standard kit) and save the score;
/// nothing is written unless the whole transcription succeeds.
pub fn run(
    input: &Path,
    output: &Path,
    kit_path: Option<&Path>,
    title: Option<String>,
    levels: Levels,
) -> anyhow::Result<()> {
    let (kit, kit_ref) = import_kit(kit_path, output)?;
    let options = Options {
        kit_ref,
        title,
        levels,
    };
    let (score, report) = transcribe::transcribe_file(input, &kit, &options)?;
    let source = format!(
        "{} strokes heard ({} rolls), {:.0} bpm, tuned {:+.0} cents from A440",
        report.strokes, report.rolls, report.bpm, report.tuning_cents
    );
    save_imported(
        (input, output),
        &score,
        &kit,
        &Imported {
            source: &source,
            duplicates_dropped: 0,
            octave_moves: report.octave_moves,
        },
    )?;
    for n in &report.notices {
        eprintln!("note: {n}");
    }
    Ok(())
}
