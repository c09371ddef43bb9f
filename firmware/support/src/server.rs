//! The server board's glue towards the ground over the space data link (issue 28): TC transfer
//! frames arrive as UDP datagrams and go into the library's [`FrameGateway`] (SDLS, FARM-1 per
//! robot, the PUS gateway); the legacy
//! commands its `tick` says are due go to board A (one visit each, as the host simulator's
//! `FrameGatewayTask` makes them); the heartbeats the visits bring back go into the gateway;
//! every TM transfer frame it says is due (protected by SDLS) goes to the ground, one per
//! datagram; what the gateway asks to keep goes to the durable store first.
//!
//! Generic over the I/O ([`Datagrams`], [`BoardLink`], [`Clock`]) and the durable store
//! ([`EntryStore`]), so the host tests drive it with mocks and the image with embassy-net and
//! flash. It decides nothing the library does not: the only choices here are the order of the
//! steps (the simulator's, `host/src/sim/durable.rs`), what is counted when an I/O fails, and
//! how long a failing store is left alone.
//!
//! **Starting** ([`ServerGlue::new`]), as the simulator's `boot_gateway`: each robot's link
//! starts from the keys read from the `mmic_keys` partition and what the store kept
//! (`store::boot`: the keys' fingerprints, the SDLS counters, FARM-1's progress, the gateway's
//! kept telecommand keys), through `add` or `add_restarted`, then `secure`. A robot whose keys
//! are missing or refused, whose store is blank, of another key, or incomplete, is not served:
//! its link stays stopped (its frames are refused by the frame checks as no robot's, nothing of
//! it is sent), the reason kept ([`LinkStop`]) for the image's log, and the board serves the
//! others. Nothing here panics on what the flash holds.
//!
//! **Keeping** (every pass: after each TC frame, before the tick, before and after each TM
//! frame): every entry `durable_due` gives is written and confirmed with `durable_written`;
//! until the progress and kept keys are confirmed the gateway sends no TM frame and no visit.
//! A write that fails is not tried again at once: the store is left alone for 10 ms, doubling
//! to 1 s while the writes keep failing (counted), so a failing flash is not erased and
//! compacted on every pass.

use crate::counters::{EntryStore, FlashLog, LogError};
use crate::net;
use core::fmt;
use embedded_storage::nor_flash::NorFlash;
use heapless::Vec;
use mmic::link::sdls::{mission, Key256};
use mmic::node::server::frames::{FrameConfig, FrameGateway, SecureError, FRAME_LEN};
use mmic::node::server::store::keys::{self, KeySet, KeysError};
use mmic::node::server::store::{self, Boot, End, Entry, Stopped};
use mmic::units::BoardNumber;
use mmic::wire::command::COMMAND_LEN;
use mmic::wire::heartbeat::{HeartbeatRepr, HEARTBEAT_LEN};
use zeroize::Zeroize;

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
/// Distinct keys of one served robot the store can hold (`store::foreign` counts them as
/// that robot's): its two SDLS counters, their two fingerprints, FARM-1's progress with and
/// without SDLS, four kept-key slots, and the 16 slots of its telecommand queue's ring
/// (`store::queue`). A log of `ENTRIES_PER_ROBOT * R` keys is never full.
pub const ENTRIES_PER_ROBOT: usize = 10 + mmic::node::server::store::queue::QUEUE_SLOTS;
/// Entries of robots the image does not serve kept aside in RAM (and carried over at a
/// compaction); more are counted and left out.
pub const FOREIGN: usize = 16;
/// The first wait after a failed durable write, ms; it doubles while writes keep failing.
pub const BACKOFF_MIN_MS: u32 = 10;
/// The longest wait between tries of a failing store, ms.
pub const BACKOFF_MAX_MS: u32 = 1000;
/// Entries taken from the gateway per round of a persist (rounds repeat until none is due).
const DUE_BATCH: usize = 16;

/// The gateway the server board runs, for `R` robots (the image's: one FARM-1, queue, key log
/// and TM framer each, about 4.4 KB of RAM per robot).
pub type Gateway<const R: usize> = FrameGateway<R, QUEUE, KEYS, TM_WAITING>;

/// The ground's datagram socket (UDP): TC frames in, TM frames out.
pub trait Datagrams {
    /// The next datagram waiting, copied into `buf` (a longer one is cut to `buf.len()`): its
    /// length and its source address (`None` when the socket cannot say); `None` when none
    /// waits (never blocks).
    fn recv(&mut self, buf: &mut [u8]) -> Option<(usize, Option<[u8; 4]>)>;
    /// Sends one datagram to the ground; false when it did not go.
    fn send(&mut self, datagram: &[u8]) -> bool;
}

/// The legacy link to the robots' board A (the visits: connect, send the 14-byte command, wait
/// for the heartbeat from the visited board's address, [`net::visit_peer`], disconnect).
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

/// Why a flash partition could not be used (the image's reasons, kept in [`LinkStop`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum PartitionFault {
    /// The partition table could not be read or is not valid.
    #[error(
        "the partition table could not be read: flash with --partition-table server-ccsds/partitions.csv"
    )]
    Table,
    /// No partition of that label.
    #[error("no such partition: flash with --partition-table server-ccsds/partitions.csv")]
    Absent,
    /// The partition is not data/undefined, or the image cannot use it as it is (an encrypted
    /// counters partition).
    #[error("the partition's type or flags are not server-ccsds/partitions.csv's")]
    Kind,
    /// Reading it failed.
    #[error("the partition could not be read")]
    Read,
}

/// Why a robot's link is stopped: it is not served, and the image says why (a log line at
/// start-up and periodically). Never shows a key.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum LinkStop {
    /// The keys partition (`mmic_keys`) could not be read.
    #[error("keys partition mmic_keys: {0}")]
    KeysPartition(PartitionFault),
    /// The keys partition was refused (blank, corrupt, a weak key: the library's reason).
    #[error("keys partition mmic_keys: {0}")]
    Keys(KeysError),
    /// The keys partition holds no key for one of the robot's SAs.
    #[error("keys partition mmic_keys has no key for SPI {spi}: provision it (mmic sdls image)")]
    NoKey {
        /// The SA's SPI.
        spi: u16,
    },
    /// The counters partition (`mmic_ctr`) could not be read.
    #[error("durable store mmic_ctr: {0}")]
    StorePartition(PartitionFault),
    /// The durable log could not be opened.
    #[error("durable store mmic_ctr: {0}")]
    Store(LogError),
    /// The store is not provisioned for these keys (the library's boot check).
    #[error("durable store mmic_ctr: {0}")]
    Boot(Stopped),
    /// The library could not secure the link (it must not run in clear instead).
    #[error("{0}")]
    Secure(SecureError),
    /// More robots than the image has places for, or one twice.
    #[error("more robots than the image serves, or this one twice")]
    NotServed,
}

impl LinkStop {
    /// A short name (logs): the library's where it has one.
    pub const fn name(&self) -> &'static str {
        match self {
            LinkStop::KeysPartition(_) => "keys-partition",
            LinkStop::Keys(_) => "keys",
            LinkStop::NoKey { .. } => "no-key",
            LinkStop::StorePartition(_) => "store-partition",
            LinkStop::Store(_) => "store",
            LinkStop::Boot(s) => s.name(),
            LinkStop::Secure(_) => "secure",
            LinkStop::NotServed => "not-served",
        }
    }

    /// The reason's code in ST\[5\] `link_stopped` (`mmic::pus::event::LINK_STOPPED_REASONS`).
    pub const fn code(&self) -> u8 {
        match self {
            LinkStop::Boot(s) => s.code(),
            LinkStop::KeysPartition(_) | LinkStop::Keys(_) | LinkStop::NoKey { .. } => 4,
            LinkStop::StorePartition(_) | LinkStop::Store(_) => 5,
            LinkStop::Secure(_) | LinkStop::NotServed => 6,
        }
    }
}

/// What the glue counts (each wraps at `u32::MAX`); FARM-1's and the gateway's own counts are
/// the library's ([`Gateway::counters`], [`Gateway::refused`]).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Counts {
    /// Datagrams from the ground.
    pub tc_datagrams: u32,
    /// Of those, from elsewhere than the ground's address (FARM-1 obeys no BC frame of them).
    pub tc_elsewhere: u32,
    /// Durable entries written and confirmed.
    pub store_writes: u32,
    /// Durable writes the store refused (nothing confirmed: the gateway asks again; until a
    /// write succeeds, frames wait or are refused, never protected or accepted beyond what is
    /// durable).
    pub store_failed: u32,
    /// Passes that left the store alone because the last write failed (the back-off).
    pub store_deferred: u32,
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

/// A robot ready to be served: what it starts from, and its keys.
struct Ready {
    board: BoardNumber,
    boot: Boot,
    tc: Key256,
    tm: Key256,
}

/// The back-off of a failing store.
#[derive(Debug, Clone, Copy, Default)]
struct Backoff {
    /// No write before this (ms since boot), while writes fail.
    retry_at: Option<u32>,
    /// The next wait, ms.
    wait_ms: u32,
}

/// The server board's state besides its sockets, for `R` robots.
pub struct ServerGlue<St, const R: usize> {
    gateway: Gateway<R>,
    store: Option<St>,
    stopped: Vec<(BoardNumber, LinkStop), R>,
    counts: Counts,
    backoff: Backoff,
}

impl<St, const R: usize> fmt::Debug for ServerGlue<St, R> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("ServerGlue")
            .field("stopped", &self.stopped)
            .field("counts", &self.counts)
            .finish_non_exhaustive()
    }
}

impl<St: EntryStore, const R: usize> ServerGlue<St, R> {
    /// The gateway for `robots`, each started from `store` and secured with SDLS under its
    /// keys from `keys` (`mmic::link::sdls::mission`: robot n's TC SA is SPI 0x100 + n, its TM
    /// SA 0x200 + n). `keys` and `store` are what the image could read, or why not: every
    /// robot's link is then stopped with that reason. A robot that cannot start is left out
    /// ([`ServerGlue::stopped`]); the others are served.
    pub fn new(
        config: FrameConfig,
        robots: &[BoardNumber; R],
        keys: Result<&KeySet, LinkStop>,
        store: Result<St, LinkStop>,
    ) -> Self {
        let mut stopped: Vec<(BoardNumber, LinkStop), R> = Vec::new();
        let mut ready: Vec<Ready, R> = Vec::new();
        for (i, &board) in robots.iter().enumerate() {
            let why = if robots[..i].contains(&board) {
                Err(LinkStop::NotServed)
            } else {
                prepare(board, keys, store.as_ref())
            };
            // Both hold at most R: one place per robot given.
            let _ = match why {
                Ok(r) => ready.push(r).map_err(drop),
                Err(why) => stopped.push((board, why)).map_err(drop),
            };
        }
        // The library must secure every link it serves: a robot it refuses is left out, and
        // the gateway is built again without it (a gateway cannot forget a robot).
        let gateway = loop {
            match build(config, &ready) {
                Ok(g) => break g,
                Err((i, why)) => {
                    let r = ready.remove(i);
                    let _ = stopped.push((r.board, why));
                }
            }
        };
        // Said over the link at the first chance: ST[5] link_stopped in the telemetry of every
        // robot whose link runs (a stopped link itself has no trusted way to send anything).
        let mut gateway = gateway;
        for (board, why) in &stopped {
            gateway.link_stopped(0, *board, why.code());
        }
        ServerGlue {
            gateway,
            store: store.ok(),
            stopped,
            counts: Counts::default(),
            backoff: Backoff::default(),
        }
    }

    /// The robots whose links are stopped, and why.
    pub fn stopped(&self) -> &[(BoardNumber, LinkStop)] {
        &self.stopped
    }

    /// Whether robot `board`'s link is served.
    pub fn serves(&self, board: BoardNumber) -> bool {
        self.gateway.farm(board).is_some()
    }

    /// The library's gateway (FARM-1, the link counters).
    pub const fn gateway(&self) -> &Gateway<R> {
        &self.gateway
    }

    /// What the glue counted.
    pub const fn counts(&self) -> &Counts {
        &self.counts
    }

    /// The durable store (`None`: it could not be opened, every link stopped).
    pub fn store(&mut self) -> Option<&mut St> {
        self.store.as_mut()
    }

    /// While the store is failing: the current wait between tries, ms.
    pub const fn backoff_ms(&self) -> Option<u32> {
        match self.backoff.retry_at {
            Some(_) => Some(self.backoff.wait_ms),
            None => None,
        }
    }

    /// Writes what the gateway asks to keep and confirms each write that succeeded (nothing
    /// leaves that depends on an unconfirmed one); after a failure, nothing is tried before
    /// the back-off ends.
    fn persist(&mut self, now: u32) {
        let Some(store) = self.store.as_mut() else {
            return;
        };
        if let Some(at) = self.backoff.retry_at {
            // Serial-number order: the clock wraps.
            if (now.wrapping_sub(at) as i32) < 0 {
                self.counts.store_deferred = self.counts.store_deferred.wrapping_add(1);
                return;
            }
        }
        // Every round confirms at least one entry, or stops: seven per robot at most are due.
        for _ in 0..R * mmic::node::server::frames::DUE_PER_ROBOT / DUE_BATCH + 2 {
            let due: Vec<Entry, DUE_BATCH> = self.gateway.durable_due();
            if due.is_empty() {
                break;
            }
            let mut fresh = false;
            for e in &due {
                if store.write(e).is_err() {
                    self.counts.store_failed = self.counts.store_failed.wrapping_add(1);
                    let wait = (self.backoff.wait_ms.saturating_mul(2))
                        .clamp(BACKOFF_MIN_MS, BACKOFF_MAX_MS);
                    self.backoff = Backoff {
                        retry_at: Some(now.wrapping_add(wait)),
                        wait_ms: wait,
                    };
                    return;
                }
                self.counts.store_writes = self.counts.store_writes.wrapping_add(1);
                fresh |= self.gateway.durable_written(e);
            }
            if !fresh {
                break;
            }
        }
        self.backoff = Backoff::default();
    }

    /// One pass, in the host simulator's order: every TC frame waiting (each followed by the
    /// durable entries it made); every heartbeat the visits brought back; the durable entries;
    /// the gateway's tick (its legacy commands to the board link); every TM frame due. Returns
    /// when the gateway next needs a pass if nothing arrives (ms since boot), for the shell's
    /// sleep.
    pub fn poll(
        &mut self,
        clock: &mut impl Clock,
        ground: &mut impl Datagrams,
        board: &mut impl BoardLink,
    ) -> Option<u32> {
        let mut buf = [0u8; TC_DATAGRAM];
        self.persist(clock.now_ms());
        while let Some((n, from)) = ground.recv(&mut buf) {
            self.counts.tc_datagrams = self.counts.tc_datagrams.wrapping_add(1);
            let origin = net::origin(from);
            if origin != mmic::node::server::frames::Origin::Ground {
                self.counts.tc_elsewhere = self.counts.tc_elsewhere.wrapping_add(1);
            }
            let now = clock.now_ms();
            // SDLS, FARM-1 and the PUS gateway: the library's (a refused frame is counted
            // there, per reason; a BC frame from elsewhere is not obeyed).
            self.gateway
                .tc_frame_from(now, buf.get(..n).unwrap_or(&[]), origin);
            // What a restart resumes from, before anything of the frame leaves the board.
            self.persist(now);
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
        let now = clock.now_ms();
        self.persist(now);
        let mut visits = self.gateway.tick(now);
        // A telecommand the tick held until the store says it left the queue (write-ahead):
        // written now, and handed to board A in this same pass.
        if visits.is_empty() && !self.gateway.durable_due::<1>().is_empty() {
            self.persist(now);
            visits = self.gateway.tick(now);
        }
        for (b, command) in visits {
            if board.command(b, command.to_bytes()) {
                self.counts.commands = self.counts.commands.wrapping_add(1);
            } else {
                self.counts.commands_busy = self.counts.commands_busy.wrapping_add(1);
            }
        }
        let now = clock.now_ms();
        let mut tm = [0u8; FRAME_LEN];
        self.persist(now);
        while let Some((_, len)) = self.gateway.frame(now, &mut tm) {
            let sent = ground.send(tm.get(..len).unwrap_or(&[]));
            self.persist(now);
            if sent {
                self.counts.tm_frames = self.counts.tm_frames.wrapping_add(1);
            } else {
                self.counts.tm_unsent = self.counts.tm_unsent.wrapping_add(1);
            }
        }
        let next = self.gateway.next_deadline(now);
        match (next, self.backoff.retry_at) {
            (None, at) => at,
            (Some(t), None) => Some(t),
            // The earlier of the two.
            (Some(t), Some(at)) => Some(if (at.wrapping_sub(t) as i32) < 0 {
                at
            } else {
                t
            }),
        }
    }
}

/// The octets of the keys partition the image reads: its header, [`keys::MAX_KEYS`] keys and
/// the CRC (the rest of the 4 KiB partition is erased).
pub const KEYS_READ: usize = keys::HEADER_LEN + keys::MAX_KEYS * keys::ENTRY_LEN + 4;

/// The keys read from the keys partition into `buf`, or why they are refused (blank, corrupt,
/// a weak key: `keys::parse`); `buf` is cleared either way (it held the keys).
pub fn keys_from(buf: &mut [u8]) -> Result<KeySet, LinkStop> {
    let parsed = keys::parse(buf).map_err(LinkStop::Keys);
    buf.zeroize();
    parsed
}

/// The durable log on the counters partition's `flash`, for the image serving `robots`: the
/// entries of other robots (`store::foreign`) set apart. Only reads.
pub fn open_store<F: NorFlash, const S: usize, const X: usize>(
    flash: F,
    robots: &[BoardNumber],
) -> Result<FlashLog<F, S, X>, LinkStop> {
    FlashLog::open_with(flash, |k| store::foreign(robots, k)).map_err(LinkStop::Store)
}

/// What robot `board` starts from, or why it cannot start.
fn prepare<St: EntryStore>(
    board: BoardNumber,
    keys: Result<&KeySet, LinkStop>,
    store: Result<&St, &LinkStop>,
) -> Result<Ready, LinkStop> {
    let keys = keys?;
    let store = store.map_err(|why| *why)?;
    let (tc_spi, tm_spi) = (mission::tc_spi(board), mission::tm_spi(board));
    let tc = keys.get(tc_spi).ok_or(LinkStop::NoKey { spi: tc_spi })?;
    let tm = keys.get(tm_spi).ok_or(LinkStop::NoKey { spi: tm_spi })?;
    let boot =
        store::boot(End::Server, board, tc, tm, |k| store.lookup(k)).map_err(LinkStop::Boot)?;
    Ok(Ready {
        board,
        boot,
        tc: tc.clone(),
        tm: tm.clone(),
    })
}

/// The gateway serving every robot of `ready`, each restarted with what it kept and secured;
/// or the first one the library refused, and why.
fn build<const R: usize>(
    config: FrameConfig,
    ready: &[Ready],
) -> Result<Gateway<R>, (usize, LinkStop)> {
    let mut g = Gateway::<R>::new(config);
    for (i, r) in ready.iter().enumerate() {
        let added = match &r.boot.kept {
            Some(k) => g.add_restarted(r.board, k.clone()),
            None => g.add(r.board),
        };
        if !added {
            return Err((i, LinkStop::NotServed));
        }
        g.secure(r.board, r.tc.clone(), r.tm.clone(), r.boot.stored)
            .map_err(|e| (i, LinkStop::Secure(e)))?;
        // The telecommands it had accepted and not yet sent to board A: each runs once.
        if !r.boot.queue.is_empty() && !g.restore_queue(r.board, &r.boot.queue) {
            return Err((i, LinkStop::NotServed));
        }
    }
    Ok(g)
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
