//! The reconfiguration map of Figure 9, computed at compile time from the geometric model.
//!
//! ```
//! use mmic::motion::{map, Primitive, State};
//! assert_eq!(map::primitive(State::A, State::D), Some(Primitive::BackExtend));
//! assert_eq!(map::primitive(State::A, State::M), None); // needs two primitives
//! assert_eq!(map::moves().count(), 72);
//! ```

use super::geometry::single_move;
use super::{Primitive, State};

const N: usize = 15;

const fn build() -> [[Option<Primitive>; N]; N] {
    let mut m = [[None; N]; N];
    let mut i = 0;
    while i < N {
        let mut j = 0;
        while j < N {
            if let (Some(from), Some(to)) = (State::from_index(i), State::from_index(j)) {
                if let Some((_, p)) = single_move(from, to) {
                    m[i][j] = Some(p);
                }
            }
            j += 1;
        }
        i += 1;
    }
    m
}

/// Figure 9: the primitive that takes row state to column state, if one does.
pub const MAP: [[Option<Primitive>; N]; N] = build();

/// The primitive for a single-primitive reconfiguration from `from` to `to`.
pub const fn primitive(from: State, to: State) -> Option<Primitive> {
    MAP[from.index()][to.index()]
}

/// Every single-primitive move, as (from, to, primitive), rows and columns in Table 5 order.
pub fn moves() -> impl Iterator<Item = (State, State, Primitive)> {
    State::ALL.into_iter().flat_map(|f| {
        State::ALL
            .into_iter()
            .filter_map(move |t| primitive(f, t).map(|p| (f, t, p)))
    })
}

/// Whether the move `from → to` appears in a chosen plan between two matched states (the final
/// states of reconfiguration commands). Moves that do not are the paper's asterisked cells:
/// possible, but never used. Which moves these are depends on the plan tie-break
/// ([`plan`](super::plan)).
pub fn used_between_matched(from: State, to: State) -> bool {
    State::MATCHED.into_iter().any(|f| {
        State::MATCHED.into_iter().any(|t| {
            let p = super::plan::lookup(f, t);
            let mut at = f;
            p.states().iter().any(|&next| {
                let hit = at == from && next == to;
                at = next;
                hit
            })
        })
    })
}

/// Renders the map as a text grid in the manner of Figure 9: rows are initial states, columns
/// target states; a cell holds the primitive number, `F` when the target is a final (matched)
/// state or `i` when intermediate, and `*` when no chosen plan between matched states uses the
/// move; `--` marks the diagonal and `.` pairs with no single-primitive move.
pub fn render(out: &mut impl core::fmt::Write) -> core::fmt::Result {
    out.write_str("from\\to")?;
    for t in State::ALL {
        write!(out, " {:>4}", t.letter())?;
    }
    out.write_char('\n')?;
    for f in State::ALL {
        write!(out, "{:>7}", f.letter())?;
        for t in State::ALL {
            if f == t {
                write!(out, " {:>4}", "--")?;
                continue;
            }
            match primitive(f, t) {
                None => write!(out, " {:>4}", ".")?,
                Some(p) => {
                    let kind = if t.is_matched() { 'F' } else { 'i' };
                    let star = if used_between_matched(f, t) { ' ' } else { '*' };
                    write!(out, "  {}{}{}", p.number(), kind, star)?
                }
            }
        }
        out.write_char('\n')?;
    }
    Ok(())
}
