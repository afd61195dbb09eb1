//! Secco beats performed: the free hand moves to the head, rests on it at the damp tick
//! with its stick turned up (no stray contact), and the head it touches falls silent.

use std::path::Path;
use timpanist::body::skeleton::Joint;
use timpanist::mocap::db::MotionDb;
use timpanist::render::{RenderParams, Rendering, render};
use timpanist::score::LoadedScore;
use timpanist::sound::{self, Touch};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn study() -> Rendering {
    let loaded = LoadedScore::load(&root().join("scores/secco-study.ron")).unwrap();
    let db = MotionDb::load(&root().join("mocap")).unwrap();
    render(&loaded, &db, &RenderParams::default(), &mut |_| true).unwrap()
}

/// RMS of `samples` (interleaved stereo at `rate` Hz) from `from_s` to `to_s`.
fn rms(audio: &sound::Audio, from_s: f64, to_s: f64) -> f64 {
    let rate = f64::from(audio.rate_hz);
    let range = (from_s * rate) as usize * 2..(to_s * rate) as usize * 2;
    let window = audio.samples.to_vec_of(range);
    (window.iter().map(|&x| f64::from(x).powi(2)).sum::<f64>() / window.len() as f64).sqrt()
}

/// Every damped beat of the study is stopped by a hand that reaches its head within 50 ms
/// of the damp tick: the hand (its grip joint, the fingers) rests just above the head,
/// over it, while its stick points up well clear of it, and no stick touches a head but
/// for the scored strokes.
#[test]
fn the_free_hand_rests_on_the_head_at_the_damp_tick() {
    let r = study();
    let d = &r.damping;
    assert_eq!(d.by_hand.len(), 4, "{d:?}");
    assert!(d.missed.is_empty() && d.without_hand.is_empty(), "{d:?}");
    for &(beat, off) in &d.by_hand {
        assert!(off.abs() < 0.05, "beat {beat}: touched {off:+.3} s off");
    }
    assert_eq!(r.timing.missed, 0);
    assert!(
        r.events
            .iter()
            .all(|e| e.beat.is_some() && e.recontacts == 0),
        "a stick touched a head outside its strokes"
    );
    let skeleton = r.skeleton();
    let comp = &r.composition;
    let muffles = &comp.muffles.played;
    // Both ways: a free hand damping another's drum, and the striker damping its own.
    let struck_by = |beat: usize| comp.strokes.iter().find(|s| s.beat == beat).unwrap().hand;
    assert!(muffles.iter().any(|m| m.hand != struck_by(m.damp.beat)));
    assert!(muffles.iter().any(|m| m.hand == struck_by(m.damp.beat)));
    for m in muffles {
        let drum = &r.kit.drums[m.damp.drum].placement;
        let k = ((m.damp.touch_s + 0.1 - comp.start_s) * comp.rate_hz).round() as usize;
        let frames = skeleton.forward(&r.motion.poses[k]);
        let hand = frames.position[Joint::arm(m.hand)[3].index()];
        let tip = frames.tip(m.hand);
        let above = hand.z - drum.head_height_m;
        let from_centre = (hand.x - drum.x_m).hypot(hand.y - drum.y_m);
        let radius = 0.5 * r.kit.drums[m.damp.drum].diameter_m;
        assert!(
            (0.0..0.045).contains(&above) && from_centre < radius,
            "beat {}: hand {above:.3} m above the head, {from_centre:.3} m from its centre",
            m.damp.beat
        );
        assert!(
            tip.z - drum.head_height_m > 0.15,
            "beat {}: stick tip only {:.3} m above the head",
            m.damp.beat,
            tip.z - drum.head_height_m
        );
    }
}

/// The touched head's own sound (its stem), 200–300 ms after the touch, is at least
/// 20 dB below the same performance's with no hand on it; before the touch they are equal.
#[test]
fn a_touched_head_falls_silent() {
    let r = study();
    let duration_s = r.audio.frames() as f64 / f64::from(r.audio.rate_hz);
    let model = r.params.sound;
    let damped = sound::stems(&r.kit, (&r.drums, &r.touches), duration_s, model).unwrap();
    let free = sound::stems(&r.kit, (&r.drums, &[] as &[Touch]), duration_s, model).unwrap();
    for touch in &r.touches {
        // The audio's time is the score's (its first sample at 0 s).
        let at = touch.at_s;
        let (with, without) = (&damped[touch.drum], &free[touch.drum]);
        let db = 20.0 * (rms(with, at + 0.2, at + 0.3) / rms(without, at + 0.2, at + 0.3)).log10();
        assert!(db <= -20.0, "drum {} at {at:.2} s: {db:.1} dB", touch.drum);
        let before = rms(with, at - 0.1, at) / rms(without, at - 0.1, at);
        assert!(
            (before - 1.0).abs() < 0.05,
            "drum {} before the touch: {before}",
            touch.drum
        );
    }
}

/// The head moves as a player's does through the study's two-stick strokes and damping
/// hands: neither the neck's nor the head's joint turns faster than 1000°/s. (With the
/// trunk's IK target turning with every strike-through dip and reach, the neck and head,
/// driven for a trunk that could not follow, whipped round at up to 4700°/s here.)
#[test]
fn the_head_never_whips_round() {
    let r = study();
    let rate = r.motion.rate_hz;
    let poses: Vec<_> = r.motion.poses.iter().collect();
    for joint in [Joint::Neck, Joint::Head] {
        let j = joint.index();
        let (fastest, at) = poses
            .windows(2)
            .enumerate()
            .map(|(k, w)| (w[0][j].angle_between(w[1][j]).to_degrees() * rate, k))
            .fold((0.0, 0), |a, b| if b.0 > a.0 { b } else { a });
        let at_s = r.start_s + at as f64 / rate;
        assert!(
            fastest < 1000.0,
            "{joint:?} turned at {fastest:.0}°/s at {at_s:.2} s"
        );
    }
}

/// Making a beat secco in the editor (a damp added to the study's beat at tick 9600 on
/// the 29-inch drum) re-renders from a saved state before the edit and gives bit for bit
/// what rendering the edited study whole gives: the damping hand's way to the head and
/// its touch all come after the first target the edit changes.
#[test]
fn adding_a_damp_resumes_as_a_whole_render_does() {
    use timpanist::render::{Resume, render_after};
    let loaded = LoadedScore::load(&root().join("scores/secco-study.ron")).unwrap();
    let db = MotionDb::load(&root().join("mocap")).unwrap();
    let params = RenderParams::default();
    let mut resume: Option<Resume> = None;
    render_after(&mut resume, None, &loaded, &db, &params, &mut |_| true).unwrap();
    let mut edited = loaded.clone();
    let beat = edited
        .score
        .beats
        .iter_mut()
        .find(|b| b.tick == 9600)
        .unwrap();
    assert_eq!(beat.damp, None);
    beat.damp = Some(480);
    let whole = render(&edited, &db, &params, &mut |_| true).unwrap();
    let resumed = render_after(&mut resume, None, &edited, &db, &params, &mut |_| true).unwrap();
    let from = resumed.stats.resumed_from_s.expect("the edit resumes");
    assert!(from > 1.0, "resumed at {from:.2} s");
    assert!(whole.touches.len() > study().touches.len(), "the new touch");
    assert!(
        resumed.audio.samples == whole.audio.samples,
        "the audio differs"
    );
    assert!(resumed.motion == whole.motion, "the motion differs");
    assert_eq!(resumed.touches, whole.touches);
}
