//! The PUS path on the whole simulated robot (issue 15): the gateway
//! ([`mmic::node::server::gateway`]) in lock-step with boards A and B and the plant
//! (`mmic_host::sim::lockstep`, deterministic), the ground's PUS plan runner
//! ([`mmic::node::ground::pus`]) through the packets' bytes, and `mmic sim --protocol pus` end
//! to end (threads, UDP and TCP on loopback).

use mmic::ccsds::tm::TmRepr;
use mmic::command::{Command, Reconfiguration};
use mmic::faults::Fault;
use mmic::mode::Mode;
use mmic::motion::State;
use mmic::node::ground::plan_runner::{PlanEnd, PlanRunner, PlanStep};
use mmic::node::ground::pus::{self, MAX_TC_LEN};
use mmic::node::robot::board_a::Event;
use mmic::node::server::gateway::{Config, Gateway, Out, Tc};
use mmic::pus::request::Request;
use mmic::pus::verification::{Report, RequestId, Stage};
use mmic::refusal::Refusal;
use mmic::units::BoardNumber;
use mmic_host::sim::lockstep::Robot;
use mmic_host::sim::{report, run, LinkLayer, PlantConfig, Protocol, SimConfig, Summary};
use serde_json::Value;
use std::collections::{BTreeMap, BTreeSet};
use std::path::PathBuf;

const APID: u16 = 0x101;

/// A report the gateway sent, as the ground reads it back from the packet's bytes.
#[derive(Debug, Clone)]
struct Tm {
    at: u32,
    service: u8,
    subservice: u8,
    data: Vec<u8>,
}

impl Tm {
    fn st1(&self) -> Option<Report> {
        (self.service == 1)
            .then(|| Report::parse(self.subservice, &self.data).ok())
            .flatten()
    }
}

/// The gateway serving one lock-step robot: every 10 ms the gateway ticks, its legacy command
/// (if any) reaches board A in that tick, and board A's heartbeat goes back to the gateway.
/// Every report is written as a TM packet and parsed back.
struct Loop {
    g: Gateway<1, 8, 64>,
    r: Robot,
    tm: Vec<Tm>,
}

impl Loop {
    fn new(state: State) -> Loop {
        let mut g = Gateway::new(Config::default());
        assert!(g.add(BoardNumber::ONE));
        Loop {
            g,
            r: Robot::new(state, PlantConfig::default()),
            tm: Vec::new(),
        }
    }

    fn take<const M: usize>(&mut self, out: Out<M>) -> Vec<Tm> {
        assert_eq!(out.overflow, 0);
        let mut new = Vec::new();
        for t in &out.reports {
            let mut b = [0u8; 256];
            let n = self.g.encode(t, self.r.now, &mut b).expect("fits");
            let p = TmRepr::parse(&b[..n], &[APID]).expect("our TM parses");
            new.push(Tm {
                at: self.r.now,
                service: p.header.service,
                subservice: p.header.subservice,
                data: p.source_data.to_vec(),
            });
        }
        self.tm.extend(new.iter().cloned());
        new
    }

    /// A telecommand packet (ack: every report) from the ground; returns the reports it got.
    fn tc(&mut self, seq: u16, c: Command) -> Vec<Tm> {
        let tc = pus::TcOut {
            request: RequestId {
                apid: APID,
                seq_count: seq,
            },
            source_id: 1,
            command: c,
        };
        let mut b = [0u8; MAX_TC_LEN];
        let n = tc.emit(&mut b).expect("a function");
        let out = self.g.tc_packet(&b[..n]).expect("accepted packet");
        self.take(out)
    }

    /// One 10 ms tick of the gateway and the robot; returns the reports made.
    fn step(&mut self) -> Vec<Tm> {
        let now = self.r.now + mmic_host::sim::lockstep::TICK_MS;
        let out = self.g.tick(now);
        let command = out.to_robots.first().map(|(_, c)| *c);
        let mut new = self.take(out);
        match command {
            Some(c) => {
                if let Some(hb) = self.r.tick_with(Some(c)) {
                    let out = self.g.heartbeat(self.r.now, &hb);
                    new.extend(self.take(out));
                }
            }
            None => self.r.tick(),
        }
        new
    }

    /// Ticks until `pred` holds for a new report (returns it) or `max_ms` passed.
    fn until(&mut self, max_ms: u32, pred: impl Fn(&Tm) -> bool) -> Option<Tm> {
        let end = self.r.now + max_ms;
        while self.r.now < end {
            if let Some(t) = self.step().into_iter().find(|t| pred(t)) {
                return Some(t);
            }
        }
        None
    }

    /// The ST[1] report of `stage` for TC `seq`, waiting up to `max_ms`.
    fn report(&mut self, max_ms: u32, seq: u16, stage: Stage) -> Option<(u32, Report)> {
        if let Some(r) = self.reports(seq).into_iter().find(|r| r.1.stage == stage) {
            return Some(r);
        }
        self.until(max_ms, |t| {
            t.st1()
                .is_some_and(|r| r.request.seq_count == seq && r.stage == stage)
        })
        .and_then(|t| t.st1().map(|r| (t.at, r)))
    }

    /// Every ST[1] report about TC `seq` so far.
    fn reports(&self, seq: u16) -> Vec<(u32, Report)> {
        self.tm
            .iter()
            .filter_map(|t| t.st1().map(|r| (t.at, r)))
            .filter(|(_, r)| r.request.seq_count == seq)
            .collect()
    }

    /// When board A reached `s`.
    fn reached(&self, s: State) -> Option<u32> {
        self.r
            .events
            .iter()
            .find(|(_, e)| *e == Event::Reached(s))
            .map(|(t, _)| *t)
    }

    /// Operational (TC 0 completed) and the servos homed.
    fn operational(state: State) -> Loop {
        let mut l = Loop::new(state);
        l.tc(0, Command::Mode(Mode::Operational));
        let done = l.report(5_000, 0, Stage::Completion).expect("completed");
        assert_eq!(done.1.failure, None);
        let end = l.r.now + 10_000;
        while l.r.now < end && l.r.a.in_motion() {
            l.step();
        }
        assert!(!l.r.a.in_motion(), "homed");
        l
    }
}

fn reconfigure(from: State, to: State) -> Command {
    Command::Reconfigure(Reconfiguration::new(from, to).expect("matched states"))
}

#[test]
fn a_reconfiguration_completes_with_tm_1_7_only_once_the_robot_reached_its_target() {
    let mut l = Loop::operational(State::A);
    let tc = l.tc(1, reconfigure(State::A, State::M));
    assert_eq!(tc[0].st1().map(|r| r.stage), Some(Stage::Acceptance));
    let (started, r) = l.report(2_000, 1, Stage::Start).expect("started");
    assert_eq!(r.failure, None);
    let (completed, r) = l.report(60_000, 1, Stage::Completion).expect("completed");
    assert_eq!(r.failure, None, "{r:?}");
    let reached = l.reached(State::M).expect("board A reached m");
    assert!(
        started < reached && reached <= completed,
        "started {started}, reached {reached}, completed {completed}"
    );
    assert!(completed - started > 5_000, "the motion took its time");
    assert_eq!(l.r.a.state(), Some(State::M));
    // One report per stage: the reconfiguration ran once.
    let stages: Vec<Stage> = l.reports(1).iter().map(|(_, r)| r.stage).collect();
    assert_eq!(stages, [Stage::Acceptance, Stage::Start, Stage::Completion]);
    let runs =
        l.r.events
            .iter()
            .filter(|(_, e)| {
                matches!(
                    e,
                    Event::Executed {
                        command: Some(Command::Reconfigure(_)),
                        refusal: None,
                        ..
                    }
                )
            })
            .count();
    assert_eq!(runs, 1);
}

#[test]
fn a_stop_mid_motion_then_reset_completes_the_original_tc() {
    let mut l = Loop::operational(State::A);
    l.tc(1, reconfigure(State::A, State::B));
    l.report(2_000, 1, Stage::Start).expect("started");
    // a -> b turns the hip through 90°: stopped once it has turned 10°.
    let end = l.r.now + 40_000;
    while l.r.now < end && (l.r.hip() - 18_000.0).abs() <= 1_000.0 {
        l.step();
    }
    l.tc(2, Command::Stop);
    let (_, stop) = l.report(2_000, 2, Stage::Completion).expect("stop done");
    assert_eq!(stop.failure, None);
    // Held: no completion of the reconfiguration while stopped.
    let none = l.until(5_000, |t| t.st1().is_some_and(|r| r.request.seq_count == 1));
    assert!(none.is_none(), "{none:?}");
    assert_eq!(l.reached(State::B), None);
    l.tc(3, Command::Reset);
    let (_, reset) = l.report(2_000, 3, Stage::Completion).expect("reset done");
    assert_eq!(reset.failure, None);
    let (completed, r) = l.report(60_000, 1, Stage::Completion).expect("completed");
    assert_eq!(r.failure, None, "{r:?}");
    let reached = l.reached(State::B).expect("resumed to b");
    assert!(reached <= completed);
}

#[test]
fn a_fault_mid_motion_fails_the_tc_with_the_faults_code_and_an_event() {
    let mut l = Loop::operational(State::A);
    l.tc(1, reconfigure(State::A, State::M));
    l.report(2_000, 1, Stage::Start).expect("started");
    for _ in 0..200 {
        l.step();
    }
    // Board B cut off: internal comm loss, Safed.
    l.r.a_to_b = false;
    l.r.b_to_a = false;
    let (_, r) = l.report(5_000, 1, Stage::Completion).expect("ended");
    let f = r.failure.expect("a failure");
    let bit = Fault::InternalCommLoss.bit();
    assert_eq!(f.code, 0x0100 + u16::from(bit));
    assert_ne!(f.data & (1 << bit), 0, "the latched map has it");
    assert_eq!(l.reached(State::M), None);
    let events: Vec<(u16, Vec<u8>)> =
        l.tm.iter()
            .filter(|t| t.service == 5)
            .map(|t| {
                (
                    u16::from_be_bytes([t.data[0], t.data[1]]),
                    t.data[2..].to_vec(),
                )
            })
            .collect();
    let safed = Mode::Safed.to_wire();
    assert!(
        events.contains(&(0x0100 + u16::from(bit), vec![safed, 0, 0, 0])),
        "{events:?}"
    );
    assert!(
        events.contains(&(1, vec![Mode::Operational.to_wire(), safed, 0, 0])),
        "{events:?}"
    );
}

#[test]
fn a_deferred_fault_mid_motion_lets_the_tc_complete_then_standby() {
    // Table 8: low battery is deferred to the motion's end. The reconfiguration completes
    // (TM(1,7) when the robot reached its target), the fault is a medium-severity event
    // (TM(5,3)), and the robot is in Standby only after the motion completed.
    let mut l = Loop::operational(State::A);
    l.tc(1, reconfigure(State::A, State::M));
    l.report(2_000, 1, Stage::Start).expect("started");
    for _ in 0..100 {
        l.step();
    }
    assert!(l.r.a.in_motion());
    let sag = l.r.now;
    l.r.plant.config_mut().low_battery_at = Some(sag);
    let (done_at, r) = l.report(60_000, 1, Stage::Completion).expect("ended");
    assert_eq!(
        r.failure, None,
        "the motion completes despite the deferred fault"
    );
    let reached = l.reached(State::M).expect("reached its target");
    assert!(reached <= done_at);
    // Let the gateway see the Standby heartbeat after the completion.
    for _ in 0..100 {
        l.step();
    }
    let events: Vec<(u32, u8, u16, Vec<u8>)> =
        l.tm.iter()
            .filter(|t| t.service == 5)
            .map(|t| {
                (
                    t.at,
                    t.subservice,
                    u16::from_be_bytes([t.data[0], t.data[1]]),
                    t.data[2..].to_vec(),
                )
            })
            .collect();
    let bit = u16::from(Fault::LowBattery.bit());
    let fault = events
        .iter()
        .find(|e| e.2 == 0x0100 + bit)
        .unwrap_or_else(|| panic!("no low-battery event: {events:?}"));
    assert_eq!(fault.1, 3, "deferred: medium severity, TM(5,3)");
    assert!(fault.0 >= sag);
    let standby = events
        .iter()
        .find(|e| e.2 == 1 && e.3[1] == Mode::Standby.to_wire())
        .unwrap_or_else(|| panic!("no mode change to Standby: {events:?}"));
    assert!(standby.0 >= done_at, "Standby only after the completion");
    assert_eq!(l.r.a.mode(), Mode::Standby);
}

/// The ground's PUS plan runner against the gateway and the lock-step robot: every packet
/// crosses as bytes; `lose(k)` drops the k-th packet on the ground link (either way).
fn run_plan(
    steps: &[PlanStep],
    start: State,
    max_ms: u32,
    lose: impl Fn(usize) -> bool,
) -> (Option<PlanEnd>, Loop, Vec<Vec<u8>>) {
    let mut l = Loop::new(start);
    let mut run = PlanRunner::pus(pus::Config::default(), BoardNumber::ONE);
    let mut sent = Vec::new();
    let mut k = 0;
    let end = l.r.now + max_ms;
    while l.r.now < end {
        let t = run.tick(steps, l.r.now);
        if let Some(e) = t.end {
            return (Some(e), l, sent);
        }
        if let Some(tc) = t.send {
            let mut b = [0u8; MAX_TC_LEN];
            let n = tc.emit(&mut b).expect("a function");
            sent.push(b[..n].to_vec());
            k += 1;
            if !lose(k) {
                let out = l.g.tc_packet(&b[..n]).expect("accepted packet");
                for tm in l.take(out) {
                    k += 1;
                    if !lose(k) {
                        run.telemetry(steps, l.r.now, tm.service, tm.subservice, &tm.data);
                    }
                }
            }
        }
        for tm in l.step() {
            k += 1;
            if !lose(k) {
                run.telemetry(steps, l.r.now, tm.service, tm.subservice, &tm.data);
            }
        }
    }
    (run.end(), l, sent)
}

fn demo() -> Vec<PlanStep> {
    mmic_host::sim::demo_steps()
        .iter()
        .map(|s| s.step)
        .collect()
}

/// Board A's executions of commands other than heartbeat requests, per legacy number.
fn executions(l: &Loop) -> BTreeMap<u16, u32> {
    let mut m = BTreeMap::new();
    for (_, e) in &l.r.events {
        if let Event::Executed { seq, command, .. } = e {
            if *command != Some(Command::Heartbeat) {
                *m.entry(*seq).or_insert(0) += 1;
            }
        }
    }
    m
}

#[test]
fn the_pus_plan_runner_runs_the_demo_through_the_gateway_in_lock_step() {
    let steps = demo();
    let (end, l, sent) = run_plan(&steps, State::A, 400_000, |_| false);
    assert_eq!(end, Some(PlanEnd::Completed), "at {} ms", l.r.now);
    assert_eq!(l.r.a.state(), Some(State::N));
    // Every telecommand got its three reports, in order, each once.
    let keys: BTreeSet<u16> = sent
        .iter()
        .map(|b| u16::from_be_bytes([b[2], b[3]]) & 0x3FFF)
        .collect();
    let commands = steps
        .iter()
        .filter(|s| matches!(s, PlanStep::Command(_)))
        .count();
    assert_eq!(keys.len(), commands, "one telecommand per command step");
    for seq in &keys {
        let stages: Vec<Stage> = l.reports(*seq).iter().map(|(_, r)| r.stage).collect();
        let distinct: Vec<Stage> = stages.iter().fold(Vec::new(), |mut v, s| {
            if v.last() != Some(s) {
                v.push(*s);
            }
            v
        });
        assert_eq!(
            distinct,
            [Stage::Acceptance, Stage::Start, Stage::Completion],
            "TC {seq}: {stages:?}"
        );
    }
    assert!(executions(&l).values().all(|&n| n == 1));
    assert_eq!(executions(&l).len(), commands);
}

#[test]
fn lost_tcs_and_reports_are_resent_and_nothing_runs_twice() {
    let steps = demo();
    // Every fifth packet on the ground link lost, either way.
    let (end, l, sent) = run_plan(&steps, State::A, 600_000, |k| k % 5 == 0);
    assert_eq!(end, Some(PlanEnd::Completed), "at {} ms", l.r.now);
    let keys: BTreeSet<&[u8]> = sent.iter().map(|b| &b[2..4]).collect();
    assert!(sent.len() > keys.len() + 5, "resends went out");
    // A resend is the same packet, byte for byte.
    let mut by_key: BTreeMap<&[u8], BTreeSet<&Vec<u8>>> = BTreeMap::new();
    for b in &sent {
        by_key.entry(&b[2..4]).or_default().insert(b);
    }
    assert!(by_key.values().all(|v| v.len() == 1));
    assert!(
        executions(&l).values().all(|&n| n == 1),
        "{:?}",
        executions(&l)
    );
}

#[test]
fn a_refusal_ends_the_pus_plan_with_its_refusal() {
    // A reconfiguration from a state the robot is not in.
    let steps = [
        PlanStep::Command(Command::Mode(Mode::Operational)),
        PlanStep::Command(reconfigure(State::B, State::M)),
    ];
    let (end, l, _) = run_plan(&steps, State::A, 60_000, |_| false);
    assert!(
        matches!(
            end,
            Some(PlanEnd::Refused {
                step: 1,
                refusal: Refusal::InitialStateMismatch,
                ..
            })
        ),
        "{end:?}"
    );
    let start = l
        .reports(1)
        .into_iter()
        .find(|(_, r)| r.stage == Stage::Start);
    assert_eq!(
        start.and_then(|(_, r)| r.failure).map(|f| f.code),
        Some(u16::from(Refusal::InitialStateMismatch.to_wire()))
    );
}

#[test]
fn a_request_the_gateway_refuses_is_tc_1_2_and_runs_nothing() {
    let mut l = Loop::new(State::A);
    let out = l.g.tc(&Tc {
        request: RequestId {
            apid: APID,
            seq_count: 5,
        },
        source_id: 1,
        ack: 0b1111,
        request_of: Request::parse(8, 1, &[0xEE]),
    });
    let tm = l.take(out);
    assert_eq!(tm.len(), 1);
    assert_eq!(tm[0].subservice, 2);
}

// ---- mmic sim --protocol pus, end to end ----

fn out_dir(name: &str) -> PathBuf {
    let d = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn simulate(name: &str, mut cfg: SimConfig) -> (Summary, Vec<Value>) {
    cfg.protocol = Protocol::Pus;
    let path = out_dir(name).join("sim.jsonl");
    cfg.log_path = Some(path.clone());
    let s = run(&cfg).unwrap();
    let records: Vec<Value> = std::fs::read_to_string(&path)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    eprintln!("{name}:\n{}", report::text(&s));
    (s, records)
}

/// The TM packets the ground received, in order: (t_ms, the decoded packet).
fn tm_received(records: &[Value]) -> Vec<(u64, &Value)> {
    records
        .iter()
        .filter(|r| r["packet_kind"] == "tm" && r["fate"] == "delivered")
        .map(|r| (r["t_ms"].as_u64().unwrap(), &r["packet"]))
        .collect()
}

#[test]
fn the_demo_plan_completes_over_pus() {
    let (s, records) = simulate("pus_demo", SimConfig::demo());
    assert!(s.completed(), "{}", report::text(&s));
    assert_eq!(s.status["faults"], serde_json::json!([]));
    assert!(report::text(&s).contains("protocol: pus"));
    let tm = tm_received(&records);
    // Every telecommand got its acceptance, start and completion reports.
    let tcs: BTreeSet<u64> = records
        .iter()
        .filter(|r| r["packet_kind"] == "tc" && r["fate"] == "delivered")
        .map(|r| r["packet"]["seq_count"].as_u64().unwrap())
        .collect();
    assert_eq!(tcs.len(), 10, "one per command step of the demo");
    for seq in &tcs {
        let stages: BTreeSet<&str> = tm
            .iter()
            .filter(|(_, p)| p["service"] == 1 && p["report"]["seq_count"] == *seq)
            .inspect(|(_, p)| assert!(p["report"]["failure"].is_null(), "{p}"))
            .map(|(_, p)| p["report"]["stage"].as_str().unwrap())
            .collect();
        assert_eq!(
            stages,
            BTreeSet::from(["acceptance", "start", "completion"]),
            "TC {seq}"
        );
    }
    // Housekeeping every second (the gateway's default interval), unasked, from the first
    // heartbeat on; a visit of board A may hold one back by up to its 200 ms wait.
    let hk: Vec<u64> = tm
        .iter()
        .filter(|(_, p)| p["service"] == 3 && p["subservice"] == 25)
        .map(|(t, _)| *t)
        .collect();
    let span = hk.last().unwrap() - hk.first().unwrap();
    assert!(span + 1500 >= s.sim_ms as u64, "HK throughout the run");
    let expected = span / 1000 + 1;
    assert!(
        (hk.len() as u64).abs_diff(expected) <= 1,
        "{} HK reports over {span} ms",
        hk.len()
    );
    assert!(
        hk.windows(2).all(|w| (900..=1300).contains(&(w[1] - w[0]))),
        "{hk:?}"
    );
    // An ST[5] mode-change event for each of board A's mode changes, in order.
    let changes: Vec<(String, String)> = records
        .iter()
        .filter(|r| r["kind"] == "event" && r["node"] == "board_a1" && r["event"]["type"] == "mode")
        .map(|r| {
            let e = &r["event"];
            (e["from"].to_string(), e["to"].to_string())
        })
        .collect();
    let mode = |w: u64| {
        serde_json::to_value(Mode::from_wire(w as u8).unwrap())
            .unwrap()
            .to_string()
    };
    let events: Vec<(String, String)> = tm
        .iter()
        .filter(|(_, p)| p["service"] == 5 && p["report"]["event_id"] == 1)
        .map(|(_, p)| {
            let aux = p["report"]["aux"].as_str().unwrap();
            let b = |i: usize| u64::from_str_radix(&aux[i..i + 2], 16).unwrap();
            (mode(b(0)), mode(b(2)))
        })
        .collect();
    assert_eq!(changes.len(), 2, "standby -> operational -> standby");
    assert_eq!(events, changes);
    // Every packet logged with its hex and kind, on both links.
    for (link, kinds) in [
        ("udp_ground", ["tc", "tm"]),
        ("wifi", ["command", "heartbeat"]),
    ] {
        for k in kinds {
            assert!(
                records.iter().any(|r| r["link"] == link
                    && r["packet_kind"] == k
                    && r["hex"].as_str().is_some_and(|h| !h.is_empty())),
                "{link} {k}"
            );
        }
    }
    assert!(report::executed_twice(&s).is_empty());
}

#[test]
fn a_fault_over_pus_fails_its_tc_and_is_reported_as_an_event() {
    // The arm meets an obstacle during `reconfigure a -> m` (22-34 s over PUS): Safed.
    let mut cfg = SimConfig {
        scale: 20.0,
        max_sim_ms: 120_000,
        ..SimConfig::demo()
    };
    cfg.inject("locomotion-overcurrent@28".parse().unwrap())
        .unwrap();
    let (s, records) = simulate("pus_overcurrent", cfg);
    assert!(
        matches!(
            s.ends[0],
            Some(PlanEnd::Interrupted {
                mode: Mode::Safed,
                ..
            })
        ),
        "{:?}",
        s.ends
    );
    let tm = tm_received(&records);
    let failed: Vec<u64> = tm
        .iter()
        .filter(|(_, p)| p["service"] == 1 && p["subservice"] == 8)
        .map(|(_, p)| p["report"]["failure"]["code"].as_u64().unwrap())
        .collect();
    assert_eq!(failed.len(), 1, "{failed:?}");
    let bit = failed[0] - 0x0100;
    let fault = Fault::ALL
        .into_iter()
        .find(|f| u64::from(f.bit()) == bit)
        .expect("a fault's code");
    assert_eq!(
        fault.table8(),
        Some(mmic::faults::Table8::LocomotionOvercurrent)
    );
    let event = tm
        .iter()
        .find(|(_, p)| p["service"] == 5 && p["report"]["event_id"] == failed[0]);
    assert!(event.is_some(), "the fault's ST[5] event");
    assert_eq!(
        event.unwrap().1["subservice"],
        4,
        "high severity: it safes the robot"
    );
}

// req: P7.18, T8/hip_mismatch
#[test]
fn hip_mismatch_at_power_up_over_pus_refuses_the_next_step() {
    let mut cfg = SimConfig {
        scale: 20.0,
        max_sim_ms: 60_000,
        ..SimConfig::demo()
    };
    cfg.inject("hip-mismatch@0".parse().unwrap()).unwrap();
    let (s, records) = simulate("pus_hip_mismatch", cfg);
    assert!(
        matches!(
            s.ends[0],
            Some(PlanEnd::Refused {
                refusal: Refusal::NotAllowedInMode,
                robot: Some((Mode::Safed, _)),
                ..
            })
        ),
        "{:?}",
        s.ends
    );
    let tm = tm_received(&records);
    let code = u64::from(Refusal::NotAllowedInMode.to_wire());
    assert!(tm.iter().any(|(_, p)| p["service"] == 1
        && p["subservice"] == 4
        && p["report"]["failure"]["code"] == code));
    let hip = 0x0100 + u64::from(Fault::HipMismatch.bit());
    assert!(tm
        .iter()
        .any(|(_, p)| p["service"] == 5 && p["report"]["event_id"] == hip));
    assert_eq!(report::last_mode(&s), "safed");
}

#[test]
fn the_demo_completes_over_the_space_data_link_with_loss_and_runs_nothing_twice() {
    // The acceptance run: `mmic sim --protocol pus --link frames --wifi-loss 0.3
    // --serial-loss 0.2` (the serial loss is the ground link's: every TC and TM frame).
    let cfg = SimConfig {
        link: LinkLayer::Frames,
        wifi_loss: 0.3,
        serial_loss: 0.2,
        ..SimConfig::demo()
    };
    let (s, records) = simulate("pus_frames_lossy", cfg.clone());
    assert!(s.completed(), "{}", report::text(&s));
    assert!(report::executed_twice(&s).is_empty());
    let f = s.frames.expect("the link's figures");
    assert!(f.retransmissions > 0 && f.tm_lost > 0, "{f:?}");
    assert_eq!(f.lockout_reports, 0, "{f:?}");
    assert!(
        f.clcws * 2 > f.tm_frames,
        "most TM frames reach the ground: {f:?}"
    );
    assert!(report::text(&s).contains("link: frames"));
    // Frames on the ground link, decoded in the log; packets nowhere else on it.
    let kinds: BTreeSet<&str> = records
        .iter()
        .filter(|r| r["kind"] == "packet" && r["link"] == "udp_ground")
        .filter_map(|r| r["packet_kind"].as_str())
        .collect();
    assert_eq!(kinds, BTreeSet::from(["tc_frame", "tm_frame"]));
    // Virtual time: the same seed gives the same run.
    let again = run(&SimConfig {
        protocol: Protocol::Pus,
        log_path: None,
        ..cfg
    })
    .unwrap();
    assert_eq!(again.frames, s.frames);
    assert_eq!(again.sim_ms, s.sim_ms);
}
