//! Model checks (stateright) of exactly-once commanding (also across restarts of every node), of
//! the paper's scheme, of COP-1 and of SDLS's counters across restarts.
//!
//! One test binary per area, each file a module: fewer binaries to link than one per file.

mod cfdp;
mod cop1;
mod protocol_exactly_once;
mod protocol_paper;
mod protocol_pus;
mod restarts;
mod sdls;

use mmic::node::robot::board_a::{self, BoardA, Event};

/// Threads for one model check: one. libtest already runs two checks at once (one a core on
/// this 2-core machine), and two threads inside one checker fought over the allocator's locks
/// (perf, `exactly_once_commanding_and_safed_on_link_loss`: a quarter of its samples in the
/// kernel's futex wake and wait under glibc's malloc): with one thread each the binary took
/// 24.8 s instead of 27.8 (2026-11-29, issue 40). The unique state counts are the same on any
/// number of threads.
fn model_threads() -> usize {
    1
}

/// A node's state inside a model's state, shared until it changes and hashed once when it
/// does.
///
/// Stateright fingerprints every state it visits by hashing all of it, and clones a state for
/// each of its successors. In the exactly-once models most actions (time passing, a packet
/// dropped, duplicated or handed to the ground) leave board A and the gateway as they were,
/// yet hashing board A field by field (SipHash, a call a field) and copying it took a third of
/// the checker's time (perf, `exactly_once_commanding_and_safed_on_link_loss`). Here a clone
/// shares the node (`Arc`), a change copies it once (`Arc::make_mut`) and a state's hash takes
/// the node's 64-bit digest, made by `FxHasher` (a multiply a field, fixed seed: the same in
/// every run). Stateright's fingerprint is itself a 64-bit hash of the state, so a collision
/// was already possible; the state counts written to `spec/protocol/` are unchanged by this
/// digest. Equality still compares the nodes whole.
#[derive(Clone)]
pub(crate) struct Shared<T> {
    node: std::sync::Arc<T>,
    digest: u64,
}

impl<T: std::hash::Hash + Clone> Shared<T> {
    pub(crate) fn new(node: T) -> Self {
        let digest = Self::digest_of(&node);
        Self {
            node: std::sync::Arc::new(node),
            digest,
        }
    }

    fn digest_of(node: &T) -> u64 {
        use std::hash::Hasher;
        let mut h = rustc_hash::FxHasher::default();
        node.hash(&mut h);
        h.finish()
    }

    /// Changes the node (copied first if another state shares it) and hashes it again.
    pub(crate) fn update<R>(&mut self, f: impl FnOnce(&mut T) -> R) -> R {
        let r = f(std::sync::Arc::make_mut(&mut self.node));
        self.digest = Self::digest_of(&self.node);
        r
    }
}

impl<T> std::ops::Deref for Shared<T> {
    type Target = T;
    fn deref(&self) -> &T {
        &self.node
    }
}

impl<T> std::hash::Hash for Shared<T> {
    fn hash<H: std::hash::Hasher>(&self, state: &mut H) {
        state.write_u64(self.digest);
    }
}

impl<T: PartialEq> PartialEq for Shared<T> {
    fn eq(&self, other: &Self) -> bool {
        self.digest == other.digest && *self.node == *other.node
    }
}

impl<T: Eq> Eq for Shared<T> {}

impl<T: std::fmt::Debug> std::fmt::Debug for Shared<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.node.fmt(f)
    }
}

/// A link's packets in flight, kept sorted: a multiset, so that two states that differ only in
/// the order of their packets are one state (the network may deliver any of them first). At most
/// four in every model (each bounds its links to two or three); fixed capacity, so that a state's
/// clone allocates nothing (with `Vec`s the allocator took a fifth of the checker's time, theirs
/// and stateright's own).
pub(crate) type InFlight<P> = heapless::Vec<P, 4>;

/// Puts `p` on a link (sorted in). A model that lets a link take a fifth packet is wrong: panic.
pub(crate) fn put<P: Ord>(link: &mut InFlight<P>, p: P) {
    assert!(
        link.push(p).is_ok(),
        "a model bounds its links to four packets"
    );
    link.sort_unstable();
}

/// Each packet on a link once (the link is sorted: copies are neighbours).
pub(crate) fn distinct<P: Copy + PartialEq>(link: &InFlight<P>) -> impl Iterator<Item = P> + '_ {
    link.iter()
        .enumerate()
        .filter(|&(k, p)| k == 0 || link[k - 1] != *p)
        .map(|(_, p)| *p)
}

use mmic::wire::command::COMMAND_LEN;
use mmic::wire::heartbeat::HEARTBEAT_LEN;

/// Board A takes a command packet off the WiFi link, one 10 ms tick after its last, at home
/// with nothing else sensed (both models deliver it so): `executed` hears each sequence number
/// it runs; gives its heartbeat's bytes.
fn board_a_takes(
    a: &mut BoardA,
    a_now: &mut u32,
    bytes: [u8; COMMAND_LEN],
    mut executed: impl FnMut(u16),
) -> Option<[u8; HEARTBEAT_LEN]> {
    *a_now += 10;
    let out = a.tick(
        *a_now,
        &board_a::Inputs {
            command: Some(bytes),
            ..board_a::Inputs::at_home()
        },
    );
    for e in &out.events {
        if let Event::Executed { seq, .. } = e {
            executed(*seq);
        }
    }
    out.heartbeat
}
