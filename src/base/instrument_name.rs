//! The names scores give the timpani part, in the languages orchestral scores are written
//! in: one test that the MIDI import (track and instrument names) and the MusicXML import
//! (part, abbreviation and instrument names) share, so both recognise the same parts.

/// Words that name the timpani on their own (lower case): Italian, English, German,
/// French/Spanish, with the usual abbreviations ("Timp.", "Tymp.", "Pk.", "Pkn.").
const WORDS: &[&str] = &[
    "timpani",
    "timpano",
    "timpanos",
    "timp",
    "timps",
    "tympani",
    "tympano",
    "tymp",
    "kettledrum",
    "kettledrums",
    "pauke",
    "pauken",
    "kesselpauke",
    "kesselpauken",
    "pk",
    "pkn",
    "timbales",
    "timbale",
    "timbal",
    "ティンパニ",
];

/// What the names of a timpani part are, for messages.
pub const TIMPANI_NAMES: &str =
    "\"Timpani\", \"Timp.\", \"Tympani\", \"Kettledrums\", \"Pauken\", \"Pk.\" or \"Timbales\"";

/// Whether `name` names a timpani part: one of its words (split at anything not a letter
/// or digit, trailing digits ignored: "Timp.1", "Timpani II") is a name of the timpani, or
/// two of them are "kettle drum(s)". Whole words only: "Paukenschlag Violin" is no
/// timpani part.
pub fn is_timpani_name(name: &str) -> bool {
    let lower = name.to_lowercase();
    let words: Vec<&str> = lower
        .split(|c: char| !c.is_alphanumeric())
        .map(|w| w.trim_end_matches(|c: char| c.is_ascii_digit()))
        .filter(|w| !w.is_empty())
        .collect();
    words.iter().any(|w| WORDS.contains(w))
        || words
            .windows(2)
            .any(|p| p[0] == "kettle" && matches!(p[1], "drum" | "drums"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn timpani_names_in_every_language_and_no_substrings() {
        for yes in [
            "Timpani",
            "Timp.",
            "Timp.1",
            "Timpani II",
            "Tympani",
            "Tymp.",
            "Kettledrums",
            "Kettle Drums",
            "Kettle-drum",
            "Pauken",
            "Pauke",
            "Kesselpauken",
            "Pk.",
            "Pkn.",
            "Timbales",
            "4 Timpani (C-G)",
            "ティンパニ",
        ] {
            assert!(is_timpani_name(yes), "{yes}");
        }
        for no in [
            "Paukenschlag Violin",
            "Violin",
            "Timpanist's notes",
            "Kettle",
            "Drums",
            "Pkw",
            "",
            "Tempo",
        ] {
            assert!(!is_timpani_name(no), "{no}");
        }
    }
}
