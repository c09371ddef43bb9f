//! `mmic ground`: the Rust side of the ground interop tests (ground/): packets made by the real
//! PUS gateway ([`mmic::node::server::gateway::Gateway`]) for Python `spacepackets`, `ccsdspy` and
//! YAMCS to read, and a UDP stand-in robot for the YAMCS loop.
//!
//! Both put a trivial stand-in for board A ([`StubBoardA`]) behind the gateway: it takes every
//! legacy command at once, changes mode when told, refuses motions outside Operational
//! (`not_allowed_in_mode`) and completes a motion after a fixed time. It is no model of the
//! robot — `mmic sim --protocol pus` is (ground/README.md says how to plug it in instead); it
//! only lets the real gateway make every report it makes.

use crate::pus::{decode_tc, decode_tm, encode_tc};
use mmic::bolter::{BolterAttempt, BolterPair};
use mmic::command::Command;
use mmic::faults::{Fault, Faults};
use mmic::mode::Mode;
use mmic::motion::State;
use mmic::node::server::gateway::{Config, Gateway, Out};
use mmic::refusal::Refusal;
use mmic::units::{BoardNumber, Electrical, HipAngle, PulseWidth};
use mmic::wire::command::CommandRepr;
use mmic::wire::heartbeat::HeartbeatRepr;
use serde_json::{json, Value};
use std::io::Write;
use std::net::UdpSocket;
use std::path::Path;
use std::time::{Duration, Instant};

/// The gateway of the ground tools: one robot, 8 queued telecommands, 64 remembered keys.
pub type OneRobot = Gateway<1, 8, 64>;

/// A stand-in for board A behind the gateway (see the module docs).
#[derive(Debug, Clone)]
pub struct StubBoardA {
    /// What its next heartbeat says.
    pub hb: HeartbeatRepr,
    /// How long a motion takes, ms.
    pub motion_ms: u32,
    done_at: Option<u32>,
}

impl StubBoardA {
    /// Robot `board` in Standby.
    pub fn new(board: BoardNumber, motion_ms: u32) -> StubBoardA {
        StubBoardA {
            hb: HeartbeatRepr {
                board,
                ..HeartbeatRepr::default()
            },
            motion_ms,
            done_at: None,
        }
    }

    /// A legacy command arrives at `now`; returns the heartbeat that answers it.
    pub fn command(&mut self, now: u32, c: &CommandRepr) -> HeartbeatRepr {
        self.tick(now);
        if c.seq == self.hb.last_seq {
            return self.hb; // a resend: answered, not run again
        }
        self.hb.last_seq = c.seq;
        self.hb.refusal = None;
        match c.command {
            Command::Mode(m) => self.hb.mode = m,
            cmd if cmd.kind().moves() => {
                if self.hb.mode != Mode::Operational {
                    self.hb.refusal = Some(Refusal::NotAllowedInMode);
                } else {
                    if let Command::Reconfigure(r) = cmd {
                        self.hb.target_state = Some(r.target());
                    }
                    self.hb.command_complete = false;
                    self.done_at = Some(now.wrapping_add(self.motion_ms));
                }
            }
            _ => {}
        }
        self.hb
    }

    /// Time passes: a motion completes when its time is up.
    pub fn tick(&mut self, now: u32) {
        if let Some(t) = self.done_at {
            if now.wrapping_sub(t) < u32::MAX / 2 {
                self.done_at = None;
                self.hb.command_complete = true;
            }
        }
    }
}

/// The gateway and the stand-in together, with every packet they make encoded.
pub struct Bench {
    /// The real gateway.
    pub gateway: OneRobot,
    /// Board A's stand-in.
    pub board: StubBoardA,
    /// Every TM packet so far, in order, with the time it was made.
    pub tm: Vec<(u32, Vec<u8>)>,
}

impl Bench {
    /// Robot 1, gateway with its default configuration but `hk_ms`.
    pub fn new(hk_ms: u32, motion_ms: u32) -> Bench {
        let mut gateway = OneRobot::new(Config {
            hk_interval_ms: hk_ms,
            ..Config::default()
        });
        gateway.add(BoardNumber::ONE);
        Bench {
            gateway,
            board: StubBoardA::new(BoardNumber::ONE, motion_ms),
            tm: Vec::new(),
        }
    }

    fn take<const M: usize>(&mut self, now: u32, out: Out<M>) -> usize {
        let mut n = 0;
        for tm in &out.reports {
            let mut buf = [0u8; mmic::ccsds::MAX_PACKET_LEN];
            if let Ok(len) = self.gateway.encode(tm, now, &mut buf) {
                self.tm.push((now, buf[..len].to_vec()));
                n += 1;
            }
        }
        for (_, c) in &out.to_robots {
            let hb = self.board.command(now, c);
            let more = self.gateway.heartbeat(now, &hb);
            n += self.take(now, more);
        }
        n
    }

    /// A TC packet from the ground; its refusal's name if the CCSDS layer refuses it.
    pub fn tc(&mut self, now: u32, bytes: &[u8]) -> Result<usize, &'static str> {
        match self.gateway.tc_packet(bytes) {
            Ok(out) => Ok(self.take(now, out)),
            Err(e) => Err(e.name()),
        }
    }

    /// Time passes to `now`.
    pub fn tick(&mut self, now: u32) -> usize {
        self.board.tick(now);
        let out = self.gateway.tick(now);
        self.take(now, out)
    }

    /// Runs ticks every 10 ms from `from` to `to`.
    pub fn run(&mut self, from: u32, to: u32) {
        let mut t = from;
        while t <= to {
            self.tick(t);
            t += 10;
        }
    }

    /// A heartbeat as if board A had sent one by itself (for changes the stand-in does not
    /// make: faults, bolting attempts).
    pub fn set(&mut self, now: u32, hb: HeartbeatRepr) {
        self.board.hb = hb;
        let out = self.gateway.heartbeat(now, &hb);
        self.take(now, out);
    }
}

fn tc(json: &str) -> Vec<u8> {
    encode_tc(json).unwrap_or_default()
}

/// Heartbeats with the edge values of every housekeeping parameter.
pub fn edge_heartbeats() -> Vec<HeartbeatRepr> {
    // Seven different values per side, so that two fields swapped anywhere show.
    let e = |v: u16| Electrical {
        v_bat: v,
        i_bat: !v,
        i_loc: v.wrapping_add(1),
        i_grip: !v.wrapping_add(1),
        i_3v3: v ^ 0x0F0F,
        v_reg: v.rotate_left(3),
        i_bo: v.wrapping_add(7),
    };
    let pw = |us| PulseWidth::new(us).unwrap_or(PulseWidth::CENTER);
    let all = Faults::from_iter(Fault::ALL);
    let base = HeartbeatRepr::default();
    vec![
        base,
        HeartbeatRepr {
            board: BoardNumber::ONE,
            mode: Mode::Operational,
            faults: Faults::EMPTY.with(Fault::BoltingFailure),
            refusal: Some(Refusal::ALL[0]),
            last_seq: 1,
            target_state: Some(State::A),
            command_complete: true,
            active_bolter: Some(BolterPair::ALL[0]),
            bolter_attempt: BolterAttempt::new(1).unwrap_or(BolterAttempt::NONE),
            hip_target: HipAngle::ZERO,
            hip_now: HipAngle::new(1).unwrap_or(HipAngle::ZERO),
            arm_a_target: PulseWidth::MIN,
            arm_a_now: PulseWidth::MAX,
            arm_b_target: pw(501),
            arm_b_now: pw(2499),
            gripper_a_target: pw(1000),
            gripper_a_now: pw(2000),
            gripper_b_target: pw(1234),
            gripper_b_now: pw(2345),
            electrical_a: e(0),
            electrical_b: e(1),
            boot: mmic::restart::Boot::from_wire(0x21),
        },
        HeartbeatRepr {
            board: BoardNumber::ONE,
            mode: Mode::Safed,
            faults: all,
            refusal: Refusal::ALL.last().copied(),
            boot: mmic::restart::Boot::from_wire(u8::MAX),
            last_seq: u16::MAX,
            target_state: Some(State::O),
            command_complete: false,
            active_bolter: BolterPair::ALL.last().copied(),
            bolter_attempt: BolterAttempt::new(3).unwrap_or(BolterAttempt::NONE),
            hip_target: HipAngle::new(HipAngle::TURN - 1).unwrap_or(HipAngle::ZERO),
            hip_now: HipAngle::STRAIGHT,
            arm_a_target: PulseWidth::MAX,
            arm_a_now: PulseWidth::MIN,
            arm_b_target: pw(2500),
            arm_b_now: pw(500),
            gripper_a_target: pw(777),
            gripper_a_now: pw(1777),
            gripper_b_target: pw(2222),
            gripper_b_now: pw(1111),
            electrical_a: e(u16::MAX),
            electrical_b: Electrical {
                v_bat: 12_600,
                i_bat: 1_234,
                i_loc: 3_500,
                i_grip: 2_500,
                i_3v3: 150,
                v_reg: 7_400,
                i_bo: 2_600,
            },
        },
        HeartbeatRepr {
            board: BoardNumber::ONE,
            mode: Mode::Standby,
            faults: Faults::EMPTY
                .with(Fault::SensorLoss)
                .with(Fault::LowBattery),
            last_seq: 0x1234,
            target_state: Some(State::M),
            electrical_a: e(0x8000),
            electrical_b: e(0x7FFF),
            ..base
        },
    ]
}

/// The HK stream: one TM(3,25) per edge heartbeat, a second apart, made by the gateway (its
/// sequence counts, message type counters and times); with each packet's decoded JSON.
pub fn hk_stream() -> Vec<(Vec<u8>, Value)> {
    let mut b = Bench::new(1000, 500);
    let mut out = Vec::new();
    for (i, hb) in edge_heartbeats().into_iter().enumerate() {
        let now = 1337 * i as u32 + 7;
        b.set(now, hb);
        let from = b.tm.len();
        b.tick(now);
        for (_, p) in b.tm[from..].iter() {
            if let Ok(v) = decode_tm(p, &[0x101]) {
                if v["service"] == 3 {
                    out.push((p.clone(), v));
                }
            }
        }
    }
    out
}

/// Packets, each with a line saying what it is.
pub type Labelled = Vec<(String, Vec<u8>)>;

/// The session's first TCs, each given its second to be answered: (time ms, what, TC JSON).
const COMMANDS: [(u32, &str, &str); 7] = [
    (
        1000,
        "are-you-alive",
        r#"{"seq_count":1,"source_id":7,"service":17,"subservice":1}"#,
    ),
    (
        3000,
        "reconfiguration refused in standby",
        r#"{"seq_count":2,"source_id":7,"function":"reconfiguration","args":{"initial":"a","target":"m"}}"#,
    ),
    (
        5000,
        "mode operational",
        r#"{"seq_count":3,"source_id":7,"function":"mode","args":{"mode":2}}"#,
    ),
    (
        7000,
        "reconfiguration",
        r#"{"seq_count":4,"source_id":7,"function":"reconfiguration","args":{"initial":"a","target":"m"}}"#,
    ),
    (
        9000,
        "hk interval",
        r#"{"seq_count":5,"source_id":7,"service":3,"subservice":31,"interval_ms":500}"#,
    ),
    (
        11000,
        "hk disable",
        r#"{"seq_count":6,"source_id":7,"service":3,"subservice":6}"#,
    ),
    (
        13000,
        "hk enable",
        r#"{"seq_count":7,"source_id":7,"service":3,"subservice":5}"#,
    ),
];

/// A motion that a fault ends (TM(1,8)), with the fault (5,4) and mode change events.
const PRIMITIVE: &str = r#"{"seq_count":9,"source_id":7,"function":"primitive","args":{"primitive":4,"final_state":"d"}}"#;

/// Sends `json` at `now` (recorded in `tcs` as `what`) and runs the bench for a second.
fn step(b: &mut Bench, now: u32, what: &str, json: &str, tcs: &mut Labelled) {
    let p = tc(json);
    let _ = b.tc(now, &p);
    tcs.push((what.to_string(), p));
    b.run(now, now + 1000);
}

/// Every kind of TM the gateway emits, from one scripted session: TM(1,1/2/3/4/7/8), (3,25),
/// (5,1..4), (17,2). Returns (what, packet) in order.
pub fn session() -> (Labelled, Labelled) {
    let mut b = Bench::new(1000, 300);
    let mut tcs = Vec::new();
    b.run(0, 500);
    for (now, what, json) in COMMANDS {
        step(&mut b, now, what, json, &mut tcs);
    }
    unknown_function(&mut b, &mut tcs);
    step(&mut b, 16000, "primitive", PRIMITIVE, &mut tcs);
    bolting_attempts(&mut b);
    motion_ended_by_fault(&mut b, &mut tcs);
    let tms =
        b.tm.iter()
            .map(|(t, p)| (format!("t={t} ms"), p.clone()))
            .collect();
    (tms, tcs)
}

/// A TC whose function does not exist (its ID patched, its CRC redone): refused at acceptance
/// (TM(1,2)).
fn unknown_function(b: &mut Bench, tcs: &mut Labelled) {
    let mut bad = tc(r#"{"seq_count":8,"source_id":7,"function":"stop"}"#);
    if let Some(id) = bad.get_mut(11) {
        *id = 13;
    }
    let n = bad.len();
    let crc = mmic::ccsds::pec(&bad[..n - 2]).to_be_bytes();
    bad[n - 2..].copy_from_slice(&crc);
    let _ = b.tc(15000, &bad);
    tcs.push(("unknown function (refused)".into(), bad));
    b.run(15000, 15500);
}

/// Bolting attempts on pair 2: attempt 1 running, then 2 (1 failed: (5,2)), then done ((5,1)).
fn bolting_attempts(b: &mut Bench) {
    let hb = b.board.hb;
    let attempt = |n| BolterAttempt::new(n).unwrap_or(BolterAttempt::NONE);
    let pair = BolterPair::ALL.get(1).copied();
    for (now, active_bolter, n) in [(18000, pair, 1), (18100, pair, 2), (18200, None, 0)] {
        let bolter_attempt = attempt(n);
        b.set(
            now,
            HeartbeatRepr {
                active_bolter,
                bolter_attempt,
                ..hb
            },
        );
    }
}

/// A motion accepted, then a high-severity fault safes the robot: (5,4), (5,1), (1,8); then a
/// deferred fault (medium severity, (5,3)), and every fault cleared ((5,1)).
fn motion_ended_by_fault(b: &mut Bench, tcs: &mut Labelled) {
    let p = tc(
        r#"{"seq_count":10,"source_id":7,"function":"reconfiguration","args":{"initial":"m","target":"a"}}"#,
    );
    let _ = b.tc(19000, &p);
    tcs.push(("reconfiguration m to a, ended by a fault".into(), p));
    b.run(19000, 19100); // accepted and started; its motion takes 300 ms
    let hb = b.board.hb;
    let safed = HeartbeatRepr {
        mode: Mode::Safed,
        faults: hb.faults.with(Fault::SensorLoss),
        ..hb
    };
    b.board.done_at = None;
    b.set(20100, safed);
    // A deferred fault (medium severity, (5,3)), then every fault cleared ((5,1)).
    b.set(
        20200,
        HeartbeatRepr {
            faults: safed.faults.with(Fault::LowBattery),
            ..safed
        },
    );
    b.set(
        20300,
        HeartbeatRepr {
            faults: Faults::EMPTY,
            mode: Mode::Standby,
            ..safed
        },
    );
    b.run(20300, 21500);
}

/// Writes the fixtures into `dir`: `tm.jsonl` and `tc.jsonl` (each line `{"what","hex",
/// "decoded"}`: every TM of [`session`] and the TCs that made it), `hk.bin` (the TM(3,25)
/// stream of [`hk_stream`], packets back to back) and `hk.json` (what each packet carries,
/// as `mmic decode pus-tm` prints it). Returns the files written.
pub fn write_fixtures(dir: &Path) -> std::io::Result<Vec<std::path::PathBuf>> {
    std::fs::create_dir_all(dir)?;
    let (tms, tcs) = session();
    let line = |what: &str, p: &[u8], decoded: Value| {
        json!({"what": what, "hex": crate::codec::to_hex(p), "decoded": decoded}).to_string() + "\n"
    };
    let tm_text: String = tms
        .iter()
        .map(|(w, p)| line(w, p, decode_tm(p, &[0x101]).unwrap_or(Value::Null)))
        .collect();
    let tc_text: String = tcs
        .iter()
        .map(|(w, p)| {
            let d = decode_tc(p, &[0x101]).unwrap_or_else(|e| json!({"refused": e.to_string()}));
            line(w, p, d)
        })
        .collect();
    let hk = hk_stream();
    let bin: Vec<u8> = hk.iter().flat_map(|(p, _)| p.clone()).collect();
    let hk_json = Value::Array(hk.into_iter().map(|(_, v)| v).collect());
    let files = [
        (dir.join("tm.jsonl"), tm_text.into_bytes()),
        (dir.join("tc.jsonl"), tc_text.into_bytes()),
        (dir.join("hk.bin"), bin),
        (
            dir.join("hk.json"),
            (hk_json.to_string() + "\n").into_bytes(),
        ),
    ];
    let mut written = Vec::new();
    for (path, bytes) in files {
        std::fs::write(&path, bytes)?;
        written.push(path);
    }
    Ok(written)
}

/// `mmic ground robot`: the stand-in robot on UDP. Telecommands arrive on 127.0.0.1:`tc_port`
/// (0: any free port), telemetry goes to 127.0.0.1:`tm_port`. Prints one JSON line per event
/// on `log`: first `{"ready":true,"tc_port":N}`, then `{"dir":"tc","hex":..,"refused":null|name}`
/// for each datagram and `{"dir":"tm","hex":..}` for each packet sent. Stops after `seconds`.
pub fn robot(
    tm_port: u16,
    tc_port: u16,
    seconds: f64,
    hk_ms: u32,
    motion_ms: u32,
    log: &mut dyn Write,
) -> std::io::Result<()> {
    let sock = UdpSocket::bind(("127.0.0.1", tc_port))?;
    sock.set_read_timeout(Some(Duration::from_millis(10)))?;
    let port = sock.local_addr()?.port();
    writeln!(log, "{}", json!({"ready": true, "tc_port": port}))?;
    log.flush()?;
    let start = Instant::now();
    let mut b = Bench::new(hk_ms, motion_ms);
    let mut buf = [0u8; 65536];
    while start.elapsed().as_secs_f64() < seconds {
        let now = start.elapsed().as_millis() as u32;
        if let Ok((n, _)) = sock.recv_from(&mut buf) {
            let p = &buf[..n];
            let refused = b.tc(now, p).err();
            writeln!(
                log,
                "{}",
                json!({"dir": "tc", "hex": crate::codec::to_hex(p), "refused": refused})
            )?;
        }
        b.tick(now);
        for (_, p) in b.tm.drain(..) {
            sock.send_to(&p, ("127.0.0.1", tm_port))?;
            writeln!(
                log,
                "{}",
                json!({"dir": "tm", "hex": crate::codec::to_hex(&p)})
            )?;
        }
        log.flush()?;
    }
    Ok(())
}
