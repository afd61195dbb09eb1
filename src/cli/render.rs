//! `timpanist render`: a whole score to a WAV (and optionally the simulated motion as CSV
//! and one JSON object per contact, and a PNG of tip heights and contact forces), through the same pipeline as the editor, with a
//! progress bar on stderr and, with `--stats`, where the time went. Everything is computed
//! before anything is written; each file is written atomically. A database lacking a
//! playing mode is completed from the shipped synthetic one, and the beats played with a
//! unit of other labels than asked are told as notes (`super::compose`). Every message
//! names a beat by its number in the file's `beats` list, as `check` does
//! ([`BeatPlaces`]), whatever order the file lists them in.

use super::args::{
    BvhRateArg, BvhUnitsArg, ControlArg, RoomArg, SoundArg, VideoCameraArg, VideoFpsArg,
    WavFormatArg,
};
use crate::base::ron_file;
use crate::body::sim::{BodyStep, Pipeline, SimParams};
use crate::exports;
use crate::io::{bvh, figures, video};
use crate::mocap::shipped::DbSource;
use crate::motion::plan::{self, PlanParams};
use crate::render::reach::OutOfReach;
use crate::render::{Progress, RenderError, RenderParams, Rendering, render, strikes};
use crate::score::{BeatPlaces, LoadedScore};
use crate::sound::{Room, SoundModel};
use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::time::Duration;

/// Where to write what.
pub struct Outputs<'a> {
    pub wav: &'a Path,
    pub motion: Option<&'a Path>,
    pub c3d: Option<&'a Path>,
    pub events: Option<&'a Path>,
    pub plot: Option<&'a Path>,
    /// A folder for one WAV per drum.
    pub stems: Option<&'a Path>,
    /// The teaching exports.
    pub exports: &'a ExportArgs,
}

/// The teaching exports of `render` (README "Exports"), flattened into its flags.
#[derive(Clone, Debug, clap::Args)]
pub struct ExportArgs {
    /// Also write the simulated performer as BVH (Y up, 11 joints, the sticks ending at
    /// their tips; for Blender and other animation tools).
    #[arg(long)]
    pub bvh: Option<PathBuf>,
    /// BVH frames per second: every task sample (250) or resampled (120, 60).
    #[arg(long, value_enum, default_value = "250", requires = "bvh")]
    pub bvh_rate: BvhRateArg,
    /// BVH length unit: metres or centimetres.
    #[arg(long, value_enum, default_value = "m", requires = "bvh")]
    pub bvh_units: BvhUnitsArg,
    /// Also write the scene as binary glTF 2.0: the body and sticks as boxes, the drums,
    /// the performance as node animation (250 Hz).
    #[arg(long)]
    pub glb: Option<PathBuf>,
    /// Sample format of every WAV written (the mix and the stems): 16- or 24-bit integer
    /// PCM or 32-bit float.
    #[arg(long, value_enum, default_value = "16")]
    pub wav_format: WavFormatArg,
    /// Also write the performed hits as a Standard MIDI File: a note per stroke's contact
    /// at its simulated time under the score's tempo map, velocity from its peak force.
    #[arg(long)]
    pub performed_midi: Option<PathBuf>,
    /// Also send every contact as an OSC `/timpanist/hit` message over UDP to HOST:PORT
    /// (drum, hand, x, y, peak force, impact speed, time), in time order.
    #[arg(long, value_name = "HOST:PORT", value_parser = crate::io::osc::parse_target)]
    pub osc: Option<(String, u16)>,
    /// Send the OSC messages as the hits sound (paced in real time) instead of at once.
    #[arg(long, requires = "osc")]
    pub osc_realtime: bool,
    /// Also film the performance: the 3D view over the timeline with its playhead, with
    /// the mix, as H.264/AAC video (.mp4, .mov or .mkv) through the system's ffmpeg.
    #[arg(long)]
    pub video: Option<PathBuf>,
    /// Without ffmpeg: write the video's frames as numbered PNGs into this new folder,
    /// with the mix as audio.wav and join.sh, the ffmpeg command that joins them.
    #[arg(long, value_name = "DIR")]
    pub video_frames: Option<PathBuf>,
    /// Video frames per second.
    #[arg(long, value_enum, default_value = "30")]
    pub video_fps: VideoFpsArg,
    /// Video frame size, WIDTHxHEIGHT px (even sides, 64–4096).
    #[arg(long, default_value = "1280x720", value_parser = parse_size)]
    pub video_size: (u32, u32),
    /// Where the video looks from: the editor's default camera or a named view.
    #[arg(long, value_enum, default_value = "editor")]
    pub video_camera: VideoCameraArg,
}

/// `--video-size`: "WIDTHxHEIGHT".
fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("{s:?}: give WIDTHxHEIGHT, e.g. 1280x720"))?;
    let side = |v: &str| {
        v.trim()
            .parse::<u32>()
            .ok()
            .filter(|v| (64..=4096).contains(v) && v.is_multiple_of(2))
            .ok_or_else(|| format!("{v:?}: each side must be an even number of px, 64-4096"))
    };
    Ok((side(w)?, side(h)?))
}

impl ExportArgs {
    /// How a video is to look.
    fn video_options(&self) -> exports::video::VideoOptions {
        exports::video::VideoOptions {
            width: self.video_size.0,
            height: self.video_size.1,
            fps: self.video_fps.fps(),
            camera: self.video_camera.camera(),
        }
    }

    /// Refuse, before rendering, a video that could not be written (no ffmpeg, an
    /// unknown container, a frames folder that holds something).
    fn check_video(&self) -> anyhow::Result<()> {
        if let Some(path) = &self.video {
            video::check_target(path)?;
            let version = video::ffmpeg_version()?;
            eprintln!("video through {version}");
        }
        if let Some(dir) = &self.video_frames {
            crate::io::pack::folder::check(dir, false)?;
        }
        Ok(())
    }
}

/// How to render, as `render` and `export-pack` take it on the command line.
#[derive(Clone, Debug, clap::Args)]
pub struct RenderArgs {
    /// The control pipeline driving the body [default: the score's settings, himc].
    #[arg(long, value_enum)]
    pub control: Option<ControlArg>,
    /// The sound model [default: the score's settings, modal].
    #[arg(long, value_enum)]
    pub sound: Option<SoundArg>,
    /// The room the drums are heard in: dry (the heads' own sound), a studio or a concert
    /// hall (its reverberation added to the mix and to every stem) [default: the score's
    /// settings, dry].
    #[arg(long, value_enum)]
    pub room: Option<RoomArg>,
    /// The motion database folder [default: the first of ./mocap,
    /// ~/.local/share/timpanist/mocap, <prefix>/share/timpanist/mocap holding an
    /// index.ron, else the database built into the program].
    #[arg(long)]
    pub db: Option<PathBuf>,
    /// Seed of the choice among near-equal motion units.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Hold the body within the database performer's ranges of motion (seed 000
    /// Alg. 1 joint limits, each axis widened to a floor within published human
    /// ranges): the IK keeps its postures inside them and the simulator's stops hold
    /// the body. Strokes at the edge of the ranges (outer drums, across the body) may
    /// then fail to render.
    #[arg(long)]
    pub joint_limits: bool,
    /// The body's dynamics rate between contacts, Hz: 10000 steps the body with the
    /// drums and the stick–head contact (the reference, a score's `body_step:
    /// Reference`); 5000 (the fast default) or 2500 step it 2 or 4 times longer while
    /// the contact and the drums keep 10 kHz [default: the score's settings].
    #[arg(long, value_parser = ["10000", "5000", "2500"])]
    pub body_hz: Option<String>,
}

impl RenderArgs {
    /// The choices these flags make, printing statistics if `stats`.
    pub fn choices(&self, stats: bool) -> Choices {
        Choices {
            control: self.control.map(Into::into),
            sound: self.sound.map(Into::into),
            room: self.room.map(Into::into),
            seed: self.seed,
            stats,
            joint_limits: self.joint_limits,
            body_hz: self.body_hz.as_deref().and_then(|hz| hz.parse().ok()),
        }
    }
}

/// How to render, as asked on the command line.
pub struct Choices {
    /// The control pipeline (default: the score's settings).
    pub control: Option<Pipeline>,
    /// The sound model (default: the score's settings).
    pub sound: Option<SoundModel>,
    /// The room (default: the score's settings).
    pub room: Option<Room>,
    /// Seed of the choice among near-equal motion units.
    pub seed: u64,
    /// Print where the time went and the force by dynamic.
    pub stats: bool,
    /// Hold the body within the database performer's joint limits.
    pub joint_limits: bool,
    /// The body's dynamics rate, Hz (default: the score's settings).
    pub body_hz: Option<f64>,
}

/// The score's pedal changes (`score::tuning`), the first few of them.
fn pedal_notes(path: &Path, loaded: &LoadedScore, places: &BeatPlaces) {
    const SHOWN: usize = 3;
    let changes = loaded.score.pedal_changes_placed(&loaded.kit, places);
    for change in changes.iter().take(SHOWN) {
        eprintln!("note: {}: {change}", path.display());
    }
    if changes.len() > SHOWN {
        eprintln!(
            "note: {} more pedal changes ({} in all, {} of them quick)",
            changes.len() - SHOWN,
            changes.len(),
            changes.iter().filter(|c| c.is_quick()).count()
        );
    }
}

/// Load and render `score` as `choices` ask, with the progress bar on stderr; the notes
/// of loading and the substituted motion units printed. The score, where its beats stood
/// in the file, its rendering and the wall time it took.
pub fn rendered(
    score: &Path,
    source: &DbSource,
    choices: &Choices,
) -> anyhow::Result<(LoadedScore, BeatPlaces, Rendering, Duration)> {
    let Choices {
        control,
        sound,
        room,
        seed,
        stats,
        joint_limits,
        body_hz,
    } = *choices;
    let (loaded, places) = LoadedScore::load_placed(score)?;
    for notice in &loaded.notices {
        eprintln!("note: {notice}");
    }
    pedal_notes(score, &loaded, &places);
    let db = super::compose::load_db(source)?;
    if stats {
        println!("database: {source}");
    }
    let settings = RenderParams::for_score(&loaded.score.settings);
    let params = RenderParams {
        control: control.unwrap_or(settings.control),
        sound: sound.unwrap_or(settings.sound),
        room: room.unwrap_or(settings.room),
        plan: PlanParams {
            seed,
            ..PlanParams::default()
        },
        joint_limits,
        sim: SimParams {
            contact_substeps: body_hz.map_or(settings.sim.contact_substeps, |hz| {
                (settings.sim.sim_hz / hz).round().max(1.0) as usize
            }),
            // The fast step's calm stretches only at its own rate.
            calm_substeps: body_hz.map_or(settings.sim.calm_substeps, |hz| {
                let fast = BodyStep::Fast;
                let rate = settings.sim.sim_hz / fast.contact_substeps() as f64;
                if hz == rate { fast.calm_substeps() } else { 0 }
            }),
            ..settings.sim.clone()
        },
        ..settings
    };
    let started = std::time::Instant::now();
    let mut bar = ProgressBar::new();
    let rendering = render(&loaded, &db, &params, &mut |p| {
        bar.show(p);
        true
    });
    bar.finish();
    let rendering = rendering
        .map_err(|e| anyhow::anyhow!("{}: {}", score.display(), renumbered(e, &places)))?;
    let wall = started.elapsed();
    super::compose::print_substitutions(
        &plan::substitutions(&rendering.composition.strokes, &loaded.score, &db),
        &places,
    );
    Ok((loaded, places, rendering, wall))
}

/// `e` naming its beat by its number in the file (`places`), not in the score's time order.
fn renumbered(e: RenderError, places: &BeatPlaces) -> RenderError {
    match e {
        RenderError::OutOfReach(r) => RenderError::OutOfReach(OutOfReach {
            beat: places.number(r.beat),
            ..r
        }),
        RenderError::Diverged { time_s, beat, what } => RenderError::Diverged {
            time_s,
            beat: beat.map(|b| places.number(b)),
            what,
        },
        e => e,
    }
}

/// Render `score` and write `outputs`.
pub fn run(
    score: &Path,
    source: &DbSource,
    outputs: &Outputs,
    choices: &Choices,
) -> anyhow::Result<()> {
    let osc = outputs
        .exports
        .osc
        .as_ref()
        .map(super::osc::connect)
        .transpose()?;
    outputs.exports.check_video()?;
    let (loaded, places, rendering, wall) = rendered(score, source, choices)?;
    let ex = outputs.exports;
    let performance = exports::performance(&rendering, &loaded.score);
    let hits = performance.hits();
    let events = outputs
        .events
        .map(|_| serde_json::to_string_pretty(&rendering.events))
        .transpose()?;
    let motion = outputs.motion.map(|_| performance.motion_csv());
    let c3d = outputs.c3d.map(|_| performance.c3d());
    let bvh = ex
        .bvh
        .as_ref()
        .map(|path| {
            let options = bvh::Options {
                rate_hz: ex.bvh_rate.hz(),
                units: ex.bvh_units.into(),
            };
            (performance.bvh(&options)).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))
        })
        .transpose()?;
    let glb = ex
        .glb
        .as_ref()
        .map(|path| (performance.glb()).map_err(|e| anyhow::anyhow!("{}: {e}", path.display())))
        .transpose()?;
    let figure = outputs
        .plot
        .map(|_| figures::performance_figure(&performance));
    let duration_s = rendering.audio.frames() as f64 / f64::from(rendering.audio.rate_hz);
    let recorded = (&rendering.drums, &rendering.touches[..]);
    let (kit, model) = (&rendering.kit, rendering.params.voicing());
    let stems = outputs
        .stems
        .map(|_| crate::sound::stems(kit, recorded, duration_s, model))
        .transpose()?;
    let hand_stems = outputs
        .stems
        .map(|_| crate::sound::hands::hand_stems(kit, recorded, duration_s, model))
        .transpose()?;
    let performed_midi = ex
        .performed_midi
        .as_ref()
        .map(|_| performance.performed_midi());
    let format = ex.wav_format.into();
    crate::sound::write_wav_as(outputs.wav, &rendering.audio, format)?;
    if let (Some(dir), Some(stems)) = (outputs.stems, stems) {
        std::fs::create_dir_all(dir).map_err(|e| anyhow::anyhow!("{}: {e}", dir.display()))?;
        for (j, (stem, drum)) in stems.iter().zip(&rendering.kit.drums).enumerate() {
            let name: String = drum
                .name
                .chars()
                .map(|c| {
                    if c.is_alphanumeric() || c == '-' {
                        c
                    } else {
                        '_'
                    }
                })
                .collect();
            crate::sound::write_wav_as(&dir.join(format!("{}-{name}.wav", j + 1)), stem, format)?;
        }
    }
    if let (Some(dir), Some(hands)) = (outputs.stems, hand_stems) {
        for (stem, hand) in hands.iter().zip(["left", "right"]) {
            crate::sound::write_wav_as(&dir.join(format!("{hand}.wav")), stem, format)?;
        }
    }
    if let (Some(path), Some(bytes)) = (&ex.performed_midi, performed_midi) {
        ron_file::write_atomic(path, &bytes)?;
    }
    if let (Some(path), Some(figure)) = (outputs.plot, figure) {
        figure.save_png(path)?;
        let spectra = path.with_file_name(format!(
            "{}-spectra.png",
            path.file_stem()
                .map_or("plot".into(), |s| s.to_string_lossy())
        ));
        let panels = figures::first_stroke_spectra(&performance);
        figures::spectra_figure(panels).save_png(&spectra)?;
    }
    if let (Some(path), Some(text)) = (outputs.motion, motion) {
        ron_file::write_atomic(path, text.as_bytes())?;
    }
    if let (Some(path), Some(bytes)) = (outputs.c3d, c3d) {
        ron_file::write_atomic(path, &bytes)?;
    }
    if let (Some(path), Some(text)) = (outputs.events, events) {
        ron_file::write_atomic(path, text.as_bytes())?;
    }
    if let (Some(path), Some(text)) = (&ex.bvh, bvh) {
        ron_file::write_atomic(path, text.as_bytes())?;
    }
    if let (Some(path), Some(bytes)) = (&ex.glb, glb) {
        ron_file::write_atomic(path, &bytes)?;
    }
    let t = &rendering.timing;
    println!(
        "{} -> {}: {} strokes, {} contacts, {:.1} s of audio; timing median {:.2} ms, worst {:.2} ms{}; rendered in {:.1} s",
        score.display(),
        outputs.wav.display(),
        t.strokes,
        rendering.events.len(),
        rendering.audio.frames() as f64 / f64::from(rendering.audio.rate_hz),
        t.median_abs_s * 1e3,
        t.worst_abs_s * 1e3,
        if t.missed > 0 {
            format!(", {} strokes missed the head", t.missed)
        } else {
            String::new()
        },
        wall.as_secs_f64()
    );
    warn_of_missed_beats(&rendering, &places);
    if ex.bvh.is_some() || ex.glb.is_some() {
        println!(
            "motion frame 0 (BVH, glTF) is at {:.3} s of the score, the WAV's start at 0 s",
            rendering.start_s
        );
    }
    film(&rendering, &loaded.score, ex)?;
    if choices.stats {
        print_stats(&rendering, &places);
    }
    if let Some(socket) = osc {
        let super::osc::Sent { sent, unheard } = super::osc::send(&socket, &hits, ex.osc_realtime)?;
        println!("sent {sent} OSC hits to {}", socket.peer_addr()?);
        if unheard > 0 {
            eprintln!(
                "note: {}: no program was listening for {unheard} of them (start the receiver first, e.g. the Pure Data patch in README \"Exports\")",
                socket.peer_addr()?
            );
        }
    }
    Ok(())
}

/// Name the beats whose strokes found no head (the first [`NAMED_MISSES`]), so a
/// performance the body could not follow is not taken for a good one.
fn warn_of_missed_beats(rendering: &Rendering, places: &BeatPlaces) {
    let missed = &rendering.missed_beats;
    if missed.is_empty() {
        return;
    }
    let named = numbers(&missed[..missed.len().min(NAMED_MISSES)], places);
    eprintln!(
        "warning: the strokes of {} beat(s) found no head: beat {}{}; the simulated player could not follow there (a passage too fast or too far for it, or a body that lost its balance after a long run: see README \"Rendering a score\")",
        missed.len(),
        named,
        if missed.len() > NAMED_MISSES {
            ", …"
        } else {
            ""
        }
    );
}

/// The beats `beats` (indices in the score's time order) as the file numbers them,
/// e.g. "4, 7, 12".
fn numbers(beats: &[usize], places: &BeatPlaces) -> String {
    (beats.iter())
        .map(|&b| places.number(b).to_string())
        .collect::<Vec<_>>()
        .join(", ")
}

/// How many missed beats [`warn_of_missed_beats`] names.
const NAMED_MISSES: usize = 12;

/// `--video` and `--video-frames`, with a progress bar.
fn film(rendering: &Rendering, score: &crate::score::Score, ex: &ExportArgs) -> anyhow::Result<()> {
    let options = ex.video_options();
    let mut bar = ProgressBar::new();
    let mut progress = |done: u64, total: u64| {
        bar.show(Progress {
            stage: "filming the video",
            fraction: done as f64 / total.max(1) as f64,
        });
        true
    };
    if let Some(path) = &ex.video {
        let spec = exports::video::write_video(rendering, score, options, path, &mut progress)
            .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
        println!(
            "{}: {} frames at {} fps ({:.2} s), {}x{}, with the mix",
            path.display(),
            spec.frames,
            spec.fps,
            spec.duration_s(),
            spec.width,
            spec.height
        );
    }
    if let Some(dir) = &ex.video_frames {
        let (written, spec) =
            exports::video::write_frames(rendering, score, options, dir, false, &mut progress)
                .map_err(|e| anyhow::anyhow!("{}: {e}", dir.display()))?;
        println!(
            "{}: {} PNG frames at {} fps, audio.wav and join.sh (ffmpeg joins them)",
            written.display(),
            spec.frames,
            spec.fps
        );
    }
    bar.finish();
    Ok(())
}

/// `--stats` lists the strokes whose peak force is off its aim by more than this fraction.
const FORCE_AIM_TOLERANCE: f64 = 0.2;

fn print_stats(r: &Rendering, places: &BeatPlaces) {
    let s = &r.stats;
    let contact_hz = 1.0 / r.drums.dt_s();
    let body_hz = contact_hz / r.params.sim.contact_substeps.max(1) as f64;
    let calm = match r.params.sim.calm_substeps {
        0 => String::new(),
        n => format!("; {:.0} Hz while calm", contact_hz / n as f64),
    };
    println!(
        "score: {:.2} s of motion, {} strokes in {} clusters at {body_hz:.0} Hz (body{calm}), \
         {contact_hz:.0} Hz (drums and contact)",
        s.score_s,
        r.composition.strokes.len(),
        s.clusters,
    );
    println!(
        "speed: {:.1}x real time overall (score s per wall s); body+drums {:.1} simulated s \
         per wall s ({:.2} s simulated in {} attempts, retries included)",
        s.realtime_factor(),
        s.simulation_speed(),
        s.simulated_s,
        s.attempts
    );
    let per_cluster: Vec<String> = s
        .attempts_per_cluster
        .iter()
        .enumerate()
        .filter(|(_, n)| **n > 0)
        .map(|(k, n)| format!("{} for {n}", k + 1))
        .collect();
    if !per_cluster.is_empty() {
        println!("attempts per cluster: {} clusters", per_cluster.join(", "));
    }
    println!(
        "time: compose {:.3} s, simulate {:.3} s (drums and contact {:.3} s), sound {:.3} s; \
         total {:.3} s",
        s.compose.as_secs_f64(),
        s.simulate.as_secs_f64(),
        s.drums.as_secs_f64(),
        s.sound.as_secs_f64(),
        s.wall().as_secs_f64()
    );
    if let Some(room) = crate::sound::room::Acoustics::of(r.params.room) {
        println!(
            "room: {} ({:.0} m³, T60 {:.2} s at 125 Hz and {:.2} s at 4 kHz, microphones at \
             {:.1} m: the reverberation {:.1} dB below the direct sound)",
            r.params.room,
            room.volume_m3,
            room.t60_at(125.0),
            room.t60_at(4000.0),
            room.microphone_m,
            10.0 * room.direct_to_reverberant().log10()
        );
    }
    let t = &r.timing;
    println!(
        "timing: median {:.2} ms, worst {:.2} ms, missed {} of {}; normalisation gain {:.3}",
        t.median_abs_s * 1e3,
        t.worst_abs_s * 1e3,
        t.missed,
        t.strokes,
        r.audio.gain
    );
    match r.worst_joint_radius() {
        Some((joint, radius, at_s)) => println!(
            "joint limits: worst {} at {radius:.2} of its ellipsoid (1 = on it) at {at_s:.2} s",
            joint.name()
        ),
        None => println!("joint limits: none held"),
    }
    print_damping(&r.damping, places);
    let forces = strikes::forces_by_dynamic(&r.events);
    let recontacts: usize = forces.iter().map(|f| f.recontacts).sum();
    println!("force by dynamic (peak force of each stroke's contact; re-contacts ≥ 5 N after it):");
    for f in &forces {
        println!(
            "  {:>2}: {:3} strokes, median {:6.1} N ({:+4.0} % to {:+4.0} %), contact {:.1}–{:.1} ms, {} re-contacts",
            f.dynamic,
            f.strokes,
            f.median_n,
            (f.low - 1.0) * 100.0,
            (f.high - 1.0) * 100.0,
            f.shortest_ms,
            f.longest_ms,
            f.recontacts
        );
    }
    println!(
        "re-contacts: {recontacts} after {} strokes",
        forces.iter().map(|f| f.strokes).sum::<usize>()
    );
    let strokes = &r.composition.strokes;
    let off: Vec<String> = (r.events.iter())
        .filter_map(|e| {
            let stroke = strokes.iter().find(|s| Some(s.beat) == e.beat)?;
            let aim = r.params.force_aim_n(stroke.dynamic);
            let ratio = e.peak_force_n / aim;
            ((ratio - 1.0).abs() > FORCE_AIM_TOLERANCE).then(|| {
                format!(
                    "beat {} {:.0} N for {:.0}",
                    places.number(stroke.beat),
                    e.peak_force_n,
                    aim
                )
            })
        })
        .collect();
    println!(
        "force aims ({:.0} N + {:.0} N x velocity): {} of {} strokes off by more than {:.0} %{}{}",
        r.params.force_at_silence_n,
        r.params.force_range_n,
        off.len(),
        strokes.len(),
        FORCE_AIM_TOLERANCE * 100.0,
        if off.is_empty() { "" } else { ": " },
        off.iter().take(8).cloned().collect::<Vec<_>>().join(", ")
    );
}

/// A one-line progress bar on stderr, redrawn when the percentage changes (plain lines
/// per stage when stderr is not a terminal).
struct ProgressBar {
    tty: bool,
    last: Option<(&'static str, u32)>,
}

impl ProgressBar {
    fn new() -> ProgressBar {
        ProgressBar {
            tty: std::io::stderr().is_terminal(),
            last: None,
        }
    }

    fn show(&mut self, p: Progress) {
        let percent = (p.fraction * 100.0).floor() as u32;
        let key = (p.stage, percent);
        if self.last == Some(key) || (!self.tty && self.last.is_some_and(|l| l.0 == p.stage)) {
            return;
        }
        self.last = Some(key);
        let stage = p.stage;
        let mut err = std::io::stderr();
        if self.tty {
            let filled = (percent as usize * 30) / 100;
            let _ = write!(
                err,
                "\r[{}{}] {percent:3}% {stage:<24}",
                "#".repeat(filled),
                "-".repeat(30 - filled)
            );
        } else {
            let _ = writeln!(err, "{stage}...");
        }
        let _ = err.flush();
    }

    fn finish(&mut self) {
        if self.tty && self.last.is_some() {
            eprintln!();
        }
    }
}

/// The `secco` line of `--stats`: how each damped beat's head was stopped.
fn print_damping(d: &crate::render::damping::DampReport, places: &BeatPlaces) {
    let total = d.by_hand.len() + d.missed.len() + d.without_hand.len();
    if total == 0 {
        return;
    }
    let beats = |b: &[usize]| numbers(b, places);
    let (early, late) = d
        .by_hand
        .iter()
        .fold((0.0f64, 0.0f64), |(lo, hi), &(_, off)| {
            (lo.min(off), hi.max(off))
        });
    println!(
        "secco: {total} damped beats; {} touched by the free hand ({:+.0} to {:+.0} ms from the damp tick){}{}",
        d.by_hand.len(),
        early * 1e3,
        late * 1e3,
        if d.missed.is_empty() {
            String::new()
        } else {
            format!(
                "; the hand did not reach the head for beats {} (damped at the tick)",
                beats(&d.missed)
            )
        },
        if d.without_hand.is_empty() {
            String::new()
        } else {
            format!(
                "; no hand free for beats {} (damped at the tick, no gesture)",
                beats(&d.without_hand)
            )
        }
    );
}
