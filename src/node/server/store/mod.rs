//! What the server board keeps across restarts, and what the ground keeps of its SDLS
//! counters: entries of one durable store, the same in every shell (the server image's flash
//! log, the host simulator's state file, the provisioning tool's images).
//!
//! | key | aux | value | what |
//! |---|---|---|---|
//! | `0x0100 + n`, `0x0200 + n` | 0 | the SDLS counter | robot n's TC and TM associations ([`crate::link::sdls::counter`]: a sender's reservation, a receiver's floor) |
//! | `0x1000 \| SPI` | 0 | the key's [`Fingerprint`] (64 bits) | which key that counter belongs to |
//! | `0x2000 + n` | V(R) | the last TC IV accepted | FARM-1 and the TC window exactly where they stood |
//! | `0x2100 + n` | V(R) | 0 | FARM-1 on a link without SDLS |
//! | `0x3000 + 4n + slot` | 1 (0: empty) | source ID << 16 \| sequence count | the gateway's kept telecommand keys ([`Kept`]) |
//! | `0x4000 + 16n + slot` | 1 (0: empty) | a queued telecommand ([`queue`]) | the gateway's queue, written before a telecommand is acknowledged and before it leaves for board A |
//!
//! A link starts only from a provisioned store ([`boot`]): each of its SPIs needs its key's
//! fingerprint and its counter. A blank store, a fingerprint of another key, or a counter
//! missing stop that robot's link ([`Stopped`]), never the board, until the explicit
//! provisioning step ([`provision`]: `mmic sdls provision`) writes the fingerprints and the
//! first counters. Why not start afresh on a blank store: a store can be blank because it was
//! erased, or because the image runs on a spare board with the same keys; starting the TM
//! counter at 0 again would reuse IVs (AES-GCM then leaks its keystream and its GHASH key),
//! starting the TC window afresh would accept every telecommand frame ever captured.
//!
//! ```
//! use mmic::link::sdls::Key256;
//! use mmic::node::server::store::{self, End, Resume, Stopped};
//! use mmic::units::BoardNumber;
//! use std::collections::BTreeMap;
//!
//! let key = |s: u8| Key256::from_bytes(core::array::from_fn(|i| (i as u8).wrapping_mul(29) ^ s));
//! let (tc, tm) = (key(1), key(2));
//! let one = BoardNumber::ONE;
//! let mut flash: BTreeMap<u16, (u8, u128)> = BTreeMap::new();
//! // A blank store stops the link, naming what is missing.
//! let blank = store::boot(End::Server, one, &tc, &tm, |k| flash.get(&k).copied());
//! assert_eq!(blank.unwrap_err(), Stopped::Unprovisioned { spi: 257 });
//! // Provisioning writes the fingerprints and the first counters; then the link starts.
//! for e in store::provision(End::Server, one, &tc, &tm, Resume::FRESH).unwrap() {
//!     flash.insert(e.key, (e.aux, e.value));
//! }
//! let boot = store::boot(End::Server, one, &tc, &tm, |k| flash.get(&k).copied()).unwrap();
//! assert_eq!(boot.stored.tm, Some(0)); // TM IVs from 0
//! // The same store under another TM key: refused, the counter is not that key's.
//! let other = store::boot(End::Server, one, &tc, &key(3), |k| flash.get(&k).copied());
//! assert_eq!(other.unwrap_err(), Stopped::OtherKey { spi: 513 });
//! ```
// req: D:sdls-store, D:restart-server

pub mod keys;
pub mod log;
pub mod queue;

use super::gateway::{Kept, KEPT_SOURCES};
use crate::link::low;
use crate::link::sdls::key::{Fingerprint, WeakKey};
use crate::link::sdls::{mission, Key256};
use crate::units::BoardNumber;

/// Values are below this: the IV is a 96-bit counter.
pub const VALUE_LIMIT: u128 = 1 << 96;

/// A receiving association's counter when it has accepted nothing yet: the last IV before 0
/// (modulo 2^96), so that IV 0 is the first one ahead.
pub const NOTHING_ACCEPTED: u128 = VALUE_LIMIT - 1;

/// One durable entry.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Entry {
    /// What it is (the table above).
    pub key: u16,
    /// A small value beside it (V(R), a slot's validity).
    pub aux: u8,
    /// The value, below [`VALUE_LIMIT`].
    pub value: u128,
}

/// Which end of the space data link keeps the store: the roles of the two associations.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum End {
    /// The server board: receives the TC association, sends the TM one.
    Server,
    /// The ground: sends TC, receives TM.
    Ground,
}

/// The key of an SPI's key fingerprint.
pub const fn fingerprint_key(spi: u16) -> u16 {
    0x1000 | spi
}

/// The key of robot `board`'s FARM-1 progress on a secured link.
pub const fn progress_key(board: BoardNumber) -> u16 {
    u16::from_be_bytes([0x20, board.get()])
}

/// The key of robot `board`'s FARM-1 progress on a link without SDLS.
pub const fn clear_progress_key(board: BoardNumber) -> u16 {
    u16::from_be_bytes([0x21, board.get()])
}

/// The key of robot `board`'s kept telecommand key in `slot` (0..[`KEPT_SOURCES`]).
pub const fn kept_key(board: BoardNumber, slot: u8) -> u16 {
    // 0x3000 + 4 × board + slot: the three parts' bits do not overlap (the board's end at
    // bit 9), so or-ing them adds them. Widened through from_be_bytes (a const fn may not
    // call From).
    0x3000 | (u16::from_be_bytes([0, board.get()]) << 2) | u16::from_be_bytes([0, slot & 3])
}

/// Where FARM-1 and the TC window stood after the last accepted frame: the server board
/// resumes exactly there after a restart, so that the ground's FOP-1 finds the N(R) it
/// expects and the ground's next transmission is accepted at once (decision
/// `restart-server`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Progress {
    /// FARM-1's V(R).
    pub vr: u8,
    /// The last TC IV accepted (secured links; `None` before the first, or without SDLS).
    pub tc_iv: Option<u128>,
}

impl Progress {
    /// The entry that keeps it, for robot `board`'s link (`secured`: under SDLS).
    pub fn entry(&self, board: BoardNumber, secured: bool) -> Entry {
        match (secured, self.tc_iv) {
            (true, Some(iv)) => Entry {
                key: progress_key(board),
                aux: self.vr,
                value: iv % VALUE_LIMIT,
            },
            _ => Entry {
                key: clear_progress_key(board),
                aux: self.vr,
                value: 0,
            },
        }
    }

    /// Read back from the store (the secured entry first).
    pub fn load(board: BoardNumber, lookup: &impl Fn(u16) -> Option<(u8, u128)>) -> Option<Self> {
        if let Some((vr, iv)) = lookup(progress_key(board)) {
            return Some(Progress {
                vr,
                tc_iv: Some(iv),
            });
        }
        lookup(clear_progress_key(board)).map(|(vr, _)| Progress { vr, tc_iv: None })
    }
}

/// The entries that keep robot `board`'s kept telecommand keys, one per slot.
pub fn kept_entries(board: BoardNumber, kept: &Kept) -> [Entry; KEPT_SOURCES] {
    core::array::from_fn(|slot| {
        let (aux, value) = match kept.get(slot) {
            Some((source, count)) => (1, (u128::from(*source) << 16) | u128::from(*count)),
            None => (0, 0),
        };
        Entry {
            // slot < KEPT_SOURCES = 4: its low octet is all of it.
            key: kept_key(board, low::u8_of_usize(slot)),
            aux,
            value,
        }
    })
}

/// Robot `board`'s kept telecommand keys read back; `None` when none was ever written.
pub fn kept_load(board: BoardNumber, lookup: &impl Fn(u16) -> Option<(u8, u128)>) -> Option<Kept> {
    let mut kept = Kept::new();
    let mut any = false;
    for slot in (0u8..).take(KEPT_SOURCES) {
        if let Some((aux, value)) = lookup(kept_key(board, slot)) {
            any = true;
            if aux == 1 {
                let [.., s0, s1, c0, c1] = value.to_be_bytes();
                let _ = kept.push((u16::from_be_bytes([s0, s1]), u16::from_be_bytes([c0, c1])));
            }
        }
    }
    any.then_some(kept)
}

/// Why a robot's secured link does not start: the link stays stopped (no frame accepted, none
/// sent) and the shell says why, until the store is provisioned.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Stopped {
    /// No fingerprint for the SPI: a blank store, or one never provisioned for this robot.
    #[error("SPI {spi}: no key fingerprint in the store (blank or not provisioned): run the provisioning step")]
    Unprovisioned {
        /// The SPI.
        spi: u16,
    },
    /// The stored fingerprint is another key's: the counters are not this key's.
    #[error("SPI {spi}: the store's counter belongs to another key (the fingerprints differ): provision the store for this key")]
    OtherKey {
        /// The SPI.
        spi: u16,
    },
    /// A fingerprint without its counter (a provisioning cut short).
    #[error("SPI {spi}: a key fingerprint but no counter in the store: provision it again")]
    NoCounter {
        /// The SPI.
        spi: u16,
    },
    /// The key itself is refused.
    #[error("SPI {spi}: {reason}")]
    Weak {
        /// The SPI.
        spi: u16,
        /// Why.
        reason: WeakKey,
    },
}

impl Stopped {
    /// Every reason's name.
    pub const NAMES: [&'static str; 4] = ["unprovisioned", "other-key", "no-counter", "weak-key"];

    /// The reason's name (logs, ST\[5\]).
    pub const fn name(&self) -> &'static str {
        match self {
            Stopped::Unprovisioned { .. } => Self::NAMES[0],
            Stopped::OtherKey { .. } => Self::NAMES[1],
            Stopped::NoCounter { .. } => Self::NAMES[2],
            Stopped::Weak { .. } => Self::NAMES[3],
        }
    }

    /// The code of ST\[5\]'s `link_stopped` ([`crate::pus::event::LINK_STOPPED_REASONS`]).
    pub const fn code(&self) -> u8 {
        // A place among four names: its low octet is all of it.
        low::u8_of_usize(self.position())
    }

    /// The reason's place in [`Stopped::NAMES`].
    pub const fn position(&self) -> usize {
        match self {
            Stopped::Unprovisioned { .. } => 0,
            Stopped::OtherKey { .. } => 1,
            Stopped::NoCounter { .. } => 2,
            Stopped::Weak { .. } => 3,
        }
    }
}

// The boot check's reasons are the first of ST[5]'s link_stopped reasons, in order.
#[cfg_attr(
    not(test),
    expect(
        clippy::indexing_slicing,
        reason = "evaluated by the compiler: an index out of range fails the build, never a run"
    )
)]
const _: () = {
    let mut i = 0;
    while i < Stopped::NAMES.len() {
        let (a, b) = (
            Stopped::NAMES[i].as_bytes(),
            crate::pus::event::LINK_STOPPED_REASONS[i].as_bytes(),
        );
        assert!(a.len() == b.len());
        let mut j = 0;
        while j < a.len() {
            assert!(a[j] == b[j]);
            j += 1;
        }
        i += 1;
    }
};

/// What the shell kept in durable storage, per robot (this module's entries): where the TC
/// window's floor and the TM counter's reservation stood (`None`: a new association), and
/// where FARM-1 and the TC window stood after the last accepted frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Stored {
    /// The TC floor.
    pub tc: Option<u128>,
    /// The TM reservation.
    pub tm: Option<u128>,
    /// FARM-1's V(R) and the last TC IV accepted (`None`: FARM-1 starts at V(R) = 0).
    pub progress: Option<Progress>,
}

/// What a link starts from.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Boot {
    /// The SDLS counters and FARM-1's progress.
    pub stored: Stored,
    /// The gateway's kept telecommand keys (`None`: none kept, a first start).
    pub kept: Option<Kept>,
    /// The gateway's queue as kept: (slot, telecommand), oldest first.
    pub queue: heapless::Vec<(u8, crate::node::server::gateway::Job), { queue::QUEUE_SLOTS }>,
}

/// One association's counter, if its key's fingerprint is the stored one.
fn counter(
    spi: u16,
    key: &Key256,
    lookup: &impl Fn(u16) -> Option<(u8, u128)>,
) -> Result<u128, Stopped> {
    key.check()
        .map_err(|reason| Stopped::Weak { spi, reason })?;
    let (_, fp) = lookup(fingerprint_key(spi)).ok_or(Stopped::Unprovisioned { spi })?;
    if fp != fingerprint_value(key.fingerprint()) {
        return Err(Stopped::OtherKey { spi });
    }
    let (_, value) = lookup(spi).ok_or(Stopped::NoCounter { spi })?;
    Ok(value)
}

fn fingerprint_value(fp: Fingerprint) -> u128 {
    u128::from(u64::from_be_bytes(fp.to_bytes()))
}

/// Robot `board`'s link at `end`, from what `lookup` finds in the store (key → aux, value), the
/// keys it runs under: its counters, its progress and kept keys (the server's), or why it must
/// not start.
pub fn boot(
    end: End,
    board: BoardNumber,
    tc_key: &Key256,
    tm_key: &Key256,
    lookup: impl Fn(u16) -> Option<(u8, u128)>,
) -> Result<Boot, Stopped> {
    let tc = counter(mission::tc_spi(board), tc_key, &lookup)?;
    let tm = counter(mission::tm_spi(board), tm_key, &lookup)?;
    let server = end == End::Server;
    Ok(Boot {
        stored: Stored {
            tc: Some(tc),
            tm: Some(tm),
            progress: if server {
                Progress::load(board, &lookup)
            } else {
                None
            },
        },
        kept: if server {
            kept_load(board, &lookup)
        } else {
            None
        },
        queue: if server {
            queue::queue_load(board, &lookup)
        } else {
            heapless::Vec::new()
        },
    })
}

/// Robot `board`'s link without SDLS at the server board: FARM-1's progress and the kept keys
/// (no counter, nothing to provision).
pub fn boot_clear(board: BoardNumber, lookup: impl Fn(u16) -> Option<(u8, u128)>) -> Boot {
    Boot {
        stored: Stored {
            tc: None,
            tm: None,
            progress: Progress::load(board, &lookup),
        },
        kept: kept_load(board, &lookup),
        queue: queue::queue_load(board, &lookup),
    }
}

/// Where provisioning starts the counters.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Resume {
    /// The sending association's first IV.
    pub tx_from: u128,
    /// The receiving association's last IV accepted (`None`: nothing yet).
    pub rx_after: Option<u128>,
}

impl Resume {
    /// New keys: IVs from 0, nothing accepted.
    pub const FRESH: Resume = Resume {
        tx_from: 0,
        rx_after: None,
    };
}

/// The entries that provision robot `board`'s store at `end` for these keys: both
/// fingerprints and both counters. Weak keys are refused.
pub fn provision(
    end: End,
    board: BoardNumber,
    tc_key: &Key256,
    tm_key: &Key256,
    resume: Resume,
) -> Result<[Entry; 4], Stopped> {
    let (tc_spi, tm_spi) = (mission::tc_spi(board), mission::tm_spi(board));
    for (spi, key) in [(tc_spi, tc_key), (tm_spi, tm_key)] {
        key.check()
            .map_err(|reason| Stopped::Weak { spi, reason })?;
    }
    let tx = resume.tx_from % VALUE_LIMIT;
    let rx = resume
        .rx_after
        .map_or(NOTHING_ACCEPTED, |v| v % VALUE_LIMIT);
    let (tc, tm) = match end {
        End::Server => (rx, tx),
        End::Ground => (tx, rx),
    };
    let entry = |key, value| Entry { key, aux: 0, value };
    Ok([
        entry(
            fingerprint_key(tc_spi),
            fingerprint_value(tc_key.fingerprint()),
        ),
        entry(
            fingerprint_key(tm_spi),
            fingerprint_value(tm_key.fingerprint()),
        ),
        entry(tc_spi, tc),
        entry(tm_spi, tm),
    ])
}

/// Whether an entry's key belongs to none of the `served` robots (another image's, or no
/// key this layout knows): reported, never used.
pub fn foreign(served: &[BoardNumber], key: u16) -> bool {
    let robot = match key {
        // Each range's robot number fits an octet: the conversions hold.
        0x0100..=0x02FF | 0x1100..=0x12FF | 0x2000..=0x21FF => u8::try_from(key & 0xFF).ok(),
        0x3000..=0x33FF => u8::try_from(key.saturating_sub(0x3000) / 4).ok(),
        0x4000..=0x4FFF => u8::try_from(key.saturating_sub(0x4000) / 16).ok(),
        _ => None,
    };
    !robot.is_some_and(|r| served.iter().any(|b| b.get() == r))
}
