//! `render --osc HOST:PORT`: every contact of the rendering sent as an OSC
//! `/timpanist/hit` message (`io::osc`) over UDP, in time order — at once, or with
//! `--osc-realtime` each when it sounds, as if the WAV started playing (score time 0)
//! when sending began.

use crate::base::hit::Hit;
use crate::io::osc;
use std::net::{SocketAddr, ToSocketAddrs, UdpSocket};
use std::time::{Duration, Instant};

/// A UDP socket aimed at `host:port`, resolved and bound now (before the render, so a
/// bad address fails at once).
pub fn connect((host, port): &(String, u16)) -> anyhow::Result<UdpSocket> {
    let target: SocketAddr = (host.as_str(), *port)
        .to_socket_addrs()
        .map_err(|e| anyhow::anyhow!("--osc {host}:{port}: {e}"))?
        .next()
        .ok_or_else(|| anyhow::anyhow!("--osc {host}:{port}: the host has no address"))?;
    let local: SocketAddr = if target.is_ipv4() {
        "0.0.0.0:0"
    } else {
        "[::]:0"
    }
    .parse()
    .expect("a valid local address");
    let socket = UdpSocket::bind(local).map_err(|e| anyhow::anyhow!("--osc: {e}"))?;
    socket
        .connect(target)
        .map_err(|e| anyhow::anyhow!("--osc {target}: {e}"))?;
    Ok(socket)
}

/// What [`send`] did: messages sent, and of them how many the receiving host said no
/// program was listening for (UDP: the hit is lost, the next ones are still sent).
pub struct Sent {
    pub sent: usize,
    pub unheard: usize,
}

/// Send one message per hit in time order; with `realtime`, each at its score time
/// after the call.
pub fn send(socket: &UdpSocket, hits: &[Hit], realtime: bool) -> anyhow::Result<Sent> {
    let start = Instant::now();
    let mut unheard = 0;
    for hit in hits {
        if realtime {
            let due = Duration::from_secs_f64(hit.time_s.max(0.0));
            if let Some(wait) = due.checked_sub(start.elapsed()) {
                std::thread::sleep(wait);
            }
        }
        match socket.send(&osc::encode(hit)) {
            Ok(_) => {}
            // The port answered that nothing listens (an earlier datagram's ICMP
            // reply): a receiver may start later, so keep sending.
            Err(e) if e.kind() == std::io::ErrorKind::ConnectionRefused => unheard += 1,
            Err(e) => anyhow::bail!("--osc: sending a hit: {e}"),
        }
    }
    Ok(Sent {
        sent: hits.len(),
        unheard,
    })
}
