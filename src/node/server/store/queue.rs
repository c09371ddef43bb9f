//! The gateway's queued telecommands in the store (write-ahead, decision `restart-server`):
//! one entry per slot of a ring of [`QUEUE_SLOTS`], each a [`Job`] in 12 octets.
//!
//! | octets of the value | what |
//! |---|---|
//! | 0..2 | the packet sequence count (14 bits), big-endian |
//! | 2..4 | the source ID, big-endian |
//! | 4 | the acknowledgement flags (bits 0..3); bit 7: an are-you-alive |
//! | 5 | the command's opcode (`wire::opcode`) |
//! | 6..12 | its parameters |
//!
//! `aux` 1: a queued telecommand; 0: an empty slot. The APID is the robot's. The queue holds a
//! run of consecutive slots in the ring, oldest first; the slot before it is never queued
//! (there are more slots than a queue holds), which is where a restored queue starts.
//!
//! ```
//! use mmic::command::Command;
//! use mmic::node::server::gateway::Job;
//! use mmic::node::server::store::queue::{job_entry, queue_load};
//! use mmic::pus::verification::RequestId;
//! use mmic::units::BoardNumber;
//! use std::collections::BTreeMap;
//!
//! let one = BoardNumber::ONE;
//! let job = |seq| Job {
//!     request: RequestId { apid: 0x101, seq_count: seq },
//!     source_id: 9, ack: 0xF, command: Command::Stop, alive: false,
//! };
//! let mut f = BTreeMap::new();
//! for (slot, seq) in [(15u8, 7), (0, 8), (1, 9)] {
//!     let e = job_entry(one, slot, Some(&job(seq)));
//!     f.insert(e.key, (e.aux, e.value));
//! }
//! let q = queue_load(one, &|k| f.get(&k).copied());
//! assert_eq!(q.iter().map(|(_, j)| j.request.seq_count).collect::<Vec<_>>(), [7, 8, 9]);
//! ```

use super::Entry;
use crate::node::server::gateway::Job;
use crate::pus::robot_apid;
use crate::pus::verification::RequestId;
use crate::units::BoardNumber;
use crate::wire::opcode::{self, PARAM_LEN};
use heapless::Vec;

/// Slots of a robot's ring: more than a queue holds (the gateway's queue is at most 15).
pub const QUEUE_SLOTS: usize = 16;

/// [`QUEUE_SLOTS`] as a slot's number: its low octet, which is all of it (checked below).
pub const SLOTS: u8 = {
    let [.., low] = QUEUE_SLOTS.to_be_bytes();
    low
};
const _: () = assert!(QUEUE_SLOTS <= 0xFF);

/// The ring's slot after slot `s` (slots count modulo [`QUEUE_SLOTS`]).
pub const fn ring_after(s: u8) -> u8 {
    // s % SLOTS is below SLOTS: the sum cannot saturate.
    (s % SLOTS).saturating_add(1) % SLOTS
}

/// The key of robot `board`'s queue slot `slot`.
pub const fn queue_key(board: BoardNumber, slot: u8) -> u16 {
    // Widened through from_be_bytes (a const fn may not call From); the key is at most
    // 0x4000 + 16 × 255 + 15 = 0x4FFF: no step saturates.
    let slots = u16::from_be_bytes([0, SLOTS]);
    let board = u16::from_be_bytes([0, board.get()]);
    let slot = u16::from_be_bytes([0, slot % SLOTS]);
    0x4000u16
        .saturating_add(slots.saturating_mul(board))
        .saturating_add(slot)
}

/// Slot `slot` of robot `board`'s ring holding `job` (`None`: empty).
pub fn job_entry(board: BoardNumber, slot: u8, job: Option<&Job>) -> Entry {
    let key = queue_key(board, slot);
    let Some(j) = job else {
        return Entry {
            key,
            aux: 0,
            value: 0,
        };
    };
    let (op, params) = opcode::encode(&j.command);
    let mut v = [0u8; 16];
    v[4..6].copy_from_slice(&(j.request.seq_count & 0x3FFF).to_be_bytes());
    v[6..8].copy_from_slice(&j.source_id.to_be_bytes());
    v[8] = (j.ack & 0x0F) | if j.alive { 0x80 } else { 0 };
    v[9] = op;
    v[10..10 + PARAM_LEN].copy_from_slice(&params);
    Entry {
        key,
        aux: 1,
        value: u128::from_be_bytes(v),
    }
}

/// The job a slot's value holds for robot `board`; `None` when it does not decode.
pub fn job_of(board: BoardNumber, value: u128) -> Option<Job> {
    let v = value.to_be_bytes();
    if v[..4] != [0; 4] || v[8] & 0x70 != 0 || v[4] & 0xC0 != 0 {
        return None;
    }
    let mut params = [0u8; PARAM_LEN];
    params.copy_from_slice(&v[10..10 + PARAM_LEN]);
    let command = opcode::decode(v[9], params).ok()?;
    Some(Job {
        request: RequestId {
            apid: robot_apid(board),
            seq_count: u16::from_be_bytes([v[4], v[5]]),
        },
        source_id: u16::from_be_bytes([v[6], v[7]]),
        ack: v[8] & 0x0F,
        command,
        alive: v[8] & 0x80 != 0,
    })
}

/// Robot `board`'s queue as the store kept it: (slot, job), oldest first. The queued slots form
/// one run in the ring; it starts after a slot that is not queued. A slot that does not decode
/// ends the run (what follows it is not trusted to be in order).
pub fn queue_load(
    board: BoardNumber,
    lookup: &impl Fn(u16) -> Option<(u8, u128)>,
) -> Vec<(u8, Job), QUEUE_SLOTS> {
    let queued = |s: u8| lookup(queue_key(board, s)).filter(|(aux, _)| *aux == 1);
    // The slot before `s` in the ring.
    let before = |s: u8| s.checked_sub(1).unwrap_or(SLOTS - 1);
    let mut out = Vec::new();
    let Some(start) = (0..SLOTS).find(|&s| queued(s).is_some() && queued(before(s)).is_none())
    else {
        return out;
    };
    // The ring from `start` round: its two halves.
    for s in (start..SLOTS).chain(0..start) {
        let Some(job) = queued(s).and_then(|(_, v)| job_of(board, v)) else {
            break;
        };
        let _ = out.push((s, job));
    }
    out
}
