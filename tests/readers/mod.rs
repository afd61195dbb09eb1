//! Independent readers for the exports, written from the formats' descriptions and not
//! from the writers' code: a BVH parser with forward kinematics (plain 3×3 matrices, any
//! declared channel order, root position channels absolute over a zero offset as Blender
//! reads them).
// Each test crate uses only some of these.
#![allow(dead_code)]

/// One BVH joint (or end site) as declared.
#[derive(Debug, Clone)]
pub struct BvhJoint {
    pub name: String,
    pub parent: Option<usize>,
    pub offset: [f64; 3],
    pub channels: Vec<String>,
    /// Index of its first channel in a frame's values.
    pub first_channel: usize,
}

/// A parsed BVH file.
#[derive(Debug, Clone)]
pub struct Bvh {
    pub joints: Vec<BvhJoint>,
    pub frame_time_s: f64,
    pub frames: Vec<Vec<f64>>,
}

type Mat = [[f64; 3]; 3];

fn mul(a: &Mat, b: &Mat) -> Mat {
    let mut m = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            m[i][j] = (0..3).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    m
}

fn apply(a: &Mat, v: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| (0..3).map(|k| a[i][k] * v[k]).sum())
}

/// The rotation by `deg` degrees about axis `axis` ('X', 'Y' or 'Z').
fn axis_rotation(axis: char, deg: f64) -> Mat {
    let (s, c) = deg.to_radians().sin_cos();
    match axis {
        'X' => [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]],
        'Y' => [[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]],
        'Z' => [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]],
        _ => panic!("no axis {axis}"),
    }
}

impl Bvh {
    /// Parse BVH text; panics with the offending token on malformed input.
    pub fn parse(text: &str) -> Bvh {
        let mut tokens = text.split_whitespace().peekable();
        let mut next = || tokens.next().expect("unexpected end of file");
        assert_eq!(next(), "HIERARCHY");
        let mut joints: Vec<BvhJoint> = Vec::new();
        let mut stack: Vec<usize> = Vec::new();
        let mut channels_total = 0;
        loop {
            let t = next();
            match t {
                "ROOT" | "JOINT" | "End" => {
                    let name = if t == "End" {
                        assert_eq!(next(), "Site");
                        format!("{}_end", joints[*stack.last().unwrap()].name)
                    } else {
                        next().to_string()
                    };
                    assert_eq!(next(), "{");
                    joints.push(BvhJoint {
                        name,
                        parent: stack.last().copied(),
                        offset: [0.0; 3],
                        channels: Vec::new(),
                        first_channel: channels_total,
                    });
                    stack.push(joints.len() - 1);
                }
                "OFFSET" => {
                    let j = joints.last_mut().unwrap();
                    for v in &mut j.offset {
                        *v = next().parse().unwrap();
                    }
                }
                "CHANNELS" => {
                    let n: usize = next().parse().unwrap();
                    let j = joints.last_mut().unwrap();
                    j.first_channel = channels_total;
                    j.channels = (0..n).map(|_| next().to_string()).collect();
                    channels_total += n;
                }
                "}" => {
                    stack.pop();
                }
                "MOTION" => break,
                other => panic!("unexpected token {other}"),
            }
        }
        assert!(stack.is_empty(), "unbalanced braces");
        assert_eq!(next(), "Frames:");
        let count: usize = next().parse().unwrap();
        assert_eq!((next(), next()), ("Frame", "Time:"));
        let frame_time_s: f64 = next().parse().unwrap();
        let values: Vec<f64> = std::iter::from_fn(|| tokens.next())
            .map(|v| v.parse().unwrap())
            .collect();
        assert_eq!(values.len(), count * channels_total, "values per frame");
        let frames = values
            .chunks(channels_total.max(1))
            .map(<[f64]>::to_vec)
            .collect();
        Bvh {
            joints,
            frame_time_s,
            frames,
        }
    }

    /// Index of the joint (or `NAME_end` end site) called `name`.
    pub fn index(&self, name: &str) -> usize {
        self.joints
            .iter()
            .position(|j| j.name == name)
            .unwrap_or_else(|| panic!("no joint {name}"))
    }

    /// World position of every joint and end site in frame `f` (file units and axes).
    pub fn positions(&self, f: usize) -> Vec<[f64; 3]> {
        let values = &self.frames[f];
        let mut pos = vec![[0.0; 3]; self.joints.len()];
        let mut rot: Vec<Mat> = vec![[[0.0; 3]; 3]; self.joints.len()];
        let identity = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        for (i, j) in self.joints.iter().enumerate() {
            let mut local = identity;
            let mut translation = j.offset;
            for (k, c) in j.channels.iter().enumerate() {
                let v = values[j.first_channel + k];
                let axis = c.chars().next().unwrap();
                match &c[1..] {
                    "position" => translation["XYZ".find(axis).unwrap()] = v,
                    "rotation" => local = mul(&local, &axis_rotation(axis, v)),
                    other => panic!("unknown channel {other}"),
                }
            }
            (pos[i], rot[i]) = match j.parent {
                None => (translation, local),
                Some(p) => {
                    let d = apply(&rot[p], translation);
                    (
                        std::array::from_fn(|a| pos[p][a] + d[a]),
                        mul(&rot[p], &local),
                    )
                }
            };
        }
        pos
    }
}
