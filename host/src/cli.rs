//! The `mmic` command line: its arguments (clap derive), its errors and exit codes, and
//! [`run`], which does the work and writes to the given streams, so that `main.rs` only parses
//! the arguments and maps the error to an exit code.
//!
//! Exit codes: [`EXIT_OK`] 0; [`EXIT_INVALID_PACKET`] 1 when the bytes are not a valid packet,
//! frame or CLCW (stderr names the failed check: length, header, checksum, field or command;
//! for PUS packets and link frames the check's name, e.g. `fecf`); [`EXIT_INPUT`] 2
//! for bad input (unknown kind or state, invalid JSON, malformed hex) and usage errors (clap's
//! own code); [`EXIT_IO`] 3 when a page cannot be written or stdout is closed.

use crate::codec;
use crate::{ground, link, motion, pages, pus, xtce};
use clap::{Parser, Subcommand};
use mmic::motion::State;
use mmic::wire::PacketKind;
use std::io::Write;
use std::path::PathBuf;

pub use crate::error::CliError;
pub use crate::exit::{EXIT_HOST, EXIT_INPUT, EXIT_INVALID_PACKET, EXIT_IO, EXIT_OK};

const AFTER_HELP: &str = "\
Units: servo pulse widths in µs (500..=2500), hip angles in 0.01° (0..=35999, 9000 = 90.00°),
voltages in mV, currents in mA. JSON field names are the `name` column of the field tables
(`mmic spec`, spec/pages/*.md); a dotted name such as `electrical_a.v_bat` is a nested object.

Exit codes:
  0  success
  1  the bytes are not a valid packet; stderr names the failed check
     (length, header, checksum, field or command; for pus-tc/pus-tm the check's name of
     spec/ccsds/bad-inputs.toml, e.g. `checksum`, `unknown-function`; for tc-frame, tm-frame
     and clcw the frame's check, e.g. `fecf`, `spacecraft-id`, `packet-boundary`) with the
     numbers
  2  bad input: unknown kind, invalid or out-of-range JSON, malformed hex, usage error
  3  a file could not be written (spec --write), or stdout is closed

Examples:
  mmic encode command '{\"board\":1,\"command\":\"stop\"}'
  mmic decode command 4d49434d0102000000000000ad97
  mmic encode pus-tc '{\"apid\":257,\"seq_count\":1,\"function\":\"reconfiguration\",\"args\":{\"initial\":\"a\",\"target\":\"m\"}}'
  mmic decode pus-tc 1901c00100082f08010000096164....
  mmic decode tc-frame 0101001400c01842c00700062f1101000012d06a5a --apid 0x42
  mmic encode tc-frame '{\"spacecraft_id\":257,\"kind\":\"bc\",\"control\":{\"set-vr\":5}}'
  mmic decode clcw 01000c07
  mmic xtce > spec/ccsds/mmic.xtce.xml
  mmic spec --write spec/pages";

const ENCODE_HELP: &str = "\
Encode a packet from its JSON form; prints the bytes as lowercase hex on one line.

The JSON is exactly what `mmic decode` prints: every field, no others (an unknown or
misspelt field is refused). Values are checked as the robot checks them: pulse widths
500..=2500 µs, hip angles 0..=35999 (0.01°), boards 1..=255, states 'a'..='o' (Table 5),
primitives 1..=8 (Table 6) with a final state the primitive reaches (Figure 9), bolter pairs
1..=4. `mmic spec` lists every command's JSON.";

const ENCODE_AFTER: &str = "\
Examples (command packet, Table 2):
  mmic encode command '{\"board\":1,\"command\":\"stop\"}'
  mmic encode command '{\"board\":1,\"command\":{\"arm\":{\"side\":\"a\",\"target\":\"contract\"}}}'
  mmic encode command '{\"board\":1,\"command\":{\"arm\":{\"side\":\"a\",\"target\":{\"position\":1200}}}}'   (1200 µs)
  mmic encode command '{\"board\":1,\"command\":{\"hip\":{\"angle\":9000}}}'   (90.00°)
  mmic encode command '{\"board\":1,\"command\":{\"primitive\":{\"primitive\":4,\"target\":\"d\"}}}'   (primitive 4 ending in d)
  mmic encode command '{\"board\":1,\"command\":{\"reconfigure\":{\"initial\":\"a\",\"target\":\"m\"}}}'
  mmic encode command '{\"board\":1,\"command\":{\"power\":{\"target\":{\"module\":\"hip\"},\"on\":true}}}'
  mmic encode command '{\"board\":1,\"command\":\"stop\",\"seq\":258}'   (exactly-once sequence number; omitted = 0)
  mmic encode b-command '{\"seq\":1,\"flags\":{\"regulator\":true,\"arm\":true,\"gripper\":false,\"bolter\":false,\"stop\":false},\"arm_target\":1500,\"gripper_target\":500,\"bolter\":null}'

Space data link (CCSDS 232.0 TC frames, 132.0 TM frames, the CLCW; host/src/link.rs has the
JSON shapes; every key has a default: spacecraft 257 = robot 1, VC 0, MAP 0, counts 0):
  mmic encode tc-frame '{\"spacecraft_id\":257,\"seq\":0,\"kind\":\"ad\",\"data\":\"1842c00700062f1101000012d0\"}'
    (AD frame carrying one packet; \"map_id\":null for no segment header)
  mmic encode tc-frame '{\"kind\":\"bc\",\"control\":\"unlock\"}'
  mmic encode tm-frame '{\"spacecraft_id\":322,\"data\":\"0842c009000e201102000300000000005a8000ef0f\",\"pad\":true,\"clcw\":{\"report_value\":7}}'
    (the data field is given whole, or with \"pad\":true ends in one idle packet;
     \"first_header_pointer\": offset, \"no-packet-start\" or \"only-idle-data\")
  mmic encode clcw '{\"vcid\":0,\"retransmit\":true,\"farm_b_counter\":2,\"report_value\":7}'

Exit codes: 0 success; 1 the result would be refused (pus-tc, pus-tm, tc-frame, tm-frame,
clcw: stderr names the check, e.g. `packet-boundary`); 2 bad kind or JSON (the message names
the field and the allowed range).";

const DECODE_HELP: &str = "\
Decode a packet from hex; prints its JSON form on one line, every field included.

The hex may contain spaces, colons, commas, dashes and 0x prefixes. Pulse widths are printed
in µs, hip angles in 0.01°, voltages in mV, currents in mA; `null` is an empty optional field
(no refusal, no bolter order, no gravity reading yet).";

const DECODE_AFTER: &str = "\
Examples:
  mmic decode command 4d49434d0102000000000000ad97
    {\"board\":1,\"command\":\"stop\",\"seq\":0}
  mmic decode command '4d:49:43:4d:01:22:00:00:b0:04:00:00:4a:d4'
    {\"board\":1,\"command\":{\"arm\":{\"side\":\"a\",\"target\":{\"position\":1200}}},\"seq\":0}
  mmic decode command 4d49434d0102000000000201eee1
    {\"board\":1,\"command\":\"stop\",\"seq\":258}

Exit codes: 0 success; 1 not a valid packet, stderr names the failed check, e.g.
  mmic: checksum check failed: command packet: checksum carried 0xd54a (bytes 4a d5),
  computed 0xd44a (bytes 4a d4)
2 bad kind or malformed hex (the message gives the 0-based character position).

Frames: `decode tc-frame` and `decode tm-frame` check the mission's parameters
(spec/ccsds/link.toml: VC 0, TC frames with the segment header for MAP 0 and at most 256
octets, TM frames of 256 octets with OCF; FECF on both), any spacecraft unless
--spacecraft-id names one; --vcid, --map-id, --frame-len, --no-segment-header, --no-fecf,
--no-ocf change them. A TC frame's packets are listed, each decoded as `decode pus-tc` would
(with --apid) where it is a valid telecommand; a TM frame's OCF is decoded as a CLCW.
  mmic decode tc-frame 3101000700004bfd
    {\"kind\":\"bc\",...,\"control\":\"unlock\",...}
  mmic decode tm-frame <512 hex digits> --spacecraft-id 0x142
  mmic decode clcw 01000c07";

/// `mmic`: encode and decode MMIC-I packets, print the spec tables.
#[derive(Debug, Parser)]
#[command(
    name = "mmic",
    version,
    about = "MMIC-I packet codec (JSON ⇄ hex), motion plans and the paper's tables",
    after_help = AFTER_HELP
)]
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub cmd: Cmd,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Cmd {
    /// Encode a packet from JSON; prints lowercase hex.
    #[command(long_about = ENCODE_HELP, after_help = ENCODE_AFTER)]
    Encode {
        /// Packet kind: command | heartbeat | internal-heartbeat | b-command | pus-tc | pus-tm;
        /// or a space data link frame or word: tc-frame | tm-frame | clcw.
        #[arg(value_parser = parse_any_kind)]
        kind: AnyKind,
        /// The packet as JSON (as `mmic decode` prints it).
        json: String,
    },
    /// Decode a packet from hex; prints JSON with every field.
    #[command(long_about = DECODE_HELP, after_help = DECODE_AFTER)]
    Decode {
        /// Packet kind: command | heartbeat | internal-heartbeat | b-command | pus-tc | pus-tm;
        /// or a space data link frame or word: tc-frame | tm-frame | clcw.
        #[arg(value_parser = parse_any_kind)]
        kind: AnyKind,
        /// The packet bytes in hex.
        hex: String,
        /// pus-tc, pus-tm (and the packets of a tc-frame): an APID to accept (repeatable;
        /// decimal or 0x hex). Default: every robot's, 0x101..=0x1FF.
        #[arg(long = "apid", value_parser = pus::parse_apid)]
        apids: Vec<u16>,
        /// The frame options (tc-frame, tm-frame only).
        #[command(flatten)]
        frame: FrameArgs,
    },
    /// The XTCE mission database of the PUS-C packets, generated from the library and spec/
    /// (spec/ccsds/mmic.xtce.xml is this output); or the ccsdspy field list of TM(3,25).
    #[command(after_help = XTCE_AFTER)]
    Xtce {
        /// Print the ccsdspy field list of TM(3,25) (CSV) instead.
        #[arg(long)]
        ccsdspy: bool,
    },
    /// Tools for the ground interop tests (ground/): fixtures made by the real PUS gateway, and
    /// a UDP stand-in robot (the gateway and a trivial board A) for the YAMCS loop.
    #[command(subcommand)]
    Ground(GroundCmd),
    /// The shortest primitive sequence between two states (Table 5 letters a..o).
    #[command(
        after_help = "Example: mmic plan a m --json\n  {\"from\":\"a\",\"to\":\"m\",\"primitives\":[4,1]}"
    )]
    Plan {
        /// Initial state, a..o.
        #[arg(value_parser = motion::state)]
        from: State,
        /// Target state, a..o.
        #[arg(value_parser = motion::state)]
        to: State,
        /// Print {"from":..,"to":..,"primitives":[..]} (numbers per Table 6).
        #[arg(long)]
        json: bool,
    },
    /// Replay a scenario recorded by `mmic sim --record` through one robot's nodes on this
    /// host, and compare the outputs with another run's (the RV32 runner's under QEMU):
    /// identical, or the first record and field that differ.
    Replay {
        /// The trace (`mmic sim --record FILE`).
        #[arg(required_unless_present = "record_scenarios")]
        trace: Option<PathBuf>,
        /// Instead: record the scenarios CI replays on RV32 (the demo over both protocols and
        /// over the space data link, every Table 8 fault, lossy links) as DIR/NAME.trace.
        #[arg(long, value_name = "DIR", conflicts_with_all = ["trace", "against", "out"])]
        record_scenarios: Option<PathBuf>,
        /// Compare with this output stream (the RV32 runner's); exit 1 on any difference.
        #[arg(long, value_name = "FILE")]
        against: Option<PathBuf>,
        /// Write this host's output stream here.
        #[arg(long, value_name = "FILE")]
        out: Option<PathBuf>,
    },
    /// The RV32 runner's costs (benches/rv32): instructions and stack per node over the cost
    /// files, as a Markdown table; with --budget or --robot-budget, exit 1 if any call took more
    /// instructions than its node's budget.
    #[command(name = "rv32-costs")]
    Rv32Costs {
        /// Cost files written by the runner.
        #[arg(required = true)]
        files: Vec<PathBuf>,
        /// The most instructions any one call may take (of the robot's boards too, unless
        /// --robot-budget is given).
        #[arg(long, value_name = "INSTRUCTIONS")]
        budget: Option<u32>,
        /// The most instructions one call of the robot's boards (board A's control and WiFi
        /// tasks, board B) may take.
        #[arg(long, value_name = "INSTRUCTIONS")]
        robot_budget: Option<u32>,
    },
    /// The reconfiguration map (Figure 9): which primitive takes one state to another.
    Map {
        /// Print {"moves":[{"from":..,"to":..,"primitive":..},..]}.
        #[arg(long)]
        json: bool,
    },
    /// SDLS's durable stores: provision the simulator's state file, or the server image's
    /// keys and counters partitions, for a set of keys (the explicit step a first start needs).
    #[command(subcommand)]
    Sdls(crate::sdlscli::SdlsCmd),
    /// Run the host simulator: opsUI, server board, boards A and B and a plant model, in
    /// virtual time (deterministic) or with --realtime on real transports, driving a plan (the
    /// built-in demo without --plan).
    #[command(long_about = crate::simcli::SIM_HELP, after_help = crate::simcli::SIM_AFTER)]
    Sim(Box<crate::simcli::SimArgs>),
    /// The opsUI on a real serial device: runs a plan (the built-in demo without --plan)
    /// through the server board on DEV, a command every 1.2 s, answered within 0.7 s.
    #[command(long_about = crate::opsui::HELP, after_help = crate::opsui::AFTER)]
    Opsui(Box<crate::opsui::OpsuiArgs>),
    /// The fault swarm: random scenarios (plans, link faults, plant faults, the operator's Stop
    /// and Reset) in virtual time, invariants checked on every tick; a failing seed prints the
    /// command that replays it.
    #[command(long_about = crate::swarm::cli::HELP, after_help = crate::swarm::cli::AFTER)]
    Swarm(Box<crate::swarm::cli::SwarmArgs>),
    /// A fleet of N robots, each with its own server board, against one ground polling every
    /// robot at 1.2 s: in virtual time (robot-seconds per wall second) or on the wall clock
    /// with async tasks (every answer within 0.7 s?); --sweep over sizes with a plot.
    #[command(long_about = crate::fleet::cli::HELP, after_help = crate::fleet::cli::AFTER)]
    Fleet(Box<crate::fleet::cli::FleetArgs>),
    /// Scale benchmark of the realtime threaded engine (eight threads per robot): the largest N
    /// for which every heartbeat arrives within the timeout (`mmic fleet` runs fleets as async
    /// tasks or in virtual time).
    #[command(after_help = "Example: mmic bench --max 64 --seconds 30")]
    Bench {
        /// Largest number of robots to try (doubling from 1, then bisecting).
        #[arg(long, default_value_t = 64)]
        max: u8,
        /// Simulated (= wall, scale 1) seconds per trial.
        #[arg(long, default_value_t = 30)]
        seconds: u32,
    },
    /// Print the packet grids, field tables, opcodes and Tables 7/8; or write the review pages.
    #[command(
        after_help = "Regenerate the committed pages (a test fails when they are stale):\n  \
                            cargo run -p mmic-host -- spec --write spec/pages"
    )]
    Spec {
        /// Write one Markdown page per packet, plus commands.md, modes.md and faults.md, into
        /// this directory (the repository keeps them in spec/pages) instead of printing.
        #[arg(long, value_name = "DIR")]
        write: Option<PathBuf>,
    },
}

/// `mmic decode tc-frame|tm-frame`: the receiver's managed parameters, the mission's
/// (spec/ccsds/link.toml) unless given.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct FrameArgs {
    /// tc-frame, tm-frame: the one spacecraft ID accepted (decimal or 0x hex; the robot of
    /// board n is 0x100 + n). Default: the frame header's, so any robot's frame decodes.
    #[arg(long, value_parser = link::parse_spacecraft_id)]
    pub spacecraft_id: Option<u16>,
    /// tc-frame, tm-frame: the virtual channel accepted. Default: the mission's, 0.
    #[arg(long)]
    pub vcid: Option<u8>,
    /// tc-frame: the MAP accepted. Default: the mission's, 0.
    #[arg(long)]
    pub map_id: Option<u8>,
    /// tc-frame: the longest frame accepted; tm-frame: the frame length. Default: the
    /// mission's, 256 octets.
    #[arg(long, value_name = "OCTETS")]
    pub frame_len: Option<usize>,
    /// tc-frame: the virtual channel's AD and BD frames have no segment header.
    #[arg(long)]
    pub no_segment_header: bool,
    /// tc-frame, tm-frame: the frames have no FECF.
    #[arg(long)]
    pub no_fecf: bool,
    /// tm-frame: the frames have no OCF (no CLCW).
    #[arg(long)]
    pub no_ocf: bool,
}

impl FrameArgs {
    fn given(&self) -> bool {
        self.spacecraft_id.is_some()
            || self.vcid.is_some()
            || self.map_id.is_some()
            || self.frame_len.is_some()
            || self.no_segment_header
            || self.no_fecf
            || self.no_ocf
    }

    fn options(&self, apids: &[u16]) -> link::FrameOptions {
        link::FrameOptions {
            spacecraft_id: self.spacecraft_id,
            vcid: self.vcid,
            map_id: self.map_id,
            frame_len: self.frame_len,
            no_segment_header: self.no_segment_header,
            no_fecf: self.no_fecf,
            no_ocf: self.no_ocf,
            apids: apids.to_vec(),
        }
    }
}

const XTCE_AFTER: &str = "\
Regenerate the committed files (tests fail when they are stale):
  cargo run -q -p mmic-host -- xtce > spec/ccsds/mmic.xtce.xml
  cargo run -q -p mmic-host -- xtce --ccsdspy > spec/ccsds/hk-3-25.ccsdspy.csv";

/// `mmic ground ...`.
#[derive(Debug, Subcommand)]
pub enum GroundCmd {
    /// Write the interop fixtures: tm.jsonl, tc.jsonl (every TM type the gateway emits, the TCs
    /// that made them, with their decoded JSON), hk.bin + hk.json (a TM(3,25) stream).
    Fixtures {
        /// Directory to write into (created).
        #[arg(long, value_name = "DIR")]
        out: PathBuf,
    },
    /// The stand-in robot: TCs on UDP 127.0.0.1:TC_PORT, TM to 127.0.0.1:TM_PORT; one JSON line
    /// per packet on stdout (first {"ready":true,"tc_port":N}).
    Robot {
        /// Where TM goes (YAMCS's UDP TM link).
        #[arg(long)]
        tm_port: u16,
        /// Where TCs arrive (0: a free port, printed first).
        #[arg(long, default_value_t = 0)]
        tc_port: u16,
        /// Stop after this many seconds.
        #[arg(long, default_value_t = 60.0)]
        seconds: f64,
        /// Housekeeping collection interval, ms.
        #[arg(long, default_value_t = 1000)]
        hk_ms: u32,
        /// How long the stand-in's motions take, ms.
        #[arg(long, default_value_t = 500)]
        motion_ms: u32,
    },
}

/// A packet kind of `mmic encode|decode`: a legacy packet, or a PUS-C TC or TM.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AnyKind {
    /// One of the paper's packets.
    Legacy(PacketKind),
    /// A PUS-C telecommand.
    PusTc,
    /// A PUS-C telemetry packet.
    PusTm,
    /// A TC transfer frame (CCSDS 232.0-B).
    TcFrame,
    /// A TM transfer frame (CCSDS 132.0-B).
    TmFrame,
    /// A Communications Link Control Word (CCSDS 232.0-B §4.2).
    Clcw,
    /// A CFDP PDU (CCSDS 727.0-B-5), decode only.
    Cfdp,
}

/// A packet kind from its name: the legacy names, `pus-tc`, `pus-tm`, `tc-frame`, `tm-frame`,
/// `clcw`, `cfdp` (decode only).
pub fn parse_any_kind(name: &str) -> Result<AnyKind, CliError> {
    match name {
        "pus-tc" => Ok(AnyKind::PusTc),
        "pus-tm" => Ok(AnyKind::PusTm),
        "tc-frame" => Ok(AnyKind::TcFrame),
        "tm-frame" => Ok(AnyKind::TmFrame),
        "clcw" => Ok(AnyKind::Clcw),
        "cfdp" => Ok(AnyKind::Cfdp),
        _ => parse_kind(name).map(AnyKind::Legacy),
    }
}

/// The command line, with the help texts computed from the library (the map's legend).
pub fn command() -> clap::Command {
    <Cli as clap::CommandFactory>::command()
        .mut_subcommand("map", |c| {
            c.after_help(format!(
                "The grid's codes:\n{}\nExample: mmic map --json",
                motion::map_legend()
            ))
        })
        .mut_subcommand("sim", |c| c.long_about(crate::simcli::sim_help()))
}

/// Parses the process's arguments with [`command`]; prints help or the usage error and exits
/// as clap does (code 2 for a usage error).
pub fn parse() -> Cli {
    let matches = command().get_matches();
    <Cli as clap::FromArgMatches>::from_arg_matches(&matches).unwrap_or_else(|e| e.exit())
}

/// A packet kind from its name ([`PacketKind::from_name`]).
pub fn parse_kind(name: &str) -> Result<PacketKind, CliError> {
    PacketKind::from_name(name).ok_or_else(|| CliError::UnknownKind {
        name: name.to_string(),
    })
}

/// `mmic encode`: the packet or frame of `json`, in hex.
fn encode(kind: AnyKind, json: &str, out: &mut dyn Write) -> Result<(), CliError> {
    let bytes = match kind {
        AnyKind::Legacy(k) => codec::encode(k, json)?,
        AnyKind::PusTc => pus::encode_tc(json)?,
        AnyKind::PusTm => pus::encode_tm(json)?,
        AnyKind::TcFrame => link::encode_tc_frame(json, &[])?,
        AnyKind::TmFrame => link::encode_tm_frame(json)?,
        AnyKind::Clcw => link::encode_clcw(json)?,
        AnyKind::Cfdp => {
            return Err(CliError::Usage(
                "mmic encode cfdp: CFDP PDUs are decoded only (mmic decode cfdp HEX)".into(),
            ))
        }
    };
    writeln!(out, "{}", codec::to_hex(&bytes)).map_err(CliError::Output)
}

/// `mmic decode`: the packet or frame of `hex` as JSON; `apids` the PUS packets' (the robot's
/// when none), `frame` a frame's parameters.
fn decode(
    kind: AnyKind,
    hex: &str,
    apids: Vec<u16>,
    frame: &FrameArgs,
    out: &mut dyn Write,
) -> Result<(), CliError> {
    if frame.given() && !matches!(kind, AnyKind::TcFrame | AnyKind::TmFrame) {
        return Err(CliError::Usage(
            "--spacecraft-id, --vcid, --map-id, --frame-len, --no-segment-header, \
             --no-fecf and --no-ocf are for tc-frame and tm-frame only"
                .into(),
        ));
    }
    let bytes = codec::from_hex(hex)?;
    let options = frame.options(&apids);
    let apids = if apids.is_empty() {
        pus::robot_apids()
    } else {
        apids
    };
    let json = match kind {
        AnyKind::Legacy(k) => codec::decode(k, &bytes)?,
        AnyKind::PusTc => pus::decode_tc(&bytes, &apids)?.to_string(),
        AnyKind::PusTm => pus::decode_tm(&bytes, &apids)?.to_string(),
        AnyKind::TcFrame => link::decode_tc_frame(&bytes, &options)?.to_string(),
        AnyKind::TmFrame => link::decode_tm_frame(&bytes, &options)?.to_string(),
        AnyKind::Clcw => link::decode_clcw(&bytes)?.to_string(),
        AnyKind::Cfdp => crate::cfdp::decode(&bytes)?.to_string(),
    };
    writeln!(out, "{json}").map_err(CliError::Output)
}

/// Runs one command: results on `out`, progress notes (`spec --write`) on `log`.
pub fn run(cli: Cli, out: &mut dyn Write, log: &mut dyn Write) -> Result<(), CliError> {
    match cli.cmd {
        Cmd::Encode { kind, json } => encode(kind, &json, out)?,
        Cmd::Decode {
            kind,
            hex,
            apids,
            frame,
        } => decode(kind, &hex, apids, &frame, out)?,
        Cmd::Xtce { ccsdspy } => {
            let text = if ccsdspy {
                xtce::ccsdspy_csv()
            } else {
                xtce::generate()?
            };
            write!(out, "{text}").map_err(CliError::Output)?;
        }
        Cmd::Ground(GroundCmd::Fixtures { out: dir }) => {
            let files = ground::write_fixtures(&dir).map_err(|source| CliError::Write {
                path: dir.clone(),
                source,
            })?;
            for f in files {
                writeln!(log, "wrote {}", f.display()).map_err(CliError::Output)?;
            }
        }
        Cmd::Ground(GroundCmd::Robot {
            tm_port,
            tc_port,
            seconds,
            hk_ms,
            motion_ms,
        }) => ground::robot(tm_port, tc_port, seconds, hk_ms, motion_ms, out)
            .map_err(CliError::Sim)?,
        Cmd::Plan { from, to, json } => {
            let text = if json {
                motion::plan_json(from, to)
            } else {
                motion::plan_text(from, to)
            };
            writeln!(out, "{text}").map_err(CliError::Output)?;
        }
        Cmd::Replay {
            record_scenarios: Some(dir),
            ..
        } => crate::replay::cli_record(&dir, out)?,
        Cmd::Replay {
            trace: Some(trace),
            against,
            out: to,
            ..
        } => crate::replay::cli(&trace, against.as_deref(), to.as_deref(), out)?,
        Cmd::Rv32Costs {
            files,
            budget,
            robot_budget,
        } => crate::replay::cli_costs(&files, (budget, robot_budget), out)?,
        Cmd::Replay { .. } => {
            return Err(CliError::Usage(
                "mmic replay: give a TRACE or --record-scenarios DIR".into(),
            ))
        }
        Cmd::Map { json } => {
            if json {
                writeln!(out, "{}", motion::map_json())
            } else {
                write!(out, "{}", motion::map_text())
            }
            .map_err(CliError::Output)?;
        }
        Cmd::Sdls(cmd) => crate::sdlscli::run(cmd, out)?,
        Cmd::Sim(args) => crate::simcli::sim(*args, out)?,
        Cmd::Opsui(args) => crate::opsui::run(*args, out)?,
        Cmd::Swarm(args) => crate::swarm::cli::run(*args, out)?,
        Cmd::Fleet(args) => crate::fleet::cli::run(*args, out)?,
        Cmd::Bench { max, seconds } => crate::simcli::bench(max, seconds, out)?,
        Cmd::Spec { write: None } => {
            for (_, page) in pages::all() {
                writeln!(out, "{page}").map_err(CliError::Output)?;
            }
        }
        Cmd::Spec { write: Some(dir) } => {
            std::fs::create_dir_all(&dir).map_err(|source| CliError::Write {
                path: dir.clone(),
                source,
            })?;
            for (name, page) in pages::all() {
                let path = dir.join(name);
                std::fs::write(&path, page).map_err(|source| CliError::Write {
                    path: path.clone(),
                    source,
                })?;
                writeln!(log, "wrote {}", path.display()).map_err(CliError::Output)?;
            }
        }
    }
    Ok(())
}
