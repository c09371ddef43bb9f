//! ST\[1\] request verification: the reports that tell the ground what became of a telecommand,
//! and the failure codes they carry — the library's own refusal and fault codes.
//!
//! Source data: the request ID (the TC's packet ID and sequence control, 4 bytes), then for a
//! failure report the failure code (u16) and one data word (u32) with the numbers that
//! explain it. Failure codes (spec/ccsds/services.toml):
//!
//! | code | meaning | data |
//! |---|---|---|
//! | 1..=255 | board A refused the command: the refusal code of spec/modes.toml | 0 |
//! | 0x0100 + n | fault bit n was raised while the command ran | the latched fault map |
//! | 0x0200 | board A never acknowledged it: it ran once or not at all, never twice | attempts |
//! | 0x0201 | abandoned before completion: the mode changed, or a Stop's pause was dropped | mode |
//! | 0x03xx | the gateway refused the TC (`RequestError::code`, queue full, key reused) | detail |
//!
//! ```
//! use mmic::pus::verification::{Failure, Report, Stage, RequestId};
//! let req = RequestId { apid: 0x101, seq_count: 42 };
//! let r = Report { stage: Stage::Completion, request: req, failure: Some(Failure::refusal(6)) };
//! let mut buf = [0u8; 10];
//! let n = r.emit(&mut buf);
//! assert_eq!(&buf[..n], &[0x19, 0x01, 0xC0, 42, 0, 6, 0, 0, 0, 0]);
//! assert_eq!(r.subservice(), 8);
//! assert_eq!(Report::parse(8, &buf[..n]), Ok(r));
//! ```

use crate::faults::{Fault, Faults};
use crate::refusal::Refusal;

/// The fields of the telecommand a report is about (PUS-C 5.4.11: packet version, type,
/// secondary header flag, APID, sequence flags and count; version 0, type TC, flag set and
/// sequence flags "unsegmented" for every TC we accept).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RequestId {
    /// The TC's APID.
    pub apid: u16,
    /// The TC's packet sequence count (14 bits).
    pub seq_count: u16,
}

impl RequestId {
    /// The four bytes: packet ID, then sequence control.
    pub const fn to_bytes(self) -> [u8; 4] {
        let id = 0x1800 | (self.apid & 0x07FF);
        let sc = 0xC000 | (self.seq_count & 0x3FFF);
        let [a, b] = id.to_be_bytes();
        let [c, d] = sc.to_be_bytes();
        [a, b, c, d]
    }
}

/// Which report.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Stage {
    /// TM(1,1) / (1,2): the TC was taken (or not).
    Acceptance,
    /// TM(1,3) / (1,4): board A started executing it (or refused it).
    Start,
    /// TM(1,7) / (1,8): its execution completed (or failed).
    Completion,
}

/// A failure notice: code and data (the table above).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Failure {
    /// Failure code.
    pub code: u16,
    /// What explains it.
    pub data: u32,
}

/// Code of an unacknowledged command.
pub const UNACKNOWLEDGED: u16 = 0x0200;
/// Code of a command abandoned before completion.
pub const ABANDONED: u16 = 0x0201;
/// Code of a copy of a telecommand the gateway took before it restarted: it ran at most once,
/// and what became of it is not known any more (decision `restart-server`).
pub const RESTARTED: u16 = 0x0202;
/// The gateway's robot queue is full.
pub const QUEUE_FULL: u16 = 0x0307;
/// A request ID already used by a different telecommand.
pub const KEY_REUSED: u16 = 0x0308;

impl Failure {
    /// Board A refused with refusal code `r`.
    pub const fn refusal(r: u8) -> Failure {
        Failure {
            code: u16::from_be_bytes([0, r]),
            data: 0,
        }
    }

    /// Board A refused.
    pub const fn refused(r: Refusal) -> Failure {
        Failure::refusal(r.to_wire())
    }

    /// Fault `f` was raised while the command ran; `latched` is the fault map.
    pub const fn fault(f: Fault, latched: Faults) -> Failure {
        Failure {
            // 0x0100 + the bit, which is below 256: the code's low octet.
            code: u16::from_be_bytes([0x01, f.bit()]),
            data: latched.bits(),
        }
    }
}

/// One ST\[1\] report.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Report {
    /// Which.
    pub stage: Stage,
    /// About which TC.
    pub request: RequestId,
    /// Success (none) or the failure notice.
    pub failure: Option<Failure>,
}

/// Source data of a success report, bytes.
pub const SUCCESS_LEN: usize = 4;
/// Source data of a failure report, bytes.
pub const FAILURE_LEN: usize = 10;

/// Why source data is no ST\[1\] report of ours.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum VerificationError {
    /// Not a subservice of ours (1, 2, 3, 4, 7, 8).
    #[error("TM(1,{0}) is no report of ours (1, 2, 3, 4, 7, 8)")]
    Subservice(u8),
    /// Not the subservice's length.
    #[error("TM(1,{subservice}): {found} bytes, expected {expected}")]
    Length {
        /// Subservice.
        subservice: u8,
        /// Bytes expected.
        expected: usize,
        /// Bytes found.
        found: usize,
    },
    /// The request ID is not a TC's (version 0, type 1, flag set, unsegmented).
    #[error("request ID {found:#010x} is not an unsegmented PUS TC's")]
    RequestId {
        /// The four bytes.
        found: u32,
    },
}

impl Report {
    /// The TM(1,x) subservice.
    pub const fn subservice(&self) -> u8 {
        let ok = self.failure.is_none();
        match self.stage {
            Stage::Acceptance => {
                if ok {
                    1
                } else {
                    2
                }
            }
            Stage::Start => {
                if ok {
                    3
                } else {
                    4
                }
            }
            Stage::Completion => {
                if ok {
                    7
                } else {
                    8
                }
            }
        }
    }

    /// Writes the source data; returns its length (4 or 10; `out` shorter writes nothing
    /// and returns 0).
    pub fn emit(&self, out: &mut [u8]) -> usize {
        let mut b = [0u8; FAILURE_LEN];
        let [r0, r1, r2, r3] = self.request.to_bytes();
        b[..4].copy_from_slice(&[r0, r1, r2, r3]);
        let n = match self.failure {
            None => SUCCESS_LEN,
            Some(f) => {
                let [c0, c1] = f.code.to_be_bytes();
                let [d0, d1, d2, d3] = f.data.to_be_bytes();
                b[4..].copy_from_slice(&[c0, c1, d0, d1, d2, d3]);
                FAILURE_LEN
            }
        };
        match out.get_mut(..n) {
            Some(dst) => {
                dst.copy_from_slice(b.get(..n).unwrap_or(&[]));
                n
            }
            None => 0,
        }
    }

    /// Reads a TM(1,`subservice`) report's source data.
    pub fn parse(subservice: u8, data: &[u8]) -> Result<Report, VerificationError> {
        let (stage, failed) = match subservice {
            1 => (Stage::Acceptance, false),
            2 => (Stage::Acceptance, true),
            3 => (Stage::Start, false),
            4 => (Stage::Start, true),
            7 => (Stage::Completion, false),
            8 => (Stage::Completion, true),
            s => return Err(VerificationError::Subservice(s)),
        };
        let expected = if failed { FAILURE_LEN } else { SUCCESS_LEN };
        let w = |i: usize| {
            data.get(i..)
                .and_then(<[u8]>::first_chunk::<2>)
                .map_or(0, |&s| u16::from_be_bytes(s))
        };
        if data.len() != expected {
            return Err(VerificationError::Length {
                subservice,
                expected,
                found: data.len(),
            });
        }
        let (id, sc) = (w(0), w(2));
        if id & 0xF800 != 0x1800 || sc & 0xC000 != 0xC000 {
            return Err(VerificationError::RequestId {
                found: u32::from(id) << 16 | u32::from(sc),
            });
        }
        let request = RequestId {
            apid: id & 0x07FF,
            seq_count: sc & 0x3FFF,
        };
        let failure = failed.then(|| Failure {
            code: w(4),
            data: u32::from(w(6)) << 16 | u32::from(w(8)),
        });
        Ok(Report {
            stage,
            request,
            failure,
        })
    }
}
