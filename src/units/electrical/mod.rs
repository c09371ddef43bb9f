//! One side's voltages and currents, as its ADS7828 reads them.

#[cfg(feature = "serde")]
mod ser;

/// A voltage in millivolts (battery 10.0–12.6 V, regulator 7.4 V: both fit a u16).
pub type Millivolts = u16;
/// A current in milliamperes (unsigned: the sense resistors measure draw only).
pub type Milliamps = u16;

/// Voltage and current readings of one side's ADS7828 (Table 3 bytes 25–52, Table 4 bytes 12–25).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(from = "ser::Json"))]
pub struct Electrical {
    /// Battery voltage V_bat, mV.
    pub v_bat: Millivolts,
    /// Battery current I_bat, mA.
    pub i_bat: Milliamps,
    /// Locomotion (arm and hip) current I_loc, mA.
    pub i_loc: Milliamps,
    /// Gripper current I_grip, mA.
    pub i_grip: Milliamps,
    /// 3.3 V rail current I_3v3, mA.
    pub i_3v3: Milliamps,
    /// Regulated voltage V_reg, mV.
    pub v_reg: Millivolts,
    /// Bolter current I_bo, mA.
    pub i_bo: Milliamps,
}
