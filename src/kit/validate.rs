//! Checks that a kit is physically sensible: ranges hold their tunings, parameters are
//! positive and finite, drums do not overlap, mallets are usable.

use super::Kit;

pub use crate::base::problem::Problem;

fn positive(x: f64) -> bool {
    x.is_finite() && x > 0.0
}

/// The kettle volumes a drum may have, as shares of π·a³ (a the head's radius).
const KETTLE_SHARE: (f64, f64) = (0.2, 5.0);

/// Every problem in `kit`, in file order.
pub fn problems(kit: &Kit) -> Vec<Problem> {
    let mut out = Vec::new();
    if kit.drums.is_empty() || kit.drums.len() > 8 {
        out.push(Problem::new(
            "drums",
            format!("expected 1 to 8 drums, found {}", kit.drums.len()),
        ));
    }
    for (i, d) in kit.drums.iter().enumerate() {
        let place = format!("drum {i} ({})", d.name);
        let mut bad = |message: String| out.push(Problem::new(place.clone(), message));
        if !(0.3..=1.0).contains(&d.diameter_m) {
            bad(format!(
                "diameter {} m is not between 0.3 and 1.0 m",
                d.diameter_m
            ));
        }
        if !(d.lowest <= d.tuning && d.tuning <= d.highest) {
            bad(format!(
                "tuning {} is outside its range {}–{}",
                d.tuning, d.lowest, d.highest
            ));
        }
        let m = &d.membrane;
        if !positive(m.tension_n_per_m) || !positive(m.areal_density_kg_per_m2) {
            bad("membrane tension and areal density must be positive".into());
        }
        if !(positive(m.air_loading) && m.air_loading <= 1.0) {
            bad(format!("air_loading {} is not in (0, 1]", m.air_loading));
        }
        if let Some(v) = d.kettle_volume_m3 {
            // A kettle holds about π·a³ of air under a head of radius a (the standard
            // 26-inch drum's 0.111 m³ is 0.98 of it); far outside that it is no kettle.
            let cube = std::f64::consts::PI * d.radius_m().powi(3);
            let (low, high) = (KETTLE_SHARE.0 * cube, KETTLE_SHARE.1 * cube);
            if !(v.is_finite() && (low..=high).contains(&v)) {
                bad(format!(
                    "kettle_volume_m3 {v} is not between {low:.3} and {high:.3} m³ ({}–{} times π·a³ for this head)",
                    KETTLE_SHARE.0, KETTLE_SHARE.1
                ));
            }
        }
        if d.modes.is_empty() {
            bad("the mode table is empty".into());
        }
        for (k, mode) in d.modes.iter().enumerate() {
            let usable = mode.n >= 1
                && positive(mode.ratio)
                && positive(mode.decay_s)
                && mode.gain.is_finite()
                && mode.gain >= 0.0;
            if !usable {
                bad(format!(
                    "mode {k} ({},{}): n must be ≥ 1, ratio and decay_s positive, gain ≥ 0",
                    mode.m, mode.n
                ));
            }
            if d.modes[..k].iter().any(|o| (o.m, o.n) == (mode.m, mode.n)) {
                bad(format!("mode ({},{}) is listed twice", mode.m, mode.n));
            }
        }
        if !positive(d.min_same_hand_gap_s) {
            bad("min_same_hand_gap_s must be positive".into());
        }
        let p = &d.placement;
        if ![p.x_m, p.y_m, p.head_height_m]
            .iter()
            .all(|v| v.is_finite())
            || !(0.3..=1.5).contains(&p.head_height_m)
        {
            bad("placement must be finite with head_height_m between 0.3 and 1.5 m".into());
        }
        for (j, other) in kit.drums[..i].iter().enumerate() {
            let gap = d.centre().truncate().distance(other.centre().truncate())
                - d.radius_m()
                - other.radius_m();
            if gap < 0.0 {
                bad(format!(
                    "overlaps drum {j} ({}) by {:.0} mm",
                    other.name,
                    -gap * 1000.0
                ));
            }
        }
    }
    if kit.mallets.is_empty() {
        out.push(Problem::new("mallets", "give at least one mallet"));
    }
    for (i, m) in kit.mallets.iter().enumerate() {
        let ok = positive(m.mass_kg)
            && positive(m.length_m)
            && positive(m.felt_stiffness)
            && positive(m.head_radius_m)
            && (1.0..=4.0).contains(&m.contact_exponent);
        if !ok {
            out.push(Problem::new(
                format!("mallet {i} ({})", m.name),
                "mass, length, stiffness and head radius must be positive and the contact exponent 1–4",
            ));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The standard kettles pass; none, an empty, a negative, a NaN or a room-sized one
    /// is named with the drum.
    #[test]
    fn kettle_volumes_are_held_to_the_head() {
        let standard = Kit::standard();
        assert!(problems(&standard).is_empty());
        for v in [0.0, -0.1, 1e-9, f64::NAN, 1e9] {
            let mut kit = standard.clone();
            kit.drums[2].kettle_volume_m3 = Some(v);
            let found = problems(&kit);
            assert_eq!(found.len(), 1, "{v}: {found:?}");
            let text = found[0].to_string();
            assert!(
                text.contains("drum 2") && text.contains("kettle_volume_m3"),
                "{text}"
            );
        }
    }
}
