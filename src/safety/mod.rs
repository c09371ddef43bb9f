//! Operating modes, power policy and autonomous fault detection (Section 7, Tables 7 and 8).
//!
//! - [`policy`]: Table 7 (what each mode powers and accepts) and Table 8 (which mode each fault
//!   leads to, and which faults wait for the running motion) as total functions.
//! - [`detect`]: the fault detectors, pure functions of filtered sensor values and time, with
//!   every threshold in one [`detect::Config`].
//! - [`supervisor`]: the mode state machine that latches faults and answers commands.
//!
//! ```
//! use mmic::command::CommandKind;
//! use mmic::mode::Mode;
//! use mmic::safety::{policy, ModuleSet};
//! assert!(!policy::accepts(Mode::Standby, CommandKind::Arm));
//! assert!(policy::accepts(Mode::Safed, CommandKind::Hip));
//! assert!(!policy::accepts(Mode::Safed, CommandKind::Gripper));
//! assert_eq!(policy::powered(Mode::Standby, ModuleSet::ALL), ModuleSet::EMPTY);
//! assert_eq!(policy::powered(Mode::Safed, ModuleSet::ALL), ModuleSet::HIP_AND_ARMS);
//! ```
// req: P7.7, P2.7

pub mod detect;
mod module_set;
pub mod policy;
pub mod supervisor;

pub use module_set::ModuleSet;
