//! A rendering's files: the one bridge from a `render::Rendering` (with the score it
//! rendered) to the plain parts the `io` writers take (`io::performance::Performance`),
//! from which every rendered export and the lesson pack (`io::pack`) are written. `io`
//! sits beside `render` and never names a rendering; `timpanist render`, `timpanist
//! export-pack` and the editor's File > Export all come through here, so each file is
//! made by one code path (the methods of `Performance`, and `io::pack::write`). The video
//! (`video`) is filmed here too: it draws the rendering through `scene`.

pub mod video;

use crate::io::midi_performed::ForceScale;
use crate::io::performance::{Contact, Performance};
use crate::render::Rendering;
use crate::render::strikes::StrikeEvent;
use crate::score::Score;

/// A contact event as the writers take it.
pub fn contact(e: &StrikeEvent) -> Contact {
    Contact {
        hit: e.hit(),
        beat: e.beat,
        scheduled_s: e.scheduled_s,
        duration_s: e.duration_ms * 1e-3,
    }
}

/// The plain parts of `r`, a rendering of `score`.
pub fn performance<'a>(r: &'a Rendering, score: &'a Score) -> Performance<'a> {
    Performance {
        score,
        kit: &r.kit,
        motion: &r.motion,
        reference: &r.reference,
        start_s: r.start_s,
        skeleton: r.skeleton(),
        audio: &r.audio,
        strokes: &r.composition.strokes,
        contacts: r.events.iter().map(contact).collect(),
        force_scale: ForceScale {
            at_silence_n: r.params.force_at_silence_n,
            range_n: r.params.force_range_n,
        },
    }
}
