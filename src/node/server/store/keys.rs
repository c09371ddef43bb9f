//! The keys partition (`mmic_keys`, firmware/server-ccsds/partitions.csv): the server board's SDLS
//! keys, flashed apart from the image (the image carries no key), read at start-up.
//!
//! | octets | what |
//! |---|---|
//! | 0..8 | magic `MMICKEYS` |
//! | 8 | version, 1 |
//! | 9 | n, the keys that follow (1..=[`MAX_KEYS`]) |
//! | 10..12 | `0x0000` |
//! | 12 + 36 i .. | key i: SPI (big-endian, 2), `0x0000`, the 32 key octets |
//! | 12 + 36 n .. +4 | CRC-32/ISO-HDLC of everything before, big-endian |
//!
//! The rest of the partition is erased (`0xFF`). Each refusal is named ([`KeysError`]), and a
//! key is checked ([`Key256::check`]) when read: an all-zero or published test key is refused
//! here as at provisioning.
//!
//! ```
//! use mmic::link::sdls::Key256;
//! use mmic::node::server::store::keys;
//!
//! let k = |s: u8| Key256::from_bytes(core::array::from_fn(|i| (i as u8).wrapping_mul(77) ^ s));
//! let mut part = [0xFF; 4096];
//! let n = keys::emit(&[(257, &k(1)), (513, &k(2))], &mut part).unwrap();
//! assert_eq!(n, 12 + 2 * 36 + 4);
//! let set = keys::parse(&part).unwrap();
//! assert_eq!(set.spis().collect::<Vec<_>>(), [257, 513]);
//! assert!(set.get(257).is_some());
//! assert_eq!(keys::parse(&[0xFF; 64]).unwrap_err(), keys::KeysError::Blank);
//! part[20] ^= 1; // a flipped key bit
//! assert!(matches!(keys::parse(&part), Err(keys::KeysError::Crc { .. })));
//! ```

use crate::link::sdls::key::{WeakKey, KEY_LEN};
use crate::link::sdls::Key256;
use crc::{Crc, NoTable, CRC_32_ISO_HDLC};
use heapless::Vec;

/// The magic at the partition's start.
pub const MAGIC: [u8; 8] = *b"MMICKEYS";
/// The layout's version.
pub const VERSION: u8 = 1;
/// Keys a partition holds at most: the TC and TM keys of 8 robots.
pub const MAX_KEYS: usize = 16;
/// The header's octets.
pub const HEADER_LEN: usize = 12;
/// One key's octets.
pub const ENTRY_LEN: usize = 4 + KEY_LEN;

const CRC32: Crc<u32, NoTable> = Crc::<u32, NoTable>::new(&CRC_32_ISO_HDLC);

/// Why a keys partition was refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum KeysError {
    /// Erased: nothing was ever written (the keys were not provisioned).
    #[error("the keys partition is erased: no keys were provisioned")]
    Blank,
    /// Not this layout.
    #[error("the keys partition does not start with MMICKEYS")]
    Magic,
    /// Another version.
    #[error("the keys partition has layout version {found}, this image reads {expected}")]
    Version {
        /// [`VERSION`].
        expected: u8,
        /// What it holds.
        found: u8,
    },
    /// No key, or more than [`MAX_KEYS`].
    #[error("the keys partition says {found} keys, 1..={max} expected")]
    Count {
        /// [`MAX_KEYS`].
        max: usize,
        /// What it says.
        found: usize,
    },
    /// Shorter than its keys and CRC.
    #[error("the keys partition needs {needed} octets, has {found}")]
    Truncated {
        /// Octets needed.
        needed: usize,
        /// Octets there.
        found: usize,
    },
    /// The CRC does not match: a torn or altered write.
    #[error("the keys partition's CRC is {found:#010x}, its contents give {expected:#010x}")]
    Crc {
        /// Computed.
        expected: u32,
        /// Stored.
        found: u32,
    },
    /// A reserved field is not zero.
    #[error("the keys partition's reserved octets at {at} are not zero")]
    Reserved {
        /// Their offset.
        at: usize,
    },
    /// An SPI twice.
    #[error("SPI {spi} appears twice in the keys partition")]
    Duplicate {
        /// The SPI.
        spi: u16,
    },
    /// A key nobody should use.
    #[error("SPI {spi}: {reason}")]
    Weak {
        /// The SPI.
        spi: u16,
        /// Why.
        reason: WeakKey,
    },
    /// The output is too small ([`emit`]).
    #[error("{needed} octets needed to write the keys, {found} given")]
    Room {
        /// Octets needed.
        needed: usize,
        /// Octets given.
        found: usize,
    },
}

impl KeysError {
    /// Every refusal's name.
    pub const NAMES: [&'static str; 9] = [
        "blank",
        "magic",
        "version",
        "count",
        "truncated",
        "crc",
        "reserved",
        "duplicate",
        "weak-key",
    ];

    /// The refusal's name ([`KeysError::Room`], a writer's error, is `room`).
    pub const fn name(&self) -> &'static str {
        match self {
            KeysError::Blank => Self::NAMES[0],
            KeysError::Magic => Self::NAMES[1],
            KeysError::Version { .. } => Self::NAMES[2],
            KeysError::Count { .. } => Self::NAMES[3],
            KeysError::Truncated { .. } => Self::NAMES[4],
            KeysError::Crc { .. } => Self::NAMES[5],
            KeysError::Reserved { .. } => Self::NAMES[6],
            KeysError::Duplicate { .. } => Self::NAMES[7],
            KeysError::Weak { .. } => Self::NAMES[8],
            KeysError::Room { .. } => "room",
        }
    }
}

/// The keys read from a partition, by SPI (zeroized when dropped).
#[derive(Debug, Default)]
pub struct KeySet {
    keys: Vec<(u16, Key256), MAX_KEYS>,
}

impl KeySet {
    /// The key of `spi`.
    pub fn get(&self, spi: u16) -> Option<&Key256> {
        self.keys.iter().find(|(s, _)| *s == spi).map(|(_, k)| k)
    }

    /// Every SPI, in the partition's order.
    pub fn spis(&self) -> impl Iterator<Item = u16> + '_ {
        self.keys.iter().map(|(s, _)| *s)
    }
}

/// Reads a keys partition (its first octets at least; the rest is ignored).
pub fn parse(part: &[u8]) -> Result<KeySet, KeysError> {
    let head: &[u8; HEADER_LEN] = part.first_chunk().ok_or(KeysError::Truncated {
        needed: HEADER_LEN,
        found: part.len(),
    })?;
    if head.iter().all(|&b| b == 0xFF) {
        return Err(KeysError::Blank);
    }
    if head[..8] != MAGIC {
        return Err(KeysError::Magic);
    }
    if head[8] != VERSION {
        return Err(KeysError::Version {
            expected: VERSION,
            found: head[8],
        });
    }
    let n = usize::from(head[9]);
    if n == 0 || n > MAX_KEYS {
        return Err(KeysError::Count {
            max: MAX_KEYS,
            found: n,
        });
    }
    if head[10..12] != [0, 0] {
        return Err(KeysError::Reserved { at: 10 });
    }
    let end = signed_len(n).saturating_add(4);
    let truncated = KeysError::Truncated {
        needed: end,
        found: part.len(),
    };
    let (signed, crc) = part
        .get(..end)
        .and_then(<[u8]>::split_last_chunk::<4>)
        .ok_or(truncated)?;
    let found = u32::from_be_bytes(*crc);
    let expected = CRC32.checksum(signed);
    if found != expected {
        return Err(KeysError::Crc { expected, found });
    }
    read_entries(signed, truncated)
}

/// The entries after the header of `signed` (the header and whole entries: `as_chunks` leaves
/// nothing over), each checked; `truncated` is the error of a key cut short.
fn read_entries(signed: &[u8], truncated: KeysError) -> Result<KeySet, KeysError> {
    let (entries, _) = signed
        .get(HEADER_LEN..)
        .unwrap_or_default()
        .as_chunks::<ENTRY_LEN>();
    let mut set = KeySet::default();
    for (i, e) in entries.iter().enumerate() {
        let spi = u16::from_be_bytes([e[0], e[1]]);
        if e[2..4] != [0, 0] {
            return Err(KeysError::Reserved {
                at: signed_len(i).saturating_add(2),
            });
        }
        if set.get(spi).is_some() {
            return Err(KeysError::Duplicate { spi });
        }
        let key = Key256::from_slice(&e[4..]).map_err(|_| truncated)?;
        key.check()
            .map_err(|reason| KeysError::Weak { spi, reason })?;
        // Unreachable past MAX_KEYS (n is checked above).
        let _ = set.keys.push((spi, key));
    }
    Ok(set)
}

/// The octets the CRC covers for `n` keys: the header and the entries.
const fn signed_len(n: usize) -> usize {
    // n is at most MAX_KEYS (the callers check it first): neither step saturates.
    HEADER_LEN.saturating_add(n.saturating_mul(ENTRY_LEN))
}

/// Writes `keys` in the partition's layout at the start of `out` (the caller erases the rest
/// and clears `out` once it is written out: it holds the keys). Weak keys and repeated SPIs
/// are refused. Returns the octets written.
pub fn emit(keys: &[(u16, &Key256)], out: &mut [u8]) -> Result<usize, KeysError> {
    let count = KeysError::Count {
        max: MAX_KEYS,
        found: keys.len(),
    };
    let n = u8::try_from(keys.len()).map_err(|_| count)?;
    if keys.is_empty() || keys.len() > MAX_KEYS {
        return Err(count);
    }
    let end = signed_len(keys.len()).saturating_add(4);
    let room = KeysError::Room {
        needed: end,
        found: out.len(),
    };
    if out.len() < end {
        return Err(room);
    }
    for (i, (spi, key)) in keys.iter().enumerate() {
        key.check()
            .map_err(|reason| KeysError::Weak { spi: *spi, reason })?;
        if keys.iter().take(i).any(|(s, _)| s == spi) {
            return Err(KeysError::Duplicate { spi: *spi });
        }
    }
    let (signed, crc) = out
        .get_mut(..end)
        .and_then(<[u8]>::split_last_chunk_mut::<4>)
        .ok_or(room)?;
    let (head, rest) = signed.split_first_chunk_mut::<HEADER_LEN>().ok_or(room)?;
    head[..8].copy_from_slice(&MAGIC);
    head[8] = VERSION;
    head[9] = n;
    head[10..12].fill(0);
    let (entries, _) = rest.as_chunks_mut::<ENTRY_LEN>();
    for ((spi, key), e) in keys.iter().zip(entries) {
        e[..2].copy_from_slice(&spi.to_be_bytes());
        e[2..4].fill(0);
        e[4..].copy_from_slice(key.octets());
    }
    *crc = CRC32.checksum(signed).to_be_bytes();
    Ok(end)
}
