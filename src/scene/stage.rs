//! The stage as marks through a camera: the floor grid, each drum (kettle, translucent
//! head, and rings and spokes over the head lifted by the membrane's motion, magnified
//! [`MEMBRANE_MAGNIFICATION`] times), and the body as depth-sorted capsules with its
//! sticks. The editor's viewport and the video draw the stage with these.

use super::camera::Projector;
use super::marks::{Anchor, Mark, Rgba};
use crate::body::model::BodyModel;
use crate::body::skeleton::{JOINT_COUNT, Joint, Pose};
use crate::drum::ContactEvent;
use crate::kit::Drum;
use glam::{DVec2, DVec3};
use std::f64::consts::TAU;

/// How much the membranes' motion is magnified in the view (a loud strike moves the
/// head a millimetre or two).
pub const MEMBRANE_MAGNIFICATION: f64 = 150.0;
/// Background of the 3D view.
pub const BACKGROUND: Rgba = Rgba::rgb(28, 30, 36);
/// Colour of the sticks.
pub const STICK: Rgba = Rgba::rgb(190, 150, 100);
const KETTLE: Rgba = Rgba::rgb(150, 110, 60);
/// Points around a ring.
const RING_POINTS: usize = 48;

/// The floor grid: 3 m × 2.5 m in 25 cm squares around the player.
pub fn floor(proj: &Projector, out: &mut Vec<Mark>) {
    let colour = Rgba::grey(60);
    let mut line = |a: DVec3, b: DVec3| {
        if let (Some((pa, _)), Some((pb, _))) = (proj.project(a), proj.project(b)) {
            out.push(Mark::segment(pa, pb, 0.6, colour));
        }
    };
    for k in 0..=12 {
        let x = -1.5 + 0.25 * f64::from(k);
        line(DVec3::new(x, -0.75, 0.0), DVec3::new(x, 1.75, 0.0));
    }
    for k in 0..=10 {
        let y = -0.75 + 0.25 * f64::from(k);
        line(DVec3::new(-1.5, y, 0.0), DVec3::new(1.5, y, 0.0));
    }
}

/// A drum: kettle, head (translucent) and, on the head, three rings and eight spokes
/// lifted by `membrane` (the head's displacement at a point, m; magnified, at most 5 cm).
pub fn drum(proj: &Projector, drum: &Drum, membrane: &dyn Fn(DVec3) -> f64, out: &mut Vec<Mark>) {
    let centre = DVec3::new(
        drum.placement.x_m,
        drum.placement.y_m,
        drum.placement.head_height_m,
    );
    let r = 0.5 * drum.diameter_m;
    let around = |k: usize| TAU * k as f64 / RING_POINTS as f64;
    let on_head = |a: f64, scale: f64| {
        let mut p = centre + DVec3::new(a.cos(), a.sin(), 0.0) * r * scale;
        p.z += (MEMBRANE_MAGNIFICATION * membrane(p)).clamp(-0.05, 0.05);
        proj.project(p).map(|(q, _)| q)
    };
    let ring = |z_drop: f64, scale: f64| -> Option<Vec<DVec2>> {
        (0..RING_POINTS)
            .map(|k| {
                let a = around(k);
                let p = centre + DVec3::new(a.cos(), a.sin(), 0.0) * r * scale - DVec3::Z * z_drop;
                proj.project(p).map(|(q, _)| q)
            })
            .collect()
    };
    let head = ring(0.0, 1.0);
    if let Some(bowl) = ring(0.55 * drum.diameter_m, 0.45) {
        out.push(Mark::Line {
            points: bowl.clone(),
            closed: true,
            width: 1.0,
            colour: KETTLE,
        });
        if let Some(head) = &head {
            for k in (0..RING_POINTS).step_by(6) {
                out.push(Mark::segment(head[k], bowl[k], 1.0, KETTLE.with_alpha(178)));
            }
        }
    }
    if let Some(head) = head {
        out.push(Mark::Fill {
            points: head.clone(),
            colour: Rgba([225, 215, 190, 170]),
        });
        out.push(Mark::Line {
            points: head,
            closed: true,
            width: 1.5,
            colour: KETTLE,
        });
    }
    // The membrane: three rings and eight spokes over the head (the rim is fixed).
    let grid = Rgba([120, 100, 70, 150]);
    for scale in [0.25, 0.5, 0.75] {
        let points: Option<Vec<DVec2>> = (0..RING_POINTS)
            .map(|k| on_head(around(k), scale))
            .collect();
        if let Some(points) = points {
            out.push(Mark::Line {
                points,
                closed: true,
                width: 1.0,
                colour: grid,
            });
        }
    }
    for k in 0..8 {
        let a = TAU * f64::from(k) / 8.0;
        let points: Option<Vec<DVec2>> = (0..=8).map(|i| on_head(a, f64::from(i) / 8.0)).collect();
        if let Some(points) = points {
            out.push(Mark::Line {
                points,
                closed: false,
                width: 1.0,
                colour: grid,
            });
        }
    }
    drum_label(proj, drum, out);
}

/// A drum's name at the centre of its head.
pub fn drum_label(proj: &Projector, drum: &Drum, out: &mut Vec<Mark>) {
    if let Some((q, _)) = proj.project(drum.centre()) {
        out.push(Mark::Label {
            at: q,
            anchor: Anchor::Centre,
            text: drum.name.clone(),
            size: 10.0,
            colour: Rgba::grey(60),
        });
    }
}

/// Colour of a ghost pose: a faint blue-grey.
pub const GHOST: Rgba = Rgba([150, 175, 210, 70]);

/// The body in `pose`: one capsule per segment, as wide as the segment (at least
/// 1.5 px), the far ones first; the sticks in [`STICK`], the body shaded by depth.
pub fn body(proj: &Projector, model: &BodyModel, pose: &Pose, out: &mut Vec<Mark>) {
    capsules(proj, model, pose, None, out);
}

/// Colour of the target pose overlaid on the simulated one (the composed tips through
/// the IK): a faint green.
pub const TARGET_POSE: Rgba = Rgba([120, 220, 140, 90]);
/// Colour of the previous rendering's pose overlaid on the current one: a faint amber.
pub const PREVIOUS_POSE: Rgba = Rgba([240, 170, 80, 90]);

/// A ghost of the body in `pose` (e.g. at a selected beat's impact), every segment in
/// translucent `tint` ([`GHOST`], [`TARGET_POSE`], [`PREVIOUS_POSE`]).
pub fn ghost(proj: &Projector, model: &BodyModel, pose: &Pose, tint: Rgba, out: &mut Vec<Mark>) {
    capsules(proj, model, pose, Some(tint), out);
}

/// The body's capsules, in `tint` when given.
fn capsules(
    proj: &Projector,
    model: &BodyModel,
    pose: &Pose,
    tint: Option<Rgba>,
    out: &mut Vec<Mark>,
) {
    let frames = model.skeleton.forward(pose);
    let mut capsules: Vec<(f64, DVec2, DVec2, f32, Rgba)> = Vec::with_capacity(JOINT_COUNT);
    for j in Joint::ALL {
        let seg = &model.segments[j.index()];
        let a = frames.position[j.index()];
        let b = a + frames.rotation[j.index()] * seg.axis_m;
        let (Some((pa, za)), Some((pb, zb))) = (proj.project(a), proj.project(b)) else {
            continue;
        };
        let depth = 0.5 * (za + zb);
        let width = (2.0 * seg.radius_m * proj.scale_at(depth)) as f32;
        let colour = if let Some(tint) = tint {
            tint
        } else if matches!(j, Joint::GripL | Joint::GripR) {
            STICK
        } else {
            let shade = (215.0 - 25.0 * depth).clamp(120.0, 210.0) as u8;
            Rgba::rgb(shade, shade.saturating_sub(20), shade.saturating_sub(35))
        };
        capsules.push((depth, pa, pb, width.max(1.5), colour));
    }
    capsules.sort_by(|a, b| b.0.total_cmp(&a.0));
    for (_, a, b, width, colour) in capsules {
        out.push(Mark::segment(a, b, width, colour));
        out.push(Mark::Disc {
            centre: a,
            radius: 0.5 * width,
            colour,
        });
        out.push(Mark::Disc {
            centre: b,
            radius: 0.5 * width,
            colour,
        });
    }
}

/// How long a contact's force arrow stays after the contact starts, fading, s.
pub const CONTACT_SHOW_S: f64 = 0.6;
/// Length of the arrow of a [`FULL_ARROW_N`] contact, m.
const FULL_ARROW_M: f64 = 0.2;
const FULL_ARROW_N: f64 = 110.0;

/// Each contact of the last [`CONTACT_SHOW_S`] before `time_s` as an arrow pressing down
/// on the head at the point the felt touched, as long as its peak force asks (0.2 m for
/// 110 N), in its hand's colour, with the force written beside it, fading as it ages.
pub fn contacts(proj: &Projector, contacts: &[ContactEvent], time_s: f64, out: &mut Vec<Mark>) {
    for c in contacts {
        let age = (time_s - c.start_s) / CONTACT_SHOW_S;
        if !(0.0..1.0).contains(&age) || !c.peak_force_n.is_finite() {
            continue;
        }
        let colour = super::strip::hand_colour(c.side).with_alpha((255.0 * (1.0 - age)) as u8);
        let length = FULL_ARROW_M * (c.peak_force_n / FULL_ARROW_N).clamp(0.05, 1.5);
        let (Some((tip, _)), Some((tail, _))) = (
            proj.project(c.point),
            proj.project(c.point + DVec3::Z * length),
        ) else {
            continue;
        };
        out.push(Mark::segment(tail, tip, 3.0, colour));
        let back = (tail - tip).try_normalize().unwrap_or(DVec2::Y);
        let side = back.perp();
        for s in [-1.0, 1.0] {
            out.push(Mark::segment(
                tip,
                tip + 9.0 * back + 5.0 * s * side,
                3.0,
                colour,
            ));
        }
        out.push(Mark::Label {
            at: tail + DVec2::new(6.0, 0.0),
            anchor: Anchor::LeftCentre,
            text: format!("{:.0} N", c.peak_force_n),
            size: 12.0,
            colour,
        });
    }
}

/// A 3D polyline (a trajectory) as marks: the projected points, split where a point is
/// behind the camera.
pub fn path(proj: &Projector, points: &[DVec3], width: f32, colour: Rgba, out: &mut Vec<Mark>) {
    let mut run: Vec<DVec2> = Vec::new();
    let mut flush = |run: &mut Vec<DVec2>| {
        if run.len() >= 2 {
            out.push(Mark::Line {
                points: std::mem::take(run),
                closed: false,
                width,
                colour,
            });
        }
        run.clear();
    };
    for p in points {
        match proj.project(*p) {
            Some((q, _)) => run.push(q),
            None => flush(&mut run),
        }
    }
    flush(&mut run);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::camera::Camera;

    fn projector() -> Projector {
        Camera::default().projector(DVec2::new(800.0, 600.0))
    }

    /// The floor's 24 grid lines (13 along y, 11 along x) are all in view from the default camera.
    #[test]
    fn floor_grid_is_in_view() {
        let mut marks = Vec::new();
        floor(&projector(), &mut marks);
        assert_eq!(marks.len(), 24);
    }

    /// The standing body is drawn as 11 capsules plus their end discs, the nearest last.
    #[test]
    fn body_capsules_far_to_near() {
        let model = BodyModel::default();
        let mut marks = Vec::new();
        body(
            &projector(),
            &model,
            &crate::body::skeleton::REST,
            &mut marks,
        );
        assert_eq!(marks.len(), 3 * JOINT_COUNT);
    }

    /// A contact shows as an arrow (shaft and two barbs) with its force for 0.6 s after
    /// it starts, the later the fainter; not before it, not after.
    #[test]
    fn contact_arrows_fade_out() {
        let c = ContactEvent {
            side: crate::kit::Side::Right,
            drum: 0,
            start_s: 1.0,
            end_s: 1.006,
            peak_force_n: 82.0,
            impact_speed_mps: 3.0,
            point: DVec3::new(0.1, 0.5, 0.8),
        };
        let at = |t: f64| {
            let mut marks = Vec::new();
            contacts(&projector(), std::slice::from_ref(&c), t, &mut marks);
            marks
        };
        assert!(at(0.99).is_empty());
        assert!(at(1.61).is_empty());
        let early = at(1.01);
        assert_eq!(early.len(), 4);
        assert!(matches!(&early[3], Mark::Label { text, .. } if text == "82 N"));
        let alpha = |m: &Mark| match m {
            Mark::Line { colour, .. } => colour.0[3],
            _ => 0,
        };
        assert!(alpha(&early[0]) > alpha(&at(1.5)[0]));
    }

    /// A path behind the camera splits into the visible runs.
    #[test]
    fn path_splits_behind_the_eye() {
        let cam = Camera::default();
        let proj = projector();
        let eye = cam.basis().eye;
        let behind = eye - cam.basis().forward;
        let pts = [
            DVec3::new(0.0, 0.3, 1.0),
            DVec3::new(0.1, 0.3, 1.0),
            behind,
            DVec3::new(0.2, 0.3, 1.0),
            DVec3::new(0.3, 0.3, 1.0),
        ];
        let mut marks = Vec::new();
        path(&proj, &pts, 1.0, Rgba::grey(200), &mut marks);
        assert_eq!(marks.len(), 2);
    }
}
