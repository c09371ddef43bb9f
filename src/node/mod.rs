//! The system's nodes as pure functions: board A, board B, the server board and the ground's
//! command uplink, plus the pieces they share (Sections 3 and 4, Figures 3–7, 10 and 11).
//!
//! Every node is a value stepped with the time and what arrived; it returns what to send and
//! what to drive. The shells (ESP32 firmware, the host simulator in `host/`) move bytes and
//! read sensors, nothing else. Commanding is exactly-once: the ground numbers its commands
//! ([`ground`]), board A runs each number once ([`exactly_once`]) and acknowledges it in every
//! heartbeat; spec/protocol/README.md has the design and what stateright checked.
//!
//! ```
//! use mmic::command::Command;
//! use mmic::mode::Mode;
//! use mmic::node::board_a::{self, BoardA};
//! use mmic::node::ground::{self, Outcome, Uplink};
//! use mmic::units::BoardNumber;
//! use mmic::wire::heartbeat::HeartbeatRepr;
//!
//! // The ground asks for Operational; the packet reaches board A, whose heartbeat comes back.
//! let mut up = Uplink::new(ground::Config::default(), BoardNumber::ONE);
//! let mut a = BoardA::new(board_a::Config::default());
//! up.submit(Command::Mode(Mode::Operational)).unwrap();
//! let packet = up.tick(0).send.unwrap().to_bytes();
//! let out = a.tick(5, &board_a::Inputs { command: Some(packet), ..board_a::Inputs::at_home() });
//! let hb = HeartbeatRepr::parse(&out.heartbeat.unwrap()).unwrap();
//! let done = up.heartbeat(40, &hb).done.unwrap();
//! assert_eq!(done.outcome, Outcome::Accepted);
//! assert_eq!(a.mode(), Mode::Operational);
//! ```

pub mod b_link;
pub mod board_a;
pub mod board_b;
pub mod exactly_once;
pub mod gateway;
pub mod ground;
pub mod ground_link;
#[cfg(any(
    target_has_atomic = "ptr",
    feature = "portable-atomic-critical-section",
    feature = "portable-atomic"
))]
pub mod handoff;
pub mod plan_runner;
pub mod pus_ground;
pub mod sensed;
pub mod server;
pub mod visit;
pub mod wifi_session;
