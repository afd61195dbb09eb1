//! The Y-up axes the animation formats use (BVH as Blender reads it, glTF 2.0): Y up, the
//! performer facing +Z, their right hand toward −X, metres. The performer frame (x right,
//! y forward, z up) maps to (X, Y, Z) = (−x, z, y), a proper rotation, so a rotation maps
//! by turning its axis the same way.

use glam::{DQuat, DVec3};

/// A performer-frame vector in Y-up axes.
pub fn vector(v: DVec3) -> DVec3 {
    DVec3::new(-v.x, v.z, v.y)
}

/// A performer-frame rotation in Y-up axes (the same turn about the mapped axis).
pub fn rotation(q: DQuat) -> DQuat {
    let axis = vector(DVec3::new(q.x, q.y, q.z));
    DQuat::from_xyzw(axis.x, axis.y, axis.z, q.w)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Mapping a rotation and then turning a mapped vector is mapping the turned vector;
    /// forward becomes +Z, up +Y, right −X.
    #[test]
    fn rotations_follow_vectors() {
        let q = DQuat::from_axis_angle(DVec3::new(0.2, -0.7, 0.4).normalize(), 1.1);
        let v = DVec3::new(0.3, -1.2, 0.5);
        assert!((rotation(q) * vector(v) - vector(q * v)).length() < 1e-12);
        assert_eq!(vector(DVec3::Y), DVec3::Z);
        assert_eq!(vector(DVec3::Z), DVec3::Y);
        assert_eq!(vector(DVec3::X), -DVec3::X);
    }
}
