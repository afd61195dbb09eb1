//! The editor's own file browser, shown in the window as a modal where the system's file
//! dialog cannot open: places to start (the score's folder, the recent files' folders,
//! the working folder, home) beside the folder's subfolders and the files the filter
//! admits, a path field, a file-name field, Open or Save and Cancel. Keyboard: Enter
//! opens or saves, Escape cancels, Backspace in an empty name field goes up a folder.
//! Saving over an existing file asks first; a name typed without the filter's extension
//! gets it. (Written here rather than taken from a crate: the egui 0.37 file-dialog
//! crates draw their titles and icons with emoji glyphs egui's fonts no longer carry.)

use eframe::egui;
use std::path::{Path, PathBuf};

/// One entry of the folder shown.
#[derive(Clone, Debug, PartialEq)]
struct Entry {
    name: String,
    folder: bool,
}

/// What the browser gave this frame.
#[derive(Debug, PartialEq)]
pub enum Outcome {
    /// Still showing.
    Open,
    Chosen(PathBuf),
    Cancelled,
}

/// The browser's state while it shows.
pub struct FileBrowser {
    title: String,
    save: bool,
    /// Lower-case extensions the files shown have (without dots).
    extensions: Vec<String>,
    places: Vec<PathBuf>,
    folder: PathBuf,
    folder_text: String,
    entries: Result<Vec<Entry>, String>,
    name: String,
    /// A file asked to be replaced, while the question shows.
    replacing: Option<PathBuf>,
}

impl FileBrowser {
    /// A browser in the first of `places` (folders), for a file to read or, with `save`,
    /// to write (suggesting `name`), showing files with one of `extensions`.
    pub fn new(
        title: &str,
        save: bool,
        extensions: &[&str],
        places: Vec<PathBuf>,
        name: Option<String>,
    ) -> FileBrowser {
        let folder = places
            .first()
            .cloned()
            .unwrap_or_else(|| PathBuf::from("."));
        let mut browser = FileBrowser {
            title: title.to_string(),
            save,
            extensions: extensions.iter().map(|e| e.to_ascii_lowercase()).collect(),
            places,
            folder: PathBuf::new(),
            folder_text: String::new(),
            entries: Ok(Vec::new()),
            name: name.unwrap_or_default(),
            replacing: None,
        };
        browser.go_to(folder);
        browser
    }

    fn go_to(&mut self, folder: PathBuf) {
        self.entries = list(&folder, &self.extensions);
        self.folder_text = folder.display().to_string();
        self.folder = folder;
        if !self.save {
            self.name.clear();
        }
    }

    /// The path the name field names (the filter's first extension added when saving a
    /// name without one); `None` while the name is empty.
    fn target(&self) -> Option<PathBuf> {
        let name = self.name.trim();
        if name.is_empty() {
            return None;
        }
        let mut path = self.folder.join(name);
        if self.save
            && path.extension().is_none()
            && let Some(ext) = self.extensions.first()
        {
            path.set_extension(ext);
        }
        Some(path)
    }

    /// Open (or save) what the name field names: a folder is entered; a missing file to
    /// open, or an existing file to save over, is not taken at once.
    fn confirm(&mut self) -> Outcome {
        let Some(path) = self.target() else {
            return Outcome::Open;
        };
        if path.is_dir() {
            self.go_to(path);
            self.name.clear();
            return Outcome::Open;
        }
        match (self.save, path.exists()) {
            (false, true) | (true, false) => Outcome::Chosen(path),
            (true, true) => {
                self.replacing = Some(path);
                Outcome::Open
            }
            (false, false) => {
                self.entries = Err(format!("{} does not exist", path.display()));
                Outcome::Open
            }
        }
    }

    /// Draw the browser; what the user did.
    pub fn show(&mut self, ctx: &egui::Context) -> Outcome {
        let mut outcome = Outcome::Open;
        let modal = egui::Modal::new(egui::Id::unique("timpanist-file-browser")).show(ctx, |ui| {
            ui.set_width(640.0);
            ui.heading(&self.title);
            if let Some(path) = self.replacing.clone() {
                ui.label(format!("{} already exists. Replace it?", path.display()));
                ui.horizontal(|ui| {
                    if ui.button("Replace").clicked() {
                        outcome = Outcome::Chosen(path);
                    }
                    if ui.button("Back").clicked() {
                        self.replacing = None;
                    }
                });
                return;
            }
            ui.horizontal(|ui| {
                if ui.button("Up").on_hover_text("the parent folder").clicked()
                    && let Some(parent) = self.folder.parent()
                {
                    self.go_to(parent.to_path_buf());
                }
                let label = ui.label("Folder:");
                let field = ui
                    .add(
                        egui::TextEdit::singleline(&mut self.folder_text)
                            .desired_width(f32::INFINITY),
                    )
                    .labelled_by(label.id);
                if field.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter)) {
                    self.go_to(PathBuf::from(self.folder_text.trim()));
                }
            });
            ui.separator();
            ui.horizontal_top(|ui| {
                ui.vertical(|ui| {
                    ui.set_width(140.0);
                    ui.strong("Places");
                    for place in self.places.clone() {
                        let label = place.file_name().map_or(place.display().to_string(), |n| {
                            n.to_string_lossy().into_owned()
                        });
                        let button = ui.button(label).on_hover_text(place.display().to_string());
                        if button.clicked() {
                            self.go_to(place);
                        }
                    }
                });
                ui.add_space(8.0);
                ui.vertical(|ui| {
                    egui::ScrollArea::vertical()
                        .max_height(300.0)
                        .auto_shrink([false, false])
                        .show(ui, |ui| outcome = self.entries_list(ui));
                });
            });
            ui.separator();
            ui.horizontal(|ui| {
                let label = ui.label("File name:");
                let field = ui
                    .add(egui::TextEdit::singleline(&mut self.name).desired_width(f32::INFINITY))
                    .labelled_by(label.id);
                let keys = ui.input(|i| {
                    (
                        i.key_pressed(egui::Key::Enter),
                        i.key_pressed(egui::Key::Backspace),
                    )
                });
                if field.lost_focus() && keys.0 {
                    outcome = self.confirm();
                } else if field.has_focus()
                    && keys.1
                    && self.name.is_empty()
                    && let Some(parent) = self.folder.parent()
                {
                    self.go_to(parent.to_path_buf());
                }
            });
            ui.horizontal(|ui| {
                let verb = if self.save { "Save" } else { "Open" };
                if ui
                    .add_enabled(self.target().is_some(), egui::Button::new(verb))
                    .clicked()
                {
                    outcome = self.confirm();
                }
                if ui.button("Cancel").clicked() {
                    outcome = Outcome::Cancelled;
                }
            });
        });
        if modal.should_close() && outcome == Outcome::Open {
            outcome = Outcome::Cancelled;
        }
        outcome
    }

    /// The folder's entries: a click names an entry, a double click enters a folder or
    /// takes a file.
    fn entries_list(&mut self, ui: &mut egui::Ui) -> Outcome {
        let entries = match &self.entries {
            Ok(entries) => entries.clone(),
            Err(e) => {
                ui.colored_label(ui.visuals().error_fg_color, e);
                return Outcome::Open;
            }
        };
        if entries.is_empty() {
            ui.weak("(no folders or matching files here)");
        }
        for entry in entries {
            let label = if entry.folder {
                format!("{}/", entry.name)
            } else {
                entry.name.clone()
            };
            let item = ui.selectable_label(self.name == entry.name, label);
            if item.double_clicked() {
                if entry.folder {
                    self.go_to(self.folder.join(&entry.name));
                    return Outcome::Open;
                }
                self.name = entry.name;
                return self.confirm();
            }
            if item.clicked() {
                self.name = entry.name;
            }
        }
        Outcome::Open
    }
}

/// The subfolders of `folder` and its files with one of `extensions` (hidden ones left
/// out), folders first, each by name.
fn list(folder: &Path, extensions: &[String]) -> Result<Vec<Entry>, String> {
    let read = std::fs::read_dir(folder).map_err(|e| format!("{}: {e}", folder.display()))?;
    let mut entries: Vec<Entry> = read
        .filter_map(Result::ok)
        .filter_map(|e| {
            let name = e.file_name().to_string_lossy().into_owned();
            let folder = e.path().is_dir();
            let wanted = folder
                || Path::new(&name)
                    .extension()
                    .and_then(|x| x.to_str())
                    .is_some_and(|x| extensions.contains(&x.to_ascii_lowercase()));
            (wanted && !name.starts_with('.')).then_some(Entry { name, folder })
        })
        .collect();
    entries.sort_by(|a, b| b.folder.cmp(&a.folder).then(a.name.cmp(&b.name)));
    Ok(entries)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Folders first, then the files the filter admits; hidden files left out; a saved
    /// name gets the extension; saving over a file asks; opening a missing one does not
    /// choose it.
    #[test]
    fn lists_filters_and_confirms() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        std::fs::create_dir(d.join("sub")).unwrap();
        for f in ["b.ron", "a.RON", "notes.txt", ".hidden.ron"] {
            std::fs::write(d.join(f), "").unwrap();
        }
        let names: Vec<String> = list(d, &["ron".into()])
            .unwrap()
            .into_iter()
            .map(|e| e.name)
            .collect();
        assert_eq!(names, ["sub", "a.RON", "b.ron"]);

        let mut save = FileBrowser::new("Save", true, &["ron"], vec![d.into()], Some("x".into()));
        assert_eq!(save.confirm(), Outcome::Chosen(d.join("x.ron")));
        save.name = "b".into();
        assert_eq!(save.confirm(), Outcome::Open);
        assert_eq!(save.replacing, Some(d.join("b.ron")));

        let mut open = FileBrowser::new("Open", false, &["ron"], vec![d.into()], None);
        open.name = "missing.ron".into();
        assert_eq!(open.confirm(), Outcome::Open);
        open.name = "sub".into();
        assert_eq!(open.confirm(), Outcome::Open);
        assert_eq!(open.folder, d.join("sub"));
        open.go_to(d.into());
        open.name = "a.RON".into();
        assert_eq!(open.confirm(), Outcome::Chosen(d.join("a.RON")));
    }
}
