//! The timeline: a ruler (bars, playhead, loop region), one lane per hand (Right, Auto,
//! Left) with beats drawn by playing mode (colour and shape), dynamic (size) and drum
//! (label), a bar and beat grid with snapping, zoom and pan. Editing: click an empty spot
//! to add a beat, click/Shift-click to select, drag beats to move them in time and
//! between lanes, drag on empty space to box-select. Every change is pushed as a command.

use super::command::Command;
use super::selection::{self, LANES, Selection, lane_of};
use super::time_axis::{TimeAxis, snap};
use crate::score::edit::ScoreEdit;
use crate::score::{Beat, LoadedScore, MeterMap, PlayingMode};
use eframe::egui::{self, Color32, Pos2, Rect, Sense, Shape, Stroke, Vec2};
use std::collections::BTreeSet;

/// Colour of each playing mode.
pub fn mode_colour(mode: PlayingMode) -> Color32 {
    match mode {
        PlayingMode::Legato => Color32::from_rgb(90, 170, 255),
        PlayingMode::Tenuto => Color32::from_rgb(120, 210, 140),
        PlayingMode::Accent => Color32::from_rgb(255, 170, 60),
        PlayingMode::VerticalAccent => Color32::from_rgb(240, 90, 90),
        PlayingMode::Staccato => Color32::from_rgb(200, 130, 240),
    }
}

const LANE_NAMES: [&str; 3] = ["Right", "Auto", "Left"];
/// Height of the bar ruler, px.
pub const RULER_H: f32 = 18.0;
/// Height of one hand lane, px.
pub const LANE_H: f32 = 42.0;
/// Width of the lane labels, px.
pub const LABEL_W: f32 = 52.0;

/// A beat drag in progress.
struct BeatDrag {
    origin: Vec<Beat>,
    selected: BTreeSet<usize>,
    press_tick: f64,
    press_lane: i64,
    last: (i64, i64),
}

/// Where things were drawn last frame (for hit tests and tests).
#[derive(Clone, Copy, Debug)]
pub struct Geometry {
    pub axis: TimeAxis,
    pub lanes: Rect,
}

impl Geometry {
    /// Screen position of `tick` in the middle of lane `lane`.
    pub fn point(&self, tick: f64, lane: usize) -> Pos2 {
        Pos2::new(self.axis.x_of(tick) as f32, self.lane_y(lane))
    }

    /// Screen `y` of the middle of lane `lane`.
    fn lane_y(&self, lane: usize) -> f32 {
        self.lanes.top() + LANE_H * (lane as f32 + 0.5)
    }

    /// The lane under screen `y`, clamped to the lanes.
    pub fn lane_at(&self, y: f32) -> usize {
        (((y - self.lanes.top()) / LANE_H).floor().max(0.0) as usize).min(LANES.len() - 1)
    }
}

/// The timeline's view state (zoom, scroll, drags in progress).
#[derive(Default)]
pub struct TimelineView {
    axis: Option<TimeAxis>,
    drag: Option<BeatDrag>,
    box_from: Option<Pos2>,
    loop_from: Option<u64>,
    /// Snap added and moved beats to the grid.
    pub snap: bool,
    /// Last frame's layout.
    pub geometry: Option<Geometry>,
}

/// What the timeline shows besides the score.
pub struct TimelineInput<'a> {
    pub doc: &'a LoadedScore,
    pub selection: &'a Selection,
    pub playhead_s: f64,
    pub loop_ticks: Option<(u64, u64)>,
}

impl TimelineView {
    pub fn new() -> TimelineView {
        TimelineView {
            snap: true,
            ..Default::default()
        }
    }

    /// Fit the whole score in view at the next frame.
    pub fn fit(&mut self) {
        self.axis = None;
    }

    /// Zoom by `factor` about the middle of the view.
    pub fn zoom(&mut self, factor: f64) {
        if let (Some(axis), Some(g)) = (&mut self.axis, &self.geometry) {
            axis.zoom_about(f64::from(g.lanes.center().x), factor);
        }
    }

    /// The grid step used for snapping and nudging, ticks (a sixteenth note when the
    /// view is wide enough, the beat otherwise).
    pub fn grid_ticks(&self, doc: &LoadedScore) -> u64 {
        let beat = u64::from(doc.score.ticks_per_quarter);
        match &self.axis {
            Some(a) => a.grid_step(beat, 12.0),
            None => beat / 4,
        }
    }

    /// Scroll so that `tick` (the playhead while playing) stays in view.
    pub fn follow(&mut self, tick: f64) {
        if let (Some(axis), Some(g)) = (&mut self.axis, &self.geometry) {
            let width = f64::from(g.lanes.width());
            let x = axis.x_of(tick) - axis.left_px;
            if x < 0.0 || x > 0.95 * width {
                axis.start_tick = tick - 0.05 * width * axis.ticks_per_px;
            }
        }
    }

    /// The axis in use (after the first frame).
    pub fn axis(&self) -> Option<TimeAxis> {
        self.axis
    }

    /// Draw the ruler and lanes and handle the pointer; commands go to `out`.
    pub fn show(&mut self, ui: &mut egui::Ui, input: &TimelineInput, out: &mut Vec<Command>) {
        let score = &input.doc.score;
        let meter = score.meter_map();
        let end_tick = score.beats.iter().map(|b| b.end_tick()).max().unwrap_or(0);
        let last_bar = meter.position(end_tick).bar + 2;
        let (rect, ruler, lanes) = allocate(ui);
        let axis = *self.axis.get_or_insert_with(|| {
            TimeAxis::fit(
                meter.bar_start(last_bar) as f64,
                f64::from(lanes.left()),
                f64::from(lanes.width()),
            )
        });
        let geometry = Geometry { axis, lanes };
        self.geometry = Some(geometry);
        let grid = self.grid_ticks(input.doc);

        let (lanes_resp, ruler_resp) = interact(ui, lanes, ruler);
        if lanes_resp.hovered() || ruler_resp.hovered() {
            self.zoom_and_scroll(ui);
        }

        // Drawn with the axis as it was at the start of the frame.
        let canvas = Canvas::new(ui, rect, ruler, geometry);
        canvas.draw_loop(input.loop_ticks);
        canvas.draw_grid(&meter, last_bar, grid, score.ticks_per_quarter);
        canvas.draw_lanes();
        // The dragged beats are already moved in the score.
        canvas.draw_beats(&score.beats, input.selection);
        canvas.draw_playhead(score.tempo_map().tick_at(input.playhead_s));

        self.ruler_input(&ruler_resp, &geometry, input, grid, out);
        self.lanes_input(ui, &lanes_resp, &geometry, input, grid, out);
        if let (Some(from), Some(to)) = (self.box_from, lanes_resp.interact_pointer_pos()) {
            canvas.painter.rect_stroke(
                Rect::from_two_pos(from, to),
                0.0,
                Stroke::new(1.0, ui.visuals().selection.stroke.color),
                egui::StrokeKind::Inside,
            );
        }
    }

    /// Zoom (Ctrl+wheel or pinch) about the pointer and scroll (wheel) the axis, from
    /// this frame's input.
    fn zoom_and_scroll(&mut self, ui: &egui::Ui) {
        let (zoom, scroll, pointer) =
            ui.input(|i| (i.zoom_delta(), i.smooth_scroll_delta, i.pointer.hover_pos()));
        let Some(axis) = self.axis.as_mut() else {
            return;
        };
        if zoom != 1.0
            && let Some(p) = pointer
        {
            axis.zoom_about(f64::from(p.x), 1.0 / f64::from(zoom));
        }
        let dx = if scroll.x != 0.0 { scroll.x } else { scroll.y };
        if dx != 0.0 {
            axis.pan(-f64::from(dx));
        }
    }

    fn ruler_input(
        &mut self,
        resp: &egui::Response,
        g: &Geometry,
        input: &TimelineInput,
        grid: u64,
        out: &mut Vec<Command>,
    ) {
        let Some(p) = resp.interact_pointer_pos() else {
            self.loop_from = None;
            return;
        };
        let tick = snap(
            g.axis.tick_of(f64::from(p.x)),
            if self.snap { grid } else { 1 },
        );
        let shift = resp.ctx.input(|i| i.modifiers.shift);
        if shift || self.loop_from.is_some() {
            let from = *self.loop_from.get_or_insert(tick);
            let (a, b) = (from.min(tick), from.max(tick));
            out.push(Command::SetLoop((b > a).then_some((a, b))));
        } else if resp.clicked() || resp.dragged() || resp.is_pointer_button_down_on() {
            out.push(Command::Seek(
                input.doc.score.tempo_map().seconds_at(tick as f64),
            ));
        }
    }

    fn lanes_input(
        &mut self,
        ui: &egui::Ui,
        resp: &egui::Response,
        g: &Geometry,
        input: &TimelineInput,
        grid: u64,
        out: &mut Vec<Command>,
    ) {
        let beats = &input.doc.score.beats;
        let grid = if self.snap { grid } else { 1 };
        let modifiers = ui.input(|i| i.modifiers);
        let additive = modifiers.shift || modifiers.command;
        if resp.clicked()
            && let Some(p) = resp.interact_pointer_pos()
        {
            match hit_beat(beats, g, p) {
                Some(i) if additive => {
                    let mut sel = input.selection.clone();
                    sel.toggle(i);
                    sel.handle = None;
                    out.push(Command::Select(sel));
                }
                Some(i) => out.push(Command::Select(Selection::only(i))),
                None => {
                    let tick = snap(g.axis.tick_of(f64::from(p.x)), grid);
                    let hand = LANES[g.lane_at(p.y)];
                    // Like the last selected beat, else on the first drum the lane's hand
                    // prefers (the far drums are out of the other hand's reach).
                    let kit = input.doc.score.settings.kit(&input.doc.kit);
                    let template = input
                        .selection
                        .beats
                        .iter()
                        .next_back()
                        .and_then(|&i| beats.get(i))
                        .copied()
                        .unwrap_or_else(|| Beat::plain(0, default_drum(&kit, hand)));
                    let beat = Beat {
                        tick,
                        hand,
                        roll: None,
                        damp: None,
                        ..template
                    };
                    let at = beats.partition_point(|b| b.tick <= tick);
                    out.push(Command::Gesture);
                    out.push(Command::Edit(ScoreEdit::AddBeat { beat, at: None }));
                    out.push(Command::Select(Selection::only(at)));
                }
            }
        }
        if resp.drag_started()
            && let Some(origin) = ui.input(|i| i.pointer.press_origin())
        {
            match hit_beat(beats, g, origin) {
                Some(i) => {
                    let mut sel = input.selection.beats.clone();
                    if !sel.contains(&i) {
                        sel = if additive {
                            let mut s = sel;
                            s.insert(i);
                            s
                        } else {
                            BTreeSet::from([i])
                        };
                    }
                    out.push(Command::Gesture);
                    out.push(Command::Select(Selection {
                        beats: sel.clone(),
                        handle: None,
                    }));
                    self.drag = Some(BeatDrag {
                        origin: beats.clone(),
                        selected: sel,
                        press_tick: g.axis.tick_of(f64::from(origin.x)),
                        press_lane: g.lane_at(origin.y) as i64,
                        last: (0, 0),
                    });
                }
                None => self.box_from = Some(origin),
            }
        }
        if let (Some(drag), Some(p)) = (&mut self.drag, resp.interact_pointer_pos()) {
            let raw = g.axis.tick_of(f64::from(p.x)) - drag.press_tick;
            let g_f = grid.max(1) as f64;
            let dtick = ((raw / g_f).round() * g_f) as i64;
            let dlane = g.lane_at(p.y) as i64 - drag.press_lane;
            if (dtick, dlane) != drag.last {
                drag.last = (dtick, dlane);
                let (after, sel) = selection::moved(&drag.origin, &drag.selected, dtick, dlane);
                out.push(Command::Edit(ScoreEdit::SetBeats {
                    before: beats.clone(),
                    after,
                }));
                out.push(Command::Select(Selection {
                    beats: sel,
                    handle: None,
                }));
            }
        }
        if resp.drag_stopped() {
            self.drag = None;
            if let (Some(from), Some(to)) = (self.box_from.take(), resp.interact_pointer_pos()) {
                let area = Rect::from_two_pos(from, to);
                let mut sel = if additive {
                    input.selection.beats.clone()
                } else {
                    BTreeSet::new()
                };
                sel.extend(
                    beats
                        .iter()
                        .enumerate()
                        .filter(|(_, b)| area.contains(g.point(b.tick as f64, lane_of(b.hand))))
                        .map(|(i, _)| i),
                );
                out.push(Command::Select(Selection {
                    beats: sel,
                    handle: None,
                }));
            }
        }
        if !resp.is_pointer_button_down_on() && !resp.drag_stopped() {
            self.drag = None;
            self.box_from = None;
        }
    }
}

/// Allocate the timeline's area at the full available width: the whole, the ruler (on
/// top, right of the lane labels) and the lanes below it.
fn allocate(ui: &mut egui::Ui) -> (Rect, Rect, Rect) {
    let height = RULER_H + LANE_H * LANES.len() as f32;
    let (rect, _) = ui.allocate_exact_size(Vec2::new(ui.available_width(), height), Sense::hover());
    let ruler = Rect::from_min_max(
        Pos2::new(rect.left() + LABEL_W, rect.top()),
        Pos2::new(rect.right(), rect.top() + RULER_H),
    );
    let lanes = Rect::from_min_max(Pos2::new(rect.left() + LABEL_W, ruler.bottom()), rect.max);
    (rect, ruler, lanes)
}

/// Make the lanes and the ruler clickable and draggable (named canvases for
/// accessibility); their responses, lanes first.
fn interact(ui: &egui::Ui, lanes: Rect, ruler: Rect) -> (egui::Response, egui::Response) {
    let lanes_resp = ui
        .interact(
            lanes,
            ui.make_persistent_id("timeline-lanes"),
            Sense::click_and_drag(),
        )
        .on_hover_text_at_pointer("Click: add a beat. Drag: move or box-select.");
    lanes_resp.widget_info(|| egui::WidgetInfo::labeled(egui::Role::Canvas, true, "Timeline"));
    let ruler_resp = ui.interact(
        ruler,
        ui.make_persistent_id("timeline-ruler"),
        Sense::click_and_drag(),
    );
    ruler_resp.widget_info(|| egui::WidgetInfo::labeled(egui::Role::Canvas, true, "Ruler"));
    (lanes_resp, ruler_resp)
}

/// Where one frame of the timeline is drawn, and in which colours.
struct Canvas {
    painter: egui::Painter,
    /// The whole timeline.
    rect: Rect,
    /// The bar ruler.
    ruler: Rect,
    /// The axis and the lanes.
    geometry: Geometry,
    grid_colour: Color32,
    text_colour: Color32,
}

impl Canvas {
    /// A painter for `rect`, its background filled.
    fn new(ui: &egui::Ui, rect: Rect, ruler: Rect, geometry: Geometry) -> Canvas {
        let painter = ui.painter_at(rect);
        let visuals = ui.visuals();
        painter.rect_filled(rect, 4.0, visuals.extreme_bg_color);
        Canvas {
            painter,
            rect,
            ruler,
            geometry,
            grid_colour: visuals.widgets.noninteractive.bg_stroke.color,
            text_colour: visuals.text_color(),
        }
    }

    /// Screen x of `tick`.
    fn x_of(&self, tick: f64) -> f32 {
        self.geometry.axis.x_of(tick) as f32
    }

    /// Shade the loop region `(start, end)` (ticks) over the ruler and lanes.
    fn draw_loop(&self, loop_ticks: Option<(u64, u64)>) {
        if let Some((a, b)) = loop_ticks {
            let r = Rect::from_x_y_ranges(
                self.x_of(a as f64)..=self.x_of(b as f64),
                self.rect.y_range(),
            );
            self.painter.rect_filled(
                r.intersect(self.geometry.lanes.union(self.ruler)),
                0.0,
                Color32::from_rgba_unmultiplied(80, 160, 80, 40),
            );
        }
    }

    /// Bar lines numbered on the ruler up to `last_bar`, and grid lines every `grid`
    /// ticks within each bar (heavier on the beats).
    fn draw_grid(&self, meter: &MeterMap, last_bar: u64, grid: u64, ticks_per_quarter: u32) {
        let (rect, lanes) = (self.rect, self.geometry.lanes);
        for bar in 1..=last_bar {
            let start = meter.bar_start(bar);
            let x = self.x_of(start as f64);
            if x > rect.right() {
                break;
            }
            let sig = meter.signature_at(start);
            if x >= lanes.left() {
                self.painter.line_segment(
                    [Pos2::new(x, rect.top()), Pos2::new(x, rect.bottom())],
                    Stroke::new(1.5, self.grid_colour),
                );
                self.painter.text(
                    Pos2::new(x + 3.0, self.ruler.center().y),
                    egui::Align2::LEFT_CENTER,
                    bar.to_string(),
                    egui::FontId::monospace(10.0),
                    self.text_colour,
                );
            }
            let bar_len = sig.bar_ticks(ticks_per_quarter);
            let mut t = start + grid;
            while t < start + bar_len {
                let bx = self.x_of(t as f64);
                if bx >= lanes.left() && bx <= rect.right() {
                    let on_beat = (t - start).is_multiple_of(sig.beat_ticks(ticks_per_quarter));
                    self.painter.line_segment(
                        [Pos2::new(bx, lanes.top()), Pos2::new(bx, rect.bottom())],
                        Stroke::new(if on_beat { 0.8 } else { 0.3 }, self.grid_colour),
                    );
                }
                t += grid;
            }
        }
    }

    /// The lane names and the line at the top of each lane.
    fn draw_lanes(&self) {
        let lanes = self.geometry.lanes;
        for (lane, name) in LANE_NAMES.iter().enumerate() {
            self.painter.text(
                Pos2::new(self.rect.left() + 6.0, self.geometry.lane_y(lane)),
                egui::Align2::LEFT_CENTER,
                *name,
                egui::FontId::proportional(12.0),
                self.text_colour,
            );
            self.painter.line_segment(
                [
                    Pos2::new(lanes.left(), lanes.top() + LANE_H * lane as f32),
                    Pos2::new(lanes.right(), lanes.top() + LANE_H * lane as f32),
                ],
                Stroke::new(0.5, self.grid_colour),
            );
        }
    }

    /// The beats in view, clipped to the lanes: shape by mode, size by dynamic, a bar to
    /// the end of a roll, the drum below; selected ones outlined.
    fn draw_beats(&self, beats: &[Beat], selection: &Selection) {
        let lanes = self.geometry.lanes;
        let beat_painter = self.painter.with_clip_rect(lanes);
        for (i, beat) in beats.iter().enumerate() {
            let x = self.x_of(beat.tick as f64);
            if x < lanes.left() - 20.0 || x > self.rect.right() + 20.0 {
                continue;
            }
            let centre = Pos2::new(x, self.geometry.lane_y(lane_of(beat.hand)));
            let r = beat_radius(beat);
            let colour = mode_colour(beat.mode);
            if let Some(roll) = beat.roll {
                let end = self.x_of((beat.tick + roll.length_ticks) as f64);
                beat_painter.rect_filled(
                    Rect::from_min_max(
                        centre - Vec2::new(0.0, 3.0),
                        Pos2::new(end, centre.y + 3.0),
                    ),
                    2.0,
                    colour.gamma_multiply(0.6),
                );
            }
            let selected = selection.beats.contains(&i);
            beat_painter.add(beat_shape(beat.mode, centre, r, colour, selected));
            beat_painter.text(
                centre + Vec2::new(0.0, r + 6.0),
                egui::Align2::CENTER_CENTER,
                beat.drum.to_string(),
                egui::FontId::monospace(9.0),
                self.text_colour,
            );
        }
    }

    /// The playhead line at `tick`, when it is in view.
    fn draw_playhead(&self, tick: f64) {
        let ph = self.x_of(tick);
        if ph >= self.geometry.lanes.left() && ph <= self.rect.right() {
            self.painter.line_segment(
                [
                    Pos2::new(ph, self.rect.top()),
                    Pos2::new(ph, self.rect.bottom()),
                ],
                Stroke::new(1.5, Color32::from_rgb(250, 80, 80)),
            );
        }
    }
}

/// Drawn radius of a beat, px (grows with the dynamic).
fn beat_radius(beat: &Beat) -> f32 {
    4.0 + 9.0 * beat.dynamic.velocity() as f32
}

/// The beat drawn under `p`, if any (the last drawn wins, as it is on top).
pub fn hit_beat(beats: &[Beat], g: &Geometry, p: Pos2) -> Option<usize> {
    beats
        .iter()
        .enumerate()
        .rev()
        .find(|(_, b)| g.point(b.tick as f64, lane_of(b.hand)).distance(p) <= beat_radius(b) + 3.0)
        .map(|(i, _)| i)
}

/// Legato circle, tenuto square, accent triangle, vertical accent inverted triangle,
/// staccato diamond; selected beats get a bright outline.
fn beat_shape(mode: PlayingMode, c: Pos2, r: f32, fill: Color32, selected: bool) -> Shape {
    let stroke = if selected {
        Stroke::new(2.5, Color32::WHITE)
    } else {
        Stroke::new(1.0, Color32::BLACK)
    };
    let poly = |pts: Vec<Pos2>| Shape::convex_polygon(pts, fill, stroke);
    match mode {
        PlayingMode::Legato => Shape::Circle(egui::epaint::CircleShape {
            center: c,
            radius: r,
            fill,
            stroke,
        }),
        PlayingMode::Tenuto => poly(vec![
            c + Vec2::new(-0.85 * r, -0.85 * r),
            c + Vec2::new(0.85 * r, -0.85 * r),
            c + Vec2::new(0.85 * r, 0.85 * r),
            c + Vec2::new(-0.85 * r, 0.85 * r),
        ]),
        PlayingMode::Accent => poly(vec![
            c + Vec2::new(-r, r),
            c + Vec2::new(r, r),
            c + Vec2::new(0.0, -r),
        ]),
        PlayingMode::VerticalAccent => poly(vec![
            c + Vec2::new(-r, -r),
            c + Vec2::new(0.0, r),
            c + Vec2::new(r, -r),
        ]),
        PlayingMode::Staccato => poly(vec![
            c + Vec2::new(0.0, -r),
            c + Vec2::new(r, 0.0),
            c + Vec2::new(0.0, r),
            c + Vec2::new(-r, 0.0),
        ]),
    }
}

/// The drum a new beat in `hand`'s lane goes on when there is nothing to copy: the first
/// drum that hand prefers (any hand: the first drum).
fn default_drum(kit: &crate::kit::Kit, hand: crate::score::Hand) -> usize {
    hand.side()
        .and_then(|side| kit.drums.iter().position(|d| d.preferred_hand == side))
        .unwrap_or(0)
}
