//! PUS-C services (ECSS-E-ST-70-41C) of the robot, over the CCSDS packets of `crate::ccsds`:
//! what each telecommand means and what each report carries.
//!
//! The services map onto the library's existing logic — no behaviour is implemented twice:
//! an ST[8] function is the [`crate::command::Command`] of Table 1 it names
//! ([`function`]), an ST[3] housekeeping report is the heartbeat's content
//! ([`housekeeping`]), an ST[5] event is a change between two heartbeats ([`event`]), and the
//! ST[1] verification reports carry the library's refusal and fault codes ([`verification`]).
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

pub mod event;
pub mod function;
pub mod housekeeping;
pub mod request;
pub mod verification;

use crate::units::BoardNumber;

/// The APID of robot 1 is `ROBOT_APID_BASE + 1`.
pub const ROBOT_APID_BASE: u16 = 0x100;

/// The APID of robot `n`'s packets, telecommands and telemetry: `0x100 + n`.
pub const fn robot_apid(n: BoardNumber) -> u16 {
    ROBOT_APID_BASE + n.get() as u16
}

/// The robot an APID belongs to; none for any other APID.
pub const fn robot_of_apid(apid: u16) -> Option<BoardNumber> {
    if apid > ROBOT_APID_BASE && apid <= ROBOT_APID_BASE + 255 {
        match BoardNumber::new((apid - ROBOT_APID_BASE) as u8) {
            Ok(n) => Some(n),
            Err(_) => None,
        }
    } else {
        None
    }
}
