//! `timpanist sound …`: measure notes ([`crate::sound::analysis`]).

use crate::io::figures::{spectra_figure, spectrum_panel};
use crate::sound::analysis::{self, OCTAVE_CENTRES_HZ};
use crate::sound::calibration::{Calibration, Residual};
use crate::sound::fit::{self, Note};
use std::path::{Path, PathBuf};

/// How far past the range of the nearest standard drum `sound stroke` tunes its head,
/// semitones: a fifth (a C2 on the 32-inch drum, whose range starts at D2).
const MAX_SEMITONES_PAST_RANGE: i32 = 7;

/// Render one scripted stroke at `pitch` and `dynamic` to a mono WAV, heard in `room`;
/// a pitch more than a fifth past every standard drum's range is refused.
pub fn stroke(
    (pitch, dynamic): (&str, crate::score::Dynamic),
    seconds: f64,
    room: crate::sound::Room,
    wav: &Path,
) -> anyhow::Result<()> {
    let pitch: crate::base::pitch::Pitch = pitch.parse()?;
    if !(seconds.is_finite() && (0.1..=60.0).contains(&seconds)) {
        anyhow::bail!("--seconds {seconds} is outside 0.1-60 s");
    }
    let kit = fit::kit_for(pitch.hz());
    let drum = &kit.drums[0];
    let past = |edge: crate::base::pitch::Pitch| (i32::from(edge.0) - i32::from(pitch.0)).abs();
    if !drum.in_range(pitch) && past(drum.lowest).min(past(drum.highest)) > MAX_SEMITONES_PAST_RANGE
    {
        let standard = crate::kit::Kit::standard();
        let (low, high) = (
            standard
                .drums
                .iter()
                .map(|d| d.lowest)
                .min()
                .unwrap_or(drum.lowest),
            standard
                .drums
                .iter()
                .map(|d| d.highest)
                .max()
                .unwrap_or(drum.highest),
        );
        anyhow::bail!(
            "--pitch {pitch}: no timpani of the standard kit reaches it (they span {low}-{high}; a head may be tuned up to {MAX_SEMITONES_PAST_RANGE} semitones past its drum's range)"
        );
    }
    let (mut mono, contact) = fit::struck(&kit, dynamic, Calibration::shipped(), seconds)?;
    crate::sound::room::reverberate_mono(room, &mut mono);
    let audio = crate::sound::Audio {
        rate_hz: crate::sound::SAMPLE_RATE_HZ,
        channels: 1,
        samples: mono.into(),
        gain: 1.0,
    };
    crate::sound::write_wav(wav, &audio)?;
    println!(
        "{} on the {} tuned to {pitch}: {:?}{}",
        wav.display(),
        kit.drums[0].name,
        dynamic,
        if room.is_dry() {
            String::new()
        } else {
            format!(", in the {room}")
        }
    );
    if let Some(c) = contact {
        println!(
            "  contact {:.1} ms, peak force {:.1} N, impact speed {:.2} m/s",
            c.duration_s() * 1e3,
            c.peak_force_n,
            c.impact_speed_mps
        );
    }
    Ok(())
}

/// Fit the modal sound to `files` (default: the embedded recordings) and write `output`.
pub fn fit(files: &[PathBuf], output: &Path) -> anyhow::Result<()> {
    let notes: Vec<Note> = if files.is_empty() {
        fit::embedded_notes()?
    } else {
        files
            .iter()
            .map(|path| {
                let (samples, rate_hz) = read_recording(path)?;
                if let Some(why) = analysis::not_a_note(&samples, rate_hz) {
                    anyhow::bail!("{}: {why}", path.display());
                }
                let top = OCTAVE_CENTRES_HZ.len() - 1;
                let top_hz = analysis::band_top_hz(top);
                if f64::from(rate_hz) < 2.0 * top_hz {
                    anyhow::bail!(
                        "{}: recorded at {rate_hz} Hz, which cannot hold the fit's top octave \
                         band ({:.0} Hz, up to {top_hz:.0} Hz): the fit needs at least {:.0} Hz",
                        path.display(),
                        OCTAVE_CENTRES_HZ[top],
                        (2.0 * top_hz).ceil()
                    );
                }
                Ok(Note {
                    name: path.display().to_string(),
                    samples,
                    rate_hz,
                })
            })
            .collect::<anyhow::Result<_>>()?
    };
    let worst = |r: &[Residual]| {
        r.iter()
            .flat_map(|r| r.bands_db)
            .fold(0.0f64, |m, d| m.max(d.abs()))
    };
    let cal = fit::fit(&notes, &mut |round, residuals| {
        eprintln!(
            "round {round}: worst band residual {:.1} dB",
            worst(residuals)
        );
    })?;
    cal.save(output)?;
    for note in fit::bounds_reached(&cal) {
        eprintln!("note: {note}");
    }
    println!(
        "{} notes -> {}: worst band residual {:.1} dB",
        notes.len(),
        output.display(),
        worst(&cal.residuals)
    );
    for r in &cal.residuals {
        let bands: Vec<String> = r.bands_db.iter().map(|d| format!("{d:+.1}")).collect();
        println!(
            "  {}: model - recording {} dB",
            r.recording,
            bands.join(" ")
        );
    }
    Ok(())
}

/// A recording read to mono (samples, rate in Hz), its notes printed.
fn read_recording(path: &Path) -> anyhow::Result<(Vec<f32>, u32)> {
    let (samples, rate, notes) = crate::sound::recording::read_mono_noted(path)?;
    for note in notes {
        eprintln!("note: {note}");
    }
    Ok((samples, rate))
}

/// Print each file's measurements, one block per file (per note with `at`); with `plot`,
/// draw their spectra against the recordings. A file or note that cannot be measured is
/// named on stderr and the others are still measured; the command then fails, and no plot
/// is written.
pub fn analyse(files: &[PathBuf], at: &[f64], plot: Option<&Path>) -> anyhow::Result<()> {
    let mut panels = Vec::new();
    let (mut asked, mut failed) = (0, 0);
    let mut report = |result: anyhow::Result<()>| {
        asked += 1;
        if let Err(e) = result {
            eprintln!("error: {e:#}");
            failed += 1;
        }
    };
    for path in files {
        let (all, rate) = match read_recording(path) {
            Ok(read) => read,
            Err(e) => {
                report(Err(e));
                continue;
            }
        };
        let duration = all.len() as f64 / f64::from(rate);
        let starts: Vec<Option<f64>> = if at.is_empty() {
            vec![None]
        } else {
            at.iter().map(|t| Some(*t)).collect()
        };
        for (k, start) in starts.iter().copied().enumerate() {
            let from = match start {
                Some(t) if t.is_finite() && (0.0..duration).contains(&t) => {
                    ((t - 0.01).max(0.0) * f64::from(rate)) as usize
                }
                Some(t) => {
                    report(Err(anyhow::anyhow!(
                        "{}: --at {t} s is outside the file (0-{duration:.2} s)",
                        path.display()
                    )));
                    continue;
                }
                None => 0,
            };
            // A note ends where the next one asked for starts.
            let to = starts
                .get(k + 1)
                .copied()
                .flatten()
                .filter(|t| t.is_finite() && *t * f64::from(rate) > from as f64)
                .map_or(all.len(), |t| ((t - 0.01) * f64::from(rate)) as usize)
                .min(all.len());
            let label = start.map_or(String::new(), |t| format!(" at {t} s"));
            let name = format!("{}{label}", path.display());
            let measured = analyse_note(&name, &all[from..to], rate);
            if measured.is_ok() && plot.is_some() {
                panels.push(spectrum_panel(&name, &all[from..to], rate));
            }
            report(measured);
        }
    }
    if failed > 0 {
        let plot = plot.map_or(String::new(), |p| format!(" ({} not written)", p.display()));
        anyhow::bail!("{failed} of the {asked} notes asked for could not be measured{plot}");
    }
    if let Some(path) = plot {
        spectra_figure(panels).save_png(path)?;
        println!("spectra -> {}", path.display());
    }
    Ok(())
}

/// Print one note's measurements.
fn analyse_note(name: &str, samples: &[f32], rate: u32) -> anyhow::Result<()> {
    if let Some(why) = analysis::not_a_note(samples, rate) {
        anyhow::bail!("{name}: {why}");
    }
    let p = analysis::profile(samples, rate).ok_or_else(|| anyhow::anyhow!("{name}: silent"))?;
    println!("{name}");
    let after_s = samples.len() as f64 / f64::from(rate) - p.onset_s;
    if after_s < analysis::SHORT_NOTE_S {
        println!(
            "  note: only {after_s:.2} s after the onset; the bands and centroid are over that, \
             not a second"
        );
    }
    // The peak of the analysed span (the onset's first second).
    let from = (p.onset_s * f64::from(rate)) as usize;
    let span = &samples[from..(from + rate as usize).min(samples.len())];
    let peak = span.iter().fold(0.0f32, |m, s| m.max(s.abs()));
    println!(
        "  onset {:.3} s, rate {rate} Hz, peak {:.1} dBFS",
        p.onset_s,
        20.0 * peak.max(1e-12).log10()
    );
    // A band wholly above the file's Nyquist frequency holds nothing to measure.
    let nyquist_hz = f64::from(rate) / 2.0;
    let bands: Vec<String> = OCTAVE_CENTRES_HZ
        .iter()
        .zip(&p.bands_db)
        .enumerate()
        .map(|(i, (c, b))| {
            if analysis::band_top_hz(i) / 2f64 >= nyquist_hz {
                format!("{c:.0} Hz -")
            } else {
                format!("{c:.0} Hz {b:.1}")
            }
        })
        .collect();
    println!("  octave bands (dB of the total): {}", bands.join(", "));
    if analysis::band_top_hz(OCTAVE_CENTRES_HZ.len() - 1) > nyquist_hz {
        println!(
            "  note: recorded at {rate} Hz: the bands reaching above {nyquist_hz:.0} Hz (half \
             the rate) are measured only up to it; -: a band wholly above it"
        );
    }
    println!("  spectral centroid {:.0} Hz", p.centroid_hz);
    let decays: Vec<String> = OCTAVE_CENTRES_HZ
        .iter()
        .map(|&c| {
            analysis::band_t60(
                samples,
                rate,
                c,
                ((0.02, 1.0), 0.08),
                analysis::MIN_DECAY_DB,
            )
            .map_or(format!("{c:.0} Hz -"), |t| format!("{c:.0} Hz {t:.2} s"))
        })
        .collect();
    println!("  octave-band T60 over 0-1 s: {}", decays.join(", "));
    match p.principal_hz {
        Some(f) => {
            let t0 = p.onset_s;
            let span = ((t0 + 0.05, t0 + 1.5), 0.1);
            let t60 = analysis::partial_t60(samples, rate, f, span, analysis::MIN_DECAY_DB);
            let glide = analysis::glide_percent(samples, rate, f);
            print!("  (1,1) {f:.2} Hz");
            if let Some(t60) = t60 {
                print!(", T60 {t60:.2} s");
            }
            if let Some(g) = glide {
                print!(", glide {g:+.2} % (10-70 ms against 0.5-0.6 s)");
            }
            println!();
        }
        None => println!("  no kettledrum (1,1) found between 40 and 400 Hz"),
    }
    Ok(())
}
