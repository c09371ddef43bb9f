//! Board A's command log: the receiving half of exactly-once commanding.
//!
//! The paper's ground software resends a command until a heartbeat answers it, so a command
//! whose heartbeat is lost arrives twice and runs twice (the counterexamples in
//! spec/protocol/paper-counterexample.txt). With a sequence number in the packet
//! ([`CommandRepr::seq`](crate::wire::command::CommandRepr::seq)), board A runs a command only
//! when its number is newer than the last one it took, and answers every copy with the
//! heartbeat that reports that number and its outcome (bytes 57–58 and 62).
//!
//! ```
//! use mmic::node::exactly_once::{Admission, CommandLog};
//! let mut log = CommandLog::new();
//! assert_eq!(log.admit(1), Admission::Execute);
//! log.record(1, None);                         // ran, accepted
//! assert_eq!(log.admit(1), Admission::Duplicate); // a resend: answered, not run again
//! assert_eq!(log.admit(2), Admission::Execute);
//! log.record(2, None);
//! assert_eq!(log.admit(1), Admission::Stale);     // a late copy of an old command
//! assert_eq!(log.admit(0), Admission::Execute);   // unsequenced: the paper's behaviour
//! ```
//!
//! Why "newer" and not "different": the ground sends one command at a time and numbers them in
//! order, so a number older than the last taken can only be a late copy (a duplicating or
//! reordering link). Serial-number arithmetic (RFC 1982) over 16 bits keeps this true across
//! wrap-around as long as fewer than 32,768 commands separate a copy from its original.
//! Board A's log is in RAM: after a reset the first sequenced command is taken whatever its
//! number (documented in spec/protocol/README.md).
// req: D:exactly-once-window

use crate::refusal::Refusal;

/// What to do with a received command.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Admission {
    /// Run it (then [`CommandLog::record`] its outcome if it was sequenced).
    Execute,
    /// The last command taken, again: answer with its recorded outcome, do not run it.
    Duplicate,
    /// Older than the last command taken: answer, do not run it.
    Stale,
}

/// The last sequenced command taken and its outcome.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct CommandLog {
    last: Option<(u16, Option<Refusal>)>,
}

/// `a` is newer than `b` in 16-bit serial-number arithmetic.
pub const fn newer(a: u16, b: u16) -> bool {
    let d = a.wrapping_sub(b);
    d != 0 && d < 0x8000
}

impl CommandLog {
    /// Nothing taken yet (startup).
    pub const fn new() -> CommandLog {
        CommandLog { last: None }
    }

    /// Decides on a command numbered `seq` (0 = unsequenced, always run).
    pub const fn admit(&self, seq: u16) -> Admission {
        match self.last {
            _ if seq == 0 => Admission::Execute,
            None => Admission::Execute,
            Some((last, _)) if seq == last => Admission::Duplicate,
            Some((last, _)) if newer(seq, last) => Admission::Execute,
            Some(_) => Admission::Stale,
        }
    }

    /// Records that sequenced command `seq` was taken with this outcome (`None` = accepted).
    /// Unsequenced commands (0) are not recorded.
    pub fn record(&mut self, seq: u16, refusal: Option<Refusal>) {
        if seq != 0 {
            self.last = Some((seq, refusal));
        }
    }

    /// The last sequenced command taken (0 = none) and its outcome: heartbeat bytes 57–58 and,
    /// when answering a sequenced command, byte 62.
    pub const fn last(&self) -> (u16, Option<Refusal>) {
        match self.last {
            Some(l) => l,
            None => (0, None),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    // req: D:exactly-once-window
    #[test]
    fn serial_arithmetic_at_the_wrap() {
        assert!(newer(0, 0xffff) && newer(1, 0xffff) && !newer(0xffff, 0));
        assert!(newer(0x7fff, 0) && !newer(0x8000, 0));
        // Exhaustive over one operand: exactly half of the other values are newer. Under Miri
        // (.ci/miri), some 100x slower, every 257th distance d = a − b and the distances at the
        // edges (0, 1, 0x7fff, 0x8000, 0xffff): newer exactly when 0 < d < 0x8000.
        for b in [0u16, 1, 0x7fff, 0x8000, 0xffff] {
            if cfg!(miri) {
                let edges = [0u16, 1, 0x7fff, 0x8000, 0xffff];
                let mut n = 0;
                for d in (0..=u16::MAX).step_by(257).chain(edges) {
                    let a = b.wrapping_add(d);
                    assert_eq!(newer(a, b), (1..0x8000).contains(&d), "{a:#x} {b:#x}");
                    n += usize::from(newer(a, b));
                }
                assert_eq!(n, 127 + 2, "257, …, 127 × 257 = 0x7f7f, and 1, 0x7fff");
            } else {
                let n = (0..=u16::MAX).filter(|&a| newer(a, b)).count();
                assert_eq!(n, 0x7fff);
            }
        }
    }

    // req: D:exactly-once-window
    #[test]
    fn duplicates_report_the_recorded_outcome() {
        let mut log = CommandLog::new();
        assert_eq!(log.last(), (0, None));
        assert_eq!(log.admit(40_000), Admission::Execute);
        log.record(40_000, Some(Refusal::NotAllowedInMode));
        assert_eq!(log.admit(40_000), Admission::Duplicate);
        assert_eq!(log.last(), (40_000, Some(Refusal::NotAllowedInMode)));
        log.record(0, None);
        assert_eq!(log.last(), (40_000, Some(Refusal::NotAllowedInMode)));
    }
}
