//! Plan files: the steps the ground software (opsUI) sends to one robot, as text a person can
//! write, review and diff.
//!
//! ```
//! use mmic::command::{Command, ServoTarget};
//! use mmic::units::Side;
//! use mmic_host::plan::{self, Action};
//!
//! let plan = plan::parse(
//!     "robot 2              # board A's client number\n\
//!      mode operational\n\
//!      arm a extend\n\
//!      wait 1.5s\n\
//!      reconfigure a -> m\n",
//! )?;
//! assert_eq!(plan.robot.get(), 2);
//! assert_eq!(plan.steps.len(), 4);
//! assert_eq!(
//!     plan.steps[1].action,
//!     Action::Command(Command::Arm { side: Side::A, target: ServoTarget::Extend })
//! );
//! assert_eq!(plan.steps[2].action, Action::Wait { ms: 1500 });
//! assert_eq!(plan.steps[2].line, 4);
//!
//! // Errors point at the offending token, 1-based line and column.
//! let e = plan::parse("mode operational\nbolt 5\n").unwrap_err();
//! assert_eq!((e.line, e.column), (2, 6));
//! assert_eq!(e.to_string(), "line 2, column 6: bolter pair must be 1..=4, found 5");
//!
//! // The canonical text parses back to the same plan.
//! assert_eq!(plan::parse(&plan.to_text())?.steps[3].action, plan.steps[3].action);
//! # Ok::<(), plan::PlanError>(())
//! ```
//!
//! # Why a text format
//!
//! A plan is reviewed before it is flown: a line-oriented file reads in a code review, diffs
//! line by line, takes comments, and every error can name the line and column to fix. Each step
//! maps onto exactly one [`Command`] (or a wait), so what the file says is what goes on the
//! wire; nothing is guessed or clamped. A value out of range is an error, not a saturation,
//! because a silently moved servo target is worse than a refused file.
//!
//! # Format
//!
//! UTF-8 text, one step per line. `#` starts a comment that runs to the end of the line; blank
//! lines are ignored; tokens are separated by whitespace (`->` is a token of its own, so
//! `a->m` reads as `a -> m`). Keywords, side letters, state letters and units are
//! case-insensitive. Columns count characters (a tab is one column).
//!
//! An optional header `robot N` (N in 1..=255, default 1) may come before the first step, once.
//! So may `start S` (a Table 5 state letter): the state the robot is in when the plan starts.
//! With it, the parser follows the robot's state through the plan ([`Plan::trace`]) and
//! refuses a reconfiguration that starts from another state than the one the robot will be in,
//! or a primitive that does not take the robot from there to the final state the step names,
//! with the line and column of the step — before anything is sent. (`mmic sim` traces every
//! plan from its start state, `a` when not given.)
//!
//! A primitive step names its final state (`primitive 7 -> d`, or `primitive backTurnCW d`):
//! from a turn state one primitive reaches two states (spec/motion/ambiguous-primitives.txt),
//! and the command carries the one meant. With a `start` header the state may be left out where the
//! plan's state makes it unambiguous (`start a`, then `primitive 4` is `primitive 4 -> d`); the
//! parser fills it in from the map, and refuses the step, naming both candidates, where the
//! primitive reaches two states from there.
//!
//! ```
//! use mmic_host::plan::{self, PlanErrorKind};
//! use mmic::motion::State;
//! let p = plan::parse("start a\nprimitive 8\nprimitive 7 -> d\n")?; // a -> e, then e -> d
//! assert_eq!(p.trace(State::A)?, [State::E, State::D]);
//! assert_eq!(p.steps[0].action.to_string(), "primitive 8 -> e");
//! let e = plan::parse("start a\nprimitive 8\nprimitive 7\n").unwrap_err();
//! assert_eq!((e.line, e.column), (3, 11));
//! assert!(matches!(e.kind, PlanErrorKind::AmbiguousPrimitive { first: State::A, second: State::D, .. }));
//! # Ok::<(), plan::PlanError>(())
//! ```
//!
//! ```
//! let e = mmic_host::plan::parse("start a\nreconfigure a -> m\nreconfigure b -> n\n").unwrap_err();
//! assert_eq!((e.line, e.column), (3, 13));
//! assert_eq!(
//!     e.kind.to_string(),
//!     "this reconfiguration starts from b (Yneg match), but the robot is in m (Xpos match) here (since line 2)"
//! );
//! ```
//!
//! | Step | Command |
//! |------|---------|
//! | `heartbeat`, `stop`, `reset`, `system-fault`, `clear-faults` | the argument-less commands |
//! | `mode standby\|operational\|safed` | [`Command::Mode`] |
//! | `arm a\|b contract\|extend\|<µs>` | [`Command::Arm`]; pulse `1500`, `1500us` or `1500µs`, 500..=2500 |
//! | `gripper a\|b contract\|extend\|<µs>` | [`Command::Gripper`], as for `arm` |
//! | `hip home\|straight\|cw\|ccw\|<degrees>` | [`Command::Hip`]; `45`, `45.5`, `45deg` or `45°`, 0..=359.99, at most 2 decimals |
//! | `bolt 1\|2\|3\|4\|all`, `unbolt 1\|2\|3\|4\|all`, `bolters down` | [`Command::Bolter`] |
//! | `primitive 1..8 [->] <final>` (or a Table 6 name, e.g. `fwdContract`), state `a`..`o` | [`Command::Primitive`]; the final state may be left out where the plan's state settles it |
//! | `reconfigure <initial> -> <target>`, states `a`..`o` | [`Command::Reconfigure`] |
//! | `power on\|off <module>\|all` | [`Command::Power`] |
//! | `wait <duration>`: `500ms`, `2s`, `1.5s`; at most 1 hour, whole milliseconds | [`Action::Wait`] |
//!
//! The module keywords of `power` are those of [`module_keyword`]: `hip`, `arm-a`, `arm-b`,
//! `gripper-a`, `gripper-b`, `bolter-a`, `bolter-b`.

use mmic::command::{
    BolterCommand, BolterPair, Command, Fasteners, HipTarget, PowerTarget, PrimitiveMove,
    PrimitiveMoveError, ReconfigurationError, ServoTarget,
};
use mmic::mode::Mode;
use mmic::motion::{Primitive, State};
use mmic::units::{BoardNumber, HipAngle, Module, PulseWidth, Side};
use std::fmt;

/// Longest wait a step may ask for: one hour, in milliseconds. Longer pauses belong to the
/// operator, not to a plan that keeps a robot waiting unattended.
pub const MAX_WAIT_MS: u32 = 3_600_000;

/// Every step keyword, in the order of the module docs (for error messages and tools).
pub const STEP_KEYWORDS: [&str; 16] = [
    "heartbeat",
    "stop",
    "reset",
    "system-fault",
    "clear-faults",
    "mode",
    "arm",
    "gripper",
    "hip",
    "bolt",
    "unbolt",
    "bolters",
    "primitive",
    "reconfigure",
    "power",
    "wait",
];

/// A parsed plan: which robot it addresses, where it starts and its steps in order.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Plan {
    /// Robot (board A's WiFi client number) the steps are sent to.
    pub robot: BoardNumber,
    /// The state the robot is in when the plan starts (`start` header), if the plan says.
    pub start: Option<State>,
    /// The steps, in file order.
    pub steps: Vec<Step>,
}

/// One step of a plan, with where it came from so that progress and errors can show it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Step {
    /// 1-based line number in the source text.
    pub line: usize,
    /// What to do.
    pub action: Action,
    /// The source line, trimmed (comment included), for progress display.
    pub text: String,
    /// 1-based column of each token of the step, keyword first, for errors found after
    /// parsing ([`Plan::trace`]).
    pub columns: Vec<usize>,
}

/// What a step does: send a command, or pause before the next step.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Action {
    /// Send this command to the robot.
    Command(Command),
    /// Wait this long before the next step.
    Wait {
        /// Milliseconds, at most [`MAX_WAIT_MS`].
        ms: u32,
    },
}

/// A plan that does not parse: where (1-based line and column of the offending token, the
/// column counted in characters) and why.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("line {line}, column {column}: {kind}")]
pub struct PlanError {
    /// 1-based line.
    pub line: usize,
    /// 1-based column, in characters.
    pub column: usize,
    /// What is wrong.
    pub kind: PlanErrorKind,
}

/// Why a plan does not parse.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum PlanErrorKind {
    /// The first token of a line is no step keyword.
    #[error("unknown step {found:?}; expected one of: {}", STEP_KEYWORDS.join(", "))]
    UnknownStep {
        /// The token found.
        found: String,
    },
    /// The line ends before the step is complete. The column is the one just past the line's
    /// last token.
    #[error("{step}: missing {expected}")]
    MissingArgument {
        /// The step keyword.
        step: &'static str,
        /// What should follow.
        expected: &'static str,
    },
    /// An argument is not one of the accepted words or numbers.
    #[error("expected {expected}, found {found:?}")]
    BadArgument {
        /// What is accepted there.
        expected: &'static str,
        /// The token found.
        found: String,
    },
    /// A number outside its range (never clamped).
    #[error("{quantity} must be {min}..={max}, found {found}")]
    OutOfRange {
        /// The quantity.
        quantity: &'static str,
        /// Smallest accepted value, with its unit.
        min: &'static str,
        /// Largest accepted value, with its unit.
        max: &'static str,
        /// The token found.
        found: String,
    },
    /// A token after a complete step.
    #[error("unexpected {found:?} after a complete step")]
    TrailingToken {
        /// The token found.
        found: String,
    },
    /// A `robot` header after the first step: the robot must be known before anything is sent.
    #[error("`robot` must come before the first step")]
    RobotAfterSteps,
    /// A second `robot` header.
    #[error("`robot` given twice (first on line {first})")]
    RobotTwice {
        /// Line of the first header.
        first: usize,
    },
    /// A reconfiguration the library refuses.
    #[error("{0}")]
    Reconfiguration(ReconfigurationError),
    /// A `start` header after the first step, or given twice.
    #[error("`start` must come once, before the first step")]
    StartMisplaced,
    /// A reconfiguration that starts from another state than the one the robot is in at that
    /// point of the plan ([`Plan::trace`]); the robot would refuse it (initial state mismatch).
    #[error(
        "this reconfiguration starts from {found}, but the robot is in {tracked} here ({})",
        since_text(*since)
    )]
    StateMismatch {
        /// The initial state the step names.
        found: State,
        /// The state the plan has the robot in.
        tracked: State,
        /// The line whose step put the robot there; none for the start state.
        since: Option<usize>,
    },
    /// A primitive that is no move from the state the robot is in at that point of the plan.
    #[error(
        "primitive {primitive} is no move from {tracked} (Figure 9), where the robot is here ({})",
        since_text(*since)
    )]
    NoSuchMove {
        /// The primitive's number.
        primitive: u8,
        /// The state the plan has the robot in.
        tracked: State,
        /// The line whose step put the robot there; none for the start state.
        since: Option<usize>,
    },
    /// A primitive step that names one of the geometric model's 12 turns between two
    /// right-angle states from the state the robot is in at that point of the plan: the moving
    /// arm would turn about the holding arm, which the hip cannot do; the robot would refuse it
    /// (`turn_without_hip`; spec/decisions.toml, `turn-to-turn-moves`).
    #[error(
        "primitive {primitive} from {tracked} to {target} is a turn between two right-angle states, which the hip cannot make (Figure 9 as read in spec/decisions.toml turn-to-turn-moves; the robot refuses it: turn_without_hip); the robot is in {tracked} here ({})",
        since_text(*since)
    )]
    TurnWithoutHip {
        /// The primitive's number.
        primitive: u8,
        /// The state the plan has the robot in.
        tracked: State,
        /// The final state of the move (named by the step, or the model's only one).
        target: State,
        /// The line whose step put the robot there; none for the start state.
        since: Option<usize>,
    },
    /// A primitive step whose final state is not where the primitive takes the robot from the
    /// state it is in at that point of the plan; the robot would refuse it (initial state
    /// mismatch).
    #[error(
        "primitive {primitive} takes {tracked} to {}, not to {target} (Figure 9); the robot is in {tracked} here ({})",
        or_list(reaches),
        since_text(*since)
    )]
    WrongFinalState {
        /// The primitive's number.
        primitive: u8,
        /// The final state the step names.
        target: State,
        /// The state the plan has the robot in.
        tracked: State,
        /// Where the primitive does take the robot from there (one or two states).
        reaches: Vec<State>,
        /// The line whose step put the robot there; none for the start state.
        since: Option<usize>,
    },
    /// A primitive step without its final state, where the primitive reaches two states from
    /// the state the robot is in (spec/motion/ambiguous-primitives.txt): the step must say
    /// which.
    #[error(
        "primitive {primitive} from {tracked} reaches both {first} and {second} (Figure 9): name the final state, e.g. `primitive {primitive} -> {}` (the robot is in {tracked} here, {})",
        first.letter(),
        since_text(*since)
    )]
    AmbiguousPrimitive {
        /// The primitive's number.
        primitive: u8,
        /// The state the plan has the robot in.
        tracked: State,
        /// The first candidate, in Table 5 order.
        first: State,
        /// The second candidate.
        second: State,
        /// The line whose step put the robot there; none for the start state.
        since: Option<usize>,
    },
    /// A primitive step without its final state in a plan without a `start` header: nothing
    /// says where the robot is, so nothing can fill the state in.
    #[error(
        "primitive {primitive} needs its final state, e.g. `primitive {primitive} -> {}`, or a `start` header to fill it in from",
        first_final_state(*primitive)
    )]
    MissingFinalState {
        /// The primitive's number.
        primitive: u8,
    },
    /// A final state the primitive reaches from no state at all.
    #[error("{0}")]
    Primitive(PrimitiveMoveError),
    /// No step at all: an empty plan is more likely a wrong file than an intent. Reported at
    /// line 1, column 1.
    #[error("the plan has no steps")]
    Empty,
}

/// The letter of the first state (Table 5 order) primitive number `n` can end in, for
/// examples in messages.
fn first_final_state(n: u8) -> char {
    PrimitiveMove::all()
        .find(|m| m.primitive().number() == n)
        .map_or('a', |m| m.target().letter())
}

/// `a (Xneg match)` or `a (Xneg match) or d (Xneg Xpos stretch)`.
fn or_list(states: &[State]) -> String {
    let names: Vec<String> = states.iter().map(State::to_string).collect();
    names.join(" or ")
}

fn since_text(since: Option<usize>) -> String {
    match since {
        Some(line) => format!("since line {line}"),
        None => "its start state".to_string(),
    }
}

/// The keyword of a module in `power` steps: the variant name in kebab case.
pub const fn module_keyword(m: Module) -> &'static str {
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

/// The module with keyword `word` (case-insensitive).
pub fn module_from_keyword(word: &str) -> Option<Module> {
    Module::ALL
        .into_iter()
        .find(|m| module_keyword(*m).eq_ignore_ascii_case(word))
}

/// What `power` accepts after `on`/`off`; a test checks it names every [`module_keyword`].
const POWER_TARGETS: &str =
    "a module (hip, arm-a, arm-b, gripper-a, gripper-b, bolter-a, bolter-b) or all";

/// Parses a plan; see the module docs for the format.
pub fn parse(text: &str) -> Result<Plan, PlanError> {
    // A byte-order mark is not part of the first line as an editor shows it.
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut robot: Option<(BoardNumber, usize)> = None;
    let mut start: Option<State> = None;
    let mut steps: Vec<Pending> = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        let tokens = tokenize(raw);
        let Some(first) = tokens.first() else {
            continue;
        };
        let mut cur = Cursor {
            line,
            tokens: &tokens,
            next: 1,
        };
        if first.text.eq_ignore_ascii_case("robot") {
            if !steps.is_empty() {
                return Err(cur.error_at(first, PlanErrorKind::RobotAfterSteps));
            }
            if let Some((_, first_line)) = robot {
                return Err(cur.error_at(first, PlanErrorKind::RobotTwice { first: first_line }));
            }
            let tok = cur.next("robot", "a robot number 1..=255")?;
            let n = cur.integer(tok, "a robot number 1..=255")?;
            let n = u8::try_from(n)
                .ok()
                .and_then(|n| BoardNumber::new(n).ok())
                .ok_or_else(|| cur.out_of_range(tok, "robot number", "1", "255"))?;
            cur.finish()?;
            robot = Some((n, line));
            continue;
        }
        if first.text.eq_ignore_ascii_case("start") {
            if !steps.is_empty() || start.is_some() {
                return Err(cur.error_at(first, PlanErrorKind::StartMisplaced));
            }
            start = Some(state_token(&mut cur, "start")?);
            cur.finish()?;
            continue;
        }
        let parsed = step(&mut cur, first)?;
        cur.finish()?;
        steps.push(Pending {
            line,
            parsed,
            text: raw.trim().to_string(),
            columns: tokens.iter().map(|t| t.column).collect(),
        });
    }
    if steps.is_empty() {
        return Err(PlanError {
            line: 1,
            column: 1,
            kind: PlanErrorKind::Empty,
        });
    }
    // Every line parsed: now the robot's state, from a declared start. A step that does not
    // fit it is an error of the file, found before anything is sent; a primitive without its
    // final state gets the one the map gives from there, if there is exactly one.
    let mut at = start.map(|s| (s, None));
    let mut done = Vec::with_capacity(steps.len());
    for p in steps {
        let action = match p.parsed {
            Parsed::Action(a) => a,
            Parsed::BarePrimitive(primitive) => {
                let column = p.columns.get(1).copied().unwrap_or(1);
                let target = fill_in(primitive, at).map_err(|kind| PlanError {
                    line: p.line,
                    column,
                    kind,
                })?;
                Action::Command(Command::Primitive(target))
            }
        };
        let step = Step {
            line: p.line,
            action,
            text: p.text,
            columns: p.columns,
        };
        if let Some(now) = at {
            at = Some(follow(now, &step)?);
        }
        done.push(step);
    }
    Ok(Plan {
        robot: robot.map_or(BoardNumber::ONE, |(r, _)| r),
        start,
        steps: done,
    })
}

/// A step as its line parses, before the robot's state is followed through the plan.
struct Pending {
    line: usize,
    parsed: Parsed,
    text: String,
    columns: Vec<usize>,
}

/// What a step's tokens say: an action, or a primitive whose final state the plan's state
/// must supply.
enum Parsed {
    Action(Action),
    BarePrimitive(Primitive),
}

/// The one move `primitive` makes from the robot's state `at` (and the line that put it
/// there), for a step that does not name its final state.
fn fill_in(
    primitive: Primitive,
    at: Option<(State, Option<usize>)>,
) -> Result<PrimitiveMove, PlanErrorKind> {
    let number = primitive.number();
    let Some((tracked, since)) = at else {
        return Err(PlanErrorKind::MissingFinalState { primitive: number });
    };
    let mut ends = mmic::motion::map::targets(tracked, primitive);
    match (ends.next(), ends.next()) {
        (Some(to), None) => PrimitiveMove::new(primitive, to).map_err(PlanErrorKind::Primitive),
        (Some(first), Some(second)) => Err(PlanErrorKind::AmbiguousPrimitive {
            primitive: number,
            tracked,
            first,
            second,
            since,
        }),
        (None, _) => Err(match hipless_target(tracked, primitive) {
            Some(target) => PlanErrorKind::TurnWithoutHip {
                primitive: number,
                tracked,
                target,
                since,
            },
            None => PlanErrorKind::NoSuchMove {
                primitive: number,
                tracked,
                since,
            },
        }),
    }
}

/// The final state of the model's turn without a hip rotation that `primitive` names from
/// `from`, if it names one (then it is the primitive's only move of the model from there).
fn hipless_target(from: State, primitive: Primitive) -> Option<State> {
    mmic::motion::geometry::model_moves()
        .find(|&(f, t, _, p)| {
            f == from && p == primitive && mmic::motion::geometry::turns_without_hip(f, t)
        })
        .map(|(_, t, _, _)| t)
}

/// The robot's state after `step`, from `at` (the state, and the line whose step put the robot
/// there): a reconfiguration must start from it and ends in its target; a primitive must be
/// the map's move from it to the final state the step names, and ends there; every other step
/// leaves it as it is (the plan runner sends a step only after the previous one settled).
fn follow(
    (tracked, since): (State, Option<usize>),
    step: &Step,
) -> Result<(State, Option<usize>), PlanError> {
    let column = |i: usize| step.columns.get(i).copied().unwrap_or(1);
    let error = |column: usize, kind: PlanErrorKind| PlanError {
        line: step.line,
        column,
        kind,
    };
    match step.action {
        Action::Command(Command::Reconfigure(r)) => {
            if tracked != r.initial() {
                return Err(error(
                    column(1),
                    PlanErrorKind::StateMismatch {
                        found: r.initial(),
                        tracked,
                        since,
                    },
                ));
            }
            Ok((r.target(), Some(step.line)))
        }
        Action::Command(Command::Primitive(m)) => {
            if m.is_move_from(tracked) {
                return Ok((m.target(), Some(step.line)));
            }
            if m.turns_without_hip_from(tracked) {
                return Err(error(
                    column(1),
                    PlanErrorKind::TurnWithoutHip {
                        primitive: m.primitive().number(),
                        tracked,
                        target: m.target(),
                        since,
                    },
                ));
            }
            let reaches: Vec<State> = mmic::motion::map::targets(tracked, m.primitive()).collect();
            let primitive = m.primitive().number();
            Err(if reaches.is_empty() {
                error(
                    column(1),
                    PlanErrorKind::NoSuchMove {
                        primitive,
                        tracked,
                        since,
                    },
                )
            } else {
                // The final state is the step's last token.
                let last = step.columns.last().copied().unwrap_or(1);
                error(
                    last,
                    PlanErrorKind::WrongFinalState {
                        primitive,
                        target: m.target(),
                        tracked,
                        reaches,
                        since,
                    },
                )
            })
        }
        _ => Ok((tracked, since)),
    }
}

impl Plan {
    /// Canonical text: a `robot` header and one canonical step per line (see [`Action`]'s
    /// `Display`). It parses back to a plan with the same robot and actions, so tools can
    /// rewrite plans and tests can round-trip them.
    pub fn to_text(&self) -> String {
        let mut s = format!("robot {}\n", self.robot.get());
        if let Some(st) = self.start {
            s += &format!("start {}\n", st.letter());
        }
        for step in &self.steps {
            s += &step.action.to_string();
            s.push('\n');
        }
        s
    }
}

impl Plan {
    /// Follows the robot's state through the plan from `start`, as board A tracks it: a
    /// reconfiguration must start from the state the robot is in and leaves it in its target;
    /// a primitive must take the robot from that state to the final state the step names
    /// (Figure 9) and leaves it there; every other step leaves the state as it is (the plan
    /// runner sends a step only after the previous one settled). Returns the state after each
    /// step, or the first step that does not fit, with its line and the column of the
    /// offending token.
    pub fn trace(&self, start: State) -> Result<Vec<State>, PlanError> {
        let mut at = (start, None);
        let mut out = Vec::with_capacity(self.steps.len());
        for step in &self.steps {
            at = follow(at, step)?;
            out.push(at.0);
        }
        Ok(out)
    }
}

impl Action {
    /// A short description for people (progress lines, logs), e.g. `arm A to 1500 µs`.
    pub fn describe(&self) -> String {
        let c = match self {
            Action::Wait { ms } => return format!("wait {}", duration(*ms, " ")),
            Action::Command(c) => c,
        };
        match c {
            Command::Heartbeat => "request a heartbeat".into(),
            Command::Stop => "emergency stop".into(),
            Command::Reset => "resume after a stop".into(),
            Command::SystemFault => "trigger the system fault".into(),
            Command::ClearFaults => "clear latched faults".into(),
            Command::Mode(m) => format!("switch to {m} mode"),
            Command::Arm { side, target } => servo_description("arm", *side, *target),
            Command::Gripper { side, target } => servo_description("gripper", *side, *target),
            Command::Hip(HipTarget::Home) => "hip home".into(),
            Command::Hip(HipTarget::Straight) => "hip straight (180°)".into(),
            Command::Hip(HipTarget::RightAngleCw) => "hip 90° clockwise".into(),
            Command::Hip(HipTarget::RightAngleCcw) => "hip 90° counter-clockwise".into(),
            Command::Hip(HipTarget::Angle(a)) => format!("hip to {}°", degrees(*a)),
            Command::Bolter(BolterCommand::Bolt(f)) => format!("bolt {}", fasteners(*f)),
            Command::Bolter(BolterCommand::Unbolt(f)) => format!("unbolt {}", fasteners(*f)),
            Command::Bolter(BolterCommand::Down) => "lower both bolters".into(),
            Command::Primitive(m) => format!(
                "primitive {} ({}) to {}",
                m.primitive().number(),
                m.primitive().name(),
                m.target()
            ),
            Command::Reconfigure(r) => format!("reconfigure {} -> {}", r.initial(), r.target()),
            Command::Power { target, on } => format!(
                "power {} {}",
                if *on { "on" } else { "off" },
                match target {
                    PowerTarget::Module(m) => module_keyword(*m),
                    PowerTarget::All => "all modules",
                }
            ),
        }
    }
}

/// The canonical step text, as [`Plan::to_text`] writes it: lowercase keywords, pulse widths in
/// `us`, angles in degrees with at most 2 decimals, waits in `s` when whole seconds else `ms`.
impl fmt::Display for Action {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let c = match self {
            Action::Wait { ms } => return write!(f, "wait {}", duration(*ms, "")),
            Action::Command(c) => c,
        };
        match c {
            Command::Heartbeat => f.write_str("heartbeat"),
            Command::Stop => f.write_str("stop"),
            Command::Reset => f.write_str("reset"),
            Command::SystemFault => f.write_str("system-fault"),
            Command::ClearFaults => f.write_str("clear-faults"),
            Command::Mode(m) => write!(f, "mode {}", m.name()),
            Command::Arm { side, target } => {
                write!(f, "arm {} {}", side_word(*side), servo(*target))
            }
            Command::Gripper { side, target } => {
                write!(f, "gripper {} {}", side_word(*side), servo(*target))
            }
            Command::Hip(h) => match h {
                HipTarget::Home => f.write_str("hip home"),
                HipTarget::Straight => f.write_str("hip straight"),
                HipTarget::RightAngleCw => f.write_str("hip cw"),
                HipTarget::RightAngleCcw => f.write_str("hip ccw"),
                HipTarget::Angle(a) => write!(f, "hip {}", degrees(*a)),
            },
            Command::Bolter(BolterCommand::Bolt(w)) => write!(f, "bolt {}", fastener_word(*w)),
            Command::Bolter(BolterCommand::Unbolt(w)) => write!(f, "unbolt {}", fastener_word(*w)),
            Command::Bolter(BolterCommand::Down) => f.write_str("bolters down"),
            Command::Primitive(m) => write!(
                f,
                "primitive {} -> {}",
                m.primitive().number(),
                m.target().letter()
            ),
            Command::Reconfigure(r) => write!(
                f,
                "reconfigure {} -> {}",
                r.initial().letter(),
                r.target().letter()
            ),
            Command::Power { target, on } => write!(
                f,
                "power {} {}",
                if *on { "on" } else { "off" },
                match target {
                    PowerTarget::Module(m) => module_keyword(*m),
                    PowerTarget::All => "all",
                }
            ),
        }
    }
}

fn side_word(s: Side) -> &'static str {
    match s {
        Side::A => "a",
        Side::B => "b",
    }
}

fn servo(t: ServoTarget) -> String {
    match t {
        ServoTarget::Contract => "contract".into(),
        ServoTarget::Extend => "extend".into(),
        ServoTarget::Position(pw) => format!("{}us", pw.micros()),
    }
}

fn servo_description(what: &str, side: Side, t: ServoTarget) -> String {
    match t {
        ServoTarget::Contract => format!("{what} {side}: contract"),
        ServoTarget::Extend => format!("{what} {side}: extend"),
        ServoTarget::Position(pw) => format!("{what} {side} to {} µs", pw.micros()),
    }
}

fn fastener_word(f: Fasteners) -> String {
    match f {
        Fasteners::Pair(p) => p.number().to_string(),
        Fasteners::All => "all".into(),
    }
}

fn fasteners(f: Fasteners) -> String {
    match f {
        Fasteners::Pair(p) => format!("pair {}", p.number()),
        Fasteners::All => "all pairs".into(),
    }
}

/// `45`, `45.5`, `123.45`: centidegrees as degrees without trailing zeros.
fn degrees(a: HipAngle) -> String {
    let c = a.centidegrees();
    let (whole, frac) = (c / 100, c % 100);
    match frac {
        0 => whole.to_string(),
        f if f % 10 == 0 => format!("{whole}.{}", f / 10),
        f => format!("{whole}.{f:02}"),
    }
}

/// `2s`, `1.5s`, `500ms` (with `sep` between number and unit).
fn duration(ms: u32, sep: &str) -> String {
    if ms >= 1000 && ms.is_multiple_of(1000) {
        format!("{}{sep}s", ms / 1000)
    } else if ms >= 1000 && ms.is_multiple_of(100) {
        format!("{}.{}{sep}s", ms / 1000, (ms % 1000) / 100)
    } else {
        format!("{ms}{sep}ms")
    }
}

/// A token and its 1-based character column.
#[derive(Debug, Clone, Copy)]
struct Token<'a> {
    text: &'a str,
    column: usize,
}

/// The tokens of one line: comment stripped, split at whitespace, `->` a token of its own.
fn tokenize(line: &str) -> Vec<Token<'_>> {
    let code = line.split_once('#').map_or(line, |(code, _)| code);
    let mut out = Vec::new();
    let mut start: Option<(usize, usize)> = None; // byte offset, column
    let mut chars = code.char_indices().enumerate().peekable();
    while let Some((i, (b, c))) = chars.next() {
        let column = i + 1;
        let arrow = c == '-' && matches!(chars.peek(), Some((_, (_, '>'))));
        if c.is_whitespace() || arrow {
            if let Some((s, col)) = start.take() {
                out.push(Token {
                    text: &code[s..b],
                    column: col,
                });
            }
            if arrow {
                chars.next();
                out.push(Token {
                    text: &code[b..b + 2],
                    column,
                });
            }
        } else if start.is_none() {
            start = Some((b, column));
        }
    }
    if let Some((s, col)) = start {
        out.push(Token {
            text: &code[s..],
            column: col,
        });
    }
    out
}

/// The tokens of one line being consumed.
struct Cursor<'t, 'a> {
    line: usize,
    tokens: &'t [Token<'a>],
    next: usize,
}

impl<'a> Cursor<'_, 'a> {
    fn error_at(&self, t: &Token<'_>, kind: PlanErrorKind) -> PlanError {
        PlanError {
            line: self.line,
            column: t.column,
            kind,
        }
    }

    fn bad(&self, t: Token<'_>, expected: &'static str) -> PlanError {
        self.error_at(
            &t,
            PlanErrorKind::BadArgument {
                expected,
                found: t.text.to_string(),
            },
        )
    }

    fn out_of_range(
        &self,
        t: Token<'_>,
        quantity: &'static str,
        min: &'static str,
        max: &'static str,
    ) -> PlanError {
        self.error_at(
            &t,
            PlanErrorKind::OutOfRange {
                quantity,
                min,
                max,
                found: t.text.to_string(),
            },
        )
    }

    /// The next token, or a [`PlanErrorKind::MissingArgument`] just past the last one.
    fn next(&mut self, step: &'static str, expected: &'static str) -> Result<Token<'a>, PlanError> {
        match self.tokens.get(self.next) {
            Some(t) => {
                self.next += 1;
                Ok(*t)
            }
            None => {
                let column = self
                    .tokens
                    .last()
                    .map_or(1, |t| t.column + t.text.chars().count());
                Err(PlanError {
                    line: self.line,
                    column,
                    kind: PlanErrorKind::MissingArgument { step, expected },
                })
            }
        }
    }

    fn finish(&self) -> Result<(), PlanError> {
        match self.tokens.get(self.next) {
            None => Ok(()),
            Some(t) => Err(self.error_at(
                t,
                PlanErrorKind::TrailingToken {
                    found: t.text.to_string(),
                },
            )),
        }
    }

    /// An integer token (optionally negative); too large a magnitude saturates, which every
    /// caller then refuses as out of range.
    fn integer(&self, t: Token<'_>, expected: &'static str) -> Result<i64, PlanError> {
        integer(t.text).ok_or_else(|| self.bad(t, expected))
    }
}

/// `-?[0-9]+` as an i64, saturating.
fn integer(s: &str) -> Option<i64> {
    fixed(s, 0).and_then(Result::ok)
}

/// `-?[0-9]+(\.[0-9]+)?` scaled by 10^`decimals`, saturating; `Some(Err(()))` when the fraction
/// has non-zero digits beyond `decimals`.
fn fixed(s: &str, decimals: u32) -> Option<Result<i64, ()>> {
    let (neg, s) = match s.strip_prefix('-') {
        Some(rest) => (true, rest),
        None => (false, s),
    };
    let (whole, frac) = s.split_once('.').unwrap_or((s, ""));
    let digits = |d: &str| !d.is_empty() && d.bytes().all(|b| b.is_ascii_digit());
    if !digits(whole) || (s.contains('.') && !digits(frac)) {
        return None;
    }
    let mut v: i64 = 0;
    for b in whole.bytes() {
        v = v.saturating_mul(10).saturating_add(i64::from(b - b'0'));
    }
    for i in 0..decimals as usize {
        let d = frac.as_bytes().get(i).map_or(0, |b| b - b'0');
        v = v.saturating_mul(10).saturating_add(i64::from(d));
    }
    if frac.bytes().skip(decimals as usize).any(|b| b != b'0') {
        return Some(Err(()));
    }
    Some(Ok(if neg { -v } else { v }))
}

fn strip_suffix_ci<'s>(s: &'s str, suffix: &str) -> Option<&'s str> {
    let cut = s.len().checked_sub(suffix.len())?;
    if s.is_char_boundary(cut) && s[cut..].eq_ignore_ascii_case(suffix) {
        Some(&s[..cut])
    } else {
        None
    }
}

const SIDE: &str = "a side: a or b";
const SERVO: &str = "contract, extend or a pulse width 500..=2500 us";
const HIP: &str = "home, straight, cw, ccw or an angle in degrees (e.g. 45.5)";
const PAIR: &str = "a bolter pair 1..=4 or all";
const PRIMITIVE: &str = "a primitive number 1..=8 or a Table 6 name";
const STATE: &str = "a state letter a..o (Table 5)";
const DURATION: &str = "a duration with unit ms or s (e.g. 500ms, 1.5s)";

/// One step of a plan: its keyword `first`, then its arguments from `cur`.
fn step(cur: &mut Cursor<'_, '_>, first: &Token<'_>) -> Result<Parsed, PlanError> {
    let kw = first.text.to_ascii_lowercase();
    let cmd = match kw.as_str() {
        "heartbeat" => Command::Heartbeat,
        "stop" => Command::Stop,
        "reset" => Command::Reset,
        "system-fault" => Command::SystemFault,
        "clear-faults" => Command::ClearFaults,
        "mode" => mode_step(cur)?,
        "arm" => servo_step(cur, "arm")?,
        "gripper" => servo_step(cur, "gripper")?,
        "hip" => Command::Hip(hip_target(cur)?),
        "bolt" => bolt_step(cur, "bolt")?,
        "unbolt" => bolt_step(cur, "unbolt")?,
        "bolters" => bolters_step(cur)?,
        "primitive" => return primitive_step(cur),
        "reconfigure" => reconfigure_step(cur)?,
        "power" => power_step(cur)?,
        "wait" => return wait(cur).map(Parsed::Action),
        _ => {
            return Err(cur.error_at(
                first,
                PlanErrorKind::UnknownStep {
                    found: first.text.to_string(),
                },
            ))
        }
    };
    Ok(Parsed::Action(Action::Command(cmd)))
}

/// `mode standby|operational|safed`.
fn mode_step(cur: &mut Cursor<'_, '_>) -> Result<Command, PlanError> {
    const MODES: &str = "a mode: standby, operational or safed";
    let t = cur.next("mode", MODES)?;
    let m = Mode::ALL
        .into_iter()
        .find(|m| m.name().eq_ignore_ascii_case(t.text))
        .ok_or_else(|| cur.bad(t, MODES))?;
    Ok(Command::Mode(m))
}

/// `arm|gripper SIDE TARGET` (`step` is which).
fn servo_step(cur: &mut Cursor<'_, '_>, step: &'static str) -> Result<Command, PlanError> {
    let side = side(cur, step)?;
    let target = servo_target(cur, step)?;
    Ok(if step == "arm" {
        Command::Arm { side, target }
    } else {
        Command::Gripper { side, target }
    })
}

/// `bolt|unbolt PAIR|all` (`step` is which).
fn bolt_step(cur: &mut Cursor<'_, '_>, step: &'static str) -> Result<Command, PlanError> {
    let t = cur.next(step, PAIR)?;
    let which = if t.text.eq_ignore_ascii_case("all") {
        Fasteners::All
    } else {
        let n = cur.integer(t, PAIR)?;
        u8::try_from(n)
            .ok()
            .and_then(BolterPair::from_number)
            .map(Fasteners::Pair)
            .ok_or_else(|| cur.out_of_range(t, "bolter pair", "1", "4"))?
    };
    Ok(Command::Bolter(if step == "bolt" {
        BolterCommand::Bolt(which)
    } else {
        BolterCommand::Unbolt(which)
    }))
}

/// `bolters down`.
fn bolters_step(cur: &mut Cursor<'_, '_>) -> Result<Command, PlanError> {
    let t = cur.next("bolters", "down")?;
    if !t.text.eq_ignore_ascii_case("down") {
        return Err(cur.bad(t, "down"));
    }
    Ok(Command::Bolter(BolterCommand::Down))
}

/// `primitive N|NAME [->] STATE`, or without the state: a bare primitive whose final state the
/// plan's state fills in.
fn primitive_step(cur: &mut Cursor<'_, '_>) -> Result<Parsed, PlanError> {
    let t = cur.next("primitive", PRIMITIVE)?;
    let by_name = Primitive::ALL
        .into_iter()
        .find(|p| p.name().eq_ignore_ascii_case(t.text));
    let p = match by_name {
        Some(p) => p,
        None => {
            let n = cur.integer(t, PRIMITIVE)?;
            u8::try_from(n)
                .ok()
                .and_then(Primitive::from_number)
                .ok_or_else(|| cur.out_of_range(t, "primitive", "1", "8"))?
        }
    };
    // The final state: `-> s` or `s`; none, to be filled in from the plan's state.
    if cur.tokens.get(cur.next).is_some_and(|t| t.text == "->") {
        cur.next += 1;
    } else if cur.tokens.get(cur.next).is_none() {
        return Ok(Parsed::BarePrimitive(p));
    }
    let target_tok = cur.tokens.get(cur.next).copied();
    let target = state_token(cur, "primitive")?;
    let cmd = Command::primitive(p, target).map_err(|e| {
        let at = target_tok.unwrap_or(t);
        cur.error_at(&at, PlanErrorKind::Primitive(e))
    })?;
    Ok(Parsed::Action(Action::Command(cmd)))
}

/// `reconfigure STATE -> STATE`.
fn reconfigure_step(cur: &mut Cursor<'_, '_>) -> Result<Command, PlanError> {
    let initial = state(cur)?;
    let arrow = cur.next("reconfigure", "`->` and a target state")?;
    if arrow.text != "->" {
        return Err(cur.bad(arrow, "`->`"));
    }
    let target_tok = cur.tokens.get(cur.next).copied();
    let target = state(cur)?;
    Command::reconfigure(initial, target).map_err(|e| {
        let at = target_tok.unwrap_or(arrow);
        cur.error_at(&at, PlanErrorKind::Reconfiguration(e))
    })
}

/// `power on|off MODULE|all`.
fn power_step(cur: &mut Cursor<'_, '_>) -> Result<Command, PlanError> {
    let t = cur.next("power", "on or off")?;
    let on = match t.text.to_ascii_lowercase().as_str() {
        "on" => true,
        "off" => false,
        _ => return Err(cur.bad(t, "on or off")),
    };
    let t = cur.next("power", POWER_TARGETS)?;
    let target = if t.text.eq_ignore_ascii_case("all") {
        PowerTarget::All
    } else {
        PowerTarget::Module(module_from_keyword(t.text).ok_or_else(|| cur.bad(t, POWER_TARGETS))?)
    };
    Ok(Command::Power { target, on })
}

fn side(cur: &mut Cursor<'_, '_>, step: &'static str) -> Result<Side, PlanError> {
    let t = cur.next(step, SIDE)?;
    match t.text.to_ascii_lowercase().as_str() {
        "a" => Ok(Side::A),
        "b" => Ok(Side::B),
        _ => Err(cur.bad(t, SIDE)),
    }
}

fn servo_target(cur: &mut Cursor<'_, '_>, step: &'static str) -> Result<ServoTarget, PlanError> {
    let t = cur.next(step, SERVO)?;
    let word = t.text.to_lowercase();
    match word.as_str() {
        "contract" => return Ok(ServoTarget::Contract),
        "extend" => return Ok(ServoTarget::Extend),
        _ => {}
    }
    let number = ["us", "µs", "μs"]
        .into_iter()
        .find_map(|u| strip_suffix_ci(&word, u))
        .unwrap_or(&word);
    let us = integer(number).ok_or_else(|| cur.bad(t, SERVO))?;
    u16::try_from(us)
        .ok()
        .and_then(|us| PulseWidth::new(us).ok())
        .map(ServoTarget::Position)
        .ok_or_else(|| cur.out_of_range(t, "pulse width", "500us", "2500us"))
}

fn hip_target(cur: &mut Cursor<'_, '_>) -> Result<HipTarget, PlanError> {
    let t = cur.next("hip", HIP)?;
    let word = t.text.to_lowercase();
    match word.as_str() {
        "home" => return Ok(HipTarget::Home),
        "straight" => return Ok(HipTarget::Straight),
        "cw" => return Ok(HipTarget::RightAngleCw),
        "ccw" => return Ok(HipTarget::RightAngleCcw),
        _ => {}
    }
    let number = ["deg", "°"]
        .into_iter()
        .find_map(|u| strip_suffix_ci(&word, u))
        .unwrap_or(&word);
    let cdeg = match fixed(number, 2) {
        None => return Err(cur.bad(t, HIP)),
        Some(Err(())) => {
            return Err(cur.bad(t, "an angle with at most 2 decimals (0.01 degree steps)"))
        }
        Some(Ok(c)) => c,
    };
    u16::try_from(cdeg)
        .ok()
        .and_then(|c| HipAngle::new(c).ok())
        .map(HipTarget::Angle)
        .ok_or_else(|| cur.out_of_range(t, "hip angle", "0", "359.99 degrees"))
}

fn state(cur: &mut Cursor<'_, '_>) -> Result<State, PlanError> {
    state_token(cur, "reconfigure")
}

fn state_token(cur: &mut Cursor<'_, '_>, step: &'static str) -> Result<State, PlanError> {
    let t = cur.next(step, STATE)?;
    let mut chars = t.text.chars();
    match (chars.next(), chars.next()) {
        (Some(c), None) => State::from_letter(c.to_ascii_lowercase()),
        _ => None,
    }
    .ok_or_else(|| cur.bad(t, STATE))
}

fn wait(cur: &mut Cursor<'_, '_>) -> Result<Action, PlanError> {
    let t = cur.next("wait", DURATION)?;
    let word = t.text.to_ascii_lowercase();
    let parsed = if let Some(n) = word.strip_suffix("ms") {
        fixed(n, 0)
    } else if let Some(n) = word.strip_suffix('s') {
        fixed(n, 3)
    } else {
        None
    };
    let ms = match parsed {
        None => return Err(cur.bad(t, DURATION)),
        Some(Err(())) => return Err(cur.bad(t, "a duration in whole milliseconds")),
        Some(Ok(ms)) => ms,
    };
    u32::try_from(ms)
        .ok()
        .filter(|ms| *ms <= MAX_WAIT_MS)
        .map(|ms| Action::Wait { ms })
        .ok_or_else(|| cur.out_of_range(t, "wait", "0ms", "3600s (1 hour)"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn power_error_names_every_module_keyword() {
        for m in Module::ALL {
            assert!(POWER_TARGETS.contains(module_keyword(m)), "{m:?}");
            assert_eq!(module_from_keyword(module_keyword(m)), Some(m));
        }
    }

    #[test]
    fn tokens_carry_character_columns() {
        let t = tokenize("\tµs  a->m # x");
        let got: Vec<(&str, usize)> = t.iter().map(|t| (t.text, t.column)).collect();
        assert_eq!(got, [("µs", 2), ("a", 6), ("->", 7), ("m", 9)]);
    }

    #[test]
    fn fixed_point_numbers() {
        assert_eq!(fixed("45", 2), Some(Ok(4500)));
        assert_eq!(fixed("45.5", 2), Some(Ok(4550)));
        assert_eq!(fixed("45.50", 2), Some(Ok(4550)));
        assert_eq!(fixed("45.555", 2), Some(Err(())));
        assert_eq!(fixed("-1", 0), Some(Ok(-1)));
        assert_eq!(fixed("99999999999999999999999", 0), Some(Ok(i64::MAX)));
        for bad in ["", "-", ".5", "5.", "1e3", "1.2.3", "+1", "x"] {
            assert_eq!(fixed(bad, 2), None, "{bad:?}");
        }
    }

    #[test]
    fn durations_and_degrees_render_canonically() {
        assert_eq!(duration(2000, ""), "2s");
        assert_eq!(duration(1500, ""), "1.5s");
        assert_eq!(duration(1250, ""), "1250ms");
        assert_eq!(duration(0, ""), "0ms");
        assert_eq!(duration(999, " "), "999 ms");
        for (c, s) in [
            (0, "0"),
            (4500, "45"),
            (4550, "45.5"),
            (12345, "123.45"),
            (5, "0.05"),
        ] {
            assert_eq!(degrees(HipAngle::wrapping(c)), s);
        }
    }
}
