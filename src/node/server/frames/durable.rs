//! What the shell must keep durable for the frame gateway, as [`Entry`]s of the store
//! ([`crate::node::server::store`]): the SDLS counters' reservations, FARM-1's progress after
//! each accepted frame, the gateway's kept telecommand keys.
//!
//! The shell writes every entry [`FrameGateway::durable_due`] gives and confirms each with
//! [`FrameGateway::durable_written`] once it is durable. Until the progress of a robot is
//! confirmed, no TM frame of that robot goes out (its CLCW would acknowledge a frame a restart
//! could not resume from); until every progress and kept key is confirmed, the gateway's tick
//! sends no legacy command to a board A (a telecommand must not reach the robot before a
//! restart can recognise it again). The SDLS counters do not hold anything back: their
//! reservations run ahead, and nothing is protected or accepted beyond a confirmed one.

use super::{FrameGateway, RobotLink};
use crate::node::server::store::{kept_entries, Entry};
use heapless::Vec;

/// Entries one robot may have due at once: two SDLS counters, the progress, four kept keys.
pub const DUE_PER_ROBOT: usize = 7;

impl<const N: usize> RobotLink<N> {
    /// The gating entries of this link that differ from what the shell confirmed: the
    /// progress, then each kept key slot.
    fn gating_due(&self, kept: Option<&super::Kept>, out: &mut impl FnMut(Entry)) {
        let secured = self.sdls.is_some();
        if self.progress != self.progress_kept {
            out(self.progress.entry(self.board, secured));
        }
        if let Some(kept) = kept {
            for (e, written) in kept_entries(self.board, kept)
                .iter()
                .zip(self.kept_written.iter())
            {
                // Nothing written yet and nothing kept: an empty slot need not be written.
                let empty_unwritten = written.is_none() && e.aux == 0;
                if Some(*e) != *written && !empty_unwritten {
                    out(*e);
                }
            }
        }
    }
}

impl<const R: usize, const Q: usize, const K: usize, const N: usize> FrameGateway<R, Q, K, N> {
    /// Every entry to write now, up to `M` (call again after confirming them): the gating
    /// ones first (progress, kept keys), then the SDLS counters' reservations.
    pub fn durable_due<const M: usize>(&self) -> Vec<Entry, M> {
        let mut due = Vec::new();
        for l in &self.links {
            let kept = self.gateway.kept(l.board);
            l.gating_due(kept.as_ref(), &mut |e| {
                let _ = due.push(e);
            });
        }
        for (spi, value) in self.due() {
            let _ = due.push(Entry {
                key: spi,
                aux: 0,
                value,
            });
        }
        due
    }

    /// The shell wrote `e` durably (one of [`FrameGateway::durable_due`]'s). False when it is
    /// none of this gateway's, or no longer what is due (nothing changes then).
    pub fn durable_written(&mut self, e: &Entry) -> bool {
        if let Some(l) = self
            .links
            .iter_mut()
            .find(|l| l.progress.entry(l.board, l.sdls.is_some()) == *e)
        {
            if l.progress != l.progress_kept {
                l.progress_kept = l.progress;
                return true;
            }
            return false;
        }
        for l in self.links.iter_mut() {
            let Some(kept) = self.gateway.kept(l.board) else {
                continue;
            };
            let entries = kept_entries(l.board, &kept);
            if let Some(slot) = entries.iter().position(|k| k == e) {
                if let Some(w) = l.kept_written.get_mut(slot) {
                    let fresh = *w != Some(*e);
                    *w = Some(*e);
                    return fresh;
                }
            }
        }
        e.aux == 0 && self.persisted(e.key, e.value)
    }

    /// Whether an entry that holds the gateway's tick back is due.
    pub(super) fn gated(&self) -> bool {
        self.links.iter().any(|l| {
            let mut any = false;
            l.gating_due(self.gateway.kept(l.board).as_ref(), &mut |_| any = true);
            any
        })
    }

    /// Takes what a restart kept of the kept keys as written (they are in the store already).
    pub(super) fn kept_restored(&mut self, board: crate::units::BoardNumber) {
        let Some(kept) = self.gateway.kept(board) else {
            return;
        };
        if let Some(l) = self.links.iter_mut().find(|l| l.board == board) {
            for (w, e) in l
                .kept_written
                .iter_mut()
                .zip(kept_entries(board, &kept).iter())
            {
                *w = Some(*e);
            }
        }
    }
}
