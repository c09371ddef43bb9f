//! FOP-1's actions (232.1-B-2 §5.2): the steps the cells of Table 5-1 are made of, shared by
//! the directives, the CLCW's arrival, the requests and the timer.

use super::{AlertCode, Fop, FopFrame, FopOutput, FopState, FrameData, Sent};
use crate::link::{ControlCommand, FrameKind};

impl<P: Clone, const K: usize> Fop<P, K> {
    pub(super) fn state_number(&self) -> u8 {
        match self.state {
            FopState::Active => 1,
            FopState::RetransmitWithoutWait => 2,
            FopState::RetransmitWithWait => 3,
            FopState::InitialisingWithoutBc => 4,
            FopState::InitialisingWithBc => 5,
            FopState::Initial => 6,
        }
    }

    /// Negative confirm for each frame of the sent queue, which empties; NN(R) := V(S), so
    /// that V(S) − NN(R) stays the sent queue's length (NN(R) is the oldest frame on it, and
    /// with none the next one; YAMCS's `purgeSentQueue` does the same, dariol83/ccsds leaves
    /// NN(R) behind, after which no CLCW can acknowledge anything).
    pub(super) fn purge_sent_queue(&mut self, out: &mut impl FnMut(FopOutput<P>)) {
        for s in self.sent.iter() {
            out(FopOutput::NegativeConfirm {
                ns: s.ns,
                fdu: s.fdu.clone(),
            });
        }
        self.sent.clear();
        self.bc = None;
        self.nnr = self.vs;
    }

    pub(super) fn purge_wait_queue(&mut self, out: &mut impl FnMut(FopOutput<P>)) {
        if let Some(p) = self.wait.take() {
            out(FopOutput::Rejected(p));
        }
    }

    pub(super) fn initialise(&mut self, out: &mut impl FnMut(FopOutput<P>)) {
        self.purge_sent_queue(out);
        self.purge_wait_queue(out);
        self.tx_count = 1;
        self.suspend_state = 0;
        self.timer = None;
    }

    pub(super) fn alert(&mut self, code: AlertCode, out: &mut impl FnMut(FopOutput<P>)) {
        self.timer = None;
        self.purge_sent_queue(out);
        self.purge_wait_queue(out);
        out(FopOutput::Alert(code));
        self.state = FopState::Initial;
    }

    pub(super) fn suspend(&mut self, out: &mut impl FnMut(FopOutput<P>)) {
        self.suspend_state = self.state_number();
        out(FopOutput::Suspended);
        self.state = FopState::Initial;
    }

    /// Positive confirm for each frame N(R) acknowledges; NN(R) := N(R); count := 1.
    pub(super) fn remove_acknowledged(&mut self, nr: u8, out: &mut impl FnMut(FopOutput<P>)) {
        while self.nnr != nr && !self.sent.is_empty() {
            let s = self.sent.remove(0);
            out(FopOutput::Confirmed { ns: s.ns });
            self.nnr = self.nnr.wrapping_add(1);
            self.tx_count = 1;
        }
    }

    pub(super) fn initiate_ad_retransmission(&mut self, now_ms: u32) {
        self.tx_count = self.tx_count.saturating_add(1);
        self.timer = Some(now_ms);
        for s in self.sent.iter_mut() {
            s.to_be_retransmitted = true;
        }
    }

    pub(super) fn transmit_bc(
        &mut self,
        c: ControlCommand,
        now_ms: u32,
        out: &mut impl FnMut(FopOutput<P>),
    ) {
        self.bc = Some((c, false));
        self.tx_count = 1;
        self.timer = Some(now_ms);
        out(FopOutput::Transmit(FopFrame {
            kind: FrameKind::Bc,
            ns: 0,
            data: FrameData::Control(c),
        }));
    }

    /// "Look for FDU" with a transport that is always ready: every frame marked for
    /// retransmission, then the wait queue's FDU if V(S) < NN(R) + K.
    pub(super) fn look_for_fdu(&mut self, now_ms: u32, out: &mut impl FnMut(FopOutput<P>)) {
        for s in self.sent.iter_mut().filter(|s| s.to_be_retransmitted) {
            s.to_be_retransmitted = false;
            out(FopOutput::Transmit(FopFrame {
                kind: FrameKind::Ad,
                ns: s.ns,
                data: FrameData::Fdu(s.fdu.clone()),
            }));
        }
        let in_window = self.vs.wrapping_sub(self.nnr) < self.config.window;
        if !in_window || self.sent.is_full() {
            return;
        }
        let Some(fdu) = self.wait.take() else { return };
        // Transmit type-AD frame (§5.2.x): N(S) := V(S), V(S) + 1, on the sent queue.
        let ns = self.vs;
        if self.sent.is_empty() {
            self.tx_count = 1;
        }
        if let Err(s) = self.sent.push(Sent {
            ns,
            fdu: fdu.clone(),
            to_be_retransmitted: false,
        }) {
            self.wait = Some(s.fdu); // cannot happen: checked not full
            return;
        }
        self.vs = self.vs.wrapping_add(1);
        self.timer = Some(now_ms);
        out(FopOutput::Transmit(FopFrame {
            kind: FrameKind::Ad,
            ns,
            data: FrameData::Fdu(fdu),
        }));
    }
}
