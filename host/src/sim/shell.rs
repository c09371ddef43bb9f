//! What every engine's shells share: one control tick of each side of a robot (sensors in
//! through the library's front end, the board's tick, the plant driven), board A's events as
//! JSON, and the ground's side of a run (plan runners, injections, what is logged). The
//! threaded realtime engine ([`super::realtime`]), the virtual-time engine ([`super::engine`])
//! and the lock-step robot ([`super::lockstep`]) all run the robot through these, so the three
//! paths run the same node code and differ only in how bytes and time reach it.

use super::inject::{self, Scheduled};
use super::log::Log;
use super::plant::{Drives, Plant, Senses};
use super::progress::Progress;
use super::steps::SimStep;
use mmic::motion::State;
use mmic::node::exactly_once::uplink::Efficiency;
use mmic::node::ground::plan_runner::{Link, PlanEnd, PlanRunner, PlanStep, PlanTick};
use mmic::node::ground::pus::{self, TcLink, TcOut};
use mmic::node::robot::board_a::{self, BoardA, Event};
use mmic::node::robot::board_b::{self, BoardB};
use mmic::sensors::frontend::{self, Frontend, WINDOW};
use mmic::wire::b_command::B_COMMAND_LEN;
use mmic::wire::command::{CommandRepr, COMMAND_LEN};
use mmic::wire::deframer::{Deframed, Deframer, Frame};
use mmic::wire::heartbeat::HeartbeatRepr;
use mmic::wire::internal_heartbeat::INTERNAL_HEARTBEAT_LEN;
use serde_json::{json, Value};

/// Board A's control side: the library's board A and side A's sensor front end.
pub struct SideA {
    /// The library's board A.
    pub board: BoardA,
    /// Side A's front end (with the hip encoder).
    pub sensors: Frontend<WINDOW>,
    /// What the last tick sensed (`mmic sim --record` writes it to the trace).
    pub sensed: Option<Senses>,
}

impl SideA {
    /// Board A with side A's front end, empty.
    pub fn new(board: BoardA) -> SideA {
        SideA {
            board,
            sensors: Frontend::new(frontend::Config::default()),
            sensed: None,
        }
    }

    /// One control tick at `now`: the plant advanced to `now` and sensed on side A, the
    /// readings through the front end, board A's tick with `command` (from the WiFi hand-off
    /// queue) and `from_b` (board B's serial line), and the plant driven with the outputs (a
    /// state reached sets the plant's pose).
    pub fn tick(
        &mut self,
        plant: &mut Plant,
        now: u32,
        command: Option<[u8; COMMAND_LEN]>,
        from_b: Option<[u8; INTERNAL_HEARTBEAT_LEN]>,
    ) -> board_a::Outputs {
        tick_a_into(
            &mut self.board,
            &mut self.sensors,
            plant,
            now,
            command,
            from_b,
            &mut self.sensed,
        )
    }

    /// Board A's mode, faults, state and motion for a run's summary, at `now`.
    pub fn status(&self, now: u32) -> Value {
        let a = &self.board;
        json!({
            "mode": a.mode(), "faults": a.faults(), "state": a.state(),
            "in_motion": a.in_motion(), "t_ms": now,
        })
    }
}

/// Board B's side: the library's board B and side B's sensor front end (no hip encoder).
pub struct SideB {
    /// The library's board B.
    pub board: BoardB,
    /// Side B's front end.
    pub sensors: Frontend<WINDOW>,
    /// What the last tick sensed (`mmic sim --record` writes it to the trace).
    pub sensed: Option<Senses>,
}

impl SideB {
    /// Board B with side B's front end, empty.
    pub fn new(board: BoardB) -> SideB {
        SideB {
            board,
            sensors: Frontend::new(frontend::Config {
                hip_encoder: false,
                ..frontend::Config::default()
            }),
            sensed: None,
        }
    }

    /// One tick at `now`: side B sensed (the plant is advanced by board A's ticks), the
    /// readings through the front end, board B's tick with `command` (board A's serial line),
    /// and side B of the plant driven.
    pub fn tick(
        &mut self,
        plant: &mut Plant,
        now: u32,
        command: Option<[u8; B_COMMAND_LEN]>,
    ) -> board_b::Outputs {
        tick_b_into(
            &mut self.board,
            &mut self.sensors,
            plant,
            now,
            command,
            &mut self.sensed,
        )
    }
}

/// [`SideA::tick`] on its parts.
pub fn tick_a(
    board: &mut BoardA,
    sensors: &mut Frontend<WINDOW>,
    plant: &mut Plant,
    now: u32,
    command: Option<[u8; COMMAND_LEN]>,
    from_b: Option<[u8; INTERNAL_HEARTBEAT_LEN]>,
) -> board_a::Outputs {
    tick_a_into(board, sensors, plant, now, command, from_b, &mut None)
}

/// [`tick_a`], also writing what side A sensed to `sensed`: the outputs are returned straight from
/// board A's tick, not moved through a tuple (board A's [`board_a::Outputs`], its events
/// inline, is the biggest value of a tick; the swarm runs this one twice a simulated 10 ms).
pub fn tick_a_into(
    board: &mut BoardA,
    sensors: &mut Frontend<WINDOW>,
    plant: &mut Plant,
    now: u32,
    command: Option<[u8; COMMAND_LEN]>,
    from_b: Option<[u8; INTERNAL_HEARTBEAT_LEN]>,
    sensed: &mut Option<Senses>,
) -> board_a::Outputs {
    plant.advance(now);
    let s = plant.sense(0, now);
    *sensed = Some(s);
    let f = sensors.push(&s.raw);
    let inputs = board_a::Inputs::sensed(&f, s.arm_contracted, s.bolter_at_home, command, from_b);
    let out = board.tick(now, &inputs);
    plant.drive_a(
        Drives {
            arm: out.arm,
            gripper: out.gripper,
            regulator: out.regulator,
            bolter: out.bolter,
            mux: out.mux,
        },
        out.hip,
    );
    for e in &out.events {
        if let Event::Reached(st) = e {
            plant.set_state(*st);
        }
    }
    out
}

/// [`SideB::tick`] on its parts.
pub fn tick_b(
    board: &mut BoardB,
    sensors: &mut Frontend<WINDOW>,
    plant: &mut Plant,
    now: u32,
    command: Option<[u8; B_COMMAND_LEN]>,
) -> board_b::Outputs {
    tick_b_into(board, sensors, plant, now, command, &mut None)
}

/// [`tick_b`], writing what side B sensed to `sensed` (as [`tick_a_into`]).
pub fn tick_b_into(
    board: &mut BoardB,
    sensors: &mut Frontend<WINDOW>,
    plant: &mut Plant,
    now: u32,
    command: Option<[u8; B_COMMAND_LEN]>,
    sensed: &mut Option<Senses>,
) -> board_b::Outputs {
    let s = plant.sense(1, now);
    *sensed = Some(s);
    let f = sensors.push(&s.raw);
    let inputs = board_b::Inputs::sensed(&f, s.arm_contracted, s.bolter_at_home, command);
    let out = board.tick(now, &inputs);
    plant.drive_b(Drives {
        arm: out.arm,
        gripper: out.gripper,
        regulator: out.regulator,
        bolter: out.bolter,
        mux: out.mux,
    });
    out
}

/// The packets a deframer finds in `bytes` (a stream's next read).
pub fn frames(d: &mut Deframer<256>, bytes: &[u8]) -> Vec<Frame> {
    let mut out = Vec::new();
    d.feed(bytes, |e| {
        if let Deframed::Frame(f) = e {
            out.push(f);
        }
    });
    out
}

/// Board A's event as JSON.
pub fn event_json(e: &Event) -> Value {
    match e {
        Event::Executed {
            seq,
            command,
            refusal,
        } => json!({"type": "executed", "seq": seq, "command": command, "refusal": refusal}),
        Event::Duplicate { seq } => json!({"type": "duplicate", "seq": seq}),
        Event::Stale { seq } => json!({"type": "stale", "seq": seq}),
        Event::Rejected(w) => json!({"type": "rejected", "error": w.to_string()}),
        Event::OtherRobot { board } => json!({"type": "other_robot", "board": board.get()}),
        Event::Faults(f) => json!({"type": "faults", "faults": f}),
        Event::Mode { from, to } => json!({"type": "mode", "from": from, "to": to}),
        Event::Reached(s) => json!({"type": "reached", "state": s}),
        Event::Bolting(f) => json!({"type": "bolting", "fault": f}),
        Event::Pair { pair, attempts, ok } => {
            json!({"type": "pair", "pair": pair.number(), "attempts": attempts, "ok": ok})
        }
        Event::BoltersDown { contact } => json!({"type": "bolters_down", "contact": contact}),
        Event::Paused => json!({"type": "paused"}),
        Event::Resumed => json!({"type": "resumed"}),
    }
}

/// The ground's part of an injection: an out-of-band command handed to the plan runner, or
/// the next reconfiguration misstated; nothing for the plant's and the line's. Returns why
/// the runner did not take the command, if it did not.
fn ground_injection<L: Link>(
    run: &mut PlanRunner<L>,
    injection: inject::Injection,
) -> Option<String> {
    if let Some(c) = injection.command() {
        return run.interject(c).err().map(|e| e.to_string());
    }
    if injection == inject::Injection::Fault(mmic::faults::Table8::InitialStateMismatch) {
        run.misstate_next_reconfiguration();
    }
    None
}

/// The ground's plan runner over one protocol: ticks, packets from the server board in,
/// packets to it out.
pub trait Ground {
    /// What the runner sends.
    type Packet: Copy;
    /// Advances to `now`.
    fn tick(&mut self, steps: &[PlanStep], now: u32) -> PlanTick<Self::Packet>;
    /// A packet from the server board: what the runner made of it, and whether it answered
    /// the command outstanding (for the latency); none if it is no packet of the protocol.
    fn receive(
        &mut self,
        steps: &[PlanStep],
        now: u32,
        bytes: &[u8],
    ) -> Option<(PlanTick<Self::Packet>, bool)>;
    /// A packet's bytes.
    fn bytes(p: &Self::Packet) -> Vec<u8>;
    /// A packet's sequence number (the legacy command's, the telecommand's sequence count):
    /// the number its command's `done` carries.
    fn seq(p: &Self::Packet) -> u16;
    /// The robot's status as last reported (a heartbeat, or a housekeeping report).
    fn status(&self) -> Option<HeartbeatRepr>;
    /// The attempts answered, Figure 11.
    fn efficiency(&self) -> Efficiency;
    /// An injection's ground part: an out-of-band command handed to the runner, or the next
    /// reconfiguration misstated; returns why the runner did not take it, if it did not.
    fn inject(&mut self, injection: inject::Injection) -> Option<String>;
    /// The runner after the ground restarted: from what its disk kept (the plan's position,
    /// the link's numbering: decision `restart-ground`), the rest lost.
    fn restarted(&self) -> Self
    where
        Self: Sized;
}

/// The legacy ground: the plan runner over the uplink, and the last heartbeat.
pub struct LegacyGround {
    /// The plan runner.
    pub run: PlanRunner,
    /// The last heartbeat received.
    pub last: Option<HeartbeatRepr>,
}

impl Ground for LegacyGround {
    type Packet = CommandRepr;

    fn tick(&mut self, steps: &[PlanStep], now: u32) -> PlanTick {
        self.run.tick(steps, now)
    }

    fn receive(&mut self, steps: &[PlanStep], now: u32, bytes: &[u8]) -> Option<(PlanTick, bool)> {
        let hb = HeartbeatRepr::parse(bytes).ok()?;
        let answers = hb.last_seq == self.run.uplink().outstanding().unwrap_or(0);
        self.last = Some(hb);
        Some((self.run.heartbeat(steps, now, &hb), answers))
    }

    fn bytes(p: &CommandRepr) -> Vec<u8> {
        p.to_bytes().to_vec()
    }

    fn seq(p: &CommandRepr) -> u16 {
        p.seq
    }

    fn status(&self) -> Option<HeartbeatRepr> {
        self.last
    }

    fn efficiency(&self) -> Efficiency {
        self.run.uplink().efficiency()
    }

    fn inject(&mut self, injection: inject::Injection) -> Option<String> {
        ground_injection(&mut self.run, injection)
    }

    fn restarted(&self) -> LegacyGround {
        LegacyGround {
            run: PlanRunner::restarted(self.run.uplink().restarted(), self.run.kept()),
            last: None,
        }
    }
}

impl Ground for PlanRunner<TcLink> {
    type Packet = TcOut;

    fn tick(&mut self, steps: &[PlanStep], now: u32) -> PlanTick<TcOut> {
        PlanRunner::tick(self, steps, now)
    }

    fn receive(
        &mut self,
        steps: &[PlanStep],
        now: u32,
        bytes: &[u8],
    ) -> Option<(PlanTick<TcOut>, bool)> {
        let tm = mmic::ccsds::tm::TmRepr::parse(bytes, &[self.uplink().apid()]).ok()?;
        let h = tm.header;
        let answers = h.service == mmic::pus::request::ST_VERIFICATION
            && mmic::pus::verification::Report::parse(h.subservice, tm.source_data)
                .is_ok_and(|r| Some(r.request.seq_count) == self.uplink().outstanding());
        let t = self.telemetry(steps, now, h.service, h.subservice, tm.source_data);
        Some((t, answers))
    }

    fn bytes(p: &TcOut) -> Vec<u8> {
        let mut b = [0u8; pus::MAX_TC_LEN];
        match p.emit(&mut b) {
            Ok(n) => b.get(..n).unwrap_or(&[]).to_vec(),
            Err(_) => Vec::new(),
        }
    }

    fn seq(p: &TcOut) -> u16 {
        p.request.seq_count
    }

    fn status(&self) -> Option<HeartbeatRepr> {
        self.uplink().status()
    }

    fn efficiency(&self) -> Efficiency {
        self.uplink().efficiency()
    }

    fn inject(&mut self, injection: inject::Injection) -> Option<String> {
        ground_injection(self, injection)
    }

    fn restarted(&self) -> PlanRunner<TcLink> {
        PlanRunner::restarted(self.uplink().restarted(), self.kept())
    }
}

/// What the ground measured over a run.
#[derive(Debug, Clone, Default)]
pub struct GroundStats {
    /// Simulated time when the ground stopped, ms.
    pub sim_ms: u32,
    /// (simulated s, efficiency % over the last 100 attempts) after each attempt, robot 1.
    pub efficiency: Vec<(f64, f64)>,
    /// Attempts answered in time and attempts made, all robots.
    pub attempts: (u64, u64),
    /// Longest command-to-answer time observed, ms.
    pub max_latency_ms: u32,
    /// Robot 1's last heartbeat as the ground received it.
    pub last_heartbeat: Option<HeartbeatRepr>,
}

/// The ground's side of a run (one ground process): a plan runner per robot, the injections
/// it makes, and what it logs (`inject`, `attempt`, `done`, `step`, `plan_end` events) and
/// measures. Each engine calls [`GroundSide::tick`] for every robot in its loop and
/// [`GroundSide::receive`] for every packet from a server board, and writes the packets they
/// return to that robot's link.
pub struct GroundSide<G: Ground> {
    steps: Vec<PlanStep>,
    plan: Vec<SimStep>,
    injections: Vec<Scheduled>,
    runners: Vec<G>,
    ends: Vec<Option<PlanEnd>>,
    sent_at: Vec<Option<u32>>,
    /// Per robot: the commands sent and not yet done, by number, with their first
    /// transmission's time.
    open: Vec<std::collections::BTreeMap<u16, u32>>,
    /// Per robot: the numbers of the last commands done. A link may transmit a command again
    /// after it is done (the PUS link asks about a started motion until its completion
    /// report): such a transmission opens nothing.
    recent: Vec<std::collections::VecDeque<u16>>,
    next_injection: Vec<usize>,
    stats: GroundStats,
    progress: Progress,
    log: Option<Log>,
}

impl<G: Ground> GroundSide<G> {
    /// One runner per robot for `plan`, the run's injections (in time order), progress on
    /// stderr or not, the log.
    pub fn new(
        plan: &[SimStep],
        start: State,
        injections: &[Scheduled],
        runners: Vec<G>,
        progress: bool,
        log: Option<Log>,
    ) -> GroundSide<G> {
        let n = runners.len();
        GroundSide {
            steps: plan.iter().map(|s| s.step).collect(),
            plan: plan.to_vec(),
            injections: injections.to_vec(),
            runners,
            ends: vec![None; n],
            sent_at: vec![None; n],
            open: vec![Default::default(); n],
            recent: vec![Default::default(); n],
            next_injection: vec![0; n],
            stats: GroundStats::default(),
            progress: Progress::new(progress, plan.to_vec(), start),
            log,
        }
    }

    /// Every robot's plan has ended.
    pub fn all_ended(&self) -> bool {
        self.ends.iter().all(Option::is_some)
    }

    /// Every robot's plan has ended and every command sent has ended too (a plan can end
    /// with an out-of-band command still outstanding: its link goes on until that command is
    /// answered or given up, and its outcome is logged like any other).
    pub fn all_done(&self) -> bool {
        self.all_ended() && self.open.iter().all(|m| m.is_empty())
    }

    fn event(&self, now: u32, what: Value) {
        if let Some(l) = &self.log {
            l.event(now, "ground", what);
        }
    }

    /// Robot `i` at `now`: the injections due, then the runner's tick. Returns the packet to
    /// send to its server board. A runner whose plan ended still runs its link (resends and
    /// answers of a command outstanding when the plan ended; an injection is then refused by
    /// the runner, and logged so). One packet at most, as an `Option` rather than a vector: the
    /// engines call this every 10 ms per robot, and most calls send nothing.
    pub fn tick(&mut self, i: usize, now: u32) -> Option<Vec<u8>> {
        self.stats.sim_ms = self.stats.sim_ms.max(now);
        if i >= self.runners.len() {
            return None;
        }
        while let Some(inj) = self
            .injections
            .get(self.next_injection[i])
            .filter(|s| s.at_ms <= now)
            .copied()
        {
            self.next_injection[i] += 1;
            let refused = self.runners[i].inject(inj.injection);
            if i == 0 {
                self.progress.inject(now, inj.injection);
            }
            self.event(
                now,
                json!({"type": "inject", "robot": i + 1, "name": inj.injection.name(),
                       "at_ms": inj.at_ms, "refused": refused}),
            );
        }
        let t = self.runners[i].tick(&self.steps, now);
        self.handle(i, now, t)
    }

    /// A packet from robot `i`'s server board at `now`; returns the packet to send, if any.
    pub fn receive(&mut self, i: usize, now: u32, bytes: &[u8]) -> Option<Vec<u8>> {
        if i >= self.runners.len() {
            return None;
        }
        let (t, answers) = self.runners[i].receive(&self.steps, now, bytes)?;
        if let (Some(s), true) = (self.sent_at[i], answers) {
            self.stats.max_latency_ms = self.stats.max_latency_ms.max(now.saturating_sub(s));
        }
        self.handle(i, now, t)
    }

    /// Logs and measures one tick's outcome; the packet to send, if any.
    fn handle(&mut self, i: usize, now: u32, t: PlanTick<G::Packet>) -> Option<Vec<u8>> {
        let send = t.send.map(|p| {
            self.sent_at[i] = Some(now);
            let seq = G::seq(&p);
            if !self.recent[i].contains(&seq) {
                self.open[i].entry(seq).or_insert(now);
            }
            G::bytes(&p)
        });
        if let Some(ok) = t.attempt {
            self.stats.attempts.1 += 1;
            self.stats.attempts.0 += ok as u64;
            if i == 0 {
                let e = self.runners[i].efficiency().percent().unwrap_or(0);
                self.stats.efficiency.push((now as f64 / 1000.0, e as f64));
            }
            self.event(now, json!({"type": "attempt", "robot": i + 1, "ok": ok}));
        }
        if let Some(d) = t.done {
            self.open[i].remove(&d.seq);
            let recent = &mut self.recent[i];
            if recent.len() >= 16 {
                recent.pop_front();
            }
            recent.push_back(d.seq);
            self.event(
                now,
                json!({
                    "type": "done", "robot": i + 1, "seq": d.seq, "command": d.command,
                    "outcome": d.outcome, "attempts": d.attempts,
                }),
            );
        }
        if let (Some(k), 0) = (t.started, i) {
            self.progress.step(now, k);
            if let Some(s) = self.plan.get(k) {
                self.event(
                    now,
                    json!({"type": "step", "robot": 1, "step": k + 1,
                           "line": s.line, "text": s.text}),
                );
            }
        }
        if let (Some(e), None) = (t.end, self.ends[i]) {
            self.ends[i] = Some(e);
            self.event(
                now,
                json!({"type": "plan_end", "robot": i + 1, "end": format!("{e:?}")}),
            );
        }
        send
    }

    /// Robot `i`'s ground restarted at `now` (its runner from what the disk kept): every
    /// command it had open ends, logged as lost with the RAM (`ended_unknown`: it ran at most
    /// once); a plan whose step was open ends [`PlanEnd::Restarted`].
    pub fn restart(&mut self, i: usize, now: u32) {
        let Some(r) = self.runners.get(i) else { return };
        let fresh = r.restarted();
        self.runners[i] = fresh;
        for (seq, since) in std::mem::take(&mut self.open[i]) {
            self.event(
                now,
                json!({"type": "ended_unknown", "robot": i + 1, "seq": seq, "open_since_ms": since,
                       "why": "the ground restarted"}),
            );
        }
        // The plan's end, if the restart ended it, comes with the runner's next tick.
        self.sent_at[i] = None;
    }

    /// Robot `i`'s commands sent and not done (number, first transmission's time, ms): at most
    /// the one outstanding, as the runner sends one command at a time.
    pub fn open_commands(&self, i: usize) -> Vec<(u16, u32)> {
        self.open
            .get(i)
            .map(|m| m.iter().map(|(s, t)| (*s, *t)).collect())
            .unwrap_or_default()
    }

    /// Live progress from robot 1's last status, at `now`.
    pub fn progress(&mut self, now: u32) {
        if let Some(r) = self.runners.first() {
            if let Some(hb) = r.status() {
                self.progress.status(now, &hb, r.efficiency());
            }
        }
    }

    /// Ends the run at `now`: how each plan ended (none: still running) and what was measured.
    pub fn finish(mut self, now: u32) -> (Vec<Option<PlanEnd>>, GroundStats) {
        self.progress.finish();
        self.stats.sim_ms = self.stats.sim_ms.max(now);
        self.stats.last_heartbeat = self.runners.first().and_then(Ground::status);
        (self.ends, self.stats)
    }
}
