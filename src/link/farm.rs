//! FARM-1, the receiving end of COP-1 (CCSDS 232.1-B-2 §6): one per spacecraft and TC virtual
//! channel, it takes each AD frame exactly once and in order, lets BD frames through, obeys the
//! BC control commands, and reports its state in the [`Clcw`].
//!
//! ```
//! use mmic::link::farm::{Farm, FarmEvent, FarmState, FarmWindow, Verdict, DiscardReason};
//! use mmic::link::ControlCommand;
//!
//! let mut farm = Farm::new(FarmWindow::MISSION); // W = 20, Open, V(R) = 0
//! assert_eq!(farm.step(FarmEvent::Ad { ns: 0, buffer_ready: true }), Verdict::Accept);
//! assert_eq!(farm.step(FarmEvent::Ad { ns: 0, buffer_ready: true }),
//!            Verdict::Discard(DiscardReason::Behind));             // a duplicate
//! assert_eq!(farm.step(FarmEvent::Ad { ns: 3, buffer_ready: true }),
//!            Verdict::Discard(DiscardReason::Ahead));              // a gap: Retransmit set
//! assert!(farm.clcw(Default::default(), false, false).retransmit);
//! assert_eq!(farm.step(FarmEvent::Ad { ns: 100, buffer_ready: true }),
//!            Verdict::Discard(DiscardReason::LockoutArea));        // outside the window
//! assert_eq!(farm.state(), FarmState::Lockout);
//! farm.step(FarmEvent::Bc(ControlCommand::Unlock));
//! assert_eq!((farm.state(), farm.vr()), (FarmState::Open, 1));
//! ```
//!
//! The state table (232.1-B-2 Table 6-1) is transcribed in `spec/ccsds/farm-1.toml`, and
//! `tests/ccsds/farm_table.rs` checks [`Farm::step`] against it cell by cell for every V(R),
//! N(S), state and window of a set. Where the references differ, the choice is written at
//! the cell (the Wait flag in Lockout, below).
//!
//! The frame's checks (its header, CRC, spacecraft and VC) are the frame parser's: what
//! reaches FARM-1 is a valid frame's kind, N(S) and control command, or
//! [`FarmEvent::Invalid`] for a frame that failed them (E9). All arithmetic on sequence
//! numbers is modulo 256 (232.1-B-2 §6.2.1, note).

use super::clcw::{Clcw, ClcwVcid, FarmBCounter, StatusField};
use super::{ControlCommand, FrameKind};

mod event;
mod outcome;
mod table;
mod window;

pub use event::{EventId, FarmEvent};
pub use outcome::{DiscardReason, FarmCounters, Verdict};
pub use window::{FarmWindow, FarmWindowError, WindowPlace, FARM_WINDOW};

/// FARM-1's three states (232.1-B-2 §6.1.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "kebab-case"))]
pub enum FarmState {
    /// S1: AD frames in sequence are accepted.
    #[default]
    Open,
    /// S2: no buffer for AD frames; the Wait flag is set until the buffer is released.
    Wait,
    /// S3: an AD frame fell in the lockout area; no AD frame is taken until an Unlock.
    Lockout,
}

/// FARM-1's state variables (232.1-B-2 §6.1): what the CLCW reports, without the counters.
/// [`Farm::status`] reads them, [`Farm::restore`] builds a FARM from them (tests, model
/// checks, a restart).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct FarmStatus {
    /// S1, S2 or S3.
    pub state: FarmState,
    /// V(R), the N(S) of the next AD frame expected.
    pub vr: u8,
    /// The Retransmit flag (§6.1.3).
    pub retransmit: bool,
    /// The Wait flag (§6.1.4): set in Wait, and kept in Lockout when Lockout was entered
    /// from Wait (until a buffer release or an Unlock).
    pub wait: bool,
    /// The FARM-B counter (§6.1.5).
    pub farm_b: FarmBCounter,
}

impl FarmStatus {
    /// Whether the variables fit together as Table 6-1 can leave them: Wait ⇔ the Wait flag
    /// outside Lockout, and the Wait flag ⇒ the Retransmit flag (E2 sets both; only E1, E7
    /// and E8 clear Retransmit, and each leaves Wait behind).
    pub const fn is_consistent(&self) -> bool {
        let wait_ok = match self.state {
            FarmState::Open => !self.wait,
            FarmState::Wait => self.wait,
            FarmState::Lockout => true,
        };
        wait_ok && (!self.wait || self.retransmit)
    }
}

/// FARM-1 for one TC virtual channel.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Farm {
    window: FarmWindow,
    status: FarmStatus,
    counters: FarmCounters,
}

impl Farm {
    /// FARM-1 in Open with V(R) = 0 and every flag clear: the state after the ground's
    /// "Initiate AD service" on a fresh link (232.1-B-2 leaves the initial state to the
    /// mission; dariol83/ccsds starts in Lockout, which the ground leaves with an Unlock —
    /// both work with FOP-1's "initiate with Unlock").
    pub const fn new(window: FarmWindow) -> Farm {
        Farm {
            window,
            status: FarmStatus {
                state: FarmState::Open,
                vr: 0,
                retransmit: false,
                wait: false,
                farm_b: FarmBCounter::ZERO,
            },
            counters: FarmCounters {
                accepted_ad: 0,
                accepted_bd: 0,
                control: 0,
                discarded: [0; 6],
            },
        }
    }

    /// FARM-1 with these variables and zero counters; `None` if they do not fit together
    /// ([`FarmStatus::is_consistent`]).
    pub const fn restore(window: FarmWindow, status: FarmStatus) -> Option<Farm> {
        if !status.is_consistent() {
            return None;
        }
        let mut farm = Farm::new(window);
        farm.status = status;
        Some(farm)
    }

    /// The state.
    pub const fn state(&self) -> FarmState {
        self.status.state
    }

    /// V(R).
    pub const fn vr(&self) -> u8 {
        self.status.vr
    }

    /// The state variables.
    pub const fn status(&self) -> FarmStatus {
        self.status
    }

    /// The window.
    pub const fn window(&self) -> FarmWindow {
        self.window
    }

    /// The counters.
    pub const fn counters(&self) -> &FarmCounters {
        &self.counters
    }

    /// The event number of Table 6-1 that `event` is in the present state.
    pub const fn classify(&self, event: FarmEvent) -> EventId {
        match event {
            FarmEvent::Ad { ns, buffer_ready } => match self.window.place(self.status.vr, ns) {
                WindowPlace::Expected if buffer_ready => EventId::E1,
                WindowPlace::Expected => EventId::E2,
                WindowPlace::Positive => EventId::E3,
                WindowPlace::Negative => EventId::E4,
                WindowPlace::Lockout => EventId::E5,
            },
            FarmEvent::Bd => EventId::E6,
            FarmEvent::Bc(ControlCommand::Unlock) => EventId::E7,
            FarmEvent::Bc(ControlCommand::SetVr(_)) => EventId::E8,
            FarmEvent::Invalid => EventId::E9,
            FarmEvent::BufferRelease => EventId::E10,
        }
    }

    /// A frame as the frame parser reads it ([`FarmEvent::of_frame`]).
    pub fn frame(
        &mut self,
        kind: FrameKind,
        ns: u8,
        control: Option<ControlCommand>,
        buffer_ready: bool,
    ) -> Verdict {
        self.step(FarmEvent::of_frame(kind, ns, control, buffer_ready))
    }

    /// The higher procedures freed the buffer (E10).
    pub fn buffer_released(&mut self) {
        self.step(FarmEvent::BufferRelease);
    }

    /// Runs `event` through Table 6-1 of 232.1-B-2: the actions of its cell for the present
    /// state, then the cell's next state.
    pub fn step(&mut self, event: FarmEvent) -> Verdict {
        let id = self.classify(event);
        let verdict = self.status.cell(id, event);
        self.counters.count(id, verdict);
        verdict
    }

    /// The CLCW reporting this FARM (232.1-B-2 §6.2.4 "Report", E11): status field 0, COP-1,
    /// the flags and V(R) from the state; `vcid` and the two physical-layer flags are the
    /// caller's.
    pub const fn clcw(&self, vcid: ClcwVcid, no_rf_available: bool, no_bit_lock: bool) -> Clcw {
        Clcw {
            status: StatusField::ZERO,
            vcid,
            no_rf_available,
            no_bit_lock,
            lockout: matches!(self.status.state, FarmState::Lockout),
            wait: self.status.wait,
            retransmit: self.status.retransmit,
            farm_b_counter: self.status.farm_b,
            report_value: self.status.vr,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ad(ns: u8) -> FarmEvent {
        FarmEvent::Ad {
            ns,
            buffer_ready: true,
        }
    }

    #[test]
    #[cfg_attr(
        miri,
        ignore = "u8 arithmetic only, no dependency's unsafe code: nothing for Miri to find"
    )]
    fn window_places_match_the_bounds_of_table_6_1() {
        let w = FarmWindow::new(10).unwrap(); // PW = NW = 5
        let mut places = [WindowPlace::Expected; 256];
        for (ns, p) in places.iter_mut().enumerate() {
            *p = w.place(0, ns as u8);
        }
        assert_eq!(places[0], WindowPlace::Expected);
        assert!(places[1..=4].iter().all(|p| *p == WindowPlace::Positive));
        assert_eq!(places[5], WindowPlace::Lockout);
        assert_eq!(places[250], WindowPlace::Lockout);
        assert!(places[251..=255]
            .iter()
            .all(|p| *p == WindowPlace::Negative));
        // W sequence numbers in the window, 256 − W in the lockout area, for every W.
        for width in (2..=254).step_by(2) {
            let w = FarmWindow::new(width).unwrap();
            for vr in [0u8, 7, 255] {
                let n = (0..=255u8)
                    .filter(|ns| w.place(vr, *ns) != WindowPlace::Lockout)
                    .count();
                assert_eq!(n, width as usize);
            }
        }
        assert!(FarmWindow::new(0).is_err());
        assert!(FarmWindow::new(3).is_err());
        assert!(FarmWindow::new(255).is_err());
        assert_eq!(FarmWindow::new(1), Err(FarmWindowError { found: 1 }));
    }

    // req: 232.1-B-2/FARM-9
    #[test]
    fn wait_then_release_then_the_same_frame_is_taken() {
        let mut f = Farm::new(FarmWindow::MISSION);
        let busy = FarmEvent::Ad {
            ns: 0,
            buffer_ready: false,
        };
        assert_eq!(f.step(busy), Verdict::Discard(DiscardReason::NoBuffer));
        assert_eq!(f.state(), FarmState::Wait);
        let c = f.clcw(ClcwVcid::ZERO, false, false);
        assert!(c.wait && c.retransmit && !c.lockout);
        f.buffer_released();
        assert_eq!(f.state(), FarmState::Open);
        assert_eq!(f.step(ad(0)), Verdict::Accept);
        assert!(!f.clcw(ClcwVcid::ZERO, false, false).retransmit);
        assert_eq!(f.counters().accepted_ad, 1);
        assert_eq!(f.counters().discarded(DiscardReason::NoBuffer), 1);
    }

    // req: 232.1-B-2/FARM-5
    #[test]
    fn lockout_from_wait_keeps_the_wait_flag_until_release_or_unlock() {
        let mut f = Farm::new(FarmWindow::MISSION);
        f.step(FarmEvent::Ad {
            ns: 0,
            buffer_ready: false,
        });
        assert_eq!(
            f.step(ad(128)),
            Verdict::Discard(DiscardReason::LockoutArea)
        );
        let c = f.clcw(ClcwVcid::ZERO, false, false);
        assert!(c.lockout && c.wait);
        f.buffer_released();
        assert_eq!(f.state(), FarmState::Lockout);
        assert!(!f.clcw(ClcwVcid::ZERO, false, false).wait);
        assert_eq!(
            f.step(FarmEvent::Bc(ControlCommand::SetVr(9))),
            Verdict::Control {
                command: ControlCommand::SetVr(9),
                executed: false
            }
        );
        assert_eq!(f.vr(), 0);
        f.step(FarmEvent::Bc(ControlCommand::Unlock));
        f.step(FarmEvent::Bc(ControlCommand::SetVr(9)));
        assert_eq!((f.state(), f.vr()), (FarmState::Open, 9));
        // Three B frames: the counter says 3.
        assert_eq!(f.clcw(ClcwVcid::ZERO, false, false).farm_b_counter.get(), 3);
        f.step(FarmEvent::Bd);
        assert_eq!(f.clcw(ClcwVcid::ZERO, false, false).farm_b_counter.get(), 0);
    }

    #[test]
    fn frames_map_to_events() {
        use ControlCommand::*;
        use FrameKind::*;
        assert_eq!(
            FarmEvent::of_frame(Ad, 3, None, false),
            FarmEvent::Ad {
                ns: 3,
                buffer_ready: false
            }
        );
        assert_eq!(FarmEvent::of_frame(Bd, 3, None, true), FarmEvent::Bd);
        assert_eq!(
            FarmEvent::of_frame(Bc, 3, Some(Unlock), true),
            FarmEvent::Bc(Unlock)
        );
        assert_eq!(FarmEvent::of_frame(Bc, 3, None, true), FarmEvent::Invalid);
        assert_eq!(
            FarmEvent::of_frame(Ad, 3, Some(SetVr(1)), true),
            FarmEvent::Invalid
        );
        assert!(Farm::restore(
            FarmWindow::MISSION,
            FarmStatus {
                state: FarmState::Wait,
                ..FarmStatus::default()
            }
        )
        .is_none());
    }

    /// The default window is the mission's; a FARM keeps the window it was made with.
    #[test]
    fn the_window_is_the_one_given_and_defaults_to_the_missions() {
        assert_eq!(FarmWindow::default(), FarmWindow::MISSION);
        let w = FarmWindow::new(10).unwrap();
        assert_ne!(w, FarmWindow::MISSION);
        assert_eq!(Farm::new(w).window(), w);
        assert_eq!(
            Farm::new(FarmWindow::default()).window(),
            FarmWindow::MISSION
        );
    }
}
