//! `timpanist compose`: write the two composed stick-tip trajectories of a score as CSV
//! and, with `--plot`, a PNG of tip height and depth against time with the beats marked.
//!
//! Also what `compose` and `render` share about the motion database: a database lacking
//! a playing mode is completed from the shipped synthetic one ([`load_db`]), and the
//! beats played with a unit of other labels than asked are told ([`print_substitutions`]).

use crate::base::ron_file;
use crate::io::plot::{Figure, HAND_COLOURS, Panel, Series};
use crate::io::tips_csv;
use crate::kit::Side;
use crate::mocap::db::MotionDb;
use crate::mocap::shipped::{self, DbSource};
use crate::motion::compose::{ComposeParams, Composition};
use crate::motion::perform;
use crate::motion::plan::{self, PlanParams, Substitution};
use crate::score::{BeatPlaces, LoadedScore};
use crate::score::{Grip, PlayingMode};
use std::path::Path;

/// Compose `score` with the database from `source`; write CSV to `output` and a plot.
pub fn run(
    score: &Path,
    source: &DbSource,
    output: &Path,
    plot: Option<&Path>,
    seed: u64,
) -> anyhow::Result<()> {
    let (loaded, places) = LoadedScore::load_placed(score)?;
    let db = load_db(source)?;
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
    .map_err(|e| anyhow::anyhow!("{source}: {e}"))?;
    let took = started.elapsed();
    print_substitutions(
        &plan::substitutions(&comp.strokes, &loaded.score, &db),
        &places,
    );
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

/// The motion database from `source`, completed for the playing modes (per grip) it has
/// no unit of by the shipped synthetic database ([`MotionDb::with_fallback`], from the
/// copy built into the program), saying on stderr which modes came from it. The built-in
/// database itself (or one holding every mode of both grips) is used as it is.
pub fn load_db(source: &DbSource) -> anyhow::Result<MotionDb> {
    let db = source.load()?;
    let has = |key: (Grip, PlayingMode)| db.index.units.iter().any(|u| (u.grip, u.mode) == key);
    let complete = [Grip::French, Grip::German]
        .into_iter()
        .all(|grip| PlayingMode::ALL.into_iter().all(|mode| has((grip, mode))));
    if complete || *source == DbSource::BuiltIn {
        return Ok(db);
    }
    let shipped = shipped::built_in()?;
    let lacking = db.modes_lacking(&shipped);
    if !lacking.is_empty() {
        let modes: Vec<String> = (lacking.iter())
            .map(|(grip, mode)| format!("{} ({grip:?})", mode.name()))
            .collect();
        eprintln!(
            "note: {source} has no unit of {}: those come from the built-in synthetic database",
            modes.join(", "),
        );
    }
    Ok(db.with_fallback(&shipped))
}

/// Substitutions told one by one; beyond these, a summary line.
const LISTED_SUBSTITUTIONS: usize = 8;

/// Tell on stderr which beats were played with a unit of other labels than asked
/// ("note: beat 12 (staccato, right, mf): no such unit; used accent, right, mf"), the
/// first few one by one and then how many more and of what; each beat named by its
/// number in the file (`places`).
pub fn print_substitutions(substitutions: &[Substitution], places: &BeatPlaces) {
    for s in substitutions.iter().take(LISTED_SUBSTITUTIONS) {
        let named = Substitution {
            beat: places.number(s.beat),
            ..s.clone()
        };
        eprintln!("note: {named}");
    }
    if substitutions.len() > LISTED_SUBSTITUTIONS {
        eprintln!(
            "note: {} more beats played with units of other labels ({} in all: {})",
            substitutions.len() - LISTED_SUBSTITUTIONS,
            substitutions.len(),
            kinds(substitutions)
        );
    }
}

/// How many substitutions change each label, e.g. "3 of mode, 12 of dynamic".
fn kinds(substitutions: &[Substitution]) -> String {
    let differences: Vec<_> = (substitutions.iter())
        .map(|s| s.wanted.differences(&s.used))
        .collect();
    let count = |f: fn(&plan::Differences) -> bool| differences.iter().filter(|d| f(d)).count();
    [
        ("mode", count(|d| d.mode)),
        ("hand", count(|d| d.hand)),
        ("location", count(|d| d.location)),
        ("dynamic", count(|d| d.dynamic)),
        ("grip", count(|d| d.grip)),
    ]
    .into_iter()
    .filter(|(_, n)| *n > 0)
    .map(|(what, n)| format!("{n} of {what}"))
    .collect::<Vec<_>>()
    .join(", ")
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
