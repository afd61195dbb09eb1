//! The words of a gesture score every layer names: the side of the body, the hand of a
//! beat, the five playing modes (seed 000 §2.4), the grip, the dynamic and the impact
//! location on the head. Plain data with their names and conversions; no behaviour.

use serde::{Deserialize, Serialize};

/// A side of the body.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub enum Side {
    Left,
    Right,
}

impl Side {
    /// The other side.
    pub fn other(self) -> Side {
        match self {
            Side::Left => Side::Right,
            Side::Right => Side::Left,
        }
    }

    /// −1 for left, +1 for right (the hand-value convention of seed 003 §4.2.2).
    pub fn sign(self) -> f64 {
        match self {
            Side::Left => -1.0,
            Side::Right => 1.0,
        }
    }
}

/// The hand that plays a beat.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Hand {
    Left,
    Right,
    /// Let a sticking method choose (see `motion::sticking`).
    Auto,
}

impl Hand {
    /// The side, if the hand is fixed.
    pub fn side(self) -> Option<Side> {
        match self {
            Hand::Left => Some(Side::Left),
            Hand::Right => Some(Side::Right),
            Hand::Auto => None,
        }
    }
}

impl From<Side> for Hand {
    fn from(side: Side) -> Hand {
        match side {
            Side::Left => Hand::Left,
            Side::Right => Hand::Right,
        }
    }
}

/// The five timpani playing modes (seed 000 §2.4).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub enum PlayingMode {
    Legato,
    Tenuto,
    Accent,
    VerticalAccent,
    Staccato,
}

impl PlayingMode {
    /// All modes in the order of the number keys 1–5.
    pub const ALL: [PlayingMode; 5] = [
        PlayingMode::Legato,
        PlayingMode::Tenuto,
        PlayingMode::Accent,
        PlayingMode::VerticalAccent,
        PlayingMode::Staccato,
    ];

    /// Lower-case name as used on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            PlayingMode::Legato => "legato",
            PlayingMode::Tenuto => "tenuto",
            PlayingMode::Accent => "accent",
            PlayingMode::VerticalAccent => "vertical accent",
            PlayingMode::Staccato => "staccato",
        }
    }
}

/// Grip of the sticks.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Grip {
    /// Thumbs up, palms facing each other: large vertical motion.
    French,
    /// Palms down: smaller vertical motion, more wrist.
    German,
}

/// How loud a beat is: a dynamic marking or an exact velocity in 0–1.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum Dynamic {
    Pp,
    P,
    Mp,
    Mf,
    F,
    Ff,
    /// A velocity in 0–1 (1 is MIDI velocity 127).
    Velocity(f64),
}

impl Dynamic {
    /// The markings from soft to loud with their MIDI velocities.
    pub const MARKS: [(Dynamic, u8, &'static str); 6] = [
        (Dynamic::Pp, 33, "pp"),
        (Dynamic::P, 49, "p"),
        (Dynamic::Mp, 64, "mp"),
        (Dynamic::Mf, 80, "mf"),
        (Dynamic::F, 96, "f"),
        (Dynamic::Ff, 112, "ff"),
    ];

    /// Velocity in 0–1.
    pub fn velocity(self) -> f64 {
        match self {
            Dynamic::Velocity(v) => v,
            mark => {
                let (_, midi, _) = Self::MARKS
                    .iter()
                    .find(|(m, _, _)| *m == mark)
                    .expect("every marking is in MARKS");
                f64::from(*midi) / 127.0
            }
        }
    }

    /// MIDI velocity 1–127.
    pub fn midi_velocity(self) -> u8 {
        (self.velocity() * 127.0).round().clamp(1.0, 127.0) as u8
    }

    /// The marking for a MIDI velocity if it is exactly a marking's, else a velocity.
    pub fn from_midi_velocity(velocity: u8) -> Dynamic {
        Self::MARKS
            .iter()
            .find(|(_, v, _)| *v == velocity)
            .map(|(m, _, _)| *m)
            .unwrap_or(Dynamic::Velocity(f64::from(velocity) / 127.0))
    }

    /// The nearest marking's name, e.g. "mf".
    pub fn nearest_mark(self) -> &'static str {
        let v = self.velocity() * 127.0;
        Self::MARKS
            .iter()
            .min_by(|a, b| {
                (f64::from(a.1) - v)
                    .abs()
                    .total_cmp(&(f64::from(b.1) - v).abs())
            })
            .map(|m| m.2)
            .expect("MARKS is not empty")
    }
}

/// Where the mallet strikes the head.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum ImpactLocation {
    /// The centre of the head (dull, short sound).
    Centre,
    /// The usual playing spot, a third of the radius in from the rim, toward the player.
    PlayingSpot,
    /// Just inside the rim, toward the player.
    Rim,
    /// Any point: radius as a fraction of the head radius (0 centre, 1 rim) and angle in
    /// degrees from the direction toward the player, counter-clockwise seen from above.
    Point { radius: f64, angle_deg: f64 },
}

impl ImpactLocation {
    /// Radius fraction of the playing spot.
    pub const PLAYING_SPOT_RADIUS: f64 = 2.0 / 3.0;
    /// Radius fraction of a rim stroke.
    pub const RIM_RADIUS: f64 = 0.92;

    /// (radius fraction, angle in degrees) on the head.
    pub fn polar(self) -> (f64, f64) {
        match self {
            ImpactLocation::Centre => (0.0, 0.0),
            ImpactLocation::PlayingSpot => (Self::PLAYING_SPOT_RADIUS, 0.0),
            ImpactLocation::Rim => (Self::RIM_RADIUS, 0.0),
            ImpactLocation::Point { radius, angle_deg } => (radius, angle_deg),
        }
    }

    /// Short name for display.
    pub fn name(self) -> String {
        match self {
            ImpactLocation::Centre => "centre".into(),
            ImpactLocation::PlayingSpot => "playing spot".into(),
            ImpactLocation::Rim => "rim".into(),
            ImpactLocation::Point { radius, angle_deg } => {
                format!("r {radius:.2} at {angle_deg:.0}°")
            }
        }
    }
}
