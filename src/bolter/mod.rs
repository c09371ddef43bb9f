//! The bolter state machine (Section 5, Figure 8) and its vocabulary.
//!
//! The same [`BolterSide`] executor runs each side's bolter on boards A and B; board A's
//! [`Coordinator`] orders both sides step by step (side B through the A→B command packet's
//! bolter bytes, side B answering in the internal heartbeat's auxiliary bytes) and advances only
//! when both sides report the same step, of the same order, complete. The handshake and its
//! exhaustive check are described in spec/control/bolter.md.
//!
//! ```
//! use mmic::bolter::{BolterStep, MuxLines};
//! use mmic::bolter::BolterPair;
//! assert_eq!(BolterStep::from_wire(BolterStep::Rotate.to_wire()), Some(BolterStep::Rotate));
//! assert_eq!(MuxLines::for_pair(BolterPair::P3), MuxLines { a0: true, a1: false });
//! ```
// req: P2.8, P5.9, P5.10, P5.11

use crate::units::ranged;
use crate::wire_enum::wire_enum;

mod coordinator;
mod order;
mod progress;
mod side;

pub use coordinator::{Config, Coordinator, Job, Output, Status};
pub use order::{BolterOrder, Fasteners};
pub use progress::BolterAux;
pub use side::{BolterSide, Drive, Sensed, SideConfig};

wire_enum! {
    /// One of the four bolter pairs of a face, selected through the ADG1604 multiplexer.
    #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
    #[cfg_attr(feature = "defmt", derive(defmt::Format))]
    #[cfg_attr(
        feature = "serde",
        derive(serde::Serialize, serde::Deserialize),
        serde(try_from = "crate::units::Number", into = "u8")
    )]
    pub enum BolterPair: u8 {
        /// Pair 1.
        P1 = 1,
        /// Pair 2.
        P2 = 2,
        /// Pair 3.
        P3 = 3,
        /// Pair 4.
        P4 = 4,
    }

    /// Pairs 1..=4 in the order "all four" runs them.
    const ALL;
    /// Pair number 1..=4.
    pub const fn number(self) -> u8;
    /// Pair with number `n`.
    pub const fn from_number(n: u8) -> Option<Self>;

    /// A pair number outside 1..=4.
    #[error("bolter pair must be 1..=4, found {0}")]
    pub struct BolterPairError(pub u8);
    impl TryFrom<Number>("bolter pair");
}

wire_enum! {
    /// Bolting or unbolting.
    #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
    #[cfg_attr(feature = "defmt", derive(defmt::Format))]
    #[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
    #[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
    pub enum BolterDirection {
        /// Engage and lock the fasteners (wire 1).
        Bolt = 1,
        /// Unlock and release them (wire 2).
        Unbolt = 2,
    }

    /// Wire value.
    pub const fn to_wire(self) -> u8;
    /// Direction from its wire value.
    pub const fn from_wire(b: u8) -> Option<Self>;
}

wire_enum! {
    /// A step of the bolter state machine (Figure 8) that a side is executing. Steps marked * end
    /// on a current threshold and have a timeout.
    #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
    #[cfg_attr(feature = "defmt", derive(defmt::Format))]
    #[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
    #[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
    pub enum BolterStep {
        /// 1*: translate towards the fastener and push until the current threshold.
        Descend = 1,
        /// 2: go back to the initial configuration.
        Retract = 2,
        /// 3*: descend again until the threshold, to engage.
        DescendEngage = 3,
        /// 4*: rotate the head until the current says locked (unlocked when unbolting).
        Rotate = 4,
        /// 5: counter-rotate to free the head and go back to the initial configuration; ends at home.
        CounterRotate = 5,
        /// 6: after a timed-out attempt, go back to the initial configuration; ends at home.
        ReturnHome = 6,
        /// 7: run finished, pair (un)bolted.
        Done = 7,
        /// 8: run failed (timeout).
        Failed = 8,
    }

    /// All steps in order.
    const ALL;
    /// Wire value 1..=8 (0 on the wire means idle).
    pub const fn to_wire(self) -> u8;
    /// Step from its wire value.
    pub const fn from_wire(b: u8) -> Option<Self>;
}

/// The ADG1604 select lines A0 and A1.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct MuxLines {
    /// Line A0 high.
    pub a0: bool,
    /// Line A1 high.
    pub a1: bool,
}

impl MuxLines {
    /// The paper lists the combinations of "A0-A1 (low-low, low-high, high-low, high-high)";
    /// pairs 1–4 take them in that order, so (A0, A1) is pair n − 1 in binary, A0 the high bit.
    pub const fn for_pair(p: BolterPair) -> MuxLines {
        let (a0, a1) = match p {
            BolterPair::P1 => (false, false),
            BolterPair::P2 => (false, true),
            BolterPair::P3 => (true, false),
            BolterPair::P4 => (true, true),
        };
        MuxLines { a0, a1 }
    }

    /// Wire byte: bit 0 = A0, bit 1 = A1.
    pub const fn to_wire(self) -> u8 {
        // `if`, not `u8::from(bool)`: that is not `const`.
        (if self.a0 { 0b01 } else { 0 }) | (if self.a1 { 0b10 } else { 0 })
    }

    /// Lines from the wire byte; other bits must be zero.
    pub const fn from_wire(b: u8) -> Option<MuxLines> {
        if b > 0b11 {
            None
        } else {
            Some(MuxLines {
                a0: b & 1 != 0,
                a1: b & 2 != 0,
            })
        }
    }
}
ranged! {
    /// Which attempt of the bolter state machine is running: 0 (none), 1, 2 or 3.
    #[derive(Default)]
    pub struct BolterAttempt(u8), min 0, max 3, "bolter attempt";
}

impl BolterAttempt {
    /// Three attempts at most (Table 8).
    pub const MAX: u8 = 3;
    /// No attempt running.
    pub const NONE: BolterAttempt = BolterAttempt(0);
}

#[cfg(test)]
mod tests {
    use super::{BolterAttempt, BolterPair, MuxLines};

    /// The paper's order of the select lines: pairs 1–4 take A0-A1 low-low, low-high,
    /// high-low, high-high; the wire byte has A0 in bit 0 and A1 in bit 1, and refuses others.
    // req: P2.8, P5.10
    #[test]
    fn mux_lines_per_pair_and_on_the_wire() {
        let want = [(false, false), (false, true), (true, false), (true, true)];
        for (n, (a0, a1)) in (1..=4u8).zip(want) {
            let p = BolterPair::from_number(n).unwrap();
            assert_eq!(MuxLines::for_pair(p), MuxLines { a0, a1 }, "pair {n}");
        }
        for b in 0..=u8::MAX {
            let got = MuxLines::from_wire(b);
            if b > 3 {
                assert_eq!(got, None, "{b:#x}");
            } else {
                let m = MuxLines {
                    a0: b & 1 == 1,
                    a1: b >> 1 == 1,
                };
                assert_eq!(got, Some(m), "{b:#x}");
                assert_eq!(m.to_wire(), b);
            }
        }
        assert_eq!(
            MuxLines {
                a0: true,
                a1: false
            }
            .to_wire(),
            1
        );
        assert_eq!(
            MuxLines {
                a0: false,
                a1: true
            }
            .to_wire(),
            2
        );
    }

    // req: T3/bolter_attempt
    #[cfg(feature = "serde")]
    #[test]
    fn bolter_attempt_from_a_number() {
        for n in 0..=5u8 {
            let got: Result<BolterAttempt, _> = serde_json::from_slice(&[b'0' + n]);
            assert_eq!(got.ok(), BolterAttempt::new(n).ok(), "{n}");
        }
    }

    /// A side's executor times a sensed step out past `sensed_ms` and a step that ends at home
    /// past `home_ms` (different here), selects its order's pair on the multiplexer and
    /// reports its direction.
    // req: P5.10
    #[test]
    fn side_timeouts_mux_and_direction() {
        use super::BolterOrder;
        use super::{BolterDirection, BolterSide, BolterStep, Sensed, SideConfig};
        let cfg = SideConfig {
            sensed_ms: 1_000,
            home_ms: 3_000,
            ..SideConfig::default()
        };
        let nothing = Sensed {
            i_bo: 0,
            at_home: false,
        };
        for (step, limit) in [
            (BolterStep::Descend, 1_000),
            (BolterStep::DescendEngage, 1_000),
            (BolterStep::Rotate, 1_000),
            (BolterStep::Retract, 3_000),
            (BolterStep::CounterRotate, 3_000),
            (BolterStep::ReturnHome, 3_000),
        ] {
            let mut s = BolterSide::new();
            assert_eq!((s.direction(), s.mux()), (None, MuxLines::default()));
            let order = BolterOrder {
                pair: BolterPair::P4,
                direction: BolterDirection::Unbolt,
                step,
            };
            s.order(7, Some(order), 0);
            s.tick(&cfg, limit, nothing);
            assert!(!s.aux().timed_out, "{step:?} at its limit");
            s.tick(&cfg, limit + 1, nothing);
            assert!(s.aux().timed_out, "{step:?} past its limit");
            assert_eq!(s.direction(), Some(BolterDirection::Unbolt));
            assert_eq!(s.mux(), MuxLines { a0: true, a1: true });
        }
    }

    // req: T3/bolter_attempt
    #[test]
    fn bolter_attempt_range() {
        for n in 0..=u8::MAX {
            match BolterAttempt::new(n) {
                Ok(a) => assert!(n <= 3 && a.get() == n && u8::from(a) == n),
                Err(e) => assert!(n > 3 && e.found == u32::from(n)),
            }
            assert_eq!(BolterAttempt::try_from(n), BolterAttempt::new(n));
        }
    }
}
