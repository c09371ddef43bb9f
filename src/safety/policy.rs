//! Table 7 (operating modes) and Table 8 (fault → mode) as total functions over finite domains.
// req: T7/*, T8/*, P7.3, P7.4, P7.5, P7.8, P7.9, P7.14

use super::module_set::ModuleSet;
use crate::command::CommandKind;
use crate::faults::Fault;
use crate::mode::Mode;

/// Table 7, "Command availability": whether `mode` accepts commands of `kind`.
///
/// Standby: mode changes only; Safed: hip and arm actuator commands, Reset (to resume an arm or
/// hip motion a Stop interrupted) and mode changes;
/// Operational: everything. In every mode the supervisory commands are accepted as well:
/// heartbeat requests are answered and Stop is obeyed (Section 7 and the project's issue),
/// the assembly-system fault can be injected (it must reach a robot in any mode) and latched
/// faults can be cleared (otherwise a fault in Standby could never be cleared).
pub const fn accepts(mode: Mode, kind: CommandKind) -> bool {
    use CommandKind::*;
    match kind {
        Heartbeat | Stop | Mode | SystemFault | ClearFaults => true,
        // Reset resumes what a Stop interrupted, so it goes wherever something can move.
        Arm | Hip | Reset => !matches!(mode, self::Mode::Standby),
        Gripper | Bolter | Primitive | PowerControl | Reconfiguration => {
            matches!(mode, self::Mode::Operational)
        }
    }
}

/// Table 7, "Power availability to modules": what is powered in `mode`, given the modules the
/// operator has enabled with Power Control commands.
///
/// Standby: nothing (regulator off). Operational: the enabled modules. Safed: the enabled
/// modules among the hip and the arms. Because every mode's set is a subset of `enabled` and
/// Safed's is a subset of Operational's, no fault transition (Operational → Safed or
/// Standby) can ever raise power.
pub const fn powered(mode: Mode, enabled: ModuleSet) -> ModuleSet {
    match mode {
        Mode::Standby => ModuleSet::EMPTY,
        Mode::Operational => enabled,
        Mode::Safed => enabled.intersect(ModuleSet::HIP_AND_ARMS),
    }
}

/// Whether the 7.4 V regulator is on in `mode` (off in Standby: Section 7).
pub const fn regulator_on(mode: Mode) -> bool {
    !matches!(mode, Mode::Standby)
}

/// What a fault does when it is detected in Operational (Table 8).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct FaultAction {
    /// Mode the robot enters.
    pub mode: Mode,
    /// The mode change waits for the running motion to complete (Section 7: low battery and
    /// assembly system faults); otherwise it is immediate.
    pub deferred: bool,
}

/// Table 8's mode column, and Section 7's deferral rule.
///
/// Where the paper disagrees with itself (spec/modes.toml records it): bolting failure and
/// initial state mismatch go to Standby as Table 8 and the paragraph before it say (the robot
/// is fully gripped, so cutting power cannot drop it), not to Safed as the sentence "All the
/// other faults switch the mode to safed" would have it. Table 8's duplicated "Locomotion
/// module overcurrent" row is one fault, split here into its idle and operational checks.
pub const fn fault_action(f: Fault) -> FaultAction {
    use Fault::*;
    match f {
        BoltingFailure | InitialStateMismatch => FaultAction {
            mode: Mode::Standby,
            deferred: false,
        },
        LowBattery | AssemblySystem => FaultAction {
            mode: Mode::Standby,
            deferred: true,
        },
        ArmNotContracted
        | BolterOvercurrentIdle
        | BolterOvercurrent
        | GripperOvercurrentIdle
        | GripperOvercurrent
        | LocomotionOvercurrentIdle
        | LocomotionOvercurrent
        | HipMismatch
        | InternalCommLoss
        // Not Table 8's: a motion step stalled mid-primitive, so hold hip and arms as the
        // other mid-motion faults do.
        | MotionTimeout
        // Not Table 8's: a side's ADC or hip encoder silent for a window. Like losing board
        // B, the robot no longer knows its currents or its hip: hold everything.
        | SensorLoss => FaultAction {
            mode: Mode::Safed,
            deferred: false,
        },
    }
}

/// Conditions that hold over time (a level, not an event): Operational cannot be entered
/// while one holds. The others are events, raised at one instant: a failed bolting run, an
/// arm contraction not sensed, a refused reconfiguration, the hip check on entering
/// Operational, the idle overcurrent checks at the start and end of a reconfiguration, a
/// motion step that timed out, and the externally injected assembly-system fault.
pub const fn is_condition(f: Fault) -> bool {
    use Fault::*;
    matches!(
        f,
        BolterOvercurrent
            | GripperOvercurrent
            | LocomotionOvercurrent
            | InternalCommLoss
            | LowBattery
            | SensorLoss
    )
}
