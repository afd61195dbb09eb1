//! The modes of one timpani head: circular-membrane modes (m, n) with shapes
//! Φ = J_m(j_mn·r/a)·cos(mθ) or ·sin(mθ) (both orientations of each degenerate pair),
//! frequencies from the kit's measured ratios or from tension and density, per-mode decay
//! (T60), radiation weight and modal mass — the diagonal M_S, K_S of seed 000 eq. 5.
//!
//! Head-local coordinates: origin at the head centre, metres, +x pointing from the centre
//! toward the player (horizontally), +y 90° counter-clockwise from it seen from above, so
//! θ is the angle of [`Drum::point_on_head`].
//!
//! **Air loading** ([`air_share`]): a head moving in a pattern of wavenumber κ = j_mn/a
//! drags along, on each face, a layer of air of about ρ/κ per unit area (the near field
//! of a rippled surface reaches a distance of order 1/κ), so the air's share of a mode's
//! mass falls as 1/j_mn: σ_k = σ·(1 + x·j11/j_mn), with x = 1/air_loading² − 1 set by the
//! kit's air loading of the (1,1). Stiffness is the membrane's alone, K_k = σ·∫Φ²dA·ω_vac²
//! (the air adds mass, not tension), so the low modes are lowered most and the high ones
//! approach the in-vacuo membrane (Fletcher & Rossing §18.2).
//!
//! Modes the kit does not list (e.g. (0,1), (1,2), (6,1)) ring at √(K_k/M_k), the in-vacuo
//! frequency j_mn/(2πa)·√(T/σ) lowered by their air share (this puts (0,2) and (1,2)
//! within 5 % of Fletcher & Rossing's 65-cm kettledrum), with a T60 and gain
//! scaled from the kit's highest listed mode by f_last/f (higher modes die faster and
//! radiate less), and axisymmetric (m = 0) modes a quarter of that T60 (they die fast, guide §5).
//!
//! **The kettle** ([`kettle_spring`]): an axisymmetric mode also sweeps a net volume of
//! air, S = ∫Φ dA, in and out of the kettle, whose air (volume V) is a spring ρc²·S²/V on
//! it. The mode rings at √((K_vac + ρc²S²/V)/M_k): the 26-inch drum's (0,1) at 0.85 of its
//! (1,1), as Rossing measured on a 65-cm kettledrum (127 against 150 Hz), where the head
//! without its kettle puts it near 0.54 (0.55 here).
//! The sound it radiates damps it ([`radiation_t60_s`]): the (0,1) rings about 0.15 s, the
//! short low thump of a timpani stroke. Modes with nodal diameters move no net air.

use super::bessel::{EXACT_ZERO_LIMIT, Radial, bessel_zeros_below, debye_zero};
use super::{DrumError, FrequencySource, ModeConfig};
use crate::kit::Drum;
use glam::{DVec2, DVec3};
use std::f64::consts::{PI, TAU};

/// Density of air, kg/m³ (20 °C).
pub const AIR_DENSITY_KG_PER_M3: f64 = 1.204;
/// Speed of sound in air, m/s (20 °C).
pub const SOUND_SPEED_MPS: f64 = 343.0;

/// The squared volume an axisymmetric mode of zero `zero` (shape J0(j·r/a), 1 at the
/// centre, J1(zero)² `j1_squared`) sweeps per unit modal displacement on a head of radius
/// `a_m`: S² = (2πa²·J1(j)/j)², m⁴.
fn swept_squared(a_m: f64, zero: f64, j1_squared: f64) -> f64 {
    (TAU * a_m * a_m).powi(2) * j1_squared / (zero * zero)
}

/// The kettle's air spring on an axisymmetric mode, ρc²·S²/V (N/m; 0 without a kettle),
/// for a head of radius `a_m` and a mode of zero `zero` with J1(zero)² `j1_squared`.
pub fn kettle_spring(a_m: f64, zero: f64, j1_squared: f64, kettle_m3: Option<f64>) -> f64 {
    kettle_m3.map_or(0.0, |v| {
        AIR_DENSITY_KG_PER_M3
            * SOUND_SPEED_MPS
            * SOUND_SPEED_MPS
            * swept_squared(a_m, zero, j1_squared)
            / v
    })
}

/// The air's share of the mass a mode of zero `zero` carries, relative to the head's own
/// areal density: (1/air_loading² − 1)·j11/j (module docs), so the (1,1) carries
/// σ/air_loading² and higher modes less.
pub fn air_share(air_loading: f64, zero: f64) -> f64 {
    (1.0 / (air_loading * air_loading) - 1.0) * crate::kit::BESSEL_J11 / zero
}

/// Which of a degenerate pair: the shape's angular factor cos(mθ) or sin(mθ) (m = 0 modes
/// have only `Cos`, whose factor is 1).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Orientation {
    Cos,
    Sin,
}

/// One mode orientation of a head.
#[derive(Clone, Debug)]
pub struct HeadMode {
    /// Nodal diameters.
    pub m: u32,
    /// Nodal circles counting the rim (from 1).
    pub n: u32,
    pub orientation: Orientation,
    /// Frequency, Hz.
    pub freq_hz: f64,
    /// Time to decay by 60 dB, s.
    pub t60_s: f64,
    /// Relative radiated amplitude per unit modal velocity (the (1,1) mode is 1).
    pub gain: f64,
    /// Modal mass M_k = σ·(1 + [`air_share`])·∫ Φ_k² dA: the head and the air it carries, kg.
    pub modal_mass_kg: f64,
    /// ∫ Φ_k² dA over the head, m².
    pub area_m2: f64,
    /// Whether the kit's mode table lists this (m, n).
    pub listed: bool,
    radial: Radial,
}

impl HeadMode {
    /// The zero j_mn of this mode's radial profile.
    pub fn bessel_zero(&self) -> f64 {
        self.radial.zero()
    }

    /// Mode shape Φ at head-local polar coordinates (s = r/a, θ rad); 0 outside the head.
    pub fn shape_polar(&self, s: f64, theta: f64) -> f64 {
        let radial = self.radial.at(s);
        if self.m == 0 {
            return radial;
        }
        let (sin, cos) = (f64::from(self.m) * theta).sin_cos();
        match self.orientation {
            Orientation::Cos => radial * cos,
            Orientation::Sin => radial * sin,
        }
    }
}

/// How many modes a head gets: a count, or all below a frequency (Hz).
#[derive(Clone, Copy, Debug)]
enum Extent {
    Count(usize),
    BelowHz(f64),
}

/// Unlisted (zero, m, n) with j_mn below `x_max`: exact zeros below [`EXACT_ZERO_LIMIT`],
/// Debye's above, each (m, n) once.
fn unlisted_zeros(x_max: f64, is_listed: &dyn Fn(u32, u32) -> bool) -> Vec<(f64, u32, u32)> {
    let mut found = Vec::new();
    for m in (0..).take_while(|&m| f64::from(m) < x_max) {
        let exact = bessel_zeros_below(m, x_max.min(EXACT_ZERO_LIMIT));
        let mut n = exact.len() as u32;
        for (i, z) in exact.into_iter().enumerate() {
            found.push((z, m, i as u32 + 1));
        }
        if x_max > EXACT_ZERO_LIMIT {
            loop {
                n += 1;
                let z = debye_zero(m, n);
                if z >= x_max {
                    break;
                }
                found.push((z, m, n));
            }
        }
    }
    found.retain(|&(_, m, n)| !is_listed(m, n));
    found
}

/// Time for an axisymmetric mode of modal mass `mass_kg` ringing at `freq_hz` to lose
/// 60 dB to the sound it radiates from one face of a baffled head of radius `a_m`, s:
/// R = ρc·S²/(πa²)·(1 − 2J1(2ka)/(2ka)) (a baffled piston of the same volume velocity,
/// ρω²S²/(2πc) at low ka), T60 = ln(1000)·2M/R. The 26-inch drum's (0,1): about 0.15 s.
pub fn radiation_t60_s(a_m: f64, zero: f64, j1_squared: f64, freq_hz: f64, mass_kg: f64) -> f64 {
    let swept_squared = swept_squared(a_m, zero, j1_squared);
    let two_ka = 2.0 * TAU * freq_hz / SOUND_SPEED_MPS * a_m;
    let piston = 1.0 - 2.0 * super::bessel::bessel_j(1, two_ka) / two_ka;
    let resistance =
        AIR_DENSITY_KG_PER_M3 * SOUND_SPEED_MPS * swept_squared / (PI * a_m * a_m) * piston;
    1000f64.ln() * 2.0 * mass_kg / resistance
}

/// The modes of one head and where it is.
#[derive(Clone, Debug)]
pub struct HeadModes {
    radius_m: f64,
    centre: DVec3,
    /// Unit horizontal vector from the centre toward the player (head-local +x).
    toward_player: DVec2,
    modes: Vec<HeadMode>,
}

impl HeadModes {
    /// The first `config.count` mode orientations of `drum`: the kit's listed modes first
    /// (in kit order, cos then sin), then the others by rising frequency.
    pub fn new(drum: &Drum, config: &ModeConfig) -> Result<HeadModes, DrumError> {
        config.check()?;
        Self::build(drum, config.source, Extent::Count(config.count))
    }

    /// Every mode orientation of `drum` below `max_hz` (the listed ones first, then the
    /// others by rising frequency): a full-band head for sound. Zeros above
    /// [`EXACT_ZERO_LIMIT`] come from Debye's asymptotic form.
    pub fn below_hz(
        drum: &Drum,
        source: FrequencySource,
        max_hz: f64,
    ) -> Result<HeadModes, DrumError> {
        Self::build(drum, source, Extent::BelowHz(max_hz))
    }

    fn build(drum: &Drum, source: FrequencySource, extent: Extent) -> Result<HeadModes, DrumError> {
        let a = drum.radius_m();
        let mem = &drum.membrane;
        if !(a > 0.0 && mem.tension_n_per_m > 0.0 && mem.areal_density_kg_per_m2 > 0.0) {
            return Err(DrumError::InvalidDrum(drum.name.clone()));
        }
        let f11 = drum.tuning.hz();
        let wave_hz_per_zero =
            (mem.tension_n_per_m / mem.areal_density_kg_per_m2).sqrt() / (TAU * a);
        let sigma = mem.areal_density_kg_per_m2;
        // The air's share of mode mass (1 + share): frequency-dependent for measured
        // frequencies (module docs), uniform for the ideal membrane's.
        let share = |zero: f64| match source {
            FrequencySource::Measured => air_share(mem.air_loading, zero),
            FrequencySource::Membrane => 1.0 / (mem.air_loading * mem.air_loading) - 1.0,
        };
        let last = drum
            .modes
            .last()
            .ok_or_else(|| DrumError::InvalidDrum(drum.name.clone()))?;
        let last_hz = last.ratio * f11;
        let is_listed = |m: u32, n: u32| drum.modes.iter().any(|k| (k.m, k.n) == (m, n));

        // Candidate unlisted (m, n) pairs with their zeros, rising.
        let mut unlisted = match extent {
            Extent::Count(need) => {
                // The exact zeros below x_max, widening x_max until they hold the
                // orientations needed.
                let mut x_max = 12.0;
                loop {
                    let found = unlisted_zeros(x_max, &is_listed);
                    let orientations: usize = found
                        .iter()
                        .map(|&(_, m, _)| if m == 0 { 1 } else { 2 })
                        .sum();
                    if orientations >= need {
                        break found;
                    }
                    x_max *= 1.5;
                }
            }
            Extent::BelowHz(max_hz) => {
                // A mode of zero j rings at w·j/√(1 + share(j)) with the share falling in j:
                // every one below max_hz has j below x·√(1 + share(x)), x = max_hz/w.
                let x = max_hz / wave_hz_per_zero;
                unlisted_zeros(x * (1.0 + share(x)).sqrt(), &is_listed)
            }
        };
        unlisted.sort_by(|x, y| x.0.total_cmp(&y.0).then((x.1, x.2).cmp(&(y.1, y.2))));

        let mut modes = Vec::new();
        let room = |modes: &Vec<HeadMode>| match extent {
            Extent::Count(count) => modes.len() < count,
            Extent::BelowHz(_) => true,
        };
        let orientations = |m: u32| {
            if m == 0 {
                &[Orientation::Cos][..]
            } else {
                &[Orientation::Cos, Orientation::Sin][..]
            }
        };
        let push = |m: u32,
                    n: u32,
                    zero: f64,
                    listed: Option<&crate::kit::Mode>,
                    modes: &mut Vec<HeadMode>| {
            let radial = Radial::of(m, n, zero);
            let membrane_hz = wave_hz_per_zero * zero;
            let (freq_hz, t60_s, gain) = match (listed, source) {
                (Some(k), FrequencySource::Measured) => (k.ratio * f11, k.decay_s, k.gain),
                (Some(k), FrequencySource::Membrane) => {
                    (mem.air_loading * membrane_hz, k.decay_s, k.gain)
                }
                (None, _) => {
                    let f = membrane_hz / (1.0 + share(zero)).sqrt();
                    let scale = last_hz / f;
                    let t60 = last.decay_s * scale * if m == 0 { 0.25 } else { 1.0 };
                    (f, t60, last.gain * scale.min(1.0))
                }
            };
            // ∫ Φ² dA = π a² J1(j)² for m = 0, π a²/2 · J_{m+1}(j)² otherwise.
            let angular = if m == 0 { PI } else { PI / 2.0 };
            let norm = angular * a * a * radial.j_next_squared();
            // Every mode carries its share of air (module docs); an unlisted axisymmetric
            // one also sweeps the kettle's air, a spring on it, and what it radiates damps it.
            let modal_mass_kg = sigma * (1.0 + share(zero)) * norm;
            let (freq_hz, t60_s) = if m == 0 && listed.is_none() {
                let stiffness = sigma * norm * (TAU * membrane_hz).powi(2);
                let j1_squared = radial.j_next_squared();
                let spring = kettle_spring(a, zero, j1_squared, drum.kettle_volume_m3);
                let f = ((stiffness + spring) / modal_mass_kg).sqrt() / TAU;
                let radiated = radiation_t60_s(a, zero, j1_squared, f, modal_mass_kg);
                (f, t60_s.min(radiated))
            } else {
                (freq_hz, t60_s)
            };
            for &orientation in orientations(m) {
                if !room(modes) {
                    return;
                }
                if let Extent::BelowHz(max_hz) = extent
                    && freq_hz >= max_hz
                {
                    return;
                }
                modes.push(HeadMode {
                    m,
                    n,
                    orientation,
                    freq_hz,
                    t60_s,
                    gain,
                    modal_mass_kg,
                    area_m2: norm,
                    listed: listed.is_some(),
                    radial: radial.clone(),
                });
            }
        };
        for k in &drum.modes {
            let zero = super::bessel::bessel_zero(k.m, k.n);
            push(k.m, k.n, zero, Some(k), &mut modes);
        }
        for &(zero, m, n) in &unlisted {
            if !room(&modes) {
                break;
            }
            push(m, n, zero, None, &mut modes);
        }
        Ok(HeadModes {
            radius_m: a,
            centre: drum.centre(),
            toward_player: drum.toward_player(),
            modes,
        })
    }

    /// Keep only the modes at `indices` (rising), in that order.
    pub fn retain_indices(&mut self, indices: &[usize]) {
        let mut keep = indices.iter().peekable();
        let mut k = 0;
        self.modes.retain(|_| {
            let hit = keep.next_if_eq(&&k).is_some();
            k += 1;
            hit
        });
    }

    /// The mode orientations, listed modes first.
    pub fn modes(&self) -> &[HeadMode] {
        &self.modes
    }

    /// Head radius, m.
    pub fn radius_m(&self) -> f64 {
        self.radius_m
    }

    /// Head centre in the performer frame (on the head surface at rest), m.
    pub fn centre(&self) -> DVec3 {
        self.centre
    }

    /// A performer-frame point's head-local horizontal coordinates, m.
    pub fn local(&self, point: DVec3) -> DVec2 {
        let d = point.truncate() - self.centre.truncate();
        let u = self.toward_player;
        DVec2::new(d.dot(u), d.dot(u.perp()))
    }

    /// Head-local coordinates back to a performer-frame point on the resting head, m.
    pub fn world(&self, local: DVec2) -> DVec3 {
        let u = self.toward_player;
        self.centre + (u * local.x + u.perp() * local.y).extend(0.0)
    }

    /// Whether a head-local point lies on the head (r ≤ a).
    pub fn contains(&self, local: DVec2) -> bool {
        local.length_squared() <= self.radius_m * self.radius_m
    }

    /// Every mode's shape Φ_k at a head-local point, written to `out` (same order as
    /// [`modes`](Self::modes); `out` must be at least as long).
    pub fn shapes_at(&self, local: DVec2, out: &mut [f64]) {
        let s = local.length() / self.radius_m;
        let theta = local.y.atan2(local.x);
        for (o, mode) in out.iter_mut().zip(&self.modes) {
            *o = mode.shape_polar(s, theta);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kit::Kit;

    fn standard_26() -> Drum {
        Kit::standard().drums[2].clone()
    }

    /// The default orientations start with the kit's five (m,1) modes at the kit
    /// ratios (both orientations), and include the (0,1) and (1,2).
    #[test]
    fn default_modes_follow_the_kit() {
        let d = standard_26();
        let h = HeadModes::new(&d, &ModeConfig::default()).unwrap();
        assert_eq!(h.modes().len(), crate::base::choices::DEFAULT_MODE_COUNT);
        let f11 = d.tuning.hz();
        for (i, want) in [1.0, 1.5, 1.98, 2.44, 2.94].iter().enumerate() {
            let (c, s) = (&h.modes()[2 * i], &h.modes()[2 * i + 1]);
            assert_eq!(
                (c.m, c.n, c.orientation),
                (i as u32 + 1, 1, Orientation::Cos)
            );
            assert_eq!(s.orientation, Orientation::Sin);
            assert!((c.freq_hz / f11 - want).abs() < 1e-12);
        }
        let has = |m, n| h.modes().iter().any(|k| (k.m, k.n) == (m, n));
        assert!(has(0, 1) && has(1, 2) && has(0, 2));
        // (0,2) and (1,2) near Fletcher & Rossing's 1.68 and 2.09 (within 5 %).
        let ratio = |m, n| {
            h.modes()
                .iter()
                .find(|k| (k.m, k.n) == (m, n))
                .unwrap()
                .freq_hz
                / f11
        };
        assert!((ratio(0, 2) / 1.68 - 1.0).abs() < 0.05, "{}", ratio(0, 2));
        assert!((ratio(1, 2) / 2.09 - 1.0).abs() < 0.05, "{}", ratio(1, 2));
    }

    /// A full-band head below a frequency holds every mode a counted head has below it,
    /// although air loading lowers each mode by its own share (the search bound
    /// x·√(1 + share(x)) of [`HeadModes::below_hz`]), and the air's share falls with the
    /// mode's zero: modes above the (1,1) sit nearer their in-vacuo frequency.
    #[test]
    fn full_band_heads_miss_no_mode() {
        let d = standard_26();
        let counted = HeadModes::new(
            &d,
            &ModeConfig {
                count: 200,
                ..ModeConfig::default()
            },
        )
        .unwrap();
        let max_hz = 1000.0;
        let full = HeadModes::below_hz(&d, FrequencySource::Measured, max_hz).unwrap();
        let key = |k: &HeadMode| (k.m, k.n, k.orientation);
        let below: Vec<_> = counted
            .modes()
            .iter()
            .filter(|k| k.freq_hz < max_hz)
            .map(key)
            .collect();
        assert!(below.len() > 40, "{}", below.len());
        for k in &below {
            assert!(full.modes().iter().any(|f| key(f) == *k), "{k:?} missing");
        }
        assert!(full.modes().iter().all(|k| k.freq_hz < max_hz));
        let al = d.membrane.air_loading;
        assert!((air_share(al, crate::kit::BESSEL_J11) - (1.0 / (al * al) - 1.0)).abs() < 1e-12);
        assert!(air_share(al, 10.0) < air_share(al, 5.0));
    }

    /// With 200 modes the unlisted ones with nodal diameters come in rising frequency (the
    /// kettle moves the axisymmetric ones), all finite and positive.
    #[test]
    fn two_hundred_modes_are_sorted_and_sane() {
        let d = standard_26();
        let cfg = ModeConfig {
            count: 200,
            ..ModeConfig::default()
        };
        let h = HeadModes::new(&d, &cfg).unwrap();
        assert_eq!(h.modes().len(), 200);
        let unlisted: Vec<f64> = h
            .modes()
            .iter()
            .filter(|k| !k.listed && k.m > 0)
            .map(|k| k.freq_hz)
            .collect();
        assert!(unlisted.windows(2).all(|w| w[0] <= w[1]));
        assert!(h.modes().iter().all(|k| k.freq_hz > 0.0
            && k.t60_s > 0.0
            && k.modal_mass_kg > 0.0
            && k.gain.is_finite()));
        assert!(ModeConfig { count: 0, ..cfg }.check().is_err());
        assert!(ModeConfig { count: 201, ..cfg }.check().is_err());
    }

    /// The kettle's air spring raises the (0,1) of the 26-inch drum from about 0.54 of the
    /// (1,1) (head open below: Rossing's drum without its kettle) to Rossing's 0.85, a smaller kettle
    /// raises it more, and modes with nodal diameters do not feel it.
    #[test]
    fn the_kettle_raises_the_axisymmetric_modes() {
        let ratio_01 = |volume: Option<f64>| {
            let mut d = standard_26();
            d.kettle_volume_m3 = volume;
            let h = HeadModes::new(&d, &ModeConfig::default()).unwrap();
            let of = |m, n| {
                h.modes()
                    .iter()
                    .find(|k| (k.m, k.n) == (m, n))
                    .unwrap()
                    .freq_hz
            };
            (of(0, 1) / d.tuning.hz(), of(1, 2))
        };
        let (open, open_12) = ratio_01(None);
        let (kettle, kettle_12) = ratio_01(standard_26().kettle_volume_m3);
        let (small, _) = ratio_01(Some(0.06));
        assert!((open - 0.54).abs() < 0.03, "{open}");
        assert!((kettle - 0.85).abs() < 0.02, "{kettle}");
        assert!(small > kettle + 0.1, "{small}");
        assert_eq!(open_12, kettle_12);
        // Its radiation damps the (0,1) within about 0.15 s; at low ka the piston law is
        // ρω²S²/(2πc).
        let h = HeadModes::new(&standard_26(), &ModeConfig::default()).unwrap();
        let mode = h.modes().iter().find(|k| (k.m, k.n) == (0, 1)).unwrap();
        assert!((0.08..0.2).contains(&mode.t60_s), "{}", mode.t60_s);
        let (a, z, j1s) = (0.01, mode.bessel_zero(), mode.radial.j_next_squared());
        let s2 = (TAU * a * a).powi(2) * j1s / (z * z);
        let omega = TAU * 100.0;
        let r = AIR_DENSITY_KG_PER_M3 * omega * omega * s2 / (TAU * SOUND_SPEED_MPS);
        let want = 1000f64.ln() * 2.0 * 1e-3 / r;
        let t60 = radiation_t60_s(a, z, j1s, 100.0, 1e-3);
        assert!((t60 / want - 1.0).abs() < 1e-3, "{t60} {want}");
    }

    /// The membrane source reproduces the ideal-membrane ratios j_mn/j_11 and the kit's
    /// membrane f11.
    #[test]
    fn membrane_source_uses_bessel_ratios() {
        let d = standard_26();
        let cfg = ModeConfig {
            count: 24,
            source: FrequencySource::Membrane,
        };
        let h = HeadModes::new(&d, &cfg).unwrap();
        let f11 = h.modes()[0].freq_hz;
        assert!((f11 / d.membrane_f11_hz() - 1.0).abs() < 1e-9);
        assert!((h.modes()[2].freq_hz / f11 - 5.135_622 / 3.831_706).abs() < 1e-5);
    }

    /// Modal mass equals σ·(1 + air share)·∫Φ² dA by numerical quadrature (1e-3), the
    /// (1,1) carrying σ/air_loading², and shapes are 0 at the rim,
    /// J_m(0) at the centre, and cos/sin in angle.
    #[test]
    fn modal_mass_and_shapes() {
        let d = standard_26();
        // The first 24 (the quadrature grid resolves them).
        let config = ModeConfig {
            count: 24,
            ..ModeConfig::default()
        };
        let h = HeadModes::new(&d, &config).unwrap();
        let a = h.radius_m();
        let sigma = d.membrane.areal_density_kg_per_m2;
        let mut shapes = vec![0.0; h.modes().len()];
        let mut integral = vec![0.0; h.modes().len()];
        let (nr, nt) = (200, 96);
        for i in 0..nr {
            let r = (i as f64 + 0.5) / nr as f64 * a;
            for j in 0..nt {
                let t = (j as f64 + 0.5) / nt as f64 * TAU;
                h.shapes_at(DVec2::from_angle(t) * r, &mut shapes);
                let da = r * (a / nr as f64) * (TAU / nt as f64);
                for (acc, s) in integral.iter_mut().zip(&shapes) {
                    *acc += s * s * da;
                }
            }
        }
        for (k, mode) in h.modes().iter().enumerate() {
            let m =
                sigma * (1.0 + air_share(d.membrane.air_loading, mode.bessel_zero())) * integral[k];
            if (mode.m, mode.n) == (1, 1) {
                let loaded = sigma / d.membrane.air_loading.powi(2) * integral[k];
                assert!((m / loaded - 1.0).abs() < 1e-12);
            }
            assert!(
                (m / mode.modal_mass_kg - 1.0).abs() < 1e-3,
                "mode {k}: {m} vs {}",
                mode.modal_mass_kg
            );
        }
        h.shapes_at(DVec2::ZERO, &mut shapes);
        for (s, mode) in shapes.iter().zip(h.modes()) {
            let want = if mode.m == 0 { 1.0 } else { 0.0 };
            assert!((s - want).abs() < 1e-9);
        }
        h.shapes_at(DVec2::new(a, 0.0), &mut shapes);
        assert!(shapes.iter().all(|s| s.abs() < 1e-6));
        // Local frame: the point toward the player is local +x.
        let p = d.point_on_head(0.5, 0.0);
        let l = h.local(p);
        assert!((l - DVec2::new(0.5 * a, 0.0)).length() < 1e-12);
        let q = d.point_on_head(0.5, 90.0);
        assert!((h.local(q) - DVec2::new(0.0, 0.5 * a)).length() < 1e-12);
        assert!((h.world(h.local(q)) - q).length() < 1e-12);
    }
}
