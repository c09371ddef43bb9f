//! COP-1 under an on-path attacker without keys (issue 38, item 6). BC frames (Unlock, Set
//! V(R)) go in clear and the CLCW is outside the TM frames' MAC, as CCSDS 355.0 and YAMCS have
//! them: an attacker who relays every frame can forge Set V(R) = N(S) + 1 just before the
//! authentic AD frame N(S) (FARM-1 then discards it as behind and its CLCW acknowledges it to
//! FOP-1), rewrite the N(R) and flags of the CLCWs it relays (N(R) = V(S) acknowledges every
//! frame outstanding), forge Unlock, drop and duplicate frames. COP-1 may then report
//! delivered what was lost: these tests show that the ground's end-to-end layer above it
//! still loses nothing silently and runs nothing twice.
//!
//! In the loop, the library's real stations: the ground's [`TcLink`] (the PUS telecommand
//! link with [`TcConfig::under_cop1`], as the simulator's ground over frames) over its
//! [`GroundLink`] (FOP-1, SDLS), the attacker, the server board's [`FrameGateway`] (FARM-1,
//! SDLS, the PUS gateway), and a board A stand-in that runs each legacy sequence number once
//! (board A's exactly-once log) and each motion for 30 ms. Every telecommand is an arm move to
//! its own pulse width, so that board A's executions are counted per telecommand.
//!
//! The property, for every telecommand the ground submits: it ends either in its ST\[1\]
//! completion (read back through authentic TM: the attacker cannot forge a report) or in a
//! failure the ground reports ([`TcLink`] giving it up as unacknowledged, an ST\[1\]
//! failure), within [`bound_ms`] of its submission; one the gateway never took is given up
//! within `max_attempts × timeout_ms` ([`untaken_bound_ms`]); board A runs none twice, and
//! every one reported completed ran exactly once (one given up may have run once: the ground
//! reports its outcome unknown). And the attack bites: FOP-1 confirms AD frames FARM-1 never
//! accepted (their packets never reached the gateway), so the tests cannot pass vacuously.
//! Once the attacker stops, the link recovers by itself: the next telecommand completes (the
//! ground's re-initiation unlocks a FARM-1 the attack left in Lockout).
//!
//! The attacker relays the ground's own frames, so it is not stopped by FARM-1 taking BC
//! frames only from the source of the last authenticated frame (decision `sdls-bc-source`);
//! it has no key, so it makes nothing run and forges no report.

use crate::common::Rng;
use mmic::ccsds::tm::TmRepr;
use mmic::command::{Command, ServoTarget};
use mmic::link::clcw::Clcw;
use mmic::link::farm::Verdict;
use mmic::link::fop::FopConfig;
use mmic::link::sdls::Key256;
use mmic::link::tc_frame::{SpacecraftId, TcContent, TcFrameRepr, Vcid};
use mmic::link::tm_frame::{FECF_LEN, OCF_LEN};
use mmic::link::ControlCommand;
use mmic::mode::Mode;
use mmic::node::exactly_once::uplink::Outcome;
use mmic::node::ground::frames::GroundLink;
use mmic::node::ground::link::{Link, MotionEnd};
use mmic::node::ground::pus::{Config as TcConfig, TcLink, MAX_TC_LEN};
use mmic::node::server::frames::{FrameConfig, FrameGateway, Stored};
use mmic::node::server::gateway::Config;
use mmic::units::{BoardNumber, PulseWidth, Side};
use mmic::wire::heartbeat::HeartbeatRepr;
use std::collections::{BTreeMap, BTreeSet};

type Server = FrameGateway<1, 4, 64, 4096>;
type Ground = GroundLink<10, 64, 1024>;

/// The ground's PUS link over frames, as the simulator's ground runs it
/// (`Config::under_cop1`, decision `pus-ground-under-cop1`): 1 s timeout, 5 s query, 30
/// attempts.
fn tc_config() -> TcConfig {
    TcConfig::default().under_cop1(&FopConfig::MISSION)
}

/// How long after its submission a telecommand the gateway never took is given up:
/// `max_attempts` transmissions, `timeout_ms` apart, none answered (30 × 1 s = 30 s).
fn untaken_bound_ms() -> u32 {
    let c = tc_config();
    u32::from(c.max_attempts) * c.timeout_ms
}

/// How long after its submission any telecommand (a motion) has its outcome at the latest, by
/// [`TcLink`]'s timers: before its acceptance at most `max_attempts` unanswered transmissions
/// `timeout_ms` apart (an answer resets the count; the acceptance is the only answer that does
/// not end the wait, as board A here starts every command within milliseconds); after it, one
/// query `query_ms` later and then `max_attempts` unanswered queries for the start report; the
/// same again for the completion report; plus a second for the gateway's own handling (its
/// uplink to board A, the TM frames' gathering). 30 × 1 s + 2 × 31 × 5 s + 1 s = 341 s.
fn bound_ms() -> u32 {
    let c = tc_config();
    let max = u32::from(c.max_attempts);
    max * c.timeout_ms + 2 * (max + 1) * c.query_ms + 1000
}

/// For an attacker of `tactics` that stops: when FOP-1 has had time for its longest recovery
/// since, its transmission limit × T1 (10 × 3 s) after the attack's end.
fn recovered_ms(tactics: &Tactics) -> Option<u32> {
    let fop = FopConfig::MISSION;
    (tactics.until > 0 && tactics.until < u32::MAX)
        .then(|| tactics.until + u32::from(fop.tx_limit) * fop.t1_ms)
}

/// A wire: frames delivered in order 2..=6 ms after they were sent (tests/common's seeded
/// generator).
struct Wire {
    rng: Rng,
    queue: Vec<(u32, Vec<u8>)>,
    last: u32,
}

impl Wire {
    fn new(seed: u64) -> Wire {
        Wire {
            rng: Rng::seeded(seed),
            queue: Vec::new(),
            last: 0,
        }
    }

    fn send(&mut self, now: u32, frame: &[u8]) {
        let at = (now + 2 + self.rng.pick(5)).max(self.last);
        self.last = at;
        self.queue.push((at, frame.to_vec()));
    }

    fn due(&mut self, now: u32) -> Vec<Vec<u8>> {
        let n = self.queue.iter().take_while(|(t, _)| *t <= now).count();
        self.queue.drain(..n).map(|(_, f)| f).collect()
    }
}

/// How a CLCW is rewritten.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Rewrite {
    /// N(R) = the ground's V(S) as the attacker saw it: every frame outstanding acknowledged.
    AckAll,
    /// The same, with the Wait flag.
    AckAllWait,
    /// The same, with the Retransmit flag.
    AckAllRetransmit,
    /// The Lockout flag set.
    Lockout,
    /// The Wait flag set.
    Wait,
    /// The Retransmit flag set.
    Retransmit,
    /// N(R) moved by this much.
    Shift(u8),
}

impl Rewrite {
    const ALL: [Rewrite; 9] = [
        Rewrite::AckAll,
        Rewrite::AckAllWait,
        Rewrite::AckAllRetransmit,
        Rewrite::Lockout,
        Rewrite::Wait,
        Rewrite::Retransmit,
        Rewrite::Shift(1),
        Rewrite::Shift(255),
        Rewrite::Shift(128),
    ];

    fn apply(self, c: &mut Clcw, vs: u8) {
        match self {
            Rewrite::AckAll => c.report_value = vs,
            Rewrite::AckAllWait => {
                c.report_value = vs;
                c.wait = true;
            }
            Rewrite::AckAllRetransmit => {
                c.report_value = vs;
                c.retransmit = true;
            }
            Rewrite::Lockout => c.lockout = true,
            Rewrite::Wait => c.wait = true,
            Rewrite::Retransmit => c.retransmit = true,
            Rewrite::Shift(d) => c.report_value = c.report_value.wrapping_add(d),
        }
    }
}

/// What the attacker does at random, each with its probability.
#[derive(Debug, Clone, Copy, Default)]
struct Tactics {
    /// Per AD frame relayed: a forged Set V(R) = N(S) + 1 just before it.
    skip: f64,
    /// Per AD frame relayed: drop it and rewrite the next CLCW to N(R) = V(S).
    drop_and_ack: f64,
    /// Every CLCW rewritten to N(R) = V(S).
    ack_all: bool,
    /// Per uplink frame relayed: a forged Set V(R) to any value before it.
    set_vr: f64,
    /// Per uplink frame relayed: a forged Unlock before it.
    unlock: f64,
    /// Per TM frame relayed: its CLCW rewritten (N(R) to V(S), ±1 or any value; each flag
    /// set or cleared).
    rewrite: f64,
    /// Per frame, either way: dropped.
    drop: f64,
    /// Per frame, either way: relayed twice.
    dup: f64,
    /// The attacker acts only before this, ms (then it relays every frame as it is).
    until: u32,
}

/// One attack at a chosen place (the exhaustive tests).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Scripted {
    /// This BC command forged just before the uplink frame of this index (every uplink
    /// frame the attacker relays counts: AD frames and the ground's BC frames).
    Bc(usize, ControlCommand),
    /// The CLCW of the TM frame of this index rewritten.
    Clcw(usize, Rewrite),
    /// The AD frame of the first index dropped, and the CLCW of the TM frame of the second
    /// rewritten to acknowledge everything.
    DropAndAck(usize, usize),
}

/// The on-path attacker: it sees and relays every frame; it has no key.
struct Attacker {
    rng: Rng,
    tactics: Tactics,
    script: Option<Scripted>,
    /// The ground's V(S) as seen on the uplink (the highest N(S) + 1, or the value of the
    /// ground's own Set V(R)).
    vs: Option<u8>,
    /// The next CLCW goes out with N(R) = V(S).
    ack_next: bool,
    up_index: usize,
    down_index: usize,
    /// BC frames forged, CLCWs rewritten, frames dropped.
    forged: u32,
    rewritten: u32,
    dropped: u32,
}

/// A BC frame to robot 1, in clear (all it takes: the spacecraft ID, seen on every frame).
fn bc(cmd: ControlCommand) -> Vec<u8> {
    let mut buf = [0u8; 16];
    let n = TcFrameRepr {
        spacecraft_id: SpacecraftId::of_board(BoardNumber::ONE),
        vcid: Vcid::new(0).unwrap(),
        seq: 0,
        content: TcContent::Bc(cmd),
    }
    .emit(&mut buf)
    .unwrap();
    buf[..n].to_vec()
}

/// The kind of a TC frame by its header flags: (bypass, control command), and its N(S).
fn tc_kind(f: &[u8]) -> (bool, bool, u8) {
    (f[0] & 0x20 != 0, f[0] & 0x10 != 0, f[4])
}

impl Attacker {
    fn new(seed: u64, tactics: Tactics, script: Option<Scripted>) -> Attacker {
        Attacker {
            rng: Rng::seeded(seed ^ 0xa77a_c4e7),
            tactics,
            script,
            vs: None,
            ack_next: false,
            up_index: 0,
            down_index: 0,
            forged: 0,
            rewritten: 0,
            dropped: 0,
        }
    }

    fn forge(&mut self, out: &mut Vec<Vec<u8>>, cmd: ControlCommand) {
        self.forged += 1;
        out.push(bc(cmd));
    }

    /// An uplink frame arrives at the attacker: what it hands the server board, in order.
    fn up(&mut self, now: u32, frame: Vec<u8>) -> Vec<Vec<u8>> {
        let (bypass, control, ns) = tc_kind(&frame);
        let ad = !bypass && !control;
        if ad {
            let next = ns.wrapping_add(1);
            let ahead = self.vs.is_none_or(|v| next.wrapping_sub(v) < 128);
            if ahead {
                self.vs = Some(next);
            }
        } else if control {
            // The ground's own Set V(R) (its re-initiation): octet 7 is the value.
            if frame.len() >= 8 && frame[5] == 0x82 && frame[6] == 0x00 {
                self.vs = Some(frame[7]);
            }
        }
        let index = self.up_index;
        self.up_index += 1;
        let mut out = Vec::new();
        if let Some(Scripted::Bc(i, cmd)) = self.script
            && i == index
        {
            self.forge(&mut out, cmd);
        }
        if let Some(Scripted::DropAndAck(i, _)) = self.script
            && i == index
            && ad
        {
            self.dropped += 1;
            return out;
        }
        let t = self.tactics;
        if now < t.until {
            if ad && self.rng.maybe(t.skip) {
                self.forge(&mut out, ControlCommand::SetVr(ns.wrapping_add(1)));
            }
            if self.rng.maybe(t.set_vr) {
                let v = self.rng.pick(256) as u8;
                self.forge(&mut out, ControlCommand::SetVr(v));
            }
            if self.rng.maybe(t.unlock) {
                self.forge(&mut out, ControlCommand::Unlock);
            }
            if ad && self.rng.maybe(t.drop_and_ack) {
                self.dropped += 1;
                self.ack_next = true;
                return out;
            }
            if self.rng.maybe(t.drop) {
                self.dropped += 1;
                return out;
            }
            if self.rng.maybe(t.dup) {
                out.push(frame.clone());
            }
        }
        out.push(frame);
        out
    }

    /// A TM frame arrives at the attacker: what it hands the ground.
    fn down(&mut self, now: u32, mut frame: Vec<u8>) -> Vec<Vec<u8>> {
        let index = self.down_index;
        self.down_index += 1;
        let mut rewrite: Option<Rewrite> = None;
        match self.script {
            Some(Scripted::Clcw(j, r)) if j == index => rewrite = Some(r),
            Some(Scripted::DropAndAck(_, j)) if j == index => rewrite = Some(Rewrite::AckAll),
            _ => {}
        }
        let t = self.tactics;
        let active = now < t.until;
        if active && (self.ack_next || t.ack_all) {
            self.ack_next = false;
            rewrite = Some(Rewrite::AckAll);
        }
        let random = active && rewrite.is_none() && self.rng.maybe(t.rewrite);
        let ocf = frame.len() - FECF_LEN - OCF_LEN;
        if rewrite.is_some() || random {
            let mut c = Clcw::parse(&frame[ocf..ocf + OCF_LEN]).unwrap();
            let vs = self.vs.unwrap_or(c.report_value);
            if let Some(r) = rewrite {
                r.apply(&mut c, vs);
            } else {
                c.report_value = match self.rng.pick(4) {
                    0 => vs,
                    1 => c.report_value.wrapping_add(1),
                    2 => c.report_value.wrapping_sub(1),
                    _ => self.rng.pick(256) as u8,
                };
                for flag in [&mut c.lockout, &mut c.wait, &mut c.retransmit] {
                    if self.rng.maybe(0.25) {
                        *flag = !*flag;
                    }
                }
            }
            frame[ocf..ocf + OCF_LEN].copy_from_slice(&c.emit());
            // The FECF made good: the frame passes the ground's frame checks, and the MAC
            // does not cover the OCF.
            let n = frame.len();
            let crc = mmic::ccsds::pec(&frame[..n - FECF_LEN]);
            frame[n - FECF_LEN..].copy_from_slice(&crc.to_be_bytes());
            self.rewritten += 1;
        }
        if active && self.rng.maybe(t.drop) {
            self.dropped += 1;
            return Vec::new();
        }
        if active && self.rng.maybe(t.dup) {
            return vec![frame.clone(), frame];
        }
        vec![frame]
    }
}

/// How a telecommand ended, as the ground reports it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum End {
    /// Its ST\[1\] completion (success) came.
    Completed,
    /// A failure the ground reports: given up (unacknowledged) before or after its start, or
    /// an ST\[1\] failure.
    Failed(&'static str),
}

/// One telecommand the ground submitted.
#[derive(Debug, Clone, Copy)]
struct Submitted {
    seq: u16,
    at: u32,
    end: Option<(u32, End)>,
}

/// Board A: runs each legacy sequence number once (its exactly-once log), each arm move for
/// 30 ms, and answers every command 3 ms later with a heartbeat.
#[derive(Default)]
struct BoardA {
    seqs: BTreeSet<u16>,
    /// Executions per telecommand (the index its pulse width carries).
    runs: BTreeMap<u16, u32>,
    /// When each telecommand ran.
    ran_at: BTreeMap<u16, u32>,
    moving_until: u32,
    answers: Vec<(u32, u16, bool)>,
}

impl BoardA {
    fn command(&mut self, now: u32, seq: u16, command: Command) {
        let new = self.seqs.insert(seq);
        let mut starts = false;
        if new
            && let Command::Arm {
                target: ServoTarget::Position(pw),
                ..
            } = command
        {
            let k = pw.get() - 900;
            *self.runs.entry(k).or_default() += 1;
            self.ran_at.entry(k).or_insert(now);
            self.moving_until = now + 30;
            starts = true;
        }
        self.answers.push((now + 3, seq, starts));
    }

    fn due(&mut self, now: u32) -> Vec<HeartbeatRepr> {
        let (due, rest): (Vec<_>, Vec<_>) = self.answers.iter().partition(|a| a.0 <= now);
        self.answers = rest;
        due.into_iter()
            .map(|(_, seq, starts)| HeartbeatRepr {
                last_seq: seq,
                mode: Mode::Operational,
                command_complete: !starts && now >= self.moving_until,
                ..HeartbeatRepr::default()
            })
            .collect()
    }
}

/// Telecommand `k`: move arm A to 900 + k µs.
fn arm(k: u16) -> Command {
    Command::Arm {
        side: Side::A,
        target: ServoTarget::Position(PulseWidth::new(900 + k).unwrap()),
    }
}

struct Run {
    cmds: Vec<Submitted>,
    board: BoardA,
    /// AD frames FOP-1 confirmed that FARM-1 had not accepted since their first transmission.
    bites: u32,
    forged: u32,
    rewritten: u32,
    dropped: u32,
    /// Uplink and downlink frames the attacker relayed (its indices' ranges).
    up_frames: usize,
    down_frames: usize,
    /// The gateway's packet count (copies included) and FOP-1's confirmations.
    tc_packets: u32,
    confirmed: u32,
    ad_frames: u32,
    /// FOP-1's alerts.
    alerts: u32,
    /// TM frames the ground refused by a frame check or for their MAC: none, a rewritten CLCW
    /// with its FECF made good passes both. (SDLS refuses the attacker's copies as replays,
    /// and, rarely, an authentic frame whose IV ran past the ground's durable floor before this
    /// loop wrote it, as not-reserved: neither is the attack's doing.)
    tm_refused: u32,
    /// When the run stopped, ms.
    end_ms: u32,
}

impl Run {
    /// Checks the property: every telecommand ended, completed or failed as the ground
    /// reports, within the bounds; none ran twice; each one completed ran once. Returns the
    /// largest time from submission to outcome.
    fn check(&self, what: &str) -> u32 {
        let mut worst = 0;
        assert_eq!(self.tm_refused, 0, "{what}: the ground refused a TM frame");
        for (k, c) in self.cmds.iter().enumerate() {
            let k = k as u16;
            let runs = self.board.runs.get(&k).copied().unwrap_or(0);
            assert!(runs <= 1, "{what}: telecommand {k} ran {runs} times");
            let Some((t, end)) = c.end else {
                panic!(
                    "{what}: telecommand {k} (seq {}) submitted at {} ms has no outcome at {} ms",
                    c.seq, c.at, self.end_ms
                );
            };
            let took = t - c.at;
            worst = worst.max(took);
            assert!(
                took <= bound_ms(),
                "{what}: telecommand {k}: {end:?} after {took} ms"
            );
            match end {
                End::Completed => assert_eq!(runs, 1, "{what}: {k} completed, ran {runs} times"),
                End::Failed(_) if runs == 0 => assert!(
                    took <= untaken_bound_ms() + 1,
                    "{what}: {k} never taken, given up after {took} ms"
                ),
                End::Failed(_) => {}
            }
        }
        worst
    }

    fn completed(&self) -> usize {
        let done = |c: &&Submitted| matches!(c.end, Some((_, End::Completed)));
        self.cmds.iter().filter(done).count()
    }
}

/// `n` telecommands, each submitted when the one before has its outcome, with the attacker
/// in the loop; at most `limit_ms` of simulated time (1 ms steps). The run ends once every
/// telecommand has its outcome and the link is quiet.
fn run(n: u16, seed: u64, tactics: Tactics, script: Option<Scripted>, limit_ms: u32) -> Run {
    let board = BoardNumber::ONE;
    let mut server = Server::new(FrameConfig {
        gateway: Config {
            hk_enabled: false,
            ..Config::default()
        },
        ..FrameConfig::default()
    });
    assert!(server.add(board));
    let mut ground = Ground::new(board);
    // Throwaway keys made from the seed at run time (no key is in the tree).
    let key = |k: u64| {
        let mut r = Rng::seeded(seed.wrapping_mul(31).wrapping_add(k));
        let bytes: Vec<u8> = (0..32).map(|_| r.next() as u8).collect();
        Key256::from_slice(&bytes).unwrap()
    };
    assert!(server
        .secure(board, key(1), key(2), Stored::default())
        .is_ok());
    ground.secure(key(1), key(2), (None, None));
    let mut tc = TcLink::new(tc_config(), board);
    let mut up = Wire::new(seed);
    let mut down = Wire::new(seed ^ 0x5555);
    let mut attacker = Attacker::new(seed, tactics, script);
    let mut board_a = BoardA::default();
    let mut cmds: Vec<Submitted> = Vec::new();
    // A started motion the ground follows until its completion report.
    let mut following: Option<usize> = None;
    // The bookkeeping of the bites: when each N(S) was first sent in the present
    // initiation, when FARM-1 last accepted it.
    let mut first_tx: [Option<u32>; 256] = [None; 256];
    let mut accepted_at: [Option<u32>; 256] = [None; 256];
    let mut bites = 0;
    let mut emitted: Vec<Vec<u8>> = Vec::new();
    ground.start(0, &mut |f: &[u8]| emitted.push(f.to_vec()));
    let mut end_ms = limit_ms;
    for now in 0..limit_ms {
        // The server board keeps what it must (SDLS counters, FARM-1's progress, kept keys)
        // before anything that depends on it leaves, as its shells do.
        for e in server.durable_due::<16>() {
            server.durable_written(&e);
        }
        for (spi, v) in ground.due().collect::<Vec<_>>() {
            ground.persisted(spi, v);
        }
        // The uplink, through the attacker.
        for f in up.due(now) {
            for g in attacker.up(now, f) {
                // On the path: its frames come from the ground's address.
                let got = server.tc_frame(now, &g);
                for e in server.durable_due::<16>() {
                    server.durable_written(&e);
                }
                let (bypass, control, ns) = tc_kind(&g);
                if !bypass && !control && got.verdict == Ok(Verdict::Accept) {
                    accepted_at[ns as usize] = Some(now);
                }
            }
        }
        // The downlink, through the attacker.
        let initiations = ground.counters().initiations;
        let mut packets: Vec<Vec<u8>> = Vec::new();
        for f in down.due(now) {
            for g in attacker.down(now, f) {
                let (nnr, inits) = (ground.fop().nnr(), ground.counters().initiations);
                let _ = ground.tm_frame(
                    now,
                    &g,
                    &mut |t: &[u8]| emitted.push(t.to_vec()),
                    &mut |p: &[u8]| packets.push(p.to_vec()),
                );
                if ground.counters().initiations == inits {
                    // Confirmed now: N(S) from the old NN(R) up to the new.
                    let mut ns = nnr;
                    while ns != ground.fop().nnr() {
                        if let Some(t) = first_tx[ns as usize].take()
                            && accepted_at[ns as usize].is_none_or(|a| a < t)
                        {
                            bites += 1;
                        }
                        ns = ns.wrapping_add(1);
                    }
                }
            }
        }
        // The ground's PUS link hears the reports.
        for p in packets {
            let Ok(tm) = TmRepr::parse(&p, &[tc.apid()]) else {
                continue;
            };
            let h = tm.header;
            let heard = tc.telemetry(h.service, h.subservice, tm.source_data);
            let at = |seq: u16, cmds: &mut Vec<Submitted>| cmds.iter().position(|c| c.seq == seq);
            if let Some(d) = heard.done {
                let i = at(d.seq, &mut cmds).unwrap();
                match d.outcome {
                    Outcome::Accepted => following = Some(i),
                    Outcome::Refused(_) => cmds[i].end = Some((now, End::Failed("refused"))),
                    Outcome::Unacknowledged => {
                        cmds[i].end = Some((now, End::Failed("start unacknowledged")))
                    }
                }
            }
            if let Some((seq, how)) = heard.ended {
                let i = at(seq, &mut cmds).unwrap();
                following = None;
                let end = match how {
                    MotionEnd::Completed => End::Completed,
                    MotionEnd::Interrupted { .. } => End::Failed("interrupted"),
                    MotionEnd::Unacknowledged => End::Failed("completion unacknowledged"),
                };
                cmds[i].end.get_or_insert((now, end));
            }
            if let Some((seq, _)) = heard.rejected {
                let i = at(seq, &mut cmds).unwrap();
                cmds[i].end.get_or_insert((now, End::Failed("rejected")));
            }
        }
        // The ground submits the next telecommand once the last has its outcome; the last one
        // of a run whose attacker stops only once COP-1 had time to recover.
        let last_held =
            cmds.len() + 1 == n as usize && recovered_ms(&tactics).is_some_and(|t| now < t);
        if tc.is_idle() && following.is_none() && cmds.len() < n as usize && !last_held {
            let seq = tc.submit(arm(cmds.len() as u16)).unwrap();
            cmds.push(Submitted {
                seq,
                at: now,
                end: None,
            });
        }
        let t = tc.tick(now);
        if let Some(out) = t.send {
            let mut b = [0u8; MAX_TC_LEN];
            let len = out.emit(&mut b).unwrap();
            // A full outbox refuses the packet: the link sends it again at its next timeout.
            let _ = ground.send(&b[..len], now, &mut |f: &[u8]| emitted.push(f.to_vec()));
        }
        if let Some(d) = t.done {
            let i = cmds.iter().position(|c| c.seq == d.seq).unwrap();
            cmds[i].end = Some((now, End::Failed("given up before its start")));
        }
        if let Some((seq, _)) = t.ended {
            let i = cmds.iter().position(|c| c.seq == seq).unwrap();
            following = None;
            cmds[i]
                .end
                .get_or_insert((now, End::Failed("given up before its completion")));
        }
        ground.tick(now, &mut |f: &[u8]| emitted.push(f.to_vec()));
        if ground.counters().initiations != initiations {
            // A re-initiation purged every frame outstanding: nothing of them is confirmed.
            first_tx = [None; 256];
        }
        for f in emitted.drain(..) {
            let (bypass, control, ns) = tc_kind(&f);
            if !bypass && !control {
                first_tx[ns as usize].get_or_insert(now);
            }
            up.send(now, &f);
        }
        // The server board: its gateway's commands to board A, board A's answers, TM frames.
        for (_, c) in server.tick(now) {
            board_a.command(now, c.seq, c.command);
        }
        for hb in board_a.due(now) {
            server.heartbeat(now, &hb);
        }
        let mut buf = [0u8; 256];
        while let Some((_, len)) = server.frame(now, &mut buf) {
            down.send(now, &buf[..len]);
        }
        // Done: every telecommand has its outcome, and the link is quiet (or, if COP-1 is
        // still busy, two seconds have passed since the last outcome).
        let all_done = cmds.len() == n as usize && cmds.iter().all(|c| c.end.is_some());
        let last = cmds.iter().filter_map(|c| c.end).map(|e| e.0).max();
        let quiet = ground.fop().sent_len() == 0 && ground.waiting() == 0;
        if all_done && (quiet || last.is_some_and(|t| now >= t + 2000)) {
            end_ms = now;
            break;
        }
    }
    let c = *ground.counters();
    Run {
        cmds,
        board: board_a,
        bites,
        forged: attacker.forged,
        rewritten: attacker.rewritten,
        dropped: attacker.dropped,
        up_frames: attacker.up_index,
        down_frames: attacker.down_index,
        tc_packets: server.counters(board).unwrap().tc_packets,
        confirmed: c.confirmed,
        ad_frames: c.ad_frames,
        alerts: c.alerts.iter().sum(),
        tm_refused: {
            let sec = ground.security().unwrap();
            c.tm_refused + sec.refused_for("bad-mac")
        },
        end_ms,
    }
}

/// The clean run the exhaustive tests attack: three telecommands, no attack.
#[test]
fn a_clean_run_completes_every_telecommand() {
    let r = run(3, 1, Tactics::default(), None, 60_000);
    let worst = r.check("clean");
    assert_eq!(r.completed(), 3);
    assert_eq!((r.bites, r.tc_packets), (0, 3));
    println!(
        "clean: {} uplink frames, {} TM frames, done at {} ms, longest {worst} ms",
        r.up_frames, r.down_frames, r.end_ms
    );
}

/// The attack at its strongest: before every AD frame a forged Set V(R) = N(S) + 1 (or every
/// AD frame dropped and every CLCW rewritten to N(R) = V(S)). COP-1 reports every frame
/// delivered (FOP-1 confirms them all, no alert) while the gateway takes no packet; the ground
/// gives every telecommand up, unacknowledged, `max_attempts × timeout_ms` after its
/// submission, and board A runs nothing.
#[test]
fn every_frame_skipped_cop1_says_delivered_and_the_ground_gives_each_up() {
    for (what, tactics) in [
        (
            "forged Set V(R) = N(S) + 1 before every AD frame",
            Tactics {
                skip: 1.0,
                until: u32::MAX,
                ..Tactics::default()
            },
        ),
        (
            "every AD frame dropped, every CLCW's N(R) = V(S)",
            Tactics {
                drop_and_ack: 1.0,
                ack_all: true,
                until: u32::MAX,
                ..Tactics::default()
            },
        ),
    ] {
        let r = run(3, 7, tactics, None, 200_000);
        r.check(what);
        for c in &r.cmds {
            assert_eq!(
                c.end.map(|(t, e)| (t - c.at, e)),
                Some((untaken_bound_ms(), End::Failed("given up before its start"))),
                "{what}"
            );
        }
        assert!(
            r.board.runs.is_empty(),
            "{what}: board A ran {:?}",
            r.board.runs
        );
        assert_eq!(r.tc_packets, 0, "{what}: the gateway took a packet");
        // COP-1 says delivered: FOP-1 confirmed AD frames FARM-1 never took, 30 per
        // telecommand (one transmission a second for 30 s).
        assert_eq!(r.bites, r.confirmed, "{what}");
        assert_eq!(r.alerts, 0, "{what}");
        assert!(r.confirmed >= 3 * 29, "{what}: {} confirmed", r.confirmed);
        println!(
            "{what}: {} AD frames, {} confirmed by FOP-1, 0 packets taken; each telecommand given up after {} ms",
            r.ad_frames,
            r.confirmed,
            untaken_bound_ms()
        );
    }
}

/// Every BC frame the attacker can forge (Set V(R) to each of the 256 values, Unlock) just
/// before every uplink frame of a short run (three telecommands: the clean run's three AD
/// frames): 771 runs. Set V(R) = N(S) + 1 skips the frame (FOP-1 confirms it) and the ground's
/// link sends the telecommand again after its timeout. A Set V(R) that puts the next frame in
/// FARM-1's lockout area (236 of the 256 values) locks FARM-1 out; the ground's
/// re-initiation unlocks it (an Unlock before its Set V(R), which Lockout ignores) and every
/// telecommand completes: one forged frame costs seconds, never a telecommand.
#[test]
fn every_forged_bc_frame_before_every_frame_of_a_short_run() {
    let clean = run(3, 1, Tactics::default(), None, 60_000);
    assert_eq!(clean.completed(), 3);
    let mut commands: Vec<ControlCommand> = (0..=255u8).map(ControlCommand::SetVr).collect();
    commands.push(ControlCommand::Unlock);
    let (mut runs, mut bitten, mut worst, mut given_up) = (0, 0, 0, 0);
    for i in 0..clean.up_frames {
        for &cmd in &commands {
            let what = format!("{cmd:?} before uplink frame {i}");
            let r = run(
                3,
                1,
                Tactics::default(),
                Some(Scripted::Bc(i, cmd)),
                400_000,
            );
            worst = worst.max(r.check(&what));
            runs += 1;
            bitten += u32::from(r.bites > 0);
            given_up += 3 - r.completed();
            assert_eq!(r.completed(), 3, "{what}: {:?}", r.cmds);
            if cmd == ControlCommand::SetVr(i as u8 + 1) {
                // The attack itself: the frame skipped, acknowledged, and sent again by the
                // ground's link after its timeout, under the same key.
                assert_eq!(r.bites, 1, "{what}");
                assert_eq!(r.completed(), 3, "{what}");
            }
        }
    }
    println!(
        "{runs} runs: the attack bit in {bitten}; {given_up} telecommands given up; longest time to an outcome {worst} ms (bound {} ms)",
        bound_ms()
    );
}

/// Every rewrite of a CLCW (N(R) to V(S), with and without Wait or Retransmit; Lockout, Wait,
/// Retransmit set; N(R) ± 1, + 128) in every TM frame of the short run, and every AD frame
/// dropped with every later CLCW rewritten to acknowledge it.
#[test]
fn every_clcw_rewrite_in_every_tm_frame_of_a_short_run() {
    let clean = run(3, 1, Tactics::default(), None, 60_000);
    let (mut runs, mut bitten, mut worst, mut given_up) = (0, 0, 0, 0);
    let mut scripts = Vec::new();
    for j in 0..clean.down_frames {
        for r in Rewrite::ALL {
            scripts.push(Scripted::Clcw(j, r));
        }
        for i in 0..clean.up_frames {
            scripts.push(Scripted::DropAndAck(i, j));
        }
    }
    for s in scripts {
        let what = format!("{s:?}");
        let r = run(3, 1, Tactics::default(), Some(s), 400_000);
        worst = worst.max(r.check(&what));
        runs += 1;
        bitten += u32::from(r.bites > 0);
        given_up += 3 - r.completed();
        assert_eq!(r.completed(), 3, "{what}: {:?}", r.cmds);
    }
    assert!(bitten > 0);
    println!(
        "{runs} runs: the attack bit in {bitten}; {given_up} telecommands given up; longest time to an outcome {worst} ms (bound {} ms)",
        bound_ms()
    );
}

/// A seeded attacker doing everything at random (forged Set V(R) = N(S) + 1 and to any value,
/// Unlock, CLCWs rewritten, drops, copies) over 90 seeds (`COP1_SEEDS` for more): ten
/// telecommands each; in half of the runs the attack stops after 60 s and the last
/// telecommand is submitted 30 s later (FOP-1's longest recovery, tx_limit × T1): it
/// completes. In three tests of a third of the seeds each (they run side by side), each with
/// the attack biting in most of its runs.
fn random_attacks(part: u64) {
    let (mut runs, mut bitten, mut bites, mut worst) = (0, 0, 0, 0);
    let (mut completed, mut given_up, mut ran_unknown) = (0, 0, 0);
    let (mut forged, mut rewritten, mut dropped) = (0, 0, 0);
    // The last telecommands of the runs whose attacker stopped (submitted after FOP-1's
    // longest recovery), and those of them completed.
    let (mut after, mut after_done) = (0, 0);
    let seeds: u64 = std::env::var("COP1_SEEDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(90);
    for seed in part * seeds / 3 + 1..=(part + 1) * seeds / 3 {
        let mut rng = Rng::seeded(seed);
        // Every third run an aggressive attacker (up to a forged frame before every AD frame,
        // every CLCW rewritten, half the frames dropped); the others a moderate one.
        let scale = if seed % 3 == 0 { 1.0 } else { 0.0 };
        let mut p = |moderate: f64, aggressive: f64| {
            let max = moderate + scale * (aggressive - moderate);
            (rng.pick(1001) as f64 / 1000.0) * max
        };
        let tactics = Tactics {
            skip: p(0.5, 1.0),
            drop_and_ack: p(0.2, 0.6),
            set_vr: p(0.05, 0.4),
            unlock: p(0.05, 0.4),
            rewrite: p(0.3, 1.0),
            drop: p(0.2, 0.5),
            dup: p(0.1, 0.4),
            until: if seed % 2 == 0 { 60_000 } else { u32::MAX },
            ack_all: false,
        };
        let what = format!("seed {seed}: {tactics:?}");
        let r = run(10, seed, tactics, None, 4_000_000);
        worst = worst.max(r.check(&what));
        runs += 1;
        bitten += u32::from(r.bites > 0);
        bites += r.bites;
        completed += r.completed();
        given_up += r.cmds.len() - r.completed();
        ran_unknown += r
            .cmds
            .iter()
            .enumerate()
            .filter(|(k, c)| {
                matches!(c.end, Some((_, End::Failed(_))))
                    && r.board.runs.contains_key(&(*k as u16))
            })
            .count();
        if let Some(t) = recovered_ms(&tactics) {
            let last = r.cmds.last().unwrap();
            assert!(last.at >= t, "{what}");
            after += 1;
            after_done += usize::from(matches!(last.end, Some((_, End::Completed))));
            // The link recovers once the attacker stops: the next telecommand completes.
            assert_eq!(last.end.map(|e| e.1), Some(End::Completed), "{what}");
        }
        forged += r.forged;
        rewritten += r.rewritten;
        dropped += r.dropped;
    }
    assert!(
        bitten > runs / 2,
        "the attack bit in {bitten} of {runs} runs"
    );
    println!(
        "seeds, part {part} of 3: {runs} runs: {forged} BC frames forged, {rewritten} CLCWs rewritten, {dropped} frames dropped; the attack bit in {bitten} runs ({bites} frames confirmed unaccepted); {completed} telecommands completed, {given_up} given up ({ran_unknown} of them ran once); longest time to an outcome {worst} ms (bound {} ms); after the attack stopped, {after_done} of {after} telecommands completed",
        bound_ms()
    );
}

#[test]
fn a_random_on_path_attacker_loses_nothing_silently_and_runs_nothing_twice_part_0() {
    random_attacks(0);
}

#[test]
fn a_random_on_path_attacker_loses_nothing_silently_and_runs_nothing_twice_part_1() {
    random_attacks(1);
}

#[test]
fn a_random_on_path_attacker_loses_nothing_silently_and_runs_nothing_twice_part_2() {
    random_attacks(2);
}
