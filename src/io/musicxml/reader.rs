//! Reading the chosen part, measure by measure in performed order: its sounding notes
//! (ties joined, grace and cue notes left out), tremolos and trills as rolls (a trill's
//! wavy line ending it), articulations as playing modes, dynamics and hairpins, hands,
//! damping, tempo marks and measure lengths, with everything read but not performed
//! reported.

use super::*;

/// A sounding note (ties joined), in score ticks.
#[derive(Clone, Debug)]
pub(super) struct XNote {
    pub(super) tick: u64,
    pub(super) end: u64,
    pub(super) pitch: u8,
    pub(super) mode: PlayingMode,
    /// The sticking written as `<other-technical>` "R" or "L".
    pub(super) hand: Hand,
    /// Strokes per quarter of a tremolo; the roll's length is the note's.
    pub(super) strokes: Option<u32>,
    /// The end of the last tied note that carries the tremolo (a damped roll's tremolo
    /// may stop before its tied notes do), or that a trill's wavy line reaches.
    pub(super) roll_end: u64,
    /// A trill mark, read as a roll.
    pub(super) trill: Option<Trill>,
    /// Marked `<stopped/>`: the hand damps the head when the (tied) note ends.
    pub(super) damped: bool,
    /// Half of a two-note tremolo.
    pub(super) two_note: Option<TwoNote>,
    pub(super) roll: Option<Roll>,
    /// The drum a `<?timpanist drum="N"?>` processing instruction in the note names (what
    /// timpanist's own export writes; other programs leave it alone).
    pub(super) drum: Option<usize>,
    /// Ticks from the last stroke to the damping touch.
    pub(super) damp: Option<u64>,
}

/// How far a trill's roll reaches over the notes tied to its note.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Trill {
    /// Over every tied note: no wavy line, or one not stopped yet.
    Tied,
    /// Its wavy line stopped: to `roll_end`, the end of the note it stopped on.
    Stopped,
}

/// A trill's wavy line waiting for its stop.
pub(super) struct TrillLine {
    /// The line's `number` ("1" when there is none).
    number: String,
    /// The trilled note (an index into the notes read).
    trilled: usize,
    /// The last note under it so far, rolled: the trilled note, then each new note of its
    /// voice under the line.
    last: usize,
    /// The new notes rolled because they are under the line.
    under: Vec<usize>,
    /// The trilled note's `<voice>` ("1" when there is none).
    voice: String,
    /// Where it starts ("measure 3").
    place: String,
}

/// What a written note is to the sounding notes, for its wavy lines.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Written {
    /// A grace note: no time, no sounding note.
    Grace,
    /// A later note of a tie, lengthening the sounding note at this index.
    Tied(usize),
    /// A new sounding note at this index, with a trill mark or not.
    New(usize, bool),
}

/// A note's part in a two-note tremolo.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum TwoNote {
    /// The first note; strokes per quarter of the alternation.
    Start(u32),
    Stop,
}

/// What a note's notations say about how it is played.
pub(super) struct NoteMarks {
    pub(super) mode: PlayingMode,
    pub(super) strokes: Option<u32>,
    pub(super) hand: Hand,
    pub(super) damped: bool,
    pub(super) two_note: Option<TwoNote>,
    /// A `<trill-mark>`: a roll at the unmeasured tremolo's rate unless a tremolo says.
    pub(super) trill: bool,
}

/// A measure as read: where it starts, how long it is, its written time signature.
#[derive(Clone, Debug)]
pub(super) struct Measure {
    pub(super) length: u64,
    pub(super) signature: Option<(u32, u32)>,
    pub(super) number: String,
    pub(super) implicit: bool,
}

/// A dynamic instruction at a tick.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum DynEvent {
    /// A new level (MIDI velocity).
    Level(f64),
    /// One stroke at this velocity (accented for sf, sfz, fz…), then the level `then`
    /// (or back to the level before).
    Single {
        vel: f64,
        then: Option<f64>,
        accent: bool,
    },
    /// A hairpin starts (true: crescendo) with this number.
    Wedge { up: bool, number: u32 },
    /// The hairpin with this number ends.
    WedgeStop { number: u32 },
}

pub(super) struct PartReader<'a, 'd> {
    pub(super) path: &'a Path,
    pub(super) doc: &'a Document<'d>,
    pub(super) tpq: u64,
    /// Only notes of this instrument (a part with several).
    pub(super) instrument: Option<String>,
    pub(super) divisions: f64,
    /// Whether the part has said its `<divisions>` yet (before it does, 1 is assumed,
    /// and the first duration read so says).
    divisions_given: bool,
    /// Sounding pitch minus written pitch, semitones.
    pub(super) transpose: i32,
    pub(super) notes: Vec<XNote>,
    pub(super) measures: Vec<Measure>,
    /// The part's own tempo marks and, placed on its measures, the other parts'.
    pub(super) tempos: Vec<TempoMark>,
    /// The other parts' tempo marks by written measure ([`score_tempo::other_parts`]).
    pub(super) score_tempos: Vec<Vec<WrittenTempo>>,
    pub(super) dynamics: Vec<(u64, DynEvent)>,
    pub(super) notices: Notices,
    /// Open ties: (pitch, note index).
    pub(super) ties: Vec<(u8, usize)>,
    /// Trills' wavy lines not stopped yet.
    pub(super) trill_lines: Vec<TrillLine>,
    pub(super) rounded: bool,
    /// The time signature in force.
    pub(super) signature: Option<(u32, u32)>,
}

/// Velocities of the dynamic levels, softest to loudest.
pub(super) const LEVELS: [(&str, f64); 12] = [
    ("pppppp", 3.0),
    ("ppppp", 6.0),
    ("pppp", 10.0),
    ("ppp", 16.0),
    ("pp", 33.0),
    ("p", 49.0),
    ("mp", 64.0),
    ("mf", 80.0),
    ("f", 96.0),
    ("ff", 112.0),
    ("fff", 120.0),
    ("ffff", 127.0),
];

pub(super) fn level(name: &str) -> Option<f64> {
    match name {
        "fffff" | "ffffff" => Some(127.0),
        _ => LEVELS.iter().find(|(n, _)| *n == name).map(|(_, v)| *v),
    }
}

/// Elements that only concern how the page looks or analyses the music: read silently.
pub(super) const PAGE_ONLY: &[&str] = &[
    "print",
    "key",
    "clef",
    "staves",
    "staff-details",
    "part-symbol",
    "instruments",
    "measure-style",
    "footnote",
    "level",
    "harmony",
    "figured-bass",
    "bookmark",
    "link",
    "grouping",
    "listening",
    "for-part",
];

impl<'a, 'd> PartReader<'a, 'd> {
    pub(super) fn new(
        path: &'a Path,
        doc: &'a Document<'d>,
        tpq: u64,
        instrument: Option<String>,
    ) -> Self {
        PartReader {
            path,
            doc,
            tpq,
            instrument,
            divisions: 1.0,
            divisions_given: false,
            transpose: 0,
            notes: Vec::new(),
            measures: Vec::new(),
            tempos: Vec::new(),
            score_tempos: Vec::new(),
            dynamics: Vec::new(),
            notices: Notices::default(),
            ties: Vec::new(),
            trill_lines: Vec::new(),
            rounded: false,
            signature: None,
        }
    }

    fn line(&self, node: Node) -> u32 {
        self.doc.text_pos_at(node.range().start).row
    }

    fn invalid(&self, node: Node, measure: &str, message: String) -> MusicXmlError {
        MusicXmlError::Invalid {
            path: self.path.to_path_buf(),
            line: self.line(node),
            measure: measure.to_string(),
            message,
        }
    }

    /// A duration element's value in ticks.
    fn ticks(&mut self, node: Node, measure: &str) -> Result<u64, MusicXmlError> {
        let text = node.text().unwrap_or("").trim();
        let value: f64 = text
            .parse()
            .ok()
            .filter(|v: &f64| v.is_finite() && *v >= 0.0 && *v < 1e12)
            .ok_or_else(|| {
                self.invalid(
                    node,
                    measure,
                    format!(
                        "<{}> \"{text}\" is not a duration (a number of divisions ≥ 0)",
                        node.tag_name().name()
                    ),
                )
            })?;
        if !self.divisions_given && value > 0.0 {
            // Said once: every later duration is read at the same assumed resolution.
            self.divisions_given = true;
            self.notices.add(
                "a duration before any <divisions>: read at 1 division per quarter (if the \
                 durations come out too long, the file lacks its <divisions>)",
                &format!("measure {measure}"),
            );
        }
        let exact = value * self.tpq as f64 / self.divisions;
        if exact > 1e12 {
            return Err(self.invalid(
                node,
                measure,
                format!(
                    "<{}> {text} at {} divisions per quarter is longer than a score can hold",
                    node.tag_name().name(),
                    self.divisions
                ),
            ));
        }
        let ticks = exact.round();
        if (ticks - exact).abs() > 1e-6 && !self.rounded {
            self.rounded = true;
            self.notices.add(
                "a duration is not a whole number of score ticks; rounded",
                &format!("measure {measure}"),
            );
        }
        Ok(ticks as u64)
    }

    pub(super) fn read(&mut self, part: Node) -> Result<(), MusicXmlError> {
        let written: Vec<Node> = part
            .children()
            .filter(|n| n.has_tag_name("measure"))
            .collect();
        let order = match repeats::performed_order(&written) {
            Some((order, notes)) => {
                for note in notes {
                    self.notices.push_text(note);
                }
                order
            }
            None => {
                self.notices.push_text(
                    "the repeats and endings do not resolve into an order of measures; the music is played once, as written".into(),
                );
                (0..written.len()).collect()
            }
        };
        if order.len() != written.len() {
            self.notices.push_text(format!(
                "repeats expanded: the {} written measures are played as {}",
                written.len(),
                order.len()
            ));
        }
        for i in order {
            let m = written[i];
            let number = m.attribute("number").unwrap_or("?").to_string();
            let start = self.measures.iter().map(|m| m.length).sum::<u64>();
            let length = self.read_measure(m, start, &number)?;
            let nominal = self
                .signature
                .map(|(n, d)| u64::from(n) * 4 * self.tpq / u64::from(d));
            // A measure with nothing in it lasts its time signature.
            let length = if length == 0 {
                nominal.unwrap_or(0)
            } else {
                length
            };
            // Other parts' marks, none later than the end of this measure.
            for t in self.score_tempos.get(i).into_iter().flatten() {
                let offset = (t.quarters * self.tpq as f64)
                    .round()
                    .clamp(0.0, length as f64);
                self.tempos.push(TempoMark {
                    tick: start + offset as u64,
                    bpm: t.bpm,
                    sound: t.sound,
                    other_part: Some(t.place.clone()),
                });
            }
            self.measures.push(Measure {
                length,
                signature: self.signature,
                number,
                implicit: m.attribute("implicit") == Some("yes"),
            });
        }
        for line in std::mem::take(&mut self.trill_lines) {
            for &j in &line.under {
                self.unroll(j);
            }
            self.notices.add(
                "a trill's wavy line never stops: the roll ends with the notes tied to its trilled note",
                &line.place,
            );
        }
        self.notes = two_note_tremolos(std::mem::take(&mut self.notes), self.tpq);
        let max_damp = crate::score::validate::MAX_DAMP_QUARTERS * self.tpq;
        for n in &mut self.notes {
            // A damped roll's tremolo may stop before its tied notes do, a trill where
            // its wavy line stops.
            let roll_end = if n.damped || n.trill.is_some() {
                n.roll_end
            } else {
                n.end
            };
            n.roll = n.strokes.and_then(|spq| {
                (roll_end > n.tick).then_some(Roll {
                    length_ticks: roll_end - n.tick,
                    strokes_per_quarter: spq,
                })
            });
            let last_stroke = n.tick + n.roll.map_or(0, |r| r.length_ticks);
            n.damp = n
                .damped
                .then(|| n.end.saturating_sub(last_stroke).clamp(1, max_damp));
        }
        Ok(())
    }

    /// Read one measure starting at score tick `start`; returns its length in ticks.
    fn read_measure(&mut self, m: Node, start: u64, number: &str) -> Result<u64, MusicXmlError> {
        let place = format!("measure {number}");
        let mut pos: i64 = 0;
        let mut longest: i64 = 0;
        let mut last_start: i64 = 0;
        for el in m.children().filter(Node::is_element) {
            let at = |p: i64| start.saturating_add_signed(p.max(-(start as i64)));
            match el.tag_name().name() {
                "attributes" => self.attributes(el, number)?,
                "note" => {
                    let chord = el.children().any(|c| c.has_tag_name("chord"));
                    let grace = el.children().any(|c| c.has_tag_name("grace"));
                    let duration = match el.children().find(|c| c.has_tag_name("duration")) {
                        Some(d) => self.ticks(d, number)? as i64,
                        None => 0,
                    };
                    let note_start = if chord { last_start } else { pos };
                    if grace {
                        self.notices
                            .add("grace note: skipped (grace notes take no time)", &place);
                        // A trill's wavy line may stop on a grace note after it.
                        self.wavy_lines(el, at(note_start), Written::Grace, &place);
                        continue;
                    }
                    if !chord {
                        last_start = pos;
                        pos += duration;
                        longest = longest.max(pos);
                    }
                    self.note(el, at(note_start), duration as u64, number)?;
                }
                "backup" => {
                    let d = el.children().find(|c| c.has_tag_name("duration"));
                    let d = match d {
                        Some(d) => self.ticks(d, number)? as i64,
                        None => 0,
                    };
                    pos -= d;
                    if pos < 0 {
                        self.notices.add(
                            "<backup> goes back past the start of its measure; clamped",
                            &place,
                        );
                        pos = 0;
                    }
                }
                "forward" => {
                    let d = el.children().find(|c| c.has_tag_name("duration"));
                    if let Some(d) = d {
                        pos += self.ticks(d, number)? as i64;
                        longest = longest.max(pos);
                    }
                }
                "direction" => {
                    let offset = match el.children().find(|c| c.has_tag_name("offset")) {
                        Some(o) => self.signed_ticks(o, number)?,
                        None => 0,
                    };
                    self.direction(el, at(pos + offset), number);
                }
                "sound" => {
                    let offset = match el.children().find(|c| c.has_tag_name("offset")) {
                        Some(o) => self.signed_ticks(o, number)?,
                        None => 0,
                    };
                    self.sound(el, at(pos + offset), number);
                }
                "barline" => self.barline(el, number),
                name if PAGE_ONLY.contains(&name) => {}
                other => self.notices.add(format!("<{other}>: not read"), &place),
            }
        }
        Ok(longest.max(0) as u64)
    }

    /// An `<offset>` (may be negative) in ticks.
    fn signed_ticks(&mut self, node: Node, measure: &str) -> Result<i64, MusicXmlError> {
        let text = node.text().unwrap_or("").trim();
        let negative = text.starts_with('-');
        let value: f64 = text.trim_start_matches('-').parse().map_err(|_| {
            self.invalid(
                node,
                measure,
                format!("<offset> \"{text}\" is not a number of divisions"),
            )
        })?;
        let ticks = (value * self.tpq as f64 / self.divisions).round() as i64;
        Ok(if negative { -ticks } else { ticks })
    }

    fn attributes(&mut self, el: Node, number: &str) -> Result<(), MusicXmlError> {
        let place = format!("measure {number}");
        for a in el.children().filter(Node::is_element) {
            match a.tag_name().name() {
                "divisions" => {
                    self.divisions_given = true;
                    let text = a.text().unwrap_or("").trim();
                    self.divisions = text
                        .parse::<f64>()
                        .ok()
                        .filter(|d| d.is_finite() && *d > 0.0)
                        .ok_or_else(|| {
                            self.invalid(
                                a,
                                number,
                                format!("<divisions> \"{text}\" is not a positive number"),
                            )
                        })?;
                }
                "time" => self.time(a, &place),
                "transpose" => {
                    let chromatic: i32 = text_of(a, "chromatic").parse().unwrap_or(0);
                    let octaves: i32 = text_of(a, "octave-change").parse().unwrap_or(0);
                    self.transpose = chromatic + 12 * octaves;
                }
                "directive" => self.notices.add(
                    format!(
                        "directive \"{}\": not performed",
                        a.text().unwrap_or("").trim()
                    ),
                    &place,
                ),
                name if PAGE_ONLY.contains(&name) => {}
                other => self.notices.add(format!("<{other}>: not read"), &place),
            }
        }
        Ok(())
    }

    /// A `<time>`: the sum of its beats/beat-type pairs ("3+2" beats add up).
    fn time(&mut self, t: Node, place: &str) {
        if t.children().any(|c| c.has_tag_name("senza-misura")) {
            self.notices.add(
                "senza misura (no time signature): bars follow the written measures",
                place,
            );
            self.signature = None;
            return;
        }
        let beats: Vec<u32> = t
            .children()
            .filter(|c| c.has_tag_name("beats"))
            .map(|c| {
                c.text()
                    .unwrap_or("")
                    .split('+')
                    .map(|x| x.trim().parse::<u32>().unwrap_or(0))
                    .sum()
            })
            .collect();
        let types: Vec<u32> = t
            .children()
            .filter(|c| c.has_tag_name("beat-type"))
            .map(|c| c.text().unwrap_or("").trim().parse().unwrap_or(0))
            .collect();
        let ok = !beats.is_empty()
            && beats.len() == types.len()
            && types.iter().all(|d| d.is_power_of_two() && *d <= 32)
            && beats.iter().all(|b| *b > 0);
        if !ok {
            self.notices.add(
                "a time signature timpanist cannot hold (beat types other than 1–32, or none): bars follow the written measures",
                place,
            );
            return;
        }
        let den = *types.iter().max().expect("not empty");
        let num: u32 = beats.iter().zip(&types).map(|(b, d)| b * (den / d)).sum();
        if beats.len() > 1 {
            self.notices.add(
                format!("compound time signature read as {num}/{den}"),
                place,
            );
        }
        self.signature = Some((num, den));
    }

    /// A `<note>` at score tick `tick`, lasting `duration` ticks.
    fn note(
        &mut self,
        el: Node,
        tick: u64,
        duration: u64,
        number: &str,
    ) -> Result<(), MusicXmlError> {
        let place = format!("measure {number}");
        if el.children().any(|c| c.has_tag_name("rest")) {
            return Ok(());
        }
        if el.children().any(|c| c.has_tag_name("cue")) {
            self.notices
                .add("cue note (another part's music): skipped", &place);
            return Ok(());
        }
        if let Some(want) = &self.instrument {
            let inst = el
                .children()
                .find(|c| c.has_tag_name("instrument"))
                .and_then(|c| c.attribute("id"));
            if inst.is_some_and(|i| i != want) {
                return Ok(());
            }
        }
        let Some(pitch) = self.pitch(el, number)? else {
            return Ok(());
        };
        for c in el.children().filter(Node::is_element) {
            match c.tag_name().name() {
                "grace" | "cue" | "chord" | "pitch" | "unpitched" | "rest" | "duration" | "tie"
                | "instrument" | "footnote" | "level" | "voice" | "type" | "dot" | "accidental"
                | "time-modification" | "stem" | "notehead" | "notehead-text" | "staff"
                | "beam" | "notations" | "lyric" | "play" | "listen" => {}
                other => self
                    .notices
                    .add(format!("<{other}> in a note: not read"), &place),
            }
        }
        let tie_types: Vec<&str> = el
            .children()
            .filter(|c| c.has_tag_name("tie"))
            .chain(
                el.children()
                    .filter(|c| c.has_tag_name("notations"))
                    .flat_map(|n| n.children().filter(|c| c.has_tag_name("tied"))),
            )
            .filter_map(|t| t.attribute("type"))
            .collect();
        let tie_stop = tie_types.iter().any(|t| *t == "stop" || *t == "continue");
        let tie_start = tie_types.iter().any(|t| *t == "start" || *t == "continue");
        if tie_stop {
            let open = self
                .ties
                .iter()
                .position(|&(p, i)| p == pitch && self.notes[i].end == tick)
                .or_else(|| self.ties.iter().position(|&(p, _)| p == pitch));
            if let Some(k) = open {
                let i = self.ties[k].1;
                self.notes[i].end = self.notes[i].end.max(tick + duration);
                let rolled = has_mark(el, "ornaments", "tremolo");
                let trilled = self.notes[i].trill == Some(Trill::Tied);
                if (rolled || trilled) && self.notes[i].strokes.is_some() {
                    self.notes[i].roll_end = self.notes[i].end;
                }
                self.notes[i].damped |= has_mark(el, "technical", "stopped");
                if !tie_start {
                    self.ties.remove(k);
                }
                self.wavy_lines(el, tick, Written::Tied(i), &place);
                return Ok(());
            }
            self.notices.add(
                "a tie ends on a note no tie starts on: played as a new stroke",
                &place,
            );
        }
        self.ties.retain(|&(p, _)| p != pitch);
        let marks = self.notations(el, tick, &place);
        let drum = el
            .children()
            .filter_map(|c| c.pi())
            .find(|pi| pi.target == super::DRUM_PI_TARGET)
            .and_then(|pi| pi.value)
            .and_then(drum_of_pi);
        self.notes.push(XNote {
            tick,
            end: tick + duration,
            pitch,
            mode: marks.mode,
            hand: marks.hand,
            strokes: marks.strokes,
            roll_end: tick + duration,
            trill: marks.trill.then_some(Trill::Tied),
            damped: marks.damped,
            two_note: marks.two_note,
            roll: None,
            damp: None,
            drum,
        });
        let index = self.notes.len() - 1;
        if tie_start {
            self.ties.push((pitch, index));
        }
        self.wavy_lines(el, tick, Written::New(index, marks.trill), &place);
        Ok(())
    }

    /// The sounding MIDI pitch of a note (`None`: outside MIDI's range, reported).
    fn pitch(&mut self, el: Node, number: &str) -> Result<Option<u8>, MusicXmlError> {
        let place = format!("measure {number}");
        let (node, step_tag, octave_tag) =
            if let Some(p) = el.children().find(|c| c.has_tag_name("pitch")) {
                (p, "step", "octave")
            } else if let Some(p) = el.children().find(|c| c.has_tag_name("unpitched")) {
                self.notices.add(
                    "unpitched (percussion staff) note: read at its written staff position",
                    &place,
                );
                (p, "display-step", "display-octave")
            } else {
                return Err(self.invalid(
                    el,
                    number,
                    "a <note> with neither <pitch>, <unpitched> nor <rest>".into(),
                ));
            };
        if node.has_tag_name("unpitched")
            && !node.children().any(|c| c.has_tag_name("display-step"))
        {
            // No staff position: the middle line of a treble staff.
            return Ok(Some(71));
        }
        let step = match text_of(node, step_tag).as_str() {
            "C" => 0,
            "D" => 2,
            "E" => 4,
            "F" => 5,
            "G" => 7,
            "A" => 9,
            "B" => 11,
            other => {
                return Err(self.invalid(
                    node,
                    number,
                    format!("<{step_tag}> \"{other}\" is not A–G"),
                ));
            }
        };
        let octave_text = text_of(node, octave_tag);
        let octave: i32 = octave_text.parse().map_err(|_| {
            self.invalid(
                node,
                number,
                format!("<{octave_tag}> \"{octave_text}\" is not an octave number"),
            )
        })?;
        let alter_text = text_of(node, "alter");
        let alter: f64 = if alter_text.is_empty() {
            0.0
        } else {
            alter_text.parse().map_err(|_| {
                self.invalid(
                    node,
                    number,
                    format!("<alter> \"{alter_text}\" is not a number of semitones"),
                )
            })?
        };
        if alter.fract() != 0.0 {
            self.notices.add(
                "microtonal alteration: rounded to the nearest semitone",
                &place,
            );
        }
        let midi = (octave + 1) * 12 + step + alter.round() as i32 + self.transpose;
        match u8::try_from(midi).ok().filter(|m| *m <= 127) {
            Some(m) => Ok(Some(m)),
            None => {
                self.notices
                    .add("a note outside MIDI's pitch range: skipped", &place);
                Ok(None)
            }
        }
    }

    /// A note's playing mode, tremolo, sticking and damping from its notations; its
    /// dynamics and what is not performed go to the dynamics and the notices.
    fn notations(&mut self, el: Node, tick: u64, place: &str) -> NoteMarks {
        let mut marks: Vec<PlayingMode> = Vec::new();
        let mut strokes = None;
        let mut two_note = None;
        let (mut hand, mut damped, mut trill) = (Hand::Auto, false, false);
        for notations in el.children().filter(|c| c.has_tag_name("notations")) {
            for n in notations.children().filter(Node::is_element) {
                match n.tag_name().name() {
                    "tied" | "slur" | "tuplet" | "accidental-mark" | "footnote" | "level" => {}
                    "articulations" => {
                        for a in n.children().filter(Node::is_element) {
                            match a.tag_name().name() {
                                "accent" => marks.push(PlayingMode::Accent),
                                "strong-accent" => marks.push(PlayingMode::VerticalAccent),
                                "staccato" | "staccatissimo" | "spiccato" => {
                                    marks.push(PlayingMode::Staccato);
                                }
                                "tenuto" | "detached-legato" => marks.push(PlayingMode::Tenuto),
                                other => self
                                    .notices
                                    .add(format!("articulation <{other}>: not performed"), place),
                            }
                        }
                    }
                    "ornaments" => {
                        for o in n.children().filter(Node::is_element) {
                            if o.has_tag_name("tremolo") {
                                match o.attribute("type") {
                                    Some("start") => {
                                        two_note = Some(TwoNote::Start(two_note_strokes(el, o)));
                                    }
                                    Some("stop") => two_note = Some(TwoNote::Stop),
                                    _ => strokes = self.tremolo(o, place).or(strokes),
                                }
                            } else if o.has_tag_name("trill-mark") {
                                trill = true;
                            } else if !o.has_tag_name("accidental-mark")
                                && !o.has_tag_name("wavy-line")
                            {
                                self.notices.add(
                                    format!("ornament <{}>: not performed", o.tag_name().name()),
                                    place,
                                );
                            }
                        }
                    }
                    "dynamics" => self.dynamics(n, tick, place),
                    "technical" => {
                        for t in n.children().filter(Node::is_element) {
                            match (t.tag_name().name(), t.text().map(str::trim)) {
                                ("stopped", _) => damped = true,
                                ("other-technical", Some("R")) => hand = Hand::Right,
                                ("other-technical", Some("L")) => hand = Hand::Left,
                                (other, _) => self
                                    .notices
                                    .add(format!("technical mark <{other}>: not performed"), place),
                            }
                        }
                    }
                    "fermata" => self.notices.add(
                        "fermata: not performed (the note keeps its written length)",
                        place,
                    ),
                    other => self
                        .notices
                        .add(format!("notation <{other}>: not performed"), place),
                }
            }
        }
        // Several marks: the strongest (marcato, accent, staccato, tenuto).
        let rank = |m: &PlayingMode| match m {
            PlayingMode::VerticalAccent => 0,
            PlayingMode::Accent => 1,
            PlayingMode::Staccato => 2,
            PlayingMode::Tenuto => 3,
            PlayingMode::Legato => 4,
        };
        let mode = marks
            .into_iter()
            .min_by_key(rank)
            .unwrap_or(PlayingMode::Legato);
        // A trill is a free roll: the unmeasured tremolo's.
        if trill {
            strokes = strokes.or(Some(UNMEASURED_STROKES_PER_QUARTER));
        }
        NoteMarks {
            mode,
            strokes,
            hand,
            damped,
            two_note,
            trill,
        }
    }

    /// The `<wavy-line>`s of the written note `el` at `tick`, in the order written (a stop
    /// and a start of the same number on one note end one line and begin the next). A
    /// line starting on a trilled note is the trill's, and every new note of the trilled
    /// note's voice under it is rolled too, at the trill's rate (each re-struck, as a
    /// timpanist plays a roll over untied notes), unless it has a tremolo of its own: the
    /// line's stop on the last of them or a note tied to it ends the roll with that note;
    /// a stop on the note (or grace note) right after its tied notes is their end. A line
    /// on a new note without a trill mark is reported as not performed.
    fn wavy_lines(&mut self, el: Node, tick: u64, written: Written, place: &str) {
        if let Written::New(note, _) = written {
            let voice = voice_of(el);
            for line in &mut self.trill_lines {
                if line.voice == voice {
                    line.last = note;
                    let n = &mut self.notes[note];
                    if n.strokes.is_none() {
                        (n.strokes, n.trill) =
                            (Some(UNMEASURED_STROKES_PER_QUARTER), Some(Trill::Tied));
                        line.under.push(note);
                    }
                }
            }
        }
        let lines = el
            .children()
            .filter(|c| c.has_tag_name("notations"))
            .flat_map(|n| n.children().filter(|c| c.has_tag_name("ornaments")))
            .flat_map(|o| o.children().filter(|c| c.has_tag_name("wavy-line")));
        for w in lines {
            let number = w.attribute("number").unwrap_or("1").to_string();
            let open = self.trill_lines.iter().position(|l| l.number == number);
            match (w.attribute("type"), written, open) {
                (Some("start"), Written::New(note, true), _) => {
                    self.trill_lines.retain(|l| l.number != number);
                    self.trill_lines.push(TrillLine {
                        number,
                        trilled: note,
                        last: note,
                        under: Vec::new(),
                        voice: voice_of(el),
                        place: place.to_string(),
                    });
                }
                (Some("stop"), _, Some(k)) => {
                    let line = self.trill_lines.remove(k);
                    self.end_trill(line, tick, written);
                }
                (Some("start" | "stop"), Written::New(..), _) => self
                    .notices
                    .add("ornament <wavy-line>: not performed", place),
                _ => {}
            }
        }
    }

    /// A trill's wavy line stops on the `written` note at `tick`. On a new note after the
    /// trilled one, the stop marks where the line ends: that note is not rolled for it (as
    /// notation programs write a trill's stop on the note after it).
    fn end_trill(&mut self, line: TrillLine, tick: u64, written: Written) {
        let on = match written {
            Written::New(j, _) if j != line.trilled => {
                if line.under.last() == Some(&j) {
                    self.unroll(j);
                }
                return;
            }
            Written::Tied(i) | Written::New(i, _) => Some(i),
            Written::Grace => None,
        };
        let n = &mut self.notes[line.last];
        if n.trill.is_none() {
            // Its own tremolo, not the trill, sets how far its roll reaches.
            return;
        }
        n.trill = Some(Trill::Stopped);
        if on == Some(line.last) {
            n.roll_end = n.end;
        } else if tick > n.roll_end {
            self.notices.add(
                "a trill's wavy line runs on past the notes tied to its trilled note: the roll ends with them, the notes under the rest of the line are played as written",
                &line.place,
            );
        }
    }

    /// Note `j` is not rolled after all.
    fn unroll(&mut self, j: usize) {
        let n = &mut self.notes[j];
        (n.strokes, n.trill) = (None, None);
    }

    /// A `<tremolo>`: single with n marks is 2^n strokes per quarter (1 mark eighths, 3
    /// thirty-seconds); unmeasured is a free roll; two-note tremolos are reported.
    fn tremolo(&mut self, t: Node, place: &str) -> Option<u32> {
        match t.attribute("type").unwrap_or("single") {
            "single" => {
                let marks: u32 = t.text().unwrap_or("").trim().parse().unwrap_or(3);
                if !(1..=5).contains(&marks) {
                    self.notices.add(
                        format!("tremolo with {marks} marks: read as an unmeasured roll"),
                        place,
                    );
                    return Some(UNMEASURED_STROKES_PER_QUARTER);
                }
                Some(1 << marks)
            }
            "unmeasured" => Some(UNMEASURED_STROKES_PER_QUARTER),
            _ => None,
        }
    }

    /// `<dynamics>` at `tick`.
    fn dynamics(&mut self, d: Node, tick: u64, place: &str) {
        for m in d.children().filter(Node::is_element) {
            let name = m.tag_name().name();
            let event = match name {
                "sf" | "sfz" | "fz" | "rf" | "rfz" => Some(DynEvent::Single {
                    vel: 96.0,
                    then: None,
                    accent: true,
                }),
                "sffz" => Some(DynEvent::Single {
                    vel: 112.0,
                    then: None,
                    accent: true,
                }),
                "fp" => Some(DynEvent::Single {
                    vel: 96.0,
                    then: Some(49.0),
                    accent: false,
                }),
                "sfp" | "sfzp" => Some(DynEvent::Single {
                    vel: 96.0,
                    then: Some(49.0),
                    accent: true,
                }),
                "sfpp" => Some(DynEvent::Single {
                    vel: 96.0,
                    then: Some(33.0),
                    accent: true,
                }),
                "pf" => Some(DynEvent::Single {
                    vel: 49.0,
                    then: Some(96.0),
                    accent: false,
                }),
                other => level(other).map(DynEvent::Level),
            };
            match event {
                Some(e) => self.dynamics.push((tick, e)),
                None => self
                    .notices
                    .add(format!("dynamic <{name}>: not read"), place),
            }
        }
    }

    /// A `<direction>` whose time is `tick`.
    fn direction(&mut self, el: Node, tick: u64, number: &str) {
        let place = format!("measure {number}");
        let has_sound_tempo = has_sound_tempo(el);
        for c in el.children().filter(Node::is_element) {
            match c.tag_name().name() {
                "direction-type" => {
                    for t in c.children().filter(Node::is_element) {
                        self.direction_type(t, tick, &place, has_sound_tempo);
                    }
                }
                "sound" => self.sound(c, tick, number),
                "offset" | "voice" | "staff" | "footnote" | "level" | "listening" => {}
                other => self
                    .notices
                    .add(format!("<{other}> in a direction: not read"), &place),
            }
        }
    }

    fn direction_type(&mut self, t: Node, tick: u64, place: &str, has_sound_tempo: bool) {
        match t.tag_name().name() {
            "dynamics" => self.dynamics(t, tick, place),
            "wedge" => {
                let number = t
                    .attribute("number")
                    .and_then(|n| n.parse().ok())
                    .unwrap_or(1);
                match t.attribute("type") {
                    Some("crescendo") => self
                        .dynamics
                        .push((tick, DynEvent::Wedge { up: true, number })),
                    Some("diminuendo") => {
                        self.dynamics
                            .push((tick, DynEvent::Wedge { up: false, number }));
                    }
                    Some("stop") => self.dynamics.push((tick, DynEvent::WedgeStop { number })),
                    _ => {}
                }
            }
            "metronome" => {
                // <sound tempo> in the same direction is what is played.
                if has_sound_tempo {
                    return;
                }
                match metronome_bpm(t) {
                    Some(bpm) => self.tempos.push(TempoMark {
                        tick,
                        bpm,
                        sound: false,
                        other_part: None,
                    }),
                    None => self.notices.add(
                        "metronome mark other than \"note = number\" (e.g. a metric modulation): not read",
                        place,
                    ),
                }
            }
            "words" => {
                let text: String = t.text().unwrap_or("").trim().chars().take(40).collect();
                if !text.is_empty() && !repeats::is_jump_mark(&text) {
                    self.notices
                        .add(format!("text \"{text}\": not performed"), place);
                }
            }
            "rehearsal" | "dashes" | "bracket" | "octave-shift" | "image" => {}
            // Followed by `repeats`.
            "segno" | "coda" => {}
            other => self
                .notices
                .add(format!("direction <{other}>: not performed"), place),
        }
    }

    /// A `<sound>`: its tempo (quarter notes per minute); jumps are reported.
    fn sound(&mut self, s: Node, tick: u64, number: &str) {
        let place = format!("measure {number}");
        match sound_bpm(s) {
            Some(Ok(bpm)) => self.tempos.push(TempoMark {
                tick,
                bpm,
                sound: true,
                other_part: None,
            }),
            Some(Err(tempo)) => self
                .notices
                .add(format!("<sound tempo=\"{tempo}\">: not a tempo"), &place),
            None => {}
        }
        // Jumps (dacapo, dalsegno, tocoda, fine, segno, coda) are followed by
        // `repeats`; a forward repeat is read from the bar line.
    }

    fn barline(&mut self, b: Node, number: &str) {
        let place = format!("measure {number}");
        for c in b.children().filter(Node::is_element) {
            match c.tag_name().name() {
                "segno" | "coda" => self.notices.add(
                    format!(
                        "{} on a bar line: not followed (write it as a direction)",
                        c.tag_name().name()
                    ),
                    &place,
                ),
                "fermata" => self
                    .notices
                    .add("fermata on a barline: not performed", &place),
                _ => {}
            }
        }
    }
}

/// The `<voice>` of the written note `el` ("1" when it has none).
fn voice_of(el: Node) -> String {
    (el.children().find(|c| c.has_tag_name("voice")))
        .and_then(|v| v.text())
        .map_or("1", str::trim)
        .to_string()
}

/// Whether `note` has the notation `<notations><group><name>` (e.g. technical, stopped).
pub(super) fn has_mark(note: Node, group: &str, name: &str) -> bool {
    note.children()
        .filter(|c| c.has_tag_name("notations"))
        .flat_map(|n| n.children().filter(|c| c.has_tag_name(group)))
        .any(|g| g.children().any(|c| c.has_tag_name(name)))
}

/// Strokes per quarter of a two-note tremolo starting at `note` with mark `tremolo`: its
/// marks add to the beams of the notes' written type (three marks between half notes
/// are thirty-seconds: 8 per quarter), 1 (eighths) to 5 in all.
pub(super) fn two_note_strokes(note: Node, tremolo: Node) -> u32 {
    let marks: u32 = tremolo.text().unwrap_or("").trim().parse().unwrap_or(3);
    let beams = match text_of(note, "type").as_str() {
        "eighth" => 1,
        "16th" => 2,
        "32nd" => 3,
        "64th" => 4,
        _ => 0,
    };
    1 << (marks + beams).clamp(1, 5)
}

/// Two-note tremolos as their strokes: from the first note's start to the second's end,
/// alternating between the two pitches at the tremolo's rate (each a note of its own;
/// the first stroke on each pitch keeps its note's mode and hand). A half without its
/// other half is played as written.
pub(super) fn two_note_tremolos(notes: Vec<XNote>, tpq: u64) -> Vec<XNote> {
    let mut out = Vec::with_capacity(notes.len());
    let mut open: std::collections::VecDeque<(XNote, u32)> = Default::default();
    for n in notes {
        match n.two_note {
            Some(TwoNote::Start(spq)) => open.push_back((n, spq)),
            Some(TwoNote::Stop) => match open.pop_front() {
                Some((first, spq)) => out.extend(alternate(&first, &n, spq, tpq)),
                None => out.push(n),
            },
            None => out.push(n),
        }
    }
    out.extend(open.into_iter().map(|(n, _)| n));
    out
}

/// The strokes of a two-note tremolo from `a` to `b` at `spq` strokes per quarter.
pub(super) fn alternate(a: &XNote, b: &XNote, spq: u32, tpq: u64) -> Vec<XNote> {
    let spacing = (tpq / u64::from(spq.max(1))).max(1);
    let end = a.end.max(b.end);
    (a.tick..end)
        .step_by(spacing as usize)
        .enumerate()
        .map(|(k, tick)| {
            let from = if k % 2 == 0 { a } else { b };
            let first = k < 2;
            XNote {
                tick,
                end: (tick + spacing).min(end),
                pitch: from.pitch,
                mode: if first {
                    from.mode
                } else {
                    PlayingMode::Legato
                },
                hand: if first { from.hand } else { Hand::Auto },
                strokes: None,
                roll_end: tick,
                trill: None,
                damped: false,
                two_note: None,
                roll: None,
                damp: None,
                drum: from.drum,
            }
        })
        .collect()
}

/// The drum index of a drum processing instruction's value, `drum="N"`.
fn drum_of_pi(value: &str) -> Option<usize> {
    value
        .trim()
        .strip_prefix("drum=\"")?
        .strip_suffix('"')?
        .parse()
        .ok()
}

/// The movement title, else the work title.
pub(super) fn title_of(root: Node) -> Option<String> {
    let movement = text_of(root, "movement-title");
    if !movement.is_empty() {
        return Some(movement);
    }
    let work = root.children().find(|n| n.has_tag_name("work"))?;
    Some(text_of(work, "work-title")).filter(|t| !t.is_empty())
}

/// A roll takes both hands: of notes starting together with a rolled one, keep the
/// rolled one (the lowest if several).
pub(super) fn one_roll_per_chord(mut notes: Vec<XNote>, notices: &mut Notices) -> Vec<XNote> {
    notes.sort_by_key(|n| (n.tick, n.roll.is_none(), n.pitch));
    let mut kept: Vec<XNote> = Vec::with_capacity(notes.len());
    for n in notes {
        match kept.last() {
            Some(k) if k.tick == n.tick && k.roll.is_some() => {
                notices.add(
                    "a rolled chord: rolled on its lowest (rolled) note only, as a roll takes both hands",
                    &format!("score tick {}", n.tick),
                );
            }
            _ => kept.push(n),
        }
    }
    kept
}
