//! The opsUI's end-of-run summary: the lines `mmic sim` prints about the ground (the plan's end
//! and the attempts answered, from [`crate::sim::report`]), then the efficiency over the last
//! 100 attempts (Figure 11), the commands done, what crossed the line, and the robot as its
//! last heartbeat showed it; as text, and as one JSON object (`--summary-json`).

use super::session::{Ending, Outcome};
use crate::sim::report;
use crate::sim::Summary;
use serde_json::{json, Value};
use std::fmt::Write as _;

/// The efficiency over the last (up to) 100 attempts, from the log's `attempt` events:
/// (answered, made).
pub fn last_100(records: &[Value]) -> (usize, usize) {
    let attempts: Vec<bool> = events(records, "attempt")
        .map(|e| e["ok"].as_bool().unwrap_or(false))
        .collect();
    let window = attempts
        .get(attempts.len().saturating_sub(100)..)
        .unwrap_or(&[]);
    (window.iter().filter(|ok| **ok).count(), window.len())
}

fn events<'a>(records: &'a [Value], ty: &'a str) -> impl Iterator<Item = &'a Value> + 'a {
    records
        .iter()
        .filter(move |r| r["kind"] == "event" && r["event"]["type"] == ty)
        .map(|r| &r["event"])
}

/// The commands done, by outcome: (accepted, refused, unacknowledged), and those that ended
/// unknown with the line.
fn outcomes(records: &[Value]) -> ([usize; 3], usize) {
    let mut n = [0; 3];
    for e in events(records, "done") {
        let o = &e["outcome"];
        let k = if o == "accepted" {
            0
        } else if o == "unacknowledged" {
            2
        } else {
            1
        };
        n[k] += 1;
    }
    (n, events(records, "ended_unknown").count())
}

/// The summary as text; `s` is the run as a simulator summary (for the shared lines).
pub fn text(s: &Summary, o: &Outcome, head: &str) -> String {
    let mut t = format!("{head}\n");
    let _ = writeln!(t, "{}", report::plan_line(s));
    let _ = writeln!(
        t,
        "time: {:.1} s on the plan's clock in {:.1} s wall",
        s.sim_ms as f64 / 1000.0,
        s.wall.as_secs_f64()
    );
    report::attempts_lines(&mut t, s);
    let (ok, n) = last_100(&o.records);
    let _ = writeln!(
        t,
        "efficiency: {:.0}% over the last {n} attempts ({ok} answered; Figure 11 counts 100)",
        if n == 0 {
            100.0
        } else {
            ok as f64 * 100.0 / n as f64
        }
    );
    commands_and_line(&mut t, o);
    if let Ending::Lost { at_ms, why, open } = &o.ending {
        let _ = writeln!(
            t,
            "line lost at {:.1} s: {why}; {}",
            *at_ms as f64 / 1000.0,
            open_text(open)
        );
    }
    let _ = writeln!(t, "{}", robot_line(s));
    t
}

/// The commands done by outcome, and what crossed the line.
fn commands_and_line(t: &mut String, o: &Outcome) {
    let ([acc, refd, unack], unknown) = outcomes(&o.records);
    let l = &o.line;
    let _ = writeln!(
        t,
        "commands: {} done: {acc} accepted, {refd} refused, {unack} unacknowledged; {unknown} \
         ended unknown; {} packets sent for {} commands ({} resends)",
        acc + refd + unack,
        l.commands_sent,
        l.commands_distinct,
        l.commands_sent.saturating_sub(l.commands_distinct)
    );
    let _ = writeln!(
        t,
        "line: {} bytes out, {} bytes in: {} heartbeats, {} other packets, {} bad heartbeats; \
         {} bytes dropped by the deframer, {} left incomplete",
        l.bytes_out,
        l.bytes_in,
        l.heartbeats,
        l.other_packets,
        l.bad_heartbeats,
        l.discarded,
        l.left_incomplete
    );
}

/// What became of the commands open when the line was lost.
pub fn open_text(open: &[(u16, u32)]) -> String {
    match open {
        [] => "no command was open".into(),
        _ => {
            let seqs: Vec<String> = open.iter().map(|(s, _)| s.to_string()).collect();
            format!(
                "command {} was open: it ran at most once (ended unknown)",
                seqs.join(", ")
            )
        }
    }
}

/// The robot as its last heartbeat showed it.
fn robot_line(s: &Summary) -> String {
    let Some(hb) = s.last_heartbeat else {
        return "robot: no heartbeat received".into();
    };
    let faults: Vec<String> = hb.faults.iter().map(|f| f.to_string()).collect();
    let state = match (hb.target_state, hb.command_complete) {
        (Some(st), true) => st.to_string(),
        (Some(st), false) => format!("moving to {st}"),
        (None, _) => format!("{} (not reconfigured since it started)", s.start_state),
    };
    format!(
        "robot: mode {}, state {state}, faults {} (its last heartbeat)",
        hb.mode.name(),
        if faults.is_empty() {
            "none".into()
        } else {
            faults.join(", ")
        }
    )
}

/// The summary as one JSON object, with the exit code the process returns.
pub fn json(s: &Summary, o: &Outcome, exit: u8) -> Value {
    let (ok, n) = last_100(&o.records);
    let ([acc, refd, unack], unknown) = outcomes(&o.records);
    let ending = match &o.ending {
        Ending::Done => "done",
        Ending::TimeLimit => "time_limit",
        Ending::Lost { .. } => "line_lost",
    };
    json!({
        "completed": s.completed(),
        "plan_end": o.end.map(|e| format!("{e:?}")),
        "ending": ending,
        "attempts": {"answered": s.attempts.0, "made": s.attempts.1},
        "last_100": {"answered": ok, "made": n},
        "longest_answer_ms": s.max_latency_ms,
        "commands": {"accepted": acc, "refused": refd, "unacknowledged": unack,
                     "ended_unknown": unknown},
        "line": o.line,
        "exit": exit,
    })
}
