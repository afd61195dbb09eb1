//! The inspector: properties of the selected beats (several at once: a field shows a
//! value when all agree, "(mixed)" otherwise, and setting it sets it on all), of the
//! selected trajectory handle, the score (tempo points), the kit, and the physics, sound
//! and drum settings ([`super::settings_panel`]). Every change is pushed as an edit
//! command.

use super::command::Command;
use super::selection::{self, Selection};
use crate::score::edit::ScoreEdit;
use crate::score::{Beat, Dynamic, Hand, ImpactLocation, LoadedScore, PlayingMode};
use eframe::egui;

/// The value shared by all `items`, if they agree.
pub fn common<T: PartialEq + Copy>(items: impl IntoIterator<Item = T>) -> Option<T> {
    let mut it = items.into_iter();
    let first = it.next()?;
    it.all(|x| x == first).then_some(first)
}

/// A combo box over `options`; returns the one picked this frame.
fn pick<T: PartialEq + Copy>(
    ui: &mut egui::Ui,
    label: &str,
    current: Option<T>,
    options: &[(T, String)],
) -> Option<T> {
    let shown = current
        .and_then(|c| options.iter().find(|(v, _)| *v == c))
        .map_or("(mixed)".to_string(), |(_, n)| n.clone());
    let mut picked = None;
    let name = ui.label(label);
    egui::ComboBox::from_id_salt(label)
        .selected_text(shown)
        .show_ui(ui, |ui| {
            for (v, name) in options {
                if ui.selectable_label(current == Some(*v), name).clicked() {
                    picked = Some(*v);
                }
            }
        })
        .response
        .labelled_by(name.id);
    ui.end_row();
    picked
}

/// The pitch the selected beats (all on `drum`) name: the drum's range, or none (the drum
/// as it is tuned then); and, for the selected beats that change the drum's pitch, the
/// pedal change (flagged when it is quick).
fn pitch_row(
    ui: &mut egui::Ui,
    doc: &LoadedScore,
    sel: &Selection,
    drum: usize,
    out: &mut Vec<Command>,
) {
    let beats = sel.beats.iter().filter_map(|&i| doc.score.beats.get(i));
    let kit = doc.score.kit(&doc.kit);
    let d = &kit.drums[drum];
    let (changes, sounding) =
        crate::score::tuning::walk(&doc.score, &doc.score.settings.kit(&doc.kit));
    let tuned = sel.beats.first().and_then(|&i| sounding.get(i)).copied();
    let mut pitches = vec![(None, format!("as tuned ({})", tuned.unwrap_or(d.tuning)))];
    let mut p = Some(d.lowest);
    while let Some(pitch) = p.filter(|&p| p <= d.highest) {
        pitches.push((Some(pitch), pitch.to_string()));
        p = pitch.transposed(1);
    }
    let current = common(beats.clone().map(|b| b.pitch));
    if let Some(pitch) = pick(ui, "Pitch", current, &pitches) {
        set_beats(doc, sel, out, |b| b.pitch = pitch);
    }
    if let Some(change) = changes.iter().find(|c| sel.beats.contains(&c.beat)) {
        ui.label("");
        let text = format!(
            "pedal change from {} to {}, {:.2} s after the drum's last stroke",
            change.from,
            change.to,
            change.gap_s()
        );
        let color = if change.is_quick() {
            ui.visuals().warn_fg_color
        } else {
            ui.visuals().weak_text_color()
        };
        ui.label(egui::RichText::new(text).color(color));
        ui.end_row();
    }
}

fn set_beats(doc: &LoadedScore, sel: &Selection, out: &mut Vec<Command>, f: impl FnMut(&mut Beat)) {
    let (after, beats) = selection::modify(&doc.score.beats, &sel.beats, f);
    out.push(Command::Gesture);
    out.push(Command::Edit(ScoreEdit::SetBeats {
        before: doc.score.beats.clone(),
        after,
    }));
    out.push(Command::Select(Selection {
        beats,
        handle: None,
    }));
}

/// Draw the inspector for `doc` and `sel`.
pub fn show(ui: &mut egui::Ui, doc: &LoadedScore, sel: &Selection, out: &mut Vec<Command>) {
    ui.heading("Inspector");
    let beats: Vec<&Beat> = sel
        .beats
        .iter()
        .filter_map(|&i| doc.score.beats.get(i))
        .collect();
    if beats.is_empty() {
        ui.label("No beat selected: click a beat on the timeline.");
    } else {
        ui.strong(format!("{} beat(s) selected", beats.len()));
        egui::Grid::new("beat-props").num_columns(2).show(ui, |ui| {
            let modes: Vec<(PlayingMode, String)> = PlayingMode::ALL
                .iter()
                .enumerate()
                .map(|(k, m)| (*m, format!("{} {}", k + 1, m.name())))
                .collect();
            if let Some(m) = pick(ui, "Mode", common(beats.iter().map(|b| b.mode)), &modes) {
                set_beats(doc, sel, out, |b| b.mode = m);
            }
            let hands = [
                (Hand::Right, "right".to_string()),
                (Hand::Left, "left".to_string()),
                (Hand::Auto, "auto".to_string()),
            ];
            if let Some(h) = pick(ui, "Hand", common(beats.iter().map(|b| b.hand)), &hands) {
                set_beats(doc, sel, out, |b| b.hand = h);
            }
            let dynamics: Vec<(Dynamic, String)> = Dynamic::MARKS
                .iter()
                .map(|(d, _, n)| (*d, n.to_string()))
                .collect();
            if let Some(d) = pick(
                ui,
                "Dynamic",
                common(beats.iter().map(|b| b.dynamic)),
                &dynamics,
            ) {
                set_beats(doc, sel, out, |b| b.dynamic = d);
            }
            let drums: Vec<(usize, String)> = doc
                .kit
                .drums
                .iter()
                .enumerate()
                .map(|(i, d)| (i, format!("{i}: {}", d.name)))
                .collect();
            if let Some(d) = pick(ui, "Drum", common(beats.iter().map(|b| b.drum)), &drums) {
                let drum = &doc.kit.drums[d];
                set_beats(doc, sel, out, |b| {
                    b.drum = d;
                    // A pitch the new drum cannot reach goes back to its tuning.
                    b.pitch = b.pitch.filter(|&p| drum.in_range(p));
                });
            }
            if let Some(drum) = common(beats.iter().map(|b| b.drum)) {
                pitch_row(ui, doc, sel, drum, out);
            }
            let spots = [
                (ImpactLocation::PlayingSpot, "playing spot".to_string()),
                (ImpactLocation::Centre, "centre".to_string()),
                (ImpactLocation::Rim, "rim".to_string()),
            ];
            if let Some(l) = pick(
                ui,
                "Location",
                common(beats.iter().map(|b| b.location)),
                &spots,
            ) {
                set_beats(doc, sel, out, |b| b.location = l);
            }
            let tpq = u64::from(doc.score.ticks_per_quarter);
            let mut damps: Vec<(Option<u64>, String)> = vec![
                (None, "let ring".to_string()),
                (Some(tpq / 4), "secco: touch a 16th after".to_string()),
                (Some(tpq / 2), "secco: touch an 8th after".to_string()),
                (Some(tpq), "secco: touch a quarter after".to_string()),
                (Some(2 * tpq), "secco: touch a half after".to_string()),
            ];
            let current = common(beats.iter().map(|b| b.damp));
            if let Some(Some(d)) = current
                && !damps.iter().any(|(v, _)| *v == Some(d))
            {
                damps.push((Some(d), format!("secco: touch {d} ticks after")));
            }
            if let Some(d) = pick(ui, "Damping", current, &damps) {
                set_beats(doc, sel, out, |b| b.damp = d);
            }
            ui.label("Tick");
            match common(beats.iter().map(|b| b.tick)) {
                Some(t) => ui.label(format!("{t} ({})", doc.score.meter_map().position(t))),
                None => ui.label("(mixed)"),
            };
            ui.end_row();
        });
    }
    if let Some(i) = sel.handle
        && let Some(h) = doc.score.handles.get(i)
    {
        ui.separator();
        ui.strong(format!("Handle {i} ({:?} hand, tick {})", h.hand, h.tick));
        let mut edited = *h;
        let mut started = false;
        egui::Grid::new("handle-props")
            .num_columns(2)
            .show(ui, |ui| {
                for (k, axis) in ["Offset x (m)", "Offset y (m)", "Offset z (m)"]
                    .iter()
                    .enumerate()
                {
                    let name = ui.label(*axis);
                    let r = ui
                        .add(
                            egui::DragValue::new(&mut edited.offset_m[k])
                                .speed(0.002)
                                .fixed_decimals(3),
                        )
                        .labelled_by(name.id);
                    started |= r.drag_started() || (r.changed() && !r.dragged());
                    ui.end_row();
                }
                let name = ui.label("Reach (ticks)");
                let r = ui
                    .add(
                        egui::DragValue::new(&mut edited.reach_ticks)
                            .speed(5)
                            .range(1..=100_000),
                    )
                    .labelled_by(name.id);
                started |= r.drag_started() || (r.changed() && !r.dragged());
                ui.end_row();
            });
        if started {
            out.push(Command::Gesture);
        }
        if edited != *h {
            out.push(Command::Edit(ScoreEdit::MoveHandle {
                index: i,
                from: *h,
                to: edited,
            }));
        }
        if ui.button("Remove handle").clicked() {
            out.push(Command::Gesture);
            out.push(Command::Edit(ScoreEdit::RemoveHandle {
                index: i,
                removed: None,
            }));
            out.push(Command::Select(Selection::default()));
        }
    }
    ui.separator();
    score_section(ui, doc, out);
    ui.separator();
    kit_section(ui, doc);
    super::settings_panel::show(ui, doc, out);
}

fn score_section(ui: &mut egui::Ui, doc: &LoadedScore, out: &mut Vec<Command>) {
    let s = &doc.score;
    ui.strong(&s.title);
    egui::Grid::new("score-info").num_columns(2).show(ui, |ui| {
        for (k, v) in [
            ("Grip", format!("{:?}", s.grip)),
            ("Beats", s.beats.len().to_string()),
            ("Handles", s.handles.len().to_string()),
            ("Pins", s.pins.len().to_string()),
            ("Length", format!("{:.1} s", s.duration_s())),
            (
                "Meter",
                s.meter
                    .iter()
                    .map(|m| format!("{}/{}", m.numerator, m.denominator))
                    .collect::<Vec<_>>()
                    .join(", "),
            ),
        ] {
            ui.label(k);
            ui.label(v);
            ui.end_row();
        }
    });
    ui.collapsing("Tempo points", |ui| {
        let mut after = s.tempo.clone();
        let mut started = false;
        egui::Grid::new("tempo-points")
            .num_columns(2)
            .show(ui, |ui| {
                for p in after.iter_mut() {
                    let name = ui.label(format!("tick {} ({:?})", p.tick, p.change));
                    let r = ui
                        .add(
                            egui::DragValue::new(&mut p.bpm)
                                .range(crate::score::tempo::BPM_RANGE)
                                .speed(0.5)
                                .suffix(" bpm"),
                        )
                        .labelled_by(name.id);
                    started |= r.drag_started() || (r.changed() && !r.dragged());
                    ui.end_row();
                }
            });
        if started {
            out.push(Command::Gesture);
        }
        if after != s.tempo {
            out.push(Command::Edit(ScoreEdit::SetTempo {
                before: s.tempo.clone(),
                after,
            }));
        }
    });
}

fn kit_section(ui: &mut egui::Ui, doc: &LoadedScore) {
    ui.strong(&doc.kit.name);
    // A kit file is named without its folder (the full path is in the tooltip).
    let source = std::path::Path::new(&doc.kit_source);
    let short = match source.file_name() {
        Some(name) if doc.kit_source.ends_with(".ron") => name.to_string_lossy().into_owned(),
        _ => doc.kit_source.clone(),
    };
    ui.label(format!("from {short}"))
        .on_hover_text(&doc.kit_source);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `common` gives the shared value or nothing.
    #[test]
    fn common_values() {
        assert_eq!(common([1, 1, 1]), Some(1));
        assert_eq!(common([1, 2]), None);
        assert_eq!(common(Vec::<i32>::new()), None);
    }
}
