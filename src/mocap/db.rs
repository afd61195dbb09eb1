//! The motion database on disk (`mocap/`): an index in RON (`index.ron`: takes and their
//! segmented motion units with labels) and one compact binary sample file per take
//! (`takes/NAME.tmot`) holding both stick tips and, where the source has them, the
//! upper-body joint rotations, at the capture rate.
//!
//! **`.tmot` sample files** (little-endian): the 8 bytes `TMOTION1`; u32 frame count N;
//! u32 joint count J (0 or 11); f64 sample rate in Hz; then one zlib stream holding, for each
//! tip (left, right), N validity bytes (1 = seen) followed by its x, y, z channels, and
//! then the 4·J quaternion channels (w, x, y, z per joint in `index.joints` order). Each
//! channel is quantised (positions to 10 µm, quaternion components to 1e-6), replaced by
//! its second difference in time, and written as zigzag LEB128 varints. Positions are in
//! the performer frame (metres; +x right, +y forward, +z up).

use crate::base::ron_file::{self, FileError};
use crate::body::limits::{JointLimit, JointLimits};
use crate::body::skeleton::{JOINT_COUNT, Joint, Pose};
use crate::kit::Side;
use crate::score::{Dynamic, Grip, ImpactLocation, PlayingMode};
use flate2::Compression;
use flate2::read::ZlibDecoder;
use flate2::write::ZlibEncoder;
use glam::{DQuat, DVec3};
use serde::{Deserialize, Serialize};
use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// The database format this timpanist writes and the newest it reads.
pub const DB_FORMAT_VERSION: u32 = 1;
const MAGIC: &[u8; 8] = b"TMOTION1";
const POSITION_STEP_M: f64 = 1e-5;
const QUATERNION_STEP: f64 = 1e-6;

/// The SHA-256 of a capture file's bytes in lowercase hex, as `sha256sum` prints it.
pub fn file_sha256(bytes: &[u8]) -> String {
    use sha2::Digest as _;
    sha2::Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// `index.ron`: what the database holds.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename = "MotionDb", deny_unknown_fields)]
pub struct Index {
    pub version: u32,
    /// Where the data came from, in words.
    pub description: String,
    /// Joint names of the rotation channels, in file order (empty if no take has joints).
    pub joints: Vec<String>,
    pub takes: Vec<TakeEntry>,
    pub units: Vec<UnitEntry>,
}

/// One take (one sample file).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TakeEntry {
    /// Sample file, relative to the database folder.
    pub file: String,
    pub frames: usize,
    /// Sample rate, Hz.
    pub rate_hz: f64,
    pub performer: String,
    /// The capture file it was imported from (or "synthetic").
    pub source: String,
    /// The SHA-256 of the capture file's bytes, in hex ([`file_sha256`]; for a take read
    /// from a pair of files, the left file's and the right file's joined by `+`): a take
    /// imported again from a file of the same name and bytes replaces this one
    /// ([`MotionDb::settle_import`]). Absent for synthetic takes and those imported
    /// before it was kept.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub source_sha256: Option<String>,
}

/// One motion unit: a single stroke from the end of the previous stroke's rebound to the
/// end of its own.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct UnitEntry {
    /// Index into `takes`.
    pub take: usize,
    /// First frame.
    pub start: usize,
    /// Frame of the impact.
    pub impact: usize,
    /// Last frame, inclusive.
    pub end: usize,
    pub hand: Side,
    pub mode: PlayingMode,
    pub location: ImpactLocation,
    pub dynamic: Dynamic,
    pub grip: Grip,
}

/// The samples of one take.
#[derive(Clone, Debug, PartialEq)]
pub struct TakeData {
    /// Sample rate, Hz.
    pub rate_hz: f64,
    /// Tip positions per frame, [left, right], m; `None` where not seen.
    pub tips: [Vec<Option<DVec3>>; 2],
    /// Joint rotations per frame, if the source has them.
    pub joints: Option<Vec<Pose>>,
}

impl TakeData {
    /// Frames in the take.
    pub fn frames(&self) -> usize {
        self.tips[0].len()
    }

    /// The tip track of one hand.
    pub fn tip(&self, side: Side) -> &[Option<DVec3>] {
        &self.tips[side_index(side)]
    }
}

/// The sides in the order of `[left, right]` arrays.
pub const SIDES: [Side; 2] = [Side::Left, Side::Right];

/// Index of a side in `[left, right]` arrays.
pub fn side_index(side: Side) -> usize {
    match side {
        Side::Left => 0,
        Side::Right => 1,
    }
}

/// A loaded database.
#[derive(Clone, Debug, PartialEq)]
pub struct MotionDb {
    pub index: Index,
    /// Samples of each take, in `index.takes` order.
    pub takes: Vec<TakeData>,
    /// [`MotionDb::joint_limits`] per grip, estimated on first use (≈ 25 ms for the
    /// shipped database, once, not at every composition). A clone estimates afresh;
    /// change `index` or `takes` before asking for the limits, or in a clone.
    pub limits: LimitsCache,
}

/// The joint limits of a database per grip (French, German), each estimated once.
#[derive(Default)]
pub struct LimitsCache([OnceLock<JointLimits>; 2]);

impl Clone for LimitsCache {
    /// Empty: the clone's index and takes may be changed before it is asked.
    fn clone(&self) -> Self {
        LimitsCache::default()
    }
}

impl PartialEq for LimitsCache {
    /// A cache of what the database holds: databases compare by their contents.
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl std::fmt::Debug for LimitsCache {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("LimitsCache")
    }
}

/// Names of the joints, as written in `index.joints`.
pub fn joint_names() -> Vec<String> {
    Joint::ALL.iter().map(|j| j.name().to_string()).collect()
}

/// The narrowest range of rotation a joint limit allows about any axis (each semi-axis of
/// its ellipsoid at least this, as a rotation either way from the centre), degrees, per
/// joint in [`Joint::ALL`] order. The synthetic performer plays only the two middle drums,
/// each hand on its own side, moving each arm in a plane and keeping trunk, neck and head
/// still, so its estimated ellipsoids pin whole axes that a performer on the whole kit
/// moves (an outer drum, the head turning to the drum about to be struck). The floors
/// stay inside published normal active ranges of motion (AAOS, *Joint Motion: Method of
/// Measuring and Recording*, 1965; Greene & Heckman, *The Clinical Measurement of Joint
/// Motion*, AAOS 1994; Soucie et al., Haemophilia 17:500–507, 2011):
///
/// - trunk 20°: thoracolumbar axial rotation and lateral flexion are 30–45° either way;
///   the IK keeps the trunk within ≈ 6° of upright;
/// - neck 32°, head 48°: cervical axial rotation is 70–80° either way in young adults
///   (Youdas et al., Phys. Ther. 72:770–780, 1992), and the gaze (`body::gaze`)
///   turns 40 % of it in the neck and 60 % in the head: 40 and 60 % of 80°;
/// - shoulder 30°: half the shoulder's least active range (extension ≈ 60°; flexion and
///   abduction 180°, internal and external rotation 70° and 90°);
/// - elbow 20°: the elbow is a hinge with forearm rotation; its estimate moves about both
///   (14–28°), the floor only keeps a ball joint's third axis from being pinned;
/// - wrist 25°: half the radio-ulnar deviation arc (radial ≈ 20°, ulnar ≈ 30°), its
///   least-ranging motion (flexion 80°, extension 70°);
/// - grip 20°: the stick in the fingers, no anatomical joint; its estimate spans
///   60–150° in the stroke's plane.
///
/// Measured on the demo scores (README "Physics (HIMC)"): with 20° everywhere the left
/// hand could not reach the 32-inch drum within its ranges (the task-rate IK, holding
/// 0.9 of each ellipsoid, ended up to 0.3 m short on the one-minute study); the shoulder's 30° brought the worst to
/// 19 mm, the wrist's 25° to 14 mm (8 mm with no limits at all); the neck's and head's
/// floors hold the gaze's turns within 0.99 of their ellipsoids.
pub const MIN_LIMIT_ROTATION_DEG: [f64; JOINT_COUNT] = [
    20.0, 32.0, 48.0, 30.0, 20.0, 25.0, 20.0, 30.0, 20.0, 25.0, 20.0,
];

impl MotionDb {
    /// The joint limits the simulation holds a player of `grip` to: the
    /// [estimates](MotionDb::estimated_joint_limits), each axis at least
    /// [`MIN_LIMIT_ROTATION_DEG`] wide.
    pub fn joint_limits(&self, grip: Grip) -> JointLimits {
        let slot = match grip {
            Grip::French => 0,
            Grip::German => 1,
        };
        *self.limits.0[slot].get_or_init(|| {
            let mut limits = self.estimated_joint_limits(grip);
            for (limit, floor) in limits.iter_mut().zip(MIN_LIMIT_ROTATION_DEG) {
                *limit = limit.map(|l| l.at_least(floor.to_radians()));
            }
            limits
        })
    }

    /// The joint limits of `grip` estimated from the captured joint rotations of its
    /// units (seed 000 Alg. 1; each arm only while it plays, every fifth frame); `None`
    /// for every joint when no unit of that grip has captured joints (tip-only captures).
    pub fn estimated_joint_limits(&self, grip: Grip) -> JointLimits {
        let units: Vec<&UnitEntry> = self
            .index
            .units
            .iter()
            .filter(|u| u.grip == grip && self.takes[u.take].joints.is_some())
            .collect();
        // Each joint's estimate is independent (its iterated mean is most of a render's
        // start): spread over the cores, in joint order.
        let estimates = crate::base::parallel::chunked(&Joint::ALL, |&joint| {
            let j = joint.index();
            let samples: Vec<_> = units
                .iter()
                .filter(|u| !Joint::arm(u.hand.other()).contains(&joint))
                .flat_map(|u| {
                    let poses = self.takes[u.take].joints.as_deref().unwrap_or_default();
                    poses[u.start..=u.end.min(poses.len().saturating_sub(1))]
                        .iter()
                        .step_by(5)
                        .map(move |p| p[j])
                })
                .collect();
            JointLimit::estimate(&samples)
        });
        std::array::from_fn(|j| estimates[j])
    }

    /// A database with no takes yet.
    pub fn empty(description: &str) -> MotionDb {
        MotionDb {
            index: Index {
                version: DB_FORMAT_VERSION,
                description: description.to_string(),
                joints: joint_names(),
                takes: Vec::new(),
                units: Vec::new(),
            },
            takes: Vec::new(),
            limits: LimitsCache::default(),
        }
    }

    /// Load `dir/index.ron` and every sample file it names.
    pub fn load(dir: &Path) -> Result<MotionDb, FileError> {
        let index_path = dir.join("index.ron");
        let text = ron_file::read_text(&index_path)?;
        Self::from_parts(dir, &text, &|path| {
            std::fs::read(path).map_err(|e| FileError::io(path, e))
        })
    }

    /// A database from its index text and a reader of its sample files (`read` gets
    /// `dir` joined with each take's file); errors name paths under `dir`.
    pub(crate) fn from_parts(
        dir: &Path,
        index_text: &str,
        read: &dyn Fn(&Path) -> Result<Vec<u8>, FileError>,
    ) -> Result<MotionDb, FileError> {
        let index_path = dir.join("index.ron");
        let index: Index = ron_file::parse(&index_path, index_text)?;
        if index.version > DB_FORMAT_VERSION {
            return Err(FileError::TooNew {
                path: index_path,
                found: index.version,
                supported: DB_FORMAT_VERSION,
            });
        }
        let files = index
            .takes
            .iter()
            .map(|t| {
                let path = dir.join(&t.file);
                let bytes = read(&path)?;
                Ok((path, bytes, t.frames))
            })
            .collect::<Result<Vec<_>, FileError>>()?;
        let takes = decode_all(&files)?;
        for (i, u) in index.units.iter().enumerate() {
            let ok = index
                .takes
                .get(u.take)
                .is_some_and(|t| u.start < u.impact && u.impact < u.end && u.end < t.frames);
            if !ok {
                return Err(FileError::invalid(
                    &index_path,
                    format!("unit {i}"),
                    "frames outside its take, or start < impact < end violated",
                ));
            }
        }
        Ok(MotionDb {
            index,
            takes,
            limits: LimitsCache::default(),
        })
    }

    /// Write every sample file and then the index, each atomically. Every sample file is
    /// encoded and read back first: one that would not read back as its take is an error
    /// before anything is written.
    pub fn save(&self, dir: &Path) -> Result<(), FileError> {
        let encoded = self
            .index
            .takes
            .iter()
            .zip(&self.takes)
            .map(|(entry, data)| {
                let path = dir.join(&entry.file);
                let bytes = encode_take(data);
                let back = decode_take(&path, &bytes)?;
                if back.frames() != data.frames() {
                    return Err(FileError::invalid(
                        &path,
                        "encoding",
                        format!("{} frames read back of {}", back.frames(), data.frames()),
                    ));
                }
                Ok((path, bytes))
            })
            .collect::<Result<Vec<_>, FileError>>()?;
        for (path, bytes) in encoded {
            if let Some(parent) = path.parent() {
                std::fs::create_dir_all(parent).map_err(|e| FileError::io(parent, e))?;
            }
            ron_file::write_atomic(&path, &bytes)?;
        }
        ron_file::save(&dir.join("index.ron"), &self.index)
    }

    /// The (grip, playing mode) pairs `other` has units of and this database has none of,
    /// in `other`'s order of first appearance.
    pub fn modes_lacking(&self, other: &MotionDb) -> Vec<(Grip, PlayingMode)> {
        let has = |db: &MotionDb, key: (Grip, PlayingMode)| {
            db.index.units.iter().any(|u| (u.grip, u.mode) == key)
        };
        let mut lacking: Vec<(Grip, PlayingMode)> = Vec::new();
        for key in other.index.units.iter().map(|u| (u.grip, u.mode)) {
            if !lacking.contains(&key) && !has(self, key) {
                lacking.push(key);
            }
        }
        lacking
    }

    /// This database completed by `shipped` (the synthetic one): for every playing mode of
    /// a grip this database has no unit of ([`MotionDb::modes_lacking`]), `shipped`'s
    /// units of it and the takes they are cut from are added (after this database's own,
    /// their files under `fallback/`), so a score asking for that mode gets a stroke of
    /// its own mode rather than the nearest of another. Labels this database has are left
    /// alone, even where `shipped` has more of them (hands, locations, dynamics).
    pub fn with_fallback(&self, shipped: &MotionDb) -> MotionDb {
        let lacking = self.modes_lacking(shipped);
        let mut db = self.clone();
        if lacking.is_empty() {
            return db;
        }
        let mut taken: Vec<Option<usize>> = vec![None; shipped.takes.len()];
        for unit in &shipped.index.units {
            if !lacking.contains(&(unit.grip, unit.mode)) {
                continue;
            }
            let take = *taken[unit.take].get_or_insert_with(|| {
                let entry = &shipped.index.takes[unit.take];
                db.index.takes.push(TakeEntry {
                    file: format!("fallback/{}", entry.file),
                    ..entry.clone()
                });
                db.takes.push(shipped.takes[unit.take].clone());
                db.takes.len() - 1
            });
            db.index.units.push(UnitEntry {
                take,
                ..unit.clone()
            });
        }
        if db.takes.iter().any(|t| t.joints.is_some()) {
            db.index.joints = joint_names();
        }
        db.index.description = format!(
            "{} Completed with the modes it lacks from: {}",
            self.index.description, shipped.index.description
        );
        db
    }

    /// Settle the last take, just imported from `path` (a capture whose bytes hash to
    /// `sha256`, [`file_sha256`]): record the hash, and if an earlier take was imported
    /// from a file of the same name with the same bytes, put the new take in its place
    /// (same sample file; its units replaced by the new take's). A file of the same name
    /// with other bytes is kept beside it (its sample file already named apart, `NAME-2`).
    /// Returns the note saying which of these happened, if either did.
    pub fn settle_import(&mut self, path: &Path, sha256: &str) -> Option<String> {
        let last = self.index.takes.len().checked_sub(1)?;
        self.index.takes[last].source_sha256 = Some(sha256.to_string());
        let name = path.file_name()?;
        let named_alike = |t: &TakeEntry| Path::new(&t.source).file_name() == Some(name);
        let earlier = &self.index.takes[..last];
        let same = earlier
            .iter()
            .position(|t| named_alike(t) && t.source_sha256.as_deref() == Some(sha256));
        let other = earlier.iter().position(named_alike);
        let shown = name.to_string_lossy();
        let Some(old) = same else {
            let other = &self.index.takes[other?];
            let bytes = match other.source_sha256 {
                Some(_) => "with other bytes",
                None => "its bytes unrecorded (imported before they were kept)",
            };
            return Some(format!(
                "another file named {shown} is already in the database (take {}, from {}, \
                 {bytes}): this one is added beside it as take {}",
                other.file, other.source, self.index.takes[last].file
            ));
        };
        let entry = self.index.takes.pop()?;
        let data = self.takes.pop()?;
        let file = self.index.takes[old].file.clone();
        let was = std::mem::replace(&mut self.index.takes[old], TakeEntry { file, ..entry });
        self.takes[old] = data;
        self.index.units.retain(|u| u.take != old);
        for u in &mut self.index.units {
            if u.take == last {
                u.take = old;
            }
        }
        Some(format!(
            "take {} already in the database (the same bytes, imported from {}): replaced",
            was.file, was.source
        ))
    }

    /// The tip samples of unit `u` for its own hand, from start to end.
    pub fn unit_tip(&self, u: &UnitEntry) -> &[Option<DVec3>] {
        &self.takes[u.take].tip(u.hand)[u.start..=u.end]
    }
}

/// Serialise one take as a `.tmot` file.
pub fn encode_take(data: &TakeData) -> Vec<u8> {
    let n = data.frames();
    let mut out = Vec::new();
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&(n as u32).to_le_bytes());
    let joints = if data.joints.is_some() {
        JOINT_COUNT
    } else {
        0
    };
    out.extend_from_slice(&(joints as u32).to_le_bytes());
    out.extend_from_slice(&data.rate_hz.to_le_bytes());
    let mut z = ZlibEncoder::new(out, Compression::default());
    let mut body = Vec::new();
    for tip in &data.tips {
        body.extend(tip.iter().map(|p| u8::from(p.is_some())));
        for axis in 0..3 {
            put_channel(
                &mut body,
                tip.iter()
                    .map(|p| p.map_or(0.0, |p| p[axis]) / POSITION_STEP_M),
            );
        }
    }
    if let Some(poses) = &data.joints {
        for j in 0..JOINT_COUNT {
            for c in 0..4 {
                put_channel(
                    &mut body,
                    poses
                        .iter()
                        .map(|p| canonical(p[j]).to_array()[(c + 3) % 4] / QUATERNION_STEP),
                );
            }
        }
    }
    z.write_all(&body).expect("writing to memory cannot fail");
    z.finish().expect("writing to memory cannot fail")
}

/// Decode each (path, bytes, frames the index expects) on the machine's cores (decoding
/// the shipped database is most of the program's start), failing on the first bad file in
/// index order.
fn decode_all(files: &[(PathBuf, Vec<u8>, usize)]) -> Result<Vec<TakeData>, FileError> {
    let decode = |(path, bytes, frames): &(PathBuf, Vec<u8>, usize)| {
        let data = decode_take(path, bytes)?;
        if data.frames() != *frames {
            return Err(FileError::invalid(
                path,
                "header",
                format!("{} frames, but index.ron says {frames}", data.frames()),
            ));
        }
        Ok(data)
    };
    crate::base::parallel::chunked(files, decode)
        .into_iter()
        .collect()
}

/// Read a `.tmot` file; `path` names it in errors. Corrupt or truncated data is an error.
pub fn decode_take(path: &Path, bytes: &[u8]) -> Result<TakeData, FileError> {
    let bad = |place: &str, msg: String| FileError::invalid(path, place.to_string(), msg);
    if bytes.len() < 24 || &bytes[..8] != MAGIC {
        return Err(bad(
            "header",
            "not a timpanist .tmot sample file (expected the 24-byte TMOTION1 header)".into(),
        ));
    }
    let n = u32::from_le_bytes(bytes[8..12].try_into().expect("4 bytes")) as usize;
    let joints = u32::from_le_bytes(bytes[12..16].try_into().expect("4 bytes")) as usize;
    let rate_hz = f64::from_le_bytes(bytes[16..24].try_into().expect("8 bytes"));
    if !(rate_hz.is_finite() && rate_hz > 0.0) {
        return Err(bad(
            "header",
            format!("sample rate {rate_hz} Hz is not positive"),
        ));
    }
    if joints != 0 && joints != JOINT_COUNT {
        return Err(bad(
            "header",
            format!("{joints} joints; expected 0 or {JOINT_COUNT}"),
        ));
    }
    let limit = (n as u64 + 1) * 8 * (6 + 4 * JOINT_COUNT as u64) + 64;
    // Room for all of it at once (no copies as it grows; pages left untouched cost
    // nothing): twice the least the header's frames need (a sample's delta takes a byte
    // or two), never more than deflate's largest ratio (1032:1) over what is there nor
    // 256 MB (a corrupt header then only grows the buffer as data comes).
    let least = (n as u64) * (2 * 4 + 4 * JOINT_COUNT as u64);
    let room = (2 * least + 64)
        .min(limit)
        .min(bytes.len() as u64 * 1032)
        .min(1 << 28);
    let mut body = Vec::with_capacity(usize::try_from(room).unwrap_or(0));
    ZlibDecoder::new(&bytes[24..])
        .take(limit)
        .read_to_end(&mut body)
        .map_err(|e| bad("sample data", format!("corrupt compressed data: {e}")))?;
    // Every frame takes at least a byte in each channel (a tip's flags and three axes,
    // four per joint): a frame count the data cannot hold is refused before anything is
    // allocated for it.
    let needed = n.checked_mul(2 * 4 + 4 * joints);
    if needed.is_none_or(|needed| body.len() < needed) {
        return Err(bad(
            "sample data",
            format!(
                "{n} frames cannot fit in {} bytes of samples (truncated?)",
                body.len()
            ),
        ));
    }
    let mut reader = Channels {
        body: &body,
        pos: 0,
    };
    let mut tips: [Vec<Option<DVec3>>; 2] = [Vec::new(), Vec::new()];
    for tip in &mut tips {
        let seen = reader
            .bytes(n)
            .ok_or_else(|| bad("sample data", "truncated validity flags".into()))?
            .to_vec();
        let axes: Vec<Vec<f64>> = (0..3)
            .map(|_| reader.channel(n, POSITION_STEP_M))
            .collect::<Option<_>>()
            .ok_or_else(|| bad("sample data", "truncated tip channel".into()))?;
        *tip = (0..n)
            .map(|f| (seen[f] == 1).then(|| DVec3::new(axes[0][f], axes[1][f], axes[2][f])))
            .collect();
    }
    let joints = if joints == 0 {
        None
    } else {
        // Each channel straight into its component of the poses (w, x, y, z per joint).
        let mut poses = vec![[DQuat::IDENTITY; JOINT_COUNT]; n];
        for c in 0..4 * JOINT_COUNT {
            let (j, k) = (c / 4, c % 4);
            reader
                .channel_into(n, QUATERNION_STEP, |f, v| {
                    let q = &mut poses[f][j];
                    match k {
                        0 => q.w = v,
                        1 => q.x = v,
                        2 => q.y = v,
                        _ => q.z = v,
                    }
                })
                .ok_or_else(|| bad("sample data", "truncated joint channel".into()))?;
        }
        for q in poses.iter_mut().flatten() {
            *q = q.normalize();
        }
        Some(poses)
    };
    if reader.pos != body.len() {
        return Err(bad(
            "sample data",
            format!(
                "{} bytes left over after the last channel",
                body.len() - reader.pos
            ),
        ));
    }
    Ok(TakeData {
        rate_hz,
        tips,
        joints,
    })
}

/// The quaternion with w ≥ 0 (q and −q are the same rotation), so channels stay smooth.
fn canonical(q: DQuat) -> DQuat {
    if q.w < 0.0 { -q } else { q }
}

/// Append one channel: quantised, second-differenced, zigzag LEB128.
fn put_channel(out: &mut Vec<u8>, values: impl Iterator<Item = f64>) {
    let (mut prev, mut prev_delta) = (0i64, 0i64);
    for v in values {
        let q = v.round() as i64;
        let delta = q - prev;
        let dd = delta - prev_delta;
        prev = q;
        prev_delta = delta;
        let mut z = ((dd << 1) ^ (dd >> 63)) as u64;
        loop {
            let byte = (z & 0x7f) as u8;
            z >>= 7;
            if z == 0 {
                out.push(byte);
                break;
            }
            out.push(byte | 0x80);
        }
    }
}

struct Channels<'a> {
    body: &'a [u8],
    pos: usize,
}

impl Channels<'_> {
    fn bytes(&mut self, n: usize) -> Option<&[u8]> {
        let slice = self.body.get(self.pos..self.pos.checked_add(n)?)?;
        self.pos += n;
        Some(slice)
    }

    fn varint(&mut self) -> Option<i64> {
        let mut z = 0u64;
        for shift in (0..64).step_by(7) {
            let byte = *self.body.get(self.pos)?;
            self.pos += 1;
            z |= u64::from(byte & 0x7f) << shift;
            if byte & 0x80 == 0 {
                return Some((z >> 1) as i64 ^ -((z & 1) as i64));
            }
        }
        None
    }

    fn channel(&mut self, n: usize, step: f64) -> Option<Vec<f64>> {
        let mut out = vec![0.0; n];
        self.channel_into(n, step, |f, v| out[f] = v)?;
        Some(out)
    }

    /// Decode `n` values of a channel, handing each (frame, value) to `put`.
    fn channel_into(&mut self, n: usize, step: f64, mut put: impl FnMut(usize, f64)) -> Option<()> {
        let (mut value, mut delta) = (0i64, 0i64);
        for f in 0..n {
            delta = delta.checked_add(self.varint()?)?;
            value = value.checked_add(delta)?;
            put(f, value as f64 * step);
        }
        Some(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample_take() -> TakeData {
        let n = 300;
        let tip = |phase: f64| {
            (0..n)
                .map(|f| {
                    let t = f as f64 / 250.0;
                    (f % 97 != 0).then(|| {
                        DVec3::new(
                            0.3 * phase,
                            0.5 + 0.01 * t,
                            0.8 + 0.2 * (t * 7.0 + phase).sin(),
                        )
                    })
                })
                .collect()
        };
        let poses = (0..n)
            .map(|f| std::array::from_fn(|j| DQuat::from_rotation_x(0.001 * (f * (j + 1)) as f64)))
            .collect();
        TakeData {
            rate_hz: 250.0,
            tips: [tip(-1.0), tip(1.0)],
            joints: Some(poses),
        }
    }

    /// Add a take imported from `source` (sample file `takes/<file>.tmot`) with one unit
    /// per hand, as `ingest` does.
    fn add_take(db: &mut MotionDb, source: &str, file: &str, phase: f64) {
        let take = db.index.takes.len();
        let mut data = sample_take();
        data.tips[0][0] = Some(DVec3::splat(phase));
        db.index.takes.push(TakeEntry {
            file: format!("takes/{file}.tmot"),
            frames: data.frames(),
            rate_hz: data.rate_hz,
            performer: "p".into(),
            source: source.into(),
            source_sha256: None,
        });
        db.takes.push(data);
        for hand in SIDES {
            db.index.units.push(UnitEntry {
                take,
                start: 10,
                impact: 20,
                end: 30,
                hand,
                mode: PlayingMode::Legato,
                location: ImpactLocation::PlayingSpot,
                dynamic: Dynamic::F,
                grip: Grip::French,
            });
        }
    }

    /// A take imported again from a file of the same name and bytes takes the earlier
    /// one's place (its units re-pointed, the other takes' left alone); a take imported
    /// before hashes were kept is never taken for the same file.
    #[test]
    fn a_take_imported_again_replaces_the_earlier_one() {
        assert_eq!(
            file_sha256(b"abc"),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
        );
        let mut db = MotionDb::empty("t");
        add_take(&mut db, "old/roll.csv", "roll", 1.0);
        add_take(&mut db, "lab/other.c3d", "other", 2.0);
        add_take(&mut db, "lab/roll.csv", "roll-2", 3.0);
        let note = db.settle_import(Path::new("lab/roll.csv"), "aa").unwrap();
        assert!(
            note.contains("(take takes/roll.tmot, from old/roll.csv, its bytes unrecorded"),
            "{note}"
        );
        assert_eq!(db.index.takes.len(), 3);
        add_take(&mut db, "lab/other.c3d", "other-2", 4.0);
        let note = db.settle_import(Path::new("lab/other.c3d"), "bb");
        assert!(note.unwrap().ends_with(
            "its bytes unrecorded (imported before they were kept)): this one is added beside \
             it as take takes/other-2.tmot"
        ));
        assert_eq!(db.index.takes.len(), 4);
        add_take(&mut db, "/copy/roll.csv", "roll-3", 5.0);
        let note = db.settle_import(Path::new("/copy/roll.csv"), "aa").unwrap();
        assert_eq!(
            note,
            "take takes/roll-2.tmot already in the database (the same bytes, imported from \
             lab/roll.csv): replaced"
        );
        assert_eq!(db.index.takes.len(), 4);
        let replaced = &db.index.takes[2];
        assert_eq!(
            (replaced.file.as_str(), replaced.source.as_str()),
            ("takes/roll-2.tmot", "/copy/roll.csv")
        );
        assert_eq!(db.takes[2].tips[0][0], Some(DVec3::splat(5.0)));
        let takes: Vec<usize> = db.index.units.iter().map(|u| u.take).collect();
        assert_eq!(takes, [0, 0, 1, 1, 3, 3, 2, 2]);
    }

    /// Encoding then decoding keeps positions to 10 µm, rotations to 1e-5 and gaps as gaps.
    #[test]
    fn tmot_round_trip() {
        let data = sample_take();
        let bytes = encode_take(&data);
        let back = decode_take(Path::new("t.tmot"), &bytes).unwrap();
        for side in 0..2 {
            for (a, b) in data.tips[side].iter().zip(&back.tips[side]) {
                match (a, b) {
                    (Some(a), Some(b)) => assert!((*a - *b).abs().max_element() <= 0.5e-5 + 1e-12),
                    (None, None) => {}
                    _ => panic!("gap not kept"),
                }
            }
        }
        for (pa, pb) in data
            .joints
            .as_ref()
            .unwrap()
            .iter()
            .zip(back.joints.as_ref().unwrap())
        {
            for (a, b) in pa.iter().zip(pb) {
                assert!(a.angle_between(*b) < 1e-5);
            }
        }
    }

    /// Decoding on several threads keeps the index's order, and of several bad files
    /// names the first in that order (a frame count the index disagrees with, then a
    /// truncated file).
    #[test]
    fn takes_decode_in_order_and_the_first_bad_one_is_named() {
        let takes: Vec<TakeData> = (0..7)
            .map(|k| {
                let mut t = sample_take();
                t.tips[0].truncate(300 - 10 * k);
                t.tips[1].truncate(300 - 10 * k);
                t.joints.as_mut().unwrap().truncate(300 - 10 * k);
                t
            })
            .collect();
        let files: Vec<(PathBuf, Vec<u8>, usize)> = takes
            .iter()
            .enumerate()
            .map(|(k, t)| {
                (
                    PathBuf::from(format!("{k}.tmot")),
                    encode_take(t),
                    t.frames(),
                )
            })
            .collect();
        let decoded = decode_all(&files).expect("all good");
        for (a, b) in decoded.iter().zip(&files) {
            assert_eq!(a.frames(), b.2);
            assert_eq!(a, &decode_take(&b.0, &b.1).unwrap());
        }
        let mut bad = files.clone();
        bad[2].2 += 1;
        let cut = bad[5].1.len() / 2;
        bad[5].1.truncate(cut);
        let err = decode_all(&bad).unwrap_err().to_string();
        assert!(
            err.contains("2.tmot") && err.contains("index.ron says"),
            "{err}"
        );
        let err = decode_all(&bad[3..]).unwrap_err().to_string();
        assert!(err.contains("5.tmot"), "{err}");
    }

    /// Truncated or corrupted sample files are errors, never panics.
    #[test]
    fn corrupt_files_are_errors() {
        let bytes = encode_take(&sample_take());
        for cut in [0, 7, 23, 24, 40, bytes.len() / 2, bytes.len() - 1] {
            assert!(
                decode_take(Path::new("t.tmot"), &bytes[..cut]).is_err(),
                "cut at {cut}"
            );
        }
        for at in (24..bytes.len()).step_by(bytes.len() / 40 + 1) {
            let mut b = bytes.clone();
            b[at] ^= 0x5a;
            let _ = decode_take(Path::new("t.tmot"), &b);
        }
        let mut huge = bytes.clone();
        huge[8..12].copy_from_slice(&u32::MAX.to_le_bytes());
        let err = decode_take(Path::new("t.tmot"), &huge)
            .unwrap_err()
            .to_string();
        assert!(err.contains("cannot fit"), "{err}");
    }
}
