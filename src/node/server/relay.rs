//! The server board (Figure 4): one pending command per robot, delivered by visiting robots
//! in turn.
//!
//! The server reads 14-byte commands from the opsUI's serial line and keeps each one — the
//! paper's "command byte" — until its packet has reached the robot it is addressed to. Each
//! loop it connects to one robot with a pending command, sends it, forwards the heartbeat that
//! comes back, and disconnects, so one server serves several robots. This module is that
//! bookkeeping; the shell does the connecting.
//!
//! The ground builds the whole packet (sequence number included) and the server forwards it
//! unchanged after checking it, where the paper's server "identifies the command and fills the
//! command packet" from a command ID: the number is the ground's to give, so the server must
//! not rebuild the packet (spec/decisions.toml, `server-forwards-packet`).
//!
//! A pending command is never dropped silently: it leaves its slot only when delivered
//! ([`Server::delivered`]) or when the ground replaces it with another command for the same
//! robot, which [`Server::accept`] reports as [`Accepted::Superseded`]. The ground sends one
//! command at a time per robot, so it replaces a command only after it has finished with it
//! (acknowledged, or reported unacknowledged); the stateright model in
//! proofs/tests/protocol/protocol_exactly_once.rs checks exactly that.
//!
//! ```
//! use mmic::command::Command;
//! use mmic::node::server::relay::{Accepted, Server};
//! use mmic::units::BoardNumber;
//! use mmic::wire::command::CommandRepr;
//!
//! let two = BoardNumber::new(2).unwrap();
//! let mut server: Server<4> = Server::new();
//! let stop = CommandRepr { board: two, command: Command::Stop, seq: 1 }.to_bytes();
//! assert_eq!(server.accept(&stop), Ok(Accepted::Queued));
//! assert_eq!(server.accept(&stop), Ok(Accepted::Resend)); // the ground resent it
//! let (robot, packet) = server.next_visit().unwrap();
//! assert_eq!((robot, packet), (two, stop));
//! server.delivered(robot, &packet);
//! assert_eq!(server.next_visit(), None);
//! ```
// req: P3.5, P3.6, P3.7, D:server-pending-slot

use crate::units::BoardNumber;
use crate::wire::command::{CommandRepr, COMMAND_LEN};
use crate::wire::WireError;

/// A command packet.
pub type Packet = [u8; COMMAND_LEN];

/// The opsUI's answer window, ms (Section 8: "If the heartbeat packet is not received within
/// 0.7 s, the opsUI counts that as a failed communication attempt"); the uplink's default
/// [`timeout_ms`](crate::node::exactly_once::uplink::Config::timeout_ms).
pub const ANSWER_MS: u32 = 700;

/// What the serial line and the loops on either side of it take of [`ANSWER_MS`], ms: the
/// command's 14 octets and the heartbeat's 66 at 115,200 baud (1.2 ms and 5.7 ms), the
/// server's idle poll of its serial line (10 ms in the image) and the opsUI's 10 ms tick,
/// 27 ms in all (spec/boards.toml `[server]`, decision `relay-visit-window`).
pub const SERIAL_RESERVE_MS: u32 = 30;

/// How long the relay's visit of a robot lasts at most, connecting included, ms: as long as the
/// opsUI's 0.7 s window allows once the serial line's share is set aside. A heartbeat that
/// comes later could not reach the opsUI in time, which would count the attempt failed anyway
/// (decision `relay-visit-window`). The simulator and the relay image use this one number.
pub const VISIT_MS: u32 = ANSWER_MS - SERIAL_RESERVE_MS;

/// What became of an accepted packet.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Accepted {
    /// Now pending for its robot.
    Queued,
    /// The same packet was already pending (a resend from the ground).
    Resend,
    /// It replaced a different pending packet for the same robot, handed back here.
    Superseded(Packet),
}

/// Why the server refused a packet from the ground.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ServerError {
    /// Not a valid command packet.
    #[error("not a command packet: {0}")]
    Invalid(#[from] WireError),
    /// Every robot slot is taken by other robots; the packet is handed back.
    #[error("no slot for robot {n}: all {capacity} slots serve other robots", n = board.get())]
    Full {
        /// The robot addressed.
        board: BoardNumber,
        /// Slots.
        capacity: usize,
        /// The packet.
        packet: Packet,
    },
}

/// Pending commands for up to `N` robots.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Server<const N: usize> {
    slots: [Option<(BoardNumber, Option<Packet>)>; N],
    cursor: usize,
}

impl<const N: usize> Default for Server<N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const N: usize> Server<N> {
    /// No robot known.
    pub const fn new() -> Server<N> {
        Server {
            slots: [None; N],
            cursor: 0,
        }
    }

    /// Takes a packet from the ground's serial line.
    pub fn accept(&mut self, packet: &Packet) -> Result<Accepted, ServerError> {
        let board = CommandRepr::parse(packet)?.board;
        // The robot's own slot, else the first free one (empty, or a robot with nothing pending).
        let known = self.slot_of(board);
        let free = || {
            self.slots
                .iter()
                .position(|s| s.is_none_or(|(_, p)| p.is_none()))
        };
        let Some(slot) = known.or_else(free).and_then(|i| self.slots.get_mut(i)) else {
            return Err(ServerError::Full {
                board,
                capacity: N,
                packet: *packet,
            });
        };
        // A free slot has nothing pending; the robot's own may.
        let pending = slot.and_then(|(b, p)| if b == board { p } else { None });
        *slot = Some((board, Some(*packet)));
        Ok(match pending {
            None => Accepted::Queued,
            Some(old) if old == *packet => Accepted::Resend,
            Some(old) => Accepted::Superseded(old),
        })
    }

    fn slot_of(&self, board: BoardNumber) -> Option<usize> {
        self.slots
            .iter()
            .position(|s| matches!(s, Some((b, _)) if *b == board))
    }

    /// The next robot to visit and the packet to deliver, round robin over robots with a
    /// pending command. The packet stays pending until [`delivered`](Self::delivered).
    pub fn next_visit(&mut self) -> Option<(BoardNumber, Packet)> {
        // From the cursor to the end, then from the start: the slots in visiting order.
        let (before, after) = self.slots.split_at(self.cursor.min(N));
        let start = before.len();
        let (i, b, p) = after
            .iter()
            .zip(start..)
            .chain(before.iter().zip(0..))
            .find_map(|(s, i)| match *s {
                Some((b, Some(p))) => Some((i, b, p)),
                _ => None,
            })?;
        // i is a slot's index, below N: the sum cannot saturate.
        let next = i.saturating_add(1);
        self.cursor = if next < N { next } else { 0 };
        Some((b, p))
    }

    /// The packet reached `board` (written to its connection). Clears the slot only if that
    /// packet is still the pending one (a newer one stays).
    pub fn delivered(&mut self, board: BoardNumber, packet: &Packet) {
        let slot = self
            .slots
            .iter_mut()
            .find(|s| matches!(s, Some((b, _)) if *b == board));
        if let Some(slot) = slot
            && let Some((b, Some(p))) = *slot
            && p == *packet
        {
            *slot = Some((b, None));
        }
    }

    /// The packet pending for `board`.
    pub fn pending(&self, board: BoardNumber) -> Option<Packet> {
        self.slots
            .iter()
            .flatten()
            .find(|(b, _)| *b == board)
            .and_then(|(_, p)| *p)
    }

    /// Robots with a pending packet.
    pub fn pending_count(&self) -> usize {
        self.slots
            .iter()
            .filter(|s| matches!(s, Some((_, Some(_)))))
            .count()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::command::Command;

    fn packet(board: u8, seq: u16) -> Packet {
        match BoardNumber::new(board) {
            Ok(board) => CommandRepr {
                board,
                command: Command::Heartbeat,
                seq,
            }
            .to_bytes(),
            Err(_) => [0; COMMAND_LEN],
        }
    }

    /// `Default` (beside the public `new`) is the server that knows no robot: nothing
    /// pending, nothing to visit.
    #[test]
    fn the_default_server_knows_no_robot() {
        let mut s: Server<2> = Server::default();
        assert_eq!(s, Server::new());
        assert_eq!(s.pending_count(), 0);
        assert_eq!(s.next_visit(), None);
    }

    // req: P3.5, P3.6
    #[test]
    fn full_hands_the_packet_back_and_free_slots_are_reused() {
        let mut s: Server<2> = Server::new();
        assert_eq!(s.accept(&packet(1, 1)), Ok(Accepted::Queued));
        assert_eq!(s.accept(&packet(2, 1)), Ok(Accepted::Queued));
        let third = packet(3, 1);
        assert!(
            matches!(s.accept(&third), Err(ServerError::Full { packet, capacity: 2, .. }) if packet == third)
        );
        let visit = s.next_visit();
        assert!(visit.is_some());
        if let Some((b, p)) = visit {
            s.delivered(b, &p);
        }
        assert_eq!(s.accept(&third), Ok(Accepted::Queued));
        assert_eq!(s.pending_count(), 2);
    }

    // req: P3.7
    #[test]
    fn supersession_is_reported_and_visits_alternate() {
        let mut s: Server<4> = Server::new();
        s.accept(&packet(1, 1)).ok();
        s.accept(&packet(2, 1)).ok();
        assert_eq!(
            s.accept(&packet(1, 2)),
            Ok(Accepted::Superseded(packet(1, 1)))
        );
        let a = s.next_visit().map(|(b, _)| b.get());
        let b = s.next_visit().map(|(b, _)| b.get());
        assert_eq!((a, b), (Some(1), Some(2)));
        // Delivery of a packet that is no longer pending keeps the newer one.
        if let Ok(one) = BoardNumber::new(1) {
            s.delivered(one, &packet(1, 1));
            assert_eq!(s.pending(one), Some(packet(1, 2)));
        }
        let mut bad = packet(1, 3);
        bad[13] ^= 1;
        assert!(matches!(s.accept(&bad), Err(ServerError::Invalid(_))));
    }
}
