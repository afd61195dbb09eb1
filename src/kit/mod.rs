//! The timpani kit: drums (size, tuning and range, membrane, mode table, placement around
//! the player) and mallets, read from and written to strict RON files (`kits/*.ron`).
//!
//! **Performer frame** (used by every position in timpanist): right-handed, metres, origin
//! on the floor at the centre of the player's stance; +x to the player's right, +y forward
//! (away from the player), +z up.

pub mod validate;

pub use crate::base::gesture::Side;
use crate::base::pitch::Pitch;
use crate::base::ron_file::{self, FileError};
use glam::DVec3;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The kit file format this timpanist writes and the newest it reads.
pub const KIT_FORMAT_VERSION: u32 = 1;

/// Kits compiled into the program, by name: usable from any score as `kit: "standard"`.
pub const BUNDLED_KITS: &[(&str, &str)] = &[
    ("standard", include_str!("../../kits/standard.ron")),
    ("pair", include_str!("../../kits/pair.ron")),
    ("solo", include_str!("../../kits/solo.ron")),
];

/// A set of drums and mallets.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename = "Kit", deny_unknown_fields)]
pub struct Kit {
    /// File format version (currently 1).
    pub version: u32,
    /// Display name.
    pub name: String,
    /// The drums, conventionally from the lowest to the highest.
    pub drums: Vec<Drum>,
    /// The mallets; the first is the default.
    pub mallets: Vec<Mallet>,
}

/// One kettledrum.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Drum {
    /// Display name, e.g. "26-inch".
    pub name: String,
    /// Head diameter, m.
    pub diameter_m: f64,
    /// The pitch of the principal (1,1) mode when the kit is set up.
    pub tuning: Pitch,
    /// Lowest pitch the pedal reaches.
    pub lowest: Pitch,
    /// Highest pitch the pedal reaches.
    pub highest: Pitch,
    /// Physical parameters of the head at the kit tuning.
    pub membrane: Membrane,
    /// Measured modes: frequency ratios to the (1,1) mode, decay and radiation weight.
    pub modes: Vec<Mode>,
    /// Where the head is, in the performer frame.
    pub placement: Placement,
    /// The hand that plays this drum by default (sticking, seed 003 §3.4.2).
    pub preferred_hand: Side,
    /// Shortest comfortable time between two strokes of one hand on this drum, s
    /// (`minTimeGap` of seed 003 Alg. 3.1).
    pub min_same_hand_gap_s: f64,
    /// Volume of air the kettle encloses under the head, m³: its spring raises the
    /// axisymmetric modes (none: a head open below, as kits written before it read).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub kettle_volume_m3: Option<f64>,
}

/// The drum head as a membrane.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Membrane {
    /// Tension per unit length at the kit tuning, N/m.
    pub tension_n_per_m: f64,
    /// Mass per unit area, kg/m².
    pub areal_density_kg_per_m2: f64,
    /// Factor (0–1] by which air loading lowers the (1,1) mode below the in-vacuo
    /// membrane: f11 = air_loading · j11/(2πa) · √(T/σ).
    pub air_loading: f64,
}

/// One vibration mode of the head.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Mode {
    /// Nodal diameters.
    pub m: u32,
    /// Nodal circles (counting the rim), from 1.
    pub n: u32,
    /// Frequency as a ratio to the (1,1) mode.
    pub ratio: f64,
    /// Time to decay by 60 dB, s.
    pub decay_s: f64,
    /// Relative radiated amplitude (the (1,1) mode is 1).
    pub gain: f64,
}

/// Where a drum stands.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Placement {
    /// Head centre, to the player's right, m.
    pub x_m: f64,
    /// Head centre, forward of the player, m.
    pub y_m: f64,
    /// Height of the head above the floor, m.
    pub head_height_m: f64,
}

/// A pair of timpani mallets.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Mallet {
    /// Display name, e.g. "general".
    pub name: String,
    /// Mass of one mallet, kg.
    pub mass_kg: f64,
    /// Stick length from grip end to the centre of the head, m.
    pub length_m: f64,
    /// Hertz felt stiffness k in F = k·c^α, N/m^α.
    pub felt_stiffness: f64,
    /// Hertz contact exponent α (felt: about 2–3).
    pub contact_exponent: f64,
    /// Radius of the felt head, m.
    pub head_radius_m: f64,
    /// Hunt–Crossley loss λ of the felt in F = k·c^α·(1 + λ·ċ), s/m (0: elastic; kits
    /// written before it existed read as elastic).
    #[serde(default)]
    pub felt_loss_s_per_m: f64,
}

/// Zero j11 of the Bessel function J1: the (1,1) mode of an ideal circular membrane.
pub const BESSEL_J11: f64 = 3.831_705_970_207_512;

impl Drum {
    /// Head radius, m.
    pub fn radius_m(&self) -> f64 {
        self.diameter_m / 2.0
    }

    /// Whether the pedal reaches `pitch`.
    pub fn in_range(&self, pitch: Pitch) -> bool {
        (self.lowest..=self.highest).contains(&pitch)
    }

    /// Head centre in the performer frame, m.
    pub fn centre(&self) -> DVec3 {
        DVec3::new(
            self.placement.x_m,
            self.placement.y_m,
            self.placement.head_height_m,
        )
    }

    /// A point on the head in the performer frame, from a radius fraction (0 centre,
    /// 1 rim) and an angle in degrees measured from the direction pointing from the head
    /// centre to the player, counter-clockwise seen from above.
    pub fn point_on_head(&self, radius_fraction: f64, angle_deg: f64) -> DVec3 {
        let dir = glam::DVec2::from_angle(angle_deg.to_radians()).rotate(self.toward_player());
        self.centre() + (dir * radius_fraction * self.radius_m()).extend(0.0)
    }

    /// The horizontal unit vector from the head centre toward the player, who stands at the
    /// origin (−y for a drum placed at the origin itself).
    pub fn toward_player(&self) -> glam::DVec2 {
        (-self.centre().truncate()).normalize_or(glam::DVec2::NEG_Y)
    }

    /// Frequency of the (1,1) mode at the kit tuning predicted from the membrane,
    /// f11 = air_loading · j11/(2πa) · √(T/σ), Hz.
    pub fn membrane_f11_hz(&self) -> f64 {
        let m = &self.membrane;
        m.air_loading * BESSEL_J11 / (std::f64::consts::TAU * self.radius_m())
            * (m.tension_n_per_m / m.areal_density_kg_per_m2).sqrt()
    }

    /// Head tension that tunes the (1,1) mode to `pitch`, N/m (f ∝ √T).
    pub fn tension_for(&self, pitch: Pitch) -> f64 {
        self.membrane.tension_n_per_m * (pitch.hz() / self.tuning.hz()).powi(2)
    }

    /// This drum with its pedal set to `pitch`: the head's tension set by
    /// [`tension_for`](Drum::tension_for), all else as it is.
    pub fn retuned(&self, pitch: Pitch) -> Drum {
        let mut drum = self.clone();
        if pitch != self.tuning {
            drum.membrane.tension_n_per_m = self.tension_for(pitch);
            drum.tuning = pitch;
        }
        drum
    }
}

/// A pedal change during a performance: from `at_s` on, drum `drum` plays at `pitch`
/// (its head retuned by [`Drum::retuned`]). The player damps the head before it: the
/// change lies between the drum's last stroke at its old pitch (`after_s`) and its
/// first at the new one.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Retune {
    /// Index of the drum in the kit.
    pub drum: usize,
    /// Score time from which the new pitch holds, s.
    pub at_s: f64,
    /// Score time of the drum's last stroke at the old pitch, s.
    pub after_s: f64,
    pub pitch: Pitch,
}

/// The pitch drum `drum` of `kit` is tuned to at score time `time_s` (s) under the pedal
/// changes `retunes` (in time order): that of its latest change at or before `time_s`,
/// else the kit's. None for an unknown drum.
pub fn pitch_at(kit: &Kit, retunes: &[Retune], drum: usize, time_s: f64) -> Option<Pitch> {
    let tuning = kit.drums.get(drum)?.tuning;
    let latest = retunes.iter().rfind(|r| r.drum == drum && r.at_s <= time_s);
    Some(latest.map_or(tuning, |r| r.pitch))
}

impl Kit {
    /// Parse kit text, strictly, then validate it; `path` names the file in errors.
    pub fn parse(path: &Path, text: &str) -> Result<Kit, FileError> {
        #[derive(Deserialize)]
        #[serde(rename = "Kit")]
        struct Probe {
            version: u32,
        }
        let probe: Probe = ron_file::parse(path, text)?;
        let kit: Kit = match probe.version {
            1 => ron_file::parse(path, text)?,
            found => {
                return Err(ron_file::unsupported_version(
                    path,
                    found,
                    KIT_FORMAT_VERSION,
                ));
            }
        };
        if let Some(p) = validate::problems(&kit).into_iter().next() {
            return Err(FileError::problem(path, p));
        }
        Ok(kit)
    }

    /// Load and validate a kit file.
    pub fn load(path: &Path) -> Result<Kit, FileError> {
        Kit::parse(path, &ron_file::read_text(path)?)
    }

    /// Save atomically as pretty RON.
    pub fn save(&self, path: &Path) -> Result<(), FileError> {
        ron_file::save(path, self)
    }

    /// A kit compiled into the program, by name (see [`BUNDLED_KITS`]).
    pub fn bundled(name: &str) -> Option<Kit> {
        BUNDLED_KITS
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(n, text)| {
                Kit::parse(Path::new(&format!("<bundled kit {n}>")), text)
                    .expect("bundled kits are valid (checked by tests)")
            })
    }

    /// The standard four-drum set (32, 29, 26, 23 inch).
    pub fn standard() -> Kit {
        Kit::bundled("standard").expect("the standard kit is bundled")
    }

    /// The drum whose head centre is horizontally nearest `point` (m), among the drums
    /// `hand` prefers when given; `None` when there is no such drum.
    pub fn nearest_drum(&self, point: DVec3, hand: Option<Side>) -> Option<usize> {
        (0..self.drums.len())
            .filter(|&i| hand.is_none_or(|h| self.drums[i].preferred_hand == h))
            .min_by(|&a, &b| {
                let d = |i: usize| self.drums[i].centre().truncate().distance(point.truncate());
                d(a).total_cmp(&d(b))
            })
    }

    /// Drums whose range holds `pitch`, by index.
    pub fn drums_for(&self, pitch: Pitch) -> impl Iterator<Item = usize> + '_ {
        self.drums
            .iter()
            .enumerate()
            .filter(move |(_, d)| d.in_range(pitch))
            .map(|(i, _)| i)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every bundled kit parses, validates, and survives a save → load round trip.
    #[test]
    fn bundled_kits_round_trip() {
        let dir = tempfile::tempdir().unwrap();
        for (name, _) in BUNDLED_KITS {
            let kit = Kit::bundled(name).unwrap();
            let path = dir.path().join(format!("{name}.ron"));
            kit.save(&path).unwrap();
            assert_eq!(Kit::load(&path).unwrap(), kit);
        }
    }

    /// The standard set is 32/29/26/23 inch, each tension tuning its head to within 1 %
    /// of the kit pitch, with the measured kettledrum ratios of the guide.
    #[test]
    fn standard_set_is_physical() {
        let kit = Kit::standard();
        let inches: Vec<f64> = kit.drums.iter().map(|d| d.diameter_m / 0.0254).collect();
        for (got, want) in inches.iter().zip([32.0, 29.0, 26.0, 23.0]) {
            assert!((got - want).abs() < 0.01, "{got} inch");
        }
        for d in &kit.drums {
            let f = d.membrane_f11_hz();
            assert!(
                (f / d.tuning.hz() - 1.0).abs() < 0.01,
                "{}: {f} Hz vs {}",
                d.name,
                d.tuning.hz()
            );
            let ratios: Vec<f64> = d
                .modes
                .iter()
                .filter(|m| m.n == 1 && m.m >= 1)
                .map(|m| m.ratio)
                .collect();
            assert_eq!(ratios, vec![1.00, 1.50, 1.98, 2.44, 2.94]);
        }
    }

    /// Angle 0 on the head points at the player; the centre is the centre.
    #[test]
    fn head_geometry() {
        let kit = Kit::standard();
        let d = &kit.drums[2];
        assert_eq!(d.point_on_head(0.0, 30.0), d.centre());
        let near = d.point_on_head(1.0, 0.0);
        let far = d.point_on_head(1.0, 180.0);
        assert!(near.truncate().length() < far.truncate().length());
        assert!((near.distance(d.centre()) - d.radius_m()).abs() < 1e-12);
        assert!(
            (d.tension_for(d.tuning.transposed(12).unwrap()) / d.membrane.tension_n_per_m - 4.0)
                .abs()
                < 1e-9
        );
    }
}
