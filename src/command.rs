//! The command set of Table 1 as one enum, and its wire encoding in the 14-byte command packet.
//!
//! Byte 5 of the packet (Table 2) is an *opcode*: one value per command variant class, so the
//! discrete choices (side, module, pair, primitive, mode, on/off) live in the opcode and the
//! parameter bytes 6–11 carry only the quantities Table 2 names for them: the hip target in
//! bytes 6–7, arm A's in 8–9, arm B's in 10–11, and, for a reconfiguration, the final state in
//! byte 8 and the initial state in byte 9; a primitive names its final state in byte 8 too,
//! because from a turn state one primitive can reach two states. Every parameter byte a
//! command does not use must be zero, so a corrupted or mis-built packet is refused instead of
//! guessed at.
//!
//! ```
//! use mmic::command::{Command, ServoTarget};
//! use mmic::units::{PulseWidth, Side};
//! use mmic::motion::{Primitive, State};
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
//!
//! // Primitive 7 (backTurnCW) from e reaches a or d: the packet says which.
//! let p = Command::primitive(Primitive::BackTurnCw, State::D).unwrap();
//! assert_eq!(p.encode(), (0x57, [0, 0, b'd', 0, 0, 0]));
//! assert!(Command::decode(0x57, [0; 6]).is_err()); // no final state: refused
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

/// An arm target from JSON, refused outside the arms' travel.
#[cfg(feature = "serde")]
fn arm_target<'de, D: serde::Deserializer<'de>>(d: D) -> Result<ServoTarget, D::Error> {
    use serde::Deserialize as _;
    let t = ServoTarget::deserialize(d)?;
    crate::control::interp::Travel::ARM
        .check(t)
        .map_err(|e| serde::de::Error::custom(format_args!("arm target: {e}")))
}

/// A gripper target from JSON, refused outside the grippers' travel.
#[cfg(feature = "serde")]
fn gripper_target<'de, D: serde::Deserializer<'de>>(d: D) -> Result<ServoTarget, D::Error> {
    use serde::Deserialize as _;
    let t = ServoTarget::deserialize(d)?;
    crate::control::interp::Travel::GRIPPER
        .check(t)
        .map_err(|e| serde::de::Error::custom(format_args!("gripper target: {e}")))
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

/// A validated primitive command: the primitive (Table 6) and the final state it must end in.
///
/// From a turn state a primitive can reach two states (12 such pairs,
/// spec/motion/ambiguous-primitives.txt), so the number alone leaves the move to chance; the
/// final state makes every one of the 60 moves of Figure 9 commandable. Built only for a
/// final state the primitive reaches from some state in the geometric model (its 72 moves,
/// [`map::reaches`](crate::motion::map::reaches)): where the robot is now is board A's to
/// check (the move must be the primitive's cell of the map from its tracked state, and one of
/// the model's 12 turns without a hip rotation is refused by that name).
///
/// ```
/// use mmic::command::{PrimitiveMove, PrimitiveMoveError};
/// use mmic::motion::{map, Primitive, State};
/// let m = PrimitiveMove::new(Primitive::BackTurnCw, State::D).unwrap();
/// assert_eq!(map::primitive(State::E, m.target()), Some(m.primitive())); // e -> d by 7
/// assert!(m.is_move_from(State::E) && !m.is_move_from(State::A));
/// // No state is taken to a match by primitive 3 (an extension ends stretched).
/// assert_eq!(
///     PrimitiveMove::new(Primitive::FwdExtend, State::A),
///     Err(PrimitiveMoveError::Unreachable { primitive: Primitive::FwdExtend, target: State::A })
/// );
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct PrimitiveMove {
    primitive: Primitive,
    target: State,
}

impl PrimitiveMove {
    /// Refused when no state is taken to `target` by `primitive` (Figure 9): such a command
    /// could never run, wherever the robot is.
    pub const fn new(primitive: Primitive, target: State) -> Result<Self, PrimitiveMoveError> {
        if crate::motion::map::reaches(primitive, target) {
            Ok(PrimitiveMove { primitive, target })
        } else {
            Err(PrimitiveMoveError::Unreachable { primitive, target })
        }
    }

    /// The primitive (Table 6).
    pub const fn primitive(self) -> Primitive {
        self.primitive
    }

    /// The state the primitive must end in (packet byte 8).
    pub const fn target(self) -> State {
        self.target
    }

    /// Whether this is the map's move from `from`: the primitive takes `from` to the target.
    /// Board A runs the command only then.
    pub const fn is_move_from(self, from: State) -> bool {
        match crate::motion::map::primitive(from, self.target) {
            Some(p) => p as u8 == self.primitive as u8,
            None => false,
        }
    }

    /// Whether this names, from `from`, one of the model's 12 turns between two right-angle
    /// states, which the robot cannot make
    /// ([`turns_without_hip`](crate::motion::geometry::turns_without_hip)). Board A refuses
    /// such a command by that name (`Refusal::TurnWithoutHip`), not as a wrong initial state:
    /// the ground's belief of where the robot is holds, the move does not exist.
    ///
    /// ```
    /// use mmic::command::PrimitiveMove;
    /// use mmic::motion::{geometry, Primitive, State};
    /// let (_, p) = geometry::single_move(State::G, State::J).unwrap();
    /// let m = PrimitiveMove::new(p, State::J).unwrap(); // well formed: the model has the move
    /// assert!(m.turns_without_hip_from(State::G) && !m.is_move_from(State::G));
    /// ```
    pub const fn turns_without_hip_from(self, from: State) -> bool {
        match crate::motion::geometry::single_move(from, self.target) {
            Some((_, p)) => {
                p as u8 == self.primitive as u8
                    && crate::motion::geometry::turns_without_hip(from, self.target)
            }
            None => false,
        }
    }

    /// Every valid primitive command, primitives in Table 6 order, each one's final states in
    /// Table 5 order: 60 of them (72 moves, fewer the 12 that share a primitive and a final
    /// state with another move).
    pub fn all() -> impl Iterator<Item = PrimitiveMove> {
        Primitive::ALL.into_iter().flat_map(|primitive| {
            State::ALL
                .into_iter()
                .filter_map(move |target| PrimitiveMove::new(primitive, target).ok())
        })
    }
}

#[cfg(feature = "serde")]
impl<'de> serde::Deserialize<'de> for PrimitiveMove {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        #[derive(serde::Deserialize)]
        #[serde(deny_unknown_fields)]
        struct Raw {
            primitive: Primitive,
            target: State,
        }
        let r = Raw::deserialize(d)?;
        PrimitiveMove::new(r.primitive, r.target).map_err(serde::de::Error::custom)
    }
}

/// A primitive command that cannot be executed from any state.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum PrimitiveMoveError {
    /// No state is taken to `target` by `primitive` (Figure 9).
    #[error("primitive {primitive} takes no state to {target} (Figure 9)")]
    Unreachable {
        /// The primitive.
        primitive: Primitive,
        /// The final state named.
        target: State,
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
    /// Move one arm. A position must lie within the arms' travel (`Travel::ARM`, 900..=2100 µs):
    /// decoding and JSON refuse one outside it.
    Arm {
        /// Which arm.
        side: Side,
        /// Where to.
        #[cfg_attr(feature = "serde", serde(deserialize_with = "arm_target"))]
        target: ServoTarget,
    },
    /// Move one gripper. A position must lie within the grippers' travel (`Travel::GRIPPER`,
    /// 1000..=2000 µs): decoding and JSON refuse one outside it.
    Gripper {
        /// Which gripper.
        side: Side,
        /// Where to.
        #[cfg_attr(feature = "serde", serde(deserialize_with = "gripper_target"))]
        target: ServoTarget,
    },
    /// Rotate the hip.
    Hip(HipTarget),
    /// Bolt, unbolt or lower the bolters.
    Bolter(BolterCommand),
    /// Execute one motion primitive, ending in the final state it names.
    Primitive(PrimitiveMove),
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

    /// A primitive command; see [`PrimitiveMove::new`].
    pub const fn primitive(
        primitive: Primitive,
        target: State,
    ) -> Result<Command, PrimitiveMoveError> {
        match PrimitiveMove::new(primitive, target) {
            Ok(m) => Ok(Command::Primitive(m)),
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
    // Each primitive with its first final state in Table 5 order.
    for p in Primitive::ALL {
        if let Some(m) = PrimitiveMove::all().find(|m| m.primitive() == p) {
            visit(Command::Primitive(m));
        }
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

/// Calls `visit` with every representable command: each variant class, an arm or gripper
/// with every pulse width of its travel, every hip angle, every valid primitive command and
/// every valid reconfiguration: 40,595 calls.
pub fn for_each_command(mut visit: impl FnMut(Command)) {
    for_each_variant_class(PulseWidth::CENTER, HipAngle::ZERO, |c| match c {
        Command::Arm {
            side,
            target: ServoTarget::Position(_),
        } => {
            let t = crate::control::interp::Travel::ARM;
            for us in t.min().micros()..=t.max().micros() {
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
            let t = crate::control::interp::Travel::GRIPPER;
            for us in t.min().micros()..=t.max().micros() {
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
        Command::Primitive(m) => {
            for other in PrimitiveMove::all().filter(|o| o.primitive() == m.primitive()) {
                visit(Command::Primitive(other));
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

    /// The commands the exhaustive checks below walk, and how many: every command
    /// (`for_each_command`), 40,595. Under Miri, which interprets each step some 100x slower
    /// (.ci/miri), every opcode class once, at the top of the travel the arm and gripper servos
    /// share (2000 µs) and of the hip's circle (359.99°): 61.
    fn each_command_checked(visit: impl FnMut(Command)) -> usize {
        if cfg!(miri) {
            let (pw, angle) = (PulseWidth::new(2000), HipAngle::new(HipAngle::TURN - 1));
            for_each_variant_class(pw.unwrap(), angle.unwrap(), visit);
            61
        } else {
            for_each_command(visit);
            // 61 classes; 2 positional arm classes × 1201 widths (the arms' travel,
            // 900..=2100), 2 gripper classes × 1001 (1000..=2000), 36000 angles, 60 primitive
            // commands (8 classes), 84 reconfigurations.
            61 - 4 - 1 - 8 - 1 + 2 * 1201 + 2 * 1001 + 36000 + 60 + (15 * 6 - 6)
        }
    }

    #[test]
    fn every_command_round_trips_through_its_encoding() {
        let mut n = 0;
        let expected = each_command_checked(|c| {
            let (id, p) = c.encode();
            assert_eq!(Command::decode(id, p), Ok(c), "{c:?}");
            n += 1;
        });
        assert_eq!(n, expected);
        assert_eq!(expected, if cfg!(miri) { 61 } else { 40_595 });
    }

    #[test]
    fn no_command_uses_its_sequence_slot() {
        // The exactly-once sequence number may take `seq_slot(id)`: exhaustive over all commands.
        let mut n = 0;
        let expected = each_command_checked(|c| {
            let (id, p) = c.encode();
            let at = seq_slot(id).offset();
            assert_eq!((p[at], p[at + 1]), (0, 0), "{c:?}");
            n += 1;
        });
        assert_eq!(n, expected);
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
        assert_eq!(
            Command::decode(0x60, [0, 0, b'm', 0, 0, 0]),
            Err(CommandError::MissingState { index: 9 })
        );
    }

    #[test]
    fn a_primitive_names_its_final_state_in_byte_8() {
        // 7 (backTurnCW): e -> a and e -> d; both commandable, each its own bytes.
        for (target, byte) in [(State::A, b'a'), (State::D, b'd')] {
            let c = Command::primitive(Primitive::BackTurnCw, target);
            assert_eq!(c.map(|c| c.encode()), Ok((0x57, [0, 0, byte, 0, 0, 0])));
            assert_eq!(
                Command::decode(0x57, [0, 0, byte, 0, 0, 0]),
                c.map_err(CommandError::from)
            );
        }
        // The old layout (no final state), a non-letter, a state the primitive reaches from
        // nowhere, and an initial state in byte 9 (not carried for a primitive).
        assert_eq!(
            Command::decode(0x57, [0; 6]),
            Err(CommandError::MissingState { index: 8 })
        );
        assert_eq!(
            Command::decode(0x57, [0, 0, b'p', 0, 0, 0]),
            Err(CommandError::State {
                index: 8,
                found: b'p'
            })
        );
        assert_eq!(
            Command::decode(0x57, [0, 0, b'm', 0, 0, 0]),
            Err(CommandError::Primitive(PrimitiveMoveError::Unreachable {
                primitive: Primitive::BackTurnCw,
                target: State::M
            }))
        );
        assert_eq!(
            Command::decode(0x57, [0, 0, b'd', b'e', 0, 0]),
            Err(CommandError::UnusedNotZero {
                id: 0x57,
                index: 9,
                found: b'e'
            })
        );
    }

    #[test]
    fn every_move_of_the_model_is_one_primitive_command() {
        // 72 moves of the model, 60 commands: a command is (primitive, final state); the
        // robot's state supplies the row. Each command is the move of exactly the rows it
        // names: 60 moves of the map (run), 12 turns without a hip rotation (refused by name).
        let (mut moves, mut hipless) = (0, 0);
        for m in PrimitiveMove::all() {
            for from in State::ALL {
                let cell = crate::motion::map::primitive(from, m.target());
                assert_eq!(m.is_move_from(from), cell == Some(m.primitive()));
                let model = crate::motion::geometry::single_move(from, m.target());
                assert_eq!(
                    m.turns_without_hip_from(from),
                    model.map(|x| x.1) == Some(m.primitive()) && cell.is_none(),
                    "{m:?} from {from}"
                );
                assert!(!(m.is_move_from(from) && m.turns_without_hip_from(from)));
                moves += usize::from(m.is_move_from(from));
                hipless += usize::from(m.turns_without_hip_from(from));
            }
        }
        assert_eq!((PrimitiveMove::all().count(), moves, hipless), (60, 60, 12));
        for (from, to, p) in crate::motion::map::moves() {
            assert!(PrimitiveMove::new(p, to).is_ok_and(|m| m.is_move_from(from)));
        }
    }
}
