//! The frame gateway's security: SDLS on a robot's link (secured from the store's counters,
//! resumed exactly after a restart), its figures and durable numbers, and the ST\[5\] reports of
//! what it refused and of links that could not start.

use super::{FrameGateway, Progress, SecureError, Stored};
use crate::link::farm::Farm;
use crate::link::sdls::{self, Key256, SaTable, SdlsCounters};
use crate::link::tm_framer::TmFramer;
use crate::node::server::gateway::TmOut;
use crate::pus::event::Event;
use crate::pus::robot_apid;
use crate::units::BoardNumber;
use heapless::Vec;

impl<const R: usize, const Q: usize, const K: usize, const N: usize> FrameGateway<R, Q, K, N> {
    /// Secures robot `board`'s link with SDLS (`crate::link::sdls::mission`): its TC frames
    /// are verified under `tc_key` (and refused unless they verify, BC frames excepted), its
    /// TM frames protected under `tm_key`; `stored`, what the shell kept (the counters, and
    /// FARM-1's progress, [`FrameGateway::resume`]). Call it right after
    /// [`FrameGateway::add`], before any frame: the TM framer starts again with room for the
    /// security header and MAC. An error leaves the link as it was: the shell must not run it
    /// in clear instead.
    pub fn secure(
        &mut self,
        board: BoardNumber,
        tc_key: Key256,
        tm_key: Key256,
        stored: Stored,
    ) -> Result<(), SecureError> {
        let idle = self.cfg.idle_period_ms;
        let n = board.get();
        let link = self
            .links
            .iter_mut()
            .find(|l| l.board == board)
            .ok_or(SecureError::NotServed { board: n })?;
        let params = sdls::frames::secured_tm_params(*link.framer.params())
            .ok_or(SecureError::Layout { board: n })?;
        let mut table = SaTable::new();
        let tc = sdls::mission::tc_receiver(board, tc_key, stored.tc);
        let tm = sdls::mission::tm_sender(board, tm_key, stored.tm);
        // Unreachable: an empty table of two places takes two SPIs that differ.
        if table.add(tc).is_err() || table.add(tm).is_err() {
            return Err(SecureError::NotServed { board: n });
        }
        link.framer = TmFramer::new(params, idle);
        link.sdls = Some(table);
        if let Some(p) = stored.progress {
            self.resume(board, p);
        }
        // Where the TC window stands now is what a restart must resume from, exactly: kept
        // before anything leaves, even before the first frame (else a restart would take the
        // floor, a block ahead, as the last IV accepted, and refuse the ground's next frames).
        if let Some(link) = self.links.iter_mut().find(|l| l.board == board) {
            let spi = sdls::mission::tc_spi(board);
            let last = link
                .sdls
                .as_ref()
                .and_then(|t| t.get(spi))
                .and_then(|sa| match sa.role() {
                    sdls::Role::Receive(w) => Some(w.last().get()),
                    sdls::Role::Send(_) => None,
                });
            link.progress.tc_iv = last;
        }
        Ok(())
    }

    /// Robot `board`'s FARM-1 resumes at the kept V(R) (Open, no flag), and, on a secured link,
    /// its TC window at the last IV accepted (when the durable floor covers it). False when
    /// the robot is not served.
    pub fn resume(&mut self, board: BoardNumber, p: Progress) -> bool {
        let window = self.cfg.farm_window;
        let Some(link) = self.links.iter_mut().find(|l| l.board == board) else {
            return false;
        };
        let status = crate::link::farm::FarmStatus {
            vr: p.vr,
            ..Farm::new(window).status()
        };
        if let Some(farm) = Farm::restore(window, status) {
            link.farm = farm;
        }
        let spi = sdls::mission::tc_spi(board);
        if let (Some(table), Some(iv)) = (link.sdls.as_mut(), p.tc_iv) {
            table.resume(spi, iv);
        }
        link.progress = p;
        link.progress_kept = p;
        true
    }

    /// SDLS's counters of robot `board`, when its link is secured.
    pub fn security(&self, board: BoardNumber) -> Option<&SdlsCounters> {
        self.links
            .iter()
            .find(|l| l.board == board)
            .and_then(|l| l.sdls.as_ref())
            .map(|t| t.counters())
    }

    /// The shell wrote `value` for `spi` durably.
    pub fn persisted(&mut self, spi: u16, value: u128) -> bool {
        self.links
            .iter_mut()
            .filter_map(|l| l.sdls.as_mut())
            .any(|t| t.persisted(spi, value))
    }

    /// The ST\[5\] reports of SDLS refusals due now: per robot and reason, at most one per
    /// [`SECURITY_EVENT_PERIOD_MS`], counting every frame refused since the last.
    pub(super) fn security_reports(&mut self, now: u32) {
        let mut due: Vec<(u16, Event), 16> = Vec::new();
        for l in self.links.iter_mut() {
            // One alarm per refusal reason, far fewer than 256: the zip ends before the
            // reason's count could pass u8::MAX.
            for (a, reason) in l.alarms.iter_mut().zip(0u8..) {
                if a.ready(now) {
                    let e = Event::Security {
                        reason,
                        refused: a.pending,
                        spi: a.spi,
                    };
                    if due.push((robot_apid(l.board), e)).is_ok() {
                        a.pending = 0;
                        a.last = Some(now);
                    }
                }
            }
        }
        for (apid, e) in due {
            self.report(now, &TmOut::new(apid, 5, e.severity(), 0, &e.to_bytes()));
        }
    }

    /// Robot `stopped`'s link could not start (`reason`: its place in
    /// [`crate::pus::event::LINK_STOPPED_REASONS`]): reported as ST\[5\] `link_stopped` in
    /// every served robot's telemetry, the first chance an operator has to learn it over the
    /// link (a stopped link has no trusted way to send anything). False when no link runs.
    pub fn link_stopped(&mut self, now: u32, stopped: BoardNumber, reason: u8) -> bool {
        let e = Event::LinkStopped {
            board: stopped.get(),
            reason,
        };
        let apids: Vec<u16, R> = self.links.iter().map(|l| robot_apid(l.board)).collect();
        for apid in &apids {
            self.report(now, &TmOut::new(*apid, 5, e.severity(), 0, &e.to_bytes()));
        }
        !apids.is_empty()
    }

    /// The durable numbers to write now, (SPI, value): the shell writes each and confirms it
    /// with [`FrameGateway::persisted`] once it is durable.
    pub fn due(&self) -> impl Iterator<Item = (u16, u128)> + '_ {
        self.links
            .iter()
            .filter_map(|l| l.sdls.as_ref())
            .flat_map(|t| t.due())
    }
}
