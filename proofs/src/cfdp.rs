//! Properties of the CFDP PDU layer (`mmic::cfdp`), shared by the harness of
//! `tests/harnesses/cfdp.rs` and the fuzz target `cfdp_pdu`.
//!
//! The oracle, [`cfdp_oracle`], is written from the bit positions of CCSDS 727.0-B-5 §5.1 and
//! the documented check order (truncated → version → large file → segment metadata → the
//! header's variable fields → length → a data field long enough for the CRC → CRC), on raw
//! octets and with the bitwise CRC [`crate::crc16_bitwise`], sharing no code with the library.
//!
//! ```
//! use mmic_proofs::cfdp::{cfdp_oracle, check_cfdp_parse};
//!
//! // YAMCS's EOF PDU (its PacketParseTest).
//! let eof = [0x00, 0x00, 0x0a, 0x13, 0x00, 0x18, 0x00, 0x00, 0x00, 0x01, 0x00, 0x15,
//!            0x04, 0x80, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x65, 0xfc];
//! assert_eq!(cfdp_oracle(&eof), Ok(()));
//! assert!(check_cfdp_parse(&eof)); // accepted, and re-emitted identically but for the version
//! assert!(!check_cfdp_parse(&eof[..21])); // refused as the oracle says
//! ```

use crate::crc16_bitwise;
use mmic::cfdp::directive::PduRepr;
use mmic::cfdp::header::PduType;
use mmic::cfdp::{emit, Pdu, PduError};

/// Longest input the property takes; the fuzz target cuts its input to it.
pub const MAX_PDU: usize = 600;

/// The verdict the documented checks give `b` as one whole PDU.
pub fn cfdp_oracle(b: &[u8]) -> Result<(), PduError> {
    let n = b.len();
    if n < 4 {
        return Err(PduError::Truncated {
            expected: 4,
            found: n,
        });
    }
    let version = b[0] >> 5;
    if version > 1 {
        return Err(PduError::Version { found: version });
    }
    if b[0] & 0x01 != 0 {
        return Err(PduError::LargeFile);
    }
    if b[3] & 0x08 != 0 {
        return Err(PduError::SegmentMetadata);
    }
    let entity = usize::from((b[3] >> 4) & 0x07) + 1;
    let seq = usize::from(b[3] & 0x07) + 1;
    let header = 4 + 2 * entity + seq;
    if n < header {
        return Err(PduError::Truncated {
            expected: header,
            found: n,
        });
    }
    let declared = usize::from(u16::from_be_bytes([b[1], b[2]]));
    if n - header != declared {
        return Err(PduError::Length {
            declared,
            found: n - header,
        });
    }
    if b[0] & 0x02 != 0 {
        if declared < 2 {
            return Err(PduError::Truncated {
                expected: header + 2,
                found: n,
            });
        }
        let expected = crc16_bitwise(&b[..n - 2]);
        let found = u16::from_be_bytes([b[n - 2], b[n - 1]]);
        if expected != found {
            return Err(PduError::Crc { expected, found });
        }
    }
    Ok(())
}

/// `Pdu::parse` of `b` gives exactly the oracle's verdict (check and numbers); an accepted PDU
/// re-emits from its header and data to the same octets, but for the version, always 001.
/// Returns whether it was accepted.
pub fn check_cfdp_parse(b: &[u8]) -> bool {
    let ours = Pdu::parse(b);
    assert_eq!(ours.map(|_| ()), cfdp_oracle(b), "{b:02x?}");
    let Ok(pdu) = ours else { return false };
    assert_eq!(pdu.as_bytes(), b);
    let mut out = [0u8; MAX_PDU + 8];
    let n = emit(pdu.header(), pdu.data(), &mut out).expect("an accepted PDU re-emits");
    assert_eq!(n, b.len());
    assert_eq!((out[0] >> 5, out[0] & 0x1f), (1, b[0] & 0x1f));
    if pdu.header().crc {
        // The version is under the CRC: compare the octets between.
        assert_eq!(&out[1..n - 2], &b[1..n - 2]);
    } else {
        assert_eq!(&out[1..n], &b[1..]);
    }
    true
}

/// The bits of a directive's data field that carry nothing [`PduRepr`] keeps, by the octet's
/// place: spare and reserved bits (727.0-B-5 §5.2), the ACK's subtype (written from the
/// acknowledged code), the Prompt's seven spare bits. Written from the standard's tables.
fn kept_bits(code: Option<u8>, at: usize) -> u8 {
    match (code, at) {
        (Some(0x04), 1) => 0xf0, // EOF: condition, spare
        (Some(0x05), 1) => 0xf7, // Finished: condition, spare, delivery, status
        (Some(0x06), 1) => 0xf0, // ACK: acknowledged code, subtype
        (Some(0x06), 2) => 0xf3, // ACK: condition, spare, status
        (Some(0x07), 1) => 0x4f, // Metadata: reserved, closure, reserved, checksum type
        (Some(0x09), 1) => 0x80, // Prompt: response required, spare
        _ => 0xff,
    }
}

/// `PduRepr::parse` of a PDU `Pdu::parse` accepts either refuses it by one of the directive
/// checks (or `truncated`), or gives fields that emit, from the PDU's own header, to the same
/// octets but for the version and the bits of `kept_bits` (which emit writes as 727.0-B-5
/// says: zero, the ACK's subtype from its code); and those octets read as the same fields.
/// Returns whether the fields were read.
pub fn check_cfdp_directive(b: &[u8]) -> bool {
    let Ok(pdu) = Pdu::parse(b) else { return false };
    let repr = match PduRepr::parse(&pdu) {
        Ok(r) => r,
        Err(e) => {
            let at = e.position();
            assert!(at == 0 || (6..PduError::PARSE).contains(&at), "{e:?}");
            return false;
        }
    };
    let mut out = [0u8; MAX_PDU + 8];
    let n = repr
        .emit(pdu.header(), &mut out)
        .expect("fields read re-emit");
    assert_eq!(n, b.len(), "{b:02x?}");
    let start = pdu.header().len();
    let end = if pdu.header().crc { n - 2 } else { n };
    let code = (pdu.header().pdu_type == PduType::Directive).then(|| b[start]);
    assert_eq!(out[0] & 0x1f, b[0] & 0x1f);
    assert_eq!(&out[1..start], &b[1..start]);
    for at in 0..end - start {
        let keep = kept_bits(code, at);
        assert_eq!(
            out[start + at] & keep,
            b[start + at] & keep,
            "octet {at}: {b:02x?}"
        );
        // What emit writes there: zero, but for the subtype of an ACK of Finished (0001).
        let ack_of_finished = code == Some(0x06) && at == 1 && out[start + 1] >> 4 == 0x05;
        assert_eq!(
            out[start + at] & !keep,
            u8::from(ack_of_finished),
            "octet {at}"
        );
    }
    let again = Pdu::parse(&out[..n]).expect("the emitted PDU is whole");
    assert_eq!(PduRepr::parse(&again), Ok(repr));
    true
}
