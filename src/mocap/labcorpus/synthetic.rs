//! The performer-frame samples of the sticks of a synthetic database take: the tips, the
//! stick frames by forward kinematics of the stored joints, arm markers, the impacts;
//! resampled to the output rate.

use super::*;

/// One hand's samples in the performer frame at the output rate.
pub(super) struct SideSamples {
    pub(super) side: Side,
    pub(super) tip: Vec<DVec3>,
    /// Stick frame (world from stick; its −Z runs along the stick toward the tip).
    pub(super) stick: Vec<DQuat>,
    /// Arm markers: name and positions.
    pub(super) markers: Vec<(String, Vec<DVec3>)>,
    pub(super) impacts: Vec<Impact>,
}

/// A take ready to be written.
pub(super) struct PerformerTake {
    /// Capture name (file stem).
    pub(super) name: String,
    pub(super) rate_hz: f64,
    pub(super) sides: Vec<SideSamples>,
    pub(super) labels: SourceLabels,
}

impl PerformerTake {
    pub(super) fn frames(&self) -> usize {
        self.sides.first().map_or(0, |s| s.tip.len())
    }
}

/// Forward kinematics may put a tip this far from the stored one, m.
pub(super) const FK_TOLERANCE_M: f64 = 1e-3;

/// The arm markers of the synthetic performer.
pub(super) const ARM_MARKERS: [(&str, usize); 3] = [("Shoulder", 0), ("Elbow", 1), ("Wrist", 2)];

/// The performer-frame samples of database take `take`.
pub(super) fn synthetic_take(
    db: &MotionDb,
    take: usize,
    style: &LabStyle,
) -> Result<PerformerTake, CorpusError> {
    let entry = db.index.takes.get(take).ok_or(CorpusError::NoSuchTake {
        take,
        takes: db.index.takes.len(),
    })?;
    let data = &db.takes[take];
    let poses = data.joints.as_ref().ok_or(CorpusError::NoJoints(take))?;
    let units: Vec<&UnitEntry> = db.index.units.iter().filter(|u| u.take == take).collect();
    let first = *units.first().ok_or(CorpusError::NoUnits(take))?;
    let skeleton = Performer::new().skeleton;
    let frames: Vec<Frames> = poses.iter().map(|p| skeleton.forward(p)).collect();
    let error_m = fk_error_m(&frames, &data.tips);
    if error_m > FK_TOLERANCE_M {
        return Err(CorpusError::SkeletonMismatch {
            take,
            error_mm: error_m * 1e3,
        });
    }
    let hands: Vec<Side> = SIDES
        .into_iter()
        .filter(|s| style.sticks == Sticks::Both || units.iter().any(|u| u.hand == *s))
        .collect();
    let resample_at = |values: Vec<DVec3>| resample(&values, data.rate_hz, style.rate_hz);
    let sides = hands
        .into_iter()
        .map(|side| {
            let arm = Joint::arm(side);
            let grip = arm[3].index();
            SideSamples {
                side,
                tip: resample_at(frames.iter().map(|f| f.tip(side)).collect()),
                stick: resample(
                    &frames.iter().map(|f| f.rotation[grip]).collect::<Vec<_>>(),
                    data.rate_hz,
                    style.rate_hz,
                ),
                markers: ARM_MARKERS
                    .iter()
                    .map(|&(name, k)| {
                        let j = arm[k].index();
                        (
                            name.to_string(),
                            resample_at(frames.iter().map(|f| f.position[j]).collect()),
                        )
                    })
                    .collect(),
                // Every impact of the clean source tip, the first and last strokes of the
                // take too (they give no unit, but a person counts them).
                impacts: crate::mocap::segment::segment(
                    data.tip(side),
                    data.rate_hz,
                    &crate::mocap::segment::SegmentParams::default(),
                )
                .impacts
                .iter()
                .map(|&f| Impact {
                    time_s: f as f64 / data.rate_hz,
                    dynamic: units
                        .iter()
                        .find(|u| u.hand == side && u.impact == f)
                        .map(|u| u.dynamic),
                })
                .collect(),
            }
        })
        .collect();
    let impact_tips: Vec<DVec3> = units.iter().map(|u| frames[u.impact].tip(u.hand)).collect();
    let (drum, drum_name) = nearest_drum(mean(&impact_tips), None);
    let name = Path::new(&entry.file)
        .file_stem()
        .map_or_else(|| format!("take-{take}"), |s| s.to_string_lossy().into());
    Ok(PerformerTake {
        name,
        rate_hz: style.rate_hz,
        sides,
        labels: SourceLabels {
            source: format!("{} (synthetic database take {take})", entry.file),
            drum,
            drum_name,
            location: Some(first.location),
            mode: Some(first.mode),
            grip: Some(first.grip),
        },
    })
}

/// The largest distance between a forward-kinematics tip and the stored tip, m.
pub(super) fn fk_error_m(frames: &[Frames], tips: &[Vec<Option<DVec3>>; 2]) -> f64 {
    SIDES
        .into_iter()
        .zip(tips)
        .flat_map(|(side, stored)| {
            frames
                .iter()
                .zip(stored)
                .filter_map(move |(f, t)| t.map(|t| f.tip(side).distance(t)))
        })
        .fold(0.0, f64::max)
}

pub(super) fn mean(points: &[DVec3]) -> DVec3 {
    points.iter().sum::<DVec3>() / points.len().max(1) as f64
}

/// The drum of the standard kit whose centre is horizontally nearest `point` (among the
/// drums `hand` plays by default, if given): index and name.
pub(super) fn nearest_drum(point: DVec3, hand: Option<Side>) -> (usize, String) {
    let kit = Kit::standard();
    let i = kit
        .nearest_drum(point, hand)
        .expect("the standard kit has a drum for each hand");
    (i, kit.drums[i].name.clone())
}

/// Mixes two samples: linear interpolation of positions, slerp of rotations.
pub(super) trait Mix: Copy {
    fn mix(self, other: Self, t: f64) -> Self;
}

impl Mix for DVec3 {
    fn mix(self, other: Self, t: f64) -> Self {
        self.lerp(other, t)
    }
}

impl Mix for DQuat {
    fn mix(self, other: Self, t: f64) -> Self {
        self.slerp(other, t)
    }
}

/// `values` sampled at `from_hz` resampled at `to_hz` over the same span (frame 0 at
/// time 0 in both).
pub(super) fn resample<T: Mix>(values: &[T], from_hz: f64, to_hz: f64) -> Vec<T> {
    let Some(last) = values.len().checked_sub(1) else {
        return Vec::new();
    };
    let frames = (last as f64 * to_hz / from_hz + 1e-9).floor() as usize + 1;
    (0..frames)
        .map(|k| {
            let s = k as f64 * from_hz / to_hz;
            let i = (s.floor() as usize).min(last);
            let a = s - i as f64;
            if i < last && a > 1e-12 {
                values[i].mix(values[i + 1], a)
            } else {
                values[i]
            }
        })
        .collect()
}
