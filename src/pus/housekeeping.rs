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
use crate::wire::heartbeat::{Boot, HeartbeatRepr};

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

/// One side's seven electrical readings, suffixed `_a` or `_b` (the order of
/// [`Electrical`]'s fields and of the heartbeat's blocks).
macro_rules! side_rows {
    ($x:literal, $side:literal) => {
        [
            f(
                concat!("v_bat_", $x),
                2,
                "mV",
                concat!("side ", $side, " battery voltage"),
            ),
            f(
                concat!("i_bat_", $x),
                2,
                "mA",
                concat!("side ", $side, " battery current"),
            ),
            f(
                concat!("i_loc_", $x),
                2,
                "mA",
                concat!("side ", $side, " locomotion (arm and hip) current"),
            ),
            f(
                concat!("i_grip_", $x),
                2,
                "mA",
                concat!("side ", $side, " gripper current"),
            ),
            f(
                concat!("i_3v3_", $x),
                2,
                "mA",
                concat!("side ", $side, " 3.3 V rail current"),
            ),
            f(
                concat!("v_reg_", $x),
                2,
                "mV",
                concat!("side ", $side, " 7.4 V regulator voltage"),
            ),
            f(
                concat!("i_bo_", $x),
                2,
                "mA",
                concat!("side ", $side, " bolter current"),
            ),
        ]
    };
}

/// `head`, then side A's readings, then side B's, then `tail`: the report's order (`N` is
/// their sum, checked where [`FIELDS`] is built). Slice patterns, not indices: a `const fn`
/// has no iterators.
const fn with_sides<const H: usize, const T: usize, const N: usize>(
    head: [Field; H],
    tail: [Field; T],
) -> [Field; N] {
    let (a, b): ([Field; 7], [Field; 7]) = (side_rows!("a", "A"), side_rows!("b", "B"));
    let mut out = [head[0]; N];
    let mut dst: &mut [Field] = &mut out;
    let parts: [&[Field]; 4] = [&head, &a, &b, &tail];
    let mut parts: &[&[Field]] = &parts;
    while let [part, more_parts @ ..] = parts {
        let mut src: &[Field] = part;
        while let [s, more @ ..] = src {
            // Moved out, so that its rest can take its place.
            let whole = dst;
            dst = match whole {
                [d, rest @ ..] => {
                    *d = *s;
                    rest
                }
                [] => &mut [],
            };
            src = more;
        }
        parts = more_parts;
    }
    out
}

/// The number of parameters.
pub const N_FIELDS: usize = 34;

/// The parameters after the structure ID, in order.
pub const FIELDS: [Field; N_FIELDS] = with_sides(HEAD, TAIL);
const _: () = assert!(N_FIELDS == HEAD.len() + 14 + TAIL.len());

/// The parameters after the two sides' readings: added after the first layout, at the end, so
/// that every earlier parameter keeps its offset.
const TAIL: [Field; 1] = [f(
    "boot",
    1,
    "number",
    "heartbeat byte 59: board A's last start, reset cause in bits 7..5 (spec/decisions.toml heartbeat-boot), boot count modulo 32 in bits 4..0; 0 = not reported",
)];

/// The parameters before the two sides' electrical readings.
const HEAD: [Field; 19] = [
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
];

/// Source data length of TM(3,25): structure ID and every parameter.
pub const REPORT_LEN: usize = {
    let mut n = 1;
    let mut rest: &[Field] = &FIELDS;
    while let [f, more @ ..] = rest {
        n += f.len;
        rest = more;
    }
    n
};

/// Why source data is no report of ours. Each names the check and the numbers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
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

fn electrical(e: &Electrical) -> [u32; 7] {
    [
        e.v_bat, e.i_bat, e.i_loc, e.i_grip, e.i_3v3, e.v_reg, e.i_bo,
    ]
    .map(u32::from)
}

/// The parameter values of a heartbeat, in [`FIELDS`] order.
pub fn values(hb: &HeartbeatRepr) -> [u32; N_FIELDS] {
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
    let tail = [u32::from(hb.boot.to_wire())];
    let mut out = [0u32; N_FIELDS];
    for (o, v) in out.iter_mut().zip(
        head.iter()
            .chain(&electrical(&hb.electrical_a))
            .chain(&electrical(&hb.electrical_b))
            .chain(&tail),
    ) {
        *o = *v;
    }
    out
}

/// Writes TM(3,25)'s source data for `hb`.
pub fn emit(hb: &HeartbeatRepr, out: &mut [u8; REPORT_LEN]) {
    let Some((sid, mut rest)) = out.split_first_mut() else {
        return; // never: the report is not empty
    };
    *sid = ROBOT_SID;
    for (field, v) in FIELDS.iter().zip(values(hb)) {
        let bytes = v.to_be_bytes();
        // A field's octets are the value's last `len` (1, 2 or 4).
        let src = bytes
            .len()
            .checked_sub(field.len)
            .and_then(|from| bytes.get(from..))
            .unwrap_or(&[]);
        let Some((dst, more)) = core::mem::take(&mut rest).split_at_mut_checked(field.len) else {
            return; // never: the fields fill the report
        };
        dst.copy_from_slice(src);
        rest = more;
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
    let v = Values::read(data);
    // The faults are checked first, as they always were: with several bad parameters, the
    // error names the same one.
    let faults = v.faults(2)?;
    Ok(HeartbeatRepr {
        board: BoardNumber::new(v.byte(0)?).map_err(|_| v.bad(0))?,
        mode: Mode::from_wire(v.byte(1)?).ok_or(v.bad(1))?,
        faults,
        refusal: v.opt(3, Refusal::from_wire)?,
        last_seq: v.word(4)?,
        target_state: v.opt(5, State::from_wire)?,
        command_complete: v.flag(6)?,
        active_bolter: v.opt(7, BolterPair::from_number)?,
        bolter_attempt: BolterAttempt::new(v.byte(8)?).map_err(|_| v.bad(8))?,
        hip_target: v.angle(9)?,
        hip_now: v.angle(10)?,
        arm_a_target: v.pulse(11)?,
        arm_a_now: v.pulse(12)?,
        arm_b_target: v.pulse(13)?,
        arm_b_now: v.pulse(14)?,
        gripper_a_target: v.pulse(15)?,
        gripper_a_now: v.pulse(16)?,
        gripper_b_target: v.pulse(17)?,
        gripper_b_now: v.pulse(18)?,
        electrical_a: v.electrical(19)?,
        electrical_b: v.electrical(26)?,
        boot: Boot::from_wire(v.byte(33)?),
    })
}

/// The report's parameter values, in [`FIELDS`] order, and the checked reading of each: a
/// value its type refuses is a [`HousekeepingError::Parameter`] naming the field.
struct Values([u32; N_FIELDS]);

impl Values {
    /// The values of `data`, whose length is checked.
    fn read(data: &[u8]) -> Values {
        let mut v = [0u32; N_FIELDS];
        let mut rest = data.get(1..).unwrap_or(&[]);
        for (field, slot) in FIELDS.iter().zip(v.iter_mut()) {
            // Short data (never: its length is checked) leaves the rest 0.
            let (octets, more) = rest.split_at_checked(field.len).unwrap_or((&[], &[]));
            for b in octets {
                *slot = *slot << 8 | u32::from(*b);
            }
            rest = more;
        }
        Values(v)
    }

    fn bad(&self, i: usize) -> HousekeepingError {
        HousekeepingError::Parameter {
            name: FIELDS.get(i).map_or("?", |f| f.name),
            value: self.raw(i),
        }
    }

    /// Value `i`; the callers' `i` are constants below [`N_FIELDS`], so the fallback (a
    /// value no field accepts) never shows.
    fn raw(&self, i: usize) -> u32 {
        self.0.get(i).copied().unwrap_or(u32::MAX)
    }

    fn byte(&self, i: usize) -> Result<u8, HousekeepingError> {
        u8::try_from(self.raw(i)).map_err(|_| self.bad(i))
    }

    fn word(&self, i: usize) -> Result<u16, HousekeepingError> {
        u16::try_from(self.raw(i)).map_err(|_| self.bad(i))
    }

    /// 0 for none, else what `from` makes of the byte (refused when it makes nothing).
    fn opt<T>(
        &self,
        i: usize,
        from: impl Fn(u8) -> Option<T>,
    ) -> Result<Option<T>, HousekeepingError> {
        match self.byte(i)? {
            0 => Ok(None),
            b => from(b).map(Some).ok_or(self.bad(i)),
        }
    }

    fn flag(&self, i: usize) -> Result<bool, HousekeepingError> {
        match self.byte(i)? {
            0 => Ok(false),
            1 => Ok(true),
            _ => Err(self.bad(i)),
        }
    }

    fn pulse(&self, i: usize) -> Result<PulseWidth, HousekeepingError> {
        PulseWidth::new(self.word(i)?).map_err(|_| self.bad(i))
    }

    fn angle(&self, i: usize) -> Result<HipAngle, HousekeepingError> {
        HipAngle::new(self.word(i)?).map_err(|_| self.bad(i))
    }

    fn faults(&self, i: usize) -> Result<Faults, HousekeepingError> {
        let [_, _, hi, lo] = self.raw(i).to_be_bytes();
        if self.raw(i) > 0xFFFF {
            return Err(self.bad(i));
        }
        Faults::from_wire([lo, hi]).map_err(|_| self.bad(i))
    }

    /// The seven readings from `k` on, in [`Electrical`]'s order.
    fn electrical(&self, k: usize) -> Result<Electrical, HousekeepingError> {
        // `k` is 19 or 26: never saturates.
        let w = |j: usize| self.word(k.saturating_add(j));
        Ok(Electrical {
            v_bat: w(0)?,
            i_bat: w(1)?,
            i_loc: w(2)?,
            i_grip: w(3)?,
            i_3v3: w(4)?,
            v_reg: w(5)?,
            i_bo: w(6)?,
        })
    }
}
