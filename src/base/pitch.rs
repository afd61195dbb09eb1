//! Musical pitch as a MIDI note number, written in files as a note name such as `"D3"`
//! or `"Bb2"` (scientific pitch notation, C4 = MIDI 60, A4 = 440 Hz, equal temperament).

use serde::{Deserialize, Deserializer, Serialize, Serializer};
use std::fmt;
use std::str::FromStr;

/// A pitch as a MIDI note number (0–127).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Pitch(pub u8);

/// Names of the twelve pitch classes as they are written back to files.
const NAMES: [&str; 12] = [
    "C", "C#", "D", "Eb", "E", "F", "F#", "G", "Ab", "A", "Bb", "B",
];

impl Pitch {
    /// Frequency in Hz under equal temperament with A4 = 440 Hz.
    pub fn hz(self) -> f64 {
        440.0 * 2f64.powf((f64::from(self.0) - 69.0) / 12.0)
    }

    /// The pitch `semitones` away, or `None` if it leaves the MIDI range.
    pub fn transposed(self, semitones: i32) -> Option<Pitch> {
        let n = i32::from(self.0) + semitones;
        u8::try_from(n).ok().filter(|&n| n <= 127).map(Pitch)
    }
}

impl fmt::Display for Pitch {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let octave = i32::from(self.0) / 12 - 1;
        write!(f, "{}{}", NAMES[usize::from(self.0 % 12)], octave)
    }
}

/// Why a note name could not be read.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "`{0}` is not a note name: expected a letter A–G, optional # or b, and an octave, e.g. \"D3\", \"F#2\", \"Bb2\" (MIDI 0–127)"
)]
pub struct PitchParseError(pub String);

impl FromStr for Pitch {
    type Err = PitchParseError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let err = || PitchParseError(s.to_string());
        let mut chars = s.trim().chars().peekable();
        let class = match chars.next().map(|c| c.to_ascii_uppercase()) {
            Some('C') => 0,
            Some('D') => 2,
            Some('E') => 4,
            Some('F') => 5,
            Some('G') => 7,
            Some('A') => 9,
            Some('B') => 11,
            _ => return Err(err()),
        };
        let mut accidental = 0i32;
        while let Some(&c) = chars.peek() {
            match c {
                '#' | '♯' => accidental += 1,
                'b' | '♭' => accidental -= 1,
                _ => break,
            }
            chars.next();
        }
        let octave: i32 = chars.collect::<String>().parse().map_err(|_| err())?;
        let midi = (octave + 1) * 12 + class + accidental;
        u8::try_from(midi)
            .ok()
            .filter(|&m| m <= 127)
            .map(Pitch)
            .ok_or_else(err)
    }
}

impl Serialize for Pitch {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(self)
    }
}

impl<'de> Deserialize<'de> for Pitch {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let text = String::deserialize(d)?;
        text.parse().map_err(serde::de::Error::custom)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Note names parse to the MIDI numbers of scientific pitch notation and print back.
    #[test]
    fn names_round_trip() {
        assert_eq!("C4".parse::<Pitch>().unwrap(), Pitch(60));
        assert_eq!("D2".parse::<Pitch>().unwrap(), Pitch(38));
        assert_eq!("Bb2".parse::<Pitch>().unwrap(), Pitch(46));
        assert_eq!("A#2".parse::<Pitch>().unwrap(), Pitch(46));
        assert_eq!("C-1".parse::<Pitch>().unwrap(), Pitch(0));
        for n in 0..=127u8 {
            let p = Pitch(n);
            assert_eq!(p.to_string().parse::<Pitch>().unwrap(), p);
        }
    }

    /// Malformed names and names outside MIDI 0–127 are rejected.
    #[test]
    fn rejects_bad_names() {
        for bad in ["", "H2", "D", "Dx3", "A9", "C-2", "3D"] {
            assert!(bad.parse::<Pitch>().is_err(), "{bad}");
        }
    }

    /// A4 is 440 Hz and an octave doubles the frequency.
    #[test]
    fn frequency() {
        assert!((Pitch(69).hz() - 440.0).abs() < 1e-9);
        assert!((Pitch(57).hz() - 220.0).abs() < 1e-9);
    }
}
