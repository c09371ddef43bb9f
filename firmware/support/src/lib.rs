//! The MMIC-I firmware's shared glue: moves bytes and readings between the ESP32's peripherals
//! and the `mmic` library's pure nodes, and decides nothing (every decision is in `mmic`).
//!
//! Hardware-free parts build on the host and are tested there with mocked peripherals
//! (`tests/`); the esp-hal parts are behind `cfg(target_arch = "riscv32")`.
#![no_std]

pub mod control;
pub mod counters;
pub mod drivers;
pub mod durable;
pub mod link;
pub mod restart;
pub mod sensors;
pub mod server;

#[cfg(target_arch = "riscv32")]
pub mod chip;
#[cfg(target_arch = "riscv32")]
pub mod hw;
#[cfg(target_arch = "riscv32")]
pub mod wdt;

/// The A–B serial line's rate, baud.
pub const BAUD: u32 = 115_200;

/// Where board A of robot `n` listens for the server board, and the server board's address
/// (a private 192.168.4.0/24 network on the lab's access point, see README.md).
pub mod net {
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
    /// The lab network's name, at build time (`MMIC_SSID`).
    pub const SSID: &str = match option_env!("MMIC_SSID") {
        Some(s) => s,
        None => "mmic",
    };
    /// Its password, at build time (`MMIC_PASSWORD`).
    pub const PASSWORD: &str = match option_env!("MMIC_PASSWORD") {
        Some(s) => s,
        None => "mmic-password",
    };
    /// Board A of robot `n` (192.168.4.(10 + n), wrapping).
    pub const fn robot(n: u8) -> [u8; 4] {
        [192, 168, 4, 10u8.wrapping_add(n)]
    }
}
