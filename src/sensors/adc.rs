//! The ADS7828's eight channels and their scaling to mV and mA (spec/control/adc.toml).
//!
//! The ADS7828 returns 12-bit codes (0..=4095) against its 2.5 V internal reference. Each
//! channel sees its quantity through a divider or a current-sense amplifier; its full-scale
//! value (the quantity at code 4095) is a configuration value with the defaults below.
//!
//! ```
//! use mmic::sensors::adc::{scale, Channel, Scaling};
//! let s = Scaling::default();
//! assert_eq!(scale(&s, Channel::VBat, 4095), 15_000); // full scale, mV
//! assert_eq!(scale(&s, Channel::VBat, 2730), 10_000); // 10.0 V, the low-battery threshold
//! ```
// req: P2.6

use crate::units::widen::to_u32;
use crate::units::Electrical;

/// ADS7828 input channels, in channel order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Channel {
    /// CH0: battery voltage V_bat (mV).
    VBat,
    /// CH1: battery current I_bat (mA).
    IBat,
    /// CH2: locomotion (arm and hip) current I_loc (mA).
    ILoc,
    /// CH3: gripper current I_grip (mA).
    IGrip,
    /// CH4: 3.3 V rail current I_3v3 (mA).
    I3v3,
    /// CH5: regulated voltage V_reg (mV).
    VReg,
    /// CH6: bolter current I_bo (mA).
    IBo,
    /// CH7: not connected.
    Spare,
}

impl Channel {
    /// All channels in ADS7828 order (CH0..CH7).
    pub const ALL: [Channel; 8] = [
        Channel::VBat,
        Channel::IBat,
        Channel::ILoc,
        Channel::IGrip,
        Channel::I3v3,
        Channel::VReg,
        Channel::IBo,
        Channel::Spare,
    ];
}

/// Full-scale value of each channel (the quantity at code 4095), in mV or mA.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Scaling {
    /// Per channel, CH0..CH7.
    pub full_scale: [u16; 8],
}

impl Default for Scaling {
    /// V_bat 15 V (divider 6:1 on 2.5 V), I_bat 10 A, I_loc 5 A, I_grip 3 A, I_3v3 1 A,
    /// V_reg 10 V (4:1), I_bo 5 A, spare 0.
    fn default() -> Self {
        Scaling {
            full_scale: [15_000, 10_000, 5_000, 3_000, 1_000, 10_000, 5_000, 0],
        }
    }
}

/// Largest 12-bit code.
pub const CODE_MAX: u16 = 4095;

/// [`CODE_MAX`] as the divisor of the scaling.
const CODE_MAX_U32: u32 = to_u32(CODE_MAX.to_le_bytes());

/// Scales a 12-bit code (codes above 4095 are clamped) to the channel's unit, rounding to
/// nearest.
pub fn scale(s: &Scaling, ch: Channel, code: u16) -> u16 {
    let c = u32::from(code.min(CODE_MAX));
    let fs = u32::from(s.of(ch));
    // Exact: at most 4095 × 65535 + 2047 < 2³²; the quotient is at most `fs`, a u16.
    let q = c.wrapping_mul(fs).wrapping_add(CODE_MAX_U32 / 2) / CODE_MAX_U32;
    u16::try_from(q).unwrap_or(u16::MAX)
}

impl Scaling {
    /// The full-scale value of channel `ch`.
    pub const fn of(&self, ch: Channel) -> u16 {
        let [v_bat, i_bat, i_loc, i_grip, i_3v3, v_reg, i_bo, spare] = self.full_scale;
        match ch {
            Channel::VBat => v_bat,
            Channel::IBat => i_bat,
            Channel::ILoc => i_loc,
            Channel::IGrip => i_grip,
            Channel::I3v3 => i_3v3,
            Channel::VReg => v_reg,
            Channel::IBo => i_bo,
            Channel::Spare => spare,
        }
    }
}

/// One side's readings from the eight (filtered) codes.
pub fn electrical(s: &Scaling, codes: [u16; 8]) -> Electrical {
    let [v_bat, i_bat, i_loc, i_grip, i_3v3, v_reg, i_bo, _spare] = codes;
    Electrical {
        v_bat: scale(s, Channel::VBat, v_bat),
        i_bat: scale(s, Channel::IBat, i_bat),
        i_loc: scale(s, Channel::ILoc, i_loc),
        i_grip: scale(s, Channel::IGrip, i_grip),
        i_3v3: scale(s, Channel::I3v3, i_3v3),
        v_reg: scale(s, Channel::VReg, v_reg),
        i_bo: scale(s, Channel::IBo, i_bo),
    }
}
