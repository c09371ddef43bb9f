//! The 66-byte WiFi heartbeat of Table 3 (board A → server → opsUI).
//!
//! ```
//! use mmic::wire::heartbeat::{HeartbeatRepr, HEARTBEAT_LEN};
//! let hb = HeartbeatRepr::default();
//! let bytes = hb.to_bytes();
//! assert_eq!(bytes.len(), HEARTBEAT_LEN);
//! assert_eq!(&bytes[57..60], &[0, 0, 0]); // the paper's "empty" bytes: no sequenced command yet,
//!                                          // no start reported
//! let acked = HeartbeatRepr { last_seq: 0x0102, ..hb };
//! assert_eq!(&acked.to_bytes()[57..60], &[2, 1, 0]); // bytes 57–58 acknowledge command 0x0102
//! assert_eq!(HeartbeatRepr::parse(&bytes), Ok(hb));
//! ```
// req: T3/*, P3.16

use super::layout::{fields, ElectricalLayout};
use super::{check, field_err, get_bool, optional, pulse, seal, Packet, PacketKind, WireError};
use crate::command::BolterPair;
use crate::faults::Faults;
use crate::mode::Mode;
use crate::pose::State;
use crate::refusal::Refusal;
pub use crate::restart::{Boot, ResetCause};
use crate::units::{BoardNumber, Electrical, HipAngle, PulseWidth};
use zerocopy::byteorder::little_endian::U16;
use zerocopy::{FromBytes, Immutable, IntoBytes, KnownLayout, Unaligned};

/// Length of the WiFi heartbeat.
pub const HEARTBEAT_LEN: usize = 66;
const KIND: PacketKind = PacketKind::Heartbeat;

/// Table 3, byte for byte.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, FromBytes, IntoBytes, KnownLayout, Immutable, Unaligned,
)]
#[repr(C)]
#[expect(
    missing_docs,
    reason = "each field is described in FIELDS and spec/packets/heartbeat.toml"
)]
pub struct HeartbeatPacket {
    pub header: [u8; 4],
    pub board: u8,
    pub hip_target: U16,
    pub hip_now: U16,
    pub arm_a_target: U16,
    pub arm_a_now: U16,
    pub arm_b_target: U16,
    pub arm_b_now: U16,
    pub gripper_a_target: U16,
    pub gripper_a_now: U16,
    pub gripper_b_target: U16,
    pub gripper_b_now: U16,
    pub electrical_a: ElectricalLayout,
    pub electrical_b: ElectricalLayout,
    pub target_state: u8,
    pub command_complete: u8,
    pub active_bolter: u8,
    pub bolter_attempt: u8,
    pub last_seq: U16,
    pub boot: u8,
    pub faults: [u8; 2],
    pub refusal: u8,
    pub mode: u8,
    pub checksum: U16,
}

impl Packet for HeartbeatPacket {
    const KIND: PacketKind = KIND;
}

const _: () = assert!(core::mem::size_of::<HeartbeatPacket>() == HEARTBEAT_LEN);

// The fields, from the layout (spec/packets/heartbeat.toml is checked against it).
fields! {
    HeartbeatPacket;
    // CONST: (name, field, type, unit, the paper's label)
    HEADER: ("header", header, [u8; 4], Header, "header"),
    BOARD: ("board", board, u8, Board, "board number"),
    HIP_TARGET: ("hip_target", hip_target, U16, Centidegrees, "hip-target"),
    HIP_NOW: ("hip_now", hip_now, U16, Centidegrees, "hip-now"),
    ARM_A_TARGET: ("arm_a_target", arm_a_target, U16, Micros, "arm A-target"),
    ARM_A_NOW: ("arm_a_now", arm_a_now, U16, Micros, "arm A-now"),
    ARM_B_TARGET: ("arm_b_target", arm_b_target, U16, Micros, "arm B-target"),
    ARM_B_NOW: ("arm_b_now", arm_b_now, U16, Micros, "arm B-now"),
    GRIPPER_A_TARGET: ("gripper_a_target", gripper_a_target, U16, Micros, "gripper A-target"),
    GRIPPER_A_NOW: ("gripper_a_now", gripper_a_now, U16, Micros, "gripper A-now"),
    GRIPPER_B_TARGET: ("gripper_b_target", gripper_b_target, U16, Micros, "gripper B-target"),
    GRIPPER_B_NOW: ("gripper_b_now", gripper_b_now, U16, Micros, "gripper B-now"),
    [
        ELECTRICAL_A_V_BAT, ELECTRICAL_A_I_BAT, ELECTRICAL_A_I_LOC, ELECTRICAL_A_I_GRIP,
        ELECTRICAL_A_I_3V3, ELECTRICAL_A_V_REG, ELECTRICAL_A_I_BO,
    ]:
        ..electrical(electrical_a, "A"),
    [
        ELECTRICAL_B_V_BAT, ELECTRICAL_B_I_BAT, ELECTRICAL_B_I_LOC, ELECTRICAL_B_I_GRIP,
        ELECTRICAL_B_I_3V3, ELECTRICAL_B_V_REG, ELECTRICAL_B_I_BO,
    ]:
        ..electrical(electrical_b, "B"),
    TARGET_STATE: ("target_state", target_state, u8, StateLetter, "target state"),
    COMMAND_COMPLETE: ("command_complete", command_complete, u8, Bool, "command complete"),
    ACTIVE_BOLTER: ("active_bolter", active_bolter, u8, Enum, "active bolter"),
    BOLTER_ATTEMPT: ("bolter_attempt", bolter_attempt, u8, Enum, "bolter attempt"),
    LAST_SEQ: ("last_seq", last_seq, U16, Sequence16, "empty", cells &["empty", "empty"]),
    BOOT: ("boot", boot, u8, Bits, "empty"),
    FAULTS: (
        "faults", faults, [u8; 2], Bits, "fault byte0-1",
        cells &["fault byte0", "fault byte1"]
    ),
    REFUSAL: ("refusal", refusal, u8, Enum, "fault byte2"),
    MODE: ("mode", mode, u8, Enum, "operating mode"),
    CHECKSUM: ("checksum", checksum, U16, Crc16, "checksum"),
}

/// The attempt counter is the bolter's ([`crate::bolter`]); the heartbeat reports it.
pub use crate::bolter::BolterAttempt;

/// The WiFi heartbeat: the robot's whole status.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct HeartbeatRepr {
    /// Robot number.
    pub board: BoardNumber,
    /// Commanded hip angle.
    pub hip_target: HipAngle,
    /// Measured hip angle (encoder).
    pub hip_now: HipAngle,
    /// Arm A target pulse.
    pub arm_a_target: PulseWidth,
    /// Arm A last interpolated pulse.
    pub arm_a_now: PulseWidth,
    /// Arm B target pulse.
    pub arm_b_target: PulseWidth,
    /// Arm B last interpolated pulse.
    pub arm_b_now: PulseWidth,
    /// Gripper A target pulse.
    pub gripper_a_target: PulseWidth,
    /// Gripper A last interpolated pulse.
    pub gripper_a_now: PulseWidth,
    /// Gripper B target pulse.
    pub gripper_b_target: PulseWidth,
    /// Gripper B last interpolated pulse.
    pub gripper_b_now: PulseWidth,
    /// Side A voltages and currents.
    pub electrical_a: Electrical,
    /// Side B voltages and currents (relayed from B's internal heartbeat).
    pub electrical_b: Electrical,
    /// Last commanded target state; none before the first reconfiguration.
    pub target_state: Option<State>,
    /// The last command has completed.
    pub command_complete: bool,
    /// Bolter pair being operated, if any.
    pub active_bolter: Option<BolterPair>,
    /// Attempt of the bolter state machine on that pair.
    pub bolter_attempt: BolterAttempt,
    /// Latched faults.
    pub faults: Faults,
    /// Byte 62 (paper: "fault byte2"): the outcome of the command this heartbeat reports on —
    /// the packet it answers, or, for a copy of a sequenced command board A does not judge
    /// again (duplicate, stale), the command `last_seq` names; none = accepted, else why it
    /// was refused (spec/decisions.toml, `heartbeat-byte-62`).
    pub refusal: Option<Refusal>,
    /// Operating mode.
    pub mode: Mode,
    /// Bytes 57–58 (paper: "empty"): sequence number of the last sequenced command board A
    /// has taken (executed or refused), 0 before the first; when the answered packet is
    /// sequenced, `refusal` is this command's outcome.
    /// The ground's acknowledgement for exactly-once commanding (spec/protocol/README.md).
    #[cfg_attr(feature = "serde", serde(default))]
    #[cfg_attr(feature = "serde", serde(deserialize_with = "crate::units::de::seq16"))]
    pub last_seq: u16,
    /// Byte 59 (paper: "empty"): board A's last start, its reset cause and boot count modulo
    /// 32 ([`Boot`]); 0 = not reported (a paper-era robot). Every byte is valid. A change
    /// between two heartbeats means board A restarted (decision `heartbeat-boot`).
    #[cfg_attr(feature = "serde", serde(default))]
    pub boot: Boot,
}

impl Default for HeartbeatRepr {
    /// Robot 1 at startup: Standby, no fault, servos centred, hip at 180°.
    fn default() -> Self {
        let straight = HipAngle::STRAIGHT;
        HeartbeatRepr {
            board: BoardNumber::ONE,
            hip_target: straight,
            hip_now: straight,
            arm_a_target: PulseWidth::CENTER,
            arm_a_now: PulseWidth::CENTER,
            arm_b_target: PulseWidth::CENTER,
            arm_b_now: PulseWidth::CENTER,
            gripper_a_target: PulseWidth::CENTER,
            gripper_a_now: PulseWidth::CENTER,
            gripper_b_target: PulseWidth::CENTER,
            gripper_b_now: PulseWidth::CENTER,
            electrical_a: Electrical::default(),
            electrical_b: Electrical::default(),
            target_state: None,
            command_complete: false,
            active_bolter: None,
            bolter_attempt: BolterAttempt::NONE,
            faults: Faults::EMPTY,
            refusal: None,
            mode: Mode::Standby,
            last_seq: 0,
            boot: Boot::UNREPORTED,
        }
    }
}

fn angle(kind: PacketKind, name: &'static str, at: usize, v: U16) -> Result<HipAngle, WireError> {
    HipAngle::new(v.get())
        .map_err(|_| field_err(kind, at, name, "0..=35999 (0.01 deg)", u32::from(v.get())))
}

/// Index of the first byte of layout field `$f`.
macro_rules! at {
    ($f:ident) => {
        core::mem::offset_of!(HeartbeatPacket, $f)
    };
}

impl HeartbeatRepr {
    /// Checks length, header, checksum and every field.
    pub fn parse(bytes: &[u8]) -> Result<HeartbeatRepr, WireError> {
        let p: &HeartbeatPacket = check(bytes)?;
        // Every field's check at once, none reporting: the common case, a valid packet, takes
        // no branch per field (issue 25). Any failure goes to `fields`, which runs the same
        // checks one by one, in their order, for the first failure's error.
        let opt = |b: u8, ok: bool| b == 0 || ok;
        let pulse_ok = |v: U16| PulseWidth::new(v.get()).is_ok();
        let all = BoardNumber::new(p.board).is_ok()
            & opt(p.target_state, State::from_wire(p.target_state).is_some())
            & opt(
                p.active_bolter,
                BolterPair::from_number(p.active_bolter).is_some(),
            )
            & BolterAttempt::new(p.bolter_attempt).is_ok()
            & Faults::from_wire(p.faults).is_ok()
            & opt(p.refusal, Refusal::from_wire(p.refusal).is_some())
            & Mode::from_wire(p.mode).is_some()
            & HipAngle::new(p.hip_target.get()).is_ok()
            & HipAngle::new(p.hip_now.get()).is_ok()
            & pulse_ok(p.arm_a_target)
            & pulse_ok(p.arm_a_now)
            & pulse_ok(p.arm_b_target)
            & pulse_ok(p.arm_b_now)
            & pulse_ok(p.gripper_a_target)
            & pulse_ok(p.gripper_a_now)
            & pulse_ok(p.gripper_b_target)
            & pulse_ok(p.gripper_b_now)
            & (p.command_complete <= 1);
        if !all {
            return Self::fields(p);
        }
        let pulse = |v: U16| PulseWidth::saturating(v.get());
        let hip = |v: U16| HipAngle::new(v.get()).unwrap_or(HipAngle::ZERO);
        Ok(HeartbeatRepr {
            board: BoardNumber::new(p.board).unwrap_or(BoardNumber::ONE),
            hip_target: hip(p.hip_target),
            hip_now: hip(p.hip_now),
            arm_a_target: pulse(p.arm_a_target),
            arm_a_now: pulse(p.arm_a_now),
            arm_b_target: pulse(p.arm_b_target),
            arm_b_now: pulse(p.arm_b_now),
            gripper_a_target: pulse(p.gripper_a_target),
            gripper_a_now: pulse(p.gripper_a_now),
            gripper_b_target: pulse(p.gripper_b_target),
            gripper_b_now: pulse(p.gripper_b_now),
            electrical_a: Electrical::from(&p.electrical_a),
            electrical_b: Electrical::from(&p.electrical_b),
            target_state: State::from_wire(p.target_state),
            command_complete: p.command_complete != 0,
            active_bolter: BolterPair::from_number(p.active_bolter),
            bolter_attempt: BolterAttempt::new(p.bolter_attempt).unwrap_or(BolterAttempt::NONE),
            faults: Faults::from_wire(p.faults).unwrap_or(Faults::EMPTY),
            refusal: Refusal::from_wire(p.refusal),
            mode: Mode::from_wire(p.mode).unwrap_or(Mode::Standby),
            last_seq: p.last_seq.get(),
            boot: Boot::from_wire(p.boot),
        })
    }

    /// The field checks one by one, in order: the first failure's error (or the fields, if
    /// none fails).
    #[cold]
    #[inline(never)]
    fn fields(p: &HeartbeatPacket) -> Result<HeartbeatRepr, WireError> {
        let board =
            BoardNumber::new(p.board).map_err(|_| field_err(KIND, 4, "board", "1..=255", 0))?;
        // The error of a byte field whose JSON name is the layout field's name.
        macro_rules! refuse {
            ($f:ident, $expected:literal) => {
                field_err(KIND, at!($f), stringify!($f), $expected, p.$f as u32)
            };
        }
        // An optional byte field named so.
        macro_rules! opt {
            ($f:ident, $expected:literal, $from:path) => {
                optional(KIND, at!($f), stringify!($f), $expected, p.$f, $from)?
            };
        }
        let target_state = opt!(target_state, "0 or 'a'..='o'", State::from_wire);
        let active_bolter = opt!(active_bolter, "0..=4", BolterPair::from_number);
        let bolter_attempt =
            BolterAttempt::new(p.bolter_attempt).map_err(|_| refuse!(bolter_attempt, "0..=3"))?;
        let faults = Faults::from_wire(p.faults)
            .map_err(|e| field_err(KIND, at!(faults), "faults", "bits 0..=14 only", e.reserved))?;
        let refusal = opt!(refusal, "0 (accepted) or 1..=8", Refusal::from_wire);
        let mode = Mode::from_wire(p.mode)
            .ok_or_else(|| refuse!(mode, "1 (standby), 2 (operational) or 3 (safed)"))?;
        // A servo field whose JSON name is the layout field's name.
        macro_rules! servo {
            ($check:ident, $f:ident) => {
                $check(KIND, stringify!($f), at!($f), p.$f)?
            };
        }
        Ok(HeartbeatRepr {
            board,
            hip_target: servo!(angle, hip_target),
            hip_now: servo!(angle, hip_now),
            arm_a_target: servo!(pulse, arm_a_target),
            arm_a_now: servo!(pulse, arm_a_now),
            arm_b_target: servo!(pulse, arm_b_target),
            arm_b_now: servo!(pulse, arm_b_now),
            gripper_a_target: servo!(pulse, gripper_a_target),
            gripper_a_now: servo!(pulse, gripper_a_now),
            gripper_b_target: servo!(pulse, gripper_b_target),
            gripper_b_now: servo!(pulse, gripper_b_now),
            electrical_a: Electrical::from(&p.electrical_a),
            electrical_b: Electrical::from(&p.electrical_b),
            target_state,
            command_complete: get_bool(
                KIND,
                at!(command_complete),
                "command_complete",
                p.command_complete,
            )?,
            active_bolter,
            bolter_attempt,
            faults,
            refusal,
            mode,
            last_seq: p.last_seq.get(),
            boot: Boot::from_wire(p.boot),
        })
    }

    /// Writes the packet, header and checksum included.
    pub fn emit(&self, out: &mut [u8; HEARTBEAT_LEN]) {
        let u = |v: u16| U16::new(v);
        let pw = |v: PulseWidth| U16::new(v.micros());
        let p = HeartbeatPacket {
            header: KIND.header(),
            board: self.board.get(),
            hip_target: u(self.hip_target.centidegrees()),
            hip_now: u(self.hip_now.centidegrees()),
            arm_a_target: pw(self.arm_a_target),
            arm_a_now: pw(self.arm_a_now),
            arm_b_target: pw(self.arm_b_target),
            arm_b_now: pw(self.arm_b_now),
            gripper_a_target: pw(self.gripper_a_target),
            gripper_a_now: pw(self.gripper_a_now),
            gripper_b_target: pw(self.gripper_b_target),
            gripper_b_now: pw(self.gripper_b_now),
            electrical_a: ElectricalLayout::from(&self.electrical_a),
            electrical_b: ElectricalLayout::from(&self.electrical_b),
            target_state: self.target_state.map_or(0, State::to_wire),
            command_complete: u8::from(self.command_complete),
            active_bolter: self.active_bolter.map_or(0, BolterPair::number),
            bolter_attempt: self.bolter_attempt.get(),
            last_seq: U16::new(self.last_seq),
            boot: self.boot.to_wire(),
            faults: self.faults.to_wire(),
            refusal: self.refusal.map_or(0, Refusal::to_wire),
            mode: self.mode.to_wire(),
            checksum: U16::ZERO,
        };
        out.copy_from_slice(p.as_bytes());
        seal(KIND, out);
    }

    /// The packet as a new array.
    pub fn to_bytes(&self) -> [u8; HEARTBEAT_LEN] {
        let mut out = [0u8; HEARTBEAT_LEN];
        self.emit(&mut out);
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::wire::checksum::crc16;

    /// `parse` takes every field's check at once and leaves the order to `fields`: the two
    /// agree on every packet whose one octet (header and checksum aside) holds any value,
    /// from a sample of valid packets, the checksum made right each time.
    // req: T3/*
    #[test]
    fn the_fast_path_agrees_with_the_checks_in_order() {
        let samples = [
            HeartbeatRepr::default(),
            HeartbeatRepr {
                target_state: Some(State::M),
                active_bolter: BolterPair::from_number(4),
                bolter_attempt: BolterAttempt::new(3).unwrap_or(BolterAttempt::NONE),
                command_complete: true,
                refusal: Refusal::from_wire(8),
                mode: Mode::Safed,
                hip_target: HipAngle::new(35999).unwrap_or(HipAngle::ZERO),
                arm_a_target: PulseWidth::MIN,
                gripper_b_now: PulseWidth::MAX,
                last_seq: 0xffff,
                ..HeartbeatRepr::default()
            },
        ];
        // Under Miri (about 100x slower, .ci/miri) the first sample with every sixth octet at
        // 255 (10 packets; 60 took 18 s there): the view's code (zerocopy's cast, what Miri
        // checks) does not depend on the values, and the walk runs natively, all 256 values of
        // every octet of both samples.
        let (samples, values, every) = if cfg!(miri) {
            (&samples[..1], 255..=255u8, 6)
        } else {
            (&samples[..], 0..=255u8, 1)
        };
        let mut checked = 0u32;
        for repr in samples {
            let good = repr.to_bytes();
            assert_eq!(HeartbeatRepr::parse(&good), Ok(*repr));
            for at in (field::BOARD.start..field::CHECKSUM.start).step_by(every) {
                for v in values.clone() {
                    let mut b = good;
                    b[at] = v;
                    let crc = crc16(&b[..field::CHECKSUM.start]).to_le_bytes();
                    b[field::CHECKSUM].copy_from_slice(&crc);
                    let p = check::<HeartbeatPacket>(&b).expect("header and checksum are right");
                    assert_eq!(
                        HeartbeatRepr::parse(&b),
                        HeartbeatRepr::fields(p),
                        "byte {at} = {v:#04x}"
                    );
                    checked += 1;
                }
            }
        }
        let expected = if cfg!(miri) { 10 } else { 2 * 60 * 256 };
        assert_eq!(checked, expected);
    }
}
