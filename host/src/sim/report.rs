//! Live progress, the end-of-run summary and the plots (Figure 10 and 11 analogues).

use super::inject::Injection;
use super::Summary;
use crate::plot::{bar_chart, line_chart_with, LineOptions, Series};
use mmic::faults::Fault;
use mmic::node::ground::plan_runner::PlanEnd;
use mmic::refusal::Refusal;
use std::fmt::Write as _;
use std::path::Path;

/// Robot 1's board A in the log (its events carry this node name).
const BOARD_A1: &str = "board_a1";

/// Robot 1's Table 8 faults in the order board A raised them (its `faults` events; faults of
/// one tick in bit order), each once, by their `--inject` names: a module's idle-check and
/// operational-check overcurrent bits are both that module's row. The project's own motion
/// timeout (no Table 8 row) is `motion-timeout`.
pub fn faults_raised(s: &Summary) -> Vec<String> {
    let mut names: Vec<String> = Vec::new();
    for e in s.events("faults").filter(|e| e["node"] == BOARD_A1) {
        let bits = e["event"]["faults"].as_array().cloned().unwrap_or_default();
        for f in bits {
            let Ok(f) = serde_json::from_value::<Fault>(f) else {
                continue;
            };
            let name = match f.table8() {
                Some(row) => Injection::Fault(row).name(),
                None => f.name().replace('_', "-"),
            };
            if !names.contains(&name) {
                names.push(name);
            }
        }
    }
    names
}

/// Robot 1's refusals in the order board A gave them (its `executed` events): the names of
/// spec/modes.toml `[refusals]`, repeats included (a `busy` step is sent again and may be
/// refused again).
pub fn refusals(s: &Summary) -> Vec<String> {
    s.events("executed")
        .filter(|e| e["node"] == BOARD_A1)
        .filter_map(|e| e["event"]["refusal"].as_str().map(str::to_string))
        .collect()
}

/// The robot's mode as last reported: in the last heartbeat the ground received (board A's
/// own last status if none arrived).
pub fn last_mode(s: &Summary) -> String {
    match s.last_heartbeat {
        Some(hb) => hb.mode.name().to_string(),
        None => s.status["mode"].as_str().unwrap_or("standby").to_string(),
    }
}

/// `mmic sim --summary-json`: the run as one JSON object, its fields in this order.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct SummaryJson {
    /// Every robot's plan completed.
    pub completed: bool,
    /// [`last_mode`].
    pub mode: String,
    /// [`faults_raised`].
    pub faults: Vec<String>,
    /// [`refusals`].
    pub refusals: Vec<String>,
    /// The process's exit code (the caller decides it).
    pub exit: u8,
    /// With `--protocol pus`: "packets" or "frames" (absent with the legacy protocol).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub link: Option<String>,
    /// With `--link frames`: the space data link's figures (retransmissions, alerts, CLCWs);
    /// with `--sdls` also `sdls` ([`crate::sim::SdlsStats`]): `server` and `ground`, each
    /// `verified`, `protected` and `refused` by reason (`SdlsRefusal::NAMES`), and the
    /// attacker's `attack_frames`, `attacks_refused_sdls`, `attacks_refused_frame` and
    /// `attacks_passed`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frames: Option<serde_json::Value>,
    /// Sequenced commands board A took more than once (0 unless exactly-once broke).
    pub executed_twice: u64,
    /// Restarts injected (`--inject reboot-*`), all robots: `board_a`, `board_b`, `server`.
    pub restarts: serde_json::Value,
}

/// The run's [`SummaryJson`], given the exit code the process returns.
pub fn summary_json(s: &Summary, exit: u8) -> SummaryJson {
    SummaryJson {
        completed: s.completed(),
        mode: last_mode(s),
        faults: faults_raised(s),
        refusals: refusals(s),
        exit,
        link: (s.protocol == super::Protocol::Pus).then(|| s.link.name().to_string()),
        frames: s.frames.and_then(|f| serde_json::to_value(f).ok()),
        // The virtual-time engine counts as board A takes them, logged or not; the realtime
        // engine's count comes from its log.
        executed_twice: if s.realtime {
            executed_twice(s).len() as u64
        } else {
            s.executed_twice
        },
        restarts: serde_json::json!({
            "board_a": s.restarts[0], "board_b": s.restarts[1], "server": s.restarts[2],
            "ground": s.restarts[3],
        }),
    }
}

/// Pairs bolted at the 1st, 2nd and 3rd attempt, and failed (from board A's events).
pub fn bolting(s: &Summary) -> [u64; 4] {
    let mut bins = [0u64; 4];
    for e in s.events("pair") {
        let ok = e["event"]["ok"].as_bool().unwrap_or(false);
        let a = e["event"]["attempts"].as_u64().unwrap_or(0);
        let i = if ok { (a.clamp(1, 3) - 1) as usize } else { 3 };
        bins[i] += 1;
    }
    bins
}

/// Sequence numbers board A executed more than once (counted from its events).
pub fn executed_twice(s: &Summary) -> Vec<u64> {
    let mut count = std::collections::BTreeMap::new();
    for e in s.events("executed") {
        let seq = e["event"]["seq"].as_u64().unwrap_or(0);
        // `BoardA::may_run_again` on the logged event: the Heartbeat poll.
        if seq != 0 && e["event"]["command"] != "heartbeat" {
            *count.entry((e["node"].to_string(), seq)).or_insert(0u32) += 1;
        }
    }
    count
        .into_iter()
        .filter(|(_, n)| *n > 1)
        .map(|((_, s), _)| s)
        .collect()
}

/// Which WiFi packets of a run crossed and which were lost (from the packet log; none when
/// packets were not logged).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct WifiCrossings {
    /// Command packets the server boards sent to boards A.
    pub commands: u64,
    /// ... of which the link lost.
    pub commands_lost: u64,
    /// Heartbeats boards A sent back while the server was connected.
    pub heartbeats: u64,
    /// ... of which the link lost.
    pub heartbeats_lost: u64,
}

/// Counts the WiFi link's packets in the log.
pub fn wifi_crossings(s: &Summary) -> Option<WifiCrossings> {
    let mut w = WifiCrossings::default();
    let mut any = false;
    for r in s
        .records
        .iter()
        .filter(|r| r["kind"] == "packet" && r["link"] == "wifi")
    {
        any = true;
        let lost = r["fate"] == "lost";
        let from_server = r["from"].as_str().is_some_and(|f| f.starts_with("server"));
        let counted = r["fate"] == "delivered" || lost;
        match (from_server, counted) {
            (true, true) => {
                w.commands += 1;
                w.commands_lost += lost as u64;
            }
            (false, true) => {
                w.heartbeats += 1;
                w.heartbeats_lost += lost as u64;
            }
            _ => {}
        }
    }
    any.then_some(w)
}

/// The PUS packets between the ground and the server boards (`--protocol pus`), from the
/// packet log: telecommands sent, telemetry per service, and how many the link lost.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct PusCounts {
    /// Telecommand transmissions (first sends, resends and queries).
    pub tc: u64,
    /// ... of which the link lost.
    pub tc_lost: u64,
    /// Distinct telecommands (keys).
    pub tc_keys: u64,
    /// Telemetry packets the server boards sent.
    pub tm: u64,
    /// ... of which the link lost.
    pub tm_lost: u64,
    /// ST\[1\] reports, ST\[3\] housekeeping reports, ST\[5\] events, ST\[17\] answers among them.
    pub st1: u64,
    /// See `st1`.
    pub st3: u64,
    /// See `st1`.
    pub st5: u64,
    /// See `st1`.
    pub st17: u64,
}

/// Counts the PUS packets in the log; none when packets were not logged or none was PUS.
pub fn pus_counts(s: &Summary) -> Option<PusCounts> {
    let mut c = PusCounts::default();
    let mut keys = std::collections::BTreeSet::new();
    for r in s.records.iter().filter(|r| r["kind"] == "packet") {
        let lost = r["fate"] == "lost";
        match r["packet_kind"].as_str() {
            Some("tc") => {
                c.tc += 1;
                c.tc_lost += lost as u64;
                keys.insert((
                    r["packet"]["apid"].as_u64(),
                    r["packet"]["source_id"].as_u64(),
                    r["packet"]["seq_count"].as_u64(),
                ));
            }
            Some("tm") => {
                c.tm += 1;
                c.tm_lost += lost as u64;
                match r["packet"]["service"].as_u64() {
                    Some(1) => c.st1 += 1,
                    Some(3) => c.st3 += 1,
                    Some(5) => c.st5 += 1,
                    Some(17) => c.st17 += 1,
                    _ => {}
                }
            }
            _ => {}
        }
    }
    c.tc_keys = keys.len() as u64;
    (c.tc + c.tm > 0).then_some(c)
}

/// The share of attempts answered that independent losses of `loss` each way predict, and its
/// standard deviation over `n` attempts: an attempt is answered only when its command and the
/// heartbeat both cross, (1 − loss)².
pub fn expected_efficiency(loss: f64, n: u64) -> (f64, f64) {
    let p = (1.0 - loss.clamp(0.0, 1.0)).powi(2);
    (p, (p * (1.0 - p) / n.max(1) as f64).sqrt())
}

fn step_ref(s: &Summary, k: usize) -> String {
    match s.plan.get(k) {
        Some(st) => format!(
            "step {} of {} (line {}: {})",
            k + 1,
            s.plan.len(),
            st.line,
            st.text.split('#').next().unwrap_or("").trim()
        ),
        None => format!("step {} of {}", k + 1, s.plan.len()),
    }
}

fn fault_list(faults: &mmic::faults::Faults) -> String {
    let f: Vec<String> = faults.iter().map(|f| f.to_string()).collect();
    if f.is_empty() {
        "none".to_string()
    } else {
        f.join(", ")
    }
}

/// The plan's end as one line (and, for a state mismatch, what the plan expected and what
/// the robot reported).
pub fn plan_line(s: &Summary) -> String {
    match s.ends.first().copied().flatten() {
        Some(PlanEnd::Completed) => format!("plan: completed, all {} steps", s.plan.len()),
        Some(PlanEnd::Refused {
            step,
            refusal,
            robot,
        }) => {
            let mut t = format!(
                "plan: stopped at {}: refused ({refusal})",
                step_ref(s, step)
            );
            if let Some((mode, faults)) = robot {
                let _ = write!(t, ", robot in {mode} (faults: {})", fault_list(&faults));
            }
            if refusal == Refusal::InitialStateMismatch {
                let _ = write!(t, "\n  {}", mismatch(s, step));
            }
            t
        }
        Some(PlanEnd::Unacknowledged { step }) => {
            format!("plan: stopped at {}: unacknowledged", step_ref(s, step))
        }
        Some(PlanEnd::Restarted { step }) => format!(
            "plan: stopped at {}: the ground restarted while it was open (it ran at most once)",
            step_ref(s, step)
        ),
        Some(PlanEnd::Interrupted { step, mode, faults }) => format!(
            "plan: stopped at {}: interrupted, robot in {mode} (faults: {})",
            step_ref(s, step),
            fault_list(&faults)
        ),
        Some(PlanEnd::Rejected { step, code }) => format!(
            "plan: stopped at {}: the PUS gateway refused the telecommand (failure code {code:#06x})",
            step_ref(s, step)
        ),
        None => "plan: time limit reached".to_string(),
    }
}

/// The initial state of the last reconfiguration the ground sent (robot 1, from its `done`
/// events), as sent: it differs from the plan's when an initial-state-mismatch was injected.
fn sent_initial(s: &Summary) -> Option<mmic::motion::State> {
    s.events("done")
        .filter(|e| e["event"]["robot"] == 1)
        .filter_map(|e| {
            serde_json::from_value(e["event"]["command"]["reconfigure"]["initial"].clone()).ok()
        })
        .last()
}

/// What the refused step expected and what the robot last reported.
fn mismatch(s: &Summary, step: usize) -> String {
    let expected = match s.plan.get(step).map(|st| st.step) {
        Some(mmic::node::ground::plan_runner::PlanStep::Command(
            mmic::command::Command::Reconfigure(r),
        )) => match sent_initial(s).filter(|i| *i != r.initial()) {
            // An injected initial-state-mismatch: the ground sent another initial state.
            Some(sent) => format!(
                "the plan expected the robot in {}, but the ground sent the reconfiguration \
                 from {sent} (initial-state-mismatch injected)",
                r.initial()
            ),
            None => format!("the plan expected the robot in {}", r.initial()),
        },
        Some(mmic::node::ground::plan_runner::PlanStep::Command(
            mmic::command::Command::Primitive(m),
        )) => {
            format!(
                "primitive {} does not take the robot from the state it is in to {}",
                m.primitive().number(),
                m.target()
            )
        }
        _ => "the step does not fit the robot's state".to_string(),
    };
    let reported = match s.last_heartbeat {
        Some(hb) => match (hb.target_state, hb.command_complete) {
            (Some(st), true) => format!("the robot last reported {st}"),
            (Some(st), false) => format!("the robot last reported moving to {st}"),
            (None, _) => format!(
                "the robot has not been reconfigured since it started in {}",
                s.start_state
            ),
        },
        None => "no heartbeat was received".to_string(),
    };
    format!("{expected}; {reported}")
}

/// The bolting outcomes (Figure 10's counts) and robot 1's final mode, state and faults.
pub fn robot_lines(t: &mut String, s: &Summary) {
    let b = bolting(s);
    let _ = writeln!(
        t,
        "bolting: {} pairs; first attempt {}, second {}, third {}, failed {}",
        b.iter().sum::<u64>(),
        b[0],
        b[1],
        b[2],
        b[3]
    );
    let _ = writeln!(
        t,
        "robot: mode {}, state {}, faults {}",
        s.status["mode"], s.status["state"], s.status["faults"]
    );
}

/// The summary as text: one line per aspect of the run, each from a function below.
pub fn text(s: &Summary) -> String {
    let mut t = String::new();
    let _ = writeln!(t, "{}", plan_line(s));
    time_line(&mut t, s);
    if s.protocol == super::Protocol::Pus {
        pus_lines(&mut t, s);
    }
    attempts_lines(&mut t, s);
    clock_line(&mut t, s);
    commands_line(&mut t, s);
    injected_line(&mut t, s);
    robot_lines(&mut t, s);
    t
}

/// Simulated against wall time, and their ratio.
fn time_line(t: &mut String, s: &Summary) {
    let _ = writeln!(
        t,
        "time: {:.1} s simulated in {:.1} s wall ({:.1}x)",
        s.sim_ms as f64 / 1000.0,
        s.wall.as_secs_f64(),
        s.sim_ms as f64 / 1000.0 / s.wall.as_secs_f64().max(1e-9)
    );
}

/// With `--protocol pus`: the ground link, and how many packets of each service crossed it.
fn pus_lines(t: &mut String, s: &Summary) {
    let _ = writeln!(
        t,
        "protocol: pus -- PUS-C telecommands and telemetry {} between the ground and the \
         server board (the PUS gateway); legacy commands to board A",
        if s.realtime {
            "over UDP on loopback"
        } else {
            "over a simulated datagram link"
        }
    );
    if let Some(f) = &s.frames {
        let _ = writeln!(
            t,
            "link: frames -- TC transfer frames under COP-1, 256-octet TM frames with the CLCW: \
             {} TC frames ({} retransmissions, {} alerts), FARM-1 accepted {} and discarded {}; \
             {} TM frames ({} lost, {} packets cut), {} CLCWs ({} with Lockout)",
            f.tc_frames,
            f.retransmissions,
            f.alerts,
            f.accepted,
            f.discarded,
            f.tm_frames,
            f.tm_lost,
            f.tm_packets_dropped,
            f.clcws,
            f.lockout_reports
        );
        if let Some(x) = &f.sdls {
            let _ = writeln!(t, "{}", sdls_text(x));
        }
    }
    if let Some(c) = pus_counts(s) {
        let _ = writeln!(
            t,
            "pus: {} TC sent ({} telecommands, the rest resends and queries; {} lost), \
             {} TM ({} lost): {} ST[1], {} ST[3] housekeeping, {} ST[5] events, {} ST[17]",
            c.tc, c.tc_keys, c.tc_lost, c.tm, c.tm_lost, c.st1, c.st3, c.st5, c.st17
        );
    }
}

/// How many attempts were answered in time, and, with WiFi loss, what loss predicts and what
/// this run lost.
pub fn attempts_lines(t: &mut String, s: &Summary) {
    let (ok, n) = s.attempts;
    let _ = writeln!(
        t,
        "{}: {ok}/{n} attempts answered within the timeout ({:.1}%), longest answer {} ms",
        match s.protocol {
            super::Protocol::Legacy => "wifi",
            // The gateway resends to board A itself: the ground's attempts are its TCs.
            super::Protocol::Pus => "udp (ground's TC transmissions)",
        },
        if n == 0 {
            100.0
        } else {
            ok as f64 * 100.0 / n as f64
        },
        s.max_latency_ms
    );
    if s.wifi_loss > 0.0 && s.protocol == super::Protocol::Legacy {
        let (p, sd) = expected_efficiency(s.wifi_loss, n);
        let _ = writeln!(
            t,
            "  expected at {:.0}% loss each way: (1 - {:.2})^2 = {:.1}% +/- {:.1}% (1 sigma, {n} attempts)",
            s.wifi_loss * 100.0,
            s.wifi_loss,
            p * 100.0,
            sd * 100.0
        );
        if let Some(w) = wifi_crossings(s) {
            let pct = |a: u64, b: u64| a as f64 * 100.0 / b.max(1) as f64;
            let _ = writeln!(
                t,
                "  this run lost {}/{} commands ({:.1}%) and {}/{} heartbeats ({:.1}%)",
                w.commands_lost,
                w.commands,
                pct(w.commands_lost, w.commands),
                w.heartbeats_lost,
                w.heartbeats,
                pct(w.heartbeats_lost, w.heartbeats)
            );
        }
        let _ = writeln!(
            t,
            "  (an attempt is answered only if its command and the heartbeat both cross the WiFi\n  \
             link: the server forwards each attempt once and waits {} ms, the ground resends after 1.2 s)",
            s.visit_ms
        );
    }
}

/// Virtual time's guarantee, or how late the real-time run's ticks started.
pub fn clock_line(t: &mut String, s: &Summary) {
    let held = if s.held_ms > 0 {
        format!("; the clock waited {} ms for slow nodes", s.held_ms)
    } else {
        String::new()
    };
    if !s.realtime {
        let _ = writeln!(
            t,
            "engine: virtual time -- every tick on time by construction; the same seed and \
             options give the same run and log (--realtime: threads and real transports)"
        );
    } else {
        let _ = writeln!(
            t,
            "host: board ticks started at most {} ms (simulated) late{}{held}",
            s.max_tick_lateness_ms,
            match (s.host_fell_behind(), s.pace_slack_ms) {
                (true, _) =>
                    " -- the host fell behind the simulated clock, so timeouts and faults \
                          in this run may come from the host, not the robot"
                        .to_string(),
                (false, Some(slack)) => format!(" (paced, bound {slack} ms)"),
                (false, None) => String::new(),
            }
        );
    }
}

/// How many commands board A executed, answered as copies, or (wrongly) executed twice.
pub fn commands_line(t: &mut String, s: &Summary) {
    let executed = s.events("executed").count();
    let dups = s.events("duplicate").count() + s.events("stale").count();
    let twice = executed_twice(s);
    let _ = writeln!(
        t,
        "commands: {executed} executed by board A, {dups} copies answered without running, {} executed twice",
        twice.len()
    );
}

/// The injections into robot 1 and the Table 8 faults they raised (nothing when none).
fn injected_line(t: &mut String, s: &Summary) {
    let injected: Vec<String> = s
        .events("inject")
        .filter(|e| e["event"]["robot"] == 1)
        .map(|e| {
            format!(
                "{}@{}",
                e["event"]["name"].as_str().unwrap_or("?"),
                e["event"]["at_ms"].as_f64().unwrap_or(0.0) / 1000.0
            )
        })
        .collect();
    if !injected.is_empty() {
        let _ = writeln!(
            t,
            "injected: {}; Table 8 faults raised: {}",
            injected.join(", "),
            match faults_raised(s) {
                f if f.is_empty() => "none".to_string(),
                f => f.join(", "),
            }
        );
    }
}

/// The Figure 11 analogue: robot 1's efficiency over its last 100 attempts against simulated
/// time, the axis ending where the run did, headroom above 100 %, and — with WiFi loss — the
/// share that independent losses predict, (1 − loss)², as a reference line.
pub fn efficiency_chart(s: &Summary) -> String {
    let expected: Vec<(f64, f64)> = match (s.efficiency.first(), s.efficiency.last()) {
        (Some(first), Some(last)) if s.wifi_loss > 0.0 => {
            let p = expected_efficiency(s.wifi_loss, 1).0 * 100.0;
            vec![(first.0, p), (last.0, p)]
        }
        _ => Vec::new(),
    };
    let expected_name = format!("expected (1-{:.2})^2", s.wifi_loss);
    let mut series = vec![Series {
        name: "robot 1",
        points: &s.efficiency,
    }];
    if !expected.is_empty() {
        series.push(Series {
            name: &expected_name,
            points: &expected,
        });
    }
    line_chart_with(
        "WiFi efficiency over the last 100 attempts (Figure 11 analogue)",
        "simulated time (s)",
        "efficiency (%)",
        LineOptions {
            y_range: Some((0.0, 110.0)),
            x_at_data: true,
            legend: true,
        },
        &series,
    )
}

/// Writes wifi-efficiency.svg and bolting-attempts.svg into `dir`; returns their paths.
pub fn plots(s: &Summary, dir: &Path) -> std::io::Result<Vec<std::path::PathBuf>> {
    std::fs::create_dir_all(dir)?;
    let eff = efficiency_chart(s);
    let b = bolting(s);
    let bars = bar_chart(
        "Bolting attempts per fastener pair (Figure 10 analogue)",
        "pairs",
        &[
            ("1st attempt", b[0] as f64),
            ("2nd attempt", b[1] as f64),
            ("3rd attempt", b[2] as f64),
            ("failed", b[3] as f64),
        ],
    );
    let p1 = dir.join("wifi-efficiency.svg");
    let p2 = dir.join("bolting-attempts.svg");
    std::fs::write(&p1, eff)?;
    std::fs::write(&p2, bars)?;
    Ok(vec![p1, p2])
}

/// The SDLS line of a run's summary: both ends' figures, and the attacker's.
pub fn sdls_text(x: &crate::sim::SdlsStats) -> String {
    let mut t = format!(
        "sdls: AES-256-GCM both ways -- server verified {} TC frames, refused {} ({}), \
         protected {} TM frames; ground protected {} TC frames, verified {} TM frames, refused {} \
         ({})",
        x.server.verified,
        x.server.refused_total(),
        x.server.refusals_text(),
        x.server.protected,
        x.ground.protected,
        x.ground.verified,
        x.ground.refused_total(),
        x.ground.refusals_text(),
    );
    if x.attack_frames > 0 {
        t.push_str(&format!(
            "; attacker sent {} frames (replays, bit flips, BC frames from its own address): {} \
             refused by SDLS, {} by a frame check or as BC frames not from the ground, {} passed to \
             FARM-1",
            x.attack_frames, x.attacks_refused_sdls, x.attacks_refused_frame, x.attacks_passed
        ));
    }
    t
}
