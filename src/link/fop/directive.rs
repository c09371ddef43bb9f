//! FOP-1's directives (232.1-B-2 §5.1.11, Table 5-1's E23–E39): what the ground's operator
//! or software asks of it, and its answer; one named step per kind of directive.

use super::{AlertCode, Fop, FopOutput, FopState, TimeoutType};
use crate::link::ControlCommand;

/// A FOP-1 directive from the ground's operator or software (232.1-B-2 §5.1.11).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "kebab-case"))]
pub enum Directive {
    /// E23: start at once, V(S) as it is.
    InitiateWithoutClcw,
    /// E24: start when a CLCW shows FARM-1 expecting V(S), with no flag set.
    InitiateWithClcw,
    /// E25: send an Unlock and start when a CLCW shows it obeyed.
    InitiateWithUnlock,
    /// E27: V(S) := v, send Set V(R) to v and start when a CLCW shows it obeyed.
    InitiateWithSetVr(u8),
    /// E29: stop the AD service (an alert "terminated" if it was running).
    Terminate,
    /// E30–E34: take up a suspended AD service.
    Resume,
    /// E35: V(S) := NN(R) := v (only in Initial, not suspended).
    SetVs(u8),
    /// E36: the sliding window K.
    SetWindow(u8),
    /// E37: T1.
    SetT1(u32),
    /// E38: the transmission limit.
    SetTxLimit(u8),
    /// E39: the timeout type.
    SetTimeoutType(TimeoutType),
}

/// FOP-1's answer to a directive (232.1-B-2 §5.2: "Accept", "Reject", "Positive Confirm").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "kebab-case"))]
pub enum DirectiveResponse {
    /// Accepted and done.
    Confirmed,
    /// Accepted; [`FopOutput::InitiateConfirmed`] (or an alert) follows.
    Accepted,
    /// Not allowed in the present state (or a parameter out of range).
    Rejected,
}

impl<P: Clone, const K: usize> Fop<P, K> {
    /// A directive (E23–E39).
    pub fn directive(
        &mut self,
        d: Directive,
        now_ms: u32,
        out: &mut impl FnMut(FopOutput<P>),
    ) -> DirectiveResponse {
        use DirectiveResponse::*;
        let initial = self.state == FopState::Initial;
        match d {
            Directive::InitiateWithoutClcw
            | Directive::InitiateWithClcw
            | Directive::InitiateWithUnlock
            | Directive::InitiateWithSetVr(_) => self.initiate(d, now_ms, out),
            Directive::Terminate => {
                if !initial {
                    self.alert(AlertCode::Term, out);
                }
                Confirmed
            }
            Directive::Resume => self.resume(now_ms),
            Directive::SetVs(v) => {
                if initial && self.suspend_state == 0 {
                    self.vs = v;
                    self.nnr = v;
                    Confirmed
                } else {
                    Rejected
                }
            }
            Directive::SetWindow(_)
            | Directive::SetT1(_)
            | Directive::SetTxLimit(_)
            | Directive::SetTimeoutType(_) => self.set_parameter(d),
        }
    }

    /// The four "Initiate AD service" directives (E23–E27): taken only in Initial, each
    /// starting from an empty sent queue and a count of 1; any other directive is rejected.
    fn initiate(
        &mut self,
        d: Directive,
        now_ms: u32,
        out: &mut impl FnMut(FopOutput<P>),
    ) -> DirectiveResponse {
        use DirectiveResponse::*;
        use FopState::*;
        if self.state != Initial {
            return Rejected;
        }
        match d {
            Directive::InitiateWithoutClcw => {
                self.initialise(out);
                self.state = Active;
                Confirmed
            }
            Directive::InitiateWithClcw => {
                self.initialise(out);
                self.timer = Some(now_ms);
                self.state = InitialisingWithoutBc;
                Accepted
            }
            Directive::InitiateWithUnlock => {
                self.initialise(out);
                self.transmit_bc(ControlCommand::Unlock, now_ms, out);
                self.state = InitialisingWithBc;
                Accepted
            }
            Directive::InitiateWithSetVr(v) => {
                self.initialise(out);
                self.vs = v;
                self.nnr = v;
                self.transmit_bc(ControlCommand::SetVr(v), now_ms, out);
                self.state = InitialisingWithBc;
                Accepted
            }
            _ => Rejected,
        }
    }

    /// "Resume AD service" (E29–E34): back to the state a suspend left, T1 started again;
    /// rejected with no suspend to resume (E30) or outside Initial.
    fn resume(&mut self, now_ms: u32) -> DirectiveResponse {
        use FopState::*;
        let to = match self.suspend_state {
            1 => Active,
            2 => RetransmitWithoutWait,
            3 => RetransmitWithWait,
            4 => InitialisingWithoutBc,
            _ => return DirectiveResponse::Rejected, // E30
        };
        if self.state != Initial {
            return DirectiveResponse::Rejected;
        }
        self.timer = Some(now_ms);
        self.suspend_state = 0;
        self.state = to;
        DirectiveResponse::Confirmed
    }

    /// The managed parameters' directives (E36–E39): taken in every state, rejected when the
    /// value is one FOP-1 cannot run with (a window beyond the sent queue, a limit of 0).
    fn set_parameter(&mut self, d: Directive) -> DirectiveResponse {
        use DirectiveResponse::*;
        match d {
            Directive::SetWindow(k) if k >= 1 && usize::from(k) <= K => self.config.window = k,
            Directive::SetT1(t) => self.config.t1_ms = t,
            Directive::SetTxLimit(n) if n >= 1 => self.config.tx_limit = n,
            Directive::SetTimeoutType(t) => self.config.timeout_type = t,
            _ => return Rejected,
        }
        Confirmed
    }
}
