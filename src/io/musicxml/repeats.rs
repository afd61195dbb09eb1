//! The order in which a MusicXML part's measures are performed: repeat bar lines
//! (`<repeat direction="forward|backward" times="n">`, `times` counting every pass, 2 by
//! default) and volta endings (`<ending number="1, 2" type="start|stop|discontinue">`)
//! expanded, for [`super`], as music21 and MuseScore do: a backward repeat
//! returns to the forward repeat it closes, else to the start (so it encloses earlier
//! repeats, which play all their passes again); one inside an ending jumps back until
//! the highest ending number of its run of endings has been reached.
//!
//! Then one jump, as music21's `expandRepeats` follows it: at the end of the last pass
//! through a measure marked *da capo* or *dal segno* (`<sound dacapo="yes">`,
//! `<sound dalsegno="x">`, or the words "D.C.", "Da capo", "D.S.", "Dal segno"), the
//! music goes back to the start or to the measure with the segno (`<segno/>`,
//! `<sound segno="x">`) and is played once more without repeats (each run of endings by its
//! last ending), up to the end of a measure marked *fine* (`<sound fine>`, "Fine"), or
//! from a measure marked *to coda* (`<sound tocoda="x">`, "To Coda") on to the coda
//! (`<coda/>`, `<sound coda="x">`) and the end. Jump marks taken as measure-wide: a jump
//! happens at the end of its measure, a segno or coda marks its start.

use roxmltree::Node;

/// The most measures an expansion may play per written measure before it is taken for a
/// loop that does not end.
const MAX_PASSES_PER_MEASURE: usize = 64;

/// What a measure's bar lines say about repeats and endings.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
struct Bars {
    forward: bool,
    /// Passes of a backward repeat at the end (`times`), if one is written.
    backward: Option<Option<u32>>,
    /// The pass numbers of an ending starting here.
    ending_start: Option<Vec<u32>>,
    /// An ending stops (or is discontinued) here.
    ending_stop: bool,
}

/// An ending: its first and last measure (indices) and pass numbers.
#[derive(Clone, Debug, PartialEq, Eq)]
struct Ending {
    first: usize,
    last: usize,
    numbers: Vec<u32>,
}

/// The jump marks of one measure (labels as written, "" when unnamed).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
struct Jumps {
    da_capo: bool,
    dal_segno: Option<String>,
    segno: Option<String>,
    to_coda: Option<String>,
    coda: Option<String>,
    fine: bool,
}

/// The indices of `measures` in performed order, or `None` when the repeats never end
/// (more than [`MAX_PASSES_PER_MEASURE`] passes per measure), with what about the jumps
/// could not be followed.
pub(crate) fn performed_order(measures: &[Node]) -> Option<(Vec<usize>, Vec<String>)> {
    let bars: Vec<Bars> = measures.iter().map(|m| bars_of(*m)).collect();
    let jumps: Vec<Jumps> = measures.iter().map(|m| jumps_of(*m)).collect();
    let mut notes = Vec::new();
    let order = jump(&bars, &jumps, order(&bars)?, &mut notes);
    Some((order, notes))
}

fn jumps_of(measure: Node) -> Jumps {
    let mut j = Jumps::default();
    let label = |v: &str| v.trim().to_string();
    for n in measure.descendants().filter(Node::is_element) {
        match n.tag_name().name() {
            "sound" => {
                j.da_capo |= n.attribute("dacapo").is_some_and(|v| v.trim() == "yes");
                j.fine |= n.attribute("fine").is_some();
                for (attr, slot) in [
                    ("dalsegno", &mut j.dal_segno),
                    ("segno", &mut j.segno),
                    ("tocoda", &mut j.to_coda),
                    ("coda", &mut j.coda),
                ] {
                    if let Some(v) = n.attribute(attr) {
                        *slot = Some(label(v));
                    }
                }
            }
            "segno" if n.parent().is_some_and(|p| p.has_tag_name("direction-type")) => {
                j.segno.get_or_insert_with(String::new);
            }
            "coda" if n.parent().is_some_and(|p| p.has_tag_name("direction-type")) => {
                j.coda.get_or_insert_with(String::new);
            }
            "words" => words(n.text().unwrap_or(""), &mut j),
            _ => {}
        }
    }
    j
}

/// Whether `text` is a jump mark this module follows ("D.C. al Fine", "Fine", …).
pub(crate) fn is_jump_mark(text: &str) -> bool {
    let mut j = Jumps::default();
    words(text, &mut j);
    j != Jumps::default()
}

/// Jump marks written as words ("D.C. al Fine", "D.S. al Coda", "Fine", "To Coda").
fn words(text: &str, j: &mut Jumps) {
    let t = text.trim().to_lowercase();
    let compact: String = t.chars().filter(|c| !c.is_whitespace()).collect();
    if compact.starts_with("d.c.") || t.starts_with("da capo") {
        j.da_capo = true;
    } else if compact.starts_with("d.s.") || t.starts_with("dal segno") {
        j.dal_segno.get_or_insert_with(String::new);
    } else if t == "fine" {
        j.fine = true;
    } else if t.starts_with("to coda") {
        j.to_coda.get_or_insert_with(String::new);
    }
}

/// `order` (the measures with their repeats) with the first da capo or dal segno
/// followed (see the module's doc); what could not be followed goes into `notes`.
fn jump(bars: &[Bars], jumps: &[Jumps], order: Vec<usize>, notes: &mut Vec<String>) -> Vec<usize> {
    let Some(from) = jumps
        .iter()
        .position(|j| j.da_capo || j.dal_segno.is_some())
    else {
        return order;
    };
    let target = if jumps[from].da_capo {
        Some(0)
    } else {
        let wanted = jumps[from].dal_segno.as_deref().unwrap_or("");
        let segnos = || jumps.iter().enumerate().filter(|(_, j)| j.segno.is_some());
        segnos()
            .find(|(_, j)| j.segno.as_deref() == Some(wanted))
            .or_else(|| segnos().next())
            .map(|(i, _)| i)
    };
    let Some(target) = target else {
        notes.push(format!(
            "dal segno in measure {}: no segno to go back to; not followed",
            from + 1
        ));
        return order;
    };
    if jumps
        .iter()
        .skip(from + 1)
        .any(|j| j.da_capo || j.dal_segno.is_some())
    {
        notes.push("a second da capo or dal segno: only the first is followed".into());
    }
    // Up to the last pass through the jump's measure.
    let Some(last) = order.iter().rposition(|&i| i == from) else {
        return order;
    };
    let mut out = order[..=last].to_vec();
    let endings = endings(bars);
    let mut i = target;
    let mut coda_taken = false;
    while i < bars.len() {
        if let Some(e) = ending_at(&endings, i).filter(|&e| endings[e].first == i)
            && !endings[e].numbers.contains(&highest_pass(&endings, e))
        {
            i = endings[e].last + 1;
            continue;
        }
        out.push(i);
        if jumps[i].fine {
            return out;
        }
        if let (Some(wanted), false) = (&jumps[i].to_coda, coda_taken) {
            let codas = || (i + 1..bars.len()).filter(|&c| jumps[c].coda.is_some());
            match codas()
                .find(|&c| jumps[c].coda.as_ref() == Some(wanted))
                .or_else(|| codas().next())
            {
                Some(c) => {
                    coda_taken = true;
                    i = c;
                    continue;
                }
                None => notes.push(format!(
                    "to coda in measure {}: no coda after it; not followed",
                    i + 1
                )),
            }
        }
        i += 1;
    }
    out
}

fn bars_of(measure: Node) -> Bars {
    let mut bars = Bars::default();
    let elements = measure
        .children()
        .filter(|c| c.has_tag_name("barline"))
        .flat_map(|b| b.children().filter(Node::is_element));
    for e in elements {
        match (
            e.tag_name().name(),
            e.attribute("direction"),
            e.attribute("type"),
        ) {
            ("repeat", Some("forward"), _) => bars.forward = true,
            ("repeat", Some("backward"), _) => {
                bars.backward = Some(e.attribute("times").and_then(|t| t.trim().parse().ok()));
            }
            ("ending", _, Some("start")) => {
                bars.ending_start = Some(numbers(e.attribute("number").unwrap_or("1")));
            }
            ("ending", _, Some("stop" | "discontinue")) => bars.ending_stop = true,
            _ => {}
        }
    }
    bars
}

/// Pass numbers of an ending: "1", "1, 2", "1,2" or "1 2".
fn numbers(text: &str) -> Vec<u32> {
    text.split([',', ' '])
        .filter_map(|n| n.trim().parse().ok())
        .collect()
}

/// Each ending from its start to the first measure where it stops (at the latest the
/// measure before the next ending starts; itself if none).
fn endings(bars: &[Bars]) -> Vec<Ending> {
    let mut out = Vec::new();
    for (first, b) in bars.iter().enumerate() {
        let Some(numbers) = &b.ending_start else {
            continue;
        };
        let next_start = (first + 1..bars.len())
            .find(|&j| bars[j].ending_start.is_some())
            .unwrap_or(bars.len());
        let last = (first..next_start)
            .find(|&j| bars[j].ending_stop)
            .unwrap_or(first);
        out.push(Ending {
            first,
            last,
            numbers: numbers.clone(),
        });
    }
    out
}

/// The ending measure `i` lies in.
fn ending_at(endings: &[Ending], i: usize) -> Option<usize> {
    endings.iter().position(|e| e.first <= i && i <= e.last)
}

/// The highest pass number among the run of endings that follow each other around `e`.
fn highest_pass(endings: &[Ending], e: usize) -> u32 {
    let first = run_of(endings, e);
    let mut last = first;
    while last + 1 < endings.len() && endings[last].last + 1 == endings[last + 1].first {
        last += 1;
    }
    endings[first..=last]
        .iter()
        .flat_map(|x| x.numbers.iter().copied())
        .max()
        .unwrap_or(1)
}

/// Where each backward repeat returns to: the forward repeat it closes (the latest
/// forward repeat not yet closed), else the start of the piece, so a repeat without its
/// own forward sign encloses the repeats before it (they are nested).
fn targets(bars: &[Bars]) -> Vec<usize> {
    let mut open = Vec::new();
    let mut out = vec![0; bars.len()];
    for (i, b) in bars.iter().enumerate() {
        if b.forward {
            open.push(i);
        }
        if b.backward.is_some() {
            out[i] = open.pop().unwrap_or(0);
        }
    }
    out
}

/// Whose count of passes a backward repeat advances: its run of endings (by the run's
/// first ending), or its own measure.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Counter {
    Run(usize),
    Measure(usize),
}

/// The first ending of the run of endings that follow each other around `e`.
fn run_of(endings: &[Ending], e: usize) -> usize {
    let mut first = e;
    while first > 0 && endings[first - 1].last + 1 == endings[first].first {
        first -= 1;
    }
    first
}

/// The performed order of measures with these bar lines: each backward repeat returns
/// to its target until it has played `times` passes (then its count starts afresh, for
/// an enclosing repeat); an ending plays on the passes it names, counted by the backward
/// repeats of its run of endings.
fn order(bars: &[Bars]) -> Option<Vec<usize>> {
    let endings = endings(bars);
    let targets = targets(bars);
    let cap = MAX_PASSES_PER_MEASURE * bars.len() + 16;
    let mut jumps: std::collections::HashMap<Counter, u32> = Default::default();
    let mut out = Vec::new();
    let mut i = 0;
    while i < bars.len() {
        if out.len() > cap {
            return None;
        }
        let here = ending_at(&endings, i);
        if let Some(e) = here.filter(|&e| endings[e].first == i) {
            let pass = jumps.get(&Counter::Run(run_of(&endings, e))).unwrap_or(&0) + 1;
            if !endings[e].numbers.contains(&pass) {
                i = endings[e].last + 1;
                continue;
            }
        }
        out.push(i);
        if let Some(times) = bars[i].backward {
            let (counter, default) = match here {
                Some(e) => (Counter::Run(run_of(&endings, e)), highest_pass(&endings, e)),
                None => (Counter::Measure(i), 2),
            };
            let done = jumps.entry(counter).or_insert(0);
            if *done + 1 < times.unwrap_or(default) {
                *done += 1;
                i = targets[i];
                continue;
            }
            if counter == Counter::Measure(i) {
                *done = 0;
            }
        }
        i += 1;
        // Past the last ending of a run: the run's passes start afresh.
        for (e, ending) in endings.iter().enumerate() {
            if ending.last + 1 == i && endings.get(e + 1).is_none_or(|n| n.first != i) {
                jumps.remove(&Counter::Run(run_of(&endings, e)));
            }
        }
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bars(n: usize, edit: impl Fn(&mut [Bars])) -> Vec<Bars> {
        let mut b = vec![Bars::default(); n];
        edit(&mut b);
        b
    }

    /// |: 0 1 :| 2 plays 0 1 0 1 2; a backward repeat without a forward one returns to
    /// the start; times="3" plays three passes.
    #[test]
    fn simple_repeats() {
        let b = bars(3, |b| {
            b[0].forward = true;
            b[1].backward = Some(None);
        });
        assert_eq!(order(&b), Some(vec![0, 1, 0, 1, 2]));
        let b = bars(3, |b| b[1].backward = Some(Some(3)));
        assert_eq!(order(&b), Some(vec![0, 1, 0, 1, 0, 1, 2]));
        // A backward repeat without its own forward sign returns to the start: the
        // repeat before it is nested and plays both its passes again.
        let b = bars(4, |b| {
            b[1].forward = true;
            b[1].backward = Some(None);
            b[2].backward = Some(None);
        });
        assert_eq!(order(&b), Some(vec![0, 1, 1, 2, 0, 1, 1, 2, 3]));
    }

    /// 0 [1: 1 :|] [2: 2] 3.
    fn first_and_second_ending() -> Vec<Bars> {
        bars(4, |b| {
            b[1].ending_start = Some(vec![1]);
            b[1].ending_stop = true;
            b[1].backward = Some(None);
            b[2].ending_start = Some(vec![2]);
            b[2].ending_stop = true;
        })
    }

    /// 0 [1: 1 :|] [2: 2] 3 plays 0 1 0 2 3; a run of endings 1 … 3 with repeats in
    /// the first two plays each in turn; a repeat after the endings, without a forward
    /// sign, returns to the start and the endings play again from the first.
    #[test]
    fn endings() {
        let b = first_and_second_ending();
        assert_eq!(order(&b), Some(vec![0, 1, 0, 2, 3]));
        let b = bars(5, |b| {
            for (i, n) in [(1, 1), (2, 2), (3, 3)] {
                b[i].ending_start = Some(vec![n]);
                b[i].ending_stop = true;
            }
            b[1].backward = Some(None);
            b[2].backward = Some(None);
            b[4].backward = Some(None);
        });
        assert_eq!(
            order(&b),
            Some(vec![0, 1, 0, 2, 0, 3, 4, 0, 1, 0, 2, 0, 3, 4])
        );
        // "1, 2" shares an ending between two passes.
        assert_eq!(numbers("1, 2"), vec![1, 2]);
        assert_eq!(numbers("1,2 3"), vec![1, 2, 3]);
    }

    /// A repeat asking for absurdly many passes is refused rather than expanded.
    #[test]
    fn runaway_repeat() {
        let b = bars(1, |b| b[0].backward = Some(Some(1000)));
        assert_eq!(order(&b), None);
    }

    /// A dal segno with no segno, or a to coda with no coda after it, is reported and not
    /// followed; a D.C. with neither fine nor coda plays everything once more, its ending
    /// run by its last ending; words are recognised as jump marks.
    #[test]
    fn jumps_without_their_marks() {
        let plain = bars(3, |_| {});
        let mut notes = Vec::new();
        let mut jumps = vec![Jumps::default(); 3];
        jumps[2].dal_segno = Some(String::new());
        assert_eq!(
            jump(&plain, &jumps, vec![0, 1, 2], &mut notes),
            vec![0, 1, 2]
        );
        assert!(notes[0].contains("no segno"), "{notes:?}");
        let mut notes = Vec::new();
        let mut jumps = vec![Jumps::default(); 3];
        jumps[1].da_capo = true;
        jumps[0].to_coda = Some("x".into());
        assert_eq!(
            jump(&plain, &jumps, vec![0, 1, 2], &mut notes),
            vec![0, 1, 0, 1, 2]
        );
        assert!(notes[0].contains("no coda"), "{notes:?}");
        // 0 [1: 1 :|] [2: 2] 3(D.C.): after the jump only the second ending plays.
        let b = first_and_second_ending();
        let mut jumps = vec![Jumps::default(); 4];
        jumps[3].da_capo = true;
        let mut notes = Vec::new();
        let order = order(&b).unwrap();
        assert_eq!(
            jump(&b, &jumps, order, &mut notes),
            vec![0, 1, 0, 2, 3, 0, 2, 3]
        );
        assert!(notes.is_empty());
        assert!(is_jump_mark("D. C. al Fine") && is_jump_mark("Dal Segno") && is_jump_mark("Fine"));
        assert!(!is_jump_mark("dolce") && !is_jump_mark("finely"));
    }
}
