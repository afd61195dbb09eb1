//! Marks into pixels without a GPU: shapes anti-aliased by tiny-skia, labels drawn from
//! the editor's own font (Ubuntu Light, compiled in) through ab_glyph. A [`Canvas`] is
//! an opaque RGBA image the size of a video frame.

use super::marks::{Anchor, Mark, Rgba};
use ab_glyph::{Font, FontRef, PxScale, ScaleFont, point};
use tiny_skia::{FillRule, LineCap, LineJoin, Paint, PathBuilder, Pixmap, Stroke, Transform};

/// Why a canvas could not be made.
#[derive(Debug, thiserror::Error)]
pub enum RasterError {
    #[error("a {0}×{1} px image cannot be made (each side 16–8192 px)")]
    Size(u32, u32),
    #[error("cannot encode the PNG: {0}")]
    Png(String),
}

/// An opaque image to draw marks on.
pub struct Canvas {
    pixmap: Pixmap,
    font: FontRef<'static>,
}

impl Canvas {
    /// A `width` × `height` px canvas filled with `background` (made opaque).
    pub fn new(width: u32, height: u32, background: Rgba) -> Result<Canvas, RasterError> {
        let sane = |v: u32| (16..=8192).contains(&v);
        let mut pixmap = Pixmap::new(width, height)
            .filter(|_| sane(width) && sane(height))
            .ok_or(RasterError::Size(width, height))?;
        let [r, g, b, _] = background.0;
        pixmap.fill(tiny_skia::Color::from_rgba8(r, g, b, 255));
        let font = FontRef::try_from_slice(epaint_default_fonts::UBUNTU_LIGHT)
            .expect("the compiled-in font parses");
        Ok(Canvas { pixmap, font })
    }

    pub fn width(&self) -> u32 {
        self.pixmap.width()
    }

    pub fn height(&self) -> u32 {
        self.pixmap.height()
    }

    /// Fill the whole canvas with `colour` (made opaque).
    pub fn clear(&mut self, colour: Rgba) {
        let [r, g, b, _] = colour.0;
        self.pixmap.fill(tiny_skia::Color::from_rgba8(r, g, b, 255));
    }

    /// Draw `marks` in order.
    pub fn draw(&mut self, marks: &[Mark]) {
        for mark in marks {
            self.draw_one(mark);
        }
    }

    /// The pixels, row by row from the top, RGBA with alpha 255 (the canvas is opaque, so
    /// the premultiplied and straight forms agree).
    pub fn rgba(&self) -> &[u8] {
        self.pixmap.data()
    }

    /// The canvas as a PNG file's bytes.
    pub fn png(&self) -> Result<Vec<u8>, RasterError> {
        self.pixmap
            .encode_png()
            .map_err(|e| RasterError::Png(e.to_string()))
    }

    fn draw_one(&mut self, mark: &Mark) {
        match mark {
            Mark::Line {
                points,
                closed,
                width,
                colour,
            } => {
                let Some(path) = polyline(points, *closed) else {
                    return;
                };
                let stroke = Stroke {
                    width: width.max(0.5),
                    line_cap: LineCap::Round,
                    line_join: LineJoin::Round,
                    ..Stroke::default()
                };
                self.pixmap.stroke_path(
                    &path,
                    &paint(*colour),
                    &stroke,
                    Transform::identity(),
                    None,
                );
            }
            Mark::Fill { points, colour } => self.fill(polyline(points, true), *colour),
            Mark::Disc {
                centre,
                radius,
                colour,
            } => {
                let ok = centre.is_finite() && radius.is_finite() && *radius > 0.0;
                let disc = ok
                    .then(|| PathBuilder::from_circle(centre.x as f32, centre.y as f32, *radius))
                    .flatten();
                self.fill(disc, *colour);
            }
            Mark::Label {
                at,
                anchor,
                text,
                size,
                colour,
            } => self.label(at.x as f32, at.y as f32, *anchor, text, *size, *colour),
        }
    }

    /// Fill `path`, if there is one.
    fn fill(&mut self, path: Option<tiny_skia::Path>, colour: Rgba) {
        if let Some(path) = path {
            self.pixmap.fill_path(
                &path,
                &paint(colour),
                FillRule::Winding,
                Transform::identity(),
                None,
            );
        }
    }

    /// Text from ab_glyph's outlines, blended by coverage.
    fn label(&mut self, x: f32, y: f32, anchor: Anchor, text: &str, size: f32, colour: Rgba) {
        if !(x.is_finite() && y.is_finite() && size > 0.0) {
            return;
        }
        let font = self.font.as_scaled(PxScale::from(size));
        let width: f32 = text.chars().map(|c| font.h_advance(font.glyph_id(c))).sum();
        let height = font.ascent() - font.descent();
        let (left, top) = match anchor {
            Anchor::LeftTop => (x, y),
            Anchor::LeftCentre => (x, y - 0.5 * height),
            Anchor::Centre => (x - 0.5 * width, y - 0.5 * height),
            Anchor::RightTop => (x - width, y),
            Anchor::LeftBottom => (x, y - height),
        };
        let (w, h) = (self.pixmap.width() as i32, self.pixmap.height() as i32);
        let data = self.pixmap.data_mut();
        let [r, g, b, a] = colour.0;
        let mut pen = left;
        for c in text.chars() {
            let id = font.glyph_id(c);
            let glyph = id.with_scale_and_position(font.scale(), point(pen, top + font.ascent()));
            pen += font.h_advance(id);
            let Some(outline) = self.font.outline_glyph(glyph) else {
                continue;
            };
            let bounds = outline.px_bounds();
            outline.draw(|gx, gy, coverage| {
                let px = bounds.min.x as i32 + gx as i32;
                let py = bounds.min.y as i32 + gy as i32;
                if px < 0 || py < 0 || px >= w || py >= h {
                    return;
                }
                let alpha = coverage.clamp(0.0, 1.0) * f32::from(a) / 255.0;
                let i = 4 * (py as usize * w as usize + px as usize);
                for (k, src) in [r, g, b].into_iter().enumerate() {
                    let dst = f32::from(data[i + k]);
                    data[i + k] = (dst + (f32::from(src) - dst) * alpha).round() as u8;
                }
            });
        }
    }
}

fn paint(colour: Rgba) -> Paint<'static> {
    let [r, g, b, a] = colour.0;
    let mut paint = Paint::default();
    paint.set_color_rgba8(r, g, b, a);
    paint.anti_alias = true;
    paint
}

/// The path through `points` (closed: back to the first), if it has two finite points.
fn polyline(points: &[glam::DVec2], closed: bool) -> Option<tiny_skia::Path> {
    if points.len() < 2 || points.iter().any(|p| !p.is_finite()) {
        return None;
    }
    let mut pb = PathBuilder::new();
    pb.move_to(points[0].x as f32, points[0].y as f32);
    for p in &points[1..] {
        pb.line_to(p.x as f32, p.y as f32);
    }
    if closed {
        pb.close();
    }
    pb.finish()
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec2;

    fn pixel(c: &Canvas, x: u32, y: u32) -> [u8; 4] {
        let i = 4 * (y * c.width() + x) as usize;
        c.rgba()[i..i + 4].try_into().unwrap()
    }

    /// A disc, a line and a label change the pixels they cover and no others.
    #[test]
    fn marks_land_where_they_are() {
        let mut c = Canvas::new(100, 60, Rgba::grey(0)).unwrap();
        c.draw(&[
            Mark::Disc {
                centre: DVec2::new(20.0, 20.0),
                radius: 5.0,
                colour: Rgba::rgb(255, 0, 0),
            },
            Mark::segment(
                DVec2::new(50.0, 5.0),
                DVec2::new(50.0, 55.0),
                3.0,
                Rgba::rgb(0, 255, 0),
            ),
            Mark::Label {
                at: DVec2::new(60.0, 40.0),
                anchor: Anchor::LeftTop,
                text: "Hi".into(),
                size: 14.0,
                colour: Rgba::grey(255),
            },
        ]);
        assert_eq!(pixel(&c, 20, 20), [255, 0, 0, 255]);
        assert_eq!(pixel(&c, 50, 30), [0, 255, 0, 255]);
        assert_eq!(pixel(&c, 5, 55), [0, 0, 0, 255]);
        let text_lit = (60..80)
            .flat_map(|x| (40..56).map(move |y| (x, y)))
            .filter(|&(x, y)| pixel(&c, x, y)[0] > 128)
            .count();
        assert!(text_lit > 10, "the label lit {text_lit} pixels");
    }

    /// Half-transparent fills blend; the canvas stays opaque.
    #[test]
    fn fills_blend_and_stay_opaque() {
        let mut c = Canvas::new(40, 40, Rgba::grey(0)).unwrap();
        c.draw(&[Mark::rect(
            DVec2::new(0.0, 0.0),
            DVec2::new(40.0, 40.0),
            Rgba([200, 200, 200, 128]),
        )]);
        let p = pixel(&c, 20, 20);
        assert!((95..=105).contains(&p[0]), "{p:?}");
        assert_eq!(p[3], 255);
    }

    /// Absurd sizes are refused; non-finite marks are skipped, not drawn or panicking.
    #[test]
    fn bad_sizes_and_points() {
        assert!(Canvas::new(0, 10, Rgba::grey(0)).is_err());
        assert!(Canvas::new(10, 100_000, Rgba::grey(0)).is_err());
        let mut c = Canvas::new(20, 20, Rgba::grey(0)).unwrap();
        c.draw(&[Mark::segment(
            DVec2::new(f64::NAN, 0.0),
            DVec2::new(10.0, 10.0),
            2.0,
            Rgba::grey(255),
        )]);
        assert!(c.rgba().chunks(4).all(|p| p == [0, 0, 0, 255]));
        let png = c.png().unwrap();
        assert_eq!(&png[1..4], b"PNG");
    }
}
