//! File dialogs that always open. The system's dialog (rfd; on Linux through the XDG
//! desktop portal) is used while it works; where it cannot open — no D-Bus session bus,
//! no portal answering (a minimal window manager, a remote X display, Xvfb), or a dialog
//! that "closes" faster than anyone could cancel it — the editor says why once and from
//! then on shows its own in-window file browser ([`super::file_browser`]), with the
//! score's folder, the recent files' folders, the working folder, home and the installed
//! demo scores (`<prefix>/share/timpanist/scores`) as places to start.
//!
//! A request names its [`Purpose`]; the chosen path comes back with it, at once from the
//! system dialog or on a later frame from the in-window one ([`Dialogs::show`]).
//! `TIMPANIST_FILE_DIALOG=window` (or `system`) forces one kind.

use super::export::Export;
use super::file_browser::{FileBrowser, Outcome};
use eframe::egui;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// What the chosen file is for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Purpose {
    /// Open a score or import MIDI or MusicXML.
    Open,
    /// Save the score under a new name.
    SaveScore,
    /// Write an export.
    Export(Export),
}

/// One question for a file.
#[derive(Clone, Debug)]
pub struct Request {
    pub purpose: Purpose,
    pub title: &'static str,
    /// The filter's name and its extensions (without dots).
    pub filter: (&'static str, &'static [&'static str]),
    /// Whether the file is written (a save dialog) rather than read.
    pub save: bool,
    /// The name to suggest when saving.
    pub file_name: Option<String>,
    /// The folder to start in.
    pub folder: Option<PathBuf>,
}

/// Which dialogs to use.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Kind {
    /// The system's, until it fails to open.
    System,
    /// The in-window browser (after the system's failed, or when asked for).
    InWindow,
}

/// What asking gave.
#[derive(Debug, PartialEq)]
pub enum Asked {
    Chosen(Purpose, PathBuf),
    Cancelled(Purpose),
    /// The in-window browser shows; its answer comes from [`Dialogs::show`].
    InWindow,
}

/// A system dialog answering "cancelled" sooner than this did not open.
const FASTEST_HUMAN_CANCEL: Duration = Duration::from_millis(300);

/// The file dialogs of one editor window.
pub struct Dialogs {
    kind: Kind,
    /// Said once, when the in-window browser first replaces the system dialog.
    notice: Option<String>,
    open: Option<Browser>,
}

/// The in-window browser while it shows.
struct Browser {
    purpose: Purpose,
    browser: FileBrowser,
}

impl Dialogs {
    /// Dialogs of `kind` (see [`Dialogs::from_environment`] for the default).
    pub fn new(kind: Kind) -> Dialogs {
        Dialogs {
            kind,
            notice: None,
            open: None,
        }
    }

    /// `TIMPANIST_FILE_DIALOG` when set to `window` or `system`; else the system's
    /// dialog unless there is no session bus for a portal to answer on.
    pub fn from_environment() -> Dialogs {
        let forced = std::env::var("TIMPANIST_FILE_DIALOG").ok();
        match forced.as_deref() {
            Some("window") => Dialogs::new(Kind::InWindow),
            Some("system") => Dialogs::new(Kind::System),
            _ => match no_portal_reason() {
                Some(reason) => {
                    let mut d = Dialogs::new(Kind::InWindow);
                    d.notice = Some(in_window_notice(&reason));
                    d
                }
                None => Dialogs::new(Kind::System),
            },
        }
    }

    /// Whether the in-window browser is showing.
    pub fn is_open(&self) -> bool {
        self.open.is_some()
    }

    /// Why the in-window browser is used, the first time it is (then `None`).
    pub fn take_notice(&mut self) -> Option<String> {
        self.notice.take()
    }

    /// Ask for a file; the folders of `recent_files` are offered as places to start.
    pub fn ask(&mut self, request: Request, recent_files: &[PathBuf]) -> Asked {
        if self.kind == Kind::System {
            let asked = Instant::now();
            match system_dialog(&request) {
                Some(path) => return Asked::Chosen(request.purpose, path),
                None if asked.elapsed() >= FASTEST_HUMAN_CANCEL => {
                    return Asked::Cancelled(request.purpose);
                }
                None => {
                    self.kind = Kind::InWindow;
                    self.notice = Some(in_window_notice(
                        "the system file dialog did not open (no desktop portal answered)",
                    ));
                }
            }
        }
        self.open_in_window(request, recent_files);
        Asked::InWindow
    }

    fn open_in_window(&mut self, request: Request, recent_files: &[PathBuf]) {
        let mut places: Vec<PathBuf> = Vec::new();
        let home = crate::base::dirs::home().map(PathBuf::from);
        let installed_scores = crate::base::dirs::installed_data_dir().map(|d| d.join("scores"));
        let recent_folders = recent_files.iter().filter_map(|f| f.parent());
        let candidates = (request.folder.iter().cloned())
            .chain(recent_folders.map(Path::to_path_buf))
            .chain(std::env::current_dir().ok())
            .chain(home)
            .chain(installed_scores);
        for place in candidates {
            if place.is_dir() && !places.contains(&place) {
                places.push(place);
            }
        }
        let browser = FileBrowser::new(
            request.title,
            request.save,
            request.filter.1,
            places,
            request.file_name,
        );
        self.open = Some(Browser {
            purpose: request.purpose,
            browser,
        });
    }

    /// Draw the in-window browser, if open; its answer once the user picks a file or
    /// closes it.
    pub fn show(&mut self, ctx: &egui::Context) -> Option<Asked> {
        let open = self.open.as_mut()?;
        let answer = match open.browser.show(ctx) {
            Outcome::Open => return None,
            Outcome::Chosen(path) => Asked::Chosen(open.purpose, path),
            Outcome::Cancelled => Asked::Cancelled(open.purpose),
        };
        self.open = None;
        Some(answer)
    }
}

fn in_window_notice(reason: &str) -> String {
    format!("{reason}: using the editor's own file browser")
}

/// Why no desktop portal can answer, if that is known without asking: no D-Bus session
/// bus (Linux only; elsewhere the system dialogs need no portal).
fn no_portal_reason() -> Option<String> {
    if !cfg!(target_os = "linux") {
        return None;
    }
    let address = std::env::var_os("DBUS_SESSION_BUS_ADDRESS").filter(|a| !a.is_empty());
    let runtime_bus = std::env::var_os("XDG_RUNTIME_DIR")
        .map(|d| Path::new(&d).join("bus"))
        .is_some_and(|p| p.exists());
    (address.is_none() && !runtime_bus)
        .then(|| "no D-Bus session bus, so no desktop portal for the system file dialog".into())
}

fn system_dialog(request: &Request) -> Option<PathBuf> {
    let mut dialog = rfd::FileDialog::new().set_title(request.title);
    // A filter with no extension (a folder to create, e.g. the lesson pack) adds none.
    if !request.filter.1.is_empty() {
        dialog = dialog.add_filter(request.filter.0, request.filter.1);
    }
    if let Some(folder) = &request.folder {
        dialog = dialog.set_directory(folder);
    }
    if let Some(name) = &request.file_name {
        dialog = dialog.set_file_name(name);
    }
    if request.save {
        dialog.save_file()
    } else {
        dialog.pick_file()
    }
}
