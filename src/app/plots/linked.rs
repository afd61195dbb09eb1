//! What every time plot shares: its time axis follows the timeline's visible window
//! (linked time axes), the playhead is a vertical line, a click seeks; and a [`Series`]
//! keeps a long line at full resolution but hands the plot at most [`MAX_POINTS`] points
//! of the visible window (min/max decimation, rebuilt only when the window changes).

use super::decimate;
use eframe::egui::{self, Color32};
use egui_plot::{Legend, Plot, PlotPoint, PlotTransform, PlotUi, VLine};

/// Most points a line hands to the plot per frame.
pub const MAX_POINTS: usize = 2000;

/// Colour of the playhead line.
pub const PLAYHEAD: Color32 = Color32::from_rgb(250, 80, 80);

/// The timeline's state the time plots follow.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TimeLink {
    /// Visible score-time window of the timeline, s (`None`: fit the data).
    pub window: Option<(f64, f64)>,
    /// The playhead, s.
    pub playhead_s: f64,
}

/// A time plot's outcome this frame.
pub struct Shown {
    /// Where a click asked to seek to, s.
    pub seek: Option<f64>,
    /// Screen ↔ plot mapping of this frame (for tests and picking).
    pub transform: PlotTransform,
}

/// What a tab's time plots did this frame: the first seek asked for and the first plot's
/// mapping.
#[derive(Default)]
pub struct Outcome {
    pub seek: Option<f64>,
    pub transform: Option<PlotTransform>,
}

impl Outcome {
    /// Take in one more plot.
    pub fn add(&mut self, shown: Shown) {
        self.seek = self.seek.or(shown.seek);
        self.transform.get_or_insert(shown.transform);
    }
}

/// The legend of every plot: small text over a see-through box, items in drawing order.
pub fn legend() -> Legend {
    Legend::default()
        .text_style(egui::TextStyle::Small)
        .background_alpha(0.5)
        .follow_insertion_order(true)
}

/// Show a plot of `height` px with time (s) across, `y_label` up, linked to `link`; `build`
/// adds the items.
pub fn time_plot<'a>(
    ui: &mut egui::Ui,
    id: &str,
    y_label: &str,
    height: f32,
    link: TimeLink,
    build: impl FnOnce(&mut PlotUi<'a>) + 'a,
) -> Shown {
    let shown = Plot::new(id)
        .height(height)
        .legend(legend())
        .x_axis_label("time (s)")
        .y_axis_label(y_label)
        .allow_drag(false)
        .allow_zoom(false)
        .allow_scroll(false)
        .allow_double_click_reset(false)
        .show(ui, move |plot| {
            if let Some((t0, t1)) = link.window {
                plot.set_plot_bounds_x(t0..=t1);
                plot.set_auto_bounds([false, true]);
            }
            build(plot);
            plot.vline(VLine::new("playhead", link.playhead_s).color(PLAYHEAD));
            (plot.response().clicked())
                .then(|| plot.pointer_coordinate())
                .flatten()
                .map(|p| p.x)
        });
    Shown {
        seek: shown.inner,
        transform: shown.transform,
    }
}

/// One line of a plot: all its points, sorted by x, and the decimated view of the last
/// window asked for.
#[derive(Clone, Debug, Default)]
pub struct Series {
    full: Vec<[f64; 2]>,
    view: Vec<PlotPoint>,
    /// The window `view` was made for (bit patterns), `None` before the first.
    key: Option<Option<(u64, u64)>>,
}

impl Series {
    /// A series of `points`, sorted by x; points that are not finite are left out (the
    /// plot library cannot order them).
    pub fn new(mut points: Vec<[f64; 2]>) -> Series {
        points.retain(|p| p.iter().all(|v| v.is_finite()));
        debug_assert!(points.windows(2).all(|w| w[0][0] <= w[1][0]));
        Series {
            full: points,
            view: Vec::new(),
            key: None,
        }
    }

    /// At most [`MAX_POINTS`] points drawing `window` (s; `None`: everything).
    pub fn view(&mut self, window: Option<(f64, f64)>) -> &[PlotPoint] {
        let key = window.map(|(a, b)| (a.to_bits(), b.to_bits()));
        if self.key != Some(key) {
            self.key = Some(key);
            let part = match window {
                Some((a, b)) => decimate::visible(&self.full, a, b),
                None => &self.full[..],
            };
            self.view = decimate::min_max(part, MAX_POINTS)
                .into_iter()
                .map(|[x, y]| PlotPoint::new(x, y))
                .collect();
        }
        &self.view
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A long series is capped per window, and the view is rebuilt only for a new window.
    #[test]
    fn series_view_is_capped_and_cached() {
        let mut s = Series::new((0..20_000).map(|k| [k as f64 * 0.004, 0.0]).collect());
        assert_eq!(s.view(None).len(), 1000, "a flat bucket keeps one point");
        let s2: Vec<[f64; 2]> = (0..20_000)
            .map(|k| [k as f64 * 0.004, (k as f64).sin()])
            .collect();
        let mut s = Series::new(s2);
        assert!(s.view(None).len() <= MAX_POINTS);
        let whole = s.view(None).as_ptr();
        assert_eq!(s.view(None).as_ptr(), whole, "same window: no rebuild");
        let part = s.view(Some((10.001, 12.001))).to_vec();
        assert_eq!(
            part.len(),
            502,
            "500 samples in the window and one each side"
        );
        assert!(part[0].x < 10.001 && part[501].x > 12.001);
    }
}
