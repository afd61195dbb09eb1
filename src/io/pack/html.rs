//! The lesson pack's `index.html`: one self-contained page (inline CSS, a few lines of
//! inline script, nothing fetched from the network) that refers only to the pack's own
//! files, by relative paths: the score as a table (time, bar and beat, hand, drum, mode,
//! dynamic, location), a player for the whole mix and one per phrase, the plots (SVG
//! images), every contact's numbers (timing error, contact time, peak force, impact
//! speed) and a list of the pack's files. The script marks the page
//! (`data-missing`, `data-plots-shown`) and shows a warning naming any file that did not
//! load, e.g. when `index.html` was copied without its folders.

use super::phrases::Phrase;
use crate::base::pitch::Pitch;
use crate::io::performance::{Contact, Performance};
use crate::score::{BarBeat, Beat, Dynamic, Hand};
use std::fmt::Write;

/// One file of the pack as the page lists it.
pub struct Listed {
    /// Path relative to the pack, with `/`.
    pub path: String,
    /// What it is, for the list.
    pub about: String,
}

/// One plot of the page.
pub struct Plot {
    pub path: String,
    pub caption: String,
    /// Its drawing size, px.
    pub size: (u32, u32),
}

/// What the page shows besides the performance.
pub struct Page<'a> {
    /// The whole mix, relative path.
    pub mix: &'a str,
    /// The phrases with their audio's relative path and span of the mix (s).
    pub phrases: &'a [(Phrase, String, (f64, f64))],
    pub plots: &'a [Plot],
    pub files: &'a [Listed],
}

/// `text` with `&`, `<`, `>` and quotes escaped for HTML text and attribute values.
pub fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

const STYLE: &str = "
body { font-family: system-ui, sans-serif; max-width: 1240px; margin: 1.5em auto; padding: 0 1em; color: #222; line-height: 1.4; }
h1 { margin-bottom: 0.2em; }
.meta { color: #555; margin-top: 0; }
nav a { margin-right: 1em; }
table { border-collapse: collapse; margin: 0.5em 0 1.5em; font-size: 0.92em; }
th, td { border-bottom: 1px solid #ddd; padding: 0.25em 0.6em; text-align: left; vertical-align: middle; }
td { white-space: nowrap; }
th { background: #f3f3f3; position: sticky; top: 0; }
td.n { text-align: right; font-variant-numeric: tabular-nums; }
tr.rebound td { color: #888; }
figure { margin: 1em 0 2em; }
figure img { max-width: 100%; height: auto; border: 1px solid #eee; }
figcaption { color: #444; font-size: 0.92em; }
audio { vertical-align: middle; }
.warning { background: #fff3cd; border: 1px solid #e0b000; padding: 0.6em 1em; }
.left { color: #1f77b4; } .right { color: #e67814; }
@media print { audio, nav, .warning { display: none; } th { position: static; } }
";

/// Checks that every image and audio file loaded; names the ones that did not.
const SCRIPT: &str = "
(function () {
  var missing = [];
  var note = document.getElementById('missing');
  function report(url) {
    if (missing.indexOf(url) >= 0) return;
    missing.push(url);
    note.hidden = false;
    note.textContent = 'These files of the pack did not load (keep index.html beside its folders): ' + missing.join(', ');
    document.body.setAttribute('data-missing', missing.join(' '));
  }
  var images = document.querySelectorAll('img');
  images.forEach(function (img) {
    if (img.complete && img.naturalWidth === 0) report(img.getAttribute('src'));
    img.addEventListener('error', function () { report(img.getAttribute('src')); });
  });
  document.querySelectorAll('audio').forEach(function (a) {
    if (a.error) report(a.getAttribute('src'));
    a.addEventListener('error', function () { report(a.getAttribute('src')); });
  });
  window.addEventListener('load', function () {
    var shown = 0;
    images.forEach(function (img) {
      if (img.naturalWidth > 0) shown += 1; else report(img.getAttribute('src'));
    });
    document.body.setAttribute('data-plots-shown', String(shown));
  });
})();
";

fn dynamic_name(d: Dynamic) -> String {
    match d {
        Dynamic::Velocity(v) => format!("velocity {v:.2} (≈ {})", d.nearest_mark()),
        mark => mark.nearest_mark().to_string(),
    }
}

/// The hand as scored, and as played when the sticking chose it.
fn hand_name(beat: &Beat, index: usize, p: &Performance) -> String {
    let played = p.strokes.iter().find(|s| s.beat == index).map(|s| s.hand);
    let side = |s: crate::kit::Side| format!("{s:?}").to_lowercase();
    match (beat.hand, played) {
        (Hand::Auto, Some(s)) => format!("auto: {}", side(s)),
        (Hand::Auto, None) => "auto".into(),
        (h, _) => format!("{h:?}").to_lowercase(),
    }
}

/// The beat's drum and the pitch it sounds (`pitch`).
fn drum_name(p: &Performance, beat: &Beat, pitch: Pitch) -> String {
    match p.kit.drums.get(beat.drum) {
        Some(d) => format!("{} ({pitch})", d.name),
        None => format!("drum {}", beat.drum),
    }
}

fn score_table(out: &mut String, p: &Performance) {
    let meter = p.score.meter_map();
    let tempo = p.score.tempo_map();
    out.push_str(
        "<table id=\"score-table\">\n<tr><th>beat</th><th>time (s)</th><th>bar:beat</th>\
         <th>hand</th><th>drum (pitch)</th><th>mode</th><th>dynamic</th><th>location</th>\
         <th>roll, damping</th></tr>\n",
    );
    let sounding = crate::score::tuning::sounding_pitches(p.score, p.kit);
    for (i, (b, &pitch)) in p.score.beats.iter().zip(&sounding).enumerate() {
        let pos = meter.position(b.tick);
        let mut extra = Vec::new();
        if let Some(r) = b.roll {
            let quarters = r.length_ticks as f64 / f64::from(p.score.ticks_per_quarter);
            extra.push(format!(
                "roll of {quarters:.2} quarters, {} strokes per quarter",
                r.strokes_per_quarter
            ));
        }
        if let Some(d) = b.damp {
            let quarters = d as f64 / f64::from(p.score.ticks_per_quarter);
            extra.push(format!("secco after {quarters:.2} quarters"));
        }
        let at = bar_beat(pos);
        let _ = writeln!(
            out,
            "<tr><td class=\"n\">{i}</td><td class=\"n\">{:.3}</td><td>{at}</td><td>{}</td>\
             <td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
            tempo.seconds_at(b.tick as f64),
            escape(&hand_name(b, i, p)),
            escape(&drum_name(p, b, pitch)),
            b.mode.name(),
            escape(&dynamic_name(b.dynamic)),
            escape(&b.location.name()),
            escape(&extra.join("; ")),
        );
    }
    out.push_str("</table>\n");
}

fn phrase_table(out: &mut String, page: &Page) {
    out.push_str(
        "<table id=\"phrases\">\n<tr><th>phrase</th><th>bars</th><th>beats</th>\
         <th>audio from–to (s)</th><th>listen</th></tr>\n",
    );
    for (k, (phrase, path, (from, to))) in page.phrases.iter().enumerate() {
        let beats = match (phrase.beats.first(), phrase.beats.last()) {
            (Some(a), Some(b)) if a != b => format!("{a}–{b}"),
            (Some(a), _) => a.to_string(),
            _ => String::new(),
        };
        let bars = if phrase.bars.start() == phrase.bars.end() {
            phrase.bars.start().to_string()
        } else {
            format!("{}–{}", phrase.bars.start(), phrase.bars.end())
        };
        let _ = writeln!(
            out,
            "<tr><td class=\"n\">{}</td><td>{bars}</td><td>{beats}</td>\
             <td class=\"n\">{from:.2}–{to:.2}</td>\
             <td><audio controls preload=\"metadata\" src=\"{}\"></audio></td></tr>",
            k + 1,
            escape(path)
        );
    }
    out.push_str("</table>\n");
}

/// "bar:beat", with "+ticks" into the beat when off it.
fn bar_beat(pos: BarBeat) -> String {
    if pos.tick == 0 {
        format!("{}:{}", pos.bar, pos.beat)
    } else {
        format!("{}:{}+{}", pos.bar, pos.beat, pos.tick)
    }
}

/// [`bar_beat`] of score time `t_s` (a roll's strokes each at their own).
fn bar_beat_at(p: &Performance, t_s: f64) -> String {
    let tick = p.score.tempo_map().tick_at(t_s).round().max(0.0) as u64;
    bar_beat(p.score.meter_map().position(tick))
}

fn contact_row(out: &mut String, p: &Performance, c: &Contact) {
    let drum = p
        .kit
        .drums
        .get(c.hit.drum)
        .map_or(format!("drum {}", c.hit.drum), |d| d.name.clone());
    let (beat, at, scheduled, error) = match (c.beat, c.scheduled_s, c.timing_error_s()) {
        (Some(b), Some(s), Some(e)) => (
            b.to_string(),
            bar_beat_at(p, s),
            format!("{s:.3}"),
            format!("{:+.2}", e * 1e3),
        ),
        _ => (
            "rebound".into(),
            String::new(),
            String::new(),
            String::new(),
        ),
    };
    let hand = c.hit.hand();
    let _ = writeln!(
        out,
        "<tr{}><td>{beat}</td><td>{at}</td><td class=\"{hand}\">{hand}</td><td>{}</td>\
         <td class=\"n\">{scheduled}</td><td class=\"n\">{:.3}</td><td class=\"n\">{error}</td>\
         <td class=\"n\">{:.2}</td><td class=\"n\">{:.1}</td><td class=\"n\">{:.2}</td>\
         <td class=\"n\">{}</td></tr>",
        if c.beat.is_none() {
            " class=\"rebound\""
        } else {
            ""
        },
        escape(&drum),
        c.hit.time_s,
        c.duration_s * 1e3,
        c.hit.peak_force_n,
        c.hit.impact_speed_mps,
        p.force_scale.velocity(c.hit.peak_force_n),
    );
}

fn contacts_table(out: &mut String, p: &Performance) {
    let errors: Vec<f64> = (p.contacts.iter())
        .filter_map(|c| c.timing_error_s().map(f64::abs))
        .collect();
    let played = errors.len();
    let mut sorted = errors.clone();
    sorted.sort_by(f64::total_cmp);
    let median = sorted.get(sorted.len() / 2).copied().unwrap_or(0.0);
    let worst = sorted.last().copied().unwrap_or(0.0);
    let _ = writeln!(
        out,
        "<p>{} contacts: {played} of the {} scheduled strokes found their contact \
         (median timing error {:.2} ms, worst {:.2} ms), {} rebounds and \
         re-contacts. Timing error is the contact's time minus the stroke's scheduled time \
         (positive: late); contact time is how long the felt touched the head; the MIDI \
         velocity is the one the performed MIDI file gives the stroke, from its peak \
         force. Beats are numbered from 0, as the editor numbers them.</p>",
        p.contacts.len(),
        p.strokes.len(),
        median * 1e3,
        worst * 1e3,
        p.contacts.len() - played
    );
    out.push_str(
        "<table id=\"contacts\">\n<tr><th>beat</th><th>bar:beat</th><th>hand</th><th>drum</th>\
         <th>scheduled (s)</th><th>contact (s)</th><th>timing error (ms)</th>\
         <th>contact time (ms)</th><th>peak force (N)</th><th>impact speed (m/s)</th>\
         <th>MIDI velocity</th></tr>\n",
    );
    for c in &p.contacts {
        contact_row(out, p, c);
    }
    out.push_str("</table>\n");
}

/// The kit's name as the score gives it: a bundled kit's name, or a kit file's stem.
fn kit_name(kit: &str) -> &str {
    let file = kit.rsplit(['/', '\\']).next().unwrap_or(kit);
    file.strip_suffix(".ron").unwrap_or(file)
}

/// The text of `index.html` for `p` with `page`'s files.
pub fn page(p: &Performance, page: &Page) -> String {
    let s = p.score;
    let title = escape(&s.title);
    let mut out = String::new();
    let _ = write!(
        out,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
         <title>{title}: lesson pack</title>\n<style>{STYLE}</style>\n</head>\n<body>\n"
    );
    let meter = s.meter.first().map_or("4/4".into(), |m| {
        format!("{}/{}", m.numerator, m.denominator)
    });
    let bpm = s.tempo.first().map_or(0.0, |t| t.bpm);
    let _ = writeln!(
        out,
        "<header>\n<h1>{title}</h1>\n<p class=\"meta\">{} beats on the {} kit ({} drums), \
         {meter} at {bpm:.0} bpm{}, {:?} grip; {:.1} s of sound ({} Hz, {} channels). \
         Performed by timpanist {}'s simulated timpanist.</p>\n</header>",
        s.beats.len(),
        escape(kit_name(&s.kit)),
        p.kit.drums.len(),
        if s.tempo.len() > 1 || s.meter.len() > 1 {
            " (changing later)"
        } else {
            ""
        },
        s.grip,
        p.duration_s(),
        p.audio.rate_hz,
        p.audio.channels,
        env!("CARGO_PKG_VERSION"),
    );
    out.push_str("<p id=\"missing\" class=\"warning\" hidden></p>\n");
    out.push_str(
        "<nav><a href=\"#listen\">Listen</a><a href=\"#score\">Score</a>\
         <a href=\"#plots\">Plots</a><a href=\"#strokes\">Strokes</a>\
         <a href=\"#files\">Files</a></nav>\n",
    );
    let _ = writeln!(
        out,
        "<section id=\"listen\">\n<h2>Listen</h2>\n<p>The whole performance: \
         <audio controls preload=\"metadata\" src=\"{}\"></audio></p>\n\
         <p>Phrase by phrase (runs of bars that hold strokes, cut at every rest of a whole \
         bar and after at most {} bars; each stops just before the next phrase starts):</p>",
        escape(page.mix),
        page.phrases
            .iter()
            .map(|(ph, _, _)| ph.bars.end() - ph.bars.start() + 1)
            .max()
            .unwrap_or(1)
    );
    phrase_table(&mut out, page);
    out.push_str("</section>\n<section id=\"score\">\n<h2>Score</h2>\n");
    score_table(&mut out, p);
    out.push_str("</section>\n<section id=\"plots\">\n<h2>Plots</h2>\n");
    for plot in page.plots {
        let _ = writeln!(
            out,
            "<figure><img src=\"{}\" alt=\"{}\" width=\"{}\" height=\"{}\">\
             <figcaption>{}</figcaption></figure>",
            escape(&plot.path),
            escape(&plot.caption),
            plot.size.0,
            plot.size.1,
            escape(&plot.caption)
        );
    }
    out.push_str("</section>\n<section id=\"strokes\">\n<h2>Each stroke's numbers</h2>\n");
    contacts_table(&mut out, p);
    out.push_str("</section>\n<section id=\"files\">\n<h2>Files in this pack</h2>\n<ul>\n");
    for f in page.files {
        let _ = writeln!(
            out,
            "<li><a href=\"{0}\">{0}</a>: {1}</li>",
            escape(&f.path),
            escape(&f.about)
        );
    }
    out.push_str("</ul>\n</section>\n");
    let _ = write!(out, "<script>{SCRIPT}</script>\n</body>\n</html>\n");
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Markup characters in text and attributes are escaped.
    #[test]
    fn escapes() {
        assert_eq!(
            escape("<a href=\"x\">Tom & 'Jerry'</a>"),
            "&lt;a href=&quot;x&quot;&gt;Tom &amp; &#39;Jerry&#39;&lt;/a&gt;"
        );
    }
}
