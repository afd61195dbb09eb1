//! The tempo lane under the timeline: the tempo (quarter notes per minute) against score
//! time on the timeline's axis, steps drawn as jumps and ramps as slopes. Drag a point to
//! change its tempo (and, except the first, its position); double-click to add a point;
//! right-click a point to make it a step or a ramp, or delete it. Each drag is one step.

use super::command::Command;
use super::time_axis::{TimeAxis, snap};
use crate::score::edit::ScoreEdit;
use crate::score::tempo::BPM_RANGE;
use crate::score::{TempoChange, TempoPoint};
use eframe::egui::{self, Color32, Pos2, Rect, Sense, Stroke, Vec2};

/// Height of the tempo lane, px.
pub const TEMPO_H: f32 = 56.0;

/// The tempo range shown: the map's range with a margin, bpm.
pub fn bpm_range(points: &[TempoPoint]) -> (f64, f64) {
    let lo = points.iter().map(|p| p.bpm).fold(f64::INFINITY, f64::min);
    let hi = points
        .iter()
        .map(|p| p.bpm)
        .fold(f64::NEG_INFINITY, f64::max);
    if !lo.is_finite() {
        return (60.0, 180.0);
    }
    (lo - 15.0, hi + 15.0)
}

/// `points` with point `i` moved to (`tick`, `bpm`): kept strictly between its neighbours
/// (the first stays at tick 0) and inside the allowed tempo range.
pub fn moved_point(points: &[TempoPoint], i: usize, tick: u64, bpm: f64) -> Vec<TempoPoint> {
    let mut out = points.to_vec();
    let lo = if i == 0 { 0 } else { points[i - 1].tick + 1 };
    let hi = points
        .get(i + 1)
        .map_or(u64::MAX, |p| p.tick.saturating_sub(1));
    out[i].tick = if i == 0 {
        0
    } else {
        tick.clamp(lo, hi.max(lo))
    };
    out[i].bpm = (bpm.clamp(*BPM_RANGE.start(), *BPM_RANGE.end()) * 10.0).round() / 10.0;
    out
}

/// `points` with a new point at `tick` (keeping the tempo there, as a step), unless one
/// is already there.
pub fn with_point(points: &[TempoPoint], tick: u64, bpm: f64) -> Option<Vec<TempoPoint>> {
    if points.iter().any(|p| p.tick == tick) {
        return None;
    }
    let mut out = points.to_vec();
    let at = out.partition_point(|p| p.tick < tick);
    out.insert(
        at,
        TempoPoint {
            tick,
            bpm,
            change: TempoChange::Step,
        },
    );
    Some(out)
}

/// The tempo lane's drag state.
#[derive(Default)]
pub struct TempoLane {
    dragging: Option<usize>,
    /// The tempo range shown when the drag began (held so the scale does not move
    /// under the pointer).
    range: Option<(f64, f64)>,
}

impl TempoLane {
    /// Draw the lane for `points` on `axis`; edits go to `out`.
    pub fn show(
        &mut self,
        ui: &mut egui::Ui,
        axis: TimeAxis,
        points: &[TempoPoint],
        ticks_per_quarter: u32,
        grid: u64,
        out: &mut Vec<Command>,
    ) {
        let (outer, _) =
            ui.allocate_exact_size(Vec2::new(ui.available_width(), TEMPO_H), Sense::hover());
        let rect = Rect::from_min_max(Pos2::new(axis.left_px as f32, outer.top()), outer.max);
        let painter = ui.painter_at(outer);
        painter.rect_filled(outer, 4.0, ui.visuals().extreme_bg_color);
        painter.text(
            Pos2::new(outer.left() + 6.0, outer.center().y),
            egui::Align2::LEFT_CENTER,
            "Tempo",
            egui::FontId::proportional(12.0),
            ui.visuals().text_color(),
        );
        let (lo, hi) = match (self.dragging, self.range) {
            (Some(_), Some(r)) => r,
            _ => bpm_range(points),
        };
        let y_of = |bpm: f64| {
            rect.bottom() - 4.0 - ((bpm - lo) / (hi - lo)) as f32 * (rect.height() - 8.0)
        };
        let bpm_of =
            |y: f32| lo + f64::from((rect.bottom() - 4.0 - y) / (rect.height() - 8.0)) * (hi - lo);
        let x_of = |t: u64| axis.x_of(t as f64) as f32;
        let colour = Color32::from_rgb(230, 200, 90);
        let stroke = Stroke::new(1.5, colour);
        let clip = painter.with_clip_rect(rect);
        let map = crate::score::TempoMap::new(points, ticks_per_quarter);
        for (i, p) in points.iter().enumerate() {
            let next_x = points.get(i + 1).map_or(rect.right(), |n| x_of(n.tick));
            let next_change = points.get(i + 1).map(|n| n.change);
            let start = Pos2::new(x_of(p.tick), y_of(p.bpm));
            let end_bpm = match next_change {
                Some(TempoChange::Ramp) => points[i + 1].bpm,
                _ => p.bpm,
            };
            clip.line_segment([start, Pos2::new(next_x, y_of(end_bpm))], stroke);
            if next_change == Some(TempoChange::Step) {
                clip.line_segment(
                    [
                        Pos2::new(next_x, y_of(p.bpm)),
                        Pos2::new(next_x, y_of(points[i + 1].bpm)),
                    ],
                    Stroke::new(1.0, colour.gamma_multiply(0.6)),
                );
            }
        }
        // The lane first, so the points drawn on it are on top for the pointer.
        let lane = ui.interact(rect, ui.make_persistent_id("tempo-lane"), Sense::click());
        lane.widget_info(|| egui::WidgetInfo::labeled(egui::Role::Canvas, true, "Tempo lane"));
        let mut hovered_point = None;
        let pointer = ui.input(|i| i.pointer.hover_pos());
        // A label is drawn only clear of the last one drawn (points a few ticks apart
        // would print their tempos over each other); the point hovered always has one.
        let mut label_free_from = f32::NEG_INFINITY;
        for (i, p) in points.iter().enumerate() {
            let c = Pos2::new(x_of(p.tick), y_of(p.bpm));
            if !rect.expand(6.0).contains(c) {
                continue;
            }
            let id = ui.make_persistent_id(("tempo-point", i));
            let resp = ui.interact(
                Rect::from_center_size(c, Vec2::splat(12.0)),
                id,
                Sense::click_and_drag(),
            );
            if resp.hovered() || self.dragging == Some(i) {
                hovered_point = Some(i);
            }
            clip.circle(c, 4.5, colour, Stroke::new(1.0, Color32::BLACK));
            if c.x >= label_free_from || hovered_point == Some(i) {
                let label = clip.text(
                    c + Vec2::new(6.0, -7.0),
                    egui::Align2::LEFT_BOTTOM,
                    format!("{:.0}", p.bpm),
                    egui::FontId::monospace(9.0),
                    colour,
                );
                label_free_from = label_free_from.max(label.right() + 2.0);
            }
            if resp.drag_started() {
                self.dragging = Some(i);
                self.range = Some((lo, hi));
                out.push(Command::Gesture);
            }
            if self.dragging == Some(i)
                && let Some(pos) = resp.interact_pointer_pos()
            {
                let tick = snap(axis.tick_of(f64::from(pos.x)), grid);
                let after = moved_point(points, i, tick, bpm_of(pos.y));
                if after != points {
                    out.push(Command::Edit(ScoreEdit::SetTempo {
                        before: points.to_vec(),
                        after,
                    }));
                }
            }
            if resp.drag_stopped() {
                self.dragging = None;
            }
            resp.context_menu(|ui| {
                for (label, change) in [("Step", TempoChange::Step), ("Ramp", TempoChange::Ramp)] {
                    if i > 0 && ui.button(label).clicked() {
                        let mut after = points.to_vec();
                        after[i].change = change;
                        out.push(Command::Gesture);
                        out.push(Command::Edit(ScoreEdit::SetTempo {
                            before: points.to_vec(),
                            after,
                        }));
                    }
                }
                if i > 0 && ui.button("Delete tempo point").clicked() {
                    let mut after = points.to_vec();
                    after.remove(i);
                    out.push(Command::Gesture);
                    out.push(Command::Edit(ScoreEdit::SetTempo {
                        before: points.to_vec(),
                        after,
                    }));
                }
            });
        }
        if hovered_point.is_none()
            && lane.double_clicked()
            && let Some(p) = pointer
        {
            let tick = snap(axis.tick_of(f64::from(p.x)), grid);
            if let Some(after) = with_point(points, tick, map.bpm_at(tick as f64).round()) {
                out.push(Command::Gesture);
                out.push(Command::Edit(ScoreEdit::SetTempo {
                    before: points.to_vec(),
                    after,
                }));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn points() -> Vec<TempoPoint> {
        vec![
            TempoPoint {
                tick: 0,
                bpm: 100.0,
                change: TempoChange::Step,
            },
            TempoPoint {
                tick: 3840,
                bpm: 80.0,
                change: TempoChange::Ramp,
            },
        ]
    }

    /// A moved point stays between its neighbours, the first stays at 0, tempo is clamped.
    #[test]
    fn moving_points_stays_valid() {
        let p = moved_point(&points(), 0, 500, 120.04);
        assert_eq!((p[0].tick, p[0].bpm), (0, 120.0));
        let p = moved_point(&points(), 1, 0, 1000.0);
        assert_eq!((p[1].tick, p[1].bpm), (1, *BPM_RANGE.end()));
        assert!(crate::score::tempo::validate_points(&p).is_empty());
    }

    /// Adding a point inserts it in order and refuses a duplicate tick.
    #[test]
    fn adding_points() {
        let p = with_point(&points(), 1920, 90.0).unwrap();
        assert_eq!(
            p.iter().map(|p| p.tick).collect::<Vec<_>>(),
            [0, 1920, 3840]
        );
        assert!(with_point(&points(), 3840, 90.0).is_none());
        assert_eq!(bpm_range(&points()), (65.0, 115.0));
    }
}
