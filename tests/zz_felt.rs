use timpanist::base::gesture::Dynamic;
use timpanist::sound::{analysis, calibration::Calibration, fit};

#[test]
#[ignore]
fn felt_sweep() {
    let variants: Vec<(f64, f64, f64, f64)> = std::env::var("FELT")
        .unwrap()
        .split(';')
        .map(|v| {
            let x: Vec<f64> = v.split(',').map(|s| s.parse().unwrap()).collect();
            (x[0], x[1], x[2], x[3])
        })
        .collect();
    let hz: f64 = std::env::var("HZ")
        .map(|s| s.parse().unwrap())
        .unwrap_or(146.83);
    for (k, alpha, loss, mass) in variants {
        let mut kit = fit::kit_for(hz);
        kit.mallets[0].felt_stiffness = k;
        kit.mallets[0].contact_exponent = alpha;
        kit.mallets[0].felt_loss_s_per_m = loss;
        kit.mallets[0].mass_kg = mass;
        let mut cents = vec![];
        for d in [Dynamic::P, Dynamic::Mf, Dynamic::Ff] {
            let (mono, c) = fit::struck(&kit, d, Calibration::shipped(), 1.2).unwrap();
            let p = analysis::profile(&mono, 48000).unwrap();
            let c = c.unwrap();
            cents.push(p.centroid_hz);
            println!(
                "k {k:.1e} a {alpha} l {loss} m {mass} {d:?}: dur {:.2} ms F {:.0} v {:.2} cent {:.0} bands {:?}",
                (c.end_s - c.start_s) * 1e3,
                c.peak_force_n,
                c.impact_speed_mps,
                p.centroid_hz,
                p.bands_db
                    .iter()
                    .map(|b| (b * 10.0).round() / 10.0)
                    .collect::<Vec<_>>()
            );
        }
        println!(
            "  => p->ff centroid {:+.1} %",
            (cents[2] / cents[0] - 1.0) * 100.0
        );
    }
}
