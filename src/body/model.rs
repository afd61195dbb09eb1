//! Mass properties of the simulated upper body (seed 000 Table 1, Fig. 3): each of the 11
//! segments is a capsule from its joint toward its child joint, with a mass that is the
//! Table 1 percentage of the total body mass and the inertia of a solid cylinder of the
//! capsule's length and radius about its centre of mass. The pelvis is fixed.
//!
//! Table 1 (guide §5): head 4 %, neck 4 %, trunk 46 %, upper arms 2 % each, forearms 1 %
//! each, hands 0.5 % each, sticks 0.25 % each (the rest — pelvis and legs — is not
//! simulated).

use super::skeleton::{JOINT_COUNT, Joint, Skeleton};
use glam::{DMat3, DVec3};

/// One rigid segment, in its own frame (the frame of the joint that moves it; at rest
/// aligned with the performer frame, x right, y forward, z up).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Segment {
    /// Mass, kg.
    pub mass_kg: f64,
    /// Centre of mass from the joint, m (segment frame).
    pub com_m: DVec3,
    /// Inertia about the centre of mass, kg·m² (segment frame).
    pub inertia: DMat3,
    /// Capsule axis from the joint to its far end, m (segment frame).
    pub axis_m: DVec3,
    /// Capsule radius, m.
    pub radius_m: f64,
}

/// The whole simulated body: skeleton plus mass properties.
#[derive(Clone, Debug, PartialEq)]
pub struct BodyModel {
    pub skeleton: Skeleton,
    /// Per segment, indexed by [`Joint::index`].
    pub segments: [Segment; JOINT_COUNT],
    /// Total body mass the percentages refer to, kg.
    pub total_mass_kg: f64,
}

/// Table 1 mass fraction and capsule radius (m) of each segment.
fn table_1(joint: Joint) -> (f64, f64) {
    use Joint::*;
    match joint {
        Trunk => (0.46, 0.15),
        Neck => (0.04, 0.05),
        Head => (0.04, 0.10),
        ShoulderL | ShoulderR => (0.02, 0.045),
        ElbowL | ElbowR => (0.01, 0.035),
        WristL | WristR => (0.005, 0.03),
        GripL | GripR => (0.0025, 0.012),
    }
}

impl BodyModel {
    /// A body of `total_mass_kg` on `skeleton`.
    pub fn new(skeleton: Skeleton, total_mass_kg: f64) -> BodyModel {
        let segments = Joint::ALL.map(|j| {
            let axis = segment_axis(&skeleton, j);
            let (fraction, radius) = table_1(j);
            let m = fraction * total_mass_kg;
            let l = axis.length();
            let axial = 0.5 * m * radius * radius;
            let transverse = m * (3.0 * radius * radius + l * l) / 12.0;
            let inertia = inertia_along(axis, transverse, axial);
            Segment {
                mass_kg: m,
                com_m: axis * 0.5,
                inertia,
                axis_m: axis,
                radius_m: radius,
            }
        });
        BodyModel {
            skeleton,
            segments,
            total_mass_kg,
        }
    }

    /// The same body holding mallets of `mass_kg` instead of Table 1's sticks (the seed's
    /// drumsticks; a timpani mallet weighs 40–50 g): a third of the mass in the felt head
    /// at the tip and the rest in a uniform shaft, so the centre of mass is at 2/3 of the
    /// length, the transverse inertia about it m·L²/9, and the mass a free mallet presents
    /// at its tip when it pivots about the grip 5/9 of it (as the drum's contact assumes).
    pub fn holding_mallets(mut self, mass_kg: f64) -> BodyModel {
        for side in [crate::kit::Side::Left, crate::kit::Side::Right] {
            let segment = &mut self.segments[Joint::arm(side)[3].index()];
            let axis = segment.axis_m;
            let l = axis.length();
            let axial = 0.5 * mass_kg * segment.radius_m * segment.radius_m;
            let transverse = mass_kg * l * l / 9.0;
            segment.mass_kg = mass_kg;
            segment.com_m = axis * (2.0 / 3.0);
            segment.inertia = inertia_along(axis, transverse, axial);
        }
        self
    }

    /// Total simulated mass, kg.
    pub fn simulated_mass_kg(&self) -> f64 {
        self.segments.iter().map(|s| s.mass_kg).sum()
    }
}

impl Default for BodyModel {
    /// A 1.75 m, 70 kg player with 0.37 m mallets.
    fn default() -> Self {
        BodyModel::new(Skeleton::default(), 70.0)
    }
}

/// The inertia (kg·m²) of a body symmetric about `axis` (segment frame): `transverse`
/// about any line across it through its centre of mass, `axial` about the axis itself.
fn inertia_along(axis: DVec3, transverse: f64, axial: f64) -> DMat3 {
    // Diagonal in a frame whose z is the axis, turned onto the segment axis.
    let dir = axis.try_normalize().unwrap_or(DVec3::Z);
    let r = DMat3::from_quat(glam::DQuat::from_rotation_arc(DVec3::Z, dir));
    r * DMat3::from_diagonal(DVec3::new(transverse, transverse, axial)) * r.transpose()
}

/// The segment's extent from its joint (segment frame, m): to its child joint, or for the
/// end segments (head, sticks) along their rest direction.
pub fn segment_axis(skeleton: &Skeleton, joint: Joint) -> DVec3 {
    let child = Joint::ALL
        .iter()
        .find(|c| c.parent() == Some(joint) && !matches!(c, Joint::ShoulderL | Joint::ShoulderR));
    match (joint, child) {
        (Joint::Head, _) => DVec3::new(
            0.0,
            0.0,
            0.22 * skeleton.offsets[Joint::Head.index()].z / 0.10,
        ),
        (Joint::GripL | Joint::GripR, _) => DVec3::new(0.0, 0.0, -skeleton.stick_length_m),
        (_, Some(c)) => skeleton.offsets[c.index()],
        (_, None) => DVec3::ZERO,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A mallet pivoting freely about the grip presents 5/9 of its mass at the tip,
    /// as the drum contact assumes.
    #[test]
    fn mallets_present_five_ninths_at_the_tip() {
        let body = BodyModel::default().holding_mallets(0.045);
        let stick = body.segments[Joint::GripR.index()];
        let l = stick.axis_m.length();
        let d = stick.axis_m.normalize();
        // Inertia about the grip for a turn perpendicular to the stick.
        let n = d.any_orthonormal_vector();
        let about_com = n.dot(stick.inertia * n);
        let about_grip = about_com + stick.mass_kg * stick.com_m.length_squared();
        let at_tip = about_grip / (l * l);
        assert!((at_tip - 0.025).abs() < 1e-12, "{at_tip}");
        assert_eq!(stick.mass_kg, 0.045);
    }

    /// The simulated segments carry 61.5 % of the body mass (Table 1 without pelvis and
    /// legs); inertias are symmetric positive definite; a stick spins about its own axis
    /// with an inertia near 1e-5 kg·m² (guide §5).
    #[test]
    fn mass_properties() {
        let body = BodyModel::default();
        assert!((body.simulated_mass_kg() - 0.615 * 70.0).abs() < 1e-9);
        for s in &body.segments {
            let i = s.inertia;
            assert!(
                (i - i.transpose())
                    .abs()
                    .to_cols_array()
                    .iter()
                    .all(|v| *v < 1e-12)
            );
            assert!(i.determinant() > 0.0 && i.x_axis.x > 0.0);
        }
        let stick = body.segments[Joint::GripR.index()];
        let spin = stick.inertia.mul_vec3(DVec3::Z).z;
        assert!(spin > 1e-6 && spin < 1e-4, "{spin}");
        assert!((stick.axis_m.length() - body.skeleton.stick_length_m).abs() < 1e-12);
    }
}
