//! The 15 allowed configurations of Table 5.
// req: T5/*, P6.1, P6.2, P6.3, D:state-letters

use crate::units::slice;
use crate::units::widen::to_u32;
use crate::wire_enum::wire_enum;

/// Shape of a configuration (Section 6).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
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

wire_enum! {
    /// One of the 15 configuration states of Table 5, lettered `a`..`o`.
    ///
    /// On the wire a state is its lowercase ASCII letter (`0x61`..`0x6f`), so it reads plainly in a
    /// hex dump and a zero byte is never a state.
    #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
    #[cfg_attr(feature = "defmt", derive(defmt::Format))]
    #[cfg_attr(
        feature = "serde",
        derive(serde::Serialize, serde::Deserialize),
        serde(try_from = "char", into = "char")
    )]
    #[expect(missing_docs, reason = "the letters are documented by `name()` and Table 5")]
    pub enum State {
        A = b'a' => "Xneg match",
        B = b'b' => "Yneg match",
        C = b'c' => "Zneg match",
        D = b'd' => "Xneg Xpos stretch",
        E = b'e' => "Xneg Ypos turn",
        F = b'f' => "Xneg Zpos turn",
        G = b'g' => "Yneg Xpos turn",
        H = b'h' => "Yneg Ypos stretch",
        I = b'i' => "Yneg Zpos turn",
        J = b'j' => "Zneg Xpos turn",
        K = b'k' => "Zneg Ypos turn",
        L = b'l' => "Zneg Zpos stretch",
        M = b'm' => "Xpos match",
        N = b'n' => "Ypos match",
        O = b'o' => "Zpos match",
    }

    /// All states in Table 5 order.
    const ALL;
    /// Byte on the wire: the ASCII letter.
    pub const fn to_wire(self) -> u8;
    /// State from its wire byte.
    pub const fn from_wire(b: u8) -> Option<Self>;
    /// Table 5 descriptive name.
    pub const fn name(self) -> &'static str;
    /// Index 0..15 in Table 5 order.
    pub const fn index(self) -> usize;
    impl Display("{} ({})", letter, name);
}

impl State {
    /// The six matched (final) states.
    pub const MATCHED: [State; 6] = [State::A, State::B, State::C, State::M, State::N, State::O];

    /// State at Table 5 index `i`.
    pub const fn from_index(i: usize) -> Option<State> {
        match slice::get(&Self::ALL, i) {
            Some(s) => Some(*s),
            None => None,
        }
    }

    /// Table 5 letter.
    pub const fn letter(self) -> char {
        // Every u8 is a char (U+0000..=U+00FF): the fallback never applies.
        match char::from_u32(to_u32(self.to_wire().to_le_bytes())) {
            Some(c) => c,
            None => char::REPLACEMENT_CHARACTER,
        }
    }

    /// State with Table 5 letter `c` (lowercase).
    pub fn from_letter(c: char) -> Option<State> {
        u8::try_from(c).ok().and_then(State::from_wire)
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

/// A character that is not a Table 5 letter.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
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

    // req: T5/*, D:state-letters
    #[test]
    fn letters_wire_and_index_agree() {
        for (i, s) in State::ALL.iter().enumerate() {
            assert_eq!(s.index(), i);
            assert_eq!(State::from_letter(s.letter()), Some(*s));
            assert_eq!(State::from_wire(s.to_wire()), Some(*s));
            assert_eq!(s.to_wire(), s.letter() as u8);
        }
        // Table 5 letters in order: a..=o.
        assert!(State::ALL
            .iter()
            .zip('a'..='o')
            .all(|(s, c)| s.letter() == c));
        assert_eq!(State::from_wire(0), None);
        assert_eq!(State::from_wire(b'p'), None);
        assert_eq!(State::from_letter('p'), None);
    }

    // req: P6.3
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
