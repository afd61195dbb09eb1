//! Open Sound Control messages of the performed hits, for a sound server or a patch
//! listening live (the seeds' architecture sent every strike to one): one
//! `/timpanist/hit` message per contact with the arguments
//! `drum` (int, kit index), `hand` (string, "left" or "right"), `x`, `y` (float, where
//! the felt first touched, performer frame: x right, y forward, m), `force` (float, peak
//! contact force, N), `speed` (float, downward tip speed at first touch, m/s) and `time`
//! (float, score time of the first touch, s). Building and encoding only (rosc); the
//! sockets are the CLI's and the editor's.

use crate::base::hit::Hit;
use rosc::{OscMessage, OscPacket, OscType};

/// The address every hit is sent to.
pub const HIT_ADDRESS: &str = "/timpanist/hit";

/// The message for `hit`.
pub fn hit_message(hit: &Hit) -> OscMessage {
    OscMessage {
        addr: HIT_ADDRESS.to_string(),
        args: vec![
            OscType::Int(i32::try_from(hit.drum).unwrap_or(i32::MAX)),
            OscType::String(hit.hand().to_string()),
            OscType::Float(hit.x_m as f32),
            OscType::Float(hit.y_m as f32),
            OscType::Float(hit.peak_force_n as f32),
            OscType::Float(hit.impact_speed_mps as f32),
            OscType::Float(hit.time_s as f32),
        ],
    }
}

/// The UDP datagram for `hit`.
pub fn encode(hit: &Hit) -> Vec<u8> {
    rosc::encoder::encode(&OscPacket::Message(hit_message(hit)))
        .expect("encoding an OSC message to memory cannot fail")
}

/// The hits of `hits` (in time order) that sound after `after_s` and up to `up_to_s`
/// (score seconds): what a player moving its playhead between the two sends.
pub fn due(hits: &[Hit], after_s: f64, up_to_s: f64) -> &[Hit] {
    let from = hits.partition_point(|h| h.time_s <= after_s);
    let to = hits.partition_point(|h| h.time_s <= up_to_s).max(from);
    &hits[from..to]
}

/// A `HOST:PORT` (a name or address and a UDP port), checked for its shape: the port a
/// number 1–65535 and the host not empty. Resolving the name is the caller's.
pub fn parse_target(s: &str) -> Result<(String, u16), String> {
    let (host, port) = s
        .rsplit_once(':')
        .ok_or_else(|| format!("\"{s}\" is not HOST:PORT"))?;
    let host = host.trim_start_matches('[').trim_end_matches(']');
    let port: u16 = port
        .parse()
        .ok()
        .filter(|p| *p > 0)
        .ok_or_else(|| format!("\"{s}\": the port must be a number from 1 to 65535"))?;
    if host.is_empty() {
        return Err(format!("\"{s}\": no host before the port"));
    }
    Ok((host.to_string(), port))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kit::Side;

    fn hit(time_s: f64) -> Hit {
        Hit {
            time_s,
            drum: 2,
            side: Side::Left,
            x_m: -0.25,
            y_m: 0.5,
            peak_force_n: 80.0,
            impact_speed_mps: 2.5,
            primary: true,
        }
    }

    /// A hit encodes to a message rosc decodes back with the address and the seven
    /// arguments in order.
    #[test]
    fn message_round_trip() {
        let bytes = encode(&hit(1.5));
        let (rest, packet) = rosc::decoder::decode_udp(&bytes).unwrap();
        assert!(rest.is_empty());
        let OscPacket::Message(m) = packet else {
            panic!("not a message")
        };
        assert_eq!(m.addr, "/timpanist/hit");
        assert_eq!(
            m.args,
            vec![
                OscType::Int(2),
                OscType::String("left".into()),
                OscType::Float(-0.25),
                OscType::Float(0.5),
                OscType::Float(80.0),
                OscType::Float(2.5),
                OscType::Float(1.5),
            ]
        );
    }

    /// Hits are due once, in the window after the previous playhead up to the new one.
    #[test]
    fn due_windows() {
        let hits: Vec<Hit> = [0.1, 0.2, 0.2, 0.5].into_iter().map(hit).collect();
        assert_eq!(due(&hits, 0.0, 0.1).len(), 1);
        assert_eq!(due(&hits, 0.1, 0.2).len(), 2);
        assert_eq!(due(&hits, 0.2, 0.4).len(), 0);
        assert_eq!(due(&hits, 0.4, 0.3).len(), 0);
        assert_eq!(due(&hits, -1.0, 9.0).len(), 4);
    }

    /// Targets: host and port, IPv6 in brackets; bad ones say what is wrong.
    #[test]
    fn targets() {
        assert_eq!(
            parse_target("127.0.0.1:9000"),
            Ok(("127.0.0.1".into(), 9000))
        );
        assert_eq!(parse_target("[::1]:57120"), Ok(("::1".into(), 57120)));
        assert!(parse_target("localhost").unwrap_err().contains("HOST:PORT"));
        assert!(parse_target("localhost:0").unwrap_err().contains("port"));
        assert!(parse_target("localhost:x").unwrap_err().contains("port"));
        assert!(parse_target(":9000").unwrap_err().contains("host"));
    }
}
