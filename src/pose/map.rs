//! The reconfiguration map of Figure 9, computed at compile time from the geometric model.
//!
//! ```
//! use mmic::pose::{map, Primitive, State};
//! assert_eq!(map::primitive(State::A, State::D), Some(Primitive::BackExtend));
//! assert_eq!(map::primitive(State::A, State::M), None); // needs two primitives
//! assert_eq!(map::moves().count(), 60);
//! // The model's 12 turns between two right-angle states need a joint the robot lacks.
//! assert_eq!(map::primitive(State::G, State::J), None);
//! // From a turn state one primitive may reach two states: a primitive command names its
//! // final state (spec/motion/ambiguous-primitives.txt).
//! assert!(map::targets(State::E, Primitive::BackTurnCw).eq([State::A, State::D]));
//! assert_eq!(map::ambiguous().count(), 12);
//! ```
// req: P6.9, P6.7, D:turn-to-turn-moves

use super::geometry::{robot_move, single_move};
use super::{Primitive, State};
use crate::units::slice;

const N: usize = 15;

/// The grid of [`robot_move`] (`robot`) or of the model's [`single_move`].
/// Runs at compile time only (for [`MAP`] and the model's grid); the loop counters stop at
/// `N`, far below saturation.
const fn build(robot: bool) -> [[Option<Primitive>; N]; N] {
    let mut m = [[None; N]; N];
    let mut i = 0;
    while let (Some(row), Some(from)) = (slice::get_mut(&mut m, i), State::from_index(i)) {
        let mut j = 0;
        while let (Some(cell), Some(to)) = (slice::get_mut(row, j), State::from_index(j)) {
            let mv = if robot {
                robot_move(from, to)
            } else {
                single_move(from, to)
            };
            if let Some((_, p)) = mv {
                *cell = Some(p);
            }
            j = j.saturating_add(1);
        }
        i = i.saturating_add(1);
    }
    m
}

/// The cell of `grid` in row `from`, column `to` (both always in range: a state's index is
/// below 15).
const fn cell(grid: &[[Option<Primitive>; N]; N], from: State, to: State) -> Option<Primitive> {
    match slice::get(grid, from.index()) {
        Some(row) => match slice::get(row, to.index()) {
            Some(p) => *p,
            None => None,
        },
        None => None,
    }
}

/// Figure 9: the primitive that takes row state to column state, if the robot can make the
/// move ([`robot_move`]: the model's 72 moves but the 12 turns without a hip rotation).
pub const MAP: [[Option<Primitive>; N]; N] = build(true);

/// The geometric model's moves ([`single_move`]: the map's 60 and the 12 turns without a hip
/// rotation), for [`reaches`].
const MODEL: [[Option<Primitive>; N]; N] = build(false);

/// The primitive for a single-primitive reconfiguration from `from` to `to`.
pub const fn primitive(from: State, to: State) -> Option<Primitive> {
    cell(&MAP, from, to)
}

/// Every single-primitive move, as (from, to, primitive), rows and columns in Table 5 order.
pub fn moves() -> impl Iterator<Item = (State, State, Primitive)> {
    State::ALL.into_iter().flat_map(|f| {
        State::ALL
            .into_iter()
            .filter_map(move |t| primitive(f, t).map(|p| (f, t, p)))
    })
}

/// The states primitive `p` takes `from` to, in Table 5 order: none, one, or two. Two happen
/// from the turn states, where the moving side can swing onto the face the other side grips
/// (a match) or onto the opposite face of that axis (a stretch), with the same rotation of
/// its arm; the primitive alone does not say which, so a primitive command carries its final
/// state.
pub fn targets(from: State, p: Primitive) -> impl Iterator<Item = State> {
    State::ALL
        .into_iter()
        .filter(move |&to| primitive(from, to) == Some(p))
}

/// Whether the model takes some state to `to` by `p` ([`single_move`], the 72 moves): whether
/// `to` can be the final state of a primitive command for `p` at all (a command naming another
/// is malformed, whatever state the robot is in). The model's moves, not the map's: a command
/// naming one of the 12 turns without a hip rotation is well formed, and board A refuses it by
/// that name when the robot is where the move starts (`Refusal::TurnWithoutHip`).
pub const fn reaches(p: Primitive, to: State) -> bool {
    match slice::get(&REACHED, p.index()) {
        Some(row) => matches!(slice::get(row, to.index()), Some(true)),
        None => false,
    }
}

/// For each primitive (Table 6 order), whether the model takes some state to each state
/// (Table 5 order) by it. Built at compile time from the model's grid, so that [`reaches`]
/// (run on every primitive command board A parses, and by the checks that enumerate commands)
/// is one lookup, not a walk down a column of the grid: the walk was 98 % of the time of the
/// harnesses that sample commands (issue 40).
const REACHED: [[bool; N]; 8] = reached();

/// Runs at compile time only (for [`REACHED`]): the counters stop at `N`, a state's index is
/// below 15 and a primitive's below 8.
const fn reached() -> [[bool; N]; 8] {
    let mut t = [[false; N]; 8];
    let mut i = 0;
    while let Some(from) = State::from_index(i) {
        let mut j = 0;
        while let Some(to) = State::from_index(j) {
            if let Some(p) = cell(&MODEL, from, to)
                && let Some(row) = slice::get_mut(&mut t, p.index())
                && let Some(reached) = slice::get_mut(row, to.index())
            {
                *reached = true;
            }
            j = j.saturating_add(1);
        }
        i = i.saturating_add(1);
    }
    t
}

/// The (state, primitive) pairs whose primitive reaches two states, as (from, primitive,
/// first target, second target) with the targets in Table 5 order; rows in Table 5, then
/// Table 6 order. There are 12, two from each turn state (spec/motion/ambiguous-primitives.txt).
pub fn ambiguous() -> impl Iterator<Item = (State, Primitive, State, State)> {
    State::ALL.into_iter().flat_map(|from| {
        Primitive::ALL.into_iter().filter_map(move |p| {
            let mut to = targets(from, p);
            match (to.next(), to.next()) {
                (Some(first), Some(second)) => Some((from, p, first, second)),
                _ => None,
            }
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The table `reaches` reads is the model's moves: run here at run time (the constant ran
    /// it at build time), against the geometry's definition of a move, pair by pair.
    // req: P6.9
    #[test]
    fn reached_is_every_final_state_of_the_models_moves() {
        let t = reached();
        assert_eq!(t, REACHED);
        let mut pairs = 0;
        for p in Primitive::ALL {
            for to in State::ALL {
                let by_model = State::ALL
                    .into_iter()
                    .any(|from| matches!(single_move(from, to), Some((_, q)) if q == p));
                assert_eq!(t[p.index()][to.index()], by_model, "{p} to {to}");
                assert_eq!(reaches(p, to), by_model, "{p} to {to}");
                pairs += usize::from(by_model);
            }
        }
        // The 72 moves name 60 (primitive, final state) pairs: 12 share one with another.
        assert_eq!(pairs, 60);
    }
}
