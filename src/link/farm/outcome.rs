//! What FARM-1 did with an event, and why it discarded a frame, with the counts of both for
//! reports: the outputs of Table 6-1, apart from the state it leaves.

use super::EventId;
use crate::link::ControlCommand;

/// Why FARM-1 discarded a frame: one reason per event of Table 6-1 that discards, so the
/// discard counters say what the link did.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "kebab-case"))]
pub enum DiscardReason {
    /// E2 (and E1 in Wait): the expected frame, but no buffer for it.
    NoBuffer,
    /// E3: ahead of V(R), inside the positive window (a frame before it was lost).
    Ahead,
    /// E4: behind V(R), inside the negative window (already accepted).
    Behind,
    /// E5 in Open or Wait: in the lockout area; FARM-1 goes to Lockout.
    LockoutArea,
    /// E1–E5 in Lockout: no AD frame is taken until an Unlock.
    Locked,
    /// E9: the frame failed validation.
    Invalid,
}

impl DiscardReason {
    /// Every reason, in the order of the counters.
    pub const ALL: [DiscardReason; 6] = [
        DiscardReason::NoBuffer,
        DiscardReason::Ahead,
        DiscardReason::Behind,
        DiscardReason::LockoutArea,
        DiscardReason::Locked,
        DiscardReason::Invalid,
    ];

    /// Kebab-case name (reports, `spec/ccsds/farm-1.toml`).
    pub const fn name(self) -> &'static str {
        match self {
            DiscardReason::NoBuffer => "no-buffer",
            DiscardReason::Ahead => "ahead",
            DiscardReason::Behind => "behind",
            DiscardReason::LockoutArea => "lockout-area",
            DiscardReason::Locked => "locked",
            DiscardReason::Invalid => "invalid",
        }
    }

    /// The reason's place in [`DiscardReason::ALL`] (and in the counters).
    const fn index(self) -> usize {
        match self {
            DiscardReason::NoBuffer => 0,
            DiscardReason::Ahead => 1,
            DiscardReason::Behind => 2,
            DiscardReason::LockoutArea => 3,
            DiscardReason::Locked => 4,
            DiscardReason::Invalid => 5,
        }
    }
}

/// What FARM-1 did with an event.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "kebab-case"))]
pub enum Verdict {
    /// The AD or BD frame's FDU goes to the higher procedures ("Accept", §6.2.2).
    Accept,
    /// The frame is dropped ("Discard", §6.2.3).
    Discard(DiscardReason),
    /// A BC frame was taken (FARM-B counter incremented); `executed` is false for Set V(R) in
    /// Lockout, which the table counts but does not obey.
    Control {
        /// The command.
        command: ControlCommand,
        /// Whether it changed V(R) or the state as it says.
        executed: bool,
    },
    /// The buffer release was noted (E10).
    Released,
}
/// Counts of what FARM-1 did, for reports. Each wraps at `u32::MAX` (a report takes
/// differences; 4 × 10⁹ frames is years of link).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct FarmCounters {
    /// AD frames accepted.
    pub accepted_ad: u32,
    /// BD frames accepted.
    pub accepted_bd: u32,
    /// BC frames taken (executed or not).
    pub control: u32,
    /// Frames discarded, by [`DiscardReason`] in the order of [`DiscardReason::ALL`].
    pub discarded: [u32; 6],
}

impl FarmCounters {
    /// Frames discarded for `reason`.
    #[cfg_attr(
        not(test),
        expect(
            clippy::indexing_slicing,
            reason = "index() is the reason's place in DiscardReason::ALL, one counter per reason"
        )
    )]
    pub const fn discarded(&self, reason: DiscardReason) -> u32 {
        self.discarded[reason.index()]
    }

    /// Counts `verdict`, the verdict of event `id` (a BD frame's acceptance apart from an
    /// AD frame's).
    #[inline]
    pub(super) fn count(&mut self, id: EventId, verdict: Verdict) {
        match verdict {
            Verdict::Accept if id == EventId::E6 => {
                self.accepted_bd = self.accepted_bd.wrapping_add(1)
            }
            Verdict::Accept => self.accepted_ad = self.accepted_ad.wrapping_add(1),
            Verdict::Discard(r) => {
                if let Some(n) = self.discarded.get_mut(r.index()) {
                    *n = n.wrapping_add(1);
                }
            }
            Verdict::Control { .. } => self.control = self.control.wrapping_add(1),
            Verdict::Released => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::DiscardReason;

    /// The counters' order is the one `ALL` documents.
    #[test]
    fn index_is_the_place_in_all() {
        for (i, r) in DiscardReason::ALL.iter().enumerate() {
            assert_eq!(r.index(), i, "{r:?}");
        }
    }
}
