//! Figures of time series (for `compose --plot`, `render --plot` and the lesson pack):
//! stacked panels sharing an x axis (time, or frequency for spectra), lines per series,
//! point markers and vertical guide lines, drawn with plotters as a PNG (the font egui
//! ships, so no system fonts are needed; written atomically) or as SVG text (one drawing
//! code for both).

use plotters::prelude::*;
use std::path::Path;
use std::sync::Once;

/// Colours of the left and right hand's lines and markers, [left, right].
pub const HAND_COLOURS: [RGBColor; 2] = [RGBColor(31, 119, 180), RGBColor(230, 120, 20)];

/// One line of a panel.
pub struct Series {
    pub label: String,
    pub colour: RGBColor,
    /// (time s, value) points.
    pub points: Vec<(f64, f64)>,
}

/// One panel: a y label, lines and markers.
pub struct Panel {
    pub y_label: String,
    pub series: Vec<Series>,
    /// (time s, value, colour) dots, e.g. impacts.
    pub markers: Vec<(f64, f64, RGBColor)>,
}

/// A figure of stacked panels over a common time axis.
pub struct Figure {
    pub title: String,
    /// The shared x axis's label, e.g. "time (s)".
    pub x_label: String,
    pub panels: Vec<Panel>,
    /// Times of vertical guide lines (e.g. beats), s.
    pub guides: Vec<f64>,
    pub size: (u32, u32),
}

fn register_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The font is compiled in; registering it cannot fail for a valid TTF.
        let _ = plotters::style::register_font(
            "sans-serif",
            FontStyle::Normal,
            epaint_default_fonts::UBUNTU_LIGHT,
        );
    });
}

fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| {
        (l.min(v), h.max(v))
    });
    if lo.is_finite() && hi > lo {
        let pad = 0.05 * (hi - lo);
        (lo - pad, hi + pad)
    } else {
        (lo.min(0.0) - 1.0, hi.max(0.0) + 1.0)
    }
}

/// Why a figure could not be written.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PlotError {
    /// The PNG (or its temporary file beside it) could not be written.
    #[error("{}: {source}", path.display())]
    Io {
        path: std::path::PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// Plotters could not draw the figure.
    #[error("{}: cannot draw the figure: {message}", path.display())]
    Draw {
        path: std::path::PathBuf,
        message: String,
    },
    /// Plotters could not draw the figure as SVG.
    #[error("cannot draw the figure \"{title}\" as SVG: {message}")]
    Svg { title: String, message: String },
}

impl Figure {
    /// Draw the figure to a PNG at `path`, atomically.
    pub fn save_png(&self, path: &Path) -> Result<(), PlotError> {
        register_font();
        let io = |source| PlotError::Io {
            path: path.to_path_buf(),
            source,
        };
        let dest = crate::base::staged::destination(path);
        let tmp = crate::base::staged::beside(&dest, ".png")
            .map_err(io)?
            .into_temp_path();
        let root = BitMapBackend::new(&tmp, self.size).into_drawing_area();
        self.draw(root).map_err(|e| PlotError::Draw {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
        crate::base::staged::put(tmp, &dest).map_err(io)
    }

    /// The figure as the text of an SVG document (`width` and `height` in pixels of
    /// [`Figure::size`]; text as `<text>` in the viewer's sans-serif font).
    pub fn to_svg(&self) -> Result<String, PlotError> {
        register_font();
        let mut text = String::new();
        {
            let root = SVGBackend::with_string(&mut text, self.size).into_drawing_area();
            self.draw(root).map_err(|e| PlotError::Svg {
                title: self.title.clone(),
                message: e.to_string(),
            })?;
        }
        Ok(text)
    }

    /// Draw on `root`, whatever the backend (PNG file or SVG text).
    fn draw<DB: DrawingBackend>(
        &self,
        root: DrawingArea<DB, plotters::coord::Shift>,
    ) -> Result<(), Box<dyn std::error::Error>>
    where
        DB::ErrorType: 'static,
    {
        root.fill(&WHITE)?;
        let root = root.titled(&self.title, ("sans-serif", 22))?;
        // The time axis spans the lines, the markers and the guides (a panel of markers
        // alone, e.g. forces per stroke, still gets its times).
        let (t0, t1) = range(
            self.panels
                .iter()
                .flat_map(|p| {
                    let lines = p.series.iter().flat_map(|s| s.points.iter().map(|p| p.0));
                    lines.chain(p.markers.iter().map(|m| m.0))
                })
                .chain(self.guides.iter().copied()),
        );
        let areas = root.split_evenly((self.panels.len().max(1), 1));
        for (panel, area) in self.panels.iter().zip(&areas) {
            let (y0, y1) = range(
                panel
                    .series
                    .iter()
                    .flat_map(|s| s.points.iter().map(|p| p.1))
                    .chain(panel.markers.iter().map(|m| m.1)),
            );
            let mut chart = ChartBuilder::on(area)
                .margin(8)
                .x_label_area_size(32)
                .y_label_area_size(56)
                .build_cartesian_2d(t0..t1, y0..y1)?;
            chart
                .configure_mesh()
                .x_desc(self.x_label.as_str())
                .y_desc(panel.y_label.as_str())
                .light_line_style(WHITE.mix(0.0))
                .draw()?;
            for &g in self.guides.iter().filter(|g| (t0..=t1).contains(*g)) {
                chart.draw_series(LineSeries::new([(g, y0), (g, y1)], BLACK.mix(0.12)))?;
            }
            for s in &panel.series {
                chart
                    .draw_series(LineSeries::new(
                        s.points.iter().copied(),
                        s.colour.stroke_width(2),
                    ))?
                    .label(s.label.as_str())
                    .legend(move |(x, y)| {
                        PathElement::new([(x, y), (x + 16, y)], s.colour.stroke_width(2))
                    });
            }
            chart.draw_series(
                panel
                    .markers
                    .iter()
                    .map(|&(t, v, c)| Circle::new((t, v), 4, c.filled())),
            )?;
            // A panel of markers alone has no legend (an empty box otherwise).
            if !panel.series.is_empty() {
                chart
                    .configure_series_labels()
                    .background_style(WHITE.mix(0.8))
                    .border_style(BLACK.mix(0.3))
                    .draw()?;
            }
        }
        root.present()?;
        Ok(())
    }
}
