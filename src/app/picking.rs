//! Picking and dragging in the 3D viewport, as pure geometry: the nearest point of a
//! projected polyline to the pointer (screen space), the distance between a viewing ray
//! and a segment, and the constrained drags of a 3D handle — along an axis (the point of
//! the axis line nearest the pointer's ray) or in a plane (ray–plane intersection).

use glam::{DVec2, DVec3};

/// The nearest point of segment `a`–`b` to `p`: its parameter in [0, 1] and the distance.
pub fn nearest_on_segment_2d(p: DVec2, a: DVec2, b: DVec2) -> (f64, f64) {
    let ab = b - a;
    let len2 = ab.length_squared();
    let t = if len2 > 0.0 {
        ((p - a).dot(ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (t, p.distance(a + ab * t))
}

/// The vertex of a projected polyline (`None` where a point is not visible) nearest to
/// `p` within `tolerance` pixels, measured to the segments: (vertex index, distance).
pub fn pick_polyline(points: &[Option<DVec2>], p: DVec2, tolerance: f64) -> Option<(usize, f64)> {
    let mut best: Option<(usize, f64)> = None;
    let mut consider = |k: usize, d: f64| {
        if d <= tolerance && best.is_none_or(|(_, bd)| d < bd) {
            best = Some((k, d));
        }
    };
    for (k, w) in points.windows(2).enumerate() {
        if let (Some(a), Some(b)) = (w[0], w[1]) {
            let (t, d) = nearest_on_segment_2d(p, a, b);
            consider(if t < 0.5 { k } else { k + 1 }, d);
        }
    }
    if points.len() == 1
        && let Some(a) = points[0]
    {
        consider(0, p.distance(a));
    }
    best
}

/// Distance between the ray `origin + s·dir` (s ≥ 0, `dir` unit) and segment `a`–`b`,
/// and the segment parameter in [0, 1] of the nearest point.
pub fn ray_segment_distance(origin: DVec3, dir: DVec3, a: DVec3, b: DVec3) -> (f64, f64) {
    let ab = b - a;
    let w = a - origin;
    let (aa, ad) = (ab.length_squared(), ab.dot(dir));
    let denom = aa - ad * ad;
    let mut t = if denom > 1e-18 {
        ((ad * w.dot(dir) - w.dot(ab)) / denom).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let mut s = (a + ab * t - origin).dot(dir).max(0.0);
    if aa > 0.0 {
        // Re-project the ray point onto the segment after clamping s.
        t = ((origin + dir * s - a).dot(ab) / aa).clamp(0.0, 1.0);
        s = (a + ab * t - origin).dot(dir).max(0.0);
    }
    ((origin + dir * s).distance(a + ab * t), t)
}

/// Drag along an axis: the signed distance `u` along unit `axis` from `anchor` such that
/// `anchor + u·axis` is the point of the axis line nearest the ray; `None` when the ray
/// runs parallel to the axis.
pub fn drag_along_axis(origin: DVec3, dir: DVec3, anchor: DVec3, axis: DVec3) -> Option<f64> {
    let w = anchor - origin;
    let b = axis.dot(dir);
    let denom = 1.0 - b * b;
    if denom < 1e-6 {
        return None;
    }
    Some((b * w.dot(dir) - w.dot(axis)) / denom)
}

/// Drag in a plane: where the ray meets the plane through `anchor` with unit `normal`;
/// `None` when the ray is parallel to the plane or the plane is behind the eye.
pub fn drag_in_plane(origin: DVec3, dir: DVec3, anchor: DVec3, normal: DVec3) -> Option<DVec3> {
    let denom = dir.dot(normal);
    if denom.abs() < 1e-9 {
        return None;
    }
    let s = (anchor - origin).dot(normal) / denom;
    (s > 0.0).then(|| origin + dir * s)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Point-to-segment distances: beside the middle, past an end, on a degenerate segment.
    #[test]
    fn segment_distance_2d() {
        let (a, b) = (DVec2::ZERO, DVec2::new(10.0, 0.0));
        let (t, d) = nearest_on_segment_2d(DVec2::new(5.0, 3.0), a, b);
        assert!((t - 0.5).abs() < 1e-12 && (d - 3.0).abs() < 1e-12);
        let (t, d) = nearest_on_segment_2d(DVec2::new(13.0, 4.0), a, b);
        assert!((t - 1.0).abs() < 1e-12 && (d - 5.0).abs() < 1e-12);
        assert_eq!(nearest_on_segment_2d(DVec2::ONE, a, a), (0.0, 2f64.sqrt()));
    }

    /// The polyline pick returns the nearer vertex of the nearest segment, skips hidden
    /// points, and nothing beyond the tolerance.
    #[test]
    fn polyline_pick() {
        let pts = [
            Some(DVec2::new(0.0, 0.0)),
            Some(DVec2::new(10.0, 0.0)),
            None,
            Some(DVec2::new(30.0, 0.0)),
            Some(DVec2::new(40.0, 0.0)),
        ];
        assert_eq!(
            pick_polyline(&pts, DVec2::new(8.0, 2.0), 5.0).map(|p| p.0),
            Some(1)
        );
        assert_eq!(
            pick_polyline(&pts, DVec2::new(37.0, 1.0), 5.0).map(|p| p.0),
            Some(4)
        );
        assert!(pick_polyline(&pts, DVec2::new(20.0, 0.0), 5.0).is_none());
    }

    /// Ray to segment: a ray crossing above a segment's middle, and one passing its end.
    #[test]
    fn ray_to_segment() {
        let (o, d) = (DVec3::new(0.5, -1.0, 0.2), DVec3::Y);
        let (dist, t) = ray_segment_distance(o, d, DVec3::ZERO, DVec3::X);
        assert!((dist - 0.2).abs() < 1e-12 && (t - 0.5).abs() < 1e-12);
        let (dist, t) = ray_segment_distance(DVec3::new(2.0, -1.0, 0.0), d, DVec3::ZERO, DVec3::X);
        assert!((dist - 1.0).abs() < 1e-12 && (t - 1.0).abs() < 1e-12);
        // The segment behind the ray's origin is measured from the origin.
        let (dist, _) = ray_segment_distance(DVec3::new(0.0, 1.0, 0.0), d, DVec3::ZERO, DVec3::X);
        assert!((dist - 1.0).abs() < 1e-12);
    }

    /// An axis drag follows the ray's nearest approach; parallel rays give nothing.
    #[test]
    fn axis_drag() {
        let anchor = DVec3::new(0.0, 0.0, 1.0);
        let u = drag_along_axis(DVec3::new(0.3, -2.0, 1.5), DVec3::Y, anchor, DVec3::X).unwrap();
        assert!((u - 0.3).abs() < 1e-12);
        assert!(drag_along_axis(DVec3::ZERO, DVec3::X, anchor, DVec3::X).is_none());
    }

    /// A plane drag lands on the plane where the ray meets it; never behind the eye.
    #[test]
    fn plane_drag() {
        let hit = drag_in_plane(
            DVec3::new(0.2, 0.4, 2.0),
            -DVec3::Z,
            DVec3::new(0.0, 0.0, 0.8),
            DVec3::Z,
        )
        .unwrap();
        assert!((hit - DVec3::new(0.2, 0.4, 0.8)).length() < 1e-12);
        assert!(
            drag_in_plane(DVec3::new(0.0, 0.0, 2.0), DVec3::Z, DVec3::ZERO, DVec3::Z).is_none()
        );
    }
}
