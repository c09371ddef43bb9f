//! `mmic sim` and `mmic bench`: argument handling around [`crate::sim`].

use crate::error::CliError;
use crate::exit::EXIT_OK;
use crate::sim::inject::{InjectError, Injection, Scheduled};
use crate::sim::{self, report, SimConfig};
use mmic::faults::Table8;
use mmic::link::sdls::Key256;
use mmic::motion::State;
use std::io::Write;
use std::path::PathBuf;

fn ms(s: Option<f64>) -> Option<u32> {
    s.map(|s| (s.max(0.0) * 1000.0) as u32)
}

/// `mmic sim --help`'s description (then [`sim_help`] adds the injections).
pub const SIM_HELP: &str = "\
Run the host simulator. The four nodes of the paper's Figure 3 run the real mmic library: the
opsUI plan runner, the server board (relay, or PUS gateway), board A's WiFi task and control
task joined by the library's hand-off queues, and board B, around a plant model that moves the
servos, draws currents, drains the battery and locks fasteners with the paper's Figure 10
probabilities.

By default they run in virtual time: a discrete-event simulation in one thread, with simulated
links (latency, jitter, loss, duplication, reordering, cuts). It is deterministic -- the same
options and --seed give a byte-identical log -- and runs the demo at thousands of times real
time. --realtime runs the same nodes on the wall clock instead: threads, OS pipes (the serial
lines), TCP on loopback for each visit (the WiFi link), UDP with --protocol pus, at --scale
times real time; its timing depends on how busy the host is.

Live progress goes to stderr; at the end a summary is printed, the JSON-lines log of every
packet and event is written (OUT/sim.jsonl), and two SVG plots: OUT/wifi-efficiency.svg
(Figure 11 analogue) and OUT/bolting-attempts.svg (Figure 10 analogue).

--protocol pus runs the same plan over CCSDS space packets with PUS-C services: the ground
sends each step as a TC(8,1) function to the server board, which runs the PUS gateway (legacy
commands to board A as before) and answers with ST[1] verification reports, periodic ST[3]
housekeeping and ST[5] events; a step is done at its ST[1] completion. Every packet (TC, TM,
legacy) is logged with its hex and kind. --serial-loss applies to the ground link; every
injection works as in the legacy run. The default is --protocol legacy.

With --realtime the clock is paced: simulated time never runs more than 20 ms ahead of the
slowest node, so a busy host slows the run down instead of making the firmware's timeouts fire.
Before anything is sent, the plan is checked against the robot's state, from its `start` line
(`a` if none).";

/// `mmic sim --help`'s part on `--summary-json`; [`summary_json_help`] puts the library's
/// refusal names in place of `REFUSALS`.
const SUMMARY_JSON_HELP: &str = r#"--summary-json FILE writes one JSON object when the run ends:
  {"completed": false, "mode": "safed", "faults": ["bolter-overcurrent"],
   "refusals": ["not_allowed_in_mode"], "exit": 1, "executed_twice": 0,
   "restarts": {"board_a": 1, "board_b": 0, "ground": 0, "server": 0}}
completed: every step of the plan done. mode: standby, safed or operational, as the robot
last reported it (the last heartbeat the ground received). faults: the Table 8 faults board A
raised, in the order raised, each once, by their --inject names (a module's idle-check and
operational-check overcurrent bits are both that module's name). refusals: every command
board A refused, in order, by the names of spec/modes.toml [refusals]:
  REFUSALS.
exit: the exit code this run of mmic sim returns. executed_twice: sequenced commands board A
accepted more than once (0 unless exactly-once broke: a script checks it). restarts: the
restarts injected with --inject reboot-a/-b/-server/-ground, all robots (the ground's once per robot)."#;

/// `mmic sim --help`'s part on `--summary-json`, with the refusal names of the library
/// (spec/modes.toml `[refusals]`).
pub fn summary_json_help() -> String {
    let refusals: Vec<&str> = mmic::refusal::Refusal::ALL
        .iter()
        .map(|r| r.name())
        .collect();
    SUMMARY_JSON_HELP.replace("REFUSALS", &refusals.join(", "))
}

/// `mmic sim --help`'s description, with every injection and what it does.
pub fn sim_help() -> String {
    let width = Injection::ALL
        .iter()
        .chain(&Injection::REBOOTS)
        .map(|i| i.name().len())
        .max()
        .unwrap_or(0);
    let mut t = format!(
        "{SIM_HELP}\n\n\
         --inject NAME@SECONDS (repeatable; simulated seconds, decimals allowed) makes one of\n\
         Table 8's ten faults happen, silences a sensor, or sends the operator's Stop or Reset,\n\
         at that time.\n\
         Each acts physically where it can, and the firmware must detect it as the robot would:\n"
    );
    for i in Injection::ALL.iter().chain(&Injection::REBOOTS) {
        t.push_str(&format!("  {:width$}  {}\n", i.name(), i.effect()));
    }
    t.push_str(
        "Out-of-band commands (assembly-system, stop, reset) take the uplink's next free slot,\n\
         ahead of the plan's next step and of polling, each with its own sequence number; while\n\
         an accepted Stop holds, the plan starts no step until an accepted Reset. Table 8's\n\
         modes: bolting-failure and initial-state-mismatch Standby at once; low-battery and\n\
         assembly-system Standby once the motion in progress has completed; the others Safed.\n\
         The hip check runs only when Operational is entered: the demo plan enters it at its\n\
         first step, so hip-mismatch@0 is the natural use.\n\n",
    );
    t.push_str(&summary_json_help());
    t
}

/// `mmic sim --help`'s examples and exit codes.
pub const SIM_AFTER: &str = "\
Examples:
  mmic sim                                   the built-in demo plan (host/plans/demo.plan)
  mmic sim --plan my.plan --scale 20
  mmic sim --plan my.plan --check-plan       parse it and trace the robot's state, run nothing
  mmic sim --wifi-loss 0.3                   30 % of WiFi packets lost, each way
  mmic sim --inject low-battery@25 --summary-json out.json   the battery sags mid-reconfiguration
  mmic sim --inject hip-mismatch@0           the hip encoder reads off from power-up
  mmic sim --inject stop@28 --inject reset@31   the operator stops the motion and resumes it
  mmic sim --protocol pus                    the demo over PUS: telecommands and telemetry
  mmic sim --wifi-dup 0.2 --wifi-jitter 5    virtual-time links: duplicated, jittered WiFi packets
  mmic sim --realtime --scale 20             the same on real threads, pipes and TCP
  mmic sim --realtime --opsui-serial /dev/ttyUSB1   robot and server board for `mmic opsui`
                                             on the far end of the device (no ground here)

Exit codes: 0 the plan completed; 1 it stopped (refused or unacknowledged step, time limit);
2 bad arguments or a malformed plan file, or a step that does not fit the robot's state
(line and column are given); 3 an I/O error; 4 (--realtime only) the host fell so far behind
the simulated clock that the outcome may be the host's (the paced clock prevents this: it
waits for the slowest node, so a busy host slows the run down instead). With --opsui-serial:
0 the run ended (the line closed, or --max-seconds), 1 board A ran a command twice, 5 the
serial device cannot be opened.";

/// Arguments of `mmic sim`.
#[derive(Debug, clap::Args)]
pub struct SimArgs {
    /// Plan file (format: see host/plans/demo.plan); the built-in demo without it.
    #[arg(long, value_name = "FILE")]
    pub plan: Option<PathBuf>,
    /// Between the ground and the server board: legacy (the paper's packets over the serial
    /// line) or pus (PUS-C telecommands and telemetry over UDP, the server board as gateway).
    #[arg(long, default_value = "legacy", value_parser = protocol)]
    pub protocol: sim::Protocol,
    /// With --protocol pus: packets (one space packet per datagram) or frames (the space data
    /// link: TC transfer frames under COP-1, fixed-length TM transfer frames with the CLCW).
    #[arg(long, default_value = "packets", value_parser = link_layer)]
    pub link: sim::LinkLayer,
    /// With --realtime: simulated seconds per wall second (default 10; 1 with --opsui-serial,
    /// whose opsUI must then run at the same scale).
    #[arg(long)]
    pub scale: Option<f64>,
    /// Seed for losses and fastener locks.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// WiFi packet loss, each direction, 0..1.
    #[arg(long, default_value_t = 0.0, value_parser = probability)]
    pub wifi_loss: f64,
    /// opsUI <-> server serial packet loss (the UDP link's with --protocol pus), 0..1.
    #[arg(long, default_value_t = 0.0, value_parser = probability)]
    pub serial_loss: f64,
    /// Board A <-> board B serial packet loss, 0..1.
    #[arg(long, default_value_t = 0.0, value_parser = probability)]
    pub ab_loss: f64,
    /// Inject a Table 8 fault, or send the operator's Stop or Reset, at a simulated time
    /// (repeatable); the names and what each does are listed above.
    #[arg(long = "inject", value_name = "NAME@SECONDS", value_parser = parse_injection)]
    pub inject: Vec<Scheduled>,
    /// Write the run's summary as one JSON object to this file (format above).
    #[arg(long, value_name = "FILE")]
    pub summary_json: Option<PathBuf>,
    /// The battery sags below 10 V from this simulated second on (= --inject low-battery@S).
    #[arg(long, value_name = "S")]
    pub low_battery_at: Option<f64>,
    /// Arm A hits an obstacle (3.5 A for 0.5 s) at this simulated second
    /// (= --inject locomotion-overcurrent@S).
    #[arg(long, value_name = "S")]
    pub overcurrent_at: Option<f64>,
    /// Board B is cut off from board A at this simulated second
    /// (= --inject internal-comm-loss@S).
    #[arg(long, value_name = "S")]
    pub cut_b_at: Option<f64>,
    /// Give up after this many simulated seconds.
    #[arg(long, default_value_t = 900.0)]
    pub max_seconds: f64,
    /// Directory for the log and the plots.
    #[arg(long, value_name = "DIR", default_value = "target/sim")]
    pub out: PathBuf,
    /// No live progress.
    #[arg(long)]
    pub quiet: bool,
    /// With --protocol pus: an external ground (YAMCS) instead of the plan runner. The
    /// server board sends its telemetry to this UDP address (e.g. 127.0.0.1:18015) and takes
    /// telecommands on --ground-tc-port; no plan runs, the scale is 1 (the ground's timeouts
    /// are wall time) and the run ends after --max-seconds or when killed. Prints one JSON line
    /// per packet on stdout, with --link frames one per TC and TM transfer frame (one frame per
    /// datagram each way; ground/README.md).
    #[arg(long, value_name = "ADDR", requires = "ground_tc_port")]
    pub ground_tm_to: Option<std::net::SocketAddr>,
    /// The UDP port on 127.0.0.1 where the external ground's telecommands arrive (0: a free
    /// one, printed in the first line).
    #[arg(long, value_name = "PORT", requires = "ground_tm_to")]
    pub ground_tc_port: Option<u16>,
    /// SDLS on the space data link (--link frames; implies --sdls): the directory of the keys,
    /// `spi-<TC SPI>.key` and `spi-<TM SPI>.key` of each robot n (TC SPI 256 + n, TM SPI
    /// 512 + n: robot 1's are `spi-257.key` and `spi-513.key`), 32 octets each (YAMCS's
    /// `keyFile`s). With an external ground (--ground-tm-to), robot 1's. Keys stay out of the
    /// source tree, the logs and the output.
    #[arg(long, value_name = "DIR")]
    pub sdls_keys: Option<PathBuf>,
    /// The durable state of the --sdls-keys's counters (required with them; not inside the
    /// key directory): key fingerprints (not keys), SDLS counters, FARM-1's progress and the
    /// kept telecommand keys, written (temporary file, fsync, rename) before anything that
    /// depends on it leaves. Made once per set of keys by `mmic sdls provision --keys DIR
    /// --state FILE`; a run never makes it, and refuses to start without it.
    #[arg(long, value_name = "FILE")]
    pub sdls_state: Option<PathBuf>,
    /// SDLS (CCSDS 355.0, AES-256-GCM) on the space data link of the simulator's own ground
    /// (--protocol pus --link frames): the ground protects its TC data frames and verifies the
    /// TM frames, the server board verifies the TC frames before FARM-1 and protects its TM
    /// frames; both ends' durable counters are kept for the run. Keys from --sdls-keys, else
    /// made at run time: in virtual time derived from --seed, so that a run stays
    /// deterministic (such keys are for simulation only: anyone with the seed has them); with
    /// --realtime, random. The summary gains both ends' SDLS figures (frames verified,
    /// protected, refused by reason); the log shows a protected frame's headers, SPI and IV,
    /// never its packets or a key.
    #[arg(long)]
    pub sdls: bool,
    /// With --sdls, virtual time: an attacker on each robot's uplink. For each TC frame the
    /// uplink delivers, the chance (0..1) that the attacker also sends, from its own address, a
    /// captured TC data frame again, a copy with one bit flipped (its FECF made good), or a BC
    /// frame (Unlock, or Set V(R) to any value), a third each. Every such frame must be refused
    /// before FARM-1; the summary counts them.
    #[arg(long, value_name = "P", default_value_t = 0.0)]
    pub sdls_attack: f64,
    /// Run on the wall clock instead of in virtual time: real threads, OS pipes, TCP and UDP
    /// on loopback, at --scale times real time (the transports' own test; its timing depends
    /// on how busy the host is). The default is the virtual-time engine: deterministic, one
    /// thread, as fast as the host goes.
    #[arg(long)]
    pub realtime: bool,
    /// With --realtime: the server board's opsUI line on this serial device (spec/boards.toml
    /// `[ops_line]`) instead of the internal pipe, and no ground of its own: an opsUI at the other
    /// end (`mmic opsui --serial`) runs the plan. Robot 1 and the paper's server board (legacy
    /// relay) run until the line closes (end of file or hang-up: the opsUI side finished) or
    /// --max-seconds; the robot starts in --plan's `start` state (its steps are the opsUI's).
    /// Prints the server board's summary (commands queued, resent, superseded, refused,
    /// heartbeats forwarded) and board A's (commands executed, executed twice).
    #[arg(long, value_name = "DEV", requires = "realtime")]
    pub opsui_serial: Option<String>,
    /// Virtual time: latency of each direction of the WiFi link, ms (jitter: --wifi-jitter).
    #[arg(long, value_name = "MS")]
    pub wifi_latency: Option<f64>,
    /// Virtual time: up to this much extra delay per WiFi packet, ms.
    #[arg(long, value_name = "MS")]
    pub wifi_jitter: Option<f64>,
    /// Virtual time: probability that a WiFi packet arrives twice, 0..1.
    #[arg(long, default_value_t = 0.0, value_parser = probability)]
    pub wifi_dup: f64,
    /// Virtual time: probability that a WiFi packet is held back 50 ms and overtaken, 0..1.
    #[arg(long, default_value_t = 0.0, value_parser = probability)]
    pub wifi_reorder: f64,
    /// Parse the plan and follow the robot's state through it, then exit without running:
    /// a step that does not fit the state is reported with its line and column.
    #[arg(long)]
    pub check_plan: bool,
    /// Virtual time: write robot 1's replay trace to FILE (every call of its nodes with its
    /// time, sensor readings and bytes), for `mmic replay` and the bare-metal RV32 runner
    /// (benches/rv32/README.md).
    #[arg(long, value_name = "FILE", conflicts_with_all = ["realtime", "ground_tm_to"])]
    pub record: Option<std::path::PathBuf>,
}

/// `--inject`'s value.
fn parse_injection(s: &str) -> Result<Scheduled, InjectError> {
    s.parse()
}

/// Every injection of the command line: the `--inject` values, then the older options, which
/// are aliases of theirs.
fn injections(a: &SimArgs) -> Result<Vec<Scheduled>, InjectError> {
    let mut all = a.inject.clone();
    for (seconds, row) in [
        (a.low_battery_at, Table8::LowBattery),
        (a.overcurrent_at, Table8::LocomotionOvercurrent),
        (a.cut_b_at, Table8::InternalCommLoss),
    ] {
        if let Some(s) = seconds {
            all.push(Scheduled::at_seconds(Injection::Fault(row), s)?);
        }
    }
    Ok(all)
}

fn protocol(s: &str) -> Result<sim::Protocol, String> {
    s.parse()
}

fn link_layer(s: &str) -> Result<sim::LinkLayer, String> {
    s.parse()
}

fn probability(s: &str) -> Result<f64, String> {
    let v: f64 = s.parse().map_err(|e| format!("{s:?}: {e}"))?;
    if (0.0..=1.0).contains(&v) {
        Ok(v)
    } else {
        Err(format!("{v} is not a probability in 0..=1"))
    }
}

/// The plan `mmic sim` (and `mmic opsui`) runs (the built-in demo without `--plan`), with its
/// name for errors.
pub(crate) fn load_plan(
    plan: Option<&std::path::Path>,
) -> Result<(PathBuf, crate::plan::Plan), CliError> {
    let (path, text) = match plan {
        None => (
            PathBuf::from("host/plans/demo.plan (built in)"),
            sim::DEMO_PLAN.to_string(),
        ),
        Some(path) => {
            let text = std::fs::read_to_string(path).map_err(|source| CliError::Read {
                path: path.to_path_buf(),
                source,
            })?;
            (path.to_path_buf(), text)
        }
    };
    let plan = crate::plan::parse(&text).map_err(|error| CliError::Plan {
        path: path.clone(),
        error,
    })?;
    Ok((path, plan))
}

/// Runs `mmic sim`.
pub fn sim(a: SimArgs, out: &mut dyn Write) -> Result<(), CliError> {
    let (path, plan) = load_plan(a.plan.as_deref())?;
    // Every step must fit the state the robot will be in: refused here, with its line and
    // column, before anything is sent.
    let scheduled = injections(&a)?;
    if a.opsui_serial.is_some() {
        crate::opsui::server::refuse(&a, &scheduled)?;
    }
    let start = plan.start.unwrap_or(SimConfig::DEFAULT_START);
    let states = plan
        .trace(start)
        .map_err(|error| CliError::Plan { path, error })?;
    if a.check_plan {
        return plan_ok(&plan, start, &states, out);
    }
    let steps = sim::steps_of(&plan);
    std::fs::create_dir_all(&a.out).map_err(|source| CliError::Write {
        path: a.out.clone(),
        source,
    })?;
    let mut cfg = config(&a, steps, start, scheduled)?;
    if let Some(device) = &a.opsui_serial {
        return crate::opsui::server::sim(&a, cfg, device, out);
    }
    let ground = a.ground_tm_to.zip(a.ground_tc_port);
    let sdls = sdls_options(&a, &cfg, ground.is_some())?;
    if let Some((tm_to, tc_port)) = ground {
        let (keys, store) =
            match sdls {
                Some(Sdls {
                    keys: sim::SdlsKeys::Given(mut v),
                    state: Some(store),
                }) if !v.is_empty() => (Some(v.swap_remove(0)), store),
                // Refused by sdls_options: an external ground's link is secured only with
                // given keys and their state.
                Some(_) => return Err(CliError::Usage(
                    "--sdls with an external ground needs --sdls-keys DIR and --sdls-state FILE"
                        .into(),
                )),
                None => (None, sim::durable::Durable::memory()),
            };
        return external(cfg, tm_to, tc_port, keys, store, out);
    }
    if let Some(Sdls { keys, state }) = sdls {
        cfg.sdls = Some(sim::SdlsConfig {
            keys,
            state: state.and_then(|d| d.path()),
            attack: a.sdls_attack,
        });
    }
    let summary = sim::run(&cfg).map_err(CliError::Sim)?;
    let plots = report::plots(&summary, &a.out).map_err(|source| CliError::Write {
        path: a.out.clone(),
        source,
    })?;
    write!(out, "{}", report::text(&summary)).map_err(CliError::Output)?;
    writeln!(out, "log: {}", a.out.join("sim.jsonl").display()).map_err(CliError::Output)?;
    for p in plots {
        writeln!(out, "plot: {}", p.display()).map_err(CliError::Output)?;
    }
    let verdict = verdict(&summary);
    if let Some(path) = &a.summary_json {
        let exit = exit_code(&summary);
        let json = serde_json::to_string_pretty(&report::summary_json(&summary, exit))
            .map_err(|e| CliError::Output(e.into()))?;
        std::fs::write(path, json + "\n").map_err(|source| CliError::Write {
            path: path.clone(),
            source,
        })?;
    }
    verdict
}

/// `--check-plan`: the plan's step count, robot and the states it passes through.
fn plan_ok(
    plan: &crate::plan::Plan,
    start: State,
    states: &[State],
    out: &mut dyn Write,
) -> Result<(), CliError> {
    let mut path_of_states = vec![start.letter().to_string()];
    for s in states {
        if path_of_states.last().map(String::as_str) != Some(&s.letter().to_string()) {
            path_of_states.push(s.letter().to_string());
        }
    }
    writeln!(
        out,
        "plan OK: {} steps for robot {}, states {}",
        plan.steps.len(),
        plan.robot.get(),
        path_of_states.join(" -> ")
    )
    .map_err(CliError::Output)
}

/// The simulation's configuration from the command line: the plan's steps from `start`, the
/// links, the scheduled injections, the pace and the outputs.
fn config(
    a: &SimArgs,
    steps: Vec<sim::SimStep>,
    start: State,
    scheduled: Vec<Scheduled>,
) -> Result<SimConfig, CliError> {
    let mut cfg = SimConfig::with_steps(steps);
    cfg.start_state = start;
    cfg.protocol = a.protocol;
    cfg.link = a.link;
    if a.link == sim::LinkLayer::Frames && a.protocol != sim::Protocol::Pus {
        return Err(CliError::Usage("--link frames needs --protocol pus".into()));
    }
    cfg.scale = a
        .scale
        .unwrap_or(if a.opsui_serial.is_some() { 1.0 } else { 10.0 });
    cfg.seed = a.seed;
    cfg.wifi_loss = a.wifi_loss;
    cfg.serial_loss = a.serial_loss;
    cfg.ab_loss = a.ab_loss;
    for s in scheduled {
        cfg.inject(s)?;
    }
    cfg.realtime = a.realtime;
    if let Some(l) = a.wifi_latency {
        cfg.links.wifi.latency_us = (l.max(0.0) * 1000.0) as u64;
    }
    if let Some(j) = a.wifi_jitter {
        cfg.links.wifi.jitter_us = (j.max(0.0) * 1000.0) as u64;
    }
    cfg.links.wifi.duplicate = a.wifi_dup;
    cfg.links.wifi.reorder = a.wifi_reorder;
    cfg.links.wifi.reorder_us = 50_000;
    cfg.max_sim_ms = ms(Some(a.max_seconds)).unwrap_or(u32::MAX);
    cfg.log_path = Some(a.out.join("sim.jsonl"));
    cfg.record = a.record.clone();
    cfg.progress = !a.quiet;
    Ok(cfg)
}

/// The SDLS a run was asked for: its keys and, for given keys, their durable store.
struct Sdls {
    keys: sim::SdlsKeys,
    state: Option<sim::durable::Durable>,
}

/// The SDLS options, checked as a whole: nothing runs weaker than asked. Any SDLS option asks
/// for SDLS; every set that cannot give it is refused here, naming what is missing (exit 2),
/// before anything is sent: SDLS needs the space data link; given keys need their state file
/// (else a second run reuses IVs and accepts the first run's frames); an external ground
/// needs given keys (it holds the same); a state file must be provisioned for those keys.
fn sdls_options(a: &SimArgs, cfg: &SimConfig, external: bool) -> Result<Option<Sdls>, CliError> {
    let asked = a.sdls || a.sdls_keys.is_some() || a.sdls_state.is_some() || a.sdls_attack != 0.0;
    if !asked {
        return Ok(None);
    }
    let usage = |m: &str| Err(CliError::Usage(m.to_string()));
    if cfg.protocol != sim::Protocol::Pus || cfg.link != sim::LinkLayer::Frames {
        return usage("SDLS (--sdls, --sdls-keys, --sdls-state, --sdls-attack) protects the space data link: it needs --protocol pus --link frames; refusing to run without the protection asked for");
    }
    if a.sdls_attack != 0.0 && !a.sdls && a.sdls_keys.is_none() {
        return usage("--sdls-attack attacks a secured link: it needs --sdls");
    }
    if !(0.0..=1.0).contains(&a.sdls_attack) {
        return Err(CliError::Usage(format!(
            "--sdls-attack {}: a chance, 0..1",
            a.sdls_attack
        )));
    }
    if a.sdls_attack > 0.0 && (cfg.realtime || external) {
        return usage("--sdls-attack runs in virtual time with the simulator's own ground (not with --realtime or an external ground)");
    }
    if cfg.record.is_some() {
        return usage("--record runs without SDLS (a replay trace has no keys)");
    }
    let (dir, state) = match (&a.sdls_keys, &a.sdls_state) {
        (None, Some(_)) => return usage("--sdls-state keeps the counters of given keys: it needs --sdls-keys DIR"),
        (Some(_), None) => return usage("--sdls-keys DIR needs --sdls-state FILE: the durable counters of those keys, kept between runs (made once by `mmic sdls provision --keys DIR --state FILE`); without them a second run would reuse IVs and accept the first run's frames again"),
        (None, None) if external => return usage("--sdls with an external ground (--ground-tm-to) needs --sdls-keys DIR (the ground's keys) and --sdls-state FILE: refusing to run the link in clear"),
        (None, None) => {
            let keys = if cfg.realtime { sim::SdlsKeys::Random } else { sim::SdlsKeys::Seeded };
            return Ok(Some(Sdls { keys, state: None }));
        }
        (Some(d), Some(s)) => (d, s),
    };
    crate::sdlscli::outside_keys(dir, state, "--sdls-state")?;
    let robots = if external { 1 } else { cfg.robots.max(1) };
    let keys = (0..robots)
        .map(|i| {
            let n = mmic::units::BoardNumber::new((i % 255) as u8 + 1)
                .unwrap_or(mmic::units::BoardNumber::ONE);
            crate::sdlscli::read_keys(dir, n)
        })
        .collect::<Result<Vec<_>, _>>()?;
    let store = sim::durable::Durable::open(state).map_err(|e| CliError::Usage(e.to_string()))?;
    // Every robot's link must boot from it, at both ends the run has: refused now (exit 2)
    // rather than a link stopped later.
    for (i, (tc, tm)) in keys.iter().enumerate() {
        let n = mmic::units::BoardNumber::new((i % 255) as u8 + 1)
            .unwrap_or(mmic::units::BoardNumber::ONE);
        let ends: &[_] = if external {
            &[(
                mmic::node::server::store::End::Server,
                sim::durable::Section::Server,
            )]
        } else {
            &[
                (
                    mmic::node::server::store::End::Server,
                    sim::durable::Section::Server,
                ),
                (
                    mmic::node::server::store::End::Ground,
                    sim::durable::Section::Ground,
                ),
            ]
        };
        for (end, section) in ends {
            mmic::node::server::store::boot(*end, n, tc, tm, |k| store.lookup(*section, k))
                .map_err(|e| {
                    CliError::Usage(format!(
                        "--sdls-state {}: robot {}, the {} end: {e}",
                        state.display(),
                        n.get(),
                        section.name()
                    ))
                })?;
        }
    }
    Ok(Some(Sdls {
        keys: sim::SdlsKeys::Given(keys),
        state: Some(store),
    }))
}

/// `mmic sim --ground-tm-to`: the robot and its server board, commanded by an external ground
/// over UDP for --max-seconds of wall time; the packet lines go to `out`.
fn external(
    mut cfg: SimConfig,
    tm_to: std::net::SocketAddr,
    tc_port: u16,
    sdls: Option<(Key256, Key256)>,
    store: sim::durable::Durable,
    out: &mut dyn Write,
) -> Result<(), CliError> {
    if cfg.protocol != sim::Protocol::Pus {
        return Err(CliError::Usage(
            "--ground-tm-to and --ground-tc-port need --protocol pus".into(),
        ));
    }
    cfg.realtime = true;
    cfg.scale = 1.0;
    cfg.paced = false;
    cfg.progress = false;
    // The node threads send their packet lines here; this thread writes them to `out`
    // (which may hold the stdout lock) until the run ends.
    let (tx, rx) = std::sync::mpsc::channel::<Vec<u8>>();
    cfg.external = Some(sim::External {
        tm_to,
        tc_port,
        wire: sim::nodes::WireLog(std::sync::Arc::new(std::sync::Mutex::new(Box::new(Lines(
            tx,
        ))))),
        sdls,
        store,
    });
    let summary = std::thread::scope(|s| -> Result<sim::Summary, CliError> {
        let run = s.spawn(move || sim::run(&cfg));
        for line in rx {
            out.write_all(&line)
                .and_then(|_| out.flush())
                .map_err(CliError::Output)?;
        }
        run.join()
            .map_err(|_| CliError::Sim(std::io::Error::other("the simulation panicked")))?
            .map_err(CliError::Sim)
    })?;
    let done =
        serde_json::json!({"done": true, "sim_ms": summary.sim_ms, "status": summary.status});
    writeln!(out, "{done}").map_err(CliError::Output)?;
    Ok(())
}

/// A writer that hands what it is given to another thread.
struct Lines(std::sync::mpsc::Sender<Vec<u8>>);

impl Write for Lines {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.0
            .send(buf.to_vec())
            .map_err(|_| std::io::Error::other("output closed"))?;
        Ok(buf.len())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

/// The exit code `mmic sim` returns for this run: 0 completed, 1 incomplete, 4 the host fell
/// behind (the `exit` of `--summary-json`).
pub fn exit_code(summary: &sim::Summary) -> u8 {
    verdict(summary)
        .err()
        .map_or(EXIT_OK, |e| CliError::exit_code(&e))
}

/// How the run ends for the process: completed, incomplete, or not the robot's outcome.
fn verdict(summary: &sim::Summary) -> Result<(), CliError> {
    if summary.host_fell_behind() {
        // Only an unpaced run can get here; say so rather than report the host's timeouts as
        // the robot's.
        return Err(CliError::HostBehind {
            late_ms: summary.max_tick_lateness_ms,
        });
    }
    if summary.completed() {
        Ok(())
    } else {
        Err(CliError::Incomplete(
            report::text(summary)
                .lines()
                .next()
                .unwrap_or_default()
                .to_string(),
        ))
    }
}

/// Runs `mmic bench`.
pub fn bench(max: u8, seconds: u32, out: &mut dyn Write) -> Result<(), CliError> {
    let result = crate::sim::bench::largest(max, seconds, &mut |line| {
        eprintln!("{line}");
    })
    .map_err(CliError::Sim)?;
    writeln!(out, "{result}").map_err(CliError::Output)?;
    Ok(())
}
