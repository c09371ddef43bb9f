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
use crate::node::server::gateway::Job;
use crate::node::server::store::queue::{job_entry, queue_key, ring_after, QUEUE_SLOTS, SLOTS};
use crate::node::server::store::{kept_entries, Entry};
use crate::units::BoardNumber;
use heapless::Vec;

/// Entries one robot may have due at once: two SDLS counters, the progress, four kept keys.
pub const DUE_PER_ROBOT: usize = 7;

impl<const N: usize> RobotLink<N> {
    /// Follows the gateway's queue in the ring: slots of telecommands that left are freed,
    /// new ones take the next slots in order (the queue only grows at its end and leaves at its
    /// head, so it stays one run of slots, oldest first).
    fn sync_ring(&mut self, queue: &[Job]) {
        for slot in self.ring.iter_mut() {
            if slot.is_some_and(|k| !queue.iter().any(|j| j.key() == k)) {
                *slot = None;
            }
        }
        for j in queue {
            if !self.ring.contains(&Some(j.key())) {
                let s = self.ring_next % SLOTS;
                if let Some(slot) = self.ring.get_mut(usize::from(s)) {
                    *slot = Some(j.key());
                }
                self.ring_next = ring_after(s);
            }
        }
    }

    /// What slot `s` should hold: its telecommand, or empty when none, or when it is the head
    /// about to leave for board A (`wants_out`).
    fn slot_due(&self, s: u8, queue: &[Job], wants_out: Option<(u16, u16)>) -> Entry {
        let key = self.ring.get(usize::from(s)).copied().flatten();
        let job = key
            .filter(|k| Some(*k) != wants_out)
            .and_then(|k| queue.iter().find(|j| j.key() == k));
        job_entry(self.board, s, job)
    }

    /// The gating entries of this link that differ from what the shell confirmed: the
    /// progress, each kept key slot, each queue slot.
    fn gating_due(
        &self,
        kept: Option<&super::Kept>,
        queue: &[Job],
        wants_out: Option<(u16, u16)>,
        out: &mut impl FnMut(Entry),
    ) {
        for s in 0..SLOTS {
            let written = self.ring_written.get(usize::from(s)).copied().flatten();
            // A slot that holds nothing and was never written is not due: skip encoding its
            // empty entry (most slots, most calls; issue 40).
            if written.is_none() && self.ring.get(usize::from(s)).copied().flatten().is_none() {
                continue;
            }
            let e = self.slot_due(s, queue, wants_out);
            // An empty slot never written need not be.
            if Some(e) != written && !(written.is_none() && e.aux == 0) {
                out(e);
            }
        }
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
            let (queue, out) = (
                self.gateway.queued(l.board),
                self.gateway.wants_out(l.board),
            );
            l.gating_due(kept.as_ref(), queue, out, &mut |e| {
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
        if let Some(done) = self.queue_written(e) {
            return done;
        }
        for l in self.links.iter_mut() {
            let Some(kept) = self.gateway.kept(l.board) else {
                continue;
            };
            let entries = kept_entries(l.board, &kept);
            if let Some(slot) = entries.iter().position(|k| k == e)
                && let Some(w) = l.kept_written.get_mut(slot)
            {
                let fresh = *w != Some(*e);
                *w = Some(*e);
                return fresh;
            }
        }
        e.aux == 0 && self.persisted(e.key, e.value)
    }

    /// Whether an entry that holds the gateway's tick back is due.
    pub(super) fn gated(&self) -> bool {
        self.links.iter().any(|l| {
            let mut any = false;
            let (queue, out) = (
                self.gateway.queued(l.board),
                self.gateway.wants_out(l.board),
            );
            l.gating_due(self.gateway.kept(l.board).as_ref(), queue, out, &mut |_| {
                any = true
            });
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

    /// A queue slot's entry written: noted; when it is the head's emptied slot, the head may
    /// leave for board A. `None` when `e` is no queue entry of ours.
    fn queue_written(&mut self, e: &Entry) -> Option<bool> {
        let l = self
            .links
            .iter_mut()
            .find(|l| (0..SLOTS).any(|s| queue_key(l.board, s) == e.key))?;
        let board = l.board;
        let s = (0..SLOTS).find(|&s| queue_key(board, s) == e.key)?;
        let queue = self.gateway.queued(board);
        let wants_out = self.gateway.wants_out(board);
        if l.slot_due(s, queue, wants_out) != *e {
            return Some(false);
        }
        let fresh = l.ring_written.get(usize::from(s)).copied().flatten() != Some(*e);
        if let Some(w) = l.ring_written.get_mut(usize::from(s)) {
            *w = Some(*e);
        }
        let head = l.ring.get(usize::from(s)).copied().flatten();
        if let (Some(k), Some(out)) = (head, wants_out)
            && k == out
            && e.aux == 0
        {
            self.gateway.clear_to_send(board, k);
        }
        Some(fresh)
    }

    /// Every link's ring follows its gateway queue.
    pub(super) fn sync_rings(&mut self) {
        for l in self.links.iter_mut() {
            l.sync_ring(self.gateway.queued(l.board));
        }
    }

    /// After a restart, robot `board`'s queue as its store kept it, `(slot, job)` oldest first
    /// (`store::Boot::queue`): each runs once. False when the robot is not served or the
    /// queue could not take them all.
    pub fn restore_queue(&mut self, board: BoardNumber, queue: &[(u8, Job)]) -> bool {
        let jobs: Vec<Job, QUEUE_SLOTS> = queue.iter().map(|(_, j)| *j).collect();
        let all = self.gateway.restore_queue(board, &jobs);
        let Some(l) = self.links.iter_mut().find(|l| l.board == board) else {
            return false;
        };
        for (slot, job) in queue {
            let s = *slot % SLOTS;
            if let Some(r) = l.ring.get_mut(usize::from(s)) {
                *r = Some(job.key());
            }
            if let Some(w) = l.ring_written.get_mut(usize::from(s)) {
                *w = Some(job_entry(board, s, Some(job)));
            }
            l.ring_next = ring_after(s);
        }
        all
    }
}
