//! The flash log's record: 20 octets that hold one [`Entry`] or a sector's header
//! (`firmware/support/src/counters.rs` keeps them in two alternating NOR flash sectors;
//! [`image`] builds a freshly provisioned log for `espflash write-bin`).
//!
//! | octets | entry | sector header (slot 0 of a sector) |
//! |---|---|---|
//! | 0 | tag `0xC7` | tag `0x5E` |
//! | 1 | aux | `0x00` |
//! | 2..4 | key, big-endian | `0x0000` |
//! | 4..16 | value (96 bits), big-endian | 8 × `0x00`, then the generation (u32, big-endian) |
//! | 16..20 | CRC-32/ISO-HDLC of octets 0..16, big-endian | the same |
//!
//! A record torn by a power cut fails its CRC ([`Record::Invalid`]); an all-`0xFF` slot is free.
//! 20 octets are a multiple of the ESP32's 4-octet write and read units.
//!
//! ```
//! use mmic::node::server::store::log::{decode, encode_entry, Record, RECORD_LEN};
//! use mmic::node::server::store::Entry;
//!
//! let e = Entry { key: 0x0101, aux: 0, value: 16 };
//! let r = encode_entry(&e).unwrap();
//! assert_eq!(r.len(), RECORD_LEN);
//! assert_eq!(decode(&r), Record::Entry(e));
//! let mut torn = r;
//! torn[9] ^= 1;
//! assert_eq!(decode(&torn), Record::Invalid);
//! assert_eq!(decode(&[0xFF; RECORD_LEN]), Record::Free);
//! ```

use super::{Entry, VALUE_LIMIT};
use crc::{Crc, NoTable, CRC_32_ISO_HDLC};

/// One record, octets.
pub const RECORD_LEN: usize = 20;

const TAG_ENTRY: u8 = 0xC7;
const TAG_SECTOR: u8 = 0x5E;
/// Bitwise CRC: the log is read at start-up and written once per durable step, so a table
/// would cost flash for nothing.
const CRC32: Crc<u32, NoTable> = Crc::<u32, NoTable>::new(&CRC_32_ISO_HDLC);

/// What a slot holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Record {
    /// Erased: all `0xFF`.
    Free,
    /// A torn or foreign record (CRC, tag or layout wrong).
    Invalid,
    /// An entry.
    Entry(Entry),
    /// A sector's header with its generation.
    Header(u32),
}

fn seal(mut r: [u8; RECORD_LEN]) -> [u8; RECORD_LEN] {
    let crc = CRC32.checksum(&r[..16]).to_be_bytes();
    r[16..].copy_from_slice(&crc);
    r
}

/// An entry's record; `None` when its value does not fit 96 bits.
pub fn encode_entry(e: &Entry) -> Option<[u8; RECORD_LEN]> {
    if e.value >= VALUE_LIMIT {
        return None;
    }
    let mut r = [0u8; RECORD_LEN];
    r[0] = TAG_ENTRY;
    r[1] = e.aux;
    r[2..4].copy_from_slice(&e.key.to_be_bytes());
    r[4..16].copy_from_slice(&e.value.to_be_bytes()[4..]);
    Some(seal(r))
}

/// A sector header's record.
pub fn encode_header(generation: u32) -> [u8; RECORD_LEN] {
    let mut r = [0u8; RECORD_LEN];
    r[0] = TAG_SECTOR;
    r[12..16].copy_from_slice(&generation.to_be_bytes());
    seal(r)
}

/// What a slot's 20 octets hold.
pub fn decode(r: &[u8; RECORD_LEN]) -> Record {
    if r.iter().all(|&b| b == 0xFF) {
        return Record::Free;
    }
    let crc = u32::from_be_bytes([r[16], r[17], r[18], r[19]]);
    if CRC32.checksum(&r[..16]) != crc {
        return Record::Invalid;
    }
    let key = u16::from_be_bytes([r[2], r[3]]);
    let mut v = [0u8; 16];
    v[4..].copy_from_slice(&r[4..16]);
    let value = u128::from_be_bytes(v);
    match r[0] {
        TAG_ENTRY => Record::Entry(Entry {
            key,
            aux: r[1],
            value,
        }),
        // A header's generation is a u32: a value beyond one is no header.
        TAG_SECTOR if r[1] == 0 && key == 0 => {
            u32::try_from(value).map_or(Record::Invalid, Record::Header)
        }
        _ => Record::Invalid,
    }
}

/// Why a log image could not be built.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
pub enum ImageError {
    /// The output is not two sectors of at least two records each.
    #[error(
        "a log image is 2 sectors of {sector} octets (at least {min} each): {found} octets given"
    )]
    Size {
        /// The sector size asked for.
        sector: usize,
        /// The least sector size.
        min: usize,
        /// The output's length.
        found: usize,
    },
    /// More entries than a sector holds after its header.
    #[error("{entries} entries do not fit a {sector}-octet sector ({fit} at most)")]
    TooMany {
        /// Entries given.
        entries: usize,
        /// The sector size.
        sector: usize,
        /// Entries that fit.
        fit: usize,
    },
    /// A value does not fit 96 bits.
    #[error("entry {key:#06x}'s value does not fit 96 bits")]
    Value {
        /// The entry's key.
        key: u16,
    },
}

/// A log of two `sector`-octet sectors holding `entries` (generation 1 in sector 0, sector 1
/// erased), written over the whole of `out` (its length: two sectors).
pub fn image(entries: &[Entry], sector: usize, out: &mut [u8]) -> Result<(), ImageError> {
    let min = 2 * RECORD_LEN;
    if sector < min || sector.checked_mul(2) != Some(out.len()) {
        return Err(ImageError::Size {
            sector,
            min,
            found: out.len(),
        });
    }
    // At least 2 records' room (checked above): the subtraction cannot saturate.
    let fit = (sector / RECORD_LEN).saturating_sub(1);
    if entries.len() > fit {
        return Err(ImageError::TooMany {
            entries: entries.len(),
            sector,
            fit,
        });
    }
    out.fill(0xFF);
    let mut slots = out.chunks_exact_mut(RECORD_LEN);
    if let Some(s) = slots.next() {
        s.copy_from_slice(&encode_header(1));
    }
    for (e, s) in entries.iter().zip(slots) {
        let r = encode_entry(e).ok_or(Error::Value { key: e.key })?;
        s.copy_from_slice(&r);
    }
    Ok(())
}

use ImageError as Error;

#[cfg(test)]
mod tests {
    use super::*;

    /// Golden records: a counter entry, an entry with aux, a header (CRCs from Python's
    /// `zlib.crc32`).
    #[test]
    fn golden_records() {
        let e = Entry {
            key: 0x0201,
            aux: 0,
            value: 0x100,
        };
        let r = encode_entry(&e).unwrap();
        assert_eq!(
            &r[..16],
            &[0xC7, 0, 2, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0]
        );
        assert_eq!(&r[16..], &0x4622_8447u32.to_be_bytes());
        assert_eq!(decode(&r), Record::Entry(e));
        let h = encode_header(7);
        assert_eq!(
            &h[..16],
            &[0x5E, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 7]
        );
        assert_eq!(&h[16..], &0x9a04_e039u32.to_be_bytes());
        assert_eq!(decode(&h), Record::Header(7));
        let big = Entry {
            key: 0x2001,
            aux: 9,
            value: VALUE_LIMIT - 1,
        };
        assert_eq!(decode(&encode_entry(&big).unwrap()), Record::Entry(big));
        assert_eq!(
            encode_entry(&Entry {
                value: VALUE_LIMIT,
                ..big
            }),
            None
        );
    }

    #[test]
    fn every_single_bit_flip_is_invalid() {
        let r = encode_entry(&Entry {
            key: 0x1101,
            aux: 3,
            value: 0xdead_beef,
        })
        .unwrap();
        for bit in 0..RECORD_LEN * 8 {
            let mut t = r;
            t[bit / 8] ^= 1 << (bit % 8);
            assert_eq!(decode(&t), Record::Invalid, "bit {bit}");
        }
    }

    #[test]
    fn an_image_holds_its_entries_and_a_header() {
        let entries = [
            Entry {
                key: 0x1101,
                aux: 0,
                value: 5,
            },
            Entry {
                key: 0x0101,
                aux: 0,
                value: VALUE_LIMIT - 1,
            },
        ];
        let mut out = [0u8; 2 * 4096];
        image(&entries, 4096, &mut out).unwrap();
        let slot = |i: usize| -> [u8; RECORD_LEN] {
            out[i * RECORD_LEN..][..RECORD_LEN].try_into().unwrap()
        };
        assert_eq!(decode(&slot(0)), Record::Header(1));
        assert_eq!(decode(&slot(1)), Record::Entry(entries[0]));
        assert_eq!(decode(&slot(2)), Record::Entry(entries[1]));
        assert_eq!(decode(&slot(3)), Record::Free);
        assert!(out[4096..].iter().all(|&b| b == 0xFF));
        assert!(matches!(
            image(&entries, 4096, &mut [0u8; 100]),
            Err(ImageError::Size { .. })
        ));
    }

    /// A sealed record (its CRC right) of an unknown tag, or a header with a key or an aux,
    /// is read as invalid: only the two known forms are records.
    #[test]
    fn a_sealed_record_of_an_unknown_form_is_invalid() {
        let mut r = [0u8; RECORD_LEN];
        r[15] = 1;
        for (tag, aux, key) in [
            (0x00, 0, 0),
            (0xC6, 0, 0),
            (TAG_SECTOR, 1, 0),
            (TAG_SECTOR, 0, 1),
        ] {
            r[0] = tag;
            r[1] = aux;
            r[3] = key;
            assert_eq!(
                decode(&seal(r)),
                Record::Invalid,
                "tag {tag:#04x} aux {aux} key {key}"
            );
        }
        r[0] = TAG_SECTOR;
        (r[1], r[3]) = (0, 0);
        assert_eq!(decode(&seal(r)), Record::Header(1));
    }

    /// An image refuses more entries than a sector holds after its header, with the numbers.
    #[test]
    fn an_image_refuses_more_entries_than_a_sector_holds() {
        let entries = [Entry {
            key: 0x1101,
            aux: 0,
            value: 5,
        }; 3];
        let mut out = [0u8; 2 * 3 * RECORD_LEN];
        assert_eq!(
            image(&entries, 3 * RECORD_LEN, &mut out),
            Err(ImageError::TooMany {
                entries: 3,
                sector: 60,
                fit: 2
            })
        );
        assert_eq!(image(&entries[..2], 3 * RECORD_LEN, &mut out), Ok(()));
    }
}
