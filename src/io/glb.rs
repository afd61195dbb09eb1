//! glTF 2.0 binary (`.glb`) of the whole scene, for Blender and web viewers: the 11
//! body segments and the two sticks as boxes on a node hierarchy that mirrors
//! `body::skeleton` (a node per joint, named as the joint, its segment's box a child of
//! it; `stick_tip_l`/`stick_tip_r` at the tips), the kit's drums as kettles with their
//! heads on top, and one animation, "performance", with a rotation channel for every
//! joint node (the only nodes that move: no joint translates) at the motion's rate
//! (250 Hz), linearly interpolated (slerp). The JSON is built with `gltf-json`; the
//! binary container (header, JSON and BIN chunks) is framed here.
//!
//! Axes: glTF is Y up with the asset's front facing +Z, metres; the performer frame
//! (x right, y forward, z up) is written as (−x, z, y) (`y_up`, as the BVH). Animation time 0 is the motion's
//! first sample (score time `Rendering::start_s`, the lead-in before score time 0).

use super::y_up;
use crate::body::model::segment_axis;
use crate::body::sim::Motion;
use crate::body::skeleton::{Joint, Pose, Skeleton};
use crate::kit::Kit;
use glam::{DQuat, DVec3};
use gltf_json as json;
use json::validation::Checked::Valid;
use json::validation::USize64;
use std::collections::BTreeMap;

/// Why a scene could not be made.
#[derive(Debug, thiserror::Error, PartialEq)]
#[non_exhaustive]
pub enum GlbError {
    #[error("the motion has no samples")]
    Empty,
    #[error("the scene is larger than the 4 GiB a .glb file may hold")]
    TooLarge,
}

fn f32s(v: DVec3) -> [f32; 3] {
    [v.x as f32, v.y as f32, v.z as f32]
}

/// Width and depth of each segment's box, m (across its axis).
fn segment_size(joint: Joint) -> (f64, f64) {
    match joint {
        Joint::Trunk => (0.34, 0.2),
        Joint::Neck => (0.1, 0.1),
        Joint::Head => (0.16, 0.19),
        Joint::ShoulderL | Joint::ShoulderR => (0.09, 0.09),
        Joint::ElbowL | Joint::ElbowR => (0.07, 0.07),
        Joint::WristL | Joint::WristR => (0.05, 0.08),
        Joint::GripL | Joint::GripR => (0.015, 0.015),
    }
}

/// Depth of a drum's kettle below its head, m.
const KETTLE_DEPTH_M: f64 = 0.55;

/// Sides of the drums' cylinders.
const CYLINDER_SIDES: usize = 32;

/// The scene as the bytes of a `.glb` file: `motion` played by `skeleton` at `kit`.
pub fn to_glb(motion: &Motion, skeleton: &Skeleton, kit: &Kit) -> Result<Vec<u8>, GlbError> {
    if motion.poses.is_empty() {
        return Err(GlbError::Empty);
    }
    let mut b = Builder::default();
    let skin = b.material("skin", [0.80, 0.62, 0.50, 1.0]);
    let wood = b.material("stick", [0.35, 0.22, 0.12, 1.0]);
    let felt = b.material("felt", [0.92, 0.90, 0.85, 1.0]);
    let copper = b.material("kettle", [0.72, 0.45, 0.20, 1.0]);
    let head = b.material("head", [0.93, 0.88, 0.76, 1.0]);
    let body_box = b.box_mesh("segment", skin);
    let stick_box = b.box_mesh("stick", wood);
    let felt_box = b.box_mesh("felt", felt);
    let drum = b.cylinder_mesh("drum", copper, head);

    let first = &motion.poses[0];
    let mut joint_nodes = Vec::new();
    for joint in Joint::ALL {
        let offset = match joint.parent() {
            None => skeleton.trunk_origin,
            Some(_) => skeleton.offsets[joint.index()],
        };
        let axis = y_up::vector(segment_axis(skeleton, joint));
        let (w, d) = segment_size(joint);
        let stick = matches!(joint, Joint::GripL | Joint::GripR);
        let mut children = vec![b.node(json::Node {
            mesh: Some(if stick { stick_box } else { body_box }),
            translation: Some(f32s(axis * 0.5)),
            rotation: Some(quaternion(DQuat::from_rotation_arc(
                DVec3::Y,
                axis.normalize_or(DVec3::Y),
            ))),
            scale: Some(f32s(DVec3::new(w, axis.length(), d))),
            name: Some(format!("{}_segment", joint.name())),
            ..Default::default()
        })];
        if stick {
            let side = if joint == Joint::GripL { "l" } else { "r" };
            let felt_node = b.node(json::Node {
                mesh: Some(felt_box),
                scale: Some([0.036; 3]),
                ..Default::default()
            });
            children.push(b.node(json::Node {
                translation: Some(f32s(axis)),
                children: Some(vec![felt_node]),
                name: Some(format!("stick_tip_{side}")),
                ..Default::default()
            }));
        }
        let node = b.node(json::Node {
            translation: Some(f32s(y_up::vector(offset))),
            rotation: Some(quaternion(y_up::rotation(first[joint.index()]))),
            children: Some(children),
            name: Some(joint.name().to_string()),
            ..Default::default()
        });
        joint_nodes.push(node);
    }
    // Each joint node carries its children joints after its segment.
    for joint in Joint::ALL {
        if let Some(parent) = joint.parent() {
            let (node, p) = (joint_nodes[joint.index()], joint_nodes[parent.index()]);
            let p = &mut b.root.nodes[p.value()];
            p.children.get_or_insert_with(Vec::new).push(node);
        }
    }
    let mut scene_nodes = vec![joint_nodes[Joint::Trunk.index()]];
    for d in &kit.drums {
        let p = &d.placement;
        let r = d.diameter_m / 2.0;
        scene_nodes.push(b.node(json::Node {
            mesh: Some(drum),
            translation: Some(f32s(y_up::vector(DVec3::new(
                p.x_m,
                p.y_m,
                p.head_height_m,
            )))),
            scale: Some(f32s(DVec3::new(r, KETTLE_DEPTH_M, r))),
            name: Some(d.name.clone()),
            ..Default::default()
        }));
    }
    b.animation(motion, &joint_nodes);
    b.root.push(json::Scene {
        extensions: Default::default(),
        extras: Default::default(),
        name: Some("timpanist".into()),
        nodes: scene_nodes,
    });
    b.root.scene = Some(json::Index::new(0));
    b.glb()
}

fn quaternion(q: DQuat) -> json::scene::UnitQuaternion {
    let q = q.normalize();
    json::scene::UnitQuaternion([q.x as f32, q.y as f32, q.z as f32, q.w as f32])
}

/// The document being made and its binary buffer.
#[derive(Default)]
struct Builder {
    root: json::Root,
    bin: Vec<u8>,
}

impl Builder {
    fn node(&mut self, node: json::Node) -> json::Index<json::Node> {
        self.root.push(node)
    }

    fn material(&mut self, name: &str, colour: [f32; 4]) -> json::Index<json::Material> {
        self.root.push(json::Material {
            name: Some(name.into()),
            pbr_metallic_roughness: json::material::PbrMetallicRoughness {
                base_color_factor: json::material::PbrBaseColorFactor(colour),
                metallic_factor: json::material::StrengthFactor(0.0),
                roughness_factor: json::material::StrengthFactor(0.8),
                ..Default::default()
            },
            ..Default::default()
        })
    }

    /// `bytes` appended to the buffer (4-byte aligned) as a buffer view.
    fn view(
        &mut self,
        bytes: &[u8],
        target: Option<json::buffer::Target>,
    ) -> json::Index<json::buffer::View> {
        let offset = self.bin.len();
        self.bin.extend_from_slice(bytes);
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        self.root.push(json::buffer::View {
            buffer: json::Index::new(0),
            byte_length: USize64::from(bytes.len()),
            byte_offset: Some(USize64::from(offset)),
            byte_stride: None,
            extensions: Default::default(),
            extras: Default::default(),
            name: None,
            target: target.map(Valid),
        })
    }

    /// An accessor of `values` (f32), `per` components each (`kind`), with its bounds
    /// when `bounds`.
    fn floats(
        &mut self,
        values: &[f32],
        kind: json::accessor::Type,
        per: usize,
        (target, bounds): (Option<json::buffer::Target>, bool),
    ) -> json::Index<json::Accessor> {
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        let view = self.view(&bytes, target);
        let (min, max) = if bounds {
            let pick = |f: fn(f32, f32) -> f32, start: f32| {
                let mut m = vec![start; per];
                for chunk in values.chunks_exact(per) {
                    for (m, v) in m.iter_mut().zip(chunk) {
                        *m = f(*m, *v);
                    }
                }
                Some(json::Value::from(m))
            };
            (pick(f32::min, f32::MAX), pick(f32::max, f32::MIN))
        } else {
            (None, None)
        };
        self.root.push(json::Accessor {
            buffer_view: Some(view),
            byte_offset: None,
            count: USize64::from(values.len() / per),
            component_type: Valid(json::accessor::GenericComponentType(
                json::accessor::ComponentType::F32,
            )),
            extensions: Default::default(),
            extras: Default::default(),
            type_: Valid(kind),
            min,
            max,
            name: None,
            normalized: false,
            sparse: None,
        })
    }

    fn indices(&mut self, indices: &[u16]) -> json::Index<json::Accessor> {
        let bytes: Vec<u8> = indices.iter().flat_map(|v| v.to_le_bytes()).collect();
        let view = self.view(&bytes, Some(json::buffer::Target::ElementArrayBuffer));
        self.root.push(json::Accessor {
            buffer_view: Some(view),
            byte_offset: None,
            count: USize64::from(indices.len()),
            component_type: Valid(json::accessor::GenericComponentType(
                json::accessor::ComponentType::U16,
            )),
            extensions: Default::default(),
            extras: Default::default(),
            type_: Valid(json::accessor::Type::Scalar),
            min: None,
            max: None,
            name: None,
            normalized: false,
            sparse: None,
        })
    }

    /// A triangle list with normals in `material`.
    fn primitive(
        &mut self,
        (positions, normals): (&[[f32; 3]], &[[f32; 3]]),
        indices: &[u16],
        material: json::Index<json::Material>,
    ) -> json::mesh::Primitive {
        let vertex = (Some(json::buffer::Target::ArrayBuffer), true);
        let p = self.floats(
            positions.as_flattened(),
            json::accessor::Type::Vec3,
            3,
            vertex,
        );
        let n = self.floats(
            normals.as_flattened(),
            json::accessor::Type::Vec3,
            3,
            (vertex.0, false),
        );
        let i = self.indices(indices);
        json::mesh::Primitive {
            attributes: BTreeMap::from([
                (Valid(json::mesh::Semantic::Positions), p),
                (Valid(json::mesh::Semantic::Normals), n),
            ]),
            extensions: Default::default(),
            extras: Default::default(),
            indices: Some(i),
            material: Some(material),
            mode: Valid(json::mesh::Mode::Triangles),
            targets: None,
        }
    }

    fn mesh(
        &mut self,
        name: &str,
        primitives: Vec<json::mesh::Primitive>,
    ) -> json::Index<json::Mesh> {
        self.root.push(json::Mesh {
            extensions: Default::default(),
            extras: Default::default(),
            name: Some(name.into()),
            primitives,
            weights: None,
        })
    }

    /// A unit cube centred on the origin.
    fn box_mesh(
        &mut self,
        name: &str,
        material: json::Index<json::Material>,
    ) -> json::Index<json::Mesh> {
        let mut positions = Vec::new();
        let mut normals = Vec::new();
        let mut indices = Vec::new();
        for axis in 0..3 {
            for sign in [-1.0f32, 1.0] {
                let mut n = [0.0; 3];
                n[axis] = sign;
                // Two directions across the face, ordered so the face winds outward.
                let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
                let base = positions.len() as u16;
                for (a, c) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
                    let mut p = [0.0; 3];
                    p[axis] = 0.5 * sign;
                    p[u] = 0.5 * a;
                    p[v] = 0.5 * c * sign;
                    positions.push(p);
                    normals.push(n);
                }
                indices.extend([base, base + 1, base + 2, base, base + 2, base + 3]);
            }
        }
        let primitive = self.primitive((&positions, &normals), &indices, material);
        self.mesh(name, vec![primitive])
    }

    /// A cylinder of radius 1 from y = −1 to 0: the kettle's side in `side` and the head
    /// on top in `top`.
    fn cylinder_mesh(
        &mut self,
        name: &str,
        side: json::Index<json::Material>,
        top: json::Index<json::Material>,
    ) -> json::Index<json::Mesh> {
        let n = CYLINDER_SIDES;
        let ring = |k: usize| {
            let a = std::f32::consts::TAU * k as f32 / n as f32;
            (a.cos(), a.sin())
        };
        let (mut positions, mut normals, mut indices) = (Vec::new(), Vec::new(), Vec::new());
        for k in 0..n {
            let (c, s) = ring(k);
            positions.extend([[c, 0.0, s], [c, -1.0, s]]);
            normals.extend([[c, 0.0, s]; 2]);
            let (a, b) = (2 * k as u16, 2 * ((k + 1) % n) as u16);
            indices.extend([a, b, a + 1, b, b + 1, a + 1]);
        }
        let kettle = self.primitive((&positions, &normals), &indices, side);
        let mut positions = vec![[0.0f32; 3]];
        let mut indices = Vec::new();
        for k in 0..n {
            let (c, s) = ring(k);
            positions.push([c, 0.0, s]);
            let (a, b) = (1 + k as u16, 1 + ((k + 1) % n) as u16);
            indices.extend([0, b, a]);
        }
        let normals = vec![[0.0, 1.0, 0.0]; positions.len()];
        let head = self.primitive((&positions, &normals), &indices, top);
        self.mesh(name, vec![kettle, head])
    }

    /// The performance: every joint node's rotation per sample.
    fn animation(&mut self, motion: &Motion, joint_nodes: &[json::Index<json::Node>]) {
        let times: Vec<f32> = (0..motion.poses.len())
            .map(|k| (k as f64 / motion.rate_hz) as f32)
            .collect();
        let input = self.floats(&times, json::accessor::Type::Scalar, 1, (None, true));
        let mut samplers = Vec::new();
        let mut channels = Vec::new();
        for joint in Joint::ALL {
            let values: Vec<f32> = motion
                .poses
                .iter()
                .flat_map(|pose: &Pose| quaternion(y_up::rotation(pose[joint.index()])).0)
                .collect();
            let output = self.floats(&values, json::accessor::Type::Vec4, 4, (None, false));
            let sampler = json::Index::new(samplers.len() as u32);
            samplers.push(json::animation::Sampler {
                extensions: Default::default(),
                extras: Default::default(),
                input,
                interpolation: Valid(json::animation::Interpolation::Linear),
                output,
            });
            channels.push(json::animation::Channel {
                sampler,
                target: json::animation::Target {
                    extensions: Default::default(),
                    extras: Default::default(),
                    node: joint_nodes[joint.index()],
                    path: Valid(json::animation::Property::Rotation),
                },
                extensions: Default::default(),
                extras: Default::default(),
            });
        }
        self.root.push(json::Animation {
            extensions: Default::default(),
            extras: Default::default(),
            channels,
            name: Some("performance".into()),
            samplers,
        });
    }

    /// The `.glb` bytes: header, JSON chunk (padded with spaces), BIN chunk.
    fn glb(mut self) -> Result<Vec<u8>, GlbError> {
        self.root.push(json::Buffer {
            byte_length: USize64::from(self.bin.len()),
            extensions: Default::default(),
            extras: Default::default(),
            name: None,
            uri: None,
        });
        self.root.asset.generator = Some(format!("timpanist {}", env!("CARGO_PKG_VERSION")));
        let mut json = json::serialize::to_vec(&self.root).expect("a glTF document serialises");
        while !json.len().is_multiple_of(4) {
            json.push(b' ');
        }
        let total = 12 + 8 + json.len() + 8 + self.bin.len();
        let length = u32::try_from(total).map_err(|_| GlbError::TooLarge)?;
        let mut out = Vec::with_capacity(total);
        out.extend_from_slice(b"glTF");
        out.extend_from_slice(&2u32.to_le_bytes());
        out.extend_from_slice(&length.to_le_bytes());
        for (kind, chunk) in [(b"JSON", &json), (b"BIN\0", &self.bin)] {
            out.extend_from_slice(&(chunk.len() as u32).to_le_bytes());
            out.extend_from_slice(kind);
            out.extend_from_slice(chunk);
        }
        Ok(out)
    }
}
