//! Model checks (stateright) of exactly-once commanding and of the paper's scheme.
//!
//! One test binary per area, each file a module: fewer binaries to link than one per file.

mod protocol_exactly_once;
mod protocol_paper;
mod protocol_pus;
