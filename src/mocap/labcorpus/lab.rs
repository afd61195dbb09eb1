//! The lab view of a take: tracks in the lab frame with noise, gaps and dropped rows, and
//! the capture (files and truth) made from them.

use super::*;

/// What a written track is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Kind {
    /// A rigid body (position and rotation).
    Body,
    /// A solved marker of a rigid body's cluster.
    ClusterMarker,
    /// A plain marker.
    Marker,
}

/// One track as written: lab frame, metres.
pub(super) struct OutTrack {
    pub(super) label: String,
    pub(super) kind: Kind,
    /// The rigid body's number (Motive IDs).
    pub(super) body: usize,
    pub(super) positions: Vec<Option<DVec3>>,
    /// Per frame for bodies; empty for markers.
    pub(super) rotations: Vec<Option<DQuat>>,
    pub(super) gaps: Vec<[usize; 2]>,
}

/// The whole file's content before formatting.
pub(super) struct OutTake {
    pub(super) name: String,
    pub(super) rate_hz: f64,
    pub(super) frames: usize,
    /// The frames written (0-based), in order.
    pub(super) rows: Vec<usize>,
    pub(super) tracks: Vec<OutTrack>,
    pub(super) labels: SourceLabels,
}

/// The cluster markers of a rigid body, in the body frame, m.
pub(super) const CLUSTER_MARKERS: [[f64; 3]; 3] = [
    [0.0, 0.035, 0.0],
    [0.03, -0.02, 0.0],
    [-0.025, -0.015, 0.02],
];

/// The side's letter in labels.
pub(super) fn side_letter(side: Side) -> &'static str {
    match side {
        Side::Left => "L",
        Side::Right => "R",
    }
}

/// Build the file's tracks and the stick tracks' truth from the performer samples.
pub(super) fn lab_tracks(
    take: &PerformerTake,
    style: &LabStyle,
) -> (Vec<OutTrack>, Vec<TrackTruth>) {
    let mut tracks = Vec::new();
    let truth = take
        .sides
        .iter()
        .enumerate()
        .map(|(b, s)| {
            let (label, offset) = if style.layout.rigid_body() {
                let (label, offset) = push_body(&mut tracks, s, b + 1, style);
                (label, Some(offset.to_array()))
            } else {
                (push_markers(&mut tracks, s, style), None)
            };
            TrackTruth {
                label,
                hand: s.side,
                impacts: s.impacts.clone(),
                tip_offset_body_m: offset,
                stick_markers_m: (!style.layout.rigid_body() && !style.stick_markers_m.is_empty())
                    .then(|| style.stick_markers_m.clone()),
                gaps: Vec::new(),
            }
        })
        .collect();
    (tracks, truth)
}

/// Push the rigid body of one stick (number `body`); its label and the tip in its frame.
pub(super) fn push_body(
    tracks: &mut Vec<OutTrack>,
    s: &SideSamples,
    body: usize,
    style: &LabStyle,
) -> (String, DVec3) {
    let lab = style.transform();
    let turn = lab.rotation(style.up);
    let along = DVec3::new(0.0, 0.0, style.origin_from_tip_m);
    let label = format!("Stick{}", side_letter(s.side));
    let rotations: Vec<DQuat> = s.stick.iter().map(|q| turn * *q * style.cluster).collect();
    let origins: Vec<DVec3> = s
        .tip
        .iter()
        .zip(&s.stick)
        .map(|(t, q)| lab.to_lab(*t + *q * along, style.up))
        .collect();
    tracks.push(OutTrack {
        label: label.clone(),
        kind: Kind::Body,
        body,
        positions: origins.into_iter().map(Some).collect(),
        rotations: rotations.into_iter().map(Some).collect(),
        gaps: Vec::new(),
    });
    (label, style.cluster.inverse() * -along)
}

/// Push the tip marker and the arm markers of one stick; the tip's label.
pub(super) fn push_markers(
    tracks: &mut Vec<OutTrack>,
    s: &SideSamples,
    style: &LabStyle,
) -> String {
    let lab = style.transform();
    let prefix = if style.layout == Layout::Vicon {
        "Player:"
    } else {
        ""
    };
    let letter = side_letter(s.side);
    let to_lab = |v: &[DVec3]| -> Vec<Option<DVec3>> {
        v.iter().map(|p| Some(lab.to_lab(*p, style.up))).collect()
    };
    let label = if style.stick_markers_m.is_empty() {
        let label = format!("{prefix}Tip{letter}");
        tracks.push(marker_track(label.clone(), to_lab(&s.tip)));
        label
    } else {
        let mut labels = Vec::new();
        for (k, place) in style.stick_markers_m.iter().enumerate() {
            let on_stick = DVec3::from(*place);
            let positions: Vec<DVec3> = s
                .tip
                .iter()
                .zip(&s.stick)
                .map(|(t, q)| *t + *q * on_stick)
                .collect();
            let label = format!("{prefix}Stick{letter}{}", k + 1);
            tracks.push(marker_track(label.clone(), to_lab(&positions)));
            labels.push(label);
        }
        labels.join("+")
    };
    for (name, positions) in &s.markers {
        tracks.push(marker_track(
            format!("{prefix}{name}{letter}"),
            to_lab(positions),
        ));
    }
    label
}

/// The tracks with Motive's solved cluster markers after each body: computed from the
/// body's (noisy) pose, so missing where it is.
pub(super) fn with_cluster_markers(tracks: Vec<OutTrack>) -> Vec<OutTrack> {
    tracks
        .into_iter()
        .flat_map(|body| {
            let markers: Vec<OutTrack> = CLUSTER_MARKERS
                .iter()
                .enumerate()
                .filter(|_| body.kind == Kind::Body)
                .map(|(k, m)| OutTrack {
                    label: format!("{}:Marker{}", body.label, k + 1),
                    kind: Kind::ClusterMarker,
                    body: body.body,
                    positions: body
                        .positions
                        .iter()
                        .zip(&body.rotations)
                        .map(|(p, q)| p.zip(*q).map(|(p, q)| p + q * DVec3::from(*m)))
                        .collect(),
                    rotations: Vec::new(),
                    gaps: body.gaps.clone(),
                })
                .collect();
            std::iter::once(body).chain(markers)
        })
        .collect()
}

pub(super) fn marker_track(label: String, positions: Vec<Option<DVec3>>) -> OutTrack {
    OutTrack {
        label,
        kind: Kind::Marker,
        body: 0,
        positions,
        rotations: Vec::new(),
        gaps: Vec::new(),
    }
}

/// Add noise to every sample of `track`.
pub(super) fn add_noise(track: &mut OutTrack, style: &LabStyle, rng: &mut Rng) {
    let mut gauss = |sd: f64| DVec3::new(rng.normal(), rng.normal(), rng.normal()) * sd;
    for p in track.positions.iter_mut().flatten() {
        *p += gauss(style.position_noise_m);
    }
    for q in track.rotations.iter_mut().flatten() {
        *q = (DQuat::from_scaled_axis(gauss(style.rotation_noise_rad)) * *q).normalize();
    }
}

/// Runs of missing frames covering about `fraction` of `frames`, each 1–`max_run`
/// frames long, not overlapping: [first, length], in order.
pub(super) fn gap_runs(
    frames: usize,
    fraction: f64,
    max_run: usize,
    rng: &mut Rng,
) -> Vec<[usize; 2]> {
    let target = (fraction * frames as f64).round() as usize;
    let mut missing = vec![false; frames];
    let mut count = 0;
    for _ in 0..frames.saturating_mul(4) {
        if count >= target {
            break;
        }
        let len = (1 + (rng.unit() * max_run as f64) as usize).min(target - count);
        let start = (rng.unit() * frames as f64) as usize;
        for m in missing.iter_mut().skip(start).take(len) {
            count += usize::from(!*m);
            *m = true;
        }
    }
    let mut runs: Vec<[usize; 2]> = Vec::new();
    for (f, _) in missing.iter().enumerate().filter(|(_, m)| **m) {
        match runs.last_mut() {
            Some([s, l]) if *s + *l == f => *l += 1,
            _ => runs.push([f, 1]),
        }
    }
    runs
}

/// Blank the samples of `track` in its gap runs.
pub(super) fn punch_gaps(track: &mut OutTrack, runs: Vec<[usize; 2]>) {
    for &[start, len] in &runs {
        for f in start..start + len {
            track.positions[f] = None;
            if let Some(q) = track.rotations.get_mut(f) {
                *q = None;
            }
        }
    }
    track.gaps = runs;
}

/// Swap the first two markers of a stick of loose markers (`label`: `A+B+…`) for
/// `style.marker_swaps` runs of 5–40 frames each, as a labelling pass that mistook one
/// for the other would.
pub(super) fn swap_labels(tracks: &mut [OutTrack], label: &str, style: &LabStyle, rng: &mut Rng) {
    let names: Vec<&str> = label.split('+').collect();
    let (Some(a), Some(b)) = (
        tracks
            .iter()
            .position(|t| Some(&t.label.as_str()) == names.first()),
        tracks
            .iter()
            .position(|t| Some(&t.label.as_str()) == names.get(1)),
    ) else {
        return;
    };
    let frames = tracks[a].positions.len();
    for _ in 0..style.marker_swaps {
        let len = 5 + (rng.unit() * 36.0) as usize;
        let start = (rng.unit() * frames.saturating_sub(len) as f64) as usize;
        for f in start..(start + len).min(frames) {
            let p = tracks[a].positions[f];
            tracks[a].positions[f] = tracks[b].positions[f];
            tracks[b].positions[f] = p;
        }
    }
}

/// The frames to drop: about `fraction` of them, never the first or last.
pub(super) fn dropped_frames(frames: usize, fraction: f64, rng: &mut Rng) -> Vec<usize> {
    let target = (fraction * frames as f64).round() as usize;
    let mut dropped = vec![false; frames];
    let inner = frames.saturating_sub(2);
    let mut count = 0;
    for _ in 0..frames.saturating_mul(4) {
        if count >= target.min(inner) {
            break;
        }
        let f = 1 + (rng.unit() * inner as f64) as usize;
        count += usize::from(!dropped[f]);
        dropped[f] = true;
    }
    (0..frames).filter(|&f| dropped[f]).collect()
}

/// Put `take` into the lab as `style` says, with its imperfections, and write the file.
pub(super) fn capture(take: &PerformerTake, style: &LabStyle, rng: Rng) -> GeneratedCapture {
    let frames = take.frames();
    let (mut tracks, mut truth_tracks) = lab_tracks(take, style);
    for (i, track) in tracks.iter_mut().enumerate() {
        add_noise(track, style, &mut rng.fork(2 * i as u64));
        let runs = gap_runs(
            frames,
            style.gap_fraction,
            style.max_gap_frames,
            &mut rng.fork(2 * i as u64 + 1),
        );
        punch_gaps(track, runs);
    }
    if style.layout == Layout::Motive {
        tracks = with_cluster_markers(tracks);
    }
    for (k, t) in truth_tracks.iter().enumerate() {
        swap_labels(
            &mut tracks,
            &t.label,
            style,
            &mut rng.fork(0x5A9 + k as u64),
        );
    }
    for t in &mut truth_tracks {
        // A stick of loose markers (`A+B+…`) has the gaps of each of them.
        let mut gaps: Vec<[usize; 2]> = t
            .label
            .split('+')
            .filter_map(|label| tracks.iter().find(|k| k.label == label))
            .flat_map(|track| track.gaps.iter().copied())
            .collect();
        gaps.sort_unstable();
        t.gaps = gaps;
    }
    let dropped = dropped_frames(frames, style.dropped_fraction, &mut rng.fork(u64::MAX));
    let rows = (0..frames)
        .filter(|f| dropped.binary_search(f).is_err())
        .collect();
    let out = OutTake {
        name: take.name.clone(),
        rate_hz: take.rate_hz,
        frames,
        rows,
        tracks,
        labels: take.labels.clone(),
    };
    let file = style.layout.file_name(&take.name);
    let text = write_layout(&out, style);
    let stick_labels: Vec<&str> = truth_tracks.iter().map(|t| t.label.as_str()).collect();
    let truth = Truth {
        files: vec![file.clone()],
        layout: style.layout,
        rate_hz: take.rate_hz,
        frames,
        first_frame_number: style.layout.first_frame_number(),
        dropped_frames: dropped,
        unit: style.written_unit().symbol().into(),
        up_axis: style.up.name().trim_start_matches('+').into(),
        lab: style.transform(),
        noise: Noise {
            position_m: style.position_noise_m,
            rotation_rad: style.rotation_noise_rad,
        },
        source: take.labels.clone(),
        other_labels: out
            .tracks
            .iter()
            .map(|t| t.label.clone())
            .filter(|l| !stick_labels.contains(&l.as_str()))
            .collect(),
        tracks: truth_tracks,
    };
    GeneratedCapture {
        files: vec![(file, text.into_bytes())],
        truth,
    }
}
