//! The durable store's flash log: the entries of `mmic::node::server::store` (SDLS counters
//! and their keys' fingerprints, FARM-1's progress, the gateway's kept telecommand keys; board
//! A's record, [`crate::durable`]) kept in NOR flash across resets and power loss.
//!
//! Why a log and not a fixed cell per key: NOR flash is erased by whole sectors (4 KiB on the
//! ESP32) and a write can only clear bits, so rewriting a cell in place means erasing its sector,
//! and a power cut between the erase and the write would lose every entry in it — after which
//! a sender would reuse IVs. Instead every write appends one record; the newest valid record of
//! a key is its entry. Two sectors alternate: when the active one is full, the other is erased,
//! the newest record of every key is copied into it, and its header (with a generation number
//! one higher) is written last. Until that header is whole, the old sector stays the active one,
//! so a cut anywhere in a compaction loses nothing.
//!
//! The record is the library's (`mmic::node::server::store::log`: 20 octets, tag, aux, key,
//! the 96-bit value, CRC-32), so the images `mmic sdls image --counters-image` writes for
//! `espflash write-bin` open here as they are ([`FlashLog::open`]). A record torn by a power
//! cut fails its CRC and is skipped; the slot stays used (it cannot be rewritten without an
//! erase), and the next record goes after it. An all-`0xFF` slot is free.
//!
//! Opening only reads. A region with no valid sector header (erased, or corrupt) opens empty
//! ([`LogState`]) and is formatted only by the first write: the server board never writes to
//! such a store (its links need the provisioned fingerprints first, `store::boot`), so an
//! erased or damaged store is reported, never silently made into a fresh one.
//!
//! Entries of keys the image does not serve (`store::foreign`, another image's robots) are set
//! apart when the log opens ([`FlashLog::open_with`]): never looked up, never a reason to
//! refuse a write; they are carried over at a compaction while room is left, and counted.

use embedded_storage::nor_flash::{NorFlash, NorFlashError, NorFlashErrorKind};
use heapless::Vec;
use mmic::node::server::store::log::{self, Record};
use mmic::node::server::store::Entry;

pub use mmic::node::server::store::log::RECORD_LEN;
pub use mmic::node::server::store::VALUE_LIMIT;

/// Sectors the log alternates between.
pub const SECTORS: u32 = 2;

/// The server board's durable store, as the glue uses it ([`crate::server::ServerGlue`]).
pub trait EntryStore {
    /// The newest entry of `key`: (aux, value); `None` when none was ever written.
    fn lookup(&self, key: u16) -> Option<(u8, u128)>;
    /// Makes `e` the durable entry of its key. Once this returns `Ok`, a reset finds it.
    fn write(&mut self, e: &Entry) -> Result<(), LogError>;
}

/// Why the log refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum LogError {
    /// The value does not fit 96 bits.
    #[error("value {0:#x} is not below 2^96")]
    TooLarge(u128),
    /// The flash region is too small or its units do not divide a record.
    #[error(
        "flash region of {capacity} octets, erase unit {erase}, write unit {write}, read unit {read}: \
         needs 2 erase units, each holding at least 2 records of {RECORD_LEN} octets, \
         and units dividing {RECORD_LEN}"
    )]
    Geometry {
        /// The region's size, octets.
        capacity: usize,
        /// Its erase unit, octets.
        erase: usize,
        /// Its write unit, octets.
        write: usize,
        /// Its read unit, octets.
        read: usize,
    },
    /// More distinct keys than the log was built for (its `S`), or more than a sector holds.
    #[error("more than {0} keys: the log cannot take another")]
    Full(usize),
    /// The flash driver failed.
    #[error("flash: {0:?}")]
    Flash(NorFlashErrorKind),
}

impl LogError {
    /// A short name (logs).
    pub const fn name(&self) -> &'static str {
        match self {
            LogError::TooLarge(_) => "too-large",
            LogError::Geometry { .. } => "geometry",
            LogError::Full(_) => "full",
            LogError::Flash(_) => "flash",
        }
    }
}

/// What the region held when the log opened.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LogState {
    /// Both sectors' headers erased: nothing was ever written (or the region was erased).
    Blank,
    /// No valid sector header, but not erased either: a corrupt or foreign region.
    NoHeader,
    /// The active sector and its generation.
    Active {
        /// The sector's generation.
        generation: u32,
    },
}

/// A record slot, aligned for the ESP32's flash driver (an unaligned buffer makes it copy
/// through a 4 KiB buffer on the stack).
#[repr(align(4))]
struct Slot([u8; RECORD_LEN]);

/// Whether generation `a` is newer than `b` (serial-number order: generations wrap).
const fn newer(a: u32, b: u32) -> bool {
    let d = a.wrapping_sub(b);
    d != 0 && d < 1 << 31
}

/// The log on a NOR flash region (addresses from 0: a partition, see README.md) of at least
/// two erase units, for up to `S` distinct keys of its own and `X` of keys it does not serve.
pub struct FlashLog<F: NorFlash, const S: usize, const X: usize = 0> {
    flash: F,
    /// The newest entry of every key of the image's in the active sector (what a reset would
    /// find).
    entries: Vec<Entry, S>,
    /// The same for keys the image does not serve (carried over, never used).
    foreign: Vec<Entry, X>,
    /// Records of keys set apart that did not fit `foreign` (or no longer fit a compaction),
    /// and of the image's own keys beyond `S`: not carried over at the next compaction.
    dropped: u32,
    /// The active sector (0 or 1); `None` before the first write on a region without a valid
    /// header.
    active: Option<u32>,
    state: LogState,
    /// Its generation.
    generation: u32,
    /// The first free slot in it.
    next: u32,
}

impl<F: NorFlash, const S: usize, const X: usize> FlashLog<F, S, X> {
    /// The sector size: one erase unit.
    const SECTOR: u32 = F::ERASE_SIZE as u32;
    /// Record slots per sector (slot 0 is the header).
    const SLOTS: u32 = Self::SECTOR / RECORD_LEN as u32;

    /// Opens the log on `flash`, every key the image's (board A's record).
    pub fn open(flash: F) -> Result<Self, LogError> {
        Self::open_with(flash, |_| false)
    }

    /// Opens the log on `flash`: finds the active sector (the valid header with the newest
    /// generation) and its first free slot, and reads its entries; those whose key `foreign`
    /// says the image does not serve are set apart. Only reads: a region with no valid header
    /// opens empty, and is formatted by the first write.
    pub fn open_with(mut flash: F, foreign: impl Fn(u16) -> bool) -> Result<Self, LogError> {
        let geometry = LogError::Geometry {
            capacity: flash.capacity(),
            erase: F::ERASE_SIZE,
            write: F::WRITE_SIZE,
            read: F::READ_SIZE,
        };
        let units_ok = F::WRITE_SIZE > 0
            && F::READ_SIZE > 0
            && RECORD_LEN.is_multiple_of(F::WRITE_SIZE)
            && RECORD_LEN.is_multiple_of(F::READ_SIZE);
        if !units_ok
            || F::ERASE_SIZE > u32::MAX as usize / 2
            || Self::SLOTS < 2
            || flash.capacity() < (SECTORS * Self::SECTOR) as usize
        {
            return Err(geometry);
        }
        let mut best: Option<(u32, u32)> = None;
        let mut blank = true;
        for sector in 0..SECTORS {
            match read(&mut flash, sector * Self::SECTOR)? {
                Record::Header(g) => {
                    blank = false;
                    if best.is_none_or(|(_, b)| newer(g, b)) {
                        best = Some((sector, g));
                    }
                }
                Record::Free => {}
                Record::Invalid | Record::Entry(_) => blank = false,
            }
        }
        let mut store = FlashLog {
            flash,
            entries: Vec::new(),
            foreign: Vec::new(),
            dropped: 0,
            active: None,
            state: if blank {
                LogState::Blank
            } else {
                LogState::NoHeader
            },
            generation: 0,
            next: 1,
        };
        if let Some((sector, g)) = best {
            store.active = Some(sector);
            store.generation = g;
            store.state = LogState::Active { generation: g };
            store.scan(&foreign)?;
        }
        Ok(store)
    }

    /// The flash back (for a simulated reset in tests, or another user).
    pub fn release(self) -> F {
        self.flash
    }

    /// What the region held when the log opened.
    pub const fn state(&self) -> LogState {
        self.state
    }

    /// Records still free in the active sector.
    pub const fn free_slots(&self) -> u32 {
        Self::SLOTS - self.next
    }

    /// The active sector's generation (one more per compaction; 0 before the first write on
    /// a region without a valid header).
    pub const fn generation(&self) -> u32 {
        self.generation
    }

    /// The entries of keys the image does not serve (set apart at opening, carried over).
    pub fn foreign(&self) -> &[Entry] {
        &self.foreign
    }

    /// Records left out: of keys set apart beyond the room kept for them, or of the image's
    /// own keys beyond `S` (none when `S` covers the keys the image serves).
    pub const fn dropped(&self) -> u32 {
        self.dropped
    }

    /// Every entry of the image's keys.
    pub fn entries(&self) -> &[Entry] {
        &self.entries
    }

    fn addr(&self, sector: u32, slot: u32) -> u32 {
        sector * Self::SECTOR + slot * RECORD_LEN as u32
    }

    fn erase(&mut self, sector: u32) -> Result<(), LogError> {
        let from = sector * Self::SECTOR;
        self.flash
            .erase(from, from + Self::SECTOR)
            .map_err(|e| LogError::Flash(e.kind()))
    }

    fn program(&mut self, addr: u32, record: [u8; RECORD_LEN]) -> Result<(), LogError> {
        let slot = Slot(record);
        self.flash
            .write(addr, &slot.0)
            .map_err(|e| LogError::Flash(e.kind()))
    }

    /// Reads the active sector: the newest entry of each key, and the slot after the last one
    /// used (valid or torn).
    fn scan(&mut self, foreign: &impl Fn(u16) -> bool) -> Result<(), LogError> {
        let Some(active) = self.active else {
            return Ok(());
        };
        self.next = 1;
        for slot in 1..Self::SLOTS {
            let at = self.addr(active, slot);
            match read(&mut self.flash, at)? {
                Record::Free => continue,
                Record::Entry(e) if foreign(e.key) => self.set_apart(e),
                Record::Entry(e) => {
                    if remember(&mut self.entries, e).is_err() {
                        self.dropped = self.dropped.saturating_add(1);
                    }
                }
                Record::Invalid | Record::Header(_) => {}
            }
            self.next = slot + 1;
        }
        Ok(())
    }

    fn set_apart(&mut self, e: Entry) {
        if remember(&mut self.foreign, e).is_err() {
            self.dropped = self.dropped.saturating_add(1);
        }
    }

    /// Erases sector 0 and makes it the active one (generation 1): the first write on a region
    /// without a valid header.
    fn format(&mut self) -> Result<(), LogError> {
        self.erase(0)?;
        self.program(0, log::encode_header(1))?;
        self.active = Some(0);
        self.generation = 1;
        self.next = 1;
        Ok(())
    }

    /// Copies the newest record of every key into the other sector (the image's first, then
    /// those set apart while room is left for one more record), then makes it the active one
    /// by writing its header last.
    fn compact(&mut self, active: u32) -> Result<(), LogError> {
        let own = self.entries.len() as u32;
        // The header, the image's entries, and the record this compaction makes room for.
        if own + 2 > Self::SLOTS {
            return Err(LogError::Full(S));
        }
        let room = (Self::SLOTS - own - 2) as usize;
        if self.foreign.len() > room {
            let cut = self.foreign.len() - room;
            self.dropped = self.dropped.saturating_add(cut as u32);
            self.foreign.truncate(room);
        }
        let target = 1 - active;
        self.erase(target)?;
        let mut slot = 1;
        for i in 0..self.entries.len() + self.foreign.len() {
            let e = match self.entries.get(i) {
                Some(e) => *e,
                None => self.foreign[i - self.entries.len()],
            };
            // Every value was below 2^96 when it was read or written.
            let record = log::encode_entry(&e).ok_or(LogError::TooLarge(e.value))?;
            let at = self.addr(target, slot);
            self.program(at, record)?;
            slot += 1;
        }
        let generation = self.generation.wrapping_add(1);
        let at = self.addr(target, 0);
        self.program(at, log::encode_header(generation))?;
        self.active = Some(target);
        self.generation = generation;
        self.state = LogState::Active { generation };
        self.next = slot;
        Ok(())
    }
}

/// Keeps `e` as the newest entry of its key in `table`; `Err` when the table is full.
fn remember<const N: usize>(table: &mut Vec<Entry, N>, e: Entry) -> Result<(), Entry> {
    match table.iter_mut().find(|t| t.key == e.key) {
        Some(t) => {
            *t = e;
            Ok(())
        }
        None => table.push(e),
    }
}

fn read<F: NorFlash>(flash: &mut F, addr: u32) -> Result<Record, LogError> {
    let mut s = Slot([0; RECORD_LEN]);
    flash
        .read(addr, &mut s.0)
        .map_err(|e| LogError::Flash(e.kind()))?;
    Ok(log::decode(&s.0))
}

impl<F: NorFlash, const S: usize, const X: usize> EntryStore for FlashLog<F, S, X> {
    /// From RAM: the entries were read at [`FlashLog::open_with`] and follow every write.
    fn lookup(&self, key: u16) -> Option<(u8, u128)> {
        self.entries
            .iter()
            .find(|e| e.key == key)
            .map(|e| (e.aux, e.value))
    }

    fn write(&mut self, e: &Entry) -> Result<(), LogError> {
        let record = log::encode_entry(e).ok_or(LogError::TooLarge(e.value))?;
        if self.entries.len() == S && self.lookup(e.key).is_none() {
            return Err(LogError::Full(S));
        }
        let active = match self.active {
            Some(a) if self.next < Self::SLOTS => a,
            Some(a) => {
                self.compact(a)?;
                1 - a
            }
            None => {
                self.format()?;
                0
            }
        };
        let at = self.addr(active, self.next);
        // The slot is used from here on, whole or torn.
        self.next += 1;
        self.program(at, record)?;
        self.state = LogState::Active {
            generation: self.generation,
        };
        // Room checked above.
        let _ = remember(&mut self.entries, *e);
        Ok(())
    }
}
