//! Every head of a kit stepped at the simulation rate with the two stick tips in contact
//! (seed 000 eqs. 5–6), two-way: each tip's Hertz force F = k·c^α, with
//! c = (head surface + d(x)) − (tip − felt radius) and d(x) = Σ q_k Φ_k(x), pushes the
//! membrane modes down (generalised force −F·Φ_k(x)) and the stick up, so the stick
//! rebounds physically and a strike on a ringing head feels its motion.
//!
//! A head no tip comes near (its free-ringing bound below the tip) is not stepped: it
//! lags and is caught up when it is needed — at each membrane frame by one exact step
//! over the whole frame, or step by step when a tip comes near — which equals stepping it
//! every step to rounding and takes the drums' share of a render from ~1.4 s to ~0.35 s
//! on the one-minute study.
//!
//! Each mode is advanced by its exact (ZOH) step with the force held over the step. The
//! force is implicit in the contact: the one that satisfies F = k·c^α with c the
//! compression at the *end* of the step, predicted from the modes' exact response to F
//! and the tip moving on with its velocity (plus F·dt²/m_eff, m_eff from
//! [`effective_mass_kg`](super::contact::effective_mass_kg)). An explicit force (from the
//! start-of-step state) gained energy when a stick rested on the head and blew up. Modes at or
//! above the simulation's Nyquist frequency (f ≥ 1/(2·dt)) are left out of the mechanical
//! coupling — they would alias — but still sound: the audio voices (48 kHz) take every
//! mode below the audio Nyquist, driven by the recorded force.

use super::contact::HertzContact;
use super::modes::HeadModes;
use super::oscillator::ModeStep;
use super::{DrumError, ModeConfig};
use crate::base::chunks::SharedChunks;
use crate::kit::{Kit, Mallet, Retune, Side};
use glam::{DVec2, DVec3};
use std::sync::Arc;

/// One touch of a stick tip on a head, from the first step with force to the first
/// step without.
#[derive(Clone, Debug, PartialEq)]
pub struct ContactEvent {
    pub side: Side,
    /// Drum index in the kit.
    pub drum: usize,
    /// Time of the first step with force, s.
    pub start_s: f64,
    /// Time of the first step without force (for a contact still going on: the end of
    /// the latest step), s.
    pub end_s: f64,
    /// Largest force during the contact, N.
    pub peak_force_n: f64,
    /// Downward tip speed at first touch, m/s (≥ 0).
    pub impact_speed_mps: f64,
    /// Where the tip first touched: the point on the resting head under the tip,
    /// performer frame, m.
    pub point: DVec3,
}

impl ContactEvent {
    /// Contact duration, s.
    pub fn duration_s(&self) -> f64 {
        self.end_s - self.start_s
    }
}

/// The force one tip put on one head during one step: what drives the sound.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Excitation {
    /// Step index (0 = the first call of [`DrumSet::step`]).
    pub step: u64,
    /// Time of the step, s (force held from `time_s` to `time_s + dt`).
    pub time_s: f64,
    pub drum: usize,
    pub side: Side,
    /// Contact point in head-local coordinates (see [`HeadModes::local`]), m.
    pub point: DVec2,
    /// Force pressing the head down, N (> 0).
    pub force_n: f64,
}

/// A head's mechanics at one tuning (its pedal setting).
#[derive(Debug)]
struct Tuning {
    /// Score time from which it holds, s (−∞ for the tuning the performance starts at).
    from_s: f64,
    /// The modes at this tuning: the same modes in the same order as the head's first
    /// (their shapes do not depend on the tension), ringing at other frequencies.
    modes: HeadModes,
    steps: Vec<ModeStep>,
    frame_steps: Vec<ModeStep>,
}

/// One head's mechanical state: the modes below the simulation Nyquist frequency.
#[derive(Clone, Debug)]
struct Head {
    /// The modes at the first tuning: where the head is and its mode shapes.
    modes: HeadModes,
    /// Every tuning of the performance, in time order (pedal changes: [`Retune`]), and
    /// the one `steps` and `frame_steps` hold.
    tunings: Arc<Vec<Tuning>>,
    tuning: usize,
    /// Indices (into `modes.modes()`) of the coupled modes.
    coupled: Vec<usize>,
    steps: Vec<ModeStep>,
    inv_mass: Vec<f64>,
    /// Each coupled mode's exact step over a whole membrane frame
    /// ([`MEMBRANE_FRAME_STEPS`] steps).
    frame_steps: Vec<ModeStep>,
    /// State per coupled mode: (ω₀·q, q̇), m/s, `lag` steps behind the set.
    x: Vec<[f64; 2]>,
    /// Steps the state lags behind: a head no tip comes near rings freely and is caught
    /// up only when it is needed (at each membrane frame, or when a tip comes near).
    lag: u64,
    /// Σ |x_k|/ω₀ ≥ |d(x)| anywhere on the head (|Φ| ≤ 1), m, for as long as it rings
    /// freely (|x_k|² is twice the mode's energy per unit modal mass, which damping only
    /// takes away): a cheap "far above" test.
    bound_m: f64,
}

impl Head {
    /// `drum`'s head at rest, its modes below the Nyquist frequency of a step of `dt_s`
    /// coupled.
    fn new(drum: &crate::kit::Drum, config: &ModeConfig, dt_s: f64) -> Result<Head, DrumError> {
        let nyquist = 0.5 / dt_s;
        let modes = HeadModes::new(drum, config)?;
        let coupled: Vec<usize> = (0..modes.modes().len())
            .filter(|&k| modes.modes()[k].freq_hz < nyquist)
            .collect();
        let inv_mass = coupled
            .iter()
            .map(|&k| 1.0 / modes.modes()[k].modal_mass_kg)
            .collect();
        let first = Tuning::of(modes.clone(), &coupled, f64::NEG_INFINITY, dt_s);
        Ok(Head {
            x: vec![[0.0; 2]; coupled.len()],
            lag: 0,
            steps: first.steps.clone(),
            frame_steps: first.frame_steps.clone(),
            tunings: Arc::new(vec![first]),
            tuning: 0,
            modes,
            coupled,
            inv_mass,
            bound_m: 0.0,
        })
    }

    /// Hold tuning `k` from now on (the state is left as it is).
    fn set_tuning(&mut self, k: usize) {
        if k != self.tuning {
            self.tuning = k;
            self.steps.clone_from(&self.tunings[k].steps);
            self.frame_steps.clone_from(&self.tunings[k].frame_steps);
        }
    }

    /// At score time `time_s`, s: a pedal change that has come is carried out — the
    /// head rung up to now at its old tuning, then damped to rest (the player stops it
    /// before moving the pedal) and retuned.
    fn retune_at(&mut self, time_s: f64) {
        let Some(next) = self.tunings.get(self.tuning + 1) else {
            return;
        };
        if next.from_s > time_s {
            return;
        }
        self.catch_up();
        let due = self.tunings.iter().rposition(|t| t.from_s <= time_s);
        self.set_tuning(due.unwrap_or(0));
        self.x.fill([0.0; 2]);
        self.bound_m = 0.0;
    }

    /// Ring freely up to the set's step: the state `lag` steps on, by one exact step over
    /// the whole frame when it lags exactly a frame.
    fn catch_up(&mut self) {
        if self.lag == MEMBRANE_FRAME_STEPS {
            for (x, s) in self.x.iter_mut().zip(&self.frame_steps) {
                *x = s.advance(*x, 0.0);
            }
        } else {
            for _ in 0..self.lag {
                for (x, s) in self.x.iter_mut().zip(&self.steps) {
                    *x = s.advance(*x, 0.0);
                }
            }
        }
        if self.lag > 0 {
            self.lag = 0;
            self.bound_m = self.energy_bound();
        }
    }

    /// Σ |x_k|/ω₀, m (see `bound_m`).
    fn energy_bound(&self) -> f64 {
        self.x
            .iter()
            .zip(&self.steps)
            // Not `hypot`: these magnitudes can neither overflow nor underflow, and libm's
            // careful hypot cost ~1 % of a render.
            .map(|(x, s)| (x[0] * x[0] + x[1] * x[1]).sqrt() / s.omega0)
            .sum()
    }

    fn displacement(&self, shapes: &[f64]) -> f64 {
        self.coupled
            .iter()
            .zip(&self.x)
            .zip(&self.steps)
            .map(|((&k, x), s)| x[0] / s.omega0 * shapes[k])
            .sum()
    }
}

impl Tuning {
    /// The exact steps of the `coupled` modes of `modes` over one step of `dt_s` and over
    /// a membrane frame, holding from `from_s`.
    fn of(modes: HeadModes, coupled: &[usize], from_s: f64, dt_s: f64) -> Tuning {
        let step_over = |dt: f64| -> Vec<ModeStep> {
            coupled
                .iter()
                .map(|&k| {
                    let m = &modes.modes()[k];
                    ModeStep::new(m.freq_hz, m.t60_s, dt)
                })
                .collect()
        };
        Tuning {
            steps: step_over(dt_s),
            frame_steps: step_over(MEMBRANE_FRAME_STEPS as f64 * dt_s),
            from_s,
            modes,
        }
    }
}

/// A [`DrumSet`]'s state at one step, without its history (which it only truncates).
#[derive(Clone, Debug, PartialEq)]
pub struct DrumCheckpoint {
    step: u64,
    /// Per head: the coupled modes' states, their lag, their bound and its tuning.
    heads: Vec<(Vec<[f64; 2]>, u64, f64, usize)>,
    contacts: usize,
    /// Each tip's ongoing contact as it was.
    open: [Option<(usize, ContactEvent)>; 2],
    excitation: usize,
    membrane: usize,
}

impl DrumCheckpoint {
    /// Contacts started before the checkpoint.
    pub fn contacts(&self) -> usize {
        self.contacts
    }
}

/// Every head of a kit with both stick tips; `Clone` is the snapshot for re-simulation.
#[derive(Clone, Debug)]
pub struct DrumSet {
    dt_s: f64,
    config: ModeConfig,
    law: HertzContact,
    /// The tip's effective mass used to predict its motion over a step, kg.
    tip_mass_kg: f64,
    heads: Vec<Head>,
    step: u64,
    contacts: Vec<ContactEvent>,
    /// Index in `contacts` of each tip's ongoing contact.
    open: [Option<usize>; 2],
    excitation: Vec<Excitation>,
    /// Scratch: mode shapes under each tip.
    shapes: [Vec<f64>; 2],
    /// Time of step 0, s.
    first_time_s: f64,
    /// Every [`MEMBRANE_FRAME_STEPS`] steps from step 0, each head's coupled mode
    /// displacements q_k (m), heads one after another: the membranes' motion to show,
    /// in chunks of whole frames shared with the set's clones (a rendering handed over
    /// while the performance goes on does not copy it).
    membrane: SharedChunks<f32>,
    /// Scratch: whether a tip came near each head this step.
    near: Vec<bool>,
    /// The pedal changes the heads carry out, in time order.
    retunes: Vec<Retune>,
}

/// Steps between recorded membrane frames (10 ms at 10 kHz).
pub const MEMBRANE_FRAME_STEPS: u64 = 100;
/// Membrane frames per shared chunk of the record (1 s at 10 kHz).
const MEMBRANE_CHUNK_FRAMES: usize = 100;

const SIDES: [Side; 2] = [Side::Left, Side::Right];

impl DrumSet {
    /// Every drum of `kit` at rest, struck with `mallet`, stepped every `dt_s` seconds.
    pub fn new(
        kit: &Kit,
        mallet: &Mallet,
        config: &ModeConfig,
        dt_s: f64,
    ) -> Result<DrumSet, DrumError> {
        if !(dt_s.is_finite() && dt_s > 0.0) {
            return Err(DrumError::TimeStep(dt_s));
        }
        let law = HertzContact::of(mallet)?;
        // Each head on its own thread: building a head's modes (Bessel zeros and radial
        // tables) is most of a fresh render's set-up, and the heads share nothing.
        let heads = crate::base::parallel::each(&kit.drums, |drum| Head::new(drum, config, dt_s))
            .into_iter()
            .collect::<Result<Vec<_>, DrumError>>()?;
        let heads_len = heads.len();
        let per_frame: usize = heads.iter().map(|h| h.coupled.len()).sum();
        let most = heads
            .iter()
            .map(|h| h.modes.modes().len())
            .max()
            .unwrap_or(0);
        Ok(DrumSet {
            dt_s,
            config: *config,
            law,
            tip_mass_kg: super::contact::effective_mass_kg(mallet),
            heads,
            step: 0,
            contacts: Vec::new(),
            open: [None, None],
            excitation: Vec::new(),
            shapes: [vec![0.0; most], vec![0.0; most]],
            first_time_s: 0.0,
            membrane: SharedChunks::new(per_frame * MEMBRANE_CHUNK_FRAMES),
            near: vec![false; heads_len],
            retunes: Vec::new(),
        })
    }

    /// This set (at rest, before its first step) carrying out the pedal changes
    /// `retunes` of `kit`'s drums (the kit it was built from): at each, the head is
    /// damped to rest and retuned ([`Drum::retuned`](crate::kit::Drum::retuned)).
    pub fn retuned(mut self, kit: &Kit, retunes: &[Retune]) -> Result<DrumSet, DrumError> {
        let mut retunes = retunes.to_vec();
        retunes.retain(|r| r.drum < self.heads.len());
        retunes.sort_by(|a, b| a.at_s.total_cmp(&b.at_s));
        for (j, head) in self.heads.iter_mut().enumerate() {
            let mut tunings = vec![Tuning::of(
                head.modes.clone(),
                &head.coupled,
                f64::NEG_INFINITY,
                self.dt_s,
            )];
            for r in retunes.iter().filter(|r| r.drum == j) {
                let modes = HeadModes::new(&kit.drums[j].retuned(r.pitch), &self.config)?;
                debug_assert!(modes.modes().iter().zip(head.modes.modes()).all(|(a, b)| (
                    a.m,
                    a.n,
                    a.orientation
                ) == (
                    b.m,
                    b.n,
                    b.orientation
                )));
                tunings.push(Tuning::of(modes, &head.coupled, r.at_s, self.dt_s));
            }
            head.tunings = Arc::new(tunings);
        }
        self.retunes = retunes;
        Ok(self)
    }

    /// One simulation step at `time_s`: `tips[i]` = (position m, velocity m/s) of tip i
    /// (0 left, 1 right), performer frame. Returns the force on each tip, N (+z pushes
    /// the stick up). A tip outside every head (horizontally) never touches.
    pub fn step(&mut self, time_s: f64, tips: [(DVec3, DVec3); 2]) -> [DVec3; 2] {
        let dt = self.dt_s;
        if self.step == 0 {
            self.first_time_s = time_s;
        }
        if !self.retunes.is_empty() {
            for head in &mut self.heads {
                head.retune_at(time_s);
            }
        }
        if self.step.is_multiple_of(MEMBRANE_FRAME_STEPS) {
            for head in &mut self.heads {
                head.catch_up();
                let q = head.x.iter().zip(&head.steps).map(|(x, s)| x[0] / s.omega0);
                self.membrane.extend(q.map(|q| q as f32));
            }
        }
        let mut force = [0.0f64; 2];
        let mut touching: [Option<(usize, DVec2)>; 2] = [None, None];
        // Heads a tip comes near this step are stepped; the others are left to lag.
        self.near.fill(false);
        for (i, &(p, v)) in tips.iter().enumerate() {
            let Some((j, local)) = self.head_under(p) else {
                continue;
            };
            let bottom = p.z - self.law.ball_radius_m;
            let bottom_end = bottom + v.z * dt;
            let surface = self.heads[j].modes.centre().z;
            // NaN positions fail every comparison and never touch.
            let height = bottom.min(bottom_end) - surface;
            if height.is_nan() || height > self.heads[j].bound_m {
                continue;
            }
            self.heads[j].catch_up();
            self.near[j] = true;
            let head = &self.heads[j];
            head.modes.shapes_at(local, &mut self.shapes[i]);
            // Compression at the end of the step as a function of the force F held over
            // it: c(F) = c0 − S·F, with the membrane's free motion and the response to the
            // other tip's force (already solved) in c0, and S the membrane's one-step
            // compliance at the point plus the tip's (dt²/m_eff). Solving F = k·c(F)^α
            // (implicit in the contact) keeps the stiff felt–membrane coupling stable.
            let other = touching[1 - i]
                .filter(|&(tj, _)| tj == j)
                .map(|_| (force[1 - i], &self.shapes[1 - i]));
            let mut d_free = 0.0;
            let mut compliance = 0.0;
            for ((&k, x), (step, inv_m)) in head
                .coupled
                .iter()
                .zip(&head.x)
                .zip(head.steps.iter().zip(&head.inv_mass))
            {
                let phi = self.shapes[i][k];
                let other_u = other.map_or(0.0, |(f, sh)| -f * sh[k] * inv_m);
                d_free += phi * step.advance(*x, other_u)[0] / step.omega0;
                compliance += phi * phi * step.b[0] / step.omega0 * inv_m;
            }
            let tip_compliance = dt * dt / self.tip_mass_kg;
            // Mid-step compression (trapezoidal: second order, no numerical damping of
            // the contact for a linear spring, still implicit in F).
            let c_now = surface + head.displacement(&self.shapes[i]) - bottom;
            // A tip that is already deeper than the felt radius without having been in
            // contact came from the side or below the head: it does not touch it.
            if self.open[i].is_none() && c_now > self.law.ball_radius_m {
                continue;
            }
            let c_end = surface + d_free - bottom_end;
            let c0 = 0.5 * (c_now + c_end);
            let f = self
                .law
                .solve(c0, 0.5 * (compliance + tip_compliance), c_now, dt);
            if f > 0.0 {
                force[i] = f;
                touching[i] = Some((j, local));
            }
        }
        for (j, head) in self.heads.iter_mut().enumerate() {
            if !self.near[j] {
                head.lag += 1;
                continue;
            }
            for (&k, (x, (s, inv_m))) in head
                .coupled
                .iter()
                .zip(head.x.iter_mut().zip(head.steps.iter().zip(&head.inv_mass)))
            {
                let mut generalised = 0.0;
                for i in 0..2 {
                    if let Some((tj, _)) = touching[i]
                        && tj == j
                    {
                        generalised -= force[i] * self.shapes[i][k];
                    }
                }
                *x = s.advance(*x, generalised * inv_m);
            }
            head.bound_m = head.energy_bound();
        }
        for i in 0..2 {
            self.record(i, time_s, tips[i], force[i], touching[i]);
        }
        self.step += 1;
        [
            DVec3::new(0.0, 0.0, force[0]),
            DVec3::new(0.0, 0.0, force[1]),
        ]
    }

    fn head_under(&self, p: DVec3) -> Option<(usize, DVec2)> {
        self.heads.iter().enumerate().find_map(|(j, h)| {
            let local = h.modes.local(p);
            h.modes.contains(local).then_some((j, local))
        })
    }

    fn record(
        &mut self,
        i: usize,
        time_s: f64,
        (p, v): (DVec3, DVec3),
        force: f64,
        touching: Option<(usize, DVec2)>,
    ) {
        let Some((drum, local)) = touching else {
            self.open[i] = None;
            return;
        };
        self.excitation.push(Excitation {
            step: self.step,
            time_s,
            drum,
            side: SIDES[i],
            point: local,
            force_n: force,
        });
        let end_s = time_s + self.dt_s;
        if let Some(c) = self.open[i].map(|k| &mut self.contacts[k])
            && c.drum == drum
        {
            c.end_s = end_s;
            c.peak_force_n = c.peak_force_n.max(force);
            return;
        }
        self.open[i] = Some(self.contacts.len());
        let head = &self.heads[drum].modes;
        self.contacts.push(ContactEvent {
            side: SIDES[i],
            drum,
            start_s: time_s,
            end_s,
            peak_force_n: force,
            impact_speed_mps: (-v.z).max(0.0),
            point: head.world(head.local(p)),
        });
    }

    /// Where the drums are now: enough to [`rewind`](DrumSet::rewind) them there.
    pub fn checkpoint(&self) -> DrumCheckpoint {
        DrumCheckpoint {
            step: self.step,
            heads: self
                .heads
                .iter()
                .map(|h| (h.x.clone(), h.lag, h.bound_m, h.tuning))
                .collect(),
            contacts: self.contacts.len(),
            open: self.open.map(|o| o.map(|k| (k, self.contacts[k].clone()))),
            excitation: self.excitation.len(),
            membrane: self.membrane.len(),
        }
    }

    /// Go back to `checkpoint` (taken from this set, not after a rewind before it):
    /// modes, ongoing contacts and the records are as they were then.
    pub fn rewind(&mut self, checkpoint: &DrumCheckpoint) {
        self.step = checkpoint.step;
        for (head, (x, lag, bound, tuning)) in self.heads.iter_mut().zip(&checkpoint.heads) {
            head.set_tuning(*tuning);
            head.x.clone_from(x);
            head.lag = *lag;
            head.bound_m = *bound;
        }
        self.contacts.truncate(checkpoint.contacts);
        self.excitation.truncate(checkpoint.excitation);
        self.membrane.truncate(checkpoint.membrane);
        self.open = checkpoint.open.clone().map(|o| {
            o.map(|(k, contact)| {
                self.contacts[k] = contact;
                k
            })
        });
    }

    /// A copy with what the sound needs (the contacts, the excitation, the heads) but not
    /// the membranes' recorded motion, the bulk of a long performance's record.
    pub fn for_sound(&self) -> DrumSet {
        DrumSet {
            dt_s: self.dt_s,
            config: self.config,
            law: self.law,
            tip_mass_kg: self.tip_mass_kg,
            heads: self.heads.clone(),
            step: self.step,
            contacts: self.contacts.clone(),
            open: self.open,
            excitation: self.excitation.clone(),
            shapes: self.shapes.clone(),
            first_time_s: self.first_time_s,
            membrane: SharedChunks::new(1),
            near: self.near.clone(),
            retunes: self.retunes.clone(),
        }
    }

    /// Finished and ongoing contacts, in start order.
    pub fn contacts(&self) -> &[ContactEvent] {
        &self.contacts
    }

    /// The force record that drives the sound: one entry per step and touching tip.
    pub fn excitation(&self) -> &[Excitation] {
        &self.excitation
    }

    /// A copy whose records (contacts and excitation) hold only `side`'s stick: what that
    /// hand alone put on the heads, for sound rendered per hand.
    pub fn only_side(&self, side: Side) -> DrumSet {
        let mut copy = self.clone();
        copy.contacts.retain(|c| c.side == side);
        copy.excitation.retain(|e| e.side == side);
        copy.open = [None; 2];
        copy
    }

    /// Membrane displacement (m, +up) of drum `drum` at the performer-frame point
    /// `point` (its height is ignored); 0 off the head or for an unknown drum.
    pub fn displacement_at(&self, drum: usize, point: DVec3) -> f64 {
        let Some(head) = self.heads.get(drum) else {
            return 0.0;
        };
        let local = head.modes.local(point);
        if !head.modes.contains(local) {
            return 0.0;
        }
        let mut shapes = vec![0.0; head.modes.modes().len()];
        head.modes.shapes_at(local, &mut shapes);
        if head.lag == 0 {
            head.displacement(&shapes)
        } else {
            let mut now = head.clone();
            now.catch_up();
            now.displacement(&shapes)
        }
    }

    /// The recorded displacement (m, +up) of drum `drum`'s head at the performer-frame
    /// point `point` at `time_s` (the frame before it, every 10 ms; coupled modes only);
    /// 0 off the head, for an unknown drum, or outside the recorded time.
    pub fn recorded_displacement(&self, drum: usize, time_s: f64, point: DVec3) -> f64 {
        // The shapes (Bessel functions of every coupled mode) only for a head that moves.
        let Some(q) = self.recorded_modes(drum, time_s) else {
            return 0.0;
        };
        self.coupled_shapes_at(drum, point)
            .map_or(0.0, |shapes| recorded_sum(q, &shapes))
    }

    /// The recorded amplitudes (m) of drum `drum`'s coupled modes in the frame before
    /// `time_s`; None for an unknown drum, outside the recorded time, or a head at rest.
    pub fn recorded_modes(&self, drum: usize, time_s: f64) -> Option<&[f32]> {
        let head = self.heads.get(drum)?;
        let frame_s = MEMBRANE_FRAME_STEPS as f64 * self.dt_s;
        let per_frame: usize = self.heads.iter().map(|h| h.coupled.len()).sum();
        let frames = self.membrane.len() / per_frame.max(1);
        let f = ((time_s - self.first_time_s) / frame_s).floor();
        if !(0.0..frames as f64).contains(&f) {
            return None;
        }
        let offset: usize = self.heads[..drum].iter().map(|h| h.coupled.len()).sum();
        let q = self
            .membrane
            .slice(f as usize * per_frame + offset, head.coupled.len());
        (!q.iter().all(|q| q.abs() < 1e-9)).then_some(q)
    }

    /// The shapes of drum `drum`'s coupled modes at the performer-frame point `point`, in
    /// the order of [`DrumSet::recorded_modes`]; None off the head or for an unknown drum.
    /// Computed once per point, they turn each frame's amplitudes into a displacement
    /// with [`recorded_sum`].
    pub fn coupled_shapes_at(&self, drum: usize, point: DVec3) -> Option<Vec<f64>> {
        let head = self.heads.get(drum)?;
        let local = head.modes.local(point);
        if !head.modes.contains(local) {
            return None;
        }
        let mut shapes = vec![0.0; head.modes.modes().len()];
        head.modes.shapes_at(local, &mut shapes);
        Some(head.coupled.iter().map(|&k| shapes[k]).collect())
    }

    /// The modes of drum `drum` (all of them, coupled or not) at the tuning the
    /// performance starts at.
    pub fn head(&self, drum: usize) -> Option<&HeadModes> {
        self.heads.get(drum).map(|h| &h.modes)
    }

    /// The tuning drum `drum` holds at score time `time_s` (s) — how many of its pedal
    /// changes came before — and its modes then.
    pub fn head_at(&self, drum: usize, time_s: f64) -> Option<(usize, &HeadModes)> {
        let head = self.heads.get(drum)?;
        let k = head.tunings.iter().rposition(|t| t.from_s <= time_s);
        let k = k.unwrap_or(0);
        Some((k, &head.tunings[k].modes))
    }

    /// The pedal changes the heads carry out, in time order.
    pub fn retunes(&self) -> &[Retune] {
        &self.retunes
    }

    /// Number of heads.
    pub fn len(&self) -> usize {
        self.heads.len()
    }

    /// Whether the kit has no drums.
    pub fn is_empty(&self) -> bool {
        self.heads.is_empty()
    }

    /// How many modes of drum `drum` take part in the mechanical coupling (those below
    /// the simulation's Nyquist frequency).
    pub fn coupled_mode_count(&self, drum: usize) -> usize {
        self.heads.get(drum).map_or(0, |h| h.coupled.len())
    }

    /// Simulation step, s.
    pub fn dt_s(&self) -> f64 {
        self.dt_s
    }

    /// Steps taken so far.
    pub fn steps_taken(&self) -> u64 {
        self.step
    }

    /// The mode configuration every head was built with.
    pub fn config(&self) -> &ModeConfig {
        &self.config
    }

    /// The mallet's contact law.
    pub fn contact_law(&self) -> &HertzContact {
        &self.law
    }

    /// The stick tip's mass in the contact's implicit solve: the mallet's effective mass
    /// at its tip, kg.
    pub fn tip_mass_kg(&self) -> f64 {
        self.tip_mass_kg
    }
}

/// A displacement (m) from recorded modal amplitudes and the shapes at one point
/// ([`DrumSet::recorded_modes`], [`DrumSet::coupled_shapes_at`]).
pub fn recorded_sum(amplitudes: &[f32], shapes: &[f64]) -> f64 {
    amplitudes
        .iter()
        .zip(shapes)
        .map(|(&q, &s)| f64::from(q) * s)
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drum::strike;

    /// A struck head that no tip comes near lags and is caught up by one exact step per
    /// membrane frame: its displacement matches the same head stepped every step to
    /// rounding, and its free-ringing bound holds the displacement all along.
    #[test]
    fn a_lagging_head_rings_as_one_stepped_every_step() {
        let kit = Kit::standard();
        let mallet = &kit.mallets[0];
        let mut drums = DrumSet::new(&kit, mallet, &ModeConfig::default(), 1e-4).unwrap();
        let drum = &kit.drums[2];
        let point = drum.point_on_head(0.6, 0.0);
        strike::scripted(&mut drums, drum, mallet, Side::Right, point, 3.0, 0.02);
        let (mut lazy, mut stepped) = (drums.clone(), drums);
        let away = (DVec3::new(0.0, 0.0, 10.0), DVec3::ZERO);
        let mut largest: f64 = 0.0;
        for n in 0..2000 {
            let t = 0.02 + f64::from(n) * 1e-4;
            lazy.step(t, [away; 2]);
            stepped.step(t, [away; 2]);
            for head in &mut stepped.heads {
                head.catch_up();
            }
            let (d, want) = (
                lazy.displacement_at(2, point),
                stepped.displacement_at(2, point),
            );
            largest = largest.max(want.abs());
            assert!((d - want).abs() <= 1e-12, "step {n}: {d} vs {want}");
            assert!(want.abs() <= lazy.heads[2].bound_m, "step {n}");
        }
        assert!(largest > 1e-5, "the head rings: {largest} m");
        assert!(lazy.heads[2].lag > 0 && stepped.heads[2].lag == 0);
        assert_eq!(lazy.membrane.len(), stepped.membrane.len());
        for (a, b) in lazy.membrane.iter().zip(stepped.membrane.iter()) {
            assert!((a - b).abs() <= 1e-9, "{a} vs {b}");
        }
    }

    /// A pedal change damps the head to rest and retunes it at its time: the struck head
    /// rings before it, is still after it, rings at the new pitch when struck again, and
    /// a rewind across the change replays it bit for bit.
    #[test]
    fn a_pedal_change_damps_and_retunes_the_head() {
        use crate::base::pitch::Pitch;
        use strike::ScriptedStick;
        let kit = Kit::standard();
        let mallet = &kit.mallets[0];
        let a2: Pitch = "A2".parse().unwrap();
        let retune = Retune {
            drum: 2,
            at_s: 0.3,
            after_s: 0.05,
            pitch: a2,
        };
        let dt = 1e-4;
        let mut drums = DrumSet::new(&kit, mallet, &ModeConfig::default(), dt)
            .unwrap()
            .retuned(&kit, &[retune])
            .unwrap();
        assert_eq!(drums.retunes(), [retune]);
        let drum = &kit.drums[2];
        let point = drum.point_on_head(0.6, 0.0);
        let parked = ScriptedStick::parked(mallet);
        // Strike at t = 0 and at t = 0.5 with the right stick; the left stays parked.
        let record = |drums: &mut DrumSet, from: usize, to: usize| -> Vec<f64> {
            let mut stick = ScriptedStick::above(drum, mallet, point, 3.0, 0.001);
            let mut out = Vec::new();
            for n in from..to {
                let t = n as f64 * dt;
                if n == 5000 {
                    stick = ScriptedStick::above(drum, mallet, point, 3.0, 0.001);
                }
                let tip = if n < 300 || (5000..5300).contains(&n) {
                    stick.tip()
                } else {
                    parked.tip()
                };
                let f = drums.step(t, [parked.tip(), tip]);
                stick.advance(f[1], dt);
                out.push(drums.displacement_at(2, point));
            }
            out
        };
        let before = record(&mut drums, 0, 2500);
        let checkpoint = drums.checkpoint();
        let after = record(&mut drums, 2500, 7000);
        let rings = |d: &[f64]| d.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        assert!(rings(&before[2000..]) > 1e-5, "struck, it rings");
        assert_eq!(
            rings(&after[500..2500]),
            0.0,
            "damped at 0.3 s until struck again"
        );
        assert!(rings(&after[2600..]) > 1e-5, "struck again, it rings");
        // The (1,1) now rings at A2 (the kit's 26-inch drum is D3).
        let k11 = drums.heads[2]
            .coupled
            .iter()
            .position(|&k| {
                let m = &drums.heads[2].modes.modes()[k];
                (m.m, m.n) == (1, 1)
            })
            .unwrap();
        let hz = drums.heads[2].steps[k11].omega0 / std::f64::consts::TAU;
        assert!((hz / a2.hz() - 1.0).abs() < 0.01, "{hz} Hz");
        let f11 = |t: f64| drums.head_at(2, t).unwrap().1.modes()[k11].freq_hz;
        assert!((f11(0.29) / drum.tuning.hz() - 1.0).abs() < 0.01);
        assert!((f11(0.31) / a2.hz() - 1.0).abs() < 0.01);
        // Back before the change: the old tuning, and the same future again.
        drums.rewind(&checkpoint);
        assert_eq!(drums.heads[2].tuning, 0);
        assert_eq!(record(&mut drums, 2500, 7000), after);
    }
}
