//! The teaching exports of `timpanist render` (README "Exports") read back by readers
//! independent of the writers (`readers`): the BVH's forward kinematics against the
//! motion CSV's stick tips.

mod readers;

use readers::Bvh;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// Run `timpanist render SCORE` with `args` from the repository; the output.
fn render(score: &str, args: &[&std::ffi::OsStr]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_timpanist"))
        .current_dir(root())
        .args(["render", score])
        .args(args)
        .output()
        .unwrap()
}

fn ok(out: &Output) {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// The motion CSV's rows as numbers (header dropped).
fn csv_rows(path: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    (header, rows)
}

/// A CSV tip (performer frame: x right, y forward, z up, m) in the Y-up axes of the BVH
/// and glTF files (the performer facing +Z: (−x, z, y)) and `per_metre` units.
fn tip_y_up(header: &[String], row: &[f64], hand: &str, per_metre: f64) -> [f64; 3] {
    let col = |axis: &str| {
        let name = format!("{hand}_tip_{axis}_m");
        row[header.iter().position(|h| *h == name).unwrap()]
    };
    [-col("x"), col("z"), col("y")].map(|v| v * per_metre)
}

fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    (0..3).map(|i| (a[i] - b[i]).powi(2)).sum::<f64>().sqrt()
}

/// The BVH written by `render --bvh`, parsed and posed by an independent forward
/// kinematics, puts both stick tips (the grips' end sites) where the motion CSV has them,
/// within 1 mm in every frame, with a frame per CSV row at the task rate; resampled to
/// 60 Hz in centimetres, the frames at whole tenths of a second (where 60 Hz and 250 Hz
/// samples coincide) do too, and the frame count covers the same duration.
#[test]
fn bvh_forward_kinematics_matches_the_motion_csv() {
    let dir = tempfile::tempdir().unwrap();
    let (wav, csv, bvh, bvh60) = (
        dir.path().join("out.wav"),
        dir.path().join("motion.csv"),
        dir.path().join("out.bvh"),
        dir.path().join("out60.bvh"),
    );
    let out = render(
        "scores/improvisation.ron",
        &[
            "--wav".as_ref(),
            wav.as_os_str(),
            "--motion".as_ref(),
            csv.as_os_str(),
            "--bvh".as_ref(),
            bvh.as_os_str(),
        ],
    );
    ok(&out);
    let (header, rows) = csv_rows(&csv);
    let parsed = Bvh::parse(&std::fs::read_to_string(&bvh).unwrap());
    assert_eq!(parsed.frames.len(), rows.len(), "a frame per CSV row");
    assert!((parsed.frame_time_s - (rows[1][0] - rows[0][0])).abs() < 1e-6);
    assert!((parsed.frame_time_s - 1.0 / 250.0).abs() < 1e-9);
    // 11 joints with channels, the root with six; the stick tips and the head as ends.
    let moving: Vec<_> = parsed
        .joints
        .iter()
        .filter(|j| !j.channels.is_empty())
        .collect();
    assert_eq!(moving.len(), 11);
    assert_eq!(moving[0].channels.len(), 6);
    let tips = [parsed.index("grip_l_end"), parsed.index("grip_r_end")];
    let mut worst = 0.0f64;
    for (f, row) in rows.iter().enumerate() {
        let p = parsed.positions(f);
        for (tip, hand) in tips.iter().zip(["left", "right"]) {
            worst = worst.max(distance(p[*tip], tip_y_up(&header, row, hand, 1.0)));
        }
    }
    eprintln!(
        "BVH tips vs motion CSV: worst {worst} m over {} frames",
        rows.len()
    );
    assert!(worst < 1e-3, "worst tip distance {worst} m");
    // Y is up: the head is above the trunk, the tips below the shoulders at rest height.
    let p = parsed.positions(0);
    assert!(p[parsed.index("head")][1] > p[parsed.index("trunk")][1]);

    let out = render(
        "scores/improvisation.ron",
        &[
            "--wav".as_ref(),
            wav.as_os_str(),
            "--bvh".as_ref(),
            bvh60.as_os_str(),
            "--bvh-rate".as_ref(),
            "60".as_ref(),
            "--bvh-units".as_ref(),
            "cm".as_ref(),
        ],
    );
    ok(&out);
    let parsed = Bvh::parse(&std::fs::read_to_string(&bvh60).unwrap());
    assert!((parsed.frame_time_s - 1.0 / 60.0).abs() < 1e-8);
    let duration_s = (rows.len() - 1) as f64 / 250.0;
    assert_eq!(
        parsed.frames.len(),
        (duration_s * 60.0 + 1e-9).floor() as usize + 1
    );
    let mut checked = 0;
    for f in (0..parsed.frames.len()).step_by(6) {
        let row = &rows[f / 6 * 25];
        let p = parsed.positions(f);
        for (tip, hand) in tips.iter().zip(["left", "right"]) {
            let d = distance(p[*tip], tip_y_up(&header, row, hand, 100.0));
            assert!(d < 0.1, "frame {f} {hand}: {d} cm");
        }
        checked += 1;
    }
    assert!(checked > 10);
}

/// Impossible BVH options are refused by name before anything is written.
#[test]
fn bvh_options_are_checked() {
    let dir = tempfile::tempdir().unwrap();
    let wav: PathBuf = dir.path().join("out.wav");
    let out = render(
        "scores/improvisation.ron",
        &[
            "--wav".as_ref(),
            wav.as_os_str(),
            "--bvh".as_ref(),
            dir.path().join("x.bvh").as_os_str(),
            "--bvh-rate".as_ref(),
            "100".as_ref(),
        ],
    );
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("--bvh-rate"));
    let out = render(
        "scores/improvisation.ron",
        &[
            "--wav".as_ref(),
            wav.as_os_str(),
            "--bvh-units".as_ref(),
            "cm".as_ref(),
        ],
    );
    assert!(!out.status.success(), "--bvh-units without --bvh");
    assert!(String::from_utf8_lossy(&out.stderr).contains("--bvh"));
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

/// A WAV's spec and samples as numbers in [−1, 1] (integer formats over their full
/// scale), read with hound.
fn wav_samples(path: &Path) -> (hound::WavSpec, Vec<f64>) {
    let mut r = hound::WavReader::open(path).unwrap();
    let spec = r.spec();
    let samples = match spec.sample_format {
        hound::SampleFormat::Float => r.samples::<f32>().map(|s| f64::from(s.unwrap())).collect(),
        hound::SampleFormat::Int => {
            let full = f64::from((1i32 << (spec.bits_per_sample - 1)) - 1);
            r.samples::<i32>()
                .map(|s| f64::from(s.unwrap()) / full)
                .collect()
        }
    };
    (spec, samples)
}

/// `--wav-format 24` and `f32` write the same sound as the default 16-bit WAV: every
/// sample within the 16-bit step's rounding (plus the 24-bit one's), the 24-bit one far
/// closer to the float one than 16-bit can be.
#[test]
fn wav_formats_hold_the_same_samples() {
    let dir = tempfile::tempdir().unwrap();
    let mut read = Vec::new();
    for format in ["16", "24", "f32"] {
        let wav = dir.path().join(format!("{format}.wav"));
        let args = [
            "--wav".as_ref(),
            wav.as_os_str(),
            "--wav-format".as_ref(),
            format.as_ref(),
        ];
        ok(&render("scores/improvisation.ron", &args));
        read.push(wav_samples(&wav));
    }
    let bits: Vec<_> = read.iter().map(|(s, _)| s.bits_per_sample).collect();
    assert_eq!(bits, [16, 24, 32]);
    assert_eq!(read[2].0.sample_format, hound::SampleFormat::Float);
    let (s16, s24, f32_) = (&read[0].1, &read[1].1, &read[2].1);
    assert_eq!(s16.len(), s24.len());
    assert_eq!(s16.len(), f32_.len());
    assert!(f32_.iter().any(|s| s.abs() > 0.1), "not silent");
    let step16 = 1.0 / 32767.0;
    let step24 = 1.0 / 8_388_607.0;
    let worst = |a: &[f64], b: &[f64]| {
        a.iter()
            .zip(b)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max)
    };
    assert!(worst(s16, f32_) <= 0.5 * step16 + 1e-9);
    assert!(worst(s16, s24) <= 0.5 * (step16 + step24) + 1e-9);
    assert!(worst(s24, f32_) <= 0.5 * step24 + 1e-9);
}

/// `--stems` writes `left.wav` and `right.wav` besides the drums' stems: each hand's
/// sound, silent before that hand's first contact, both sounding, and together the mix
/// to the float rounding (32-bit float files); the drums' stems sum to the mix too.
#[test]
fn hand_stems_sum_to_the_mix() {
    let dir = tempfile::tempdir().unwrap();
    let (wav, json, stems) = (
        dir.path().join("mix.wav"),
        dir.path().join("events.json"),
        dir.path().join("stems"),
    );
    let args = [
        "--wav".as_ref(),
        wav.as_os_str(),
        "--events".as_ref(),
        json.as_os_str(),
        "--stems".as_ref(),
        stems.as_os_str(),
        "--wav-format".as_ref(),
        "f32".as_ref(),
    ];
    ok(&render("scores/tempo-change.ron", &args));
    let (spec, mix) = wav_samples(&wav);
    let (_, left) = wav_samples(&stems.join("left.wav"));
    let (_, right) = wav_samples(&stems.join("right.wav"));
    assert_eq!((left.len(), right.len()), (mix.len(), mix.len()));
    let peak = |s: &[f64]| s.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let events: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    // Silent until a millisecond before the hand's first contact (the force is spread
    // over one simulation step each side): checked on a hand starting after 0.1 s.
    let mut latest_start_s = 0.0f64;
    for (hand, stem) in [("left", &left), ("right", &right)] {
        let first_s = events
            .as_array()
            .unwrap()
            .iter()
            .filter(|e| e["hand"] == hand)
            .map(|e| e["contact_s"].as_f64().unwrap())
            .fold(f64::INFINITY, f64::min);
        latest_start_s = latest_start_s.max(first_s);
        let before = ((first_s - 1e-3).max(0.0) * f64::from(spec.sample_rate)) as usize * 2;
        assert_eq!(
            peak(&stem[..before]),
            0.0,
            "{hand} sounds before its first hit"
        );
        assert!(peak(stem) > 0.05, "{hand} is silent");
    }
    assert!(latest_start_s > 0.1, "both hands start at once");
    let worst = (0..mix.len())
        .map(|i| (left[i] + right[i] - mix[i]).abs())
        .fold(0.0, f64::max);
    eprintln!("hands sum to the mix within {worst}");
    assert!(worst < 1e-5, "hands sum to the mix within {worst}");
    let drums: Vec<Vec<f64>> = std::fs::read_dir(&stems)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            p.file_name()
                .unwrap()
                .to_str()
                .unwrap()
                .starts_with(char::is_numeric)
        })
        .map(|p| wav_samples(&p).1)
        .collect();
    assert_eq!(drums.len(), 4, "a stem per drum of the standard kit");
    let worst = (0..mix.len())
        .map(|i| (drums.iter().map(|d| d[i]).sum::<f64>() - mix[i]).abs())
        .fold(0.0, f64::max);
    assert!(worst < 1e-5, "drums sum to the mix within {worst}");
}

/// The note ons of a MIDI track: (absolute tick, key, velocity).
fn note_ons(track: &[midly::TrackEvent]) -> Vec<(u64, u8, u8)> {
    let mut tick = 0;
    let mut ons = Vec::new();
    for e in track {
        tick += u64::from(e.delta.as_int());
        if let midly::TrackEventKind::Midi {
            message: midly::MidiMessage::NoteOn { key, vel },
            ..
        } = e.kind
            && vel.as_int() > 0
        {
            ons.push((tick, key.as_int(), vel.as_int()));
        }
    }
    ons
}

/// Seconds at `tick` under a file's tempo events ((tick, µs per quarter), sorted).
fn seconds_at(tempos: &[(u64, u32)], tpq: f64, tick: f64) -> f64 {
    let mut s = 0.0;
    let mut at = (0u64, 500_000u32);
    for &(t, us) in tempos.iter().filter(|(t, _)| (*t as f64) <= tick) {
        s += (t - at.0) as f64 * f64::from(at.1) * 1e-6 / tpq;
        at = (t, us);
    }
    s + (tick - at.0 as f64) * f64::from(at.1) * 1e-6 / tpq
}

/// `--performed-midi` parses back (midly) with one note per stroke's contact of the
/// events, each at its contact time within one tick under the file's own tempo map (the
/// score's accelerando), keyed by its drum's tuning, velocities never falling as peak
/// force rises.
#[test]
fn performed_midi_has_a_note_per_contact() {
    let dir = tempfile::tempdir().unwrap();
    let (wav, json, mid) = (
        dir.path().join("mix.wav"),
        dir.path().join("events.json"),
        dir.path().join("performed.mid"),
    );
    let args = [
        "--wav".as_ref(),
        wav.as_os_str(),
        "--events".as_ref(),
        json.as_os_str(),
        "--performed-midi".as_ref(),
        mid.as_os_str(),
    ];
    ok(&render("scores/tempo-change.ron", &args));
    let events: Vec<serde_json::Value> =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let strokes: Vec<&serde_json::Value> = events.iter().filter(|e| !e["beat"].is_null()).collect();
    let bytes = std::fs::read(&mid).unwrap();
    let smf = midly::Smf::parse(&bytes).unwrap();
    let midly::Timing::Metrical(tpq) = smf.header.timing else {
        panic!("not metrical")
    };
    let tpq = f64::from(tpq.as_int());
    let mut tick = 0;
    let mut tempos = Vec::new();
    for e in &smf.tracks[0] {
        tick += u64::from(e.delta.as_int());
        if let midly::TrackEventKind::Meta(midly::MetaMessage::Tempo(us)) = e.kind {
            tempos.push((tick, us.as_int()));
        }
    }
    assert!(tempos.len() > 2, "the score's tempo change: {tempos:?}");
    let ons = note_ons(&smf.tracks[1]);
    assert_eq!(ons.len(), strokes.len(), "a note per stroke's contact");
    let kit = timpanist::kit::Kit::standard();
    for ((tick, key, _), e) in ons.iter().zip(&strokes) {
        let t = e["contact_s"].as_f64().unwrap();
        let per_tick =
            seconds_at(&tempos, tpq, *tick as f64 + 1.0) - seconds_at(&tempos, tpq, *tick as f64);
        let off = (seconds_at(&tempos, tpq, *tick as f64) - t) / per_tick;
        assert!(
            off.abs() <= 1.0,
            "note at tick {tick} is {off} ticks off {t} s"
        );
        let drum = e["drum"].as_u64().unwrap() as usize;
        assert_eq!(*key, kit.drums[drum].tuning.0);
    }
    let mut by_force: Vec<(f64, u8)> = ons
        .iter()
        .zip(&strokes)
        .map(|((_, _, v), e)| (e["peak_force_n"].as_f64().unwrap(), *v))
        .collect();
    by_force.sort_by(|a, b| a.0.total_cmp(&b.0));
    assert!(
        by_force.windows(2).all(|w| w[0].1 <= w[1].1),
        "{by_force:?}"
    );
    assert!(
        by_force[0].1 < by_force[by_force.len() - 1].1,
        "velocities all equal"
    );
}

/// `--osc HOST:PORT` sends one `/timpanist/hit` per contact to a real UDP receiver on
/// loopback, decoded with rosc: the drum, hand, place, force, speed and time of each
/// event of `--events`, in order.
#[test]
fn osc_sends_a_message_per_contact() {
    let rx = std::net::UdpSocket::bind("127.0.0.1:0").unwrap();
    rx.set_read_timeout(Some(std::time::Duration::from_secs(60)))
        .unwrap();
    let port = rx.local_addr().unwrap().port();
    let dir = tempfile::tempdir().unwrap();
    let (wav, json) = (dir.path().join("mix.wav"), dir.path().join("events.json"));
    let target = format!("127.0.0.1:{port}");
    let args = [
        "--wav".as_ref(),
        wav.as_os_str(),
        "--events".as_ref(),
        json.as_os_str(),
        "--osc".as_ref(),
        target.as_ref(),
    ];
    let receiver = std::thread::spawn(move || {
        let mut got = Vec::new();
        let mut buf = [0u8; 1536];
        rx.set_read_timeout(Some(std::time::Duration::from_secs(60)))
            .unwrap();
        while let Ok(n) = rx.recv(&mut buf) {
            let (_, packet) = rosc::decoder::decode_udp(&buf[..n]).unwrap();
            let rosc::OscPacket::Message(m) = packet else {
                panic!("not a message")
            };
            got.push(m);
            rx.set_read_timeout(Some(std::time::Duration::from_secs(2)))
                .unwrap();
        }
        got
    });
    let out = render("scores/tempo-change.ron", &args);
    ok(&out);
    assert!(String::from_utf8_lossy(&out.stdout).contains("OSC hits"));
    let got = receiver.join().unwrap();
    let events: Vec<serde_json::Value> =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(got.len(), events.len(), "a message per contact");
    for (m, e) in got.iter().zip(&events) {
        assert_eq!(m.addr, "/timpanist/hit");
        let a = &m.args;
        assert_eq!(a.len(), 7);
        assert_eq!(
            a[0].clone().int().unwrap() as u64,
            e["drum"].as_u64().unwrap()
        );
        assert_eq!(a[1].clone().string().unwrap(), e["hand"].as_str().unwrap());
        for (k, key) in [
            (2, "x_m"),
            (3, "y_m"),
            (4, "peak_force_n"),
            (5, "impact_speed_mps"),
            (6, "contact_s"),
        ] {
            let want = e[key].as_f64().unwrap();
            let have = f64::from(a[k].clone().float().unwrap());
            assert!(
                (have - want).abs() <= 1e-6 * want.abs().max(1.0),
                "{key}: {have} vs {want}"
            );
        }
    }
}

/// A bad `--osc` target is refused by name before anything is rendered or written; a
/// good one where nothing listens gets a note, the render standing.
#[test]
fn osc_target_is_checked() {
    let dir = tempfile::tempdir().unwrap();
    let wav = dir.path().join("out.wav");
    for bad in ["localhost", "127.0.0.1:0", "no-such-host.invalid:9000"] {
        let out = render(
            "scores/improvisation.ron",
            &[
                "--wav".as_ref(),
                wav.as_os_str(),
                "--osc".as_ref(),
                bad.as_ref(),
            ],
        );
        assert!(!out.status.success(), "{bad}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains("--osc"), "{bad}: {err}");
    }
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    // A good address where nothing listens (UDP): the render stands, with a note.
    let port = std::net::UdpSocket::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port();
    let target = format!("127.0.0.1:{port}");
    let out = render(
        "scores/improvisation.ron",
        &[
            "--wav".as_ref(),
            wav.as_os_str(),
            "--osc".as_ref(),
            target.as_ref(),
        ],
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("no program was listening"), "{err}");
    assert!(wav.exists());
}

/// `--glb` is read back by the `gltf` crate (an independent reader): one scene with the
/// body, the sticks and the kit's drum; one animation whose channels are exactly the 11
/// joint nodes' rotations, every sampler with a key per motion sample (the CSV's rows,
/// 4 ms apart) in its input and output accessors; and the node hierarchy posed by those
/// rotations puts the `stick_tip_l`/`stick_tip_r` nodes where the motion CSV has the tips
/// (glTF axes, Y up and the performer facing +Z: (−x, z, y)) within 1 mm in every tenth frame.
#[test]
fn glb_animates_every_joint_and_reaches_the_tips() {
    use glam::{DMat4, DQuat, DVec3};
    let dir = tempfile::tempdir().unwrap();
    let (wav, csv, glb) = (
        dir.path().join("out.wav"),
        dir.path().join("motion.csv"),
        dir.path().join("scene.glb"),
    );
    let args = [
        "--wav".as_ref(),
        wav.as_os_str(),
        "--motion".as_ref(),
        csv.as_os_str(),
        "--glb".as_ref(),
        glb.as_os_str(),
    ];
    ok(&render("scores/improvisation.ron", &args));
    let (header, rows) = csv_rows(&csv);
    let gltf = gltf::Gltf::from_slice(&std::fs::read(&glb).unwrap()).unwrap();
    let blob = gltf.blob.clone().unwrap();
    let names: Vec<String> = gltf
        .nodes()
        .map(|n| n.name().unwrap_or_default().to_string())
        .collect();
    let joints = [
        "trunk",
        "neck",
        "head",
        "shoulder_l",
        "elbow_l",
        "wrist_l",
        "grip_l",
        "shoulder_r",
        "elbow_r",
        "wrist_r",
        "grip_r",
    ];
    assert_eq!(gltf.scenes().count(), 1);
    assert!(names.iter().any(|n| n == "23-inch"), "the solo kit's drum");
    assert!(gltf.meshes().count() >= 3);
    let animation = gltf.animations().next().unwrap();
    assert_eq!(gltf.animations().count(), 1);
    let mut rotations: std::collections::HashMap<usize, Vec<[f32; 4]>> = Default::default();
    for channel in animation.channels() {
        assert_eq!(
            channel.target().property(),
            gltf::animation::Property::Rotation
        );
        let sampler = channel.sampler();
        assert_eq!(sampler.input().count(), rows.len());
        assert_eq!(sampler.output().count(), rows.len());
        let reader = channel.reader(|_| Some(&blob[..]));
        let times: Vec<f32> = reader.read_inputs().unwrap().collect();
        assert!((f64::from(times[1] - times[0]) - 0.004).abs() < 1e-6);
        let gltf::animation::util::ReadOutputs::Rotations(r) = reader.read_outputs().unwrap()
        else {
            panic!("not rotations")
        };
        rotations.insert(channel.target().node().index(), r.into_f32().collect());
    }
    let mut animated: Vec<&str> = rotations.keys().map(|&i| names[i].as_str()).collect();
    animated.sort();
    let mut want = joints.to_vec();
    want.sort();
    assert_eq!(
        animated, want,
        "a channel for every joint node and no other"
    );
    // Parents, then each node's world transform at frame k.
    let mut parent = vec![None; names.len()];
    for n in gltf.nodes() {
        for c in n.children() {
            parent[c.index()] = Some(n.index());
        }
    }
    let world = |node: usize, k: usize| {
        let mut m = DMat4::IDENTITY;
        let mut at = Some(node);
        while let Some(i) = at {
            let (t, r, s) = gltf.nodes().nth(i).unwrap().transform().decomposed();
            let r = rotations.get(&i).map_or(r, |v| v[k]);
            let local = DMat4::from_scale_rotation_translation(
                DVec3::from(s.map(f64::from)),
                DQuat::from_array(r.map(f64::from)).normalize(),
                DVec3::from(t.map(f64::from)),
            );
            m = local * m;
            at = parent[i];
        }
        m.transform_point3(DVec3::ZERO)
    };
    let tips = ["stick_tip_l", "stick_tip_r"].map(|n| names.iter().position(|m| m == n).unwrap());
    let mut worst = 0.0f64;
    for (k, row) in rows.iter().enumerate().step_by(10) {
        for (tip, hand) in tips.iter().zip(["left", "right"]) {
            let want = DVec3::from(tip_y_up(&header, row, hand, 1.0));
            worst = worst.max(world(*tip, k).distance(want));
        }
    }
    eprintln!("glTF tips vs motion CSV: worst {worst} m");
    assert!(worst < 1e-3, "worst tip distance {worst} m");
}
