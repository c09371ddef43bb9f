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
