//! Board A's end of the A→B serial command: when to send, and the number every command carries.
//!
//! Every A→B command is a snapshot of what side B must do (spec/packets/b-command.toml). A
//! snapshot whose content differs from the last one sent is a *new command* and gets a new
//! number; an unchanged snapshot is resent every `period_ms` with the same number, as a
//! refresh. Board B echoes the number of the last command it parsed (Table 4 byte 35, "command
//! received"), so every new command is acknowledged on its own, and a command resent
//! repeatedly without that echo is what Table 8's internal communication loss rule counts
//! ([`CommMonitor`](crate::safety::detect::CommMonitor)). Number 0 is never sent: B reports 0
//! before it has parsed anything.
//!
//! B's bolter executor records the number of the packet from which it adopted its current
//! order (Table 4 bytes 26–34). A bolter order stays in the snapshot over a run of
//! consecutive numbers (a run that other changes — an arm target, a power switch — may extend);
//! [`BLink::carried`] says whether a number B reports belongs to the run of the order in
//! force, which is how board A matches B's report to its coordinator's order.
//!
//! ```
//! use mmic::node::robot::b_link::BLink;
//! use mmic::wire::b_command::{BCommandRepr, BPower};
//! use mmic::units::PulseWidth;
//! let mut link = BLink::new();
//! let snap = BCommandRepr {
//!     seq: 0, // ignored: the link numbers it
//!     power: BPower::default(),
//!     stop: false,
//!     arm_target: PulseWidth::CENTER,
//!     gripper_target: PulseWidth::CENTER,
//!     bolter: None,
//! };
//! assert_eq!(link.due(0, 50, snap).map(|c| c.seq), Some(1)); // first command
//! assert_eq!(link.due(10, 50, snap), None); // unchanged, not yet time for a refresh
//! assert_eq!(link.due(50, 50, snap).map(|c| c.seq), Some(1)); // refresh: same number
//! let moved = BCommandRepr { arm_target: PulseWidth::MAX, ..snap };
//! assert_eq!(link.due(60, 50, moved).map(|c| c.seq), Some(2)); // new content: new number
//! ```
// req: P4.5, D:a-to-b-sequence-number

use crate::units::Instant;
use crate::wire::b_command::{BCommandRepr, BolterOrder};

/// Numbering and resend timing of the A→B commands.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct BLink {
    /// The last command sent and when.
    sent: Option<(Instant, BCommandRepr)>,
    /// The first number of the run of commands that carried the bolter field now in force.
    order_since: u8,
}

/// The number after `n`, skipping 0 (B's "nothing received yet").
const fn next(n: u8) -> u8 {
    match n.wrapping_add(1) {
        0 => 1,
        m => m,
    }
}

impl BLink {
    /// Nothing sent yet.
    pub const fn new() -> BLink {
        BLink {
            sent: None,
            order_since: 0,
        }
    }

    /// The command to send at `now` for `snapshot` (whose own `seq` is ignored), or `None` when
    /// nothing is due: new content is sent at once with the next number, unchanged content
    /// every `period_ms` with the number it already has.
    pub fn due(
        &mut self,
        now: u32,
        period_ms: u32,
        snapshot: BCommandRepr,
    ) -> Option<BCommandRepr> {
        let now = Instant::from_millis(now);
        let seq = match self.sent {
            Some((t, last))
                if BCommandRepr {
                    seq: last.seq,
                    ..snapshot
                } == last =>
            {
                if now.since(t).millis() < period_ms {
                    return None;
                }
                last.seq
            }
            last => {
                let seq = next(last.map_or(0, |(_, c)| c.seq));
                if last.map(|(_, c)| c.bolter) != Some(snapshot.bolter) {
                    self.order_since = seq;
                }
                seq
            }
        };
        let cmd = BCommandRepr { seq, ..snapshot };
        self.sent = Some((now, cmd));
        Some(cmd)
    }

    /// Whether a bolter report that names packet number `seq` is about `order`, the order in
    /// force: the commands sent carry `order` now, and `seq` is one of the run of numbers that
    /// has carried it since it first went out (the packet B adopted it from may be any of
    /// them: earlier ones can be lost).
    pub fn carried(&self, seq: u8, order: &BolterOrder) -> bool {
        match self.sent {
            Some((_, last)) if last.bolter.as_ref() == Some(order) => {
                seq != 0
                    && seq.wrapping_sub(self.order_since) <= last.seq.wrapping_sub(self.order_since)
            }
            _ => false,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bolter::{BolterDirection, BolterPair, BolterStep};
    use crate::units::PulseWidth;
    use crate::wire::b_command::BPower;

    fn snap(arm: u16, bolter: Option<BolterOrder>) -> BCommandRepr {
        BCommandRepr {
            seq: 0,
            power: BPower::default(),
            stop: false,
            arm_target: PulseWidth::saturating(arm),
            gripper_target: PulseWidth::CENTER,
            bolter,
        }
    }

    const ORDER: BolterOrder = BolterOrder {
        pair: BolterPair::P2,
        direction: BolterDirection::Bolt,
        step: BolterStep::Descend,
    };

    // req: P4.5
    #[test]
    fn every_new_content_gets_a_new_number_and_zero_is_skipped() {
        let mut link = BLink::new();
        let mut last = 0u8;
        for i in 0..600u32 {
            let arm = 900 + (i % 2) as u16 * 100;
            let c = link.due(i, 50, snap(arm, None));
            assert!(
                c.is_some_and(|c| c.seq != 0 && c.seq != last),
                "tick {i}: {c:?} after {last}"
            );
            last = c.map_or(last, |c| c.seq);
        }
    }

    #[test]
    fn an_order_is_matched_over_its_whole_run_of_numbers_and_only_then() {
        let mut link = BLink::new();
        let a = link.due(0, 50, snap(900, None)).map_or(0, |c| c.seq);
        let first = link
            .due(10, 50, snap(900, Some(ORDER)))
            .map_or(0, |c| c.seq);
        // An arm target changes while the order is in force: a new number, same order.
        let second = link
            .due(20, 50, snap(1000, Some(ORDER)))
            .map_or(0, |c| c.seq);
        assert!(a != 0 && first != 0 && second != 0, "all sent");
        assert!(link.carried(first, &ORDER) && link.carried(second, &ORDER));
        assert!(!link.carried(a, &ORDER), "sent before the order");
        assert!(
            !link.carried(second.wrapping_add(1), &ORDER),
            "not sent yet"
        );
        let other = BolterOrder {
            step: BolterStep::Retract,
            ..ORDER
        };
        assert!(!link.carried(first, &other), "another order");
        // The order is withdrawn and given again (a Stop, then Reset): only the new run counts.
        link.due(30, 50, snap(1000, None));
        let again = link.due(40, 50, snap(1000, Some(ORDER))).map(|c| c.seq);
        assert!(!link.carried(first, &ORDER) && !link.carried(second, &ORDER));
        assert!(again.is_some_and(|s| link.carried(s, &ORDER)));
    }
}
