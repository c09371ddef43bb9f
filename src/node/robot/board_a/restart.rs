//! Board A across a restart: what it keeps (its exactly-once log and its boot count, in flash
//! on the robot: decision `restart-board-a`) and how it comes up (Table 7's power-on: Standby,
//! every servo unpowered, nothing resumed, the state unknown).
//!
//! The shell writes [`BoardA::ahead`]'s record *before* the tick that takes a new sequenced
//! command, and [`BoardA::durable`]'s after every tick that changed it. A restart at any
//! instant then finds the number of every command that may have run in the store, and a
//! resend of it is answered, never run again.
//!
//! ```
//! use mmic::command::Command;
//! use mmic::mode::Mode;
//! use mmic::restart::ResetCause;
//! use mmic::node::robot::board_a::{BoardA, Config, Inputs};
//! use mmic::units::BoardNumber;
//! use mmic::wire::command::CommandRepr;
//! use mmic::wire::heartbeat::HeartbeatRepr;
//!
//! let mut a = BoardA::new(Config::default());
//! let cmd = CommandRepr { board: BoardNumber::ONE, command: Command::Mode(Mode::Operational), seq: 7 };
//! let ahead = a.ahead(Some(&cmd.to_bytes())).unwrap(); // written before the tick
//! a.tick(0, &Inputs { command: Some(cmd.to_bytes()), ..Inputs::at_home() });
//! assert_eq!(a.durable().last_seq, ahead.last_seq);
//! // Power cut: board A starts again from what flash kept.
//! let mut a = BoardA::restarted(Config::default(), Some(a.durable()), ResetCause::BrownOut);
//! assert_eq!(a.mode(), Mode::Standby);
//! let out = a.tick(10, &Inputs { command: Some(cmd.to_bytes()), ..Inputs::at_home() });
//! let hb = HeartbeatRepr::parse(&out.heartbeat.unwrap()).unwrap();
//! assert_eq!((hb.last_seq, hb.mode), (7, Mode::Standby)); // answered, not run again
//! assert_eq!(hb.boot.cause, ResetCause::BrownOut);
//! ```

use super::BoardA;
use super::Config;
use crate::node::exactly_once::{Admission, CommandLog};
use crate::refusal::Refusal;
use crate::restart::{Boot, ResetCause};

/// What board A keeps across a restart: the exactly-once log's last entry and the boot count.
/// Five octets in flash ([`Durable::to_bytes`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Durable {
    /// The last sequenced command taken (0 = none).
    pub last_seq: u16,
    /// Its outcome (`None` = accepted).
    pub outcome: Option<Refusal>,
    /// Starts in all (wrapping).
    pub boots: u16,
}

impl Durable {
    /// Length of the record.
    pub const LEN: usize = 5;

    /// The record: sequence number and boot count little-endian, the outcome byte (0 =
    /// accepted, else the refusal code, as heartbeat byte 62) between them.
    pub fn to_bytes(&self) -> [u8; Durable::LEN] {
        let [s0, s1] = self.last_seq.to_le_bytes();
        let [b0, b1] = self.boots.to_le_bytes();
        [s0, s1, self.outcome.map_or(0, Refusal::to_wire), b0, b1]
    }

    /// Reads a record back; `None` when the outcome byte is no refusal code (a record the
    /// storage's own check let through corrupted: the shell then boots as from a fresh flash).
    pub fn from_bytes(b: &[u8; Durable::LEN]) -> Option<Durable> {
        let outcome = match b[2] {
            0 => None,
            x => Some(Refusal::from_wire(x)?),
        };
        Some(Durable {
            last_seq: u16::from_le_bytes([b[0], b[1]]),
            outcome,
            boots: u16::from_le_bytes([b[3], b[4]]),
        })
    }
}

impl BoardA {
    /// Board A after a restart for `cause`, from what the store kept (`None`: a fresh flash,
    /// the first start). As at power-on (Table 7): Standby, no fault latched, every servo
    /// unpowered, no motion resumed, the state unknown; the exactly-once log as it was, so that
    /// no command taken before the restart runs again; the boot count one more.
    pub fn restarted(cfg: Config, kept: Option<Durable>, cause: ResetCause) -> BoardA {
        let kept = kept.unwrap_or_default();
        let mut a = BoardA::new(cfg);
        let mut log = CommandLog::new();
        log.record(kept.last_seq, kept.outcome);
        a.log = log;
        a.kept = (kept.last_seq, kept.outcome);
        a.boots = kept.boots.wrapping_add(1);
        a.boot = Boot::after(cause, a.boots);
        a
    }

    /// Whether `command` may run again after a restart: the Heartbeat poll, which does
    /// nothing and which the gateway sends four times a second when idle, so board A's flash
    /// leaves it out of [`BoardA::durable`] (a flash write per poll would wear the sector out
    /// in months: decision `restart-board-a`). Every other sequenced command is remembered,
    /// and the simulator's checks count a second run of it.
    ///
    /// ```
    /// use mmic::command::Command;
    /// use mmic::node::robot::board_a::BoardA;
    ///
    /// assert!(BoardA::may_run_again(Some(Command::Heartbeat)));
    /// assert!(!BoardA::may_run_again(Some(Command::Stop)));
    /// ```
    pub fn may_run_again(command: Option<crate::command::Command>) -> bool {
        command == Some(crate::command::Command::Heartbeat)
    }

    /// What to keep now (write it after a tick that changed it): the log's last entry, Heartbeat
    /// polls left out (they do nothing, so running one again after a restart harms nothing,
    /// and a write per poll would wear the flash out).
    pub const fn durable(&self) -> Durable {
        let (last_seq, outcome) = self.kept;
        Durable {
            last_seq,
            outcome,
            boots: self.boots,
        }
    }

    /// The record to write *before* the tick that takes `command`, when that tick may run it:
    /// a new sequenced command for this robot, its outcome recorded as not known
    /// ([`Refusal::Restarted`]: a restart before the tick's own outcome replaces it in
    /// [`BoardA::durable`] leaves a command that ran at most once, and a copy is answered so,
    /// never as accepted). `None` when the tick runs nothing the log must
    /// remember (no packet, another robot's, a copy, an unsequenced command).
    pub fn ahead(
        &self,
        command: Option<&[u8; crate::wire::command::COMMAND_LEN]>,
    ) -> Option<Durable> {
        let (seq, _) = self.unpack(command?).ok()?;
        (seq != 0 && self.log.admit(seq) == Admission::Execute).then_some(Durable {
            last_seq: seq,
            outcome: Some(Refusal::Restarted),
            boots: self.boots,
        })
    }

    /// This start as heartbeat byte 59 reports it.
    pub const fn boot(&self) -> Boot {
        self.boot
    }
}
