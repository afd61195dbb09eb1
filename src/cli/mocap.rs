//! `timpanist mocap synth | stats`: build the synthetic motion database and summarise a
//! database (per playing mode and grip, per dynamic, and joint limits).

use crate::body::skeleton::Joint;
use crate::mocap::db::MotionDb;
use crate::mocap::limits::JointLimit;
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
        db.index.rate_hz
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
        "{}: {} takes, {} units, {} Hz",
        dir.display(),
        db.index.takes.len(),
        db.index.units.len(),
        db.index.rate_hz
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
    if db.takes.iter().any(|t| t.joints.is_some()) {
        println!(
            "\njoint limits (seed 000 Alg. 1): semi-axes of the bounding ellipsoid as rotation angles, degrees; Table 1 as printed"
        );
        for joint in Joint::ALL {
            let samples: Vec<_> = db
                .takes
                .iter()
                .filter_map(|t| t.joints.as_ref())
                .flat_map(|poses| poses.iter().step_by(5).map(move |p| p[joint.index()]))
                .collect();
            let Some(limit) = JointLimit::estimate(&samples) else {
                continue;
            };
            let deg = limit.semi_axes.map(|a| (2.0 * a).to_degrees());
            let table = TABLE_1
                .iter()
                .find(|(n, _)| joint.name().starts_with(n))
                .map_or(String::new(), |(_, t)| format!("   Table 1: {:?}", t));
            println!(
                "  {:<11} {:>6.1} {:>6.1} {:>6.1}   axes ({:+.2} {:+.2} {:+.2}) ({:+.2} {:+.2} {:+.2}) ({:+.2} {:+.2} {:+.2}){table}",
                joint.name(),
                deg[0],
                deg[1],
                deg[2],
                limit.axes[0].x,
                limit.axes[0].y,
                limit.axes[0].z,
                limit.axes[1].x,
                limit.axes[1].y,
                limit.axes[1].z,
                limit.axes[2].x,
                limit.axes[2].y,
                limit.axes[2].z,
            );
        }
    }
    Ok(())
}
