//! Figure 9 as the paper draws it: the reconfiguration map ([`map`](super::map)) with, for each
//! move, whether a chosen plan between two matched states uses it ([`route`](super::route));
//! the moves no such plan uses are the figure's asterisked cells. It reads both the map and the
//! plans, so that the map does not depend on the plans made from it.
//!
//! ```
//! use mmic::motion::{figure9, State};
//! // b → h starts the plan b-h-k-c between the matched states b and c.
//! assert!(figure9::used_between_matched(State::B, State::H));
//! let mut grid = String::new();
//! figure9::render(&mut grid).unwrap();
//! assert!(grid.starts_with("from\\to"));
//! ```
// req: P6.9, P6.10

use crate::pose::map::primitive;
use crate::pose::{Primitive, State};
use core::fmt::Write as _;

/// Whether the move `from → to` appears in a chosen plan between two matched states (the final
/// states of reconfiguration commands). Moves that do not are the paper's asterisked cells:
/// possible, but never used. Which moves these are depends on the plan tie-break
/// ([`route`](super::route)).
pub fn used_between_matched(from: State, to: State) -> bool {
    State::MATCHED.into_iter().any(|f| {
        State::MATCHED.into_iter().any(|t| {
            let p = super::route::lookup(f, t);
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
/// move; `--` marks the diagonal, `x` the model's turns without a hip rotation (no move of the
/// robot) and `.` the other pairs with no single-primitive move ([`write_legend`] says so for
/// readers of the grid). Each column is five characters wide, the cell text
/// right-aligned under its state letter and the `*` after it; lines carry no trailing blanks.
pub fn render(out: &mut impl core::fmt::Write) -> core::fmt::Result {
    let mut line: heapless::String<128> = heapless::String::new();
    let flush = |line: &mut heapless::String<128>, out: &mut dyn core::fmt::Write| {
        let r = out
            .write_str(line.trim_end())
            .and_then(|_| out.write_char('\n'));
        line.clear();
        r
    };
    write!(line, "from\\to")?;
    for t in State::ALL {
        write!(line, " {:>3} ", t.letter())?;
    }
    flush(&mut line, out)?;
    for f in State::ALL {
        write!(line, "{:>7}", f.letter())?;
        for t in State::ALL {
            if f == t {
                write!(line, " {:>3} ", "--")?;
                continue;
            }
            match primitive(f, t) {
                None if crate::pose::geometry::turns_without_hip(f, t) => {
                    write!(line, " {:>3} ", "x")?
                }
                None => write!(line, " {:>3} ", ".")?,
                Some(p) => {
                    let kind = if t.is_matched() { 'F' } else { 'i' };
                    let star = if used_between_matched(f, t) { ' ' } else { '*' };
                    write!(line, "  {}{}{}", p.number(), kind, star)?
                }
            }
        }
        flush(&mut line, out)?;
    }
    Ok(())
}

/// What the codes of [`render`]'s grid mean, with the primitives' Table 6 names.
pub fn write_legend(out: &mut impl core::fmt::Write) -> core::fmt::Result {
    out.write_str(
        "rows: initial state, columns: target state (Table 5 letters)\n\
         4i   primitive 4 (Table 6) takes the row's state to the column's, an intermediate state\n\
         \x20    (i: green in Figure 9)\n\
         2F   primitive 2 takes it to a final (matched) state (F: blue in Figure 9)\n\
         *    possible, but no chosen plan between matched states uses the move (Figure 9's\n\
         \x20    asterisk)\n\
         x    a turn between two right-angle states: the geometric model has it, but the moving\n\
         \x20    arm would turn about the holding arm, which the hip cannot do: no move of the\n\
         \x20    robot (grey, as read here; spec/decisions.toml turn-to-turn-moves)\n\
         .    no single primitive does it (grey in Figure 9); a sequence may\n\
         --   the same state: not a reconfiguration (black in Figure 9)\n\
         primitives:",
    )?;
    for p in Primitive::ALL {
        write!(out, " {} {}", p.number(), p.name())?;
    }
    out.write_char('\n')
}
