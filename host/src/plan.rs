//! Plan files: what the simulated opsUI sends, one step per line.
//!
//! ```
//! use mmic_host::plan::{parse, Action};
//! let plan = parse("robot 2\nmode operational   # power up\nreconfigure a -> m\nwait 1.5s\n").unwrap();
//! assert_eq!(plan.robot.get(), 2);
//! assert_eq!(plan.steps.len(), 3);
//! assert_eq!(plan.steps[2].action, Action::Wait { ms: 1500 });
//! let err = parse("mode operational\nbolt 5\n").unwrap_err();
//! assert_eq!((err.line, err.column), (2, 6));
//! assert_eq!(err.to_string(), "line 2, column 6: expected a bolter pair 1..=4 or `all`, found \"5\"");
//! ```
//!
//! # Format
//!
//! UTF-8 text. `#` starts a comment; blank lines are skipped; keywords are case-insensitive
//! and separated by spaces or tabs. An optional first step-less line `robot N` (1..=255,
//! default 1) names the robot. Each other line is one step:
//!
//! | step | meaning (Table 1) |
//! |---|---|
//! | `heartbeat`, `stop`, `reset`, `system-fault`, `clear-faults` | those commands |
//! | `mode standby\|operational\|safed` | operating mode (Table 7) |
//! | `arm a\|b contract\|extend\|<µs>` | arm servo; a pulse width 500..=2500, `1500` or `1500us` |
//! | `gripper a\|b contract\|extend\|<µs>` | gripper servo |
//! | `hip home\|straight\|cw\|ccw\|<degrees>` | hip; degrees 0 ≤ d < 360, up to 2 decimals, `45`, `45.5deg` |
//! | `bolt 1..4\|all`, `unbolt 1..4\|all`, `bolters down` | bolters |
//! | `primitive 1..8` | a motion primitive (Table 6) |
//! | `reconfigure <from> -> <to>` | a reconfiguration between Table 5 states a..o |
//! | `power on\|off <module>\|all` | modules: `hip`, `arm-a`, `arm-b`, `gripper-a`, `gripper-b`, `bolter-a`, `bolter-b` |
//! | `wait <duration>` | `500ms`, `2s`, `1.5s`; at most one hour |
//!
//! Errors name the line and the column (1-based, in characters) of the offending token.

use mmic::command::{
    BolterCommand, BolterPair, Command, Fasteners, HipTarget, PowerTarget, ReconfigurationError,
    ServoTarget,
};
use mmic::mode::Mode;
use mmic::motion::{Primitive, State};
use mmic::units::{BoardNumber, HipAngle, Module, PulseWidth, Side};
use std::fmt::Write as _;

/// A parsed plan.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Plan {
    /// The robot it is for.
    pub robot: BoardNumber,
    /// The steps, in order.
    pub steps: Vec<Step>,
}

/// One step.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Step {
    /// Line number, 1-based.
    pub line: usize,
    /// The line without its comment, trimmed (for progress output).
    pub text: String,
    /// What to do.
    pub action: Action,
}

/// What a step does.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Action {
    /// Send a command.
    Command(Command),
    /// Wait.
    Wait {
        /// Milliseconds.
        ms: u32,
    },
}

/// A malformed plan: where, and why.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("line {line}, column {column}: {kind}")]
pub struct PlanError {
    /// Line, 1-based.
    pub line: usize,
    /// Column of the offending token, 1-based, in characters.
    pub column: usize,
    /// What is wrong.
    pub kind: PlanErrorKind,
}

/// What is wrong with a plan.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum PlanErrorKind {
    /// The first word is no step.
    #[error("unknown step {found:?}; expected one of: {STEPS}")]
    UnknownStep {
        /// The word.
        found: String,
    },
    /// The line ends too early.
    #[error("`{step}` needs {expected}")]
    Missing {
        /// The step.
        step: &'static str,
        /// What it needs next.
        expected: &'static str,
    },
    /// A word is not what the step takes.
    #[error("expected {expected}, found {found:?}")]
    Bad {
        /// What was expected.
        expected: &'static str,
        /// The word.
        found: String,
    },
    /// More words than the step takes.
    #[error("unexpected {found:?} after a complete step")]
    Trailing {
        /// The word.
        found: String,
    },
    /// `robot` after the first step, or twice.
    #[error("`robot` must come once, before the first step")]
    RobotAfterSteps,
    /// The reconfiguration is not one.
    #[error("{0}")]
    Reconfiguration(ReconfigurationError),
    /// No step at all.
    #[error("the plan has no step")]
    Empty,
}

const STEPS: &str = "heartbeat, stop, reset, system-fault, clear-faults, mode, arm, gripper, hip, bolt, unbolt, bolters, primitive, reconfigure, power, wait";

/// A word and its 1-based column.
#[derive(Debug, Clone, Copy)]
struct Tok<'a> {
    text: &'a str,
    col: usize,
}

fn tokens(line: &str) -> Vec<Tok<'_>> {
    let mut out = Vec::new();
    let mut start: Option<(usize, usize)> = None; // (byte, column)
    let mut col = 0;
    let chars: Vec<(usize, char)> = line.char_indices().collect();
    let mut i = 0;
    while i < chars.len() {
        let (b, c) = chars[i];
        col += 1;
        let arrow = c == '-' && chars.get(i + 1).is_some_and(|&(_, n)| n == '>');
        if c.is_whitespace() || arrow {
            if let Some((s, sc)) = start.take() {
                out.push(Tok {
                    text: &line[s..b],
                    col: sc,
                });
            }
            if arrow {
                out.push(Tok {
                    text: &line[b..b + 2],
                    col,
                });
                col += 1;
                i += 1;
            }
        } else if start.is_none() {
            start = Some((b, col));
        }
        i += 1;
    }
    if let Some((s, sc)) = start {
        out.push(Tok {
            text: &line[s..],
            col: sc,
        });
    }
    out
}

struct Line<'a> {
    n: usize,
    toks: Vec<Tok<'a>>,
    at: usize,
    end_col: usize,
}

impl<'a> Line<'a> {
    fn err(&self, col: usize, kind: PlanErrorKind) -> PlanError {
        PlanError {
            line: self.n,
            column: col,
            kind,
        }
    }

    fn next(&mut self, step: &'static str, expected: &'static str) -> Result<Tok<'a>, PlanError> {
        match self.toks.get(self.at) {
            Some(t) => {
                self.at += 1;
                Ok(*t)
            }
            None => Err(self.err(self.end_col, PlanErrorKind::Missing { step, expected })),
        }
    }

    fn bad(&self, t: Tok<'_>, expected: &'static str) -> PlanError {
        self.err(
            t.col,
            PlanErrorKind::Bad {
                expected,
                found: t.text.to_string(),
            },
        )
    }

    fn done(&self) -> Result<(), PlanError> {
        match self.toks.get(self.at) {
            None => Ok(()),
            Some(t) => Err(self.err(
                t.col,
                PlanErrorKind::Trailing {
                    found: t.text.to_string(),
                },
            )),
        }
    }
}

fn lower(t: Tok<'_>) -> String {
    t.text.to_ascii_lowercase()
}

fn side(l: &mut Line<'_>, step: &'static str) -> Result<Side, PlanError> {
    let t = l.next(step, "a side, `a` or `b`")?;
    match lower(t).as_str() {
        "a" => Ok(Side::A),
        "b" => Ok(Side::B),
        _ => Err(l.bad(t, "a side, `a` or `b`")),
    }
}

const SERVO: &str = "`contract`, `extend` or a pulse width 500..=2500 us";

fn servo(l: &mut Line<'_>, step: &'static str) -> Result<ServoTarget, PlanError> {
    let t = l.next(step, SERVO)?;
    let w = lower(t);
    match w.as_str() {
        "contract" => Ok(ServoTarget::Contract),
        "extend" => Ok(ServoTarget::Extend),
        _ => {
            let digits = w.strip_suffix("us").unwrap_or(&w);
            digits
                .parse::<u16>()
                .ok()
                .and_then(|v| PulseWidth::new(v).ok())
                .map(ServoTarget::Position)
                .ok_or_else(|| l.bad(t, SERVO))
        }
    }
}

const HIP: &str = "`home`, `straight`, `cw`, `ccw` or an angle 0 <= degrees < 360 (2 decimals)";

fn hip(l: &mut Line<'_>) -> Result<HipTarget, PlanError> {
    let t = l.next("hip", HIP)?;
    let w = lower(t);
    Ok(match w.as_str() {
        "home" => HipTarget::Home,
        "straight" => HipTarget::Straight,
        "cw" => HipTarget::RightAngleCw,
        "ccw" => HipTarget::RightAngleCcw,
        _ => {
            let num = w.strip_suffix("deg").unwrap_or(&w);
            let centi = decimal(num, 2).ok_or_else(|| l.bad(t, HIP))?;
            let a = u16::try_from(centi)
                .ok()
                .and_then(|c| HipAngle::new(c).ok())
                .ok_or_else(|| l.bad(t, HIP))?;
            HipTarget::Angle(a)
        }
    })
}

/// `s` as an integer number of 10^-`places` units (no sign, at most `places` decimals).
fn decimal(s: &str, places: u32) -> Option<u64> {
    let (int, frac) = s.split_once('.').unwrap_or((s, ""));
    if int.is_empty() || !int.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    if frac.len() > places as usize || !frac.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    let scale = 10u64.pow(places);
    let i: u64 = int.parse().ok()?;
    let f: u64 = if frac.is_empty() {
        0
    } else {
        frac.parse::<u64>().ok()? * 10u64.pow(places - frac.len() as u32)
    };
    i.checked_mul(scale)?.checked_add(f)
}

const PAIR: &str = "a bolter pair 1..=4 or `all`";

fn fasteners(l: &mut Line<'_>, step: &'static str) -> Result<Fasteners, PlanError> {
    let t = l.next(step, PAIR)?;
    if lower(t) == "all" {
        return Ok(Fasteners::All);
    }
    t.text
        .parse::<u8>()
        .ok()
        .and_then(BolterPair::from_number)
        .map(Fasteners::Pair)
        .ok_or_else(|| l.bad(t, PAIR))
}

const STATE: &str = "a Table 5 state a..o";

fn state(l: &mut Line<'_>) -> Result<State, PlanError> {
    let t = l.next("reconfigure", "`<from> -> <to>` (states a..o)")?;
    let mut cs = t.text.chars();
    match (cs.next(), cs.next()) {
        (Some(c), None) => {
            State::from_letter(c.to_ascii_lowercase()).ok_or_else(|| l.bad(t, STATE))
        }
        _ => Err(l.bad(t, STATE)),
    }
}

const MODULE: &str =
    "a module (hip, arm-a, arm-b, gripper-a, gripper-b, bolter-a, bolter-b) or `all`";

/// The plan-file name of a module.
pub fn module_name(m: Module) -> &'static str {
    match m {
        Module::Hip => "hip",
        Module::ArmA => "arm-a",
        Module::ArmB => "arm-b",
        Module::GripperA => "gripper-a",
        Module::GripperB => "gripper-b",
        Module::BolterA => "bolter-a",
        Module::BolterB => "bolter-b",
    }
}

const WAIT: &str = "a duration such as `500ms`, `2s` or `1.5s` (at most 1 h)";

fn step(l: &mut Line<'_>, first: Tok<'_>) -> Result<Action, PlanError> {
    let c = |c: Command| Ok(Action::Command(c));
    match lower(first).as_str() {
        "heartbeat" => c(Command::Heartbeat),
        "stop" => c(Command::Stop),
        "reset" => c(Command::Reset),
        "system-fault" => c(Command::SystemFault),
        "clear-faults" => c(Command::ClearFaults),
        "mode" => {
            const M: &str = "`standby`, `operational` or `safed`";
            let t = l.next("mode", M)?;
            c(Command::Mode(match lower(t).as_str() {
                "standby" => Mode::Standby,
                "operational" => Mode::Operational,
                "safed" => Mode::Safed,
                _ => return Err(l.bad(t, M)),
            }))
        }
        "arm" => {
            let side = side(l, "arm")?;
            let target = servo(l, "arm")?;
            c(Command::Arm { side, target })
        }
        "gripper" => {
            let side = side(l, "gripper")?;
            let target = servo(l, "gripper")?;
            c(Command::Gripper { side, target })
        }
        "hip" => c(Command::Hip(hip(l)?)),
        "bolt" => c(Command::Bolter(BolterCommand::Bolt(fasteners(l, "bolt")?))),
        "unbolt" => c(Command::Bolter(BolterCommand::Unbolt(fasteners(
            l, "unbolt",
        )?))),
        "bolters" => {
            let t = l.next("bolters", "`down`")?;
            if lower(t) != "down" {
                return Err(l.bad(t, "`down`"));
            }
            c(Command::Bolter(BolterCommand::Down))
        }
        "primitive" => {
            const P: &str = "a primitive number 1..=8 (Table 6)";
            let t = l.next("primitive", P)?;
            let p = t
                .text
                .parse::<u8>()
                .ok()
                .and_then(Primitive::from_number)
                .ok_or_else(|| l.bad(t, P))?;
            c(Command::Primitive(p))
        }
        "reconfigure" => {
            let from_tok = l.toks.get(l.at).copied();
            let from = state(l)?;
            let arrow = l.next("reconfigure", "`->` between the two states")?;
            if arrow.text != "->" {
                return Err(l.bad(arrow, "`->` between the two states"));
            }
            let to = state(l)?;
            Command::reconfigure(from, to)
                .map(Action::Command)
                .map_err(|e| {
                    l.err(
                        from_tok.map_or(first.col, |t| t.col),
                        PlanErrorKind::Reconfiguration(e),
                    )
                })
        }
        "power" => {
            const ON: &str = "`on` or `off`";
            let t = l.next("power", ON)?;
            let on = match lower(t).as_str() {
                "on" => true,
                "off" => false,
                _ => return Err(l.bad(t, ON)),
            };
            let t = l.next("power", MODULE)?;
            let w = lower(t);
            let target = if w == "all" {
                PowerTarget::All
            } else {
                PowerTarget::Module(
                    Module::ALL
                        .into_iter()
                        .find(|m| module_name(*m) == w)
                        .ok_or_else(|| l.bad(t, MODULE))?,
                )
            };
            c(Command::Power { target, on })
        }
        "wait" => {
            let t = l.next("wait", WAIT)?;
            let w = lower(t);
            let ms = if let Some(v) = w.strip_suffix("ms") {
                decimal(v, 0)
            } else if let Some(v) = w.strip_suffix('s') {
                decimal(v, 3)
            } else {
                None
            };
            match ms {
                Some(ms) if ms <= 3_600_000 => Ok(Action::Wait { ms: ms as u32 }),
                _ => Err(l.bad(t, WAIT)),
            }
        }
        _ => Err(l.err(
            first.col,
            PlanErrorKind::UnknownStep {
                found: first.text.to_string(),
            },
        )),
    }
}

/// Parses a plan file.
pub fn parse(text: &str) -> Result<Plan, PlanError> {
    let mut robot = None;
    let mut steps = Vec::new();
    let mut last_line = 0;
    for (i, raw) in text.lines().enumerate() {
        let n = i + 1;
        last_line = n;
        let code = raw.split('#').next().unwrap_or("");
        let toks = tokens(code);
        let Some(&first) = toks.first() else { continue };
        let mut l = Line {
            n,
            end_col: code.trim_end().chars().count() + 1,
            toks,
            at: 1,
        };
        if lower(first) == "robot" {
            if robot.is_some() || !steps.is_empty() {
                return Err(l.err(first.col, PlanErrorKind::RobotAfterSteps));
            }
            const R: &str = "a robot number 1..=255";
            let t = l.next("robot", R)?;
            robot = Some(
                t.text
                    .parse::<u8>()
                    .ok()
                    .and_then(|v| BoardNumber::new(v).ok())
                    .ok_or_else(|| l.bad(t, R))?,
            );
            l.done()?;
            continue;
        }
        let action = step(&mut l, first)?;
        l.done()?;
        steps.push(Step {
            line: n,
            text: code.trim().to_string(),
            action,
        });
    }
    if steps.is_empty() {
        return Err(PlanError {
            line: last_line.max(1),
            column: 1,
            kind: PlanErrorKind::Empty,
        });
    }
    Ok(Plan {
        robot: robot.unwrap_or(BoardNumber::ONE),
        steps,
    })
}

impl Action {
    /// The step as a plan-file line.
    pub fn describe(&self) -> String {
        match self {
            Action::Wait { ms } => format!("wait {ms}ms"),
            Action::Command(c) => command_text(c),
        }
    }
}

fn servo_text(t: ServoTarget) -> String {
    match t {
        ServoTarget::Contract => "contract".into(),
        ServoTarget::Extend => "extend".into(),
        ServoTarget::Position(p) => format!("{}us", p.micros()),
    }
}

fn fasteners_text(f: Fasteners) -> String {
    match f {
        Fasteners::All => "all".into(),
        Fasteners::Pair(p) => p.number().to_string(),
    }
}

/// A command as a plan-file line.
pub fn command_text(c: &Command) -> String {
    let side = |s: Side| if s == Side::A { "a" } else { "b" };
    match *c {
        Command::Heartbeat => "heartbeat".into(),
        Command::Stop => "stop".into(),
        Command::Reset => "reset".into(),
        Command::SystemFault => "system-fault".into(),
        Command::ClearFaults => "clear-faults".into(),
        Command::Mode(m) => format!("mode {}", m.name()),
        Command::Arm { side: s, target } => format!("arm {} {}", side(s), servo_text(target)),
        Command::Gripper { side: s, target } => {
            format!("gripper {} {}", side(s), servo_text(target))
        }
        Command::Hip(h) => match h {
            HipTarget::Home => "hip home".into(),
            HipTarget::Straight => "hip straight".into(),
            HipTarget::RightAngleCw => "hip cw".into(),
            HipTarget::RightAngleCcw => "hip ccw".into(),
            HipTarget::Angle(a) => {
                let c = a.centidegrees();
                format!("hip {}.{:02}", c / 100, c % 100)
            }
        },
        Command::Bolter(BolterCommand::Bolt(f)) => format!("bolt {}", fasteners_text(f)),
        Command::Bolter(BolterCommand::Unbolt(f)) => format!("unbolt {}", fasteners_text(f)),
        Command::Bolter(BolterCommand::Down) => "bolters down".into(),
        Command::Primitive(p) => format!("primitive {}", p.number()),
        Command::Reconfigure(r) => format!(
            "reconfigure {} -> {}",
            r.initial().letter(),
            r.target().letter()
        ),
        Command::Power { target, on } => format!(
            "power {} {}",
            if on { "on" } else { "off" },
            match target {
                PowerTarget::All => "all",
                PowerTarget::Module(m) => module_name(m),
            }
        ),
    }
}

impl Plan {
    /// The plan as canonical text; parses back to an equal plan (line numbers aside).
    pub fn to_text(&self) -> String {
        let mut t = format!("robot {}\n", self.robot.get());
        for s in &self.steps {
            let _ = writeln!(t, "{}", s.action.describe());
        }
        t
    }
}
