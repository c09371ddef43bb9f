//! Authentication masks: which header bits the MAC covers (355.0-B-2 §4.2.2.2).
//!
//! The mission's masks cover every header octet an attacker could change to redirect, replay
//! or reinterpret a frame: the whole primary header (version, bypass and control flags, spare,
//! spacecraft ID, virtual channel, length, frame sequence number; a TM frame's counts and data
//! field status with its first header pointer), a TC frame's segment header (MAP), and the SPI.
//! The IV is masked out of the AAD as YAMCS does: it is GCM's nonce, so a changed IV fails the
//! MAC anyway. YAMCS's defaults ([`YAMCS_TC_DEFAULT`], [`YAMCS_TM_DEFAULT`]) cover only the
//! VCID, the segment header and the SPI: a frame's sequence number, bypass flag and spacecraft
//! ID could be changed without failing the MAC (decision `sdls-auth-mask`), so YAMCS is
//! configured with ours (`authMask` in `ground/yamcs/links/`).
//!
//! ```
//! use mmic::link::sdls::mask;
//!
//! // TC: primary header (5), segment header (1), SPI (2), IV (12).
//! assert_eq!(mask::TC.as_bytes().len(), 20);
//! assert_eq!(mask::TC.as_bytes()[..8], [0xff; 8]);
//! assert_eq!(mask::TC.as_bytes()[8..], [0; 12]);
//! ```

use super::sa::AuthMask;

const fn mask(octets: &[u8]) -> AuthMask {
    AuthMask::truncated(octets)
}

/// The mission's TC mask: the primary header and the segment header whole, the SPI; not the IV.
pub const TC: AuthMask = mask(&[
    0xff, 0xff, 0xff, 0xff, 0xff, // primary header
    0xff, // segment header
    0xff, 0xff, // SPI
    0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, // IV
]);

/// The mission's TM mask: the primary header whole, the SPI; not the IV.
pub const TM: AuthMask = mask(&[
    0xff, 0xff, 0xff, 0xff, 0xff, 0xff, // primary header
    0xff, 0xff, // SPI
    0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, // IV
]);

/// YAMCS 5.12.8's default TC mask with a segment header (`StandardAuthMask.TC`): the VCID,
/// the segment header and the SPI only.
pub const YAMCS_TC_DEFAULT: AuthMask = mask(&[
    0,
    0,
    0b1111_1100,
    0,
    0,    // VCID
    0xff, // segment header
    0xff,
    0xff, // SPI
    0,
    0,
    0,
    0,
    0,
    0,
    0,
    0,
    0,
    0,
    0,
    0, // IV
]);

/// YAMCS 5.12.8's default TM mask without a secondary header (`StandardAuthMask.TM`): the VCID
/// and the SPI only.
pub const YAMCS_TM_DEFAULT: AuthMask = mask(&[
    0,
    0b0000_1110,
    0,
    0,
    0,
    0, // VCID
    0xff,
    0xff, // SPI
    0,
    0,
    0,
    0,
    0,
    0,
    0,
    0,
    0,
    0,
    0,
    0, // IV
]);
