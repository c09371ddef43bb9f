//! The server board's loop steps (Figure 4): commands from the opsUI's serial line into the
//! library's pending slots ([`Server`]), and the heartbeat of a visited robot back.

use crate::link::{ByteSource, Link};
use mmic::node::server::{Accepted, Server, ServerError};
use mmic::wire::command::COMMAND_LEN;
use mmic::wire::heartbeat::HEARTBEAT_LEN;
use mmic::wire::PacketKind;

/// Robots one server board serves.
pub const ROBOTS: usize = 4;

/// What the server glue counts.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Counters {
    /// Commands the library refused (invalid, or no free slot).
    pub refused: u32,
    /// Pending commands replaced by a newer one from the ground.
    pub superseded: u32,
    /// Heartbeats forwarded to the opsUI.
    pub forwarded: u32,
}

/// The server board's state besides its sockets.
pub struct ServerGlue {
    /// The library's pending slots.
    pub srv: Server<ROBOTS>,
    /// The opsUI's serial line, receive side.
    pub ground: Link,
    /// The visited robot's TCP stream.
    pub robot: Link,
    /// Counts.
    pub counters: Counters,
}

impl Default for ServerGlue {
    fn default() -> Self {
        Self::new()
    }
}

impl ServerGlue {
    /// No robot known.
    pub const fn new() -> Self {
        ServerGlue {
            srv: Server::new(),
            ground: Link::new(PacketKind::Command),
            robot: Link::new(PacketKind::Heartbeat),
            counters: Counters {
                refused: 0,
                superseded: 0,
                forwarded: 0,
            },
        }
    }

    /// Takes every command the opsUI's line has now into the pending slots.
    pub fn from_ground(&mut self, line: &mut impl ByteSource) {
        while let Some(p) = self.ground.next::<COMMAND_LEN>(line) {
            match self.srv.accept(&p) {
                Ok(Accepted::Queued | Accepted::Resend) => {}
                Ok(Accepted::Superseded(_)) => self.counters.superseded += 1,
                Err(ServerError::Invalid(_) | ServerError::Full { .. }) => {
                    self.counters.refused += 1
                }
            }
        }
    }

    /// Bytes from the visited robot; the first heartbeat in them, to forward.
    pub fn from_robot(&mut self, bytes: &[u8]) -> Option<[u8; HEARTBEAT_LEN]> {
        let mut hb = None;
        self.robot.feed(bytes, |p| {
            hb.get_or_insert(p);
        });
        if hb.is_some() {
            self.counters.forwarded += 1;
        }
        hb
    }
}
