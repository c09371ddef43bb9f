//! The SDLS counters' durable store (sdls-plan.md, "Counters"): one number per SPI (the
//! sender's IV reservation, the receiver's floor), kept in NOR flash across resets and power
//! loss.
//!
//! Why a log and not a fixed cell per SPI: NOR flash is erased by whole sectors (4 KiB on the
//! ESP32) and a write can only clear bits, so rewriting a cell in place means erasing its sector,
//! and a power cut between the erase and the write would lose every counter in it — after which
//! a sender would reuse IVs. Instead every store appends one record; the newest valid record of
//! an SPI is its value. Two sectors alternate: when the active one is full, the other is erased,
//! the newest record of every SPI is copied into it, and its header (with a generation number
//! one higher) is written last. Until that header is whole, the old sector stays the active one,
//! so a cut anywhere in a compaction loses nothing.
//!
//! Record (20 octets, [`RECORD_LEN`]; a multiple of the ESP32's 4-octet write and read units):
//!
//! | octets | counter record | sector header (slot 0 of a sector) |
//! |---|---|---|
//! | 0 | tag `0xC7` | tag `0x5E` |
//! | 1 | `0x00` | `0x00` |
//! | 2..4 | SPI, big-endian | `0x0000` |
//! | 4..16 | value (96 bits), big-endian | 8 × `0x00`, then the generation (u32, big-endian) |
//! | 16..20 | CRC-32/ISO-HDLC of octets 0..16, big-endian | the same |
//!
//! A record torn by a power cut fails its CRC and is skipped; the slot stays used (it cannot be
//! rewritten without an erase), and the next record goes after it. An all-`0xFF` slot is free.

use crc::{Crc, NoTable, CRC_32_ISO_HDLC};
use embedded_storage::nor_flash::{NorFlash, NorFlashError, NorFlashErrorKind};
use heapless::Vec;

/// One record, octets.
pub const RECORD_LEN: usize = 20;
/// Values must be below this (the IV is a 96-bit counter).
pub const VALUE_LIMIT: u128 = 1 << 96;
/// Sectors the store alternates between.
pub const SECTORS: u32 = 2;

const TAG_COUNTER: u8 = 0xC7;
const TAG_SECTOR: u8 = 0x5E;
/// Bitwise CRC: the store runs at start-up and once per reserved block, so the 1 KiB table
/// would cost flash for nothing.
const CRC32: Crc<u32, NoTable> = Crc::<u32, NoTable>::new(&CRC_32_ISO_HDLC);

/// The shell's durable store of one number per SPI (sdls-plan.md: `load(spi) -> Option<u128>`,
/// `store(spi, value)` with `value < 2^96`).
pub trait CounterStore {
    /// The last value stored for `spi`; `None` when none ever was.
    fn load(&mut self, spi: u16) -> Option<u128>;
    /// Makes `value` the durable value of `spi`. Once this returns `Ok`, a reset finds it.
    fn store(&mut self, spi: u16, value: u128) -> Result<(), CounterError>;
}

/// Why the store refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum CounterError {
    /// The value does not fit the 96-bit counter.
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
    /// More distinct SPIs than the store was built for (its `S`), or more than a sector holds.
    #[error("more than {0} SPIs: the store cannot compact")]
    Full(usize),
    /// The flash driver failed.
    #[error("flash: {0:?}")]
    Flash(NorFlashErrorKind),
}

/// A record slot, aligned for the ESP32's flash driver (an unaligned buffer makes it copy
/// through a 4 KiB buffer on the stack).
#[repr(align(4))]
struct Slot([u8; RECORD_LEN]);

/// What a slot holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Record {
    Free,
    /// A torn or foreign record.
    Invalid,
    Counter(u16, u128),
    Header(u32),
}

fn encode(tag: u8, spi: u16, value: u128) -> Slot {
    let mut s = Slot([0; RECORD_LEN]);
    s.0[0] = tag;
    s.0[2..4].copy_from_slice(&spi.to_be_bytes());
    s.0[4..16].copy_from_slice(&value.to_be_bytes()[4..]);
    let crc = CRC32.checksum(&s.0[..16]);
    s.0[16..].copy_from_slice(&crc.to_be_bytes());
    s
}

fn decode(s: &Slot) -> Record {
    if s.0.iter().all(|&b| b == 0xFF) {
        return Record::Free;
    }
    let crc = u32::from_be_bytes([s.0[16], s.0[17], s.0[18], s.0[19]]);
    if CRC32.checksum(&s.0[..16]) != crc || s.0[1] != 0 {
        return Record::Invalid;
    }
    let spi = u16::from_be_bytes([s.0[2], s.0[3]]);
    let mut v = [0u8; 16];
    v[4..].copy_from_slice(&s.0[4..16]);
    let value = u128::from_be_bytes(v);
    match s.0[0] {
        TAG_COUNTER => Record::Counter(spi, value),
        TAG_SECTOR if spi == 0 && value >> 32 == 0 => Record::Header(value as u32),
        _ => Record::Invalid,
    }
}

/// Whether generation `a` is newer than `b` (serial-number order: generations wrap).
const fn newer(a: u32, b: u32) -> bool {
    let d = a.wrapping_sub(b);
    d != 0 && d < 1 << 31
}

/// The counter log on a NOR flash region (addresses from 0: a partition, see README.md) of at
/// least two erase units, for up to `S` distinct SPIs.
pub struct FlashCounters<F: NorFlash, const S: usize> {
    flash: F,
    /// The newest value of every SPI in the active sector (what a reset would find).
    values: Vec<(u16, u128), S>,
    /// The sector being appended to (0 or 1).
    active: u32,
    /// Its generation.
    generation: u32,
    /// The first free slot in it.
    next: u32,
}

impl<F: NorFlash, const S: usize> FlashCounters<F, S> {
    /// The sector size: one erase unit.
    const SECTOR: u32 = F::ERASE_SIZE as u32;
    /// Record slots per sector (slot 0 is the header).
    const SLOTS: u32 = Self::SECTOR / RECORD_LEN as u32;

    /// Opens the store on `flash`: finds the active sector (the valid header with the newest
    /// generation) and its first free slot. A region with no valid header is formatted
    /// (sector 0 erased, generation 1): a new device, or one whose first format was cut.
    pub fn open(mut flash: F) -> Result<Self, CounterError> {
        let geometry = CounterError::Geometry {
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
        for sector in 0..SECTORS {
            if let Record::Header(g) = read(&mut flash, sector * Self::SECTOR)? {
                if best.is_none_or(|(_, b)| newer(g, b)) {
                    best = Some((sector, g));
                }
            }
        }
        let mut store = FlashCounters {
            flash,
            values: Vec::new(),
            active: 0,
            generation: 1,
            next: 1,
        };
        match best {
            Some((sector, g)) => {
                store.active = sector;
                store.generation = g;
                store.scan()?;
            }
            None => {
                store.erase(0)?;
                store.write(0, &encode(TAG_SECTOR, 0, 1))?;
            }
        }
        Ok(store)
    }

    /// The flash back (for a simulated reset in tests, or another user).
    pub fn release(self) -> F {
        self.flash
    }

    /// Records still free in the active sector.
    pub const fn free_slots(&self) -> u32 {
        Self::SLOTS - self.next
    }

    /// The active sector's generation (one more per compaction).
    pub const fn generation(&self) -> u32 {
        self.generation
    }

    fn addr(&self, sector: u32, slot: u32) -> u32 {
        sector * Self::SECTOR + slot * RECORD_LEN as u32
    }

    fn erase(&mut self, sector: u32) -> Result<(), CounterError> {
        let from = sector * Self::SECTOR;
        self.flash
            .erase(from, from + Self::SECTOR)
            .map_err(|e| CounterError::Flash(e.kind()))
    }

    fn write(&mut self, addr: u32, slot: &Slot) -> Result<(), CounterError> {
        self.flash
            .write(addr, &slot.0)
            .map_err(|e| CounterError::Flash(e.kind()))
    }

    /// Reads the active sector: the newest value of each SPI, and the slot after the last one
    /// used (valid or torn).
    fn scan(&mut self) -> Result<(), CounterError> {
        self.next = 1;
        for slot in 1..Self::SLOTS {
            let at = self.addr(self.active, slot);
            match read(&mut self.flash, at)? {
                Record::Free => continue,
                Record::Counter(spi, v) => self.remember(spi, v)?,
                Record::Invalid | Record::Header(_) => {}
            }
            self.next = slot + 1;
        }
        Ok(())
    }

    fn remember(&mut self, spi: u16, value: u128) -> Result<(), CounterError> {
        match self.values.iter_mut().find(|(s, _)| *s == spi) {
            Some(e) => e.1 = value,
            None => self
                .values
                .push((spi, value))
                .map_err(|_| CounterError::Full(S))?,
        }
        Ok(())
    }

    /// Copies the newest record of every SPI into the other sector, then makes it the active
    /// one by writing its header last.
    fn compact(&mut self) -> Result<(), CounterError> {
        let n = self.values.len() as u32;
        if n + 1 >= Self::SLOTS {
            return Err(CounterError::Full(S));
        }
        let target = 1 - self.active;
        self.erase(target)?;
        for i in 0..self.values.len() {
            let (spi, v) = self.values[i];
            let at = self.addr(target, 1 + i as u32);
            self.write(at, &encode(TAG_COUNTER, spi, v))?;
        }
        let generation = self.generation.wrapping_add(1);
        let at = self.addr(target, 0);
        self.write(at, &encode(TAG_SECTOR, 0, u128::from(generation)))?;
        self.active = target;
        self.generation = generation;
        self.next = 1 + n;
        Ok(())
    }
}

fn read<F: NorFlash>(flash: &mut F, addr: u32) -> Result<Record, CounterError> {
    let mut s = Slot([0; RECORD_LEN]);
    flash
        .read(addr, &mut s.0)
        .map_err(|e| CounterError::Flash(e.kind()))?;
    Ok(decode(&s))
}

impl<F: NorFlash, const S: usize> CounterStore for FlashCounters<F, S> {
    /// From RAM: the values were read at [`FlashCounters::open`] and follow every store.
    fn load(&mut self, spi: u16) -> Option<u128> {
        self.values.iter().find(|(s, _)| *s == spi).map(|e| e.1)
    }

    fn store(&mut self, spi: u16, value: u128) -> Result<(), CounterError> {
        if value >= VALUE_LIMIT {
            return Err(CounterError::TooLarge(value));
        }
        if self.values.len() == S && self.load(spi).is_none() {
            return Err(CounterError::Full(S));
        }
        if self.next >= Self::SLOTS {
            self.compact()?;
        }
        let at = self.addr(self.active, self.next);
        // The slot is used from here on, whole or torn.
        self.next += 1;
        self.write(at, &encode(TAG_COUNTER, spi, value))?;
        self.remember(spi, value)
    }
}
