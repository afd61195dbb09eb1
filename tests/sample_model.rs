//! The sample-replay sound model with a scripted stick: the left and right sticks replay
//! different recordings of the note, each pitched to the tuning; soft strokes are darker
//! than loud ones; a render repeats bit for bit.

use timpanist::drum::strike::{self, PLAYING_SPOT_FRACTION, SIM_RATE_HZ, impact_speed_mps};
use timpanist::drum::{DrumSet, ModeConfig};
use timpanist::kit::{Kit, Side};
use timpanist::score::Dynamic;
use timpanist::sound::analysis::{KETTLEDRUM_RATIOS, profile};
use timpanist::sound::spectrum::{principal_hz, spectrum};
use timpanist::sound::{SAMPLE_RATE_HZ, sample};

const DT: f64 = 1.0 / SIM_RATE_HZ;
const D26: usize = 2;
/// Length of each render, s.
const RENDER_S: f64 = 2.0;

/// One free stroke by `side` at `speed` (m/s) on the playing spot of drum `d` of the
/// standard kit: the drum's sample-model output, mono.
fn stroke(d: usize, side: Side, speed: f64) -> Vec<f32> {
    let kit = Kit::standard();
    let mallet = &kit.mallets[0];
    let mut drums = DrumSet::new(&kit, mallet, &ModeConfig::default(), DT).unwrap();
    let drum = &kit.drums[d];
    let point = drum.point_on_head(PLAYING_SPOT_FRACTION, 0.0);
    strike::scripted(&mut drums, drum, mallet, side, point, speed, 0.05);
    assert!(!drums.contacts().is_empty());
    assert!(
        drums
            .contacts()
            .iter()
            .all(|c| c.side == side && c.drum == d)
    );
    let mut out = vec![0.0; (RENDER_S * f64::from(SAMPLE_RATE_HZ)) as usize];
    assert!(sample::render_drum(&kit, (&drums, &[]), d, &mut out).unwrap());
    assert!(out.iter().all(|s| s.is_finite()));
    out
}

/// On every drum of the standard kit, a left and a right stroke at the same speed replay
/// different recordings (their difference holds at least 10 % of the energy), and each
/// sounds its (1,1) within 1 % of the tuning.
#[test]
fn left_and_right_strokes_differ_and_are_in_tune() {
    let kit = Kit::standard();
    let speed = impact_speed_mps(Dynamic::Mf);
    for (d, drum) in kit.drums.iter().enumerate() {
        let f0 = drum.tuning.hz();
        let [l, r] = [Side::Left, Side::Right].map(|side| stroke(d, side, speed));
        for (side, x) in [("left", &l), ("right", &r)] {
            let f11 = principal_hz(
                &spectrum(x, SAMPLE_RATE_HZ),
                40.0,
                400.0,
                &KETTLEDRUM_RATIOS,
            )
            .unwrap_or_else(|| panic!("drum {d} {side}: no (1,1)"));
            eprintln!("drum {d} {side}: (1,1) {f11:.2} Hz, tuning {f0:.2} Hz");
            assert!(
                (f11 / f0 - 1.0).abs() < 0.01,
                "drum {d} {side}: {f11} Hz vs {f0} Hz"
            );
        }
        let energy =
            |x: &mut dyn Iterator<Item = f32>| x.map(|s| f64::from(s).powi(2)).sum::<f64>();
        let diff = energy(&mut l.iter().zip(&r).map(|(a, b)| a - b));
        let share = diff / energy(&mut l.iter().copied()).max(energy(&mut r.iter().copied()));
        eprintln!("drum {d}: L − R energy / note energy {share:.3}");
        assert!(
            share > 0.1,
            "drum {d}: left and right nearly equal ({share})"
        );
    }
}

/// The brightness follows the impact speed: on the 26-inch drum, for either stick, the
/// spectral centroid over the first second of a p stroke is at least 10 % below that of
/// an ff stroke, and mf lies between them.
#[test]
fn soft_strokes_are_darker() {
    for side in [Side::Left, Side::Right] {
        let centroid = |dynamic| {
            let x = stroke(D26, side, impact_speed_mps(dynamic));
            profile(&x, SAMPLE_RATE_HZ).unwrap().centroid_hz
        };
        let [p, mf, ff] = [Dynamic::P, Dynamic::Mf, Dynamic::Ff].map(centroid);
        eprintln!(
            "{side:?}: centroid p {p:.1} Hz, mf {mf:.1} Hz, ff {ff:.1} Hz (p/ff {:.3})",
            p / ff
        );
        assert!(p <= 0.9 * ff, "{side:?}: p {p} Hz, ff {ff} Hz");
        assert!(p < mf && mf < ff, "{side:?}: p {p}, mf {mf}, ff {ff} Hz");
    }
}

/// The same stroke simulated and rendered twice gives the same samples bit for bit.
#[test]
fn renders_repeat_bit_for_bit() {
    for side in [Side::Left, Side::Right] {
        let speed = impact_speed_mps(Dynamic::P);
        let (a, b) = (stroke(D26, side, speed), stroke(D26, side, speed));
        assert!(a.iter().any(|s| *s != 0.0));
        assert!(a.iter().zip(&b).all(|(x, y)| x.to_bits() == y.to_bits()));
    }
}
