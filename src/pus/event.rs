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
use crate::mode::Mode;
use crate::safety::policy::fault_action;
use crate::wire::heartbeat::HeartbeatRepr;

/// How a bolting attempt ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum AttemptResult {
    /// The pair is done (locked, or unlocked for an unbolt).
    Done = 0,
    /// This attempt failed; the next one runs.
    Failed = 1,
    /// The third attempt failed: bolting failure.
    GaveUp = 2,
    /// Ended by a Stop, a mode change or another fault before it could finish.
    Interrupted = 3,
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
}

/// Source data of an event report, bytes.
pub const EVENT_LEN: usize = 6;

impl Event {
    /// The event definition ID.
    pub const fn id(&self) -> u16 {
        match self {
            Event::Fault { fault, .. } => 0x0100 + fault.bit() as u16,
            Event::ModeChanged { .. } => 1,
            Event::Attempt { .. } => 2,
            Event::Cleared(_) => 3,
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
            } => [pair.number(), *attempt, *result as u8, 0],
            Event::Cleared(f) => f.bits().to_be_bytes(),
        };
        let [i0, i1] = self.id().to_be_bytes();
        [i0, i1, aux[0], aux[1], aux[2], aux[3]]
    }
}

/// The events between two consecutive heartbeats `a` then `b`: new faults (bit order), the
/// mode change, the bolting attempts that ended, faults cleared. `stopped`: the gateway
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
    faults
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
) -> impl Iterator<Item = Event> {
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
