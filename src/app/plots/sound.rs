//! The rendered sound: the waveform's envelope (the channel mean's min and max per bucket
//! of about a pixel, never every sample) on the linked time axis, and the magnitude
//! spectrum (dB re full scale against frequency on a log axis, Hann window,
//! `sound::spectrum`) of one strike: the first selected beat's, else the one nearest the
//! playhead, over [`ANALYSIS_S`] of audio from its first touch — overlaid with the
//! spectrum of the embedded recorded timpani note nearest the drum's tuning (FluidR3,
//! `sound::sample`), its frequencies scaled to the tuning and its strongest bin put level
//! with the stroke's, to hear and see how far the simulation is from a real drum.

use super::decimate::Envelope;
use super::linked::{MAX_POINTS, Outcome, Series, TimeLink, legend, time_plot};
use crate::render::Rendering;
use crate::render::strikes::StrikeEvent;
use crate::sound::Audio;
use eframe::egui::{self, Color32};
use egui_plot::{FilledArea, GridInput, GridMark, HoverPosition, Line, Plot, Span};
use std::collections::BTreeSet;

/// Audio analysed per strike, s.
pub const ANALYSIS_S: f64 = 0.5;
/// Lowest frequency plotted, Hz.
const LOWEST_HZ: f64 = 20.0;
/// Spectrum floor below its strongest bin, dB.
const RANGE_DB: f64 = 80.0;
const WAVE_COLOUR: Color32 = Color32::from_rgb(150, 200, 120);
const SPECTRUM_COLOUR: Color32 = Color32::from_rgb(230, 200, 120);
const RECORDED_COLOUR: Color32 = Color32::from_rgb(120, 170, 230);

/// Points and caches of one rendering.
#[derive(Default)]
pub struct SoundPlot {
    rendering: Option<u64>,
    envelope: Envelope,
    /// The envelope drawn last: its key (window bits, buckets) and bucket centres, minima
    /// and maxima.
    wave_key: Option<(Option<(u64, u64)>, usize)>,
    wave: [Vec<f64>; 3],
    /// The strike analysed (event index) and its spectrum (log10 Hz, dB).
    strike: Option<usize>,
    spectrum: Series,
    /// The recorded note's spectrum for that strike, and its name.
    recorded: Series,
    recorded_name: String,
}

/// The strike to analyse: the first contact of the first selected beat that has one,
/// else the scored strike nearest `playhead_s`, else the contact nearest it.
pub fn selected_strike(
    events: &[StrikeEvent],
    selected_beats: &BTreeSet<usize>,
    playhead_s: f64,
) -> Option<usize> {
    let of_selection = selected_beats.iter().find_map(|&b| {
        events
            .iter()
            .enumerate()
            .filter(|(_, e)| e.beat == Some(b))
            .min_by(|x, y| x.1.contact_s.total_cmp(&y.1.contact_s))
            .map(|(i, _)| i)
    });
    let nearest = |scored: bool| {
        events
            .iter()
            .enumerate()
            .filter(|(_, e)| !scored || e.beat.is_some())
            .min_by(|x, y| {
                (x.1.contact_s - playhead_s)
                    .abs()
                    .total_cmp(&(y.1.contact_s - playhead_s).abs())
            })
            .map(|(i, _)| i)
    };
    of_selection
        .or_else(|| nearest(true))
        .or_else(|| nearest(false))
}

/// Magnitude spectrum of the channel mean of `audio` over `window_s` from `t0_s`:
/// (log10 of frequency in Hz, level in dB re full scale) from [`LOWEST_HZ`] to Nyquist,
/// floored [`RANGE_DB`] below the strongest bin. Empty if the window holds no audio.
pub fn strike_spectrum(audio: &Audio, t0_s: f64, window_s: f64) -> Vec<[f64; 2]> {
    let rate = f64::from(audio.rate_hz);
    let a = ((t0_s * rate).round().max(0.0) as usize).min(audio.frames());
    let z = (((t0_s + window_s) * rate).round().max(0.0) as usize).min(audio.frames());
    let mono = audio.mono_of(a..z);
    let spec = crate::sound::spectrum(&mono, audio.rate_hz);
    let db = |amp: f64| 20.0 * amp.max(1e-12).log10();
    let top = spec
        .iter()
        .map(|&(_, m)| db(m))
        .fold(f64::NEG_INFINITY, f64::max);
    spec.into_iter()
        .filter(|&(f, _)| f >= LOWEST_HZ)
        .map(|(f, m)| [f.log10(), db(m).max(top - RANGE_DB)])
        .collect()
}

/// The spectrum of the recorded note nearest `tuning_hz` over [`ANALYSIS_S`] from its
/// onset ([`crate::sound::analysis::recorded_reference`]), as [`strike_spectrum`] draws
/// it, levels shifted so its strongest bin is at `top_db`; with the recording's name.
pub fn recorded_spectrum(tuning_hz: f64, top_db: f64) -> Option<(Vec<[f64; 2]>, String)> {
    let (name, spec) = crate::sound::analysis::recorded_reference(tuning_hz, ANALYSIS_S)?;
    let points = spec
        .into_iter()
        .filter(|&(f, _)| f >= LOWEST_HZ)
        .map(|(f, d)| [f.log10(), (d + top_db).max(top_db - RANGE_DB)])
        .collect();
    Some((points, name))
}

/// A frequency for an axis: "50 Hz", "1 kHz", "2.5 kHz".
fn hz_label(f: f64) -> String {
    if f >= 1000.0 {
        format!("{} kHz", (f / 100.0).round() / 10.0)
    } else {
        format!("{} Hz", f.round())
    }
}

/// Grid lines of a log10 frequency axis: every 1–9 × 10^k, decades the strongest.
fn log_grid(input: GridInput) -> Vec<GridMark> {
    let (lo, hi) = input.bounds;
    let mut marks = Vec::new();
    for decade in (lo.floor() as i32)..=(hi.ceil() as i32) {
        for m in 1..10 {
            let value = f64::from(decade) + f64::from(m).log10();
            if (lo..=hi).contains(&value) {
                let step_size = match m {
                    1 => 1.0,
                    2 | 5 => 0.3,
                    _ => 0.1,
                };
                marks.push(GridMark { value, step_size });
            }
        }
    }
    marks
}

/// One line naming a strike.
fn describe(e: &StrikeEvent) -> String {
    let what = match e.beat {
        Some(b) => format!("beat {b}"),
        None => "rebound".to_string(),
    };
    format!(
        "Spectrum of the strike at {:.3} s ({what}, {} hand, drum {}, {:.0} N peak, {:.1} ms contact), {:.1} s of sound",
        e.contact_s,
        e.hand,
        e.drum + 1,
        e.peak_force_n,
        e.duration_ms,
        ANALYSIS_S
    )
}

impl SoundPlot {
    /// The waveform and spectrum of rendering `r` (identified by `id`).
    pub fn show(
        &mut self,
        ui: &mut egui::Ui,
        r: &Rendering,
        id: u64,
        link: TimeLink,
        selected_beats: &BTreeSet<usize>,
    ) -> Outcome {
        let audio = &r.audio;
        if self.rendering != Some(id) {
            self.rendering = Some(id);
            self.envelope = Envelope::new(
                &audio.samples,
                usize::from(audio.channels),
                f64::from(audio.rate_hz),
            );
            self.wave_key = None;
            self.strike = None;
            self.spectrum = Series::default();
        }
        let strike = selected_strike(&r.events, selected_beats, link.playhead_s);
        if strike != self.strike {
            self.strike = strike;
            let points = strike.map_or_else(Vec::new, |i| {
                strike_spectrum(audio, r.events[i].contact_s, ANALYSIS_S)
            });
            let top = points
                .iter()
                .map(|p| p[1])
                .fold(f64::NEG_INFINITY, f64::max);
            let tuning = strike.and_then(|i| r.kit.drums.get(r.events[i].drum));
            let (recorded, name) = tuning
                .filter(|_| top.is_finite())
                .and_then(|d| recorded_spectrum(d.tuning.hz(), top))
                .unwrap_or_default();
            self.spectrum = Series::new(points);
            self.recorded = Series::new(recorded);
            self.recorded_name = name;
        }
        ui.label(
            strike.map_or("No strikes in this rendering.".to_string(), |i| {
                describe(&r.events[i])
            }),
        );
        let height = ui.available_height().max(100.0);
        let duration = audio.frames() as f64 / f64::from(audio.rate_hz);
        let (t0, t1) = link.window.unwrap_or((0.0, duration));
        let mut outcome = Outcome::default();
        let span = strike.map(|i| r.events[i].contact_s);
        let spectrum = self.spectrum.view(None);
        let recorded = self.recorded.view(None);
        let recorded_name = self.recorded_name.clone();
        ui.columns(2, |cols| {
            let buckets = (cols[0].available_width() as usize).clamp(16, MAX_POINTS / 2);
            let key = (
                link.window.map(|(a, b)| (a.to_bits(), b.to_bits())),
                buckets,
            );
            if self.wave_key != Some(key) {
                self.wave_key = Some(key);
                let b = self.envelope.buckets(&audio.samples, t0, t1, buckets);
                self.wave = [
                    b.iter().map(|b| 0.5 * (b.t0_s + b.t1_s)).collect(),
                    b.iter().map(|b| f64::from(b.min)).collect(),
                    b.iter().map(|b| f64::from(b.max)).collect(),
                ];
            }
            let [xs, lo, hi] = &self.wave;
            outcome.add(time_plot(
                &mut cols[0],
                "waveform",
                "output (L+R)/2",
                height,
                link,
                move |plot| {
                    plot.add(
                        FilledArea::new("waveform", xs, lo, hi)
                            .fill_color(WAVE_COLOUR.gamma_multiply(0.8)),
                    );
                    if let Some(t) = span {
                        plot.add(
                            Span::new("analysed strike", t..=t + ANALYSIS_S)
                                .fill(SPECTRUM_COLOUR.gamma_multiply(0.15)),
                        );
                    }
                },
            ));
            Plot::new("strike-spectrum")
                .height(height)
                .legend(legend())
                .x_axis_label("frequency (Hz)")
                .y_axis_label("level (dBFS)")
                .x_grid_spacer(log_grid)
                .x_axis_formatter(|mark, _| hz_label(10f64.powf(mark.value)))
                .label_formatter(|pos| {
                    let p = match pos {
                        HoverPosition::NearDataPoint { position, .. } => position,
                        HoverPosition::Elsewhere { position } => position,
                    };
                    Some(format!("{:.1} Hz\n{:.1} dB", 10f64.powf(p.x), p.y))
                })
                .include_x(LOWEST_HZ.log10())
                .include_x(f64::from(audio.rate_hz / 2).log10())
                .show(&mut cols[1], |plot| {
                    plot.line(
                        Line::new(recorded_name, recorded)
                            .color(RECORDED_COLOUR.gamma_multiply(0.7)),
                    );
                    plot.line(Line::new("simulated stroke", spectrum).color(SPECTRUM_COLOUR));
                });
        });
        outcome
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn event(beat: Option<usize>, t: f64) -> StrikeEvent {
        StrikeEvent {
            beat,
            hand: "right",
            drum: 0,
            scheduled_s: beat.map(|_| t),
            contact_s: t,
            duration_ms: 4.0,
            peak_force_n: 60.0,
            impact_speed_mps: 3.0,
            x_m: 0.0,
            y_m: 0.5,
            recontacts: 0,
            mode: None,
            dynamic: None,
        }
    }

    /// The selected beat's strike wins; otherwise the scored strike nearest the playhead
    /// (not a nearer rebound); with only rebounds, the nearest contact.
    #[test]
    fn strike_selection() {
        let events = [
            event(Some(0), 1.0),
            event(None, 1.05),
            event(Some(1), 2.0),
            event(Some(1), 2.3),
        ];
        let none = BTreeSet::new();
        assert_eq!(selected_strike(&events, &none, 1.06), Some(0));
        assert_eq!(selected_strike(&events, &none, 1.7), Some(2));
        assert_eq!(selected_strike(&events, &BTreeSet::from([1]), 0.0), Some(2));
        assert_eq!(
            selected_strike(&events, &BTreeSet::from([7, 0]), 9.0),
            Some(0)
        );
        assert_eq!(selected_strike(&events[1..2], &none, 0.0), Some(0));
        assert_eq!(selected_strike(&[], &none, 0.0), None);
    }

    /// A 146.83 Hz tone starting at the strike peaks at that frequency near its level
    /// (−6 dB for amplitude 0.5), the floor is 80 dB under the peak, and the axis is
    /// log10 Hz from 20 Hz up.
    #[test]
    fn spectrum_of_a_tone() {
        let rate = 48_000;
        let mut samples = vec![0.0f32; 2 * rate];
        for k in rate / 2..rate {
            let v = 0.5 * (std::f64::consts::TAU * 146.83 * k as f64 / rate as f64).sin();
            samples[2 * k] = v as f32;
            samples[2 * k + 1] = v as f32;
        }
        let audio = Audio {
            rate_hz: rate as u32,
            channels: 2,
            samples: samples.into(),
            gain: 1.0,
        };
        let s = strike_spectrum(&audio, 0.5, ANALYSIS_S);
        let peak = s
            .iter()
            .copied()
            .fold([0.0, f64::MIN], |a, p| if p[1] > a[1] { p } else { a });
        assert!(
            (10f64.powf(peak[0]) / 146.83 - 1.0).abs() < 0.005,
            "{peak:?}"
        );
        assert!((peak[1] + 6.02).abs() < 0.2, "{peak:?}");
        assert!(s[0][0] >= LOWEST_HZ.log10() && s.windows(2).all(|w| w[0][0] < w[1][0]));
        let floor = s.iter().map(|p| p[1]).fold(f64::MAX, f64::min);
        assert!((floor - (peak[1] - RANGE_DB)).abs() < 0.5, "{floor}");
        assert!(
            strike_spectrum(&audio, 5.0, ANALYSIS_S).is_empty(),
            "past the end"
        );
        assert_eq!(hz_label(1000.0), "1 kHz");
        assert_eq!(hz_label(2500.0), "2.5 kHz");
        assert_eq!(hz_label(50.0), "50 Hz");
    }

    /// The overlay is the G2 recording pitched to D3: its strongest bin is where it was
    /// put, and its (1,1) is a peak at the tuning.
    #[test]
    fn recorded_note_overlay() {
        let (points, name) = recorded_spectrum(146.83, -10.0).unwrap();
        assert!(name.contains("Timpani_3L"), "{name}");
        let top = points
            .iter()
            .map(|p| p[1])
            .fold(f64::NEG_INFINITY, f64::max);
        assert!((top + 10.0).abs() < 1e-9, "{top}");
        // The recording's (1,1), pitched to the tuning, is a peak within 1 % of it.
        let near: Vec<&[f64; 2]> = points
            .iter()
            .filter(|p| (10f64.powf(p[0]) / 146.83 - 1.0).abs() < 0.01)
            .collect();
        let around: Vec<&[f64; 2]> = points
            .iter()
            .filter(|p| (10f64.powf(p[0]) / 146.83 - 1.0).abs() < 0.1)
            .collect();
        let peak_near = near.iter().map(|p| p[1]).fold(f64::NEG_INFINITY, f64::max);
        let peak_around = around
            .iter()
            .map(|p| p[1])
            .fold(f64::NEG_INFINITY, f64::max);
        assert_eq!(peak_near, peak_around);
    }

    /// Decades and their 2 and 5 are the stronger grid lines; marks stay in bounds.
    #[test]
    fn log_grid_marks() {
        let marks = log_grid(GridInput {
            bounds: (1.3, 3.0),
            base_step_size: 0.01,
        });
        assert!(marks.iter().all(|m| (1.3..=3.0).contains(&m.value)));
        let at = |f: f64| {
            marks
                .iter()
                .find(|m| (m.value - f.log10()).abs() < 1e-9)
                .map(|m| m.step_size)
        };
        assert_eq!(at(100.0), Some(1.0));
        assert_eq!(at(500.0), Some(0.3));
        assert_eq!(at(30.0), Some(0.1));
        assert_eq!(at(10.0), None);
    }
}
