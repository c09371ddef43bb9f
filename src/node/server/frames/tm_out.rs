//! The server board's TM frames out: each robot's reports written as PUS packets into its
//! framer, the frames due handed out with the robot's CLCW (protected by SDLS on a secured
//! link), and when the next is due.

use super::FrameGateway;
use crate::ccsds::tm::TM_MIN_LEN;
use crate::link::sdls::{self, frames as secured};
use crate::node::server::gateway::{Out, TmOut, MAX_TM_DATA};
use crate::pus::robot_apid;
use crate::units::BoardNumber;

/// The largest telemetry packet the gateway writes.
const MAX_TM_LEN: usize = TM_MIN_LEN + MAX_TM_DATA;

impl<const R: usize, const Q: usize, const K: usize, const N: usize> FrameGateway<R, Q, K, N> {
    /// The next TM frame due at `now` of any robot, written into `out` (at least
    /// [`TM_FRAME_LEN`] octets): the robot and the frame's length. Call until `None`.
    ///
    /// [`TM_FRAME_LEN`]: crate::link::tm_frame::TM_FRAME_LEN
    pub fn frame(&mut self, now: u32, out: &mut [u8]) -> Option<(BoardNumber, usize)> {
        let gather = self.cfg.gather_ms;
        let link = self.links.iter_mut().find(|l| {
            l.due(now, gather)
                // The CLCW would report a V(R) a restart could not resume from.
                && l.progress == l.progress_kept
                && l.sdls
                    .as_ref()
                    .is_none_or(|t| t.ready(sdls::mission::tm_spi(l.board)))
        })?;
        let clcw = link.clcw();
        let n = link.framer.next_frame(now, clcw, out).ok()?;
        if let Some(table) = link.sdls.as_mut() {
            let params = *link.framer.params();
            let spi = sdls::mission::tm_spi(link.board);
            // Unreachable (the association is ready, the layout the framer's): counted.
            if secured::protect_tm(table, spi, &params, out).is_err() {
                link.counters.tm_unprotected = link.counters.tm_unprotected.wrapping_add(1);
                return None;
            }
        }
        link.clcw_sent = Some(clcw);
        link.counters.tm_frames = link.counters.tm_frames.wrapping_add(1);
        link.oldest = (link.framer.waiting() > 0).then_some(now);
        Some((link.board, n))
    }

    /// The earliest time from `now` on when something is due: the gateway's next deadline, a
    /// TM frame (the idle period, a gathered report). `now` when something is due already.
    pub fn next_deadline(&self, now: u32) -> Option<u32> {
        let wait = |t: u32| {
            let d = t.wrapping_sub(now);
            if d > i32::MAX.unsigned_abs() {
                0
            } else {
                d
            }
        };
        let mut best = self.gateway.next_deadline(now).map(wait);
        for l in &self.links {
            let d = if l.due(now, self.cfg.gather_ms) {
                0
            } else {
                let idle = self.cfg.idle_period_ms;
                let gathered = l.oldest.map(|t| wait(t.wrapping_add(self.cfg.gather_ms)));
                let idle_at = l
                    .framer
                    .last_frame_ms()
                    .map_or(0, |t| wait(t.wrapping_add(idle)));
                gathered.map_or(idle_at, |g| g.min(idle_at))
            };
            let alarm = l.alarms.iter().filter_map(|a| a.wait(now)).min();
            let d = alarm.map_or(d, |a| a.min(d));
            best = Some(best.map_or(d, |b| b.min(d)));
        }
        best.map(|d| now.wrapping_add(d))
    }

    /// Writes the reports of `out` into their robots' framers.
    pub(super) fn downlink<const M: usize>(&mut self, now: u32, out: Out<M>) {
        for tm in &out.reports {
            self.report(now, tm);
        }
        if out.overflow > 0
            && let Some(l) = self.links.first_mut()
        {
            l.counters.tm_overflow = l.counters.tm_overflow.wrapping_add(u32::from(out.overflow));
        }
    }

    pub(super) fn report(&mut self, now: u32, tm: &TmOut) {
        let mut buf = [0u8; MAX_TM_LEN];
        let Ok(n) = self.gateway.encode(tm, now, &mut buf) else {
            return;
        };
        let Some(link) = self
            .links
            .iter_mut()
            .find(|l| robot_apid(l.board) == tm.apid)
        else {
            return;
        };
        match link.framer.push(buf.get(..n).unwrap_or(&[])) {
            Ok(()) => {
                link.oldest.get_or_insert(now);
            }
            Err(_) => link.counters.tm_overflow = link.counters.tm_overflow.wrapping_add(1),
        }
    }
}
