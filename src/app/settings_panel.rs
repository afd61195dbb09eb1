//! The inspector's performance and sound settings: control pipeline, IK
//! method, PD gain scale, body step, sound model, membrane modes and frequency source, and the kit's
//! drums with editable head diameter and tension. Every change is one undoable edit of
//! the score's settings (a drag is one step) and the editor re-renders.

use super::command::Command;
use crate::body::ik::IkMethod;
use crate::body::sim::{BodyStep, Pipeline};
use crate::drum::FrequencySource;
use crate::score::LoadedScore;
use crate::score::edit::ScoreEdit;
use crate::score::settings::{
    DIAMETER_RANGE_M, DrumChange, GAIN_SCALE_RANGE, MODE_COUNT_RANGE, Settings,
    TENSION_RANGE_N_PER_M,
};
use crate::sound::{Room, SoundModel};
use eframe::egui;

/// A combo box over `options` bound to `value`; whether it changed.
fn choose<T: PartialEq + Copy>(
    ui: &mut egui::Ui,
    label: &str,
    value: &mut T,
    options: &[(T, &str)],
) -> bool {
    let before = *value;
    let shown = options
        .iter()
        .find(|(v, _)| *v == *value)
        .map_or("?", |(_, n)| n);
    let name = ui.label(label);
    egui::ComboBox::from_id_salt(("settings", label))
        .selected_text(shown)
        .show_ui(ui, |ui| {
            for (v, n) in options {
                ui.selectable_value(value, *v, *n);
            }
        })
        .response
        .labelled_by(name.id);
    ui.end_row();
    *value != before
}

/// Whether a widget's response begins a new undo step (a drag starting or a one-off
/// change such as typing or a click).
fn begins(r: &egui::Response) -> bool {
    r.drag_started() || (r.changed() && !r.dragged())
}

/// Draw the settings of `doc`'s score; edits go to `out`.
pub fn show(ui: &mut egui::Ui, doc: &LoadedScore, out: &mut Vec<Command>) {
    let before = &doc.score.settings;
    let mut after = before.clone();
    let mut started = false;
    ui.collapsing("Physics and sound", |ui| {
        egui::Grid::new("settings").num_columns(2).show(ui, |ui| {
            started |= choose(
                ui,
                "Control",
                &mut after.control,
                &[
                    (Pipeline::Himc, "HIMC (IK nested in PD)"),
                    (Pipeline::Id, "ID (PD + inverse dynamics)"),
                    (Pipeline::Ik, "IK (kinematic)"),
                ],
            );
            started |= choose(
                ui,
                "IK method",
                &mut after.ik,
                &[
                    (IkMethod::DampedLeastSquares, "damped least squares"),
                    (IkMethod::PseudoInverse, "pseudo-inverse"),
                    (IkMethod::Transpose, "Jacobian transpose"),
                ],
            );
            let name = ui.label("PD gains");
            let r = ui
                .add(
                    egui::DragValue::new(&mut after.gain_scale)
                        .range(GAIN_SCALE_RANGE)
                        .speed(0.01)
                        .prefix("× "),
                )
                .labelled_by(name.id);
            started |= begins(&r);
            ui.end_row();
            started |= choose(
                ui,
                "Body step",
                &mut after.body_step,
                &[
                    (
                        BodyStep::Fast,
                        "fast (5 kHz between contacts, 2.5 kHz while calm)",
                    ),
                    (BodyStep::Reference, "reference (10 kHz)"),
                ],
            );
            started |= choose(
                ui,
                "Sound model",
                &mut after.sound,
                &[
                    (SoundModel::Modal, "modal (simulated force)"),
                    (SoundModel::Sample, "sample replay"),
                    (SoundModel::Signal, "signal (partials + noise)"),
                ],
            );
            let name = ui.label("Membrane modes");
            let r = ui
                .add(egui::DragValue::new(&mut after.modes).range(MODE_COUNT_RANGE))
                .labelled_by(name.id);
            started |= begins(&r);
            ui.end_row();
            started |= choose(
                ui,
                "Frequencies",
                &mut after.frequencies,
                &[
                    (FrequencySource::Measured, "measured kettledrum ratios"),
                    (FrequencySource::Membrane, "ideal membrane (tension)"),
                ],
            );
            started |= choose(
                ui,
                "Room",
                &mut after.room,
                &[
                    (Room::Dry, "dry (the heads alone)"),
                    (Room::Studio, "studio (T60 0.5 s, close microphones)"),
                    (Room::Hall, "concert hall (T60 2.2 s)"),
                ],
            );
        });
        if ui
            .add_enabled(!before.is_default(), egui::Button::new("Reset to defaults"))
            .clicked()
        {
            started = true;
            after = Settings::default();
        }
    });
    started |= drums(ui, doc, &mut after);
    if started {
        out.push(Command::Gesture);
    }
    if after != *before {
        out.push(Command::Edit(ScoreEdit::SetSettings {
            before: before.clone(),
            after,
        }));
    }
}

/// The kit's drums with editable diameter and tension (as changes in `settings`);
/// whether an edit began.
fn drums(ui: &mut egui::Ui, doc: &LoadedScore, settings: &mut Settings) -> bool {
    let mut started = false;
    let kit = settings.kit(&doc.kit);
    // What each drum plays the score at (the pitch its beats name, `score::tuning`).
    let pitches = crate::score::tuning::drum_pitches(&doc.score, &kit);
    ui.collapsing("Drums and membranes", |ui| {
        egui::Grid::new("drums").striped(true).show(ui, |ui| {
            for h in ["#", "drum", "tuning", "diameter", "tension", "modes"] {
                ui.strong(h);
            }
            ui.end_row();
            for (i, d) in kit.drums.iter().enumerate() {
                ui.label(i.to_string());
                ui.label(&d.name);
                ui.label(if pitches[i] == d.tuning {
                    d.tuning.to_string()
                } else {
                    format!("{} (kit {})", pitches[i], d.tuning)
                });
                let (mut diameter, mut tension) = (d.diameter_m, d.membrane.tension_n_per_m);
                let r = ui.add(
                    egui::DragValue::new(&mut diameter)
                        .range(DIAMETER_RANGE_M)
                        .speed(0.001)
                        .max_decimals(3)
                        .suffix(" m"),
                );
                started |= begins(&r);
                let t = ui.add(
                    egui::DragValue::new(&mut tension)
                        .range(TENSION_RANGE_N_PER_M)
                        .speed(10.0)
                        .max_decimals(0)
                        .suffix(" N/m"),
                );
                started |= begins(&t);
                ui.label(d.modes.len().to_string());
                ui.end_row();
                if r.changed() || t.changed() {
                    let original = &doc.kit.drums[i];
                    settings.set_drum(DrumChange {
                        drum: i,
                        diameter_m: (diameter != original.diameter_m).then_some(diameter),
                        tension_n_per_m: (tension != original.membrane.tension_n_per_m)
                            .then_some(tension),
                    });
                }
            }
        });
        ui.label("Changes are saved with the score; the kit file is left as it is.");
    });
    started
}
