//! The real audio path (issue 20): the editor's own [`Playback`] plays through kira, cpal
//! and ALSA into a PulseAudio null sink (`tests/scripts/audio-server.sh start`), and the
//! sink's monitor is recorded with `parec`.
//!
//! - The improvisation, rendered offline, is played (2048-frame buffers) and recorded: every stroke the onset
//!   detector of `transcribe` finds in the rendered audio is found in the recording within
//!   20 ms, after one constant offset (the latency) is taken off.
//! - The server is killed mid-play (the device disappears): playback falls back to the
//!   silent clock with its notice and the playhead keeps running; the server is started
//!   again and playback goes on on it by itself, and is heard in the recording.
//!
//! With no server (or no `timpanist_null` sink) each test prints "skipped: no PulseAudio
//! server (run tests/scripts/audio-server.sh start)" and passes — unless
//! `TIMPANIST_REQUIRE_AUDIO_SERVER=1` (CI sets it), where it fails. Run locally with
//! `eval "$(tests/scripts/audio-server.sh start)"` then
//! `cargo test --test audio_server -- --nocapture` (the measured figures are printed).

mod common;

use std::io::Read;
use std::process::{Child, Command, Stdio};
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};
use timpanist::app::playback::{DeviceEvent, LOST_NOTICE, Playback};
use timpanist::mocap::db::MotionDb;
use timpanist::render::{RenderParams, render};
use timpanist::score::LoadedScore;
use timpanist::transcribe::onsets;

use common::root;

/// The null sink the script makes.
const SINK: &str = "timpanist_null";
/// What a test says when it cannot run.
const SKIP: &str = "skipped: no PulseAudio server (run tests/scripts/audio-server.sh start)";
/// Set to 1 (CI) to fail instead of skipping.
const REQUIRE: &str = "TIMPANIST_REQUIRE_AUDIO_SERVER";
/// Sample rate of the recording and of the audio played, Hz.
const RATE: u32 = 48_000;
/// Frames per buffer asked of the default device (43 ms at 48 kHz, two of them). The
/// device's own choice through PulseAudio's ALSA plugin is two 10.7 ms periods, which
/// underran once in 17 runs on this 2-core machine while another build ran (a 60 ms gap
/// in the first stroke).
const BUFFER_FRAMES: u32 = 2048;
/// Each rendered onset must be heard this close to its time, s.
const TOLERANCE_S: f64 = 0.020;

/// One test at a time uses the server (one of them stops it).
static SERVER: Mutex<()> = Mutex::new(());

/// Skip (`None`, with the message) or, when required, fail: `why` the test cannot run.
fn skip(test: &str, why: &str) -> Option<MutexGuard<'static, ()>> {
    if std::env::var(REQUIRE).is_ok_and(|v| v == "1") {
        panic!("{REQUIRE}=1, but {test} cannot run: {why}; {SKIP}");
    }
    println!("{test}: {SKIP} ({why})");
    None
}

/// The server, held for this test; or skip (see [`skip`]).
fn server(test: &str) -> Option<MutexGuard<'static, ()>> {
    let guard = SERVER.lock().unwrap_or_else(PoisonError::into_inner);
    let why = match Command::new("pactl")
        .args(["list", "short", "sinks"])
        .output()
    {
        Err(e) => format!("pactl: {e}"),
        Ok(o) if !o.status.success() => {
            let said = String::from_utf8_lossy(&o.stderr)
                .trim()
                .replace('\n', "; ");
            match std::env::var("PULSE_SERVER") {
                Ok(_) => said,
                Err(_) => format!("{said}; PULSE_SERVER is not set: eval the script's output"),
            }
        }
        Ok(o) if String::from_utf8_lossy(&o.stdout).contains(SINK) => return Some(guard),
        Ok(_) => format!("the server has no sink {SINK}"),
    };
    drop(guard);
    skip(test, &why)
}

/// Run the script with `command`; its standard output.
fn script(command: &str) -> String {
    let out = Command::new("bash")
        .arg(root().join("tests/scripts/audio-server.sh"))
        .arg(command)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "audio-server.sh {command}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// Mono: the mean of the channels of interleaved stereo.
fn mono(stereo: &[f32]) -> Vec<f32> {
    stereo
        .chunks_exact(2)
        .map(|lr| 0.5 * (lr[0] + lr[1]))
        .collect()
}

/// The onset times of interleaved stereo at [`RATE`], s.
fn onset_times(stereo: &[f32]) -> Vec<f64> {
    onsets::detect(&mono(stereo), RATE)
        .iter()
        .map(|o| o.time_s)
        .collect()
}

/// What the recorder read: the bytes, and after each block when it arrived and how many
/// bytes had arrived by then.
type Recorded = (Vec<u8>, Vec<(Instant, usize)>);

/// `parec` on the sink's monitor (float stereo at [`RATE`]), read on a thread that notes
/// when each block arrived.
struct Recorder {
    child: Child,
    reader: JoinHandle<Recorded>,
}

impl Recorder {
    /// Start recording, and wait until the first audio arrives.
    fn start() -> Recorder {
        let mut child = Command::new("parec")
            .args([
                "-d",
                &format!("{SINK}.monitor"),
                "--raw",
                "--format=float32le",
            ])
            .args(["--rate=48000", "--channels=2", "--latency-msec=10"])
            .stdout(Stdio::piped())
            .spawn()
            .expect("parec (apt-get install pulseaudio-utils)");
        let mut stdout = child.stdout.take().unwrap();
        let (first_tx, first_rx) = std::sync::mpsc::channel();
        let reader = std::thread::spawn(move || {
            let (mut bytes, mut arrivals) = (Vec::new(), Vec::new());
            let mut block = [0u8; 8192];
            while let Ok(n) = stdout.read(&mut block) {
                if n == 0 {
                    break;
                }
                bytes.extend_from_slice(&block[..n]);
                arrivals.push((Instant::now(), bytes.len()));
                let _ = first_tx.send(());
            }
            (bytes, arrivals)
        });
        first_rx
            .recv_timeout(Duration::from_secs(5))
            .expect("parec recorded nothing in 5 s");
        Recorder { child, reader }
    }

    /// Stop: the interleaved samples, and when sample 0 was in the sink (the earliest
    /// that any block's arrival allows: a block is read after its last sample was played,
    /// so this is late by at most the monitor's delivery time).
    fn stop(mut self) -> (Vec<f32>, Instant) {
        self.child.kill().unwrap();
        self.child.wait().unwrap();
        let (bytes, arrivals) = self.reader.join().unwrap();
        let samples: Vec<f32> = bytes
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect();
        let start = arrivals
            .iter()
            .map(|&(at, len)| at - Duration::from_secs_f64(len as f64 / 8.0 / f64::from(RATE)))
            .min()
            .unwrap();
        (samples, start)
    }
}

/// The constant offset (recorded − rendered, s) that puts the most rendered onsets within
/// [`TOLERANCE_S`] of a recorded one (ties: the smaller total error), refined to the
/// median of those differences; and each rendered onset's error after it (`None` where
/// no recorded onset is that close).
fn align(rendered: &[f64], recorded: &[f64]) -> (f64, Vec<Option<f64>>) {
    let errors = |offset: f64| -> Vec<Option<f64>> {
        rendered
            .iter()
            .map(|r| {
                recorded
                    .iter()
                    .map(|c| c - r - offset)
                    .filter(|e| e.abs() <= TOLERANCE_S)
                    .min_by(|a, b| a.abs().total_cmp(&b.abs()))
            })
            .collect()
    };
    let score = |offset: f64| {
        let e = errors(offset);
        let found = e.iter().flatten().count();
        let total: f64 = e.iter().flatten().map(|x| x.abs()).sum();
        (found, -total)
    };
    let candidates = rendered
        .iter()
        .flat_map(|r| recorded.iter().map(move |c| c - r));
    let best = candidates
        .max_by(|a, b| score(*a).partial_cmp(&score(*b)).unwrap())
        .unwrap_or(0.0);
    let mut diffs: Vec<f64> = errors(best).iter().flatten().map(|e| best + e).collect();
    diffs.sort_by(f64::total_cmp);
    let offset = diffs.get(diffs.len() / 2).copied().unwrap_or(best);
    (offset, errors(offset))
}

/// The improvisation rendered offline with the defaults, after 0.5 s of silence (so its
/// first stroke is not at the very start), as interleaved stereo at [`RATE`].
fn rendered_improvisation() -> Vec<f32> {
    let loaded = LoadedScore::load(&root().join("scores/improvisation.ron")).unwrap();
    let db = MotionDb::load(&root().join("mocap")).unwrap();
    let rendering = render(&loaded, &db, &RenderParams::default(), &mut |_| true).unwrap();
    assert_eq!(rendering.audio.rate_hz, RATE);
    assert_eq!(rendering.audio.channels, 2);
    let mut samples = vec![0.0; RATE as usize];
    samples.extend(rendering.audio.samples.iter());
    samples
}

/// Call `check_device` every 20 ms for `seconds`, failing on any event.
fn keep_playing(p: &mut Playback, seconds: f64) {
    let t0 = Instant::now();
    while t0.elapsed().as_secs_f64() < seconds {
        if let Some(e) = p.check_device() {
            panic!("unexpected device event while playing: {e:?}");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// Call `check_device` every 20 ms until the device has run for about a second (a
/// stream that has just opened may wait seconds before it is first asked for audio),
/// failing on any event; how long that took, s.
fn wait_until_running(p: &mut Playback) -> f64 {
    let t0 = Instant::now();
    while !p.device_runs() {
        assert!(
            t0.elapsed() < Duration::from_secs(10),
            "the stream did not run in 10 s"
        );
        keep_playing(p, 0.02);
    }
    t0.elapsed().as_secs_f64()
}

/// Call `check_device` every 20 ms until it reports an event (within `limit_s`); the
/// event and how long it took.
fn wait_for_event(p: &mut Playback, limit_s: f64) -> (DeviceEvent, f64) {
    let t0 = Instant::now();
    loop {
        if let Some(e) = p.check_device() {
            return (e, t0.elapsed().as_secs_f64());
        }
        assert!(
            t0.elapsed().as_secs_f64() < limit_s,
            "no device event in {limit_s} s (notice: {:?})",
            p.notice()
        );
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// The rendered improvisation, played by the editor's playback on the null sink and
/// recorded from its monitor: each stroke heard within 20 ms of its rendered onset after
/// the one latency offset.
#[test]
fn played_strokes_reach_the_sink_on_time() {
    let Some(_server) = server("played_strokes_reach_the_sink_on_time") else {
        return;
    };
    let source = rendered_improvisation();
    let rendered = onset_times(&source);
    assert!(rendered.len() >= 5, "rendered onsets: {rendered:?}");
    let mut p = Playback::open(None, Some(BUFFER_FRAMES));
    assert!(
        p.has_device(),
        "the server answers but playback did not open: {:?}",
        p.notice()
    );
    assert_eq!(p.notice(), None);
    p.set_audio(Arc::new(source.clone())).unwrap();
    let started_s = wait_until_running(&mut p);

    let recorder = Recorder::start();
    keep_playing(&mut p, 0.3);
    let played_at = Instant::now();
    p.play_from(0.0);
    let seconds = source.len() as f64 / 2.0 / f64::from(RATE);
    keep_playing(&mut p, seconds + 0.7);
    let (position, wall) = (p.position_s(), played_at.elapsed().as_secs_f64());
    p.pause();
    let (recording, recorded_from) = recorder.stop();

    let recorded = onset_times(&recording);
    let (offset, errors) = align(&rendered, &recorded);
    let latency_ms = (offset - (played_at - recorded_from).as_secs_f64()) * 1e3;
    let worst_ms = errors.iter().flatten().fold(0.0f64, |w, e| w.max(e.abs())) * 1e3;
    let peak = |s: &[f32]| s.iter().fold(0.0f32, |m, x| m.max(x.abs()));
    let report = format!(
        "{} rendered onsets {rendered:.4?}; {} recorded {recorded:.4?}; latency {latency_ms:.1} ms \
         (play_from to the sink, from the recorder's clock); errors after it (ms) {:?}; worst \
         {worst_ms:.2} ms; peak rendered {:.3} recorded {:.3}; playback position {position:.3} s \
         after {wall:.3} s; the stream ran {started_s:.2} s after opening",
        rendered.len(),
        recorded.len(),
        errors
            .iter()
            .map(|e| e.map(|e| (e * 1e4).round() / 10.0))
            .collect::<Vec<_>>(),
        peak(&source),
        peak(&recording),
    );
    println!("{report}");
    assert!(
        errors.iter().all(Option::is_some),
        "a stroke not heard within 20 ms: {report}"
    );
    assert!(
        (0.5..2.0).contains(&(peak(&recording) / peak(&source))),
        "level: {report}"
    );
    assert!((position - wall).abs() < 0.1, "the tape's clock: {report}");
}

/// Restarts the script's server when dropped (a failed test leaves it running).
struct Restart;

impl Drop for Restart {
    fn drop(&mut self) {
        let _ = Command::new("bash")
            .arg(root().join("tests/scripts/audio-server.sh"))
            .arg("start")
            .output();
    }
}

/// Clicks every 0.25 s for `seconds`: a 2 kHz burst decaying over 5 ms, interleaved stereo.
fn clicks(seconds: f64) -> Vec<f32> {
    let n = (seconds * f64::from(RATE)) as usize;
    (0..n)
        .flat_map(|i| {
            let t = (i % (RATE as usize / 4)) as f64 / f64::from(RATE);
            let v =
                (0.5 * (2.0 * std::f64::consts::PI * 2000.0 * t).sin() * (-t / 0.005).exp()) as f32;
            [v, v]
        })
        .collect()
}

/// The server killed mid-play: the silent clock takes over with the notice and the
/// playhead keeps running; the server started again: playback returns to it by itself,
/// and the clicks are heard again in the sink's monitor.
#[test]
fn a_lost_server_falls_back_to_the_clock_and_comes_back() {
    let test = "a_lost_server_falls_back_to_the_clock_and_comes_back";
    let Some(_server) = server(test) else {
        return;
    };
    // Only the server the script started is stopped, never one of the user's own.
    let ours = script("env");
    let env = std::env::var("PULSE_SERVER").unwrap_or_default();
    if !ours.contains(&format!("PULSE_SERVER={env}")) || env.is_empty() {
        skip(
            test,
            &format!("PULSE_SERVER={env:?} is not the script's ({})", ours.trim()),
        );
        return;
    }
    let _restart = Restart;
    let mut p = Playback::open(None, Some(BUFFER_FRAMES));
    assert!(p.has_device(), "{:?}", p.notice());
    p.set_audio(Arc::new(clicks(60.0))).unwrap();
    let started_s = wait_until_running(&mut p);
    p.play_from(0.0);
    keep_playing(&mut p, 1.0);

    script("kill");
    let (lost, detected_s) = wait_for_event(&mut p, 3.0);
    let DeviceEvent::Lost(notice) = lost else {
        panic!("{lost:?}");
    };
    assert!(notice.starts_with(LOST_NOTICE), "{notice}");
    assert!(p.is_playing() && !p.has_device() && p.is_recovering());
    let before = p.position_s();
    keep_playing(&mut p, 1.5);
    let ran = p.position_s() - before;
    assert!((ran - 1.5).abs() < 0.1, "the playhead ran {ran} s in 1.5 s");

    script("start");
    let (back, back_s) = wait_for_event(&mut p, 5.0);
    assert_eq!(back, DeviceEvent::Back);
    assert!(p.has_device() && p.notice().is_none() && !p.is_recovering());
    let runs_s = wait_until_running(&mut p);
    let recorder = Recorder::start();
    let from = p.position_s();
    keep_playing(&mut p, 1.5);
    let ran = p.position_s() - from;
    let (recording, _) = recorder.stop();
    let heard = onset_times(&recording);
    println!(
        "the stream ran {started_s:.2} s after opening; lost {detected_s:.2} s after the \
         server was killed ({notice}); back {back_s:.2} s after it restarted, running \
         {runs_s:.2} s later; then {} clicks heard in 1.5 s, the playhead ran {ran:.3} s",
        heard.len()
    );
    assert!(heard.len() >= 3, "clicks heard after the return: {heard:?}");
    assert!((ran - 1.5).abs() < 0.1, "the playhead ran {ran} s in 1.5 s");
}
