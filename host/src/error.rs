//! Why a `mmic` command failed, and the exit code each failure maps to.

use crate::codec::CodecError;
use crate::exit::{
    EXIT_HOST, EXIT_INPUT, EXIT_IO, EXIT_LINE_LOST, EXIT_SERIAL_OPEN, EXIT_UNACKNOWLEDGED,
};
use std::path::PathBuf;

/// Why `mmic` failed.
#[derive(Debug, thiserror::Error)]
pub enum CliError {
    /// The packet kind is not one of the names.
    #[error(
        "unknown packet kind {name:?}; expected one of: command, heartbeat, internal-heartbeat, \
         b-command, pus-tc, pus-tm, tc-frame, tm-frame, clcw"
    )]
    UnknownKind {
        /// What was given.
        name: String,
    },
    /// The state is not a Table 5 letter.
    #[error("unknown state {text:?}: expected a Table 5 letter a..o")]
    UnknownState {
        /// What was given.
        text: String,
    },
    /// Encoding or decoding failed.
    #[error(transparent)]
    Codec(#[from] CodecError),
    /// A PUS-C packet was refused, or its JSON is bad.
    #[error(transparent)]
    Pus(#[from] crate::pus::PusCodecError),
    /// spec/ could not be turned into the XTCE mission database.
    #[error(transparent)]
    Xtce(#[from] crate::xtce::XtceError),
    /// A page could not be written.
    #[error("cannot write {}: {source}", path.display())]
    Write {
        /// The file or directory.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// The plan file could not be read.
    #[error("cannot read {}: {source}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// The plan file is malformed.
    #[error("{}: {error}", path.display())]
    Plan {
        /// The file.
        path: PathBuf,
        /// Where and why.
        error: crate::plan::PlanError,
    },
    /// An injection (`mmic sim --inject`, or an alias) was not taken.
    #[error(transparent)]
    Inject(#[from] crate::sim::inject::InjectError),
    /// The simulation failed (transport set-up).
    #[error("simulation failed: {0}")]
    Sim(#[source] std::io::Error),
    /// The plan did not complete.
    #[error("the plan did not complete: {0}")]
    Incomplete(String),
    /// The host fell so far behind the simulated clock that the run's timeouts may be the
    /// host's, not the robot's (an unpaced run on a loaded machine).
    #[error(
        "the host fell behind: a board tick started {late_ms} ms (simulated) late, beyond what \
         the firmware's timers tolerate, so this run's outcome is not the robot's; rerun with a \
         smaller --scale"
    )]
    HostBehind {
        /// The latest tick, simulated ms.
        late_ms: u32,
    },
    /// The fault swarm found a broken invariant (the replay command is in the message).
    #[error("{0}")]
    Invariant(String),
    /// A fleet run missed its goal (an answer later than 0.7 s, or none).
    #[error("{0}")]
    Fleet(String),
    /// Options that do not go together.
    #[error("{0}")]
    Usage(String),
    /// `mmic replay --against`: the two runs' outputs differ (where, in the message).
    #[error("{0}")]
    Replay(String),
    /// The serial device of the opsUI line cannot be opened or set up.
    #[error("cannot open serial device {device}: {why}")]
    SerialOpen {
        /// The device path.
        device: String,
        /// The OS's or the settings' reason.
        why: String,
    },
    /// The opsUI line was lost before the plan ended.
    #[error("serial line {device} lost at {at_s:.1} s: {why}; {outstanding}")]
    LineLost {
        /// The device path.
        device: String,
        /// When, on the plan's clock, s.
        at_s: f64,
        /// End of file, hang-up, or the I/O error.
        why: String,
        /// What became of the command outstanding.
        outstanding: String,
    },
    /// The plan ended at a step the robot never acknowledged.
    #[error("{0}")]
    Unacknowledged(String),
    /// Standard output or error is closed.
    #[error("cannot write output: {0}")]
    Output(#[source] std::io::Error),
}

impl CliError {
    /// The process exit code (see the module docs).
    pub fn exit_code(&self) -> u8 {
        match self {
            CliError::Codec(e) => e.exit_code(),
            CliError::Pus(e) => e.exit_code(),
            CliError::Xtce(_) | CliError::Usage(_) => EXIT_INPUT,
            CliError::UnknownKind { .. } | CliError::UnknownState { .. } => EXIT_INPUT,
            CliError::Plan { .. } | CliError::Inject(_) => EXIT_INPUT,
            CliError::Incomplete(_)
            | CliError::Invariant(_)
            | CliError::Fleet(_)
            | CliError::Replay(_) => 1,
            CliError::HostBehind { .. } => EXIT_HOST,
            CliError::SerialOpen { .. } => EXIT_SERIAL_OPEN,
            CliError::LineLost { .. } => EXIT_LINE_LOST,
            CliError::Unacknowledged(_) => EXIT_UNACKNOWLEDGED,
            CliError::Write { .. }
            | CliError::Output(_)
            | CliError::Read { .. }
            | CliError::Sim(_) => EXIT_IO,
        }
    }
}
