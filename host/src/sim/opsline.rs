//! The simulator's server board with its opsUI line on a real serial device (`mmic sim
//! --realtime --opsui-serial DEV`): the realtime engine's robot and the paper's server board
//! (the legacy relay, [`super::nodes::ServerTask`]: the library's `relay::Server` and `Visit`)
//! as always, but the server's serial line to the opsUI is DEV instead of the internal pipe,
//! and the run has no ground of its own: an opsUI at the other end of DEV (`mmic opsui
//! --serial`, or any program speaking the paper's packets) commands the robot.
//!
//! This module is only the shell of that line: [`reader`] finds the command packets on DEV with
//! the library's deframer and hands them to the server board's task (counting every byte it
//! drops and every packet that is no command), the server's heartbeats are written to DEV by
//! the task itself, and [`wait`] holds the run until the line closes (end of file or hang-up:
//! the opsUI side finished) or `--max-seconds`. A real serial line has no hang-up (no modem
//! lines with no flow control), so there only `--max-seconds` ends the run.

use super::clock::Clock;
use super::shell::GroundStats;
use super::{FrameStats, SimConfig};
use crate::error::CliError;
use crate::serial::{self, Read};
use mmic::node::ground::plan_runner::PlanEnd;
use mmic::wire::deframer::{Deframed, Deframer};
use mmic::wire::PacketKind;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc::Sender;
use std::sync::{Arc, Mutex};

/// The two ends of the device: what the server board reads, and what it writes to.
pub struct Ends {
    /// Read by [`reader`].
    pub read: Box<dyn serialport::SerialPort>,
    /// The server board's heartbeats go here.
    pub write: Box<dyn serialport::SerialPort>,
}

/// What crossed the line from the opsUI, as the server board's reader saw it.
#[derive(Debug, Default)]
pub struct LineStats {
    /// Bytes read.
    pub bytes_in: AtomicU64,
    /// Command packets handed to the server board.
    pub commands: AtomicU64,
    /// Packets that are no command (dropped).
    pub other_packets: AtomicU64,
    /// Bytes the deframer dropped.
    pub discarded: AtomicU64,
    /// Bytes still in the deframer when the reader stopped.
    pub left_incomplete: AtomicU64,
    /// The line closed (end of file, hang-up, I/O error).
    pub closed: AtomicBool,
    /// Why, when it did.
    pub why: Mutex<Option<String>>,
}

impl LineStats {
    fn add(n: &AtomicU64, k: u64) {
        n.fetch_add(k, Ordering::Relaxed);
    }

    /// A figure's value.
    pub fn get(n: &AtomicU64) -> u64 {
        n.load(Ordering::Relaxed)
    }

    /// Why the line closed, if it did.
    pub fn closed_why(&self) -> Option<String> {
        self.why.lock().map(|w| w.clone()).unwrap_or(None)
    }
}

/// The server board's opsUI line on a device, for [`SimConfig::ops_line`]. Its ends are taken
/// once, by robot 1's server board.
#[derive(Clone)]
pub struct OpsLine {
    /// The device's path.
    pub device: String,
    /// Its settings, as `115200 8N1, no flow control`.
    pub settings: String,
    ends: Arc<Mutex<Option<Ends>>>,
    /// What the reader saw.
    pub stats: Arc<LineStats>,
}

impl std::fmt::Debug for OpsLine {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("OpsLine")
            .field("device", &self.device)
            .finish_non_exhaustive()
    }
}

impl OpsLine {
    /// Opens `device` with spec/boards.toml `[ops_line]`.
    pub fn open(device: &str) -> Result<OpsLine, CliError> {
        let (write, settings) = serial::open(device)?;
        let read = write.try_clone().map_err(|e| CliError::SerialOpen {
            device: device.to_string(),
            why: e.to_string(),
        })?;
        Ok(OpsLine {
            device: device.to_string(),
            settings: settings.describe(),
            ends: Arc::new(Mutex::new(Some(Ends { read, write }))),
            stats: Arc::new(LineStats::default()),
        })
    }

    /// The device's ends, the first time (none after).
    pub fn take(&self) -> Option<Ends> {
        self.ends.lock().ok().and_then(|mut e| e.take())
    }
}

/// Reads the opsUI's bytes from `read` until the line closes or `stop` is set: every command
/// packet the deframer finds goes to `tx` (the server board's task), everything else is
/// counted in `stats`.
pub fn reader(
    mut read: Box<dyn serialport::SerialPort>,
    tx: Sender<Vec<u8>>,
    stats: &LineStats,
    stop: &AtomicBool,
) {
    let mut d = Deframer::<256>::new();
    let mut buf = [0u8; 512];
    while !stop.load(Ordering::Relaxed) {
        let n = match serial::read(&mut *read, &mut buf) {
            Read::Bytes(n) => n,
            Read::Idle => continue,
            Read::Lost(why) => {
                if let Ok(mut w) = stats.why.lock() {
                    *w = Some(why);
                }
                stats.closed.store(true, Ordering::Release);
                break;
            }
        };
        LineStats::add(&stats.bytes_in, n as u64);
        let mut commands = Vec::new();
        d.feed(buf.get(..n).unwrap_or(&[]), |e| match e {
            Deframed::Discarded(k) => LineStats::add(&stats.discarded, k as u64),
            Deframed::Frame(f) if f.kind() == PacketKind::Command => {
                commands.push(f.as_bytes().to_vec());
            }
            Deframed::Frame(_) => LineStats::add(&stats.other_packets, 1),
        });
        for c in commands {
            LineStats::add(&stats.commands, 1);
            if tx.send(c).is_err() {
                break;
            }
        }
    }
    stats
        .left_incomplete
        .store(d.buffered() as u64, Ordering::Relaxed);
}

/// The run's "ground" with the opsUI on a device: waits until the line closes or the time
/// limit; no plan of its own ends.
pub fn wait(
    cfg: &SimConfig,
    clock: &Clock,
    line: &OpsLine,
) -> (Vec<Option<PlanEnd>>, GroundStats, FrameStats) {
    super::realtime::without_ground(cfg, clock, || line.stats.closed.load(Ordering::Acquire))
}
