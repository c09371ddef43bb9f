//! The boards' tick inputs from a side's sensor front end ([`Filtered`]) and its two switches:
//! the one mapping every shell (the firmware's control tasks, the simulator, the RV32 replay)
//! used to write out field by field.
//!
//! ```
//! use mmic::node::robot::board_a;
//! use mmic::sensors::frontend::{self, Frontend, Raw, WINDOW};
//!
//! let mut side: Frontend<WINDOW> = Frontend::new(frontend::Config::default());
//! let f = side.push(&Raw { adc: None, accel: None, encoder: None });
//! let inputs = board_a::Inputs::sensed(&f, true, true, None, None);
//! assert_eq!((inputs.hip, inputs.lost), (f.hip, f.lost));
//! ```
// req: P2.7

use super::{board_a, board_b};
use crate::sensors::frontend::Filtered;
use crate::wire::b_command::B_COMMAND_LEN;
use crate::wire::command::COMMAND_LEN;
use crate::wire::internal_heartbeat::INTERNAL_HEARTBEAT_LEN;

impl board_a::Inputs {
    /// Board A's inputs: side A's filtered readings `f`, its arm and bolter switches, and the
    /// packets the tick takes (a command from the WiFi task, a heartbeat from board B).
    pub const fn sensed(
        f: &Filtered,
        arm_contracted: bool,
        bolter_at_home: bool,
        command: Option<[u8; COMMAND_LEN]>,
        from_b: Option<[u8; INTERNAL_HEARTBEAT_LEN]>,
    ) -> Self {
        board_a::Inputs {
            command,
            from_b,
            electrical: f.electrical,
            hip: f.hip,
            gravity: f.gravity,
            arm_contracted,
            bolter_at_home,
            lost: f.lost,
        }
    }
}

impl board_b::Inputs {
    /// Board B's inputs: side B's filtered readings `f` (its hip encoder is board A's), its
    /// arm and bolter switches, and board A's command, if one came.
    pub const fn sensed(
        f: &Filtered,
        arm_contracted: bool,
        bolter_at_home: bool,
        command: Option<[u8; B_COMMAND_LEN]>,
    ) -> Self {
        board_b::Inputs {
            command,
            electrical: f.electrical,
            gravity: f.gravity,
            arm_contracted,
            bolter_at_home,
            lost: f.lost,
        }
    }
}
