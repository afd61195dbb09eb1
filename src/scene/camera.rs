//! The 3D viewport's orbit camera: a pinhole camera looking at a target point from a
//! yaw/pitch/distance orbit (performer frame, z up), with projection of points to the
//! viewport's pixels and the inverse (a pixel's viewing ray), named views and eased moves
//! between cameras, framing a set of points, and following the hand that strikes next
//! (the hand, and a first-order lag that keeps the target from jerking) — pure math, no
//! egui.

use crate::kit::Side;
use glam::{DVec2, DVec3};
use std::f64::consts::{FRAC_PI_2, PI, TAU};

/// An orbit camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// The point orbited and looked at, m (performer frame).
    pub target: DVec3,
    /// Angle of the camera about the vertical through the target, rad (0: on +y, in
    /// front of the player looking back at them).
    pub yaw: f64,
    /// Elevation above the horizontal, rad.
    pub pitch: f64,
    /// Distance from the target, m.
    pub distance: f64,
    /// Vertical field of view, rad.
    pub fov_y: f64,
}

/// The viewing basis of a camera.
#[derive(Clone, Copy, Debug)]
pub struct Basis {
    pub eye: DVec3,
    pub forward: DVec3,
    pub right: DVec3,
    pub up: DVec3,
}

/// The steepest the camera looks down (or up), rad.
pub const MAX_PITCH_RAD: f64 = 1.45;

/// The nearest and farthest the camera orbits its target, m.
pub const DISTANCE_RANGE_M: std::ops::RangeInclusive<f64> = 0.3..=30.0;

/// Points closer to the eye than this are not drawn, m.
pub const NEAR_M: f64 = 0.05;

impl Default for Camera {
    /// Above and in front of the player, to the right, seeing body and drums.
    fn default() -> Self {
        Camera {
            target: DVec3::new(0.0, 0.35, 0.95),
            yaw: 0.6,
            pitch: 0.4,
            distance: 2.6,
            fov_y: 0.8,
        }
    }
}

impl Camera {
    /// The eye position and viewing axes.
    pub fn basis(&self) -> Basis {
        let (sy, cy) = self.yaw.sin_cos();
        let (sp, cp) = self.pitch.sin_cos();
        let eye = self.target + self.distance * DVec3::new(cp * sy, cp * cy, sp);
        let forward = (self.target - eye).normalize();
        let right = forward.cross(DVec3::Z).normalize();
        let up = right.cross(forward);
        Basis {
            eye,
            forward,
            right,
            up,
        }
    }

    /// Focal length in pixels for a viewport `height` pixels high.
    pub fn focal_px(&self, height: f64) -> f64 {
        0.5 * height / (0.5 * self.fov_y).tan()
    }

    /// Pixel position (from the viewport's top-left) of `p` in a `size` viewport, and its
    /// depth along the view axis (m); `None` behind or too near the eye.
    pub fn project(&self, p: DVec3, size: DVec2) -> Option<(DVec2, f64)> {
        self.projector(size).project(p)
    }

    /// A projector with the basis computed once (for many points per frame).
    pub fn projector(&self, size: DVec2) -> Projector {
        Projector {
            basis: self.basis(),
            focal: self.focal_px(size.y),
            centre: 0.5 * size,
        }
    }

    /// The viewing ray through pixel `px`: origin (the eye) and unit direction.
    pub fn ray(&self, px: DVec2, size: DVec2) -> (DVec3, DVec3) {
        let b = self.basis();
        let f = self.focal_px(size.y);
        let d = b.forward + b.right * (px.x - 0.5 * size.x) / f + b.up * (0.5 * size.y - px.y) / f;
        (b.eye, d.normalize())
    }

    /// Orbit by a pointer movement of `delta` pixels.
    pub fn orbit(&mut self, delta: DVec2) {
        self.yaw -= 0.008 * delta.x;
        self.pitch = (self.pitch + 0.008 * delta.y).clamp(-MAX_PITCH_RAD, MAX_PITCH_RAD);
    }

    /// Move the target with the pointer by `delta` pixels in a viewport `height` high, so
    /// the point under the pointer at the target's depth follows it.
    pub fn pan(&mut self, delta: DVec2, height: f64) {
        let b = self.basis();
        let scale = self.distance / self.focal_px(height);
        self.target += (-b.right * delta.x + b.up * delta.y) * scale;
    }

    /// Zoom by `factor` (> 1 moves away).
    pub fn zoom(&mut self, factor: f64) {
        self.distance =
            (self.distance * factor).clamp(*DISTANCE_RANGE_M.start(), *DISTANCE_RANGE_M.end());
    }
}

/// The named views the camera can jump to (a teacher's usual angles on the player).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum View {
    /// Over the player's shoulder, looking at the drums as they see them.
    Player,
    /// In front of the player, across the drums.
    Front,
    /// From the player's right.
    Side,
    /// From above.
    Top,
}

impl View {
    /// Every view, in menu order.
    pub const ALL: [View; 4] = [View::Player, View::Front, View::Side, View::Top];

    /// The view's name in menus and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            View::Player => "player's view",
            View::Front => "front",
            View::Side => "side",
            View::Top => "top",
        }
    }
}

/// How long a move to a named view takes in the editor, s.
pub const MOVE_S: f64 = 0.4;

impl Camera {
    /// The camera of a named view (the default target and field of view).
    pub fn of_view(view: View) -> Camera {
        let (yaw, pitch, distance, target) = match view {
            View::Player => (PI - 0.45, 0.85, 1.9, DVec3::new(0.0, 0.5, 0.75)),
            View::Front => (0.0, 0.3, 2.8, Camera::default().target),
            View::Side => (FRAC_PI_2, 0.2, 2.8, Camera::default().target),
            View::Top => (0.0, 1.45, 2.8, DVec3::new(0.0, 0.35, 0.8)),
        };
        Camera {
            target,
            yaw,
            pitch,
            distance,
            ..Camera::default()
        }
    }

    /// The camera a fraction `s` (0–1) of the way from `self` to `to`, eased in and out:
    /// target and distance straight, yaw the shorter way round.
    pub fn toward(&self, to: &Camera, s: f64) -> Camera {
        if s >= 1.0 {
            return *to;
        }
        let s = s.max(0.0);
        let e = s * s * (3.0 - 2.0 * s);
        let turn = (to.yaw - self.yaw + PI).rem_euclid(TAU) - PI;
        let mix = |a: f64, b: f64| a + (b - a) * e;
        Camera {
            target: self.target.lerp(to.target, e),
            yaw: self.yaw + turn * e,
            pitch: mix(self.pitch, to.pitch),
            distance: mix(self.distance, to.distance),
            fov_y: mix(self.fov_y, to.fov_y),
        }
    }
}

/// Framing leaves this much room around the points (1: the points' sphere touches the
/// edges).
const FRAME_MARGIN: f64 = 1.2;

/// The smallest radius framed, m (a single point is shown with some room around it).
const MIN_FRAME_RADIUS_M: f64 = 0.12;

impl Camera {
    /// This camera moved, looking the same way, so the sphere around `points` fills a
    /// view `aspect` (width / height) wide: the target at the centre of their bounds, the
    /// distance so the sphere fits the narrower field of view with a margin. `None`
    /// without points.
    pub fn framing(&self, points: &[DVec3], aspect: f64) -> Option<Camera> {
        let first = *points.first()?;
        let (lo, hi) = points
            .iter()
            .fold((first, first), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
        let centre = 0.5 * (lo + hi);
        let radius = points
            .iter()
            .map(|p| p.distance(centre))
            .fold(MIN_FRAME_RADIUS_M, f64::max);
        let half_y = 0.5 * self.fov_y;
        let half_x = (aspect.max(0.1) * half_y.tan()).atan();
        let half = half_x.min(half_y);
        let mut framed = Camera {
            target: centre,
            ..*self
        };
        framed.distance = 1.0;
        framed.zoom(FRAME_MARGIN * radius / half.sin());
        Some(framed)
    }
}

/// Time constant of the followed target's lag behind the hand, s.
pub const FOLLOW_LAG_S: f64 = 0.25;

/// The hand whose next stroke (at or after `t_s`) comes soonest, of `strokes` (time, s,
/// and hand); past the last stroke, the hand of the last. `None` without strokes.
pub fn next_hand(strokes: impl IntoIterator<Item = (f64, Side)>, t_s: f64) -> Option<Side> {
    let mut last: Option<(f64, Side)> = None;
    let mut next: Option<(f64, Side)> = None;
    for (t, hand) in strokes {
        if t >= t_s && next.is_none_or(|(n, _)| t < n) {
            next = Some((t, hand));
        }
        if last.is_none_or(|(l, _)| t > l) {
            last = Some((t, hand));
        }
    }
    next.or(last).map(|(_, hand)| hand)
}

/// `from` moved toward `to` over `dt_s` seconds by a first-order lag of time constant
/// [`FOLLOW_LAG_S`] (never past it, however long the step).
pub fn follow_step(from: DVec3, to: DVec3, dt_s: f64) -> DVec3 {
    let k = 1.0 - (-dt_s.max(0.0) / FOLLOW_LAG_S).exp();
    from.lerp(to, k)
}

/// Projection with a precomputed basis.
#[derive(Clone, Copy, Debug)]
pub struct Projector {
    pub basis: Basis,
    focal: f64,
    centre: DVec2,
}

impl Projector {
    /// Pixel position and depth of `p`, as [`Camera::project`].
    pub fn project(&self, p: DVec3) -> Option<(DVec2, f64)> {
        let rel = p - self.basis.eye;
        let z = rel.dot(self.basis.forward);
        if z < NEAR_M {
            return None;
        }
        let x = rel.dot(self.basis.right);
        let y = rel.dot(self.basis.up);
        Some((
            self.centre + DVec2::new(self.focal * x / z, -self.focal * y / z),
            z,
        ))
    }

    /// Pixels per metre at depth `z`.
    pub fn scale_at(&self, z: f64) -> f64 {
        self.focal / z.max(NEAR_M)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SIZE: DVec2 = DVec2::new(800.0, 600.0);

    /// Each named view sees the player's hands (in front of the body, at drum height), and
    /// the side view looks along −x; a move ends exactly on its view and turns the short
    /// way round.
    #[test]
    fn named_views_and_moves() {
        let hands = DVec3::new(0.0, 0.35, 0.9);
        for view in View::ALL {
            let cam = Camera::of_view(view);
            let (px, _) = cam.project(hands, SIZE).unwrap();
            assert!(
                px.x > 0.0 && px.x < SIZE.x && px.y > 0.0 && px.y < SIZE.y,
                "{view:?}"
            );
        }
        assert!(Camera::of_view(View::Side).basis().forward.x < -0.9);
        let from = Camera {
            yaw: 3.0,
            ..Camera::default()
        };
        let to = Camera {
            yaw: -3.0,
            ..Camera::default()
        };
        let half = from.toward(&to, 0.5);
        assert!((half.yaw - PI).abs() < 1e-9, "the short way: {}", half.yaw);
        let end = from.toward(&Camera::of_view(View::Top), 1.0);
        assert_eq!(
            end.project(hands, SIZE),
            Camera::of_view(View::Top).project(hands, SIZE)
        );
    }

    /// The target projects to the viewport centre at the orbit distance.
    #[test]
    fn target_is_centred() {
        let cam = Camera::default();
        let (px, depth) = cam.project(cam.target, SIZE).unwrap();
        assert!((px - SIZE * 0.5).length() < 1e-9, "{px}");
        assert!((depth - cam.distance).abs() < 1e-12);
    }

    /// A pixel's ray passes through every point that projects to that pixel.
    #[test]
    fn ray_inverts_projection() {
        let cam = Camera {
            yaw: -1.1,
            pitch: 0.3,
            ..Camera::default()
        };
        for p in [
            DVec3::new(0.3, 0.5, 0.8),
            DVec3::new(-0.4, 0.1, 1.5),
            DVec3::new(0.0, 0.9, 0.2),
        ] {
            let (px, depth) = cam.project(p, SIZE).unwrap();
            let (o, d) = cam.ray(px, SIZE);
            let along = (p - o).dot(d);
            assert!((o + d * along - p).length() < 1e-9);
            assert!(along >= depth - 1e-9);
        }
    }

    /// Up in the world is up on screen; points behind the eye are not projected.
    #[test]
    fn orientation_and_clipping() {
        let cam = Camera::default();
        let (low, _) = cam.project(cam.target, SIZE).unwrap();
        let (high, _) = cam.project(cam.target + DVec3::Z * 0.1, SIZE).unwrap();
        assert!(high.y < low.y);
        let behind = cam.basis().eye - cam.basis().forward;
        assert!(cam.project(behind, SIZE).is_none());
    }

    /// Panning by some pixels moves a point at the target's depth by the same pixels
    /// (it stays under the pointer).
    #[test]
    fn pan_follows_pointer() {
        let mut cam = Camera::default();
        let p = cam.target;
        let (before, _) = cam.project(p, SIZE).unwrap();
        cam.pan(DVec2::new(40.0, -25.0), SIZE.y);
        let (after, _) = cam.project(p, SIZE).unwrap();
        assert!((after - before - DVec2::new(40.0, -25.0)).length() < 1e-6);
    }

    /// Framing puts the points' centre at the view's centre and every point inside the
    /// view, nearer for close points than for spread ones, keeping the direction.
    #[test]
    fn framing_fits_points() {
        let cam = Camera::default();
        assert!(cam.framing(&[], 1.5).is_none());
        let near = [DVec3::new(0.1, 0.4, 0.8), DVec3::new(0.2, 0.45, 0.8)];
        let wide = [DVec3::new(-0.6, 0.2, 0.8), DVec3::new(0.7, 0.9, 0.8)];
        let narrow_view = DVec2::new(400.0, 600.0);
        let (a, b) = (
            cam.framing(&near, 1.0).unwrap(),
            cam.framing(&wide, 400.0 / 600.0).unwrap(),
        );
        assert!(a.distance < b.distance);
        assert_eq!((a.yaw, a.pitch), (cam.yaw, cam.pitch));
        let (centre, _) = a.project(0.5 * (near[0] + near[1]), SIZE).unwrap();
        assert!((centre - 0.5 * SIZE).length() < 1e-6);
        for p in wide {
            let (px, _) = b.project(p, narrow_view).unwrap();
            assert!(
                px.x > 0.0 && px.x < narrow_view.x && px.y > 0.0 && px.y < narrow_view.y,
                "{px}"
            );
        }
    }

    /// The next hand is the one striking soonest from now (at the stroke itself too), the
    /// last one's after the end; the follow lag approaches the goal without overshoot.
    #[test]
    fn following_the_next_hand() {
        let strokes = [(1.0, Side::Right), (0.5, Side::Left), (1.5, Side::Left)];
        assert_eq!(next_hand(strokes, 0.0), Some(Side::Left));
        assert_eq!(next_hand(strokes, 0.7), Some(Side::Right));
        assert_eq!(next_hand(strokes, 1.0), Some(Side::Right));
        assert_eq!(next_hand(strokes, 1.2), Some(Side::Left));
        assert_eq!(next_hand(strokes, 9.0), Some(Side::Left));
        assert_eq!(next_hand([], 0.0), None);
        let (from, to) = (DVec3::ZERO, DVec3::X);
        let one = follow_step(from, to, FOLLOW_LAG_S);
        assert!((one.x - (1.0 - (-1.0f64).exp())).abs() < 1e-12);
        assert!(follow_step(from, to, 100.0).x <= 1.0);
        assert_eq!(follow_step(from, to, -1.0), from);
    }

    /// Orbit keeps the distance to the target; zoom is clamped.
    #[test]
    fn orbit_and_zoom() {
        let mut cam = Camera::default();
        cam.orbit(DVec2::new(120.0, 500.0));
        assert!((cam.basis().eye.distance(cam.target) - cam.distance).abs() < 1e-9);
        assert!(cam.pitch <= 1.45);
        cam.zoom(1e-6);
        assert_eq!(cam.distance, 0.3);
    }
}
