//! FOP-1, the sending end of COP-1 (CCSDS 232.1-B-2 §5): it numbers the AD frames, keeps each
//! on the sent queue until a CLCW acknowledges it, retransmits on the Retransmit flag or when
//! timer T1 runs out, and alerts when the link cannot be repaired. The simulator's ground and
//! the tests drive it; the real ground is YAMCS's (`Cop1TcPacketHandler`), configured with the
//! same parameters (`spec/ccsds/link.toml`).
//!
//! ```
//! use mmic::link::fop::{Directive, DirectiveResponse, Fop, FopConfig, FopOutput, FopState};
//! use mmic::link::clcw::Clcw;
//!
//! // FDUs are packet handles here (u16); the window K is at most 10.
//! let mut fop: Fop<u16, 10> = Fop::new(FopConfig::MISSION);
//! let mut sent = Vec::new();
//! let mut out = |o: FopOutput<u16>| sent.push(o);
//! assert_eq!(fop.directive(Directive::InitiateWithoutClcw, 0, &mut out), DirectiveResponse::Confirmed);
//! assert_eq!(fop.transfer_ad(42, 0, &mut out), Ok(()));       // sent as N(S) = 0
//! assert_eq!((fop.state(), fop.vs(), fop.sent_len()), (FopState::Active, 1, 1));
//! fop.clcw(&Clcw { report_value: 1, ..Clcw::default() }, 10, &mut out); // N(R) = 1: acknowledged
//! assert_eq!(fop.sent_len(), 0);
//! assert!(matches!(sent[0], FopOutput::Transmit(f) if f.ns == 0));
//! assert_eq!(sent[1], FopOutput::Confirmed { ns: 0 });
//! ```
//!
//! No I/O and no clock: every input takes the time (`now_ms`, wrapping) and every output goes
//! to the caller's `out` ([`FopOutput`]: frames to send, confirmations, alerts). Events and
//! actions follow 232.1-B-2 Table 5-1 as dariol83/ccsds's `FopEngine` and `S1FopState` …
//! `S6FopState` implement it (event numbers as there: E1–E14 and E101–E103 for CLCWs, E16–E18
//! and E104 for the timer, E19–E21 for requests, E23–E40 for directives).
//!
//! Where the references differ, or the table as written loses a frame, the choice:
//!
//! - E10 in Retransmit with Wait (S3): "initiate AD retransmission, look for FDU" as in S1
//!   (YAMCS); dariol83/ccsds leaves out the look for FDU, so nothing would go out until the
//!   next event.
//! - Purging the sent queue (alert, initialise) sets NN(R) := V(S), as YAMCS does; dariol83
//!   leaves NN(R) behind, after which V(S) − NN(R) no longer counts the sent queue and no
//!   CLCW acknowledges anything.
//! - E1 in S4 ("initiate with CLCW") needs N(R) = V(S) = NN(R) (dariol83); YAMCS instead
//!   adopts the CLCW's N(R) as V(S) and NN(R) on the first CLCW in S4. Here a FARM-1 that
//!   expects another N(S) gives "NN(R)" (E13): set V(S) first ([`Directive::SetVs`]) or
//!   initiate with Set V(R).
//! - [`FopConfig::restart_t1_after_wait`]: T1 starts again when a CLCW takes FOP-1 out of
//!   Retransmit with Wait with frames unacknowledged (neither reference does; without it the
//!   COP-1 model finds a frame left unsent for good).
//!
//! Simplification (allowed by the standard's "lower procedures" being local): the transport
//! always accepts a frame at once, so the AD, BC and BD "out ready" flags are always Ready and
//! events E41–E46 never happen: where the standard waits for "AD Accept" to look for the next
//! FDU, [`Fop`] sends every frame due in one go (all frames marked for retransmission, in
//! order, then the FDU of the wait queue if the window allows).

use super::{ControlCommand, FrameKind};

mod actions;
mod arrival;
mod directive;
mod output;

pub use arrival::ClcwEvent;
pub use directive::{Directive, DirectiveResponse};
pub use output::{AlertCode, FopFrame, FopOutput, FrameData};

/// The mission's FOP sliding window K (`spec/ccsds/link.toml`, `cop1.fop_window`).
pub const FOP_WINDOW: u8 = 10;
/// The mission's timer T1 in milliseconds (`cop1.t1_ms`).
pub const T1_MS: u32 = 3000;
/// The mission's transmission limit (`cop1.tx_limit`).
pub const TX_LIMIT: u8 = 10;

// K ≤ PW: with at most K frames unacknowledged, every frame FOP-1 sends or resends lies in
// FARM-1's window (N(S) ≤ NN(R) + K − 1 ≤ V(R) + PW − 1, N(S) ≥ NN(R) ≥ V(R) − K ≥ V(R) − NW),
// so the link never reaches the lockout area by itself.
const _: () = assert!(FOP_WINDOW <= super::farm::FARM_WINDOW / 2);

/// FOP-1's six states (232.1-B-2 §5.1.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "kebab-case"))]
pub enum FopState {
    /// S1: sending and acknowledging AD frames.
    Active,
    /// S2: retransmitting, FARM-1 not in Wait.
    RetransmitWithoutWait,
    /// S3: FARM-1 reports Wait; nothing is sent until it lifts.
    RetransmitWithWait,
    /// S4: "initiate AD service with CLCW": waiting for a CLCW that fits.
    InitialisingWithoutBc,
    /// S5: "initiate AD service with Unlock / Set V(R)": the BC frame sent, waiting for the
    /// CLCW that shows it obeyed.
    InitialisingWithBc,
    /// S6: AD service not running (at start, after an alert, a suspend or a terminate).
    Initial,
}

/// What to do when T1 runs out with the transmission count at the limit (232.1-B-2 §5.1.8).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "kebab-case"))]
pub enum TimeoutType {
    /// 0: alert (T1) and stop the AD service (YAMCS's default).
    #[default]
    Alert,
    /// 1: suspend; a Resume directive takes up where it stopped.
    Suspend,
}

/// The managed parameters of one FOP-1 (232.1-B-2 §5.1.6–§5.1.9).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct FopConfig {
    /// K: at most this many AD frames unacknowledged (1..=255, at most the capacity of the
    /// sent queue, and at most FARM-1's PW for the lockout area never to be reached).
    pub window: u8,
    /// T1 in milliseconds.
    pub t1_ms: u32,
    /// How often the oldest frame may be sent in all (1 or more).
    pub tx_limit: u8,
    /// What the timer's last expiry does.
    pub timeout_type: TimeoutType,
    /// Start T1 when a CLCW takes FOP-1 out of Retransmit with Wait (S3) into S1 or S2 with
    /// frames still unacknowledged and T1 stopped. Table 5-1 ignores T1's expiry in S3
    /// (dariol83/ccsds and YAMCS do nothing then, so T1 stops), and leaving S3 by E6
    /// ("remove acknowledged frames, look for FDU") starts nothing: when FARM-1 has meanwhile
    /// cleared its Retransmit flag by accepting a late copy, no CLCW and no timer ever sends
    /// the remaining frames again (the COP-1 model in proofs/tests/protocol/cop1.rs finds the
    /// path). `false` is the table as written; the mission sets `true`.
    pub restart_t1_after_wait: bool,
}

impl FopConfig {
    /// The mission's parameters.
    pub const MISSION: FopConfig = FopConfig {
        window: FOP_WINDOW,
        t1_ms: T1_MS,
        tx_limit: TX_LIMIT,
        timeout_type: TimeoutType::Alert,
        restart_t1_after_wait: true,
    };
}

/// An AD frame on the sent queue.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
struct Sent<P> {
    ns: u8,
    fdu: P,
    to_be_retransmitted: bool,
}

/// FOP-1 for one TC virtual channel; `P` is the FDU (a packet, or its handle), `K` the sent
/// queue's capacity (the largest window K the caller will set).
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct Fop<P, const K: usize> {
    state: FopState,
    config: FopConfig,
    vs: u8,
    nnr: u8,
    sent: heapless::Vec<Sent<P>, K>,
    /// The BC frame on the sent queue and its To_Be_Retransmitted flag.
    bc: Option<(ControlCommand, bool)>,
    wait: Option<P>,
    tx_count: u8,
    /// When T1 was (re)started; `None` when it is not running.
    timer: Option<u32>,
    /// 0, or the state (1–4) a suspend left (§5.1.10).
    suspend_state: u8,
}

impl<P: Clone, const K: usize> Fop<P, K> {
    /// FOP-1 in Initial (S6), V(S) = NN(R) = 0, the window clamped to the sent queue's
    /// capacity.
    pub fn new(config: FopConfig) -> Fop<P, K> {
        let cap = u8::try_from(K).unwrap_or(u8::MAX);
        Fop {
            state: FopState::Initial,
            config: FopConfig {
                window: config.window.clamp(1, cap.max(1)),
                tx_limit: config.tx_limit.max(1),
                ..config
            },
            vs: 0,
            nnr: 0,
            sent: heapless::Vec::new(),
            bc: None,
            wait: None,
            tx_count: 1,
            timer: None,
            suspend_state: 0,
        }
    }

    /// The state.
    pub fn state(&self) -> FopState {
        self.state
    }
    /// V(S): the N(S) of the next new AD frame.
    pub fn vs(&self) -> u8 {
        self.vs
    }
    /// NN(R): the N(S) of the oldest unacknowledged AD frame.
    pub fn nnr(&self) -> u8 {
        self.nnr
    }
    /// AD frames on the sent queue.
    pub fn sent_len(&self) -> usize {
        self.sent.len()
    }
    /// Whether an FDU waits in the wait queue.
    pub fn waiting(&self) -> bool {
        self.wait.is_some()
    }
    /// The transmission count.
    pub fn tx_count(&self) -> u8 {
        self.tx_count
    }
    /// The parameters.
    pub fn config(&self) -> FopConfig {
        self.config
    }
    /// 0, or the state a suspend left.
    pub fn suspend_state(&self) -> u8 {
        self.suspend_state
    }
    /// When T1 runs out, if it runs.
    pub fn timer_deadline(&self) -> Option<u32> {
        self.timer.map(|t| t.wrapping_add(self.config.t1_ms))
    }

    // ------------------------------------------------------------------ inputs

    /// "Request to transfer FDU" (E19, E20): `Ok` if taken into the wait queue (and sent at
    /// once if the window and the state allow); `Err(fdu)` back if rejected (the wait queue
    /// full, or the AD service not running).
    pub fn transfer_ad(
        &mut self,
        fdu: P,
        now_ms: u32,
        out: &mut impl FnMut(FopOutput<P>),
    ) -> Result<(), P> {
        use FopState::*;
        if self.wait.is_some() {
            return Err(fdu); // E20
        }
        match self.state {
            Active | RetransmitWithoutWait => {
                self.wait = Some(fdu);
                self.look_for_fdu(now_ms, out);
                Ok(())
            }
            RetransmitWithWait => {
                self.wait = Some(fdu);
                Ok(())
            }
            InitialisingWithoutBc | InitialisingWithBc | Initial => Err(fdu),
        }
    }

    /// "Request to transfer FDU" on the expedited service (E21): a BD frame, sent whatever
    /// the state.
    pub fn transfer_bd(&mut self, fdu: P, out: &mut impl FnMut(FopOutput<P>)) {
        out(FopOutput::Transmit(FopFrame {
            kind: FrameKind::Bd,
            ns: 0,
            data: FrameData::Fdu(fdu),
        }));
    }

    /// Timer T1 (E16–E18, E104): call with the time as often as convenient; when T1 has run
    /// out since it was last (re)started, the expiry is handled once.
    pub fn tick(&mut self, now_ms: u32, out: &mut impl FnMut(FopOutput<P>)) {
        let Some(start) = self.timer else { return };
        if now_ms.wrapping_sub(start) < self.config.t1_ms {
            return;
        }
        self.timer = None;
        self.timer_expired(now_ms, out);
    }

    /// T1 runs out now, whatever the time (E16–E18, E104); nothing if it is not running.
    /// For model checks, where expiry is a nondeterministic step.
    pub fn expire_timer(&mut self, now_ms: u32, out: &mut impl FnMut(FopOutput<P>)) {
        if self.timer.take().is_some() {
            self.timer_expired(now_ms, out);
        }
    }

    fn timer_expired(&mut self, now_ms: u32, out: &mut impl FnMut(FopOutput<P>)) {
        use FopState::*;
        let below_limit = self.tx_count < self.config.tx_limit;
        let suspend = self.config.timeout_type == TimeoutType::Suspend;
        match self.state {
            Active | RetransmitWithoutWait if below_limit => {
                // E16 / E104.
                self.initiate_ad_retransmission(now_ms);
                self.look_for_fdu(now_ms, out);
            }
            RetransmitWithWait if below_limit => {}
            Active | RetransmitWithoutWait | RetransmitWithWait => {
                if suspend {
                    self.suspend(out);
                } else {
                    self.alert(AlertCode::T1, out);
                }
            }
            InitialisingWithoutBc => {
                if suspend {
                    self.suspend(out);
                } else {
                    self.alert(AlertCode::T1, out);
                }
            }
            InitialisingWithBc if below_limit => {
                // Initiate BC retransmission, look for directive.
                self.tx_count = self.tx_count.saturating_add(1);
                self.timer = Some(now_ms);
                if let Some((c, _)) = self.bc {
                    self.bc = Some((c, false));
                    out(FopOutput::Transmit(FopFrame {
                        kind: FrameKind::Bc,
                        ns: 0,
                        data: FrameData::Control(c),
                    }));
                }
            }
            InitialisingWithBc => self.alert(AlertCode::T1, out),
            Initial => {}
        }
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::link::clcw::Clcw;
    use std::vec::Vec;

    type F = Fop<u8, 10>;

    fn run<R>(f: impl FnOnce(&mut dyn FnMut(FopOutput<u8>)) -> R) -> (R, Vec<FopOutput<u8>>) {
        let mut v = Vec::new();
        let r = f(&mut |o| v.push(o));
        (r, v)
    }

    fn clcw(nr: u8) -> Clcw {
        Clcw {
            report_value: nr,
            ..Clcw::default()
        }
    }

    fn sent_ns(outs: &[FopOutput<u8>]) -> Vec<u8> {
        outs.iter()
            .filter_map(|o| match o {
                FopOutput::Transmit(FopFrame {
                    kind: FrameKind::Ad,
                    ns,
                    ..
                }) => Some(*ns),
                _ => None,
            })
            .collect()
    }

    fn active(config: FopConfig) -> F {
        let mut f = F::new(config);
        let (r, _) = run(|o| f.directive(Directive::InitiateWithoutClcw, 0, &mut |x| o(x)));
        assert_eq!(r, DirectiveResponse::Confirmed);
        f
    }

    fn small() -> FopConfig {
        FopConfig {
            window: 3,
            t1_ms: 100,
            tx_limit: 3,
            timeout_type: TimeoutType::Alert,
            restart_t1_after_wait: true,
        }
    }

    // req: 232.1-B-2/FOP-2, 232.1-B-2/FOP-4
    #[test]
    fn window_full_holds_the_fdu_until_an_acknowledgement() {
        let mut f = active(small());
        let mut outs = Vec::new();
        for p in 0..3u8 {
            assert_eq!(f.transfer_ad(p, 0, &mut |o| outs.push(o)), Ok(()));
        }
        assert_eq!(sent_ns(&outs), [0, 1, 2]);
        // Window full: the fourth waits, the fifth is rejected.
        assert_eq!(f.transfer_ad(3, 0, &mut |o| outs.push(o)), Ok(()));
        assert_eq!(f.transfer_ad(4, 0, &mut |o| outs.push(o)), Err(4));
        assert_eq!(sent_ns(&outs), [0, 1, 2]);
        assert!(f.waiting());
        // N(R) = 2: two acknowledged, the waiting one goes out as N(S) = 3.
        outs.clear();
        f.clcw(&clcw(2), 10, &mut |o| outs.push(o));
        assert_eq!(
            outs[..2],
            [
                FopOutput::Confirmed { ns: 0 },
                FopOutput::Confirmed { ns: 1 }
            ]
        );
        assert_eq!(sent_ns(&outs), [3]);
        assert_eq!((f.nnr(), f.vs(), f.sent_len()), (2, 4, 2));
    }

    // req: 232.1-B-2/FOP-7
    #[test]
    fn retransmit_flag_resends_everything_outstanding() {
        let mut f = active(small());
        let mut outs = Vec::new();
        for p in 0..3u8 {
            f.transfer_ad(p, 0, &mut |o| outs.push(o)).unwrap();
        }
        outs.clear();
        // FARM-1 has 0, lost 1, saw 2: N(R) = 1 with Retransmit.
        let c = Clcw {
            retransmit: true,
            ..clcw(1)
        };
        assert_eq!(f.classify(&c), ClcwEvent::E8);
        f.clcw(&c, 5, &mut |o| outs.push(o));
        assert_eq!(f.state(), FopState::RetransmitWithoutWait);
        assert_eq!(sent_ns(&outs), [1, 2]);
        assert_eq!(f.tx_count(), 2);
        // All acknowledged: back to Active, timer stopped.
        outs.clear();
        f.clcw(&clcw(3), 6, &mut |o| outs.push(o));
        assert_eq!(f.state(), FopState::Active);
        assert_eq!(f.timer_deadline(), None);
    }

    // req: 232.1-B-2/FOP-5, 232.1-B-2/FOP-6, 232.1-B-2/FOP-11
    #[test]
    fn timer_expiry_retransmits_until_the_limit_then_alerts() {
        let mut f = active(small());
        let mut outs = Vec::new();
        f.transfer_ad(7, 0, &mut |o| outs.push(o)).unwrap();
        assert_eq!(f.timer_deadline(), Some(100));
        outs.clear();
        f.tick(99, &mut |o| outs.push(o));
        assert!(outs.is_empty());
        f.tick(100, &mut |o| outs.push(o));
        assert_eq!(sent_ns(&outs), [0]);
        assert_eq!(f.tx_count(), 2);
        f.tick(200, &mut |o| outs.push(o));
        assert_eq!(f.tx_count(), 3);
        outs.clear();
        f.tick(300, &mut |o| outs.push(o));
        assert_eq!(
            outs,
            [
                FopOutput::NegativeConfirm { ns: 0, fdu: 7 },
                FopOutput::Alert(AlertCode::T1)
            ]
        );
        assert_eq!(f.state(), FopState::Initial);
    }

    // req: 232.1-B-2/FOP-6, 232.1-B-2/FOP-9
    #[test]
    fn timeout_type_1_suspends_and_resume_takes_up() {
        let mut f = active(FopConfig {
            timeout_type: TimeoutType::Suspend,
            tx_limit: 1,
            ..small()
        });
        let mut outs = Vec::new();
        f.transfer_ad(7, 0, &mut |o| outs.push(o)).unwrap();
        outs.clear();
        f.tick(100, &mut |o| outs.push(o));
        assert_eq!(outs, [FopOutput::Suspended]);
        assert_eq!(
            (f.state(), f.suspend_state(), f.sent_len()),
            (FopState::Initial, 1, 1)
        );
        assert_eq!(
            f.directive(Directive::SetVs(3), 0, &mut |o| outs.push(o)),
            DirectiveResponse::Rejected
        );
        assert_eq!(
            f.directive(Directive::Resume, 150, &mut |o| outs.push(o)),
            DirectiveResponse::Confirmed
        );
        assert_eq!(f.state(), FopState::Active);
        assert_eq!(f.timer_deadline(), Some(250));
        f.clcw(&clcw(1), 160, &mut |o| outs.push(o));
        assert_eq!(f.sent_len(), 0);
    }

    /// Suspended while retransmitting with wait (S3, suspend state 3), resume takes S3 up
    /// again (E29's row for that state).
    // req: 232.1-B-2/FOP-6, 232.1-B-2/FOP-9
    #[test]
    fn resume_takes_up_retransmit_with_wait() {
        let mut f = active(FopConfig {
            timeout_type: TimeoutType::Suspend,
            tx_limit: 2,
            ..small()
        });
        let mut outs = Vec::new();
        f.transfer_ad(7, 0, &mut |o| outs.push(o)).unwrap();
        // Retransmit (E10: the second and last transmission, T1 from 10), then wait with the
        // limit reached (E103): S3, where T1's expiry suspends.
        let retransmit = Clcw {
            retransmit: true,
            ..clcw(0)
        };
        f.clcw(&retransmit, 10, &mut |o| outs.push(o));
        assert_eq!(f.state(), FopState::RetransmitWithoutWait);
        let waiting = Clcw {
            wait: true,
            ..retransmit
        };
        f.clcw(&waiting, 20, &mut |o| outs.push(o));
        assert_eq!(f.state(), FopState::RetransmitWithWait);
        outs.clear();
        f.tick(110, &mut |o| outs.push(o));
        assert_eq!(outs, [FopOutput::Suspended]);
        assert_eq!((f.state(), f.suspend_state()), (FopState::Initial, 3));
        assert_eq!(
            f.directive(Directive::Resume, 150, &mut |o| outs.push(o)),
            DirectiveResponse::Confirmed
        );
        assert_eq!(
            (f.state(), f.suspend_state(), f.timer_deadline()),
            (FopState::RetransmitWithWait, 0, Some(250))
        );
    }

    // req: 232.1-B-2/FOP-8, 232.1-B-2/FOP-11
    #[test]
    fn lockout_alerts_and_unlock_recovers() {
        let mut f = active(small());
        let mut outs = Vec::new();
        f.transfer_ad(1, 0, &mut |o| outs.push(o)).unwrap();
        outs.clear();
        let locked = Clcw {
            lockout: true,
            ..clcw(0)
        };
        f.clcw(&locked, 1, &mut |o| outs.push(o));
        assert_eq!(
            outs,
            [
                FopOutput::NegativeConfirm { ns: 0, fdu: 1 },
                FopOutput::Alert(AlertCode::Lockout)
            ]
        );
        // Initiate with Unlock: the BC frame, then the CLCW that shows FARM-1 open and
        // expecting V(S) — after Set V(S) to FARM-1's V(R).
        outs.clear();
        assert_eq!(
            f.directive(Directive::SetVs(0), 2, &mut |o| outs.push(o)),
            DirectiveResponse::Confirmed
        );
        assert_eq!(
            f.directive(Directive::InitiateWithUnlock, 2, &mut |o| outs.push(o)),
            DirectiveResponse::Accepted
        );
        assert_eq!(
            outs,
            [FopOutput::Transmit(FopFrame {
                kind: FrameKind::Bc,
                ns: 0,
                data: FrameData::Control(ControlCommand::Unlock)
            })]
        );
        assert_eq!(f.state(), FopState::InitialisingWithBc);
        // Still locked (Unlock not yet there): ignored. T1: the BC frame again.
        outs.clear();
        f.clcw(&locked, 3, &mut |o| outs.push(o));
        assert!(outs.is_empty());
        f.tick(102, &mut |o| outs.push(o));
        assert_eq!(outs.len(), 1);
        outs.clear();
        f.clcw(&clcw(0), 104, &mut |o| outs.push(o));
        assert_eq!(outs, [FopOutput::InitiateConfirmed]);
        assert_eq!(f.state(), FopState::Active);
    }

    // req: 232.1-B-2/FOP-8, 232.1-B-2/FOP-9, 232.1-B-2/FOP-11
    #[test]
    fn initiate_with_clcw_and_with_set_vr() {
        let mut f = F::new(small());
        let mut outs = Vec::new();
        assert_eq!(f.transfer_ad(1, 0, &mut |o| outs.push(o)), Err(1));
        assert_eq!(
            f.directive(Directive::InitiateWithClcw, 0, &mut |o| outs.push(o)),
            DirectiveResponse::Accepted
        );
        assert_eq!(f.state(), FopState::InitialisingWithoutBc);
        // A CLCW with Wait: alert CLCW.
        f.clcw(
            &Clcw {
                wait: true,
                ..clcw(0)
            },
            1,
            &mut |o| outs.push(o),
        );
        assert_eq!(outs, [FopOutput::Alert(AlertCode::Clcw)]);
        outs.clear();
        f.directive(Directive::InitiateWithClcw, 2, &mut |o| outs.push(o));
        f.clcw(&clcw(0), 3, &mut |o| outs.push(o));
        assert_eq!(outs, [FopOutput::InitiateConfirmed]);
        // Terminate, then Set V(R) 200.
        outs.clear();
        f.directive(Directive::Terminate, 4, &mut |o| outs.push(o));
        assert_eq!(outs, [FopOutput::Alert(AlertCode::Term)]);
        outs.clear();
        f.directive(Directive::InitiateWithSetVr(200), 5, &mut |o| outs.push(o));
        assert_eq!((f.vs(), f.nnr()), (200, 200));
        assert!(matches!(
            outs[0],
            FopOutput::Transmit(FopFrame {
                data: FrameData::Control(ControlCommand::SetVr(200)),
                ..
            })
        ));
        // The BC frame's retransmissions run to the limit, then T1.
        outs.clear();
        f.tick(105, &mut |o| outs.push(o));
        f.tick(205, &mut |o| outs.push(o));
        f.tick(305, &mut |o| outs.push(o));
        assert_eq!(outs.len(), 3);
        assert_eq!(outs[2], FopOutput::Alert(AlertCode::T1));
    }

    /// T1 runs out in Retransmit with Wait (ignored: T1 stops); FARM-1 then accepts a late
    /// copy of N(S) = 0, which clears its Retransmit flag, and reports N(R) = 1 with no flag.
    /// FOP-1 goes back to Active with N(S) = 1 unacknowledged: with the table as written
    /// nothing will ever send it again; with `restart_t1_after_wait` T1 does.
    #[test]
    fn leaving_wait_restarts_t1_for_what_is_left() {
        for restart in [false, true] {
            let mut f = active(FopConfig {
                restart_t1_after_wait: restart,
                ..small()
            });
            let mut outs = Vec::new();
            f.transfer_ad(0, 0, &mut |o| outs.push(o)).unwrap();
            f.transfer_ad(1, 0, &mut |o| outs.push(o)).unwrap();
            let waiting = Clcw {
                retransmit: true,
                wait: true,
                ..clcw(0)
            };
            f.clcw(&waiting, 1, &mut |o| outs.push(o));
            assert_eq!(f.state(), FopState::RetransmitWithWait);
            f.tick(100, &mut |o| outs.push(o));
            assert_eq!(f.timer_deadline(), None);
            f.clcw(&clcw(1), 200, &mut |o| outs.push(o));
            assert_eq!((f.state(), f.sent_len()), (FopState::Active, 1));
            assert_eq!(f.timer_deadline(), restart.then_some(300));
            outs.clear();
            f.tick(300, &mut |o| outs.push(o));
            assert_eq!(sent_ns(&outs), if restart { &[1][..] } else { &[][..] });
        }
    }

    // req: 232.1-B-2/FOP-1, 232.1-B-2/FOP-3
    #[test]
    fn clcw_events_are_classified_as_table_5_1_says() {
        let mut f = active(FopConfig {
            window: 5,
            ..small()
        });
        let mut outs = Vec::new();
        for p in 0..3 {
            f.transfer_ad(p, 0, &mut |o| outs.push(o)).unwrap();
        }
        // NN(R) = 0, V(S) = 3.
        let c = |nr: u8, r: bool, w: bool| Clcw {
            retransmit: r,
            wait: w,
            ..clcw(nr)
        };
        use ClcwEvent::*;
        assert_eq!(f.classify(&c(3, false, false)), E2);
        assert_eq!(f.classify(&c(3, false, true)), E3);
        assert_eq!(f.classify(&c(3, true, false)), E4);
        assert_eq!(f.classify(&c(0, false, false)), E5);
        assert_eq!(f.classify(&c(1, false, false)), E6);
        assert_eq!(f.classify(&c(1, false, true)), E7);
        assert_eq!(f.classify(&c(1, true, false)), E8);
        assert_eq!(f.classify(&c(1, true, true)), E9);
        assert_eq!(f.classify(&c(0, true, false)), E10);
        assert_eq!(f.classify(&c(0, true, true)), E11);
        assert_eq!(f.classify(&c(4, false, false)), E13);
        assert_eq!(f.classify(&c(255, false, false)), E13);
        assert_eq!(
            f.classify(&Clcw {
                lockout: true,
                ..c(0, false, false)
            }),
            E14
        );
        // Wait flag with Retransmit and no progress: to Retransmit with Wait, no sending.
        outs.clear();
        f.clcw(&c(0, true, true), 1, &mut |o| outs.push(o));
        assert_eq!(f.state(), FopState::RetransmitWithWait);
        assert!(outs.is_empty());
        // Requests wait; the Wait lifted with progress: acknowledged, back to Active.
        assert_eq!(f.transfer_ad(9, 2, &mut |o| outs.push(o)), Ok(()));
        assert!(sent_ns(&outs).is_empty());
        f.clcw(&c(1, false, false), 3, &mut |o| outs.push(o));
        assert_eq!(f.state(), FopState::Active);
        assert_eq!(sent_ns(&outs), [3]);
    }

    /// An Initiate or a Resume directive outside Initial (S6) is rejected and changes
    /// nothing.
    #[test]
    fn initiate_and_resume_outside_initial_are_rejected() {
        let mut f = active(small());
        let mut outs = Vec::new();
        for d in [
            Directive::InitiateWithSetVr(5),
            Directive::InitiateWithoutClcw,
            Directive::Resume,
        ] {
            assert_eq!(
                f.directive(d, 0, &mut |o| outs.push(o)),
                DirectiveResponse::Rejected,
                "{d:?}"
            );
        }
        assert!(outs.is_empty());
        assert_eq!((f.state(), f.vs()), (FopState::Active, 0));
    }

    /// The alerts go by the standard's names.
    #[test]
    fn alerts_go_by_the_standards_names() {
        let names = [
            AlertCode::Limit,
            AlertCode::T1,
            AlertCode::Lockout,
            AlertCode::Synch,
            AlertCode::NnR,
            AlertCode::Clcw,
            AlertCode::Term,
        ]
        .map(AlertCode::name);
        assert_eq!(
            names,
            ["LIMIT", "T1", "LOCKOUT", "SYNCH", "NN(R)", "CLCW", "TERM"]
        );
    }
}
