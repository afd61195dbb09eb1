//! A command's outputs are checked before any work is done, so a long render never ends
//! in a refusal it could have made at once, and a command never writes over a file it
//! reads (`transcribe take.wav -o take.wav` would replace the recording with the score).
//! Each command's paths are sorted into the files it reads, the files it writes and the
//! folders it writes into; refused: a written file that is a read one (after following
//! links and relative parts), two outputs to one file, an output whose folder does not
//! exist or that is a folder, and an output folder that is a file.

use super::{Command, MocapCommand, SoundCommand};
use crate::base::staged::folder_of;
use std::path::{Path, PathBuf};

/// The files `command` reads, the files it writes and the folders it writes into.
struct Paths<'a> {
    read: Vec<&'a Path>,
    written: Vec<&'a Path>,
    folders: Vec<&'a Path>,
}

/// Sorts `command`'s paths ([`Paths`]).
fn paths(command: &Command) -> Paths<'_> {
    let (read, written) = files(command);
    let folders = match command {
        Command::Render { stems, exports, .. } => [stems, &exports.video_frames]
            .into_iter()
            .flat_map(|p| p.as_deref())
            .collect(),
        Command::Mocap(MocapCommand::Import { output, .. }) => vec![output.as_path()],
        _ => Vec::new(),
    };
    Paths {
        read,
        written,
        folders,
    }
}

/// The files `command` reads and the files it writes.
fn files(command: &Command) -> (Vec<&Path>, Vec<&Path>) {
    fn one(p: &Option<std::path::PathBuf>) -> Vec<&Path> {
        p.as_deref().into_iter().collect()
    }
    match command {
        Command::ImportMidi {
            input, output, kit, ..
        }
        | Command::ImportMusicxml {
            input, output, kit, ..
        }
        | Command::Transcribe {
            input, output, kit, ..
        } => {
            let mut read = vec![input.as_path()];
            read.extend(one(kit));
            (read, vec![output.as_path()])
        }
        Command::ExportMidi { score, output } | Command::ExportMusicxml { score, output } => {
            (vec![score.as_path()], vec![output.as_path()])
        }
        Command::Compose {
            score,
            output,
            plot,
            ..
        } => {
            let mut written = vec![output.as_path()];
            written.extend(one(plot));
            (vec![score.as_path()], written)
        }
        Command::Render {
            score,
            wav,
            motion,
            c3d,
            events,
            plot,
            exports,
            ..
        } => {
            let mut written = vec![wav.as_path()];
            for p in [motion, c3d, events, plot, &exports.bvh, &exports.glb]
                .into_iter()
                .chain([&exports.performed_midi, &exports.video])
            {
                written.extend(one(p));
            }
            (vec![score.as_path()], written)
        }
        Command::Sound(SoundCommand::Fit { files, output }) => (
            files.iter().map(|p| p.as_path()).collect(),
            vec![output.as_path()],
        ),
        Command::Sound(SoundCommand::Analyse { files, plot, .. }) => {
            (files.iter().map(|p| p.as_path()).collect(), one(plot))
        }
        Command::Mocap(MocapCommand::Import { files, .. }) => {
            (files.iter().map(|p| p.as_path()).collect(), Vec::new())
        }
        // The score is written where the user says, its own file included.
        Command::Sticking { output, .. } => (Vec::new(), one(output)),
        Command::Sound(SoundCommand::Stroke { wav, .. }) => (Vec::new(), vec![wav.as_path()]),
        _ => (Vec::new(), Vec::new()),
    }
}

/// Where `path` leads: the file it names after following links and relative parts,
/// or, for a file not made yet, its folder's real path joined with its name.
fn identity(path: &Path) -> PathBuf {
    if let Ok(real) = std::fs::canonicalize(path) {
        return real;
    }
    match (std::fs::canonicalize(folder_of(path)), path.file_name()) {
        (Ok(dir), Some(name)) => dir.join(name),
        _ => path.to_path_buf(),
    }
}

/// Refuse `command` if its outputs cannot be written where it is told, or would
/// replace a file it reads ([`Paths`]).
pub fn check_outputs(command: &Command) -> anyhow::Result<()> {
    let Paths {
        read,
        written,
        folders,
    } = paths(command);
    let read: Vec<(PathBuf, &Path)> = read.into_iter().map(|p| (identity(p), p)).collect();
    let mut earlier: Vec<(PathBuf, &Path)> = Vec::new();
    for out in written {
        if out.is_dir() {
            anyhow::bail!("{}: is a folder; give a file name", out.display());
        }
        let folder = folder_of(out);
        if folder.is_file() {
            anyhow::bail!(
                "{}: {} is a file, not a folder",
                out.display(),
                folder.display()
            );
        }
        if !folder.is_dir() {
            anyhow::bail!(
                "{}: the folder {} does not exist",
                out.display(),
                folder.display()
            );
        }
        let id = identity(out);
        if let Some((_, input)) = read.iter().find(|(r, _)| *r == id) {
            anyhow::bail!(
                "{}: this is the file being read ({}); writing there would replace it: choose another output",
                out.display(),
                input.display()
            );
        }
        if let Some((_, other)) = earlier.iter().find(|(e, _)| *e == id) {
            anyhow::bail!(
                "{}: two outputs are asked to go to this one file ({} and {}): give each its own",
                out.display(),
                other.display(),
                out.display()
            );
        }
        earlier.push((id, out));
    }
    for dir in folders {
        if dir.exists() && !dir.is_dir() {
            anyhow::bail!("{}: is a file, not a folder", dir.display());
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    fn command(args: &[&str]) -> Command {
        super::super::Cli::parse_from(args).command.unwrap()
    }

    /// An output that is an input, named another way, is refused, as are two outputs to
    /// one file, an output in a folder that does not exist or under a file, and a stems
    /// folder that is a file; another output is not.
    #[test]
    fn an_input_is_never_an_output() {
        let dir = tempfile::tempdir().unwrap();
        let take = dir.path().join("take.wav");
        std::fs::write(&take, b"RIFF").unwrap();
        let same = dir.path().join(".").join("take.wav");
        let (take_s, same_s) = (take.to_str().unwrap(), same.to_str().unwrap());
        let err = check_outputs(&command(&["timpanist", "transcribe", take_s, "-o", same_s]))
            .unwrap_err()
            .to_string();
        assert!(err.contains("this is the file being read"), "{err}");
        let score = dir.path().join("take.ron");
        let other = command(&[
            "timpanist",
            "transcribe",
            take_s,
            "-o",
            score.to_str().unwrap(),
        ]);
        assert!(check_outputs(&other).is_ok());
        std::fs::write(&score, b"()").unwrap();
        assert!(check_outputs(&other).is_ok());
        let refusal = |out: &Path| {
            let args = [
                "timpanist",
                "transcribe",
                take_s,
                "-o",
                out.to_str().unwrap(),
            ];
            check_outputs(&command(&args)).unwrap_err().to_string()
        };
        let err = refusal(&dir.path().join("nowhere/take.ron"));
        assert!(err.contains("does not exist"), "{err}");
        let err = refusal(&take.join("take.ron"));
        assert!(err.contains("is a file, not a folder"), "{err}");
        for args in [
            vec![
                "timpanist",
                "render",
                score.to_str().unwrap(),
                "--wav",
                score.to_str().unwrap(),
            ],
            vec!["timpanist", "sound", "fit", take_s, "-o", take_s],
            vec![
                "timpanist",
                "export-midi",
                score.to_str().unwrap(),
                "-o",
                score.to_str().unwrap(),
            ],
        ] {
            assert!(check_outputs(&command(&args)).is_err(), "{args:?}");
        }
    }
}
