//! What the RV32 runner measured of each call: its instructions per [`Phase`] (from
//! `minstret` under `qemu -icount shift=0`: exact and repeatable) and its stack depth (from a
//! painted stack). One fixed-size record per trace record, little-endian:
//!
//! ```text
//! cost  tag:u8 node:u8 t_ms:u32 glue:u32 front_end:u32 node:u32 record:u32 stack_node:u32 stack_all:u32
//! ```
//!
//! `stack_node` is the deepest the stack went before the call wrote its output record (the
//! node's own need), `stack_all` the deepest including that writing; both in bytes below the
//! caller's stack pointer.
//!
//! ```
//! use mmic_replay::cost::{Cost, COST_LEN};
//! let c = Cost { tag: 1, node: 0, t: 10, phases: [5, 6, 7, 8], stack_node: 96, stack_all: 128 };
//! let mut b = [0u8; COST_LEN];
//! c.emit(&mut b);
//! assert_eq!(Cost::parse(&b), Some(c));
//! assert_eq!(c.instructions(), 18); // the output record's 8 are not the node's
//! ```

use crate::Phase;

/// A cost record's length, bytes.
pub const COST_LEN: usize = 2 + 4 + 4 * Phase::ALL.len() + 4 + 4;

/// One call's cost.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Cost {
    /// The trace record's tag.
    pub tag: u8,
    /// Its node ([`crate::trace::Node`] as a number).
    pub node: u8,
    /// Its time, ms.
    pub t: u32,
    /// Instructions per phase, in [`Phase::ALL`]'s order.
    pub phases: [u32; 4],
    /// Stack depth before the output record, bytes.
    pub stack_node: u32,
    /// Stack depth including the output record, bytes.
    pub stack_all: u32,
}

impl Cost {
    /// The node's instructions: every phase but the output record's.
    pub const fn instructions(&self) -> u32 {
        self.phases[0]
            .saturating_add(self.phases[1])
            .saturating_add(self.phases[2])
    }

    /// Writes the record into `b` (at least [`COST_LEN`] bytes; a shorter one is left alone).
    pub fn emit(&self, b: &mut [u8]) {
        let Some(b) = b.get_mut(..COST_LEN) else {
            return;
        };
        b[0] = self.tag;
        b[1] = self.node;
        let words = [
            self.t,
            self.phases[0],
            self.phases[1],
            self.phases[2],
            self.phases[3],
            self.stack_node,
            self.stack_all,
        ];
        for (d, w) in b[2..].chunks_exact_mut(4).zip(words) {
            d.copy_from_slice(&w.to_le_bytes());
        }
    }

    /// Reads a record (none if `b` is shorter than [`COST_LEN`]).
    pub fn parse(b: &[u8]) -> Option<Cost> {
        let b = b.get(..COST_LEN)?;
        let mut w = [0u32; 7];
        for (v, c) in w.iter_mut().zip(b[2..].chunks_exact(4)) {
            *v = u32::from_le_bytes([c[0], c[1], c[2], c[3]]);
        }
        Some(Cost {
            tag: b[0],
            node: b[1],
            t: w[0],
            phases: [w[1], w[2], w[3], w[4]],
            stack_node: w[5],
            stack_all: w[6],
        })
    }
}
