//! Joint limits estimated from data (seed 000 Alg. 1): per joint, the quaternion mean q̄
//! (Karcher mean), the samples carried into the tangent space at q̄ by the log map
//! v = log(q̄*·q) (half-angle rotation vectors, rad), their principal axes e_k (SVD of
//! the centred samples, here the eigenvectors of their 3×3 scatter matrix), and the
//! smallest ellipsoid along those axes, with semi-axes proportional to the standard
//! deviations, that bounds every sample.

use glam::{DMat3, DQuat, DVec3};

/// A joint's range of motion as an ellipsoid in the tangent space at its mean rotation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointLimit {
    /// Mean rotation.
    pub mean: DQuat,
    /// Principal axes (unit, orthogonal), largest extent first.
    pub axes: [DVec3; 3],
    /// Semi-axes of the bounding ellipsoid along `axes`, in half-angle radians (the units
    /// of the quaternion log; twice this is a rotation angle).
    pub semi_axes: [f64; 3],
    /// Centre of the ellipsoid in the tangent space (the mean of the logs, near zero).
    pub centre: DVec3,
}

/// A limit per joint (`None`: that joint is free), in [`crate::body::Joint`] order.
pub type JointLimits = [Option<JointLimit>; crate::body::skeleton::JOINT_COUNT];

/// Every joint free.
pub const NO_LIMITS: JointLimits = [None; crate::body::skeleton::JOINT_COUNT];

/// The quaternion log map, half-angle rotation vector (rad), shortest arc.
pub fn quat_log(q: DQuat) -> DVec3 {
    let q = if q.w < 0.0 { -q } else { q };
    q.to_scaled_axis() * 0.5
}

/// The inverse of [`quat_log`].
pub fn quat_exp(v: DVec3) -> DQuat {
    DQuat::from_scaled_axis(v * 2.0)
}

impl JointLimit {
    /// Estimate from samples; `None` for fewer than 4 samples.
    pub fn estimate(samples: &[DQuat]) -> Option<JointLimit> {
        if samples.len() < 4 {
            return None;
        }
        let mut mean = samples[0].normalize();
        for _ in 0..20 {
            let step = samples
                .iter()
                .map(|q| quat_log(mean.inverse() * *q))
                .sum::<DVec3>()
                / samples.len() as f64;
            mean = (mean * quat_exp(step)).normalize();
            if step.length() < 1e-12 {
                break;
            }
        }
        let logs: Vec<DVec3> = samples
            .iter()
            .map(|q| quat_log(mean.inverse() * *q))
            .collect();
        let centre = logs.iter().sum::<DVec3>() / logs.len() as f64;
        let scatter = logs.iter().fold(DMat3::ZERO, |m, v| {
            let d = *v - centre;
            m + DMat3::from_cols(d * d.x, d * d.y, d * d.z)
        }) / logs.len() as f64;
        let (values, vectors) = symmetric_eigen(scatter);
        let sd: [f64; 3] = values.map(|l| l.max(0.0).sqrt().max(1e-9));
        // Scale the standard-deviation ellipsoid until it holds every sample.
        let scale = logs
            .iter()
            .map(|v| {
                let d = *v - centre;
                (0..3)
                    .map(|k| (d.dot(vectors[k]) / sd[k]).powi(2))
                    .sum::<f64>()
                    .sqrt()
            })
            .fold(0.0, f64::max);
        Some(JointLimit {
            mean,
            axes: vectors,
            semi_axes: sd.map(|s| s * scale),
            centre,
        })
    }

    /// Ellipsoid "radius" of `q`: below 1 inside the limit, 1 on it, above outside.
    pub fn radius(&self, q: DQuat) -> f64 {
        let d = quat_log(self.mean.inverse() * q) - self.centre;
        (0..3)
            .map(|k| (d.dot(self.axes[k]) / self.semi_axes[k].max(1e-12)).powi(2))
            .sum::<f64>()
            .sqrt()
    }

    /// This limit with every semi-axis at least `min_rotation_rad` of rotation (half of it
    /// in the tangent space): a capture that never moved a joint about some axis (a
    /// planar synthetic performer, a still head) would otherwise pin it there.
    pub fn at_least(&self, min_rotation_rad: f64) -> JointLimit {
        JointLimit {
            semi_axes: self.semi_axes.map(|a| a.max(0.5 * min_rotation_rad)),
            ..*self
        }
    }

    /// This limit with its ellipsoid scaled by `factor` about its centre (every semi-axis
    /// times `factor`).
    pub fn scaled(&self, factor: f64) -> JointLimit {
        JointLimit {
            semi_axes: self.semi_axes.map(|a| a * factor),
            ..*self
        }
    }

    /// The rotation on the ellipsoid's surface on the ray from its centre through `q`
    /// (`q` itself when it is inside).
    pub fn boundary(&self, q: DQuat) -> DQuat {
        let r = self.radius(q);
        if r <= 1.0 {
            return q;
        }
        let d = quat_log(self.mean.inverse() * q) - self.centre;
        (self.mean * quat_exp(self.centre + d / r)).normalize()
    }

    /// The gradient of radius² with respect to a small rotation δ of the joint,
    /// q ← exp(δ)·q with δ a rotation vector (rad) in the frame `q` is expressed in (the
    /// parent segment's): the direction in which turning the joint leaves its ellipsoid
    /// fastest (the ellipsoid's outward normal, mapped from the tangent space at the mean
    /// to rotations of the joint). With m = q̄*·q, φ = 2·log(m) and d = log(m) − centre,
    /// δ moves the log by ½·J_l⁻¹(φ)·(q̄*·δ) (J_l the left Jacobian of SO(3)), so the
    /// gradient is q̄·(½·J_l⁻ᵀ(φ)·g) with g = Σ_k 2·(d·e_k)/a_k²·e_k.
    pub fn outward(&self, q: DQuat) -> DVec3 {
        let v = quat_log(self.mean.inverse() * q);
        let d = v - self.centre;
        let g: DVec3 = (0..3)
            .map(|k| {
                let a = self.semi_axes[k].max(1e-12);
                self.axes[k] * (2.0 * d.dot(self.axes[k]) / (a * a))
            })
            .sum();
        let phi = 2.0 * v;
        let theta = phi.length();
        // J_l⁻¹(φ) = I − ½[φ]× + c·[φ]×², c = 1/θ² − (1 + cos θ)/(2θ·sin θ) (→ 1/12).
        let c = if theta < 1e-4 || theta.sin() < 1e-9 {
            1.0 / 12.0
        } else {
            1.0 / (theta * theta) - (1.0 + theta.cos()) / (2.0 * theta * theta.sin())
        };
        let jt_g = g + 0.5 * phi.cross(g) + c * phi.cross(phi.cross(g));
        self.mean * (0.5 * jt_g)
    }

    /// Whether `q` lies within the limit.
    pub fn contains(&self, q: DQuat) -> bool {
        self.radius(q) <= 1.0 + 1e-9
    }
}

/// Eigenvalues (descending) and unit eigenvectors of a symmetric 3×3 matrix, by cyclic
/// Jacobi rotations.
pub fn symmetric_eigen(m: DMat3) -> ([f64; 3], [DVec3; 3]) {
    let mut a = m.to_cols_array_2d();
    let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    for _ in 0..50 {
        let off = a[0][1].powi(2) + a[0][2].powi(2) + a[1][2].powi(2);
        if off < 1e-30 {
            break;
        }
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            if a[p][q].abs() < 1e-300 {
                continue;
            }
            let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
            let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
            let t = if theta == 0.0 { 1.0 } else { t };
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            for row in &mut a {
                let (akp, akq) = (row[p], row[q]);
                row[p] = c * akp - s * akq;
                row[q] = s * akp + c * akq;
            }
            let (row_p, row_q) = (a[p], a[q]);
            for k in 0..3 {
                a[p][k] = c * row_p[k] - s * row_q[k];
                a[q][k] = s * row_p[k] + c * row_q[k];
            }
            for row in &mut v {
                let (vp, vq) = (row[p], row[q]);
                row[p] = c * vp - s * vq;
                row[q] = s * vp + c * vq;
            }
        }
    }
    let mut order = [0, 1, 2];
    order.sort_by(|&i, &j| a[j][j].total_cmp(&a[i][i]));
    let values = order.map(|i| a[i][i]);
    let vectors = order.map(|i| DVec3::new(v[0][i], v[1][i], v[2][i]).normalize());
    (values, vectors)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::rng::Rng;

    /// Jacobi recovers a known symmetric matrix's eigen-decomposition.
    #[test]
    fn eigen_of_known_matrix() {
        let r = DMat3::from_quat(DQuat::from_euler(glam::EulerRot::XYZ, 0.3, -0.7, 1.1));
        let m = r * DMat3::from_diagonal(DVec3::new(5.0, 2.0, 0.5)) * r.transpose();
        let (values, vectors) = symmetric_eigen(m);
        assert!(
            (values[0] - 5.0).abs() < 1e-9
                && (values[1] - 2.0).abs() < 1e-9
                && (values[2] - 0.5).abs() < 1e-9
        );
        for k in 0..3 {
            assert!((m * vectors[k] - vectors[k] * values[k]).length() < 1e-9);
        }
    }

    /// Samples spread along known axes about a known mean give back that mean, those
    /// axes (up to sign) in order of spread, and an ellipsoid that holds every sample.
    #[test]
    fn recovers_mean_axes_and_bounds() {
        let mean = DQuat::from_rotation_y(0.8) * DQuat::from_rotation_x(0.3);
        let axes = [
            DVec3::new(1.0, 1.0, 0.0).normalize(),
            DVec3::new(-1.0, 1.0, 0.0).normalize(),
            DVec3::Z,
        ];
        let spread = [0.3, 0.1, 0.02];
        let mut rng = Rng::new(3);
        let samples: Vec<DQuat> = (0..4000)
            .map(|_| {
                let v: DVec3 = (0..3)
                    .map(|k| axes[k] * spread[k] * rng.uniform(-1.0, 1.0))
                    .sum();
                mean * quat_exp(v)
            })
            .collect();
        let limit = JointLimit::estimate(&samples).unwrap();
        assert!(limit.mean.angle_between(mean) < 0.01);
        for (found, want) in limit.axes.iter().zip(axes) {
            assert!(found.dot(want).abs() > 0.99, "axis {want}");
        }
        assert!(limit.semi_axes[0] > limit.semi_axes[1] && limit.semi_axes[1] > limit.semi_axes[2]);
        assert!(samples.iter().all(|q| limit.contains(*q)));
        assert!(!limit.contains(mean * quat_exp(axes[0] * 0.6)));
    }

    /// [`JointLimit::outward`] is the gradient of radius² under q ← exp(δ)·q (central
    /// differences), near the mean and far from it.
    #[test]
    fn outward_is_the_gradient_of_the_radius() {
        let limit = JointLimit {
            mean: DQuat::from_rotation_y(0.8) * DQuat::from_rotation_x(0.3),
            axes: [
                DVec3::new(1.0, 1.0, 0.0).normalize(),
                DVec3::new(-1.0, 1.0, 0.0).normalize(),
                DVec3::Z,
            ],
            semi_axes: [0.5, 0.3, 0.2],
            centre: DVec3::new(0.02, -0.01, 0.03),
        };
        let mut rng = Rng::new(5);
        for spread in [0.1, 0.5, 1.2] {
            for _ in 0..20 {
                let v = DVec3::new(rng.normal(), rng.normal(), rng.normal()) * spread;
                let q = limit.mean * quat_exp(v);
                let r2 = |d: DVec3| limit.radius(DQuat::from_scaled_axis(d) * q).powi(2);
                let h = 1e-6;
                let numeric = DVec3::new(
                    r2(DVec3::X * h) - r2(DVec3::X * -h),
                    r2(DVec3::Y * h) - r2(DVec3::Y * -h),
                    r2(DVec3::Z * h) - r2(DVec3::Z * -h),
                ) / (2.0 * h);
                let analytic = limit.outward(q);
                assert!(
                    (numeric - analytic).length() < 1e-5 * (1.0 + numeric.length()),
                    "{numeric} vs {analytic} at {v}"
                );
            }
        }
    }
}
