//! The two commands that name states: a primitive with the final state it must end in, and a
//! reconfiguration between two states. Both are checked against the map of Figure 9 when they
//! are built, so a `Command` holding one can always be run from some state.
// req: P7.4, D:commands-in-every-mode

use crate::pose::{Primitive, State};

/// A validated reconfiguration: the initial state and a different, matched target state.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct Reconfiguration {
    pub(super) initial: State,
    pub(super) target: State,
}

impl Reconfiguration {
    /// Refused when `target` is not a matched (final) state or equals `initial`.
    pub const fn new(initial: State, target: State) -> Result<Self, ReconfigurationError> {
        if !target.is_matched() {
            Err(ReconfigurationError::TargetNotMatched { target })
        } else if initial.to_wire() == target.to_wire() {
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
/// [`map::reaches`](crate::pose::map::reaches)): where the robot is now is board A's to
/// check (the move must be the primitive's cell of the map from its tracked state, and one of
/// the model's 12 turns without a hip rotation is refused by that name).
///
/// ```
/// use mmic::command::{PrimitiveMove, PrimitiveMoveError};
/// use mmic::pose::{map, Primitive, State};
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
        if crate::pose::map::reaches(primitive, target) {
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
        match crate::pose::map::primitive(from, self.target) {
            Some(p) => p.number() == self.primitive.number(),
            None => false,
        }
    }

    /// Whether this names, from `from`, one of the model's 12 turns between two right-angle
    /// states, which the robot cannot make
    /// ([`turns_without_hip`](crate::pose::geometry::turns_without_hip)). Board A refuses
    /// such a command by that name (`Refusal::TurnWithoutHip`), not as a wrong initial state:
    /// the ground's belief of where the robot is holds, the move does not exist.
    ///
    /// ```
    /// use mmic::command::PrimitiveMove;
    /// use mmic::pose::{geometry, Primitive, State};
    /// let (_, p) = geometry::single_move(State::G, State::J).unwrap();
    /// let m = PrimitiveMove::new(p, State::J).unwrap(); // well formed: the model has the move
    /// assert!(m.turns_without_hip_from(State::G) && !m.is_move_from(State::G));
    /// ```
    pub const fn turns_without_hip_from(self, from: State) -> bool {
        match crate::pose::geometry::single_move(from, self.target) {
            Some((_, p)) => {
                p.number() == self.primitive.number()
                    && crate::pose::geometry::turns_without_hip(from, self.target)
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
