//! Live OSC output during playback: each contact of the current rendering sent as an
//! `/timpanist/hit` message (`io::osc`) over UDP when the playhead passes it (once per
//! frame, so up to a frame late), off by default, with its host and port set in the
//! inspector's "Live OSC output" section (kept for the session, not in the score).
//! Seeking, a loop wrap or a jump of more than [`MAX_STEP_S`] sends nothing for what was
//! skipped. A send that fails is shown in the section and the output goes on.

use crate::base::hit::Hit;
use crate::io::osc;
use crate::render::Rendering;
use eframe::egui;
use std::net::{SocketAddr, ToSocketAddrs, UdpSocket};
use std::sync::Arc;

/// A playhead step longer than this between two frames is a jump (nothing sent), s.
pub const MAX_STEP_S: f64 = 0.25;

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

/// The output: settings, socket, the rendering's hits and where the playhead was.
#[derive(Default)]
pub struct OscOut {
    pub settings: OscSettings,
    /// The socket and the settings it was opened for.
    socket: Option<(UdpSocket, String, u16)>,
    /// The hits and the rendering they were taken from.
    hits: Option<(Arc<Rendering>, Vec<Hit>)>,
    /// The playhead last frame while playing, s.
    last_s: Option<f64>,
    /// Messages sent since the output was turned on.
    pub sent: usize,
    pub error: Option<String>,
}

impl OscOut {
    /// Once per frame: send the hits of `rendering` the playhead passed since last frame.
    pub fn tick(&mut self, playing: bool, playhead_s: f64, rendering: Option<&Arc<Rendering>>) {
        let Some(r) = rendering.filter(|_| self.settings.enabled && playing) else {
            self.last_s = None;
            return;
        };
        let (from, hits) = match self.hits.take() {
            Some((from, hits)) if Arc::ptr_eq(&from, r) => (from, hits),
            _ => (Arc::clone(r), r.events.iter().map(|e| e.hit()).collect()),
        };
        self.send_due(playhead_s, &hits);
        self.hits = Some((from, hits));
    }

    /// Send the hits of `hits` (time order) after last frame's playhead up to `playhead_s`.
    pub fn send_due(&mut self, playhead_s: f64, hits: &[Hit]) {
        let after = match self.last_s {
            Some(last) if playhead_s >= last && playhead_s - last <= MAX_STEP_S => last,
            // Just started: what sounds from here on.
            None => playhead_s - 1e-9,
            Some(_) => playhead_s, // a jump
        };
        self.last_s = Some(playhead_s);
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
        let hits: Vec<Hit> = [0.5, 0.52, 0.9, 3.0].into_iter().map(hit).collect();
        // Frames every 16 ms from 0.5 s (exactly on the first hit) to 1.2 s, then a jump
        // to 2.9 s and frames to 3.1 s.
        let frames = (0..44)
            .map(|k| 0.5 + 0.016 * f64::from(k))
            .chain((0..13).map(|k| 2.95 + 0.016 * f64::from(k)));
        for t in frames {
            out.send_due(t, &hits);
        }
        assert_eq!(out.sent, 4, "{:?}", out.error);
        let mut times = Vec::new();
        let mut buf = [0u8; 1536];
        for _ in 0..4 {
            let n = rx.recv(&mut buf).unwrap();
            let (_, packet) = rosc::decoder::decode_udp(&buf[..n]).unwrap();
            let rosc::OscPacket::Message(m) = packet else {
                panic!("not a message")
            };
            assert_eq!(m.addr, "/timpanist/hit");
            times.push(m.args[6].clone().float().unwrap());
        }
        assert_eq!(times, vec![0.5, 0.52, 0.9, 3.0]);
        // A jump past a hit sends nothing for it.
        out.send_due(3.5, &hits);
        out.send_due(0.0, &hits);
        out.send_due(0.6, &hits);
        assert_eq!(out.sent, 4);
    }
}
