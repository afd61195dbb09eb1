//! `timpanist mocap synth | stats`: build the synthetic motion database and summarise a
//! database (per playing mode and grip, per dynamic, and joint limits).

use crate::body::skeleton::Joint;
use crate::mocap::db::MotionDb;
use crate::mocap::import::Format;
use crate::mocap::ingest::{IngestOptions, UpAxis, ingest};
use crate::mocap::{stats, synth};
use crate::score::{Dynamic, Grip};
use std::path::Path;

/// Build the synthetic database into `dir`.
pub fn synth(dir: &Path, seed: u64) -> anyhow::Result<()> {
    let config = synth::SynthConfig {
        seed,
        ..synth::SynthConfig::default()
    };
    eprintln!(
        "synthesising {} takes…",
        config.grips.len() * config.modes.len() * config.locations.len() * config.hands.len()
    );
    let db = synth::synthesize(&config);
    std::fs::create_dir_all(dir).map_err(|e| anyhow::anyhow!("{}: {e}", dir.display()))?;
    db.save(dir)?;
    println!(
        "wrote {}: {} takes, {} motion units at {} Hz",
        dir.display(),
        db.index.takes.len(),
        db.index.units.len(),
        config.rate_hz
    );
    Ok(())
}

/// Table 1 of seed 000: joint-limit eigenvalues as printed.
const TABLE_1: [(&str, [f64; 3]); 4] = [
    ("neck", [5.7, 2.9, 2.3]),
    ("shoulder", [4.4, 2.7, 0.1]),
    ("elbow", [14.6, 8.9, 4.4]),
    ("wrist", [19.9, 9.1, 2.1]),
];

/// Print the statistics of the database in `dir`.
pub fn stats(dir: &Path) -> anyhow::Result<()> {
    let db = MotionDb::load(dir)?;
    println!(
        "{}: {} takes, {} units",
        dir.display(),
        db.index.takes.len(),
        db.index.units.len(),
    );
    for grip in [None, Some(Grip::French), Some(Grip::German)] {
        let rows = stats::by_mode(&db, grip);
        if rows.is_empty() {
            continue;
        }
        println!(
            "\n{}",
            grip.map_or("all grips".to_string(), |g| format!("{g:?} grip"))
        );
        println!(
            "  {:<16} {:>6} {:>10} {:>10} {:>12} {:>10}",
            "mode", "units", "height m", "depth m", "impact m/s", "stroke s"
        );
        for (mode, g) in rows {
            let m = g.mean;
            println!(
                "  {:<16} {:>6} {:>10.3} {:>10.3} {:>12.2} {:>10.3}",
                mode.name(),
                g.units,
                m.height_range_m,
                m.depth_range_m,
                m.impact_speed_mps,
                m.duration_s
            );
        }
    }
    println!("\nby dynamic");
    for d in [
        Dynamic::Pp,
        Dynamic::P,
        Dynamic::Mp,
        Dynamic::Mf,
        Dynamic::F,
        Dynamic::Ff,
    ] {
        let g = stats::group(&db, |u| u.dynamic.nearest_mark() == d.nearest_mark());
        if g.units > 0 {
            println!(
                "  {:<4} {:>6} units, height {:.3} m, impact {:.2} m/s",
                d.nearest_mark(),
                g.units,
                g.mean.height_range_m,
                g.mean.impact_speed_mps
            );
        }
    }
    for grip in [Grip::French, Grip::German] {
        print_limits(&db, grip);
    }
    Ok(())
}

/// Joint limits of one grip from the frames of its motion units (each arm only while it
/// plays), beside Table 1 of seed 000.
fn print_limits(db: &MotionDb, grip: Grip) {
    let limits = db.estimated_joint_limits(grip);
    if limits.iter().all(Option::is_none) {
        return;
    }
    println!(
        "\n{grip:?} grip joint limits (seed 000 Alg. 1): semi-axes of the bounding ellipsoid as rotation angles, degrees"
    );
    for (joint, limit) in Joint::ALL.into_iter().zip(limits) {
        let Some(limit) = limit else {
            continue;
        };
        let deg = limit.semi_axes.map(|a| (2.0 * a).to_degrees());
        let axes: Vec<String> = limit
            .axes
            .iter()
            .map(|a| format!("({:+.2} {:+.2} {:+.2})", a.x, a.y, a.z))
            .collect();
        let table = TABLE_1
            .iter()
            .find(|(n, _)| joint.name().starts_with(n))
            .map_or(String::new(), |(_, t)| {
                format!("   Table 1 as printed: {t:?}")
            });
        println!(
            "  {:<11} {:>6.1} {:>6.1} {:>6.1}   axes {}{table}",
            joint.name(),
            deg[0],
            deg[1],
            deg[2],
            axes.join(" ")
        );
    }
}

/// What `mocap import` was asked to do.
pub struct ImportArgs {
    pub files: Vec<std::path::PathBuf>,
    pub format: Option<Format>,
    pub tips: [String; 2],
    pub up: Option<UpAxis>,
    pub unit: Option<String>,
    pub tip_offset_m: Option<glam::DVec3>,
    pub mode: Option<crate::score::PlayingMode>,
    pub location: Option<crate::score::ImpactLocation>,
    pub hand: Option<crate::kit::Side>,
    pub dynamic: Option<Dynamic>,
    pub grip: Option<Grip>,
    pub performer: String,
    pub output: std::path::PathBuf,
}

/// Import captures into the database at `args.output` (created if absent). Every file
/// is read and cut before anything is written, so a bad file leaves the database as it was.
pub fn import(args: ImportArgs) -> anyhow::Result<()> {
    let mut db = if args.output.join("index.ron").exists() {
        MotionDb::load(&args.output)?
    } else {
        MotionDb::empty("Imported motion captures")
    };
    for path in &args.files {
        let bytes = std::fs::read(path).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
        let format = args.format.or_else(|| Format::guess(path, &bytes));
        let take = crate::mocap::import::read_with_unit(path, format, args.unit.as_deref())?;
        let up = args.up.unwrap_or(if format == Some(Format::Motive) {
            UpAxis::Y
        } else {
            UpAxis::Z
        });
        let options = IngestOptions {
            tips: args.tips.clone(),
            up,
            tip_offset_m: args.tip_offset_m,
            mode: args.mode,
            location: args.location,
            dynamic: args.dynamic,
            grip: args.grip,
            hand: args.hand,
            performer: args.performer.clone(),
            segment: Default::default(),
        };
        let report = ingest(&mut db, path, &take, &options)?;
        let plane = |p: Option<f64>| p.map_or("-".into(), |z| format!("{z:.3} m"));
        println!(
            "{}: {} frames at {} Hz ({}); left {} impacts -> {} units (membrane {}), right {} impacts -> {} units (membrane {})",
            path.display(),
            take.frames,
            take.rate_hz,
            take.file_unit,
            report.impacts[0],
            report.units[0],
            plane(report.plane_height_m[0]),
            report.impacts[1],
            report.units[1],
            plane(report.plane_height_m[1]),
        );
        for note in take.notes.iter().chain(&report.notices) {
            eprintln!("note: {}: {note}", path.display());
        }
    }
    std::fs::create_dir_all(&args.output)
        .map_err(|e| anyhow::anyhow!("{}: {e}", args.output.display()))?;
    db.save(&args.output)?;
    println!(
        "{}: {} takes, {} units",
        args.output.display(),
        db.index.takes.len(),
        db.index.units.len()
    );
    Ok(())
}
