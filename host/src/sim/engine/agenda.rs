//! The engine's agenda: what happens next in virtual time. Events at the same instant run in
//! the order they were scheduled (each takes the next sequence number when scheduled).
//!
//! The three periodic events (board A's tick, board B's tick, the ground's tick) are most of a
//! run's events and are always pending, one of each: they wait in slots of their own, not in
//! the heap, and are ordered against the heap's top by the same (time, sequence number) key, so
//! the order of the events is the one a single heap gives, at a fraction of its moves.

use crate::sim::inject::Node;
use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// The hops of one robot's links, each one direction of a link.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Hop {
    GroundToServer = 0,
    ServerToGround = 1,
    ServerToA = 2,
    AToServer = 3,
    AToB = 4,
    BToA = 5,
}

/// Something that happens at a virtual instant.
#[derive(Debug)]
pub(super) enum Ev {
    /// Every robot's board A control task ticks (in robot order; all boards A share a phase).
    TickA,
    /// Every robot's board B ticks (all boards B share their phase).
    TickB,
    /// Board A's WiFi task drains the heartbeat queue.
    Wifi(usize),
    /// Bytes arrive at the end of a hop (`conn`: the WiFi connection they were written to).
    Deliver {
        robot: usize,
        hop: Hop,
        conn: u64,
        bytes: Vec<u8>,
    },
    /// The server board's connection reaches board A's WiFi task.
    Open { robot: usize, conn: u64 },
    /// The server board's disconnection reaches board A's WiFi task.
    Close { robot: usize, conn: u64 },
    /// The server board stops waiting for the visit's heartbeat.
    VisitTimeout { robot: usize, conn: u64 },
    /// The server board's loop runs (the gateway's next deadline).
    Server { robot: usize, token: u64 },
    /// The ground's loop ticks every plan runner.
    GroundTick,
    /// A node of every robot restarts: it goes down now.
    Reboot(Node),
    /// Robot `i`'s node comes up again after its boot.
    Up { robot: usize, node: Node },
}

impl Ev {
    /// The periodic event's slot, if it is one.
    fn slot(&self) -> Option<usize> {
        match self {
            Ev::TickA => Some(0),
            Ev::TickB => Some(1),
            Ev::GroundTick => Some(2),
            _ => None,
        }
    }
}

/// An event's place in time: its instant (µs) in the high half, then its sequence number:
/// ordered as the pair (instant, sequence number) is, in one comparison.
type Key = u128;

/// The key of an event at `at` µs scheduled `seq`-th.
fn key(at: u64, seq: u64) -> Key {
    (u128::from(at) << 64) | u128::from(seq)
}

/// The instant of a key, µs.
fn instant(k: Key) -> u64 {
    (k >> 64) as u64
}

struct Queued {
    key: Key,
    ev: Ev,
}

impl PartialEq for Queued {
    fn eq(&self, o: &Self) -> bool {
        self.key == o.key
    }
}
impl Eq for Queued {}
impl PartialOrd for Queued {
    fn partial_cmp(&self, o: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Queued {
    fn cmp(&self, o: &Self) -> std::cmp::Ordering {
        self.key.cmp(&o.key)
    }
}

/// The pending events, earliest first.
pub(super) struct Agenda {
    seq: u64,
    heap: BinaryHeap<Reverse<Queued>>,
    /// The pending board A tick, board B tick and ground tick ([`NONE`] where none is).
    periodic: [Key; 3],
}

/// An empty periodic slot: after every key an event can have.
const NONE: Key = Key::MAX;

impl Default for Agenda {
    fn default() -> Agenda {
        Agenda {
            seq: 0,
            heap: BinaryHeap::new(),
            periodic: [NONE; 3],
        }
    }
}

impl Agenda {
    /// Schedules `ev` at `at` µs, after everything already scheduled for that instant. A
    /// periodic event replaces its pending one (each is scheduled again only once it ran).
    pub(super) fn at(&mut self, at: u64, ev: Ev) {
        self.seq += 1;
        let key = key(at, self.seq);
        match ev.slot() {
            Some(k) => self.periodic[k] = key,
            None => self.heap.push(Reverse(Queued { key, ev })),
        }
    }

    /// The next event and its instant, µs.
    pub(super) fn pop(&mut self) -> Option<(u64, Ev)> {
        let [a, b, g] = self.periodic;
        let (key, k) = if a < b { (a, 0) } else { (b, 1) };
        let (key, k) = if key < g { (key, k) } else { (g, 2) };
        if key != NONE && self.heap.peek().is_none_or(|Reverse(q)| key < q.key) {
            self.periodic[k] = NONE;
            let ev = match k {
                0 => Ev::TickA,
                1 => Ev::TickB,
                _ => Ev::GroundTick,
            };
            return Some((instant(key), ev));
        }
        self.heap.pop().map(|Reverse(q)| (instant(q.key), q.ev))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The agenda gives the events in the order one heap of (time, sequence) gives them.
    #[test]
    fn periodic_and_other_events_keep_the_order_of_one_heap() {
        let mut a = Agenda::default();
        a.at(10, Ev::TickA);
        a.at(5, Ev::Wifi(1));
        a.at(10, Ev::Wifi(2));
        a.at(3, Ev::TickB);
        a.at(10, Ev::GroundTick);
        let mut got = Vec::new();
        while let Some((t, ev)) = a.pop() {
            got.push(format!("{t}:{ev:?}"));
            if got.len() == 3 {
                a.at(10, Ev::TickB);
            }
        }
        assert_eq!(
            got,
            [
                "3:TickB",
                "5:Wifi(1)",
                "10:TickA",
                "10:Wifi(2)",
                "10:GroundTick",
                "10:TickB"
            ]
        );
    }
}
