//! The ground: the [`link`] a command plan runs over (the paper's packets through the legacy
//! [`Uplink`](crate::node::exactly_once::uplink::Uplink), or PUS telecommands through
//! [`pus::TcLink`]), and the [`plan_runner`] that sends a plan's commands one at a time over
//! either and follows the robot's heartbeats (Section 3; the 1.2 s cadence and Figures 10 and
//! 11 are Section 8's).
// req: P3.1, D:ground-uplink

pub mod frames;
pub mod link;
pub mod plan_runner;
pub mod pus;
