//! The server board's visit of one robot as a sans-I/O machine (Figure 4): connect to its
//! board A, write the command, wait a bounded time for the heartbeat that answers it, hand the
//! heartbeat on, disconnect. Written once for every shell (the ESP32 server firmware, the
//! simulator's engines and fleet), for the legacy relay ([`super::relay`]) and the PUS
//! gateway ([`super::gateway`]) alike.
//!
//! The rules the shells used to restate:
//!
//! * a visit lasts at most its `wait_ms` from its start, connecting included: a robot that
//!   cannot be reached costs the server one wait, not a connect timeout plus a wait;
//! * the visit's command leaves its pending slot ([`Server::delivered`]) once it has been
//!   written to the connection, not before (a failed connect keeps it pending for the next
//!   loop);
//! * the answer is the first whole *heartbeat* packet read on the connection; anything before
//!   it (garbage, another kind) is dropped, and a cut packet of an earlier visit never joins
//!   this one's (each visit has its own deframer);
//! * the visit ends with the answer or at its deadline, whichever comes first, and then the
//!   shell disconnects.
//!
//! No I/O, no clock (the time comes in ms, wrapping), no allocation, no panic.
//!
//! ```
//! use mmic::command::Command;
//! use mmic::node::server::relay::{Accepted, Server};
//! use mmic::node::server::visit::Visit;
//! use mmic::units::BoardNumber;
//! use mmic::wire::command::CommandRepr;
//! use mmic::wire::heartbeat::HeartbeatRepr;
//!
//! let two = BoardNumber::new(2).unwrap();
//! let mut server: Server<4> = Server::new();
//! let stop = CommandRepr { board: two, command: Command::Stop, seq: 1 }.to_bytes();
//! assert_eq!(server.accept(&stop), Ok(Accepted::Queued));
//! // The loop at t = 100 ms: the next robot with a pending command, 200 ms to answer.
//! let mut visit = Visit::next(&mut server, 100, 200).unwrap();
//! assert_eq!((visit.board(), *visit.packet()), (two, stop));
//! assert_eq!(visit.left_ms(150), Some(150));
//! // Connected: the shell writes the packet, then says so; the slot empties.
//! visit.written(&mut server);
//! assert_eq!(server.pending(two), None);
//! // Board A's heartbeat arrives in two reads; the first whole one is the answer.
//! let hb = HeartbeatRepr::default().to_bytes();
//! assert_eq!(visit.received(&hb[..10]), None);
//! assert_eq!(visit.received(&hb[10..]), Some(hb));
//! // Without it, the visit would have ended at its deadline.
//! assert_eq!(visit.left_ms(300), None);
//! ```
// req: P3.7, P3.8, P3.9, D:relay-visit-window

use super::relay::{Packet, Server};
use crate::units::BoardNumber;
use crate::wire::deframer::{Deframed, Deframer};
use crate::wire::heartbeat::HEARTBEAT_LEN;
use crate::wire::PacketKind;

/// A heartbeat packet, board A → server.
pub type Heartbeat = [u8; HEARTBEAT_LEN];

/// The deframer's buffer, bytes.
pub const READER_LEN: usize = 256;

/// One visit of a robot's board A: what to write, by when the answer must come, and the
/// connection's deframer.
#[derive(Debug, Clone)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Visit {
    board: BoardNumber,
    packet: Packet,
    deadline: u32,
    reader: Deframer<READER_LEN>,
    answered: bool,
}

impl Visit {
    /// A visit of `board` starting at `now` to deliver `packet`, ending `wait_ms` later at the
    /// latest.
    pub const fn new(now: u32, board: BoardNumber, packet: Packet, wait_ms: u32) -> Visit {
        Visit {
            board,
            packet,
            deadline: now.wrapping_add(wait_ms),
            reader: Deframer::new(),
            answered: false,
        }
    }

    /// The relay's next visit: the next robot with a pending command in `server`'s round
    /// robin ([`Server::next_visit`]), starting at `now`; none pending, none.
    pub fn next<const N: usize>(server: &mut Server<N>, now: u32, wait_ms: u32) -> Option<Visit> {
        server
            .next_visit()
            .map(|(board, packet)| Visit::new(now, board, packet, wait_ms))
    }

    /// The robot visited.
    pub const fn board(&self) -> BoardNumber {
        self.board
    }

    /// The bytes to write once connected: the command packet, unchanged.
    pub const fn packet(&self) -> &Packet {
        &self.packet
    }

    /// When the visit ends without an answer, ms.
    pub const fn deadline(&self) -> u32 {
        self.deadline
    }

    /// The packet went out on the connection: it leaves `server`'s pending slot (unless the
    /// ground replaced it meanwhile).
    pub fn written<const N: usize>(&self, server: &mut Server<N>) {
        server.delivered(self.board, &self.packet);
    }

    /// How long the shell may still wait (to connect, or for bytes) at `now`, ms; `None` once
    /// the deadline has come or the visit was answered: disconnect. Time wraps.
    pub const fn left_ms(&self, now: u32) -> Option<u32> {
        let left = self.deadline.wrapping_sub(now);
        // Past the deadline, the wrapped difference is above half the clock's range.
        if self.answered || left == 0 || left > u32::MAX / 2 {
            None
        } else {
            Some(left)
        }
    }

    /// Bytes read from the connection: the first whole heartbeat in them is the answer, which
    /// ends the visit (later calls return `None`).
    pub fn received(&mut self, bytes: &[u8]) -> Option<Heartbeat> {
        if self.answered {
            return None;
        }
        let mut answer = None;
        self.reader.feed(bytes, |e| {
            if let Deframed::Frame(f) = e
                && answer.is_none()
                && f.kind() == PacketKind::Heartbeat
            {
                answer = Heartbeat::try_from(f.as_bytes()).ok();
            }
        });
        self.answered = answer.is_some();
        answer
    }

    /// Whether the answer came.
    pub const fn answered(&self) -> bool {
        self.answered
    }

    /// Bytes of this visit's stream the deframer dropped.
    pub const fn discarded(&self) -> u64 {
        self.reader.discarded_total()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::command::Command;
    use crate::wire::command::CommandRepr;
    use crate::wire::heartbeat::HeartbeatRepr;

    fn stop(seq: u16) -> Packet {
        CommandRepr {
            board: BoardNumber::ONE,
            command: Command::Stop,
            seq,
        }
        .to_bytes()
    }

    // req: D:relay-visit-window
    #[test]
    fn the_deadline_counts_from_the_start_and_wraps() {
        let v = Visit::new(u32::MAX - 50, BoardNumber::ONE, stop(1), 100);
        assert_eq!(v.deadline(), 49);
        assert_eq!(v.left_ms(u32::MAX - 50), Some(100));
        assert_eq!(v.left_ms(48), Some(1));
        assert_eq!(v.left_ms(49), None);
        assert_eq!(v.left_ms(1_000), None);
    }

    // req: P3.8
    #[test]
    fn the_answer_is_the_first_heartbeat_after_garbage_and_other_kinds() {
        let mut v = Visit::new(0, BoardNumber::ONE, stop(1), 200);
        let hb = HeartbeatRepr::default().to_bytes();
        assert_eq!(v.received(b"MIxx garbage"), None);
        assert_eq!(v.received(&stop(2)), None);
        let mut two = [0u8; 2 * HEARTBEAT_LEN];
        two[..HEARTBEAT_LEN].copy_from_slice(&hb);
        two[HEARTBEAT_LEN..].copy_from_slice(&hb);
        assert_eq!(v.received(&two), Some(hb));
        assert!(v.answered());
        assert_eq!(v.received(&hb), None);
        assert_eq!(v.left_ms(1), None);
        assert!(v.discarded() > 0);
    }

    // req: P3.6, P3.9
    #[test]
    fn an_unwritten_visit_leaves_its_command_pending() {
        let mut s: Server<2> = Server::new();
        assert!(s.accept(&stop(1)).is_ok());
        let v = Visit::next(&mut s, 0, 200);
        assert!(v.is_some());
        assert_eq!(s.pending(BoardNumber::ONE), Some(stop(1)));
        if let Some(v) = v {
            v.written(&mut s);
        }
        assert_eq!(s.pending(BoardNumber::ONE), None);
        assert!(Visit::next(&mut s, 0, 200).is_none());
    }
}
