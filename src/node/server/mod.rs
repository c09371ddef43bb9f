//! The server board: between the robots and the ground. As the paper's [`relay`] it forwards
//! the operator's command packets and the robots' heartbeats unchanged (Section 3, Figure 4);
//! as the CCSDS/PUS [`gateway`] it takes telecommands, sends each robot its commands
//! exactly-once ([`crate::node::exactly_once`]) and reports them in PUS telemetry.
// req: P3.5

pub mod frames;
pub mod gateway;
pub mod relay;
pub mod store;
pub mod visit;
