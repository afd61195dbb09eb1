//! The command line: one subcommand per capability, each a thin call into the library.
//! Errors print as one line (`error: …`) and exit non-zero; commands that write a file
//! compute everything first and write atomically, so a failure leaves no file behind.

mod args;
mod check;
mod compose;
mod demos;
mod evaluate;
mod midi;
mod mocap;
mod musicxml;
mod osc;
mod overwrite;
mod pack;
mod render;
mod sound;
mod sticking;
mod transcribe;

use crate::io::open::OpenAction;
use args::{
    DynamicArg, GripArg, LocationArg, ModeArg, RoomArg, SideArg, UpArg, parse_format,
    parse_tip_past, parse_tips, parse_vec3,
};
use clap::{Parser, Subcommand};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Compose timpani gesture scores; hear and see them played by a simulated timpanist.
#[derive(Debug, Parser)]
#[command(name = "timpanist", version, about, long_about = None)]
#[command(args_conflicts_with_subcommands = true)]
pub struct Cli {
    /// A file to open in the editor: a score (.ron) opens as it is; a MIDI (.mid) or
    /// MusicXML (.musicxml, .xml, .mxl) file is imported into a new, unsaved score.
    pub file: Option<PathBuf>,
    #[command(subcommand)]
    pub command: Option<Command>,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Open the editor on a score (default: the bundled demo score).
    Edit {
        /// The score to open (.ron).
        score: Option<PathBuf>,
    },
    /// Validate score and kit files; print every problem with its place.
    Check {
        /// Score or kit files (.ron); the kind is read from the file.
        #[arg(required = true)]
        files: Vec<PathBuf>,
    },
    /// Import the timpani part of a Standard MIDI File (type 0 or 1) as a score.
    ImportMidi {
        /// The MIDI file.
        input: PathBuf,
        /// The score to write (.ron).
        #[arg(short, long)]
        output: PathBuf,
        /// The track to read, by index (from 0) or by (part of) its name; default: the
        /// track or channel with GM program 48 (Timpani), a track or instrument named
        /// like "Timpani", "Pk.", "Kettledrums", or the channel-10 percussion.
        #[arg(long)]
        track: Option<String>,
        /// The kit to map pitches onto (default: the bundled standard kit).
        #[arg(long)]
        kit: Option<PathBuf>,
        /// Title of the score (default: the file's sequence name or file name).
        #[arg(long)]
        title: Option<String>,
        /// Turn runs of fast, evenly spaced repeated notes into rolls.
        #[arg(long)]
        detect_rolls: bool,
    },
    /// Import the timpani part of a MusicXML score (.musicxml, .xml or compressed .mxl).
    ImportMusicxml {
        /// The MusicXML file.
        input: PathBuf,
        /// The score to write (.ron).
        #[arg(short, long)]
        output: PathBuf,
        /// The part to read, by id ("P4") or by (part of) its name; default: the part
        /// whose instrument sound is drum.timpani or MIDI program 48, else a part named
        /// like "Timpani", "Tymp.", "Kettledrums", "Pk.", "Pauken" or "Timbales".
        #[arg(long)]
        part: Option<String>,
        /// The kit to map pitches onto (default: the bundled standard kit).
        #[arg(long)]
        kit: Option<PathBuf>,
        /// Title of the score (default: the movement or work title, else the file name).
        #[arg(long)]
        title: Option<String>,
    },
    /// Transcribe a timpani recording (WAV, AIFF, FLAC, MP3, Ogg Vorbis) into a score: strokes, drums and pitches,
    /// dynamics, a tempo map and rolls.
    Transcribe {
        /// The recording (.wav in any encoding, .aiff, .flac, .mp3 or .ogg; any rate;
        /// channels mixed to mono).
        input: PathBuf,
        /// The score to write (.ron).
        #[arg(short, long)]
        output: PathBuf,
        /// The kit whose drums and ranges the pitches go to (default: the bundled standard
        /// kit).
        #[arg(long)]
        kit: Option<PathBuf>,
        /// Title of the score (default: the file name).
        #[arg(long)]
        title: Option<String>,
        /// How stroke energies become dynamics: against timpanist's own calibrated strokes
        /// (absolute), or with the median stroke taken as mf (relative, for recordings at an
        /// unknown gain).
        #[arg(long, value_enum, default_value = "absolute")]
        levels: args::LevelsArg,
    },
    /// Export a score as a type 1 Standard MIDI File (tempo map, GM Timpani, velocities).
    ExportMidi {
        /// The score (.ron).
        score: PathBuf,
        /// The MIDI file to write.
        #[arg(short, long)]
        output: PathBuf,
    },
    /// Export a score's timpani part as MusicXML (partwise 4.0; compressed when OUT ends
    /// in .mxl) for notation programs.
    ExportMusicxml {
        /// The score (.ron).
        score: PathBuf,
        /// The MusicXML file to write (.musicxml, .xml or .mxl).
        #[arg(short, long)]
        output: PathBuf,
    },
    /// List the demo scores built into the program, or write them into a folder (their
    /// kits named by bundled name, so they load anywhere).
    Demos {
        /// Write every demo score into this folder as NAME.ron (an existing file is never
        /// overwritten).
        #[arg(short, long)]
        output: Option<PathBuf>,
    },
    /// Assign hands to the beats marked Auto and print the sticking.
    Sticking {
        /// The score (.ron).
        score: PathBuf,
        /// simple: preferred hand plus alternation (seed 003 Alg. 3.1); pairwise: pair
        /// preferences blended by ρ^Δt (§4.2.2); optimal: dynamic programming over travel,
        /// crossing and repetition costs.
        #[arg(long, value_enum, default_value_t = StickingMethod::Optimal)]
        method: StickingMethod,
        /// Save the score with the hands filled in.
        #[arg(short, long)]
        output: Option<PathBuf>,
    },
    /// Compose the two stick-tip trajectories of a score from the motion database.
    Compose {
        /// The score (.ron).
        score: PathBuf,
        /// CSV to write: time, then x, y, z, beat and phase per hand.
        #[arg(short, long)]
        output: PathBuf,
        /// Also draw tip height and depth against time, beats marked, as a PNG.
        #[arg(long)]
        plot: Option<PathBuf>,
        /// The motion database folder [default: the first of ./mocap,
        /// ~/.local/share/timpanist/mocap, <prefix>/share/timpanist/mocap holding an
        /// index.ron, else the database built into the program].
        #[arg(long)]
        db: Option<PathBuf>,
        /// Seed of the choice among near-equal motion units.
        #[arg(long, default_value_t = 1)]
        seed: u64,
    },
    /// Render a score to sound (and motion): compose, simulate the body striking the modal
    /// drums (at 10 kHz, the body at 5 kHz between contacts and 2.5 kHz while calm) with
    /// timing compensation, synthesise 48 kHz stereo.
    Render {
        /// The score (.ron).
        score: PathBuf,
        /// The WAV to write (48 kHz, stereo).
        #[arg(long)]
        wav: PathBuf,
        /// Also write the simulated motion as CSV (tips, targets, joint rotations, 250 Hz).
        #[arg(long)]
        motion: Option<PathBuf>,
        /// Also write the simulated motion as C3D (joints, tips and targets, mm, 250 Hz).
        #[arg(long)]
        c3d: Option<PathBuf>,
        /// Also write one JSON object per stick-head contact.
        #[arg(long)]
        events: Option<PathBuf>,
        /// Also draw target and simulated tip heights and each contact's peak force (PNG).
        #[arg(long)]
        plot: Option<PathBuf>,
        /// Also write one WAV per drum into this folder (`1-32-inch.wav`, …): what each
        /// head radiates, panned and scaled as in the mix (the stems sum to the mix).
        #[arg(long)]
        stems: Option<PathBuf>,
        /// Print simulated seconds per wall second and where the time went.
        #[arg(long)]
        stats: bool,
        #[command(flatten)]
        how: render::RenderArgs,
        #[command(flatten)]
        exports: render::ExportArgs,
    },
    /// Render a score and write a lesson pack into a new folder: the audio (whole and per
    /// phrase), the motion (BVH, glTF, C3D, CSV), the performed and scored MIDI, plots
    /// (SVG), each contact's numbers (CSV) and a self-contained index.html handout.
    ExportPack {
        /// The score (.ron).
        score: PathBuf,
        /// The folder to write (created; refused if it exists and holds anything).
        #[arg(short, long)]
        output: PathBuf,
        /// Replace the folder if it exists and holds files (the old one is removed only
        /// once the new pack is complete).
        #[arg(long)]
        force: bool,
        /// Most bars in a phrase (a bar of rest also ends a phrase); each phrase gets its
        /// own WAV and player.
        #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u32).range(1..=64))]
        phrase_bars: u32,
        /// Sample format of every WAV: 16- or 24-bit integer PCM or 32-bit float.
        #[arg(long, value_enum, default_value = "16")]
        wav_format: args::WavFormatArg,
        #[command(flatten)]
        how: render::RenderArgs,
    },
    /// Compare the IK, ID and HIMC control pipelines on captured strokes of each playing
    /// mode (seed 000 §3.3): tip RMS error per mode with its spread across trials.
    Evaluate {
        /// Trials per mode (randomised initial posture within 2° per joint, gains within ±10 %).
        #[arg(long, default_value_t = 5)]
        trials: usize,
        /// Write the results as JSON.
        #[arg(long)]
        json: Option<PathBuf>,
        /// Draw the Fig. 5 comparison per mode as PNGs into this folder.
        #[arg(long)]
        plot: Option<PathBuf>,
        /// The motion database folder [default: the first of ./mocap,
        /// ~/.local/share/timpanist/mocap, <prefix>/share/timpanist/mocap holding an
        /// index.ron, else the database built into the program].
        #[arg(long)]
        db: Option<PathBuf>,
        /// Hold every joint within the limits estimated from the database's captured
        /// joints (seed 000 Alg. 1 ellipsoids as restoring torques).
        #[arg(long)]
        joint_limits: bool,
    },
    /// Motion-capture database: build, inspect, import.
    #[command(subcommand)]
    Mocap(MocapCommand),
    /// Sound: measure notes, fit the modal model to recordings.
    #[command(subcommand)]
    Sound(SoundCommand),
}

#[derive(Debug, Subcommand)]
pub enum SoundCommand {
    /// Measure struck notes (WAV): onset, (1,1) pitch, octave-band shares 63 Hz-4 kHz and
    /// spectral centroid over the first second, the (1,1)'s T60 and pitch glide.
    Analyse {
        /// Recordings (WAV, AIFF, FLAC, MP3 or Ogg Vorbis), one note each (the first
        /// onset is measured).
        #[arg(required = true)]
        files: Vec<PathBuf>,
        /// Measure the note starting near these times instead (s, comma-separated; e.g.
        /// the strokes of a render: each is measured from 10 ms before the time given).
        #[arg(long, value_delimiter = ',')]
        at: Vec<f64>,
        /// Also draw each note's spectrum (first 0.5 s) over the embedded recorded note
        /// nearest its (1,1), pitched to it, as a PNG.
        #[arg(long)]
        plot: Option<PathBuf>,
    },
    /// Render one scripted stroke (legato, playing spot, general mallet) on the standard
    /// drum nearest a pitch, to audition the modal sound or compare it with a recording.
    Stroke {
        /// The pitch, e.g. D3.
        #[arg(long, default_value = "D3")]
        pitch: String,
        /// The dynamic.
        #[arg(long, value_enum, default_value_t = DynamicArg::Mf)]
        dynamic: DynamicArg,
        /// Length, s.
        #[arg(long, default_value_t = 2.0)]
        seconds: f64,
        /// The room it is heard in (one microphone of the pair).
        #[arg(long, value_enum, default_value_t = RoomArg::Dry)]
        room: RoomArg,
        /// The WAV to write (48 kHz mono).
        #[arg(long)]
        wav: PathBuf,
    },
    /// Fit the modal sound to recorded notes: band radiation corrections and decays,
    /// the listed partials' decays (README "Sound calibration").
    Fit {
        /// Recorded notes (WAV, AIFF, FLAC, MP3 or Ogg Vorbis), one struck timpani note each [default: the embedded
        /// FluidR3 timpani notes].
        files: Vec<PathBuf>,
        /// The calibration file to write.
        #[arg(short, long, default_value = "kits/sound/modal.ron")]
        output: PathBuf,
    },
}

/// The sticking methods, as named on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum StickingMethod {
    Simple,
    Pairwise,
    Optimal,
}

impl From<StickingMethod> for crate::motion::sticking::Method {
    fn from(m: StickingMethod) -> Self {
        match m {
            StickingMethod::Simple => Self::Simple,
            StickingMethod::Pairwise => Self::Pairwise,
            StickingMethod::Optimal => Self::Optimal,
        }
    }
}

// The import variant carries many options; the enum is parsed once per run, so its size
// does not matter.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Subcommand)]
pub enum MocapCommand {
    /// Build the synthetic motion database (bit-for-bit reproducible from the seed).
    Synth {
        /// The database folder to write.
        #[arg(short, long, default_value = "mocap")]
        output: PathBuf,
        /// Seed of every random choice.
        #[arg(long, default_value_t = 2008)]
        seed: u64,
    },
    /// Read captures (C3D, Motive CSV, Vicon CSV, TRC, plain CSV, or any delimited text
    /// capture through a capture profile), cut them into strokes, align them to the
    /// performer and add them to a database.
    Import {
        /// Capture files.
        #[arg(required = true)]
        files: Vec<PathBuf>,
        /// File format (default: recognised from the content).
        #[arg(long, value_parser = parse_format, conflicts_with = "profile")]
        format: Option<crate::mocap::import::Format>,
        /// Capture profile for a delimited text capture: a shipped name (motive, vicon,
        /// qualisys-3d, qualisys-6d, trc, plain) or a RON file (see `mocap columns`).
        #[arg(long)]
        profile: Option<String>,
        /// The sticks' tracks: "LEFT,RIGHT", "LEFT," / ",RIGHT", or one label (its hand
        /// from --hand, the profile, or the label: StickL, RSTK, …); a stick tracked by
        /// loose markers joins them with "+", from the tip toward the grip
        /// ("RSTK1+RSTK2+RSTK3") [default: from the profile or the labels].
        #[arg(long, value_parser = parse_tips)]
        tips: Option<mocap::TipsArg>,
        /// Which axis of the capture points up: x, y, z, neg-x, neg-y or neg-z (default:
        /// a profile file's; else found from the strokes, which rebound sharply along
        /// it, and when they cannot tell it, y for Motive and TRC, z otherwise).
        #[arg(long, value_enum)]
        up: Option<UpArg>,
        /// Length unit of the file, overriding what it says: mm, cm or m.
        #[arg(long)]
        unit: Option<String>,
        /// For rigid bodies: the tip in the body's frame, metres, "x,y,z" (default: the
        /// profile's, else estimated from the impacts and reported).
        #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
        tip_offset: Option<glam::DVec3>,
        /// For a stick of loose markers along its shaft (--tips A+B+…, from the tip): the
        /// tip's distance past the first marker, metres (default: estimated).
        #[arg(long, value_parser = parse_tip_past)]
        tip_past: Option<f64>,
        /// Place the takes in the performer frame: "auto" fits each take's impacts to
        /// its drum's head, "x,y,z,yaw" (metres, degrees) turns about the vertical then
        /// moves, "none" keeps the capture's coordinates.
        #[arg(long, default_value = "none", allow_hyphen_values = true)]
        align: String,
        /// The kit for --align auto [default: the standard set].
        #[arg(long)]
        kit: Option<PathBuf>,
        /// The drum the takes were played on, by name ("26-inch", "26") or number
        /// [default: a drum named in the file name, else the drum in front of each hand].
        #[arg(long)]
        drum: Option<String>,
        /// Take the files two by two: the left stick's file, then the right stick's file
        /// of the same take (same rate, first frames together).
        #[arg(long)]
        pair: bool,
        /// Playing mode of every stroke (default: from the file name).
        #[arg(long, value_enum)]
        mode: Option<ModeArg>,
        /// Impact location (default: from the file name, else the playing spot).
        #[arg(long, value_enum)]
        location: Option<LocationArg>,
        /// The hand of a one-stick file, or keep only this hand's strokes.
        #[arg(long, value_enum)]
        hand: Option<SideArg>,
        /// Dynamic (default: from the file name, else mf).
        #[arg(long, value_enum)]
        dynamic: Option<DynamicArg>,
        /// Grip (default: from the file name, else French).
        #[arg(long, value_enum)]
        grip: Option<GripArg>,
        /// Who played.
        #[arg(long, default_value = "unknown")]
        performer: String,
        /// The database folder (created, or added to).
        #[arg(short, long)]
        output: PathBuf,
    },
    /// Show how a delimited text capture is laid out: delimiter, header, metadata,
    /// columns with their first values, and the tracks a profile finds; for writing a
    /// capture profile.
    Columns {
        /// The capture file.
        file: PathBuf,
        /// Read it with this profile (shipped name or RON file) [default: plain
        /// auto-detection].
        #[arg(long)]
        profile: Option<String>,
    },
    /// Write a test corpus of captures the way real labs write them (lab offset and
    /// turn, millimetres, rigid bodies off the tip, one stick per file, gaps, noise;
    /// Motive, Vicon, Qualisys 6D, TRC, C3D and a vendor CSV) from the shipped database and
    /// the real TrajOptDrums stroke, with the ground truth in truth.ron.
    Corpus {
        /// The folder to write.
        output: PathBuf,
        /// Seed of the noise and gaps.
        #[arg(long, default_value_t = 1)]
        seed: u64,
    },
    /// Per playing mode: tip height and depth range, impact speed, stroke duration; per
    /// joint: the limit ellipsoid.
    Stats {
        /// The database folder.
        #[arg(default_value = "mocap")]
        dir: PathBuf,
    },
}

/// Run the command line; returns the process exit code.
pub fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {}", report(&e));
            ExitCode::FAILURE
        }
    }
}

fn db_or_default(db: Option<PathBuf>) -> crate::mocap::shipped::DbSource {
    crate::mocap::shipped::DbSource::named_or_located(db)
}

/// An error and its causes, each said once: a cause whose text its effect already
/// quotes (as `path: cause` errors do) is not repeated.
fn report(e: &anyhow::Error) -> String {
    let mut text = String::new();
    for cause in e.chain().map(ToString::to_string) {
        if !text.contains(&cause) {
            if !text.is_empty() {
                text.push_str(": ");
            }
            text.push_str(&cause);
        }
    }
    text
}

/// Open the editor (built with the default `editor` feature).
#[cfg(feature = "editor")]
fn edit(score: Option<PathBuf>) -> anyhow::Result<ExitCode> {
    crate::app::run(score).map(|()| ExitCode::SUCCESS)
}

/// `timpanist FILE`: open a score, or import a MIDI or MusicXML file (errors and what the
/// import reports go to the terminal, before any window opens) and open the result.
fn open_file(path: &Path) -> anyhow::Result<ExitCode> {
    match crate::io::open::action_for(path)? {
        OpenAction::Edit(score) => edit(Some(score)),
        OpenAction::Import(file, _) => {
            let opened = crate::io::open::read(&file)?;
            eprintln!("{}", opened.message.split("; ").next().unwrap_or_default());
            for n in &opened.notices {
                eprintln!("note: {n}");
            }
            edit_document(opened)
        }
    }
}

/// Open the editor on an imported document.
#[cfg(feature = "editor")]
fn edit_document(opened: crate::io::open::Opened) -> anyhow::Result<ExitCode> {
    crate::app::run_document(opened).map(|()| ExitCode::SUCCESS)
}

/// A headless build has no editor: say how to get one.
#[cfg(not(feature = "editor"))]
fn edit_document(_opened: crate::io::open::Opened) -> anyhow::Result<ExitCode> {
    edit(None)
}

/// A headless build has no editor: say how to get one.
#[cfg(not(feature = "editor"))]
fn edit(_score: Option<PathBuf>) -> anyhow::Result<ExitCode> {
    anyhow::bail!(
        "this timpanist was built without the editor (cargo's --no-default-features); \
         rebuild it with the default features (`cargo install --path .` or `cargo build`) \
         to open the editor, or use the other commands (`timpanist --help`)"
    )
}

fn run(cli: Cli) -> anyhow::Result<ExitCode> {
    if let Some(command) = &cli.command {
        overwrite::check_outputs(command)?;
    }
    match cli.command {
        None => match cli.file {
            Some(file) => open_file(&file),
            None => edit(None),
        },
        Some(Command::Edit { score }) => edit(score),
        Some(Command::Check { files }) => Ok(check::run(&files)),
        Some(Command::ImportMidi {
            input,
            output,
            track,
            kit,
            title,
            detect_rolls,
        }) => midi::import(&input, &output, track, kit.as_deref(), title, detect_rolls)
            .map(|()| ExitCode::SUCCESS),
        Some(Command::ImportMusicxml {
            input,
            output,
            part,
            kit,
            title,
        }) => musicxml::import(&input, &output, part, kit.as_deref(), title)
            .map(|()| ExitCode::SUCCESS),
        Some(Command::Transcribe {
            input,
            output,
            kit,
            title,
            levels,
        }) => transcribe::run(&input, &output, kit.as_deref(), title, levels.into())
            .map(|()| ExitCode::SUCCESS),
        Some(Command::Demos { output }) => {
            demos::run(output.as_deref()).map(|()| ExitCode::SUCCESS)
        }
        Some(Command::Sticking {
            score,
            method,
            output,
        }) => sticking::run(&score, method.into(), output.as_deref()).map(|()| ExitCode::SUCCESS),
        Some(Command::Compose {
            score,
            output,
            plot,
            db,
            seed,
        }) => compose::run(&score, &db_or_default(db), &output, plot.as_deref(), seed)
            .map(|()| ExitCode::SUCCESS),
        Some(Command::Render {
            score,
            wav,
            motion,
            c3d,
            events,
            plot,
            stems,
            stats,
            how,
            exports,
        }) => render::run(
            &score,
            &db_or_default(how.db.clone()),
            &render::Outputs {
                wav: &wav,
                motion: motion.as_deref(),
                c3d: c3d.as_deref(),
                events: events.as_deref(),
                plot: plot.as_deref(),
                stems: stems.as_deref(),
                exports: &exports,
            },
            &how.choices(stats),
        )
        .map(|()| ExitCode::SUCCESS),
        Some(Command::ExportPack {
            score,
            output,
            force,
            phrase_bars,
            wav_format,
            how,
        }) => pack::run(
            &score,
            &db_or_default(how.db.clone()),
            &output,
            &crate::io::pack::Options {
                phrase_bars,
                wav_format: wav_format.into(),
                replace: force,
            },
            &how.choices(false),
        )
        .map(|()| ExitCode::SUCCESS),
        Some(Command::Evaluate {
            trials,
            json,
            plot,
            db,
            joint_limits,
        }) => evaluate::run(
            &db_or_default(db),
            trials,
            joint_limits,
            (json.as_deref(), plot.as_deref()),
        )
        .map(|()| ExitCode::SUCCESS),
        Some(Command::Mocap(MocapCommand::Synth { output, seed })) => {
            mocap::synth(&output, seed).map(|()| ExitCode::SUCCESS)
        }
        Some(Command::Mocap(MocapCommand::Import {
            files,
            format,
            profile,
            tips,
            up,
            unit,
            tip_offset,
            tip_past,
            align,
            kit,
            drum,
            pair,
            mode,
            location,
            hand,
            dynamic,
            grip,
            performer,
            output,
        })) => mocap::import(mocap::ImportArgs {
            files,
            format,
            profile,
            tips: tips.unwrap_or(mocap::TipsArg::Unnamed),
            up: up.map(Into::into),
            unit,
            tip_offset_m: tip_offset,
            tip_past_m: tip_past,
            align,
            kit,
            drum,
            pair,
            mode: mode.map(Into::into),
            location: location.map(Into::into),
            hand: hand.map(Into::into),
            dynamic: dynamic.map(Into::into),
            grip: grip.map(Into::into),
            performer,
            output,
        })
        .map(|()| ExitCode::SUCCESS),
        Some(Command::Mocap(MocapCommand::Columns { file, profile })) => {
            mocap::columns(&file, profile.as_deref()).map(|()| ExitCode::SUCCESS)
        }
        Some(Command::Mocap(MocapCommand::Corpus { output, seed })) => {
            mocap::corpus(&output, seed).map(|()| ExitCode::SUCCESS)
        }
        Some(Command::Mocap(MocapCommand::Stats { dir })) => {
            mocap::stats(&dir).map(|()| ExitCode::SUCCESS)
        }
        Some(Command::Sound(SoundCommand::Analyse { files, at, plot })) => {
            sound::analyse(&files, &at, plot.as_deref()).map(|()| ExitCode::SUCCESS)
        }
        Some(Command::Sound(SoundCommand::Stroke {
            pitch,
            dynamic,
            seconds,
            room,
            wav,
        })) => sound::stroke((&pitch, dynamic.into()), seconds, room.into(), &wav)
            .map(|()| ExitCode::SUCCESS),
        Some(Command::Sound(SoundCommand::Fit { files, output })) => {
            sound::fit(&files, &output).map(|()| ExitCode::SUCCESS)
        }
        Some(Command::ExportMidi { score, output }) => {
            midi::export(&score, &output).map(|()| ExitCode::SUCCESS)
        }
        Some(Command::ExportMusicxml { score, output }) => {
            musicxml::export(&score, &output).map(|()| ExitCode::SUCCESS)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A cause the error's own text already quotes is not repeated; contexts are kept.
    #[test]
    fn report_says_each_cause_once() {
        let io = std::io::Error::new(std::io::ErrorKind::NotFound, "no such file");
        let e = anyhow::Error::new(crate::base::ron_file::FileError::Io {
            path: PathBuf::from("mocap/index.ron"),
            source: io,
        })
        .context("loading the database");
        assert_eq!(
            report(&e),
            "loading the database: mocap/index.ron: no such file"
        );
    }
}
