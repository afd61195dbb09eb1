//! `timpanist sticking`: assign hands to the beats marked Auto with one of the three
//! methods, print the result and optionally save the score with the hands filled in.

use crate::motion::sticking::{self, Method, Params};
use crate::score::LoadedScore;
use std::path::Path;

/// Run `method` on the score at `input`; save to `output` if given.
pub fn run(input: &Path, method: Method, output: Option<&Path>) -> anyhow::Result<()> {
    let LoadedScore { mut score, kit, .. } = LoadedScore::load(input)?;
    let sides = sticking::assign(&score, &kit, method, &Params::default());
    let meter = score.meter_map();
    let times = score.beat_times();
    println!(
        "{:>5}  {:<16} {:>8}  {:<10} {:<5}",
        "beat", "position", "time s", "drum", "hand"
    );
    for (i, (beat, side)) in score.beats.iter().zip(&sides).enumerate() {
        let how = if beat.hand.side().is_some() {
            ""
        } else {
            " (auto)"
        };
        println!(
            "{i:>5}  {:<16} {:>8.3}  {:<10} {side:?}{how}",
            meter.position(beat.tick).to_string(),
            times[i],
            kit.drums[beat.drum].name,
        );
    }
    println!(
        "{method:?} sticking: {} right, {} left, {} arm crossings",
        sides
            .iter()
            .filter(|s| **s == crate::kit::Side::Right)
            .count(),
        sides
            .iter()
            .filter(|s| **s == crate::kit::Side::Left)
            .count(),
        sticking::crossings(&score, &kit, &sides)
    );
    if let Some(out) = output {
        sticking::apply(&mut score, &sides);
        score.save(out)?;
        println!("saved {}", out.display());
    }
    Ok(())
}
