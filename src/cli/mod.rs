//! The command line: one subcommand per capability, each a thin call into the library.
//! Errors print as one line (`error: …`) and exit non-zero; commands that write a file
//! compute everything first and write atomically, so a failure leaves no file behind.

mod check;

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
    }
}
