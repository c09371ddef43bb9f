//! Sections 3 and 4: boards A and B as nodes, and the two-core hand-off.

mod board_a;
mod board_a_restart;
mod board_b;
mod node_boards;
mod node_fidelity;
mod node_handoff;
mod node_primitives;
