//! The durable store (`mmic::node::server::store`, issue 38): a link starts only from a store
//! provisioned for its keys, the keys partition refuses every bad image by name, and a key's
//! fingerprint is a key check value that GCM never reveals.

use mmic::link::sdls::key::{test_keys, WeakKey, FINGERPRINT_BLOCK};
use mmic::link::sdls::{mission, Key256};
use mmic::node::server::store::keys::{self, KeysError, ENTRY_LEN, HEADER_LEN, MAX_KEYS};
use mmic::node::server::store::{
    self, boot, foreign, kept_entries, kept_load, provision, End, Entry, Progress, Resume, Stopped,
    NOTHING_ACCEPTED,
};
use mmic::units::BoardNumber;
use std::collections::BTreeMap;

fn key(s: u8) -> Key256 {
    Key256::from_bytes(core::array::from_fn(|i| (i as u8).wrapping_mul(37) ^ s))
}

type Flash = BTreeMap<u16, (u8, u128)>;

fn write(f: &mut Flash, entries: &[Entry]) {
    for e in entries {
        f.insert(e.key, (e.aux, e.value));
    }
}

#[test]
fn a_link_starts_only_from_a_store_provisioned_for_its_keys() {
    let one = BoardNumber::ONE;
    let (tc, tm) = (key(1), key(2));
    for end in [End::Server, End::Ground] {
        let mut f = Flash::new();
        let b =
            |f: &Flash, tc: &Key256, tm: &Key256| boot(end, one, tc, tm, |k| f.get(&k).copied());
        assert_eq!(
            b(&f, &tc, &tm).unwrap_err(),
            Stopped::Unprovisioned { spi: 257 }
        );
        write(
            &mut f,
            &provision(end, one, &tc, &tm, Resume::FRESH).unwrap(),
        );
        let ok = b(&f, &tc, &tm).unwrap();
        // The sender from IV 0, the receiver with nothing accepted.
        let (send, recv) = match end {
            End::Server => (ok.stored.tm, ok.stored.tc),
            End::Ground => (ok.stored.tc, ok.stored.tm),
        };
        assert_eq!((send, recv), (Some(0), Some(NOTHING_ACCEPTED)));
        assert_eq!(
            b(&f, &key(3), &tm).unwrap_err(),
            Stopped::OtherKey { spi: 257 }
        );
        assert_eq!(
            b(&f, &tc, &key(4)).unwrap_err(),
            Stopped::OtherKey { spi: 513 }
        );
        // A weak key never starts, whatever the store holds.
        let zero = Key256::from_bytes([0; 32]);
        assert!(matches!(
            b(&f, &zero, &tm),
            Err(Stopped::Weak { spi: 257, .. })
        ));
        // A fingerprint without its counter: a provisioning cut short.
        let mut cut = f.clone();
        cut.remove(&mission::tm_spi(one));
        assert_eq!(
            b(&cut, &tc, &tm).unwrap_err(),
            Stopped::NoCounter { spi: 513 }
        );
    }
}

#[test]
fn provisioning_refuses_weak_keys_and_resumes_above_what_was_used() {
    let one = BoardNumber::ONE;
    for (name, k) in test_keys() {
        let weak = Key256::from_bytes(k);
        assert!(
            matches!(weak.check(), Err(WeakKey::TestKey { name: n }) if n == name),
            "{name}"
        );
        assert!(provision(End::Server, one, &weak, &key(2), Resume::FRESH).is_err());
    }
    for octet in [0u8, 0xff, 0x5a, 7] {
        assert_eq!(
            Key256::from_bytes([octet; 32]).check(),
            Err(WeakKey::Repeated { octet })
        );
    }
    let r = Resume {
        tx_from: 1000,
        rx_after: Some(77),
    };
    let mut f = Flash::new();
    write(
        &mut f,
        &provision(End::Server, one, &key(1), &key(2), r).unwrap(),
    );
    let ok = boot(End::Server, one, &key(1), &key(2), |k| f.get(&k).copied()).unwrap();
    assert_eq!((ok.stored.tc, ok.stored.tm), (Some(77), Some(1000)));
}

#[test]
fn progress_and_kept_keys_round_trip_through_entries() {
    let b = BoardNumber::new(7).unwrap();
    for (p, secured) in [
        (
            Progress {
                vr: 200,
                tc_iv: Some(123_456),
            },
            true,
        ),
        (Progress { vr: 3, tc_iv: None }, false),
    ] {
        let e = p.entry(b, secured);
        let f: Flash = [(e.key, (e.aux, e.value))].into();
        assert_eq!(Progress::load(b, &|k| f.get(&k).copied()), Some(p));
    }
    let mut kept = mmic::node::server::gateway::Kept::new();
    kept.push((9, 1234)).unwrap();
    kept.push((0xffff, 0x3fff)).unwrap();
    let mut f = Flash::new();
    write(&mut f, &kept_entries(b, &kept));
    assert_eq!(kept_load(b, &|k| f.get(&k).copied()), Some(kept));
    assert_eq!(kept_load(BoardNumber::ONE, &|k| f.get(&k).copied()), None);
}

#[test]
fn entries_of_robots_not_served_are_foreign() {
    let served = [BoardNumber::ONE];
    let one = BoardNumber::ONE;
    let two = BoardNumber::new(2).unwrap();
    for e in provision(End::Server, one, &key(1), &key(2), Resume::FRESH).unwrap() {
        assert!(!foreign(&served, e.key), "{e:?}");
    }
    for e in provision(End::Server, two, &key(1), &key(2), Resume::FRESH).unwrap() {
        assert!(foreign(&served, e.key), "{e:?}");
    }
    assert!(!foreign(&served, store::progress_key(one)));
    assert!(foreign(&served, store::progress_key(two)));
    assert!(foreign(&served, store::kept_key(two, 3)));
    assert!(!foreign(&served, store::kept_key(one, 3)));
    assert!(
        foreign(&served, 0xB0A1),
        "board A's record is no server entry"
    );
}

/// The fingerprint is AES-256 of a block GCM never enciphers (its counter field 0, its IV
/// field not zero), so it is neither GHASH's key H (the zero block) nor any keystream block;
/// it differs between keys.
#[test]
fn the_fingerprint_is_a_check_value_gcm_never_reveals() {
    assert_ne!(&FINGERPRINT_BLOCK[..12], &[0u8; 12]);
    assert_eq!(&FINGERPRINT_BLOCK[12..], &[0u8; 4]);
    let fps: std::collections::BTreeSet<[u8; 8]> =
        (0..64u8).map(|s| key(s).fingerprint().to_bytes()).collect();
    assert_eq!(fps.len(), 64);
    // Independent: AES-256 from the aes crate directly, on the same block.
    use aes::cipher::{BlockEncrypt, KeyInit};
    let raw: [u8; 32] = core::array::from_fn(|i| (i as u8).wrapping_mul(37) ^ 5);
    let mut block = aes::Block::from(*b"mmic-kcv-v1\x01\0\0\0\0");
    aes::Aes256::new(&raw.into()).encrypt_block(&mut block);
    assert_eq!(key(5).fingerprint().to_bytes(), block[..8]);
    assert_eq!(format!("{:?}", key(5).fingerprint()), "Fingerprint(..)");
}

fn partition(n: usize) -> Vec<u8> {
    let ks: Vec<(u16, Key256)> = (0..n)
        .map(|i| (0x100 + i as u16, key(i as u8 + 10)))
        .collect();
    let refs: Vec<(u16, &Key256)> = ks.iter().map(|(s, k)| (*s, k)).collect();
    let mut part = vec![0xFF; 4096];
    keys::emit(&refs, &mut part).unwrap();
    part
}

/// Every refusal of the keys partition, by name; every single-bit error of a written one.
#[test]
fn the_keys_partition_refuses_every_bad_image_by_name() {
    let part = partition(2);
    let set = keys::parse(&part).unwrap();
    assert_eq!(set.spis().collect::<Vec<_>>(), [0x100, 0x101]);
    assert_eq!(keys::parse(&[0xFF; 4096]).unwrap_err(), KeysError::Blank);
    assert!(matches!(
        keys::parse(&[0; 4]),
        Err(KeysError::Truncated { .. })
    ));
    let body = HEADER_LEN + 2 * ENTRY_LEN + 4;
    for bit in 0..body * 8 {
        let mut p = part.clone();
        p[bit / 8] ^= 1 << (bit % 8);
        let e = keys::parse(&p).unwrap_err();
        assert!(
            matches!(
                e,
                KeysError::Magic
                    | KeysError::Version { .. }
                    | KeysError::Count { .. }
                    | KeysError::Reserved { .. }
                    | KeysError::Crc { .. }
                    | KeysError::Truncated { .. }
            ),
            "bit {bit}: {e:?}"
        );
    }
    let mut p = part.clone();
    p[8] = 2;
    assert_eq!(
        keys::parse(&p).unwrap_err(),
        KeysError::Version {
            expected: 1,
            found: 2
        }
    );
    // A repeated SPI and a weak key are refused when written and when read.
    let k = key(1);
    let mut out = vec![0xFF; 4096];
    assert_eq!(
        keys::emit(&[(257, &k), (257, &key(2))], &mut out).unwrap_err(),
        KeysError::Duplicate { spi: 257 }
    );
    let zero = Key256::from_bytes([0; 32]);
    assert!(matches!(
        keys::emit(&[(257, &zero)], &mut out),
        Err(KeysError::Weak { spi: 257, .. })
    ));
    assert!(matches!(
        keys::emit(&[], &mut out),
        Err(KeysError::Count { found: 0, .. })
    ));
    let too_many: Vec<(u16, Key256)> = (0..=MAX_KEYS).map(|i| (i as u16, key(i as u8))).collect();
    let refs: Vec<(u16, &Key256)> = too_many.iter().map(|(s, k)| (*s, k)).collect();
    assert!(matches!(
        keys::emit(&refs, &mut out),
        Err(KeysError::Count { .. })
    ));
    assert!(matches!(
        keys::emit(&[(257, &k)], &mut [0u8; 20]),
        Err(KeysError::Room { .. })
    ));
    // Golden layout: magic, version 1, count, the SPI, then the CRC over it all.
    let one = partition(1);
    assert_eq!(&one[..12], b"MMICKEYS\x01\x01\0\0");
    assert_eq!(&one[12..16], &[0x01, 0x00, 0, 0]);
    let crc = crc::Crc::<u32>::new(&crc::CRC_32_ISO_HDLC).checksum(&one[..48]);
    assert_eq!(&one[48..52], &crc.to_be_bytes());
    assert!(one[52..].iter().all(|&b| b == 0xFF));
}

/// Every command (the whole set, 40,595 values) in a queued telecommand round-trips through its
/// store entry, with every acknowledgement pattern and both are-you-alive flags on a sample;
/// a value with a reserved bit set or an unknown opcode does not decode.
#[test]
#[cfg_attr(miri, ignore = "every command: minutes under Miri (157 s on x86_64)")]
fn every_queued_telecommand_round_trips_through_its_entry() {
    use mmic::node::server::gateway::Job;
    use mmic::node::server::store::queue::{job_entry, job_of, queue_key};
    use mmic::pus::verification::RequestId;
    let b = BoardNumber::new(3).unwrap();
    let mut n = 0u32;
    mmic::arbitrary::for_each_command(|command| {
        let job = Job {
            request: RequestId {
                apid: 0x103,
                seq_count: (n % 0x4000) as u16,
            },
            source_id: n as u16,
            ack: (n % 16) as u8,
            command,
            alive: n.is_multiple_of(7),
        };
        let e = job_entry(b, (n % 16) as u8, Some(&job));
        assert_eq!((e.key, e.aux), (queue_key(b, (n % 16) as u8), 1));
        assert_eq!(job_of(b, e.value), Some(job), "{command:?}");
        n += 1;
    });
    assert_eq!(n, 40_595);
    let e = job_entry(b, 0, None);
    assert_eq!((e.aux, e.value), (0, 0));
    let good = job_entry(
        b,
        1,
        Some(&Job {
            request: RequestId {
                apid: 0x103,
                seq_count: 5,
            },
            source_id: 1,
            ack: 15,
            command: mmic::command::Command::Stop,
            alive: false,
        }),
    )
    .value;
    for bit in [127u32, 100, 96, 95, 94, 62, 61, 60] {
        assert_eq!(job_of(b, good | 1 << bit), None, "bit {bit}");
    }
    assert_eq!(
        job_of(b, good & !(0xFFu128 << 48) | 0xEE << 48),
        None,
        "opcode 0xEE"
    );
}

/// An entry whose reserved octets are not zero, or an SPI listed twice, is refused when read
/// even under a CRC that matches (a writer other than `keys::emit`); every refusal's name.
#[test]
fn a_sealed_partition_with_a_bad_entry_is_refused_when_read() {
    let part = partition(2);
    let signed = HEADER_LEN + 2 * ENTRY_LEN;
    let reseal = |p: &mut Vec<u8>| {
        let crc = crc::Crc::<u32>::new(&crc::CRC_32_ISO_HDLC).checksum(&p[..signed]);
        p[signed..signed + 4].copy_from_slice(&crc.to_be_bytes());
    };
    let mut same = part.clone();
    reseal(&mut same);
    assert_eq!(
        same, part,
        "the CRC is CRC-32/ISO-HDLC over header and entries"
    );
    // Entry 1's reserved octets (after its 2-octet SPI).
    let mut p = part.clone();
    p[HEADER_LEN + ENTRY_LEN + 3] = 1;
    reseal(&mut p);
    let e = keys::parse(&p).unwrap_err();
    assert_eq!(
        e,
        KeysError::Reserved {
            at: HEADER_LEN + ENTRY_LEN + 2
        }
    );
    assert_eq!(e.name(), "reserved");
    // Entry 1 with entry 0's SPI.
    let mut p = part.clone();
    p.copy_within(HEADER_LEN..HEADER_LEN + 2, HEADER_LEN + ENTRY_LEN);
    reseal(&mut p);
    let e = keys::parse(&p).unwrap_err();
    assert_eq!(e, KeysError::Duplicate { spi: 0x100 });
    assert_eq!(e.name(), "duplicate");
    assert_eq!(KeysError::Blank.name(), "blank");
    assert_eq!(
        KeysError::Weak {
            spi: 1,
            reason: WeakKey::Repeated { octet: 0 }
        }
        .name(),
        "weak-key"
    );
    assert_eq!(
        KeysError::Room {
            needed: 2,
            found: 1
        }
        .name(),
        "room"
    );
}
