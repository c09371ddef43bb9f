//! Model checks (stateright) of exactly-once commanding (also across restarts of every node), of
//! the paper's scheme, of COP-1 and of SDLS's counters across restarts.
//!
//! One test binary per area, each file a module: fewer binaries to link than one per file.

mod cop1;
mod protocol_exactly_once;
mod protocol_paper;
mod protocol_pus;
mod restarts;
mod sdls;

use mmic::node::robot::board_a::{self, BoardA, Event};

/// Threads for a model check that may run on several: libtest's own budget when it is given as
/// `RUST_TEST_THREADS` (CI's instrumented run sets 1: its one-thread processes already run side
/// by side on every core, and two threads of one instrumented process contend for its counters,
/// see .ci/cov-runner), else two. The unique state counts are the same on any number.
fn model_threads() -> usize {
    std::env::var("RUST_TEST_THREADS")
        .ok()
        .and_then(|n| n.parse().ok())
        .map_or(2, |n: usize| n.clamp(1, 2))
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
