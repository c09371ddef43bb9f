//! Table 6-1 of 232.1-B-2, cell by cell: what each event does to FARM-1's variables in each
//! state, and the verdict it gives. One match over (event, state), so that the compiler sees
//! every cell; the longer actions are named steps. `tests/ccsds/farm_table.rs` holds it to
//! `spec/ccsds/farm-1.toml`.

use super::{DiscardReason, EventId, FarmEvent, FarmState, FarmStatus, Verdict};
use crate::link::ControlCommand;

impl FarmStatus {
    /// The cell of event `id` (which `event` is) in the present state: its actions on the
    /// variables, its next state, and the verdict.
    #[inline]
    pub(super) fn cell(&mut self, id: EventId, event: FarmEvent) -> Verdict {
        use FarmState::*;
        let s = self;
        match (id, s.state) {
            // E1: N(S) = V(R), buffer ready.
            (EventId::E1, Open) => {
                s.vr = s.vr.wrapping_add(1);
                s.retransmit = false;
                Verdict::Accept
            }
            // "Not applicable" in the table: Wait means no buffer until the release (E10),
            // so the frame is refused as E2 would be in Wait.
            (EventId::E1, Wait) => Verdict::Discard(DiscardReason::NoBuffer),
            // E2: N(S) = V(R), no buffer.
            (EventId::E2, Open) => s.enter_wait(),
            (EventId::E2, Wait) => Verdict::Discard(DiscardReason::NoBuffer),
            // E3: positive window.
            (EventId::E3, Open) => {
                s.retransmit = true;
                Verdict::Discard(DiscardReason::Ahead)
            }
            (EventId::E3, Wait) => Verdict::Discard(DiscardReason::Ahead),
            // E4: negative window.
            (EventId::E4, Open | Wait) => Verdict::Discard(DiscardReason::Behind),
            // E5: lockout area.
            (EventId::E5, Open | Wait) => {
                s.state = Lockout;
                Verdict::Discard(DiscardReason::LockoutArea)
            }
            (EventId::E1 | EventId::E2 | EventId::E3 | EventId::E4 | EventId::E5, Lockout) => {
                Verdict::Discard(DiscardReason::Locked)
            }
            // E6: BD frame, every state.
            (EventId::E6, _) => {
                s.farm_b = s.farm_b.wrapping_next();
                Verdict::Accept
            }
            // E7: Unlock, every state: to Open, flags cleared.
            (EventId::E7, _) => s.unlock(),
            // E8: Set V(R): obeyed in Open and Wait (to Open), counted only in Lockout.
            (EventId::E8, Open | Wait) => s.set_vr(event, true),
            (EventId::E8, Lockout) => s.set_vr(event, false),
            // E9: invalid frame, every state.
            (EventId::E9, _) => Verdict::Discard(DiscardReason::Invalid),
            // E10: buffer release: ignored in Open; leaves Wait; clears a Wait flag carried
            // into Lockout.
            (EventId::E10, Open) => Verdict::Released,
            (EventId::E10, Wait) => {
                s.wait = false;
                s.state = Open;
                Verdict::Released
            }
            (EventId::E10, Lockout) => {
                s.wait = false;
                Verdict::Released
            }
        }
    }

    /// E2 in Open: the expected frame, no buffer for it; both flags set, to Wait.
    #[inline]
    fn enter_wait(&mut self) -> Verdict {
        self.retransmit = true;
        self.wait = true;
        self.state = FarmState::Wait;
        Verdict::Discard(DiscardReason::NoBuffer)
    }

    /// E7, every state: to Open, flags cleared.
    #[inline]
    fn unlock(&mut self) -> Verdict {
        self.farm_b = self.farm_b.wrapping_next();
        self.retransmit = false;
        self.wait = false;
        self.state = FarmState::Open;
        Verdict::Control {
            command: ControlCommand::Unlock,
            executed: true,
        }
    }

    /// E8: counted in every state; when `obey` (Open and Wait), V(R) takes the command's
    /// value and FARM-1 goes to Open with its flags cleared.
    #[inline]
    fn set_vr(&mut self, event: FarmEvent, obey: bool) -> Verdict {
        self.farm_b = self.farm_b.wrapping_next();
        let v = match event {
            FarmEvent::Bc(ControlCommand::SetVr(v)) => v,
            _ => self.vr,
        };
        if obey {
            self.retransmit = false;
            self.wait = false;
            self.state = FarmState::Open;
            self.vr = v;
        }
        Verdict::Control {
            command: ControlCommand::SetVr(v),
            executed: obey,
        }
    }
}
