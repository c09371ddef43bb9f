//! The durable log on a RAM NOR flash with the ESP32's geometry (4-octet read and write
//! units, 4 KiB erase sectors): values survive a reset, a record torn by a power cut is
//! ignored, compaction keeps the newest value of every key even when power is cut at any octet
//! of it, and the store never programs an octet twice without an erase. Opening only reads;
//! the provisioning tool's image opens as it is; entries of robots not served are set apart
//! and carried, never a panic or a refusal.

use crc::{Crc, CRC_32_ISO_HDLC};
use mmic::link::sdls::Key256;
use mmic::node::server::store::{self, log, End, Entry, Resume};
use mmic::units::BoardNumber;
use mmic_fw_support::counters::{EntryStore, FlashLog, LogError, LogState, RECORD_LEN};
use mmic_fw_support::server::{ENTRIES_PER_ROBOT, FOREIGN};

mod common;
use common::{Ram, SECTOR};

type Store = FlashLog<Ram, 64>;

/// The old counter store's calls, over entries with aux 0.
trait Counters {
    fn load(&mut self, key: u16) -> Option<u128>;
    fn store(&mut self, key: u16, value: u128) -> Result<(), LogError>;
}

impl<const S: usize, const X: usize> Counters for FlashLog<Ram, S, X> {
    fn load(&mut self, key: u16) -> Option<u128> {
        self.lookup(key).map(|(_, v)| v)
    }
    fn store(&mut self, key: u16, value: u128) -> Result<(), LogError> {
        self.write(&Entry { key, aux: 0, value })
    }
}

fn reopen(s: Store) -> Store {
    FlashLog::open(s.release().reset()).unwrap()
}

#[test]
fn opening_a_new_region_writes_nothing_and_the_first_write_formats_it() {
    // Not erased (a new chip's content), and erased: nothing found, nothing written.
    for (ram, state) in [
        (Ram::new(2), LogState::NoHeader),
        (Ram::erased(2), LogState::Blank),
    ] {
        let before = ram.mem.clone();
        let mut s = Store::open(ram).unwrap();
        assert_eq!(s.state(), state);
        assert_eq!(s.load(257), None);
        assert_eq!(s.generation(), 0);
        let ram = s.release();
        assert_eq!((ram.mem == before, ram.erases), (true, 0));
        let mut s = Store::open(ram).unwrap();
        s.store(257, 5).unwrap();
        assert_eq!(s.state(), LogState::Active { generation: 1 });
        assert_eq!(s.free_slots() as usize, SECTOR / RECORD_LEN - 2);
        let mut s = reopen(s);
        assert_eq!((s.load(257), s.generation()), (Some(5), 1));
    }
}

/// Random keys that pass the library's weak-key check.
fn key(seed: u64) -> Key256 {
    let mut x = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    let bytes: [u8; 32] = core::array::from_fn(|_| {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        x as u8
    });
    let k = Key256::from_bytes(bytes);
    assert!(k.check().is_ok());
    k
}

/// The `mmic_ctr` image `mmic sdls image` writes (the library's `log::image` of the provisioned
/// entries) opens as it is: the boot check finds its fingerprints and counters, and the log
/// goes on after them.
#[test]
fn the_provisioning_tools_image_opens_and_boots() {
    let one = BoardNumber::ONE;
    let (tc, tm) = (key(1), key(2));
    let entries = store::provision(End::Server, one, &tc, &tm, Resume::FRESH).unwrap();
    let mut image = vec![0u8; 2 * SECTOR];
    log::image(&entries, SECTOR, &mut image).unwrap();
    let mut s = Store::open(Ram::from_image(&image)).unwrap();
    assert_eq!(s.state(), LogState::Active { generation: 1 });
    assert_eq!(s.entries().len(), 4);
    let boot = store::boot(End::Server, one, &tc, &tm, |k| s.lookup(k)).unwrap();
    assert_eq!(boot.stored.tm, Some(0));
    assert_eq!(boot.stored.tc, Some(store::NOTHING_ACCEPTED));
    assert_eq!((boot.stored.progress, boot.kept), (None, None));
    s.store(0x0201, 256).unwrap();
    let mut s = reopen(s);
    assert_eq!(s.load(0x0201), Some(256));
    assert_eq!(s.entries().len(), 4);
}

/// A store holding other robots' entries and keys of no robot (another image's store, or one
/// written by hand): opened for robot 1 alone, they are set apart (never looked up), the
/// image's own keys always have room, and compactions carry what was set apart while room is
/// left: no panic, no `Full`.
#[test]
fn entries_of_robots_not_served_are_set_apart_and_never_fill_the_log() {
    type Server = FlashLog<Ram, { ENTRIES_PER_ROBOT }, { FOREIGN }>;
    let served = [BoardNumber::ONE];
    let mut entries = Vec::new();
    // Robots 2..=9 provisioned, and 100 keys of no robot at all.
    for n in 2..=9u8 {
        let b = BoardNumber::new(n).unwrap();
        entries.extend(
            store::provision(End::Server, b, &key(n.into()), &key(99), Resume::FRESH).unwrap(),
        );
    }
    for k in 0..100u16 {
        entries.push(Entry {
            key: 0x7000 + k,
            aux: 1,
            value: u128::from(k),
        });
    }
    let foreign_keys = entries.len();
    // Robot 1's own, provisioned last.
    let (tc, tm) = (key(1), key(2));
    entries.extend(store::provision(End::Server, served[0], &tc, &tm, Resume::FRESH).unwrap());
    let mut image = vec![0u8; 2 * SECTOR];
    log::image(&entries, SECTOR, &mut image).unwrap();
    let open = |ram: Ram| Server::open_with(ram, |k| store::foreign(&served, k)).unwrap();
    let mut s = open(Ram::from_image(&image));
    assert_eq!(s.entries().len(), 4);
    assert_eq!(s.foreign().len(), FOREIGN);
    assert_eq!(s.dropped() as usize, foreign_keys - FOREIGN);
    assert!(s.foreign().iter().all(|e| store::foreign(&served, e.key)));
    assert!(store::boot(End::Server, served[0], &tc, &tm, |k| s.lookup(k)).is_ok());
    // Robot 2's entries are not this image's to look up.
    assert_eq!(s.lookup(0x0202), None);
    // Every key robot 1 can have, written over several sectors' worth of records.
    let own: Vec<u16> = (0..0x5000u16)
        .filter(|&k| !store::foreign(&served, k))
        .collect();
    assert_eq!(own.len(), ENTRIES_PER_ROBOT);
    for i in 0..3 * SECTOR / RECORD_LEN {
        let k = own[i % own.len()];
        s.store(k, i as u128).unwrap();
    }
    assert!(s.generation() >= 3, "{}", s.generation());
    let mut s = open(s.release().reset());
    assert_eq!(s.entries().len(), ENTRIES_PER_ROBOT);
    // Carried over: what was set apart is still there.
    assert_eq!(s.foreign().len(), FOREIGN);
    assert_eq!(s.dropped(), 0);
    let last = 3 * SECTOR / RECORD_LEN - 1;
    assert_eq!(s.load(own[last % own.len()]), Some(last as u128));
    assert_eq!(s.release().overwrites, 0);
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
    assert_eq!(s.store(257, 1 << 96), Err(LogError::TooLarge(1 << 96)));
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
    assert_eq!(s.store(0x1000, 1), Err(LogError::Full(64)));
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
        LogError::Geometry {
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
