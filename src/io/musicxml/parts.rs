//! The parts of a MusicXML score: their names, instruments and notes as listed for the
//! user, and the one chosen as the timpani part (by `--part`, its instrument sound, its
//! General MIDI program or its name); the resolution its `<divisions>` need.

use super::*;
use crate::base::instrument_name::is_timpani_name;

/// A `<score-part>` of the part list.
#[derive(Clone, Debug)]
pub(super) struct PartInfo {
    pub(super) index: usize,
    pub(super) id: String,
    pub(super) name: String,
    pub(super) abbreviation: String,
    /// (instrument id, name, sound) of each `<score-instrument>`.
    pub(super) instruments: Vec<(String, String, String)>,
    /// MIDI programs (1–128) per instrument id ("" when the midi-instrument names none).
    pub(super) programs: Vec<(String, u32)>,
    /// Pitched notes in the part.
    pub(super) notes: usize,
}

impl PartInfo {
    pub(super) fn label(&self) -> String {
        match self.name.trim() {
            "" => format!("part {}", self.id),
            name => format!("part {} \"{}\"", self.id, name),
        }
    }
}

pub(super) fn text_of(node: Node, tag: &str) -> String {
    node.children()
        .find(|n| n.has_tag_name(tag))
        .and_then(|n| n.text())
        .unwrap_or("")
        .trim()
        .to_string()
}

pub(super) fn part_list(root: Node) -> Vec<PartInfo> {
    let part_nodes: Vec<Node> = root.children().filter(|n| n.has_tag_name("part")).collect();
    let list = root.children().find(|n| n.has_tag_name("part-list"));
    let score_parts: Vec<Node> = list
        .map(|l| {
            l.children()
                .filter(|n| n.has_tag_name("score-part"))
                .collect()
        })
        .unwrap_or_default();
    let count = score_parts.len().max(part_nodes.len());
    (0..count)
        .map(|index| {
            let sp = score_parts.get(index);
            let id = sp
                .and_then(|n| n.attribute("id"))
                .or_else(|| part_nodes.get(index).and_then(|n| n.attribute("id")))
                .unwrap_or("")
                .to_string();
            let part = part_nodes
                .iter()
                .find(|n| n.attribute("id") == Some(id.as_str()) && !id.is_empty())
                .or(part_nodes.get(index));
            let notes = part.map_or(0, |p| {
                p.descendants()
                    .filter(|n| n.has_tag_name("note"))
                    .filter(|n| {
                        n.children()
                            .any(|c| c.has_tag_name("pitch") || c.has_tag_name("unpitched"))
                    })
                    .count()
            });
            let instruments = sp.map_or_else(Vec::new, |sp| {
                sp.children()
                    .filter(|n| n.has_tag_name("score-instrument"))
                    .map(|n| {
                        (
                            n.attribute("id").unwrap_or("").to_string(),
                            text_of(n, "instrument-name"),
                            text_of(n, "instrument-sound"),
                        )
                    })
                    .collect()
            });
            let programs = sp.map_or_else(Vec::new, |sp| {
                sp.children()
                    .filter(|n| n.has_tag_name("midi-instrument"))
                    .filter_map(|n| {
                        let p = text_of(n, "midi-program").parse().ok()?;
                        Some((n.attribute("id").unwrap_or("").to_string(), p))
                    })
                    .collect()
            });
            PartInfo {
                index,
                id,
                name: sp.map(|n| text_of(*n, "part-name")).unwrap_or_default(),
                abbreviation: sp
                    .map(|n| text_of(*n, "part-abbreviation"))
                    .unwrap_or_default(),
                instruments,
                programs,
                notes,
            }
        })
        .collect()
}

/// One line per part: id, name, instruments, notes.
pub(super) fn part_listing(parts: &[PartInfo]) -> String {
    let mut out = String::new();
    for p in parts {
        let _ = write!(out, "  {}", p.label());
        let sounds: Vec<String> = p
            .instruments
            .iter()
            .map(|(_, name, sound)| match (name.as_str(), sound.as_str()) {
                (n, "") => n.to_string(),
                (n, s) => format!("{n} [{s}]"),
            })
            .filter(|s| !s.is_empty())
            .collect();
        if !sounds.is_empty() {
            let _ = write!(out, " ({})", sounds.join(", "));
        }
        let _ = writeln!(out, ": {} notes", p.notes);
    }
    out.pop();
    out
}

/// A way to recognise the timpani part: (the instrument id if one matched, why).
pub(super) type Rule = dyn Fn(&PartInfo) -> Option<(String, String)>;

/// Choose the part and say which and why.
pub(super) fn choose(
    path: &Path,
    parts: &[PartInfo],
    options: &ImportOptions,
) -> Result<(String, usize, Option<String>), MusicXmlError> {
    if parts.is_empty() {
        return Err(MusicXmlError::NoParts {
            path: path.to_path_buf(),
        });
    }
    if let Some(want) = &options.part {
        let lower = want.to_lowercase();
        let found = parts.iter().position(|p| p.id == *want).or_else(|| {
            parts.iter().position(|p| {
                p.name.to_lowercase().contains(&lower) || p.abbreviation.to_lowercase() == lower
            })
        });
        return match found {
            Some(i) => Ok((
                format!("{} (chosen with --part \"{want}\")", parts[i].label()),
                i,
                None,
            )),
            None => Err(MusicXmlError::PartNotFound {
                path: path.to_path_buf(),
                part: want.clone(),
                parts: part_listing(parts),
            }),
        };
    }
    let by_sound = |p: &PartInfo| {
        p.instruments
            .iter()
            .find(|(_, _, s)| s.starts_with("drum.timpani"))
            .map(|(id, _, s)| (id.clone(), format!("instrument sound {s}")))
            .or_else(|| {
                p.programs
                    .iter()
                    .find(|(_, prog)| *prog == GM_TIMPANI_1)
                    .map(|(id, _)| (id.clone(), "MIDI program 48 \"Timpani\"".to_string()))
            })
    };
    let by_name = |p: &PartInfo| {
        let named = [p.name.as_str(), p.abbreviation.as_str()]
            .into_iter()
            .chain(p.instruments.iter().map(|(_, n, _)| n.as_str()))
            .find(|n| is_timpani_name(n))?;
        Some((String::new(), format!("named \"{named}\"")))
    };
    let rules: [&Rule; 2] = [&by_sound, &by_name];
    for rule in rules {
        let candidates: Vec<(usize, String, String)> = parts
            .iter()
            .filter(|p| p.notes > 0)
            .filter_map(|p| rule(p).map(|(inst, why)| (p.index, inst, why)))
            .collect();
        let Some(best) = candidates
            .iter()
            .max_by_key(|(i, _, _)| (parts[*i].notes, std::cmp::Reverse(*i)))
        else {
            continue;
        };
        let (i, inst, why) = best.clone();
        let instrument = (parts[i].instruments.len() > 1 && !inst.is_empty()).then_some(inst);
        let mut text = format!("{}: {why}; {} notes", parts[i].label(), parts[i].notes);
        if candidates.len() > 1 {
            let _ = write!(text, ", the most of {} candidates", candidates.len());
        }
        return Ok((text, i, instrument));
    }
    // A timpani part with nothing to play is said as such, not as no timpani part.
    if let Some(p) = parts
        .iter()
        .find(|p| rules.iter().any(|rule| rule(p).is_some()))
    {
        return Err(MusicXmlError::TimpaniWithoutNotes {
            path: path.to_path_buf(),
            part: p.label(),
        });
    }
    Err(MusicXmlError::NoTimpani {
        path: path.to_path_buf(),
        parts: part_listing(parts),
    })
}

/// Ticks per quarter: the least common multiple of 960 and the part's divisions (when it
/// stays at most [`MAX_TICKS_PER_QUARTER`]; else 960, and durations are rounded).
pub(super) fn ticks_per_quarter(part: Node, notices: &mut Notices) -> u64 {
    let mut tpq = BASE_TICKS_PER_QUARTER;
    for d in part.descendants().filter(|n| n.has_tag_name("divisions")) {
        let Some(div) = d
            .text()
            .and_then(|t| t.trim().parse::<f64>().ok())
            .filter(|v| *v >= 1.0 && v.fract() == 0.0 && *v < 1e9)
        else {
            continue;
        };
        let div = div as u64;
        let lcm = tpq / gcd(tpq, div) * div;
        if lcm <= MAX_TICKS_PER_QUARTER {
            tpq = lcm;
        } else {
            notices.add(
                format!("{div} divisions per quarter cannot be held exactly; durations rounded to 1/{tpq} quarter"),
                "the part",
            );
        }
    }
    tpq
}

pub(super) fn gcd(a: u64, b: u64) -> u64 {
    if b == 0 { a } else { gcd(b, a % b) }
}
