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
