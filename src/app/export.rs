//! File > Export: the rendering of the score as it is now, written as a WAV
//! (16-bit stereo 48 kHz, `sound::write_wav`), as motion CSV (`io::motion_csv`, the same
//! columns as `timpanist render --motion`), as motion C3D (`io::motion_c3d`, joints and
//! tips for motion-capture tools), as BVH (`io::bvh`, the skeleton animated for Blender:
//! 250 Hz, metres, as `timpanist render --bvh`), as glTF (`io::glb`, the scene animated,
//! as `timpanist render --glb`); and the score itself as a Standard MIDI File
//! (`io::midi_export`, as `timpanist export-midi`) or as MusicXML (`io::musicxml_export`,
//! as `timpanist export-musicxml`: `.mxl` compressed, else plain); and the lesson pack (`io::pack`, as
//! `timpanist export-pack`: a new folder with the audio, motion, MIDI, plots and an
//! `index.html` handout); and the video (`exports::video`, as `render --video`: the 3D
//! view from the viewport's camera over the timeline, with the mix, through ffmpeg) or
//! its frames as PNGs with the mix (as `render --video-frames`, when there is no ffmpeg). The rendered exports come through `crate::exports`, the same
//! code as the command line's. Each is written atomically (a temporary file or folder
//! beside the target, renamed over it). The rendered exports are refused, with the
//! reason, while the only rendering is of an older version of the score or there is none.

use super::dialogs::{Purpose, Request};
use crate::base::ron_file::{self, FileError};
use crate::exports;
use crate::exports::video::{self, VideoOptions};
use crate::io::pack::{self, PackError};
use crate::io::video::VideoError;
use crate::io::{bvh, glb, midi_export, musicxml_export};
use crate::kit::Kit;
use crate::render::Rendering;
use crate::scene::camera::Camera;
use crate::score::Score;
use crate::sound::SoundError;
use std::path::{Path, PathBuf};

/// What to export.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Export {
    /// The rendered sound.
    Wav,
    /// Simulated and target tips and joint rotations per task sample.
    Motion,
    /// Joint positions and tips per task sample, as C3D points.
    MotionC3d,
    /// The skeleton animated, one frame per task sample (BVH).
    Bvh,
    /// The scene (body, sticks, drums) animated, as binary glTF.
    Glb,
    /// The score (no rendering needed).
    Midi,
    /// The score as MusicXML for notation programs (no rendering needed).
    MusicXml,
    /// The lesson pack: a new folder with everything above and an HTML handout.
    Pack,
    /// The 3D view over the timeline, with the mix, as video through ffmpeg.
    Video,
    /// The same frames as numbered PNGs in a new folder, with the mix (no ffmpeg needed).
    VideoFrames,
}

impl Export {
    /// Every export, in menu order.
    pub const ALL: [Export; 10] = [
        Export::Wav,
        Export::Motion,
        Export::MotionC3d,
        Export::Bvh,
        Export::Glb,
        Export::Midi,
        Export::MusicXml,
        Export::Video,
        Export::VideoFrames,
        Export::Pack,
    ];

    /// The File menu item.
    pub fn menu_label(self) -> &'static str {
        match self {
            Export::Wav => "Export WAV...",
            Export::Motion => "Export motion CSV...",
            Export::MotionC3d => "Export motion C3D...",
            Export::Bvh => "Export motion BVH...",
            Export::Glb => "Export scene glTF...",
            Export::Midi => "Export MIDI...",
            Export::MusicXml => "Export MusicXML...",
            Export::Pack => "Export lesson pack...",
            Export::Video => "Export video...",
            Export::VideoFrames => "Export video frames (PNG + WAV)...",
        }
    }

    /// The dialog's filter: a name and the file extension.
    pub fn filter(self) -> (&'static str, &'static [&'static str]) {
        match self {
            Export::Wav => ("WAV audio", &["wav"]),
            Export::Motion => ("motion CSV", &["csv"]),
            Export::MotionC3d => ("C3D motion capture", &["c3d"]),
            Export::Bvh => ("BVH animation", &["bvh"]),
            Export::Glb => ("binary glTF", &["glb"]),
            Export::Midi => ("Standard MIDI File", &["mid"]),
            Export::MusicXml => ("MusicXML", &["musicxml", "mxl"]),
            // A new folder: no file extension, so the dialogs list folders only.
            Export::Pack => ("lesson pack folder", &[]),
            Export::Video => ("video", &["mp4", "mov", "mkv"]),
            Export::VideoFrames => ("video frames folder", &[]),
        }
    }

    /// A file name to suggest for a score whose file (or title) is `stem`.
    pub fn suggested_name(self, stem: &str) -> String {
        match self {
            Export::Wav => format!("{stem}.wav"),
            Export::Motion => format!("{stem}-motion.csv"),
            Export::MotionC3d => format!("{stem}-motion.c3d"),
            Export::Bvh => format!("{stem}.bvh"),
            Export::Glb => format!("{stem}.glb"),
            Export::Midi => format!("{stem}.mid"),
            Export::MusicXml => format!("{stem}.musicxml"),
            Export::Pack => format!("{stem}-lesson"),
            Export::Video => format!("{stem}.mp4"),
            Export::VideoFrames => format!("{stem}-frames"),
        }
    }

    /// Whether it writes the rendering (else the score).
    pub fn needs_rendering(self) -> bool {
        !matches!(self, Export::Midi | Export::MusicXml)
    }

    /// The bytes of a score export (`None` for the rendered ones).
    fn score_bytes(self, score: &Score, kit: &Kit, path: &Path) -> Option<Vec<u8>> {
        match self {
            Export::Midi => Some(midi_export::export(score, kit)),
            Export::MusicXml => Some(musicxml_export::export_for(path, score, kit)),
            _ => None,
        }
    }
}

/// Where the editor's rendering stands, to decide whether it can be exported.
pub struct RenderState<'a> {
    pub rendering: Option<&'a Rendering>,
    /// Whether `rendering` is of the score as it is now.
    pub current: bool,
    /// Whether a render is running.
    pub busy: bool,
    /// Whether the editor renders at all.
    pub enabled: bool,
    /// Why the latest render failed.
    pub error: Option<&'a str>,
}

impl RenderState<'_> {
    /// Why there is nothing to export, or `None` when the current rendering can be.
    pub fn blocked(&self) -> Option<String> {
        match (self.rendering, self.current) {
            (Some(_), true) => None,
            _ if self.busy => Some("the score is still being rendered".into()),
            _ if self.error.is_some() => Some(format!(
                "the latest render failed ({})",
                self.error.unwrap_or_default()
            )),
            (Some(_), false) => Some("the score changed since it was rendered".into()),
            (None, _) if !self.enabled => Some("rendering is turned off".into()),
            (None, _) => Some("the score has not been rendered yet".into()),
        }
    }
}

/// Why an export was not written.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ExportError {
    #[error("cannot export to {}: the score has not been rendered", path.display())]
    NotRendered { path: PathBuf },
    #[error("cannot export to {}: {source}", path.display())]
    File {
        path: PathBuf,
        #[source]
        source: FileError,
    },
    #[error("cannot export to {}: {source}", path.display())]
    Bvh {
        path: PathBuf,
        #[source]
        source: bvh::BvhError,
    },
    #[error("cannot export to {}: {source}", path.display())]
    Glb {
        path: PathBuf,
        #[source]
        source: glb::GlbError,
    },
    #[error("cannot export to {}: {source}", path.display())]
    Sound {
        path: PathBuf,
        #[source]
        source: SoundError,
    },
    #[error("cannot export the lesson pack: {0}")]
    Pack(#[from] PackError),
    #[error("cannot export to {}: {source}", path.display())]
    Video {
        path: PathBuf,
        #[source]
        source: VideoError,
    },
}

/// Write `what` of the score (played on `kit`) or of its `rendering` to `path` (a video
/// seen from `camera`); a line for the status bar, or why it failed.
pub fn write(
    what: Export,
    (score, kit): (&Score, &Kit),
    rendering: Option<&Rendering>,
    path: &Path,
    camera: Camera,
) -> Result<String, ExportError> {
    let failed = |source| ExportError::File {
        path: path.to_path_buf(),
        source,
    };
    if let Some(bytes) = what.score_bytes(score, kit, path) {
        ron_file::write_atomic(path, &bytes).map_err(failed)?;
        return Ok(format!(
            "exported {} ({} beats, {} bytes)",
            path.display(),
            score.beats.len(),
            bytes.len()
        ));
    }
    let Some(rendering) = rendering else {
        return Err(ExportError::NotRendered {
            path: path.to_path_buf(),
        });
    };
    let performance = exports::performance(rendering, score);
    let samples = format!(
        "exported {} ({} samples at {} Hz)",
        path.display(),
        rendering.motion.poses.len(),
        rendering.motion.rate_hz
    );
    match what {
        Export::Midi | Export::MusicXml => unreachable!("written from the score above"),
        Export::MotionC3d => {
            ron_file::write_atomic(path, &performance.c3d()).map_err(failed)?;
            Ok(samples)
        }
        Export::Bvh => {
            let text = performance
                .bvh(&bvh::Options::default())
                .map_err(|e| ExportError::Bvh {
                    path: path.to_path_buf(),
                    source: e,
                })?;
            ron_file::write_atomic(path, text.as_bytes()).map_err(failed)?;
            Ok(samples)
        }
        Export::Glb => {
            let bytes = performance.glb().map_err(|e| ExportError::Glb {
                path: path.to_path_buf(),
                source: e,
            })?;
            ron_file::write_atomic(path, &bytes).map_err(failed)?;
            Ok(samples)
        }
        Export::Wav => {
            crate::sound::write_wav(path, &rendering.audio).map_err(|source| {
                ExportError::Sound {
                    path: path.to_path_buf(),
                    source,
                }
            })?;
            let a = &rendering.audio;
            Ok(format!(
                "exported {} ({:.1} s, {} Hz, {} channels)",
                path.display(),
                a.frames() as f64 / f64::from(a.rate_hz),
                a.rate_hz,
                a.channels
            ))
        }
        Export::Motion => {
            ron_file::write_atomic(path, performance.motion_csv().as_bytes()).map_err(failed)?;
            Ok(samples)
        }
        Export::Video | Export::VideoFrames => {
            let options = VideoOptions {
                camera,
                ..VideoOptions::default()
            };
            let failed = |source| ExportError::Video {
                path: path.to_path_buf(),
                source,
            };
            let mut go_on = |_, _| true;
            if what == Export::Video {
                let spec = video::write_video(rendering, score, options, path, &mut go_on)
                    .map_err(failed)?;
                Ok(format!(
                    "exported {} ({} frames at {} fps, {:.1} s, with the mix)",
                    path.display(),
                    spec.frames,
                    spec.fps,
                    spec.duration_s()
                ))
            } else {
                let (dir, spec) =
                    video::write_frames(rendering, score, options, path, false, &mut go_on)
                        .map_err(failed)?;
                Ok(format!(
                    "exported {} PNG frames at {} fps, audio.wav and join.sh into {}",
                    spec.frames,
                    spec.fps,
                    dir.display()
                ))
            }
        }
        Export::Pack => {
            let written = pack::write(&performance, path, &pack::Options::default(), &mut |_| {})?;
            Ok(format!(
                "exported the lesson pack {} ({} files, {} phrases; open index.html)",
                written.dir.display(),
                written.files.len(),
                written.phrases
            ))
        }
    }
}

/// The question for where to export `what`: beside `score_path` (when saved), named
/// from `stem` (the score file's stem or the title).
pub fn request(what: Export, score_path: Option<&Path>, stem: &str) -> Request {
    Request {
        purpose: Purpose::Export(what),
        title: what.menu_label().trim_end_matches('.'),
        filter: what.filter(),
        save: true,
        file_name: Some(what.suggested_name(stem)),
        folder: score_path.and_then(Path::parent).map(Path::to_path_buf),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Export is allowed only for a rendering of the current score; otherwise the reason
    /// says what is going on.
    #[test]
    fn blocked_reasons() {
        let state = |current, busy, enabled, error| RenderState {
            rendering: None,
            current,
            busy,
            enabled,
            error,
        };
        assert!(
            state(false, true, true, None)
                .blocked()
                .unwrap()
                .contains("still being rendered")
        );
        assert!(
            state(false, false, true, Some("diverged"))
                .blocked()
                .unwrap()
                .contains("diverged")
        );
        assert!(
            state(false, false, false, None)
                .blocked()
                .unwrap()
                .contains("turned off")
        );
        assert!(
            state(false, false, true, None)
                .blocked()
                .unwrap()
                .contains("not been rendered")
        );
        assert_eq!(Export::Motion.suggested_name("etude"), "etude-motion.csv");
        assert_eq!(Export::Wav.filter().1, ["wav"]);
    }
}
