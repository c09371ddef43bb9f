//! Out-of-band commands (an operator's Stop, Reset, a System fault): sent in the uplink's next
//! free slot, ahead of the plan's next step, from a short queue that hands a command back
//! rather than drop it.

use super::{Link, PlanEnd, PlanRunner};
use crate::command::Command;

/// Out-of-band commands that may wait for a slot at once ([`PlanRunner::interject`]): an
/// operator's Stop and Reset and a System fault fit with room to spare.
pub const INTERJECTIONS: usize = 4;

/// [`PlanRunner::interject`] did not take the command: it is handed back, never dropped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum InterjectError {
    /// [`INTERJECTIONS`] commands already wait for a slot.
    #[error("{waiting} out-of-band commands already wait for a slot; {command:?} not taken")]
    Full {
        /// The command not taken.
        command: Command,
        /// How many wait.
        waiting: usize,
    },
    /// The plan has ended, so nothing is sent any more.
    #[error("the plan has ended ({end:?}); {command:?} not taken")]
    Ended {
        /// The command not taken.
        command: Command,
        /// How the plan ended.
        end: PlanEnd,
    },
}

impl<L: Link> PlanRunner<L> {
    /// Sends `command` out of band: in the next free slot of the uplink, ahead of the plan's
    /// next step and of polling (after the command outstanding now, if any, and after those
    /// interjected before it). It gets its own sequence number and is resent until answered
    /// like any command; its answer does not advance the plan. An accepted Stop holds the
    /// plan — no step starts, no motion counts as settled — until an accepted Reset; an
    /// interjection left unacknowledged ends the plan as [`PlanEnd::Unacknowledged`] (the
    /// link is gone). Refused, with the command handed back, when [`INTERJECTIONS`] wait
    /// already or the plan has ended.
    pub fn interject(&mut self, command: Command) -> Result<(), InterjectError> {
        if let Some(end) = self.end() {
            return Err(InterjectError::Ended { command, end });
        }
        match self.pending.iter_mut().find(|p| p.is_none()) {
            Some(slot) => {
                *slot = Some(command);
                Ok(())
            }
            None => Err(InterjectError::Full {
                command,
                waiting: INTERJECTIONS,
            }),
        }
    }

    /// Out-of-band commands waiting for a slot.
    pub fn interjections_waiting(&self) -> usize {
        self.pending.iter().filter(|p| p.is_some()).count()
    }

    /// The oldest waiting interjection, taken out of the queue.
    pub(super) fn take_interjection(&mut self) -> Option<Command> {
        let c = self.pending[0]?;
        self.pending.rotate_left(1);
        self.pending[INTERJECTIONS - 1] = None;
        Some(c)
    }
}
