//! One run of the opsUI on a serial line: the library's plan runner and uplink (through the
//! simulator's ground side, [`GroundSide`], so that the attempts, commands done, steps and plan
//! end are logged and measured exactly as in `mmic sim`) on the wall clock, the packets written
//! to the line and the heartbeats read from it through the library's deframer. One thread: each
//! pass ticks the runner, then waits up to [`serial::READ_TIMEOUT`] for bytes.

use crate::serial::{self, Read};
use crate::sim::clock::Clock;
use crate::sim::log::Log;
use crate::sim::shell::{GroundSide, GroundStats, LegacyGround};
use mmic::node::ground::plan_runner::PlanEnd;
use mmic::wire::command::CommandRepr;
use mmic::wire::deframer::{Deframed, Deframer};
use mmic::wire::heartbeat::HeartbeatRepr;
use mmic::wire::PacketKind;
use serde_json::json;
use std::collections::BTreeSet;
use std::io::Write;

/// What crossed the line, as the opsUI saw it. Nothing read is dropped uncounted.
#[derive(Debug, Clone, Default, PartialEq, Eq, serde::Serialize)]
pub struct LineCounts {
    /// Bytes written (command packets).
    pub bytes_out: u64,
    /// Command packets written (first transmissions and resends).
    pub commands_sent: u64,
    /// Distinct commands written (by sequence number).
    pub commands_distinct: u64,
    /// Bytes read.
    pub bytes_in: u64,
    /// Heartbeats read and handed to the plan runner.
    pub heartbeats: u64,
    /// Packets read that are no heartbeat (their checksum held; they are logged and dropped).
    pub other_packets: u64,
    /// Heartbeats whose checksum held but whose fields did not parse (logged and dropped).
    pub bad_heartbeats: u64,
    /// Bytes the deframer dropped: garbage, or a header whose checksum failed.
    pub discarded: u64,
    /// Bytes still waiting in the deframer when the run ended (an incomplete packet).
    pub left_incomplete: u64,
}

/// How the run ended.
#[derive(Debug, Clone, PartialEq)]
pub enum Ending {
    /// The plan ended and no command is open.
    Done,
    /// `--max-seconds` on the plan's clock came first.
    TimeLimit,
    /// The line was lost at `at_ms` (the plan's clock): why, and the commands then open
    /// (sequence number, first transmission, ms), each of which ran at most once.
    Lost {
        /// When.
        at_ms: u32,
        /// End of file, hang-up, or the I/O error.
        why: String,
        /// Open commands.
        open: Vec<(u16, u32)>,
    },
}

/// What the run produced.
pub struct Outcome {
    /// How it ended.
    pub ending: Ending,
    /// How the plan ended (none: it had not).
    pub end: Option<PlanEnd>,
    /// What the ground side measured (attempts, longest answer, efficiency, last heartbeat).
    pub stats: GroundStats,
    /// The line's figures.
    pub line: LineCounts,
    /// The log's records (the line's packets, attempts, commands done, steps, plan end).
    pub records: Vec<serde_json::Value>,
}

/// The opsUI on an open line.
pub struct Session {
    /// The line.
    pub port: Box<dyn serialport::SerialPort>,
    /// The plan runner and what it logs and measures.
    pub ground: GroundSide<LegacyGround>,
    /// The plan's clock: the wall clock times the scale.
    pub clock: Clock<'static>,
    /// Where the records go.
    pub log: Log,
    /// Stop after this, on the plan's clock, ms.
    pub max_ms: u32,
    deframer: Deframer<256>,
    line: LineCounts,
    seqs: BTreeSet<u16>,
}

/// The line's name in the log.
const LINK: &str = "ops_line";

impl Session {
    /// A session on `port`, from `ground` (its runner not yet ticked), on `clock`.
    pub fn new(
        port: Box<dyn serialport::SerialPort>,
        ground: GroundSide<LegacyGround>,
        clock: Clock<'static>,
        log: Log,
        max_ms: u32,
    ) -> Session {
        Session {
            port,
            ground,
            clock,
            log,
            max_ms,
            deframer: Deframer::new(),
            line: LineCounts::default(),
            seqs: BTreeSet::new(),
        }
    }

    /// Runs to the plan's end (every command done), the time limit, or the line's loss.
    pub fn run(mut self) -> Outcome {
        let mut buf = [0u8; 512];
        let mut now;
        let ending = loop {
            now = self.clock.now_ms();
            if self.ground.all_done() {
                break Ending::Done;
            }
            if now > self.max_ms {
                break Ending::TimeLimit;
            }
            if let Err(why) = self.tick(now) {
                break self.lost(now, why);
            }
            match serial::read(&mut *self.port, &mut buf) {
                Read::Bytes(n) => {
                    if let Err(why) = self.take(buf.get(..n).unwrap_or(&[])) {
                        break self.lost(now, why);
                    }
                }
                Read::Idle => {}
                Read::Lost(why) => break self.lost(now, why),
            }
            self.ground.progress(now);
        };
        self.finish(now, ending)
    }

    /// The runner's tick at `now`: what it sends, written.
    fn tick(&mut self, now: u32) -> Result<(), String> {
        if let Some(p) = self.ground.tick(0, now) {
            self.send(now, &p)?;
        }
        Ok(())
    }

    /// Writes one command packet; an error is the line's loss.
    fn send(&mut self, now: u32, p: &[u8]) -> Result<(), String> {
        let written = self.port.write_all(p).and_then(|_| self.port.flush());
        let fate = if written.is_ok() {
            "delivered"
        } else {
            "closed"
        };
        self.log.packet(now, LINK, "ground", "server", fate, p);
        written.map_err(|e| format!("write failed: {e}"))?;
        self.line.bytes_out += p.len() as u64;
        self.line.commands_sent += 1;
        if let Ok(c) = CommandRepr::parse(p) {
            self.seqs.insert(c.seq);
        }
        Ok(())
    }

    /// Bytes read: every packet the deframer finds, the heartbeats to the runner (and what it
    /// answers with, written), the rest counted and logged.
    fn take(&mut self, bytes: &[u8]) -> Result<(), String> {
        self.line.bytes_in += bytes.len() as u64;
        let mut found = Vec::new();
        self.deframer.feed(bytes, |e| found.push(e));
        for e in found {
            let t = self.clock.now_ms();
            match e {
                Deframed::Discarded(n) => {
                    self.line.discarded += n as u64;
                    self.event(t, json!({"type": "line_discarded", "bytes": n}));
                }
                Deframed::Frame(f) => self.packet(t, f.kind(), f.as_bytes())?,
            }
        }
        Ok(())
    }

    /// One packet off the line at `t`.
    fn packet(&mut self, t: u32, kind: PacketKind, p: &[u8]) -> Result<(), String> {
        self.log.packet(t, LINK, "server", "ground", "delivered", p);
        if kind != PacketKind::Heartbeat {
            self.line.other_packets += 1;
            let hex = crate::sim::log::hex(p);
            self.event(t, json!({"type": "unexpected_packet", "hex": hex}));
            return Ok(());
        }
        if let Err(e) = HeartbeatRepr::parse(p) {
            self.line.bad_heartbeats += 1;
            let what = json!({"type": "bad_heartbeat", "error": e.to_string()});
            self.event(t, what);
            return Ok(());
        }
        self.line.heartbeats += 1;
        if let Some(q) = self.ground.receive(0, t, p) {
            self.send(t, &q)?;
        }
        Ok(())
    }

    fn event(&self, t: u32, what: serde_json::Value) {
        self.log.event(t, "ground", what);
    }

    /// The line lost at `now`: the commands open then are logged as ended unknown (each ran
    /// at most once; decision `opsui-line-lost`).
    fn lost(&mut self, now: u32, why: String) -> Ending {
        let open = self.ground.open_commands(0);
        for (seq, since) in &open {
            self.event(
                now,
                json!({"type": "ended_unknown", "robot": 1, "seq": seq, "open_since_ms": since,
                       "why": format!("the serial line was lost: {why}")}),
            );
        }
        self.event(now, json!({"type": "line_lost", "why": why}));
        Ending::Lost {
            at_ms: now,
            why,
            open,
        }
    }

    fn finish(mut self, now: u32, ending: Ending) -> Outcome {
        self.line.left_incomplete = self.deframer.buffered() as u64;
        self.line.commands_distinct = self.seqs.len() as u64;
        let (ends, stats) = self.ground.finish(now);
        Outcome {
            ending,
            end: ends.first().copied().flatten(),
            stats,
            line: self.line,
            records: self.log.take(),
        }
    }
}
