//! CFDP PDUs (CCSDS 727.0-B-5): the fixed header and the PDU view against YAMCS's golden bytes,
//! round trips of every header field combination over the mission's and the extreme lengths,
//! each refusal by name with its numbers, and the modular checksum against a word-by-word sum.

use mmic::cfdp::checksum::{modular, Modular};
use mmic::cfdp::header::{Direction, Lengths, Mode, PduHeader, PduType};
use mmic::cfdp::{emit, pdu_crc, Pdu, PduError, MAX_PDU_LEN};
use proptest::prelude::*;

/// YAMCS 5.12.8's EOF PDU of PacketParseTest (yamcs-core's tests).
const YAMCS_EOF: &str = "00000A130018000000010015048000000000000065fc";

fn unhex(s: &str) -> Vec<u8> {
    crate::ccsds::unhex(&s.to_ascii_lowercase())
}

fn header(pdu_type: PduType, crc: bool) -> PduHeader {
    PduHeader {
        pdu_type,
        direction: Direction::TowardReceiver,
        mode: Mode::Acknowledged,
        crc,
        segmentation: false,
        lengths: Lengths::MISSION,
        data_len: 0,
        source: 0x18,
        seq: 1,
        dest: 0x15,
    }
}

// req: D:cfdp-version, D:cfdp-profile
// req: 727.0-B-5/CFDP-1, 727.0-B-5/CFDP-2, 727.0-B-5/CFDP-11
#[test]
fn yamcs_eof_reads_and_writes_back_but_for_the_version() {
    let bytes = unhex(YAMCS_EOF);
    let pdu = Pdu::parse(&bytes).unwrap();
    let h = *pdu.header();
    assert_eq!(
        h,
        PduHeader {
            data_len: 10,
            ..header(PduType::Directive, false)
        }
    );
    assert_eq!(pdu.data(), &bytes[12..]);
    assert_eq!(pdu.as_bytes(), &bytes[..]);
    let mut out = [0u8; 64];
    let n = emit(&h, pdu.data(), &mut out).unwrap();
    assert_eq!(n, bytes.len());
    // Version 001 (727.0-B-5) where YAMCS writes 000; every other octet the same.
    assert_eq!(out[0], 0x20);
    assert_eq!(&out[1..n], &bytes[1..]);
    assert_eq!(Pdu::parse(&out[..n]).unwrap().header(), &h);
}

// req: D:cfdp-profile
// req: 727.0-B-5/CFDP-20, 727.0-B-5/CFDP-21
#[test]
fn the_crc_ends_the_data_field_and_is_checked() {
    let h = header(PduType::FileData, true);
    let data = [0, 0, 0, 4, b'p', b'l', b'a', b'n'];
    let mut out = [0u8; 64];
    let n = emit(&h, &data, &mut out).unwrap();
    assert_eq!(n, 12 + data.len() + 2);
    assert_eq!(
        u16::from_be_bytes([out[1], out[2]]),
        10,
        "the CRC counts in the length"
    );
    assert_eq!(
        u16::from_be_bytes([out[n - 2], out[n - 1]]),
        pdu_crc(&out[..n - 2])
    );
    let pdu = Pdu::parse(&out[..n]).unwrap();
    assert_eq!((pdu.data(), pdu.header().crc), (&data[..], true));
    // Every single-bit error of the PDU is refused (the CRC, or a header check before it) but
    // the one that clears the CRC flag: a PDU without CRC whose data ends in two octets that
    // were the CRC.
    for bit in 0..n * 8 {
        let mut bad = out[..n].to_vec();
        bad[bit / 8] ^= 0x80 >> (bit % 8);
        let crc_bit = bit == 6;
        match Pdu::parse(&bad) {
            Err(_) => {}
            Ok(p) => assert!(crc_bit && !p.header().crc, "bit {bit} went unseen"),
        }
    }
}

/// Each check refuses its bad input by name, with the numbers that explain it.
#[test]
fn refusals_name_the_check_with_their_numbers() {
    let good = unhex(YAMCS_EOF);
    let cases: Vec<(Vec<u8>, PduError)> = vec![
        (
            good[..3].to_vec(),
            PduError::Truncated {
                expected: 4,
                found: 3,
            },
        ),
        (
            [&[0x40][..], &good[1..]].concat(),
            PduError::Version { found: 2 },
        ),
        ([&[0x01][..], &good[1..]].concat(), PduError::LargeFile),
        (
            [&good[..3], &[0x1b][..], &good[4..]].concat(),
            PduError::SegmentMetadata,
        ),
        (
            good[..11].to_vec(),
            PduError::Truncated {
                expected: 12,
                found: 11,
            },
        ),
        (
            good[..21].to_vec(),
            PduError::Length {
                declared: 10,
                found: 9,
            },
        ),
        (
            [&good[..], &[0][..]].concat(),
            PduError::Length {
                declared: 10,
                found: 11,
            },
        ),
        (
            [&[0x02][..], &good[1..]].concat(),
            PduError::Crc {
                expected: pdu_crc(&[&[0x02][..], &good[1..20]].concat()),
                found: 0x65fc,
            },
        ),
    ];
    for (bytes, want) in cases {
        assert_eq!(Pdu::parse(&bytes), Err(want), "{}", want.name());
        assert_eq!(PduError::NAMES[want.position()], want.name());
        assert!(!want.to_string().is_empty());
    }
    // A stream: the first PDU and the rest.
    let two = [&good[..], &good[..]].concat();
    let (first, rest) = Pdu::parse_prefix(&two).unwrap();
    assert_eq!((first.as_bytes(), rest), (&good[..], &good[..]));
}

#[test]
fn emit_refuses_what_the_header_cannot_carry() {
    let h = header(PduType::Directive, false);
    let mut out = [0u8; 16];
    assert_eq!(
        emit(&h, &[0; 8], &mut out),
        Err(PduError::Buffer {
            needed: 20,
            found: 16
        })
    );
    let bad = PduHeader {
        lengths: Lengths { entity: 0, seq: 4 },
        ..h
    };
    assert_eq!(
        emit(&bad, &[], &mut out),
        Err(PduError::Lengths { entity: 0, seq: 4 })
    );
    let big = PduHeader {
        source: 0x1_0000,
        ..h
    };
    assert_eq!(
        emit(&big, &[], &mut out),
        Err(PduError::TooLarge {
            value: 0x1_0000,
            octets: 2
        })
    );
    for e in [
        PduError::Buffer {
            needed: 20,
            found: 16,
        },
        PduError::Lengths { entity: 0, seq: 4 },
        PduError::TooLarge {
            value: 0x1_0000,
            octets: 2,
        },
    ] {
        assert_eq!(PduError::NAMES[e.position()], e.name());
        assert!(
            e.position() >= PduError::PARSE,
            "{e}: emit's checks come last"
        );
    }
    assert!(!h.is_empty() && h.len() == 12);
    let mut huge = vec![0u8; 70_000];
    assert_eq!(
        emit(&h, &vec![0; 65_536], &mut huge),
        Err(PduError::TooLarge {
            value: 65_536,
            octets: 2
        })
    );
    assert!(MAX_PDU_LEN <= usize::from(u16::MAX));
}

/// Every combination of the header's flags, with every pair of lengths 1..=8 and the largest
/// values they hold: emitted, read back the same. Under Miri (63 s for the whole walk, CI
/// 2026-11-28) the lengths 1, 2, 4 and 8 only: every flag still, and the copies of 1 to 8 octets.
// req: 727.0-B-5/CFDP-3, 727.0-B-5/CFDP-5, 727.0-B-5/CFDP-6
#[test]
fn every_header_round_trips() {
    let lengths: &[u8] = if cfg!(miri) {
        &[1, 2, 4, 8]
    } else {
        &[1, 2, 3, 4, 5, 6, 7, 8]
    };
    let mut n = 0u32;
    for bits in 0u8..32 {
        for &entity in lengths {
            for &seq in lengths {
                let max = |octets: u8| u64::MAX >> (64 - 8 * u32::from(octets));
                let h = PduHeader {
                    pdu_type: if bits & 1 == 0 {
                        PduType::Directive
                    } else {
                        PduType::FileData
                    },
                    direction: if bits & 2 == 0 {
                        Direction::TowardReceiver
                    } else {
                        Direction::TowardSender
                    },
                    mode: if bits & 4 == 0 {
                        Mode::Acknowledged
                    } else {
                        Mode::Unacknowledged
                    },
                    crc: bits & 8 != 0,
                    segmentation: bits & 16 != 0,
                    lengths: Lengths { entity, seq },
                    data_len: 0,
                    source: max(entity),
                    seq: max(seq) - 1,
                    dest: 1,
                };
                let mut out = [0u8; 64];
                let len = emit(&h, &[7, 7, 7], &mut out).unwrap();
                let pdu = Pdu::parse(&out[..len]).unwrap();
                let data_len = 3 + if h.crc { 2 } else { 0 };
                assert_eq!(*pdu.header(), PduHeader { data_len, ..h });
                assert_eq!(pdu.data(), &[7, 7, 7]);
                n += 1;
            }
        }
    }
    assert_eq!(n as usize, 32 * lengths.len() * lengths.len());
}

/// The modular checksum: the sum of the file's big-endian words, the last padded with zeros.
fn words(file: &[u8]) -> u32 {
    file.chunks(4).fold(0u32, |s, w| {
        let mut word = [0u8; 4];
        word[..w.len()].copy_from_slice(w);
        s.wrapping_add(u32::from_be_bytes(word))
    })
}

// req: 727.0-B-5/CFDP-22
#[test]
fn the_modular_checksum_of_every_length_up_to_64() {
    let file: Vec<u8> = (0..64u32).map(|i| (i * 37 + 11) as u8).collect();
    for len in 0..=file.len() {
        assert_eq!(modular(&file[..len]), words(&file[..len]), "length {len}");
    }
    assert_eq!(modular(&(0u8..=0x0e).collect::<Vec<_>>()), 0x181c_2015);
}

proptest! {
    /// The checksum of a file taken in pieces, at any offsets, in any order, is the whole
    /// file's.
    #[test]
    fn the_checksum_of_pieces_is_the_files(
        file in proptest::collection::vec(any::<u8>(), 0..600),
        cuts in proptest::collection::vec(any::<prop::sample::Index>(), 0..8),
        order in any::<u64>(),
    ) {
        let mut at: Vec<usize> = cuts.iter().map(|c| c.index(file.len() + 1)).collect();
        at.extend([0, file.len()]);
        at.sort_unstable();
        let mut pieces: Vec<(usize, usize)> = at.windows(2).map(|w| (w[0], w[1])).collect();
        let turn = usize::try_from(order % 8).unwrap().min(pieces.len());
        pieces.rotate_left(turn);
        let mut m = Modular::new();
        for (a, b) in pieces {
            m.add(a as u64, &file[a..b]);
        }
        prop_assert_eq!(m.value(), words(&file));
    }

    /// No input makes the PDU reader panic; what it takes, it takes whole and exactly.
    #[test]
    fn any_bytes_are_a_pdu_or_refused(bytes in proptest::collection::vec(any::<u8>(), 0..80)) {
        if let Ok(p) = Pdu::parse(&bytes) {
            prop_assert_eq!(p.as_bytes(), &bytes[..]);
            prop_assert_eq!(p.header().len() + usize::from(p.header().data_len), bytes.len());
        }
    }
}

/// spec/ccsds/cfdp.toml is what the library does.
// req: D:cfdp-version, D:cfdp-profile
#[test]
#[cfg_attr(
    miri,
    ignore = "parses spec/ TOML (decisions.toml among it): slow under Miri, and no dependency's unsafe code the other spec tests do not reach"
)]
fn the_profile_in_spec_is_the_librarys() {
    let t: toml::Table = toml::from_str(&crate::ccsds::repo("spec/ccsds/cfdp.toml")).unwrap();
    crate::ccsds::assert_sections_name_decisions("spec/ccsds/cfdp.toml", &t);
    let int = |s: &str, k: &str| t[s][k].as_integer().unwrap();
    assert_eq!(
        int("version", "emitted"),
        i64::from(mmic::cfdp::header::VERSION)
    );
    let read: Vec<i64> = t["version"]["read"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_integer().unwrap())
        .collect();
    let ours: Vec<i64> = mmic::cfdp::header::VERSIONS_READ
        .iter()
        .map(|&v| i64::from(v))
        .collect();
    assert_eq!(read, ours);
    assert_eq!(
        int("lengths", "entity_id"),
        i64::from(Lengths::MISSION.entity)
    );
    assert_eq!(
        int("lengths", "sequence_number"),
        i64::from(Lengths::MISSION.seq)
    );
    assert_eq!(int("pdu", "max_len"), MAX_PDU_LEN as i64);
    assert_eq!(t["pdu"]["large_file"].as_bool(), Some(false));
    assert_eq!(t["pdu"]["segment_metadata"].as_bool(), Some(false));
    assert_eq!(int("checksum", "type"), 0);
    assert_eq!(
        int("checksum", "check"),
        i64::from(modular(&(0u8..=0x0e).collect::<Vec<_>>()))
    );
}
