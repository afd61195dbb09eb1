//! The stage as lit triangles for a depth-buffered renderer (the editor's GPU view): the
//! floor (its grid drawn per pixel), soft round shadows under the body and the drums,
//! each drum as a copper kettle with a dark hoop and a head whose displacement lifts
//! it (magnified [`MEMBRANE_MAGNIFICATION`] times, at most 5 cm) and tints it (warm up,
//! cool down), and the body as capsules — trunk, neck and head in the shirt's and skin's
//! colours, each arm in its side's colour, the sticks in wood with felt mallet balls.
//! Ghost poses are translucent. Pure geometry: positions in metres, performer frame
//! (+z up); colours linear RGBA; no GPU types here.

use super::camera::Camera;
use super::stage::MEMBRANE_MAGNIFICATION;
use crate::body::model::BodyModel;
use crate::body::skeleton::{Joint, Pose};
use crate::kit::Drum;
use glam::{DMat4, DVec2, DVec3, DVec4};
use std::f64::consts::{FRAC_PI_2, TAU};

/// How a vertex is shaded.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shading {
    /// Lit by the key light, the sky and the ground.
    Lit = 0,
    /// Its colour as it is (shadows).
    Unlit = 1,
    /// The floor: lit, with its 25 cm grid drawn per pixel.
    Floor = 2,
}

/// One vertex: position (m), unit normal, linear RGBA colour, [`Shading`] as a number.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Vertex {
    pub position: [f32; 3],
    pub normal: [f32; 3],
    pub colour: [f32; 4],
    pub shading: f32,
}

/// Triangles: vertices and the indices of their corners (counter-clockwise seen from
/// outside).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    pub vertices: Vec<Vertex>,
    pub indices: Vec<u32>,
}

/// Linear RGBA from 8-bit sRGB and an opacity.
pub fn linear(r: u8, g: u8, b: u8, alpha: f32) -> [f32; 4] {
    let l = |c: u8| (f32::from(c) / 255.0).powf(2.2);
    [l(r), l(g), l(b), alpha]
}

/// Points around a capsule, a hoop, a kettle.
const AROUND: usize = 20;
/// Rows of latitude per capsule end.
const CAP_ROWS: usize = 4;
/// Rings and sectors of a head's grid.
pub const HEAD_RINGS: usize = 8;
pub const HEAD_SECTORS: usize = 32;
/// Points of a head's grid ([`head_grid`]).
pub const HEAD_GRID_POINTS: usize = (HEAD_RINGS + 1) * (HEAD_SECTORS + 1);
/// Radius of a felt mallet ball drawn at each stick's tip, m.
pub const MALLET_RADIUS_M: f64 = 0.018;
/// Radius of a stick's shaft as drawn, m.
const STICK_RADIUS_M: f64 = 0.006;

const SHIRT: (u8, u8, u8) = (70, 78, 96);
const SKIN: (u8, u8, u8) = (214, 170, 140);
/// The arms' sleeves, [left, right]: the hands' trajectory colours, darker.
const SLEEVES: [(u8, u8, u8); 2] = [(60, 110, 190), (200, 105, 50)];
const WOOD: (u8, u8, u8) = (190, 150, 100);
const FELT: (u8, u8, u8) = (236, 232, 220);
const COPPER: (u8, u8, u8) = (176, 110, 62);
const HOOP: (u8, u8, u8) = (60, 58, 56);
const HEAD: (u8, u8, u8) = (226, 216, 190);
const FLOOR: (u8, u8, u8) = (52, 54, 60);

impl Mesh {
    fn push(&mut self, position: DVec3, normal: DVec3, colour: [f32; 4], shading: Shading) -> u32 {
        let i = self.vertices.len() as u32;
        self.vertices.push(Vertex {
            position: position.as_vec3().to_array(),
            normal: normal.as_vec3().to_array(),
            colour,
            shading: shading as u32 as f32,
        });
        i
    }

    /// Triangles joining a grid of `rows` × `cols` vertices pushed row by row from
    /// `first` (two per cell).
    fn grid(&mut self, first: u32, rows: usize, cols: usize) {
        for r in 0..rows - 1 {
            for c in 0..cols - 1 {
                let a = first + (r * cols + c) as u32;
                let b = a + cols as u32;
                self.indices.extend([a, a + 1, b, a + 1, b + 1, b]);
            }
        }
    }

    /// A capsule from `a` to `b` of radius `r` (a sphere when `a` = `b`).
    pub fn capsule(&mut self, a: DVec3, b: DVec3, r: f64, colour: [f32; 4]) {
        let w = (b - a).try_normalize().unwrap_or(DVec3::Z);
        let u = w.any_orthonormal_vector();
        let v = w.cross(u);
        let first = self.vertices.len() as u32;
        let rows = 2 * (CAP_ROWS + 1);
        for row in 0..rows {
            let (end, lat) = if row <= CAP_ROWS {
                (a, -FRAC_PI_2 + FRAC_PI_2 * row as f64 / CAP_ROWS as f64)
            } else {
                (b, FRAC_PI_2 * (row - CAP_ROWS - 1) as f64 / CAP_ROWS as f64)
            };
            for k in 0..=AROUND {
                let t = TAU * k as f64 / AROUND as f64;
                let n = (u * t.cos() + v * t.sin()) * lat.cos() + w * lat.sin();
                self.push(end + r * n, n, colour, Shading::Lit);
            }
        }
        self.grid(first, rows, AROUND + 1);
    }

    /// A torus around the vertical axis through `centre`: ring radius `big`, tube `small`.
    fn hoop(&mut self, centre: DVec3, big: f64, small: f64, colour: [f32; 4]) {
        let first = self.vertices.len() as u32;
        let tube = 8;
        for k in 0..=AROUND * 2 {
            let t = TAU * k as f64 / (AROUND * 2) as f64;
            let out = DVec3::new(t.cos(), t.sin(), 0.0);
            for j in 0..=tube {
                let s = TAU * j as f64 / tube as f64;
                let n = out * s.cos() + DVec3::Z * s.sin();
                self.push(centre + out * big + n * small, n, colour, Shading::Lit);
            }
        }
        self.grid(first, AROUND * 2 + 1, tube + 1);
    }

    /// A soft round shadow on the floor under `at`, `radius` wide, darkest `alpha` at
    /// its centre.
    fn shadow(&mut self, at: DVec3, radius: f64, alpha: f32) {
        let ground = DVec3::new(at.x, at.y, 0.002);
        let centre = self.push(ground, DVec3::Z, [0.0, 0.0, 0.0, alpha], Shading::Unlit);
        let first = self.vertices.len() as u32;
        for k in 0..AROUND {
            let t = TAU * k as f64 / AROUND as f64;
            let p = ground + radius * DVec3::new(t.cos(), t.sin(), 0.0);
            self.push(p, DVec3::Z, [0.0; 4], Shading::Unlit);
        }
        for k in 0..AROUND as u32 {
            let next = (k + 1) % AROUND as u32;
            self.indices.extend([centre, first + k, first + next]);
        }
    }
}

/// The floor: 3 m × 2.5 m around the player (the painter view's grid), its grid drawn
/// per pixel.
pub fn floor(out: &mut Mesh) {
    let c = linear(FLOOR.0, FLOOR.1, FLOOR.2, 1.0);
    let first = out.vertices.len() as u32;
    for (x, y) in [(-1.5, -0.75), (1.5, -0.75), (-1.5, 1.75), (1.5, 1.75)] {
        out.push(DVec3::new(x, y, 0.0), DVec3::Z, c, Shading::Floor);
    }
    out.grid(first, 2, 2);
}

/// Where a head's grid points are, head-local polar (radius fraction, angle): ring by
/// ring from the centre, [`HEAD_SECTORS`] + 1 points per ring (the seam repeated).
pub fn head_grid(drum: &Drum) -> Vec<DVec3> {
    let centre = drum.centre();
    let r = drum.radius_m();
    let mut points = Vec::with_capacity(HEAD_GRID_POINTS);
    for ring in 0..=HEAD_RINGS {
        let rho = r * ring as f64 / HEAD_RINGS as f64;
        for k in 0..=HEAD_SECTORS {
            let t = TAU * k as f64 / HEAD_SECTORS as f64;
            points.push(centre + rho * DVec3::new(t.cos(), t.sin(), 0.0));
        }
    }
    points
}

/// A drum: its kettle, hoop, shadow and head; `displacement` holds the head's
/// displacement (m, unmagnified) at each point of [`head_grid`] (zeros for a head at rest).
pub fn drum(drum: &Drum, displacement: &[f64], out: &mut Mesh, shadows: &mut Mesh) {
    let centre = drum.centre();
    let r = drum.radius_m();
    let depth = 0.55 * drum.diameter_m;
    // Kettle: a bowl narrowing to 45 % of the head at the bottom.
    let copper = linear(COPPER.0, COPPER.1, COPPER.2, 1.0);
    let rows = 10;
    let profile = |s: f64| -> (f64, f64) {
        let radius = r * (1.0 - 0.55 * s * s);
        (radius, centre.z - 0.02 - depth * s)
    };
    let first = out.vertices.len() as u32;
    for row in 0..=rows {
        let s = row as f64 / rows as f64;
        let (rad, z) = profile(s);
        // Slope of the profile for the normal: d(radius)/ds and dz/ds.
        let (dr, dz) = (-1.1 * r * s, -depth);
        for k in 0..=AROUND * 2 {
            let t = TAU * k as f64 / (AROUND * 2) as f64;
            let out_dir = DVec3::new(t.cos(), t.sin(), 0.0);
            let n = (out_dir * -dz + DVec3::Z * dr).normalize();
            out.push(
                DVec3::new(centre.x, centre.y, z) + out_dir * rad,
                n,
                copper,
                Shading::Lit,
            );
        }
    }
    out.grid(first, rows + 1, AROUND * 2 + 1);
    out.hoop(
        centre,
        r + 0.006,
        0.012,
        linear(HOOP.0, HOOP.1, HOOP.2, 1.0),
    );
    shadows.shadow(centre, 1.1 * r, 0.45);
    // The head.
    let points = head_grid(drum);
    let heights: Vec<f64> = (0..points.len())
        .map(|i| {
            (MEMBRANE_MAGNIFICATION * displacement.get(i).copied().unwrap_or(0.0))
                .clamp(-0.05, 0.05)
        })
        .collect();
    let cols = HEAD_SECTORS + 1;
    let height = |ring: usize, k: usize| heights[ring.min(HEAD_RINGS) * cols + k % cols];
    let first = out.vertices.len() as u32;
    for (i, p) in points.iter().enumerate() {
        let (ring, k) = (i / cols, i % cols);
        // Normal from the height's slope along the ring and the radius.
        let dr = r / HEAD_RINGS as f64;
        let radial = (height(ring + 1, k) - height(ring.saturating_sub(1), k))
            / (dr * (1 + usize::from(ring > 0 && ring < HEAD_RINGS)) as f64);
        let angle = TAU * k as f64 / HEAD_SECTORS as f64;
        let n = DVec3::new(-radial * angle.cos(), -radial * angle.sin(), 1.0).normalize();
        out.push(
            *p + DVec3::Z * heights[i],
            n,
            head_colour(heights[i]),
            Shading::Lit,
        );
    }
    out.grid(first, HEAD_RINGS + 1, cols);
}

/// The head's colour for a magnified lift `h` (m): cream at rest, warm up, cool down, full
/// at ±2 cm.
fn head_colour(h: f64) -> [f32; 4] {
    let base = linear(HEAD.0, HEAD.1, HEAD.2, 1.0);
    let (toward, s) = if h >= 0.0 {
        (linear(235, 120, 50, 1.0), (h / 0.02).min(1.0))
    } else {
        (linear(70, 120, 220, 1.0), (-h / 0.02).min(1.0))
    };
    let mix = |a: f32, b: f32| a + (b - a) * s as f32;
    [
        mix(base[0], toward[0]),
        mix(base[1], toward[1]),
        mix(base[2], toward[2]),
        1.0,
    ]
}

/// The body in `pose`: a capsule per segment (sticks thin, with a felt ball at each
/// tip) and a soft shadow under each; all in `tint` (a ghost) when given.
pub fn body(
    model: &BodyModel,
    pose: &Pose,
    tint: Option<[f32; 4]>,
    out: &mut Mesh,
    shadows: &mut Mesh,
) {
    let frames = model.skeleton.forward(pose);
    for j in Joint::ALL {
        let seg = &model.segments[j.index()];
        let a = frames.position[j.index()];
        let b = a + frames.rotation[j.index()] * seg.axis_m;
        let colour = |c: (u8, u8, u8)| tint.unwrap_or_else(|| linear(c.0, c.1, c.2, 1.0));
        match segment_look(j) {
            Look::Stick => {
                out.capsule(a, b, STICK_RADIUS_M, colour(WOOD));
                out.capsule(b, b, MALLET_RADIUS_M, colour(FELT));
            }
            Look::Head => {
                // A head-sized rounded shape (0.23 m tall, 0.17 m wide) at the middle of
                // the head segment, whatever its capsule in the mass model.
                let (mid, up) = (0.5 * (a + b), (b - a).normalize_or_zero());
                out.capsule(
                    mid - 0.03 * up,
                    mid + 0.03 * up,
                    HEAD_RADIUS_M,
                    colour(SKIN),
                );
            }
            Look::Plain(c) => out.capsule(a, b, seg.radius_m, colour(c)),
        }
        if tint.is_none() && !matches!(segment_look(j), Look::Stick | Look::Head) {
            shadows.shadow(0.5 * (a + b), 1.6 * seg.radius_m + 0.02, 0.28);
        }
    }
}

enum Look {
    Stick,
    Head,
    Plain((u8, u8, u8)),
}

/// Radius of the drawn head, m.
const HEAD_RADIUS_M: f64 = 0.085;

/// How a segment is drawn: the sticks as sticks, the arms in their side's sleeve, the
/// hands and neck in skin, the head as a head, the trunk in the shirt.
fn segment_look(j: Joint) -> Look {
    use Joint::*;
    match j {
        GripL | GripR => Look::Stick,
        ShoulderL | ElbowL => Look::Plain(SLEEVES[0]),
        ShoulderR | ElbowR => Look::Plain(SLEEVES[1]),
        Head => Look::Head,
        WristL | WristR | Neck => Look::Plain(SKIN),
        _ => Look::Plain(SHIRT),
    }
}

/// Near and far planes of [`view_projection`], m.
pub const NEAR_M: f64 = 0.05;
pub const FAR_M: f64 = 60.0;

/// The camera's view-projection matrix for a `size` px viewport (clip space with depth
/// 0–1 from [`NEAR_M`] to [`FAR_M`]): a point lands where the camera's own projector puts
/// it, so marks drawn over the solids match them.
pub fn view_projection(camera: &Camera, size: DVec2) -> DMat4 {
    let b = camera.basis();
    let f = camera.focal_px(size.y);
    let (sx, sy) = (2.0 * f / size.x, 2.0 * f / size.y);
    let (a, c) = (FAR_M / (FAR_M - NEAR_M), -FAR_M * NEAR_M / (FAR_M - NEAR_M));
    // Rows: clip = (sx·x_c, sy·y_c, a·z_c + c, z_c) with x_c, y_c, z_c the eye-relative
    // coordinates along right, up and forward.
    let row = |axis: DVec3, scale: f64, offset: f64| {
        DVec4::new(
            axis.x * scale,
            axis.y * scale,
            axis.z * scale,
            offset - scale * axis.dot(b.eye),
        )
    };
    let rows = [
        row(b.right, sx, 0.0),
        row(b.up, sy, 0.0),
        row(b.forward, a, c),
        row(b.forward, 1.0, 0.0),
    ];
    DMat4::from_cols_array_2d(&[
        [rows[0].x, rows[1].x, rows[2].x, rows[3].x],
        [rows[0].y, rows[1].y, rows[2].y, rows[3].y],
        [rows[0].z, rows[1].z, rows[2].z, rows[3].z],
        [rows[0].w, rows[1].w, rows[2].w, rows[3].w],
    ])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kit::Kit;

    /// The matrix puts points where the camera's projector does (pixels from the top
    /// left), with depth in 0–1 increasing away from the eye.
    #[test]
    fn view_projection_matches_the_projector() {
        let cam = Camera::default();
        let size = DVec2::new(900.0, 500.0);
        let m = view_projection(&cam, size);
        let proj = cam.projector(size);
        for p in [
            DVec3::new(0.0, 0.4, 0.8),
            DVec3::new(0.3, 0.7, 1.1),
            DVec3::new(-0.6, 1.2, 0.2),
        ] {
            let (px, _) = proj.project(p).unwrap();
            let clip = m * p.extend(1.0);
            let ndc = clip.truncate() / clip.w;
            let screen = DVec2::new((ndc.x + 1.0) * 0.5 * size.x, (1.0 - ndc.y) * 0.5 * size.y);
            assert!((screen - px).length() < 1e-6, "{screen} vs {px}");
            assert!((0.0..1.0).contains(&ndc.z));
        }
        let eye = cam.basis().eye;
        let near = m * (eye + cam.basis().forward * 0.5).extend(1.0);
        let far = m * (eye + cam.basis().forward * 5.0).extend(1.0);
        assert!(near.z / near.w < far.z / far.w);
    }

    /// A capsule's vertices lie at its radius from its axis segment, with unit normals
    /// pointing out, and its triangles face outward.
    #[test]
    fn capsules_are_closed_and_face_out() {
        let (a, b, r) = (DVec3::new(0.1, 0.2, 0.3), DVec3::new(0.4, 0.1, 0.9), 0.05);
        let mut m = Mesh::default();
        m.capsule(a, b, r, [1.0; 4]);
        let axis = b - a;
        for v in &m.vertices {
            let p = DVec3::from(v.position.map(f64::from));
            let t = ((p - a).dot(axis) / axis.length_squared()).clamp(0.0, 1.0);
            let d = (p - (a + axis * t)).length();
            assert!((d - r).abs() < 1e-5, "{d}");
            let n = DVec3::from(v.normal.map(f64::from));
            assert!((n.length() - 1.0).abs() < 1e-5);
        }
        let centre = 0.5 * (a + b);
        let mut outward = 0;
        for tri in m.indices.chunks(3) {
            let [p, q, s] = [tri[0], tri[1], tri[2]]
                .map(|i| DVec3::from(m.vertices[i as usize].position.map(f64::from)));
            let n = (q - p).cross(s - p);
            if n.length() < 1e-12 {
                continue;
            }
            let mid = (p + q + s) / 3.0;
            assert!(n.dot(mid - centre) > 0.0, "a triangle faces inward");
            outward += 1;
        }
        assert!(outward > 100);
    }

    /// A head at rest is flat and cream; a lifted point rises (magnified, at most 5 cm)
    /// and turns warm.
    #[test]
    fn heads_show_their_displacement() {
        let kit = Kit::standard();
        let d = &kit.drums[2];
        let points = head_grid(d);
        assert_eq!(points.len(), HEAD_GRID_POINTS);
        let (mut rest, mut shadows) = (Mesh::default(), Mesh::default());
        drum(d, &vec![0.0; points.len()], &mut rest, &mut shadows);
        let head_z = d.placement.head_height_m as f32;
        let n = points.len();
        let head = &rest.vertices[rest.vertices.len() - n..];
        assert!(head.iter().all(|v| (v.position[2] - head_z).abs() < 1e-6));
        let mut lifted = vec![0.0; n];
        lifted[HEAD_SECTORS + 2] = 1e-3;
        let mut moved = Mesh::default();
        drum(d, &lifted, &mut moved, &mut shadows);
        let v = moved.vertices[moved.vertices.len() - n + HEAD_SECTORS + 2];
        assert!(
            (v.position[2] - head_z - 0.05).abs() < 1e-6,
            "clamped at 5 cm"
        );
        assert!(v.colour[0] > head[0].colour[0] && v.colour[2] < head[0].colour[2]);
    }

    /// The body gives one capsule per segment plus a felt ball per stick, each with its
    /// shadow except the sticks'; a ghost carries its tint and no shadow.
    #[test]
    fn body_and_ghost() {
        let model = BodyModel::default();
        let (mut m, mut s) = (Mesh::default(), Mesh::default());
        body(&model, &crate::body::skeleton::REST, None, &mut m, &mut s);
        let per_capsule = 2 * (CAP_ROWS + 1) * (AROUND + 1);
        assert_eq!(m.vertices.len(), (Joint::ALL.len() + 2) * per_capsule);
        assert_eq!(s.vertices.len(), (Joint::ALL.len() - 3) * (AROUND + 1));
        let tint = [0.5, 0.6, 0.7, 0.3];
        let (mut g, mut gs) = (Mesh::default(), Mesh::default());
        body(
            &model,
            &crate::body::skeleton::REST,
            Some(tint),
            &mut g,
            &mut gs,
        );
        assert!(g.vertices.iter().all(|v| v.colour == tint));
        assert!(gs.vertices.is_empty());
    }
}
