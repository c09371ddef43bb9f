//! PUS-C services (ECSS-E-ST-70-41C) of the robot, over the CCSDS packets of [`crate::ccsds`]:
//! what each telecommand means and what each report carries.
//!
//! The services map onto the library's existing logic — no behaviour is implemented twice:
//! an ST\[8\] function is the [`crate::command::Command`] of Table 1 it names
//! ([`function`]), an ST\[3\] housekeeping report is the heartbeat's content
//! ([`housekeeping`]), an ST\[5\] event is a change between two heartbeats ([`event`]), and the
//! ST\[1\] verification reports carry the library's refusal and fault codes ([`verification`]).
//! [`request`] turns a telecommand's service, subservice and application data into one
//! request, refusing every bad input by name. spec/ccsds/ is the reviewable table of all of it.
//!
//! APIDs: one per robot, `0x100 + n` for robot (board number) `n`
//! (spec/decisions.toml, `pus-apid`).
//!
//! ```
//! use mmic::pus;
//! use mmic::units::BoardNumber;
//! let two = BoardNumber::new(2).unwrap();
//! assert_eq!(pus::robot_apid(two), 0x102);
//! assert_eq!(pus::robot_of_apid(0x102), Some(two));
//! assert_eq!(pus::robot_of_apid(0x100), None); // robot 0 does not exist
//! assert_eq!(pus::robot_of_apid(0x7FF), None); // the idle APID
//! ```
// req: D:pus-apid, D:pus-gateway

pub mod event;
pub mod function;
pub mod housekeeping;
pub mod request;
pub mod verification;

use crate::ccsds::tc::TcRepr;
use crate::ccsds::PacketError;
use crate::units::BoardNumber;
use request::{Request, RequestError};

/// Why a telecommand or telemetry packet is refused, from its first octet to its last
/// argument. The wire layer's checks are [`PusError::Packet`]; the services layer adds a
/// variant per check of its own (unknown service or subservice, application data of the wrong
/// length, an argument out of range) with its name in [`PusError::name`], and
/// `spec/ccsds/bad-inputs.toml` gains a row for each.
///
/// ```
/// use mmic::ccsds::tc::TcRepr;
/// use mmic::pus::PusError;
///
/// let e: PusError = TcRepr::parse(&[0u8; 4], &[0x10]).unwrap_err().into();
/// assert_eq!(e.name(), "truncated");
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum PusError {
    /// The space packet or its PUS secondary header.
    #[error(transparent)]
    Packet(#[from] PacketError),
    /// The service, subservice or application data (the services layer,
    /// [`request`]).
    #[error(transparent)]
    Request(#[from] RequestError),
}

impl PusError {
    /// The failed check's name.
    pub const fn name(&self) -> &'static str {
        match self {
            PusError::Packet(e) => e.name(),
            PusError::Request(e) => e.name(),
        }
    }
}

/// Reads a telecommand whole: the packet's CCSDS and PUS checks (for the `apids` given), then
/// its service, subservice and application data as one [`Request`]. Every refusal names its
/// check ([`PusError::name`]; spec/ccsds/bad-inputs.toml has a packet for each).
///
/// ```
/// use mmic::command::Command;
/// use mmic::pus::{read_tc, request::Request};
/// let stop = [0x19, 0x01, 0xC0, 0x01, 0x00, 0x07, 0x2F, 0x08, 0x01, 0x00, 0x00, 0x06, 0x00, 0x00];
/// let mut p = stop;
/// let crc = mmic::ccsds::pec(&p[..12]).to_be_bytes();
/// p[12..].copy_from_slice(&crc);
/// let (tc, request) = read_tc(&p, &[0x101]).unwrap();
/// assert_eq!((tc.seq_count.get(), request), (1, Request::Function(Command::Stop)));
/// p[11] = 13; // an unknown function, CRC rewritten
/// let crc = mmic::ccsds::pec(&p[..12]).to_be_bytes();
/// p[12..].copy_from_slice(&crc);
/// assert_eq!(read_tc(&p, &[0x101]).unwrap_err().name(), "unknown-function");
/// ```
pub fn read_tc<'a>(bytes: &'a [u8], apids: &[u16]) -> Result<(TcRepr<'a>, Request), PusError> {
    let tc = TcRepr::parse(bytes, apids)?;
    let h = tc.header;
    let request = Request::parse(h.service, h.subservice, tc.app_data)?;
    Ok((tc, request))
}

/// The APID of robot 1 is `ROBOT_APID_BASE + 1`.
pub const ROBOT_APID_BASE: u16 = 0x100;
// The board number is the APID's low octet (below).
const _: () = assert!(ROBOT_APID_BASE & 0xff == 0);

/// The APID of robot `n`'s packets, telecommands and telemetry: `0x100 + n`.
pub const fn robot_apid(n: BoardNumber) -> u16 {
    ROBOT_APID_BASE | u16::from_be_bytes([0, n.get()])
}

/// The robot an APID belongs to; none for any other APID.
pub const fn robot_of_apid(apid: u16) -> Option<BoardNumber> {
    if apid > ROBOT_APID_BASE && apid <= ROBOT_APID_BASE + 255 {
        // Within the base's block of 256: the number is the low octet.
        let [_, n] = apid.to_be_bytes();
        match BoardNumber::new(n) {
            Ok(n) => Some(n),
            Err(_) => None,
        }
    } else {
        None
    }
}
