//! A performed hit as the writers see it: one stick–head contact of a rendering (score
//! seconds, SI units, performer frame), made by `render` from its events and written by
//! `io` (performed MIDI, OSC) — plain data on the ground floor so neither imports the other.

use super::gesture::Side;

/// One contact of a stick with a head.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// When the felt first touched, score time, s.
    pub time_s: f64,
    /// Drum index in the kit.
    pub drum: usize,
    pub side: Side,
    /// Where it first touched, performer frame (x right, y forward), m.
    pub x_m: f64,
    pub y_m: f64,
    /// Largest contact force, N.
    pub peak_force_n: f64,
    /// Downward tip speed at first touch, m/s.
    pub impact_speed_mps: f64,
    /// Whether it is a scored stroke's own contact (else a rebound or re-contact).
    pub primary: bool,
}

impl Hit {
    /// The hand's name as files write it: "left" or "right".
    pub fn hand(&self) -> &'static str {
        match self.side {
            Side::Left => "left",
            Side::Right => "right",
        }
    }
}
