//! The 15 allowed configurations of Table 5.

use core::fmt;

/// Shape of a configuration (Section 6).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum StateKind {
    /// Contracted and gripped onto a single face; the final states of a reconfiguration.
    Matched,
    /// Both sides on different faces of one axis.
    Stretch,
    /// Sides along different axes.
    Turn,
}

/// One of the 15 configuration states of Table 5, lettered `a`..`o`.
///
/// On the wire a state is its lowercase ASCII letter (`0x61`..`0x6f`), so it reads plainly in a
/// hex dump and a zero byte is never a state.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(try_from = "char", into = "char")
)]
#[allow(missing_docs)] // the letters are documented by `name()` and Table 5
pub enum State {
    A,
    B,
    C,
    D,
    E,
    F,
    G,
    H,
    I,
    J,
    K,
    L,
    M,
    N,
    O,
}

/// Table 5, in order: letter, name.
const TABLE5: [(char, &str); 15] = [
    ('a', "Xneg match"),
    ('b', "Yneg match"),
    ('c', "Zneg match"),
    ('d', "Xneg Xpos stretch"),
    ('e', "Xneg Ypos turn"),
    ('f', "Xneg Zpos turn"),
    ('g', "Yneg Xpos turn"),
    ('h', "Yneg Ypos stretch"),
    ('i', "Yneg Zpos turn"),
    ('j', "Zneg Xpos turn"),
    ('k', "Zneg Ypos turn"),
    ('l', "Zneg Zpos stretch"),
    ('m', "Xpos match"),
    ('n', "Ypos match"),
    ('o', "Zpos match"),
];

impl State {
    /// All states in Table 5 order.
    pub const ALL: [State; 15] = [
        State::A,
        State::B,
        State::C,
        State::D,
        State::E,
        State::F,
        State::G,
        State::H,
        State::I,
        State::J,
        State::K,
        State::L,
        State::M,
        State::N,
        State::O,
    ];

    /// The six matched (final) states.
    pub const MATCHED: [State; 6] = [State::A, State::B, State::C, State::M, State::N, State::O];

    /// Index 0..15 in Table 5 order.
    pub const fn index(self) -> usize {
        self as usize
    }

    /// State at Table 5 index `i`.
    pub const fn from_index(i: usize) -> Option<State> {
        if i < 15 {
            Some(Self::ALL[i])
        } else {
            None
        }
    }

    /// Table 5 letter.
    pub const fn letter(self) -> char {
        TABLE5[self as usize].0
    }

    /// Table 5 descriptive name.
    pub const fn name(self) -> &'static str {
        TABLE5[self as usize].1
    }

    /// State with Table 5 letter `c` (lowercase).
    pub const fn from_letter(c: char) -> Option<State> {
        if c >= 'a' && c <= 'o' {
            State::from_index(c as usize - 'a' as usize)
        } else {
            None
        }
    }

    /// Byte on the wire: the ASCII letter.
    pub const fn to_wire(self) -> u8 {
        b'a' + self as u8
    }

    /// State from its wire byte.
    pub const fn from_wire(b: u8) -> Option<State> {
        if b >= b'a' && b <= b'o' {
            State::from_index((b - b'a') as usize)
        } else {
            None
        }
    }

    /// Matched, stretch or turn.
    pub const fn kind(self) -> StateKind {
        match self {
            State::A | State::B | State::C | State::M | State::N | State::O => StateKind::Matched,
            State::D | State::H | State::L => StateKind::Stretch,
            _ => StateKind::Turn,
        }
    }

    /// True for the matched states, the only final states of a reconfiguration.
    pub const fn is_matched(self) -> bool {
        matches!(self.kind(), StateKind::Matched)
    }
}

impl fmt::Display for State {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} ({})", self.letter(), self.name())
    }
}

/// A character that is not a Table 5 letter.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
#[error("state must be a letter 'a'..='o' (Table 5), found {0:?}")]
pub struct StateLetterError(pub char);

impl TryFrom<char> for State {
    type Error = StateLetterError;
    fn try_from(c: char) -> Result<State, StateLetterError> {
        State::from_letter(c).ok_or(StateLetterError(c))
    }
}

impl From<State> for char {
    fn from(s: State) -> char {
        s.letter()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn letters_wire_and_index_agree() {
        for (i, s) in State::ALL.iter().enumerate() {
            assert_eq!(s.index(), i);
            assert_eq!(State::from_letter(s.letter()), Some(*s));
            assert_eq!(State::from_wire(s.to_wire()), Some(*s));
            assert_eq!(s.to_wire(), s.letter() as u8);
        }
        assert_eq!(State::from_wire(0), None);
        assert_eq!(State::from_wire(b'p'), None);
        assert_eq!(State::from_letter('p'), None);
    }

    #[test]
    fn kinds_follow_names() {
        for s in State::ALL {
            let expect = if s.name().ends_with("match") {
                StateKind::Matched
            } else if s.name().ends_with("stretch") {
                StateKind::Stretch
            } else {
                StateKind::Turn
            };
            assert_eq!(s.kind(), expect, "{s}");
        }
        assert_eq!(State::ALL.iter().filter(|s| s.is_matched()).count(), 6);
    }
}
