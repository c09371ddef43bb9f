//! Fault detectors for Table 8: pure functions of filtered sensor values, time and events,
//! with every threshold in one [`Config`].
//!
//! Time is a `u32` millisecond clock that wraps every 49.7 days. Detectors never compare
//! timestamps; they add up the elapsed time between successive calls with `wrapping_sub`, so
//! the wrap is invisible. A step that looks longer than 2^31 ms can only be the clock going
//! backwards; it is counted as 0 ms rather than as a huge jump.
//!
//! ```
//! use mmic::safety::detect::{Config, LowBattery};
//! let cfg = Config::default();
//! let mut lb = LowBattery::default();
//! let t0 = u32::MAX - 100; // across the clock's wrap
//! assert!(!lb.update(&cfg, t0, 9_900, Some(11_000)));
//! assert!(!lb.update(&cfg, t0.wrapping_add(500), 9_900, Some(11_000))); // 500 ms: not yet
//! assert!(lb.update(&cfg, t0.wrapping_add(501), 9_900, Some(11_000))); // more than 0.5 s
//! // Side B not heard yet: only side A's battery is judged.
//! let mut lb = LowBattery::default();
//! assert!(!lb.update(&cfg, 0, 12_000, None) && !lb.update(&cfg, 2_000, 12_000, None));
//! ```
// req: P2.7, P7.11, P7.15, P7.16, P7.17, P7.18, P7.19

use crate::faults::{Fault, Faults};
use crate::units::{Electrical, HipAngle, Instant, Milliamps, Millivolts};

/// Current limits of the three module classes of Table 8.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Limits {
    /// Locomotion: arm and hip current I_loc.
    pub locomotion: Milliamps,
    /// Gripper current I_grip.
    pub gripper: Milliamps,
    /// Bolter current I_bo.
    pub bolter: Milliamps,
}

/// Every fault threshold, with documented defaults (spec/modes.toml lists them).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Config {
    /// Low battery: V_batA or V_batB strictly below this (Section 2: "Below 10 V, the battery is
    /// considered out of charge").
    pub low_battery_mv: Millivolts,
    /// Low battery: for strictly longer than this (Section 7: "for more than 0.5 seconds").
    pub low_battery_ms: u32,
    /// Internal comm loss: no board-B heartbeat for strictly longer than this. Default 500 ms,
    /// ten periods of B's 50 ms heartbeat.
    pub comm_timeout_ms: u32,
    /// Internal comm loss: the same command sent to B this many times without an
    /// acknowledgement. Default 10: at board A's 50 ms resend period the same 500 ms horizon
    /// as the silence rule, so a few lost packets never fault the robot (with 3, two lost
    /// heartbeats in a row did; stateright checks up to four losses).
    pub comm_max_unacked: u8,
    /// Idle check: current at rest above these (robot gripped, not moving) at the start and end
    /// of a reconfiguration. Defaults: locomotion 400 mA, gripper 200 mA, bolter 200 mA.
    pub idle: Limits,
    /// Operational check, always: absolute limits. Defaults: locomotion 3000 mA, gripper
    /// 1500 mA, bolter 2000 mA.
    pub absolute: Limits,
    /// (Un)bolting failure: this many consecutive failed attempts on one pair (Table 8: three).
    pub bolting_max_attempts: u8,
    /// The hip angle of the contracted-gripped (home) configuration. Default 180.00°.
    pub hip_home: HipAngle,
    /// Hip mismatch when entering Operational: reading farther than this from `hip_home`
    /// (circular distance, 0.01°). Default 10.00°.
    pub hip_tolerance: u16,
}

impl Default for Config {
    fn default() -> Self {
        Config {
            low_battery_mv: 10_000,
            low_battery_ms: 500,
            comm_timeout_ms: 500,
            comm_max_unacked: 10,
            bolting_max_attempts: 3,
            idle: Limits {
                locomotion: 400,
                gripper: 200,
                bolter: 200,
            },
            absolute: Limits {
                locomotion: 3000,
                gripper: 1500,
                bolter: 2000,
            },
            hip_home: HipAngle::STRAIGHT,
            hip_tolerance: 1000,
        }
    }
}

/// A condition that must hold continuously for longer than a duration.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Debounce {
    /// Time of the previous sample while the condition held.
    last: Option<Instant>,
    /// How long it has held, saturating.
    held_ms: u32,
}

impl Debounce {
    /// Feeds one sample; true when the condition has held for strictly more than `limit_ms`.
    /// The time between two samples that both hold counts as held.
    pub fn update(&mut self, now: u32, holds: bool, limit_ms: u32) -> bool {
        if !holds {
            *self = Debounce::default();
            return false;
        }
        let now = Instant::from_millis(now);
        if let Some(last) = self.last {
            self.held_ms = self.held_ms.saturating_add(now.since(last).millis());
        }
        self.last = Some(now);
        self.held_ms > limit_ms
    }

    /// How long the condition has held so far.
    pub const fn held_ms(&self) -> u32 {
        self.held_ms
    }
}

/// Low battery (Table 8): V_batA or V_batB below the threshold for longer than the duration.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LowBattery(Debounce);

impl LowBattery {
    /// Feeds the filtered battery voltages of both sides; true while the fault condition holds.
    /// Side B's is `None` until board B has reported one: a voltage nobody measured is not a
    /// low battery (before issue 24 board A judged the 0 mV of an empty report, and a board B
    /// powered more than `low_battery_ms` after A latched the fault at every start-up).
    pub fn update(
        &mut self,
        cfg: &Config,
        now: u32,
        v_bat_a: Millivolts,
        v_bat_b: Option<Millivolts>,
    ) -> bool {
        let low = |v: Millivolts| v < cfg.low_battery_mv;
        let below = low(v_bat_a) || v_bat_b.is_some_and(low);
        self.0.update(now, below, cfg.low_battery_ms)
    }
}

/// Internal communication loss (Table 8): no heartbeat from board B for too long, or the same
/// command sent to B repeatedly without acknowledgement.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct CommMonitor {
    last_seen: Option<Instant>,
    silent_ms: u32,
    pending: Option<u8>,
    sends: u8,
    /// The number B last echoed: resending that command refreshes B's snapshot, it is not a
    /// command "never acknowledged" (a lost refresh is the silence timeout's business).
    acked: Option<u8>,
}

impl CommMonitor {
    /// Advances time; silence counts from the first call (boot) until B's first heartbeat.
    pub fn tick(&mut self, now: u32) {
        let now = Instant::from_millis(now);
        if let Some(last) = self.last_seen {
            self.silent_ms = self.silent_ms.saturating_add(now.since(last).millis());
        }
        self.last_seen = Some(now);
    }

    /// Board B's heartbeat arrived, echoing sequence number `ack` ("command received").
    pub fn heartbeat(&mut self, now: u32, ack: u8) {
        self.last_seen = Some(Instant::from_millis(now));
        self.silent_ms = 0;
        self.acked = Some(ack);
        if self.pending == Some(ack) {
            self.pending = None;
            self.sends = 0;
        }
    }

    /// A command with sequence number `seq` was sent to B (a resend repeats the number). A
    /// resend of the command B has already acknowledged is a periodic refresh and is not
    /// counted: only a command B has not yet acknowledged can be "sent repeatedly without
    /// acknowledgement" (Table 8).
    pub fn sent(&mut self, seq: u8) {
        if self.acked == Some(seq) {
            return;
        }
        if self.pending == Some(seq) {
            self.sends = self.sends.saturating_add(1);
        } else {
            self.pending = Some(seq);
            self.sends = 1;
        }
    }

    /// Whether the fault condition holds.
    pub fn lost(&self, cfg: &Config) -> bool {
        self.silent_ms > cfg.comm_timeout_ms
            || (self.pending.is_some() && self.sends >= cfg.comm_max_unacked)
    }

    /// Milliseconds since B's last heartbeat (saturating).
    pub const fn silent_ms(&self) -> u32 {
        self.silent_ms
    }
}

/// One side's verdict per module class: above the limit or not.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Over {
    /// Arm (and, on side A, hip) current: the locomotion modules.
    pub locomotion: bool,
    /// Gripper current.
    pub gripper: bool,
    /// Bolter current.
    pub bolter: bool,
}

impl Over {
    /// Board A's own verdict on side A's currents: each strictly above its limit.
    pub const fn judge(e: &Electrical, l: &Limits) -> Over {
        Over {
            locomotion: e.i_loc > l.locomotion,
            gripper: e.i_grip > l.gripper,
            bolter: e.i_bo > l.bolter,
        }
    }

    fn faults(self, loco: Fault, grip: Fault, bolt: Fault) -> Faults {
        let mut f = Faults::EMPTY;
        if self.locomotion {
            f = f.with(loco);
        }
        if self.gripper {
            f = f.with(grip);
        }
        if self.bolter {
            f = f.with(bolt);
        }
        f
    }
}

/// Operational overcurrent check, performed at all times: any module above its absolute
/// limit — side A judged here from A's currents, side B as board B judged it against its own
/// limits (Table 4 bytes 41–43, spec/decisions.toml `b-overcurrent-flags`).
pub fn operational_overcurrent(cfg: &Config, a: &Electrical, b: Over) -> Faults {
    use Fault::*;
    let f = (LocomotionOvercurrent, GripperOvercurrent, BolterOvercurrent);
    Over::judge(a, &cfg.absolute)
        .faults(f.0, f.1, f.2)
        .union(b.faults(f.0, f.1, f.2))
}

/// Idle overcurrent check, at the start and the end of a reconfiguration: any module drawing
/// more than its at-rest limit (not gripping, arm stuck, bolter caught) — side A judged here,
/// side B as board B judged it (Table 4 bytes 38–40).
pub fn idle_overcurrent(cfg: &Config, a: &Electrical, b: Over) -> Faults {
    use Fault::*;
    let f = (
        LocomotionOvercurrentIdle,
        GripperOvercurrentIdle,
        BolterOvercurrentIdle,
    );
    Over::judge(a, &cfg.idle)
        .faults(f.0, f.1, f.2)
        .union(b.faults(f.0, f.1, f.2))
}

/// Hip mismatch check when entering Operational: true when the reading is within tolerance of
/// the contracted-gripped angle.
pub const fn hip_at_home(cfg: &Config, hip_now: HipAngle) -> bool {
    hip_now.distance(cfg.hip_home) <= cfg.hip_tolerance
}

/// (Un)bolting failure (Table 8): the bolter state machine has failed this many consecutive
/// attempts on one pair. The bolter module counts attempts; this is the threshold it applies.
pub const fn bolting_failure(cfg: &Config, consecutive_failed_attempts: u8) -> bool {
    consecutive_failed_attempts >= cfg.bolting_max_attempts
}

#[cfg(test)]
mod tests {
    use super::*;

    // req: P2.7, P7.11, T8/low_battery
    #[test]
    fn low_battery_boundaries() {
        let cfg = Config::default();
        // Exactly 10.0 V is not below; 9.999 V is.
        let mut lb = LowBattery::default();
        for t in (0..=2000).step_by(10) {
            assert!(!lb.update(&cfg, t, 10_000, Some(10_000)));
        }
        let mut lb = LowBattery::default();
        assert!(!lb.update(&cfg, 1000, 12_000, Some(9_999)));
        assert!(!lb.update(&cfg, 1500, 12_000, Some(9_999)));
        assert!(lb.update(&cfg, 1501, 12_000, Some(9_999)));
        // One good sample resets the debounce.
        assert!(!lb.update(&cfg, 1502, 12_000, Some(10_000)));
        assert!(!lb.update(&cfg, 1503, 9_000, Some(12_000)));
        assert!(!lb.update(&cfg, 2003, 9_000, Some(12_000)));
        assert!(lb.update(&cfg, 2004, 9_000, Some(12_000)));
        // Side B unheard judges nothing of side B, and side A alone still counts.
        let mut lb = LowBattery::default();
        assert!(!lb.update(&cfg, 0, 12_000, None));
        assert!(!lb.update(&cfg, 5_000, 12_000, None));
        assert!(!lb.update(&cfg, 5_001, 9_000, None));
        assert!(lb.update(&cfg, 5_502, 9_000, None));
    }

    // req: P7.11
    #[test]
    fn clock_going_backwards_counts_as_no_time() {
        let mut d = Debounce::default();
        assert!(!d.update(1000, true, 500));
        assert!(!d.update(900, true, 500));
        assert_eq!(d.held_ms(), 0);
        // Forward, it counts the time between samples that hold, across the clock's wrap.
        assert!(!d.update(1_200, true, 500));
        assert_eq!(d.held_ms(), 300);
        let mut d = Debounce::default();
        d.update(u32::MAX - 99, true, 500);
        d.update(150, true, 500);
        assert_eq!(d.held_ms(), 250);
        d.update(151, false, 500);
        assert_eq!(d.held_ms(), 0);
    }

    // req: P7.19, T8/internal_comm_loss
    #[test]
    fn comm_loss_by_silence_and_by_unacknowledged_resends() {
        let cfg = Config::default();
        let mut c = CommMonitor::default();
        c.tick(0);
        c.tick(500);
        assert_eq!(c.silent_ms(), 500);
        assert!(!c.lost(&cfg));
        c.tick(501);
        assert!(c.lost(&cfg));
        c.heartbeat(600, 0);
        assert!(!c.lost(&cfg));
        let n = cfg.comm_max_unacked;
        for _ in 1..n - 1 {
            c.sent(7);
        }
        assert!(!c.lost(&cfg));
        c.heartbeat(650, 6); // acknowledges an older command: not this one
        c.sent(7);
        let below = n - 1;
        assert!(!c.lost(&cfg), "{below} sends");
        c.sent(7);
        assert!(c.lost(&cfg), "{n} sends");
        c.heartbeat(700, 7);
        assert!(!c.lost(&cfg));
        // Resending the acknowledged command is a refresh: it never counts.
        for _ in 0..3 * n {
            c.sent(7);
        }
        assert!(!c.lost(&cfg));
        // A new command counts again from one.
        for _ in 0..n - 1 {
            c.sent(8);
        }
        assert!(!c.lost(&cfg));
        c.sent(8);
        assert!(c.lost(&cfg));
    }

    // req: T8/bolting_failure
    #[test]
    fn bolting_failure_after_the_third_failed_attempt() {
        let cfg = Config::default();
        assert!(!bolting_failure(&cfg, 0) && !bolting_failure(&cfg, 2));
        assert!(bolting_failure(&cfg, 3) && bolting_failure(&cfg, 4));
    }

    // req: P7.18
    #[test]
    fn hip_distance_is_circular() {
        let a = HipAngle::wrapping; // all test values are below 36000
        assert_eq!(a(100).distance(a(35900)), 200);
        assert_eq!(a(0).distance(a(18000)), 18000);
        let cfg = Config::default();
        assert!(hip_at_home(&cfg, a(17000)) && hip_at_home(&cfg, a(19000)));
        assert!(!hip_at_home(&cfg, a(16999)) && !hip_at_home(&cfg, a(19001)));
    }

    // req: P2.7, P7.17
    #[test]
    fn overcurrent_is_strictly_above_the_limit_on_a_and_as_b_reports_it() {
        let cfg = Config::default();
        let ok = Electrical {
            i_loc: 3000,
            i_grip: 1500,
            i_bo: 2000,
            ..Default::default()
        };
        let calm = Over::default();
        assert!(operational_overcurrent(&cfg, &ok, calm).is_empty());
        let hot = Electrical { i_grip: 1501, ..ok };
        assert_eq!(
            operational_overcurrent(&cfg, &hot, calm),
            Faults::EMPTY.with(Fault::GripperOvercurrent)
        );
        // Side B's own flag counts as B reported it.
        let b_hot = Over {
            bolter: true,
            ..calm
        };
        assert_eq!(
            operational_overcurrent(&cfg, &ok, b_hot),
            Faults::EMPTY.with(Fault::BolterOvercurrent)
        );
        let rest = Electrical {
            i_loc: 401,
            ..Default::default()
        };
        assert_eq!(
            idle_overcurrent(&cfg, &rest, calm),
            Faults::EMPTY.with(Fault::LocomotionOvercurrentIdle)
        );
        assert_eq!(
            idle_overcurrent(&cfg, &Electrical::default(), b_hot),
            Faults::EMPTY.with(Fault::BolterOvercurrentIdle)
        );
    }
}
