//! The timeline's horizontal axis: mapping between score ticks and screen x (with zoom
//! and pan), and snapping ticks to the beat grid — pure math, no egui.

/// A visible window of musical time drawn across a strip of pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TimeAxis {
    /// Tick at the left edge of the lanes.
    pub start_tick: f64,
    /// Ticks per pixel (zoom).
    pub ticks_per_px: f64,
    /// Screen x of the left edge of the lanes, px.
    pub left_px: f64,
}

impl TimeAxis {
    /// Screen x of `tick`.
    pub fn x_of(&self, tick: f64) -> f64 {
        self.left_px + (tick - self.start_tick) / self.ticks_per_px
    }

    /// Tick at screen `x`.
    pub fn tick_of(&self, x: f64) -> f64 {
        self.start_tick + (x - self.left_px) * self.ticks_per_px
    }

    /// An axis showing ticks `0..=end_tick` across `width` pixels from `left_px`.
    pub fn fit(end_tick: f64, left_px: f64, width: f64) -> TimeAxis {
        TimeAxis {
            start_tick: 0.0,
            ticks_per_px: end_tick.max(1.0) / width.max(1.0),
            left_px,
        }
    }

    /// Zoom by `factor` (> 1 shows more time) keeping the tick under `x` in place.
    pub fn zoom_about(&mut self, x: f64, factor: f64) {
        let anchor = self.tick_of(x);
        self.ticks_per_px = (self.ticks_per_px * factor).clamp(0.05, 1e5);
        self.start_tick = anchor - (x - self.left_px) * self.ticks_per_px;
    }

    /// Scroll by `dx` pixels (positive shows later time); never before tick 0 by more
    /// than a few pixels.
    pub fn pan(&mut self, dx: f64) {
        self.start_tick = (self.start_tick + dx * self.ticks_per_px).max(-20.0 * self.ticks_per_px);
    }

    /// A grid step (ticks) no finer than `min_px` pixels: the beat, or a power-of-two
    /// multiple or fraction of it.
    pub fn grid_step(&self, beat_ticks: u64, min_px: f64) -> u64 {
        let mut step = beat_ticks.max(1);
        while (step as f64) / self.ticks_per_px < min_px {
            step *= 2;
        }
        while step.is_multiple_of(2) && (step / 2) as f64 / self.ticks_per_px >= min_px {
            step /= 2;
        }
        step
    }
}

/// `tick` rounded to the nearest multiple of `grid` ticks (not below 0); `grid` 0 or 1
/// leaves it as is (rounded to a whole tick).
pub fn snap(tick: f64, grid: u64) -> u64 {
    let t = tick.max(0.0);
    if grid <= 1 {
        return t.round() as u64;
    }
    let g = grid as f64;
    ((t / g).round() * g) as u64
}

#[cfg(test)]
mod tests {
    use super::*;

    /// x ↔ tick round trips, and zooming keeps the tick under the pointer fixed.
    #[test]
    fn mapping_and_zoom() {
        let mut axis = TimeAxis::fit(3840.0, 60.0, 960.0);
        assert_eq!(axis.x_of(0.0), 60.0);
        assert!((axis.x_of(3840.0) - 1020.0).abs() < 1e-9);
        assert!((axis.tick_of(axis.x_of(1234.5)) - 1234.5).abs() < 1e-9);
        let under = axis.tick_of(500.0);
        axis.zoom_about(500.0, 0.5);
        assert!((axis.tick_of(500.0) - under).abs() < 1e-9);
        assert!((axis.ticks_per_px - 2.0).abs() < 1e-12);
    }

    /// Panning scrolls but stops just before the start.
    #[test]
    fn pan_stops_near_start() {
        let mut axis = TimeAxis::fit(3840.0, 0.0, 960.0);
        axis.pan(100.0);
        assert!((axis.start_tick - 400.0).abs() < 1e-9);
        axis.pan(-1000.0);
        assert!((axis.start_tick + 80.0).abs() < 1e-9);
    }

    /// Snapping rounds to the grid and never goes negative.
    #[test]
    fn snapping() {
        assert_eq!(snap(1439.0, 480), 1440);
        assert_eq!(snap(1199.0, 480), 960);
        assert_eq!(snap(-300.0, 480), 0);
        assert_eq!(snap(17.6, 0), 18);
    }

    /// The grid step is the beat when it is wide enough, coarser or finer otherwise.
    #[test]
    fn grid_steps() {
        let axis = TimeAxis::fit(3840.0, 0.0, 960.0); // 4 ticks per px
        assert_eq!(axis.grid_step(960, 20.0), 120);
        assert_eq!(axis.grid_step(960, 400.0), 1920);
    }
}
