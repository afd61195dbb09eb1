//! Writing composed tip trajectories as CSV: one row per sample with the time and, per
//! hand, x, y, z (metres, performer frame), the beat (index into the score's beats, empty
//! when resting) and the phase (rest, preparation, impact, rebound).

use crate::motion::compose::Composition;
use std::fmt::Write;

/// The CSV text of `comp`.
pub fn to_csv(comp: &Composition) -> String {
    let mut out = String::from(
        "time_s,left_x_m,left_y_m,left_z_m,left_beat,left_phase,right_x_m,right_y_m,right_z_m,right_beat,right_phase\n",
    );
    for k in 0..comp.len() {
        write!(out, "{:.4}", comp.time(k)).expect("writing to a String");
        for h in 0..2 {
            let p = comp.tips[h][k];
            let tag = comp.tags[h][k];
            let beat = tag
                .stroke
                .map_or(String::new(), |s| comp.strokes[s].beat.to_string());
            write!(
                out,
                ",{:.6},{:.6},{:.6},{beat},{}",
                p.x,
                p.y,
                p.z,
                tag.phase.name()
            )
            .expect("writing to a String");
        }
        out.push('\n');
    }
    out
}
