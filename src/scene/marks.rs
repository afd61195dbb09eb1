//! The marks a view is drawn with, in pixels from the view's top-left corner: polylines
//! (open or closed), filled convex polygons, discs and text labels, each with an RGBA
//! colour (not premultiplied). Painters draw them in order, later over earlier.

use glam::DVec2;

/// An RGBA colour, each channel 0–255, alpha not premultiplied.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Rgba(pub [u8; 4]);

impl Rgba {
    /// An opaque colour.
    pub const fn rgb(r: u8, g: u8, b: u8) -> Rgba {
        Rgba([r, g, b, 255])
    }

    /// A grey.
    pub const fn grey(v: u8) -> Rgba {
        Rgba([v, v, v, 255])
    }

    /// The same colour with alpha `a`.
    pub const fn with_alpha(self, a: u8) -> Rgba {
        let [r, g, b, _] = self.0;
        Rgba([r, g, b, a])
    }
}

/// The hands' colours, [left, right]: strokes, targets and trails.
pub const HAND_COLOURS: [Rgba; 2] = [Rgba::rgb(60, 150, 230), Rgba::rgb(240, 140, 40)];

/// Where a label sits relative to its anchor point.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Anchor {
    LeftTop,
    LeftCentre,
    Centre,
    RightTop,
    LeftBottom,
}

/// One mark.
#[derive(Clone, Debug, PartialEq)]
pub enum Mark {
    /// A polyline `width` pixels wide (closed: back to its first point).
    Line {
        points: Vec<DVec2>,
        closed: bool,
        width: f32,
        colour: Rgba,
    },
    /// A filled convex polygon.
    Fill { points: Vec<DVec2>, colour: Rgba },
    /// A filled disc.
    Disc {
        centre: DVec2,
        radius: f32,
        colour: Rgba,
    },
    /// Text `size` pixels high.
    Label {
        at: DVec2,
        anchor: Anchor,
        text: String,
        size: f32,
        colour: Rgba,
    },
}

impl Mark {
    /// A straight segment.
    pub fn segment(a: DVec2, b: DVec2, width: f32, colour: Rgba) -> Mark {
        Mark::Line {
            points: vec![a, b],
            closed: false,
            width,
            colour,
        }
    }

    /// An axis-aligned filled rectangle from `min` to `max`.
    pub fn rect(min: DVec2, max: DVec2, colour: Rgba) -> Mark {
        Mark::Fill {
            points: vec![min, DVec2::new(max.x, min.y), max, DVec2::new(min.x, max.y)],
            colour,
        }
    }
}
