//! The fault bit map carried in the heartbeat's first two fault bytes (Table 3 bytes 60–61).
//!
//! Byte 60 holds bits 0–7, byte 61 bits 8–15. One bit per Table 8 row; the overcurrent rows are
//! split into the idle check and the operational check because the paper describes two checks
//! with different thresholds and an operator needs to know which fired (bits 0–12). Bits 13
//! and 14 are the project's own causes, which no Table 8 row describes: the motion-step
//! timeout and the sensor loss. Bit 15 is spare and must be zero. Table 3's third fault byte
//! (62, "fault byte2") carries no fault bits but the outcome of the command the heartbeat
//! reports on, as a [`Refusal`](crate::refusal::Refusal) code: so the map has 16 bits, not
//! the 24 of Table 3's three fault bytes (spec/decisions.toml, `heartbeat-byte-62`).
//!
//! ```
//! use mmic::faults::{Fault, Faults};
//! let f = Faults::EMPTY.with(Fault::LowBattery).with(Fault::HipMismatch);
//! assert!(f.contains(Fault::LowBattery));
//! assert_eq!(Faults::from_wire(f.to_wire()), Ok(f));
//! assert_eq!(f.iter().count(), 2);
//! ```
// req: T8/*, P7.7, D:heartbeat-byte-62, D:faults-latched-outside-operational

#[cfg(feature = "serde")]
mod ser;

use crate::wire_enum::wire_enum;

wire_enum! {
    /// One autonomously detectable fault (Table 8), with its bit number in the fault bytes.
    #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
    #[cfg_attr(feature = "defmt", derive(defmt::Format))]
    #[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
    #[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
    pub enum Fault: u8 {
        /// Three consecutive failed (un)bolting attempts.
        BoltingFailure = 0 => "bolting_failure",
        /// Arm contraction not sensed by the switch.
        ArmNotContracted = 1 => "arm_not_contracted",
        /// Bolter current above its idle limit at the start or end of a reconfiguration.
        BolterOvercurrentIdle = 2 => "bolter_overcurrent_idle",
        /// Bolter current above its absolute limit.
        BolterOvercurrent = 3 => "bolter_overcurrent",
        /// Gripper current above its idle limit at the start or end of a reconfiguration.
        GripperOvercurrentIdle = 4 => "gripper_overcurrent_idle",
        /// Gripper current above its absolute limit.
        GripperOvercurrent = 5 => "gripper_overcurrent",
        /// Locomotion (arm and hip) current above its idle limit at the start or end of a reconfiguration.
        LocomotionOvercurrentIdle = 6 => "locomotion_overcurrent_idle",
        /// Locomotion current above its absolute limit.
        LocomotionOvercurrent = 7 => "locomotion_overcurrent",
        /// Hip angle far from its contracted-gripped value when entering Operational.
        HipMismatch = 8 => "hip_mismatch",
        /// Reconfiguration command's initial state differs from the detected state.
        InitialStateMismatch = 9 => "initial_state_mismatch",
        /// Board B heartbeat missing, or a command to B never acknowledged.
        InternalCommLoss = 10 => "internal_comm_loss",
        /// V_batA or V_batB below threshold for longer than the debounce time.
        LowBattery = 11 => "low_battery",
        /// Assembly system operation fault, injected by command.
        AssemblySystem = 12 => "assembly_system",
        /// Not a Table 8 row: a step of a primitive did not finish within its timeout and no
        /// Table 8 trigger describes why (a gripper or arm that did not reach its target, a
        /// hip turn that did not end, side B's servos not reporting done). The paper names no
        /// fault for it; the robot must not go on, so it is this project's own cause, reported
        /// in its own bit (spec/modes.toml gives its mode).
        MotionTimeout = 13 => "motion_timeout",
        /// Not a Table 8 row: a side's sensors stopped answering — the ADS7828 (every voltage
        /// and current of the side) or the hip encoder gave no reading for a whole averaging
        /// window in a row (`sensors::frontend::Config::loss_ticks`). The paper says nothing of a
        /// failed read; without currents the overcurrent checks are blind and without the hip
        /// angle the hip cannot be steered, so the robot must not go on (spec/decisions.toml,
        /// `sensor-loss`).
        SensorLoss = 14 => "sensor_loss",
    }

    /// Every fault, in bit order.
    const ALL;
    /// Bit number in the 16-bit fault map (heartbeat bytes 60–61).
    pub const fn bit(self) -> u8;
    /// Stable snake_case name (spec/ and JSON).
    pub const fn name(self) -> &'static str;
    impl Display("{}", name);
}

wire_enum! {
    /// One row of Table 8 as an operator names it: the fault bits split each overcurrent row
    /// into its idle and operational checks, and the table prints "Locomotion module
    /// overcurrent" twice, so the thirteen bits make ten rows. A report that says which of
    /// the paper's faults happened (and a simulator that injects them) speaks in rows.
    #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
    #[cfg_attr(feature = "defmt", derive(defmt::Format))]
    #[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
    #[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
    pub enum Table8 {
        /// "(Un)Bolting failure".
        BoltingFailure => "bolting_failure",
        /// "Arm not fully contracted".
        ArmNotContracted => "arm_not_contracted",
        /// "Bolter module overcurrent" (idle or operational check).
        BolterOvercurrent => "bolter_overcurrent",
        /// "Gripper module overcurrent" (idle or operational check).
        GripperOvercurrent => "gripper_overcurrent",
        /// "Locomotion module overcurrent" (idle or operational check; both printed rows).
        LocomotionOvercurrent => "locomotion_overcurrent",
        /// "Hip mismatch".
        HipMismatch => "hip_mismatch",
        /// "Initial state mismatch".
        InitialStateMismatch => "initial_state_mismatch",
        /// "Internal communication loss".
        InternalCommLoss => "internal_comm_loss",
        /// "Low battery".
        LowBattery => "low_battery",
        /// "Assembly system operation".
        AssemblySystem => "assembly_system",
    }

    /// Every row, in the table's order (the repeated row once).
    const ALL;
    /// snake_case name: the operational check's fault name for the overcurrent rows, the
    /// fault's own name for the others.
    pub const fn name(self) -> &'static str;
    impl Display("{}", name);
}

impl Table8 {
    /// The row's "Fault" cell as the paper prints it (spec/modes.toml `table8`).
    pub const fn title(self) -> &'static str {
        match self {
            Table8::BoltingFailure => "(Un)Bolting failure",
            Table8::ArmNotContracted => "Arm not fully contracted",
            Table8::BolterOvercurrent => "Bolter module overcurrent",
            Table8::GripperOvercurrent => "Gripper module overcurrent",
            Table8::LocomotionOvercurrent => "Locomotion module overcurrent",
            Table8::HipMismatch => "Hip mismatch",
            Table8::InitialStateMismatch => "Initial state mismatch",
            Table8::InternalCommLoss => "Internal communication loss",
            Table8::LowBattery => "Low battery",
            Table8::AssemblySystem => "Assembly system operation",
        }
    }
}

impl Fault {
    /// The Table 8 row this bit belongs to: both checks of a module's overcurrent are that
    /// module's row. The project's own [`Fault::MotionTimeout`] and [`Fault::SensorLoss`]
    /// belong to none.
    ///
    /// ```
    /// use mmic::faults::{Fault, Table8};
    /// assert_eq!(Fault::BolterOvercurrentIdle.table8(), Some(Table8::BolterOvercurrent));
    /// assert_eq!(Fault::BolterOvercurrent.table8(), Some(Table8::BolterOvercurrent));
    /// assert_eq!(Fault::LowBattery.table8().map(Table8::name), Some("low_battery"));
    /// assert_eq!(Fault::MotionTimeout.table8(), None);
    /// ```
    pub const fn table8(self) -> Option<Table8> {
        Some(match self {
            Fault::BoltingFailure => Table8::BoltingFailure,
            Fault::ArmNotContracted => Table8::ArmNotContracted,
            Fault::BolterOvercurrentIdle | Fault::BolterOvercurrent => Table8::BolterOvercurrent,
            Fault::GripperOvercurrentIdle | Fault::GripperOvercurrent => Table8::GripperOvercurrent,
            Fault::LocomotionOvercurrentIdle | Fault::LocomotionOvercurrent => {
                Table8::LocomotionOvercurrent
            }
            Fault::HipMismatch => Table8::HipMismatch,
            Fault::InitialStateMismatch => Table8::InitialStateMismatch,
            Fault::InternalCommLoss => Table8::InternalCommLoss,
            Fault::LowBattery => Table8::LowBattery,
            Fault::AssemblySystem => Table8::AssemblySystem,
            Fault::MotionTimeout | Fault::SensorLoss => return None,
        })
    }

    /// The name an operator reads for this bit: its Table 8 row's, or its own for the
    /// project's motion timeout and sensor loss (the idle and operational checks of a module share a name).
    pub const fn row_name(self) -> &'static str {
        match self.table8() {
            Some(r) => r.name(),
            None => self.name(),
        }
    }
}

/// A set of faults: the latched fault map, or the conditions holding now.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Faults(u32);

/// Bits set in the fault bytes that name no fault.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[error("fault bytes set reserved bits {reserved:#06x} (only bits 0..=14 name faults)")]
pub struct ReservedFaultBits {
    /// The reserved bits that were set.
    pub reserved: u32,
}

impl Faults {
    /// No fault.
    pub const EMPTY: Faults = Faults(0);
    /// Mask of the defined bits.
    pub const DEFINED: u32 = (1 << Fault::ALL.len()) - 1;

    /// This set plus `fault`.
    pub const fn with(self, fault: Fault) -> Faults {
        Faults(self.0 | 1 << fault.bit())
    }

    /// This set minus `fault`.
    pub const fn without(self, fault: Fault) -> Faults {
        Faults(self.0 & !(1 << fault.bit()))
    }

    /// Whether `fault` is in the set.
    pub const fn contains(self, fault: Fault) -> bool {
        self.0 & (1 << fault.bit()) != 0
    }

    /// Whether the set is empty.
    pub const fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// Whether every fault of `self` is in `other`.
    pub const fn is_subset_of(self, other: Faults) -> bool {
        self.0 & !other.0 == 0
    }

    /// Union.
    pub const fn union(self, other: Faults) -> Faults {
        Faults(self.0 | other.0)
    }

    /// The raw 16-bit map.
    pub const fn bits(self) -> u32 {
        self.0
    }

    /// The two fault bytes, heartbeat byte 60 first.
    pub const fn to_wire(self) -> [u8; 2] {
        let [lo, hi, _, _] = self.0.to_le_bytes();
        [lo, hi]
    }

    /// Fault set from the two fault bytes; reserved bits are refused.
    pub const fn from_wire(b: [u8; 2]) -> Result<Faults, ReservedFaultBits> {
        let raw = u32::from_le_bytes([b[0], b[1], 0, 0]);
        let reserved = raw & !Self::DEFINED;
        if reserved != 0 {
            Err(ReservedFaultBits { reserved })
        } else {
            Ok(Faults(raw))
        }
    }

    /// The faults in the set, in bit order.
    pub fn iter(self) -> impl Iterator<Item = Fault> {
        Fault::ALL.into_iter().filter(move |f| self.contains(*f))
    }
}

impl FromIterator<Fault> for Faults {
    fn from_iter<I: IntoIterator<Item = Fault>>(iter: I) -> Faults {
        iter.into_iter().fold(Faults::EMPTY, Faults::with)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `without` takes exactly its fault out and leaves the others (and an absent one) alone.
    #[test]
    fn without_removes_one_fault_only() {
        let all = Fault::ALL.into_iter().fold(Faults::EMPTY, Faults::with);
        for f in Fault::ALL {
            let rest = all.without(f);
            assert!(!rest.contains(f));
            assert!(Fault::ALL
                .into_iter()
                .filter(|&g| g != f)
                .all(|g| rest.contains(g)));
            assert_eq!(rest.without(f), rest);
            assert_eq!(rest.with(f), all);
        }
    }

    // req: T8/*
    #[test]
    fn every_subset_round_trips_and_reserved_bits_are_refused() {
        // Every subset of the 13 faults; under Miri (.ci/miri), whose interpretation is some
        // 100x slower, every 61st subset and the full set (136 of 8192, the empty set first).
        let step = if cfg!(miri) { 61 } else { 1 };
        for raw in (0..=Faults::DEFINED).step_by(step).chain([Faults::DEFINED]) {
            let b = [raw as u8, (raw >> 8) as u8];
            let f = Faults::from_wire(b);
            assert_eq!(f.map(Faults::to_wire), Ok(b));
            assert_eq!(f.map(|f| f.iter().collect::<Faults>()), f);
        }
        for bit in Fault::ALL.len()..16 {
            let raw = 1u32 << bit;
            let b = [raw as u8, (raw >> 8) as u8];
            assert_eq!(
                Faults::from_wire(b),
                Err(ReservedFaultBits { reserved: raw })
            );
        }
    }

    /// A fault with a Table 8 row goes by the row's name; one without (the project's own)
    /// by its own.
    #[test]
    fn a_fault_without_a_table_8_row_goes_by_its_own_name() {
        for f in Fault::ALL {
            match f.table8() {
                Some(r) => assert_eq!(f.row_name(), r.name()),
                None => assert_eq!(f.row_name(), f.name()),
            }
        }
        assert_eq!(Fault::MotionTimeout.row_name(), Fault::MotionTimeout.name());
    }

    /// JSON that is not a list of names is refused, saying what was expected.
    #[cfg(feature = "serde")]
    #[test]
    fn a_faults_set_that_is_not_a_list_is_refused() {
        extern crate std;
        use std::string::ToString;
        let e = serde_json::from_str::<Faults>("3").unwrap_err();
        assert!(e.to_string().contains("a list of fault names"), "{e}");
    }
}
