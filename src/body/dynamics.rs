//! Forward dynamics of the simulated upper body: Featherstone's articulated-body algorithm
//! (ABA, O(n); Featherstone 2008, *Rigid Body Dynamics Algorithms*, §7.3) in reduced
//! coordinates, each of the 11 ball joints held as a unit quaternion with its angular
//! velocity in the child segment's frame, the pelvis fixed. Gravity enters as a fictitious
//! upward acceleration of the pelvis. The joint-space mass matrix comes from the
//! composite-rigid-body algorithm (CRBA, §6.2). [`Dynamics::step`] integrates with
//! semi-implicit (symplectic) Euler on the rotation group: w += dt·ẇ, then q ← q·exp(w·dt).
//! A joint's equation may carry implicit terms K·ẇ ([`Implicit`]: a PD loop stepped
//! implicitly), which the articulated pass folds into that joint's inertia.
//! Its energy error is first order in dt: at dt = 1e-4 s a passive body swinging for 1 s
//! drifts by 0.2 % of the energy it exchanges, a collapsing one that whips the sticks to
//! some 260 rad/s by 1.9 % (see the `energy_is_conserved` test).
//!
//! Conventions. Segment frame i = parent frame · translation(offset_i) · rotation(q_i), so
//! each segment's origin is its joint. Spatial vectors are Plücker coordinates
//! (angular; linear) expressed in a segment frame at its origin. A ball joint's motion
//! subspace is S = [I₃; 0] in the child frame, so its velocity is the child's angular
//! velocity relative to the parent, in child coordinates, and its generalised force is a
//! torque in child coordinates acting on the child with the reaction on the parent.

use super::model::BodyModel;
use super::skeleton::{JOINT_COUNT, Joint};
use crate::kit::Side;
use glam::{DMat3, DQuat, DVec3};

const N: usize = JOINT_COUNT;

/// Joint state: rotation of each joint relative to the rest pose and angular velocity of
/// each segment relative to its parent, expressed in the segment (child) frame, rad/s.
#[derive(Clone, Debug, PartialEq)]
pub struct State {
    /// Joint rotations (child frame to parent frame, relative to the rest pose), unit
    /// quaternions indexed by [`Joint::index`].
    pub q: [DQuat; N],
    /// Relative angular velocities, child frame, rad/s: q̇ = ½·q·(0, w).
    pub w: [DVec3; N],
}

impl State {
    /// The rest pose, at rest.
    pub fn rest() -> State {
        State {
            q: [DQuat::IDENTITY; N],
            w: [DVec3::ZERO; N],
        }
    }

    /// True when every rotation and velocity is finite.
    pub fn is_finite(&self) -> bool {
        self.q.iter().all(|q| q.is_finite()) && self.w.iter().all(|w| w.is_finite())
    }
}

/// An external force applied at a point of a segment (e.g. the drum pushing a stick tip).
#[derive(Clone, Copy, Debug)]
pub struct ExternalForce {
    /// The segment it acts on ([`Joint::index`]; out of range panics).
    pub segment: usize,
    /// Point of application, performer frame, m.
    pub point_world: DVec3,
    /// Force, performer frame, N.
    pub force_world: DVec3,
}

/// Spatial (6D) vector: motion (angular velocity, rad/s; linear velocity of the frame
/// origin, m/s — or accelerations) or force (moment about the origin, N·m; force, N).
///
/// The small operations on it, on [`SpatialInertia`] and on [`Transform`] are marked
/// `#[inline]`: called out of line, each handed its six numbers back through memory,
/// and reading them back stalled the articulated pass (the one-minute study's
/// simulation 4 % slower, bit for bit the same).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct SpatialVec {
    ang: DVec3,
    lin: DVec3,
}

impl SpatialVec {
    const ZERO: SpatialVec = SpatialVec::new(DVec3::ZERO, DVec3::ZERO);

    const fn new(ang: DVec3, lin: DVec3) -> SpatialVec {
        SpatialVec { ang, lin }
    }

    /// Motion cross product self ×ₘ m (self a velocity).
    #[inline]
    fn cross_motion(self, m: SpatialVec) -> SpatialVec {
        SpatialVec::new(
            self.ang.cross(m.ang),
            self.ang.cross(m.lin) + self.lin.cross(m.ang),
        )
    }

    /// Force cross product self ×* f (self a velocity).
    #[inline]
    fn cross_force(self, f: SpatialVec) -> SpatialVec {
        SpatialVec::new(
            self.ang.cross(f.ang) + self.lin.cross(f.lin),
            self.ang.cross(f.lin),
        )
    }

    /// Pairing of a motion and a force vector (power, W; or energy-like products).
    #[inline]
    fn dot(self, other: SpatialVec) -> f64 {
        self.ang.dot(other.ang) + self.lin.dot(other.lin)
    }
}

impl std::ops::Add for SpatialVec {
    type Output = SpatialVec;
    #[inline]
    fn add(self, o: SpatialVec) -> SpatialVec {
        SpatialVec::new(self.ang + o.ang, self.lin + o.lin)
    }
}

impl std::ops::Sub for SpatialVec {
    type Output = SpatialVec;
    #[inline]
    fn sub(self, o: SpatialVec) -> SpatialVec {
        SpatialVec::new(self.ang - o.ang, self.lin - o.lin)
    }
}

/// Symmetric 6×6 spatial inertia [A B; Bᵀ C] (motion to force): A kg·m², B kg·m, C kg.
#[derive(Clone, Copy, Debug, PartialEq)]
struct SpatialInertia {
    a: DMat3,
    b: DMat3,
    c: DMat3,
}

impl SpatialInertia {
    const ZERO: SpatialInertia = SpatialInertia {
        a: DMat3::ZERO,
        b: DMat3::ZERO,
        c: DMat3::ZERO,
    };

    /// A rigid body of `mass` with centre of mass at `com` and rotational inertia `inertia`
    /// about it, taken about the frame origin.
    fn rigid(mass: f64, com: DVec3, inertia: DMat3) -> SpatialInertia {
        let cx = skew(com);
        SpatialInertia {
            a: inertia - mass * cx * cx,
            b: mass * cx,
            c: DMat3::from_diagonal(DVec3::splat(mass)),
        }
    }

    #[inline]
    fn mul(&self, m: SpatialVec) -> SpatialVec {
        SpatialVec::new(
            self.a * m.ang + self.b * m.lin,
            self.b.transpose() * m.ang + self.c * m.lin,
        )
    }
}

impl std::ops::AddAssign for SpatialInertia {
    #[inline]
    fn add_assign(&mut self, o: SpatialInertia) {
        self.a += o.a;
        self.b += o.b;
        self.c += o.c;
    }
}

/// Cross-product matrix: skew(v)·u = v × u.
#[inline]
fn skew(v: DVec3) -> DMat3 {
    DMat3::from_cols(
        DVec3::new(0.0, v.z, -v.y),
        DVec3::new(-v.z, 0.0, v.x),
        DVec3::new(v.y, -v.x, 0.0),
    )
}

/// skew(v)·m, column by column as cross products (27 flops against a product's 45).
#[inline]
fn skew_mul(v: DVec3, m: DMat3) -> DMat3 {
    DMat3::from_cols(v.cross(m.x_axis), v.cross(m.y_axis), v.cross(m.z_axis))
}

/// m·skew(v) = −(skew(v)·mᵀ)ᵀ (skew(v) is antisymmetric).
#[inline]
fn mul_skew(m: DMat3, v: DVec3) -> DMat3 {
    -skew_mul(v, m.transpose()).transpose()
}

/// Plücker transform from a parent frame to a child frame whose origin sits at `r` (parent
/// coordinates) and whose axes are the parent's rotated by the joint: `e` maps parent
/// coordinates to child coordinates.
#[derive(Clone, Copy, Debug)]
struct Transform {
    e: DMat3,
    r: DVec3,
}

impl Transform {
    const IDENTITY: Transform = Transform {
        e: DMat3::IDENTITY,
        r: DVec3::ZERO,
    };

    /// A motion vector from parent to child coordinates.
    #[inline]
    fn motion(&self, m: SpatialVec) -> SpatialVec {
        SpatialVec::new(self.e * m.ang, self.e * (m.lin + m.ang.cross(self.r)))
    }

    /// A force vector from child to parent coordinates (the transpose of [`Self::motion`]).
    #[inline]
    fn force_to_parent(&self, f: SpatialVec) -> SpatialVec {
        let lin = self.e.transpose() * f.lin;
        SpatialVec::new(self.e.transpose() * f.ang + self.r.cross(lin), lin)
    }

    /// An inertia from child to parent coordinates, Xᵀ·I·X.
    fn inertia_to_parent(&self, i: &SpatialInertia) -> SpatialInertia {
        let (e, et, r) = (self.e, self.e.transpose(), self.r);
        let (a, b, c) = (et * i.a * e, et * i.b * e, et * i.c * e);
        let rxc = skew_mul(r, c);
        SpatialInertia {
            a: a - mul_skew(b, r) + skew_mul(r, b.transpose()) - mul_skew(rxc, r),
            b: b + rxc,
            c,
        }
    }

    /// A purely translational inertia [0 0; 0 C] (what an articulated inertia is after a
    /// ball joint) from child to parent coordinates, Xᵀ·I·X = [−r̃C′r̃ r̃C′; C′r̃ᵀ C′] with
    /// C′ = EᵀCE.
    #[inline]
    fn translational_inertia_to_parent(&self, c: DMat3) -> SpatialInertia {
        let c = self.e.transpose() * c * self.e;
        let rxc = skew_mul(self.r, c);
        SpatialInertia {
            a: -mul_skew(rxc, self.r),
            b: rxc,
            c,
        }
    }
}

/// Per-segment quantities of one pass over the tree, kept between calls so a step does not
/// allocate.
#[derive(Clone, Debug)]
struct Scratch {
    /// Parent-to-segment transform.
    x: [Transform; N],
    /// World-from-segment rotation.
    rot: [DMat3; N],
    /// Segment origin (its joint), performer frame, m.
    pos: [DVec3; N],
    /// Spatial velocity, segment frame.
    v: [SpatialVec; N],
    /// Velocity-product acceleration v × S·w, segment frame.
    c: [SpatialVec; N],
    /// Articulated inertia (ABA) or composite inertia (CRBA), segment frame.
    ia: [SpatialInertia; N],
    /// Articulated bias force, segment frame.
    pa: [SpatialVec; N],
    /// D⁻¹ = (Sᵀ·IA·S)⁻¹, 1/(kg·m²).
    d_inv: [DMat3; N],
    /// u = τ − Sᵀ·pA, N·m.
    u: [DVec3; N],
    /// Spatial acceleration of the latest articulated pass, segment frame (the pelvis
    /// accelerating upward in place of gravity).
    acc: [SpatialVec; N],
}

/// How a stick tip answers a force on it at the start of a step: its acceleration with no
/// force there (m/s², performer frame, gravity included) and the change of it per newton,
/// J·M⁻¹·Jᵀ (the inverse of the tip's operational-space inertia, 1/kg).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TipResponse {
    pub free: DVec3,
    pub mobility: DMat3,
}

/// What an articulated child passes to its parent: a translational block alone (a free ball
/// joint) or a whole spatial inertia (a joint with [`Implicit`] terms).
enum Child {
    Translational(DMat3),
    Full(SpatialInertia),
}

/// Terms K (N·m·s²/rad, 3×3 per joint, child frame) each joint's equation carries on its
/// acceleration, Sᵀ·(IA·a + pA) + K·ẇ = τ: a PD loop stepped implicitly over a step h
/// (stable PD, Tan, Liu & Turk 2011) has K = h·Kd + h²·Kp, the loop's torque at the end of
/// the step being τ − K·ẇ. Zero for a joint without them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Implicit(pub [DMat3; N]);

/// Forward dynamics of a [`BodyModel`].
#[derive(Clone, Debug)]
pub struct Dynamics {
    model: BodyModel,
    /// Gravity, performer frame, m/s².
    gravity: DVec3,
    /// Parent segment of each segment (`None`: the fixed pelvis).
    parent: [Option<usize>; N],
    /// Rigid-body spatial inertia of each segment about its joint, segment frame.
    inertia: [SpatialInertia; N],
    scratch: Scratch,
}

impl Dynamics {
    /// Dynamics of `model` under standard gravity.
    pub fn new(model: BodyModel) -> Dynamics {
        let inertia = model
            .segments
            .map(|s| SpatialInertia::rigid(s.mass_kg, s.com_m, s.inertia));
        Dynamics {
            model,
            gravity: DVec3::new(0.0, 0.0, -9.81),
            parent: Joint::ALL.map(|j| j.parent().map(Joint::index)),
            inertia,
            scratch: Scratch {
                x: [Transform::IDENTITY; N],
                rot: [DMat3::IDENTITY; N],
                pos: [DVec3::ZERO; N],
                v: [SpatialVec::ZERO; N],
                c: [SpatialVec::ZERO; N],
                ia: [SpatialInertia::ZERO; N],
                pa: [SpatialVec::ZERO; N],
                d_inv: [DMat3::IDENTITY; N],
                u: [DVec3::ZERO; N],
                acc: [SpatialVec::ZERO; N],
            },
        }
    }

    /// The simulated body.
    pub fn model(&self) -> &BodyModel {
        &self.model
    }

    /// Gravity, m/s² (default (0,0,−9.81)).
    pub fn set_gravity(&mut self, g: DVec3) {
        self.gravity = g;
    }

    /// Gravity, m/s².
    pub fn gravity(&self) -> DVec3 {
        self.gravity
    }

    /// First ABA pass: transforms, world placement, velocities and velocity products.
    fn kinematics(&mut self, state: &State) {
        let s = &mut self.scratch;
        for i in 0..N {
            let rq = DMat3::from_quat(state.q[i]);
            let offset = self.model.skeleton.offsets[i];
            let (rot_p, pos_p, v_p) = match self.parent[i] {
                Some(p) => (s.rot[p], s.pos[p], s.v[p]),
                None => (
                    DMat3::IDENTITY,
                    self.model.skeleton.trunk_origin,
                    SpatialVec::ZERO,
                ),
            };
            s.x[i] = Transform {
                e: rq.transpose(),
                r: offset,
            };
            s.rot[i] = rot_p * rq;
            s.pos[i] = pos_p + rot_p * offset;
            let vj = SpatialVec::new(state.w[i], DVec3::ZERO);
            s.v[i] = s.x[i].motion(v_p) + vj;
            s.c[i] = s.v[i].cross_motion(vj);
        }
    }

    /// Joint accelerations (d/dt of w, segment frame, rad/s²) for joint torques `tau` (N·m,
    /// segment/child frame, acting on the child, reaction on the parent) and external
    /// forces: Featherstone ABA, O(n).
    pub fn accelerations(
        &mut self,
        state: &State,
        tau: &[DVec3; N],
        external: &[ExternalForce],
    ) -> [DVec3; N] {
        self.kinematics(state);
        self.articulated(tau, external, None)
    }

    /// ABA passes two and three, after [`Self::kinematics`] of the state, each joint's
    /// equation carrying `implicit` (see [`Implicit`]).
    fn articulated(
        &mut self,
        tau: &[DVec3; N],
        external: &[ExternalForce],
        implicit: Option<&Implicit>,
    ) -> [DVec3; N] {
        let s = &mut self.scratch;
        s.ia = self.inertia;
        for i in 0..N {
            s.pa[i] = s.v[i].cross_force(self.inertia[i].mul(s.v[i]));
        }
        for f in external {
            let i = f.segment;
            let rt = s.rot[i].transpose();
            let force = rt * f.force_world;
            let point = rt * (f.point_world - s.pos[i]);
            s.pa[i] = s.pa[i] - SpatialVec::new(point.cross(force), force);
        }
        // Articulated inertias and bias forces, tips to root.
        for i in (0..N).rev() {
            let SpatialInertia { a, b, c } = s.ia[i];
            let u = tau[i] - s.pa[i].ang;
            let extra = implicit.map_or(DMat3::ZERO, |k| k.0[i]);
            let (d_inv, child, pa) = if extra == DMat3::ZERO {
                // Through a free ball joint only the translational block survives:
                // IA − U·D⁻¹·Uᵀ = [0 0; 0 C − Bᵀ·A⁻¹·B].
                let d_inv = a.inverse();
                let ia_c = c - b.transpose() * d_inv * b;
                // pA + Ia·c + U·D⁻¹·u with U = [A; Bᵀ] and Ia = [0 0; 0 Ia_c].
                let k = d_inv * u;
                let pa = s.pa[i] + SpatialVec::new(a * k, ia_c * s.c[i].lin + b.transpose() * k);
                (d_inv, Child::Translational(ia_c), pa)
            } else {
                // D = A + K: the joint's own terms keep a share of the rotational block.
                let d_inv = (a + extra).inverse();
                let (da, db) = (d_inv * a, d_inv * b);
                let ia = SpatialInertia {
                    a: a - a * da,
                    b: b - a * db,
                    c: c - b.transpose() * db,
                };
                let k = d_inv * u;
                let pa = s.pa[i] + ia.mul(s.c[i]) + SpatialVec::new(a * k, b.transpose() * k);
                (d_inv, Child::Full(ia), pa)
            };
            (s.d_inv[i], s.u[i]) = (d_inv, u);
            if let Some(p) = self.parent[i] {
                s.ia[p] += match child {
                    Child::Translational(ia_c) => s.x[i].translational_inertia_to_parent(ia_c),
                    Child::Full(ia) => s.x[i].inertia_to_parent(&ia),
                };
                s.pa[p] = s.pa[p] + s.x[i].force_to_parent(pa);
            }
        }
        // Accelerations, root to tips; the pelvis accelerates upward to model gravity.
        let acc = &mut s.acc;
        let mut qdd = [DVec3::ZERO; N];
        for i in 0..N {
            let a_p =
                self.parent[i].map_or(SpatialVec::new(DVec3::ZERO, -self.gravity), |p| acc[p]);
            let a = s.x[i].motion(a_p) + s.c[i];
            let SpatialInertia {
                a: ia_a, b: ia_b, ..
            } = s.ia[i];
            qdd[i] = s.d_inv[i] * (s.u[i] - ia_a * a.ang - ia_b * a.lin);
            acc[i] = a + SpatialVec::new(qdd[i], DVec3::ZERO);
        }
        qdd
    }

    /// The acceleration of a stick tip (m/s², performer frame) after an articulated pass:
    /// the classical acceleration of the tip point, a_O + α×r + ω×(v_O + ω×r), with the
    /// pass's upward pelvis acceleration taken back out (gravity included).
    fn tip_acceleration(&self, side: Side) -> DVec3 {
        let s = &self.scratch;
        let i = Joint::arm(side)[3].index();
        let r = self.tip_local();
        let (a, v) = (s.acc[i], s.v[i]);
        let local = a.lin + a.ang.cross(r) + v.ang.cross(v.lin + v.ang.cross(r));
        s.rot[i] * local + self.gravity
    }

    /// How the tip of `side`, at `tip` (m, performer frame), answers a force on it under
    /// joint torques `tau` (N·m), in the state of the latest kinematics pass: four
    /// articulated passes (none, and a newton along each axis).
    fn tip_response(
        &mut self,
        tau: &[DVec3; N],
        side: Side,
        tip: DVec3,
        implicit: Option<&Implicit>,
    ) -> TipResponse {
        let segment = Joint::arm(side)[3].index();
        self.articulated(tau, &[], implicit);
        let free = self.tip_acceleration(side);
        let column = |dynamics: &mut Dynamics, axis: DVec3| {
            let push = ExternalForce {
                segment,
                point_world: tip,
                force_world: axis,
            };
            dynamics.articulated(tau, &[push], implicit);
            dynamics.tip_acceleration(side) - free
        };
        let mobility = DMat3::from_cols(
            column(self, DVec3::X),
            column(self, DVec3::Y),
            column(self, DVec3::Z),
        );
        TipResponse { free, mobility }
    }

    /// One step of length dt (s): semi-implicit (symplectic) Euler — w += dt·ẇ, then
    /// q ← q·exp(w·dt) normalised.
    pub fn step(
        &mut self,
        state: &mut State,
        tau: &[DVec3; N],
        external: &[ExternalForce],
        dt: f64,
    ) {
        let qdd = self.accelerations(state, tau, external);
        integrate(state, &qdd, dt);
    }

    /// One step like [`Self::step`] with forces on the stick tips: `contact` gets both tips'
    /// position (m) and velocity (m/s) at the start of the step, performer frame, and a way
    /// to ask how a tip ([left, right] index) answers a force ([`TipResponse`], asked only
    /// when needed: it costs four articulated passes), and returns the force on each (N,
    /// performer frame), applied at the tip during the step. One kinematics pass serves
    /// all. With `implicit`, each joint's equation carries its terms (see [`Implicit`]).
    pub fn step_with_tip_forces(
        &mut self,
        state: &mut State,
        (tau, implicit): (&[DVec3; N], Option<&Implicit>),
        contact: impl FnOnce([(DVec3, DVec3); 2], &mut dyn FnMut(usize) -> TipResponse) -> [DVec3; 2],
        dt: f64,
    ) -> [(DVec3, DVec3); 2] {
        self.kinematics(state);
        let tips = self.tips_from_kinematics();
        let forces = contact(tips, &mut |h| {
            self.tip_response(tau, [Side::Left, Side::Right][h], tips[h].0, implicit)
        });
        let external: [ExternalForce; 2] = std::array::from_fn(|h| ExternalForce {
            segment: Joint::arm([Side::Left, Side::Right][h])[3].index(),
            point_world: tips[h].0,
            force_world: forces[h],
        });
        let external: &[ExternalForce] = match forces.map(|f| f != DVec3::ZERO) {
            [false, false] => &[],
            [true, false] => &external[..1],
            [false, true] => &external[1..],
            [true, true] => &external,
        };
        let qdd = self.articulated(tau, external, implicit);
        integrate(state, &qdd, dt);
        tips
    }

    /// Kinetic and gravitational potential energy, J (potential zero at the performer
    /// frame's origin).
    pub fn energy(&mut self, state: &State) -> (f64, f64) {
        self.kinematics(state);
        let s = &self.scratch;
        let (mut kinetic, mut potential) = (0.0, 0.0);
        for (i, seg) in self.model.segments.iter().enumerate() {
            kinetic += 0.5 * s.v[i].dot(self.inertia[i].mul(s.v[i]));
            potential -= seg.mass_kg * self.gravity.dot(s.pos[i] + s.rot[i] * seg.com_m);
        }
        (kinetic, potential)
    }

    /// World position (m) and velocity (m/s) of a point given in a segment's frame (m);
    /// `segment` is a [`Joint::index`].
    pub fn point_velocity(
        &mut self,
        state: &State,
        segment: usize,
        local: DVec3,
    ) -> (DVec3, DVec3) {
        self.kinematics(state);
        let s = &self.scratch;
        let v = s.v[segment];
        (
            s.pos[segment] + s.rot[segment] * local,
            s.rot[segment] * (v.lin + v.ang.cross(local)),
        )
    }

    /// Both stick tips, [left, right]: position (m) and velocity (m/s), performer frame,
    /// from one kinematics pass.
    pub fn tips(&mut self, state: &State) -> [(DVec3, DVec3); 2] {
        self.kinematics(state);
        self.tips_from_kinematics()
    }

    /// The stick tip in its grip segment's frame, m.
    fn tip_local(&self) -> DVec3 {
        DVec3::new(0.0, 0.0, -self.model.skeleton.stick_length_m)
    }

    fn tips_from_kinematics(&self) -> [(DVec3, DVec3); 2] {
        let s = &self.scratch;
        let local = self.tip_local();
        [Side::Left, Side::Right].map(|side| {
            let i = Joint::arm(side)[3].index();
            let v = s.v[i];
            (
                s.pos[i] + s.rot[i] * local,
                s.rot[i] * (v.lin + v.ang.cross(local)),
            )
        })
    }

    /// Stick tip of a side: position (m) and velocity (m/s), performer frame.
    pub fn tip(&mut self, state: &State, side: Side) -> (DVec3, DVec3) {
        let grip = Joint::arm(side)[3].index();
        let local = self.tip_local();
        self.point_velocity(state, grip, local)
    }

    /// Inverse dynamics by the recursive Newton–Euler algorithm, O(n): the joint torques
    /// (N·m, child frames) that give `state` the joint accelerations `qdd` (rad/s², child
    /// frames) under gravity, with no external force. With zero velocity and zero `qdd` it
    /// is gravity compensation. Each of the 11 joints is one forward and one backward
    /// visit (about a microsecond), so control can afford it every task step.
    pub fn inverse_dynamics(&mut self, state: &State, qdd: &[DVec3; N]) -> [DVec3; N] {
        self.kinematics(state);
        let s = &self.scratch;
        // Forward: spatial accelerations; the pelvis accelerates upward to model gravity.
        let mut acc = [SpatialVec::ZERO; N];
        let mut force = [SpatialVec::ZERO; N];
        for i in 0..N {
            let a_p =
                self.parent[i].map_or(SpatialVec::new(DVec3::ZERO, -self.gravity), |p| acc[p]);
            acc[i] = s.x[i].motion(a_p) + s.c[i] + SpatialVec::new(qdd[i], DVec3::ZERO);
            let inertia = &self.inertia[i];
            force[i] = inertia.mul(acc[i]) + s.v[i].cross_force(inertia.mul(s.v[i]));
        }
        // Backward: each joint carries its segment's force and everything beyond it.
        let mut tau = [DVec3::ZERO; N];
        for i in (0..N).rev() {
            tau[i] = force[i].ang;
            if let Some(p) = self.parent[i] {
                force[p] = force[p] + s.x[i].force_to_parent(force[i]);
            }
        }
        tau
    }

    /// Joint-space mass matrix (33×33, row-major, joint i's three coordinates at rows
    /// 3i..3i+3, kg·m²) by the composite-rigid-body algorithm; kinetic energy is ½·wᵀ·M·w
    /// with w stacked. The diagonal 3×3 blocks of its inverse give each joint's effective
    /// inverse inertia.
    pub fn mass_matrix(&mut self, state: &State) -> Vec<f64> {
        self.kinematics(state);
        let s = &mut self.scratch;
        s.ia = self.inertia;
        for i in (0..N).rev() {
            if let Some(p) = self.parent[i] {
                let child = s.x[i].inertia_to_parent(&s.ia[i]);
                s.ia[p] += child;
            }
        }
        let mut m = vec![0.0; 9 * N * N];
        let mut set = |row: usize, col: usize, block: DMat3| {
            for (k, column) in block.to_cols_array_2d().iter().enumerate() {
                for (l, value) in column.iter().enumerate() {
                    m[(3 * row + l) * 3 * N + 3 * col + k] = *value;
                }
            }
        };
        for i in 0..N {
            // Force on segment j's joint per unit acceleration of joint i: columns of F.
            let mut f: [SpatialVec; 3] =
                std::array::from_fn(|k| SpatialVec::new(s.ia[i].a.col(k), s.ia[i].b.row(k)));
            set(i, i, s.ia[i].a);
            let mut j = i;
            while let Some(p) = self.parent[j] {
                f = f.map(|fk| s.x[j].force_to_parent(fk));
                j = p;
                let block = DMat3::from_cols(f[0].ang, f[1].ang, f[2].ang);
                set(j, i, block);
                set(i, j, block.transpose());
            }
        }
        m
    }
}

/// Semi-implicit Euler: w += dt·ẇ, then q ← q·exp(w·dt) normalised.
fn integrate(state: &mut State, qdd: &[DVec3; N], dt: f64) {
    for ((q, w), a) in state.q.iter_mut().zip(&mut state.w).zip(qdd) {
        *w += dt * *a;
        *q = (*q * rotation_exp(*w * dt)).normalize();
    }
}

/// Turns smaller than this, rad², take [`rotation_exp`]'s series (0.1 rad: 1000 rad/s
/// over a 0.1 ms step).
const SERIES_TURN_SQUARED: f64 = 0.01;

/// The unit quaternion of the rotation vector `v` (axis · angle θ, rad): (cos(θ/2),
/// v·sin(θ/2)/θ). A step's turn is small, so both come from their Taylor series in
/// (θ/2)², needing neither the square root nor a sine and cosine (to the first omitted
/// term, (θ/2)¹⁰/10! < 3e-19 below 0.1 rad: exact to rounding); larger turns take the
/// closed form.
fn rotation_exp(v: DVec3) -> DQuat {
    let theta2 = v.length_squared();
    if theta2 > SERIES_TURN_SQUARED {
        return DQuat::from_scaled_axis(v);
    }
    let h2 = 0.25 * theta2;
    let cos = 1.0 - h2 / 2.0 * (1.0 - h2 / 12.0 * (1.0 - h2 / 30.0 * (1.0 - h2 / 56.0)));
    let sin_over_theta =
        0.5 * (1.0 - h2 / 6.0 * (1.0 - h2 / 20.0 * (1.0 - h2 / 42.0 * (1.0 - h2 / 72.0))));
    let axis = v * sin_over_theta;
    DQuat::from_xyzw(axis.x, axis.y, axis.z, cos)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::rng::Rng;

    /// The cross-product forms of skew(v)·m and m·skew(v) are the matrix products.
    #[test]
    fn skew_products_by_cross_products() {
        let v = DVec3::new(0.3, -1.2, 0.7);
        let m = DMat3::from_cols_array(&[1.0, -2.0, 0.5, 3.0, 0.25, -1.5, 2.0, 4.0, -0.75]);
        let near = |a: DMat3, b: DMat3| a.abs_diff_eq(b, 1e-12);
        assert!(near(skew_mul(v, m), skew(v) * m));
        assert!(near(mul_skew(m, v), m * skew(v)));
    }

    const DOF: usize = 3 * N;

    fn dynamics() -> Dynamics {
        Dynamics::new(BodyModel::default())
    }

    fn random_vec(rng: &mut Rng, scale: f64) -> DVec3 {
        DVec3::new(
            rng.uniform(-1.0, 1.0),
            rng.uniform(-1.0, 1.0),
            rng.uniform(-1.0, 1.0),
        ) * scale
    }

    /// A random state: rotations up to about 1 rad per joint, velocities up to `speed` rad/s.
    fn random_state(rng: &mut Rng, speed: f64) -> State {
        let mut state = State::rest();
        for i in 0..N {
            state.q[i] = DQuat::from_scaled_axis(random_vec(rng, 0.6));
            state.w[i] = random_vec(rng, speed);
        }
        state
    }

    fn flatten(v: &[DVec3; N]) -> Vec<f64> {
        v.iter().flat_map(|x| x.to_array()).collect()
    }

    /// Solves the dense system a·x = b by Gaussian elimination with partial pivoting.
    fn solve(mut a: Vec<f64>, mut b: Vec<f64>) -> Vec<f64> {
        let n = b.len();
        for k in 0..n {
            let pivot = (k..n)
                .max_by(|&r, &s| a[r * n + k].abs().total_cmp(&a[s * n + k].abs()))
                .unwrap();
            for c in 0..n {
                a.swap(k * n + c, pivot * n + c);
            }
            b.swap(k, pivot);
            for r in k + 1..n {
                let factor = a[r * n + k] / a[k * n + k];
                for c in k..n {
                    a[r * n + c] -= factor * a[k * n + c];
                }
                b[r] -= factor * b[k];
            }
        }
        for k in (0..n).rev() {
            let tail: f64 = (k + 1..n).map(|c| a[k * n + c] * b[c]).sum();
            b[k] = (b[k] - tail) / a[k * n + k];
        }
        b
    }

    /// Largest absolute entry.
    fn max_abs(v: &[f64]) -> f64 {
        v.iter().fold(0.0, |m, x| m.max(x.abs()))
    }

    /// Central finite difference of `f` along each joint coordinate, q_i ← q_i·exp(ε·e_k)
    /// (the coordinates whose rates are w).
    fn gradient<T: Copy>(
        state: &State,
        mut f: impl FnMut(&State) -> T,
        sub: impl Fn(T, T) -> Vec<f64>,
    ) -> Vec<Vec<f64>> {
        let eps = 1e-6;
        (0..DOF)
            .map(|d| {
                let axis = DVec3::AXES[d % 3];
                let mut plus = state.clone();
                let mut minus = state.clone();
                plus.q[d / 3] = state.q[d / 3] * DQuat::from_scaled_axis(axis * eps);
                minus.q[d / 3] = state.q[d / 3] * DQuat::from_scaled_axis(-axis * eps);
                sub(f(&plus), f(&minus))
                    .into_iter()
                    .map(|x| x / (2.0 * eps))
                    .collect()
            })
            .collect()
    }

    /// The series exponential equals the closed form to 1e-16 for turns up to its limit
    /// and takes the closed form beyond.
    #[test]
    fn small_turns_exponentiate_exactly() {
        let mut rng = Rng::new(21);
        for scale in [1e-9, 1e-6, 1e-3, 0.02, 0.057, 0.2, 2.0] {
            for _ in 0..200 {
                let v = random_vec(&mut rng, scale);
                let (a, b) = (rotation_exp(v), DQuat::from_scaled_axis(v));
                assert!((a - b).length() < 1e-16, "{v}: {a} vs {b}");
                assert!((a.length() - 1.0).abs() < 1e-15);
            }
        }
        assert_eq!(rotation_exp(DVec3::ZERO), DQuat::IDENTITY);
    }

    /// Newton–Euler inverse dynamics inverts the articulated-body forward dynamics: the
    /// torques it gives for random accelerations produce those accelerations (1e-9 rad/s²).
    #[test]
    fn newton_euler_inverts_forward_dynamics() {
        let mut rng = Rng::new(11);
        let mut d = dynamics();
        for _ in 0..20 {
            let state = random_state(&mut rng, 3.0);
            let qdd: [DVec3; N] = std::array::from_fn(|_| random_vec(&mut rng, 20.0));
            let tau = d.inverse_dynamics(&state, &qdd);
            let back = d.accelerations(&state, &tau, &[]);
            let err = max_abs(
                &flatten(&back)
                    .iter()
                    .zip(flatten(&qdd))
                    .map(|(a, b)| a - b)
                    .collect::<Vec<_>>(),
            );
            assert!(err < 1e-9, "{err}");
        }
    }

    /// A passive body swinging under gravity from a bent, moving pose (joints turned up to
    /// 0.6 rad, moving at up to 1.5 rad/s) keeps its energy over 1 s: the total drifts by
    /// less than 0.5 % of the kinetic energy's range. With the trunk starting upright
    /// (dt = 1e-4 s) the drift is 0.19 %; with it tilted the body collapses and whips the
    /// sticks to some 260 rad/s, and the drift, first order in dt, is 1.9 % at dt = 1e-4 s and
    /// 0.32 % at the dt = 2.5e-5 s used here.
    #[test]
    fn energy_is_conserved() {
        for (trunk_tilt, dt) in [(0.0, 1e-4), (1.0, 2.5e-5f64)] {
            let mut dynamics = dynamics();
            let mut state = random_state(&mut Rng::new(7), 1.5);
            let trunk = state.q[0].to_scaled_axis();
            state.q[0] = DQuat::from_scaled_axis(trunk * trunk_tilt);
            let zero = [DVec3::ZERO; N];
            let (k0, p0) = dynamics.energy(&state);
            let (mut k_min, mut k_max, mut drift) = (k0, k0, 0.0f64);
            for _ in 0..(1.0 / dt).round() as usize {
                dynamics.step(&mut state, &zero, &[], dt);
                let (k, p) = dynamics.energy(&state);
                (k_min, k_max) = (k_min.min(k), k_max.max(k));
                drift = drift.max((k + p - k0 - p0).abs());
            }
            let range = k_max - k_min;
            assert!(range > 100.0, "the test must exchange energy: {range} J");
            assert!(
                drift < 0.005 * range,
                "dt {dt}: drift {drift} J of range {range} J"
            );
        }
    }

    /// ABA agrees with solving M·q̈ = τ − C (CRBA mass matrix, C from ABA at τ = 0) for
    /// random states and torques, to 1e-9 relative (max norm).
    #[test]
    fn aba_matches_mass_matrix() {
        let mut dynamics = dynamics();
        let mut rng = Rng::new(11);
        for _ in 0..20 {
            let state = random_state(&mut rng, 3.0);
            let tau: [DVec3; N] = std::array::from_fn(|_| random_vec(&mut rng, 5.0));
            let free = flatten(&dynamics.accelerations(&state, &[DVec3::ZERO; N], &[]));
            let aba = flatten(&dynamics.accelerations(&state, &tau, &[]));
            let m = dynamics.mass_matrix(&state);
            for r in 0..DOF {
                for c in 0..DOF {
                    assert!((m[r * DOF + c] - m[c * DOF + r]).abs() < 1e-12);
                }
            }
            let forced = solve(m, flatten(&tau));
            let expected: Vec<f64> = free.iter().zip(&forced).map(|(a, b)| a + b).collect();
            let error: Vec<f64> = aba.iter().zip(&expected).map(|(a, b)| a - b).collect();
            assert!(max_abs(&error) < 1e-9 * max_abs(&aba), "{error:?}");
        }
    }

    /// With implicit terms K (symmetric, positive, per joint) the articulated pass solves
    /// (M + K)·ẇ = τ + M·ẇ_free: the joints' own terms added to the mass matrix's diagonal
    /// blocks, as an implicit PD step needs.
    #[test]
    fn implicit_terms_add_to_the_mass_matrix() {
        let mut dynamics = dynamics();
        let mut rng = Rng::new(13);
        for _ in 0..20 {
            let state = random_state(&mut rng, 3.0);
            let tau: [DVec3; N] = std::array::from_fn(|_| random_vec(&mut rng, 5.0));
            let implicit = Implicit(std::array::from_fn(|j| {
                if j % 4 == 0 {
                    return DMat3::ZERO;
                }
                let a = DMat3::from_cols(
                    random_vec(&mut rng, 0.2),
                    random_vec(&mut rng, 0.2),
                    random_vec(&mut rng, 0.2),
                );
                a * a.transpose()
            }));
            let free = flatten(&dynamics.accelerations(&state, &[DVec3::ZERO; N], &[]));
            dynamics.kinematics(&state);
            let qdd = flatten(&dynamics.articulated(&tau, &[], Some(&implicit)));
            let m = dynamics.mass_matrix(&state);
            let residual: Vec<f64> = (0..DOF)
                .map(|r| {
                    let (j, row) = (r / 3, r % 3);
                    let k = implicit.0[j].row(row);
                    let mk: f64 = (0..DOF).map(|c| m[r * DOF + c] * qdd[c]).sum::<f64>()
                        + (0..3).map(|c| k[c] * qdd[3 * j + c]).sum::<f64>();
                    let rhs =
                        flatten(&tau)[r] + (0..DOF).map(|c| m[r * DOF + c] * free[c]).sum::<f64>();
                    mk - rhs
                })
                .collect();
            assert!(
                max_abs(&residual) < 1e-9 * max_abs(&flatten(&tau)),
                "{residual:?}"
            );
        }
    }

    /// The mass matrix is the Hessian of kinetic energy in w: ½·wᵀ·M·w equals the kinetic
    /// energy to 1e-12 relative.
    #[test]
    fn mass_matrix_gives_kinetic_energy() {
        let mut dynamics = dynamics();
        let state = random_state(&mut Rng::new(5), 2.0);
        let m = dynamics.mass_matrix(&state);
        let w = flatten(&state.w);
        let quadratic: f64 = (0..DOF)
            .map(|r| (0..DOF).map(|c| w[r] * m[r * DOF + c] * w[c]).sum::<f64>())
            .sum();
        let (kinetic, _) = dynamics.energy(&state);
        assert!(
            (0.5 * quadratic - kinetic).abs() < 1e-12 * kinetic,
            "{quadratic} {kinetic}"
        );
    }

    /// At rest, forces of −m·g at every centre of mass cancel gravity exactly (|q̈| < 1e-9
    /// rad/s²), in any pose.
    #[test]
    fn gravity_cancelled_at_centres_of_mass() {
        let mut dynamics = dynamics();
        let mut state = random_state(&mut Rng::new(3), 0.0);
        state.q[Joint::ShoulderR.index()] = DQuat::from_rotation_x(std::f64::consts::FRAC_PI_2);
        let g = dynamics.gravity();
        let segments = dynamics.model().segments;
        let external: Vec<ExternalForce> = (0..N)
            .map(|i| ExternalForce {
                segment: i,
                point_world: dynamics.point_velocity(&state, i, segments[i].com_m).0,
                force_world: -segments[i].mass_kg * g,
            })
            .collect();
        let qdd = dynamics.accelerations(&state, &[DVec3::ZERO; N], &external);
        assert!(max_abs(&flatten(&qdd)) < 1e-9, "{qdd:?}");
        let falling = dynamics.accelerations(&state, &[DVec3::ZERO; N], &[]);
        assert!(max_abs(&flatten(&falling)) > 1.0);
    }

    /// Released from rest, the generalised gravity force M·q̈ equals −∂V/∂q (finite
    /// differences of the potential energy; the Lagrangian at zero velocity), 1e-6 relative.
    #[test]
    fn gravity_matches_potential_gradient() {
        let mut dynamics = dynamics();
        let mut state = random_state(&mut Rng::new(9), 0.0);
        state.q[Joint::ShoulderR.index()] = DQuat::from_rotation_x(std::f64::consts::FRAC_PI_2);
        let qdd = flatten(&dynamics.accelerations(&state, &[DVec3::ZERO; N], &[]));
        let m = dynamics.mass_matrix(&state);
        let generalised: Vec<f64> = (0..DOF)
            .map(|r| (0..DOF).map(|c| m[r * DOF + c] * qdd[c]).sum())
            .collect();
        let grad = gradient(&state, |s| dynamics.energy(s).1, |a, b| vec![a - b]);
        let error: Vec<f64> = (0..DOF).map(|d| generalised[d] + grad[d][0]).collect();
        assert!(max_abs(&error) < 1e-6 * max_abs(&generalised), "{error:?}");
    }

    /// A force at the right stick tip, at rest without gravity, accelerates the tip along
    /// J·M⁻¹·Jᵀ·F (J by finite differences of the tip position), 1e-6 relative, with a·F > 0.
    #[test]
    fn tip_force_matches_operational_inertia() {
        let mut dynamics = dynamics();
        dynamics.set_gravity(DVec3::ZERO);
        let mut state = random_state(&mut Rng::new(13), 0.0);
        state.q[Joint::ShoulderR.index()] = DQuat::from_rotation_x(1.2);
        let (tip, _) = dynamics.tip(&state, Side::Right);
        let force = DVec3::new(0.3, -1.0, 2.0);
        let external = [ExternalForce {
            segment: Joint::GripR.index(),
            point_world: tip,
            force_world: force,
        }];
        let qdd = flatten(&dynamics.accelerations(&state, &[DVec3::ZERO; N], &external));
        let jacobian: Vec<DVec3> = gradient(
            &state,
            |s| dynamics.tip(s, Side::Right).0,
            |a, b| (a - b).to_array().to_vec(),
        )
        .iter()
        .map(|column| DVec3::from_slice(column))
        .collect();
        let j_times = |x: &[f64]| jacobian.iter().zip(x).map(|(c, x)| *c * *x).sum::<DVec3>();
        let accel = j_times(&qdd);
        assert!(accel.dot(force) > 0.0);
        let generalised = jacobian.iter().map(|c| c.dot(force)).collect();
        let expected = j_times(&solve(dynamics.mass_matrix(&state), generalised));
        assert!(
            (accel - expected).length() < 1e-6 * expected.length(),
            "{accel} vs {expected}"
        );
    }

    /// Power balance: along the exact state derivative, dE/dt equals Σ τ·w plus the power of
    /// the external force (finite differences, 1e-6 relative) — checks the torque and
    /// velocity-product conventions.
    #[test]
    fn power_balance() {
        let mut dynamics = dynamics();
        let mut rng = Rng::new(17);
        let state = random_state(&mut rng, 2.0);
        let tau: [DVec3; N] = std::array::from_fn(|_| random_vec(&mut rng, 5.0));
        let (tip, tip_velocity) = dynamics.tip(&state, Side::Left);
        let force = DVec3::new(-4.0, 1.0, 3.0);
        let external = [ExternalForce {
            segment: Joint::GripL.index(),
            point_world: tip,
            force_world: force,
        }];
        let qdd = dynamics.accelerations(&state, &tau, &external);
        let h = 1e-6;
        let mut total_energy = |sign: f64| {
            let s = State {
                q: std::array::from_fn(|i| {
                    state.q[i] * DQuat::from_scaled_axis(sign * h * state.w[i])
                }),
                w: std::array::from_fn(|i| state.w[i] + sign * h * qdd[i]),
            };
            let (k, p) = dynamics.energy(&s);
            k + p
        };
        let rate = (total_energy(1.0) - total_energy(-1.0)) / (2.0 * h);
        let power: f64 = tau
            .iter()
            .zip(&state.w)
            .map(|(t, w)| t.dot(*w))
            .sum::<f64>()
            + force.dot(tip_velocity);
        assert!(
            (rate - power).abs() < 1e-6 * power.abs(),
            "{rate} vs {power}"
        );
    }

    /// 1000 random bounded states and torques (with tip forces) give finite accelerations
    /// and finite stepped states.
    #[test]
    fn no_nan() {
        let mut dynamics = dynamics();
        let mut rng = Rng::new(23);
        for _ in 0..1000 {
            let mut state = random_state(&mut rng, 20.0);
            for q in &mut state.q {
                *q = DQuat::from_scaled_axis(random_vec(&mut rng, std::f64::consts::PI));
            }
            let tau: [DVec3; N] = std::array::from_fn(|_| random_vec(&mut rng, 50.0));
            let external = [ExternalForce {
                segment: Joint::GripR.index(),
                point_world: random_vec(&mut rng, 2.0),
                force_world: random_vec(&mut rng, 100.0),
            }];
            let qdd = dynamics.accelerations(&state, &tau, &external);
            assert!(qdd.iter().all(|a| a.is_finite()));
            dynamics.step(&mut state, &tau, &external, 1e-4);
            assert!(state.is_finite());
        }
        let mut broken = State::rest();
        broken.w[4].y = f64::NAN;
        assert!(!broken.is_finite() && State::rest().is_finite());
    }

    /// The same inputs give bit-identical trajectories, also from a fresh instance.
    #[test]
    fn deterministic() {
        let run = || {
            let mut dynamics = dynamics();
            let mut rng = Rng::new(29);
            let mut state = random_state(&mut rng, 2.0);
            let tau: [DVec3; N] = std::array::from_fn(|_| random_vec(&mut rng, 2.0));
            for _ in 0..500 {
                dynamics.step(&mut state, &tau, &[], 1e-4);
            }
            state
        };
        let (a, b) = (run(), run());
        let bits = |s: &State| -> Vec<u64> {
            let q = s.q.iter().flat_map(|q| q.to_array());
            q.chain(s.w.iter().flat_map(|w| w.to_array()))
                .map(f64::to_bits)
                .collect()
        };
        assert_eq!(bits(&a), bits(&b));
    }
}
