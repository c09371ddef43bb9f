//! The robot: board A (the primary board, WiFi task and control loop), board B (the
//! subordinate side, on A's serial line), the A→B command link between them, and the two-core
//! hand-off inside board A (Section 3, Figures 3–5).
// req: P2.11, P4.1

pub mod b_link;
pub mod board_a;
pub mod board_b;
#[cfg(any(
    target_has_atomic = "ptr",
    feature = "portable-atomic-critical-section",
    feature = "portable-atomic"
))]
pub mod handoff;
pub mod sensed;
pub mod wifi_session;
