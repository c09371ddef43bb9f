//! A telecommand on its way, and when to send it again: the link resends only a transmission that
//! got no report at all within the timeout, and gives up after `max_attempts` of them in a row.

use super::TcOut;
use crate::node::exactly_once::uplink::{Done, Outcome};
use crate::units::Instant;

/// A telecommand on its way.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(super) struct Pending {
    pub(super) tc: TcOut,
    /// When last transmitted (for a running motion: when its query timer started).
    pub(super) sent: Option<Instant>,
    /// The last transmission awaits its first report.
    pub(super) open: bool,
    /// Transmissions in a row with no report.
    pub(super) unanswered: u8,
    /// Transmissions made.
    pub(super) attempts: u8,
    /// The gateway accepted it (TM(1,1)).
    pub(super) accepted: bool,
}

/// What [`Pending::due`] decided.
pub(super) enum Due {
    /// Nothing yet.
    Wait,
    /// Transmit (again); `failed`: the previous transmission went unanswered.
    Send { failed: bool },
    /// `max_attempts` transmissions in a row went unanswered.
    GiveUp,
}

impl Pending {
    pub(super) const fn new(tc: TcOut) -> Pending {
        Pending {
            tc,
            sent: None,
            open: false,
            unanswered: 0,
            attempts: 0,
            accepted: false,
        }
    }

    /// Whether to transmit at `now`, when a transmission waits `limit` ms for an answer.
    pub(super) fn due(&mut self, now: Instant, limit: u32, max: u8) -> Due {
        let Some(t) = self.sent else {
            return Due::Send { failed: false };
        };
        if now.since(t).millis() < limit {
            return Due::Wait;
        }
        let failed = self.open;
        if failed {
            self.open = false;
            self.unanswered = self.unanswered.saturating_add(1);
        }
        if self.unanswered >= max.max(1) {
            Due::GiveUp
        } else {
            Due::Send { failed }
        }
    }

    pub(super) fn transmit(&mut self, now: Instant) -> TcOut {
        self.sent = Some(now);
        self.open = true;
        self.attempts = self.attempts.saturating_add(1);
        self.tc
    }

    /// A report about it arrived: closes the open transmission (an answered attempt).
    pub(super) fn answered(&mut self) -> Option<bool> {
        let was = self.open;
        self.open = false;
        self.unanswered = 0;
        was.then_some(true)
    }

    pub(super) const fn done(&self, outcome: Outcome) -> Done {
        Done {
            seq: self.tc.request.seq_count,
            command: self.tc.command,
            outcome,
            attempts: self.attempts,
        }
    }
}
