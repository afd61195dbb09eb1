//! The command line: one subcommand per capability, each a thin call into the library.
//! Errors print as one line (`error: …`) and exit non-zero; commands that write a file
//! compute everything first and write atomically, so a failure leaves no file behind.

mod check;
mod midi;
mod mocap;
mod sticking;

use clap::{Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;

/// Compose timpani gesture scores; hear and see them played by a simulated timpanist.
#[derive(Debug, Parser)]
#[command(name = "timpanist", version, about, long_about = None)]
pub struct Cli {
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
        /// track or channel with GM program 48 (Timpani), a track named like "Timpani",
        /// or the channel-10 percussion.
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
    /// Export a score as a type 1 Standard MIDI File (tempo map, GM Timpani, velocities).
    ExportMidi {
        /// The score (.ron).
        score: PathBuf,
        /// The MIDI file to write.
        #[arg(short, long)]
        output: PathBuf,
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
    /// Motion-capture database: build, inspect, import.
    #[command(subcommand)]
    Mocap(MocapCommand),
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
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

fn run(cli: Cli) -> anyhow::Result<ExitCode> {
    match cli.command {
        None => crate::app::run(None).map(|()| ExitCode::SUCCESS),
        Some(Command::Edit { score }) => crate::app::run(score).map(|()| ExitCode::SUCCESS),
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
        Some(Command::Sticking {
            score,
            method,
            output,
        }) => sticking::run(&score, method.into(), output.as_deref()).map(|()| ExitCode::SUCCESS),
        Some(Command::Mocap(MocapCommand::Synth { output, seed })) => {
            mocap::synth(&output, seed).map(|()| ExitCode::SUCCESS)
        }
        Some(Command::Mocap(MocapCommand::Stats { dir })) => {
            mocap::stats(&dir).map(|()| ExitCode::SUCCESS)
        }
        Some(Command::ExportMidi { score, output }) => {
            midi::export(&score, &output).map(|()| ExitCode::SUCCESS)
        }
    }
}
