//! Turning a raw capture into database units: pick each stick's track by label (a marker
//! on the tip, or a rigid body plus a tip offset in its own frame, estimated from the
//! capture when not given), turn it Z up (a Y-up capture is turned so that its −Z axis
//! points forward), segment each tip into strokes, align the take to the performer frame
//! (by hand, or fitted to the head of the drum it was played on: `mocap::align`), and
//! label every unit from options or from words in the file path.
//!
//! A take may hold one stick or both; a hand without a track gets no units and an unseen
//! tip in the database.

use super::align::{self, HabitBook, HandFit, HandStrokes, Target, Transform};
use super::db::{MotionDb, TakeData, TakeEntry, UnitEntry};
use super::import::LengthUnit;
use super::marker_body;
use super::segment::{Impact, RejectionCounts, SegmentParams, UnitSpan, fill_gaps, segment};
use super::take::{ImportError, Take, Track, extent_m};
use super::tip_estimate::{self, TipEstimate, TipEstimateError, TipPrior};
use crate::base::stats::median;
use crate::kit::{Kit, Side};
use crate::score::{Dynamic, Grip, ImpactLocation, PlayingMode};
use glam::{DQuat, DVec3};
use std::path::Path;

pub use super::vertical::UpAxis;

/// How to read one capture into the database.
#[derive(Clone, Debug)]
pub struct IngestOptions {
    /// Labels of the left and right sticks' tracks; `None`: that stick is not in the take.
    pub tips: [Option<String>; 2],
    pub up: UpAxis,
    /// For rigid-body tracks: the tip in the body's own frame, m; `None` estimates it
    /// (`mocap::tip_estimate`).
    pub tip_offset_m: Option<DVec3>,
    /// For a stick of loose markers (`A+B+…`): they are listed from the tip toward the
    /// grip, so the tip lies past the first (the user named them so); `false`: past the
    /// end that comes down faster (`mocap::marker_body`).
    pub markers_from_tip: bool,
    /// For a stick of loose markers along its shaft: the tip lies this far past the first
    /// listed marker, m; `None` estimates it.
    pub tip_past_first_m: Option<f64>,
    /// How the take is placed in the performer frame.
    pub align: Alignment,
    /// Labels; `None` reads them from the file path (see [`labels_from_path`]).
    pub mode: Option<PlayingMode>,
    pub location: Option<ImpactLocation>,
    pub dynamic: Option<Dynamic>,
    pub grip: Option<Grip>,
    /// Keep only the units of one hand.
    pub hand: Option<Side>,
    pub performer: String,
    pub segment: SegmentParams,
    /// Impact speed of each dynamic marking ([`dynamic_speeds`] of the shipped database):
    /// when no dynamic is given or in the file name, each stroke gets the marking whose
    /// speed, for the take's grip and mode, is nearest its own. Empty: mf, with a notice.
    pub dynamic_speeds: DynamicSpeeds,
}

/// How a take is placed in the performer frame.
#[derive(Clone, Debug)]
pub enum Alignment {
    /// Kept as captured (the capture is already in the performer frame).
    None,
    /// A given lab → performer transform.
    Manual(Transform),
    /// Fitted to the head of the drum each stick played: `drum` names it (else the drum in
    /// front of that hand), the impact location label names the point.
    Auto {
        kit: Kit,
        drum: Option<usize>,
        habits: HabitBook,
    },
}

/// Labels found in words of a path.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PathLabels {
    pub mode: Option<PlayingMode>,
    pub location: Option<ImpactLocation>,
    pub dynamic: Option<Dynamic>,
    pub grip: Option<Grip>,
}

/// Read labels from the words of `path` (split at anything not a letter or digit, case
/// ignored): legato, tenuto, accent, vertical accent / verticalaccent, staccato; centre /
/// center, spot / playingspot, rim / edge; pp … ff; french, german.
pub fn labels_from_path(path: &Path) -> PathLabels {
    let text = path.to_string_lossy().to_lowercase();
    let words: Vec<&str> = text
        .split(|c: char| !c.is_ascii_alphanumeric())
        .filter(|w| !w.is_empty())
        .collect();
    let mut l = PathLabels::default();
    for (i, w) in words.iter().enumerate() {
        let next = words.get(i + 1).copied();
        match *w {
            "legato" => l.mode = Some(PlayingMode::Legato),
            "tenuto" => l.mode = Some(PlayingMode::Tenuto),
            "staccato" => l.mode = Some(PlayingMode::Staccato),
            "verticalaccent" | "vaccent" => l.mode = Some(PlayingMode::VerticalAccent),
            "vertical" if next == Some("accent") => l.mode = Some(PlayingMode::VerticalAccent),
            "accent" if l.mode != Some(PlayingMode::VerticalAccent) => {
                l.mode = Some(PlayingMode::Accent)
            }
            "centre" | "center" => l.location = Some(ImpactLocation::Centre),
            "spot" | "playingspot" => l.location = Some(ImpactLocation::PlayingSpot),
            "rim" | "edge" => l.location = Some(ImpactLocation::Rim),
            "french" => l.grip = Some(Grip::French),
            "german" => l.grip = Some(Grip::German),
            mark => {
                if let Some((d, _, _)) = Dynamic::MARKS.iter().find(|(_, _, name)| *name == mark) {
                    l.dynamic = Some(*d);
                }
            }
        }
    }
    l
}

/// What one stick of a capture gave.
#[derive(Clone, Debug, PartialEq)]
pub struct HandReport {
    pub hand: Side,
    /// The track it came from.
    pub label: String,
    /// Frames of the impacts found (including the first and last, which give no unit).
    pub impacts: Vec<usize>,
    /// Units added.
    pub units: usize,
    /// Units left out for a gap too long to fill inside them.
    pub units_with_gaps: usize,
    /// Candidates turned down, by reason.
    pub rejected: RejectionCounts,
    /// Samples missing in the capture, and of those filled by interpolation.
    pub missing_frames: usize,
    pub filled_frames: usize,
    /// The tip offset estimated for a rigid body given none.
    pub tip_estimate: Option<TipEstimate>,
    /// Whether the stick is loose markers made into a body (`mocap::marker_body`), whose
    /// tip is placed beforehand past the markers on their axis rather than 0.30 m from a
    /// rigid body's origin.
    pub loose_markers: bool,
    /// Where the impacts landed after alignment.
    pub fit: Option<HandFit>,
    /// The mean tip position at the impacts, as stored (after alignment), m.
    pub impact_centroid_m: Option<DVec3>,
    /// Medians over the strokes: time between impacts, s; lift (top of the stroke above
    /// its impact), m; approach speed into the head, m/s.
    pub interval_s: Option<f64>,
    pub lift_m: Option<f64>,
    pub impact_speed_mps: Option<f64>,
}

/// What one capture added.
#[derive(Clone, Debug, PartialEq)]
pub struct IngestReport {
    /// One entry per stick found in the take.
    pub hands: Vec<HandReport>,
    /// The lab → performer transform applied.
    pub transform: Transform,
    /// Labels that were guessed, for the user to check.
    pub notices: Vec<String>,
}

impl IngestReport {
    /// Units added per hand [left, right].
    pub fn units(&self) -> [usize; 2] {
        let mut n = [0, 0];
        for h in &self.hands {
            n[crate::mocap::db::side_index(h.hand)] += h.units;
        }
        n
    }
}

/// One stick's track, Z up, before alignment.
struct Stick {
    hand: Side,
    label: String,
    tip: Vec<Option<DVec3>>,
    /// A rigid body's origin (somewhere on the stick behind the tip); empty for a marker.
    origin: Vec<Option<DVec3>>,
    estimate: Option<TipEstimate>,
    /// Whether the stick is loose markers made into a body (`mocap::marker_body`).
    loose_markers: bool,
}

/// The fastest median approach a take's strokes may have, m/s: timpanists' strokes
/// reach 1.5–3.7 m/s (guide §5) and the fastest stick strokes about 15; a median past
/// this is a length unit read wrongly (millimetres as metres make 2 m/s into 2 km/s).
pub const MAX_MEDIAN_APPROACH_MPS: f64 = 40.0;

/// Refuse a stick whose strokes descend impossibly fast (a wrong length unit), naming the
/// unit that would put them among human strokes: the one that gives the tip's whole
/// range of motion (`tip`) the half metre or so a stroking stick covers (the strokes
/// found in a capture read a thousand times too large are few and odd, their speeds no
/// guide).
fn check_stroke_speeds(
    path: &Path,
    take: &Take,
    label: &str,
    tip: &[Option<DVec3>],
    found: &[Impact],
) -> Result<(), ImportError> {
    let speeds = found.iter().map(|i| i.approach_mps);
    let Some(median) = median(speeds.clone()).filter(|&m| m > MAX_MEDIAN_APPROACH_MPS) else {
        return Ok(());
    };
    let counted = speeds.filter(|v| v.is_finite()).count();
    let span = extent_m(tip).unwrap_or(median / 3.0);
    // The smaller unit that brings the span nearest half a metre, the lengths read as
    // metres now.
    let unit = LengthUnit::Metre
        .nearest_for(span, 0.5, &[LengthUnit::Centimetre, LengthUnit::Millimetre])
        .symbol();
    let strokes = if counted == 1 {
        "stroke descends"
    } else {
        "strokes descend"
    };
    Err(ImportError::format(
        path,
        format!("track \"{label}\""),
        format!(
            "its {} {strokes} at a median {median:.0} m/s (real strokes: 1–15 m/s) and \
             it moves over {span:.0} m, so its lengths are not in {} as read: if the file is \
             in {unit}, give --unit {unit}; nothing written",
            counted, take.file_unit,
        ),
    ))
}

/// Add `take` (read from `path`) to `db` as a new take file `takes/NAME.tmot`.
pub fn ingest(
    db: &mut MotionDb,
    path: &Path,
    take: &Take,
    options: &IngestOptions,
) -> Result<IngestReport, ImportError> {
    let from_path = labels_from_path(path);
    let mut notices = Vec::new();
    let mode = options.mode.or(from_path.mode).ok_or_else(|| {
        ImportError::format(path, "labels", "cannot tell the playing mode: give --mode or put legato, tenuto, accent, vertical-accent or staccato in the file name")
    })?;
    let location = pick(
        options.location,
        from_path.location,
        ImpactLocation::PlayingSpot,
        "impact location",
        &mut notices,
    );
    // Without a dynamic given, each stroke's comes from its impact speed when a speed
    // table is at hand (else mf, said in a notice).
    let fixed_dynamic = options.dynamic.or(from_path.dynamic);
    let dynamic = match (fixed_dynamic, options.dynamic_speeds.is_empty()) {
        (Some(d), _) => d,
        (None, false) => Dynamic::Mf,
        (None, true) => pick(None, None, Dynamic::Mf, "dynamic", &mut notices),
    };
    let by_speed = fixed_dynamic.is_none() && !options.dynamic_speeds.is_empty();
    let grip = pick(
        options.grip,
        from_path.grip,
        Grip::French,
        "grip",
        &mut notices,
    );
    let wanted: Vec<(Side, &String)> = [Side::Left, Side::Right]
        .into_iter()
        .filter(|&side| options.hand.is_none_or(|h| h == side))
        .filter_map(|side| {
            Some((
                side,
                options.tips[crate::mocap::db::side_index(side)].as_ref()?,
            ))
        })
        .collect();
    // Every label is checked before any work, so a misspelt one is what the user hears of.
    for (_, label) in &wanted {
        find_tracks(path, take, label)?;
    }
    let mut sticks = Vec::new();
    for (side, label) in wanted {
        let target_height = target_for(options, path, side, location).map(|(_, p)| p.z);
        sticks.push(stick(
            path,
            take,
            side,
            label,
            options,
            target_height,
            &mut notices,
        )?);
    }
    if sticks.is_empty() {
        return Err(ImportError::format(
            path,
            "labels",
            "no stick to import: name a track with --tips (for the hand --hand gives)",
        ));
    }
    let rate = take.rate_hz;
    let segmentations: Vec<_> = sticks
        .iter()
        .map(|s| segment(&s.tip, rate, &options.segment))
        .collect();
    for (s, seg) in sticks.iter().zip(&segmentations) {
        check_stroke_speeds(path, take, &s.label, &s.tip, &seg.found)?;
    }
    let (transform, fits) = match &options.align {
        Alignment::None => (Transform::IDENTITY, Vec::new()),
        Alignment::Manual(t) => (*t, Vec::new()),
        Alignment::Auto { kit, habits, .. } => {
            let strokes: Vec<HandStrokes> = sticks
                .iter()
                .zip(&segmentations)
                .map(|(s, seg)| s.strokes(rate, &seg.impacts))
                .collect();
            let targets = target_list(options, path, &sticks, location)?;
            let habits = habits.for_stroke(grip, mode, location);
            let transform = align::fit(&strokes, &targets, kit, &habits)
                .map_err(|e| ImportError::format(path, "alignment", e.to_string()))?;
            let fits = align::report(&strokes, &targets, kit, &transform);
            (transform, fits)
        }
    };
    let take_index = db.index.takes.len();
    let mut tips: [Vec<Option<DVec3>>; 2] = [vec![None; take.frames], vec![None; take.frames]];
    let mut hands = Vec::new();
    for (s, seg) in sticks.into_iter().zip(segmentations) {
        // The stored tip has its short gaps filled as segmentation saw them; a unit with a
        // longer gap inside is left out (composition would have to jump over it).
        let filled = fill_gaps(&s.tip, (options.segment.max_gap_s * rate).round() as usize);
        let stats = stroke_stats(&filled, &seg.found, rate);
        let (whole, gapped): (Vec<&UnitSpan>, Vec<&UnitSpan>) = seg
            .units
            .iter()
            .partition(|span| filled[span.start..=span.end].iter().all(Option::is_some));
        hands.push(HandReport {
            hand: s.hand,
            label: s.label.clone(),
            impacts: seg.impacts.clone(),
            units: whole.len(),
            units_with_gaps: gapped.len(),
            rejected: seg.rejected,
            missing_frames: seg.missing_frames,
            filled_frames: seg.filled_frames,
            tip_estimate: s.estimate,
            loose_markers: s.loose_markers,
            fit: fits.iter().find(|f| f.hand == s.hand).copied(),
            impact_centroid_m: {
                let at: Vec<DVec3> = seg.impacts.iter().filter_map(|&i| filled[i]).collect();
                (!at.is_empty())
                    .then(|| transform.point(at.iter().sum::<DVec3>() / at.len() as f64))
            },
            interval_s: stats.0,
            lift_m: stats.1,
            impact_speed_mps: stats.2,
        });
        let unit_dynamic = |frame: usize| {
            let speed = seg
                .found
                .iter()
                .find(|i| i.frame == frame)
                .map(|i| i.approach_mps);
            match speed {
                Some(v) if by_speed => {
                    dynamic_for_speed(options.dynamic_speeds.for_kind(grip, mode), v)
                }
                _ => dynamic,
            }
        };
        let first_unit = db.index.units.len();
        db.index.units.extend(whole.iter().map(|span| UnitEntry {
            take: take_index,
            start: span.start,
            impact: span.impact,
            end: span.end,
            hand: s.hand,
            mode,
            location,
            dynamic: unit_dynamic(span.impact),
            grip,
        }));
        if by_speed {
            let added = &db.index.units[first_unit..];
            let counts: Vec<String> = Dynamic::MARKS
                .iter()
                .filter_map(|&(d, _, name)| {
                    let n = added.iter().filter(|u| u.dynamic == d).count();
                    (n > 0).then(|| format!("{n} {name}"))
                })
                .collect();
            notices.push(format!(
                "{:?} stick: no dynamic given or in the file name; each stroke's read from its impact speed against the shipped performer's: {}",
                s.hand,
                if counts.is_empty() { "none".into() } else { counts.join(", ") }
            ));
        }
        tips[crate::mocap::db::side_index(s.hand)] = filled
            .iter()
            .map(|p| p.map(|p| transform.point(p)))
            .collect();
    }
    let stem = path
        .file_stem()
        .map_or("take".into(), |s| s.to_string_lossy().to_string());
    let mut file = format!("takes/{stem}.tmot");
    let mut n = 2;
    while db.index.takes.iter().any(|t| t.file == file) {
        file = format!("takes/{stem}-{n}.tmot");
        n += 1;
    }
    db.index.takes.push(TakeEntry {
        file,
        frames: take.frames,
        rate_hz: take.rate_hz,
        performer: options.performer.clone(),
        source: path.display().to_string(),
        source_sha256: None,
    });
    db.takes.push(TakeData {
        rate_hz: take.rate_hz,
        tips,
        joints: None,
    });
    Ok(IngestReport {
        hands,
        transform,
        notices,
    })
}

impl Stick {
    /// The strokes at `impacts` as alignment sees them, with the stick's direction from
    /// the origin to the tip for a rigid body.
    fn strokes(&self, rate_hz: f64, impacts: &[usize]) -> HandStrokes {
        let mut strokes = align::strokes_of(&self.tip, rate_hz, impacts, self.hand);
        if !self.origin.is_empty() {
            strokes.sticks = impacts
                .iter()
                .skip(1)
                .filter_map(|&i| {
                    Some((self.tip.get(i).copied()?? - self.origin.get(i).copied()??).truncate())
                })
                .collect();
        }
        strokes
    }
}

/// The drum and point a hand's strokes belong to, when aligning automatically.
fn target_for(
    options: &IngestOptions,
    path: &Path,
    hand: Side,
    location: ImpactLocation,
) -> Option<(usize, DVec3)> {
    let Alignment::Auto { kit, drum, .. } = &options.align else {
        return None;
    };
    let drum = drum
        .or_else(|| drum_from_path(kit, path))
        .unwrap_or_else(|| front_drum(kit, hand));
    let (radius, angle) = location.polar();
    Some((drum, kit.drums[drum].point_on_head(radius, angle)))
}

/// The alignment targets of the sticks, in order.
fn target_list(
    options: &IngestOptions,
    path: &Path,
    sticks: &[Stick],
    location: ImpactLocation,
) -> Result<Vec<Target>, ImportError> {
    sticks
        .iter()
        .map(|s| {
            target_for(options, path, s.hand, location)
                .map(|(drum, point)| Target { drum, point })
                .ok_or_else(|| ImportError::format(path, "alignment", "no kit to align to"))
        })
        .collect()
}

/// The drum named by a word of the path: its whole name without punctuation ("26inch")
/// or the number it starts with ("26" for the drum "26-inch").
pub fn drum_from_path(kit: &Kit, path: &Path) -> Option<usize> {
    let text = path.to_string_lossy().to_lowercase();
    let words: Vec<&str> = text
        .split(|c: char| !c.is_ascii_alphanumeric())
        .filter(|w| !w.is_empty())
        .collect();
    kit.drums.iter().position(|d| {
        let lower = d.name.to_lowercase();
        let name: String = lower.chars().filter(char::is_ascii_alphanumeric).collect();
        let number: String = lower.chars().take_while(char::is_ascii_digit).collect();
        [name, number]
            .iter()
            .any(|n| !n.is_empty() && words.contains(&n.as_str()))
    })
}

/// The drum in front of a hand: of the drums that hand prefers, the one farthest forward.
pub fn front_drum(kit: &Kit, hand: Side) -> usize {
    (0..kit.drums.len())
        .filter(|&d| kit.drums[d].preferred_hand == hand)
        .max_by(|&a, &b| {
            kit.drums[a]
                .placement
                .y_m
                .total_cmp(&kit.drums[b].placement.y_m)
        })
        .unwrap_or(0)
}

/// One stick's tip, Z up, in the capture's place: the marker itself, or the rigid body's
/// origin carried to its tip (given or estimated); a label `A+B+…` joins loose markers
/// into the body they form (`mocap::marker_body`), whose tip is estimated.
fn stick(
    path: &Path,
    take: &Take,
    hand: Side,
    label: &str,
    options: &IngestOptions,
    head_height_m: Option<f64>,
    notices: &mut Vec<String>,
) -> Result<Stick, ImportError> {
    let tracks = find_tracks(path, take, label)?;
    let (found_label, positions, rotations, known, tip_offset_m) = match &tracks[..] {
        [track] => (
            track.label.clone(),
            track.positions.clone(),
            track.rotations.clone(),
            TipPrior::Cluster,
            options.tip_offset_m,
        ),
        markers => {
            let joined = markers
                .iter()
                .map(|t| t.label.as_str())
                .collect::<Vec<_>>()
                .join("+");
            let refused = |e: marker_body::MarkerBodyError| {
                ImportError::format(path, format!("stick \"{joined}\""), e.to_string())
            };
            let body = marker_body::from_markers(markers).map_err(refused)?;
            if options.tip_offset_m.is_some() {
                notices.push(format!(
                    "stick \"{joined}\": --tip-offset is the tip in a rigid body's own frame; this stick is loose markers, whose frame is built here, so --tip-past or the estimate places its tip"
                ));
            }
            let given = options
                .tip_past_first_m
                .map(|d| body.tip_past_first(d))
                .transpose()
                .map_err(refused)?;
            if body.misfit_frames > 0 {
                notices.push(format!(
                    "stick \"{joined}\": {} frames left out where its markers did not keep their places on the stick (a swapped or ghost marker)",
                    body.misfit_frames
                ));
            }
            let known = body.tip_prior(options.markers_from_tip);
            (joined, body.positions, body.rotations, known, given)
        }
    };
    let positions: Vec<Option<DVec3>> = positions
        .iter()
        .map(|p| p.map(|p| to_performer(p, options.up)))
        .collect();
    let rotations: Vec<Option<DQuat>> = rotations
        .iter()
        .map(|q| q.map(|q| rotation_to_performer(q, options.up)))
        .collect();
    let has_rotations = rotations.iter().any(Option::is_some);
    let (offset, estimate) = match (tip_offset_m, has_rotations) {
        (Some(d), true) => (Some(d), None),
        (None, true) => match tip_estimate::estimate(
            &positions,
            &rotations,
            take.rate_hz,
            head_height_m.unwrap_or(0.76),
            known,
        ) {
            Ok(e) => (Some(e.offset_m), Some(e)),
            // A stick that hardly plays (the idle hand of a take) has no tip to find:
            // its origin stands in.
            Err(TipEstimateError::TooFewImpacts(n)) => {
                notices.push(format!(
                    "track \"{label}\": {n} impacts are too few to estimate where its tip is; its origin is used (give --tip-offset)"
                ));
                (None, None)
            }
            Err(e) => {
                return Err(ImportError::format(
                    path,
                    format!("track \"{label}\""),
                    e.to_string(),
                ));
            }
        },
        (_, false) => (None, None),
    };
    let tip = positions
        .iter()
        .enumerate()
        .map(|(f, p)| match offset {
            Some(d) => Some(*p.as_ref()? + rotations.get(f).copied().flatten()? * d),
            None => *p,
        })
        .collect();
    Ok(Stick {
        hand,
        label: found_label,
        tip,
        origin: if offset.is_some() {
            positions
        } else {
            Vec::new()
        },
        estimate,
        loose_markers: tracks.len() > 1,
    })
}

/// The tracks a stick's label names: one track, or the markers of `A+B+…` (one stick
/// of loose markers); an error names a missing one (listing the labels the file has) or
/// one named twice.
fn find_tracks<'a>(
    path: &Path,
    take: &'a Take,
    label: &str,
) -> Result<Vec<&'a Track>, ImportError> {
    let tracks = label
        .split('+')
        .map(|one| find_track(path, take, one.trim()))
        .collect::<Result<Vec<_>, _>>()?;
    for (i, t) in tracks.iter().enumerate() {
        if tracks[..i].iter().any(|u| std::ptr::eq(*u, *t)) {
            return Err(ImportError::format(
                path,
                format!("stick \"{label}\""),
                format!("names the track \"{}\" twice", t.label),
            ));
        }
    }
    Ok(tracks)
}

/// The track labelled `label`, or an error listing the labels the file has, or naming
/// the places of two tracks labelled alike (which one is the stick cannot be told).
fn find_track<'a>(path: &Path, take: &'a Take, label: &str) -> Result<&'a Track, ImportError> {
    let track = take.track(label).ok_or_else(|| {
        ImportError::format(
            path,
            "labels",
            format!(
                "no track labelled \"{label}\"; the file has: {}",
                take.labels().join(", ")
            ),
        )
    })?;
    let places = take.places_of(track);
    if places.len() > 1 {
        return Err(ImportError::format(
            path,
            "labels",
            format!(
                "{}: rename one in the capture software (or export it again) so the stick's is told apart",
                crate::mocap::take::duplicate_label(&track.label, &places)
            ),
        ));
    }
    Ok(track)
}

/// Medians of the interval between `impacts`, the lift and the approach speed of a tip
/// (`filled`: its short gaps filled).
fn stroke_stats(
    filled: &[Option<DVec3>],
    impacts: &[Impact],
    rate_hz: f64,
) -> (Option<f64>, Option<f64>, Option<f64>) {
    let height: Vec<f64> = filled.iter().map(|p| p.map_or(f64::NAN, |p| p.z)).collect();
    let intervals = impacts
        .windows(2)
        .map(|w| (w[1].frame - w[0].frame) as f64 / rate_hz);
    let lifts = impacts.windows(2).map(|w| {
        height[w[0].frame..w[1].frame]
            .iter()
            .copied()
            .filter(|h| h.is_finite())
            .fold(f64::NEG_INFINITY, f64::max)
            - w[1].height_m
    });
    let speeds = impacts.iter().map(|i| i.approach_mps);
    (median(intervals), median(lifts), median(speeds))
}

/// How fast each dynamic marking strikes, per grip and playing mode (an accent strikes
/// faster than a legato at the same marking) and over all strokes: median impact
/// (approach) speeds, m/s, in marking order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DynamicSpeeds {
    pub overall: SpeedTable,
    pub by_kind: Vec<((Grip, PlayingMode), SpeedTable)>,
}

/// Median impact speed per dynamic marking, m/s.
pub type SpeedTable = Vec<(Dynamic, f64)>;

impl DynamicSpeeds {
    /// The table for strokes of `grip` and `mode`, else the overall one.
    pub fn for_kind(&self, grip: Grip, mode: PlayingMode) -> &[(Dynamic, f64)] {
        self.by_kind
            .iter()
            .find(|(k, _)| *k == (grip, mode))
            .map_or(&self.overall, |(_, t)| t)
    }

    /// Whether there is nothing to read speeds against.
    pub fn is_empty(&self) -> bool {
        self.overall.is_empty()
    }
}

/// The [`DynamicSpeeds`] of a database (the shipped one, for [`IngestOptions`]).
pub fn dynamic_speeds(db: &MotionDb) -> DynamicSpeeds {
    let params = SegmentParams::default();
    let mut samples: Vec<((Grip, PlayingMode), Dynamic, f64)> = Vec::new();
    for (t, data) in db.takes.iter().enumerate() {
        for side in [Side::Left, Side::Right] {
            let units: Vec<&UnitEntry> = db
                .index
                .units
                .iter()
                .filter(|u| u.take == t && u.hand == side)
                .collect();
            if units.is_empty() {
                continue;
            }
            for i in segment(data.tip(side), data.rate_hz, &params).found {
                let Some(u) = units.iter().find(|u| u.impact.abs_diff(i.frame) <= 1) else {
                    continue;
                };
                let mark = u.dynamic.nearest_mark();
                if let Some(&(d, _, _)) = Dynamic::MARKS.iter().find(|m| m.2 == mark) {
                    samples.push(((u.grip, u.mode), d, i.approach_mps));
                }
            }
        }
    }
    let table = |keep: &dyn Fn(&(Grip, PlayingMode)) -> bool| -> SpeedTable {
        Dynamic::MARKS
            .iter()
            .filter_map(|&(d, _, _)| {
                let speeds = samples.iter().filter(|s| s.1 == d && keep(&s.0));
                Some((d, median(speeds.map(|s| s.2))?))
            })
            .collect()
    };
    let mut kinds: Vec<(Grip, PlayingMode)> = samples.iter().map(|s| s.0).collect();
    kinds.sort_by_key(|k| format!("{k:?}"));
    kinds.dedup();
    DynamicSpeeds {
        overall: table(&|_| true),
        by_kind: kinds.iter().map(|&k| (k, table(&|x| *x == k))).collect(),
    }
}

/// The marking whose speed in `table` is nearest `speed` (by ratio).
fn dynamic_for_speed(table: &[(Dynamic, f64)], speed: f64) -> Dynamic {
    table
        .iter()
        .min_by(|a, b| {
            let d = |v: f64| (speed.max(1e-3) / v.max(1e-3)).ln().abs();
            d(a.1).total_cmp(&d(b.1))
        })
        .map_or(Dynamic::Mf, |t| t.0)
}

/// The given label, else the one from the path, else `default` with a notice.
fn pick<T: std::fmt::Debug + Copy>(
    given: Option<T>,
    found: Option<T>,
    default: T,
    what: &str,
    notices: &mut Vec<String>,
) -> T {
    given.or(found).unwrap_or_else(|| {
        notices.push(format!(
            "no {what} given or in the file name; assumed {default:?}"
        ));
        default
    })
}

/// Which hand a track label names, when it says: "left"/"right" in it, a word that is
/// just L or R ("R_STICK_TIP", "RStick2", "Stick_L", "TipR"), or an L/R at either end
/// of its letters ("StickL", "LSTK") — in its last `:`-separated part, else in the parts
/// before it ("StickR:Marker1", a rigid body's marker in Motive); for a stick of loose
/// markers (`A+B+…`), the hand all of them name.
pub fn hand_from_label(label: &str) -> Option<Side> {
    // A stick of loose markers (`A+B+…`): the hand all of them name.
    if label.contains('+') {
        let hands: Vec<Option<Side>> = label.split('+').map(hand_from_label).collect();
        return hands[0].filter(|h| hands.iter().all(|o| *o == Some(*h)));
    }
    let lower = label.to_ascii_lowercase();
    if lower.contains("left") {
        return Some(Side::Left);
    }
    if lower.contains("right") {
        return Some(Side::Right);
    }
    label.rsplit(':').find_map(hand_from_name)
}

/// [`hand_from_label`] for one part of a label, with no "left" or "right" in it.
fn hand_from_name(name: &str) -> Option<Side> {
    let side = |c: char| match c {
        'L' | 'l' => Some(Side::Left),
        'R' | 'r' => Some(Side::Right),
        _ => None,
    };
    let single: Vec<Side> = words(name)
        .iter()
        .filter_map(|w| match w.as_bytes() {
            [c] => side(char::from(*c)),
            _ => None,
        })
        .collect();
    if let [one] = single[..] {
        return Some(one);
    }
    let letters: String = name.chars().filter(char::is_ascii_alphabetic).collect();
    let (first, last) = (letters.chars().next()?, letters.chars().last()?);
    let upper = |c: char| side(c).filter(|_| c.is_ascii_uppercase());
    // A leading L/R names the hand of a short label ("LSTK", "RFIN") or of one whose
    // letters go on with a stick's name ("LSTICK", "RMALLET", "LSTK_TIP").
    let names_stick = || {
        let rest = letters[1..].to_ascii_lowercase();
        STICK_WORDS.iter().any(|w| rest.starts_with(w))
    };
    match (upper(last), upper(first)) {
        (Some(s), _) => Some(s),
        (None, Some(s)) if letters.len() <= 5 || names_stick() => Some(s),
        _ => None,
    }
}

/// What a stick's track is called (after its hand's letter), lower case.
pub const STICK_WORDS: [&str; 5] = ["stick", "stk", "mallet", "tip", "bead"];

/// The words of a label: runs of letters split at anything else and at case changes
/// ("R_STICK_tip2" → R, STICK, tip; "RStickTip" → R, Stick, Tip).
fn words(label: &str) -> Vec<String> {
    let chars: Vec<char> = label.chars().collect();
    let mut words = Vec::new();
    let mut word = String::new();
    for (i, &c) in chars.iter().enumerate() {
        if !c.is_ascii_alphabetic() {
            words.extend((!word.is_empty()).then(|| std::mem::take(&mut word)));
            continue;
        }
        let prev = i.checked_sub(1).map(|p| chars[p]);
        let next = chars.get(i + 1);
        let starts = c.is_ascii_uppercase()
            && prev.is_some_and(|p| {
                p.is_ascii_lowercase()
                    || (p.is_ascii_uppercase() && next.is_some_and(char::is_ascii_lowercase))
            });
        if starts && !word.is_empty() {
            words.push(std::mem::take(&mut word));
        }
        word.push(c);
    }
    words.extend((!word.is_empty()).then_some(word));
    words
}

/// A capture position in the performer frame ([`UpAxis::to_performer`]).
pub fn to_performer(p: DVec3, up: UpAxis) -> DVec3 {
    up.to_performer(p)
}

/// A capture orientation (world from body) with the world turned like [`to_performer`].
pub fn rotation_to_performer(q: DQuat, up: UpAxis) -> DQuat {
    match up {
        UpAxis::Z => q,
        _ => (up.rotation() * q).normalize(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mocap::db::{self, Index};

    /// A label's hand, in the ways labs write it; none where it does not say.
    #[test]
    fn hands_from_track_labels() {
        let cases = [
            ("StickL", Some(Side::Left)),
            ("Player:TipR", Some(Side::Right)),
            ("LSTK", Some(Side::Left)),
            ("RSTK2", Some(Side::Right)),
            ("R_STICK_TIP", Some(Side::Right)),
            ("l_mallet_top", Some(Side::Left)),
            ("RStickTop", Some(Side::Right)),
            ("Stick_L_2", Some(Side::Left)),
            ("LeftMallet", Some(Side::Left)),
            ("mallet right", Some(Side::Right)),
            ("CLAV", None),
            ("StickTop", None),
            ("Marker1", None),
            ("StickR:Marker1", Some(Side::Right)),
            ("Player:TipL", Some(Side::Left)),
            ("Player:CLAV", None),
            ("LSTK1+LSTK2", Some(Side::Left)),
            ("LSTK1+RSTK2", None),
            ("LSTICK", Some(Side::Left)),
            ("RSTICK", Some(Side::Right)),
            ("LMALLET", Some(Side::Left)),
            ("LSTICKTIP", Some(Side::Left)),
            ("RSTK_TIP", Some(Side::Right)),
            ("LASIS", Some(Side::Left)),
        ];
        for (label, hand) in cases {
            assert_eq!(hand_from_label(label), hand, "{label}");
        }
        assert_eq!(words("R_STICK_tip2"), ["R", "STICK", "tip"]);
        assert_eq!(words("RStickTip"), ["R", "Stick", "Tip"]);
    }

    /// Words of a path become labels; missing ones stay unset.
    #[test]
    fn labels_from_file_names() {
        let l = labels_from_path(Path::new("/caps/German/vertical-accent_rim_ff_take3.c3d"));
        assert_eq!(l.mode, Some(PlayingMode::VerticalAccent));
        assert_eq!(l.location, Some(ImpactLocation::Rim));
        assert_eq!(l.dynamic, Some(Dynamic::Ff));
        assert_eq!(l.grip, Some(Grip::German));
        let l = labels_from_path(Path::new("accent-center.csv"));
        assert_eq!(
            (l.mode, l.location, l.grip),
            (
                Some(PlayingMode::Accent),
                Some(ImpactLocation::Centre),
                None
            )
        );
    }

    /// A capture made from a synthetic take, given in Y-up millimetre-free metres, is cut
    /// into the same units as the synthetic database cut it.
    #[test]
    fn ingests_a_y_up_capture() {
        let source = crate::mocap::synth::synthesize(&crate::mocap::synth::SynthConfig {
            grips: vec![Grip::French],
            modes: vec![PlayingMode::Legato],
            locations: vec![ImpactLocation::Rim],
            hands: vec![Side::Right],
            dynamics: vec![Dynamic::F],
            strokes_per_dynamic: 6,
            ..Default::default()
        });
        let data = &source.takes[0];
        let from_performer = |p: DVec3| DVec3::new(p.x, p.z, -p.y);
        let track = |label: &str, side: Side| Track {
            label: label.into(),
            positions: data
                .tip(side)
                .iter()
                .map(|p| p.map(from_performer))
                .collect(),
            rotations: Vec::new(),
        };
        let take = Take {
            source: "legato_rim_f.csv".into(),
            rate_hz: data.rate_hz,
            frames: data.frames(),
            file_unit: "m".into(),
            tracks: vec![
                track("Player:TipL", Side::Left),
                track("Player:TipR", Side::Right),
            ],
            notes: Vec::new(),
        };
        let mut db = MotionDb {
            index: Index {
                version: db::DB_FORMAT_VERSION,
                description: "test".into(),
                joints: Vec::new(),
                takes: Vec::new(),
                units: Vec::new(),
            },
            takes: Vec::new(),
            limits: Default::default(),
        };
        let options = IngestOptions {
            tips: [Some("TipL".into()), Some("TipR".into())],
            up: UpAxis::Y,
            tip_offset_m: None,
            markers_from_tip: false,
            tip_past_first_m: None,
            align: Alignment::None,
            mode: None,
            location: None,
            dynamic: None,
            grip: Some(Grip::French),
            hand: None,
            performer: "test".into(),
            segment: SegmentParams::default(),
            dynamic_speeds: DynamicSpeeds::default(),
        };
        let report = ingest(&mut db, Path::new("legato_rim_f.csv"), &take, &options).unwrap();
        assert_eq!(report.units(), [0, 6], "{report:?}");
        assert!(report.notices.is_empty());
        let spans: Vec<(usize, usize)> = source
            .index
            .units
            .iter()
            .map(|u| (u.start, u.impact))
            .collect();
        let ours: Vec<(usize, usize)> =
            db.index.units.iter().map(|u| (u.start, u.impact)).collect();
        assert_eq!(spans, ours);
        assert!(db.index.units.iter().all(|u| u.mode == PlayingMode::Legato
            && u.location == ImpactLocation::Rim
            && u.dynamic == Dynamic::F));
        let err = ingest(
            &mut db,
            Path::new("x.csv"),
            &take,
            &IngestOptions {
                mode: Some(PlayingMode::Legato),
                tips: [Some("Nope".into()), Some("TipR".into())],
                ..options
            },
        )
        .unwrap_err();
        assert!(
            err.to_string().contains("Nope") && err.to_string().contains("Player:TipL"),
            "{err}"
        );
    }
}
