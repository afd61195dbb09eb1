//! A problem found while checking a kit or score: where it is and what is wrong.

use ron::error::Position;
use std::fmt;

/// One problem: `place` names where (e.g. "beat 3 (bar 2 beat 1)"), `message` says what,
/// `at` is where the place starts in the file's text (line and column), when the checked
/// thing was read from one.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Problem {
    pub place: String,
    pub message: String,
    pub at: Option<Position>,
}

impl Problem {
    pub fn new(place: impl Into<String>, message: impl Into<String>) -> Self {
        Problem {
            place: place.into(),
            message: message.into(),
            at: None,
        }
    }

    /// The same problem, its place starting at `at` in the file's text.
    pub fn at(self, at: Option<Position>) -> Self {
        Problem { at, ..self }
    }
}

impl fmt::Display for Problem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.place, self.message)
    }
}
