//! The 47-byte internal heartbeat of Table 4 (board B → board A, sent periodically).
//!
//! ```
//! use mmic::wire::internal_heartbeat::{InternalHeartbeatRepr, INTERNAL_HEARTBEAT_LEN};
//! let hb = InternalHeartbeatRepr { command_received: 42, ..Default::default() };
//! let bytes = hb.to_bytes();
//! assert_eq!(bytes.len(), INTERNAL_HEARTBEAT_LEN);
//! assert_eq!(bytes[35], 42); // Table 4 "command received": the echoed A→B sequence number
//! assert_eq!(InternalHeartbeatRepr::parse(&bytes), Ok(hb));
//! ```
// req: T4/*, P4.7

use super::layout::{fields, ElectricalLayout};
use super::{check, field_err, get_bool, optional, pulse, seal, Packet, PacketKind, WireError};
/// Bolter B's progress is the bolter's vocabulary; re-exported at its old path.
pub use crate::bolter::BolterAux;
use crate::bolter::{BolterDirection, BolterPair, BolterStep, MuxLines};
use crate::units::{Axis, Electrical, Gravity, PulseWidth, Sign};
use zerocopy::byteorder::little_endian::U16;
use zerocopy::{FromBytes, Immutable, IntoBytes, KnownLayout, Unaligned};

/// Length of the internal heartbeat.
pub const INTERNAL_HEARTBEAT_LEN: usize = 47;
const KIND: PacketKind = PacketKind::InternalHeartbeat;

/// Table 4, byte for byte. Bytes 26–34, "bolter B operation auxiliary variables" in the
/// paper, are laid out here as nine one-byte fields (see [`BolterAux`]).
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, FromBytes, IntoBytes, KnownLayout, Immutable, Unaligned,
)]
#[repr(C)]
#[expect(
    missing_docs,
    reason = "each field is described in FIELDS and spec/packets/internal-heartbeat.toml"
)]
pub struct InternalHeartbeatPacket {
    pub header: [u8; 4],
    pub arm_b_target: U16,
    pub arm_b_now: U16,
    pub gripper_b_target: U16,
    pub gripper_b_now: U16,
    pub electrical_b: ElectricalLayout,
    pub bolter_step: u8,
    pub bolter_seq: u8,
    pub bolter_pair: u8,
    pub bolter_direction: u8,
    pub bolter_threshold: u8,
    pub bolter_locked: u8,
    pub bolter_timed_out: u8,
    pub bolter_at_home: u8,
    pub bolter_mux: u8,
    pub command_received: u8,
    pub g_sign: u8,
    pub g_axis: u8,
    pub arm_over_idle: u8,
    pub gripper_over_idle: u8,
    pub bolter_over_idle: u8,
    pub arm_overcurrent: u8,
    pub gripper_overcurrent: u8,
    pub bolter_overcurrent: u8,
    pub arm_contracted: u8,
    pub checksum: U16,
}

impl Packet for InternalHeartbeatPacket {
    const KIND: PacketKind = KIND;
}

const _: () = assert!(core::mem::size_of::<InternalHeartbeatPacket>() == INTERNAL_HEARTBEAT_LEN);

macro_rules! at {
    ($f:ident) => {
        core::mem::offset_of!(InternalHeartbeatPacket, $f)
    };
}

const AUX: &str = "bolter B operation auxiliary variables";

// The fields, from the layout (spec/packets/internal-heartbeat.toml is checked against it).
fields! {
    InternalHeartbeatPacket;
    // CONST: (name, field, type, unit, the paper's label)
    HEADER: ("header", header, [u8; 4], Header, "header"),
    ARM_B_TARGET: ("arm_b_target", arm_b_target, U16, Micros, "arm B-target"),
    ARM_B_NOW: ("arm_b_now", arm_b_now, U16, Micros, "arm B-now"),
    GRIPPER_B_TARGET: ("gripper_b_target", gripper_b_target, U16, Micros, "gripper B-target"),
    GRIPPER_B_NOW: ("gripper_b_now", gripper_b_now, U16, Micros, "gripper B-now"),
    [
        ELECTRICAL_B_V_BAT, ELECTRICAL_B_I_BAT, ELECTRICAL_B_I_LOC, ELECTRICAL_B_I_GRIP,
        ELECTRICAL_B_I_3V3, ELECTRICAL_B_V_REG, ELECTRICAL_B_I_BO,
    ]:
        ..electrical(electrical_b, "B"),
    BOLTER_AUX_STEP: ("bolter_aux.step", bolter_step, u8, Enum, AUX),
    BOLTER_AUX_SEQ: ("bolter_aux.seq", bolter_seq, u8, Sequence, AUX),
    BOLTER_AUX_PAIR: ("bolter_aux.pair", bolter_pair, u8, Enum, AUX),
    BOLTER_AUX_DIRECTION: ("bolter_aux.direction", bolter_direction, u8, Enum, AUX),
    BOLTER_AUX_THRESHOLD_REACHED: ("bolter_aux.threshold_reached", bolter_threshold, u8, Bool, AUX),
    BOLTER_AUX_LOCKED: ("bolter_aux.locked", bolter_locked, u8, Bool, AUX),
    BOLTER_AUX_TIMED_OUT: ("bolter_aux.timed_out", bolter_timed_out, u8, Bool, AUX),
    BOLTER_AUX_AT_HOME: ("bolter_aux.at_home", bolter_at_home, u8, Bool, AUX),
    BOLTER_AUX_MUX: ("bolter_aux.mux", bolter_mux, u8, Bits, AUX),
    COMMAND_RECEIVED: ("command_received", command_received, u8, Sequence, "command received"),
    GRAVITY_SIGN: ("gravity.sign", g_sign, u8, Enum, "g direction sign"),
    GRAVITY_AXIS: ("gravity.axis", g_axis, u8, Enum, "g direction axis"),
    ARM_OVER_IDLE: ("arm_over_idle", arm_over_idle, u8, Bool, "arm B over-idle"),
    GRIPPER_OVER_IDLE: ("gripper_over_idle", gripper_over_idle, u8, Bool, "gripper B over-idle"),
    BOLTER_OVER_IDLE: ("bolter_over_idle", bolter_over_idle, u8, Bool, "bolter B over-idle"),
    ARM_OVERCURRENT: ("arm_overcurrent", arm_overcurrent, u8, Bool, "arm B overcurrent"),
    GRIPPER_OVERCURRENT:
        ("gripper_overcurrent", gripper_overcurrent, u8, Bool, "gripper B overcurrent"),
    BOLTER_OVERCURRENT:
        ("bolter_overcurrent", bolter_overcurrent, u8, Bool, "bolter B overcurrent"),
    ARM_CONTRACTED: ("arm_contracted", arm_contracted, u8, Bool, "arm B contracted"),
    CHECKSUM: ("checksum", checksum, U16, Crc16, "checksum"),
}

/// Board B's status, sent to A periodically.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct InternalHeartbeatRepr {
    /// Arm B target pulse.
    pub arm_b_target: PulseWidth,
    /// Arm B last interpolated pulse.
    pub arm_b_now: PulseWidth,
    /// Gripper B target pulse.
    pub gripper_b_target: PulseWidth,
    /// Gripper B last interpolated pulse.
    pub gripper_b_now: PulseWidth,
    /// Side B voltages and currents.
    pub electrical_b: Electrical,
    /// Bolter B progress.
    pub bolter_aux: BolterAux,
    #[cfg_attr(feature = "serde", serde(deserialize_with = "crate::units::de::seq8"))]
    /// Sequence number of the last A→B command received (the acknowledgement).
    pub command_received: u8,
    /// Gravity in B's IMU frame; none before the first IMU reading (both bytes 0).
    pub gravity: Option<Gravity>,
    /// Arm B current above its idle limit.
    pub arm_over_idle: bool,
    /// Gripper B current above its idle limit.
    pub gripper_over_idle: bool,
    /// Bolter B current above its idle limit.
    pub bolter_over_idle: bool,
    /// Arm B current above its absolute limit.
    pub arm_overcurrent: bool,
    /// Gripper B current above its absolute limit.
    pub gripper_overcurrent: bool,
    /// Bolter B current above its absolute limit.
    pub bolter_overcurrent: bool,
    /// Arm B's contraction switch is pressed.
    pub arm_contracted: bool,
}

impl Default for InternalHeartbeatRepr {
    /// Board B at startup: servos centred, nothing measured, nothing received.
    fn default() -> Self {
        InternalHeartbeatRepr {
            arm_b_target: PulseWidth::CENTER,
            arm_b_now: PulseWidth::CENTER,
            gripper_b_target: PulseWidth::CENTER,
            gripper_b_now: PulseWidth::CENTER,
            electrical_b: Electrical::default(),
            bolter_aux: BolterAux::default(),
            command_received: 0,
            gravity: None,
            arm_over_idle: false,
            gripper_over_idle: false,
            bolter_over_idle: false,
            arm_overcurrent: false,
            gripper_overcurrent: false,
            bolter_overcurrent: false,
            arm_contracted: false,
        }
    }
}

impl InternalHeartbeatRepr {
    /// Checks length, header, checksum and every field.
    pub fn parse(bytes: &[u8]) -> Result<InternalHeartbeatRepr, WireError> {
        let p: &InternalHeartbeatPacket = check(bytes)?;
        let b = |i: usize, name: &'static str, v: u8| get_bool(KIND, i, name, v);
        let bolter_aux = bolter_aux(p)?;
        let gravity = gravity(p)?;
        Ok(InternalHeartbeatRepr {
            arm_b_target: pulse(KIND, "arm_b_target", at!(arm_b_target), p.arm_b_target)?,
            arm_b_now: pulse(KIND, "arm_b_now", at!(arm_b_now), p.arm_b_now)?,
            gripper_b_target: pulse(
                KIND,
                "gripper_b_target",
                at!(gripper_b_target),
                p.gripper_b_target,
            )?,
            gripper_b_now: pulse(KIND, "gripper_b_now", at!(gripper_b_now), p.gripper_b_now)?,
            electrical_b: Electrical::from(&p.electrical_b),
            bolter_aux,
            command_received: p.command_received,
            gravity,
            arm_over_idle: b(at!(arm_over_idle), "arm_over_idle", p.arm_over_idle)?,
            gripper_over_idle: b(
                at!(gripper_over_idle),
                "gripper_over_idle",
                p.gripper_over_idle,
            )?,
            bolter_over_idle: b(
                at!(bolter_over_idle),
                "bolter_over_idle",
                p.bolter_over_idle,
            )?,
            arm_overcurrent: b(at!(arm_overcurrent), "arm_overcurrent", p.arm_overcurrent)?,
            gripper_overcurrent: b(
                at!(gripper_overcurrent),
                "gripper_overcurrent",
                p.gripper_overcurrent,
            )?,
            bolter_overcurrent: b(
                at!(bolter_overcurrent),
                "bolter_overcurrent",
                p.bolter_overcurrent,
            )?,
            arm_contracted: b(at!(arm_contracted), "arm_contracted", p.arm_contracted)?,
        })
    }

    /// Writes the packet, header and checksum included.
    pub fn emit(&self, out: &mut [u8; INTERNAL_HEARTBEAT_LEN]) {
        let pw = |v: PulseWidth| U16::new(v.micros());
        let a = &self.bolter_aux;
        let p = InternalHeartbeatPacket {
            header: KIND.header(),
            arm_b_target: pw(self.arm_b_target),
            arm_b_now: pw(self.arm_b_now),
            gripper_b_target: pw(self.gripper_b_target),
            gripper_b_now: pw(self.gripper_b_now),
            electrical_b: ElectricalLayout::from(&self.electrical_b),
            bolter_step: a.step.map_or(0, BolterStep::to_wire),
            bolter_seq: a.seq,
            bolter_pair: a.pair.map_or(0, BolterPair::number),
            bolter_direction: a.direction.map_or(0, BolterDirection::to_wire),
            bolter_threshold: u8::from(a.threshold_reached),
            bolter_locked: u8::from(a.locked),
            bolter_timed_out: u8::from(a.timed_out),
            bolter_at_home: u8::from(a.at_home),
            bolter_mux: a.mux.to_wire(),
            command_received: self.command_received,
            g_sign: self.gravity.map_or(0, |g| g.sign.to_wire()),
            g_axis: self.gravity.map_or(0, |g| g.axis.to_wire()),
            arm_over_idle: u8::from(self.arm_over_idle),
            gripper_over_idle: u8::from(self.gripper_over_idle),
            bolter_over_idle: u8::from(self.bolter_over_idle),
            arm_overcurrent: u8::from(self.arm_overcurrent),
            gripper_overcurrent: u8::from(self.gripper_overcurrent),
            bolter_overcurrent: u8::from(self.bolter_overcurrent),
            arm_contracted: u8::from(self.arm_contracted),
            checksum: U16::ZERO,
        };
        out.copy_from_slice(p.as_bytes());
        seal(KIND, out);
    }

    /// The packet as a new array.
    pub fn to_bytes(&self) -> [u8; INTERNAL_HEARTBEAT_LEN] {
        let mut out = [0u8; INTERNAL_HEARTBEAT_LEN];
        self.emit(&mut out);
        out
    }
}

/// Table 4 bytes 26–34: board B's bolter progress ("bolter B operation auxiliary variables").
fn bolter_aux(p: &InternalHeartbeatPacket) -> Result<BolterAux, WireError> {
    let b = |i: usize, name: &'static str, v: u8| get_bool(KIND, i, name, v);
    let step = optional(
        KIND,
        at!(bolter_step),
        "bolter_aux.step",
        "0 (idle) or 1..=8",
        p.bolter_step,
        BolterStep::from_wire,
    )?;
    let pair = optional(
        KIND,
        at!(bolter_pair),
        "bolter_aux.pair",
        "0..=4",
        p.bolter_pair,
        BolterPair::from_number,
    )?;
    let direction = optional(
        KIND,
        at!(bolter_direction),
        "bolter_aux.direction",
        "0, 1 (bolt) or 2 (unbolt)",
        p.bolter_direction,
        BolterDirection::from_wire,
    )?;
    let mux = MuxLines::from_wire(p.bolter_mux).ok_or_else(|| {
        field_err(
            KIND,
            at!(bolter_mux),
            "bolter_aux.mux",
            "bits 0 (A0) and 1 (A1) only",
            u32::from(p.bolter_mux),
        )
    })?;
    Ok(BolterAux {
        step,
        seq: p.bolter_seq,
        pair,
        direction,
        threshold_reached: b(
            at!(bolter_threshold),
            "bolter_aux.threshold_reached",
            p.bolter_threshold,
        )?,
        locked: b(at!(bolter_locked), "bolter_aux.locked", p.bolter_locked)?,
        timed_out: b(
            at!(bolter_timed_out),
            "bolter_aux.timed_out",
            p.bolter_timed_out,
        )?,
        at_home: b(at!(bolter_at_home), "bolter_aux.at_home", p.bolter_at_home)?,
        mux,
    })
}

/// Bytes 35–36: the gravity direction in B's IMU frame; none before the first reading.
fn gravity(p: &InternalHeartbeatPacket) -> Result<Option<Gravity>, WireError> {
    Ok(match (p.g_sign, p.g_axis) {
        (0, 0) => None,
        (s, a) => {
            let sign = Sign::from_wire(s).ok_or_else(|| {
                field_err(
                    KIND,
                    at!(g_sign),
                    "gravity.sign",
                    "'+' or '-' (or 0 with axis 0)",
                    u32::from(s),
                )
            })?;
            let axis = Axis::from_wire(a).ok_or_else(|| {
                field_err(
                    KIND,
                    at!(g_axis),
                    "gravity.axis",
                    "'X', 'Y' or 'Z' (or 0 with sign 0)",
                    u32::from(a),
                )
            })?;
            Some(Gravity { axis, sign })
        }
    })
}
