//! Properties of the CCSDS/PUS wire layer (`mmic::ccsds`), shared by the harnesses of
//! `tests/harnesses/ccsds.rs` and the fuzz targets `pus_tc_parser` and `pus_tm_parser`.
//!
//! The oracle, [`pus_oracle`], is written from the standards' bit positions and the documented
//! check order (truncated → version → packet type → secondary header flag → sequence flags →
//! length → PUS version → checksum → APID), on raw octets and with the bitwise CRC
//! [`crate::crc16_bitwise`], sharing no code with the library's parser.
//!
//! ```
//! use mmic::ccsds::primary::PacketType;
//! use mmic_proofs::ccsds::{check_pus_parse, pus_oracle, APIDS};
//!
//! let ping = [0x18, 0x42, 0xc0, 0x07, 0x00, 0x06, 0x2f, 0x11, 0x01, 0x00, 0x00, 0x12, 0xd0];
//! assert_eq!(pus_oracle(PacketType::Tc, &ping, APIDS), Ok(()));
//! assert!(check_pus_parse(PacketType::Tc, &ping)); // accepted, and re-emitted identically
//! assert!(!check_pus_parse(PacketType::Tm, &ping)); // refused as the oracle says
//! ```

use crate::{crc16_bitwise, Seed};
use mmic::ccsds::primary::{Apid, PacketType, SeqCount};
use mmic::ccsds::tc::{Tc, TcRepr};
use mmic::ccsds::tc_header::{AckFlags, TcSecondaryHeader};
use mmic::ccsds::tm::{Tm, TmRepr};
use mmic::ccsds::tm_header::{TimeRefStatus, TmSecondaryHeader};
use mmic::ccsds::{cuc::Cuc, PacketError};

/// The APIDs the parse properties accept: the reference APID, and the extremes 0 and 2047, so
/// that random octets reach the APID check both ways.
pub const APIDS: &[u16] = &[0x042, 0, 0x7ff];

/// Longest input the parse properties take (and packet they emit into their buffers); the
/// fuzz targets cut their input to it.
pub const MAX_PACKET: usize = 256;

/// Octets of the shortest packet of `kind` (headers and CRC).
pub const fn min_len(kind: PacketType) -> usize {
    match kind {
        PacketType::Tc => 6 + 5 + 2,
        PacketType::Tm => 6 + 13 + 2,
    }
}

/// The verdict the documented checks give `b` as a `kind` packet, worked out from the bit
/// positions of CCSDS 133.0-B-2 and ECSS-E-ST-70-41C.
pub fn pus_oracle(kind: PacketType, b: &[u8], accepted: &[u16]) -> Result<(), PacketError> {
    let n = b.len();
    if n < min_len(kind) {
        return Err(PacketError::Truncated {
            kind,
            expected: min_len(kind),
            found: n,
        });
    }
    let version = b[0] >> 5;
    if version != 0 {
        return Err(PacketError::Version {
            kind,
            expected: 0,
            found: version,
        });
    }
    let found = if b[0] & 0x10 != 0 {
        PacketType::Tc
    } else {
        PacketType::Tm
    };
    if found != kind {
        return Err(PacketError::PacketType {
            expected: kind,
            found,
        });
    }
    if b[0] & 0x08 == 0 {
        return Err(PacketError::SecondaryHeaderFlag {
            kind,
            expected: 1,
            found: 0,
        });
    }
    if b[2] >> 6 != 0b11 {
        return Err(PacketError::SequenceFlags {
            kind,
            expected: 0b11,
            found: b[2] >> 6,
        });
    }
    let declared = ((b[4] as usize) << 8 | b[5] as usize) + 7;
    if declared != n {
        return Err(PacketError::Length {
            kind,
            expected: declared,
            found: n,
        });
    }
    if b[6] >> 4 != 2 {
        return Err(PacketError::PusVersion {
            kind,
            expected: 2,
            found: b[6] >> 4,
        });
    }
    let carried = (b[n - 2] as u16) << 8 | b[n - 1] as u16;
    let computed = crc16_bitwise(&b[..n - 2]);
    if carried != computed {
        return Err(PacketError::Checksum {
            kind,
            carried,
            computed,
        });
    }
    let apid = ((b[0] & 0x07) as u16) << 8 | b[1] as u16;
    if !accepted.contains(&apid) {
        return Err(PacketError::Apid { kind, found: apid });
    }
    Ok(())
}

/// Writes the data length field for the packet's length and the CRC over the rest (bitwise),
/// leaving every other octet as it is: the packet then reaches the checks after `length`.
/// `packet` must be at least 7 octets long.
pub fn reseal(packet: &mut [u8]) {
    let n = packet.len();
    let dl = (n - 7) as u16;
    packet[4..6].copy_from_slice(&dl.to_be_bytes());
    let crc = crc16_bitwise(&packet[..n - 2]);
    packet[n - 2..].copy_from_slice(&crc.to_be_bytes());
}

/// Parses `bytes` as `kind` with `accepted` and asserts the oracle's verdict, exactly (check
/// and numbers). When accepted: the checked view agrees with the `Repr`, and emitting the
/// `Repr` gives `bytes` back (parse → emit identity). Returns whether it was accepted.
pub fn check_pus_parse_with(kind: PacketType, bytes: &[u8], accepted: &[u16]) -> bool {
    assert!(
        bytes.len() <= MAX_PACKET,
        "inputs are at most MAX_PACKET octets"
    );
    let expected = pus_oracle(kind, bytes, accepted);
    let mut out = [0u8; MAX_PACKET];
    let got = match kind {
        PacketType::Tc => Tc::new_checked(bytes, accepted).map(|tc| {
            let r = tc.repr();
            assert_eq!(TcRepr::parse(bytes, accepted), Ok(r));
            assert_eq!(r.len(), bytes.len());
            assert_eq!(tc.app_data(), &bytes[11..bytes.len() - 2]);
            r.emit(&mut out)
        }),
        PacketType::Tm => Tm::new_checked(bytes, accepted).map(|tm| {
            let r = tm.repr();
            assert_eq!(TmRepr::parse(bytes, accepted), Ok(r));
            assert_eq!(r.len(), bytes.len());
            assert_eq!(tm.source_data(), &bytes[19..bytes.len() - 2]);
            r.emit(&mut out)
        }),
    };
    match got {
        Ok(emitted) => {
            assert_eq!(expected, Ok(()), "accepted what the oracle refuses");
            let n = emitted.expect("an accepted packet fits the buffer it came in");
            assert_eq!(&out[..n], bytes, "parse -> emit is not the identity");
            true
        }
        Err(e) => {
            assert_eq!(Err(e), expected, "verdict differs from the oracle");
            false
        }
    }
}

/// [`check_pus_parse_with`] for the APIDs [`APIDS`].
pub fn check_pus_parse(kind: PacketType, bytes: &[u8]) -> bool {
    check_pus_parse_with(kind, bytes, APIDS)
}

/// A telecommand built from seed choices, with application data a prefix of `data`.
pub fn sample_tc<'a>(s: &mut Seed<'_>, data: &'a [u8]) -> TcRepr<'a> {
    TcRepr {
        apid: Apid::new(s.u16() & 0x7ff).expect("11 bits"),
        seq_count: SeqCount::new(s.u16() & 0x3fff).expect("14 bits"),
        header: TcSecondaryHeader {
            ack: AckFlags::from_bits(s.u8()),
            service: s.u8(),
            subservice: s.u8(),
            source_id: s.u16(),
        },
        app_data: &data[..s.u8() as usize % (data.len() + 1)],
    }
}

/// A telemetry packet built from seed choices, with source data a prefix of `data`.
pub fn sample_tm<'a>(s: &mut Seed<'_>, data: &'a [u8]) -> TmRepr<'a> {
    TmRepr {
        apid: Apid::new(s.u16() & 0x7ff).expect("11 bits"),
        seq_count: SeqCount::new(s.u16() & 0x3fff).expect("14 bits"),
        header: TmSecondaryHeader {
            time_ref_status: TimeRefStatus::new(s.u8() & 0xf).expect("4 bits"),
            service: s.u8(),
            subservice: s.u8(),
            counter: s.u16(),
            destination_id: s.u16(),
            time: Cuc {
                coarse: (s.u16() as u32) << 16 | s.u16() as u32,
                fine: s.u16(),
            },
        },
        source_data: &data[..s.u8() as usize % (data.len() + 1)],
    }
}

/// Emits a packet of `kind` built from `seed` and `data` into `out`: its length and APID.
pub fn emit_sample(kind: PacketType, seed: &[u8], data: &[u8], out: &mut [u8]) -> (usize, u16) {
    let s = &mut Seed::new(seed);
    let (n, apid) = match kind {
        PacketType::Tc => {
            let r = sample_tc(s, data);
            (r.emit(out), r.apid.get())
        }
        PacketType::Tm => {
            let r = sample_tm(s, data);
            (r.emit(out), r.apid.get())
        }
    };
    (n.expect("a sample fits MAX_PACKET"), apid)
}

/// Emit → parse: any packet built from `seed` (and a prefix of `data`) is emitted with the
/// length [`TcRepr::len`] says, parses back to itself when its APID is accepted, is refused
/// by the APID check when it is not, and passes [`check_pus_parse_with`].
pub fn check_pus_round_trip(kind: PacketType, seed: &[u8], data: &[u8]) {
    let mut out = [0u8; MAX_PACKET];
    let s = &mut Seed::new(seed);
    match kind {
        PacketType::Tc => {
            let r = sample_tc(s, data);
            let n = r.emit(&mut out).expect("fits");
            assert_eq!(n, r.len());
            assert_eq!(TcRepr::parse(&out[..n], &[r.apid.get()]), Ok(r));
            let other = r.apid.get() ^ 1;
            assert_eq!(
                TcRepr::parse(&out[..n], &[other]),
                Err(PacketError::Apid {
                    kind,
                    found: r.apid.get()
                })
            );
            assert!(check_pus_parse_with(kind, &out[..n], &[r.apid.get()]));
        }
        PacketType::Tm => {
            let r = sample_tm(s, data);
            let n = r.emit(&mut out).expect("fits");
            assert_eq!(n, r.len());
            assert_eq!(TmRepr::parse(&out[..n], &[r.apid.get()]), Ok(r));
            assert!(check_pus_parse_with(kind, &out[..n], &[r.apid.get()]));
        }
    }
}

/// A valid packet built from `seed`, then up to two octets overwritten (`[index, value]`, the
/// index taken modulo the length) and, if `reseal_it`, the length field and CRC rewritten:
/// near misses that reach every check. The verdict must be the oracle's, with the sample's
/// APID accepted.
pub fn check_pus_near_valid(
    kind: PacketType,
    seed: &[u8],
    data: &[u8],
    edits: &[[u8; 2]],
    reseal_it: bool,
) -> bool {
    let mut out = [0u8; MAX_PACKET];
    let (n, apid) = emit_sample(kind, seed, data, &mut out);
    let packet = &mut out[..n];
    for [at, value] in edits {
        packet[*at as usize % n] = *value;
    }
    if reseal_it {
        reseal(packet);
    }
    check_pus_parse_with(kind, packet, &[apid])
}
