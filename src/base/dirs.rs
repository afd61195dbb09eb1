//! The user's per-application folders, after the XDG base-directory convention:
//! configuration in `$XDG_CONFIG_HOME/timpanist` (else `~/.config/timpanist`), data in
//! `$XDG_DATA_HOME/timpanist` (else `~/.local/share/timpanist`); and the data installed
//! with the program, `<prefix>/share/timpanist` beside the `<prefix>/bin` holding the
//! executable (`/usr/share/timpanist` for the Debian package). `None` where no home is
//! known.

use std::ffi::OsString;
use std::path::PathBuf;

/// The application's name in every folder below.
pub const APP: &str = "timpanist";

fn xdg(var: &str, fallback: &str) -> Option<PathBuf> {
    std::env::var_os(var)
        .filter(|v| !v.is_empty())
        .map(PathBuf::from)
        .or_else(|| home().map(|h| PathBuf::from(h).join(fallback)))
        .map(|base| base.join(APP))
}

/// The user's home folder (`$HOME`), if set.
pub fn home() -> Option<OsString> {
    std::env::var_os("HOME").filter(|h| !h.is_empty())
}

/// `$XDG_CONFIG_HOME/timpanist` or `~/.config/timpanist`.
pub fn config_dir() -> Option<PathBuf> {
    xdg("XDG_CONFIG_HOME", ".config")
}

/// `$XDG_DATA_HOME/timpanist` or `~/.local/share/timpanist`.
pub fn data_dir() -> Option<PathBuf> {
    xdg("XDG_DATA_HOME", ".local/share")
}

/// `<prefix>/share/timpanist` for the running executable at `<prefix>/bin/timpanist`.
pub fn installed_data_dir() -> Option<PathBuf> {
    let exe = std::env::current_exe().ok()?;
    let prefix = exe.parent()?.parent()?;
    Some(prefix.join("share").join(APP))
}
