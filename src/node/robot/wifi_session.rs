//! Board A's WiFi task as a sans-I/O machine: what the task does with a server connection,
//! written once for every shell (the ESP32 firmware's embassy task, the simulator's
//! virtual-time and realtime engines, the realtime fleet).
//!
//! The task sits between the server board's TCP connection and the control task's two
//! hand-off queues ([`super::handoff`]). Its rules, which used to be restated by each shell:
//!
//! * a server connection is served until it closes; bytes read from it are deframed, and
//!   every *command* packet in them goes to the control task (packets of another kind are
//!   counted and dropped: only commands travel server → board A);
//! * each new connection starts with a fresh deframer: nothing of the last connection's
//!   stream (a cut packet) is carried into the next one;
//! * a heartbeat the control task queued goes out on the open connection; one made while no
//!   server was connected is dropped, never sent to the next connection (the server reads the
//!   first heartbeat of its visit as the answer to the command it just sent, so an old one
//!   would answer for the wrong state);
//! * a connection over which nothing arrived for [`WifiConfig::idle_ms`] is to be closed
//!   (a server that vanished without closing must not block the next one).
//!
//! The machine does no I/O and reads no clock: the shell accepts, reads, writes and closes,
//! passes the time in ms, and does what the machine's answers say. It allocates nothing and
//! cannot panic; the queues stay the shell's (they cross cores on the ESP32).
//!
//! ```
//! use mmic::command::Command;
//! use mmic::node::robot::wifi_session::{Outgoing, WifiConfig, WifiSession};
//! use mmic::units::BoardNumber;
//! use mmic::wire::command::CommandRepr;
//!
//! let mut wifi = WifiSession::new(WifiConfig::default());
//! // A heartbeat made while nobody listens is dropped.
//! let hb = [0u8; 66];
//! assert_eq!(wifi.heartbeat(hb), Outgoing::Drop(hb));
//! // The server connects: heartbeats still queued from before are stale, and dropped too.
//! let mut dropped = 0;
//! wifi.open(0, [hb], |_| dropped += 1);
//! assert_eq!(dropped, 1);
//! // Its command arrives in two reads; the control task gets it once whole.
//! let stop = CommandRepr { board: BoardNumber::ONE, command: Command::Stop, seq: 1 }.to_bytes();
//! let mut commands = Vec::new();
//! wifi.received(1, &stop[..5], |c| commands.push(c));
//! wifi.received(2, &stop[5..], |c| commands.push(c));
//! assert_eq!(commands, [stop]);
//! // Now a heartbeat goes out, until the connection is idle too long.
//! assert_eq!(wifi.heartbeat(hb), Outgoing::Send(hb));
//! assert!(!wifi.expired(2 + 4_999));
//! assert!(wifi.expired(2 + 5_000));
//! assert!(wifi.close());
//! assert_eq!(wifi.counts().sent, 1);
//! ```
// req: P3.14

use crate::wire::command::COMMAND_LEN;
use crate::wire::deframer::{Deframed, Deframer};
use crate::wire::heartbeat::HEARTBEAT_LEN;
use crate::wire::PacketKind;

/// A command packet, server → board A.
pub type Command = [u8; COMMAND_LEN];
/// A heartbeat packet, board A → server.
pub type Heartbeat = [u8; HEARTBEAT_LEN];

/// The deframer's buffer, bytes (the longest packet, 66, with room for a few more).
pub const READER_LEN: usize = 256;

/// The WiFi task's timing.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct WifiConfig {
    /// A connection with no bytes from the server for this long is to be closed, ms. The
    /// server's visits last a few hundred ms (its wait for the heartbeat), so 5 s only ever
    /// ends a connection the server has abandoned.
    pub idle_ms: u32,
}

impl Default for WifiConfig {
    fn default() -> Self {
        WifiConfig { idle_ms: 5_000 }
    }
}

/// What to do with a heartbeat the control task queued.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Outgoing {
    /// Write it to the open connection.
    Send(Heartbeat),
    /// Drop it: no server is connected (it is counted in [`WifiCounts::unconnected`]).
    Drop(Heartbeat),
}

/// What the session has counted since it was made.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct WifiCounts {
    /// Connections served.
    pub connections: u32,
    /// Command packets handed to the control task.
    pub commands: u32,
    /// Valid packets of another kind on the connection, dropped.
    pub other_kind: u32,
    /// Heartbeats to write.
    pub sent: u32,
    /// Heartbeats dropped because no server was connected.
    pub unconnected: u32,
}

/// Board A's WiFi task: at most one server connection, its deframer, and the counts.
#[derive(Debug, Clone)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct WifiSession {
    config: WifiConfig,
    reader: Deframer<READER_LEN>,
    /// When bytes last arrived on the open connection (or it opened), ms; `None`: closed.
    open_since: Option<u32>,
    counts: WifiCounts,
}

impl Default for WifiSession {
    fn default() -> Self {
        Self::new(WifiConfig::default())
    }
}

impl WifiSession {
    /// No connection yet.
    pub const fn new(config: WifiConfig) -> Self {
        WifiSession {
            config,
            reader: Deframer::new(),
            open_since: None,
            counts: WifiCounts {
                connections: 0,
                commands: 0,
                other_kind: 0,
                sent: 0,
                unconnected: 0,
            },
        }
    }

    /// The shell accepted a server connection at `now`. `queued` are the heartbeats still in
    /// the control task's queue: each was made before this connection, so each is handed to
    /// `dropped` (and counted), not sent. The deframer starts afresh.
    pub fn open(
        &mut self,
        now: u32,
        queued: impl IntoIterator<Item = Heartbeat>,
        mut dropped: impl FnMut(Heartbeat),
    ) {
        self.open_since = None;
        for hb in queued {
            if let Outgoing::Drop(hb) = self.heartbeat(hb) {
                dropped(hb);
            }
        }
        self.reader = Deframer::new();
        self.open_since = Some(now);
        self.counts.connections = self.counts.connections.wrapping_add(1);
    }

    /// The connection closed (the server's close, a read or write error, or [`expired`]
    /// acted on). Returns whether one was open.
    ///
    /// [`expired`]: Self::expired
    pub fn close(&mut self) -> bool {
        self.open_since.take().is_some()
    }

    /// Whether a server connection is open.
    pub const fn is_open(&self) -> bool {
        self.open_since.is_some()
    }

    /// Bytes read from the connection at `now`: every whole command packet in them, in
    /// order, is handed to `command` (for the control task's queue). Bytes read with no
    /// connection open (a shell's late read) are ignored.
    pub fn received(&mut self, now: u32, bytes: &[u8], mut command: impl FnMut(Command)) {
        if self.open_since.is_none() {
            return;
        }
        self.open_since = Some(now);
        let counts = &mut self.counts;
        self.reader.feed(bytes, |e| {
            if let Deframed::Frame(f) = e {
                match (f.kind(), Command::try_from(f.as_bytes())) {
                    (PacketKind::Command, Ok(c)) => {
                        counts.commands = counts.commands.wrapping_add(1);
                        command(c);
                    }
                    _ => counts.other_kind = counts.other_kind.wrapping_add(1),
                }
            }
        });
    }

    /// A heartbeat from the control task's queue: sent on the open connection, dropped
    /// without one.
    pub fn heartbeat(&mut self, hb: Heartbeat) -> Outgoing {
        if self.open_since.is_some() {
            self.counts.sent = self.counts.sent.wrapping_add(1);
            Outgoing::Send(hb)
        } else {
            self.counts.unconnected = self.counts.unconnected.wrapping_add(1);
            Outgoing::Drop(hb)
        }
    }

    /// Whether the open connection has been idle (no bytes from the server) for
    /// [`WifiConfig::idle_ms`] or more at `now`: the shell should close it. Time wraps.
    pub const fn expired(&self, now: u32) -> bool {
        match self.open_since {
            Some(t) => now.wrapping_sub(t) >= self.config.idle_ms,
            None => false,
        }
    }

    /// What the session has counted.
    pub const fn counts(&self) -> WifiCounts {
        self.counts
    }

    /// Bytes the deframer dropped over every connection (garbage, cut packets).
    pub const fn discarded(&self) -> u64 {
        self.reader.discarded_total()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::command::Command as Cmd;
    use crate::units::BoardNumber;
    use crate::wire::command::CommandRepr;

    fn command(seq: u16) -> Command {
        CommandRepr {
            board: BoardNumber::ONE,
            command: Cmd::Stop,
            seq,
        }
        .to_bytes()
    }

    // req: P3.14
    #[test]
    fn a_new_connection_forgets_the_last_ones_cut_packet() {
        let mut w = WifiSession::default();
        w.open(0, [], |_| {});
        let mut got = 0;
        w.received(1, &command(1)[..7], |_| got += 1);
        assert!(w.close());
        assert!(!w.close());
        w.open(2, [], |_| {});
        w.received(3, &command(2), |c| {
            got += 1;
            assert_eq!(c, command(2));
        });
        assert_eq!(got, 1);
        assert_eq!(w.counts().connections, 2);
    }

    // req: P3.14
    #[test]
    fn bytes_without_a_connection_and_other_kinds_are_not_commands() {
        let mut w = WifiSession::default();
        let mut got = 0;
        w.received(0, &command(1), |_| got += 1);
        assert_eq!(got, 0);
        w.open(0, [], |_| {});
        // A heartbeat-shaped packet is not a command: counted, dropped.
        let hb = crate::wire::heartbeat::HeartbeatRepr::default().to_bytes();
        w.received(1, &hb, |_| got += 1);
        w.received(1, &command(1), |_| got += 1);
        assert_eq!((got, w.counts().other_kind, w.counts().commands), (1, 1, 1));
    }

    // req: P3.14
    #[test]
    fn stale_heartbeats_are_dropped_and_fresh_ones_sent() {
        let mut w = WifiSession::default();
        let (a, b) = ([1u8; HEARTBEAT_LEN], [2u8; HEARTBEAT_LEN]);
        let mut dropped = [None; 2];
        let mut k = 0;
        w.open(10, [a, b], |hb| {
            if let Some(d) = dropped.get_mut(k) {
                *d = Some(hb);
            }
            k += 1;
        });
        assert_eq!(dropped, [Some(a), Some(b)]);
        assert_eq!(w.heartbeat(a), Outgoing::Send(a));
        w.close();
        assert_eq!(w.heartbeat(b), Outgoing::Drop(b));
        let c = w.counts();
        assert_eq!((c.sent, c.unconnected), (1, 3));
    }

    // req: P3.14
    #[test]
    fn idleness_counts_from_the_last_bytes_and_wraps() {
        let mut w = WifiSession::new(WifiConfig { idle_ms: 100 });
        assert!(!w.expired(u32::MAX));
        w.open(u32::MAX - 10, [], |_| {});
        assert!(!w.expired(50));
        w.received(50, &[0], |_| {});
        assert!(!w.expired(149));
        assert!(w.expired(150));
    }
}
