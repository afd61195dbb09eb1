//! The 3D viewport: orbit/pan/zoom camera, the floor, the drums with their heads (rings
//! and spokes lifted by the rendered membrane motion at the playhead, magnified
//! [`MEMBRANE_MAGNIFICATION`] times), the body as capsules with sticks, the composed target tip trajectories (one
//! colour per hand) with impacts, pins and handles marked, and room for simulated
//! trajectories in other colours. Handles: drag on a trajectory to add one and move it,
//! drag a handle to move it (in the view plane, or along x/y/z while X/Y/Z is held),
//! right-click removes it; drag an impact to pin it on the head (right-click unpins).

use super::command::Command;
use super::picking::{drag_along_axis, drag_in_plane, pick_polyline};
use super::selection::Selection;
use super::solid_frame::rendering_key;
use crate::body::model::BodyModel;
use crate::body::skeleton::Pose;
use crate::drum::DrumSet;
use crate::drum::set::recorded_sum;
use crate::kit::Side;
use crate::mocap::db::side_index;
use crate::motion::compose::Composition;
use crate::scene::camera::{
    Camera, DISTANCE_RANGE_M, MAX_PITCH_RAD, MOVE_S, Projector, View, follow_step, next_hand,
};
use crate::scene::marks::{Anchor, HAND_COLOURS, Mark, Rgba};
use crate::scene::stage;
use crate::scene::trail::{self, StrokePhase, TrailColour, level_colour, speed_level, speed_scale};
use crate::score::edit::ScoreEdit;
use crate::score::{Handle, ImpactPin, LoadedScore, SavedCamera};
use eframe::egui::{self, Color32, Pos2, Rect, Sense, Shape, Stroke, Vec2};
use glam::{DVec2, DVec3};
use std::cell::RefCell;
use std::collections::HashMap;

/// Colour of each hand's composed (target) trajectory, [left, right].
pub const TARGET_COLOURS: [Color32; 2] = [colour32(HAND_COLOURS[0]), colour32(HAND_COLOURS[1])];
/// Colour of each hand's simulated trajectory, [left, right].
pub const SIMULATED_COLOURS: [Color32; 2] = [
    Color32::from_rgb(120, 230, 230),
    Color32::from_rgb(250, 220, 90),
];

/// The flat view's head shapes: the coupled modes' shapes at each point a frame asks the
/// displacement of (rings and spokes, the same points every frame), computed once per
/// rendering — a few hundred points of a hundred Bessel modes each, which every frame
/// computed again before.
#[derive(Default)]
struct PointShapes {
    /// The rendering they were computed for ([`rendering_key`]).
    key: Option<(usize, usize)>,
    shapes: HashMap<(usize, [u64; 3]), Option<Vec<f64>>>,
}

impl PointShapes {
    /// The vertical displacement (m) of drum `index`'s head at `point` (performer frame)
    /// at score time `time_s`, as recorded by the rendering of `drums`; zero without one
    /// ([`DrumSet::recorded_displacement`], from the shapes kept for `drums`).
    fn displacement(
        &mut self,
        drums: Option<&DrumSet>,
        index: usize,
        time_s: f64,
        point: DVec3,
    ) -> f64 {
        let Some(q) = drums.and_then(|d| d.recorded_modes(index, time_s).map(|q| (d, q))) else {
            return 0.0;
        };
        let (drums, q) = q;
        let key = rendering_key(drums);
        if self.key != Some(key) {
            self.shapes.clear();
            self.key = Some(key);
        }
        let at = (index, point.to_array().map(f64::to_bits));
        (self.shapes.entry(at))
            .or_insert_with(|| drums.coupled_shapes_at(index, point))
            .as_ref()
            .map_or(0.0, |shapes| recorded_sum(q, shapes))
    }
}

/// What the viewport draws.
pub struct ViewportInput<'a> {
    pub doc: &'a LoadedScore,
    pub composition: Option<&'a Composition>,
    /// Changes whenever `composition` is replaced (for caches).
    pub generation: u64,
    /// The body pose to draw (IK now, simulated later).
    pub pose: Option<&'a Pose>,
    /// Faint poses to draw as well, each in its colour: the simulated body at the
    /// selected beats' impacts, the target pose, the previous rendering's pose.
    pub ghosts: &'a [(Pose, Rgba)],
    /// Legend lines for the overlaid poses shown (name, colour).
    pub overlays: &'a [(&'static str, Rgba)],
    /// Simulated tip trajectories on the composition's time grid, [left, right].
    pub simulated: Option<&'a [Vec<DVec3>; 2]>,
    /// The rendered drums, whose recorded membrane motion the heads show.
    pub drums: Option<&'a DrumSet>,
    pub selection: &'a Selection,
    /// The playhead, s.
    pub time_s: f64,
}

enum Drag {
    Orbit,
    Pan,
    Handle {
        index: usize,
        anchor: DVec3,
        start_offset: DVec3,
        current: Handle,
    },
    Pin {
        hand: Side,
        tick: u64,
        anchor: DVec3,
        current: DVec3,
    },
}

/// Per-sample speeds and phases of one composition, [left, right].
struct TrailCache {
    generation: u64,
    speeds: [Vec<f64>; 2],
    phases: [Vec<StrokePhase>; 2],
    /// The top of the speed ramp, m/s.
    scale: f64,
}

impl TrailCache {
    fn of(comp: &Composition, generation: u64) -> TrailCache {
        let speeds = [0, 1].map(|h| trail::speeds(&comp.tips[h], comp.rate_hz));
        let phases = [0, 1].map(|h| {
            let impacts: Vec<usize> = (comp.strokes.iter().zip(&comp.impact_samples))
                .filter(|(s, _)| side_index(s.hand) == h)
                .map(|(_, &k)| k)
                .collect();
            trail::phases(&comp.tips[h], comp.rate_hz, &impacts)
        });
        let scale = speed_scale(&[speed_scale(&speeds[0]), speed_scale(&speeds[1])]);
        TrailCache {
            generation,
            speeds,
            phases,
            scale,
        }
    }
}

struct Projected {
    key: (u64, [u64; 8], [u32; 2]),
    tips: [Vec<Option<DVec2>>; 2],
}

/// The viewport's state: camera, drag in progress, projection cache.
#[derive(Default)]
pub struct Viewport {
    pub camera: Camera,
    /// A move to a named view in progress: from, to, and when it started (egui time, s).
    moving: Option<(Camera, Camera, f64)>,
    /// Following the hand that strikes next: the egui time of the last step, s.
    following: Option<f64>,
    /// Show the composed trajectories only this far either side of the playhead, s,
    /// fading toward the ends (`None`: all of them).
    pub trajectory_window_s: Option<f64>,
    /// What the composed trajectories' colour shows.
    pub trail_colour: TrailColour,
    /// The composition's tip speeds and stroke phases, for colouring.
    trail: Option<TrailCache>,
    body: BodyModel,
    drag: Option<Drag>,
    cache: Option<Projected>,
    /// Where the viewport was drawn last frame.
    pub rect: Option<Rect>,
    /// egui's target format when the editor runs on wgpu: the stage is then drawn lit and
    /// depth-buffered on the GPU (`gpu_view`); `None` paints the flat 2D marks.
    pub gpu: Option<eframe::wgpu::TextureFormat>,
    /// The heads' mode shapes for the GPU view.
    heads: super::solid_frame::HeadShapes,
    /// The heads' mode shapes for the flat view.
    points: RefCell<PointShapes>,
}

fn to_pos(rect: Rect, p: DVec2) -> Pos2 {
    Pos2::new(rect.left() + p.x as f32, rect.top() + p.y as f32)
}

fn camera_key(c: &Camera) -> [u64; 8] {
    [
        c.target.x.to_bits(),
        c.target.y.to_bits(),
        c.target.z.to_bits(),
        c.yaw.to_bits(),
        c.pitch.to_bits(),
        c.distance.to_bits(),
        c.fov_y.to_bits(),
        0,
    ]
}

/// `camera` as saved with the score (its field of view is the editor's own).
pub fn saved_camera(camera: &Camera) -> SavedCamera {
    SavedCamera {
        target_m: camera.target.as_vec3().to_array(),
        yaw_rad: camera.yaw as f32,
        pitch_rad: camera.pitch as f32,
        distance_m: camera.distance as f32,
    }
}

/// A camera saved with a score, as the viewport's (pitch and distance held within what
/// orbit and zoom allow); `None` for numbers no camera can have.
pub fn camera_of_saved(saved: &SavedCamera) -> Option<Camera> {
    if !saved.is_usable() {
        return None;
    }
    let (near, far) = (*DISTANCE_RANGE_M.start(), *DISTANCE_RANGE_M.end());
    Some(Camera {
        target: DVec3::from_array(saved.target_m.map(f64::from)),
        yaw: f64::from(saved.yaw_rad),
        pitch: f64::from(saved.pitch_rad).clamp(-MAX_PITCH_RAD, MAX_PITCH_RAD),
        distance: f64::from(saved.distance_m).clamp(near, far),
        ..Camera::default()
    })
}

/// Longest trajectory window the View menu offers, s.
pub const MAX_WINDOW_S: f64 = 8.0;

/// The samples of `comp` shown with a trajectory window of `window_s` either side of
/// `time_s` (all of them without one).
fn shown_samples(comp: &Composition, time_s: f64, window_s: Option<f64>) -> std::ops::Range<usize> {
    match window_s {
        Some(w) => sample_of(comp, time_s - w)..(sample_of(comp, time_s + w) + 1).min(comp.len()),
        None => 0..comp.len(),
    }
}

/// Sample index of time `t` in `comp`, clamped.
fn sample_of(comp: &Composition, t: f64) -> usize {
    (((t - comp.start_s) * comp.rate_hz).round().max(0.0) as usize)
        .min(comp.len().saturating_sub(1))
}

impl Viewport {
    /// Move the camera to `view` over [`MOVE_S`], starting at egui time `now_s`.
    pub fn go_to(&mut self, view: View, now_s: f64) {
        self.move_to(Camera::of_view(view), now_s);
    }

    /// Move the camera to `to` over [`MOVE_S`], starting at egui time `now_s` (and stop
    /// following the hand).
    pub fn move_to(&mut self, to: Camera, now_s: f64) {
        self.following = None;
        self.moving = Some((self.camera, to, now_s));
    }

    /// Follow the stick tip of the hand that strikes next, from egui time `now_s`: the
    /// target glides after it (orbit and zoom still work; a pan or a move stops it).
    pub fn follow_hand(&mut self, now_s: f64) {
        self.moving = None;
        self.following = Some(now_s);
    }

    /// Whether the camera follows the hand that strikes next.
    pub fn is_following(&self) -> bool {
        self.following.is_some()
    }

    /// Stop every camera move and following (the camera is set outright).
    pub fn hold(&mut self) {
        self.moving = None;
        self.following = None;
    }

    /// Step the followed target toward the next hand's tip at `time_s` in `comp`, at egui
    /// time `now_s`; whether it is still catching up.
    fn follow(&mut self, comp: &Composition, time_s: f64, now_s: f64) -> bool {
        let Some(last) = self.following else {
            return false;
        };
        self.following = Some(now_s);
        let hand = next_hand(comp.strokes.iter().map(|s| (s.time_s, s.hand)), time_s);
        let (Some(hand), Some(tips)) = (hand, super::pose::tips_at(comp, time_s)) else {
            return false;
        };
        let goal = tips[side_index(hand)];
        self.camera.target = follow_step(self.camera.target, goal, now_s - last);
        self.camera.target.distance(goal) > 1e-4
    }

    /// The size of last frame's viewport, px.
    pub fn size(&self) -> Option<DVec2> {
        self.rect
            .map(|r| DVec2::new(f64::from(r.width()), f64::from(r.height())))
    }

    /// Advance a move in progress to egui time `now_s`; whether it is still moving.
    pub fn animate(&mut self, now_s: f64) -> bool {
        let Some((from, to, start)) = self.moving else {
            return false;
        };
        let s = (now_s - start) / MOVE_S;
        self.camera = from.toward(&to, s);
        if s >= 1.0 {
            self.moving = None;
        }
        self.moving.is_some()
    }

    /// The body model drawn.
    pub fn body(&self) -> &BodyModel {
        &self.body
    }

    /// Screen position of world point `p` in last frame's viewport.
    pub fn screen_of(&self, p: DVec3) -> Option<Pos2> {
        let rect = self.rect?;
        let size = DVec2::new(f64::from(rect.width()), f64::from(rect.height()));
        self.camera.project(p, size).map(|(q, _)| to_pos(rect, q))
    }

    /// Draw into `rect` and handle the pointer; edits go to `out`.
    pub fn show(
        &mut self,
        ui: &mut egui::Ui,
        rect: Rect,
        input: &ViewportInput,
        out: &mut Vec<Command>,
    ) {
        self.rect = Some(rect);
        let now = ui.input(|i| i.time);
        let following = input
            .composition
            .is_some_and(|comp| self.follow(comp, input.time_s, now));
        if self.animate(now) || following {
            ui.ctx().request_repaint();
        }
        let resp = ui.interact(
            rect,
            ui.make_persistent_id("viewport-3d"),
            Sense::click_and_drag(),
        );
        resp.widget_info(|| egui::WidgetInfo::labeled(egui::Role::Canvas, true, "3D view"));
        if resp.hovered() {
            let scroll = ui.input(|i| i.smooth_scroll_delta.y + (i.zoom_delta() - 1.0) * 200.0);
            if scroll != 0.0 {
                self.moving = None;
                self.camera.zoom((-f64::from(scroll) * 0.002).exp());
            }
        }
        let size = DVec2::new(f64::from(rect.width()), f64::from(rect.height()));
        self.handle_input(ui, &resp, rect, size, input, out);

        let proj = self.camera.projector(size);
        let painter = ui.painter_at(rect);
        painter.rect_filled(rect, 4.0, colour32(stage::BACKGROUND));
        let mut marks = Vec::new();
        let kit = input.doc.score.settings.kit(&input.doc.kit);
        if let Some(format) = self.gpu {
            let scene = super::solid_frame::Scene {
                kit: &kit,
                drums: input.drums,
                time_s: input.time_s,
                body: &self.body,
                pose: input.pose,
                ghosts: input.ghosts,
            };
            let frame =
                super::solid_frame::frame(&scene, &self.camera, size, &mut self.heads, format);
            super::gpu_view::paint(&painter, rect, frame);
            for drum in &kit.drums {
                stage::drum_label(&proj, drum, &mut marks);
            }
        } else {
            stage::floor(&proj, &mut marks);
            // Drums first: the body and sticks are above the heads, which are translucent.
            for (index, drum) in kit.drums.iter().enumerate() {
                let membrane = |p: DVec3| {
                    (self.points.borrow_mut()).displacement(input.drums, index, input.time_s, p)
                };
                stage::drum(&proj, drum, &membrane, &mut marks);
            }
            for (ghost, tint) in input.ghosts {
                stage::ghost(&proj, &self.body, ghost, *tint, &mut marks);
            }
            if let Some(pose) = input.pose {
                stage::body(&proj, &self.body, pose, &mut marks);
            }
        }
        if let Some(drums) = input.drums {
            stage::contacts(&proj, drums.contacts(), input.time_s, &mut marks);
        }
        paint_marks(&painter, rect, &marks);
        if let Some(comp) = input.composition {
            self.update_cache(comp, input.generation, size, &proj);
            let stale = (self.trail.as_ref()).is_none_or(|t| t.generation != input.generation);
            if self.trail_colour != TrailColour::Plain && stale {
                self.trail = Some(TrailCache::of(comp, input.generation));
            }
            self.draw_trajectories(&painter, rect, &proj, comp, input);
        }
        if let Some(sim) = input.simulated {
            for h in 0..2 {
                let pts: Vec<Pos2> = sim[h]
                    .iter()
                    .filter_map(|p| proj.project(*p).map(|(q, _)| to_pos(rect, q)))
                    .collect();
                painter.add(Shape::line(pts, Stroke::new(1.5, SIMULATED_COLOURS[h])));
            }
        }
        let mode = if ui.input(|i| i.key_down(egui::Key::X)) {
            "drag along x"
        } else if ui.input(|i| i.key_down(egui::Key::Y)) {
            "drag along y"
        } else if ui.input(|i| i.key_down(egui::Key::Z)) {
            "drag along z"
        } else {
            "drag in the view plane (hold X, Y or Z for an axis)"
        };
        painter.text(
            rect.left_bottom() + Vec2::new(6.0, -4.0),
            egui::Align2::LEFT_BOTTOM,
            format!(
                "{}Handles: {mode}. Left drag: orbit, Shift: pan, wheel: zoom",
                if self.following.is_some() {
                    "Following the hand that strikes next (a pan or F5–F8 stops). "
                } else {
                    ""
                }
            ),
            egui::FontId::proportional(11.0),
            Color32::from_gray(170),
        );
        self.legend(ui, rect, input.overlays);
    }

    /// What the trajectories' colours mean, in the view's top right corner.
    fn legend(&self, ui: &mut egui::Ui, rect: Rect, overlays: &[(&str, Rgba)]) {
        let area = Rect::from_min_size(
            rect.right_top() + Vec2::new(-128.0, 6.0),
            Vec2::new(120.0, 130.0),
        );
        let label = |ui: &mut egui::Ui, text: &str, colour: Color32| {
            let text = egui::RichText::new(text).size(11.0).color(colour);
            ui.add(egui::Label::new(text).selectable(false));
        };
        // A child of its own: it takes no room from the panels below the view.
        let ui = &mut ui.new_child(egui::UiBuilder::new().max_rect(area));
        ui.spacing_mut().item_spacing.y = 1.0;
        let scale = self.trail.as_ref().map(|t| t.scale);
        match (self.trail_colour, scale) {
            (TrailColour::Speed, Some(scale)) => {
                label(ui, "tip speed, m/s", Color32::from_gray(200));
                let (bar, _) = ui.allocate_exact_size(Vec2::new(area.width(), 8.0), Sense::hover());
                let step = bar.width() / trail::SPEED_LEVELS as f32;
                for l in 0..trail::SPEED_LEVELS {
                    let x = bar.left() + step * l as f32;
                    let cell = Rect::from_x_y_ranges(x..=x + step, bar.y_range());
                    ui.painter()
                        .rect_filled(cell, 0.0, colour32(level_colour(l)));
                }
                ui.horizontal(|ui| {
                    label(ui, "0", Color32::from_gray(200));
                    ui.with_layout(egui::Layout::right_to_left(egui::Align::Min), |ui| {
                        label(ui, &format!("{scale:.0}"), Color32::from_gray(200));
                    });
                });
            }
            (TrailColour::Phase, Some(_)) => {
                for phase in StrokePhase::ALL {
                    label(ui, phase.name(), colour32(phase.colour()));
                }
            }
            _ => {
                for (h, name) in [(0, "left target"), (1, "right target")] {
                    label(ui, name, TARGET_COLOURS[h]);
                }
            }
        }
        for (name, colour) in overlays {
            label(ui, name, colour32(colour.with_alpha(255)));
        }
    }

    fn update_cache(&mut self, comp: &Composition, generation: u64, size: DVec2, proj: &Projector) {
        let key = (
            generation,
            camera_key(&self.camera),
            [size.x as u32, size.y as u32],
        );
        if self.cache.as_ref().is_some_and(|c| c.key == key) {
            return;
        }
        let tips = [0, 1].map(|h| {
            comp.tips[h]
                .iter()
                .map(|p| proj.project(*p).map(|(q, _)| q))
                .collect()
        });
        self.cache = Some(Projected { key, tips });
    }

    fn draw_trajectories(
        &self,
        painter: &egui::Painter,
        rect: Rect,
        proj: &Projector,
        comp: &Composition,
        input: &ViewportInput,
    ) {
        let Some(cache) = &self.cache else { return };
        let shown = shown_samples(comp, input.time_s, self.trajectory_window_s);
        // Pieces of a few samples, each as opaque as its distance from the playhead
        // allows (without a window: one piece, opaque).
        let piece = if self.trajectory_window_s.is_some() {
            8
        } else {
            usize::MAX / 2
        };
        let fade = |k: usize| match self.trajectory_window_s {
            Some(w) => {
                let d = ((comp.time(k) - input.time_s).abs() / w.max(1e-3)).min(1.0);
                1.0 - 0.85 * d * d
            }
            None => 1.0,
        };
        let trail = self
            .trail
            .as_ref()
            .filter(|t| t.generation == input.generation);
        for (h, tips) in cache.tips.iter().enumerate() {
            let base = |k: usize| match (self.trail_colour, trail) {
                (TrailColour::Speed, Some(t)) => {
                    colour32(level_colour(speed_level(t.speeds[h][k], t.scale)))
                }
                (TrailColour::Phase, Some(t)) => colour32(t.phases[h][k].colour()),
                _ => TARGET_COLOURS[h],
            };
            let block = |k: usize| shown.start + (k - shown.start) / piece * piece;
            // Opaque pieces (all of them without a window) keep their colour as it is:
            // gamma_multiply(1.0) is the identity, and per sample it was most of a frame.
            let colour = |k: usize| match fade(block(k)) as f32 {
                1.0 => base(k),
                f => base(k).gamma_multiply(f),
            };
            draw_polyline(painter, rect, tips, shown.clone(), colour);
        }
        let score = &input.doc.score;
        for (stroke, &k) in comp.strokes.iter().zip(&comp.impact_samples) {
            if !shown.contains(&k) {
                continue;
            }
            let h = side_index(stroke.hand);
            if let Some(q) = cache.tips[h].get(k).copied().flatten() {
                let pinned = score
                    .pins
                    .iter()
                    .any(|p| p.hand == stroke.hand && p.tick == stroke.tick);
                let c = to_pos(rect, q);
                if pinned {
                    painter.add(Shape::convex_polygon(
                        vec![
                            c + Vec2::new(0.0, -6.0),
                            c + Vec2::new(6.0, 0.0),
                            c + Vec2::new(0.0, 6.0),
                            c + Vec2::new(-6.0, 0.0),
                        ],
                        Color32::WHITE,
                        Stroke::new(1.0, TARGET_COLOURS[h]),
                    ));
                } else {
                    painter.circle(c, 3.5, TARGET_COLOURS[h], Stroke::new(1.0, Color32::WHITE));
                }
            }
        }
        let map = score.tempo_map();
        for (i, handle) in score.handles.iter().enumerate() {
            let world = match &self.drag {
                Some(Drag::Handle {
                    index,
                    anchor,
                    start_offset,
                    current,
                }) if *index == i => *anchor + DVec3::from_array(current.offset_m) - *start_offset,
                _ => {
                    comp.tips[side_index(handle.hand)]
                        [sample_of(comp, map.seconds_at(handle.tick as f64))]
                }
            };
            if let Some((q, _)) = proj.project(world) {
                let c = to_pos(rect, q);
                let selected = input.selection.handle == Some(i);
                painter.rect(
                    Rect::from_center_size(c, Vec2::splat(if selected { 11.0 } else { 9.0 })),
                    1.0,
                    if selected {
                        Color32::YELLOW
                    } else {
                        Color32::from_gray(230)
                    },
                    Stroke::new(1.0, TARGET_COLOURS[side_index(handle.hand)]),
                    egui::StrokeKind::Middle,
                );
            }
        }
        if let Some(Drag::Pin { current, .. }) = &self.drag
            && let Some((q, _)) = proj.project(*current)
        {
            painter.circle_stroke(to_pos(rect, q), 7.0, Stroke::new(2.0, Color32::WHITE));
        }
        if let Some(tips) = super::pose::tips_at(comp, input.time_s) {
            for h in 0..2 {
                if let Some((q, _)) = proj.project(tips[h]) {
                    painter.circle_filled(to_pos(rect, q), 5.0, TARGET_COLOURS[h]);
                }
            }
        }
    }

    fn handle_input(
        &mut self,
        ui: &egui::Ui,
        resp: &egui::Response,
        rect: Rect,
        size: DVec2,
        input: &ViewportInput,
        out: &mut Vec<Command>,
    ) {
        let local = |p: Pos2| DVec2::new(f64::from(p.x - rect.left()), f64::from(p.y - rect.top()));
        let score = &input.doc.score;
        let map = score.tempo_map();
        if resp.drag_started() {
            let origin = ui
                .input(|i| i.pointer.press_origin())
                .unwrap_or(rect.center());
            let middle = resp.dragged_by(egui::PointerButton::Middle)
                || resp.dragged_by(egui::PointerButton::Secondary)
                || ui.input(|i| i.modifiers.shift);
            self.drag = if middle {
                Some(Drag::Pan)
            } else {
                input
                    .composition
                    .and_then(|comp| self.pick(comp, input, local(origin), out, &map))
                    .or(Some(Drag::Orbit))
            };
        }
        if resp.dragged() {
            let delta = resp.drag_delta();
            let d = DVec2::new(f64::from(delta.x), f64::from(delta.y));
            let pointer = resp.interact_pointer_pos().map(local);
            let axis = ui.input(|i| {
                if i.key_down(egui::Key::X) {
                    Some(DVec3::X)
                } else if i.key_down(egui::Key::Y) {
                    Some(DVec3::Y)
                } else if i.key_down(egui::Key::Z) {
                    Some(DVec3::Z)
                } else {
                    None
                }
            });
            let camera = self.camera;
            match &mut self.drag {
                Some(Drag::Orbit) => {
                    self.moving = None;
                    self.camera.orbit(d);
                }
                Some(Drag::Pan) => {
                    self.hold();
                    self.camera.pan(d, size.y);
                }
                Some(Drag::Handle {
                    index,
                    anchor,
                    start_offset,
                    current,
                }) => {
                    if let Some(px) = pointer {
                        let (o, dir) = camera.ray(px, size);
                        let target = match axis {
                            Some(a) => drag_along_axis(o, dir, *anchor, a).map(|u| *anchor + a * u),
                            None => drag_in_plane(o, dir, *anchor, camera.basis().forward),
                        };
                        if let Some(p) = target {
                            let offset = *start_offset + (p - *anchor);
                            let to = Handle {
                                offset_m: offset.to_array().map(|v| (v * 1e4).round() / 1e4),
                                ..*current
                            };
                            if to != *current {
                                out.push(Command::Edit(ScoreEdit::MoveHandle {
                                    index: *index,
                                    from: *current,
                                    to,
                                }));
                                *current = to;
                            }
                        }
                    }
                }
                Some(Drag::Pin {
                    hand,
                    tick,
                    anchor,
                    current,
                }) => {
                    if let Some(px) = pointer {
                        let (o, dir) = camera.ray(px, size);
                        if let Some(p) = drag_in_plane(o, dir, *anchor, DVec3::Z)
                            && p.distance(*current) > 1e-4
                        {
                            *current = p;
                            out.push(Command::Edit(ScoreEdit::SetPin {
                                hand: *hand,
                                tick: *tick,
                                pin: Some(ImpactPin {
                                    hand: *hand,
                                    tick: *tick,
                                    point_m: p.to_array(),
                                }),
                                before: None,
                            }));
                        }
                    }
                }
                None => {}
            }
        }
        if resp.drag_stopped() {
            self.drag = None;
        }
        if resp.secondary_clicked()
            && let (Some(comp), Some(p)) = (input.composition, resp.interact_pointer_pos())
        {
            let p = local(p);
            let proj = self.camera.projector(size);
            if let Some(i) = pick_handle(comp, input, &proj, p, &map) {
                out.push(Command::Gesture);
                out.push(Command::Edit(ScoreEdit::RemoveHandle {
                    index: i,
                    removed: None,
                }));
                out.push(Command::Select(Selection::default()));
            } else if let Some(s) = pick_impact(
                comp,
                &proj,
                p,
                input.time_s,
                &shown_samples(comp, input.time_s, self.trajectory_window_s),
            ) {
                let stroke = &comp.strokes[s];
                if score
                    .pins
                    .iter()
                    .any(|q| q.hand == stroke.hand && q.tick == stroke.tick)
                {
                    out.push(Command::Gesture);
                    out.push(Command::Edit(ScoreEdit::SetPin {
                        hand: stroke.hand,
                        tick: stroke.tick,
                        pin: None,
                        before: None,
                    }));
                }
            }
        }
    }

    /// What a press at `p` grabs: a handle, an impact, or a new handle on a trajectory.
    fn pick(
        &mut self,
        comp: &Composition,
        input: &ViewportInput,
        p: DVec2,
        out: &mut Vec<Command>,
        map: &crate::score::TempoMap,
    ) -> Option<Drag> {
        let size = self.size()?;
        let proj = self.camera.projector(size);
        let score = &input.doc.score;
        if let Some(i) = pick_handle(comp, input, &proj, p, map) {
            let h = score.handles[i];
            out.push(Command::Gesture);
            out.push(Command::Select(Selection {
                beats: Default::default(),
                handle: Some(i),
            }));
            return Some(Drag::Handle {
                index: i,
                anchor: comp.tips[side_index(h.hand)]
                    [sample_of(comp, map.seconds_at(h.tick as f64))],
                start_offset: DVec3::from_array(h.offset_m),
                current: h,
            });
        }
        let shown = shown_samples(comp, input.time_s, self.trajectory_window_s);
        if let Some(s) = pick_impact(comp, &proj, p, input.time_s, &shown) {
            let stroke = &comp.strokes[s];
            let anchor = comp.tips[side_index(stroke.hand)][comp.impact_samples[s]];
            out.push(Command::Gesture);
            return Some(Drag::Pin {
                hand: stroke.hand,
                tick: stroke.tick,
                anchor,
                current: anchor,
            });
        }
        let cache = self.cache.as_ref()?;
        let best = (0..2)
            .filter_map(|h| {
                pick_polyline(&cache.tips[h][shown.clone()], p, 6.0)
                    .map(|(k, d)| (h, shown.start + k, d))
            })
            .min_by(|a, b| a.2.total_cmp(&b.2))?;
        let (h, k, _) = best;
        let hand = if h == 0 { Side::Left } else { Side::Right };
        let tick = map.tick_at(comp.time(k)).round().max(0.0) as u64;
        let handle = Handle {
            hand,
            tick,
            reach_ticks: u64::from(score.ticks_per_quarter) / 2,
            offset_m: [0.0; 3],
        };
        out.push(Command::Gesture);
        out.push(Command::Edit(ScoreEdit::AddHandle(handle)));
        out.push(Command::Select(Selection {
            beats: Default::default(),
            handle: Some(score.handles.len()),
        }));
        Some(Drag::Handle {
            index: score.handles.len(),
            anchor: comp.tips[h][k],
            start_offset: DVec3::ZERO,
            current: handle,
        })
    }
}

/// Draw samples `shown` of the projected `tips` (`None`: not projected, a gap) as
/// lines 1.5 px wide, in runs of one `colour` each (a run starts at the last point of the
/// one before, so the line stays unbroken where the colour changes).
fn draw_polyline(
    painter: &egui::Painter,
    rect: Rect,
    tips: &[Option<DVec2>],
    shown: std::ops::Range<usize>,
    colour: impl Fn(usize) -> Color32,
) {
    let flush = |run: &mut Vec<Pos2>, c: Color32| {
        if run.len() > 1 {
            painter.add(Shape::line(std::mem::take(run), Stroke::new(1.5, c)));
        }
        run.clear();
    };
    let mut run: Vec<Pos2> = Vec::new();
    let mut run_colour = Color32::TRANSPARENT;
    for k in shown {
        let Some(q) = tips.get(k).copied().flatten() else {
            flush(&mut run, run_colour);
            continue;
        };
        let c = colour(k);
        if c != run_colour {
            let last = run.last().copied();
            flush(&mut run, run_colour);
            run.extend(last);
            run_colour = c;
        }
        run.push(to_pos(rect, q));
    }
    flush(&mut run, run_colour);
}

/// The handle whose marker is within 9 px of `p` (of several, the nearest in time to
/// the playhead).
fn pick_handle(
    comp: &Composition,
    input: &ViewportInput,
    proj: &Projector,
    p: DVec2,
    map: &crate::score::TempoMap,
) -> Option<usize> {
    input
        .doc
        .score
        .handles
        .iter()
        .enumerate()
        .filter_map(|(i, h)| {
            let world =
                comp.tips[side_index(h.hand)][sample_of(comp, map.seconds_at(h.tick as f64))];
            proj.project(world).map(|(q, _)| (i, q.distance(p)))
        })
        .filter(|(_, d)| *d <= 9.0)
        .min_by(|a, b| {
            let dt = |i: usize| {
                (map.seconds_at(input.doc.score.handles[i].tick as f64) - input.time_s).abs()
            };
            dt(a.0).total_cmp(&dt(b.0))
        })
        .map(|(i, _)| i)
}

/// The stroke whose impact marker is within 7 px of `p` (of several, the nearest in time
/// to the playhead at `time_s`: strokes on one spot share a marker).
fn pick_impact(
    comp: &Composition,
    proj: &Projector,
    p: DVec2,
    time_s: f64,
    shown: &std::ops::Range<usize>,
) -> Option<usize> {
    comp.strokes
        .iter()
        .zip(&comp.impact_samples)
        .enumerate()
        .filter(|(_, (_, k))| shown.contains(k))
        .filter_map(|(s, (stroke, &k))| {
            proj.project(comp.tips[side_index(stroke.hand)][k])
                .map(|(q, _)| (s, q.distance(p)))
        })
        .filter(|(_, d)| *d <= 7.0)
        .min_by(|a, b| {
            let dt = |s: usize| (comp.strokes[s].time_s - time_s).abs();
            dt(a.0).total_cmp(&dt(b.0))
        })
        .map(|(s, _)| s)
}

/// Paint scene marks (pixels from the viewport's corner) with egui.
pub fn paint_marks(painter: &egui::Painter, rect: Rect, marks: &[Mark]) {
    for mark in marks {
        match mark {
            Mark::Line {
                points,
                closed,
                width,
                colour,
            } => {
                let pts: Vec<Pos2> = points.iter().map(|p| to_pos(rect, *p)).collect();
                let stroke = Stroke::new(*width, colour32(*colour));
                painter.add(if *closed {
                    Shape::closed_line(pts, stroke)
                } else {
                    Shape::line(pts, stroke)
                });
            }
            Mark::Fill { points, colour } => {
                let pts: Vec<Pos2> = points.iter().map(|p| to_pos(rect, *p)).collect();
                painter.add(Shape::convex_polygon(pts, colour32(*colour), Stroke::NONE));
            }
            Mark::Disc {
                centre,
                radius,
                colour,
            } => {
                painter.circle_filled(to_pos(rect, *centre), *radius, colour32(*colour));
            }
            Mark::Label {
                at,
                anchor,
                text,
                size,
                colour,
            } => {
                let align = match anchor {
                    Anchor::LeftTop => egui::Align2::LEFT_TOP,
                    Anchor::LeftCentre => egui::Align2::LEFT_CENTER,
                    Anchor::Centre => egui::Align2::CENTER_CENTER,
                    Anchor::RightTop => egui::Align2::RIGHT_TOP,
                    Anchor::LeftBottom => egui::Align2::LEFT_BOTTOM,
                };
                painter.text(
                    to_pos(rect, *at),
                    align,
                    text,
                    egui::FontId::proportional(*size),
                    colour32(*colour),
                );
            }
        }
    }
}

/// A scene colour as egui's.
pub const fn colour32(c: Rgba) -> Color32 {
    let [r, g, b, a] = c.0;
    Color32::from_rgba_unmultiplied_const(r, g, b, a)
}
