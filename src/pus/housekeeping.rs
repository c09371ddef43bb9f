//! ST\[3\] housekeeping: the heartbeat's content (Table 3) as the parameters of one
//! housekeeping report structure, TM(3,25), sent periodically without being asked.
//!
//! The paper's opsUI polled every 1.2 s for a heartbeat; here the gateway keeps the latest one
//! and reports it every collection interval (TC(3,5)/(3,6) switch it on and off, TC(3,31)
//! changes the interval). The report's source data is the structure ID and then every
//! parameter of [`FIELDS`], big-endian, in that order — the one place the layout is written;
//! spec/ccsds/housekeeping.toml, the XTCE and the ccsdspy definition are generated from it.
//!
//! ```
//! use mmic::pus::housekeeping::{self, REPORT_LEN};
//! use mmic::wire::heartbeat::HeartbeatRepr;
//! let hb = HeartbeatRepr { last_seq: 7, ..HeartbeatRepr::default() };
//! let mut buf = [0u8; REPORT_LEN];
//! housekeeping::emit(&hb, &mut buf);
//! assert_eq!(buf[0], housekeeping::ROBOT_SID);
//! assert_eq!(housekeeping::parse(&buf), Ok(hb));
//! assert!(housekeeping::parse(&buf[..10]).is_err());
//! ```

use crate::bolter::{BolterAttempt, BolterPair};
use crate::faults::Faults;
use crate::mode::Mode;
use crate::pose::State;
use crate::refusal::Refusal;
use crate::units::{BoardNumber, Electrical, HipAngle, PulseWidth};
use crate::wire::heartbeat::HeartbeatRepr;

/// The robot's one housekeeping report structure.
pub const ROBOT_SID: u8 = 1;
/// Default collection interval, ms.
pub const DEFAULT_INTERVAL_MS: u32 = 1000;
/// Shortest collection interval TC(3,31) accepts, ms (the gateway's poll period).
pub const MIN_INTERVAL_MS: u32 = 100;
/// Longest, ms.
pub const MAX_INTERVAL_MS: u32 = 3_600_000;

/// One parameter of the report.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Field {
    /// Name (the heartbeat's field name, spec/packets/heartbeat.toml; `_a`/`_b` for sides).
    pub name: &'static str,
    /// Size, bytes (1, 2 or 4), unsigned big-endian.
    pub len: usize,
    /// Unit or encoding.
    pub unit: &'static str,
    /// What it is.
    pub meaning: &'static str,
}

const fn f(name: &'static str, len: usize, unit: &'static str, meaning: &'static str) -> Field {
    Field {
        name,
        len,
        unit,
        meaning,
    }
}

/// The parameters after the structure ID, in order.
pub const FIELDS: [Field; 33] = [
    f("board", 1, "number", "robot number 1..=255"),
    f("mode", 1, "enum", "1 standby, 2 operational, 3 safed"),
    f(
        "faults",
        4,
        "bitmap",
        "latched faults, bit n = fault n of spec/faults.toml",
    ),
    f(
        "refusal",
        1,
        "enum",
        "heartbeat byte 62: the outcome of the command the heartbeat reports on, 0 = accepted, else its refusal code (spec/modes.toml; spec/decisions.toml heartbeat-byte-62)",
    ),
    f(
        "last_seq",
        2,
        "number",
        "legacy sequence number the heartbeat answered",
    ),
    f(
        "target_state",
        1,
        "state",
        "last commanded target state 'a'..='o' (ASCII), 0 = none",
    ),
    f("command_complete", 1, "bool", "last command complete"),
    f("active_bolter", 1, "enum", "bolter pair 1..=4, 0 = none"),
    f("bolter_attempt", 1, "number", "attempt 0..=3 on that pair"),
    f("hip_target", 2, "0.01 deg", "commanded hip angle"),
    f(
        "hip_now",
        2,
        "0.01 deg",
        "measured hip angle (the last one read)",
    ),
    f("arm_a_target", 2, "us", "arm A target pulse"),
    f("arm_a_now", 2, "us", "arm A last interpolated pulse"),
    f("arm_b_target", 2, "us", "arm B target pulse"),
    f("arm_b_now", 2, "us", "arm B last interpolated pulse"),
    f("gripper_a_target", 2, "us", "gripper A target pulse"),
    f(
        "gripper_a_now",
        2,
        "us",
        "gripper A last interpolated pulse",
    ),
    f("gripper_b_target", 2, "us", "gripper B target pulse"),
    f(
        "gripper_b_now",
        2,
        "us",
        "gripper B last interpolated pulse",
    ),
    f("v_bat_a", 2, "mV", "side A battery voltage"),
    f("i_bat_a", 2, "mA", "side A battery current"),
    f(
        "i_loc_a",
        2,
        "mA",
        "side A locomotion (arm and hip) current",
    ),
    f("i_grip_a", 2, "mA", "side A gripper current"),
    f("i_3v3_a", 2, "mA", "side A 3.3 V rail current"),
    f("v_reg_a", 2, "mV", "side A 7.4 V regulator voltage"),
    f("i_bo_a", 2, "mA", "side A bolter current"),
    f("v_bat_b", 2, "mV", "side B battery voltage"),
    f("i_bat_b", 2, "mA", "side B battery current"),
    f(
        "i_loc_b",
        2,
        "mA",
        "side B locomotion (arm and hip) current",
    ),
    f("i_grip_b", 2, "mA", "side B gripper current"),
    f("i_3v3_b", 2, "mA", "side B 3.3 V rail current"),
    f("v_reg_b", 2, "mV", "side B 7.4 V regulator voltage"),
    f("i_bo_b", 2, "mA", "side B bolter current"),
];

/// Source data length of TM(3,25): structure ID and every parameter.
pub const REPORT_LEN: usize = {
    let mut n = 1;
    let mut i = 0;
    while i < FIELDS.len() {
        n += FIELDS[i].len;
        i += 1;
    }
    n
};

/// Why source data is no report of ours. Each names the check and the numbers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum HousekeepingError {
    /// Not the report's length.
    #[error("housekeeping report of {found} bytes, expected {expected}")]
    Length {
        /// Bytes expected.
        expected: usize,
        /// Bytes found.
        found: usize,
    },
    /// Not the robot's structure ID.
    #[error("structure ID {found}, expected {expected}")]
    StructureId {
        /// The robot's.
        expected: u8,
        /// Found.
        found: u8,
    },
    /// A parameter outside its range.
    #[error("parameter {name} = {value} out of range")]
    Parameter {
        /// Its name in [`FIELDS`].
        name: &'static str,
        /// The value found.
        value: u32,
    },
}

const fn electrical(e: &Electrical) -> [u32; 7] {
    [
        e.v_bat as u32,
        e.i_bat as u32,
        e.i_loc as u32,
        e.i_grip as u32,
        e.i_3v3 as u32,
        e.v_reg as u32,
        e.i_bo as u32,
    ]
}

/// The parameter values of a heartbeat, in [`FIELDS`] order.
pub fn values(hb: &HeartbeatRepr) -> [u32; 33] {
    let pw = |p: PulseWidth| u32::from(p.micros());
    let head = [
        u32::from(hb.board.get()),
        u32::from(hb.mode.to_wire()),
        hb.faults.bits(),
        u32::from(hb.refusal.map_or(0, Refusal::to_wire)),
        u32::from(hb.last_seq),
        u32::from(hb.target_state.map_or(0, State::to_wire)),
        u32::from(hb.command_complete),
        u32::from(hb.active_bolter.map_or(0, BolterPair::number)),
        u32::from(hb.bolter_attempt.get()),
        u32::from(hb.hip_target.centidegrees()),
        u32::from(hb.hip_now.centidegrees()),
        pw(hb.arm_a_target),
        pw(hb.arm_a_now),
        pw(hb.arm_b_target),
        pw(hb.arm_b_now),
        pw(hb.gripper_a_target),
        pw(hb.gripper_a_now),
        pw(hb.gripper_b_target),
        pw(hb.gripper_b_now),
    ];
    let mut out = [0u32; 33];
    for (o, v) in out.iter_mut().zip(
        head.iter()
            .chain(&electrical(&hb.electrical_a))
            .chain(&electrical(&hb.electrical_b)),
    ) {
        *o = *v;
    }
    out
}

/// Writes TM(3,25)'s source data for `hb`.
pub fn emit(hb: &HeartbeatRepr, out: &mut [u8; REPORT_LEN]) {
    out[0] = ROBOT_SID;
    let mut at = 1;
    for (field, v) in FIELDS.iter().zip(values(hb)) {
        let bytes = v.to_be_bytes();
        let src = bytes.get(4 - field.len..).unwrap_or(&[]);
        if let Some(dst) = out.get_mut(at..at + field.len) {
            dst.copy_from_slice(src);
        }
        at += field.len;
    }
}

/// Reads TM(3,25)'s source data back into the heartbeat it reports, every parameter checked.
pub fn parse(data: &[u8]) -> Result<HeartbeatRepr, HousekeepingError> {
    if data.len() != REPORT_LEN {
        return Err(HousekeepingError::Length {
            expected: REPORT_LEN,
            found: data.len(),
        });
    }
    let sid = data.first().copied().unwrap_or(0);
    if sid != ROBOT_SID {
        return Err(HousekeepingError::StructureId {
            expected: ROBOT_SID,
            found: sid,
        });
    }
    let mut v = [0u32; 33];
    let mut at = 1;
    for (field, slot) in FIELDS.iter().zip(v.iter_mut()) {
        for b in data.get(at..at + field.len).unwrap_or(&[]) {
            *slot = *slot << 8 | u32::from(*b);
        }
        at += field.len;
    }
    let bad = |i: usize| HousekeepingError::Parameter {
        name: FIELDS[i % FIELDS.len()].name,
        value: v[i % v.len()],
    };
    let byte = |i: usize| u8::try_from(v[i]).map_err(|_| bad(i));
    let word = |i: usize| u16::try_from(v[i]).map_err(|_| bad(i));
    let opt = |i: usize| -> Result<Option<u8>, HousekeepingError> {
        byte(i).map(|b| if b == 0 { None } else { Some(b) })
    };
    let pulse = |i: usize| word(i).and_then(|w| PulseWidth::new(w).map_err(|_| bad(i)));
    let angle = |i: usize| word(i).and_then(|w| HipAngle::new(w).map_err(|_| bad(i)));
    let el = |k: usize| -> Result<Electrical, HousekeepingError> {
        Ok(Electrical {
            v_bat: word(k)?,
            i_bat: word(k + 1)?,
            i_loc: word(k + 2)?,
            i_grip: word(k + 3)?,
            i_3v3: word(k + 4)?,
            v_reg: word(k + 5)?,
            i_bo: word(k + 6)?,
        })
    };
    let faults = Faults::from_wire({
        let [_, _, hi, lo] = v[2].to_be_bytes();
        if v[2] > 0xFFFF {
            return Err(bad(2));
        }
        [lo, hi]
    })
    .map_err(|_| bad(2))?;
    Ok(HeartbeatRepr {
        board: BoardNumber::new(byte(0)?).map_err(|_| bad(0))?,
        mode: Mode::from_wire(byte(1)?).ok_or(bad(1))?,
        faults,
        refusal: match opt(3)? {
            None => None,
            Some(r) => Some(Refusal::from_wire(r).ok_or(bad(3))?),
        },
        last_seq: word(4)?,
        target_state: match opt(5)? {
            None => None,
            Some(s) => Some(State::from_wire(s).ok_or(bad(5))?),
        },
        command_complete: match byte(6)? {
            0 => false,
            1 => true,
            _ => return Err(bad(6)),
        },
        active_bolter: match opt(7)? {
            None => None,
            Some(p) => Some(BolterPair::from_number(p).ok_or(bad(7))?),
        },
        bolter_attempt: BolterAttempt::new(byte(8)?).map_err(|_| bad(8))?,
        hip_target: angle(9)?,
        hip_now: angle(10)?,
        arm_a_target: pulse(11)?,
        arm_a_now: pulse(12)?,
        arm_b_target: pulse(13)?,
        arm_b_now: pulse(14)?,
        gripper_a_target: pulse(15)?,
        gripper_a_now: pulse(16)?,
        gripper_b_target: pulse(17)?,
        gripper_b_now: pulse(18)?,
        electrical_a: el(19)?,
        electrical_b: el(26)?,
    })
}
