//! The lab network: a private 192.168.4.0/24 on the lab's access point (README.md), where board
//! A of robot `n` listens for the server board and the server board for the ground; and who
//! may speak to whom on it (decision `sdls-scope`, issue 38): board A takes its command
//! connection only from the server board's address ([`command_peer`]), the server board takes a
//! visit's heartbeat only from the visited board A's address ([`visit_peer`]), and FARM-1 obeys
//! a BC frame only from the ground's address ([`origin`]). The WPA2 passphrase has no default
//! ([`password`]: the images do not build without one).
//!
//! These checks keep a station on the WiFi that is not the peer from holding board A's one
//! connection or posing as board A; an attacker with the passphrase who takes over a peer's
//! address (ARP spoofing, a forged source) is not kept out by them (firmware/README.md).

use mmic::node::server::frames::Origin;
use mmic::units::BoardNumber;

/// TCP port of board A's command socket.
pub const PORT: u16 = 5000;
/// The server board's address.
pub const SERVER: [u8; 4] = [192, 168, 4, 2];
/// The ground station's address (YAMCS), where the server board sends its TM frames.
pub const GROUND: [u8; 4] = [192, 168, 4, 3];
/// UDP port on the server board where TC transfer frames arrive (YAMCS `UdpTcFrameLink`'s
/// `port`). `spec/ccsds/link.toml` gives no port; 10025 and 10015 are YAMCS's own examples'.
pub const TC_PORT: u16 = 10025;
/// UDP port on the ground where TM transfer frames go (YAMCS `UdpTmFrameLink`'s `port`).
pub const TM_PORT: u16 = 10015;
/// The lab network's name, at build time (`MMIC_SSID`; not a secret).
pub const SSID: &str = match option_env!("MMIC_SSID") {
    Some(s) => s,
    None => "mmic",
};
/// The passphrase the images once took when none was given (public, in this tree's history):
/// refused.
pub const OLD_DEFAULT_PASSWORD: &str = "mmic-password";

/// Board A of robot `n` (192.168.4.(10 + n), wrapping).
pub const fn robot(n: u8) -> [u8; 4] {
    [192, 168, 4, 10u8.wrapping_add(n)]
}

/// An IPv4 endpoint as a socket names its peer: address, port.
pub type Endpoint = ([u8; 4], u16);

/// Where a TC datagram came from, for FARM-1's BC rule: the ground only from [`GROUND`]
/// (any port: YAMCS sends from a port of its system's choosing); an unknown source is
/// elsewhere.
pub fn origin(from: Option<[u8; 4]>) -> Origin {
    if from == Some(GROUND) {
        Origin::Ground
    } else {
        Origin::Elsewhere
    }
}

/// Whether board A keeps a command connection it accepted from `remote`: only from the server
/// board's address (any port: the server connects from an ephemeral one). Any other peer, or
/// one the socket cannot name, is aborted at once, before a byte of it is read.
pub fn command_peer(remote: Option<Endpoint>) -> bool {
    matches!(remote, Some((addr, _)) if addr == SERVER)
}

/// Whether the server board takes a heartbeat from the peer of its visit of robot `board`:
/// only from that robot's board A, at its address and command port.
pub fn visit_peer(board: BoardNumber, remote: Option<Endpoint>) -> bool {
    remote == Some((robot(board.get()), PORT))
}

/// The WPA2 passphrase given at build time (`option_env!("MMIC_PASSWORD")`), or why it is
/// refused: missing (there is no default), not 8..=63 printable ASCII characters (WPA2's
/// passphrase), or [`OLD_DEFAULT_PASSWORD`]. The WiFi images evaluate it in a constant, so a
/// refusal stops their build with the reason (crate `wifi`).
pub const fn password(given: Option<&'static str>) -> Result<&'static str, &'static str> {
    let Some(p) = given else {
        return Err(
            "MMIC_PASSWORD is not set: the WiFi images (board A, the server board) need \
                    the lab access point's WPA2 passphrase at build time, 8..=63 printable ASCII \
                    characters; there is no default (firmware/README.md, \"Build\")",
        );
    };
    let b = p.as_bytes();
    if b.len() < 8 {
        return Err(
            "MMIC_PASSWORD is shorter than 8 characters: a WPA2 passphrase has 8..=63 \
                    printable ASCII characters",
        );
    }
    if b.len() > 63 {
        return Err(
            "MMIC_PASSWORD is longer than 63 characters: a WPA2 passphrase has 8..=63 \
                    printable ASCII characters",
        );
    }
    let mut i = 0;
    while i < b.len() {
        if b[i] < 0x20 || b[i] > 0x7E {
            return Err(
                "MMIC_PASSWORD holds a character outside printable ASCII: a WPA2 \
                        passphrase has 8..=63 printable ASCII characters",
            );
        }
        i += 1;
    }
    let old = OLD_DEFAULT_PASSWORD.as_bytes();
    if b.len() == old.len() {
        let mut same = true;
        let mut i = 0;
        while i < b.len() {
            if b[i] != old[i] {
                same = false;
            }
            i += 1;
        }
        if same {
            return Err(
                "MMIC_PASSWORD is the old public default `mmic-password`: give the lab \
                        access point's own passphrase",
            );
        }
    }
    Ok(p)
}
