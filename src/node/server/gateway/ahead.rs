//! Write-ahead of the telecommand queue (the frame gateway's, decision `restart-server`): a
//! telecommand the gateway accepted is kept in the server board's store until it leaves for
//! board A, and leaves only once the store says so. After a restart the queue is restored and
//! every telecommand in it runs once; one that had left is never sent again (it may have run:
//! board A's log and the kept keys answer a copy).
//!
//! The shell's part: write what the frame gateway's `durable_due` gives (the queue's entries
//! among them) before anything leaves; the gateway's part: with write-ahead on, its tick sends
//! the queue's head only after [`Gateway::clear_to_send`] for it.

use super::{Gateway, Job};
use crate::pus::verification::Stage;
use crate::units::BoardNumber;

impl<const R: usize, const Q: usize, const K: usize> Gateway<R, Q, K> {
    /// Turns write-ahead on or off for robot `board` (off by default: the PUS gateway over
    /// packets keeps only its keys). False when the robot is not served.
    pub fn write_ahead(&mut self, board: BoardNumber, on: bool) -> bool {
        self.robots
            .iter_mut()
            .find(|r| r.board == board)
            .map(|r| r.write_ahead = on)
            .is_some()
    }

    /// Robot `board`'s queued telecommands, oldest first (empty for a robot not served).
    pub fn queued(&self, board: BoardNumber) -> &[Job] {
        self.robots
            .iter()
            .find(|r| r.board == board)
            .map_or(&[], |r| r.queue.as_slice())
    }

    /// The key of robot `board`'s queue head waiting to leave for board A (write-ahead): the
    /// shell writes that it left, then calls [`Gateway::clear_to_send`].
    pub fn wants_out(&self, board: BoardNumber) -> Option<(u16, u16)> {
        self.robots
            .iter()
            .find(|r| r.board == board)
            .and_then(|r| r.wants_out)
    }

    /// The store says robot `board`'s queue head `key` left: the next tick sends it. False when
    /// `key` is not the head waiting.
    pub fn clear_to_send(&mut self, board: BoardNumber, key: (u16, u16)) -> bool {
        let Some(r) = self.robots.iter_mut().find(|r| r.board == board) else {
            return false;
        };
        let ok = r.wants_out == Some(key);
        if ok {
            r.cleared = Some(key);
        }
        ok
    }

    /// After a restart ([`Gateway::add_restarted`]), robot `board`'s queue as the store kept
    /// it: each job runs once, in order (already acknowledged as accepted before the restart;
    /// a copy is answered from the key log). False when the robot is not served or the queue
    /// cannot take them all (none is lost silently: the caller is told).
    pub fn restore_queue(&mut self, board: BoardNumber, jobs: &[Job]) -> bool {
        let Some(r) = self.robots.iter_mut().find(|r| r.board == board) else {
            return false;
        };
        let mut all = true;
        for job in jobs {
            let rep = super::report(Stage::Acceptance, job.request, None);
            r.restore_job(*job, rep);
            all &= r.queue.push(*job).is_ok();
        }
        all
    }
}
