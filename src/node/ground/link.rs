//! What the ground's plan runner ([`plan_runner`](super::plan_runner)) sends its commands
//! through: one command outstanding at a time, numbered, resent until answered. The legacy
//! [`Uplink`] (the paper's 14-byte commands, heartbeats back) is one [`Link`]; the PUS
//! [`TcLink`](super::pus::TcLink) (telecommands to the gateway) is the other. The
//! trait lives apart from both links and from the runner, so that each imports it and none
//! imports another.
//!
//! ```
//! use mmic::node::exactly_once::uplink::{Config, Uplink};
//! use mmic::node::ground::link::Link;
//! use mmic::command::Command;
//! use mmic::mode::Mode;
//! use mmic::units::BoardNumber;
//! let mut up = Uplink::new(Config::default(), BoardNumber::ONE);
//! assert!(Link::is_idle(&up));
//! let seq = Link::submit(&mut up, Command::Mode(Mode::Operational)).unwrap();
//! assert_eq!(Link::tick(&mut up, 0).send.map(|c| c.seq), Some(seq));
//! ```
// req: P3.11

use crate::command::Command;
use crate::faults::Faults;
use crate::mode::Mode;
use crate::node::exactly_once::uplink::{Done, Uplink};
use crate::wire::command::CommandRepr;

/// How a started motion ended, as a link that reports it says ([`Link::POLLS`] false: the
/// PUS link's ST\[1\] completion report).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum MotionEnd {
    /// It completed.
    Completed,
    /// A fault, or a mode change, cut it short.
    Interrupted {
        /// The mode the robot reported.
        mode: Mode,
        /// Its latched faults.
        faults: Faults,
    },
    /// Its end was never heard (the link is gone).
    Unacknowledged,
}

/// What one call of a [`Link`] asks for or reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LinkTick<P> {
    /// Transmit this packet now.
    pub send: Option<P>,
    /// An attempt closed: answered in time or not (Figure 11).
    pub attempt: Option<bool>,
    /// A command finished (started, refused, or unacknowledged).
    pub done: Option<Done>,
    /// A started motion ended (only a link that reports it).
    pub ended: Option<(u16, MotionEnd)>,
}

impl<P> Default for LinkTick<P> {
    fn default() -> Self {
        LinkTick {
            send: None,
            attempt: None,
            done: None,
            ended: None,
        }
    }
}

/// What the plan runner sends its commands through: one command outstanding at a time,
/// numbered, resent until answered. The legacy [`Uplink`] (14-byte commands, heartbeats back)
/// and the PUS [`TcLink`](super::pus::TcLink) (telecommands to the gateway, ST\[1\]/ST\[3\]/ST\[5\] back).
pub trait Link {
    /// What goes out for one command.
    type Packet: Copy;
    /// The runner polls with heartbeat requests to see a motion settle (legacy); false: the
    /// link reports each motion's end itself ([`LinkTick::ended`]) and the robot's status.
    const POLLS: bool;
    /// No command is outstanding: one may be submitted.
    fn is_idle(&self) -> bool;
    /// Takes `command` and numbers it; none when one is outstanding.
    fn submit(&mut self, command: Command) -> Option<u16>;
    /// Advances to `now`: what to send, attempts closed, commands finished.
    fn tick(&mut self, now: u32) -> LinkTick<Self::Packet>;
}

impl Link for Uplink {
    type Packet = CommandRepr;
    const POLLS: bool = true;

    fn is_idle(&self) -> bool {
        Uplink::is_idle(self)
    }

    fn submit(&mut self, command: Command) -> Option<u16> {
        Uplink::submit(self, command).ok()
    }

    fn tick(&mut self, now: u32) -> LinkTick<CommandRepr> {
        let t = Uplink::tick(self, now);
        LinkTick {
            send: t.send,
            attempt: t.attempt,
            done: t.done,
            ended: None,
        }
    }
}
