//! The shipped synthetic motion database: complete, calibrated to the published facts of
//! the guide (grip ranges, seed 000 Fig. 6a orderings, speed rising with dynamic), shaped
//! like a real drum stroke, and rebuilt bit for bit by the generator.

use std::path::Path;
use timpanist::kit::Side;
use timpanist::mocap::db::{self, MotionDb};
use timpanist::mocap::stats::{self, GroupStats};
use timpanist::mocap::synth::{SynthConfig, synthesize};
use timpanist::score::{Dynamic, Grip, ImpactLocation, PlayingMode};

fn shipped() -> MotionDb {
    MotionDb::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("mocap")).unwrap()
}

fn mode_stats(db: &MotionDb, grip: Grip, mode: PlayingMode) -> GroupStats {
    stats::group(db, |u| u.grip == grip && u.mode == mode)
}

/// Every grip × mode × location × hand × dynamic has at least 8 units.
#[test]
fn database_is_complete() {
    let db = shipped();
    assert_eq!(db.index.units.len(), 1440);
    for grip in [Grip::French, Grip::German] {
        for mode in PlayingMode::ALL {
            for location in [
                ImpactLocation::Centre,
                ImpactLocation::PlayingSpot,
                ImpactLocation::Rim,
            ] {
                for hand in [Side::Left, Side::Right] {
                    for dynamic in [Dynamic::P, Dynamic::Mf, Dynamic::F] {
                        let n = db
                            .index
                            .units
                            .iter()
                            .filter(|u| {
                                u.grip == grip
                                    && u.mode == mode
                                    && u.location == location
                                    && u.hand == hand
                                    && u.dynamic == dynamic
                            })
                            .count();
                        assert!(
                            n >= 8,
                            "{grip:?} {mode:?} {location:?} {hand:?} {dynamic:?}: {n}"
                        );
                    }
                }
            }
        }
    }
}

/// Mean vertical range of mf strokes is within 5 % of 434 mm (French) and 179 mm (German).
#[test]
fn grip_ranges_match_published_figures() {
    let db = shipped();
    for (grip, want) in [(Grip::French, 0.434), (Grip::German, 0.179)] {
        let g = stats::group(&db, |u| u.grip == grip && u.dynamic == Dynamic::Mf);
        assert!(
            (g.mean.height_range_m / want - 1.0).abs() < 0.05,
            "{grip:?}: {}",
            g.mean.height_range_m
        );
    }
}

/// Seed 000 Fig. 6a: accents rise highest with the least depth travel; vertical accent and
/// staccato travel further in depth than legato, tenuto and accent — for both grips.
#[test]
fn fig_6a_orderings() {
    let db = shipped();
    for grip in [Grip::French, Grip::German] {
        let s = |m| mode_stats(&db, grip, m).mean;
        let accent = s(PlayingMode::Accent);
        for other in [
            PlayingMode::Legato,
            PlayingMode::Tenuto,
            PlayingMode::Staccato,
        ] {
            assert!(
                accent.height_range_m > s(other).height_range_m,
                "{grip:?} accent vs {other:?} height"
            );
            assert!(
                accent.depth_range_m < s(other).depth_range_m,
                "{grip:?} accent vs {other:?} depth"
            );
        }
        for deep in [PlayingMode::VerticalAccent, PlayingMode::Staccato] {
            for shallow in [
                PlayingMode::Legato,
                PlayingMode::Tenuto,
                PlayingMode::Accent,
            ] {
                assert!(
                    s(deep).depth_range_m > 1.3 * s(shallow).depth_range_m,
                    "{grip:?} {deep:?} vs {shallow:?}"
                );
            }
        }
    }
}

/// Impact speed rises with the dynamic, for each grip.
#[test]
fn impact_speed_rises_with_dynamic() {
    let db = shipped();
    for grip in [Grip::French, Grip::German] {
        let speeds: Vec<f64> = [Dynamic::P, Dynamic::Mf, Dynamic::F]
            .iter()
            .map(|d| {
                stats::group(&db, |u| u.grip == grip && u.dynamic == *d)
                    .mean
                    .impact_speed_mps
            })
            .collect();
        assert!(
            speeds[0] < speeds[1] && speeds[1] < speeds[2],
            "{grip:?}: {speeds:?}"
        );
    }
}

/// Every unit's impact frame is the lowest point of its stroke and lies at the membrane
/// (within the 12 mm a 5 m/s stick travels in half a 250 Hz frame); no tip goes below the
/// head by more than the 1 mm IK tolerance.
#[test]
fn impacts_lie_on_the_membrane() {
    let db = shipped();
    for u in &db.index.units {
        let tip = db.unit_tip(u);
        let z_impact = tip[u.impact - u.start].unwrap().z;
        assert!((z_impact - 0.76).abs() < 0.012, "unit impact at {z_impact}");
        assert!(tip.iter().flatten().all(|p| p.z > 0.76 - 1e-3));
    }
}

/// Resample `ys` (one impact-to-impact cycle) to `n` points and scale to 0–1.
fn normalised(ys: &[f64], n: usize) -> Vec<f64> {
    let (lo, hi) = ys
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &y| {
            (l.min(y), h.max(y))
        });
    (0..n)
        .map(|i| {
            let x = i as f64 / (n - 1) as f64 * (ys.len() - 1) as f64;
            let k = (x.floor() as usize).min(ys.len() - 2);
            let y = ys[k] + (ys[k + 1] - ys[k]) * (x - k as f64);
            (y - lo) / (hi - lo)
        })
        .collect()
}

fn correlation(a: &[f64], b: &[f64]) -> f64 {
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let (ma, mb) = (mean(a), mean(b));
    let cov: f64 = a.iter().zip(b).map(|(x, y)| (x - ma) * (y - mb)).sum();
    let va: f64 = a.iter().map(|x| (x - ma).powi(2)).sum();
    let vb: f64 = b.iter().map(|y| (y - mb).powi(2)).sum();
    cov / (va * vb).sqrt()
}

/// A synthetic French legato stroke has the shape of the real drum stroke in
/// `tests/fixtures/drum-stroke` (TrajOptDrums, MIT): normalised tip height over one
/// impact-to-impact cycle correlates above 0.9.
#[test]
fn stroke_shape_matches_a_real_stroke() {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/fixtures/drum-stroke/JointCenters_YPose_cm.csv"),
    )
    .unwrap();
    let bead: Vec<f64> = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(5).unwrap().parse().unwrap())
        .collect();
    // The take starts at an impact; the next impact is the lowest point of the second half.
    let half = bead.len() / 2;
    let second = half
        + bead[half..]
            .iter()
            .enumerate()
            .min_by(|a, b| a.1.total_cmp(b.1))
            .unwrap()
            .0;
    let real = normalised(&bead[..=second], 100);

    let db = shipped();
    let units: Vec<_> = db
        .index
        .units
        .iter()
        .filter(|u| {
            u.grip == Grip::French
                && u.mode == PlayingMode::Legato
                && u.hand == Side::Right
                && u.location == ImpactLocation::PlayingSpot
        })
        .collect();
    let (a, b) = (units[3], units[4]);
    assert_eq!(a.take, b.take);
    let tip = db.takes[a.take].tip(Side::Right);
    let ours: Vec<f64> = tip[a.impact..=b.impact]
        .iter()
        .map(|p| p.unwrap().z)
        .collect();
    let ours = normalised(&ours, 100);
    let r = correlation(&real, &ours);
    assert!(r > 0.9, "correlation {r}");
}

/// `timpanist mocap synth` rebuilds the shipped database bit for bit.
#[test]
fn shipped_database_rebuilds_bit_for_bit() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("mocap");
    let rebuilt = synthesize(&SynthConfig::default());
    let index_text = std::fs::read_to_string(dir.join("index.ron")).unwrap();
    assert!(
        timpanist::base::ron_file::to_pretty(&rebuilt.index) == index_text,
        "index.ron differs"
    );
    for (entry, data) in rebuilt.index.takes.iter().zip(&rebuilt.takes) {
        let on_disk = std::fs::read(dir.join(&entry.file)).unwrap();
        assert!(db::encode_take(data) == on_disk, "{} differs", entry.file);
    }
}
