//! The runner over PUS: telecommands through the gateway, progress from its ST[1] and ST[5]
//! telemetry.

use super::{settled, Link, Phase, PlanEnd, PlanRunner, PlanStep, PlanTick, Sent};
use crate::node::ground::pus::{self, TcLink, TcOut};
use crate::units::BoardNumber;

impl PlanRunner<TcLink> {
    /// At the first step, over PUS: telecommands to robot `board`'s APID through the gateway.
    pub fn pus(cfg: pus::Config, board: BoardNumber) -> PlanRunner<TcLink> {
        PlanRunner::over(TcLink::new(cfg, board))
    }

    /// A telemetry packet arrived at `now` (its CCSDS headers checked by the caller): its
    /// service, subservice and source data. ST\[1\] reports start and end the plan's commands
    /// ([`TcLink::telemetry`]); a housekeeping report settles a mode step.
    pub fn telemetry(
        &mut self,
        steps: &[PlanStep],
        now: u32,
        service: u8,
        subservice: u8,
        data: &[u8],
    ) -> PlanTick<TcOut> {
        let _ = (steps, now);
        let mut t = PlanTick::default();
        let h = self.up.telemetry(service, subservice, data);
        t.attempt = h.attempt;
        let status = self.up.status();
        if let Some(d) = h.done {
            t.done = Some(d);
            self.finished(d, status.as_ref());
        }
        if let Some((seq, _)) = h.rejected
            && self.end().is_none()
            && self.up.is_idle()
            && self.is_ours(seq)
        {
            self.sent = Sent::Step;
            self.phase = Phase::Ended(PlanEnd::Rejected {
                step: self.next,
                code: h.rejected.map_or(0, |(_, f)| f.code),
            });
        }
        if let Some((seq, e)) = h.ended {
            self.motion_ended(seq, e);
        }
        if let (
            Some(hb),
            Phase::Settling {
                mode_step: true,
                ended: true,
                ..
            },
        ) = (h.status, self.phase)
            && !self.held
            && settled(&hb)
        {
            self.next = self.next.saturating_add(1);
            self.phase = Phase::Ready;
        }
        t.end = self.end();
        t
    }

    /// Whether the telecommand numbered `seq` is one the runner sent last (its step's or an
    /// interjection's).
    fn is_ours(&self, seq: u16) -> bool {
        self.step_seq == Some(seq) || self.sent == Sent::Interjection
    }
}
