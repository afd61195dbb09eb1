//! The whole-score render (and the property test over random scores): every demo score
//! sounds every stroke on time, renders bit-identically, never produces NaN or clipping;
//! randomised scores never make the physics explode; the body at a coarser step against the
//! 10 kHz reference. The CLI's render is in cli_render.rs.

use std::path::{Path, PathBuf};
use timpanist::base::rng::Rng;
use timpanist::body::control::rotation_error;
use timpanist::body::sim::{BodyStep, Motion, SimParams};
use timpanist::drum::ContactEvent;
use timpanist::kit::Kit;
use timpanist::mocap::db::MotionDb;
use timpanist::render::replay::replay;
use timpanist::render::strikes::RECONTACT_MIN_N;
use timpanist::render::{RenderError, RenderParams, Rendering, Resume, render, render_after};
use timpanist::score::{Beat, Dynamic, Hand, ImpactLocation, LoadedScore, PlayingMode, Score};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn db() -> MotionDb {
    MotionDb::load(&root().join("mocap")).unwrap()
}

fn demo_scores() -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(root().join("scores"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    v.sort();
    v
}

fn render_file(path: &Path, db: &MotionDb) -> Rendering {
    let loaded = LoadedScore::load(path).unwrap();
    render(&loaded, db, &RenderParams::default(), &mut |_| true)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Every scored stroke of every demo score yields a contact; over all of them the median
/// |contact − scheduled| is under 1 ms and the worst under 3 ms; peak forces are in the
/// range of real strikes; the audio is finite and never clips. The sticks rebound: at
/// most 1 % of the strokes (none measured of 302) are followed by the stick falling back
/// on the head with 5 N or more. Force follows the dynamic (see [`forces_follow_dynamics`]).
/// Every primary contact lasts 2–9 ms and at most 3 % outlast 8 ms (the issue asks every one
/// within 2–8 ms: 3 of 302 reach 8.0–8.4 ms, two free strokes on the 32-inch drum's slack
/// low head and one the arm presses on the 29-inch).
#[test]
fn demo_scores_strike_every_beat_on_time() {
    let db = db();
    let mut all = Vec::new();
    let mut recontacts = 0;
    let mut long = 0;
    let mut attempts = 0;
    for path in demo_scores() {
        let r = render_file(&path, &db);
        attempts += r.stats.attempts;
        assert_eq!(r.timing.missed, 0, "{}: {:?}", path.display(), r.timing);
        if path.ends_with("dynamics-ladder.ron") {
            forces_follow_dynamics(&r.events);
        }
        if path.ends_with("roll-exercise.ron") {
            // A roll's attempts resume from the latest state their targets leave
            // unchanged: 43.3 s simulated for its 13.2 s (59.8 s when every attempt
            // played the whole roll again); 50.6 s since the arms are pulled toward their
            // posture (`body::sim::ARM_POSTURE_PULL`, 2026-12-07), which moves every
            // stroke a little and the roll's compensation with it.
            let ratio = r.stats.simulated_s / r.stats.score_s;
            assert!(ratio < 4.0, "{ratio:.2} s simulated per score second");
        }
        for e in r.events.iter().filter(|e| e.beat.is_some()) {
            recontacts += usize::from(e.recontacts > 0);
            long += usize::from(e.duration_ms > 8.0 + 1e-6);
            all.push((e.contact_s - e.scheduled_s.unwrap()).abs());
            assert!(
                (5.0..300.0).contains(&e.peak_force_n) && (2.0..=8.0).contains(&e.duration_ms),
                "{}: {e:?}",
                path.display()
            );
        }
        assert!(
            r.audio
                .samples
                .iter()
                .all(|s| s.is_finite() && s.abs() <= 1.0),
            "{}",
            path.display()
        );
        assert!(
            r.audio.samples.iter().any(|s| s.abs() > 0.05),
            "{} is silent",
            path.display()
        );
    }
    // The arm no longer presses a stick on a head (before: 3 of 319 lasted 8.0–8.9 ms
    // with the 36 g mallet, 7 of 302 up to 8.8 ms with the 45 g one).
    assert_eq!(long, 0, "{long} of {} contacts over 8 ms", all.len());
    assert_timing("without joint limits", all, recontacts);
    // Strokes start from the most alike settled stroke and correct their depth by the
    // measured force-depth law, and stop when an attempt would repeat one: 516 attempts
    // (715 before the first two, 526 before the last).
    assert!(attempts <= 600, "{attempts} attempts over the demos");
}

/// The strokes' timing errors `all` (s): median under 1 ms, worst under 3 ms, and
/// re-contacts after at most 1 % of them.
fn assert_timing(what: &str, mut all: Vec<f64>, recontacts: usize) {
    all.sort_by(f64::total_cmp);
    let (median, worst) = (all[all.len() / 2], all[all.len() - 1]);
    println!(
        "{what}, {} strokes: median {median} s, worst {worst} s, {recontacts} with re-contacts",
        all.len()
    );
    assert!(
        median < 0.001 && worst < 0.003,
        "{what}: median {median} s, worst {worst} s"
    );
    assert!(
        recontacts * 100 <= all.len(),
        "{what}: {recontacts} of {} strokes",
        all.len()
    );
}

/// Four demo scores rendered holding their performer's joint limits
/// (`RenderParams::joint_limits`, not yet the default): every stroke sounds, median
/// timing under 1 ms and worst under 3 ms, re-contacts after at most 1 % of the strokes,
/// and the body stays within the limits — shoulders, elbows and wrists within 1.05 of
/// their ellipsoids (0.91 measured; rendered without the limits they reach 2–4), every
/// limited joint within 1.3 (the released grips' rebound: 1.06 measured). Fails if
/// renders asked to stop applying the limits. Not the other two: they render with the
/// limits on (every stroke sounds, no re-contact since a released grip has no stop), but
/// the minute study's neck reaches 1.41 of its ellipsoid and the tempo-change study's
/// released right grip 1.71 (README "Physics (HIMC)").
#[test]
fn demo_scores_hold_the_joint_limits() {
    let db = db();
    let params = RenderParams {
        joint_limits: true,
        ..RenderParams::default()
    };
    let (mut all, mut recontacts) = (Vec::new(), 0);
    let holding = [
        "dynamics-ladder",
        "etude-modes",
        "improvisation",
        "roll-exercise",
    ];
    for name in holding {
        let path = root().join("scores").join(format!("{name}.ron"));
        let loaded = LoadedScore::load(&path).unwrap();
        let r = render(&loaded, &db, &params, &mut |_| true)
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        assert_eq!(r.timing.missed, 0, "{}: {:?}", path.display(), r.timing);
        assert_joints_within_limits(&path, &r);
        for e in r.events.iter().filter(|e| e.beat.is_some()) {
            recontacts += usize::from(e.recontacts > 0);
            all.push((e.contact_s - e.scheduled_s.unwrap()).abs());
        }
    }
    assert_timing("with joint limits", all, recontacts);
}

/// Every limited joint of `r` within 1.3 of its ellipsoid and the arms' (shoulders,
/// elbows, wrists) within 1.05 over the whole performance; the limits are applied.
fn assert_joints_within_limits(path: &Path, r: &Rendering) {
    use timpanist::body::Joint;
    let limits = r.limits();
    assert!(
        limits.iter().filter(|l| l.is_some()).count() == limits.len(),
        "{}: the rendering did not hold the joint limits",
        path.display()
    );
    let arm = [
        Joint::ShoulderL,
        Joint::ElbowL,
        Joint::WristL,
        Joint::ShoulderR,
        Joint::ElbowR,
        Joint::WristR,
    ];
    for (j, limit) in limits.iter().enumerate() {
        let limit = limit.unwrap();
        let worst = r
            .motion
            .poses
            .iter()
            .map(|p| limit.radius(p[j]))
            .fold(0.0, f64::max);
        let joint = Joint::ALL[j];
        let bound = if arm.contains(&joint) { 1.05 } else { 1.3 };
        assert!(
            worst < bound,
            "{}: {} at {worst:.3} of its ellipsoid",
            path.display(),
            joint.name()
        );
    }
    let (joint, radius, at_s) = r.worst_joint_radius().unwrap();
    println!(
        "{}: worst joint {} at {radius:.2} of its ellipsoid at {at_s:.2} s",
        path.display(),
        joint.name()
    );
}

/// The ladder moved to the outer drums (the right hand on the 23-inch, the left on the
/// 32-inch, whose slack head swings back hardest): forces still follow the dynamics, no
/// stick falls back on a head, every contact lasts 2–8 ms, every stroke within 3 ms.
#[test]
fn ladder_on_the_outer_drums() {
    let mut loaded = LoadedScore::load(&root().join("scores/dynamics-ladder.ron")).unwrap();
    for beat in &mut loaded.score.beats {
        beat.drum = if beat.drum == 2 { 3 } else { 0 };
    }
    let r = render(&loaded, &db(), &RenderParams::default(), &mut |_| true).unwrap();
    assert_eq!(r.timing.missed, 0, "{:?}", r.timing);
    forces_follow_dynamics(&r.events);
    let scored: Vec<_> = r.events.iter().filter(|e| e.beat.is_some()).collect();
    assert!(scored.iter().all(|e| e.recontacts == 0), "re-contacts");
    assert!(
        scored.iter().all(|e| (2.0..=8.0).contains(&e.duration_ms)),
        "a contact outside 2–8 ms"
    );
    let worst = scored
        .iter()
        .map(|e| (e.contact_s - e.scheduled_s.unwrap()).abs())
        .fold(0.0, f64::max);
    assert!(worst < 0.003, "worst {worst} s");
}

/// The ladder at the bottom of the big drums' ranges (the left hand on the 32-inch drum in
/// D2, the right on the 29-inch in F2: the slackest heads, where a free stroke of the 45 g
/// mallet lasted 8–9 ms and the arm pressed others to 9.5 ms): every contact lasts
/// 2–8 ms, no stick falls back on a head, every stroke is within 3 ms and 20 % of its
/// (mode, dynamic) median, and the medians over the modes rise from pp to ff.
#[test]
fn ladder_at_the_bottom_of_the_big_drums() {
    let mut loaded = LoadedScore::load(&root().join("scores/dynamics-ladder.ron")).unwrap();
    for beat in &mut loaded.score.beats {
        (beat.drum, beat.pitch) = if beat.drum == 2 {
            (1, Some("F2".parse().unwrap()))
        } else {
            (0, Some("D2".parse().unwrap()))
        };
    }
    let r = render(&loaded, &db(), &RenderParams::default(), &mut |_| true).unwrap();
    assert_eq!(r.timing.missed, 0, "{:?}", r.timing);
    let scored: Vec<_> = r.events.iter().filter(|e| e.beat.is_some()).collect();
    assert!(scored.iter().all(|e| e.recontacts == 0), "re-contacts");
    for e in &scored {
        // Contacts last whole 0.1 ms steps: 8 ms may read 8.000000000000895.
        assert!((2.0..=8.0 + 1e-9).contains(&e.duration_ms), "{e:?}");
        assert!(
            (e.contact_s - e.scheduled_s.unwrap()).abs() < 0.003,
            "{e:?}"
        );
    }
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        0.5 * (v[(v.len() - 1) / 2] + v[v.len() / 2])
    };
    let mut previous = 0.0;
    for (_, _, name) in Dynamic::MARKS {
        let of_dynamic = |mode: Option<&str>| -> Vec<f64> {
            scored
                .iter()
                .filter(|e| e.dynamic == Some(name) && (mode.is_none() || e.mode == mode))
                .map(|e| e.peak_force_n)
                .collect()
        };
        let m = median(of_dynamic(None));
        assert!(m > previous, "{name}: {m:.1} N after {previous:.1} N");
        previous = m;
        for mode in PlayingMode::ALL {
            let forces = of_dynamic(Some(mode.name()));
            let group = median(forces.clone());
            for f in forces {
                assert!(
                    (f / group - 1.0).abs() <= 0.2,
                    "{mode:?} {name}: {f:.1} N of {group:.1}"
                );
            }
        }
    }
}

/// The dynamics ladder (every mode × pp…ff, both hands, two drums): per mode the median
/// peak force rises strictly from pp to ff, every stroke is within ±20 % of its (mode,
/// dynamic) median, ff's median is 60–110 N and pp's about a third of it (within 25–50 %).
fn forces_follow_dynamics(events: &[timpanist::render::strikes::StrikeEvent]) {
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        let n = v.len();
        0.5 * (v[(n - 1) / 2] + v[n / 2])
    };
    let scored: Vec<_> = events.iter().filter(|e| e.beat.is_some()).collect();
    let mut modes: Vec<&str> = scored.iter().filter_map(|e| e.mode).collect();
    modes.sort();
    modes.dedup();
    assert_eq!(modes.len(), PlayingMode::ALL.len());
    for mode in modes {
        let mut previous = 0.0;
        for (_, _, name) in Dynamic::MARKS {
            let forces: Vec<f64> = scored
                .iter()
                .filter(|e| e.mode == Some(mode) && e.dynamic == Some(name))
                .map(|e| e.peak_force_n)
                .collect();
            assert!(!forces.is_empty(), "{mode} {name}");
            let m = median(forces.clone());
            assert!(
                m > previous,
                "{mode} {name}: {m:.1} N after {previous:.1} N"
            );
            for f in &forces {
                assert!(
                    (f / m - 1.0).abs() <= 0.2,
                    "{mode} {name}: {f:.1} N, median {m:.1} N"
                );
            }
            previous = m;
        }
    }
    let of = |d: &str| {
        median(
            scored
                .iter()
                .filter(|e| e.dynamic == Some(d))
                .map(|e| e.peak_force_n)
                .collect(),
        )
    };
    let (pp, ff) = (of("pp"), of("ff"));
    assert!((60.0..=110.0).contains(&ff), "ff {ff:.1} N");
    assert!(
        (0.25..=0.5).contains(&(pp / ff)),
        "pp {pp:.1} N, ff {ff:.1} N"
    );
}

/// The same score renders the same audio and motion, bit for bit.
#[test]
fn render_is_deterministic() {
    let db = db();
    let path = root().join("scores/improvisation.ron");
    let (a, b) = (render_file(&path, &db), render_file(&path, &db));
    assert_eq!(a.audio.samples, b.audio.samples);
    assert_eq!(a.motion, b.motion);
    assert_eq!(a.events, b.events);
}

/// Random one-beat edits in the second half of two demo scores (a playing mode, a
/// dynamic, a drum — the outer drums lean the trunk —, a hand, a spot on the head, a
/// damp), each re-rendered from the unedited score's saved states and rendered whole:
/// the two give bit for bit the same audio, motion and contacts (or the same refusal).
/// What an edit changes ahead of the tips it moves (the lean did) shows here.
#[test]
fn random_edits_resume_as_whole_renders_do() {
    let db = db();
    let params = RenderParams::default();
    let mut rng = Rng::new(20261206);
    let mut resumed_count = 0;
    for name in ["pedal-changes.ron", "roll-exercise.ron"] {
        let loaded = LoadedScore::load(&root().join("scores").join(name)).unwrap();
        let mut before: Option<Resume> = None;
        render_after(&mut before, None, &loaded, &db, &params, &mut |_| true).unwrap();
        let beats = loaded.score.beats.len() as u64;
        for _ in 0..4 {
            let mut edited = loaded.clone();
            let i = (beats / 2 + below(&mut rng, beats - beats / 2)) as usize;
            let beat = &mut edited.score.beats[i];
            let what = below(&mut rng, 6);
            match what {
                0 => beat.mode = PlayingMode::ALL[below(&mut rng, 5) as usize],
                1 => beat.dynamic = Dynamic::MARKS[below(&mut rng, 6) as usize].0,
                2 => beat.drum = below(&mut rng, 4) as usize,
                3 => {
                    beat.hand = match beat.hand {
                        Hand::Left => Hand::Right,
                        _ => Hand::Left,
                    }
                }
                4 => {
                    beat.location =
                        [ImpactLocation::Centre, ImpactLocation::Rim][below(&mut rng, 2) as usize]
                }
                _ => beat.damp = Some(240 * (1 + below(&mut rng, 4))),
            }
            let case = format!("{name}: beat {i}, edit {what}");
            let whole = render(&edited, &db, &params, &mut |_| true);
            let mut resume = before.clone();
            let resumed = render_after(&mut resume, None, &edited, &db, &params, &mut |_| true);
            match (whole, resumed) {
                (Ok(whole), Ok(resumed)) => {
                    resumed_count += usize::from(resumed.stats.resumed_from_s.is_some());
                    assert_same_performance(&resumed, &whole, &case);
                }
                (Err(a), Err(b)) => assert_eq!(a.to_string(), b.to_string(), "{case}"),
                (a, b) => panic!("{case}: whole {:?}, resumed {:?}", a.err(), b.err()),
            }
        }
    }
    assert!(resumed_count >= 4, "{resumed_count} of 8 edits resumed");
}

/// The sound made on the other core while the body is simulated (every
/// `render::SOUND_AHEAD_S` of settled score, resuming its state) is bit for bit the sound
/// made afresh from the finished performance: with hands damping heads (the secco study)
/// and across tempo changes.
#[test]
fn sound_made_beside_the_simulation_equals_one_made_after_it() {
    let db = db();
    for name in ["secco-study.ron", "tempo-change.ron"] {
        let r = render_file(&root().join("scores").join(name), &db);
        let comp = &r.composition;
        let end_s = comp.time(comp.len() - 1) + r.params.tail_s;
        // Long enough for the sound to have been made beside the simulation twice.
        assert!(
            end_s - r.start_s > 2.0 * timpanist::render::SOUND_AHEAD_S,
            "{name}: {end_s} s"
        );
        let (fresh, _) = timpanist::sound::render_touched(
            &r.kit,
            &r.drums,
            &r.touches,
            end_s.max(0.0),
            r.params.sound,
            None,
        )
        .unwrap();
        assert_eq!(fresh.gain, r.audio.gain, "{name}");
        assert!(
            fresh.samples == r.audio.samples,
            "{name}: the sounds differ"
        );
    }
}

/// After a one-beat edit late in a score, resuming the previous rendering's performance
/// from a saved state before the edit gives bit for bit what rendering the edited score
/// from scratch gives (audio, motion, targets, events), simulating less; an edit at the
/// first beat resumes (if at all) no later than it.
#[test]
fn resumed_render_after_an_edit_equals_a_whole_render() {
    let db = db();
    let loaded = LoadedScore::load(&root().join("scores/tempo-change.ron")).unwrap();
    let params = RenderParams::default();
    let mut after_before: Option<Resume> = None;
    let before = render_after(&mut after_before, None, &loaded, &db, &params, &mut |_| {
        true
    })
    .unwrap();
    let late = loaded.score.beats.len() * 3 / 4;
    for (beat, resumes) in [(late, true), (0, false)] {
        let mut edited = loaded.clone();
        let b = &mut edited.score.beats[beat];
        b.dynamic = if b.dynamic == Dynamic::Ff {
            Dynamic::P
        } else {
            Dynamic::Ff
        };
        let whole = render(&edited, &db, &params, &mut |_| true).unwrap();
        let mut resume = after_before.clone();
        let resumed =
            render_after(&mut resume, None, &edited, &db, &params, &mut |_| true).unwrap();
        assert!(resumed.complete);
        let edit_s = whole
            .composition
            .strokes
            .iter()
            .find(|s| s.beat == beat)
            .unwrap()
            .time_s;
        if let Some(from) = resumed.stats.resumed_from_s {
            assert!(from < edit_s, "resumed at {from} s, edit at {edit_s} s");
        }
        if resumes {
            let from = resumed.stats.resumed_from_s.expect("a late edit resumes");
            assert!(from > 0.5, "resumed at {from} s, edit at {edit_s} s");
            assert!(resumed.stats.simulated_s < 0.8 * whole.stats.simulated_s);
            // The audio before the resume point is the earlier rendering's own chunks,
            // not a copy: the edit leaves the score's loudest peak, and so the
            // normalisation gain, as it was, and nothing before the resume is rewritten.
            assert_eq!(resumed.audio.gain, before.audio.gain);
            let shared = resumed.audio.samples.shared_chunks(&before.audio.samples);
            // Audio frame 0 is score time 0 (the lead-in before it is silent).
            let before_from = (from - 1.0).floor().max(0.0) as usize;
            let chunks = resumed.audio.samples.chunks().count();
            println!("{shared} of {chunks} one-second chunks shared, resumed at {from:.2} s");
            assert!(
                shared >= before_from && shared < chunks,
                "{shared} of {chunks}"
            );
            // So is the motion before it (the poses, in chunks of MOTION_CHUNK samples).
            let poses = &resumed.motion.poses;
            let shared = poses.shared_chunks(&before.motion.poses);
            let chunk_s = timpanist::body::sim::MOTION_CHUNK as f64 / resumed.motion.rate_hz;
            let before_from = ((from - whole.start_s) / chunk_s).floor() as usize;
            println!("{shared} pose chunks shared, {before_from} before the resume at {from:.2} s");
            assert!(
                shared >= before_from && shared < poses.chunks().count(),
                "{shared} pose chunks shared, resumed at {from:.2} s"
            );
        }
        assert_eq!(resumed.audio.samples, whole.audio.samples, "beat {beat}");
        assert_eq!(resumed.motion, whole.motion, "beat {beat}");
        assert_eq!(resumed.reference.tips, whole.reference.tips, "beat {beat}");
        assert_eq!(resumed.events, whole.events, "beat {beat}");
        assert_ne!(
            whole.audio.samples, before.audio.samples,
            "the edit is heard"
        );
    }
}

/// A partial rendering that stops shortly after the resume point has final audio up to
/// its `ready_s`, the same as the whole rendering's; resuming from it completes the
/// score bit for bit as a whole rendering does.
#[test]
fn partial_render_then_rest_equals_a_whole_render() {
    let (db, loaded, params, mut resume) = tempo_change_rendered();
    let mut edited = loaded.clone();
    let beat = edited.score.beats.len() / 2;
    edited.score.beats[beat].mode = PlayingMode::Staccato;
    let whole = render(&edited, &db, &params, &mut |_| true).unwrap();
    let partial =
        render_after(&mut resume, Some(0.3), &edited, &db, &params, &mut |_| true).unwrap();
    let from = partial.stats.resumed_from_s.expect("resumes");
    assert!(!partial.complete);
    assert!(
        partial.ready_s > from + 0.2 && partial.ready_s < whole.ready_s - 0.5,
        "resumed at {from} s, ready to {} s",
        partial.ready_s
    );
    let ready = 2 * (partial.ready_s * 48_000.0) as usize;
    // The whole score may peak louder after the partial's end, so its mix can be scaled
    // down more: under the same gain the samples are bit for bit the same, else the mixes
    // before the gain are (each sample rounded once to f32 after the gain: 2^-24 each).
    let (a, b) = (&partial.audio, &whole.audio);
    if a.gain == b.gain {
        assert_eq!(a.samples.to_vec_of(0..ready), b.samples.to_vec_of(0..ready));
    }
    let first_off = (0..ready).find(|&k| {
        let (x, y) = (
            f64::from(a.samples[k]) / a.gain,
            f64::from(b.samples[k]) / b.gain,
        );
        (x - y).abs() > 2.5e-7 * x.abs().max(y.abs()) + 1e-12
    });
    assert_eq!(first_off, None, "gains {} and {}", a.gain, b.gain);
    let rest = render_after(&mut resume, None, &edited, &db, &params, &mut |_| true).unwrap();
    assert!(rest.complete && rest.stats.resumed_from_s.is_some());
    assert_same_performance(&rest, &whole, "the rest after a partial rendering");
}

/// The tempo-change demo rendered with the default parameters, and what it leaves to
/// resume from.
fn tempo_change_rendered() -> (MotionDb, LoadedScore, RenderParams, Option<Resume>) {
    let db = db();
    let loaded = LoadedScore::load(&root().join("scores/tempo-change.ron")).unwrap();
    let params = RenderParams::default();
    let mut resume = None;
    render_after(&mut resume, None, &loaded, &db, &params, &mut |_| true).unwrap();
    (db, loaded, params, resume)
}

/// Bit for bit the same audio, motion and contacts.
/// `a` and `b` sound, move and strike bit for bit the same (`case` names them on failure;
/// the audio and motion are compared whole, not printed).
fn assert_same_performance(a: &Rendering, b: &Rendering, case: &str) {
    assert!(
        a.audio.samples == b.audio.samples,
        "{case}: the audio differs"
    );
    assert!(a.motion == b.motion, "{case}: the motion differs");
    assert_eq!(a.events, b.events, "{case}");
}

/// A rendering cancelled part way (the editor cancels one at each newer edit) leaves a
/// state the next rendering resumes from: after it, rendering another edit gives bit for
/// bit what rendering that edit whole gives.
#[test]
fn rendering_after_a_cancelled_one_equals_a_whole_render() {
    let (db, loaded, params, mut resume) = tempo_change_rendered();
    let beats = loaded.score.beats.len();
    let mut first = loaded.clone();
    first.score.beats[beats / 2].mode = PlayingMode::Staccato;
    let mut calls = 0;
    let cancelled = render_after(&mut resume, None, &first, &db, &params, &mut |p| {
        calls += 1;
        p.stage != "simulating" || calls < 40
    });
    assert!(
        matches!(cancelled, Err(RenderError::Cancelled)),
        "{cancelled:?}"
    );
    let mut second = first.clone();
    second.score.beats[beats * 3 / 4].dynamic = Dynamic::Pp;
    let whole = render(&second, &db, &params, &mut |_| true).unwrap();
    let resumed = render_after(&mut resume, None, &second, &db, &params, &mut |_| true).unwrap();
    assert!(resumed.stats.resumed_from_s.is_some(), "it resumes");
    assert_same_performance(
        &resumed,
        &whole,
        "rendering after a cancelled one equals a whole render",
    );
}

/// A uniform integer in 0..n.
fn below(rng: &mut Rng, n: u64) -> u64 {
    rng.next_u64() % n
}

/// A random short score: 1–4 beats on random drums, hands, modes, dynamics and locations
/// at a random tempo.
fn random_score(rng: &mut Rng, kit: &Kit) -> Score {
    let mut score = Score::new("random");
    score.tempo[0].bpm = rng.uniform(50.0, 200.0).round();
    let tpq = u64::from(score.ticks_per_quarter);
    let mut tick = tpq;
    let beats = 1 + below(rng, 4);
    for _ in 0..beats {
        let mut beat = Beat::plain(tick, below(rng, kit.drums.len() as u64) as usize);
        beat.hand = [Hand::Auto, Hand::Left, Hand::Right][below(rng, 3) as usize];
        beat.mode = PlayingMode::ALL[below(rng, 5) as usize];
        beat.dynamic = Dynamic::MARKS[below(rng, 6) as usize].0;
        beat.location = [
            ImpactLocation::Centre,
            ImpactLocation::PlayingSpot,
            ImpactLocation::Rim,
        ][below(rng, 3) as usize];
        score.beats.push(beat);
        tick += tpq / 2 * (1 + below(rng, 4));
    }
    score
}

/// No NaN and no silent explosion over 1000 randomised scores simulated through HIMC
/// with the drums (one pass each, so every stroke's physics runs once): each renders
/// finite motion and audio, or is refused before simulating (a stroke too fast to
/// compose, or out of the hand's reach), or stops because the body lost control, naming
/// the beat (counted, and bounded).
#[test]
fn randomised_scores_never_explode() {
    let db = db();
    let kit = Kit::standard();
    let root_rng = Rng::new(2026);
    let params = RenderParams {
        max_attempts: 1,
        tail_s: 0.1,
        compose: timpanist::motion::compose::ComposeParams {
            margin_s: 0.15,
            ..Default::default()
        },
        ..RenderParams::default()
    };
    let threads = 2;
    let (rendered, lost, out_of_reach) = std::thread::scope(|scope| {
        let handles: Vec<_> = (0..threads)
            .map(|t| {
                let (db, kit, params, root_rng) = (&db, &kit, &params, &root_rng);
                scope.spawn(move || {
                    let (mut ok, mut lost, mut out_of_reach) = (0, 0, 0);
                    for i in (t..1000).step_by(threads) {
                        let mut rng = root_rng.fork(i as u64);
                        let loaded = LoadedScore {
                            score: random_score(&mut rng, kit),
                            kit: kit.clone(),
                            kit_source: "standard".into(),
                            notices: Vec::new(),
                        };
                        match render(&loaded, db, params, &mut |_| true) {
                            Ok(r) => {
                                assert!(
                                    r.motion.poses.iter().flatten().all(|q| q.is_finite())
                                        && r.audio.samples.iter().all(|s| s.is_finite()),
                                    "score {i}: non-finite output"
                                );
                                ok += 1;
                            }
                            Err(RenderError::Compose(_)) => {}
                            Err(RenderError::OutOfReach(_)) => out_of_reach += 1,
                            Err(RenderError::Diverged {
                                beat: Some(_),
                                what,
                                ..
                            }) if what.starts_with("lost control") => lost += 1,
                            Err(e) => panic!("score {i}: {e}\n{:?}", loaded.score.beats),
                        }
                    }
                    (ok, lost, out_of_reach)
                })
            })
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().unwrap())
            .fold((0, 0, 0), |a, b| (a.0 + b.0, a.1 + b.1, a.2 + b.2))
    });
    println!(
        "{rendered} of 1000 random scores rendered, {out_of_reach} refused as out of reach, \
         {lost} stopped losing control"
    );
    // Measured: 843 rendered, 156 out of reach (random hands for random drums and spots,
    // many across the body), one lost control; before the trunk leaned toward far strokes
    // (`body::lean`), 593 rendered, 407 out of reach, none lost control.
    assert!(rendered > 500, "only {rendered} of 1000 rendered");
    assert!(lost <= 10, "{lost} of 1000 lost control");
}

/// A roll on each outer drum of the standard kit (the 32-inch at the player's left, the
/// 23-inch at the right), which takes the far hand across the body beyond its upright
/// reach: the trunk leans toward the drum (`body::lean`) and every stroke sounds on time
/// (worst under 3 ms), with no stick falling back on the head and the roll's forces
/// within 25 % of their aim; the trunk is upright before the lean sets in and leans by
/// 5–30° during the roll (the lean 23° at most, the IK turning it a little more).
/// Before the lean, both rolls were refused as out of reach; with
/// the reach check lifted but no lean, the 32-inch roll missed 4 of its 18 strokes.
#[test]
fn rolls_on_the_outer_drums_lean_toward_them() {
    use timpanist::score::Roll;
    let db = db();
    for drum in [0, 3] {
        let mut score = Score::new("outer roll");
        score.tempo[0].bpm = 80.0;
        score.beats.push(Beat::plain(0, drum));
        let mut roll = Beat::plain(960, drum);
        roll.dynamic = Dynamic::P;
        roll.roll = Some(Roll {
            length_ticks: 1920,
            strokes_per_quarter: 8,
        });
        score.beats.push(roll);
        let mut last = Beat::plain(2880, drum);
        last.mode = PlayingMode::Accent;
        last.dynamic = Dynamic::F;
        score.beats.push(last);
        let loaded = LoadedScore::from_score(&root().join("outer.ron"), score).unwrap();
        let r = render(&loaded, &db, &RenderParams::default(), &mut |_| true)
            .unwrap_or_else(|e| panic!("drum {drum}: {e}"));
        assert_eq!(r.timing.missed, 0, "drum {drum}: {:?}", r.timing);
        assert!(r.timing.worst_abs_s < 0.003, "drum {drum}: {:?}", r.timing);
        let rolled: Vec<_> = r.events.iter().filter(|e| e.beat == Some(1)).collect();
        assert_eq!(rolled.len(), 16, "drum {drum}: the roll's strokes");
        let aim = RenderParams::default().force_aim_n(Dynamic::P);
        for e in &rolled {
            assert!(e.recontacts == 0, "drum {drum}: {e:?}");
            assert!(
                (e.peak_force_n / aim - 1.0).abs() < 0.25,
                "drum {drum}: {} N for {aim} N",
                e.peak_force_n
            );
        }
        let lean_deg = |t: f64| {
            let k = (((t - r.start_s) * r.motion.rate_hz).round() as usize)
                .min(r.motion.poses.len() - 1);
            let trunk = r.motion.poses[k][timpanist::body::Joint::Trunk.index()];
            trunk.angle_between(glam::DQuat::IDENTITY).to_degrees()
        };
        let roll_s = loaded.score.tempo_map().seconds_at(1920.0);
        let (before, during) = (lean_deg(r.start_s + 0.05), lean_deg(roll_s));
        println!("drum {drum}: trunk {before:.1}° before, {during:.1}° during the roll");
        assert!(
            before < 1.0,
            "drum {drum}: leaning {before:.1}° at the start"
        );
        assert!((5.0..=30.0).contains(&during), "drum {drum}: {during:.1}°");
    }
}

/// An edit that makes the trunk lean (eight of a run of sixteenths on the 26-inch drum,
/// hands alternating, moved to the 32-inch drum) changes the lean before the edited
/// strokes' own paths do — the lean is held 0.3 s and eased ahead of the far strokes — so
/// a rendering resumed after it must resume before the lean changes: it gives bit for bit
/// what rendering the edited score whole gives (before the resume compared the lean, it
/// resumed at 4.80 s, after the lean had begun, and the audio differed).
#[test]
fn an_edit_that_leans_resumes_as_a_whole_render_does() {
    let db = db();
    let mut score = Score::new("lean edit");
    score.tempo[0].bpm = 80.0;
    score.beats = (0..40u64)
        .map(|k| {
            let mut b = Beat::plain(k * 240, 2);
            b.hand = if k % 2 == 0 { Hand::Right } else { Hand::Left };
            b
        })
        .collect();
    let loaded = LoadedScore::from_score(&root().join("lean-edit.ron"), score).unwrap();
    let params = RenderParams::default();
    let mut resume: Option<Resume> = None;
    render_after(&mut resume, None, &loaded, &db, &params, &mut |_| true).unwrap();
    let mut edited = loaded.clone();
    for b in &mut edited.score.beats[28..36] {
        b.drum = 0;
    }
    let whole = render(&edited, &db, &params, &mut |_| true).unwrap();
    let resumed = render_after(&mut resume, None, &edited, &db, &params, &mut |_| true).unwrap();
    let leaned = |r: &Rendering| {
        r.motion
            .poses
            .iter()
            .map(|p| p[timpanist::body::Joint::Trunk.index()].angle_between(glam::DQuat::IDENTITY))
            .fold(0.0, f64::max)
            .to_degrees()
    };
    assert!(leaned(&whole) > 5.0, "leans {:.1}°", leaned(&whole));
    let from = resumed.stats.resumed_from_s.expect("the edit resumes");
    println!("resumed at {from:.2} s; leaning {:.1}°", leaned(&whole));
    assert_same_performance(
        &resumed,
        &whole,
        "an edit that leans resumes as a whole render does",
    );
}

/// The head follows the hands: before each stroke that moves to another drum after a
/// pause (0.6 s or more), the simulated face is turned toward that stroke's point on its
/// head — its bearing from the pelvis, as far as the neck and head turn (70°; the eyes
/// do the rest), within 15° 50 ms before the stroke — and the face turns by tens of
/// degrees over the study (it is not simply held still).
#[test]
fn the_face_turns_to_the_drum_about_to_be_struck() {
    let db = db();
    let r = render_file(&root().join("scores/minute-study.ron"), &db);
    let skeleton = r.skeleton();
    let yaw = |v: glam::DVec3| (-v.x).atan2(v.y).to_degrees();
    let face_at = |t: f64| {
        let k =
            (((t - r.start_s) * r.motion.rate_hz).round() as usize).min(r.motion.poses.len() - 1);
        let frames = skeleton.forward(&r.motion.poses[k]);
        let neck = timpanist::body::Joint::Neck.index();
        let head = timpanist::body::Joint::Head.index();
        (
            frames.rotation[head] * glam::DVec3::Y,
            frames.position[neck],
        )
    };
    let strokes = &r.composition.strokes;
    let (mut checked, mut worst, mut span) = (0, 0.0f64, (f64::INFINITY, f64::NEG_INFINITY));
    for pair in strokes.windows(2) {
        let (before, s) = (&pair[0], &pair[1]);
        let (face, pelvis) = face_at(s.time_s - 0.05);
        span = (span.0.min(yaw(face)), span.1.max(yaw(face)));
        if s.drum == before.drum || s.time_s - before.time_s < 0.6 {
            continue;
        }
        // The face turns at most MAX_YAW_RAD off the body's front (the eyes do the rest).
        let most = timpanist::body::gaze::MAX_YAW_RAD.to_degrees();
        let off = (yaw(face) - yaw(s.target - pelvis).clamp(-most, most)).abs();
        worst = worst.max(off);
        checked += 1;
    }
    println!("{checked} drum changes: face within {worst:.1}° of the drum; yaw {span:?}°");
    assert!(checked >= 5, "only {checked} drum changes checked");
    assert!(
        worst < 15.0,
        "the face was {worst:.1}° off the drum about to be struck"
    );
    assert!(span.1 - span.0 > 20.0, "the face hardly turns: {span:?}");
}

/// A long fast passage: 75 s of sixteenths at 120 bpm going round all four drums in
/// every mode. Until the arms were pulled back toward their posture (`body::sim::
/// ARM_POSTURE_PULL`) their redundancy drifted stroke after stroke, and after a minute
/// the flailing arms shook the trunk and head off their targets and 55 of the last 250
/// strokes found no head. Every stroke sounds, and the head is still held near its target
/// over the last ten seconds as over the first.
#[test]
fn a_long_fast_passage_plays_to_the_end() {
    let mut score = Score::new("long fast passage");
    score.tempo[0].bpm = 120.0;
    let sixteenth = u64::from(score.ticks_per_quarter) / 4;
    let dynamics = [Dynamic::P, Dynamic::Mf, Dynamic::F];
    for i in 0..600u64 {
        let mut beat = Beat::plain(i * sixteenth, [1, 2, 1, 2, 0, 3][(i % 6) as usize]);
        beat.mode = PlayingMode::ALL[(i % 5) as usize];
        beat.dynamic = dynamics[((i / 7) % 3) as usize];
        score.beats.push(beat);
    }
    let loaded = LoadedScore::from_score(&root().join("long-passage.ron"), score).unwrap();
    let r = render(&loaded, &db(), &RenderParams::default(), &mut |_| true).unwrap();
    assert!(r.missed_beats.is_empty(), "missed {:?}", r.missed_beats);
    assert_eq!(r.timing.missed, 0, "{:?}", r.timing);
    // The neck's and head's turns (off their rest), largest per window: the gaze turns
    // them by 10–25°; the run that lost the strokes had them at 100°.
    let turned = |from_s: f64, to_s: f64| {
        let rate = r.motion.rate_hz;
        let (a, b) = ((from_s * rate) as usize, (to_s * rate) as usize);
        let joints = [timpanist::body::Joint::Neck, timpanist::body::Joint::Head];
        (a..b.min(r.motion.poses.len()))
            .flat_map(|k| joints.map(|j| r.motion.poses[k][j.index()]))
            .map(|q| {
                rotation_error(glam::DQuat::IDENTITY, q)
                    .length()
                    .to_degrees()
            })
            .fold(0.0, f64::max)
    };
    let (first, last) = (turned(2.0, 12.0), turned(63.0, 73.0));
    println!("neck and head turned at most {first:.1}° (first 10 s), {last:.1}° (last 10 s)");
    assert!(
        last < 40.0 && last < first + 10.0,
        "{first:.1}° then {last:.1}°"
    );
}

/// The contacts of at least [`RECONTACT_MIN_N`] (grazes below it come and go with any
/// change).
fn recontact_sized(contacts: &[ContactEvent]) -> Vec<&ContactEvent> {
    contacts
        .iter()
        .filter(|c| c.peak_force_n >= RECONTACT_MIN_N)
        .collect()
}

/// [`recontact_sized`] hand by hand, each in time order (two hands striking at once may
/// start in either order).
fn by_hand(contacts: &[ContactEvent]) -> Vec<&ContactEvent> {
    let mut v = recontact_sized(contacts);
    v.sort_by(|x, y| {
        (x.side as u8)
            .cmp(&(y.side as u8))
            .then(x.start_s.total_cmp(&y.start_s))
    });
    v
}

/// How far two simulations of the same targets are apart: the tip paths (largest RMS
/// over the tips, and at worst), and over the contacts of 5 N or more (the same drum and
/// hand, one for one, each hand's in time order) the largest difference of start or length and of peak force.
#[derive(Clone, Copy, Debug, Default)]
struct Apart {
    rms_m: f64,
    /// The median distance of the tips (the larger hand's), m: the step's systematic
    /// error, which one rebound gone another way does not sway.
    median_m: f64,
    worst_m: f64,
    contact_s: f64,
    force: f64,
}

impl Apart {
    fn between(name: &str, a: (&Motion, &[ContactEvent]), b: (&Motion, &[ContactEvent])) -> Apart {
        let mut apart = Apart::default();
        for (x, y) in a.0.tips.iter().zip(&b.0.tips) {
            assert_eq!(x.len(), y.len(), "{name}");
            let mut squares = 0.0;
            let mut distances = Vec::with_capacity(x.len());
            for (p, q) in x.iter().zip(y) {
                apart.worst_m = apart.worst_m.max(p.distance(*q));
                squares += p.distance_squared(*q);
                distances.push(p.distance(*q));
            }
            apart.rms_m = apart.rms_m.max((squares / x.len() as f64).sqrt());
            distances.sort_by(f64::total_cmp);
            let median = distances.get(distances.len() / 2).copied().unwrap_or(0.0);
            apart.median_m = apart.median_m.max(median);
        }
        let (ra, rb) = (by_hand(a.1), by_hand(b.1));
        assert_eq!(ra.len(), rb.len(), "{name}: contacts of 5 N or more");
        for (r, f) in ra.iter().zip(&rb) {
            assert_eq!((r.side, r.drum), (f.side, f.drum), "{name}");
            let start = (r.start_s - f.start_s).abs();
            let length = (r.duration_s() - f.duration_s()).abs();
            apart.contact_s = apart.contact_s.max(start).max(length);
            apart.force = apart
                .force
                .max((f.peak_force_n / r.peak_force_n - 1.0).abs());
        }
        apart
    }

    fn max(self, o: Apart) -> Apart {
        Apart {
            rms_m: self.rms_m.max(o.rms_m),
            median_m: self.median_m.max(o.median_m),
            worst_m: self.worst_m.max(o.worst_m),
            contact_s: self.contact_s.max(o.contact_s),
            force: self.force.max(o.force),
        }
    }
}

impl std::fmt::Display for Apart {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "tip paths {:.2} mm RMS, {:.3} mm median, {:.2} mm at worst; contact times {:.2} ms; peak forces {:.1} %",
            self.rms_m * 1e3,
            self.median_m * 1e3,
            self.worst_m * 1e3,
            self.contact_s * 1e3,
            self.force * 100.0
        )
    }
}

/// The reference's settings at another contact rate (the nested IK kept at 2.5 kHz) and
/// `contact_substeps` contact steps per body step.
fn stepped(sim: &SimParams, hz: f64, contact_substeps: usize) -> SimParams {
    SimParams {
        sim_hz: hz,
        nested_every: (sim.nested_every as f64 * hz / sim.sim_hz).round() as usize,
        contact_substeps,
        ..sim.clone()
    }
}

/// The fast body step (`BodyStep::Fast`: the body at 5 kHz with the stick–head contact and
/// the drums still at 10 kHz, and at 2.5 kHz with its fast PD loops stepped implicitly
/// while calm — no stroke within 80 ms, no hand placed, no stick on a head) against the
/// 10 kHz reference, on the very same targets (each demo score's rendered targets replayed
/// open loop, `render::replay`), and the reference itself against the same targets
/// stepped at 20 kHz (and, on the minute study, 40 kHz). Replayed at the reference
/// settings, a rendering comes back bit for bit.
///
/// Issue 22 asks tip paths within 1 mm, contact times within 0.3 ms and peak forces
/// within 5 % of the reference. The tip paths are within 1 mm in RMS (asserted below),
/// not at their worst sample. Measured here: the fast step 0.38 mm RMS, 3.8 mm at worst,
/// contacts 0.10 ms, forces 2.6 % from the reference (the 5 kHz step alone, without the
/// calm stretches: 0.26 mm, 3.7 mm, 0.10 ms, 2.6 %); the reference 0.19 mm RMS, 3.9 mm at
/// worst, 0.15 ms and 2.3 % from its own half step. The step converges at first order
/// (20 → 40 kHz moves the tips half as far as 10 → 20 kHz), so the 10 kHz reference is
/// itself ≈ 3.9 mm from the converged motion at worst: no more accurate step can come
/// within 1 mm of it. The test holds the fast step within the reference's own step error
/// at its worst sample, in force and contact time (with a margin), within 2.5 times it in
/// RMS, and the first-order convergence.
#[test]
fn the_fast_body_step_stays_near_the_reference() {
    let db = db();
    let (mut coarse, mut fine) = (Apart::default(), Apart::default());
    let mut compared = 0;
    for path in demo_scores() {
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        let mut loaded = LoadedScore::load(&path).unwrap();
        loaded.score.settings.body_step = BodyStep::Reference;
        let params = RenderParams::for_score(&loaded.score.settings);
        assert_eq!(params.sim.contact_substeps, 1);
        let rendering = render(&loaded, &db, &params, &mut |_| true).unwrap();
        let again = replay(&rendering, &params.sim).unwrap();
        assert!(
            again.motion.tips == rendering.motion.tips,
            "{name}: the replay at the reference settings differs from the rendering"
        );
        assert_eq!(again.drums.contacts(), rendering.drums.contacts(), "{name}");
        let reference = (&rendering.motion, rendering.drums.contacts());
        let sim = &params.sim;
        let fast = SimParams {
            calm_substeps: BodyStep::Fast.calm_substeps(),
            ..stepped(sim, sim.sim_hz, BodyStep::Fast.contact_substeps())
        };
        let at_5 = replay(&rendering, &fast).unwrap();
        let at_20 = replay(&rendering, &stepped(sim, 2.0 * sim.sim_hz, 1)).unwrap();
        let at_20 = (&at_20.motion, at_20.drums.contacts());
        coarse = coarse.max(Apart::between(
            &name,
            reference,
            (&at_5.motion, at_5.drums.contacts()),
        ));
        fine = fine.max(Apart::between(&name, reference, at_20));
        compared += recontact_sized(rendering.drums.contacts()).len();
        if name == "minute-study.ron" {
            let at_40 = replay(&rendering, &stepped(sim, 4.0 * sim.sim_hz, 1)).unwrap();
            let (first, second) = (
                Apart::between(&name, reference, at_20),
                Apart::between(&name, at_20, (&at_40.motion, at_40.drums.contacts())),
            );
            println!("{name}: 10 against 20 kHz {first}; 20 against 40 kHz {second}");
            // By the median distance: one loose-grip rebound that goes another way at one
            // rate (2.8 mm at 52.2 s, 20 against 40 kHz) weighs on the RMS as much as the
            // whole score's step error (0.097 mm RMS, 0.075 without it).
            let order = first.median_m / second.median_m;
            assert!(
                (1.5..2.6).contains(&order),
                "halving the step divides the tips' median distance by {order:.2}"
            );
        }
    }
    println!("{compared} contacts: the fast step from the reference: {coarse}");
    println!("the reference from its own half step (20 kHz): {fine}");
    assert!(compared > 250, "{compared}");
    // The reference's own step error, and the coarser step within it.
    assert!(fine.worst_m > 1e-3 && fine.force > 0.01, "{fine}");
    assert!(coarse.rms_m <= 2.5 * fine.rms_m, "{coarse} against {fine}");
    assert!(
        coarse.worst_m <= 1.2 * fine.worst_m,
        "{coarse} against {fine}"
    );
    assert!(coarse.force <= 1.2 * fine.force, "{coarse} against {fine}");
    assert!(coarse.contact_s <= 0.2e-3, "{coarse}");
    // The issue's bounds, the tip paths' in RMS.
    assert!(
        coarse.rms_m <= 1e-3 && coarse.contact_s <= 0.3e-3 && coarse.force <= 0.05,
        "{coarse}"
    );
}

/// A beat's pitch tunes its drum: one stroke on the 32-inch drum (kit tuning F2) named D2,
/// F2 or A2 sounds that pitch's (1,1) — the simulated head retuned (its tension by
/// f ∝ √T), and every sound model with it. Before, every stroke sounded the kit tuning
/// (the Bach chorale's A2 notes on the 29-inch drum sounded B♭2).
#[test]
fn a_beats_pitch_tunes_its_drum_in_every_sound_model() {
    use timpanist::base::choices::SoundModel;
    let db = db();
    for name in ["D2", "F2", "A2"] {
        let pitch: timpanist::base::pitch::Pitch = name.parse().unwrap();
        let mut score = Score::new("one pitched stroke");
        score.beats = vec![Beat {
            hand: Hand::Left,
            pitch: Some(pitch),
            ..Beat::plain(0, 0)
        }];
        let loaded = on_the_standard_kit(score);
        for sound in [SoundModel::Modal, SoundModel::Sample, SoundModel::Signal] {
            let r = with_a_tail(&loaded, &db, sound);
            assert_eq!(r.kit.drums[0].tuning, pitch);
            let mono = r.audio.mono();
            let heard = timpanist::sound::analysis::profile(&mono, r.audio.rate_hz)
                .and_then(|p| p.principal_hz)
                .unwrap_or_else(|| panic!("{name}, {sound:?}: no (1,1) found"));
            // The big head's (1,1) is heard over its first second, while the
            // kettle-lifted (0,1) and a loud stroke's glide still pull it a little.
            assert!(
                (heard / pitch.hz() - 1.0).abs() < 0.02,
                "{name}, {sound:?}: heard {heard:.1} Hz, asked {:.1} Hz",
                pitch.hz()
            );
        }
    }
}

/// A pedal change within a score: the 32-inch drum (kit tuning F2) struck in D2, then
/// 3 s later in A2. The player damps the head and retunes it between the two strokes:
/// in every sound model each stroke sounds its own pitch and the drum's stem is silent
/// just before the second; an edit after the change resumes bit for bit as a whole
/// render of the edited score.
#[test]
fn a_pedal_change_retunes_the_drum_between_its_strokes() {
    use timpanist::base::choices::SoundModel;
    use timpanist::base::pitch::Pitch;
    let db = db();
    let mut score = Score::new("a pedal change");
    let quarter_s = 60.0 / score.tempo_map().bpm_at(0.0);
    let ticks = (3.0 / quarter_s * f64::from(score.ticks_per_quarter)).round() as u64;
    let second_s = ticks as f64 / f64::from(score.ticks_per_quarter) * quarter_s;
    let (d2, a2): (Pitch, Pitch) = ("D2".parse().unwrap(), "A2".parse().unwrap());
    score.beats = vec![
        Beat {
            hand: Hand::Left,
            pitch: Some(d2),
            ..Beat::plain(0, 0)
        },
        Beat {
            hand: Hand::Left,
            pitch: Some(a2),
            ..Beat::plain(ticks, 0)
        },
    ];
    let loaded = on_the_standard_kit(score);
    let retunes = loaded.score.retunes(&loaded.kit);
    assert_eq!(retunes.len(), 1);
    for sound in [SoundModel::Modal, SoundModel::Sample, SoundModel::Signal] {
        let r = with_a_tail(&loaded, &db, sound);
        assert_eq!(r.drums.retunes(), retunes);
        let rate = r.audio.rate_hz;
        let at = |s: f64| (s * f64::from(rate)) as usize;
        let mono = r.audio.mono();
        for (window, pitch) in [
            (&mono[..at(second_s - 0.3)], d2),
            (&mono[at(second_s - 0.05)..], a2),
        ] {
            let heard = timpanist::sound::analysis::profile(window, rate)
                .and_then(|p| p.principal_hz)
                .unwrap_or_else(|| panic!("{sound:?}: no (1,1) found"));
            assert!(
                (heard / pitch.hz() - 1.0).abs() < 0.02,
                "{sound:?}: heard {heard:.1} Hz, asked {pitch} ({:.1} Hz)",
                pitch.hz()
            );
        }
        // The drum's own stem: damped before the change, silent until the second stroke.
        let stems = timpanist::sound::stems(
            &r.kit,
            (&r.drums, &r.touches),
            r.audio.frames() as f64 / f64::from(rate),
            sound,
        )
        .unwrap();
        let stem = stems[0].mono();
        let peak = |s: &[f32]| s.iter().fold(0.0f32, |m, x| m.max(x.abs()));
        let (struck, before) = (
            peak(&stem[..at(1.0)]),
            peak(&stem[at(second_s - 0.09)..at(second_s - 0.02)]),
        );
        assert!(
            before <= struck * 1e-3,
            "{sound:?}: {before:e} just before the second stroke against {struck:e}"
        );
    }
    // Resumed after an edit later than the change, as the editor does.
    let params = RenderParams::default();
    let mut resume: Option<Resume> = None;
    render_after(&mut resume, None, &loaded, &db, &params, &mut |_| true).unwrap();
    let mut edited = loaded.clone();
    edited.score.beats[1].dynamic = Dynamic::Ff;
    let whole = render(&edited, &db, &params, &mut |_| true).unwrap();
    let resumed = render_after(&mut resume, None, &edited, &db, &params, &mut |_| true).unwrap();
    assert!(resumed.stats.resumed_from_s.is_some_and(|s| s > 0.0));
    assert!(
        resumed.audio.samples == whole.audio.samples,
        "the resumed sound differs"
    );
}

/// `score` on the standard kit.
fn on_the_standard_kit(score: Score) -> LoadedScore {
    LoadedScore {
        score,
        kit: Kit::standard(),
        kit_source: "standard".into(),
        notices: Vec::new(),
    }
}

/// `loaded` rendered with `sound` and a 2 s tail.
fn with_a_tail(
    loaded: &LoadedScore,
    db: &MotionDb,
    sound: timpanist::base::choices::SoundModel,
) -> Rendering {
    let params = RenderParams {
        sound,
        tail_s: 2.0,
        ..RenderParams::default()
    };
    render(loaded, db, &params, &mut |_| true).unwrap()
}

/// Quick pedal changes (a D3 roll, E3 straight after it, F3 0.15 s later, on the 26-inch
/// drum): each new note sounds at full strength and at its pitch — the damping before a
/// change ends at the change, and the change comes before the beat's contact. (Before,
/// a damping touch lasting 0.25 s past a quick change stopped the new notes 50 dB down.)
#[test]
fn quick_pedal_changes_keep_the_new_notes() {
    use timpanist::base::choices::SoundModel;
    use timpanist::score::Roll;
    let db = db();
    let mut score = Score::new("quick pedal changes");
    score.ticks_per_quarter = 960;
    let quarter_s = 60.0 / score.tempo_map().bpm_at(0.0);
    let (e3_tick, f3_tick) = (1920, 1920 + 240);
    let pitched = |tick, hand, pitch: &str| Beat {
        hand,
        pitch: Some(pitch.parse().unwrap()),
        dynamic: Dynamic::F,
        ..Beat::plain(tick, 2)
    };
    score.beats = vec![
        Beat {
            roll: Some(Roll {
                length_ticks: 1920,
                strokes_per_quarter: 4,
            }),
            ..pitched(0, Hand::Right, "D3")
        },
        pitched(e3_tick, Hand::Right, "E3"),
        pitched(f3_tick, Hand::Left, "F3"),
    ];
    let loaded = on_the_standard_kit(score);
    let changes = loaded.score.pedal_changes(&loaded.kit);
    assert_eq!(changes.len(), 2);
    assert!(changes.iter().all(|c| c.is_quick()), "{changes:?}");
    let r = with_a_tail(&loaded, &db, SoundModel::Modal);
    let stems = timpanist::sound::stems(
        &r.kit,
        (&r.drums, &r.touches),
        r.audio.frames() as f64 / f64::from(r.audio.rate_hz),
        SoundModel::Modal,
    )
    .unwrap();
    let stem = stems[2].mono();
    let rate = f64::from(r.audio.rate_hz);
    let at = |s: f64| (s * rate) as usize;
    let peak = |s: &[f32]| s.iter().fold(0.0f32, |m, x| m.max(x.abs()));
    let first = peak(&stem[..at(0.3)]);
    for tick in [e3_tick, f3_tick] {
        let t = tick as f64 / 960.0 * quarter_s;
        let new = peak(&stem[at(t)..at(t + 0.1)]);
        assert!(new >= 0.3 * first, "at {t:.2} s: {new:e} against {first:e}");
    }
    let f3_s = f3_tick as f64 / 960.0 * quarter_s;
    let heard = timpanist::sound::analysis::profile(&stem[at(f3_s - 0.005)..], r.audio.rate_hz)
        .and_then(|p| p.principal_hz)
        .unwrap();
    let f3: timpanist::base::pitch::Pitch = "F3".parse().unwrap();
    assert!((heard / f3.hz() - 1.0).abs() < 0.02, "heard {heard:.1} Hz");
}

/// A roll of 32nds at 120 bpm written right up to a note on another drum (as notation
/// programs export a tremolo resolving to the next note) is played: the hand that moves
/// leaves the roll's last stroke out and reaches the note in time (it had lost control,
/// asked to cross between drums in one eighth of a second), in both directions.
#[test]
fn a_roll_into_a_note_on_another_drum_is_played() {
    let db = db();
    for (from, to) in [(1, 2), (2, 1)] {
        let text = format!(
            r#"Score(version: 2, title: "roll into a note", kit: "standard", grip: French,
            ticks_per_quarter: 960, tempo: [(tick: 0, bpm: 120.0, change: Step)],
            meter: [(bar: 1, numerator: 4, denominator: 4)],
            beats: [
                Beat(tick: 0, hand: Auto, mode: Legato, dynamic: Mf, drum: {from}, location: PlayingSpot, roll: Some((length_ticks: 4800, strokes_per_quarter: 8))),
                Beat(tick: 4800, hand: Auto, mode: Accent, dynamic: Mf, drum: {to}, location: PlayingSpot),
            ], handles: [], pins: [])"#
        );
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("roll.ron");
        std::fs::write(&path, text).unwrap();
        let r = render_file(&path, &db);
        assert_eq!(r.timing.missed, 0, "{from} → {to}: {:?}", r.timing);
        let note = r.events.iter().find(|e| e.beat == Some(1)).unwrap();
        assert!(
            (note.contact_s - 2.5).abs() < 0.003,
            "{from} → {to}: the note at {:.4} s",
            note.contact_s
        );
    }
}
