//! The editor's preferences, kept in `preferences.ron` in the configuration folder
//! (`~/.config/timpanist`, `base::dirs`) and written atomically on every change: the
//! audio output device and buffer size, the kit of a new score, the motion database,
//! the theme and UI scale, and the folder exports are offered in. Every field has a
//! default, so an older or partial file loads; an unreadable one is reported and left
//! alone (the defaults are used until the next change writes a new one).

use crate::base::ron_file::{self, FileError};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The format this timpanist writes.
const VERSION: u32 = 1;

/// The window's colours.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum Theme {
    /// As the desktop says.
    #[default]
    System,
    Dark,
    Light,
}

impl Theme {
    pub const ALL: [Theme; 3] = [Theme::System, Theme::Dark, Theme::Light];

    pub fn label(self) -> &'static str {
        match self {
            Theme::System => "as the system",
            Theme::Dark => "dark",
            Theme::Light => "light",
        }
    }
}

/// What the user chose (see the module doc).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, rename = "Preferences")]
pub struct Preferences {
    pub version: u32,
    /// The output device's name; `None` is the system's default device.
    pub audio_device: Option<String>,
    /// Frames per audio buffer; `None` lets the device choose. Smaller answers sooner
    /// (256 frames at 48 kHz: 5.3 ms) at the risk of dropouts.
    pub buffer_frames: Option<u32>,
    /// The bundled kit a new score uses.
    pub default_kit: String,
    /// The motion database folder; `None` searches as the command line does
    /// (`mocap::shipped`). Read when the editor starts.
    pub database: Option<PathBuf>,
    pub theme: Theme,
    /// UI scale (1 = egui's size), 0.5–3.
    pub ui_scale: f32,
    /// Where exports are offered first; `None` is beside the score.
    pub export_folder: Option<PathBuf>,
}

impl Default for Preferences {
    fn default() -> Self {
        Preferences {
            version: VERSION,
            audio_device: None,
            buffer_frames: None,
            default_kit: "standard".into(),
            database: None,
            theme: Theme::System,
            ui_scale: 1.0,
            export_folder: None,
        }
    }
}

/// Buffer sizes offered, frames.
pub const BUFFER_FRAMES: [u32; 6] = [128, 256, 512, 1024, 2048, 4096];

/// The range the UI scale is held to.
pub const UI_SCALE_RANGE: std::ops::RangeInclusive<f32> = 0.5..=3.0;

/// `preferences.ron` in the configuration folder, if a home is known.
pub fn default_file() -> Option<PathBuf> {
    crate::base::dirs::config_dir().map(|d| d.join("preferences.ron"))
}

impl Preferences {
    /// The preferences in `file`: the defaults when there is no file (or no `file`), an
    /// error naming the file when it cannot be read.
    pub fn load(file: Option<&Path>) -> Result<Preferences, FileError> {
        let Some(file) = file.filter(|f| f.exists()) else {
            return Ok(Preferences::default());
        };
        let mut prefs: Preferences = ron_file::parse(file, &ron_file::read_text(file)?)?;
        if prefs.version > VERSION {
            return Err(ron_file::unsupported_version(file, prefs.version, VERSION));
        }
        prefs.version = VERSION;
        prefs.ui_scale = prefs
            .ui_scale
            .clamp(*UI_SCALE_RANGE.start(), *UI_SCALE_RANGE.end());
        if crate::kit::Kit::bundled(&prefs.default_kit).is_none() {
            prefs.default_kit = Preferences::default().default_kit;
        }
        Ok(prefs)
    }

    /// Write to `file` atomically (creating its folder).
    pub fn save(&self, file: &Path) -> Result<(), FileError> {
        if let Some(dir) = file.parent() {
            std::fs::create_dir_all(dir).map_err(|e| FileError::io(dir, e))?;
        }
        ron_file::save(file, self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Saved then loaded gives the same; a missing file is the defaults; a partial file
    /// takes defaults for what it lacks; out-of-range values are brought in; a broken
    /// file is an error naming it.
    #[test]
    fn round_trip_defaults_and_errors() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("sub/preferences.ron");
        assert_eq!(
            Preferences::load(Some(&file)).unwrap(),
            Preferences::default()
        );
        let prefs = Preferences {
            audio_device: Some("USB Audio".into()),
            buffer_frames: Some(256),
            default_kit: "pair".into(),
            database: Some("/data/mocap".into()),
            theme: Theme::Light,
            ui_scale: 1.25,
            export_folder: Some("/exports".into()),
            ..Preferences::default()
        };
        prefs.save(&file).unwrap();
        assert_eq!(Preferences::load(Some(&file)).unwrap(), prefs);

        std::fs::write(&file, "(ui_scale: 9.0, default_kit: \"nonesuch\")").unwrap();
        let partial = Preferences::load(Some(&file)).unwrap();
        assert_eq!(partial.ui_scale, 3.0);
        assert_eq!(partial.default_kit, "standard");
        assert_eq!(partial.theme, Theme::System);

        std::fs::write(&file, "(theme: Purple)").unwrap();
        let err = Preferences::load(Some(&file)).unwrap_err().to_string();
        assert!(err.contains("preferences.ron"), "{err}");
    }
}
