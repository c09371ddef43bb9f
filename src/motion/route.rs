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

use crate::pose::map::MAP;
use crate::pose::{Primitive, State};

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
        self.prims.get(..self.len as usize).unwrap_or(&[])
    }

    /// The state after each primitive (the last one is the target).
    pub fn states(&self) -> &[State] {
        self.states.get(..self.len as usize).unwrap_or(&[])
    }

    /// Number of primitives (0 when from = to).
    pub const fn len(&self) -> usize {
        self.len as usize
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

/// Depth-limited search in Table 5 order: the first plan of exactly `depth` primitives.
const fn dfs(at: State, to: State, depth: usize, mut acc: Route) -> Option<Route> {
    if depth == 0 {
        return if at.index() == to.index() {
            Some(acc)
        } else {
            None
        };
    }
    let mut j = 0;
    while j < 15 {
        if let (Some(p), Some(next)) = (MAP[at.index()][j], State::from_index(j)) {
            let k = acc.len as usize;
            if k < MAX_LEN {
                acc.prims[k] = p;
                acc.states[k] = next;
                acc.len += 1;
                if let Some(found) = dfs(next, to, depth - 1, acc) {
                    return Some(found);
                }
                acc.len -= 1;
            }
        }
        j += 1;
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
        depth += 1;
    }
    Route::EMPTY
}

const fn build() -> [[u16; 15]; 15] {
    let mut t = [[0u16; 15]; 15];
    let mut i = 0;
    while i < 15 {
        let mut j = 0;
        while j < 15 {
            if let (Some(f), Some(to)) = (State::from_index(i), State::from_index(j)) {
                let p = search(f, to);
                // Packed: bits 0–1 length, then 4 bits per visited state's Table 5 index (a
                // primitive number alone would not do: from a two-face state the same primitive
                // reaches two different states).
                let mut v = p.len as u16;
                let mut k = 0;
                while k < p.len as usize {
                    v |= (p.states[k].index() as u16) << (2 + 4 * k);
                    k += 1;
                }
                t[i][j] = v;
            }
            j += 1;
        }
        i += 1;
    }
    t
}

/// All 225 plans, packed two bytes each (450 bytes of flash), computed at compile time.
pub const TABLE: [[u16; 15]; 15] = build();

/// Flash size of [`TABLE`], bytes.
pub const TABLE_BYTES: usize = core::mem::size_of::<[[u16; 15]; 15]>();

/// The plan from `from` to `to`, from the precomputed table: O(1).
pub fn lookup(from: State, to: State) -> Route {
    let v = TABLE[from.index()][to.index()];
    let mut plan = Route::EMPTY;
    let mut at = from;
    for k in 0..(v & 0b11) as usize {
        let next = match State::from_index(((v >> (2 + 4 * k)) & 0xf) as usize) {
            Some(s) => s,
            None => break,
        };
        let p = match MAP[at.index()][next.index()] {
            Some(p) => p,
            None => break,
        };
        plan.prims[k] = p;
        plan.states[k] = next;
        plan.len += 1;
        at = next;
    }
    plan
}
