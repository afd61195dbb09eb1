//! Generates motion-capture files laid out the way real labs write them, each with its
//! ground truth (impact times, tip offset, lab transform, labels), to test importers and
//! the stick-finding steps on data whose answers are known.
//!
//! # Sources
//!
//! * A take of the synthetic database ([`generate`]): the stick of each written hand is
//!   rebuilt by forward kinematics of the stored joint rotations on the synthetic
//!   performer's skeleton (`synth::Performer::new()`: 1.75 m tall, 0.37 m mallets, so a
//!   0.33 m stick from the grip joint along the grip segment's −Z). This reproduces the
//!   stored tips to a few µm (checked on every take; more than 1 mm is an error). The
//!   impacts are those segmentation finds in the clean stored tip of that hand (its units'
//!   impacts plus the take's first and last strokes, which give no unit), in seconds.
//! * The real TrajOptDrums stroke ([`from_trajoptdrums`]; Pearl 2023, MIT; a copy is in
//!   `tests/fixtures/trajoptdrums/`): 160 frames at 240 Hz, cm, of a right arm in a
//!   vertical plane, shoulder at the origin. In `JointCenters_XPose_cm.csv` each joint's
//!   x is horizontal (forward), in `JointCenters_YPose_cm.csv` its y is **vertical**: the
//!   elbow hangs 24–27 cm below the shoulder in y while staying within 8 cm of it in x.
//!   The "Drum Bead" (the tip) rises from a low rest (−43.6 cm) to a top at 0.41 s
//!   (+9.2 cm), falls in 0.21 s at up to 9 m/s to its minimum, the impact, at 0.622 s
//!   (−47.0 cm), and rebounds 8 cm. The take repeats this stroke N times (see
//!   [`from_trajoptdrums`] for the stitching) and places it at the playing spot of the
//!   nearest drum the right hand plays by default.
//!
//! # Lab frame
//!
//! Positions start in the performer frame (m; +x right, +y forward, +z up). The lab frame
//! is the performer frame turned about the vertical by `yaw_rad`, shifted by
//! `translation_m`, then, for a Y-up lab, remapped (x, y, z) ↦ (x, z, −y) (the inverse of
//! `mocap::ingest::to_performer`). See [`LabTransform`]. Positions are written in the
//! style's unit, rotations as the layout requires.
//!
//! A **rigid body** per stick (Motive, Qualisys, vendor layouts): its frame is the stick
//! frame (the grip segment's, −Z along the stick toward the tip) times a fixed marker-
//! cluster rotation (default 90° about X then 20° about Z, `R_c = Rx(90°)·Rz(20°)`), its
//! origin on the stick `origin_from_tip_m` (default 0.27 m) from the tip, so that
//! `tip = origin + R·tip_offset_body` with `tip_offset_body = R_c⁻¹·(0, 0, −d)` (in
//! [`TrackTruth::tip_offset_body_m`]). A **marker** layout (Vicon, TRC) writes a tip
//! marker per stick and arm markers (shoulder, elbow, wrist; finger for TrajOptDrums) —
//! or, with [`LabStyle::stick_markers_m`], loose markers on each stick (`Stick{L,R}1`,
//! `2`, …, their places in [`TrackTruth::stick_markers_m`]), the first two optionally
//! swapping labels in runs ([`LabStyle::marker_swaps`]).
//!
//! Imperfections, all seeded: Gaussian noise on positions (default σ 1 mm per axis) and
//! rotations (σ 0.3° per axis, applied in the lab frame); gaps (default 2 % of the frames
//! of each track missing, in runs of 1–20 frames) written as the layout writes missing
//! data; dropped frames (rows left out, their frame numbers and times skipped; off by
//! default, since Motive, Nexus and QTM write every frame and our Motive and Vicon
//! readers refuse a skipped row).
//!
//! # Layouts (exact text; ⇥ is a tab)
//!
//! 1. **Motive CSV 1.23**, rigid bodies (and their three solved cluster markers), as read
//!    by `mocap::import::motive`; frames from 0, time 0 s:
//!    ```text
//!    Format Version,1.23,Take Name,french-legato-centre-right,Take Notes,,Capture Frame Rate,240.000000,Export Frame Rate,240.000000,Capture Start Time,2026-11-30 10.21.07.000 AM,Capture Start Frame,0,Total Frames in Take,4763,Total Exported Frames,4763,Rotation Type,Quaternion,Length Units,Millimeters,Coordinate Space,Global
//!
//!    ,Type,Rigid Body,Rigid Body,Rigid Body,Rigid Body,Rigid Body,Rigid Body,Rigid Body,Rigid Body,Rigid Body Marker,…
//!    ,Name,StickR,StickR,StickR,StickR,StickR,StickR,StickR,StickR,StickR:Marker1,…
//!    ,ID,1,1,1,1,1,1,1,1,1:1,…
//!    ,,Rotation,Rotation,Rotation,Rotation,Position,Position,Position,Mean Marker Error,Position,Position,Position,Marker Quality,…
//!    Frame,Time (Seconds),X,Y,Z,W,X,Y,Z,,X,Y,Z,,…
//!    0,0.000000,0.533530,0.241684,0.090057,0.805496,1901.927876,954.846843,161.577637,0.339267,1905.876237,…
//!    ```
//!    Missing: every cell of the body empty, and of its cluster markers (solved from it).
//! 2. **Vicon Nexus CSV**, `Trajectories` section, markers `Player:TipR`, … (Z up by
//!    default), as read by `mocap::import::vicon`; frames from 1:
//!    ```text
//!    Trajectories
//!    200
//!    ,,Player:TipR,,,Player:ShoulderR,,,Player:ElbowR,,,Player:WristR,,
//!    Frame,Sub Frame,X,Y,Z,X,Y,Z,X,Y,Z,X,Y,Z
//!    ,,mm,mm,mm,mm,mm,mm,mm,mm,mm,mm,mm,mm
//!    1,0,1797.17220,38.26364,809.77510,2011.89482,-534.27000,1488.09658,2027.66621,…
//!    ```
//!    Missing: the marker's three cells empty.
//! 3. **Qualisys QTM TSV, 6D** (Z up, always mm, angles in degrees):
//!    ```text
//!    NO_OF_FRAMES⇥3969
//!    NO_OF_CAMERAS⇥12
//!    NO_OF_BODIES⇥1
//!    FREQUENCY⇥200
//!    NO_OF_ANALOG⇥0
//!    ANALOG_FREQUENCY⇥0
//!    DESCRIPTION⇥--
//!    TIME_STAMP⇥2026-11-30, 10:21:07⇥4711.08154296
//!    DATA_INCLUDED⇥6D
//!    BODY_NAMES⇥StickR
//!    Frame⇥Time⇥StickR X⇥Y⇥Z⇥Roll⇥Pitch⇥Yaw⇥Residual⇥Rot[0]⇥Rot[1]⇥…⇥Rot[8]⇥
//!    1⇥0.00000⇥1902.60398⇥-162.96829⇥955.43038⇥158.33492⇥29.46465⇥-7.37670⇥1.35707⇥0.86345⇥…⇥
//!    455⇥2.27000⇥NaN⇥NaN⇥NaN⇥NaN⇥NaN⇥NaN⇥NaN⇥NaN⇥NaN⇥NaN⇥NaN⇥NaN⇥NaN⇥NaN⇥NaN⇥NaN⇥
//!    ```
//!    *Confirmed* from a real QTM 6D export (shiplab/dt_cv, 2020) and the QTM manual: the
//!    key/value block in this order, tab-separated; the header row naming the body only
//!    on its X column; a trailing tab on header and data rows; frames from 1; time with
//!    5 decimals; mm; the angles in degrees with QTM's convention — roll about X, then
//!    pitch about the new Y, then yaw about the new Z (intrinsic, positive by the right
//!    hand rule), so `R = Rx(roll)·Ry(pitch)·Rz(yaw)` (pitch within ±90°); `Rot[0..8]`
//!    the body-to-lab rotation matrix column by column (`Rot[1]` is R₁₀), which the real
//!    file's small-angle values bear out. *Guessed*: the column order of a second body
//!    (its 16 columns follow the first's, headed `StickL X`); the residual's size (mm,
//!    here 0.5–1.5); `NO_OF_CAMERAS` and the `TIME_STAMP` tick value; and the missing-
//!    body cells, written here as `NaN` in all 16 columns (the real file seen had no
//!    gap; QTM 3D exports write missing markers as 0).
//! 4. **OpenSim TRC** markers (tab-delimited; Y up by default):
//!    ```text
//!    PathFileType⇥4⇥(X/Y/Z)⇥french-legato-centre-right.trc
//!    DataRate⇥CameraRate⇥NumFrames⇥NumMarkers⇥Units⇥OrigDataRate⇥OrigDataStartFrame⇥OrigNumFrames
//!    120.00⇥120.00⇥2382⇥4⇥mm⇥120.00⇥1⇥2382
//!    Frame#⇥Time⇥TipR⇥⇥⇥ShoulderR⇥⇥⇥ElbowR⇥⇥⇥WristR
//!    ⇥⇥X1⇥Y1⇥Z1⇥X2⇥Y2⇥Z2⇥X3⇥Y3⇥Z3⇥X4⇥Y4⇥Z4
//!
//!    1⇥0.00000⇥1798.70669⇥811.48847⇥-39.62213⇥2011.87305⇥1487.08954⇥533.52706⇥…
//!    ```
//!    Missing: the marker's three cells empty. `NumFrames` counts the rows written.
//! 5. **Vendor CSV** no importer knows (for a RON profile): UTF-8, `;`-delimited,
//!    **decimal commas**, Y up, positions in the style's unit (2 decimals in mm),
//!    rotations as Euler angles **Z, Y, X intrinsic** (`R = Rz·Ry·Rx`) in **radians**
//!    (5 decimals), frame numbers from 1 at the capture rate (time = (frame − 1)/rate):
//!    ```text
//!    Take "Session 3 – legato" exported 2026-11-30 10:21
//!    Capture rate (Hz);200
//!    Units;mm
//!
//!    Frame;StickR Pos X;StickR Pos Y;StickR Pos Z;StickR Rot Z;StickR Rot Y;StickR Rot X
//!    1;1901,78;956,60;162,58;0,44038;0,28920;1,21921
//!    ```
//!    Line 1 is the title; then `key;value` lines up to a blank line; then the header
//!    and one row per frame. Missing: the body's six cells empty. With both sticks the
//!    left stick's six columns (`StickL …`) come first. The vendor preset drops 0.5 % of
//!    the rows (frame numbers skip).
//!
//! The `title` of a style, when set, is written as an extra first line in every layout
//! (the vendor layout's title is replaced by it): a robustness knob, off by default.

use super::db::{MotionDb, SIDES, UnitEntry};
use super::import::LengthUnit;
use super::ingest::{self, UpAxis};
use super::synth::Performer;
use crate::base::rng::Rng;
use crate::base::ron_file::{self, FileError};
use crate::body::skeleton::{Frames, Joint, Skeleton};
use crate::kit::{Kit, Side};
use crate::score::{Dynamic, Grip, ImpactLocation, PlayingMode};
use glam::{DMat3, DQuat, DVec3, EulerRot};
use serde::{Deserialize, Serialize};
use std::f64::consts::FRAC_PI_2;
use std::fmt::Write as _;
use std::path::Path;

/// How far a shaft marker's centre stands off the stick's axis, m (a 9.5 mm marker on a
/// 12 mm shaft, with its base).
pub const SHAFT_MARKER_RADIUS_M: f64 = 0.012;

/// The truth file's format version.
pub const TRUTH_FORMAT_VERSION: u32 = 1;

/// A file layout to write.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Layout {
    /// OptiTrack Motive CSV 1.23, rigid bodies with quaternions.
    Motive,
    /// Vicon Nexus CSV, `Trajectories` markers.
    Vicon,
    /// Qualisys QTM TSV, 6D bodies.
    Qualisys,
    /// OpenSim TRC markers.
    Trc,
    /// A semicolon-separated vendor CSV with decimal commas and Euler angles.
    Vendor,
}

impl Layout {
    /// Every layout.
    pub const ALL: [Layout; 5] = [
        Layout::Motive,
        Layout::Vicon,
        Layout::Qualisys,
        Layout::Trc,
        Layout::Vendor,
    ];

    /// Whether the layout writes a rigid body per stick (else a tip marker).
    pub fn rigid_body(self) -> bool {
        matches!(self, Layout::Motive | Layout::Qualisys | Layout::Vendor)
    }

    /// The file name for a capture named `stem`.
    pub fn file_name(self, stem: &str) -> String {
        match self {
            Layout::Motive => format!("{stem}-motive.csv"),
            Layout::Vicon => format!("{stem}-vicon.csv"),
            Layout::Qualisys => format!("{stem}_6D.tsv"),
            Layout::Trc => format!("{stem}.trc"),
            Layout::Vendor => format!("{stem}-vendor.csv"),
        }
    }

    /// The frame number written for the first frame.
    pub fn first_frame_number(self) -> usize {
        match self {
            Layout::Motive => 0,
            _ => 1,
        }
    }

    /// Mixed into the seed, so that each layout gets its own gaps and noise.
    fn salt(self) -> u64 {
        Layout::ALL.iter().position(|l| *l == self).unwrap_or(0) as u64
    }

    /// Decimals of a position written in millimetres.
    fn mm_decimals(self) -> usize {
        match self {
            Layout::Motive => 6,
            Layout::Vendor => 2,
            _ => 5,
        }
    }
}

/// Which sticks a file holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum Sticks {
    /// Only the stick of the hand that plays in the take.
    Playing,
    /// Both sticks (the idle one has no impacts).
    Both,
}

/// How a lab writes its captures.
#[derive(Clone, Debug, PartialEq)]
pub struct LabStyle {
    pub layout: Layout,
    /// Sample rate of the file, Hz (the source is resampled: positions interpolated
    /// linearly, rotations by slerp).
    pub rate_hz: f64,
    /// Length unit of the positions (Qualisys always writes mm).
    pub unit: LengthUnit,
    /// The lab's vertical axis.
    pub up: UpAxis,
    /// Turn of the lab frame about the vertical from the performer frame, rad.
    pub yaw_rad: f64,
    /// Position of the performer origin in the (Z-up) lab frame after the turn, m.
    pub translation_m: DVec3,
    /// Distance of a rigid body's origin from the tip, along the stick, m.
    pub origin_from_tip_m: f64,
    /// The marker cluster's rotation in the stick frame (rigid body = stick · cluster).
    pub cluster: DQuat,
    /// Marker layouts: loose markers on each stick (`Stick{L,R}1`, `2`, …) written
    /// instead of a tip marker, at these places in the stick frame (m; +z along the stick
    /// from the tip toward the grip; [`LabStyle::on_the_shaft`] puts them on the shaft);
    /// empty: a tip marker.
    pub stick_markers_m: Vec<[f64; 3]>,
    /// Runs (5–40 frames each, per stick) where the first two loose stick markers have
    /// each other's labels.
    pub marker_swaps: usize,
    pub sticks: Sticks,
    /// An extra first line, if any (the vendor layout's own title is replaced by it).
    pub title: Option<String>,
    /// Fraction of each track's frames missing, 0–0.5.
    pub gap_fraction: f64,
    /// Longest run of missing frames.
    pub max_gap_frames: usize,
    /// Fraction of rows left out of the file, 0–0.5.
    pub dropped_fraction: f64,
    /// Standard deviation of the position noise per axis, m.
    pub position_noise_m: f64,
    /// Standard deviation of the rotation noise per axis, rad.
    pub rotation_noise_rad: f64,
    /// Seed of every random choice.
    pub seed: u64,
}

impl Default for LabStyle {
    /// A typical lab: [`LabStyle::typical`] of Motive.
    fn default() -> Self {
        LabStyle::typical(Layout::Motive)
    }
}

impl LabStyle {
    /// The usual settings of a lab writing `layout`: Motive 240 Hz Y-up mm; Vicon and
    /// Qualisys 200 Hz Z-up mm; TRC 120 Hz Y-up mm; vendor 200 Hz Y-up mm with 0.5 %
    /// dropped rows. All: yaw 37°, translation (1.84, −0.62, 0.05) m, rigid-body origin
    /// 0.27 m from the tip, cluster Rx(90°)·Rz(20°), the playing stick only, 2 % gaps in
    /// runs of up to 20 frames, noise 1 mm and 0.3°, seed 2026.
    pub fn typical(layout: Layout) -> LabStyle {
        let (rate_hz, up, dropped_fraction) = match layout {
            Layout::Motive => (240.0, UpAxis::Y, 0.0),
            Layout::Vicon | Layout::Qualisys => (200.0, UpAxis::Z, 0.0),
            Layout::Trc => (120.0, UpAxis::Y, 0.0),
            Layout::Vendor => (200.0, UpAxis::Y, 0.005),
        };
        LabStyle {
            layout,
            rate_hz,
            unit: LengthUnit::Millimetre,
            up,
            yaw_rad: 37f64.to_radians(),
            translation_m: DVec3::new(1.84, -0.62, 0.05),
            origin_from_tip_m: 0.27,
            cluster: DQuat::from_rotation_x(FRAC_PI_2) * DQuat::from_rotation_z(20f64.to_radians()),
            stick_markers_m: Vec::new(),
            marker_swaps: 0,
            sticks: Sticks::Playing,
            title: None,
            gap_fraction: 0.02,
            max_gap_frames: 20,
            dropped_fraction,
            position_noise_m: 0.001,
            rotation_noise_rad: 0.3f64.to_radians(),
            seed: 2026,
        }
    }

    /// Markers on the shaft at these distances from the tip (m), each
    /// [`SHAFT_MARKER_RADIUS_M`] off the axis at 120° from the last, for
    /// [`LabStyle::stick_markers_m`].
    pub fn on_the_shaft(along_m: &[f64]) -> Vec<[f64; 3]> {
        along_m
            .iter()
            .enumerate()
            .map(|(k, d)| {
                let angle = k as f64 * std::f64::consts::TAU / 3.0;
                let r = SHAFT_MARKER_RADIUS_M;
                [r * angle.cos(), r * angle.sin(), *d]
            })
            .collect()
    }

    /// The same style without noise, gaps, dropped rows or swapped markers.
    pub fn clean(&self) -> LabStyle {
        LabStyle {
            gap_fraction: 0.0,
            dropped_fraction: 0.0,
            position_noise_m: 0.0,
            rotation_noise_rad: 0.0,
            marker_swaps: 0,
            ..self.clone()
        }
    }

    /// The lab transform of this style.
    pub fn transform(&self) -> LabTransform {
        LabTransform {
            yaw_rad: self.yaw_rad,
            translation_m: self.translation_m.to_array(),
        }
    }

    /// The unit positions are written in (Qualisys: always mm).
    fn written_unit(&self) -> LengthUnit {
        match self.layout {
            Layout::Qualisys => LengthUnit::Millimetre,
            _ => self.unit,
        }
    }

    fn check(&self) -> Result<(), CorpusError> {
        let bad = |what: &str| Err(CorpusError::Style(what.to_string()));
        if !(self.rate_hz.is_finite() && self.rate_hz > 0.0) {
            return bad("the rate must be above 0 Hz");
        }
        if !(0.0..=0.5).contains(&self.gap_fraction)
            || !(0.0..=0.5).contains(&self.dropped_fraction)
        {
            return bad("gap and dropped fractions must be within 0–0.5");
        }
        if self.max_gap_frames == 0 {
            return bad("the longest gap must be at least 1 frame");
        }
        if !(self.position_noise_m >= 0.0 && self.rotation_noise_rad >= 0.0) {
            return bad("noise must not be negative");
        }
        if !(self.origin_from_tip_m.is_finite() && self.yaw_rad.is_finite()) {
            return bad("the rigid-body origin and the yaw must be finite");
        }
        Ok(())
    }
}

/// Performer frame → lab frame: turn about the vertical by `yaw_rad`, shift by
/// `translation_m`, then the lab's vertical put where it is (Y-up labs: (x, y, z) ↦
/// (x, z, −y); [`UpAxis::from_performer`]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct LabTransform {
    /// Turn about the vertical, rad (counter-clockwise seen from above).
    pub yaw_rad: f64,
    /// Shift after the turn, in the Z-up lab axes, m.
    pub translation_m: [f64; 3],
}

impl LabTransform {
    /// The lab rotation (applied to performer-frame rotations and directions).
    pub fn rotation(&self, up: UpAxis) -> DQuat {
        up.rotation().conjugate() * DQuat::from_rotation_z(self.yaw_rad)
    }

    /// A performer-frame point in the lab frame, m.
    pub fn to_lab(&self, p: DVec3, up: UpAxis) -> DVec3 {
        let z_up = DQuat::from_rotation_z(self.yaw_rad) * p + DVec3::from(self.translation_m);
        up.from_performer(z_up)
    }

    /// A lab-frame point back in the performer frame, m.
    pub fn to_performer(&self, p: DVec3, up: UpAxis) -> DVec3 {
        let z_up = ingest::to_performer(p, up) - DVec3::from(self.translation_m);
        DQuat::from_rotation_z(-self.yaw_rad) * z_up
    }
}

/// One generated capture: its files and what is known about them.
#[derive(Clone, Debug, PartialEq)]
pub struct GeneratedCapture {
    /// File name and content of each file.
    pub files: Vec<(String, Vec<u8>)>,
    pub truth: Truth,
}

impl GeneratedCapture {
    /// The capture with `suffix` put before each file name's extension (in the truth
    /// too), e.g. to write two styles of one layout into one corpus.
    pub fn with_suffix(mut self, suffix: &str) -> GeneratedCapture {
        let rename = |name: &str| match name.rsplit_once('.') {
            Some((stem, ext)) => format!("{stem}{suffix}.{ext}"),
            None => format!("{name}{suffix}"),
        };
        for (name, _) in &mut self.files {
            *name = rename(name);
        }
        for name in &mut self.truth.files {
            *name = rename(name);
        }
        self
    }
}

/// The ground truth of one capture.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Truth {
    /// The capture's files, relative to the corpus folder.
    pub files: Vec<String>,
    pub layout: Layout,
    /// Sample rate of the files, Hz.
    pub rate_hz: f64,
    /// Frames of the capture, counting dropped ones.
    pub frames: usize,
    /// The number written for frame 0 (time 0 s).
    pub first_frame_number: usize,
    /// Frames (0-based) whose rows were left out.
    pub dropped_frames: Vec<usize>,
    /// Length unit of the positions: "mm", "cm" or "m".
    pub unit: String,
    /// The lab's vertical axis: "Y" or "Z".
    pub up_axis: String,
    pub lab: LabTransform,
    pub noise: Noise,
    pub source: SourceLabels,
    /// The stick tracks (a rigid body or a tip marker each).
    pub tracks: Vec<TrackTruth>,
    /// Labels of the other tracks (arm markers, cluster markers).
    pub other_labels: Vec<String>,
}

/// The noise added.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Noise {
    /// Standard deviation per axis of positions, m.
    pub position_m: f64,
    /// Standard deviation per axis of rotations, rad.
    pub rotation_rad: f64,
}

/// One stick track.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrackTruth {
    /// The label as written in the file.
    pub label: String,
    pub hand: Side,
    /// The stick's impacts.
    pub impacts: Vec<Impact>,
    /// For a rigid body: the tip in the body frame, m (`tip = origin + R·offset`);
    /// `None` for a tip marker.
    pub tip_offset_body_m: Option<[f64; 3]>,
    /// For a stick of loose markers (the label joins them with `+`): their places in the
    /// stick frame, m (+z along the stick from the tip toward the grip).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stick_markers_m: Option<Vec<[f64; 3]>>,
    /// Runs of missing frames: [first frame (0-based), length].
    pub gaps: Vec<[usize; 2]>,
}

/// One impact.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Impact {
    /// Time after frame 0, s.
    pub time_s: f64,
    /// The dynamic of the source stroke, if known.
    pub dynamic: Option<Dynamic>,
}

/// What the source take was.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SourceLabels {
    /// Where it came from.
    pub source: String,
    /// Index of the drum played, in the standard kit.
    pub drum: usize,
    pub drum_name: String,
    pub location: Option<ImpactLocation>,
    pub mode: Option<PlayingMode>,
    pub grip: Option<Grip>,
}

/// `truth.ron`: the truth of every capture of a corpus folder.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename = "LabCorpus", deny_unknown_fields)]
pub struct CorpusTruth {
    pub version: u32,
    pub captures: Vec<Truth>,
}

/// Why a capture could not be generated.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum CorpusError {
    #[error("take {take} is not in the database (it has {takes} takes)")]
    NoSuchTake { take: usize, takes: usize },
    #[error("take {0} has no motion units, so no known impacts")]
    NoUnits(usize),
    #[error("take {0} has no joint rotations, so the sticks' orientation is unknown")]
    NoJoints(usize),
    #[error(
        "take {take}: forward kinematics of the stored joints puts a tip {error_mm:.2} mm \
         from the stored one (the database was not made with the synthetic performer's \
         skeleton)"
    )]
    SkeletonMismatch { take: usize, error_mm: f64 },
    #[error("{file}: {place}: {message}")]
    Source {
        file: String,
        place: String,
        message: String,
    },
    #[error("lab style: {0}")]
    Style(String),
}

/// A capture of database take `take` written as `style` says.
pub fn generate(
    db: &MotionDb,
    take: usize,
    style: &LabStyle,
) -> Result<GeneratedCapture, CorpusError> {
    style.check()?;
    let source = synthetic_take(db, take, style)?;
    let salt = (take as u64 + 1) * 8 + style.layout.salt();
    Ok(capture(&source, style, Rng::new(style.seed).fork(salt)))
}

/// A capture of `strokes` repetitions of the real TrajOptDrums stroke (the contents of
/// `JointCenters_XPose_cm.csv` and `JointCenters_YPose_cm.csv`), written as `style`
/// says; rigid-body layouts get the stick frame from the finger-to-bead direction and
/// the stroke plane.
///
/// Stitching: impact k is at T_k = T_{k−1} + P_k (P_k the file's 100 bpm period with a
/// seeded ±2 % variation; the file starts 0.05 s after a virtual impact T_0 and ends half
/// a period after T_N). Between T_{k−1} and T_k the take follows the real rebound after
/// the real impact (time since T_{k−1}) and cross-fades (smoothstep, 12–37 ms after the
/// impact, before the recorded rebound ends) into the real lift-and-descent, played at
/// the pace that makes it reach its impact exactly at T_k. Each stroke's heights are
/// scaled about the impact height by a seeded factor within ±10 % (the arm markers too,
/// so their segment lengths vary by a few percent). The impacts are the bead minima:
/// the real minimum lies on the real samples' Catmull-Rom interpolant, which the take
/// follows on both sides of each T_k, so the bead is lowest exactly at every T_k.
pub fn from_trajoptdrums(
    x_csv: &str,
    y_csv: &str,
    style: &LabStyle,
    strokes: usize,
) -> Result<GeneratedCapture, CorpusError> {
    style.check()?;
    if strokes == 0 {
        return Err(CorpusError::Style("at least one stroke is needed".into()));
    }
    let stroke = RealStroke::parse(x_csv, y_csv)?;
    let mut rng = Rng::new(style.seed).fork(0x7A0D);
    let source = stroke.take(strokes, style.rate_hz, &mut rng);
    let salt = 0x7A0E * 8 + style.layout.salt();
    Ok(capture(&source, style, Rng::new(style.seed).fork(salt)))
}

/// Write every capture's files into `dir` (created if needed) and their truth as
/// `dir/truth.ron`.
///
/// Two captures writing the same file name are an error (see
/// [`GeneratedCapture::with_suffix`]).
pub fn write_all(dir: &Path, captures: &[GeneratedCapture]) -> Result<(), FileError> {
    let mut names: Vec<&str> = captures
        .iter()
        .flat_map(|c| c.files.iter().map(|(n, _)| n.as_str()))
        .collect();
    names.sort_unstable();
    if let Some(w) = names.windows(2).find(|w| w[0] == w[1]) {
        return Err(FileError::invalid(
            &dir.join(w[0]),
            "file name",
            "two captures write this file; give one a suffix",
        ));
    }
    std::fs::create_dir_all(dir).map_err(|e| FileError::io(dir, e))?;
    for (name, bytes) in captures.iter().flat_map(|c| &c.files) {
        ron_file::write_atomic(&dir.join(name), bytes)?;
    }
    let truth = CorpusTruth {
        version: TRUTH_FORMAT_VERSION,
        captures: captures.iter().map(|c| c.truth.clone()).collect(),
    };
    ron_file::save(&dir.join("truth.ron"), &truth)
}

mod lab;
mod synthetic;
mod trajopt;
mod writers;

use lab::*;
use synthetic::*;
use trajopt::*;
use writers::*;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mocap::import::{motive as motive_import, vicon as vicon_import};
    use std::sync::OnceLock;

    fn shipped() -> &'static MotionDb {
        static DB: OnceLock<MotionDb> = OnceLock::new();
        DB.get_or_init(|| {
            MotionDb::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("mocap")).unwrap()
        })
    }

    fn fixture(name: &str) -> String {
        std::fs::read_to_string(
            Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("tests/fixtures/trajoptdrums")
                .join(name),
        )
        .unwrap()
    }

    fn real_stroke() -> RealStroke {
        RealStroke::parse(
            &fixture("JointCenters_XPose_cm.csv"),
            &fixture("JointCenters_YPose_cm.csv"),
        )
        .unwrap()
    }

    fn text(c: &GeneratedCapture) -> &str {
        std::str::from_utf8(&c.files[0].1).unwrap()
    }

    /// The take of the shipped database played by the right hand, French legato centre.
    fn right_take() -> usize {
        shipped()
            .index
            .takes
            .iter()
            .position(|t| t.file.ends_with("french-legato-centre-right.tmot"))
            .unwrap()
    }

    /// The synthetic database was made with `Performer::new()`'s skeleton: forward
    /// kinematics of every take's stored joints reproduces its stored tips to < 1 mm,
    /// and each take has units of one hand only.
    #[test]
    fn fk_of_stored_joints_reproduces_stored_tips() {
        let db = shipped();
        let skeleton = Performer::new().skeleton;
        assert_eq!(skeleton, Skeleton::new(1.75, 0.37));
        let mut worst: f64 = 0.0;
        for (i, data) in db.takes.iter().enumerate() {
            let frames: Vec<Frames> = data
                .joints
                .as_ref()
                .unwrap()
                .iter()
                .map(|p| skeleton.forward(p))
                .collect();
            worst = worst.max(fk_error_m(&frames, &data.tips));
            let hands: Vec<Side> = db
                .index
                .units
                .iter()
                .filter(|u| u.take == i)
                .map(|u| u.hand)
                .collect();
            assert!(!hands.is_empty() && hands.iter().all(|h| *h == hands[0]));
        }
        assert!(worst < FK_TOLERANCE_M, "worst {:.4} mm", worst * 1e3);
        assert!(worst < 2e-5, "worst {:.4} mm", worst * 1e3);
    }

    /// The rigid body's origin plus its rotation times the tip offset is the stick tip
    /// (to 1e-9 m before noise), for both stick-frame sources.
    #[test]
    fn rigid_body_offset_gives_the_tip() {
        let style = LabStyle::typical(Layout::Qualisys).clean();
        let db = shipped();
        let take = synthetic_take(db, right_take(), &style).unwrap();
        let real = real_stroke().take(3, 200.0, &mut Rng::new(1));
        for take in [take, real] {
            let (tracks, truth) = lab_tracks(&take, &style);
            let offset = DVec3::from(truth[0].tip_offset_body_m.unwrap());
            assert!((offset.length() - style.origin_from_tip_m).abs() < 1e-12);
            let body = &tracks[0];
            let lab = style.transform();
            for (f, tip) in take.sides[0].tip.iter().enumerate().step_by(7) {
                let p = body.positions[f].unwrap() + body.rotations[f].unwrap() * offset;
                assert!(lab.to_performer(p, style.up).distance(*tip) < 1e-9);
            }
        }
    }

    /// Performer → lab → performer is the identity in both up axes, and the rotation
    /// maps directions as the point map does.
    #[test]
    fn lab_transform_round_trips() {
        let lab = LabStyle::default().transform();
        let p = DVec3::new(0.3, 0.5, 0.9);
        for up in [UpAxis::Y, UpAxis::Z] {
            assert!(lab.to_performer(lab.to_lab(p, up), up).distance(p) < 1e-12);
            let d = lab.to_lab(p, up) - lab.to_lab(DVec3::ZERO, up);
            assert!(d.distance(lab.rotation(up) * p) < 1e-12);
        }
        let y_up = lab.to_lab(DVec3::Z, UpAxis::Y) - lab.to_lab(DVec3::ZERO, UpAxis::Y);
        assert!(y_up.distance(DVec3::Y) < 1e-12);
    }

    /// The Euler conventions written: QTM's R = Rx(roll)·Ry(pitch)·Rz(yaw) and the
    /// vendor's R = Rz·Ry·Rx.
    #[test]
    fn euler_conventions() {
        let q = DQuat::from_rotation_z(0.7)
            * DQuat::from_rotation_x(-1.1)
            * DQuat::from_rotation_y(0.4);
        let [r, p, y] = qualisys_angles_deg(q).map(f64::to_radians);
        let back =
            DQuat::from_rotation_x(r) * DQuat::from_rotation_y(p) * DQuat::from_rotation_z(y);
        assert!(back.angle_between(q) < 1e-7);
        let [z, y, x] = vendor_angles_rad(q);
        let back =
            DQuat::from_rotation_z(z) * DQuat::from_rotation_y(y) * DQuat::from_rotation_x(x);
        assert!(back.angle_between(q) < 1e-7);
    }

    /// Motive: read back by our importer with the rate, the frame count, the tip back in
    /// the performer frame (from the body and the truth's offset) and the gaps as gaps.
    #[test]
    fn motive_round_trip() {
        let style = LabStyle {
            position_noise_m: 0.0,
            rotation_noise_rad: 0.0,
            ..LabStyle::default()
        };
        let cap = generate(shipped(), right_take(), &style).unwrap();
        let t = &cap.truth;
        let take = motive_import::read(Path::new(&t.files[0]), &cap.files[0].1, None).unwrap();
        assert_eq!((take.rate_hz, take.frames), (240.0, t.frames));
        assert_eq!(take.file_unit, "mm");
        let body = take.track("StickR").unwrap();
        assert_eq!(take.labels().len(), 4);
        let offset = DVec3::from(t.tracks[0].tip_offset_body_m.unwrap());
        let clean = synthetic_take(shipped(), right_take(), &style).unwrap();
        let mut missing = 0;
        for f in 0..take.frames {
            match (body.positions[f], body.rotations[f]) {
                (Some(p), Some(q)) => {
                    let tip = t.lab.to_performer(p + q * offset, UpAxis::Y);
                    assert!(tip.distance(clean.sides[0].tip[f]) < 1e-5, "frame {f}");
                }
                (None, None) => missing += 1,
                _ => panic!("half a sample at {f}"),
            }
        }
        let gaps: usize = t.tracks[0].gaps.iter().map(|g| g[1]).sum();
        assert_eq!(missing, gaps);
        let marker = take.track("StickR:Marker2").unwrap();
        for (m, b) in marker.positions.iter().zip(&body.positions) {
            assert_eq!(m.is_some(), b.is_some());
        }
        assert!((missing as f64 / t.frames as f64 - 0.02).abs() < 0.002);
        assert!(t.tracks[0].gaps.iter().all(|g| (1..=20).contains(&g[1])));
        let units = shipped()
            .index
            .units
            .iter()
            .filter(|u| u.take == right_take());
        assert_eq!(t.tracks[0].impacts.len(), units.count() + 2);
        assert_eq!(t.tracks[0].hand, Side::Right);
    }

    /// Vicon: read back by our importer; noisy tips stay within 5 σ of the clean ones and
    /// their spread is about the 1 mm asked for.
    #[test]
    fn vicon_round_trip_with_noise() {
        let style = LabStyle::typical(Layout::Vicon);
        let cap = generate(shipped(), right_take(), &style).unwrap();
        let t = &cap.truth;
        let take = vicon_import::read(Path::new("v.csv"), &cap.files[0].1, None).unwrap();
        assert_eq!((take.rate_hz, take.frames), (200.0, t.frames));
        assert_eq!(t.tracks[0].label, "Player:TipR");
        assert_eq!(t.other_labels.len(), 3);
        let tip = take.track("TipR").unwrap();
        let clean = synthetic_take(shipped(), right_take(), &style).unwrap();
        let errors: Vec<f64> = tip
            .positions
            .iter()
            .zip(&clean.sides[0].tip)
            .filter_map(|(p, c)| p.map(|p| t.lab.to_performer(p, UpAxis::Z) - *c))
            .map(|e| e.x)
            .collect();
        let sd = (errors.iter().map(|e| e * e).sum::<f64>() / errors.len() as f64).sqrt();
        assert!((sd - 0.001).abs() < 1e-4, "sd {sd}");
        assert!(errors.iter().all(|e| e.abs() < 0.005));
        assert_eq!(
            errors.len(),
            t.frames - t.tracks[0].gaps.iter().map(|g| g[1]).sum::<usize>()
        );
    }

    /// Cells of data rows of a delimited text after its first `skip` lines.
    fn data_rows(text: &str, skip: usize, sep: char) -> Vec<Vec<&str>> {
        text.lines()
            .skip(skip)
            .map(|l| l.split(sep).collect())
            .collect()
    }

    /// Qualisys 6D: the metadata block, the header, one row per frame with 16 cells per
    /// body (NaN where missing), and the rotation matrix agreeing with the angles.
    #[test]
    fn qualisys_layout() {
        let style = LabStyle {
            sticks: Sticks::Both,
            ..LabStyle::typical(Layout::Qualisys)
        };
        let cap = generate(shipped(), right_take(), &style).unwrap();
        let text = text(&cap);
        let lines: Vec<&str> = text.lines().collect();
        let keys: Vec<&str> = lines[..10]
            .iter()
            .map(|l| l.split('\t').next().unwrap())
            .collect();
        assert_eq!(
            keys,
            [
                "NO_OF_FRAMES",
                "NO_OF_CAMERAS",
                "NO_OF_BODIES",
                "FREQUENCY",
                "NO_OF_ANALOG",
                "ANALOG_FREQUENCY",
                "DESCRIPTION",
                "TIME_STAMP",
                "DATA_INCLUDED",
                "BODY_NAMES"
            ]
        );
        assert_eq!(lines[0], format!("NO_OF_FRAMES\t{}", cap.truth.frames));
        assert_eq!(lines[2], "NO_OF_BODIES\t2");
        assert_eq!(lines[9], "BODY_NAMES\tStickL\tStickR");
        assert!(
            lines[10]
                .starts_with("Frame\tTime\tStickL X\tY\tZ\tRoll\tPitch\tYaw\tResidual\tRot[0]")
        );
        let rows = data_rows(text, 11, '\t');
        assert_eq!(rows.len(), cap.truth.frames);
        assert!(
            rows.iter()
                .all(|r| r.len() == 2 + 32 + 1 && r[34].is_empty())
        );
        let nan_rows = rows.iter().filter(|r| r[2] == "NaN").count();
        let gaps: usize = cap.truth.tracks[0].gaps.iter().map(|g| g[1]).sum();
        assert_eq!(nan_rows, gaps);
        let row = rows.iter().find(|r| r[2] != "NaN").unwrap();
        let v: Vec<f64> = row[2..18].iter().map(|c| c.parse().unwrap()).collect();
        let [r, p, y] = [v[3], v[4], v[5]].map(f64::to_radians);
        let m = DMat3::from_quat(
            DQuat::from_rotation_x(r) * DQuat::from_rotation_y(p) * DQuat::from_rotation_z(y),
        );
        for (a, b) in m.to_cols_array().iter().zip(&v[7..16]) {
            assert!((a - b).abs() < 2e-5);
        }
        assert_eq!(rows[0][0..2], ["1", "0.00000"]);
    }

    /// TRC: the key and value rows, the marker and axis rows, the blank line, and one
    /// data row per frame with empty cells in gaps.
    #[test]
    fn trc_layout() {
        let style = LabStyle::typical(Layout::Trc);
        let cap = generate(shipped(), right_take(), &style).unwrap();
        let text = text(&cap);
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(
            lines[0],
            "PathFileType\t4\t(X/Y/Z)\tfrench-legato-centre-right.trc"
        );
        assert_eq!(lines[1].split('\t').count(), 8);
        let values: Vec<&str> = lines[2].split('\t').collect();
        assert_eq!(values[2], cap.truth.frames.to_string());
        assert_eq!((values[3], values[4]), ("4", "mm"));
        assert_eq!(
            lines[3],
            "Frame#\tTime\tTipR\t\t\tShoulderR\t\t\tElbowR\t\t\tWristR"
        );
        assert!(lines[4].starts_with("\t\tX1\tY1\tZ1\tX2"));
        assert!(lines[5].is_empty());
        let rows = data_rows(text, 6, '\t');
        assert_eq!(rows.len(), cap.truth.frames);
        assert!(rows.iter().all(|r| r.len() == 14));
        let empty = rows.iter().filter(|r| r[2].is_empty()).count();
        assert_eq!(
            empty,
            cap.truth.tracks[0].gaps.iter().map(|g| g[1]).sum::<usize>()
        );
        assert_eq!(rows[1][..2], ["2", "0.00833"]);
    }

    /// The vendor CSV: title, metadata, blank line, header; decimal commas; frame
    /// numbers from 1 that skip the dropped frames; empty cells in gaps; a Y-up lab.
    #[test]
    fn vendor_layout() {
        let style = LabStyle::typical(Layout::Vendor);
        let cap = generate(shipped(), right_take(), &style).unwrap();
        let t = &cap.truth;
        let text = text(&cap);
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(
            lines[0],
            "Take \"Session 3 – legato\" exported 2026-11-30 10:21"
        );
        assert_eq!(lines[1..4], ["Capture rate (Hz);200", "Units;mm", ""]);
        assert_eq!(
            lines[4],
            "Frame;StickR Pos X;StickR Pos Y;StickR Pos Z;StickR Rot Z;StickR Rot Y;StickR Rot X"
        );
        let rows = data_rows(text, 5, ';');
        assert_eq!(rows.len() + t.dropped_frames.len(), t.frames);
        assert!(!t.dropped_frames.is_empty());
        let numbers: Vec<usize> = rows.iter().map(|r| r[0].parse().unwrap()).collect();
        let kept: Vec<usize> = (0..t.frames)
            .filter(|f| !t.dropped_frames.contains(f))
            .map(|f| f + 1)
            .collect();
        assert_eq!(numbers, kept);
        let full: Vec<&Vec<&str>> = rows.iter().filter(|r| !r[1].is_empty()).collect();
        assert!(full.iter().all(|r| r.len() == 7 && r[1..].iter().all(|c| c.contains(',') && !c.contains('.'))));
        let parse = |c: &str| c.replace(',', ".").parse::<f64>().unwrap();
        let heights: Vec<f64> = full.iter().map(|r| parse(r[2])).collect();
        let mean = heights.iter().sum::<f64>() / heights.len() as f64;
        assert!((700.0..1500.0).contains(&mean), "mean height {mean} mm");
        assert!(rows.iter().any(|r| r[1..].iter().all(|c| c.is_empty())));
    }

    /// The real stroke: Y is vertical (the elbow hangs about a forearm's length below
    /// the shoulder), and the bead lifts, falls fast and is lowest at the impact, then
    /// rebounds.
    #[test]
    fn the_real_stroke_is_a_stroke() {
        let s = real_stroke();
        assert_eq!(s.names, ["Shoulder", "Elbow", "Wrist", "Finger"]);
        assert!((s.rate_hz - 240.0).abs() < 1e-6 && (s.period_s - 0.6).abs() < 1e-12);
        let elbow_up = s.up[1].iter().sum::<f64>() / s.up[1].len() as f64;
        let elbow_forward = s.forward[1].iter().map(|x| x.abs()).fold(0.0, f64::max);
        assert!(elbow_up < -0.2 && elbow_forward < 0.1);
        let bead = &s.up[s.bead()];
        let top = (0..bead.len())
            .max_by(|&a, &b| bead[a].total_cmp(&bead[b]))
            .unwrap();
        let low = (0..bead.len())
            .min_by(|&a, &b| bead[a].total_cmp(&bead[b]))
            .unwrap();
        assert!(bead[top] - bead[0] > 0.4 && top < low);
        let fastest = (top..low)
            .map(|i| (bead[i] - bead[i + 1]) * s.rate_hz)
            .fold(0.0, f64::max);
        assert!(fastest > 5.0, "descends at {fastest} m/s");
        assert!(low + 5 < bead.len() && bead[low + 5] > bead[low] + 0.05);
        assert!((s.impact_s - low as f64 / s.rate_hz).abs() < 1.0 / s.rate_hz);
    }

    /// The TrajOptDrums take, written as TRC and read back minimally: one bead minimum
    /// per stroke, within a sample of each true impact, on the drum's playing spot, and
    /// the impacts about a 100 bpm period apart.
    #[test]
    fn trajoptdrums_take_impacts() {
        let style = LabStyle::typical(Layout::Trc).clean();
        let strokes = 6;
        let cap = from_trajoptdrums(
            &fixture("JointCenters_XPose_cm.csv"),
            &fixture("JointCenters_YPose_cm.csv"),
            &style,
            strokes,
        )
        .unwrap();
        let t = &cap.truth;
        let impacts: Vec<f64> = t.tracks[0].impacts.iter().map(|i| i.time_s).collect();
        assert_eq!(impacts.len(), strokes);
        for w in impacts.windows(2) {
            assert!((w[1] - w[0] - 0.6).abs() < 0.03, "spacing {}", w[1] - w[0]);
        }
        let rows = data_rows(text(&cap), 6, '\t');
        let bead: Vec<DVec3> = rows
            .iter()
            .map(|r| {
                let v: Vec<f64> = r[2..5]
                    .iter()
                    .map(|c| c.parse::<f64>().unwrap() / 1000.0)
                    .collect();
                t.lab.to_performer(DVec3::new(v[0], v[1], v[2]), UpAxis::Y)
            })
            .collect();
        let minima: Vec<usize> = (1..bead.len() - 1)
            .filter(|&i| bead[i].z < bead[i - 1].z && bead[i].z <= bead[i + 1].z)
            .filter(|&i| bead[i].z < bead.iter().map(|p| p.z).fold(f64::MAX, f64::min) + 0.02)
            .collect();
        assert_eq!(minima.len(), strokes, "{minima:?}");
        let drum = &Kit::standard().drums[t.source.drum];
        for (m, time) in minima.iter().zip(&impacts) {
            assert!((*m as f64 / 120.0 - time).abs() <= 1.0 / 120.0);
            let above = bead[*m].z - drum.placement.head_height_m;
            assert!((0.0..0.015).contains(&above), "{above}");
        }
        assert_eq!(t.source.drum_name, "26-inch");
        let range =
            bead.iter().map(|p| p.z).fold(f64::MIN, f64::max) - drum.placement.head_height_m;
        assert!((0.45..0.65).contains(&range), "lift {range}");
    }

    /// Every layout generates for both sources, deterministically; `write_all` writes the
    /// files and a truth.ron that reads back.
    #[test]
    fn every_layout_and_write_all() {
        let mut captures = Vec::new();
        for layout in Layout::ALL {
            let style = LabStyle::typical(layout);
            let a = generate(shipped(), 7, &style).unwrap();
            assert_eq!(a, generate(shipped(), 7, &style).unwrap());
            captures.push(a);
            captures.push(
                from_trajoptdrums(
                    &fixture("JointCenters_XPose_cm.csv"),
                    &fixture("JointCenters_YPose_cm.csv"),
                    &style,
                    4,
                )
                .unwrap(),
            );
        }
        let dir = tempfile::tempdir().unwrap();
        write_all(dir.path(), &captures).unwrap();
        let text = std::fs::read_to_string(dir.path().join("truth.ron")).unwrap();
        let back: CorpusTruth = ron_file::parse(&dir.path().join("truth.ron"), &text).unwrap();
        assert_eq!(back.captures.len(), 10);
        assert_eq!(back.captures[0], captures[0].truth);
        for c in &captures {
            assert!(dir.path().join(&c.truth.files[0]).is_file());
        }
        let again = captures[0].clone();
        assert!(write_all(dir.path(), &[captures[0].clone(), again.clone()]).is_err());
        let renamed = again.with_suffix("-2");
        assert_eq!(
            renamed.truth.files,
            ["french-tenuto-centre-right-motive-2.csv"]
        );
        assert_eq!(renamed.files[0].0, renamed.truth.files[0]);
        assert!(matches!(
            generate(shipped(), 999, &LabStyle::default()),
            Err(CorpusError::NoSuchTake { take: 999, .. })
        ));
    }
}
