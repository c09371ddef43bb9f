//! The SDLS counter store on a RAM NOR flash with the ESP32's geometry (4-octet read and write
//! units, 4 KiB erase sectors): values survive a reset, a record torn by a power cut is
//! ignored, compaction keeps the newest value of every SPI even when power is cut at any octet
//! of it, and the store never programs an octet twice without an erase.

use crc::{Crc, CRC_32_ISO_HDLC};
use mmic_fw_support::counters::{CounterError, CounterStore, FlashCounters, RECORD_LEN};

mod common;
use common::{Ram, SECTOR};

type Store = FlashCounters<Ram, 64>;

fn reopen(s: Store) -> Store {
    FlashCounters::open(s.release().reset()).unwrap()
}

#[test]
fn a_new_region_is_formatted_and_holds_nothing() {
    let mut s = Store::open(Ram::new(2)).unwrap();
    assert_eq!(s.load(257), None);
    assert_eq!(s.generation(), 1);
    assert_eq!(s.free_slots() as usize, SECTOR / RECORD_LEN - 1);
    let mut s = reopen(s);
    assert_eq!(s.load(257), None);
}

#[test]
fn values_are_restored_after_a_reset() {
    let mut s = Store::open(Ram::new(2)).unwrap();
    s.store(257, 16).unwrap();
    s.store(513, 256).unwrap();
    s.store(257, 32).unwrap();
    assert_eq!((s.load(257), s.load(513)), (Some(32), Some(256)));
    let mut s = reopen(s);
    assert_eq!(
        (s.load(257), s.load(513), s.load(258)),
        (Some(32), Some(256), None)
    );
    s.store(513, 512).unwrap();
    let mut s = reopen(s);
    assert_eq!((s.load(257), s.load(513)), (Some(32), Some(512)));
    assert_eq!(s.release().overwrites, 0);
}

#[test]
fn the_record_layout_is_the_documented_one() {
    let mut s = Store::open(Ram::new(2)).unwrap();
    let value = 0x0102_0304_0506_0708_090A_0B0Cu128;
    s.store(0x0101, value).unwrap();
    let ram = s.release();
    let crc = Crc::<u32>::new(&CRC_32_ISO_HDLC);
    let mut header = [0u8; 20];
    header[0] = 0x5E;
    header[15] = 1; // generation 1
    let c = crc.checksum(&header[..16]).to_be_bytes();
    header[16..].copy_from_slice(&c);
    assert_eq!(ram.mem[..20], header);
    let mut rec = [0u8; 20];
    rec[0] = 0xC7;
    rec[2..4].copy_from_slice(&[0x01, 0x01]);
    rec[4..16].copy_from_slice(&[1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12]);
    let c = crc.checksum(&rec[..16]).to_be_bytes();
    rec[16..].copy_from_slice(&c);
    assert_eq!(ram.mem[20..40], rec);
    assert!(ram.mem[40..SECTOR].iter().all(|&b| b == 0xFF));
}

#[test]
fn only_values_below_2_to_the_96_are_stored() {
    let mut s = Store::open(Ram::new(2)).unwrap();
    let max = (1u128 << 96) - 1;
    assert_eq!(s.store(257, 1 << 96), Err(CounterError::TooLarge(1 << 96)));
    s.store(257, max).unwrap();
    let mut s = reopen(s);
    assert_eq!(s.load(257), Some(max));
}

#[test]
fn a_record_torn_by_a_power_cut_is_ignored() {
    let mut s = Store::open(Ram::new(2)).unwrap();
    s.store(257, 100).unwrap();
    s.store(513, 7).unwrap();
    let base = s.release();
    // The power fails 0..19 octets into the next record (opening spends none: it only reads).
    for cut in 0..RECORD_LEN {
        let mut ram = base.clone();
        ram.budget = Some(cut);
        let mut t = Store::open(ram).unwrap();
        assert!(t.store(257, 200).is_err());
        let mut t = reopen(t);
        assert_eq!(
            (t.load(257), t.load(513)),
            (Some(100), Some(7)),
            "cut {cut}"
        );
        // The torn slot stays used; the next record goes after it and wins.
        t.store(257, 300).unwrap();
        let mut t = reopen(t);
        assert_eq!(
            (t.load(257), t.load(513)),
            (Some(300), Some(7)),
            "cut {cut}"
        );
        assert_eq!(t.release().overwrites, 0, "cut {cut}");
    }
}

#[test]
fn a_full_sector_is_compacted_into_the_other_and_nothing_is_lost() {
    let mut s = Store::open(Ram::new(2)).unwrap();
    let slots = (SECTOR / RECORD_LEN) as u128;
    // Three SPIs, 5 sectors' worth of records: four compactions at least.
    for i in 0..5 * slots {
        let spi = [257, 513, 258][(i % 3) as usize];
        s.store(spi, i).unwrap();
        if i % 97 == 0 {
            s = reopen(s);
        }
    }
    assert!(s.generation() >= 5, "generation {}", s.generation());
    let last = 5 * slots - 1;
    let want = |k: u128| Some((0..=last).rev().find(|i| i % 3 == k).unwrap());
    let mut s = reopen(s);
    assert_eq!(
        (s.load(257), s.load(513), s.load(258)),
        (want(0), want(1), want(2))
    );
    let ram = s.release();
    assert_eq!(ram.overwrites, 0);
    assert!(ram.erases >= 4);
}

#[test]
fn a_power_cut_anywhere_in_a_compaction_loses_no_value() {
    // A full active sector holding 10 SPIs.
    let mut s = Store::open(Ram::new(2)).unwrap();
    let mut i = 0u128;
    while s.free_slots() > 0 {
        s.store(300 + (i % 10) as u16, i).unwrap();
        i += 1;
    }
    let old: Vec<Option<u128>> = (300..310).map(|spi| s.load(spi)).collect();
    let base = s.release();
    // The compaction erases 4,096 octets, writes 10 records and the header, then the new one.
    let whole = SECTOR + 12 * RECORD_LEN;
    let mut outcomes = [0usize; 2];
    for cut in (0..=whole + 3).step_by(3) {
        let mut ram = base.clone();
        ram.budget = Some(cut);
        let mut t = Store::open(ram).unwrap();
        let stored = t.store(305, 1_000_000).is_ok();
        outcomes[usize::from(stored)] += 1;
        let mut t = reopen(t);
        for (k, spi) in (300..310).enumerate() {
            let want = if spi == 305 && stored {
                Some(1_000_000)
            } else {
                old[k]
            };
            let got = t.load(spi);
            // A cut after the record was whole but before the call returned may keep it.
            let ok = got == want || (spi == 305 && got == Some(1_000_000));
            assert!(ok, "cut {cut}: SPI {spi} reads {got:?}, want {want:?}");
        }
        // And the store goes on working.
        t.store(309, 7).unwrap();
        let mut t = reopen(t);
        assert_eq!(t.load(309), Some(7), "cut {cut}");
        assert_eq!(t.release().overwrites, 0, "cut {cut}");
    }
    assert!(outcomes[0] > 1000 && outcomes[1] >= 1, "{outcomes:?}");
}

#[test]
fn many_spis_are_kept_and_one_more_than_built_for_is_refused() {
    let mut s = Store::open(Ram::new(2)).unwrap();
    for round in 0..8u128 {
        for spi in 0..64u16 {
            s.store(0x100 + spi, round * 1000 + u128::from(spi))
                .unwrap();
        }
    }
    assert_eq!(s.store(0x1000, 1), Err(CounterError::Full(64)));
    let mut s = reopen(s);
    for spi in 0..64u16 {
        assert_eq!(s.load(0x100 + spi), Some(7000 + u128::from(spi)));
    }
    assert_eq!(s.load(0x1000), None);
    assert!(s.generation() >= 3);
}

#[test]
fn a_region_of_one_sector_is_refused() {
    let e = Store::open(Ram::new(1)).err().unwrap();
    assert!(matches!(
        e,
        CounterError::Geometry {
            capacity: 4096,
            erase: 4096,
            ..
        }
    ));
}

#[test]
fn the_newer_of_two_valid_sectors_wins_and_a_torn_header_does_not() {
    // Fill sector 0, compact into sector 1 (generation 2), then tear sector 1's header by
    // hand: the store must fall back to sector 0 (generation 1) and its values.
    let mut s = Store::open(Ram::new(2)).unwrap();
    let mut i = 0u128;
    while s.free_slots() > 0 {
        s.store(257, i).unwrap();
        i += 1;
    }
    s.store(257, 9999).unwrap();
    assert_eq!(s.generation(), 2);
    let mut ram = s.release();
    let mut t = Store::open(ram.clone()).unwrap();
    assert_eq!((t.generation(), t.load(257)), (2, Some(9999)));
    ram.mem[SECTOR + 5] ^= 0x01; // one bit of the new header
    let mut t = Store::open(ram).unwrap();
    assert_eq!((t.generation(), t.load(257)), (1, Some(i - 1)));
}
