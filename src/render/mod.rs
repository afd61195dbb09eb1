//! Rendering a whole score to sound and motion: the one pipeline behind `timpanist render`
//! and the editor's playback.
//!
//! compose (plan + splice, `motion`) → targets (strike-through, per-stroke time warp,
//! [`reference`]) → the body simulated at 10 kHz by the chosen control pipeline with its
//! stick tips meeting the modal heads through the Hertz contact (`body::sim` +
//! `drum::DrumSet`, two-way), the strokes settled on the beat front to back
//! ([`compensate`]: each cluster of strokes re-simulated from a saved state until its
//! contacts are on time) → contacts matched to strokes ([`strikes`]) → sound from the
//! recorded contact forces (`sound`; what is settled is sounded on the other core while
//! the body is still simulated, every [`SOUND_AHEAD_S`]). Deterministic: the same score and parameters give
//! bit-identical audio and motion, also when a rendering resumes a previous one after an
//! edit ([`render_after`]).

pub mod compensate;
pub mod damping;
pub mod evaluate;
pub mod gaze;
pub mod reach;
pub mod reference;
pub mod replay;
pub mod strikes;

use crate::base::choices::BodyStep;
use crate::body::Joint;
use crate::body::ik::{self, IkParams};
use crate::body::limits::JointLimits;
use crate::body::model::BodyModel;
use crate::body::sim::{Motion, Pipeline, Reference, SimError, SimParams, Simulator};
use crate::body::skeleton::Skeleton;
use crate::drum::{DrumError, DrumSet, ModeConfig};
use crate::kit::{Kit, Retune};
use crate::mocap::db::MotionDb;
use crate::motion::compose::{ComposeParams, Composition};
use crate::motion::perform;
use crate::motion::plan::{PlanError, PlanParams, PlannedStroke};
use crate::score::{LoadedScore, Settings};
use crate::sound::{Audio, Room, SoundError, SoundModel, SoundState, Touch, Voicing};
use compensate::{Aims, Performance, Stage};
use damping::DampReport;
use glam::DVec3;
use reference::{Release, StrikeShape, Targets, Warp};
use std::sync::Arc;
use std::time::{Duration, Instant};
use strikes::{StrikeEvent, Timing};

/// Everything that decides a rendering.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderParams {
    pub control: Pipeline,
    pub sound: SoundModel,
    /// The room the drums are heard in.
    pub room: Room,
    pub modes: ModeConfig,
    pub sim: SimParams,
    /// Hold the body within its performer's ranges of motion, the composition's joint
    /// limits (`Composition::limits`: the motion database's for the score's grip), in
    /// the IK and with the simulator's stops; `false` (the default) leaves `sim.limits`
    /// as given (none by default). Off by default: all six demo scores render within
    /// them, but strokes at the edge of the ranges (outer drums, across the body: the
    /// ladder moved to the outer drums, four-drum eighth notes, random scores) can make
    /// the body diverge against its stops or lose a stick (README "Physics (HIMC)").
    pub joint_limits: bool,
    pub plan: PlanParams,
    pub compose: ComposeParams,
    /// Index of the kit mallet to play with.
    pub mallet: usize,
    /// Player's height, m, and mass, kg.
    pub height_m: f64,
    pub mass_kg: f64,
    /// Most simulation attempts per stroke cluster of the timing compensation (1 = none);
    /// the best attempt is kept.
    pub max_attempts: usize,
    /// A cluster is settled once every stroke's contact is this close to its time, s, and
    /// every force is within `force_tolerance` of its aim...
    pub timing_tolerance_s: f64,
    /// ...or, from attempt `settle_attempts` on, once every stroke sounds within this, s.
    pub timing_acceptable_s: f64,
    pub settle_attempts: usize,
    /// How far below the head the felt first aims at impact (strike-through), m; each
    /// stroke's depth is then adapted toward its dynamic's force.
    pub strike_depth_m: f64,
    /// Peak contact force aimed at for a stroke of MIDI velocity 0 and the increase to
    /// velocity 127, N (seed 000 measured 62–107 N strikes).
    pub force_at_silence_n: f64,
    pub force_range_n: f64,
    /// Compensation also stops once every stroke's peak force is within this fraction of
    /// its aim.
    pub force_tolerance: f64,
    /// Half-width of the strike-through dip, s: 8 ms, so the hand is already lifting
    /// through most of a 5–8 ms contact (with 12 ms it still pressed the stick into the
    /// giving head and 10 of the demo scores' 291 contacts outlasted 8 ms, 6 with 8 ms;
    /// with 4–6 ms the strokes no longer reach their forces).
    pub strike_half_width_s: f64,
    /// How long before the impact the dip is deepest, s: the target is already rising
    /// as the felt meets the head, the player lifting out of the drum, so the stroke's
    /// force comes from the throw rather than from the arm pressing the stick into the
    /// giving head (4 ms: over our eight ladders no contact outlasts 8 ms, 4 did centred).
    pub strike_lead_s: f64,
    /// How the grip lets the stick go around each impact.
    pub release: Release,
    /// A contact longer than this, s, counts as the arm pressing the stick into the head:
    /// the compensation aims that stroke shallower and tries further (timpanists want
    /// 2–8 ms).
    pub max_contact_s: f64,
    /// Sound rendered after the last motion sample, s.
    pub tail_s: f64,
    /// Every PD gain multiplied by this.
    pub gain_scale: f64,
}

impl RenderParams {
    /// What the sound is heard as: the model and the room.
    pub fn voicing(&self) -> Voicing {
        Voicing {
            model: self.sound,
            room: self.room,
        }
    }

    /// The peak contact force aimed at for a stroke of `dynamic`, N.
    pub fn force_aim_n(&self, dynamic: crate::score::Dynamic) -> f64 {
        self.force_at_silence_n + self.force_range_n * dynamic.velocity()
    }

    /// The defaults with a score's settings (control, IK, body step, gains, sound, modes).
    pub fn for_score(settings: &Settings) -> RenderParams {
        let sim = SimParams::default();
        RenderParams {
            control: settings.control,
            sim: SimParams {
                ik: IkParams {
                    method: settings.ik,
                    ..sim.ik.clone()
                },
                contact_substeps: settings.body_step.contact_substeps(),
                calm_substeps: settings.body_step.calm_substeps(),
                ..sim
            },
            gain_scale: settings.gain_scale,
            sound: settings.sound,
            room: settings.room,
            modes: ModeConfig {
                count: settings.modes,
                source: settings.frequencies,
            },
            ..RenderParams::default()
        }
    }
}

impl Default for RenderParams {
    fn default() -> Self {
        RenderParams {
            control: Pipeline::Himc,
            sound: SoundModel::Modal,
            room: Room::Dry,
            modes: ModeConfig::default(),
            sim: SimParams {
                contact_substeps: BodyStep::default().contact_substeps(),
                calm_substeps: BodyStep::default().calm_substeps(),
                ..SimParams::default()
            },
            joint_limits: false,
            plan: PlanParams::default(),
            compose: ComposeParams::default(),
            mallet: 0,
            height_m: crate::body::skeleton::DEFAULT_HEIGHT_M,
            mass_kg: 70.0,
            max_attempts: 8,
            timing_tolerance_s: 0.0015,
            timing_acceptable_s: 0.0025,
            settle_attempts: 3,
            strike_depth_m: 0.018,
            force_at_silence_n: crate::drum::strike::FORCE_AT_SILENCE_N,
            force_range_n: crate::drum::strike::FORCE_RANGE_N,
            force_tolerance: 0.12,
            strike_half_width_s: 0.008,
            strike_lead_s: 0.004,
            release: Release::DEFAULT,
            max_contact_s: 0.008,
            tail_s: 2.5,
            gain_scale: 1.0,
        }
    }
}

/// Where a rendering is, for progress bars.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Progress {
    /// What is being done ("composing", "simulating", "sound").
    pub stage: &'static str,
    /// Fraction of the whole rendering done, 0–1 (estimated: simulating is ~90 %).
    pub fraction: f64,
}

/// Where the time went, wall clock.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Stats {
    pub compose: Duration,
    /// Simulating body and drums, retries included.
    pub simulate: Duration,
    /// Of `simulate`, the time spent stepping the drums and contacts.
    pub drums: Duration,
    pub sound: Duration,
    /// Seconds of motion in the score.
    pub score_s: f64,
    /// Seconds of motion simulated, retries included (after a resumed edit: since the
    /// resume point).
    pub simulated_s: f64,
    /// Stroke clusters settled and simulation attempts over them.
    pub clusters: usize,
    pub attempts: usize,
    /// Clusters by the attempts they took: entry n counts those settled in n + 1.
    pub attempts_per_cluster: Vec<usize>,
    /// Score time the rendering resumed a previous one's performance from, s.
    pub resumed_from_s: Option<f64>,
}

impl Stats {
    /// Wall-clock time of the whole rendering.
    pub fn wall(&self) -> Duration {
        self.compose + self.simulate + self.sound
    }

    /// Seconds of score rendered per wall-clock second.
    pub fn realtime_factor(&self) -> f64 {
        self.score_s / self.wall().as_secs_f64().max(1e-9)
    }

    /// Simulated seconds (retries included) per wall-clock second of simulation.
    pub fn simulation_speed(&self) -> f64 {
        self.simulated_s / self.simulate.as_secs_f64().max(1e-9)
    }
}

/// A rendered score.
#[derive(Clone, Debug)]
pub struct Rendering {
    pub composition: Arc<Composition>,
    /// The targets the body followed (after strike-through and timing warp); time 0 is
    /// `start_s` of the score.
    pub reference: Reference,
    /// What the body did, at the task rate, from `start_s`.
    pub motion: Motion,
    /// Score time of motion sample 0, s.
    pub start_s: f64,
    /// The drums after the performance: contacts and excitation, in score seconds.
    pub drums: DrumSet,
    /// Every contact, in time order.
    pub events: Vec<StrikeEvent>,
    /// Timing of the strokes.
    pub timing: Timing,
    /// The beats (score indices, in time order, each once) of the strokes that found no
    /// contact.
    pub missed_beats: Vec<usize>,
    /// Stereo audio from score time 0.
    pub audio: Audio,
    pub stats: Stats,
    /// Whether the whole score is rendered (else it stopped as [`render_after`] was
    /// told).
    pub complete: bool,
    /// Score time up to which the audio is final, s (the end of the audio when
    /// complete).
    pub ready_s: f64,
    /// What it was rendered with.
    pub params: RenderParams,
    pub kit: Kit,
    /// Where hands damped heads (the score's secco beats, timed by the simulated hands).
    pub touches: Vec<Touch>,
    /// How each secco beat's head was stopped.
    pub damping: DampReport,
}

/// Why a score could not be rendered.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RenderError {
    #[error("cannot compose the score: {0}")]
    Compose(#[from] PlanError),
    #[error("the score is empty: nothing to render")]
    Empty,
    #[error(transparent)]
    Drum(#[from] DrumError),
    #[error("the kit has no mallet {0}")]
    NoMallet(usize),
    #[error(transparent)]
    OutOfReach(#[from] reach::OutOfReach),
    #[error(
        "the simulation {what} at {time_s:.4} s of the score{}",
        beat.map_or(String::new(), |b| format!(", during beat {b}"))
    )]
    Diverged {
        time_s: f64,
        beat: Option<usize>,
        what: String,
    },
    #[error(transparent)]
    Sound(#[from] SoundError),
    #[error("the rendering was cancelled")]
    Cancelled,
}

/// Render `loaded` with motion units from `db`. `progress` is called now and then; when
/// it returns `false` the rendering stops with [`RenderError::Cancelled`].
pub fn render(
    loaded: &LoadedScore,
    db: &MotionDb,
    params: &RenderParams,
    progress: &mut dyn FnMut(Progress) -> bool,
) -> Result<Rendering, RenderError> {
    render_after(&mut None, None, loaded, db, params, progress)
}

/// While the body is simulated, the sound of what is settled is made on the other core
/// each time this much more of the score is settled, s.
pub const SOUND_AHEAD_S: f64 = 5.0;

/// After an edit the editor first renders this far past the edited stroke, s, ready to
/// play at once...
pub const FIRST_STEP_S: f64 = 0.25;
/// ...then the rest in steps, the first this long, s, and each next one
/// [`RESUME_STEP_GROWTH`] times the last.
pub const RESUME_STEP_S: f64 = 4.0;
/// How much longer each step of the rest is than the one before. Playback started at the
/// edit never runs out as long as the rendering runs more than this many times faster
/// than real time (each step is then ready before the music reaches its start: the
/// one-minute study renders at 28× real time at the reference body step, 40× at the fast
/// one). Fewer steps hand over fewer whole copies of the audio and motion, and a longer
/// one makes its sound beside its simulation, every [`SOUND_AHEAD_S`]: with 8 the rest of
/// the one-minute study after an edit at 30 s is two steps (4 s, then all of it), the
/// whole score current again after 0.91–0.94 s against 1.05–1.07 s with 2 (four steps:
/// 4, 8, 16 s and the last).
pub const RESUME_STEP_GROWTH: f64 = 8.0;

/// What renderings leave behind to resume from after an edit: the settled performance,
/// the sound's synthesis state and what they were made from. Whoever renders again keeps
/// it (the editor's worker) and each rendering updates it in place, without copying it;
/// also one that is cancelled or fails leaves a state a later rendering can resume from.
#[derive(Clone, Debug)]
pub struct Resume {
    performance: Performance,
    sound: SoundState,
    /// The composition performed: its strokes and target tips, its start and rate (where
    /// the performer looked and leaned are its performance's targets).
    strokes: Vec<PlannedStroke>,
    tips: [Vec<DVec3>; 2],
    limits: JointLimits,
    start_s: f64,
    rate_hz: f64,
    params: RenderParams,
    kit: Kit,
    retunes: Vec<Retune>,
}

impl Resume {
    /// The settled performance (read-only: what a bench of handing it on copies).
    pub fn performance(&self) -> &Performance {
        &self.performance
    }
}

/// [`render`], resuming from `resume` (when given, and for the same kit and parameters)
/// at the latest saved state before the score changed, and its sound from there: bit
/// for bit the same result, faster. Given `stop_after_s`, a resumed rendering stops
/// about that long past the first change (the first stroke that differs, else the first
/// target sample; for the same score, the resume point), s: a partial rendering whose
/// audio is final up to [`Rendering::ready_s`], to play at once while the rest is
/// rendered (resuming from it). `resume` is left describing this rendering.
pub fn render_after(
    resume: &mut Option<Resume>,
    stop_after_s: Option<f64>,
    loaded: &LoadedScore,
    db: &MotionDb,
    params: &RenderParams,
    progress: &mut dyn FnMut(Progress) -> bool,
) -> Result<Rendering, RenderError> {
    if !progress(Progress {
        stage: "composing",
        fraction: 0.0,
    }) {
        return Err(RenderError::Cancelled);
    }
    let began = Instant::now();
    let composition = compose(loaded, db, params)?;
    let compose_time = began.elapsed();
    let mut rendering = render_composition(
        resume,
        stop_after_s,
        loaded,
        Arc::new(composition),
        params,
        progress,
    )?;
    rendering.stats.compose = compose_time;
    Ok(rendering)
}

/// The two tip trajectories `render` performs for `loaded` (planned and composed with the
/// parameters' plan and compose settings, on the kit as the score's settings change it):
/// what the editor's view shows, handed to [`render_composition`] so a score is composed
/// once.
pub fn compose(
    loaded: &LoadedScore,
    db: &MotionDb,
    params: &RenderParams,
) -> Result<Composition, RenderError> {
    let kit: &Kit = &loaded.score.kit(&loaded.kit);
    Ok(perform::trajectories(
        &loaded.score,
        kit,
        db,
        &params.plan,
        &params.compose,
    )?)
}

/// [`render_after`] of a score already composed by [`compose`] (with the same `loaded` and
/// `params`): simulate, settle and sound it.
pub fn render_composition(
    resume: &mut Option<Resume>,
    stop_after_s: Option<f64>,
    loaded: &LoadedScore,
    composition: Arc<Composition>,
    params: &RenderParams,
    progress: &mut dyn FnMut(Progress) -> bool,
) -> Result<Rendering, RenderError> {
    let kit: &Kit = &loaded.score.kit(&loaded.kit);
    let retunes = loaded.score.retunes(&loaded.kit);
    let mallet = kit
        .mallets
        .get(params.mallet)
        .ok_or(RenderError::NoMallet(params.mallet))?;
    let law = crate::drum::HertzContact::of(mallet)?;
    if composition.len() < 2 || composition.strokes.is_empty() {
        return Err(RenderError::Empty);
    }
    let skeleton = Skeleton::new(params.height_m, mallet.length_m);
    reach::check(&composition.strokes, &skeleton)?;
    let mut stats = Stats {
        score_s: (composition.len() - 1) as f64 / composition.rate_hz,
        ..Stats::default()
    };
    let shape = StrikeShape {
        ball_radius_m: law.ball_radius_m,
        half_width_s: params.strike_half_width_s,
        lead_s: params.strike_lead_s,
        release: params.release,
    };
    let earlier = resume.as_ref().map(|r| &r.performance.targets);
    let mut targets = Targets::after(&composition, &shape, params.strike_depth_m, earlier);
    targets.lean_for(&skeleton, &composition);
    let run = Run {
        kit,
        retunes: &retunes,
        mallet,
        params,
        composition: &composition,
    };
    let started = run.start(resume.take(), targets, skeleton.clone())?;
    stats.resumed_from_s = started.resumed_from_s;
    let state = resume.insert(started.state);
    let horizon = stats.resumed_from_s.zip(stop_after_s).map(|(from, after)| {
        let at = started.changed_s.map_or(from, |c: f64| c.max(from));
        ((at + after - composition.start_s) * composition.rate_hz)
            .ceil()
            .max(0.0) as usize
    });
    let previous_sound = std::mem::take(&mut state.sound);
    let (complete, sound) = run.settle_sounding(
        &mut state.performance,
        horizon,
        (&mut stats, progress),
        (&skeleton, previous_sound),
    );
    state.sound = sound;
    let complete = complete?;
    if !progress(Progress {
        stage: "sound",
        fraction: 0.93,
    }) {
        return Err(RenderError::Cancelled);
    }
    let simulated_s = simulated_to_s(&composition, &state.performance);
    let (touches, damping) = damping::touches(
        &composition,
        state.performance.sim.motion(),
        &skeleton,
        kit,
        simulated_s,
    );
    let began = Instant::now();
    let (audio, ready_s) = run.sound(state, complete, &touches)?;
    stats.sound = began.elapsed();
    progress(Progress {
        stage: "done",
        fraction: 1.0,
    });
    let performance = &state.performance;
    let drums = &performance.drums;
    let matches = strikes::match_strokes(&composition.strokes, drums.contacts());
    let timing = strikes::timing(&strikes::errors(
        &composition.strokes,
        drums.contacts(),
        &matches,
    ));
    let events = strikes::events(&composition.strokes, drums.contacts(), &matches);
    let missed_beats = strikes::missed_beats(&composition.strokes, &matches);
    Ok(Rendering {
        reference: performance.targets.reference(&performance.warp),
        motion: performance.sim.motion().clone(),
        start_s: composition.start_s,
        composition,
        drums: drums.clone(),
        events,
        timing,
        missed_beats,
        audio,
        stats,
        complete,
        ready_s: ready_s.max(0.0),
        params: params.clone(),
        kit: kit.clone(),
        touches,
        damping,
    })
}

/// The score time `performance` of `comp` is simulated to (its last sample), s.
fn simulated_to_s(comp: &Composition, performance: &Performance) -> f64 {
    comp.time(performance.sim.samples().max(1) - 1)
}

/// One rendering's fixed inputs.
struct Run<'a> {
    kit: &'a Kit,
    /// The score's pedal changes.
    retunes: &'a [Retune],
    /// The kit's mallet the params name.
    mallet: &'a crate::kit::Mallet,
    params: &'a RenderParams,
    composition: &'a Composition,
}

/// Where a rendering starts from: its state, the score time it resumed from (none when
/// it starts afresh) and where the change it renders is first heard.
struct Started {
    state: Resume,
    resumed_from_s: Option<f64>,
    changed_s: Option<f64>,
}

impl Run<'_> {
    /// The simulation settings: the parameters', holding the composition's joint limits
    /// when they say so.
    fn sim_params(&self) -> SimParams {
        held_within(&self.params.sim, self.params, self.composition.limits)
    }

    /// Resume `previous` at its latest saved state before the change, when it is of the
    /// same kit and parameters, else start a new performance (keeping the sound's state
    /// when the heads are the same: the sound compares each drum's record itself).
    fn start(
        &self,
        previous: Option<Resume>,
        targets: Targets,
        skeleton: Skeleton,
    ) -> Result<Started, RenderError> {
        let (comp, params, kit) = (self.composition, self.params, self.kit);
        let (start_s, rate) = (comp.start_s, comp.rate_hz);
        let strokes = comp.strokes.len();
        let resumable = previous
            .as_ref()
            .and_then(|p| self.resume_point(p, &targets));
        let (performance, sound, resumed_from_s, changed_s) = match (previous, resumable) {
            (Some(previous), Some((at, changed_s))) => {
                let Resume {
                    mut performance,
                    sound,
                    ..
                } = previous;
                performance.resume_at(at, targets, strokes);
                let from = start_s + performance.sim.samples() as f64 / rate;
                (performance, sound, Some(from), changed_s)
            }
            (previous, _) => {
                let first = targets.reference(&Warp::default());
                let (sim, drums) = performer(
                    (kit, self.retunes, self.mallet),
                    params,
                    &self.sim_params(),
                    skeleton,
                    &first,
                    start_s,
                )?;
                let sound = previous
                    .filter(|r| r.kit == *kit && r.params.modes == params.modes)
                    .map(|r| r.sound)
                    .unwrap_or_default();
                let performance = Performance::new(targets, sim, drums, strokes);
                (performance, sound, None, None)
            }
        };
        Ok(Started {
            state: Resume {
                performance,
                sound,
                strokes: comp.strokes.clone(),
                tips: comp.tips.clone(),
                limits: comp.limits,
                start_s,
                rate_hz: rate,
                params: params.clone(),
                kit: kit.clone(),
                retunes: self.retunes.to_vec(),
            },
            resumed_from_s,
            changed_s,
        })
    }

    /// The saved state of `previous` to resume from for this composition (none when the
    /// kit, parameters or timing differ), and where the change is heard: the first stroke
    /// that differs, else the first target sample that does (none for the same score: a
    /// rendering continued). A sample differs when a tip, the gaze or the trunk's lean
    /// does: the lean looks ahead of the tips (it is held and eased before a far stroke),
    /// so an edit that adds or moves a far stroke changes it before that stroke's path.
    fn resume_point(&self, previous: &Resume, targets: &Targets) -> Option<(usize, Option<f64>)> {
        let comp = self.composition;
        let same = previous.params == *self.params
            && previous.kit == *self.kit
            && previous.retunes == self.retunes
            && previous.limits == comp.limits
            && previous.start_s == comp.start_s
            && previous.rate_hz == comp.rate_hz;
        if !same {
            return None;
        }
        let old_len = previous.tips[0].len();
        let common = old_len.min(comp.len());
        let before = &previous.performance.targets;
        let same_until = (0..common)
            .find(|&k| {
                (0..2).any(|h| previous.tips[h][k] != comp.tips[h][k])
                    || before.gaze().get(k) != targets.gaze().get(k)
                    || before.lean_at(k) != targets.lean_at(k)
            })
            .unwrap_or(common);
        let at = previous.performance.resumable(
            &previous.strokes,
            &comp.strokes,
            targets,
            same_until,
        )?;
        let (new, old) = (&comp.strokes, &previous.strokes);
        let changed_s = (0..new.len().max(old.len()))
            .find(|&i| new.get(i) != old.get(i))
            .and_then(|i| new.get(i).or(old.get(i)))
            .map(|s| s.time_s)
            .or_else(|| {
                (same_until < old_len.max(comp.len()))
                    .then(|| comp.start_s + same_until as f64 / comp.rate_hz)
            });
        Some((at, changed_s))
    }

    /// [`settle`](Self::settle) with the modal sound of the settled clusters made on the
    /// other core as the body is simulated (every [`SOUND_AHEAD_S`] of score, and in a
    /// step that stops at a horizon once its last cluster is settled, resuming `sound`),
    /// so [`sound`](Self::sound) has only the rest left: the settled state and
    /// the sound's state to resume (bit for bit what it would be made in one go: the sound
    /// resumes where its record first differs). With one core (`base::parallel::cores`)
    /// none is made beside the simulation.
    fn settle_sounding(
        &self,
        performance: &mut Performance,
        horizon: Option<usize>,
        (stats, progress): (&mut Stats, &mut dyn FnMut(Progress) -> bool),
        (skeleton, sound): (&Skeleton, SoundState),
    ) -> (Result<bool, RenderError>, SoundState) {
        let (kit, comp, model) = (self.kit, self.composition, self.params.sound);
        let voicing = self.params.voicing();
        std::thread::scope(|scope| {
            let (jobs, queue) = std::sync::mpsc::channel::<(DrumSet, Vec<Touch>, f64)>();
            let source = self.params.modes.source;
            let worker = scope.spawn(move || {
                let mut sound = sound;
                crate::sound::prepare_heads(kit, self.retunes, source, model);
                while let Ok(mut job) = queue.recv() {
                    // Only the latest record counts: it holds every earlier one.
                    while let Ok(newer) = queue.try_recv() {
                        job = newer;
                    }
                    let (drums, touches, end_s) = job;
                    sound = crate::sound::resynthesise_on(
                        kit,
                        (&drums, &touches),
                        end_s,
                        voicing,
                        Some(sound),
                        crate::sound::Cores::One,
                    )
                    .unwrap_or_default();
                }
                sound
            });
            // Counted from where this rendering resumed: a job cuts the sound's state at
            // its end, so one sent as soon as a resumed rendering settled its first
            // cluster made every drum's sound be made again from there, also the drums
            // whose strokes did not change.
            let mut sent_s = simulated_to_s(comp, performance);
            // The last cluster a step settles before its horizon (the editor's first step
            // after an edit: the edited stroke) is sounded at once, while the step goes
            // on to its horizon, so only that stretch is left to sound after it.
            // On one core the sound made beside the simulation would only take turns with
            // it: it is all made after it instead, the same bit for bit.
            let beside = crate::base::parallel::cores() > 1;
            let mut settled = |p: &Performance, last: bool| {
                let end_s = simulated_to_s(comp, p);
                let due = if last { sent_s } else { sent_s + SOUND_AHEAD_S };
                if !beside || model != SoundModel::Modal || end_s <= due {
                    return;
                }
                sent_s = end_s;
                let (touches, _) = damping::touches(comp, p.sim.motion(), skeleton, kit, end_s);
                // Without a receiver the job is dropped: the rest is made afterwards.
                let _ = jobs.send((p.drums.for_sound(), touches, end_s.max(0.0)));
            };
            let complete = self.settle(performance, horizon, (stats, progress), &mut settled);
            drop(jobs);
            let sound = worker
                .join()
                .expect("the sound made beside the simulation panicked");
            (complete, sound)
        })
    }

    /// Settle the strokes on their beats front to back (up to `horizon` samples, when
    /// given); true when the whole score is simulated.
    fn settle(
        &self,
        performance: &mut Performance,
        horizon: Option<usize>,
        (stats, progress): (&mut Stats, &mut dyn FnMut(Progress) -> bool),
        settled: &mut dyn FnMut(&Performance, bool),
    ) -> Result<bool, RenderError> {
        let (comp, params) = (self.composition, self.params);
        let aims = Aims {
            force_n: comp
                .strokes
                .iter()
                .map(|s| params.force_aim_n(s.dynamic))
                .collect(),
            force_tolerance: params.force_tolerance,
            tolerance_s: params.timing_tolerance_s,
            acceptable_s: params.timing_acceptable_s,
            settle_attempts: params.settle_attempts,
            max_attempts: params.max_attempts.max(1),
            first_depth_m: params.strike_depth_m,
            max_contact_s: params.max_contact_s,
            free_tip_mass_kg: crate::drum::contact::effective_mass_kg(self.mallet),
        };
        let began = Instant::now();
        let mut report = |f: f64| {
            progress(Progress {
                stage: "simulating",
                fraction: 0.02 + 0.9 * f,
            })
        };
        let mut stage = Stage {
            start_s: comp.start_s,
            drum_time: Duration::ZERO,
            report: &mut report,
            settled,
        };
        let outcome = performance.run(&comp.strokes, &aims, &mut stage, horizon);
        stats.drums = stage.drum_time;
        stats.simulate = began.elapsed();
        let complete = outcome.map_err(|e| RenderError::of_simulation(e, comp.start_s))?;
        stats.simulated_s = performance.simulated_samples as f64 / comp.rate_hz;
        stats.clusters = performance.clusters_settled();
        stats.attempts = performance.attempts;
        stats.attempts_per_cluster = performance.attempts_per_cluster.clone();
        Ok(complete)
    }

    /// The sound of the performance so far, resuming the state's synthesis, and the score
    /// time up to which it is final, s (a partial rendering's audio stops where later
    /// strikes could still change it).
    fn sound(
        &self,
        state: &mut Resume,
        complete: bool,
        touches: &[Touch],
    ) -> Result<(Audio, f64), RenderError> {
        let comp = self.composition;
        let drums = &state.performance.drums;
        let (end_s, ready_s) = if complete {
            let end_s = comp.time(comp.len() - 1) + self.params.tail_s;
            (end_s, end_s)
        } else {
            let simulated_to_s = simulated_to_s(comp, &state.performance);
            (simulated_to_s, simulated_to_s - 2.0 * drums.dt_s())
        };
        let mut previous = std::mem::take(&mut state.sound);
        if !complete {
            previous.hold_gain();
        }
        let (audio, sound) = crate::sound::render_touched(
            self.kit,
            drums,
            touches,
            end_s.max(0.0),
            self.params.voicing(),
            Some(previous),
        )?;
        state.sound = sound;
        Ok((audio, ready_s))
    }
}

impl Rendering {
    /// The joint limits the body was held within (none when it was not).
    pub fn limits(&self) -> JointLimits {
        if self.params.joint_limits {
            self.composition.limits
        } else {
            self.params.sim.limits
        }
    }

    /// The farthest any limited joint went outside its ellipsoid over the performance:
    /// the joint, its largest ellipsoid radius ([`JointLimit::radius`]: 1 on the
    /// ellipsoid) and the score time, s. `None` when no joint is limited.
    ///
    /// [`JointLimit::radius`]: crate::body::limits::JointLimit::radius
    pub fn worst_joint_radius(&self) -> Option<(Joint, f64, f64)> {
        let limits = self.limits();
        let mut worst: Option<(Joint, f64, f64)> = None;
        for (k, pose) in self.motion.poses.iter().enumerate() {
            for (j, limit) in limits.iter().enumerate() {
                let Some(limit) = limit else { continue };
                let r = limit.radius(pose[j]);
                if worst.is_none_or(|w| r > w.1) {
                    let t = self.start_s + k as f64 / self.motion.rate_hz;
                    worst = Some((Joint::ALL[j], r, t));
                }
            }
        }
        worst
    }

    /// The body that played it (the player's height and the mallet's length).
    pub fn skeleton(&self) -> Skeleton {
        let mallet = self.kit.mallets.get(self.params.mallet);
        Skeleton::new(self.params.height_m, mallet.map_or(0.0, |m| m.length_m))
    }
}

/// `sim` holding the composition's joint `limits` when `params` say so
/// ([`RenderParams::joint_limits`]).
fn held_within(sim: &SimParams, params: &RenderParams, limits: JointLimits) -> SimParams {
    if params.joint_limits {
        SimParams {
            limits,
            ..sim.clone()
        }
    } else {
        sim.clone()
    }
}

/// What a performance starts from: the body (`skeleton`, the player's mass holding the
/// kit's `mallet`) at rest in the posture that reaches `reference`'s first tip targets,
/// following it with `params`' control and gains under `sim`; and the kit's drums at
/// rest, stepped at `sim`'s rate. `start_s` is the score time of the reference's start.
fn performer(
    (kit, retunes, mallet): (&Kit, &[Retune], &crate::kit::Mallet),
    params: &RenderParams,
    sim: &SimParams,
    skeleton: Skeleton,
    reference: &Reference,
    start_s: f64,
) -> Result<(Simulator, DrumSet), RenderError> {
    let model = BodyModel::new(skeleton, params.mass_kg).holding_mallets(mallet.mass_kg);
    let initial = ik::posture_reaching(
        &model.skeleton,
        [reference.tips[0][0], reference.tips[1][0]],
        &sim.ik_limits(),
    );
    let simulator = Simulator::new(
        &model,
        reference,
        params.control,
        sim,
        &initial,
        &[params.gain_scale; crate::body::skeleton::JOINT_COUNT],
    )
    .map_err(|e| RenderError::of_simulation(e, start_s))?;
    let rate = reference.rate_hz;
    let dt = 1.0 / (rate * (sim.sim_hz / rate).round().max(1.0));
    let drums = DrumSet::new(kit, mallet, &params.modes, dt)?.retuned(kit, retunes)?;
    Ok((simulator, drums))
}

impl RenderError {
    /// A simulation failure, its time moved to score time (the simulation starts at
    /// `start_s`).
    fn of_simulation(e: SimError, start_s: f64) -> RenderError {
        match e {
            SimError::Diverged(d) => RenderError::Diverged {
                time_s: d.time_s + start_s,
                beat: d.beat,
                what: d.what,
            },
            SimError::Cancelled => RenderError::Cancelled,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::score::Dynamic;

    /// The force aims rise strictly with the markings, pp is about a third of ff, and a
    /// `Velocity(v)` aims between the markings around it.
    #[test]
    fn force_aims_follow_the_dynamic() {
        let p = RenderParams::default();
        let aims: Vec<f64> = Dynamic::MARKS.iter().map(|m| p.force_aim_n(m.0)).collect();
        assert!(aims.windows(2).all(|w| w[0] < w[1]), "{aims:?}");
        let ratio = aims[0] / aims[5];
        assert!((0.28..=0.4).contains(&ratio), "pp/ff {ratio}");
        let v = p.force_aim_n(Dynamic::Velocity(0.6));
        assert!(
            p.force_aim_n(Dynamic::Mp) < v && v < p.force_aim_n(Dynamic::Mf),
            "{v}"
        );
    }
}
