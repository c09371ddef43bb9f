//! Routes: the shortest primitive sequences between states (what a reconfiguration runs): the paper's iterative search over the map, and
//! the same answers precomputed into a 450-byte table for O(1) lookup.
//!
//! **Tie-break.** Among the shortest plans, the one whose sequence of visited states is first in
//! Table 5 order (compared state by state). Iterative deepening that tries successors in Table 5
//! order finds exactly that plan, and the table is built by the same search.
//!
//! ```
//! use mmic::motion::{route, Primitive, State};
//! let p = route::lookup(State::A, State::M);
//! assert_eq!(p.primitives(), &[Primitive::BackExtend, Primitive::FwdContract]);
//! assert_eq!(route::search(State::A, State::M), p);
//! assert_eq!(route::lookup(State::A, State::B).len(), 3);
//! ```
// req: P6.11, P6.5

use crate::pose::map::primitive;
use crate::pose::{Primitive, State};
use crate::units::slice;
use crate::units::widen::{to_u16, to_usize};

/// Longest shortest plan between any two states.
pub const MAX_LEN: usize = 3;

/// A route: up to three primitives, and the states they pass through.
#[derive(Debug, Clone, Copy)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Route {
    len: u8,
    prims: [Primitive; MAX_LEN],
    states: [State; MAX_LEN],
}

impl Route {
    const EMPTY: Route = Route {
        len: 0,
        prims: [Primitive::FwdContract; MAX_LEN],
        states: [State::A; MAX_LEN],
    };

    /// The primitives in order.
    pub fn primitives(&self) -> &[Primitive] {
        // `len` never exceeds MAX_LEN; `get` keeps even a broken invariant from panicking.
        self.prims.get(..usize::from(self.len)).unwrap_or(&[])
    }

    /// The state after each primitive (the last one is the target).
    pub const fn states(&self) -> &[State] {
        // `len` never exceeds MAX_LEN; `split_at_checked` keeps even a broken invariant from
        // panicking (const, where `get` cannot be called).
        match self.states.split_at_checked(self.len()) {
            Some((used, _)) => used,
            None => &[],
        }
    }

    /// Number of primitives (0 when from = to).
    pub const fn len(&self) -> usize {
        to_usize(self.len.to_le_bytes())
    }

    /// True for the empty plan (from = to).
    pub const fn is_empty(&self) -> bool {
        self.len == 0
    }
}

impl PartialEq for Route {
    fn eq(&self, other: &Route) -> bool {
        self.primitives() == other.primitives() && self.states() == other.states()
    }
}

impl Eq for Route {}

impl core::hash::Hash for Route {
    // Consistent with `PartialEq`: only the used prefix counts.
    fn hash<H: core::hash::Hasher>(&self, h: &mut H) {
        self.primitives().hash(h);
        self.states().hash(h);
    }
}

/// Depth-limited search in Table 5 order: the first plan of exactly `depth` primitives. The
/// plan holds at most [`MAX_LEN`] primitives (a longer one is not tried: `get_mut` refuses the
/// slot), so its length never saturates.
const fn dfs(at: State, to: State, depth: usize, mut acc: Route) -> Option<Route> {
    let Some(deeper) = depth.checked_sub(1) else {
        return if at.index() == to.index() {
            Some(acc)
        } else {
            None
        };
    };
    let k = acc.len();
    let mut rest: &[State] = &State::ALL;
    while let [next, tail @ ..] = rest {
        if let Some(p) = primitive(at, *next)
            && let (Some(prim), Some(state)) = (
                slice::get_mut(&mut acc.prims, k),
                slice::get_mut(&mut acc.states, k),
            )
        {
            *prim = p;
            *state = *next;
            acc.len = acc.len.saturating_add(1);
            if let Some(found) = dfs(*next, to, deeper, acc) {
                return Some(found);
            }
            acc.len = acc.len.saturating_sub(1);
        }
        rest = tail;
    }
    None
}

/// The paper's iterative search: try plans of 0, 1, 2, 3 primitives. Every pair of states is
/// connected within three (checked exhaustively in the tests), so this always finds one.
pub const fn search(from: State, to: State) -> Route {
    let mut depth = 0;
    while depth <= MAX_LEN {
        if let Some(p) = dfs(from, to, depth, Route::EMPTY) {
            return p;
        }
        // Stops at MAX_LEN + 1: never saturates.
        depth = depth.saturating_add(1);
    }
    Route::EMPTY
}

/// Packed: bits 0–1 the length, then 4 bits per visited state's Table 5 index (a primitive
/// number alone would not do: from a two-face state the same primitive reaches two different
/// states). Three states end at bit 13: no shift loses a bit.
const fn pack(p: &Route) -> u16 {
    let mut v = to_u16(p.len.to_le_bytes());
    let mut shift: u32 = 2;
    let mut rest = p.states();
    while let [s, tail @ ..] = rest {
        // A Table 5 index is below 15: four bits.
        let index = to_u16(s.to_wire().saturating_sub(b'a').to_le_bytes());
        v |= index << shift;
        shift = shift.saturating_add(4);
        rest = tail;
    }
    v
}

/// Runs at compile time only (for [`TABLE`]).
const fn build() -> [[u16; 15]; 15] {
    let mut t = [[0u16; 15]; 15];
    let mut rows: &mut [[u16; 15]] = &mut t;
    let mut froms: &[State] = &State::ALL;
    while let ([row, rows_tail @ ..], [f, froms_tail @ ..]) = (rows, froms) {
        let mut cells: &mut [u16] = row;
        let mut tos: &[State] = &State::ALL;
        while let ([cell, cells_tail @ ..], [to, tos_tail @ ..]) = (cells, tos) {
            *cell = pack(&search(*f, *to));
            cells = cells_tail;
            tos = tos_tail;
        }
        rows = rows_tail;
        froms = froms_tail;
    }
    t
}

/// All 225 plans, packed two bytes each (450 bytes of flash), computed at compile time.
pub const TABLE: [[u16; 15]; 15] = build();

/// Flash size of [`TABLE`], bytes.
pub const TABLE_BYTES: usize = core::mem::size_of::<[[u16; 15]; 15]>();

/// The plan from `from` to `to`, from the precomputed table: O(1).
pub fn lookup(from: State, to: State) -> Route {
    // A state's index is below 15: the row and the cell are always there.
    let v = TABLE
        .get(from.index())
        .and_then(|row| row.get(to.index()))
        .copied()
        .unwrap_or(0);
    let mut plan = Route::EMPTY;
    let mut at = from;
    let mut bits = v >> 2;
    let slots = plan.prims.iter_mut().zip(plan.states.iter_mut());
    for (prim, state) in slots.take(usize::from(v & 0b11)) {
        let next = match State::from_index(usize::from(bits & 0xf)) {
            Some(s) => s,
            None => break,
        };
        bits >>= 4;
        let p = match primitive(at, next) {
            Some(p) => p,
            None => break,
        };
        *prim = p;
        *state = next;
        // At most MAX_LEN slots: never saturates.
        plan.len = plan.len.saturating_add(1);
        at = next;
    }
    plan
}
