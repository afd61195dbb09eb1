//! One frame of the GPU 3D view from what the viewport draws: the floor, each drum with
//! its head lifted by the rendered membrane motion at the playhead, the body and its
//! shadows, the ghost poses translucent. The heads' mode shapes at their grid points are
//! computed once per rendering ([`HeadShapes`]), so a frame only weighs each head's
//! recorded modal amplitudes (a few thousand multiply-adds a head).

use super::gpu_view::Frame;
use crate::body::model::BodyModel;
use crate::body::skeleton::Pose;
use crate::drum::DrumSet;
use crate::drum::set::recorded_sum;
use crate::kit::Kit;
use crate::scene::camera::Camera;
use crate::scene::marks::Rgba;
use crate::scene::solid::{self, Mesh, linear};
use crate::scene::stage::BACKGROUND;
use eframe::wgpu;
use glam::DVec2;

/// A ghost's colour (linear RGBA) from the flat view's, a little more opaque (solids
/// overlap less than the flat capsules do).
fn ghost_colour(tint: Rgba) -> [f32; 4] {
    let [r, g, b, a] = tint.0;
    linear(r, g, b, (f32::from(a) / 255.0 * 1.6).min(1.0))
}

/// Which rendering's drums `drums` are, for caches of what is computed once per rendering:
/// their address and how many contacts they recorded.
pub fn rendering_key(drums: &DrumSet) -> (usize, usize) {
    (std::ptr::from_ref(drums) as usize, drums.contacts().len())
}

/// The mode shapes of every head at its grid points ([`solid::head_grid`]), for one
/// rendering's drums and one kit.
#[derive(Default)]
pub struct HeadShapes {
    /// The rendering they were computed for ([`rendering_key`]) and the kit's drum count.
    key: Option<((usize, usize), usize)>,
    /// Per drum, per grid point, the shapes of its coupled modes (None off the head).
    shapes: Vec<Vec<Option<Vec<f64>>>>,
}

impl HeadShapes {
    /// Each drum's displacement (m) at its grid points at `time_s`, zeros at rest.
    fn displacements(&mut self, kit: &Kit, drums: Option<&DrumSet>, time_s: f64) -> Vec<Vec<f64>> {
        let Some(drums) = drums else {
            return vec![vec![0.0; solid::HEAD_GRID_POINTS]; kit.drums.len()];
        };
        let key = (rendering_key(drums), kit.drums.len());
        if self.key != Some(key) {
            self.shapes = (kit.drums.iter().map(solid::head_grid))
                .enumerate()
                .map(|(d, grid)| {
                    grid.iter()
                        .map(|p| drums.coupled_shapes_at(d, *p))
                        .collect()
                })
                .collect();
            self.key = Some(key);
        }
        (self.shapes.iter().enumerate())
            .map(|(d, points)| match drums.recorded_modes(d, time_s) {
                Some(q) => (points.iter())
                    .map(|s| s.as_ref().map_or(0.0, |s| recorded_sum(q, s)))
                    .collect(),
                None => vec![0.0; points.len()],
            })
            .collect()
    }
}

/// What a frame shows.
pub struct Scene<'a> {
    pub kit: &'a Kit,
    pub drums: Option<&'a DrumSet>,
    pub time_s: f64,
    pub body: &'a BodyModel,
    pub pose: Option<&'a Pose>,
    /// Translucent poses and their colours: impacts of selected beats, the target pose,
    /// the previous rendering's pose.
    pub ghosts: &'a [(Pose, Rgba)],
}

/// The frame of `scene` seen by `camera` in a viewport of `size` points.
pub fn frame(
    scene: &Scene,
    camera: &Camera,
    size: DVec2,
    heads: &mut HeadShapes,
    target_format: wgpu::TextureFormat,
) -> Frame {
    let (mut opaque, mut translucent) = (Mesh::default(), Mesh::default());
    solid::floor(&mut opaque);
    let lifts = heads.displacements(scene.kit, scene.drums, scene.time_s);
    for (drum, lift) in scene.kit.drums.iter().zip(&lifts) {
        solid::drum(drum, lift, &mut opaque, &mut translucent);
    }
    if let Some(pose) = scene.pose {
        solid::body(scene.body, pose, None, &mut opaque, &mut translucent);
    }
    let mut unused = Mesh::default();
    for (pose, tint) in scene.ghosts {
        let colour = Some(ghost_colour(*tint));
        solid::body(scene.body, pose, colour, &mut translucent, &mut unused);
    }
    let [r, g, b, _] = linear(BACKGROUND.0[0], BACKGROUND.0[1], BACKGROUND.0[2], 1.0);
    Frame {
        opaque,
        translucent,
        view_proj: solid::view_projection(camera, size).as_mat4(),
        eye: camera.basis().eye.as_vec3(),
        background: [f64::from(r), f64::from(g), f64::from(b)],
        target_format,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drum::strike::{PLAYING_SPOT_FRACTION, SIM_RATE_HZ, impact_speed_mps, scripted};
    use crate::drum::{DrumSet, ModeConfig};
    use crate::kit::Side;
    use crate::score::Dynamic;

    /// After a strike the struck head's vertices rise and fall and take the colour map;
    /// the other heads and the head before the strike stay flat; the cached shapes give
    /// what the drums' own displacement gives.
    #[test]
    fn struck_heads_move_in_the_frame() {
        let kit = Kit::standard();
        let (d, mallet) = (2, &kit.mallets[0]);
        let mut drums =
            DrumSet::new(&kit, mallet, &ModeConfig::default(), 1.0 / SIM_RATE_HZ).unwrap();
        let point = kit.drums[d].point_on_head(PLAYING_SPOT_FRACTION, 0.0);
        let speed = impact_speed_mps(Dynamic::Ff);
        scripted(
            &mut drums,
            &kit.drums[d],
            mallet,
            Side::Right,
            point,
            speed,
            0.3,
        );
        let body = BodyModel::default();
        let mut heads = HeadShapes::default();
        let lifts = |heads: &mut HeadShapes, t: f64| heads.displacements(&kit, Some(&drums), t);
        let start = drums.contacts()[0].start_s;
        let before = lifts(&mut heads, start - 0.02);
        assert!(before.iter().flatten().all(|h| *h == 0.0));
        let after = lifts(&mut heads, start + 0.03);
        let moved = |k: usize| after[k].iter().fold(0.0f64, |m, h| m.max(h.abs()));
        assert!(moved(d) > 1e-4, "struck head moved {} m", moved(d));
        assert!(
            (0..4)
                .filter(|&k| k != d)
                .all(|k| moved(k) < 0.2 * moved(d))
        );
        let grid = solid::head_grid(&kit.drums[d]);
        for (p, h) in grid.iter().zip(&after[d]).step_by(37) {
            let direct = drums.recorded_displacement(d, start + 0.03, *p);
            assert!(
                (direct - h).abs() <= 1e-9 + 1e-6 * direct.abs(),
                "{direct} {h}"
            );
        }
        let mut at = |t: f64| {
            let scene = Scene {
                kit: &kit,
                drums: Some(&drums),
                time_s: t,
                body: &body,
                pose: None,
                ghosts: &[],
            };
            let size = DVec2::new(800.0, 500.0);
            let format = wgpu::TextureFormat::Bgra8Unorm;
            frame(&scene, &Camera::default(), size, &mut heads, format).opaque
        };
        let (rest, struck) = (at(start - 0.02), at(start + 0.03));
        assert_eq!(rest.vertices.len(), struck.vertices.len());
        let changed: Vec<_> = (rest.vertices.iter().zip(&struck.vertices))
            .filter(|(a, b)| (a.position[2] - b.position[2]).abs() > 1e-3)
            .collect();
        let lifted = changed.len();
        assert!(changed.iter().all(|(a, b)| a.colour != b.colour));
        assert!(lifted > 20, "{lifted} head vertices lifted");
    }
}
