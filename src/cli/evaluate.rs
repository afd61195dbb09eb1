//! `timpanist evaluate`: the seed 000 §3.3 comparison of the IK, ID and HIMC pipelines on
//! captured strokes of each playing mode — a table, optional JSON, optional Fig. 5 plots.

use crate::base::rng::Rng;
use crate::base::ron_file;
use crate::body::control::rotation_error;
use crate::body::model::BodyModel;
use crate::body::sim::Motion;
use crate::body::skeleton::{Joint, REST};
use crate::io::plot::{Figure, Panel, Series};
use crate::kit::Side;
use crate::mocap::shipped::DbSource;
use crate::render::evaluate::{self, EvalParams, Report};
use crate::score::PlayingMode;
use plotters::style::RGBColor;
use std::path::Path;

/// Run the evaluation with `trials` per mode (joints held within the database's limits if
/// `joint_limits`) and report it, also as JSON and PNG figures when asked. Any database
/// will do: per mode the best-labelled units are evaluated (the table is followed by
/// which labels were used when not right hand, playing spot, mf, French), modes it lacks
/// are listed as skipped, and for tip-only captures ID replays the joint angles IK solves
/// from the tips on the capture skeleton (`render::evaluate`'s doc).
pub fn run(
    source: &DbSource,
    trials: usize,
    joint_limits: bool,
    (json, plot): (Option<&Path>, Option<&Path>),
) -> anyhow::Result<()> {
    let db = source.load()?;
    let model = evaluate::simulated_body();
    let mut params = EvalParams {
        trials: trials.max(1),
        ..EvalParams::default()
    };
    if joint_limits {
        // The evaluation prefers French-grip units (`evaluate::preferred`).
        params.sim.limits = db.joint_limits(crate::score::Grip::French);
        if params.sim.limits.iter().all(Option::is_none) {
            println!("note: no French-grip unit has captured joints: no joint limits to hold");
        }
    }
    let started = std::time::Instant::now();
    let report = evaluate::evaluate(&db, &model, &params)?;
    let took = started.elapsed().as_secs_f64();
    print_table(&report);
    print_notes(&report);
    let simulated: f64 =
        report.modes.iter().map(|m| m.duration_s).sum::<f64>() * 2.0 * params.trials as f64;
    println!(
        "simulated {simulated:.1} s of ID and HIMC at {} Hz in {took:.1} s wall ({:.0}× real time, IK included)",
        params.sim.sim_hz,
        simulated / took
    );
    if let Some(path) = json {
        let text = serde_json::to_string_pretty(&report)?;
        ron_file::write_atomic(path, text.as_bytes())?;
    }
    if let Some(dir) = plot {
        std::fs::create_dir_all(dir).map_err(|e| anyhow::anyhow!("{}: {e}", dir.display()))?;
        for mode in PlayingMode::ALL {
            let selection = evaluate::select(&db, mode, 1, params.max_gap_s);
            let Some((_, unit, reference)) = selection.units.first() else {
                continue;
            };
            let motions = evaluate::trial(&model, reference, &params, &mut Rng::new(params.seed))?;
            let captured = Motion::new(
                reference.rate_hz,
                reference.tips.clone(),
                reference.poses.clone().unwrap_or_default(),
            );
            let path = dir.join(format!("fig5-{}.png", mode.name().replace(' ', "-")));
            fig5(&model, (mode, unit.hand), &captured, &motions).save_png(&path)?;
            println!("wrote {}", path.display());
        }
    }
    Ok(())
}

fn print_table(report: &Report) {
    println!(
        "{:<16} {:>11} {:>16} {:>16} {:>16} {:>10}",
        "mode", "amplitude m", "IK rms ± sd mm", "ID rms ± sd mm", "HIMC rms ± sd mm", "HIMC/ampl"
    );
    for m in &report.modes {
        let s =
            |e: &evaluate::ErrorStat| format!("{:.2} ± {:.2}", e.rms_e_m * 1e3, e.rms_sd_m * 1e3);
        println!(
            "{:<16} {:>11.3} {:>16} {:>16} {:>16} {:>9.2}%",
            m.mode,
            m.amplitude_m,
            s(&m.ik),
            s(&m.id),
            s(&m.himc),
            100.0 * m.himc.rms_e_m / m.amplitude_m
        );
    }
}

/// Units passed over listed per mode; the rest are counted.
const LISTED_SKIPS: usize = 3;

/// Under the table, what differs from the seed's evaluation: the labels of the units
/// evaluated when not the preferred ones, units passed over, modes skipped, and what ID
/// replayed without captured joints. Nothing for the shipped database.
fn print_notes(report: &Report) {
    let preferred = evaluate::UsedLabels::of(&evaluate::preferred(PlayingMode::Legato));
    for m in &report.modes {
        if m.substituted() {
            let used: Vec<String> = (m.labels.iter())
                .map(|l| format!("{} × {}", l.units, l.describe()))
                .collect();
            println!(
                "{}: evaluated {} (no unit of {})",
                m.mode,
                used.join("; "),
                preferred.describe()
            );
        }
        for skip in m.skipped_units.iter().take(LISTED_SKIPS) {
            println!(
                "{}: passed over unit {}: {}",
                m.mode, skip.unit, skip.reason
            );
        }
        if m.skipped_units.len() > LISTED_SKIPS {
            println!(
                "{}: passed over {} more units",
                m.mode,
                m.skipped_units.len() - LISTED_SKIPS
            );
        }
    }
    for skipped in &report.skipped {
        println!("{}: skipped ({})", skipped.mode, skipped.reason);
    }
    let solved: Vec<&str> = (report.modes.iter())
        .filter(|m| m.joints_from_ik)
        .map(|m| m.mode.as_str())
        .collect();
    if !solved.is_empty() {
        println!(
            "{}: no captured joint angles; ID replays the joint angles inverse kinematics \
             solves from the captured tips on the {:.2} m capture skeleton",
            solved.join(", "),
            evaluate::CAPTURE_HEIGHT_M
        );
    }
}

const CAPTURED: RGBColor = RGBColor(0, 0, 0);
const COLOURS: [RGBColor; 3] = [
    RGBColor(40, 160, 60),
    RGBColor(40, 90, 220),
    RGBColor(220, 40, 40),
];

/// Seed 000 Fig. 5 for one mode played by `hand`: that arm's flexion angles and heights,
/// captured vs each pipeline.
fn fig5(
    model: &BodyModel,
    (mode, hand): (PlayingMode, Side),
    captured: &Motion,
    motions: &[Motion; 3],
) -> Figure {
    let [shoulder, elbow, wrist, _] = Joint::arm(hand);
    let h = crate::mocap::db::side_index(hand);
    let all: Vec<(&str, RGBColor, &Motion)> = std::iter::once(("captured", CAPTURED, captured))
        .chain(
            ["IK", "ID", "HIMC"]
                .into_iter()
                .zip(COLOURS)
                .zip(motions)
                .map(|((n, c), m)| (n, c, m)),
        )
        .collect();
    let flexion = |joint: Joint| {
        move |m: &Motion, k: usize| {
            rotation_error(REST[joint.index()], m.poses[k][joint.index()])
                .x
                .to_degrees()
        }
    };
    let height = |joint: Option<Joint>| {
        move |m: &Motion, k: usize| match joint {
            Some(j) => model.skeleton.forward(&m.poses[k]).position[j.index()].z,
            None => m.tips[h][k].z,
        }
    };
    let panel = |label: &str, f: &dyn Fn(&Motion, usize) -> f64| Panel {
        y_label: label.into(),
        series: all
            .iter()
            .map(|(name, colour, m)| Series {
                label: (*name).into(),
                colour: *colour,
                points: (0..m.poses.len().min(m.tips[h].len()))
                    .map(|k| (k as f64 / m.rate_hz, f(m, k)))
                    .collect(),
            })
            .collect(),
        markers: Vec::new(),
    };
    Figure {
        title: format!(
            "{}: captured vs IK / ID / HIMC (seed 000 Fig. 5)",
            mode.name()
        ),
        x_label: "time (s)".into(),
        panels: vec![
            panel("wrist flexion (deg)", &flexion(wrist)),
            panel("elbow flexion (deg)", &flexion(elbow)),
            panel("shoulder flexion (deg)", &flexion(shoulder)),
            panel("tip height (m)", &height(None)),
            panel("wrist height (m)", &height(Some(wrist))),
            panel("elbow height (m)", &height(Some(elbow))),
        ],
        guides: Vec::new(),
        size: (1200, 1600),
    }
}
