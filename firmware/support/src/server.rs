//! The server board's glue towards the ground over the space data link (issue 28): TC transfer
//! frames arrive as UDP datagrams, go through the frame security (SDLS, once the library has
//! it) into the library's [`FrameGateway`] (FARM-1 per robot, the PUS gateway); the legacy
//! commands its `tick` says are due go to board A (one visit each, as the host simulator's
//! `FrameGatewayTask` makes them); the heartbeats the visits bring back go into the gateway;
//! every TM transfer frame it says is due goes through the frame security to the ground, one
//! per datagram.
//!
//! Generic over the I/O ([`Datagrams`], [`BoardLink`], [`Clock`]), the frame security
//! ([`FrameSecurity`]) and the counters' durable store ([`CounterStore`]), so the host tests
//! drive it with mocks and the image with embassy-net and flash. It decides nothing the
//! library does not: the only choices here are the order of the steps (the simulator's) and
//! what is counted when an I/O fails.

use crate::counters::CounterStore;
use core::fmt;
use mmic::node::server::frames::{FrameConfig, FrameGateway, FRAME_LEN};
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

/// The TC SA's SPI of robot `board` (sdls-plan.md).
pub const fn tc_spi(board: BoardNumber) -> u16 {
    0x100 + board.get() as u16
}

/// The TM SA's SPI of robot `board` (sdls-plan.md).
pub const fn tm_spi(board: BoardNumber) -> u16 {
    0x200 + board.get() as u16
}

/// What stands between the ground's datagrams and the gateway's frames: SDLS's processing of
/// each TC frame (verify, decrypt, anti-replay) and protection of each TM frame, with the
/// counters it must keep durable going to `store`.
pub trait FrameSecurity {
    /// A TC frame as received (`frame`), processed in place: the length of the clear frame
    /// now at the start of `frame`, or `None` when the frame is refused (not authentic, a
    /// replay).
    fn tc_in<S: CounterStore>(
        &mut self,
        store: &mut S,
        now: u32,
        frame: &mut [u8],
    ) -> Option<usize>;
    /// A clear TM frame of `len` octets at the start of `frame` (which has room for
    /// [`FRAME_LEN`]), protected in place: the length to send, or `None` when it must not go
    /// (the sender's IV space or its durable reservation is spent).
    fn tm_out<S: CounterStore>(
        &mut self,
        store: &mut S,
        frame: &mut [u8],
        len: usize,
    ) -> Option<usize>;
}

/// No frame security: frames pass unchanged (the link as the host simulator runs it today).
#[derive(Debug, Clone, Copy, Default)]
pub struct Clear;

impl FrameSecurity for Clear {
    fn tc_in<S: CounterStore>(&mut self, _: &mut S, _: u32, frame: &mut [u8]) -> Option<usize> {
        Some(frame.len())
    }
    fn tm_out<S: CounterStore>(&mut self, _: &mut S, _: &mut [u8], len: usize) -> Option<usize> {
        Some(len)
    }
}

/// What the glue counts (each wraps at `u32::MAX`); FARM-1's and the gateway's own counts are
/// the library's ([`Gateway::counters`], [`Gateway::refused`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Counts {
    /// Datagrams from the ground.
    pub tc_datagrams: u32,
    /// Of those, refused by the frame security.
    pub tc_insecure: u32,
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
    /// TM frames the frame security held back, or the socket did not send.
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
pub struct ServerGlue<Sec, St, const R: usize> {
    gateway: Gateway<R>,
    security: Sec,
    store: St,
    counts: Counts,
}

impl<Sec: FrameSecurity, St: CounterStore, const R: usize> ServerGlue<Sec, St, R> {
    /// The gateway for `robots`, each of which must have both its keys in `keys` (the TC and
    /// TM SAs), with `security` between the socket and the gateway and `store` for its
    /// counters.
    pub fn new(
        config: FrameConfig,
        robots: &[BoardNumber],
        keys: &[SdlsKey],
        security: Sec,
        store: St,
    ) -> Result<Self, GlueError> {
        let mut gateway = Gateway::new(config);
        for &board in robots {
            for spi in [tc_spi(board), tm_spi(board)] {
                if !keys.iter().any(|k| k.spi == spi) {
                    return Err(GlueError::NoKey {
                        board: board.get(),
                        spi,
                    });
                }
            }
            if !gateway.add(board) {
                return Err(GlueError::Robot(board.get()));
            }
        }
        Ok(ServerGlue {
            gateway,
            security,
            store,
            counts: Counts::default(),
        })
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
        while let Some(n) = ground.recv(&mut buf) {
            self.counts.tc_datagrams = self.counts.tc_datagrams.wrapping_add(1);
            let now = clock.now_ms();
            let frame = buf.get_mut(..n).unwrap_or(&mut []);
            match self.security.tc_in(&mut self.store, now, frame) {
                Some(len) => {
                    self.gateway.tc_frame(now, frame.get(..len).unwrap_or(&[]));
                }
                None => self.counts.tc_insecure = self.counts.tc_insecure.wrapping_add(1),
            }
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
        while let Some((_, len)) = self.gateway.frame(now, &mut tm) {
            let sent = self
                .security
                .tm_out(&mut self.store, &mut tm, len)
                .is_some_and(|n| ground.send(tm.get(..n).unwrap_or(&[])));
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

/// The frame security the image runs, made from the keys it carries. **Not SDLS yet**: until
/// the library's `mmic::link::sdls` lands this returns [`Clear`] and the keys go unused; the
/// lead completes it (per robot a TC receiver SA on [`tc_spi`] and a TM sender SA on
/// [`tm_spi`], each keyed from `keys`, their counters restored through the [`CounterStore`]
/// that [`FrameSecurity`]'s calls receive).
pub fn security(keys: &[SdlsKey]) -> Clear {
    let _ = keys;
    Clear
}
