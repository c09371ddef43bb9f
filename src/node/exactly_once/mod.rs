//! Exactly-once commanding, both sides. The send side is the [`uplink`]: it numbers each
//! command, resends it until a heartbeat answers that number, and reports the outcome; the
//! ground sends with it, and so does the server board's gateway. The receive side is board A's
//! command [`log`]: it runs each number once and answers every copy from its record.
//! spec/protocol/README.md has the design and what stateright checked.
// req: D:exactly-once-window, D:command-sequence-number

pub mod log;
pub mod uplink;

pub use log::{newer, Admission, CommandLog};
