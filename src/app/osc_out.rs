//! Live OSC output during playback: each contact of the current rendering sent as an
//! `/timpanist/hit` message (`io::osc`) over UDP when the playhead passes it (once per
//! frame, so up to a frame late), off by default, with its host and port set in the
//! inspector's "Live OSC output" section (kept for the session, not in the score).
//! Seeking or a loop wrap — the playhead moving back, or further than the wall clock
//! by more than [`MAX_DRIFT_S`] — sends nothing for what was skipped; a slow frame sends
//! what it passed. A send that fails is shown in the section and the output goes on.

use crate::base::hit::Hit;
use crate::io::osc;
use crate::render::Rendering;
use eframe::egui;
use std::net::{SocketAddr, ToSocketAddrs, UdpSocket};
use std::sync::Arc;
use std::time::Instant;

/// A playhead step differing from the wall-clock time between two frames by more than
/// this is a jump (nothing sent), s.
pub const MAX_DRIFT_S: f64 = 0.1;

/// Where to send, as edited.
#[derive(Clone, Debug, PartialEq)]
pub struct OscSettings {
    pub enabled: bool,
    pub host: String,
    pub port: u16,
}

impl Default for OscSettings {
    /// Off, aimed at Pure Data's usual port on this machine.
    fn default() -> Self {
        OscSettings {
            enabled: false,
            host: "127.0.0.1".into(),
            port: 9000,
        }
    }
}

/// How the playhead came to where it is this frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Step {
    /// Playback started from this position, s.
    Started(f64),
    /// Playing on: the wall-clock time since last frame, s.
    Played(f64),
}

/// The output: settings, socket, the rendering's hits and where the playhead was.
#[derive(Default)]
pub struct OscOut {
    pub settings: OscSettings,
    /// The socket and the settings it was opened for.
    socket: Option<(UdpSocket, String, u16)>,
    /// The hits and the rendering they were taken from.
    hits: Option<(Arc<Rendering>, Vec<Hit>)>,
    /// The playhead last frame while playing, s, and when that frame was.
    last: Option<(f64, Instant)>,
    /// The playhead while stopped: where playback starts, s.
    paused_s: f64,
    /// Messages sent since the output was turned on.
    pub sent: usize,
    pub error: Option<String>,
}

impl OscOut {
    /// Once per frame: send the hits of `rendering` the playhead passed since last frame.
    pub fn tick(&mut self, playing: bool, playhead_s: f64, rendering: Option<&Arc<Rendering>>) {
        let now = Instant::now();
        let Some(r) = rendering.filter(|_| self.settings.enabled && playing) else {
            // Where playback will start from.
            self.last = None;
            self.paused_s = playhead_s;
            return;
        };
        let (from, hits) = match self.hits.take() {
            Some((from, hits)) if Arc::ptr_eq(&from, r) => (from, hits),
            _ => (Arc::clone(r), r.events.iter().map(|e| e.hit()).collect()),
        };
        let step = match self.last {
            Some((_, at)) => Step::Played((now - at).as_secs_f64()),
            None => Step::Started(self.paused_s),
        };
        self.send_due((playhead_s, step), &hits);
        self.last = Some((playhead_s, now));
        self.hits = Some((from, hits));
    }

    /// Send the hits of `hits` (time order) that sounded on the way to `playhead_s`.
    pub fn send_due(&mut self, (playhead_s, step): (f64, Step), hits: &[Hit]) {
        // From `p` on, and from the start of the audio what sounds at it too (a contact a
        // moment before score time 0).
        let from = |p: f64| {
            if p <= 0.0 {
                f64::NEG_INFINITY
            } else {
                p - 1e-9
            }
        };
        let after = match (step, self.last) {
            (Step::Started(p), _) => from(p),
            (Step::Played(wall), Some((last, _)))
                if playhead_s >= last && (playhead_s - last - wall).abs() <= MAX_DRIFT_S =>
            {
                last
            }
            (Step::Played(_), _) => from(playhead_s), // a seek or a loop wrap
        };
        self.last = Some((playhead_s, Instant::now()));
        let due = osc::due(hits, after, playhead_s);
        if due.is_empty() {
            return;
        }
        let socket = match self.socket() {
            Ok(s) => s,
            Err(e) => {
                self.error = Some(e);
                return;
            }
        };
        let mut sent = 0;
        let failed = due
            .iter()
            .map(|hit| socket.send(&osc::encode(hit)).map(|_| sent += 1))
            .find_map(Result::err);
        self.sent += sent;
        self.error = failed.map(|e| format!("sending to {}: {e}", self.target()));
    }

    fn target(&self) -> String {
        format!("{}:{}", self.settings.host, self.settings.port)
    }

    /// The socket for the current settings, opened (and the host resolved) when they
    /// changed.
    fn socket(&mut self) -> Result<&UdpSocket, String> {
        let (host, port) = (self.settings.host.trim().to_string(), self.settings.port);
        if self
            .socket
            .as_ref()
            .is_none_or(|(_, h, p)| *h != host || *p != port)
        {
            self.socket = None;
            let target: SocketAddr = (host.as_str(), port)
                .to_socket_addrs()
                .map_err(|e| format!("{}: {e}", self.target()))?
                .next()
                .ok_or_else(|| format!("{}: the host has no address", self.target()))?;
            let local = if target.is_ipv4() {
                "0.0.0.0:0"
            } else {
                "[::]:0"
            };
            let socket = UdpSocket::bind(local)
                .and_then(|s| s.connect(target).map(|()| s))
                .and_then(|s| s.set_nonblocking(true).map(|()| s))
                .map_err(|e| format!("{target}: {e}"))?;
            self.socket = Some((socket, host, port));
        }
        Ok(&self.socket.as_ref().expect("opened above").0)
    }

    /// The inspector's "Live OSC output" section.
    pub fn ui(&mut self, ui: &mut egui::Ui) {
        ui.collapsing("Live OSC output", |ui| {
            let was = self.settings.enabled;
            ui.checkbox(&mut self.settings.enabled, "Send hits during playback")
                .on_hover_text("One /timpanist/hit message per contact, when it sounds");
            if self.settings.enabled && !was {
                self.sent = 0;
                self.error = None;
            }
            egui::Grid::new("osc").num_columns(2).show(ui, |ui| {
                let label = ui.label("Host");
                ui.text_edit_singleline(&mut self.settings.host)
                    .labelled_by(label.id);
                ui.end_row();
                let label = ui.label("Port");
                ui.add(egui::DragValue::new(&mut self.settings.port).range(1..=65535))
                    .labelled_by(label.id);
                ui.end_row();
            });
            match &self.error {
                Some(e) => ui.colored_label(ui.visuals().error_fg_color, e),
                None if self.settings.enabled => ui.label(format!("{} hits sent", self.sent)),
                None => ui.label("off"),
            };
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kit::Side;
    use std::time::Duration;

    fn hit(time_s: f64) -> Hit {
        Hit {
            time_s,
            drum: 0,
            side: Side::Right,
            x_m: 0.1,
            y_m: 0.4,
            peak_force_n: 70.0,
            impact_speed_mps: 2.0,
            primary: true,
        }
    }

    /// Playing through frames sends each hit once, in order, when the playhead passes
    /// it — from the start position on, nothing skipped by a jump — to a real UDP
    /// receiver on loopback; the message decodes with rosc.
    #[test]
    fn sends_each_hit_once_when_it_sounds() {
        let rx = UdpSocket::bind("127.0.0.1:0").unwrap();
        rx.set_read_timeout(Some(Duration::from_secs(2))).unwrap();
        let mut out = OscOut {
            settings: OscSettings {
                enabled: true,
                host: "127.0.0.1".into(),
                port: rx.local_addr().unwrap().port(),
            },
            ..OscOut::default()
        };
        let hits: Vec<Hit> = [0.5, 0.52, 0.9, 1.5, 2.0, 3.0]
            .into_iter()
            .map(hit)
            .collect();
        // Frames every 16 ms from 0.5 s (exactly on the first hit) to 1.19 s, one slow
        // frame of 0.4 s, then a seek to 2.95 s and frames to 3.14 s.
        let mut frames: Vec<(f64, Step)> = vec![(0.5, Step::Started(0.5))];
        frames.extend((1..44).map(|k| (0.5 + 0.016 * f64::from(k), Step::Played(0.016))));
        frames.push((1.6, Step::Played(0.4)));
        frames.push((2.95, Step::Played(0.016)));
        frames.extend((1..13).map(|k| (2.95 + 0.016 * f64::from(k), Step::Played(0.016))));
        for f in frames {
            out.send_due(f, &hits);
        }
        assert_eq!(out.sent, 5, "{:?}", out.error);
        let mut times = Vec::new();
        let mut buf = [0u8; 1536];
        for _ in 0..5 {
            let n = rx.recv(&mut buf).unwrap();
            let (_, packet) = rosc::decoder::decode_udp(&buf[..n]).unwrap();
            let rosc::OscPacket::Message(m) = packet else {
                panic!("not a message")
            };
            assert_eq!(m.addr, "/timpanist/hit");
            times.push(m.args[6].clone().float().unwrap());
        }
        assert_eq!(
            times,
            vec![0.5, 0.52, 0.9, 1.5, 3.0],
            "2.0 s was sought past"
        );
        // A seek forward, or back to before a hit, sends nothing for what it skips...
        for t in [3.5, 0.3, 0.6] {
            out.send_due((t, Step::Played(0.016)), &hits);
        }
        assert_eq!(out.sent, 5);
        // ...and playing on from there sends the next hit.
        out.send_due((0.95, Step::Played(0.35)), &hits);
        assert_eq!(out.sent, 6);
        // Playback started at the start sends a contact a moment before score time 0,
        // even when the first frame comes later.
        let early = [hit(-1e-4), hit(0.01), hit(0.03)];
        out.send_due((0.02, Step::Started(0.0)), &early);
        assert_eq!(out.sent, 8);
        out.send_due((0.036, Step::Played(0.016)), &early);
        assert_eq!(out.sent, 9);
    }
}
