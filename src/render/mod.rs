//! Rendering a whole score to sound and motion: the one pipeline behind `timpanist render`
//! and the editor's playback (issue 6 §4–5).
//!
//! compose (plan + splice, `motion`) → targets (strike-through, per-stroke time warp,
//! [`reference`]) → the body simulated at 10 kHz by the chosen control pipeline with its
//! stick tips meeting the modal heads through the Hertz contact (`body::sim` +
//! `drum::DrumSet`, two-way), the strokes settled on the beat front to back
//! ([`compensate`]: each cluster of strokes re-simulated from a saved state until its
//! contacts are on time) → contacts matched to strokes ([`strikes`]) → sound from the
//! recorded contact forces (`sound`). Deterministic: the same score and parameters give
//! bit-identical audio and motion, also when a rendering resumes a previous one after an
//! edit ([`render_after`]).

pub mod compensate;
pub mod reach;
pub mod reference;
pub mod strikes;

use crate::body::ik::{self, IkParams};
use crate::body::model::BodyModel;
use crate::body::sim::{Motion, Pipeline, Reference, SimError, SimParams, Simulator};
use crate::body::skeleton::{Pose, REST, Skeleton};
use crate::drum::{DrumError, DrumSet, ModeConfig};
use crate::kit::Kit;
use crate::kit::Side;
use crate::mocap::db::MotionDb;
use crate::motion::compose::{ComposeParams, Composition};
use crate::motion::perform;
use crate::motion::plan::{PlanParams, PlannedStroke};
use crate::score::{LoadedScore, Settings};
use crate::sound::{Audio, SoundError, SoundModel, SoundState};
use compensate::{Aims, Performance, Stage};
use glam::DVec3;
use reference::{StrikeShape, Targets, Warp};
use std::time::{Duration, Instant};
use strikes::{StrikeEvent, Timing};

/// Everything that decides a rendering.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderParams {
    pub control: Pipeline,
    pub sound: SoundModel,
    pub modes: ModeConfig,
    pub sim: SimParams,
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
    /// Half-width of the strike-through dip, s.
    pub strike_half_width_s: f64,
    /// Sound rendered after the last motion sample, s.
    pub tail_s: f64,
    /// Every PD gain multiplied by this.
    pub gain_scale: f64,
}

impl RenderParams {
    /// The defaults with a score's settings (control, IK, gains, sound, modes).
    pub fn for_score(settings: &Settings) -> RenderParams {
        let sim = SimParams::default();
        RenderParams {
            control: settings.control,
            sim: SimParams {
                ik: IkParams {
                    method: settings.ik,
                    ..sim.ik.clone()
                },
                ..sim
            },
            gain_scale: settings.gain_scale,
            sound: settings.sound,
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
            modes: ModeConfig::default(),
            sim: SimParams::default(),
            plan: PlanParams::default(),
            compose: ComposeParams::default(),
            mallet: 0,
            height_m: crate::body::skeleton::DEFAULT_HEIGHT_M,
            mass_kg: 70.0,
            max_attempts: 6,
            timing_tolerance_s: 0.0015,
            timing_acceptable_s: 0.004,
            settle_attempts: 3,
            strike_depth_m: 0.018,
            force_at_silence_n: 15.0,
            force_range_n: 95.0,
            force_tolerance: 0.25,
            strike_half_width_s: 0.012,
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
    pub composition: Composition,
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
}

/// Why a score could not be rendered.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RenderError {
    #[error("cannot compose the score: {0}")]
    Compose(String),
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

/// After an edit the editor first renders this far past the edited stroke, s, ready to
/// play at once...
pub const FIRST_STEP_S: f64 = 0.4;
/// ...then the rest in steps of this, s (each several times faster than real time, so
/// playback started at once never runs out).
pub const RESUME_STEP_S: f64 = 4.0;

/// What renderings leave behind to resume from after an edit: the settled performance,
/// the sound's synthesis state and what they were made from. Whoever renders again keeps
/// it (the editor's worker) and each rendering updates it in place, without copying it;
/// also one that is cancelled or fails leaves a state a later rendering can resume from.
#[derive(Clone, Debug)]
pub struct Resume {
    performance: Performance,
    sound: SoundState,
    /// The composition performed: its strokes and target tips, its start and rate.
    strokes: Vec<PlannedStroke>,
    tips: [Vec<DVec3>; 2],
    start_s: f64,
    rate_hz: f64,
    params: RenderParams,
    kit: Kit,
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
    let mut stats = Stats::default();
    let kit: &Kit = &loaded.score.settings.kit(&loaded.kit);
    let mallet = kit
        .mallets
        .get(params.mallet)
        .ok_or(RenderError::NoMallet(params.mallet))?;
    let law = crate::drum::HertzContact::of(mallet)?;
    if !progress(Progress {
        stage: "composing",
        fraction: 0.0,
    }) {
        return Err(RenderError::Cancelled);
    }
    let began = Instant::now();
    let composition = perform::trajectories(&loaded.score, kit, db, &params.plan, &params.compose)
        .map_err(RenderError::Compose)?;
    stats.compose = began.elapsed();
    if composition.len() < 2 || composition.strokes.is_empty() {
        return Err(RenderError::Empty);
    }
    let skeleton = Skeleton::new(params.height_m, mallet.length_m);
    reach::check(&composition.strokes, &skeleton)?;
    let start_s = composition.start_s;
    let rate = composition.rate_hz;
    stats.score_s = (composition.len() - 1) as f64 / rate;
    let shape = StrikeShape {
        ball_radius_m: law.ball_radius_m,
        half_width_s: params.strike_half_width_s,
    };
    let targets = Targets::new(&composition, &shape, params.strike_depth_m);
    let strokes = composition.strokes.len();
    let same_heads = resume
        .as_ref()
        .is_some_and(|r| r.kit == *kit && r.params.modes == params.modes);
    let resumed = resume.as_ref().and_then(|p| {
        let same =
            p.params == *params && p.kit == *kit && p.start_s == start_s && p.rate_hz == rate;
        let old_len = p.tips[0].len();
        let same_until = (0..old_len.min(composition.len()))
            .find(|&k| (0..2).any(|h| p.tips[h][k] != composition.tips[h][k]))
            .unwrap_or(old_len.min(composition.len()));
        let at = p
            .performance
            .resumable(&p.strokes, &composition.strokes, &targets, same_until);
        // Where the change is heard: the first stroke that differs, else the first
        // target sample that does (none for the same score: a rendering continued).
        let (new, old) = (&composition.strokes, &p.strokes);
        let changed_s = (0..new.len().max(old.len()))
            .find(|&i| new.get(i) != old.get(i))
            .and_then(|i| new.get(i).or(old.get(i)))
            .map(|s| s.time_s)
            .or_else(|| {
                (same_until < old_len.max(composition.len()))
                    .then(|| start_s + same_until as f64 / rate)
            });
        same.then_some(at).flatten().map(|at| (at, changed_s))
    });
    let mut changed_s = None;
    let (performance, sound) = match resumed {
        Some((at, changed)) => {
            changed_s = changed;
            let Resume {
                mut performance,
                sound,
                ..
            } = resume.take().expect("resuming");
            performance.resume_at(at, targets, strokes);
            stats.resumed_from_s = Some(start_s + performance.sim.samples() as f64 / rate);
            (performance, sound)
        }
        None => {
            let model = BodyModel::new(skeleton, params.mass_kg);
            let first = targets.reference(&Warp::default());
            let initial = initial_pose(&model, &first);
            let sim = Simulator::new(
                &model,
                &first,
                params.control,
                &params.sim,
                &initial,
                &[params.gain_scale; crate::body::skeleton::JOINT_COUNT],
            )
            .map_err(|e| RenderError::of_simulation(e, start_s))?;
            let dt = 1.0 / (rate * (params.sim.sim_hz / rate).round().max(1.0));
            let drums = DrumSet::new(kit, mallet, &params.modes, dt)?;
            // The sound compares each drum's record itself: it resumes whenever the
            // heads are the same.
            let sound = resume
                .take()
                .filter(|_| same_heads)
                .map(|r| r.sound)
                .unwrap_or_default();
            (Performance::new(targets, sim, drums, strokes), sound)
        }
    };
    let state = resume.insert(Resume {
        performance,
        sound,
        strokes: composition.strokes.clone(),
        tips: composition.tips.clone(),
        start_s,
        rate_hz: rate,
        params: params.clone(),
        kit: kit.clone(),
    });
    let performance = &mut state.performance;
    let aims = Aims {
        force_n: composition
            .strokes
            .iter()
            .map(|s| params.force_at_silence_n + params.force_range_n * s.dynamic.velocity())
            .collect(),
        force_tolerance: params.force_tolerance,
        tolerance_s: params.timing_tolerance_s,
        acceptable_s: params.timing_acceptable_s,
        settle_attempts: params.settle_attempts,
        max_attempts: params.max_attempts.max(1),
        first_depth_m: params.strike_depth_m,
    };
    let began = Instant::now();
    let mut report = |f: f64| {
        progress(Progress {
            stage: "simulating",
            fraction: 0.02 + 0.9 * f,
        })
    };
    let mut stage = Stage {
        start_s,
        drum_time: Duration::ZERO,
        report: &mut report,
    };
    let horizon = stats.resumed_from_s.zip(stop_after_s).map(|(from, after)| {
        let at = changed_s.map_or(from, |c: f64| c.max(from));
        ((at + after - start_s) * rate).ceil().max(0.0) as usize
    });
    let outcome = performance.run(&composition.strokes, &aims, &mut stage, horizon);
    stats.drums = stage.drum_time;
    stats.simulate = began.elapsed();
    let complete = outcome.map_err(|e| RenderError::of_simulation(e, start_s))?;
    let simulated_to_s = start_s + (performance.sim.samples().max(1) - 1) as f64 / rate;
    stats.simulated_s = performance.simulated_samples as f64 / rate;
    stats.clusters = performance.clusters_settled();
    stats.attempts = performance.attempts;
    let drums = &performance.drums;
    let matches = strikes::match_strokes(&composition.strokes, drums.contacts());
    let timing = strikes::timing(&strikes::errors(
        &composition.strokes,
        drums.contacts(),
        &matches,
    ));
    if !progress(Progress {
        stage: "sound",
        fraction: 0.93,
    }) {
        return Err(RenderError::Cancelled);
    }
    let began = Instant::now();
    // A partial rendering's audio stops where later strikes could still change it.
    let (end_s, ready_s) = if complete {
        let end_s = start_s + stats.score_s + params.tail_s;
        (end_s, end_s)
    } else {
        (
            simulated_to_s,
            simulated_to_s - 2.0 * performance.drums.dt_s(),
        )
    };
    // The sound resumes whatever the performance did when the heads are the same: it
    // compares each drum's record itself.
    let previous_sound = std::mem::take(&mut state.sound);
    let (audio, sound) = crate::sound::render_resuming(
        kit,
        drums,
        end_s.max(0.0),
        params.sound,
        Some(previous_sound),
    )?;
    state.sound = sound;
    stats.sound = began.elapsed();
    let events = strikes::events(&composition.strokes, drums.contacts(), &matches);
    progress(Progress {
        stage: "done",
        fraction: 1.0,
    });
    let performance = &state.performance;
    Ok(Rendering {
        reference: performance.targets.reference(&performance.warp),
        motion: performance.sim.motion().clone(),
        composition,
        start_s,
        drums: performance.drums.clone(),
        events,
        timing,
        audio,
        stats,
        complete,
        ready_s: ready_s.max(0.0),
        params: params.clone(),
        kit: kit.clone(),
    })
}

impl Rendering {
    /// The body that played it (the player's height and the mallet's length).
    pub fn skeleton(&self) -> Skeleton {
        let mallet = self.kit.mallets.get(self.params.mallet);
        Skeleton::new(self.params.height_m, mallet.map_or(0.0, |m| m.length_m))
    }
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

/// The posture the body starts in: both tips on the reference's first targets.
fn initial_pose(model: &BodyModel, reference: &Reference) -> Pose {
    let params = IkParams {
        max_iterations: 500,
        use_trunk: false,
        ..IkParams::default()
    };
    let mut pose = REST;
    for (h, side) in [Side::Left, Side::Right].into_iter().enumerate() {
        pose = ik::solve(
            &model.skeleton,
            &pose,
            side,
            reference.tips[h][0],
            None,
            &params,
        )
        .pose;
    }
    pose
}
