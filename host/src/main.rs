//! `mmic`: encode and decode MMIC-I packets, print the spec tables.
//!
//! Exit codes: 0 success; 1 the bytes are not a valid packet (stderr names the failed check);
//! 2 bad input (unknown kind, invalid JSON, malformed hex) or usage error.

use clap::{Parser, Subcommand};
use mmic::wire::PacketKind;
use mmic_host::{codec, motion, pages};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(name = "mmic", version, about = "MMIC-I packet codec and spec tables", long_about = None)]
struct Cli {
    #[command(subcommand)]
    cmd: Cmd,
}

const KINDS: &str = "command | heartbeat | internal-heartbeat | b-command";

#[derive(Subcommand)]
enum Cmd {
    /// Encode a packet from JSON; prints lowercase hex.
    ///
    /// Units: servo pulses in µs (500..=2500), hip angles in 0.01° (0..=35999), voltages in mV,
    /// currents in mA. Field names follow spec/packets/*.toml.
    ///
    /// Example: mmic encode command '{"board":1,"command":{"arm":{"side":"a","target":{"position":1200}}}}'
    Encode {
        /// command | heartbeat | internal-heartbeat | b-command
        kind: String,
        /// The packet as JSON (as `mmic decode` prints it).
        json: String,
    },
    /// Decode a packet from hex; prints JSON with every field.
    ///
    /// Hex may contain spaces, colons, commas, dashes and 0x prefixes.
    /// Example: mmic decode command 4d49434d010200000000000000XXXX
    Decode {
        /// command | heartbeat | internal-heartbeat | b-command
        kind: String,
        /// The packet bytes in hex.
        hex: String,
    },
    /// The shortest primitive sequence between two states (Table 5 letters a..o).
    ///
    /// Example: mmic plan a m
    Plan {
        /// Initial state, a..o.
        from: String,
        /// Target state, a..o.
        to: String,
        /// Print {"from":..,"to":..,"primitives":[..]} (numbers per Table 6).
        #[arg(long)]
        json: bool,
    },
    /// The reconfiguration map (Figure 9): which primitive takes one state to another.
    Map {
        /// Print {"moves":[{"from":..,"to":..,"primitive":..},..]}.
        #[arg(long)]
        json: bool,
    },
    /// Print the packet grids, field tables, opcodes and Tables 7/8; or write the review pages.
    Spec {
        /// Write the generated pages into this directory (spec/pages) instead of printing.
        #[arg(long, value_name = "DIR")]
        write: Option<PathBuf>,
    },
}

fn kind(name: &str) -> Result<PacketKind, String> {
    PacketKind::from_name(name)
        .ok_or_else(|| format!("unknown packet kind {name:?}; expected one of: {KINDS}"))
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match cli.cmd {
        Cmd::Encode { kind: k, json } => {
            let k = match kind(&k) {
                Ok(k) => k,
                Err(e) => return fail(2, &e),
            };
            match codec::encode(k, &json) {
                Ok(bytes) => println!("{}", codec::to_hex(&bytes)),
                Err(e) => return fail(e.exit_code(), &e.to_string()),
            }
        }
        Cmd::Decode { kind: k, hex } => {
            let k = match kind(&k) {
                Ok(k) => k,
                Err(e) => return fail(2, &e),
            };
            let result = codec::from_hex(&hex).and_then(|b| codec::decode(k, &b));
            match result {
                Ok(json) => println!("{json}"),
                Err(e) => return fail(e.exit_code(), &e.to_string()),
            }
        }
        Cmd::Plan { from, to, json } => {
            let (f, t) = match (motion::state(&from), motion::state(&to)) {
                (Ok(f), Ok(t)) => (f, t),
                (Err(e), _) | (_, Err(e)) => return fail(2, &e),
            };
            println!(
                "{}",
                if json {
                    motion::plan_json(f, t)
                } else {
                    motion::plan_text(f, t)
                }
            );
        }
        Cmd::Map { json } => {
            print!(
                "{}",
                if json {
                    motion::map_json() + "\n"
                } else {
                    motion::map_text()
                }
            );
        }
        Cmd::Spec { write: None } => {
            for (_, page) in pages::all() {
                println!("{page}");
            }
        }
        Cmd::Spec { write: Some(dir) } => {
            if let Err(e) = std::fs::create_dir_all(&dir) {
                return fail(2, &format!("{}: {e}", dir.display()));
            }
            for (name, page) in pages::all() {
                let path = dir.join(name);
                if let Err(e) = std::fs::write(&path, page) {
                    return fail(2, &format!("{}: {e}", path.display()));
                }
                eprintln!("wrote {}", path.display());
            }
        }
    }
    ExitCode::SUCCESS
}

fn fail(code: u8, msg: &str) -> ExitCode {
    eprintln!("mmic: {msg}");
    ExitCode::from(code)
}
