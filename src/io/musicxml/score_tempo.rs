//! Tempo marks — `<sound tempo>` and `<metronome>` — and where they are in the score.
//! Tempo is the whole score's, and scores usually write it only in their top part
//! (music21, MuseScore, Finale and Sibelius do), so the marks of every other part are
//! read too: each kept by its written measure and its offset there in quarter notes, then
//! placed in the chosen part's performed order by [`super::reader`] (every pass through a
//! repeated measure gets it). [`super::timing`] merges them with the part's own marks.

use super::*;

/// A tempo mark at a score tick.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct TempoMark {
    pub(super) tick: u64,
    /// Quarter notes per minute.
    pub(super) bpm: f64,
    /// From `<sound tempo>` (what is played), not a metronome mark.
    pub(super) sound: bool,
    /// Where it is written when that is another part ("part P1 \"Violin\", measure 3");
    /// `None`: in the chosen part.
    pub(super) other_part: Option<String>,
}

impl TempoMark {
    /// Which of two marks at one tick is played: the chosen part's over another part's,
    /// then `<sound tempo>` over a metronome mark (the greater wins).
    pub(super) fn precedence(&self) -> (bool, bool) {
        (self.other_part.is_none(), self.sound)
    }
}

/// A mark of another part within its written measure.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct WrittenTempo {
    /// Quarter notes from the start of the measure.
    pub(super) quarters: f64,
    pub(super) bpm: f64,
    pub(super) sound: bool,
    pub(super) place: String,
}

/// The tempo of a `<sound>`: `None` without a tempo attribute, `Err` with its text when
/// it is no tempo.
pub(super) fn sound_bpm(s: Node) -> Option<Result<f64, String>> {
    let tempo = s.attribute("tempo")?;
    Some(
        tempo
            .trim()
            .parse::<f64>()
            .ok()
            .filter(|t| t.is_finite() && *t > 0.0)
            .ok_or_else(|| tempo.to_string()),
    )
}

/// Whether a `<direction>` has a `<sound tempo>`, which is what is played over a
/// metronome mark beside it.
pub(super) fn has_sound_tempo(direction: Node) -> bool {
    direction
        .children()
        .any(|c| c.has_tag_name("sound") && c.attribute("tempo").is_some())
}

/// The tempo marks of every part but `chosen`, by written measure (index from 0).
pub(super) fn other_parts(root: Node, chosen: Node, parts: &[PartInfo]) -> Vec<Vec<WrittenTempo>> {
    let mut by_measure: Vec<Vec<WrittenTempo>> = Vec::new();
    let part_nodes = root.children().filter(|n| n.has_tag_name("part"));
    for (index, part) in part_nodes.enumerate().filter(|(_, p)| *p != chosen) {
        let label = parts
            .iter()
            .find(|p| Some(p.id.as_str()) == part.attribute("id"))
            .or(parts.get(index))
            .map_or_else(|| format!("part {}", index + 1), PartInfo::label);
        let mut divisions = 1.0;
        let measures = part.children().filter(|n| n.has_tag_name("measure"));
        for (i, m) in measures.enumerate() {
            let place = format!("{label}, measure {}", m.attribute("number").unwrap_or("?"));
            let marks = measure_marks(m, &mut divisions, &place);
            if !marks.is_empty() {
                by_measure.resize(by_measure.len().max(i + 1), Vec::new());
                by_measure[i].extend(marks);
            }
        }
    }
    by_measure
}

/// The tempo marks of one measure, with the time read as the part reader reads it
/// (notes, chords, grace notes, `<backup>`, `<forward>`, `<offset>`), leniently: a value
/// that is no number counts as 0 (the chosen part's reader reports such values).
fn measure_marks(m: Node, divisions: &mut f64, place: &str) -> Vec<WrittenTempo> {
    let number = |n: Node, tag: &str| -> f64 {
        let value = text_of(n, tag).parse::<f64>().unwrap_or(0.0);
        if value.is_finite() { value } else { 0.0 }
    };
    let mut marks = Vec::new();
    let mut pos = 0.0f64;
    for el in m.children().filter(Node::is_element) {
        let at = |offset: f64| (pos + offset).max(0.0) / *divisions;
        match el.tag_name().name() {
            "attributes" => {
                let d = number(el, "divisions");
                if d > 0.0 {
                    *divisions = d;
                }
            }
            "note" => {
                let chord = el.children().any(|c| c.has_tag_name("chord"));
                let grace = el.children().any(|c| c.has_tag_name("grace"));
                if !chord && !grace {
                    pos += number(el, "duration").max(0.0);
                }
            }
            "backup" => pos = (pos - number(el, "duration")).max(0.0),
            "forward" => pos += number(el, "duration").max(0.0),
            "direction" => {
                let quarters = at(number(el, "offset"));
                let sounds = el.children().filter(|c| c.has_tag_name("sound"));
                let played = sounds.filter_map(|s| sound_bpm(s)?.ok());
                let mut found: Vec<(f64, bool)> = played.map(|bpm| (bpm, true)).collect();
                if !has_sound_tempo(el) {
                    let metronomes = el
                        .children()
                        .filter(|c| c.has_tag_name("direction-type"))
                        .flat_map(|t| t.children())
                        .filter(|c| c.has_tag_name("metronome"));
                    found.extend(metronomes.filter_map(metronome_bpm).map(|bpm| (bpm, false)));
                }
                marks.extend(found.into_iter().map(|(bpm, sound)| WrittenTempo {
                    quarters,
                    bpm,
                    sound,
                    place: place.to_string(),
                }));
            }
            "sound" => {
                if let Some(Ok(bpm)) = sound_bpm(el) {
                    marks.push(WrittenTempo {
                        quarters: at(number(el, "offset")),
                        bpm,
                        sound: true,
                        place: place.to_string(),
                    });
                }
            }
            _ => {}
        }
    }
    marks
}

/// Quarter notes per minute of a `<metronome>` "beat-unit [dots] = per-minute".
pub(super) fn metronome_bpm(m: Node) -> Option<f64> {
    let units: Vec<Node> = m
        .children()
        .filter(|c| c.has_tag_name("beat-unit"))
        .collect();
    let [unit] = units[..] else { return None };
    let quarters = match unit.text()?.trim() {
        "maxima" => 32.0,
        "long" => 16.0,
        "breve" => 8.0,
        "whole" => 4.0,
        "half" => 2.0,
        "quarter" => 1.0,
        "eighth" => 0.5,
        "16th" => 0.25,
        "32nd" => 0.125,
        "64th" => 0.0625,
        _ => return None,
    };
    let dots = m
        .children()
        .filter(|c| c.has_tag_name("beat-unit-dot"))
        .count();
    let dotted = quarters * (2.0 - 0.5f64.powi(i32::try_from(dots).ok()?));
    let text = text_of(m, "per-minute");
    // "120", "c. 120", "120-132": the first number.
    let start = text.find(|c: char| c.is_ascii_digit())?;
    let rest = &text[start..];
    let end = rest
        .find(|c: char| !(c.is_ascii_digit() || c == '.'))
        .unwrap_or(rest.len());
    let per_minute: f64 = rest[..end].trim_end_matches('.').parse().ok()?;
    (per_minute > 0.0).then_some(per_minute * dotted)
}
