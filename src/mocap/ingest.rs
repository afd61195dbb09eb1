//! Turning a raw capture into database units: pick the two stick-tip tracks by label (a
//! marker, or a rigid body plus a tip offset in its own frame), bring them into the
//! performer frame (Z up; a Y-up capture is turned so that its −Z axis points forward),
//! segment each tip into strokes, and label every unit from options or from words in the
//! file path.

use super::db::{MotionDb, TakeData, TakeEntry, UnitEntry};
use super::segment::{SegmentParams, segment};
use super::take::{ImportError, Take, Track};
use crate::kit::Side;
use crate::score::{Dynamic, Grip, ImpactLocation, PlayingMode};
use glam::DVec3;
use std::path::Path;

/// Which axis of the capture points up.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UpAxis {
    /// Y up (OptiTrack Motive's default): (x, y, z) ↦ (x, −z, y).
    Y,
    /// Z up (Vicon, Qualisys, most C3D files): kept.
    Z,
}

/// How to read one capture into the database.
#[derive(Clone, Debug)]
pub struct IngestOptions {
    /// Labels of the left and right stick-tip tracks.
    pub tips: [String; 2],
    pub up: UpAxis,
    /// For rigid-body tracks: the tip in the body's own frame, m.
    pub tip_offset_m: Option<DVec3>,
    /// Labels; `None` reads them from the file path (see [`labels_from_path`]).
    pub mode: Option<PlayingMode>,
    pub location: Option<ImpactLocation>,
    pub dynamic: Option<Dynamic>,
    pub grip: Option<Grip>,
    /// Keep only the units of one hand.
    pub hand: Option<Side>,
    pub performer: String,
    pub segment: SegmentParams,
}

/// Labels found in words of a path.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PathLabels {
    pub mode: Option<PlayingMode>,
    pub location: Option<ImpactLocation>,
    pub dynamic: Option<Dynamic>,
    pub grip: Option<Grip>,
}

/// Read labels from the words of `path` (split at anything not a letter or digit, case
/// ignored): legato, tenuto, accent, vertical accent / verticalaccent, staccato; centre /
/// center, spot / playingspot, rim / edge; pp … ff; french, german.
pub fn labels_from_path(path: &Path) -> PathLabels {
    let text = path.to_string_lossy().to_lowercase();
    let words: Vec<&str> = text
        .split(|c: char| !c.is_ascii_alphanumeric())
        .filter(|w| !w.is_empty())
        .collect();
    let mut l = PathLabels::default();
    for (i, w) in words.iter().enumerate() {
        let next = words.get(i + 1).copied();
        match *w {
            "legato" => l.mode = Some(PlayingMode::Legato),
            "tenuto" => l.mode = Some(PlayingMode::Tenuto),
            "staccato" => l.mode = Some(PlayingMode::Staccato),
            "verticalaccent" | "vaccent" => l.mode = Some(PlayingMode::VerticalAccent),
            "vertical" if next == Some("accent") => l.mode = Some(PlayingMode::VerticalAccent),
            "accent" if l.mode != Some(PlayingMode::VerticalAccent) => {
                l.mode = Some(PlayingMode::Accent)
            }
            "centre" | "center" => l.location = Some(ImpactLocation::Centre),
            "spot" | "playingspot" => l.location = Some(ImpactLocation::PlayingSpot),
            "rim" | "edge" => l.location = Some(ImpactLocation::Rim),
            "french" => l.grip = Some(Grip::French),
            "german" => l.grip = Some(Grip::German),
            mark => {
                if let Some((d, _, _)) = Dynamic::MARKS.iter().find(|(_, _, name)| *name == mark) {
                    l.dynamic = Some(*d);
                }
            }
        }
    }
    l
}

/// What one capture added.
#[derive(Clone, Debug, PartialEq)]
pub struct IngestReport {
    /// Units added per hand [left, right].
    pub units: [usize; 2],
    /// Impacts found per hand (including the dropped first and last).
    pub impacts: [usize; 2],
    /// Estimated membrane height per hand, m.
    pub plane_height_m: [Option<f64>; 2],
    /// Labels that were guessed, for the user to check.
    pub notices: Vec<String>,
}

/// Add `take` (read from `path`) to `db` as a new take file `takes/NAME.tmot`.
pub fn ingest(
    db: &mut MotionDb,
    path: &Path,
    take: &Take,
    options: &IngestOptions,
) -> Result<IngestReport, ImportError> {
    let from_path = labels_from_path(path);
    let mut notices = Vec::new();
    let mode = options.mode.or(from_path.mode).ok_or_else(|| {
        ImportError::format(path, "labels", "cannot tell the playing mode: give --mode or put legato, tenuto, accent, vertical-accent or staccato in the file name")
    })?;
    let location = pick(
        options.location,
        from_path.location,
        ImpactLocation::PlayingSpot,
        "impact location",
        &mut notices,
    );
    let dynamic = pick(
        options.dynamic,
        from_path.dynamic,
        Dynamic::Mf,
        "dynamic",
        &mut notices,
    );
    let grip = pick(
        options.grip,
        from_path.grip,
        Grip::French,
        "grip",
        &mut notices,
    );
    let tips: [Vec<Option<DVec3>>; 2] = [0, 1]
        .map(|k| tip_track(path, take, &options.tips[k], options))
        .into_iter()
        .collect::<Result<Vec<_>, _>>()?
        .try_into()
        .expect("two tips");
    let take_index = db.index.takes.len();
    let mut report = IngestReport {
        units: [0, 0],
        impacts: [0, 0],
        plane_height_m: [None, None],
        notices,
    };
    for (k, side) in [Side::Left, Side::Right].into_iter().enumerate() {
        if options.hand.is_some_and(|h| h != side) {
            continue;
        }
        let seg = segment(&tips[k], take.rate_hz, &options.segment);
        report.impacts[k] = seg.impacts.len();
        report.plane_height_m[k] = seg.plane_height_m;
        report.units[k] = seg.units.len();
        db.index
            .units
            .extend(seg.units.iter().map(|span| UnitEntry {
                take: take_index,
                start: span.start,
                impact: span.impact,
                end: span.end,
                hand: side,
                mode,
                location,
                dynamic,
                grip,
            }));
    }
    let stem = path
        .file_stem()
        .map_or("take".into(), |s| s.to_string_lossy().to_string());
    let mut file = format!("takes/{stem}.tmot");
    let mut n = 2;
    while db.index.takes.iter().any(|t| t.file == file) {
        file = format!("takes/{stem}-{n}.tmot");
        n += 1;
    }
    db.index.takes.push(TakeEntry {
        file,
        frames: take.frames,
        rate_hz: take.rate_hz,
        performer: options.performer.clone(),
        source: path.display().to_string(),
    });
    db.takes.push(TakeData {
        rate_hz: take.rate_hz,
        tips,
        joints: None,
    });
    Ok(report)
}

/// The given label, else the one from the path, else `default` with a notice.
fn pick<T: std::fmt::Debug + Copy>(
    given: Option<T>,
    found: Option<T>,
    default: T,
    what: &str,
    notices: &mut Vec<String>,
) -> T {
    given.or(found).unwrap_or_else(|| {
        notices.push(format!(
            "no {what} given or in the file name; assumed {default:?}"
        ));
        default
    })
}

/// The tip positions of the track labelled `label`, in the performer frame.
fn tip_track(
    path: &Path,
    take: &Take,
    label: &str,
    options: &IngestOptions,
) -> Result<Vec<Option<DVec3>>, ImportError> {
    let track: &Track = take.track(label).ok_or_else(|| {
        ImportError::format(
            path,
            "labels",
            format!(
                "no track labelled \"{label}\"; the file has: {}",
                take.labels().join(", ")
            ),
        )
    })?;
    let offset = options.tip_offset_m.unwrap_or(DVec3::ZERO);
    Ok(track
        .positions
        .iter()
        .enumerate()
        .map(|(f, p)| {
            let rotation = track.rotations.get(f).copied().flatten();
            let p = match rotation {
                Some(q) if options.tip_offset_m.is_some() => *p.as_ref()? + q * offset,
                _ => (*p)?,
            };
            Some(to_performer(p, options.up))
        })
        .collect())
}

/// A capture position in the performer frame.
pub fn to_performer(p: DVec3, up: UpAxis) -> DVec3 {
    match up {
        UpAxis::Z => p,
        UpAxis::Y => DVec3::new(p.x, -p.z, p.y),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mocap::db::{self, Index};

    /// Words of a path become labels; missing ones stay unset.
    #[test]
    fn labels_from_file_names() {
        let l = labels_from_path(Path::new("/caps/German/vertical-accent_rim_ff_take3.c3d"));
        assert_eq!(l.mode, Some(PlayingMode::VerticalAccent));
        assert_eq!(l.location, Some(ImpactLocation::Rim));
        assert_eq!(l.dynamic, Some(Dynamic::Ff));
        assert_eq!(l.grip, Some(Grip::German));
        let l = labels_from_path(Path::new("accent-center.csv"));
        assert_eq!(
            (l.mode, l.location, l.grip),
            (
                Some(PlayingMode::Accent),
                Some(ImpactLocation::Centre),
                None
            )
        );
    }

    /// A capture made from a synthetic take, given in Y-up millimetre-free metres, is cut
    /// into the same units as the synthetic database cut it.
    #[test]
    fn ingests_a_y_up_capture() {
        let source = crate::mocap::synth::synthesize(&crate::mocap::synth::SynthConfig {
            grips: vec![Grip::French],
            modes: vec![PlayingMode::Legato],
            locations: vec![ImpactLocation::Rim],
            hands: vec![Side::Right],
            dynamics: vec![Dynamic::F],
            strokes_per_dynamic: 6,
            ..Default::default()
        });
        let data = &source.takes[0];
        let from_performer = |p: DVec3| DVec3::new(p.x, p.z, -p.y);
        let track = |label: &str, side: Side| Track {
            label: label.into(),
            positions: data
                .tip(side)
                .iter()
                .map(|p| p.map(from_performer))
                .collect(),
            rotations: Vec::new(),
        };
        let take = Take {
            source: "legato_rim_f.csv".into(),
            rate_hz: data.rate_hz,
            frames: data.frames(),
            file_unit: "m".into(),
            tracks: vec![
                track("Player:TipL", Side::Left),
                track("Player:TipR", Side::Right),
            ],
            notes: Vec::new(),
        };
        let mut db = MotionDb {
            index: Index {
                version: db::DB_FORMAT_VERSION,
                description: "test".into(),
                joints: Vec::new(),
                takes: Vec::new(),
                units: Vec::new(),
            },
            takes: Vec::new(),
        };
        let options = IngestOptions {
            tips: ["TipL".into(), "TipR".into()],
            up: UpAxis::Y,
            tip_offset_m: None,
            mode: None,
            location: None,
            dynamic: None,
            grip: Some(Grip::French),
            hand: None,
            performer: "test".into(),
            segment: SegmentParams::default(),
        };
        let report = ingest(&mut db, Path::new("legato_rim_f.csv"), &take, &options).unwrap();
        assert_eq!(report.units, [0, 6], "{report:?}");
        assert!(report.notices.is_empty());
        let spans: Vec<(usize, usize)> = source
            .index
            .units
            .iter()
            .map(|u| (u.start, u.impact))
            .collect();
        let ours: Vec<(usize, usize)> =
            db.index.units.iter().map(|u| (u.start, u.impact)).collect();
        assert_eq!(spans, ours);
        assert!(db.index.units.iter().all(|u| u.mode == PlayingMode::Legato
            && u.location == ImpactLocation::Rim
            && u.dynamic == Dynamic::F));
        let err = ingest(
            &mut db,
            Path::new("x.csv"),
            &take,
            &IngestOptions {
                mode: Some(PlayingMode::Legato),
                tips: ["Nope".into(), "TipR".into()],
                ..options
            },
        )
        .unwrap_err();
        assert!(
            err.to_string().contains("Nope") && err.to_string().contains("Player:TipL"),
            "{err}"
        );
    }
}
