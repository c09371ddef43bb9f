//! ST\[5\] event reporting: every fault raised, every mode change, every bolting attempt's
//! result, and faults cleared — read from two consecutive heartbeats of board A.
//!
//! The legacy link carries no event stream, only heartbeats, so the gateway derives the
//! events from what changed between two of them (spec/decisions.toml, `pus-gateway`). Faults
//! are latched until cleared and the bolting attempt number only counts up, so nothing of
//! those is lost between two polls; a mode that comes and goes between two polls is.
//!
//! Source data of TM(5,x): the event definition ID (u16), then four bytes of auxiliary data
//! (spec/ccsds/services.toml lists each event's).
//!
//! ```
//! use mmic::faults::{Fault, Faults};
//! use mmic::mode::Mode;
//! use mmic::pus::event::{self, Event};
//! use mmic::wire::heartbeat::HeartbeatRepr;
//! let before = HeartbeatRepr { mode: Mode::Operational, ..HeartbeatRepr::default() };
//! let after = HeartbeatRepr {
//!     mode: Mode::Safed,
//!     faults: Faults::EMPTY.with(Fault::SensorLoss),
//!     ..before
//! };
//! let events: Vec<Event> = event::between(&before, &after, false).collect();
//! assert_eq!(events, [
//!     Event::Fault { fault: Fault::SensorLoss, mode: Mode::Safed },
//!     Event::ModeChanged { from: Mode::Operational, to: Mode::Safed },
//! ]);
//! assert_eq!(events[0].id(), 0x010E);
//! assert_eq!(events[0].severity(), 4); // TM(5,4): high severity
//! ```

use crate::bolter::BolterPair;
use crate::faults::{Fault, Faults};
use crate::link::sdls::SdlsRefusal;

/// The place of `not-reserved` among [`SdlsRefusal::NAMES`].
const NOT_RESERVED: u8 = 6;
const _: () =
    assert!(NOT_RESERVED == 6 && matches!(SdlsRefusal::NAMES[6].as_bytes(), b"not-reserved"));
use crate::mode::Mode;
use crate::restart::Boot;
use crate::safety::policy::fault_action;
use crate::wire::heartbeat::HeartbeatRepr;
use crate::wire_enum::wire_enum;

/// Why TM(5,x) source data is not an event of ours (checked in this order).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum EventError {
    /// Not a subservice of ST\[5\] (1..=4).
    #[error("TM(5,{0}) is no event report (subservices 1..=4)")]
    Subservice(u8),
    /// Not the length of an event's source data.
    #[error("event source data of {found} octets, expected {expected}")]
    Length {
        /// Octets expected ([`EVENT_LEN`]).
        expected: usize,
        /// Octets found.
        found: usize,
    },
    /// No event has this ID (or a fault event names a bit no fault has).
    #[error("unknown event ID {0:#06x}")]
    UnknownId(u16),
    /// A byte of the auxiliary data is out of its range.
    #[error("event {id:#06x}: {field} {found:#x} is out of range")]
    Field {
        /// Event ID.
        id: u16,
        /// The field (`mode`, `from`, `to`, `pair`, `attempt`, `result`, `faults`).
        field: &'static str,
        /// Its value.
        found: u32,
    },
    /// Octets the event does not use are not zero.
    #[error("event {id:#06x}: unused octets not zero")]
    Padding {
        /// Event ID.
        id: u16,
    },
    /// The subservice is not the event's severity.
    #[error("event {id:#06x} has severity {expected}, sent as TM(5,{found})")]
    Severity {
        /// Event ID.
        id: u16,
        /// Its severity ([`Event::severity`]).
        expected: u8,
        /// The subservice it came in.
        found: u8,
    },
}

wire_enum! {
    /// How a bolting attempt ended.
    #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
    #[cfg_attr(feature = "defmt", derive(defmt::Format))]
    pub enum AttemptResult: u8 {
        /// The pair is done (locked, or unlocked for an unbolt).
        Done = 0,
        /// This attempt failed; the next one runs.
        Failed = 1,
        /// The third attempt failed: bolting failure.
        GaveUp = 2,
        /// Ended by a Stop, a mode change or another fault before it could finish.
        Interrupted = 3,
    }

    /// The auxiliary byte of the event: 0..=3.
    pub const fn to_wire(self) -> u8;
}

/// One event report.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Event {
    /// A fault was raised (latched); `mode` is the mode now. ID 0x0100 + the fault's bit.
    Fault {
        /// The fault.
        fault: Fault,
        /// The mode after it.
        mode: Mode,
    },
    /// The operating mode changed. ID 0x0001.
    ModeChanged {
        /// Before.
        from: Mode,
        /// After.
        to: Mode,
    },
    /// A bolting attempt ended. ID 0x0002.
    Attempt {
        /// The pair.
        pair: BolterPair,
        /// Attempt 1..=3.
        attempt: u8,
        /// How it ended.
        result: AttemptResult,
    },
    /// Latched faults were cleared. ID 0x0003; the cleared map.
    Cleared(Faults),
    /// Board A restarted between two heartbeats (their boot bytes differ: heartbeat byte 59,
    /// decision `heartbeat-boot`): it is in Standby, its motion lost. ID 0x0004; the new boot
    /// byte (reset cause and boot count modulo 32).
    Restarted(Boot),
    /// The server board could not start another robot's link (its store or keys were not
    /// provisioned for it: decision `sdls-store`), reported at start on the links that run.
    /// ID 0x0005; the robot's board number and the reason's place in
    /// [`LINK_STOPPED_REASONS`].
    LinkStopped {
        /// The robot whose link is stopped.
        board: u8,
        /// The reason's place in [`LINK_STOPPED_REASONS`].
        reason: u8,
    },
    /// The server board's SDLS refused TC frames of the robot's link. ID 0x0200 + the
    /// reason's place in [`SdlsRefusal::NAMES`]; the auxiliary data are how many frames were
    /// refused for it since the last such report (at least one; reports are rate-limited,
    /// `node::server::frames`) and the last refused frame's SPI. Not derived from heartbeats:
    /// the link reports it.
    Security {
        /// The reason's place in [`SdlsRefusal::NAMES`].
        reason: u8,
        /// Frames refused for it since the last report (≥ 1).
        refused: u16,
        /// The last refused frame's SPI (0 when it was too short to carry one).
        spi: u16,
    },
}

/// Source data of an event report, bytes.
pub const EVENT_LEN: usize = 6;

/// Why a robot's link did not start ([`Event::LinkStopped`]): the store's boot check
/// (`node::server::store::Stopped`, the first four, in its order), then the shell's own.
pub const LINK_STOPPED_REASONS: [&str; 7] = [
    "unprovisioned",
    "other-key",
    "no-counter",
    "weak-key",
    "no-keys",
    "no-store",
    "not-served",
];

impl Event {
    /// The event definition ID.
    pub const fn id(&self) -> u16 {
        match self {
            // 0x0100 + the bit, which is below 256: the ID's low octet.
            Event::Fault { fault, .. } => u16::from_be_bytes([0x01, fault.bit()]),
            Event::ModeChanged { .. } => 1,
            Event::Attempt { .. } => 2,
            Event::Cleared(_) => 3,
            Event::Restarted(_) => 4,
            Event::LinkStopped { .. } => 5,
            Event::Security { reason, .. } => u16::from_be_bytes([0x02, *reason]),
        }
    }

    /// The TM(5,x) subservice: 1 informative, 2 low, 3 medium, 4 high severity. A fault that
    /// safes the robot (or puts it in Standby at once) is high; one deferred to the motion's
    /// end is medium; a failed attempt is low (the next attempt runs), giving up is medium.
    pub const fn severity(&self) -> u8 {
        match self {
            Event::Fault { fault, .. } => {
                if fault_action(*fault).deferred {
                    3
                } else {
                    4
                }
            }
            Event::Attempt { result, .. } => match result {
                AttemptResult::Done => 1,
                AttemptResult::Failed | AttemptResult::Interrupted => 2,
                AttemptResult::GaveUp => 3,
            },
            Event::ModeChanged { .. } | Event::Cleared(_) => 1,
            // Informative: a frame refused as not reserved verified (its MAC is good), so it is
            // the ground's own, beyond the durable floor after a restart or a long loss (the
            // next reservation lets its retransmission in): never an attack.
            Event::Security { reason, .. } if *reason == NOT_RESERVED => 1,
            // Medium: other refused frames are an attack or a fault of the link or the
            // ground's keys, and nothing of them executed. A restart stopped what the robot
            // was doing.
            Event::Security { .. } | Event::Restarted(_) => 3,
            // High: a robot cannot be commanded at all until its store is provisioned.
            Event::LinkStopped { .. } => 4,
        }
    }

    /// The source data: ID and four auxiliary bytes.
    pub fn to_bytes(&self) -> [u8; EVENT_LEN] {
        let aux: [u8; 4] = match self {
            Event::Fault { mode, .. } => [mode.to_wire(), 0, 0, 0],
            Event::ModeChanged { from, to } => [from.to_wire(), to.to_wire(), 0, 0],
            Event::Attempt {
                pair,
                attempt,
                result,
            } => [pair.number(), *attempt, result.to_wire(), 0],
            Event::Cleared(f) => f.bits().to_be_bytes(),
            Event::Restarted(b) => [b.to_wire(), 0, 0, 0],
            Event::LinkStopped { board, reason } => [*board, *reason, 0, 0],
            Event::Security { refused, spi, .. } => {
                let [r0, r1] = refused.to_be_bytes();
                let [s0, s1] = spi.to_be_bytes();
                [r0, r1, s0, s1]
            }
        };
        let [i0, i1] = self.id().to_be_bytes();
        [i0, i1, aux[0], aux[1], aux[2], aux[3]]
    }
}

impl Event {
    /// Reads TM(5,`subservice`) source data: exactly the bytes [`Event::to_bytes`] writes, sent
    /// in the event's severity. Ground tools use it; the gateway only emits.
    ///
    /// ```
    /// use mmic::mode::Mode;
    /// use mmic::pus::event::{Event, EventError};
    /// let e = Event::ModeChanged { from: Mode::Standby, to: Mode::Operational };
    /// assert_eq!(Event::parse(1, &e.to_bytes()), Ok(e));
    /// assert_eq!(
    ///     Event::parse(4, &e.to_bytes()),
    ///     Err(EventError::Severity { id: 1, expected: 1, found: 4 })
    /// );
    /// ```
    pub fn parse(subservice: u8, data: &[u8]) -> Result<Event, EventError> {
        if !(1..=4).contains(&subservice) {
            return Err(EventError::Subservice(subservice));
        }
        let b: [u8; EVENT_LEN] = data.try_into().map_err(|_| EventError::Length {
            expected: EVENT_LEN,
            found: data.len(),
        })?;
        let id = u16::from_be_bytes([b[0], b[1]]);
        let event = Event::decode(id, &b)?;
        if event.to_bytes() != b {
            return Err(EventError::Padding { id });
        }
        if event.severity() != subservice {
            return Err(EventError::Severity {
                id,
                expected: event.severity(),
                found: subservice,
            });
        }
        Ok(event)
    }

    /// The event `id` names, its fields from the octets after the ID (`b` is the whole source
    /// data); a field no event of that kind has is refused by name. Padding and severity are
    /// [`Event::parse`]'s.
    fn decode(id: u16, b: &[u8; EVENT_LEN]) -> Result<Event, EventError> {
        let field = |field, found: u32| EventError::Field { id, field, found };
        let mode = |name, x: u8| Mode::from_wire(x).ok_or(field(name, u32::from(x)));
        let [_, low] = id.to_be_bytes();
        Ok(match id {
            1 => Event::ModeChanged {
                from: mode("from", b[2])?,
                to: mode("to", b[3])?,
            },
            2 => Event::decode_attempt(id, b)?,
            3 => {
                let bits = u32::from_be_bytes([b[2], b[3], b[4], b[5]]);
                let wire = u16::try_from(bits).map(u16::to_le_bytes);
                match wire.map(Faults::from_wire) {
                    Ok(Ok(f)) if !f.is_empty() => Event::Cleared(f),
                    _ => return Err(field("faults", bits)),
                }
            }
            4 => Event::Restarted(Boot::from_wire(b[2])),
            5 => match (b[2], b[3]) {
                (0, _) => return Err(field("board", 0)),
                (board, reason) if usize::from(reason) < LINK_STOPPED_REASONS.len() => {
                    Event::LinkStopped { board, reason }
                }
                (_, reason) => return Err(field("reason", u32::from(reason))),
            },
            0x0100..=0x01FF => Event::Fault {
                fault: Fault::ALL
                    .into_iter()
                    .find(|f| 0x0100 + u16::from(f.bit()) == id)
                    .ok_or(EventError::UnknownId(id))?,
                mode: mode("mode", b[2])?,
            },
            // The reason is the ID's low octet (the ID is 0x0200 + it).
            0x0200..=0x02FF if usize::from(low) < SdlsRefusal::NAMES.len() => {
                let refused = u16::from_be_bytes([b[2], b[3]]);
                if refused == 0 {
                    return Err(field("refused", 0));
                }
                Event::Security {
                    reason: low,
                    refused,
                    spi: u16::from_be_bytes([b[4], b[5]]),
                }
            }
            _ => return Err(EventError::UnknownId(id)),
        })
    }

    /// A bolting attempt's fields (event 2): the pair, the attempt (1 to 3) and its result.
    fn decode_attempt(id: u16, b: &[u8; EVENT_LEN]) -> Result<Event, EventError> {
        let field = |field, found: u8| EventError::Field {
            id,
            field,
            found: u32::from(found),
        };
        Ok(Event::Attempt {
            pair: BolterPair::from_number(b[2]).ok_or(field("pair", b[2]))?,
            attempt: match b[3] {
                1..=3 => b[3],
                x => return Err(field("attempt", x)),
            },
            result: match b[4] {
                0 => AttemptResult::Done,
                1 => AttemptResult::Failed,
                2 => AttemptResult::GaveUp,
                3 => AttemptResult::Interrupted,
                x => return Err(field("result", x)),
            },
        })
    }
}

/// The events between two consecutive heartbeats `a` then `b`: board A's restart, new faults
/// (bit order), the mode change, the bolting attempts that ended, faults cleared. `stopped`: the gateway
/// forwarded a Stop between them (a pair that ended then was interrupted, not done).
pub fn between<'h>(
    a: &'h HeartbeatRepr,
    b: &'h HeartbeatRepr,
    stopped: bool,
) -> impl Iterator<Item = Event> + 'h {
    let raised = Faults::from_iter(b.faults.iter().filter(move |f| !a.faults.contains(*f)));
    let cleared = Faults::from_iter(a.faults.iter().filter(move |f| !b.faults.contains(*f)));
    let faults = raised.iter().map(move |fault| Event::Fault {
        fault,
        mode: b.mode,
    });
    let mode = (a.mode != b.mode).then_some(Event::ModeChanged {
        from: a.mode,
        to: b.mode,
    });
    let cleared = (!cleared.is_empty()).then_some(Event::Cleared(cleared));
    let restarted = a.boot.differs(b.boot).then_some(Event::Restarted(b.boot));
    restarted
        .into_iter()
        .chain(faults)
        .chain(mode)
        .chain(attempts(a, b, stopped, raised))
        .chain(cleared)
}

/// The attempts on `a`'s pair that ended by `b`.
fn attempts(
    a: &HeartbeatRepr,
    b: &HeartbeatRepr,
    stopped: bool,
    raised: Faults,
) -> impl Iterator<Item = Event> + use<> {
    let (pair, k) = match a.active_bolter {
        Some(p) if a.bolter_attempt.get() > 0 => (Some(p), a.bolter_attempt.get()),
        _ => (None, 0),
    };
    let same = pair.is_some() && b.active_bolter == pair;
    // Attempts k.. that failed while the pair went on (b shows a later attempt).
    let retried = if same {
        b.bolter_attempt.get().max(k)
    } else {
        k
    };
    let last = match (pair, same) {
        (Some(_), false) => Some(if raised.contains(Fault::BoltingFailure) {
            AttemptResult::GaveUp
        } else if stopped || !raised.is_empty() || a.mode != b.mode {
            AttemptResult::Interrupted
        } else {
            AttemptResult::Done
        }),
        _ => None,
    };
    let failed = (k..retried).map(move |n| (n, AttemptResult::Failed));
    let ended = last.map(|r| (retried, r));
    failed.chain(ended).filter_map(move |(attempt, result)| {
        pair.map(|pair| Event::Attempt {
            pair,
            attempt,
            result,
        })
    })
}
