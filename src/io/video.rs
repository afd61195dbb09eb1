//! Video files from frames and a mix: through the system's `ffmpeg` (H.264 and AAC in MP4,
//! MOV or Matroska; the program is found on `PATH`, or named by the `TIMPANIST_FFMPEG`
//! environment variable), or, without ffmpeg, as a folder of numbered PNG frames with the
//! mix as a WAV and the ffmpeg command that joins them. Frames come from the caller, one at
//! a time, as RGBA bytes (for the encoder) or PNG bytes (for the folder); the caller's
//! progress callback can stop the work. Both outputs are atomic: the video is encoded into
//! a hidden file beside its target and renamed over it, the folder is staged as the lesson
//! pack's is (`pack::folder`), so a failure or a stop leaves nothing half-written.

use super::pack::PackError;
use super::pack::folder::Staging;
use crate::sound::{Audio, SoundError, write_wav};
use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

/// Frame rates a video may have, per second.
pub const FRAME_RATES: [u32; 2] = [30, 60];

/// The environment variable naming the ffmpeg program to use.
pub const FFMPEG_VAR: &str = "TIMPANIST_FFMPEG";

/// A video's frames.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct VideoSpec {
    /// Frame size, px (even, as H.264 in 4:2:0 needs).
    pub width: u32,
    pub height: u32,
    /// Frames per second (one of [`FRAME_RATES`]).
    pub fps: u32,
    /// How many frames.
    pub frames: u64,
}

impl VideoSpec {
    /// The frames' length, s.
    pub fn duration_s(&self) -> f64 {
        self.frames as f64 / f64::from(self.fps)
    }

    fn check(&self) -> Result<(), VideoError> {
        if !FRAME_RATES.contains(&self.fps) {
            return Err(VideoError::FrameRate { fps: self.fps });
        }
        let side = |v: u32| (64..=4096).contains(&v) && v.is_multiple_of(2);
        if !side(self.width) || !side(self.height) {
            return Err(VideoError::Size(self.width, self.height));
        }
        if self.frames == 0 {
            return Err(VideoError::Empty);
        }
        Ok(())
    }
}

/// Why a video was not written.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum VideoError {
    #[error(
        "ffmpeg was not found ({program}: {reason}): install it (Debian/Ubuntu: apt install ffmpeg), \
         point {FFMPEG_VAR} at it, or write PNG frames and the WAV instead (`render --video-frames DIR`, \
         File > Export video frames)"
    )]
    NoFfmpeg { program: String, reason: String },
    #[error("{}: a video must end in .mp4, .mov or .mkv", path.display())]
    Extension { path: PathBuf },
    #[error("{fps} frames per second: choose 30 or 60")]
    FrameRate { fps: u32 },
    #[error("a {0}×{1} px video: each side must be even, 64–4096 px")]
    Size(u32, u32),
    #[error("nothing to film: the rendering is empty")]
    Empty,
    #[error("frame {index}: {size} bytes, {expected} expected ({width}×{height} RGBA)")]
    FrameSize {
        index: u64,
        size: usize,
        expected: usize,
        width: u32,
        height: u32,
    },
    #[error("ffmpeg failed writing {}: {message}", path.display())]
    Ffmpeg { path: PathBuf, message: String },
    #[error("{}: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("the mix: {0}")]
    Sound(#[from] SoundError),
    #[error(transparent)]
    Folder(#[from] PackError),
    #[error("frame {index}: {message}")]
    Frame { index: u64, message: String },
    #[error("stopped: nothing was written")]
    Stopped,
}

/// The ffmpeg program to run: `TIMPANIST_FFMPEG`, else `ffmpeg` on `PATH`.
pub fn ffmpeg_program() -> String {
    std::env::var(FFMPEG_VAR)
        .ok()
        .filter(|v| !v.trim().is_empty())
        .unwrap_or_else(|| "ffmpeg".to_string())
}

/// The first line of `ffmpeg -version` (e.g. "ffmpeg version 5.1.6 …"), or why ffmpeg
/// cannot be run.
pub fn ffmpeg_version() -> Result<String, VideoError> {
    let program = ffmpeg_program();
    let missing = |reason: String| VideoError::NoFfmpeg {
        program: program.clone(),
        reason,
    };
    let out = Command::new(&program)
        .arg("-version")
        .stdin(Stdio::null())
        .output()
        .map_err(|e| missing(e.to_string()))?;
    if !out.status.success() {
        return Err(missing(format!("`-version` exited with {}", out.status)));
    }
    let text = String::from_utf8_lossy(&out.stdout);
    Ok(text.lines().next().unwrap_or("ffmpeg").trim().to_string())
}

/// The container of a video path, by extension.
fn container(path: &Path) -> Result<&'static str, VideoError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("mp4") => Ok("mp4"),
        Some("mov") => Ok("mov"),
        Some("mkv") => Ok("matroska"),
        _ => Err(VideoError::Extension {
            path: path.to_path_buf(),
        }),
    }
}

/// Whether a video may be written at `path`: its extension names a container and its
/// folder exists. Changes nothing.
pub fn check_target(path: &Path) -> Result<(), VideoError> {
    container(path)?;
    match path.parent() {
        Some(dir) if !dir.as_os_str().is_empty() && !dir.is_dir() => Err(VideoError::Io {
            path: dir.to_path_buf(),
            source: std::io::Error::new(std::io::ErrorKind::NotFound, "no such folder"),
        }),
        _ => Ok(()),
    }
}

/// Encode `spec.frames` frames (`frame(k)`: frame k's RGBA bytes, rows from the top) with
/// `audio` into the video `out` through ffmpeg. `progress(k)` is called after each frame
/// with the frames done; returning false stops, leaving nothing at `out`.
pub fn encode(
    out: &Path,
    spec: &VideoSpec,
    audio: &Audio,
    frame: &mut dyn FnMut(u64) -> Result<Vec<u8>, VideoError>,
    progress: &mut dyn FnMut(u64) -> bool,
) -> Result<(), VideoError> {
    spec.check()?;
    check_target(out)?;
    let format = container(out)?;
    ffmpeg_version()?;
    let dir = crate::base::staged::folder_of(out).to_path_buf();
    let io = |path: &Path| {
        let path = path.to_path_buf();
        move |source| VideoError::Io { path, source }
    };
    let name = out
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let dest = crate::base::staged::destination(out);
    let staged = crate::base::staged::beside(&dest, &format!(".{name}.partial"))
        .map_err(io(&dir))?
        .into_temp_path();
    // The mix beside it, for ffmpeg to read (removed when `wav` drops).
    let wav = tempfile::Builder::new()
        .prefix(".timpanist-mix-")
        .suffix(".wav")
        .tempfile_in(&dir)
        .map_err(io(&dir))?
        .into_temp_path();
    write_wav(&wav, audio)?;
    let size = format!("{}x{}", spec.width, spec.height);
    let fps = spec.fps.to_string();
    let duration = format!("{:.6}", spec.duration_s());
    let mut child = Command::new(ffmpeg_program())
        .args(["-hide_banner", "-loglevel", "error", "-nostdin", "-y"])
        .args([
            "-f", "rawvideo", "-pix_fmt", "rgba", "-s", &size, "-r", &fps,
        ])
        .args(["-i", "pipe:0"])
        .arg("-i")
        .arg(&*wav)
        .args(["-map", "0:v:0", "-map", "1:a:0"])
        .args(["-c:v", "libx264", "-preset", "veryfast", "-crf", "20"])
        .args(["-pix_fmt", "yuv420p", "-threads", "1"])
        .args(["-c:a", "aac", "-b:a", "192k"])
        .args(["-t", &duration])
        .args(["-f", format])
        .arg(&*staged)
        .stdin(Stdio::piped())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| VideoError::NoFfmpeg {
            program: ffmpeg_program(),
            reason: e.to_string(),
        })?;
    let mut stderr = child.stderr.take().expect("stderr is piped");
    let errors = std::thread::spawn(move || {
        let mut text = String::new();
        let _ = stderr.read_to_string(&mut text);
        text
    });
    let expected = 4 * spec.width as usize * spec.height as usize;
    let mut stdin = child.stdin.take().expect("stdin is piped");
    let fed = (|| {
        for k in 0..spec.frames {
            let rgba = frame(k)?;
            if rgba.len() != expected {
                return Err(VideoError::FrameSize {
                    index: k,
                    size: rgba.len(),
                    expected,
                    width: spec.width,
                    height: spec.height,
                });
            }
            // A broken pipe means ffmpeg stopped: its own message says why (below).
            if stdin.write_all(&rgba).is_err() {
                return Ok(false);
            }
            if !progress(k + 1) {
                return Err(VideoError::Stopped);
            }
        }
        Ok(true)
    })();
    drop(stdin);
    if fed.is_err() {
        let _ = child.kill();
    }
    let status = child.wait().map_err(io(out))?;
    let message = errors.join().unwrap_or_default();
    fed?;
    if !status.success() {
        return Err(VideoError::Ffmpeg {
            path: out.to_path_buf(),
            message: format!("{status}: {}", message.trim()),
        });
    }
    crate::base::staged::put(staged, &dest).map_err(io(out))
}

/// The frames as the new folder `dir` (refused if it holds anything, unless `replace`):
/// `frames/frame-000001.png` … (`frame(k)`: frame k's PNG bytes), `audio.wav` and
/// `join.sh`, the ffmpeg command that makes the video from them. `progress` as in
/// [`encode`]. Returns the folder.
pub fn write_frames(
    dir: &Path,
    replace: bool,
    spec: &VideoSpec,
    audio: &Audio,
    frame: &mut dyn FnMut(u64) -> Result<Vec<u8>, VideoError>,
    progress: &mut dyn FnMut(u64) -> bool,
) -> Result<PathBuf, VideoError> {
    spec.check()?;
    let staging = Staging::begin(dir, replace)?;
    let frames = staging.folder("frames")?;
    for k in 0..spec.frames {
        let png = frame(k)?;
        let path = frames.join(format!("frame-{:06}.png", k + 1));
        std::fs::write(&path, png).map_err(|source| VideoError::Io { path, source })?;
        if !progress(k + 1) {
            return Err(VideoError::Stopped);
        }
    }
    write_wav(&staging.path().join("audio.wav"), audio)?;
    let script = format!(
        "#!/bin/sh\n# Join the frames and the mix into video.mp4 ({} frames at {} fps, {:.3} s).\n\
         cd \"$(dirname \"$0\")\" && ffmpeg -framerate {} -i frames/frame-%06d.png -i audio.wav \\\n  \
         -c:v libx264 -pix_fmt yuv420p -c:a aac -b:a 192k -t {:.6} video.mp4\n",
        spec.frames,
        spec.fps,
        spec.duration_s(),
        spec.fps,
        spec.duration_s()
    );
    let path = staging.path().join("join.sh");
    std::fs::write(&path, script).map_err(|source| VideoError::Io {
        path: path.clone(),
        source,
    })?;
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o755))
            .map_err(|source| VideoError::Io { path, source })?;
    }
    Ok(staging.commit()?)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec() -> VideoSpec {
        VideoSpec {
            width: 64,
            height: 64,
            fps: 30,
            frames: 3,
        }
    }

    fn silence() -> Audio {
        Audio {
            rate_hz: 48_000,
            channels: 2,
            samples: vec![0.0; 2 * 4800].into(),
            gain: 1.0,
        }
    }

    /// Frame rates, sizes and extensions outside what is offered are refused, naming why.
    #[test]
    fn refusals_name_the_reason() {
        let bad_fps = VideoSpec { fps: 25, ..spec() };
        assert!(matches!(
            bad_fps.check(),
            Err(VideoError::FrameRate { fps: 25 })
        ));
        let odd = VideoSpec {
            width: 65,
            ..spec()
        };
        assert!(matches!(odd.check(), Err(VideoError::Size(65, 64))));
        assert!(matches!(
            container(Path::new("a.avi")),
            Err(VideoError::Extension { .. })
        ));
        assert_eq!(container(Path::new("a.MKV")).unwrap(), "matroska");
        assert!((spec().duration_s() - 0.1).abs() < 1e-12);
    }

    /// The PNG folder holds every frame, the mix and the join script; a stop leaves nothing.
    #[test]
    fn frames_folder_is_whole_or_absent() {
        let tmp = tempfile::tempdir().unwrap();
        let target = tmp.path().join("frames-out");
        let png = |_: u64| Ok(b"\x89PNG fake".to_vec());
        let written = write_frames(
            &target,
            false,
            &spec(),
            &silence(),
            &mut { png },
            &mut |_| true,
        )
        .unwrap();
        assert!(written.join("frames/frame-000003.png").is_file());
        assert!(!written.join("frames/frame-000004.png").exists());
        assert!(written.join("audio.wav").is_file());
        let script = std::fs::read_to_string(written.join("join.sh")).unwrap();
        assert!(script.contains("-framerate 30"), "{script}");
        let stopped = tmp.path().join("stopped");
        let err = write_frames(
            &stopped,
            false,
            &spec(),
            &silence(),
            &mut { png },
            &mut |k| k < 2,
        );
        assert!(matches!(err, Err(VideoError::Stopped)));
        assert!(!stopped.exists());
        let names: Vec<_> = std::fs::read_dir(tmp.path()).unwrap().collect();
        assert_eq!(names.len(), 1, "only the first folder is left: {names:?}");
    }
}
