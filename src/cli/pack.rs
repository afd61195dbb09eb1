//! `timpanist export-pack`: render a score (as `render` does, with its progress bar) and
//! write its lesson pack (`io::pack`) into a new folder, each step said on stderr. The
//! target is checked before rendering, so a folder that would be refused costs no render.

use super::render::{Choices, rendered};
use crate::exports;
use crate::io::pack::{self, Options, folder};
use crate::mocap::shipped::DbSource;
use std::path::Path;

/// Render `score` and write its pack into `dir`.
pub fn run(
    score: &Path,
    source: &DbSource,
    dir: &Path,
    options: &Options,
    choices: &Choices,
) -> anyhow::Result<()> {
    // Refuse an occupied folder before the render (the check is made again when writing).
    folder::check(dir, options.replace)?;
    let (loaded, _, rendering, wall) = rendered(score, source, choices)?;
    let performance = exports::performance(&rendering, &loaded.score);
    let written = pack::write(&performance, dir, options, &mut |step| {
        eprintln!("pack: {step}...");
    })?;
    println!(
        "{} -> {}: {} files, {} phrase{}, {} contacts, {:.1} s of audio (rendered in {:.1} s); open {}",
        score.display(),
        written.dir.display(),
        written.files.len(),
        written.phrases,
        if written.phrases == 1 { "" } else { "s" },
        rendering.events.len(),
        performance.duration_s(),
        wall.as_secs_f64(),
        written.dir.join("index.html").display()
    );
    Ok(())
}
