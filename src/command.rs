//! The command set of Table 1 as one enum, and its wire encoding in the 14-byte command packet.
//!
//! Byte 5 of the packet (Table 2) is an *opcode*: one value per command variant class, so the
//! discrete choices (side, module, pair, primitive, mode, on/off) live in the opcode and the
//! parameter bytes 6–11 carry only the quantities Table 2 names for them: the hip target in
//! bytes 6–7, arm A's in 8–9, arm B's in 10–11, and, for a reconfiguration, the final state in
//! byte 8 and the initial state in byte 9. Every parameter byte a command does not use must be
//! zero, so a corrupted or mis-built packet is refused instead of guessed at.
//!
//! ```
//! use mmic::command::{Command, ServoTarget};
//! use mmic::units::{PulseWidth, Side};
//! use mmic::motion::State;
//!
//! let c = Command::Arm { side: Side::B, target: ServoTarget::Position(PulseWidth::new(1200).unwrap()) };
//! let (opcode, params) = c.encode();
//! assert_eq!(opcode, 0x26);
//! assert_eq!(params, [0, 0, 0, 0, 0xb0, 0x04]); // 1200 µs, low byte first, in bytes 10–11
//! assert_eq!(Command::decode(opcode, params), Ok(c));
//!
//! let r = Command::reconfigure(State::A, State::M).unwrap();
//! assert_eq!(r.encode(), (0x60, [0, 0, b'm', b'a', 0, 0]));
//! assert!(Command::reconfigure(State::A, State::D).is_err()); // d is not a final state
//! ```

use crate::mode::Mode;
use crate::motion::{Primitive, State};
use crate::units::{HipAngle, Module, PulseWidth, Side};
use crate::wire_enum::wire_enum;

/// The command's byte encoding (opcodes, parameter slots, the sequence number's slot, the
/// errors of undecodable bytes) is wire layout: it lives in [`crate::wire::opcode`].
pub use crate::wire::opcode::{self, seq_slot, CommandError, Slot, PARAM_LEN, PARAM_OFFSET};

/// Where an arm or gripper goes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum ServoTarget {
    /// Totally contract (arm retracted / gripper released).
    Contract,
    /// Totally extend (arm out / gripper engaged on the face).
    Extend,
    /// Partially contract or extend: go to this pulse width.
    Position(PulseWidth),
}

/// Where the hip goes: one of the common positions, or any angle.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum HipTarget {
    /// The contracted-gripped (home) angle, a configuration value.
    Home,
    /// Arms in line: 180.00°.
    Straight,
    /// Quarter turn clockwise: 90.00°.
    RightAngleCw,
    /// Quarter turn counter-clockwise: 270.00°.
    RightAngleCcw,
    /// Any other angle.
    Angle(HipAngle),
}

/// The angle a hip target stands for; `None` for [`HipTarget::Home`], whose angle is a
/// configuration value (the contracted-gripped angle).
pub const fn preset_angle(t: HipTarget) -> Option<HipAngle> {
    let cdeg = match t {
        HipTarget::Home => return None,
        HipTarget::Straight => 18000,
        HipTarget::RightAngleCw => 9000,
        HipTarget::RightAngleCcw => 27000,
        HipTarget::Angle(a) => return Some(a),
    };
    match HipAngle::new(cdeg) {
        Ok(a) => Some(a),
        Err(_) => None,
    }
}

/// The bolter pairs are the bolter's concept ([`crate::bolter`]); commands name them.
pub use crate::bolter::{BolterPair, BolterPairError};

/// Which fasteners a bolt or unbolt command works on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum Fasteners {
    /// One pair.
    Pair(BolterPair),
    /// Pairs 1–4 in order, stopping at the first that fails.
    All,
}

/// A bolter command (Table 1, "Bolter").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum BolterCommand {
    /// Bolt a pair of fasteners, or all four.
    Bolt(Fasteners),
    /// Unbolt a pair of fasteners, or all four.
    Unbolt(Fasteners),
    /// Move both bolters down.
    Down,
}

/// What a power command switches.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum PowerTarget {
    /// One module.
    Module(Module),
    /// Every module.
    All,
}

/// A validated reconfiguration: the initial state and a different, matched target state.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Reconfiguration {
    initial: State,
    target: State,
}

impl Reconfiguration {
    /// Refused when `target` is not a matched (final) state or equals `initial`.
    pub const fn new(initial: State, target: State) -> Result<Self, ReconfigurationError> {
        if !target.is_matched() {
            Err(ReconfigurationError::TargetNotMatched { target })
        } else if initial as u8 == target as u8 {
            Err(ReconfigurationError::SameState { state: target })
        } else {
            Ok(Reconfiguration { initial, target })
        }
    }

    /// Where the operator believes the robot is (checked against the detected state).
    pub const fn initial(self) -> State {
        self.initial
    }

    /// Where it must end: a matched state.
    pub const fn target(self) -> State {
        self.target
    }
}

#[cfg(feature = "serde")]
impl<'de> serde::Deserialize<'de> for Reconfiguration {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        #[derive(serde::Deserialize)]
        #[serde(deny_unknown_fields)]
        struct Raw {
            initial: State,
            target: State,
        }
        let r = Raw::deserialize(d)?;
        Reconfiguration::new(r.initial, r.target).map_err(serde::de::Error::custom)
    }
}

/// A reconfiguration that cannot be executed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ReconfigurationError {
    /// Only matched states are final states (Section 6).
    #[error("target state {target} is not a matched (final) state")]
    TargetNotMatched {
        /// The refused target.
        target: State,
    },
    /// Initial equals target: not a reconfiguration (the black cells of Figure 9).
    #[error("initial and target state are both {state}: not a reconfiguration")]
    SameState {
        /// The state given twice.
        state: State,
    },
}

/// A command to the robot (Table 1, plus `ClearFaults`, which the fault latching of Section 7
/// needs and the paper does not list).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(
    feature = "serde",
    serde(rename_all = "snake_case", deny_unknown_fields)
)]
pub enum Command {
    /// Request a heartbeat packet.
    Heartbeat,
    /// Emergency stop of the current motion.
    Stop,
    /// After a stop, resume the motion.
    Reset,
    /// Trigger the assembly system operation fault.
    SystemFault,
    /// Clear the latched faults whose conditions no longer hold (extension).
    ClearFaults,
    /// Change operating mode.
    Mode(Mode),
    /// Move one arm.
    Arm {
        /// Which arm.
        side: Side,
        /// Where to.
        target: ServoTarget,
    },
    /// Move one gripper.
    Gripper {
        /// Which gripper.
        side: Side,
        /// Where to.
        target: ServoTarget,
    },
    /// Rotate the hip.
    Hip(HipTarget),
    /// Bolt, unbolt or lower the bolters.
    Bolter(BolterCommand),
    /// Execute one motion primitive.
    Primitive(Primitive),
    /// Reconfigure from an initial to a target state.
    Reconfigure(Reconfiguration),
    /// Switch power to one or all modules.
    Power {
        /// What to switch.
        target: PowerTarget,
        /// On or off.
        on: bool,
    },
}

impl Command {
    /// A reconfiguration command; see [`Reconfiguration::new`].
    pub const fn reconfigure(
        initial: State,
        target: State,
    ) -> Result<Command, ReconfigurationError> {
        match Reconfiguration::new(initial, target) {
            Ok(r) => Ok(Command::Reconfigure(r)),
            Err(e) => Err(e),
        }
    }

    /// Opcode and the six parameter bytes (packet bytes 6..=11): the byte encoding in
    /// [`crate::wire::opcode`].
    pub fn encode(&self) -> (u8, [u8; PARAM_LEN]) {
        crate::wire::opcode::encode(self)
    }

    /// The command for opcode `id` and parameter bytes `p` (packet bytes 6..=11): the byte
    /// encoding in [`crate::wire::opcode`].
    pub fn decode(id: u8, p: [u8; PARAM_LEN]) -> Result<Command, CommandError> {
        crate::wire::opcode::decode(id, p)
    }

    /// Table 1 row this command belongs to.
    pub const fn kind(&self) -> CommandKind {
        match self {
            Command::Heartbeat => CommandKind::Heartbeat,
            Command::Stop => CommandKind::Stop,
            Command::Reset => CommandKind::Reset,
            Command::SystemFault => CommandKind::SystemFault,
            Command::ClearFaults => CommandKind::ClearFaults,
            Command::Mode(_) => CommandKind::Mode,
            Command::Arm { .. } => CommandKind::Arm,
            Command::Gripper { .. } => CommandKind::Gripper,
            Command::Hip(_) => CommandKind::Hip,
            Command::Bolter(_) => CommandKind::Bolter,
            Command::Primitive(_) => CommandKind::Primitive,
            Command::Reconfigure(_) => CommandKind::Reconfiguration,
            Command::Power { .. } => CommandKind::PowerControl,
        }
    }
}

wire_enum! {
    /// The rows of Table 1 (plus the `ClearFaults` extension): what mode rules and spec/ talk about.
    #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
    #[cfg_attr(feature = "defmt", derive(defmt::Format))]
    #[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
    #[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
    pub enum CommandKind {
        /// Single module: arm.
        Arm => "arm",
        /// Single module: gripper.
        Gripper => "gripper",
        /// Single module: hip.
        Hip => "hip",
        /// Single module: bolter.
        Bolter => "bolter",
        /// Primitive motion.
        Primitive => "primitive",
        /// Stop.
        Stop => "stop",
        /// Reset.
        Reset => "reset",
        /// Power control.
        PowerControl => "power_control",
        /// Reconfiguration.
        Reconfiguration => "reconfiguration",
        /// Mode.
        Mode => "mode",
        /// System fault.
        SystemFault => "system_fault",
        /// Heartbeat.
        Heartbeat => "heartbeat",
        /// Clear latched faults (extension, not in Table 1).
        ClearFaults => "clear_faults",
    }

    /// Table 1 order, then the extension.
    const ALL;
    /// snake_case name, as in spec/ and JSON.
    pub const fn name(self) -> &'static str;
    impl Display("{}", name);
}

impl CommandKind {
    /// Whether commands of this kind move an actuator (an arm, a gripper, the hip, a bolter,
    /// or several through a primitive or a reconfiguration): the commands a Stop blocks until
    /// Reset (Table 1), that Table 7 refuses outside Operational (arm and hip excepted in Safed),
    /// and that board A runs one at a time. A mode change is not one: it powers modules, and
    /// entering Operational homes the servos as part of the mode. spec/modes.toml lists them
    /// (`moving`), and a test holds this to it.
    pub const fn moves(self) -> bool {
        matches!(
            self,
            CommandKind::Arm
                | CommandKind::Gripper
                | CommandKind::Hip
                | CommandKind::Bolter
                | CommandKind::Primitive
                | CommandKind::Reconfiguration
        )
    }
}

/// Every command whose parameters are discrete, plus each parameterised variant at the given
/// representative values: the "variant classes" that exhaustive checks iterate over.
///
/// `visit` is called once per command; 61 calls, one per opcode.
pub fn for_each_variant_class(pw: PulseWidth, angle: HipAngle, mut visit: impl FnMut(Command)) {
    visit(Command::Heartbeat);
    visit(Command::Stop);
    visit(Command::Reset);
    visit(Command::SystemFault);
    visit(Command::ClearFaults);
    for m in Mode::ALL {
        visit(Command::Mode(m));
    }
    for side in Side::ALL {
        for target in [
            ServoTarget::Contract,
            ServoTarget::Extend,
            ServoTarget::Position(pw),
        ] {
            visit(Command::Arm { side, target });
        }
    }
    for side in Side::ALL {
        for target in [
            ServoTarget::Contract,
            ServoTarget::Extend,
            ServoTarget::Position(pw),
        ] {
            visit(Command::Gripper { side, target });
        }
    }
    for h in [
        HipTarget::Home,
        HipTarget::Straight,
        HipTarget::RightAngleCw,
        HipTarget::RightAngleCcw,
        HipTarget::Angle(angle),
    ] {
        visit(Command::Hip(h));
    }
    for bolt in [true, false] {
        for which in [
            Fasteners::Pair(BolterPair::P1),
            Fasteners::Pair(BolterPair::P2),
            Fasteners::Pair(BolterPair::P3),
            Fasteners::Pair(BolterPair::P4),
            Fasteners::All,
        ] {
            visit(Command::Bolter(if bolt {
                BolterCommand::Bolt(which)
            } else {
                BolterCommand::Unbolt(which)
            }));
        }
    }
    visit(Command::Bolter(BolterCommand::Down));
    for p in Primitive::ALL {
        visit(Command::Primitive(p));
    }
    visit(Command::Reconfigure(Reconfiguration {
        initial: State::A,
        target: State::M,
    }));
    for on in [true, false] {
        for m in Module::ALL {
            visit(Command::Power {
                target: PowerTarget::Module(m),
                on,
            });
        }
        visit(Command::Power {
            target: PowerTarget::All,
            on,
        });
    }
}

/// Calls `visit` with every representable command: each variant class with every pulse width,
/// every hip angle and every valid reconfiguration: 44,143 calls.
pub fn for_each_command(mut visit: impl FnMut(Command)) {
    for_each_variant_class(PulseWidth::CENTER, HipAngle::ZERO, |c| match c {
        Command::Arm {
            side,
            target: ServoTarget::Position(_),
        } => {
            for us in PulseWidth::MIN_US..=PulseWidth::MAX_US {
                if let Ok(pw) = PulseWidth::new(us) {
                    visit(Command::Arm {
                        side,
                        target: ServoTarget::Position(pw),
                    });
                }
            }
        }
        Command::Gripper {
            side,
            target: ServoTarget::Position(_),
        } => {
            for us in PulseWidth::MIN_US..=PulseWidth::MAX_US {
                if let Ok(pw) = PulseWidth::new(us) {
                    visit(Command::Gripper {
                        side,
                        target: ServoTarget::Position(pw),
                    });
                }
            }
        }
        Command::Hip(HipTarget::Angle(_)) => {
            for a in 0..HipAngle::TURN {
                if let Ok(a) = HipAngle::new(a) {
                    visit(Command::Hip(HipTarget::Angle(a)));
                }
            }
        }
        Command::Reconfigure(_) => {
            for initial in State::ALL {
                for target in State::MATCHED {
                    if let Ok(r) = Reconfiguration::new(initial, target) {
                        visit(Command::Reconfigure(r));
                    }
                }
            }
        }
        other => visit(other),
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_command_round_trips_through_its_encoding() {
        let mut n = 0;
        for_each_command(|c| {
            let (id, p) = c.encode();
            assert_eq!(Command::decode(id, p), Ok(c), "{c:?}");
            n += 1;
        });
        // 61 classes; 4 positional servo classes × 2001 widths, 36000 angles, 84 reconfigurations.
        assert_eq!(n, 61 - 4 - 1 - 1 + 4 * 2001 + 36000 + (15 * 6 - 6));
    }

    #[test]
    fn no_command_uses_its_sequence_slot() {
        // The exactly-once sequence number may take `seq_slot(id)`: exhaustive over all commands.
        let mut n = 0;
        for_each_command(|c| {
            let (id, p) = c.encode();
            let at = seq_slot(id).offset();
            assert_eq!((p[at], p[at + 1]), (0, 0), "{c:?}");
            n += 1;
        });
        assert_eq!(n, 44_143);
    }

    #[test]
    fn opcodes_are_distinct_per_variant_class() {
        let mut seen = [false; 256];
        let mut classes = 0;
        for_each_variant_class(PulseWidth::CENTER, HipAngle::ZERO, |c| {
            let (id, _) = c.encode();
            assert!(!seen[id as usize], "opcode {id:#04x} used twice");
            seen[id as usize] = true;
            classes += 1;
        });
        assert_eq!(classes, 61);
        // Every other opcode is refused, whatever the parameters.
        for id in 0..=255u8 {
            if !seen[id as usize] {
                assert_eq!(
                    Command::decode(id, [0; 6]),
                    Err(CommandError::UnknownId { id })
                );
            }
        }
    }

    #[test]
    fn unused_parameter_bytes_must_be_zero() {
        for_each_variant_class(PulseWidth::CENTER, HipAngle::ZERO, |c| {
            let (id, p) = c.encode();
            for i in 0..PARAM_LEN {
                let mut q = p;
                q[i] ^= 0x01;
                // Either the byte was unused (refused as such) or it was a value: then it must
                // decode to a different command or be refused; never to the same command.
                assert_ne!(Command::decode(id, q), Ok(c), "{c:?} byte {i}");
            }
        });
    }

    #[test]
    fn range_errors_name_the_byte() {
        let bad = 2501u16.to_le_bytes();
        assert_eq!(
            Command::decode(0x26, [0, 0, 0, 0, bad[0], bad[1]]),
            Err(CommandError::PulseWidth {
                index: 10,
                found: 2501
            })
        );
        let bad = 36000u16.to_le_bytes();
        assert_eq!(
            Command::decode(0x34, [bad[0], bad[1], 0, 0, 0, 0]),
            Err(CommandError::HipAngle {
                index: 6,
                found: 36000
            })
        );
        assert_eq!(
            Command::decode(0x60, [0, 0, b'z', b'a', 0, 0]),
            Err(CommandError::State {
                index: 8,
                found: b'z'
            })
        );
        assert_eq!(
            Command::decode(0x60, [0, 0, b'd', b'a', 0, 0]),
            Err(CommandError::Reconfiguration(
                ReconfigurationError::TargetNotMatched { target: State::D }
            ))
        );
        assert_eq!(
            Command::decode(0x60, [0, 0, b'a', b'a', 0, 0]),
            Err(CommandError::Reconfiguration(
                ReconfigurationError::SameState { state: State::A }
            ))
        );
    }
}
