//! The server board's glue towards the ground over the space data link (issue 28): TC transfer
//! frames arrive as UDP datagrams and go into the library's [`FrameGateway`] (SDLS, FARM-1 per
//! robot, the PUS gateway); the legacy
//! commands its `tick` says are due go to board A (one visit each, as the host simulator's
//! `FrameGatewayTask` makes them); the heartbeats the visits bring back go into the gateway;
//! every TM transfer frame it says is due (protected by SDLS) goes to the ground, one per
//! datagram; the SDLS counters the gateway asks to keep go to the durable store first.
//!
//! Generic over the I/O ([`Datagrams`], [`BoardLink`], [`Clock`]) and the counters' durable
//! store ([`CounterStore`]), so the host tests
//! drive it with mocks and the image with embassy-net and flash. It decides nothing the
//! library does not: the only choices here are the order of the steps (the simulator's) and
//! what is counted when an I/O fails.

use crate::counters::CounterStore;
use core::fmt;
use mmic::link::sdls::{mission, Key256};
use mmic::node::server::frames::{FrameConfig, FrameGateway, Stored, FRAME_LEN};
use mmic::units::BoardNumber;
use mmic::wire::command::COMMAND_LEN;
use mmic::wire::heartbeat::{HeartbeatRepr, HEARTBEAT_LEN};

/// Telecommands waiting per robot (the host simulator's).
pub const QUEUE: usize = 8;
/// Request keys remembered per robot (the host simulator's).
pub const KEYS: usize = 64;
/// TM packet octets waiting for frames per robot: four frames' worth (the simulator's 4 KiB
/// is for many robots' bursts on a PC; the reports of one heartbeat fit a frame).
pub const TM_WAITING: usize = 1024;
/// The largest TC datagram read: a TC frame is at most 256 octets (`spec/ccsds/link.toml`
/// `max_frame_len`); one octet more shows a longer datagram, which the frame checks refuse.
pub const TC_DATAGRAM: usize = 257;

/// The gateway the server board runs, for `R` robots (the image's: one FARM-1, queue, key log
/// and TM framer each, about 3.7 KB of RAM per robot).
pub type Gateway<const R: usize> = FrameGateway<R, QUEUE, KEYS, TM_WAITING>;

/// The ground's datagram socket (UDP): TC frames in, TM frames out.
pub trait Datagrams {
    /// The next datagram waiting, copied into `buf` (a longer one is cut to `buf.len()`): its
    /// length; `None` when none waits (never blocks).
    fn recv(&mut self, buf: &mut [u8]) -> Option<usize>;
    /// Sends one datagram to the ground; false when it did not go.
    fn send(&mut self, datagram: &[u8]) -> bool;
}

/// The legacy link to the robots' board A (the visits: connect, send the 14-byte command, wait
/// for the heartbeat, disconnect).
pub trait BoardLink {
    /// Starts a visit of `board` to deliver `packet`; false when the link is busy with another
    /// visit. A command not taken is not lost for good: the gateway's uplink numbers it and
    /// sends it again until board A acknowledges it.
    fn command(&mut self, board: BoardNumber, packet: [u8; COMMAND_LEN]) -> bool;
    /// A heartbeat a visit brought back, if any (never blocks).
    fn heartbeat(&mut self) -> Option<[u8; HEARTBEAT_LEN]>;
}

/// Milliseconds since boot, wrapping (the library's clock).
pub trait Clock {
    /// Now.
    fn now_ms(&mut self) -> u32;
}

/// One SDLS key the image carries: 32 octets for one security association (sdls-plan.md: the
/// TC SA of robot n is SPI 0x100 + n, its TM SA 0x200 + n). Its `Debug` shows the SPI only.
#[derive(Clone, Copy)]
pub struct SdlsKey {
    /// The security association's SPI.
    pub spi: u16,
    /// The AES-256 key.
    pub key: [u8; 32],
}

impl fmt::Debug for SdlsKey {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("SdlsKey")
            .field("spi", &self.spi)
            .finish_non_exhaustive()
    }
}

/// What the glue counts (each wraps at `u32::MAX`); FARM-1's and the gateway's own counts are
/// the library's ([`Gateway::counters`], [`Gateway::refused`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Counts {
    /// Datagrams from the ground.
    pub tc_datagrams: u32,
    /// Durable counter writes the store refused (the reservation is asked for again at the
    /// next pass; until one succeeds, frames wait or are refused, never protected or accepted
    /// beyond what is durable).
    pub store_failed: u32,
    /// Legacy commands handed to the board link.
    pub commands: u32,
    /// Legacy commands the board link was too busy to take (the uplink resends them).
    pub commands_busy: u32,
    /// Heartbeats handed to the gateway.
    pub heartbeats: u32,
    /// Heartbeats that did not parse (the visit's deframer passed a heartbeat-kind packet).
    pub heartbeats_unreadable: u32,
    /// TM frames sent.
    pub tm_frames: u32,
    /// TM frames the socket did not send.
    pub tm_unsent: u32,
}

/// Why the glue cannot start.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum GlueError {
    /// A robot the image serves has no key for one of its SAs.
    #[error("no SDLS key for SPI {spi} (robot {board})")]
    NoKey {
        /// The robot.
        board: u8,
        /// The SA's SPI.
        spi: u16,
    },
    /// More robots than the glue was built for, or one twice.
    #[error("robot {0} cannot be served (more robots than places, or twice)")]
    Robot(u8),
}

/// The server board's state besides its sockets, for `R` robots.
pub struct ServerGlue<St, const R: usize> {
    gateway: Gateway<R>,
    store: St,
    counts: Counts,
}

impl<St: CounterStore, const R: usize> ServerGlue<St, R> {
    /// The gateway for `robots`, each secured with SDLS (`mmic::link::sdls::mission`): its TC
    /// and TM keys from `keys` (both must be there), its counters restored from `store`.
    pub fn new(
        config: FrameConfig,
        robots: &[BoardNumber],
        keys: &[SdlsKey],
        mut store: St,
    ) -> Result<Self, GlueError> {
        let mut gateway = Gateway::new(config);
        for &board in robots {
            let key = |spi: u16| {
                keys.iter()
                    .find(|k| k.spi == spi)
                    .map(|k| Key256::from_bytes(k.key))
                    .ok_or(GlueError::NoKey {
                        board: board.get(),
                        spi,
                    })
            };
            let (tc_spi, tm_spi) = (mission::tc_spi(board), mission::tm_spi(board));
            let (tc, tm) = (key(tc_spi)?, key(tm_spi)?);
            let stored = Stored {
                tc: store.load(tc_spi),
                tm: store.load(tm_spi),
            };
            if !gateway.add(board) || !gateway.secure(board, tc, tm, stored) {
                return Err(GlueError::Robot(board.get()));
            }
        }
        let mut glue = ServerGlue {
            gateway,
            store,
            counts: Counts::default(),
        };
        glue.persist();
        Ok(glue)
    }

    /// Writes the durable counters the gateway asks for, and confirms each write that
    /// succeeded (nothing is protected or accepted beyond a confirmed write).
    fn persist(&mut self) {
        // Two associations per robot: 16 covers the eight robots a server board could serve.
        let mut due: heapless::Vec<(u16, u128), 16> = heapless::Vec::new();
        for d in self.gateway.due() {
            let _ = due.push(d);
        }
        for (spi, value) in due {
            if self.store.store(spi, value).is_ok() {
                self.gateway.persisted(spi, value);
            } else {
                self.counts.store_failed = self.counts.store_failed.wrapping_add(1);
            }
        }
    }

    /// The library's gateway (FARM-1, the link counters).
    pub const fn gateway(&self) -> &Gateway<R> {
        &self.gateway
    }

    /// What the glue counted.
    pub const fn counts(&self) -> &Counts {
        &self.counts
    }

    /// The counters' store.
    pub fn store(&mut self) -> &mut St {
        &mut self.store
    }

    /// One pass, in the host simulator's order: every TC frame waiting; every heartbeat the
    /// visits brought back; the gateway's tick (its legacy commands to the board link); every
    /// TM frame due. Returns when the gateway next needs a pass if nothing arrives (ms since
    /// boot), for the shell's sleep.
    pub fn poll(
        &mut self,
        clock: &mut impl Clock,
        ground: &mut impl Datagrams,
        board: &mut impl BoardLink,
    ) -> Option<u32> {
        let mut buf = [0u8; TC_DATAGRAM];
        self.persist();
        while let Some(n) = ground.recv(&mut buf) {
            self.counts.tc_datagrams = self.counts.tc_datagrams.wrapping_add(1);
            let now = clock.now_ms();
            // SDLS, FARM-1 and the PUS gateway: the library's (a refused frame is counted
            // there, per reason).
            self.gateway.tc_frame(now, buf.get(..n).unwrap_or(&[]));
            self.persist();
        }
        while let Some(hb) = board.heartbeat() {
            match HeartbeatRepr::parse(&hb) {
                Ok(hb) => {
                    self.counts.heartbeats = self.counts.heartbeats.wrapping_add(1);
                    self.gateway.heartbeat(clock.now_ms(), &hb);
                }
                Err(_) => {
                    self.counts.heartbeats_unreadable =
                        self.counts.heartbeats_unreadable.wrapping_add(1)
                }
            }
        }
        for (b, command) in self.gateway.tick(clock.now_ms()) {
            if board.command(b, command.to_bytes()) {
                self.counts.commands = self.counts.commands.wrapping_add(1);
            } else {
                self.counts.commands_busy = self.counts.commands_busy.wrapping_add(1);
            }
        }
        let now = clock.now_ms();
        let mut tm = [0u8; FRAME_LEN];
        self.persist();
        while let Some((_, len)) = self.gateway.frame(now, &mut tm) {
            let sent = ground.send(tm.get(..len).unwrap_or(&[]));
            self.persist();
            if sent {
                self.counts.tm_frames = self.counts.tm_frames.wrapping_add(1);
            } else {
                self.counts.tm_unsent = self.counts.tm_unsent.wrapping_add(1);
            }
        }
        self.gateway.next_deadline(now)
    }
}

/// How long the shell may sleep at `now` before the next pass, given the gateway's next
/// deadline `next` (from [`ServerGlue::poll`]): until the deadline, at most `max_ms`, at least
/// 1 ms (a deadline already past, which the clock's wrap would otherwise read as far away,
/// means a pass at once; the 1 ms keeps a deadline that stays due from spinning the CPU, and
/// a datagram wakes the shell earlier anyway).
pub const fn sleep_ms(next: Option<u32>, now: u32, max_ms: u32) -> u32 {
    let wait = match next {
        None => max_ms,
        Some(t) => {
            let d = t.wrapping_sub(now);
            if d > u32::MAX / 2 {
                0
            } else if d < max_ms {
                d
            } else {
                max_ms
            }
        }
    };
    if wait == 0 {
        1
    } else {
        wait
    }
}
