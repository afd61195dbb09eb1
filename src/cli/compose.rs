//! `timpanist compose`: write the two composed stick-tip trajectories of a score as CSV
//! and, with `--plot`, a PNG of tip height and depth against time with the beats marked.

use crate::base::ron_file;
use crate::io::plot::{Figure, Panel, Series};
use crate::io::tips_csv;
use crate::kit::Side;
use crate::mocap::db::MotionDb;
use crate::motion::compose::{ComposeParams, Composition};
use crate::motion::perform;
use crate::motion::plan::PlanParams;
use crate::score::LoadedScore;
use plotters::style::RGBColor;
use std::path::Path;

/// Colour of each hand in figures.
pub const HAND_COLOURS: [RGBColor; 2] = [RGBColor(31, 119, 180), RGBColor(230, 120, 20)];

/// Compose `score` with the database in `db_dir`; write CSV to `output` and a plot.
pub fn run(
    score: &Path,
    db_dir: &Path,
    output: &Path,
    plot: Option<&Path>,
    seed: u64,
) -> anyhow::Result<()> {
    let loaded = LoadedScore::load(score)?;
    let db = MotionDb::load(db_dir)?;
    let started = std::time::Instant::now();
    let comp = perform::trajectories(
        &loaded.score,
        &loaded.kit,
        &db,
        &PlanParams {
            seed,
            ..PlanParams::default()
        },
        &ComposeParams::default(),
    )
    .map_err(|e| anyhow::anyhow!("{}: {e}", db_dir.display()))?;
    let took = started.elapsed();
    let csv = tips_csv::to_csv(&comp);
    if let Some(plot) = plot {
        figure(&comp, &loaded.score.title).save_png(plot)?;
    }
    ron_file::write_atomic(output, csv.as_bytes())?;
    println!(
        "{} -> {}: {} strokes, {} samples at {} Hz ({:.1} s), composed in {:.1} ms",
        score.display(),
        output.display(),
        comp.strokes.len(),
        comp.len(),
        comp.rate_hz,
        comp.len() as f64 / comp.rate_hz,
        took.as_secs_f64() * 1e3
    );
    Ok(())
}

/// Height and depth of both tips against time, impacts dotted, beats as guides.
pub fn figure(comp: &Composition, title: &str) -> Figure {
    let panel = |label: &str, axis: usize| Panel {
        y_label: label.into(),
        series: [Side::Left, Side::Right]
            .iter()
            .enumerate()
            .map(|(h, side)| Series {
                label: format!("{side:?} tip").to_lowercase(),
                colour: HAND_COLOURS[h],
                points: comp
                    .tip(*side)
                    .iter()
                    .enumerate()
                    .map(|(k, p)| (comp.time(k), p[axis]))
                    .collect(),
            })
            .collect(),
        markers: comp
            .strokes
            .iter()
            .zip(&comp.impact_samples)
            .map(|(s, &k)| {
                (
                    comp.time(k),
                    comp.tip(s.hand)[k][axis],
                    HAND_COLOURS[crate::mocap::db::side_index(s.hand)],
                )
            })
            .collect(),
    };
    Figure {
        title: format!("{title}: composed stick tips"),
        x_label: "time (s)".into(),
        panels: vec![panel("height z (m)", 2), panel("depth y (m)", 1)],
        guides: comp.strokes.iter().map(|s| s.time_s).collect(),
        size: (1400, 800),
    }
}
