//! The two-core hand-off of Section 3: board A's WiFi task (core 0) passes received command
//! packets to the control loop (core 1), and the control loop passes heartbeats back, through
//! lock-free single-producer single-consumer queues (`heapless::spsc`).
//!
//! ```
//! use mmic::node::robot::handoff::{Full, PacketQueue};
//! let mut q: PacketQueue<14, 4> = PacketQueue::new();
//! let (mut wifi, mut control) = q.split();
//! for i in 0..3u8 {
//!     wifi.push([i; 14]).unwrap();
//! }
//! assert_eq!(wifi.push([9; 14]), Err(Full([9; 14]))); // capacity N − 1 = 3: handed back
//! assert_eq!(control.pop(), Some([0; 14]));
//! assert_eq!(wifi.dropped(), 0); // the caller kept the refused packet; nothing was lost
//! ```
//!
//! Why it cannot lose, duplicate or tear a packet: a packet is an array moved into the slot
//! before the producer publishes the new tail (release) and moved out before the consumer
//! publishes the new head; each index has one writer. A full queue hands the packet back
//! ([`Full`]) instead of overwriting, and the producer counts any packet its caller gives up on
//! ([`Producer::give_up`]), so a loss is always visible. Checked in
//! tests/node/node_handoff.rs by two OS threads exchanging 2,000,000 numbered, checksummed packets
//! through an 8-slot queue (every packet arrives once, in order, intact) and by a bolero
//! harness against a `VecDeque` model (proofs/tests/harnesses/node.rs).
//!
//! Needs atomic loads and stores: available on targets with atomics (ESP32, ESP32-C6, hosts);
//! on the ESP32-C3 (RV32IMC) enable mmic's feature `portable-atomic-critical-section`, or
//! `portable-atomic` when another crate already selects portable-atomic's backend (esp-hal on
//! the C3 selects `unsafe-assume-single-core`, which `critical-section` may not join).
// req: P2.11, P3.17, P3.18

use heapless::spsc;

/// A packet the queue had no room for, handed back.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[error("hand-off queue full: packet handed back")]
pub struct Full<const L: usize>(pub [u8; L]);

/// A queue of `L`-byte packets with `N` slots (holds `N − 1`).
pub struct PacketQueue<const L: usize, const N: usize> {
    q: spsc::Queue<[u8; L], N>,
}

impl<const L: usize, const N: usize> Default for PacketQueue<L, N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const L: usize, const N: usize> PacketQueue<L, N> {
    /// Empty.
    pub const fn new() -> Self {
        PacketQueue {
            q: spsc::Queue::new(),
        }
    }

    /// The two ends, one per core.
    pub fn split(&mut self) -> (Producer<'_, L, N>, Consumer<'_, L, N>) {
        let (p, c) = self.q.split();
        (Producer { p, dropped: 0 }, Consumer { c })
    }
}

/// The sending end.
pub struct Producer<'a, const L: usize, const N: usize> {
    p: spsc::Producer<'a, [u8; L]>,
    dropped: u32,
}

impl<const L: usize, const N: usize> Producer<'_, L, N> {
    /// Enqueues a packet, or hands it back when the queue is full.
    pub fn push(&mut self, packet: [u8; L]) -> Result<(), Full<L>> {
        self.p.enqueue(packet).map_err(Full)
    }

    /// The caller gives up on a packet the queue refused: counted, never silent.
    pub fn give_up(&mut self, _packet: Full<L>) {
        self.dropped = self.dropped.saturating_add(1);
    }

    /// Packets given up so far.
    pub const fn dropped(&self) -> u32 {
        self.dropped
    }
}

/// The receiving end.
pub struct Consumer<'a, const L: usize, const N: usize> {
    c: spsc::Consumer<'a, [u8; L]>,
}

impl<const L: usize, const N: usize> Consumer<'_, L, N> {
    /// The oldest packet, if any.
    pub fn pop(&mut self) -> Option<[u8; L]> {
        self.c.dequeue()
    }

    /// Packets waiting.
    pub fn len(&self) -> usize {
        self.c.len()
    }

    /// Nothing waiting.
    pub fn is_empty(&self) -> bool {
        self.c.len() == 0
    }
}

#[cfg(test)]
mod tests {
    use super::{Full, PacketQueue};

    /// Packet `i`: its number and its complement, so a torn or stale slot shows.
    fn packet(i: u32) -> [u8; 14] {
        let mut p = [0u8; 14];
        p[..4].copy_from_slice(&i.to_le_bytes());
        p[4..8].copy_from_slice(&(!i).to_le_bytes());
        p[8..].copy_from_slice(&[i as u8; 6]);
        p
    }

    /// One core's view of many laps of the ring (every index wraps many times): each packet
    /// comes out once, in order, byte for byte; a full queue (N − 1 = 3) hands the packet back
    /// and keeps what it holds; a packet given up is counted. Under Miri (.ci/miri) this walks
    /// heapless's `unsafe` slot accesses at every position of the ring.
    // req: P3.18
    #[test]
    fn packets_come_out_in_order_over_many_laps_and_a_full_queue_hands_back() {
        let mut q: PacketQueue<14, 4> = PacketQueue::default();
        let (mut tx, mut rx) = q.split();
        assert!(rx.is_empty() && rx.pop().is_none());
        let (mut sent, mut received) = (0u32, 0u32);
        for round in 0..40u32 {
            while tx.push(packet(sent)).is_ok() {
                sent += 1;
            }
            assert_eq!(rx.len(), 3, "round {round}");
            assert_eq!(tx.push(packet(sent)), Err(Full(packet(sent))));
            // Take 1, 2 or 3 so that the next fill starts at another slot.
            for _ in 0..1 + round % 3 {
                assert_eq!(rx.pop(), Some(packet(received)));
                received += 1;
            }
        }
        while let Some(p) = rx.pop() {
            assert_eq!(p, packet(received));
            received += 1;
        }
        // 79 taken in the rounds (1 + round mod 3 each: 40 + 39), 2 left after the last.
        assert_eq!((sent, received), (81, 81));
        assert!(rx.is_empty());
        assert_eq!(tx.dropped(), 0);
        assert_eq!(
            tx.push(packet(sent)),
            Ok(()),
            "an empty queue takes the packet"
        );
        for i in 1..=3 {
            if let Err(back) = tx.push(packet(sent + i)) {
                tx.give_up(back);
            }
        }
        assert_eq!(
            (rx.len(), tx.dropped()),
            (3, 1),
            "the fourth packet was given up"
        );
    }
}
