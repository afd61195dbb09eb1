//! `timpanist mocap synth | stats`: build the synthetic motion database and summarise a
//! database (per playing mode and grip, per dynamic, and joint limits).

use crate::base::ron_file::FileError;
use crate::body::skeleton::Joint;
use crate::kit::{Kit, Side};
use crate::mocap::align::{self, Transform};
use crate::mocap::db::MotionDb;
use crate::mocap::db::side_index;
use crate::mocap::import::profile::CaptureProfile;
use crate::mocap::import::{Format, LengthUnit};
use crate::mocap::ingest::{
    Alignment, IngestOptions, IngestReport, STICK_WORDS, UpAxis, hand_from_label, ingest,
};
use crate::mocap::take::{Take, extent_m};
use crate::mocap::{stats, synth, vertical};
use crate::score::{Dynamic, Grip};
use std::path::{Path, PathBuf};

/// Build the synthetic database into `dir`.
pub fn synth(dir: &Path, seed: u64) -> anyhow::Result<()> {
    let config = synth::SynthConfig {
        seed,
        ..synth::SynthConfig::default()
    };
    eprintln!(
        "synthesising {} takes…",
        config.grips.len() * config.modes.len() * config.locations.len() * config.hands.len()
    );
    let db = synth::synthesize(&config);
    std::fs::create_dir_all(dir).map_err(|e| anyhow::anyhow!("{}: {e}", dir.display()))?;
    db.save(dir)?;
    println!(
        "wrote {}: {} takes, {} motion units at {} Hz",
        dir.display(),
        db.index.takes.len(),
        db.index.units.len(),
        config.rate_hz
    );
    Ok(())
}

/// Table 1 of seed 000: joint-limit eigenvalues as printed.
const TABLE_1: [(&str, [f64; 3]); 4] = [
    ("neck", [5.7, 2.9, 2.3]),
    ("shoulder", [4.4, 2.7, 0.1]),
    ("elbow", [14.6, 8.9, 4.4]),
    ("wrist", [19.9, 9.1, 2.1]),
];

/// Print the statistics of the database in `dir`.
pub fn stats(dir: &Path) -> anyhow::Result<()> {
    let db = MotionDb::load(dir)?;
    println!(
        "{}: {} takes, {} units",
        dir.display(),
        db.index.takes.len(),
        db.index.units.len(),
    );
    for grip in [None, Some(Grip::French), Some(Grip::German)] {
        let rows = stats::by_mode(&db, grip);
        if rows.is_empty() {
            continue;
        }
        println!(
            "\n{}",
            grip.map_or("all grips".to_string(), |g| format!("{g:?} grip"))
        );
        println!(
            "  {:<16} {:>6} {:>10} {:>10} {:>12} {:>10}",
            "mode", "units", "height m", "depth m", "impact m/s", "stroke s"
        );
        for (mode, g) in rows {
            let m = g.mean;
            println!(
                "  {:<16} {:>6} {:>10.3} {:>10.3} {:>12.2} {:>10.3}",
                mode.name(),
                g.units,
                m.height_range_m,
                m.depth_range_m,
                m.impact_speed_mps,
                m.duration_s
            );
        }
    }
    println!("\nby dynamic");
    for d in [
        Dynamic::Pp,
        Dynamic::P,
        Dynamic::Mp,
        Dynamic::Mf,
        Dynamic::F,
        Dynamic::Ff,
    ] {
        let g = stats::group(&db, |u| u.dynamic.nearest_mark() == d.nearest_mark());
        if g.units > 0 {
            println!(
                "  {:<4} {:>6} units, height {:.3} m, impact {:.2} m/s",
                d.nearest_mark(),
                g.units,
                g.mean.height_range_m,
                g.mean.impact_speed_mps
            );
        }
    }
    for grip in [Grip::French, Grip::German] {
        print_limits(&db, grip);
    }
    Ok(())
}

/// Joint limits of one grip from the frames of its motion units (each arm only while it
/// plays), beside Table 1 of seed 000.
fn print_limits(db: &MotionDb, grip: Grip) {
    let limits = db.estimated_joint_limits(grip);
    if limits.iter().all(Option::is_none) {
        return;
    }
    println!(
        "\n{grip:?} grip joint limits (seed 000 Alg. 1): semi-axes of the bounding ellipsoid as rotation angles, degrees"
    );
    for (joint, limit) in Joint::ALL.into_iter().zip(limits) {
        let Some(limit) = limit else {
            continue;
        };
        let deg = limit.semi_axes.map(|a| (2.0 * a).to_degrees());
        let axes: Vec<String> = limit
            .axes
            .iter()
            .map(|a| format!("({:+.2} {:+.2} {:+.2})", a.x, a.y, a.z))
            .collect();
        let table = TABLE_1
            .iter()
            .find(|(n, _)| joint.name().starts_with(n))
            .map_or(String::new(), |(_, t)| {
                format!("   Table 1 as printed: {t:?}")
            });
        println!(
            "  {:<11} {:>6.1} {:>6.1} {:>6.1}   axes {}{table}",
            joint.name(),
            deg[0],
            deg[1],
            deg[2],
            axes.join(" ")
        );
    }
}

/// Which sticks `--tips` names.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum TipsArg {
    /// Not given: taken from the capture profile or the track labels.
    Unnamed,
    /// One label; its hand from `--hand`, the profile or the label itself.
    One(String),
    /// Left and right labels (either may be absent: "StickL," or ",StickR").
    Both(Option<String>, Option<String>),
}

/// What `mocap import` was asked to do.
pub struct ImportArgs {
    pub files: Vec<std::path::PathBuf>,
    pub format: Option<Format>,
    /// A capture profile (shipped name or RON file) for delimited text captures.
    pub profile: Option<String>,
    pub tips: TipsArg,
    pub up: Option<UpAxis>,
    pub unit: Option<String>,
    pub tip_offset_m: Option<glam::DVec3>,
    /// For a stick of loose markers: the tip's distance past the first, m.
    pub tip_past_m: Option<f64>,
    /// "none", "auto" or "x,y,z,yaw".
    pub align: String,
    /// The kit to align to (default: the standard set).
    pub kit: Option<std::path::PathBuf>,
    /// The drum the takes were played on (name or number; default: from the file name,
    /// else the drum in front of each hand).
    pub drum: Option<String>,
    /// Files come in pairs (left stick's file, right stick's file) of one take each.
    pub pair: bool,
    pub mode: Option<crate::score::PlayingMode>,
    pub location: Option<crate::score::ImpactLocation>,
    pub hand: Option<crate::kit::Side>,
    pub dynamic: Option<Dynamic>,
    pub grip: Option<Grip>,
    pub performer: String,
    pub output: std::path::PathBuf,
}

/// One take to ingest: read from one file, or two paired ones.
struct Source {
    path: PathBuf,
    /// The SHA-256 of the file's bytes (of a pair: the left's and the right's, `+`).
    sha256: String,
    take: Take,
    tips: [Option<String>; 2],
    up: UpAxis,
    tip_offset_m: Option<glam::DVec3>,
}

/// Import captures into the database at `args.output` (created if absent). Every file
/// is read, cut and aligned before anything is written, so a bad file leaves the database
/// as it was. A take from a file of the same name and bytes as one the database holds
/// replaces it; one from another file of the same name is added beside it.
pub fn import(args: ImportArgs) -> anyhow::Result<()> {
    let mut db = if args.output.join("index.ron").exists() {
        MotionDb::load(&args.output)?
    } else {
        MotionDb::empty("Imported motion captures")
    };
    let profile = args
        .profile
        .as_deref()
        .map(CaptureProfile::resolve)
        .transpose()?;
    // The shipped database, read once and only if needed: the alignment's habits, the
    // dynamics' speeds.
    let loaded = std::cell::OnceCell::new();
    let shipped = || loaded.get_or_init(crate::mocap::shipped::built_in).as_ref();
    let align = alignment(&args, &shipped)?;
    // Strokes without a dynamic label get the shipped performer's marking for their speed.
    let speeds = if args.dynamic.is_some() {
        Default::default()
    } else {
        shipped()
            .map(crate::mocap::ingest::dynamic_speeds)
            .unwrap_or_default()
    };
    let sources = if args.pair {
        if !args.files.len().is_multiple_of(2) {
            anyhow::bail!(
                "--pair takes the files two by two (left stick's file, right stick's file); {} files given",
                args.files.len()
            );
        }
        args.files
            .chunks(2)
            .map(|pair| paired_source(&pair[0], &pair[1], &args, profile.as_ref()))
            .collect::<anyhow::Result<Vec<_>>>()?
    } else {
        args.files
            .iter()
            .map(|path| single_source(path, &args, profile.as_ref(), None))
            .collect::<anyhow::Result<Vec<_>>>()?
    };
    for source in &sources {
        let options = IngestOptions {
            tips: source.tips.clone(),
            up: source.up,
            tip_offset_m: source.tip_offset_m,
            // Markers the user listed (`--tips A+B+…`) run from the tip.
            markers_from_tip: !matches!(args.tips, TipsArg::Unnamed),
            tip_past_first_m: args.tip_past_m,
            align: align.clone(),
            mode: args.mode,
            location: args.location,
            dynamic: args.dynamic,
            grip: args.grip,
            hand: args.hand,
            performer: args.performer.clone(),
            segment: Default::default(),
            dynamic_speeds: speeds.clone(),
        };
        // A take that cannot be imported still has its notes said: they often tell why.
        let mut report = ingest(&mut db, &source.path, &source.take, &options)
            .inspect_err(|_| print_notes(&source.path, &source.take.notes))?;
        report
            .notices
            .extend(db.settle_import(&source.path, &source.sha256));
        print_report(source, &report, &align);
        refuse_if_strokeless(&source.path, &source.take, &report)?;
        if matches!(align, Alignment::None) {
            warn_if_off_the_kit(&source.path, &report);
        }
    }
    std::fs::create_dir_all(&args.output)
        .map_err(|e| anyhow::anyhow!("{}: {e}", args.output.display()))?;
    db.save(&args.output)?;
    println!(
        "{}: {} takes, {} units",
        args.output.display(),
        db.index.takes.len(),
        db.index.units.len()
    );
    Ok(())
}

/// The alignment `--align` asks for, with the kit and drum it needs (`shipped`: the
/// shipped database, whose strokes the facing is read against).
fn alignment<'d>(
    args: &ImportArgs,
    shipped: &dyn Fn() -> Result<&'d MotionDb, &'d FileError>,
) -> anyhow::Result<Alignment> {
    match args.align.trim().to_ascii_lowercase().as_str() {
        "none" | "" => Ok(Alignment::None),
        "auto" => {
            let kit = match &args.kit {
                Some(path) => Kit::load(path)?,
                None => Kit::standard(),
            };
            let drum = args
                .drum
                .as_deref()
                .map(|name| find_drum(&kit, name))
                .transpose()?;
            let habits = match shipped() {
                Ok(db) => align::habits_of(db, &kit),
                Err(e) => {
                    eprintln!(
                        "note: {e}; the player is assumed to lift straight back toward themselves"
                    );
                    align::HabitBook::default()
                }
            };
            Ok(Alignment::Auto { kit, drum, habits })
        }
        text => Transform::parse(text)
            .map(Alignment::Manual)
            .map_err(|e| anyhow::anyhow!("--align: {e}; or \"auto\", or \"none\"")),
    }
}

/// A kit drum by name, by the number its name starts with, or by 1-based index.
fn find_drum(kit: &Kit, name: &str) -> anyhow::Result<usize> {
    let wanted = name.trim().to_lowercase();
    kit.drums
        .iter()
        .position(|d| {
            let lower = d.name.to_lowercase();
            lower == wanted || lower.split(|c: char| !c.is_ascii_digit()).next() == Some(&wanted)
        })
        .or_else(|| {
            wanted
                .parse::<usize>()
                .ok()
                .filter(|&i| (1..=kit.drums.len()).contains(&i))
                .map(|i| i - 1)
        })
        .ok_or_else(|| {
            let names: Vec<&str> = kit.drums.iter().map(|d| d.name.as_str()).collect();
            anyhow::anyhow!(
                "--drum: no drum \"{name}\" in the kit ({})",
                names.join(", ")
            )
        })
}

/// Read one capture with the profile or format given, with the format it was read as
/// (`None` through a profile).
fn read_take(
    path: &Path,
    args: &ImportArgs,
    profile: Option<&CaptureProfile>,
) -> anyhow::Result<(Take, Option<Format>)> {
    let unit = args.unit.as_deref();
    Ok(match profile {
        Some(p) => (
            crate::mocap::import::read_with_profile(path, p, unit)?,
            None,
        ),
        None => {
            let (take, format) = crate::mocap::import::read_detecting(path, args.format, unit)?;
            (take, Some(format))
        }
    })
}

/// The up axis: `--up`, else a profile file's (a lab's own, written for its session),
/// else found from the sticks' strokes (`mocap::vertical`), else the format's usual one
/// (a shipped profile's; Y for Motive and TRC, Z otherwise), with a note in the take
/// when the strokes overrule that or cannot tell.
fn up_axis(
    args: &ImportArgs,
    profile: Option<&CaptureProfile>,
    format: Option<Format>,
    take: &mut Take,
    tips: &[Option<String>; 2],
) -> UpAxis {
    let lab_profile = args
        .profile
        .as_deref()
        .is_some_and(|p| Path::new(p).is_file());
    let profile_up = profile.and_then(|p| p.up.map(UpAxis::from));
    if let Some(up) = args.up.or(profile_up.filter(|_| lab_profile)) {
        return up;
    }
    let usual = profile_up.unwrap_or(match format {
        // Motive and OpenSim (TRC) are Y up by convention; Vicon, Qualisys, C3D Z up.
        Some(Format::Motive | Format::Trc) => UpAxis::Y,
        _ => UpAxis::Z,
    });
    let tracks: Vec<&crate::mocap::Track> = tips
        .iter()
        .flatten()
        .flat_map(|label| label.split('+'))
        .filter_map(|label| take.track(label.trim()))
        .collect();
    let detection = vertical::detect(&tracks, take.rate_hz);
    let (up, note) = vertical::choose(usual, &detection);
    take.notes.extend(note);
    up
}

/// One file as one take; `only` restricts it to one hand (a file of a pair).
fn single_source(
    path: &Path,
    args: &ImportArgs,
    profile: Option<&CaptureProfile>,
    only: Option<Side>,
) -> anyhow::Result<Source> {
    let (mut take, format) = read_take(path, args, profile)?;
    let bytes = std::fs::read(path).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    let tips = resolve_tips(path, &take, args, profile, only)?;
    let used: Vec<String> = tips
        .iter()
        .flatten()
        .flat_map(|label| label.split('+'))
        .filter_map(|label| Some(take.track(label.trim())?.label.clone()))
        .collect();
    take.note_unused_duplicates(&used);
    let up = up_axis(args, profile, format, &mut take, &tips);
    Ok(Source {
        path: path.to_path_buf(),
        sha256: crate::mocap::db::file_sha256(&bytes),
        up,
        tip_offset_m: args
            .tip_offset_m
            .or_else(|| profile.and_then(CaptureProfile::tip_offset)),
        take,
        tips,
    })
}

/// Two files, the left stick's and the right stick's, as one take: same rate, aligned at
/// their first frames.
fn paired_source(
    left: &Path,
    right: &Path,
    args: &ImportArgs,
    profile: Option<&CaptureProfile>,
) -> anyhow::Result<Source> {
    let mut l = single_source(left, args, profile, Some(Side::Left))?;
    let r = single_source(right, args, profile, Some(Side::Right))?;
    if (l.take.rate_hz - r.take.rate_hz).abs() > 1e-6 * l.take.rate_hz {
        anyhow::bail!(
            "{} ({} Hz) and {} ({} Hz) cannot be paired: their rates differ",
            left.display(),
            l.take.rate_hz,
            right.display(),
            r.take.rate_hz
        );
    }
    let frames = l.take.frames.max(r.take.frames);
    let mut tracks = Vec::new();
    for (prefix, source) in [("left", &l), ("right", &r)] {
        for t in &source.take.tracks {
            let mut t = t.clone();
            t.label = format!("{prefix}:{}", t.label);
            t.positions.resize(frames, None);
            if !t.rotations.is_empty() {
                t.rotations.resize(frames, None);
            }
            tracks.push(t);
        }
    }
    // Each marker of a stick of loose markers (`A+B`) is prefixed too.
    let prefixed = |prefix: &str, label: String| {
        label
            .split('+')
            .map(|one| format!("{prefix}:{one}"))
            .collect::<Vec<_>>()
            .join("+")
    };
    l.tips = [
        l.tips[0].take().map(|t| prefixed("left", t)),
        r.tips[1].clone().map(|t| prefixed("right", t)),
    ];
    l.sha256 = format!("{}+{}", l.sha256, r.sha256);
    l.take = Take {
        source: left.to_path_buf(),
        rate_hz: l.take.rate_hz,
        frames,
        file_unit: l.take.file_unit.clone(),
        tracks,
        notes: l.take.notes.iter().chain(&r.take.notes).cloned().collect(),
    };
    Ok(l)
}

/// Each hand's track label for one take.
fn resolve_tips(
    path: &Path,
    take: &Take,
    args: &ImportArgs,
    profile: Option<&CaptureProfile>,
    only: Option<Side>,
) -> anyhow::Result<[Option<String>; 2]> {
    let hand_of = |label: &str| {
        profile
            .and_then(|p| p.hand_of(label))
            .or_else(|| hand_from_label(label))
    };
    let mut tips: [Option<String>; 2] = [None, None];
    let mut place = |side: Side, label: String| tips[side_index(side)] = Some(label);
    let fixed = only.or(args.hand);
    match &args.tips {
        TipsArg::Both(l, r) if only.is_none() => {
            tips = [l.clone(), r.clone()];
        }
        TipsArg::Both(l, r) => {
            let side = only.unwrap_or(Side::Left);
            let label = [l, r][side_index(side)]
                .clone()
                .ok_or_else(|| anyhow::anyhow!("--tips names no {side:?} stick"))?;
            place(side, label);
        }
        TipsArg::One(label) => {
            let side = fixed.or_else(|| hand_of(label)).ok_or_else(|| {
                anyhow::anyhow!(
                    "{}: which hand plays \"{label}\"? add --hand left or --hand right",
                    path.display()
                )
            })?;
            place(side, label.clone());
        }
        TipsArg::Unnamed => {
            // A label two tracks share is looked at once (and refused if taken).
            let mut labels = take.labels();
            let mut seen = std::collections::HashSet::new();
            labels.retain(|l| seen.insert(l.to_ascii_lowercase()));
            let sides: Vec<(Side, &str)> = labels
                .iter()
                .filter_map(|l| Some((hand_of(l)?, *l)))
                .collect();
            for side in [Side::Left, Side::Right] {
                let mine: Vec<&str> = sides.iter().filter(|s| s.0 == side).map(|s| s.1).collect();
                let sticks: Vec<&str> = mine.iter().copied().filter(|l| names_a_stick(l)).collect();
                // A lone hand-named track is the stick only if it says so, or if the
                // take holds nothing else (two tracks, `L` and `R`): a body's
                // `Daphnee:STER` reads as "right" too.
                let sticks_only = labels.len() <= 2;
                if let [one] = mine[..]
                    && (names_a_stick(one) || sticks_only)
                {
                    place(side, one.to_string());
                } else if let Some(label) = one_stick(take, &sticks) {
                    place(side, label);
                }
            }
            if let (Some(side), [one]) = (fixed, &labels[..]) {
                tips = [None, None];
                tips[side_index(side)] = Some(one.to_string());
            }
        }
    }
    if let Some(side) = fixed {
        tips[side_index(side.other())] = None;
    }
    if take.tracks.is_empty() {
        anyhow::bail!(
            "{}: the file holds no tracks (no marker or rigid body); nothing written",
            path.display()
        );
    }
    if tips.iter().all(Option::is_none) {
        anyhow::bail!(
            "{}: cannot tell which track is which stick; name them with --tips LEFT,RIGHT (or one label with --hand); the file has: {}",
            path.display(),
            take.labels().join(", ")
        );
    }
    Ok(tips)
}

/// A take none of whose sticks gave a stroke is not a stroke capture, or its sticks were
/// taken from the wrong tracks: refuse it (before anything is written) naming them.
fn refuse_if_strokeless(path: &Path, take: &Take, report: &IngestReport) -> anyhow::Result<()> {
    if report.hands.iter().any(|h| h.units > 0) {
        return Ok(());
    }
    if take.frames == 0 {
        anyhow::bail!(
            "{}: the file holds no frames; nothing written",
            path.display()
        );
    }
    let taken: Vec<String> = report
        .hands
        .iter()
        .map(|h| format!("{:?} \"{}\"", h.hand, h.label))
        .collect();
    let labels: Vec<&str> = report.hands.iter().map(|h| h.label.as_str()).collect();
    anyhow::bail!(
        "{}: no strokes found on the tracks taken as sticks ({}); if they are not the sticks, name them with --tips LEFT,RIGHT{}; nothing written",
        path.display(),
        taken.join(", "),
        unit_hint(take, &labels)
    )
}

/// When the tracks labelled `labels` span a range no stroking stick does (under 2 cm or
/// over 20 m along every axis, as read), the `--unit` that would give them a stick's
/// 0.3 m (", or if …"); else nothing.
fn unit_hint(take: &Take, labels: &[&str]) -> String {
    let span = take
        .tracks
        .iter()
        .filter(|t| labels.iter().any(|l| t.label.eq_ignore_ascii_case(l)))
        .filter_map(|t| extent_m(&t.positions))
        .fold(0.0f64, f64::max);
    if span <= 0.0 || (0.02..=20.0).contains(&span) {
        return String::new();
    }
    let Some(now) = LengthUnit::parse(&take.file_unit) else {
        return String::new();
    };
    let better = now.nearest_for(
        span,
        0.3,
        &[
            LengthUnit::Millimetre,
            LengthUnit::Centimetre,
            LengthUnit::Metre,
        ],
    );
    if better == now {
        return String::new();
    }
    format!(
        ", or if its lengths are not in {} (the sticks move {span:.3} m in all as read), give --unit {}",
        now.symbol(),
        better.symbol()
    )
}

/// A take kept in its own coordinates whose impacts are nowhere near a drum of the
/// standard kit was most likely captured in lab coordinates: say so.
fn warn_if_off_the_kit(path: &Path, report: &IngestReport) {
    let kit = Kit::standard();
    for h in &report.hands {
        let Some(c) = h.impact_centroid_m else {
            continue;
        };
        let on_a_drum = kit.drums.iter().any(|d| {
            c.truncate().distance(d.centre().truncate()) <= d.radius_m() + 0.1
                && (c.z - d.placement.head_height_m).abs() <= 0.15
        });
        if !on_a_drum {
            eprintln!(
                "note: {}: the {:?} stick's impacts lie around ({:.2}, {:.2}, {:.2}) m, on no drum of the standard kit: if the capture is in lab coordinates, import it with --align auto (or --align \"x,y,z,yaw\")",
                path.display(),
                h.hand,
                c.x,
                c.y,
                c.z
            );
        }
    }
}

/// The stick among one hand's stick-named tracks: the only one; else the only rigid
/// body; else the only tip marker; else, when all are plain markers, all of them as
/// one stick of loose markers (`A+B+…`, `mocap::marker_body`).
fn one_stick(take: &Take, sticks: &[&str]) -> Option<String> {
    let only = |keep: &dyn Fn(&str) -> bool| match sticks
        .iter()
        .filter(|l| keep(l))
        .collect::<Vec<_>>()[..]
    {
        [one] => Some(one.to_string()),
        _ => None,
    };
    let rigid = |label: &str| {
        take.track(label)
            .is_some_and(|t| t.rotations.iter().any(Option::is_some))
    };
    let tip = |label: &str| {
        let lower = label.to_ascii_lowercase();
        lower.contains("tip") || lower.contains("bead")
    };
    only(&|_| true)
        .or_else(|| only(&rigid))
        .or_else(|| only(&tip))
        .or_else(|| {
            (sticks.len() >= 2 && !sticks.iter().any(|l| rigid(l))).then(|| sticks.join("+"))
        })
}

/// Whether a track label names a stick or its tip (not an arm marker).
fn names_a_stick(label: &str) -> bool {
    let lower = label.to_ascii_lowercase();
    STICK_WORDS.iter().any(|w| lower.contains(w))
}

/// Print what one take gave.
fn print_report(source: &Source, report: &IngestReport, align: &Alignment) {
    let path = source.path.display();
    let drum_name = |d: usize| match align {
        Alignment::Auto { kit, .. } => kit.drums.get(d).map_or("?", |d| d.name.as_str()),
        _ => "?",
    };
    println!(
        "{path}: {} frames at {} Hz ({})",
        source.take.frames,
        // To the millihertz: a rate from a text file's times (1 / their median step)
        // prints as 200, not 200.00000000000426.
        (source.take.rate_hz * 1000.0).round() / 1000.0,
        source.take.file_unit
    );
    let t = report.transform;
    if t != Transform::IDENTITY {
        println!(
            "  aligned: turned {:.1}° about the vertical, moved ({:.3}, {:.3}, {:.3}) m",
            t.yaw_rad.to_degrees(),
            t.translation_m.x,
            t.translation_m.y,
            t.translation_m.z
        );
    }
    for h in &report.hands {
        let median = |x: Option<f64>, unit: &str, scale: f64| {
            x.map_or("-".into(), |x| format!("{:.2} {unit}", x * scale))
        };
        println!(
            "  {:?} stick \"{}\": {} impacts -> {} units{}; rejected: {}; {} missing frames ({} filled)",
            h.hand,
            h.label,
            h.impacts.len(),
            h.units,
            if h.units_with_gaps > 0 {
                format!(
                    " ({} more left out for a gap over 50 ms)",
                    h.units_with_gaps
                )
            } else {
                String::new()
            },
            h.rejected.summary(),
            h.missing_frames,
            h.filled_frames
        );
        println!(
            "    strokes: every {}, lift {}, impact speed {}",
            median(h.interval_s, "s", 1.0),
            median(h.lift_m, "cm", 100.0),
            median(h.impact_speed_mps, "m/s", 1.0)
        );
        if h.tip_estimate.is_some_and(|e| e.rests_on_priors()) {
            println!(
                "    the capture hardly tells where the tip is (the stick meets the head at nearly one angle): the estimate below leans on the priors ({})",
                if h.loose_markers {
                    "head 0.76 m above the floor, tip on the markers' axis 5 cm past them, or 0.30 m from their centre when they sit close together"
                } else {
                    "head 0.76 m above the floor, tip 0.30 m from the body origin; give --tip-offset if you know it"
                }
            );
        }
        if let Some(e) = &h.tip_estimate {
            println!(
                "    tip estimated at ({:.3}, {:.3}, {:.3}) m in the body frame (± {:.3}, {:.3}, {:.3}), height scatter {:.1} mm over {} impacts",
                e.offset_m.x,
                e.offset_m.y,
                e.offset_m.z,
                e.standard_error_m.x,
                e.standard_error_m.y,
                e.standard_error_m.z,
                e.residual_m * 1e3,
                e.impacts
            );
        }
        if let Some(f) = &h.fit {
            println!(
                "    on drum {} ({}): impacts {:.1} mm from the head plane (mean; max {:.1} mm), centre {:.1} cm from the target{}",
                f.drum + 1,
                drum_name(f.drum),
                f.plane_mean_m * 1e3,
                f.plane_max_m * 1e3,
                f.target_distance_m * 1e2,
                if f.off_head > 0 {
                    format!(", {} impacts off the head", f.off_head)
                } else {
                    String::new()
                }
            );
        }
    }
    print_notes(
        &source.path,
        source.take.notes.iter().chain(&report.notices),
    );
}

/// Print notes about the take read from `path` on stderr, one `note: FILE: …` line each.
fn print_notes<'a>(path: &Path, notes: impl IntoIterator<Item = &'a String>) {
    for note in notes {
        eprintln!("note: {}: {note}", path.display());
    }
}

/// Print how a delimited text capture is laid out, read with `profile` (default: a
/// profile that detects everything and finds "<name> X/Y/Z" tracks).
pub fn columns(file: &Path, profile: Option<&str>) -> anyhow::Result<()> {
    let profile = match profile {
        Some(p) => CaptureProfile::resolve(p)?,
        None => CaptureProfile::named("auto-detected"),
    };
    let bytes = std::fs::read(file).map_err(|e| anyhow::anyhow!("{}: {e}", file.display()))?;
    if Format::guess(file, &bytes) == Some(Format::C3d) {
        anyhow::bail!(
            "{}: a C3D file: `mocap columns` shows delimited text captures; C3D files name \
             their tracks themselves (`mocap import` lists them when it cannot tell the sticks)",
            file.display()
        );
    }
    let layout = crate::mocap::import::table::inspect(file, &bytes, &profile)?;
    println!(
        "{}: read with the profile \"{}\"",
        file.display(),
        profile.name
    );
    print!("{layout}");
    Ok(())
}

/// Write the lab-style test corpus into `dir`: one capture per layout from takes of the
/// shipped database (several modes and both hands), the Vicon one again as C3D, a Vicon
/// one whose stick is three loose shaft markers, and one from the real TrajOptDrums
/// stroke, with `truth.ron`.
pub fn corpus(dir: &Path, seed: u64) -> anyhow::Result<()> {
    use crate::mocap::labcorpus::{self, LabStyle, Layout};
    let db = crate::mocap::shipped::built_in()?;
    let takes = db.index.takes.len().max(1);
    let mut captures = Vec::new();
    for (k, layout) in Layout::ALL.into_iter().enumerate() {
        let style = LabStyle {
            seed: seed + k as u64,
            ..LabStyle::typical(layout)
        };
        captures.push(labcorpus::generate(&db, (k * 7 + 3) % takes, &style)?);
    }
    // C3D, the commonest lab file: a Vicon marker capture written again as C3D.
    if let Some(vicon) = captures.iter().find(|c| c.truth.layout == Layout::Vicon) {
        let (name, bytes) = &vicon.files[0];
        let take = crate::mocap::import::read_bytes(Path::new(name), bytes, Format::Vicon)?;
        let c3d_name = name.replace(".csv", ".c3d");
        let mut c3d = vicon.clone();
        c3d.files = vec![(c3d_name.clone(), crate::io::c3d_write::write_c3d(&take))];
        c3d.truth.files = vec![c3d_name];
        captures.push(c3d);
    }
    // A stick tracked by three loose markers on its shaft, no tip marker, no rigid body.
    let style = LabStyle {
        seed: seed + 11,
        stick_markers_m: LabStyle::on_the_shaft(&[0.06, 0.16, 0.26]),
        ..LabStyle::typical(Layout::Vicon)
    };
    captures.push(labcorpus::generate(&db, 17 % takes, &style)?.with_suffix("-shaft-markers"));
    let style = LabStyle {
        seed,
        ..LabStyle::typical(Layout::Trc)
    };
    captures.push(
        labcorpus::from_trajoptdrums(TRAJOPT_X, TRAJOPT_Y, &style, 12)
            .map_err(|e| anyhow::anyhow!("the TrajOptDrums stroke: {e}"))?,
    );
    labcorpus::write_all(dir, &captures)?;
    for c in &captures {
        for (name, _) in &c.files {
            println!("{}", dir.join(name).display());
        }
    }
    println!("{}", dir.join("truth.ron").display());
    Ok(())
}

/// The real drum stroke of Pearl's TrajOptDrums (MIT; `tests/fixtures/trajoptdrums/`).
const TRAJOPT_X: &str = include_str!("../../tests/fixtures/trajoptdrums/JointCenters_XPose_cm.csv");
const TRAJOPT_Y: &str = include_str!("../../tests/fixtures/trajoptdrums/JointCenters_YPose_cm.csv");
