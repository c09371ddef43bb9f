//! A telecommand's service, subservice and application data, as one request to the robot.
//!
//! The services and subservices the robot serves (spec/ccsds/services.toml):
//!
//! | TC | request | application data |
//! |---|---|---|
//! | (8,1) | perform a function: a Table 1 command | [`function`] |
//! | (17,1) | are-you-alive (replaces the heartbeat request) | none |
//! | (3,5) | enable periodic housekeeping reports | N = 1, structure ID 1 |
//! | (3,6) | disable them | N = 1, structure ID 1 |
//! | (3,31) | modify their collection interval | N = 1, structure ID 1, interval ms (u32) |
//!
//! Anything else is refused by name: an unknown service, an unknown subservice of a known
//! service, application data of the wrong length, an argument out of range.
//!
//! ```
//! use mmic::command::Command;
//! use mmic::pus::request::{Request, RequestError};
//! assert_eq!(Request::parse(8, 1, &[6]), Ok(Request::Function(Command::Stop)));
//! assert_eq!(Request::parse(17, 1, &[]), Ok(Request::AreYouAlive));
//! assert_eq!(Request::parse(3, 31, &[1, 1, 0, 0, 0x03, 0xE8]), Ok(Request::HkInterval { ms: 1000 }));
//! assert_eq!(Request::parse(9, 1, &[]), Err(RequestError::UnknownService { service: 9 }));
//! assert_eq!(Request::parse(17, 3, &[]), Err(RequestError::UnknownSubservice { service: 17, subservice: 3 }));
//! ```

use super::function::{self, FunctionError};
use super::housekeeping::{MAX_INTERVAL_MS, MIN_INTERVAL_MS, ROBOT_SID};
use crate::command::Command;

/// ST\[1\] request verification.
pub const ST_VERIFICATION: u8 = 1;
/// ST\[3\] housekeeping.
pub const ST_HOUSEKEEPING: u8 = 3;
/// ST\[5\] event reporting.
pub const ST_EVENT: u8 = 5;
/// ST\[8\] function management.
pub const ST_FUNCTION: u8 = 8;
/// ST\[17\] test.
pub const ST_TEST: u8 = 17;

/// What a telecommand asks.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Request {
    /// TC(8,1): run this command.
    Function(Command),
    /// TC(17,1): answer TM(17,2) once board A answers.
    AreYouAlive,
    /// TC(3,5): periodic housekeeping reports on.
    HkEnable,
    /// TC(3,6): periodic housekeeping reports off.
    HkDisable,
    /// TC(3,31): housekeeping reports every `ms` milliseconds.
    HkInterval {
        /// The new collection interval, ms.
        ms: u32,
    },
}

/// Why a telecommand is no request. Each names the check that failed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum RequestError {
    /// A service the robot does not serve.
    #[error("unknown service {service} (served: 3, 8, 17)")]
    UnknownService {
        /// The service type found.
        service: u8,
    },
    /// A subservice the service does not have here.
    #[error("unknown subservice ({service},{subservice})")]
    UnknownSubservice {
        /// The service type.
        service: u8,
        /// The subservice type found.
        subservice: u8,
    },
    /// Application data of the wrong length for the request.
    #[error("TC({service},{subservice}): application data of {found} bytes, expected {expected}")]
    Length {
        /// The service type.
        service: u8,
        /// The subservice type.
        subservice: u8,
        /// Bytes expected.
        expected: usize,
        /// Bytes found.
        found: usize,
    },
    /// A housekeeping argument out of range.
    #[error("TC(3,{subservice}): {argument} = {value} out of range {min}..={max}")]
    OutOfRange {
        /// The subservice type.
        subservice: u8,
        /// The argument's name.
        argument: &'static str,
        /// The value found.
        value: u32,
        /// Smallest valid value.
        min: u32,
        /// Largest valid value.
        max: u32,
    },
    /// TC(8,1)'s application data is no function.
    #[error("TC(8,1): {0}")]
    Function(#[from] FunctionError),
}

impl RequestError {
    /// Every check's name, as [`RequestError::name`] gives them.
    pub const NAMES: [&'static str; 6] = [
        "unknown-service",
        "unknown-subservice",
        "app-data-length",
        "argument-out-of-range",
        "unknown-function",
        "no-such-command",
    ];

    /// The check's name (spec/ccsds/bad-inputs.toml).
    pub const fn name(&self) -> &'static str {
        match self {
            RequestError::UnknownService { .. } => "unknown-service",
            RequestError::UnknownSubservice { .. } => "unknown-subservice",
            RequestError::Length { .. }
            | RequestError::Function(FunctionError::Length { .. })
            | RequestError::Function(FunctionError::Empty) => "app-data-length",
            RequestError::OutOfRange { .. }
            | RequestError::Function(FunctionError::OutOfRange { .. }) => "argument-out-of-range",
            RequestError::Function(FunctionError::UnknownFunction { .. }) => "unknown-function",
            RequestError::Function(_) => "no-such-command",
        }
    }

    /// The ST\[1\] failure code of this refusal (spec/ccsds/services.toml, failure codes).
    pub const fn code(&self) -> u16 {
        match self {
            RequestError::UnknownService { .. } => 0x0301,
            RequestError::UnknownSubservice { .. } => 0x0302,
            RequestError::Length { .. }
            | RequestError::Function(FunctionError::Length { .. })
            | RequestError::Function(FunctionError::Empty) => 0x0303,
            RequestError::OutOfRange { .. }
            | RequestError::Function(FunctionError::OutOfRange { .. }) => 0x0304,
            RequestError::Function(FunctionError::UnknownFunction { .. }) => 0x0305,
            RequestError::Function(_) => 0x0306,
        }
    }
}

/// Checks `data` against N = 1 and the robot's structure ID; returns what follows it.
fn one_structure(subservice: u8, data: &[u8], expected: usize) -> Result<&[u8], RequestError> {
    if data.len() != expected {
        return Err(RequestError::Length {
            service: ST_HOUSEKEEPING,
            subservice,
            expected,
            found: data.len(),
        });
    }
    let range = |argument, value: u8, v: u8| RequestError::OutOfRange {
        subservice,
        argument,
        value: value.into(),
        min: v.into(),
        max: v.into(),
    };
    match data {
        [n, ..] if *n != 1 => Err(range("N", *n, 1)),
        [_, sid, rest @ ..] if *sid == ROBOT_SID => Ok(rest),
        [_, sid, ..] => Err(range("structure_id", *sid, ROBOT_SID)),
        _ => Ok(&[]),
    }
}

impl Request {
    /// The request a telecommand's service, subservice and application data make.
    pub fn parse(service: u8, subservice: u8, data: &[u8]) -> Result<Request, RequestError> {
        let unknown = RequestError::UnknownSubservice {
            service,
            subservice,
        };
        match service {
            ST_FUNCTION => match subservice {
                1 => Ok(Request::Function(function::decode(data)?)),
                _ => Err(unknown),
            },
            ST_TEST => match subservice {
                1 if data.is_empty() => Ok(Request::AreYouAlive),
                1 => Err(RequestError::Length {
                    service,
                    subservice,
                    expected: 0,
                    found: data.len(),
                }),
                _ => Err(unknown),
            },
            ST_HOUSEKEEPING => match subservice {
                5 => one_structure(5, data, 2).map(|_| Request::HkEnable),
                6 => one_structure(6, data, 2).map(|_| Request::HkDisable),
                31 => {
                    let rest = one_structure(31, data, 6)?;
                    let ms = match rest {
                        [a, b, c, d] => u32::from_be_bytes([*a, *b, *c, *d]),
                        _ => 0,
                    };
                    if (MIN_INTERVAL_MS..=MAX_INTERVAL_MS).contains(&ms) {
                        Ok(Request::HkInterval { ms })
                    } else {
                        Err(RequestError::OutOfRange {
                            subservice: 31,
                            argument: "interval_ms",
                            value: ms,
                            min: MIN_INTERVAL_MS,
                            max: MAX_INTERVAL_MS,
                        })
                    }
                }
                _ => Err(unknown),
            },
            _ => Err(RequestError::UnknownService { service }),
        }
    }
}
