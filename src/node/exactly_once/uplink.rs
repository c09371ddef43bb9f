//! The opsUI's command uplink for one robot: the sending half of exactly-once commanding.
//!
//! Section 8: in the ground demonstration the opsUI sent a command every 1.2 s, counted a
//! heartbeat not received within 0.7 s as a failed attempt, and showed the WiFi efficiency over
//! the last 100 attempts (Figure 11); Section 3: it resends until acknowledged. Here each
//! command carries a sequence number; a heartbeat acknowledges it when its bytes 57–58 carry
//! that number, and its byte 62 then tells whether board A accepted or refused it. A command
//! is *done* when acknowledged, or when `max_attempts` attempts went unanswered: it is then
//! reported as unacknowledged (it may or may not have run, never twice), never silently
//! dropped.
//!
//! ```
//! use mmic::command::Command;
//! use mmic::node::exactly_once::uplink::{Config, Outcome, Uplink};
//! use mmic::units::BoardNumber;
//! use mmic::wire::heartbeat::HeartbeatRepr;
//!
//! let mut up = Uplink::new(Config::default(), BoardNumber::ONE);
//! let seq = up.submit(Command::Stop).unwrap();
//! let sent = up.tick(0).send.unwrap();           // first attempt at t = 0
//! assert_eq!((sent.command, sent.seq), (Command::Stop, seq));
//! assert!(up.tick(700).send.is_none());           // not yet timed out
//! let t = up.tick(701);                           // 0.7 s without a heartbeat: failed attempt
//! assert_eq!(t.attempt, Some(false));
//! let resent = up.tick(1200).send.unwrap();       // the next slot: resend, same number
//! assert_eq!(resent, sent);
//! let hb = HeartbeatRepr { last_seq: seq, ..HeartbeatRepr::default() };
//! let done = up.heartbeat(1300, &hb).done.unwrap();
//! assert_eq!((done.seq, done.outcome, done.attempts), (seq, Outcome::Accepted, 2));
//! assert_eq!(up.efficiency().percent(), Some(50));
//! ```
// req: P3.10, P3.11, P8.4, P8.5, P7.20, D:ground-uplink

use crate::command::Command;
use crate::refusal::Refusal;
use crate::units::BoardNumber;
use crate::units::{Duration, Instant};
use crate::wire::command::CommandRepr;
use crate::wire::heartbeat::HeartbeatRepr;

/// Timing of the uplink.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Config {
    /// Time between transmissions (first attempts and resends), ms. Paper: 1200.
    pub period_ms: u32,
    /// An attempt not answered within this is failed, ms. Paper: 700.
    pub timeout_ms: u32,
    /// Attempts before a command is reported unacknowledged (≥ 1). The paper resends forever.
    pub max_attempts: u8,
}

impl Default for Config {
    fn default() -> Config {
        Config {
            period_ms: 1200,
            timeout_ms: 700,
            max_attempts: 10,
        }
    }
}

/// How a command ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "snake_case"))]
pub enum Outcome {
    /// Board A took and accepted it (it ran exactly once).
    Accepted,
    /// Board A took and refused it, with the reason (it did not run).
    Refused(Refusal),
    /// No acknowledgement after every attempt, or board A answered that it restarted while
    /// taking it ([`Refusal::Restarted`]): it ran once or not at all.
    Unacknowledged,
}

/// A finished command.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Done {
    /// Its sequence number.
    pub seq: u16,
    /// The command.
    pub command: Command,
    /// How it ended.
    pub outcome: Outcome,
    /// Attempts made (transmissions).
    pub attempts: u8,
}

/// What one call asks the ground to do or report.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Tick {
    /// Transmit this packet now.
    pub send: Option<CommandRepr>,
    /// An attempt closed: answered in time (`true`) or not (`false`).
    pub attempt: Option<bool>,
    /// A command finished.
    pub done: Option<Done>,
}

/// The last 100 attempts, for the efficiency of Figure 11.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Efficiency {
    bits: u128,
    len: u8,
}

impl Efficiency {
    /// Window length.
    pub const WINDOW: u8 = 100;

    /// Adds an attempt's result, forgetting the oldest beyond the window.
    pub fn push(&mut self, ok: bool) {
        let mask = (1u128 << Self::WINDOW) - 1;
        self.bits = ((self.bits << 1) | u128::from(ok)) & mask;
        self.len = self.len.saturating_add(1).min(Self::WINDOW);
    }

    /// Successful attempts and attempts in the window.
    pub const fn counts(&self) -> (u8, u8) {
        // At most WINDOW = 100 ones (the mask): the count fits its low octet.
        (
            crate::link::low::u8_of_u32(self.bits.count_ones()),
            self.len,
        )
    }

    /// Successful attempts as a whole percentage of the window; none before the first.
    pub const fn percent(&self) -> Option<u8> {
        let (ok, n) = self.counts();
        // Widened through from_be_bytes (a const fn may not call From): ok <= n <= 100, so
        // the sum is at most 10,050 and the quotient at most 100, and n = 0 gives None.
        let (ok, n) = (u16::from_be_bytes([0, ok]), u16::from_be_bytes([0, n]));
        match ok.saturating_mul(100).saturating_add(n / 2).checked_div(n) {
            Some(p) => Some(crate::link::low::u8_of_u16(p)),
            None => None,
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
struct Outstanding {
    command: Command,
    seq: u16,
    attempts: u8,
    /// When the open attempt was sent; none once it closed.
    open_since: Option<Instant>,
}

/// The uplink's state.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Uplink {
    cfg: Config,
    board: BoardNumber,
    next_seq: u16,
    out: Option<Outstanding>,
    last_send: Option<Instant>,
    eff: Efficiency,
    /// After a restart: the outstanding command is a probe (a sequenced Heartbeat poll) until a
    /// heartbeat acknowledges it ([`Uplink::after_restart`]).
    syncing: bool,
}

/// [`Uplink::submit`] while a command is outstanding: the command is handed back.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[error("command {outstanding} is still outstanding; {command:?} not taken")]
pub struct Busy {
    /// The outstanding command's number.
    pub outstanding: u16,
    /// The command not taken.
    pub command: Command,
}

impl Uplink {
    /// No command yet; numbering starts at 1.
    pub const fn new(cfg: Config, board: BoardNumber) -> Uplink {
        Uplink::starting_at(cfg, board, 1)
    }

    /// Numbering starts after `last`, e.g. the `last_seq` a heartbeat reported after the ground
    /// restarted, so that board A does not take new commands for stale ones.
    pub const fn starting_at(cfg: Config, board: BoardNumber, next: u16) -> Uplink {
        Uplink {
            cfg,
            board,
            next_seq: if next == 0 { 1 } else { next },
            out: None,
            last_send: None,
            eff: Efficiency { bits: 0, len: 0 },
            syncing: false,
        }
    }

    /// The uplink of a sender that restarted (the ground, or the server board's gateway) and
    /// does not know which numbers board A has taken: numbering from 1 could hand a new command
    /// a number board A took before (answered as a copy, never run, yet acknowledged) or an
    /// older one (refused as stale until the numbers pass it). It first *probes*: it sends the
    /// Heartbeat poll (which does nothing but answer) sequenced, numbered 1, then one past
    /// any newer number a heartbeat reports, until a heartbeat acknowledges the probe; numbering
    /// continues after it. A probe board A runs, or answers as the copy of its last command,
    /// does nothing either way. Until then [`Uplink::submit`] is refused, no probe ends as a
    /// [`Done`], and it never gives up (the robot may be off).
    ///
    /// ```
    /// use mmic::command::Command;
    /// use mmic::node::exactly_once::uplink::{Config, Uplink};
    /// use mmic::units::BoardNumber;
    /// use mmic::wire::heartbeat::HeartbeatRepr;
    ///
    /// let mut up = Uplink::after_restart(Config::default(), BoardNumber::ONE);
    /// assert!(up.submit(Command::Stop).is_err()); // not synchronised yet
    /// let probe = up.tick(0).send.unwrap();
    /// assert_eq!((probe.command, probe.seq), (Command::Heartbeat, 1));
    /// // Board A has taken 500 before: the probe is stale, its heartbeat says 500.
    /// let t = up.heartbeat(20, &HeartbeatRepr { last_seq: 500, ..HeartbeatRepr::default() });
    /// assert!(t.done.is_none());
    /// let probe = up.tick(1200).send.unwrap();
    /// assert_eq!(probe.seq, 501);
    /// up.heartbeat(1220, &HeartbeatRepr { last_seq: 501, ..HeartbeatRepr::default() });
    /// assert_eq!(up.submit(Command::Stop), Ok(502));
    /// ```
    pub const fn after_restart(cfg: Config, board: BoardNumber) -> Uplink {
        let mut up = Uplink::starting_at(cfg, board, 2);
        up.out = Some(Outstanding {
            command: Command::Heartbeat,
            seq: 1,
            attempts: 0,
            open_since: None,
        });
        up.syncing = true;
        up
    }

    /// The number the next submitted command gets: what a restarting ground keeps to start
    /// after ([`Uplink::starting_at`]; decision `restart-ground`).
    pub const fn next_seq(&self) -> u16 {
        self.next_seq
    }

    /// The uplink of this one's ground after a restart that kept its numbering (the number it
    /// would give out next, written before a number is first sent: decision
    /// `restart-ground`): nothing outstanding, nothing measured, numbering where it stood.
    pub const fn restarted(&self) -> Uplink {
        Uplink::starting_at(self.cfg, self.board, self.next_seq)
    }

    /// Still probing after a restart ([`Uplink::after_restart`]).
    pub const fn is_syncing(&self) -> bool {
        self.syncing
    }

    /// Queues `command` as the next one; returns its number. Refused while one is outstanding.
    pub fn submit(&mut self, command: Command) -> Result<u16, Busy> {
        if let Some(o) = self.out {
            return Err(Busy {
                outstanding: o.seq,
                command,
            });
        }
        let seq = self.next_seq;
        self.next_seq = match seq.wrapping_add(1) {
            0 => 1,
            s => s,
        };
        self.out = Some(Outstanding {
            command,
            seq,
            attempts: 0,
            open_since: None,
        });
        Ok(seq)
    }

    /// No command outstanding.
    pub const fn is_idle(&self) -> bool {
        self.out.is_none()
    }

    /// The outstanding command's number.
    pub fn outstanding(&self) -> Option<u16> {
        self.out.map(|o| o.seq)
    }

    /// Efficiency over the last 100 attempts.
    pub const fn efficiency(&self) -> Efficiency {
        self.eff
    }

    /// When [`tick`](Self::tick) next has something to do, if anything is outstanding.
    pub fn next_deadline(&self) -> Option<u32> {
        let o = self.out?;
        Some(match (o.open_since, self.last_send) {
            (Some(t), _) => t
                .after(Duration::from_millis(self.cfg.timeout_ms))
                .millis()
                .wrapping_add(1),
            (None, Some(t)) => t.after(Duration::from_millis(self.cfg.period_ms)).millis(),
            (None, None) => 0,
        })
    }

    /// Advances to `now` (ms): closes a timed-out attempt, transmits when a slot is due.
    pub fn tick(&mut self, now: u32) -> Tick {
        let mut t = Tick::default();
        let Some(mut o) = self.out else { return t };
        if let Some(sent) = o.open_since
            && Instant::from_millis(now).since(sent).millis() > self.cfg.timeout_ms
        {
            o.open_since = None;
            self.eff.push(false);
            t.attempt = Some(false);
        }
        let slot_due = self
            .last_send
            .is_none_or(|l| Instant::from_millis(now).since(l).millis() >= self.cfg.period_ms);
        if o.open_since.is_none() && slot_due {
            if self.syncing && o.attempts >= self.cfg.max_attempts.max(1) {
                o.attempts = 0; // a probe never gives up
            }
            if o.attempts >= self.cfg.max_attempts.max(1) {
                self.out = None;
                t.done = Some(Done {
                    seq: o.seq,
                    command: o.command,
                    outcome: Outcome::Unacknowledged,
                    attempts: o.attempts,
                });
                return t;
            }
            // Below max_attempts (checked above).
            o.attempts = o.attempts.saturating_add(1);
            o.open_since = Some(Instant::from_millis(now));
            self.last_send = Some(Instant::from_millis(now));
            t.send = Some(CommandRepr {
                board: self.board,
                command: o.command,
                seq: o.seq,
            });
        }
        self.out = Some(o);
        t
    }

    /// A heartbeat arrived at `now`. It acknowledges the outstanding command when it is from
    /// this robot and its bytes 57–58 carry the command's number.
    ///
    /// A heartbeat reporting a number newer than any this uplink gave out (board A took it
    /// from an earlier life of this sender) moves the numbering past it; a probe after a
    /// restart is renumbered past it.
    pub fn heartbeat(&mut self, now: u32, hb: &HeartbeatRepr) -> Tick {
        let mut t = Tick::default();
        if hb.board != self.board {
            return t;
        }
        let issued = self.next_seq.wrapping_sub(1);
        if super::newer(hb.last_seq, issued) {
            self.next_seq = match hb.last_seq.wrapping_add(1) {
                0 => 1,
                s => s,
            };
        }
        let Some(mut o) = self.out else { return t };
        if self.syncing && super::newer(hb.last_seq, o.seq) {
            o.seq = self.next_seq;
            self.next_seq = match o.seq.wrapping_add(1) {
                0 => 1,
                s => s,
            };
            self.out = Some(o);
            return t;
        }
        if hb.last_seq != o.seq || o.attempts == 0 {
            return t;
        }
        if let Some(sent) = o.open_since {
            let ok = Instant::from_millis(now).since(sent).millis() <= self.cfg.timeout_ms;
            self.eff.push(ok);
            t.attempt = Some(ok);
        }
        self.out = None;
        if self.syncing {
            self.syncing = false; // the probe is acknowledged: numbering continues after it
            return t;
        }
        t.done = Some(Done {
            seq: o.seq,
            command: o.command,
            outcome: match hb.refusal {
                None => Outcome::Accepted,
                // Board A restarted while taking it: it ran at most once, not known whether.
                Some(Refusal::Restarted) => Outcome::Unacknowledged,
                Some(r) => Outcome::Refused(r),
            },
            attempts: o.attempts,
        });
        t
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    // req: P3.10, P3.11, P7.20
    #[test]
    fn gives_up_after_max_attempts_and_reports_it() {
        let cfg = Config {
            max_attempts: 3,
            ..Config::default()
        };
        let mut up = Uplink::new(cfg, BoardNumber::ONE);
        let seq = up.submit(Command::Reset).ok();
        let mut sends = 0;
        let mut done = None;
        for now in (0..10_000).step_by(100) {
            let t = up.tick(now);
            sends += t.send.is_some() as u32;
            if t.done.is_some() {
                done = t.done;
                break;
            }
        }
        assert_eq!(sends, 3);
        assert_eq!(done.map(|d| d.seq), seq);
        assert_eq!(done.map(|d| d.outcome), Some(Outcome::Unacknowledged));
        assert_eq!(up.efficiency().counts(), (0, 3));
        assert!(up.is_idle());
    }

    // req: P3.11
    #[test]
    fn stale_heartbeats_do_not_acknowledge() {
        let mut up = Uplink::new(Config::default(), BoardNumber::ONE);
        let first = up.submit(Command::Stop).ok();
        up.tick(0);
        let hb = HeartbeatRepr {
            last_seq: first.map_or(0, |s| s),
            ..HeartbeatRepr::default()
        };
        assert!(up.heartbeat(10, &hb).done.is_some());
        let second = up.submit(Command::Reset).ok();
        assert_ne!(first, second);
        assert!(up.tick(20).send.is_none(), "one transmission per period");
        assert!(up.tick(1200).send.is_some());
        // A late copy of the first heartbeat does not acknowledge the second command.
        assert!(up.heartbeat(1250, &hb).done.is_none());
        assert_eq!(up.outstanding(), second);
    }

    // req: P8.5
    #[test]
    fn efficiency_window_forgets_beyond_100() {
        let mut e = Efficiency::default();
        assert_eq!(e.percent(), None);
        for _ in 0..100 {
            e.push(false);
        }
        for _ in 0..50 {
            e.push(true);
        }
        assert_eq!(e.counts(), (50, 100));
        for _ in 0..100 {
            e.push(true);
        }
        assert_eq!(e.percent(), Some(100));
    }

    /// Numbers wrap from 65535 to 1: 0 is never a command's number.
    #[test]
    fn numbers_wrap_past_65535_to_1() {
        let mut up = Uplink::starting_at(Config::default(), BoardNumber::ONE, u16::MAX);
        assert_eq!(up.submit(Command::Reset).ok(), Some(u16::MAX));
        assert_eq!(up.next_seq(), 1);
    }

    /// A heartbeat reporting 65535, newer than any number given out, moves the numbering past
    /// it to 1; a probe renumbered to 65535 after a restart is followed by 1 too.
    #[test]
    fn numbering_resynced_from_a_heartbeat_wraps_past_65535_to_1() {
        let hb = |last_seq| HeartbeatRepr {
            last_seq,
            ..HeartbeatRepr::default()
        };
        let mut up = Uplink::starting_at(Config::default(), BoardNumber::ONE, 40_000);
        assert!(up.heartbeat(0, &hb(u16::MAX)).done.is_none());
        assert_eq!(up.submit(Command::Reset), Ok(1));

        let mut up = Uplink::after_restart(Config::default(), BoardNumber::ONE);
        // Each report newer than the probe renumbers it past the report (steps under 0x8000).
        for (report, probe) in [(30_000, 30_001), (60_000, 60_001), (65_534, u16::MAX)] {
            up.heartbeat(0, &hb(report));
            assert_eq!(up.outstanding(), Some(probe));
        }
        assert_eq!(up.next_seq(), 1);
        assert_eq!(up.tick(0).send.map(|c| c.seq), Some(u16::MAX));
        up.heartbeat(10, &hb(u16::MAX));
        assert!(!up.is_syncing());
        assert_eq!(up.submit(Command::Reset), Ok(1));
    }
}
