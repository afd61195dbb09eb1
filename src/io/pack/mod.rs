//! The lesson pack (`timpanist export-pack`, File > Export lesson pack): one folder with
//! everything a teacher hands out about a rendered score, written atomically
//! ([`folder`]): the mix and each phrase as WAV ([`phrases`]); the motion as BVH, glTF,
//! C3D and CSV; the performed hits and the score as MIDI; the plots as SVG (tip heights
//! with the beats, peak force per stroke, spectra: `io::figures`); every contact's
//! numbers as CSV; and `index.html` ([`html`]), a self-contained handout that links them
//! all by relative paths. Every file comes from the same writers as `timpanist render`'s
//! (`io::performance`).
//!
//! ```text
//! DIR/index.html
//! DIR/audio/performance.wav, audio/phrase-01.wav, …
//! DIR/motion/performer.bvh, motion/scene.glb, motion/motion.c3d, motion/motion.csv
//! DIR/midi/performed.mid, midi/score.mid
//! DIR/plots/tip-heights.svg, plots/forces.svg, plots/spectra.svg
//! DIR/data/contacts.csv
//! ```

pub mod folder;
pub mod html;
pub mod phrases;

use super::figures;
use super::performance::Performance;
use super::plot::{Figure, PlotError};
use super::{bvh, glb, midi_export};
use crate::base::ron_file::{self, FileError};
use crate::sound::{SoundError, WavFormat};
use folder::Staging;
use html::{Listed, Plot};
use std::fmt::Write;
use std::path::{Path, PathBuf};

/// How to write a pack.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Options {
    /// Most bars in a phrase (see [`phrases`]).
    pub phrase_bars: u32,
    /// Sample format of every WAV.
    pub wav_format: WavFormat,
    /// Replace a target folder that holds files (else refused).
    pub replace: bool,
}

impl Default for Options {
    /// Phrases of up to 4 bars, 16-bit WAVs, never replacing.
    fn default() -> Self {
        Options {
            phrase_bars: 4,
            wav_format: WavFormat::Pcm16,
            replace: false,
        }
    }
}

/// Why a pack was not written (nothing is left at its target then).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PackError {
    #[error(
        "{}: the folder exists and is not empty; choose a new folder (or replace it: --force)",
        path.display()
    )]
    NotEmpty { path: PathBuf },
    #[error("{}: exists and is not a folder", path.display())]
    NotAFolder { path: PathBuf },
    #[error("{}: names no folder", path.display())]
    NoName { path: PathBuf },
    #[error("{}: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error(transparent)]
    File(#[from] FileError),
    #[error(transparent)]
    Sound(#[from] SoundError),
    #[error(transparent)]
    Plot(#[from] PlotError),
    #[error("the BVH: {0}")]
    Bvh(#[from] bvh::BvhError),
    #[error("the glTF scene: {0}")]
    Glb(#[from] glb::GlbError),
}

/// What was written.
#[derive(Clone, Debug, PartialEq)]
pub struct Written {
    /// The pack's folder.
    pub dir: PathBuf,
    /// Its files, relative, with `/`.
    pub files: Vec<String>,
    /// How many phrases have their own audio.
    pub phrases: usize,
}

/// The pack being filled: the staging folder and the files listed so far.
struct Filling<'a> {
    staging: &'a Staging,
    files: Vec<Listed>,
}

impl Filling<'_> {
    /// Write `bytes` as `relative` (folders made as needed) and list it.
    fn put(&mut self, relative: &str, bytes: &[u8], about: &str) -> Result<(), PackError> {
        let path = self.staging.path().join(relative);
        if let Some(parent) = path.parent() {
            std::fs::create_dir_all(parent).map_err(|source| PackError::Io {
                path: parent.to_path_buf(),
                source,
            })?;
        }
        ron_file::write_atomic(&path, bytes)?;
        self.list(relative, about);
        Ok(())
    }

    /// Write `audio` as the WAV `relative` and list it.
    fn wav(
        &mut self,
        relative: &str,
        audio: &crate::sound::Audio,
        format: WavFormat,
        about: &str,
    ) -> Result<(), PackError> {
        let path = self.staging.path().join(relative);
        if let Some(parent) = relative.rsplit_once('/').map(|(dir, _)| dir) {
            self.staging.folder(parent)?;
        }
        crate::sound::write_wav_as(&path, audio, format)?;
        self.list(relative, about);
        Ok(())
    }

    fn list(&mut self, relative: &str, about: &str) {
        self.files.push(Listed {
            path: relative.into(),
            about: about.into(),
        });
    }

    /// Draw `figure` as the SVG `relative`; the page's entry for it.
    fn svg(&mut self, relative: &str, figure: &Figure, caption: &str) -> Result<Plot, PackError> {
        self.put(relative, figure.to_svg()?.as_bytes(), caption)?;
        Ok(Plot {
            path: relative.into(),
            caption: caption.into(),
            size: figure.size,
        })
    }
}

/// Every contact's numbers as CSV: one row per contact, in time order.
pub fn contacts_csv(p: &Performance) -> String {
    let mut out = String::from(
        "beat,hand,drum,scheduled_s,contact_s,timing_error_ms,contact_ms,peak_force_n,\
         impact_speed_mps,x_m,y_m,midi_velocity\n",
    );
    let blank = |v: Option<String>| v.unwrap_or_default();
    for c in &p.contacts {
        let _ = writeln!(
            out,
            "{},{},{},{},{:.4},{},{:.3},{:.2},{:.3},{:.4},{:.4},{}",
            blank(c.beat.map(|b| b.to_string())),
            c.hit.hand(),
            c.hit.drum,
            blank(c.scheduled_s.map(|s| format!("{s:.4}"))),
            c.hit.time_s,
            blank(c.timing_error_s().map(|e| format!("{:.3}", e * 1e3))),
            c.duration_s * 1e3,
            c.hit.peak_force_n,
            c.hit.impact_speed_mps,
            c.hit.x_m,
            c.hit.y_m,
            p.force_scale.velocity(c.hit.peak_force_n),
        );
    }
    out
}

/// Write the lesson pack of `p` into the folder `target` (see the module doc), telling
/// `progress` each step. Nothing appears at `target` until every file is written.
pub fn write(
    p: &Performance,
    target: &Path,
    options: &Options,
    progress: &mut dyn FnMut(&str),
) -> Result<Written, PackError> {
    let staging = Staging::begin(target, options.replace)?;
    let mut pack = Filling {
        staging: &staging,
        files: Vec::new(),
    };
    let format = options.wav_format;

    progress("writing the audio");
    let mix = "audio/performance.wav";
    pack.wav(mix, p.audio, format, "the whole performance, 48 kHz stereo")?;
    let cut = phrases::phrases(p.score, options.phrase_bars);
    let spans = phrases::spans(&cut, p.duration_s());
    progress(&format!("cutting {} phrases", cut.len()));
    let mut listed = Vec::new();
    for (k, (phrase, span)) in cut.into_iter().zip(spans).enumerate() {
        let path = format!("audio/phrase-{:02}.wav", k + 1);
        let about = format!(
            "phrase {} (bars {}–{}), {:.2}–{:.2} s of the performance",
            k + 1,
            phrase.bars.start(),
            phrase.bars.end(),
            span.0,
            span.1
        );
        pack.wav(
            &path,
            &phrases::slice(p.audio, span.0, span.1),
            format,
            &about,
        )?;
        listed.push((phrase, path, span));
    }

    progress("writing the motion (BVH, glTF, C3D, CSV)");
    let bvh = p.bvh(&bvh::Options::default())?;
    let about_bvh = "the performer's skeleton animated (BVH: Y up, metres, 250 Hz; Blender)";
    pack.put("motion/performer.bvh", bvh.as_bytes(), about_bvh)?;
    let about_glb =
        "the scene animated: body, sticks and drums (binary glTF 2.0; Blender, web viewers)";
    pack.put("motion/scene.glb", &p.glb()?, about_glb)?;
    let about_c3d = "joints, stick tips and targets as C3D points (mm, 250 Hz; Mokka, Visual3D)";
    pack.put("motion/motion.c3d", &p.c3d(), about_c3d)?;
    let about_csv =
        "tips, targets and joint rotations per 250 Hz sample (CSV, metres, performer frame)";
    pack.put("motion/motion.csv", p.motion_csv().as_bytes(), about_csv)?;

    progress("writing the MIDI");
    let about_performed = "the hits as performed: a note per stroke at its contact time, velocity from its force (Standard MIDI File)";
    pack.put("midi/performed.mid", &p.performed_midi(), about_performed)?;
    let about_score = "the score as written (Standard MIDI File)";
    pack.put(
        "midi/score.mid",
        &midi_export::export(p.score, p.kit),
        about_score,
    )?;
    let about_contacts =
        "every contact's numbers (CSV): timing error, contact time, peak force, impact speed";
    pack.put(
        "data/contacts.csv",
        contacts_csv(p).as_bytes(),
        about_contacts,
    )?;

    progress("drawing the plots");
    let spectra = figures::first_stroke_spectra(p);
    let plots = [
        pack.svg(
            "plots/tip-heights.svg",
            &figures::tip_heights_figure(p),
            "Stick tip heights: the targets (pale) and the simulated tips, left and right; \
             vertical lines are the scheduled strokes.",
        )?,
        pack.svg(
            "plots/forces.svg",
            &figures::forces_figure(p),
            "Peak contact force of every contact (N), left and right hand.",
        )?,
        pack.svg(
            "plots/spectra.svg",
            &figures::spectra_figure(spectra),
            "Spectrum of each drum's first stroke (0.5 s from its onset, dB re its peak) \
             over the recorded timpani note nearest its pitch.",
        )?,
    ];

    progress("writing the handout");
    let files = pack.files;
    let mut names: Vec<String> = files.iter().map(|f| f.path.clone()).collect();
    let page = html::Page {
        mix,
        phrases: &listed,
        plots: &plots,
        files: &files,
    };
    let index = html::page(p, &page);
    ron_file::write_atomic(&staging.path().join("index.html"), index.as_bytes())?;
    names.insert(0, "index.html".into());

    progress("moving the pack into place");
    let dir = staging.commit()?;
    Ok(Written {
        dir,
        files: names,
        phrases: listed.len(),
    })
}
