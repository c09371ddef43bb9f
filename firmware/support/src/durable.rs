//! Board A's durable record (`mmic::node::robot::board_a::Durable`: the exactly-once log's
//! last entry and the boot count) in NOR flash, across resets and power loss.
//!
//! The store is the server board's durable log ([`crate::counters`]): two sectors, one CRC per
//! record, a torn record skipped, a full sector compacted into the other with its header
//! written last. Board A keeps one entry in it, [`KEY`], whose 96-bit value holds the record's
//! [`Durable::LEN`] octets (the low 40 bits, little-endian; the rest zero). Why not a sibling
//! log: the same torn-write argument would be written and tested twice, for a 5-octet payload
//! that fits the 12-octet value.
//!
//! The order that keeps every command exactly-once across a restart at any instant is
//! [`crate::control::ControlA::tick`]'s: the `ahead` record before the tick that takes a new
//! sequenced command (a command whose record could not be written is not taken: the ground
//! sends it again), the `durable` record after every tick that changed it.

use crate::counters::{EntryStore, FlashLog, LogError};
use embedded_storage::nor_flash::NorFlash;
use mmic::node::robot::board_a::Durable;
use mmic::node::server::store::Entry;

/// The record's key in the log (outside the server's key namespace: the log holds board A's
/// record alone).
pub const KEY: u16 = 0xB0A1;

/// What board A's control task keeps (`Durable`), and where.
pub trait Keep {
    /// The last record kept; `None` on a fresh flash (or a record that does not read back
    /// as one: the board then starts as from a fresh flash).
    fn load(&mut self) -> Option<Durable>;
    /// Makes `d` the record a reset finds. Once this returns `Ok`, it is durable.
    fn keep(&mut self, d: &Durable) -> Result<(), LogError>;
}

/// The record as the log's value.
pub fn to_value(d: &Durable) -> u128 {
    let mut v = [0u8; 16];
    v[..Durable::LEN].copy_from_slice(&d.to_bytes());
    u128::from_le_bytes(v)
}

/// A value back as the record; `None` when it holds more than [`Durable::LEN`] octets or no
/// record.
pub fn from_value(value: u128) -> Option<Durable> {
    let v = value.to_le_bytes();
    if v[Durable::LEN..].iter().any(|&b| b != 0) {
        return None;
    }
    let mut b = [0u8; Durable::LEN];
    b.copy_from_slice(&v[..Durable::LEN]);
    Durable::from_bytes(&b)
}

/// Board A's record in a flash region of two erase units (the `mmic_a` partition:
/// board-a/partitions.csv).
pub struct FlashDurable<F: NorFlash> {
    log: FlashLog<F, 1>,
}

impl<F: NorFlash> FlashDurable<F> {
    /// Opens the log on `flash` (a region that holds none is formatted by the first write:
    /// board A then starts as from a fresh flash).
    pub fn open(flash: F) -> Result<Self, LogError> {
        Ok(FlashDurable {
            log: FlashLog::open(flash)?,
        })
    }

    /// The log (its free slots and generation, for logs).
    pub const fn log(&self) -> &FlashLog<F, 1> {
        &self.log
    }

    /// The flash back (a simulated reset in tests).
    pub fn release(self) -> F {
        self.log.release()
    }
}

impl<F: NorFlash> Keep for FlashDurable<F> {
    fn load(&mut self) -> Option<Durable> {
        from_value(self.log.lookup(KEY)?.1)
    }

    fn keep(&mut self, d: &Durable) -> Result<(), LogError> {
        self.log.write(&Entry {
            key: KEY,
            aux: 0,
            value: to_value(d),
        })
    }
}
