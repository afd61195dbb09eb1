//! `timpanist demos`: the demo scores built into the program (`score::demos`), listed with
//! their titles and lengths, or written into a folder to open, render and change.

use crate::score::demos::{self, DEMOS};
use std::path::Path;

/// List the demos, or write them into `output`: every file is checked absent first, so
/// either all are written or none (an existing score is never overwritten).
pub fn run(output: Option<&Path>) -> anyhow::Result<()> {
    let scores = DEMOS
        .iter()
        .map(|(name, _)| Ok((*name, demos::score(name)?)))
        .collect::<anyhow::Result<Vec<_>>>()?;
    let Some(dir) = output else {
        for (name, score) in &scores {
            println!(
                "{name:<16} {:>4} beats {:>5.1} s  {}",
                score.beats.len(),
                score.duration_s(),
                score.title
            );
        }
        println!("write them with: timpanist demos --output DIR");
        return Ok(());
    };
    std::fs::create_dir_all(dir)
        .map_err(|e| anyhow::anyhow!("{}: cannot create the folder: {e}", dir.display()))?;
    let paths: Vec<_> = scores
        .iter()
        .map(|(name, _)| dir.join(format!("{name}.ron")))
        .collect();
    if let Some(taken) = paths.iter().find(|p| p.exists()) {
        anyhow::bail!(
            "{}: already exists; nothing written (choose an empty folder)",
            taken.display()
        );
    }
    for ((_, score), path) in scores.iter().zip(&paths) {
        score.save(path)?;
    }
    println!("{} demo scores written to {}", paths.len(), dir.display());
    Ok(())
}
