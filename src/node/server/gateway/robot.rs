//! One robot's side of the gateway: its telecommand queue and key log, the legacy uplink
//! to its board A, the motions running there, and its telemetry counters.

use super::{report, Config, Out, Tc, TmOut};
use crate::ccsds::primary::SeqCount;
use crate::command::Command;
use crate::faults::Faults;
use crate::node::exactly_once::uplink::{Done, Outcome, Uplink};
use crate::pus::housekeeping::{self, REPORT_LEN};
use crate::pus::request::{Request, ST_HOUSEKEEPING, ST_TEST, ST_VERIFICATION};
use crate::pus::robot_apid;
use crate::pus::verification::{
    Failure, Report, RequestId, Stage, ABANDONED, FAILURE_LEN, KEY_REUSED, QUEUE_FULL, RESTARTED,
    UNACKNOWLEDGED,
};
use crate::units::{BoardNumber, Instant};
use crate::wire::heartbeat::HeartbeatRepr;
use heapless::Vec;

/// What the key log remembers of a telecommand.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub(super) struct Entry {
    pub(super) key: (u16, u16),
    pub(super) request: Request,
    /// The latest report made for it (sent again for a copy).
    pub(super) last: Option<Report>,
}

/// A telecommand on its way to board A: queued, sent, or running there (what a durable
/// store keeps of a queued one: `node::server::store::job_entry`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Job {
    /// Its request ID (APID, packet sequence count).
    pub request: RequestId,
    /// Its source.
    pub source_id: u16,
    /// The ST\[1\] reports asked for (bits 0, 1, 3: acceptance, start, completion).
    pub ack: u8,
    /// The command board A runs.
    pub command: Command,
    /// Are-you-alive: answer TM(17,2) when board A answers.
    pub alive: bool,
}

impl Job {
    /// Its key: source ID and sequence count.
    pub const fn key(&self) -> (u16, u16) {
        (self.source_id, self.request.seq_count)
    }
}

/// One robot's side of the gateway.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub(super) struct Robot<const Q: usize, const K: usize> {
    pub(super) board: BoardNumber,
    pub(super) uplink: Uplink,
    pub(super) queue: Vec<Job, Q>,
    pub(super) sent: Option<(u16, Job)>,
    /// The motions board A accepted (with the legacy number it accepted each under), until
    /// "command complete", a fault or a mode change. Several at once only where board A runs
    /// them together (single-module moves in Safed); "command complete" ends them all.
    pub(super) running: Vec<(u16, Job), Q>,
    pub(super) log: Vec<Entry, K>,
    pub(super) last: Option<HeartbeatRepr>,
    pub(super) stopped: bool,
    pub(super) hk_enabled: bool,
    pub(super) hk_interval_ms: u32,
    pub(super) hk_next: Option<Instant>,
    pub(super) next_poll: Option<Instant>,
    /// Telemetry: the APID's packet sequence count, and a message type counter per report type
    /// ([`TmOut::type_index`]).
    pub(super) tm_seq: SeqCount,
    pub(super) counters: [u16; 16],
    /// The newest key taken from each source ([`Kept`]): what the server board keeps across a
    /// restart. After one, `restored` holds what was kept then.
    pub(super) marks: Kept,
    pub(super) restored: Kept,
    /// Write-ahead (the frame gateway's): the queue's head leaves for board A only once the
    /// shell has written durably that it left ([`super::Gateway::clear_to_send`]): `cleared`
    /// is that head's key, `wants_out` the head waiting for it.
    pub(super) write_ahead: bool,
    pub(super) cleared: Option<(u16, u16)>,
    pub(super) wants_out: Option<(u16, u16)>,
}

/// How many sources (ground stations, operators) a robot's kept keys remember.
pub const KEPT_SOURCES: usize = 4;

/// What the gateway keeps of one robot across a restart: the newest telecommand key (source
/// ID, packet sequence count) taken from each source, at most [`KEPT_SOURCES`] (the source
/// heard from least recently forgotten first). Written to the server board's flash before
/// the telecommand can reach board A (decision `restart-server`).
pub type Kept = Vec<(u16, u16), KEPT_SOURCES>;

/// `a` is newer than `b` in the 14-bit packet sequence count (RFC 1982 arithmetic).
const fn newer14(a: u16, b: u16) -> bool {
    let d = a.wrapping_sub(b) & 0x3FFF;
    d != 0 && d < 0x2000
}

/// The queue's capacity, the data of a `QUEUE_FULL` failure (a queue of a few entries: it
/// fits a u32).
fn queue_capacity<const Q: usize>() -> u32 {
    u32::try_from(Q).unwrap_or(u32::MAX)
}

impl<const Q: usize, const K: usize> Robot<Q, K> {
    /// A telecommand through the key log: a copy is answered from it (its latest report
    /// again; a reused key with another request is refused), a new one is logged (the
    /// oldest key forgotten when the log is full) and its request returned; one whose request
    /// could not be read is refused at acceptance.
    pub(super) fn admit<const M2: usize>(&mut self, tc: &Tc, out: &mut Out<M2>) -> Option<Request> {
        let refuse = |code: u16, data: u32| {
            report(Stage::Acceptance, tc.request, Some(Failure { code, data }))
        };
        let request = match tc.request_of {
            Ok(q) => q,
            Err(e) => {
                self.verify(out, refuse(e.code(), 0), tc.ack, tc.source_id);
                return None;
            }
        };
        let key = (tc.source_id, tc.request.seq_count);
        if let Some(e) = self.log.iter().find(|e| e.key == key).copied() {
            if e.request == request {
                // A copy: not run again; its latest report again, for a ground that lost it.
                if let Some(rep) = e.last {
                    self.verify(out, rep, 0xF, tc.source_id);
                }
            } else {
                let rep = refuse(KEY_REUSED, u32::from(tc.request.seq_count));
                self.verify(out, rep, tc.ack, tc.source_id);
            }
            return None;
        }
        if let Some(&(_, mark)) = self.restored.iter().find(|(src, _)| *src == tc.source_id)
            && !newer14(tc.request.seq_count, mark)
        {
            // Taken before the restart, or older: it may have run; never again.
            let f = Failure {
                code: RESTARTED,
                data: u32::from(mark),
            };
            let rep = report(Stage::Start, tc.request, Some(f));
            self.log_entry(key, request, Some(rep));
            self.verify(out, rep, tc.ack, tc.source_id);
            return None;
        }
        self.log_entry(key, request, None);
        self.mark(key);
        Some(request)
    }

    /// A queued job restored after a restart: its key logged (a copy is answered, not run)
    /// with `rep`, its latest report, and marked.
    pub(super) fn restore_job(&mut self, job: Job, rep: Report) {
        let request = if job.alive {
            Request::AreYouAlive
        } else {
            Request::Function(job.command)
        };
        self.log_entry(job.key(), request, Some(rep));
        self.mark(job.key());
    }

    /// Logs a new key (the oldest forgotten when the log is full).
    fn log_entry(&mut self, key: (u16, u16), request: Request, last: Option<Report>) {
        if self.log.is_full() {
            self.log.remove(0);
        }
        let _ = self.log.push(Entry { key, request, last });
    }

    /// `key` was taken from its source: the kept mark moves to it unless it holds a newer one
    /// (telecommands can arrive out of order: a mark that went back would let a copy of the
    /// newer one run again after a restart; the stateright model in
    /// proofs/tests/protocol/restarts.rs found it). The source moves to the end; the least
    /// recently heard one is forgotten when they are full.
    fn mark(&mut self, (source, seq): (u16, u16)) {
        let mut seq = seq;
        if let Some(i) = self.marks.iter().position(|(s, _)| *s == source) {
            let (_, old) = self.marks.remove(i);
            if newer14(old, seq) {
                seq = old;
            }
        } else if self.marks.is_full() {
            self.marks.remove(0);
        }
        let _ = self.marks.push((source, seq));
    }

    /// A new telecommand's request: housekeeping settings are done at once (accepted,
    /// started, completed); a function or an are-you-alive is queued for board A.
    pub(super) fn run<const M2: usize>(&mut self, tc: &Tc, request: Request, out: &mut Out<M2>) {
        let key = (tc.source_id, tc.request.seq_count);
        let job = |command, alive| Job {
            request: tc.request,
            source_id: tc.source_id,
            ack: tc.ack,
            command,
            alive,
        };
        match request {
            Request::HkEnable => self.hk_enabled = true,
            Request::HkDisable => self.hk_enabled = false,
            Request::HkInterval { ms } => {
                self.hk_interval_ms = ms;
                self.hk_next = None;
            }
            Request::Function(c) => return self.enqueue(out, job(c, false), key),
            Request::AreYouAlive => return self.enqueue(out, job(Command::Heartbeat, true), key),
        }
        for stage in [Stage::Acceptance, Stage::Start, Stage::Completion] {
            let rep = report(stage, tc.request, None);
            self.remember(key, rep);
            self.verify(out, rep, tc.ack, tc.source_id);
        }
    }

    pub(super) fn apid(&self) -> u16 {
        robot_apid(self.board)
    }

    /// Records `rep` as the latest report of the telecommand keyed `key`.
    pub(super) fn remember(&mut self, key: (u16, u16), rep: Report) {
        if let Some(e) = self.log.iter_mut().find(|e| e.key == key) {
            e.last = Some(rep);
        }
    }

    /// Sends an ST\[1\] report: failures always, successes when `ack` asks for the stage.
    pub(super) fn verify<const M2: usize>(
        &self,
        out: &mut Out<M2>,
        rep: Report,
        ack: u8,
        dest: u16,
    ) {
        let bit = match rep.stage {
            Stage::Acceptance => 0,
            Stage::Start => 1,
            Stage::Completion => 3,
        };
        if rep.failure.is_some() || ack & (1 << bit) != 0 {
            let mut b = [0u8; FAILURE_LEN];
            let n = rep.emit(&mut b);
            out.push(TmOut::new(
                self.apid(),
                ST_VERIFICATION,
                rep.subservice(),
                dest,
                b.get(..n).unwrap_or(&[]),
            ));
        }
    }

    pub(super) fn report<const M2: usize>(&mut self, out: &mut Out<M2>, job: &Job, rep: Report) {
        self.remember((job.source_id, job.request.seq_count), rep);
        self.verify(out, rep, job.ack, job.source_id);
    }

    pub(super) fn enqueue<const M2: usize>(
        &mut self,
        out: &mut Out<M2>,
        job: Job,
        key: (u16, u16),
    ) {
        match self.queue.push(job) {
            Ok(()) => {
                let rep = report(Stage::Acceptance, job.request, None);
                self.remember(key, rep);
                self.verify(out, rep, job.ack, job.source_id);
            }
            Err(_) => {
                let f = Failure {
                    code: QUEUE_FULL,
                    data: queue_capacity::<Q>(),
                };
                let rep = report(Stage::Acceptance, job.request, Some(f));
                self.remember(key, rep);
                self.verify(out, rep, job.ack, job.source_id);
            }
        }
    }

    /// The uplink is idle: the next telecommand, else a poll when one is due. Until board A's
    /// first heartbeat came, telecommands wait in the queue and the gateway polls: ST\[5\]
    /// events are what changed between two heartbeats, so a command answered by the very
    /// first one (entering Operational, a fault raised on the way) would change nothing the
    /// gateway could report (spec/decisions.toml, `pus-gateway`).
    pub(super) fn submit_next(&mut self, now: u32, cfg: &Config) {
        let t = Instant::from_millis(now);
        if self.last.is_none() && !self.queue.is_empty() {
            if self.uplink.submit(Command::Heartbeat).is_ok() {
                self.next_poll = Some(Instant::from_millis(now.wrapping_add(cfg.poll_ms)));
            }
            return;
        }
        if let Some(head) = self.queue.first() {
            if self.write_ahead && self.cleared != Some(head.key()) {
                // Not before the store says it left: after a restart it would run again.
                self.wants_out = Some(head.key());
                return;
            }
            self.wants_out = None;
            self.cleared = None;
            let job = self.queue.remove(0);
            if let Ok(seq) = self.uplink.submit(job.command) {
                if job.command == Command::Stop {
                    self.stopped = true;
                }
                self.sent = Some((seq, job));
            }
            return;
        }
        let due = cfg.poll_ms > 0 && self.next_poll.is_none_or(|p| t.reached(p));
        if due && self.uplink.submit(Command::Heartbeat).is_ok() {
            self.next_poll = Some(Instant::from_millis(now.wrapping_add(cfg.poll_ms)));
        }
    }

    /// The uplink finished a command: start (or failure) reports, completion for what does
    /// not move.
    pub(super) fn finished<const M2: usize>(&mut self, out: &mut Out<M2>, d: Done) {
        let Some((seq, job)) = self.sent else { return };
        if seq != d.seq {
            return;
        }
        self.sent = None;
        let req = job.request;
        match d.outcome {
            Outcome::Accepted => {
                self.report(out, &job, report(Stage::Start, req, None));
                if job.alive {
                    out.push(TmOut::new(self.apid(), ST_TEST, 2, job.source_id, &[]));
                }
                if job.command.kind().moves() {
                    if self.running.push((seq, job)).is_err() {
                        // More motions at once than the queue holds: say so, never lose one.
                        let f = Failure {
                            code: QUEUE_FULL,
                            data: queue_capacity::<Q>(),
                        };
                        self.report(out, &job, report(Stage::Completion, req, Some(f)));
                    }
                } else {
                    self.report(out, &job, report(Stage::Completion, req, None));
                }
            }
            Outcome::Refused(r) => {
                self.report(
                    out,
                    &job,
                    report(Stage::Start, req, Some(Failure::refused(r))),
                );
            }
            Outcome::Unacknowledged => {
                let f = Failure {
                    code: UNACKNOWLEDGED,
                    data: u32::from(d.attempts),
                };
                self.report(out, &job, report(Stage::Start, req, Some(f)));
            }
        }
    }

    /// The running motions: complete, failed by a fault, or abandoned by a mode change. Only a
    /// heartbeat that answers a command sent after the latest of them counts: one delayed from
    /// before (or the answer to a copy, numbered 0) says nothing of them.
    pub(super) fn progress<const M2: usize>(
        &mut self,
        out: &mut Out<M2>,
        prev: &HeartbeatRepr,
        hb: &HeartbeatRepr,
    ) {
        let Some(&(newest, _)) = self.running.last() else {
            return;
        };
        if hb.last_seq == 0 || hb.last_seq.wrapping_sub(newest) >= 0x8000 {
            return;
        }
        let raised = Faults::from_iter(hb.faults.iter().filter(|f| !prev.faults.contains(*f)));
        // A fault deferred to the motion's end (Table 8: low battery, assembly system) lets
        // the motion complete; its ST[5] event reports it. Any other fails the motion.
        let stopping = raised
            .iter()
            .find(|f| !crate::safety::policy::fault_action(*f).deferred);
        // "Command complete" before the mode: a deferred fault takes the robot to its mode in
        // the very tick the motion completes, so the completing heartbeat shows both.
        let failure = match stopping {
            Some(f) => Some(Failure::fault(f, hb.faults)),
            None if hb.command_complete => None,
            None if hb.mode != prev.mode => Some(Failure {
                code: ABANDONED,
                data: u32::from(hb.mode.to_wire()),
            }),
            None => return,
        };
        for (_, job) in core::mem::take(&mut self.running) {
            self.report(out, &job, report(Stage::Completion, job.request, failure));
        }
    }

    pub(super) fn housekeeping<const M2: usize>(&mut self, now: u32, out: &mut Out<M2>) {
        let t = Instant::from_millis(now);
        let due = self.hk_next.is_none_or(|n| t.reached(n));
        if !self.hk_enabled || !due {
            return;
        }
        if let Some(hb) = self.last {
            let mut b = [0u8; REPORT_LEN];
            housekeeping::emit(&hb, &mut b);
            out.push(TmOut::new(self.apid(), ST_HOUSEKEEPING, 25, 0, &b));
            self.hk_next = Some(Instant::from_millis(now.wrapping_add(self.hk_interval_ms)));
        }
    }
}
