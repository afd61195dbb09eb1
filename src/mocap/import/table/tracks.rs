//! The tracks a profile finds in the columns: explicit ones and those discovered by
//! patterns such as `"{name} X"`, with their position and orientation columns.

use super::*;

/// Where a track's samples are (0-based columns).
#[derive(Clone, Debug, PartialEq)]
pub(super) struct TrackCols {
    pub(super) label: String,
    pub(super) position: [usize; 3],
    pub(super) rotation: Option<RotCols>,
}

/// Where and how a rigid body's rotation is written.
#[derive(Clone, Debug, PartialEq)]
pub(super) enum RotCols {
    Quaternion([usize; 4]),
    Euler {
        cols: [usize; 3],
        axes: [DVec3; 3],
        /// Radians per file unit.
        scale: f64,
        extrinsic: bool,
    },
    Matrix([usize; 9]),
}

impl RotCols {
    pub(super) fn columns(&self) -> &[usize] {
        match self {
            RotCols::Quaternion(c) => c,
            RotCols::Euler { cols, .. } => cols,
            RotCols::Matrix(c) => c,
        }
    }

    pub(super) fn kind(&self) -> &'static str {
        match self {
            RotCols::Quaternion(_) => "quaternion",
            RotCols::Euler { .. } => "euler",
            RotCols::Matrix(_) => "matrix",
        }
    }
}

impl TrackCols {
    pub(super) fn found(&self) -> FoundTrack {
        FoundTrack {
            label: self.label.clone(),
            position: self.position.map(|c| c + 1),
            orientation: self
                .rotation
                .as_ref()
                .map(|r| (r.kind(), r.columns().iter().map(|c| c + 1).collect())),
        }
    }
}

/// The profile's explicit tracks, then the tracks its patterns discover in column order
/// (an earlier pattern taking a label first); and what went wrong (a missing column, no
/// track at all).
pub(super) fn find_tracks(
    profile: &CaptureProfile,
    cols: &Columns,
) -> (Vec<TrackCols>, Vec<String>) {
    let mut tracks = Vec::new();
    let mut problems = Vec::new();
    for t in &profile.tracks {
        let refs = spec_columns(&t.position, t.orientation.as_ref());
        match resolve(cols, &refs, t.orientation.as_ref(), &t.label) {
            Ok(tc) => tracks.push(tc),
            Err(e) => problems.push(format!("track \"{}\": {e}", t.label)),
        }
    }
    let explicit = tracks.len();
    for p in &profile.patterns {
        let refs = spec_columns(&p.position, p.orientation.as_ref());
        for (label, names) in discover(cols, &refs) {
            let taken = tracks
                .iter()
                .any(|t: &TrackCols| t.label.eq_ignore_ascii_case(&label));
            let names: Vec<&str> = names.iter().map(String::as_str).collect();
            if let (false, Ok(tc)) = (taken, resolve(cols, &names, p.orientation.as_ref(), &label))
            {
                tracks.push(tc);
            }
        }
    }
    tracks[explicit..].sort_by_key(|t| t.position[0]);
    if tracks.is_empty() && problems.is_empty() {
        problems.push(
            "expected at least one track, found none: no explicit track, and no pattern \
             matched the column names"
                .into(),
        );
    }
    (tracks, problems)
}

/// A track's columns from its references (position X, Y, Z, then rotation).
pub(super) fn resolve(
    cols: &Columns,
    refs: &[&str],
    orientation: Option<&Orientation>,
    label: &str,
) -> Result<TrackCols, String> {
    let anchor = cols.find(refs[0], None)?;
    let found: Vec<usize> = refs
        .iter()
        .map(|r| cols.find(r, Some(anchor)))
        .collect::<Result<_, _>>()?;
    let rotation = orientation.map(|o| rot_cols(o, &found[3..])).transpose()?;
    Ok(TrackCols {
        label: label.to_string(),
        position: [found[0], found[1], found[2]],
        rotation,
    })
}

/// The rotation columns in the form `o` asks for.
pub(super) fn rot_cols(o: &Orientation, c: &[usize]) -> Result<RotCols, String> {
    Ok(match o {
        Orientation::Quaternion { .. } => RotCols::Quaternion([c[0], c[1], c[2], c[3]]),
        Orientation::Euler {
            order,
            angles,
            frame,
            ..
        } => RotCols::Euler {
            cols: [c[0], c[1], c[2]],
            axes: euler_axes(order)?,
            scale: match angles {
                AngleUnit::Degrees => std::f64::consts::PI / 180.0,
                AngleUnit::Radians => 1.0,
            },
            extrinsic: *frame == EulerFrame::Extrinsic,
        },
        Orientation::Matrix { .. } => {
            let mut m = [0; 9];
            m.copy_from_slice(&c[..9]);
            RotCols::Matrix(m)
        }
    })
}

/// Column names longer than this (in characters) are not matched against patterns.
pub(super) const MAX_PATTERN_NAME: usize = 160;

/// Every (label, column references) a pattern finds, in column order: for each column
/// fitting the first template, the first way of filling its placeholders for which all
/// the other columns exist.
pub(super) fn discover(cols: &Columns, refs: &[&str]) -> Vec<(String, Vec<String>)> {
    let templates: Vec<String> = refs.iter().map(|r| display_name(r)).collect();
    let Ok(first) = template_parts(&templates[0]) else {
        return Vec::new();
    };
    let mut out: Vec<(String, Vec<String>)> = Vec::new();
    for name in &cols.names {
        let text: Vec<char> = name.chars().collect();
        if text.len() > MAX_PATTERN_NAME {
            continue;
        }
        let mut hit = None;
        fill_holes(&first, &text, &mut Vec::new(), &mut |caps| {
            let names: Vec<String> = templates.iter().map(|t| substitute(t, caps)).collect();
            let label = caps
                .iter()
                .find(|(h, _)| h == "name")
                .map(|(_, v)| v.clone());
            let anchor = cols.find(&names[0], None).ok();
            let all = anchor.is_some_and(|a| names.iter().all(|n| cols.find(n, Some(a)).is_ok()));
            hit = label.filter(|_| all).map(|l| (l, names));
            hit.is_some()
        });
        if let Some((label, names)) = hit.filter(|(l, _)| !out.iter().any(|(o, _)| o == l)) {
            out.push((label, names));
        }
    }
    out
}

/// Placeholder values: (name, text).
pub(super) type Captures = Vec<(String, String)>;

/// Offer `found` every way `text` fits `parts` (text compared case-insensitively,
/// placeholders taking at least one character, a repeated placeholder the same text),
/// longest placeholder values first (so a name with spaces beats a short ID), until it
/// returns true; true if it did.
pub(super) fn fill_holes(
    parts: &[Part],
    text: &[char],
    caps: &mut Captures,
    found: &mut dyn FnMut(&Captures) -> bool,
) -> bool {
    let Some((part, rest)) = parts.split_first() else {
        return text.is_empty() && found(caps);
    };
    let starts = |t: &[char], with: &str| -> Option<usize> {
        let with: Vec<char> = with.chars().collect();
        let same = t.len() >= with.len()
            && t.iter()
                .zip(&with)
                .all(|(a, b)| a.to_lowercase().eq(b.to_lowercase()));
        same.then_some(with.len())
    };
    match part {
        Part::Text(s) => starts(text, s).is_some_and(|n| fill_holes(rest, &text[n..], caps, found)),
        Part::Hole(h) => {
            if let Some((_, v)) = caps.iter().find(|(k, _)| k == h) {
                let n = starts(text, &v.clone());
                return n.is_some_and(|n| fill_holes(rest, &text[n..], caps, found));
            }
            for n in (1..=text.len()).rev() {
                caps.push((h.to_string(), text[..n].iter().collect()));
                let done = fill_holes(rest, &text[n..], caps, found);
                caps.pop();
                if done {
                    return true;
                }
            }
            false
        }
    }
}

/// A template with its placeholders filled in (a template that does not parse is kept).
pub(super) fn substitute(template: &str, caps: &Captures) -> String {
    let Ok(parts) = template_parts(template) else {
        return template.to_string();
    };
    parts
        .iter()
        .map(|p| match p {
            Part::Text(t) => t.to_string(),
            Part::Hole(h) => caps
                .iter()
                .find(|(k, _)| k == h)
                .map_or_else(|| format!("{{{h}}}"), |(_, v)| v.clone()),
        })
        .collect()
}
