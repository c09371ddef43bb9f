//! Bolting and the A→B link: board B's report taken in, the bolting job stepped (the
//! coordinator over both sides' bolters, side A's executor here), and the A→B command
//! snapshot handed to the link, which numbers and paces it.

use super::interface::{Event, Outputs};
use super::motion::Queued;
use super::BoardA;
use crate::bolter::{self as coordinator};
use crate::faults::Faults;
use crate::mode::Mode;
use crate::safety::ModuleSet;
use crate::units::Module;
use crate::wire::b_command::{BCommandRepr, BPower, B_COMMAND_LEN};
use crate::wire::internal_heartbeat::{BolterAux, InternalHeartbeatRepr, INTERNAL_HEARTBEAT_LEN};

impl BoardA {
    /// Board B's report: refreshes the communication monitor and what A knows of side B.
    pub(super) fn ingest_b(
        &mut self,
        now: u32,
        from_b: Option<[u8; INTERNAL_HEARTBEAT_LEN]>,
        out: &mut Outputs,
    ) {
        self.comm.tick(now);
        if let Some(bytes) = from_b {
            match InternalHeartbeatRepr::parse(&bytes) {
                Ok(hb) => {
                    // B reports 0 only before it took any command: after a number, B
                    // restarted (`BoardB::restarted`) and lost what A had told it.
                    if hb.command_received == 0 && self.b.command_received != 0 {
                        self.b_restarted = true;
                    }
                    self.comm.heartbeat(now, hb.command_received);
                    self.b = hb;
                    self.b_heard = true;
                }
                Err(e) => out.push(Event::Rejected(e)),
            }
        }
    }

    /// A new job waits until B reports idle, so that B's executor cannot mistake the job's
    /// first order for its previous one (spec/control/bolter.md).
    pub(super) fn bolting_start(&mut self, now: u32) {
        if let Some(q) = self.motion.waiting_job
            && (self.b.bolter_aux.step.is_none() || !self.b_heard)
        {
            match q {
                Queued::Job(job) => self.motion.coord.start(job, now),
                Queued::Down => self.motion.coord.start_down(now),
            }
            self.motion.waiting_job = None;
        }
    }

    /// One step of the bolting job: the coordinator's order to both sides, side A's
    /// executor, and the events of pairs and jobs that ended; a failed job's fault goes into
    /// `faults`.
    pub(super) fn bolting(&mut self, now: u32, out: &mut Outputs, faults: &mut Faults) {
        self.bolting_start(now);
        let was = self.motion.coord.status();
        // B's report names the A→B packet it adopted its order from; it is about the
        // coordinator's order when that packet was one of the run that carried the order
        // (node::robot::b_link), and then it is handed over under the coordinator's number.
        let b = match self.motion.coord.order() {
            Some((seq, order))
                if self.b_heard && self.link.carried(self.b.bolter_aux.seq, &order) =>
            {
                Some(BolterAux {
                    seq,
                    ..self.b.bolter_aux
                })
            }
            _ => None,
        };
        let a_aux = self.side_a.aux();
        let o = self
            .motion
            .coord
            .step(&self.cfg.bolter, now, &a_aux, b.as_ref());
        let order = o.order;
        self.side_a
            .order(order.map_or(0, |(s, _)| s), order.map(|(_, o)| o), now);
        let down = self.motion.coord.descend_only();
        if was == coordinator::Status::Running && o.status != coordinator::Status::Running && down {
            out.push(Event::BoltersDown {
                contact: a_aux.threshold_reached && b.is_some_and(|x| x.threshold_reached),
            });
            return;
        }
        if let (Some(p), coordinator::Status::Running, false) = (o.active, o.status, down) {
            if let Some((q, attempts)) = self.motion.pair.filter(|(q, _)| *q != p) {
                out.push(Event::Pair {
                    pair: q,
                    attempts,
                    ok: true,
                });
            }
            self.motion.pair = Some((p, o.attempt.get()));
        }
        if was == coordinator::Status::Running && o.status != coordinator::Status::Running {
            let ok = o.status == coordinator::Status::Done;
            if let Some((pair, attempts)) = self.motion.pair.take() {
                out.push(Event::Pair { pair, attempts, ok });
            }
            match o.status {
                coordinator::Status::Failed(f) => {
                    *faults = faults.with(f);
                    out.push(Event::Bolting(Some(f)));
                }
                _ => out.push(Event::Bolting(None)),
            }
        }
    }

    /// The A→B command to send now, if the link says one is due: side B's power (none in
    /// Standby), the hold flag, side B's servo targets and the bolter order.
    pub(super) fn b_command(
        &mut self,
        now: u32,
        p: ModuleSet,
        regulator: bool,
    ) -> Option<[u8; B_COMMAND_LEN]> {
        let live = self.sup.mode() != Mode::Standby;
        let snapshot = BCommandRepr {
            // Numbered by the link: every new snapshot gets a new number.
            seq: 0,
            power: BPower {
                regulator,
                arm: live && p.contains(Module::ArmB),
                gripper: live && p.contains(Module::GripperB),
                bolter: live && p.contains(Module::BolterB),
            },
            stop: self.hold_b,
            arm_target: self.cfg.arm.resolve(self.motion.targets.arm.b),
            gripper_target: self.cfg.gripper.resolve(self.motion.targets.gripper.b),
            bolter: self.motion.coord.order().map(|(_, o)| o),
        };
        let cmd = self.link.due(now, self.cfg.b_period_ms, snapshot)?;
        self.comm.sent(cmd.seq);
        Some(cmd.to_bytes())
    }
}
