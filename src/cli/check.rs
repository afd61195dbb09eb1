//! `timpanist check FILE...`: validate scores and kits, printing every problem as
//! `path: place: message`, or `path:line:col: place: message` for a beat (parse errors
//! as `path:line:col: message`). Beats are named by their number in the file's `beats`
//! list, as `render` names them; a score with no beats is refused as `render` refuses it.

use crate::base::ron_file::{self, FileError};
use crate::kit::Kit;
use crate::render::RenderError;
use crate::score::Score;
use std::path::Path;
use std::process::ExitCode;

/// Check every file; exit code 0 only if all are valid.
pub fn run(files: &[std::path::PathBuf]) -> ExitCode {
    let mut failed = 0;
    for path in files {
        match check_file(path) {
            Ok(summary) => println!("ok    {}: {summary}", path.display()),
            Err(problems) => {
                failed += 1;
                for p in problems {
                    eprintln!("{p}");
                }
            }
        }
    }
    if failed > 0 {
        eprintln!("error: {failed} of {} files have problems", files.len());
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    }
}

/// A one-line summary of a valid file, or every problem found.
fn check_file(path: &Path) -> Result<String, Vec<String>> {
    let one = |e: FileError| vec![e.to_string()];
    let text = ron_file::read_text(path).map_err(one)?;
    if ron_file::top_level_name(&text) == Some("Kit") {
        let kit = Kit::parse(path, &text).map_err(one)?;
        return Ok(format!(
            "kit \"{}\", {} drums, {} mallets",
            kit.name,
            kit.drums.len(),
            kit.mallets.len()
        ));
    }
    let (score, places) = Score::parse_placed(path, &text).map_err(one)?;
    let (kit, kit_source, notices) = score.resolve_kit(path).map_err(one)?;
    let mut problems: Vec<String> = (score.problems_placed(&kit, &places).into_iter())
        .map(|p| FileError::problem(path, p).to_string())
        .collect();
    if score.beats.is_empty() {
        problems.push(format!("{}: {}", path.display(), RenderError::Empty));
    }
    if !problems.is_empty() {
        return Err(problems);
    }
    let bars = score
        .meter_map()
        .position(score.beats.iter().map(|b| b.end_tick()).max().unwrap_or(0))
        .bar;
    let mut summary = format!(
        "score \"{}\", {} beats, {bars} bars, {:.1} s, kit {kit_source}",
        score.title,
        score.beats.len(),
        score.duration_s()
    );
    for n in notices {
        summary.push_str(&format!(" (note: {n})"));
    }
    let pedals = score.pedal_changes_placed(&kit, &places);
    if let Some(first) = pedals.iter().find(|c| c.is_quick()).or(pedals.first()) {
        let quick = pedals.iter().filter(|c| c.is_quick()).count();
        summary.push_str(&format!(
            " (note: {} pedal change(s), {quick} quick; {first})",
            pedals.len()
        ));
    }
    Ok(summary)
}
