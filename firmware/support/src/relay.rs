//! The paper's server board (Section 3, Figure 4) as glue: the opsUI's command packets from
//! its serial line ("RS232 over USB") into the library's pending slots
//! ([`mmic::node::server::relay::Server`], the paper's "command byte"), then, each loop, one
//! visit of a robot with a pending command (the library's [`Visit`]: connect, send, the first
//! heartbeat by [`VISIT_MS`], disconnect), the heartbeat written back to the serial line
//! unchanged (decision `server-forwards-packet`).
//!
//! Generic over the opsUI's line ([`ByteSource`] + [`ByteSink`]), the visit's connection
//! ([`Connection`], TCP on the device) and the clock ([`Clock`]), so the host tests drive it
//! with mocks (`tests/relay.rs`) and the image (firmware/server-paper) with the USB serial
//! line and embassy-net. It decides nothing the library does not: which packet is taken, which
//! robot is visited, how long and what the answer is are `Server::accept`, `Visit::next`,
//! `Visit::left_ms` and `Visit::received`; the glue only counts what happened, and refuses a
//! peer that is not the visited board A ([`net::visit_peer`], decision `sdls-scope`).
//!
//! The paper's protocol has no authentication: whatever writes a valid command packet to the
//! serial line commands the robots, as in the paper (docs/security.md). The WiFi side keeps
//! the images' peer check.

use crate::link::{ByteSink, ByteSource, Link};
use crate::net::{self, Endpoint};
use crate::restart::CONTROL_TIMEOUT_MS;
use crate::server::Clock;
use mmic::node::server::relay::{Accepted, Server, ServerError, VISIT_MS};
use mmic::node::server::visit::Visit;
use mmic::wire::command::COMMAND_LEN;
use mmic::wire::PacketKind;

/// Robots one relay serves: the paper's packet names its robot "in the event there are
/// multiple robots attached to a single server" (Section 3); four, as the image always had.
pub const ROBOTS: usize = 4;

/// The longest a connection's ending may wait for its last segment (a close's FIN, an abort's
/// RST) to leave, ms: the image's loop period, so a pass stays one visit long.
pub const CLOSE_MS: u32 = 10;

// A pass is one visit (at most VISIT_MS, connecting included) and its ending: it must feed the
// control watchdog in time, with room for the serial line's share of the pass (the image gives
// a heartbeat's write to the USB line at most 20 ms).
const _: () = assert!(VISIT_MS + 2 * CLOSE_MS + 100 < CONTROL_TIMEOUT_MS);

/// The visit's connection to a robot's board A (a TCP socket on the device). Each method waits
/// at most the time it is given; the glue gives it what the visit has left.
#[allow(async_fn_in_trait)] // used in this workspace's single-threaded executors only
pub trait Connection {
    /// Connects to `to` within `within_ms`; false when it failed or did not finish in time.
    async fn connect(&mut self, to: Endpoint, within_ms: u32) -> bool;
    /// The connected peer as the socket names it (`None` when it cannot).
    fn peer(&self) -> Option<Endpoint>;
    /// Writes all of `bytes`; false when the connection failed first.
    async fn write_all(&mut self, bytes: &[u8]) -> bool;
    /// What arrives within `within_ms`, into `buf`: its length; 0 when nothing came in time or
    /// the connection closed (either ends the visit).
    async fn read(&mut self, buf: &mut [u8], within_ms: u32) -> usize;
    /// Ends a visit: closes, lets the FIN leave (at most [`CLOSE_MS`]), then aborts.
    async fn close(&mut self);
    /// Ends a connection at once (a reset, let out for at most [`CLOSE_MS`]), without a byte
    /// more sent or read; after a failed connect, drops its attempt.
    async fn abort(&mut self);
}

/// How one pass's visit ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Outcome {
    /// No command pending: no visit.
    Idle,
    /// The connect failed or took the whole visit: the command stays pending.
    Unreachable,
    /// The peer was not the visited board A: aborted, nothing sent or taken; the command stays
    /// pending.
    ForeignPeer,
    /// The write failed: the command stays pending.
    Unwritten,
    /// Written, but no heartbeat by the visit's end.
    Unanswered,
    /// Written and answered; the heartbeat went to the opsUI's line (or was counted as not).
    Answered,
}

/// What the relay counts (each saturates at `u32::MAX`); the ops line's resyncs are its
/// [`Link`]'s ([`Relay::ops_link`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Counts {
    /// Commands from the opsUI now pending (new, or replacing one: [`Counts::superseded`]).
    pub queued: u32,
    /// Resends of the pending command (the opsUI resends until it hears a heartbeat).
    pub resends: u32,
    /// Pending commands a different one for the same robot replaced.
    pub superseded: u32,
    /// Packets refused: not a valid command packet (`CommandRepr::parse`).
    pub invalid: u32,
    /// Packets refused: every slot serves other robots.
    pub full: u32,
    /// Visits whose connect failed or timed out.
    pub unreachable: u32,
    /// Connections whose peer was not the visited board A.
    pub foreign_peers: u32,
    /// Commands written to board A.
    pub delivered: u32,
    /// Writes that failed.
    pub unwritten: u32,
    /// Visits that ended without a heartbeat.
    pub unanswered: u32,
    /// Heartbeats written to the opsUI's line.
    pub forwarded: u32,
    /// Heartbeats the opsUI's line did not take.
    pub ops_errors: u32,
}

fn bump(n: &mut u32) {
    *n = n.saturating_add(1);
}

/// The server board's state besides its sockets: the pending slots, the ops line's deframer,
/// the counts.
pub struct Relay {
    slots: Server<ROBOTS>,
    ops: Link,
    counts: Counts,
}

impl Default for Relay {
    fn default() -> Self {
        Self::new()
    }
}

impl Relay {
    /// No robot known, nothing pending.
    pub const fn new() -> Self {
        Relay {
            slots: Server::new(),
            ops: Link::new(PacketKind::Command),
            counts: Counts {
                queued: 0,
                resends: 0,
                superseded: 0,
                invalid: 0,
                full: 0,
                unreachable: 0,
                foreign_peers: 0,
                delivered: 0,
                unwritten: 0,
                unanswered: 0,
                forwarded: 0,
                ops_errors: 0,
            },
        }
    }

    /// One loop of Figure 4: every command the opsUI's line has now into the pending slots,
    /// then one visit of the next robot with a pending command (`open` makes its connection,
    /// only when there is one). Lasts at most [`VISIT_MS`] and the connection's ending.
    pub async fn pass<O, C>(
        &mut self,
        ops: &mut O,
        open: impl FnOnce() -> C,
        clock: &mut impl Clock,
    ) -> Outcome
    where
        O: ByteSource + ByteSink,
        C: Connection,
    {
        self.take_ops(ops);
        let Some(mut visit) = Visit::next(&mut self.slots, clock.now_ms(), VISIT_MS) else {
            return Outcome::Idle;
        };
        let mut conn = open();
        let outcome = self.visit(&mut visit, &mut conn, clock, ops).await;
        // A visit ends with a close; a connection that was never the visit's, with a reset.
        match outcome {
            Outcome::Unanswered | Outcome::Answered => conn.close().await,
            _ => conn.abort().await,
        }
        outcome
    }

    /// Takes every command packet the opsUI's line has now (the paper: "when the server detects
    /// that there is information available on the serial port").
    pub fn take_ops(&mut self, ops: &mut impl ByteSource) {
        while let Some(p) = self.ops.next::<COMMAND_LEN>(ops) {
            let c = &mut self.counts;
            match self.slots.accept(&p) {
                Ok(Accepted::Queued) => bump(&mut c.queued),
                Ok(Accepted::Resend) => bump(&mut c.resends),
                Ok(Accepted::Superseded(_)) => {
                    bump(&mut c.queued);
                    bump(&mut c.superseded)
                }
                Err(ServerError::Invalid(_)) => bump(&mut c.invalid),
                Err(ServerError::Full { .. }) => bump(&mut c.full),
            }
        }
    }

    /// The visit up to its answer or its end: connect, check the peer, write (the command
    /// leaves its slot), read until the first heartbeat, forward it.
    async fn visit<C: Connection>(
        &mut self,
        visit: &mut Visit,
        conn: &mut C,
        clock: &mut impl Clock,
        ops: &mut impl ByteSink,
    ) -> Outcome {
        let board = visit.board();
        let to = (net::robot(board.get()), net::PORT);
        let left = visit.left_ms(clock.now_ms()).unwrap_or(0);
        if !conn.connect(to, left).await {
            bump(&mut self.counts.unreachable);
            return Outcome::Unreachable;
        }
        if !net::visit_peer(board, conn.peer()) {
            bump(&mut self.counts.foreign_peers);
            return Outcome::ForeignPeer;
        }
        if !conn.write_all(visit.packet()).await {
            bump(&mut self.counts.unwritten);
            return Outcome::Unwritten;
        }
        visit.written(&mut self.slots);
        bump(&mut self.counts.delivered);
        self.answer(visit, conn, clock, ops).await
    }

    /// The visited robot's first heartbeat by the visit's end, written to the opsUI's line.
    async fn answer<C: Connection>(
        &mut self,
        visit: &mut Visit,
        conn: &mut C,
        clock: &mut impl Clock,
        ops: &mut impl ByteSink,
    ) -> Outcome {
        let mut buf = [0u8; 128];
        while let Some(left) = visit.left_ms(clock.now_ms()) {
            let n = conn.read(&mut buf, left).await;
            if n == 0 {
                break;
            }
            if let Some(hb) = visit.received(&buf[..n]) {
                let c = &mut self.counts;
                bump(if ops.write(&hb) {
                    &mut c.forwarded
                } else {
                    &mut c.ops_errors
                });
                return Outcome::Answered;
            }
        }
        bump(&mut self.counts.unanswered);
        Outcome::Unanswered
    }

    /// What was counted.
    pub const fn counts(&self) -> &Counts {
        &self.counts
    }

    /// The pending slots (the paper's "command byte" per robot).
    pub const fn slots(&self) -> &Server<ROBOTS> {
        &self.slots
    }

    /// The opsUI line's deframer: bytes dropped (garbage, cut packets) and packets of another
    /// kind.
    pub const fn ops_link(&self) -> &Link {
        &self.ops
    }
}
