//! Restarts: why a node last started, and how many times it has, as the ground hears it.
//!
//! A node of the robot restarts when its supply browns out (the bolters draw amps from one
//! battery), when a watchdog bites, when it panics, or when the operator cycles its power.
//! What each node keeps across a restart is a decision per node (`spec/decisions.toml`,
//! `restart-*`); what the ground must learn is *that* it happened and *why*. Board A says it in
//! heartbeat byte 59 (the last of the paper's three unused bytes after the bolter attempt):
//! the reset cause in the top three bits, the boot count modulo 32 in the low five. A byte that changes between two heartbeats
//! means board A restarted in between; 0 is what a paper-era robot (and a board that was
//! never told its cause) sends.
//!
//! ```
//! use mmic::restart::{Boot, ResetCause};
//! let b = Boot { cause: ResetCause::Watchdog, count: 33 };
//! assert_eq!(b.to_wire(), 0b101_00001); // cause 5, 33 mod 32 = 1
//! assert_eq!(Boot::from_wire(0b101_00001), Boot { cause: ResetCause::Watchdog, count: 1 });
//! assert_eq!(Boot::from_wire(0), Boot::UNREPORTED);
//! assert!(Boot::from_wire(0x21).differs(Boot::from_wire(0x22))); // restarted in between
//! ```
// req: D:restart-board-a, D:restart-board-b, D:restart-server, D:restart-ground

use crate::wire_enum::wire_enum;

wire_enum! {
    /// Why a node last started: the three bits heartbeat byte 59 and the ST\[5\] restart event
    /// carry. The ESP32's reset reasons map onto them in the firmware (`firmware/support`).
    #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Default)]
    #[cfg_attr(feature = "defmt", derive(defmt::Format))]
    #[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
    #[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
    pub enum ResetCause: u8 {
        /// Not reported: a paper-era robot, or a board started by a host that does not say.
        #[default]
        Unreported = 0 => "unreported",
        /// The supply came up (first power, or the operator cycled it).
        PowerOn = 1 => "power_on",
        /// The brown-out detector reset the chip (the battery sagged under load).
        BrownOut = 2 => "brown_out",
        /// Software asked for it (the operator's restart command, an update).
        Software = 3 => "software",
        /// The firmware panicked (the panic handler resets the chip).
        Panic = 4 => "panic",
        /// A watchdog (the RTC or a timer group's) was not fed in time.
        Watchdog = 5 => "watchdog",
        /// The reset pin (EN) was pulled.
        External = 6 => "external",
        /// Any other cause the chip reports (deep-sleep wake, JTAG, a CPU lock-up).
        Other = 7 => "other",
    }

    /// Every cause, in wire order.
    const ALL;
    /// The cause's three bits, 0..=7.
    pub const fn bits(self) -> u8;
    /// The cause of these three bits, if they are 0..=7.
    pub const fn from_three_bits(b: u8) -> Option<Self>;
    /// The cause's name, as logs, JSON and `spec/` use it.
    pub const fn name(self) -> &'static str;
}

impl ResetCause {
    /// The names logs, JSON and `spec/` use, in wire order.
    pub const NAMES: [&'static str; 8] = [
        ResetCause::ALL[0].name(),
        ResetCause::ALL[1].name(),
        ResetCause::ALL[2].name(),
        ResetCause::ALL[3].name(),
        ResetCause::ALL[4].name(),
        ResetCause::ALL[5].name(),
        ResetCause::ALL[6].name(),
        ResetCause::ALL[7].name(),
    ];

    /// The cause of three bits (the top bits of `bits & 7` are ignored: every value is one).
    pub const fn from_bits(bits: u8) -> ResetCause {
        match Self::from_three_bits(bits & 7) {
            Some(c) => c,
            // Never: every value of three bits is a cause.
            None => ResetCause::Other,
        }
    }

    /// Whether the chip lost its RTC memory too (a power cycle or a brown-out): what a node
    /// kept there is gone, only flash remains (decision `restart-board-a`).
    pub const fn loses_rtc_memory(self) -> bool {
        matches!(
            self,
            ResetCause::PowerOn | ResetCause::BrownOut | ResetCause::Unreported
        )
    }
}

impl core::fmt::Display for ResetCause {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.name())
    }
}

/// A node's start as heartbeat byte 59 carries it: the reset cause and the boot count modulo
/// 32 (the node keeps the whole count, [`u16`], in flash).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct Boot {
    /// Why the node last started.
    pub cause: ResetCause,
    /// Its boot count, modulo 32 on the wire.
    pub count: u8,
}

impl Boot {
    /// Byte 0: no start reported (a paper-era robot, or the host simulator's first start).
    pub const UNREPORTED: Boot = Boot {
        cause: ResetCause::Unreported,
        count: 0,
    };

    /// The byte: cause in bits 7..5, count modulo 32 in bits 4..0.
    pub const fn to_wire(self) -> u8 {
        (self.cause.bits() << 5) | (self.count & 0x1f)
    }

    /// Every byte is a start: three bits of cause, five of count.
    pub const fn from_wire(b: u8) -> Boot {
        Boot {
            cause: ResetCause::from_bits(b >> 5),
            count: b & 0x1f,
        }
    }

    /// The start after `boots` starts in all (the node's whole count) for `cause`.
    pub const fn after(cause: ResetCause, boots: u16) -> Boot {
        Boot {
            cause,
            // The low five bits: a u8 holds them.
            count: boots.to_le_bytes()[0] & 0x1f,
        }
    }

    /// Whether two heartbeats' bytes tell of different starts (the node restarted between
    /// them, or 32·k times: a count the ground cannot tell from none, which at one restart a
    /// second needs 32 restarts between two heartbeats).
    pub const fn differs(self, other: Boot) -> bool {
        self.to_wire() != other.to_wire()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Decision `restart-board-a`: a power cycle or a brown-out (or a cause not reported, read
    /// as the worst) loses the RTC memory; a software, panic, watchdog, external or other reset
    /// keeps it.
    #[test]
    fn only_power_loss_loses_rtc_memory() {
        for cause in ResetCause::ALL {
            let lost = matches!(
                cause,
                ResetCause::PowerOn | ResetCause::BrownOut | ResetCause::Unreported
            );
            assert_eq!(cause.loses_rtc_memory(), lost, "{cause:?}");
        }
    }

    #[test]
    fn every_byte_is_one_boot_and_back() {
        for b in 0..=u8::MAX {
            let boot = Boot::from_wire(b);
            assert_eq!(boot.to_wire(), b);
            assert!(boot.count < 32);
            assert_eq!(boot.cause.name(), ResetCause::NAMES[usize::from(b >> 5)]);
        }
        assert_eq!(Boot::default(), Boot::UNREPORTED);
        assert_eq!(Boot::after(ResetCause::PowerOn, 1).to_wire(), 0x21);
        assert_eq!(Boot::after(ResetCause::PowerOn, 32).to_wire(), 0x20);
    }

    /// A reset cause displays as its name.
    #[test]
    fn a_cause_displays_as_its_name() {
        extern crate std;
        use std::string::ToString;
        for (i, name) in ResetCause::NAMES.iter().enumerate() {
            let cause = Boot::from_wire((i as u8) << 5).cause;
            assert_eq!(cause.to_string(), *name);
        }
    }
}
