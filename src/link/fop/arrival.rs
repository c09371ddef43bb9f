//! A CLCW's arrival (232.1-B-2 Table 5-1's E1–E14, E101–E103): which event it is in the present
//! variables, and what each state does with it.

use super::{AlertCode, Fop, FopOutput, FopState};
use crate::link::clcw::Clcw;

/// The event numbers of a CLCW's arrival (232.1-B-2 Table 5-1, numbering of dariol83/ccsds).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum ClcwEvent {
    /// N(R) = V(S) = NN(R), no flag: nothing outstanding, nothing new.
    E1,
    /// N(R) = V(S) ≠ NN(R), no flag: everything outstanding acknowledged.
    E2,
    /// N(R) = V(S), Wait without Retransmit.
    E3,
    /// N(R) = V(S), Retransmit.
    E4,
    /// NN(R) ≤ N(R) < V(S), no flag, N(R) = NN(R): no progress yet.
    E5,
    /// NN(R) < N(R) < V(S), no flag: some acknowledged.
    E6,
    /// NN(R) ≤ N(R) < V(S), Wait without Retransmit.
    E7,
    /// Retransmit, limit 1, N(R) ≠ NN(R).
    E101,
    /// Retransmit, limit 1, N(R) = NN(R).
    E102,
    /// Retransmit, N(R) ≠ NN(R), no Wait.
    E8,
    /// Retransmit, N(R) ≠ NN(R), Wait.
    E9,
    /// Retransmit, N(R) = NN(R), count < limit, no Wait.
    E10,
    /// Retransmit, N(R) = NN(R), count < limit, Wait.
    E11,
    /// Retransmit, N(R) = NN(R), count ≥ limit, no Wait.
    E12,
    /// Retransmit, N(R) = NN(R), count ≥ limit, Wait.
    E103,
    /// N(R) outside NN(R)..=V(S).
    E13,
    /// Lockout.
    E14,
}

impl<P: Clone, const K: usize> Fop<P, K> {
    /// Which event of Table 5-1 a CLCW is, in the present variables (232.1-B-2 §5.3).
    pub fn classify(&self, clcw: &Clcw) -> ClcwEvent {
        use ClcwEvent::*;
        let nr = clcw.report_value;
        let (r, w) = (clcw.retransmit, clcw.wait);
        if clcw.lockout {
            return E14;
        }
        if nr == self.vs {
            return match (r, w) {
                (false, false) if nr == self.nnr => E1,
                (false, false) => E2,
                (false, true) => E3,
                (true, _) => E4,
            };
        }
        // NN(R) ≤ N(R) < V(S), modulo 256 (V(S) − NN(R) ≤ K < 256).
        let outstanding = self.vs.wrapping_sub(self.nnr);
        if nr.wrapping_sub(self.nnr) >= outstanding {
            return E13;
        }
        let progress = nr != self.nnr;
        match (r, w) {
            (false, false) if progress => E6,
            (false, false) => E5,
            (false, true) => E7,
            (true, _) if self.config.tx_limit == 1 => {
                if progress {
                    E101
                } else {
                    E102
                }
            }
            (true, false) if progress => E8,
            (true, true) if progress => E9,
            (true, false) if self.tx_count < self.config.tx_limit => E10,
            (true, true) if self.tx_count < self.config.tx_limit => E11,
            (true, false) => E12,
            (true, true) => E103,
        }
    }

    /// A CLCW arrived for this virtual channel (E1–E14, E101–E103). The caller checks its
    /// VCID (and [`Clcw::parse`] its COP).
    pub fn clcw(&mut self, clcw: &Clcw, now_ms: u32, out: &mut impl FnMut(FopOutput<P>)) {
        use FopState::*;
        let ev = self.classify(clcw);
        let nr = clcw.report_value;
        let from = self.state;
        match self.state {
            Initial => {}
            Active | RetransmitWithoutWait | RetransmitWithWait => {
                self.clcw_running(ev, nr, now_ms, out)
            }
            InitialisingWithoutBc | InitialisingWithBc => self.clcw_initialising(ev, out),
        }
        if self.config.restart_t1_after_wait
            && from == RetransmitWithWait
            && matches!(self.state, Active | RetransmitWithoutWait)
            && !self.sent.is_empty()
            && self.timer.is_none()
        {
            self.timer = Some(now_ms);
        }
    }

    /// A CLCW in Active and the two retransmit states (S1–S3): acknowledgements, the
    /// retransmissions FARM-1 asks for, and the alerts of a link out of step.
    fn clcw_running(
        &mut self,
        ev: ClcwEvent,
        nr: u8,
        now_ms: u32,
        out: &mut impl FnMut(FopOutput<P>),
    ) {
        use ClcwEvent::*;
        use FopState::*;
        match ev {
            E1 | E5 if self.state == Active => {}
            E1 | E4 | E5 => self.alert(AlertCode::Synch, out),
            E2 => {
                self.remove_acknowledged(nr, out);
                self.timer = None;
                self.state = Active;
                self.look_for_fdu(now_ms, out);
            }
            E3 | E7 => self.alert(AlertCode::Clcw, out),
            E6 => {
                self.remove_acknowledged(nr, out);
                self.state = Active;
                self.look_for_fdu(now_ms, out);
            }
            E101 => {
                self.remove_acknowledged(nr, out);
                self.alert(AlertCode::Limit, out);
            }
            E102 => self.alert(AlertCode::Limit, out),
            E8 => {
                self.remove_acknowledged(nr, out);
                self.initiate_ad_retransmission(now_ms);
                self.state = RetransmitWithoutWait;
                self.look_for_fdu(now_ms, out);
            }
            E9 => {
                self.remove_acknowledged(nr, out);
                self.state = RetransmitWithWait;
            }
            E10 if self.state == RetransmitWithoutWait => {}
            E10 => {
                self.initiate_ad_retransmission(now_ms);
                self.state = RetransmitWithoutWait;
                self.look_for_fdu(now_ms, out);
            }
            E11 | E103 => self.state = RetransmitWithWait,
            E12 if self.state == RetransmitWithoutWait => {}
            E12 => self.state = RetransmitWithoutWait,
            E13 => self.alert(AlertCode::NnR, out),
            E14 => self.alert(AlertCode::Lockout, out),
        }
    }

    /// A CLCW while initialising (S4, S5): the one that confirms the initiation, or an alert.
    /// Every other CLCW is ignored (in S5 a Lockout or Retransmit may still show until
    /// FARM-1 has the BC frame).
    fn clcw_initialising(&mut self, ev: ClcwEvent, out: &mut impl FnMut(FopOutput<P>)) {
        use ClcwEvent::*;
        use FopState::*;
        match (self.state, ev) {
            (InitialisingWithoutBc, E1) => {
                self.timer = None;
                self.state = Active;
                out(FopOutput::InitiateConfirmed);
            }
            (InitialisingWithoutBc, E3) => self.alert(AlertCode::Clcw, out),
            (InitialisingWithoutBc, E4) => self.alert(AlertCode::Synch, out),
            (InitialisingWithoutBc, E13) => self.alert(AlertCode::NnR, out),
            (InitialisingWithoutBc, E14) => self.alert(AlertCode::Lockout, out),
            (InitialisingWithBc, E1) => {
                self.bc = None; // "release copy of the BC frame"
                self.timer = None;
                self.state = Active;
                out(FopOutput::InitiateConfirmed);
            }
            (InitialisingWithBc, E3) => self.alert(AlertCode::Clcw, out),
            _ => {}
        }
    }
}
