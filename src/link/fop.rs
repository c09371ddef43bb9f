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

use super::clcw::Clcw;
use super::{ControlCommand, FrameKind};

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
    /// the remaining frames again (the COP-1 model in host/tests/protocol/cop1.rs finds the
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

/// A FOP-1 directive from the ground's operator or software (232.1-B-2 §5.1.11).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "kebab-case"))]
pub enum Directive {
    /// E23: start at once, V(S) as it is.
    InitiateWithoutClcw,
    /// E24: start when a CLCW shows FARM-1 expecting V(S), with no flag set.
    InitiateWithClcw,
    /// E25: send an Unlock and start when a CLCW shows it obeyed.
    InitiateWithUnlock,
    /// E27: V(S) := v, send Set V(R) to v and start when a CLCW shows it obeyed.
    InitiateWithSetVr(u8),
    /// E29: stop the AD service (an alert "terminated" if it was running).
    Terminate,
    /// E30–E34: take up a suspended AD service.
    Resume,
    /// E35: V(S) := NN(R) := v (only in Initial, not suspended).
    SetVs(u8),
    /// E36: the sliding window K.
    SetWindow(u8),
    /// E37: T1.
    SetT1(u32),
    /// E38: the transmission limit.
    SetTxLimit(u8),
    /// E39: the timeout type.
    SetTimeoutType(TimeoutType),
}

/// FOP-1's answer to a directive (232.1-B-2 §5.2: "Accept", "Reject", "Positive Confirm").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "kebab-case"))]
pub enum DirectiveResponse {
    /// Accepted and done.
    Confirmed,
    /// Accepted; [`FopOutput::InitiateConfirmed`] (or an alert) follows.
    Accepted,
    /// Not allowed in the present state (or a parameter out of range).
    Rejected,
}

/// Why FOP-1 stopped the AD service (232.1-B-2 §5.2.x "Alert" reason codes).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "kebab-case"))]
pub enum AlertCode {
    /// "LIMIT": Retransmit reported with the transmission limit reached.
    Limit,
    /// "T1": the timer ran out with the transmission count at the limit.
    T1,
    /// "LOCKOUT": the CLCW reports FARM-1 in Lockout.
    Lockout,
    /// "SYNCH": the CLCW's flags contradict what FOP-1 sent.
    Synch,
    /// "NN(R)": N(R) outside NN(R)..=V(S).
    NnR,
    /// "CLCW": the Wait flag where the state does not allow it.
    Clcw,
    /// "TERM": a Terminate directive.
    Term,
}

impl AlertCode {
    /// The standard's code.
    pub const fn name(self) -> &'static str {
        match self {
            AlertCode::Limit => "LIMIT",
            AlertCode::T1 => "T1",
            AlertCode::Lockout => "LOCKOUT",
            AlertCode::Synch => "SYNCH",
            AlertCode::NnR => "NN(R)",
            AlertCode::Clcw => "CLCW",
            AlertCode::Term => "TERM",
        }
    }
}

/// What a frame carries.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "kebab-case"))]
pub enum FrameData<P> {
    /// An FDU (AD or BD frame).
    Fdu(P),
    /// A control command (BC frame).
    Control(ControlCommand),
}

/// A frame for the transport: its kind, its N(S) (0 for BD and BC frames, 232.0-B-4
/// §4.1.2.7.3) and its data.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct FopFrame<P> {
    /// AD, BD or BC.
    pub kind: FrameKind,
    /// N(S).
    pub ns: u8,
    /// FDU or control command.
    pub data: FrameData<P>,
}

/// Everything FOP-1 tells its users.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "kebab-case"))]
pub enum FopOutput<P> {
    /// Send this frame (a first transmission or a retransmission).
    Transmit(FopFrame<P>),
    /// The AD frame N(S) = `ns` was acknowledged ("Positive Confirm").
    Confirmed {
        /// Its N(S).
        ns: u8,
    },
    /// The AD frame N(S) = `ns` was purged unacknowledged ("Negative Confirm"): FARM-1 may or
    /// may not have it.
    NegativeConfirm {
        /// Its N(S).
        ns: u8,
    },
    /// An FDU of the wait queue was purged, never sent ("Reject").
    Rejected(P),
    /// The pending initiate directive completed: the AD service runs.
    InitiateConfirmed,
    /// The AD service stopped ("Alert").
    Alert(AlertCode),
    /// The AD service was suspended (timeout type 1); [`Directive::Resume`] takes it up.
    Suspended,
}

/// The event numbers of a CLCW's arrival (232.1-B-2 Table 5-1, numbering of dariol83/ccsds).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[allow(missing_docs)]
pub enum ClcwEvent {
    /// N(R) = V(S) = NN(R), no flag: nothing outstanding, nothing new.
    E1,
    /// N(R) = V(S) ≠ NN(R), no flag: everything outstanding acknowledged.
    E2,
    /// N(R) = V(S), Wait without Retransmit.
    E3,
    /// N(R) = V(S), Retransmit.
    E4,
    /// NN(R) ≤ N(R) < V(S), no flag, N(R) = NN(R): no progress yet.
    E5,
    /// NN(R) < N(R) < V(S), no flag: some acknowledged.
    E6,
    /// NN(R) ≤ N(R) < V(S), Wait without Retransmit.
    E7,
    /// Retransmit, limit 1, N(R) ≠ NN(R).
    E101,
    /// Retransmit, limit 1, N(R) = NN(R).
    E102,
    /// Retransmit, N(R) ≠ NN(R), no Wait.
    E8,
    /// Retransmit, N(R) ≠ NN(R), Wait.
    E9,
    /// Retransmit, N(R) = NN(R), count < limit, no Wait.
    E10,
    /// Retransmit, N(R) = NN(R), count < limit, Wait.
    E11,
    /// Retransmit, N(R) = NN(R), count ≥ limit, no Wait.
    E12,
    /// Retransmit, N(R) = NN(R), count ≥ limit, Wait.
    E103,
    /// N(R) outside NN(R)..=V(S).
    E13,
    /// Lockout.
    E14,
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
        let cap = if K > 255 { 255 } else { K as u8 };
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

    /// A directive (E23–E39).
    pub fn directive(
        &mut self,
        d: Directive,
        now_ms: u32,
        out: &mut impl FnMut(FopOutput<P>),
    ) -> DirectiveResponse {
        use DirectiveResponse::*;
        use FopState::*;
        let initial = self.state == Initial;
        match d {
            Directive::InitiateWithoutClcw if initial => {
                self.initialise(out);
                self.state = Active;
                Confirmed
            }
            Directive::InitiateWithClcw if initial => {
                self.initialise(out);
                self.timer = Some(now_ms);
                self.state = InitialisingWithoutBc;
                Accepted
            }
            Directive::InitiateWithUnlock if initial => {
                self.initialise(out);
                self.transmit_bc(ControlCommand::Unlock, now_ms, out);
                self.state = InitialisingWithBc;
                Accepted
            }
            Directive::InitiateWithSetVr(v) if initial => {
                self.initialise(out);
                self.vs = v;
                self.nnr = v;
                self.transmit_bc(ControlCommand::SetVr(v), now_ms, out);
                self.state = InitialisingWithBc;
                Accepted
            }
            Directive::InitiateWithoutClcw
            | Directive::InitiateWithClcw
            | Directive::InitiateWithUnlock
            | Directive::InitiateWithSetVr(_) => Rejected,
            Directive::Terminate => {
                if !initial {
                    self.alert(AlertCode::Term, out);
                }
                Confirmed
            }
            Directive::Resume => {
                let to = match self.suspend_state {
                    1 => Active,
                    2 => RetransmitWithoutWait,
                    3 => RetransmitWithWait,
                    4 => InitialisingWithoutBc,
                    _ => return Rejected, // E30
                };
                if !initial {
                    return Rejected;
                }
                self.timer = Some(now_ms);
                self.suspend_state = 0;
                self.state = to;
                Confirmed
            }
            Directive::SetVs(v) => {
                if initial && self.suspend_state == 0 {
                    self.vs = v;
                    self.nnr = v;
                    Confirmed
                } else {
                    Rejected
                }
            }
            Directive::SetWindow(k) => {
                if k >= 1 && (k as usize) <= K {
                    self.config.window = k;
                    Confirmed
                } else {
                    Rejected
                }
            }
            Directive::SetT1(t) => {
                self.config.t1_ms = t;
                Confirmed
            }
            Directive::SetTxLimit(n) => {
                if n >= 1 {
                    self.config.tx_limit = n;
                    Confirmed
                } else {
                    Rejected
                }
            }
            Directive::SetTimeoutType(t) => {
                self.config.timeout_type = t;
                Confirmed
            }
        }
    }

    /// Which event of Table 5-1 a CLCW is, in the present variables (232.1-B-2 §5.3).
    pub fn classify(&self, clcw: &Clcw) -> ClcwEvent {
        use ClcwEvent::*;
        let nr = clcw.report_value;
        let (r, w) = (clcw.retransmit, clcw.wait);
        if clcw.lockout {
            return E14;
        }
        if nr == self.vs {
            return match (r, w) {
                (false, false) if nr == self.nnr => E1,
                (false, false) => E2,
                (false, true) => E3,
                (true, _) => E4,
            };
        }
        // NN(R) ≤ N(R) < V(S), modulo 256 (V(S) − NN(R) ≤ K < 256).
        let outstanding = self.vs.wrapping_sub(self.nnr);
        if nr.wrapping_sub(self.nnr) >= outstanding {
            return E13;
        }
        let progress = nr != self.nnr;
        match (r, w) {
            (false, false) if progress => E6,
            (false, false) => E5,
            (false, true) => E7,
            (true, _) if self.config.tx_limit == 1 => {
                if progress {
                    E101
                } else {
                    E102
                }
            }
            (true, false) if progress => E8,
            (true, true) if progress => E9,
            (true, false) if self.tx_count < self.config.tx_limit => E10,
            (true, true) if self.tx_count < self.config.tx_limit => E11,
            (true, false) => E12,
            (true, true) => E103,
        }
    }

    /// A CLCW arrived for this virtual channel (E1–E14, E101–E103). The caller checks its
    /// VCID (and [`Clcw::parse`] its COP).
    pub fn clcw(&mut self, clcw: &Clcw, now_ms: u32, out: &mut impl FnMut(FopOutput<P>)) {
        use ClcwEvent::*;
        use FopState::*;
        let ev = self.classify(clcw);
        let nr = clcw.report_value;
        let from = self.state;
        match (self.state, ev) {
            (Initial, _) => {}
            // Active, and the two retransmit states.
            (Active | RetransmitWithoutWait | RetransmitWithWait, _) => match ev {
                E1 | E5 if self.state == Active => {}
                E1 | E4 | E5 => self.alert(AlertCode::Synch, out),
                E2 => {
                    self.remove_acknowledged(nr, out);
                    self.timer = None;
                    self.state = Active;
                    self.look_for_fdu(now_ms, out);
                }
                E3 | E7 => self.alert(AlertCode::Clcw, out),
                E6 => {
                    self.remove_acknowledged(nr, out);
                    self.state = Active;
                    self.look_for_fdu(now_ms, out);
                }
                E101 => {
                    self.remove_acknowledged(nr, out);
                    self.alert(AlertCode::Limit, out);
                }
                E102 => self.alert(AlertCode::Limit, out),
                E8 => {
                    self.remove_acknowledged(nr, out);
                    self.initiate_ad_retransmission(now_ms);
                    self.state = RetransmitWithoutWait;
                    self.look_for_fdu(now_ms, out);
                }
                E9 => {
                    self.remove_acknowledged(nr, out);
                    self.state = RetransmitWithWait;
                }
                E10 if self.state == RetransmitWithoutWait => {}
                E10 => {
                    self.initiate_ad_retransmission(now_ms);
                    self.state = RetransmitWithoutWait;
                    self.look_for_fdu(now_ms, out);
                }
                E11 | E103 => self.state = RetransmitWithWait,
                E12 if self.state == RetransmitWithoutWait => {}
                E12 => self.state = RetransmitWithoutWait,
                E13 => self.alert(AlertCode::NnR, out),
                E14 => self.alert(AlertCode::Lockout, out),
            },
            (InitialisingWithoutBc, E1) => {
                self.timer = None;
                self.state = Active;
                out(FopOutput::InitiateConfirmed);
            }
            (InitialisingWithoutBc, E3) => self.alert(AlertCode::Clcw, out),
            (InitialisingWithoutBc, E4) => self.alert(AlertCode::Synch, out),
            (InitialisingWithoutBc, E13) => self.alert(AlertCode::NnR, out),
            (InitialisingWithoutBc, E14) => self.alert(AlertCode::Lockout, out),
            (InitialisingWithBc, E1) => {
                self.bc = None; // "release copy of the BC frame"
                self.timer = None;
                self.state = Active;
                out(FopOutput::InitiateConfirmed);
            }
            (InitialisingWithBc, E3) => self.alert(AlertCode::Clcw, out),
            // Every other CLCW in S4 and S5 is ignored (in S5 a Lockout or Retransmit may
            // still show until FARM-1 has the BC frame).
            (InitialisingWithoutBc | InitialisingWithBc, _) => {}
        }
        if self.config.restart_t1_after_wait
            && from == RetransmitWithWait
            && matches!(self.state, Active | RetransmitWithoutWait)
            && !self.sent.is_empty()
            && self.timer.is_none()
        {
            self.timer = Some(now_ms);
        }
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

    // ------------------------------------------------------------------ actions (§5.2)

    fn state_number(&self) -> u8 {
        match self.state {
            FopState::Active => 1,
            FopState::RetransmitWithoutWait => 2,
            FopState::RetransmitWithWait => 3,
            FopState::InitialisingWithoutBc => 4,
            FopState::InitialisingWithBc => 5,
            FopState::Initial => 6,
        }
    }

    /// Negative confirm for each frame of the sent queue, which empties; NN(R) := V(S), so
    /// that V(S) − NN(R) stays the sent queue's length (NN(R) is the oldest frame on it, and
    /// with none the next one; YAMCS's `purgeSentQueue` does the same, dariol83/ccsds leaves
    /// NN(R) behind, after which no CLCW can acknowledge anything).
    fn purge_sent_queue(&mut self, out: &mut impl FnMut(FopOutput<P>)) {
        for s in self.sent.iter() {
            out(FopOutput::NegativeConfirm { ns: s.ns });
        }
        self.sent.clear();
        self.bc = None;
        self.nnr = self.vs;
    }

    fn purge_wait_queue(&mut self, out: &mut impl FnMut(FopOutput<P>)) {
        if let Some(p) = self.wait.take() {
            out(FopOutput::Rejected(p));
        }
    }

    fn initialise(&mut self, out: &mut impl FnMut(FopOutput<P>)) {
        self.purge_sent_queue(out);
        self.purge_wait_queue(out);
        self.tx_count = 1;
        self.suspend_state = 0;
        self.timer = None;
    }

    fn alert(&mut self, code: AlertCode, out: &mut impl FnMut(FopOutput<P>)) {
        self.timer = None;
        self.purge_sent_queue(out);
        self.purge_wait_queue(out);
        out(FopOutput::Alert(code));
        self.state = FopState::Initial;
    }

    fn suspend(&mut self, out: &mut impl FnMut(FopOutput<P>)) {
        self.suspend_state = self.state_number();
        out(FopOutput::Suspended);
        self.state = FopState::Initial;
    }

    /// Positive confirm for each frame N(R) acknowledges; NN(R) := N(R); count := 1.
    fn remove_acknowledged(&mut self, nr: u8, out: &mut impl FnMut(FopOutput<P>)) {
        while self.nnr != nr && !self.sent.is_empty() {
            let s = self.sent.remove(0);
            out(FopOutput::Confirmed { ns: s.ns });
            self.nnr = self.nnr.wrapping_add(1);
            self.tx_count = 1;
        }
    }

    fn initiate_ad_retransmission(&mut self, now_ms: u32) {
        self.tx_count = self.tx_count.saturating_add(1);
        self.timer = Some(now_ms);
        for s in self.sent.iter_mut() {
            s.to_be_retransmitted = true;
        }
    }

    fn transmit_bc(&mut self, c: ControlCommand, now_ms: u32, out: &mut impl FnMut(FopOutput<P>)) {
        self.bc = Some((c, false));
        self.tx_count = 1;
        self.timer = Some(now_ms);
        out(FopOutput::Transmit(FopFrame {
            kind: FrameKind::Bc,
            ns: 0,
            data: FrameData::Control(c),
        }));
    }

    /// "Look for FDU" with a transport that is always ready: every frame marked for
    /// retransmission, then the wait queue's FDU if V(S) < NN(R) + K.
    fn look_for_fdu(&mut self, now_ms: u32, out: &mut impl FnMut(FopOutput<P>)) {
        for s in self.sent.iter_mut().filter(|s| s.to_be_retransmitted) {
            s.to_be_retransmitted = false;
            out(FopOutput::Transmit(FopFrame {
                kind: FrameKind::Ad,
                ns: s.ns,
                data: FrameData::Fdu(s.fdu.clone()),
            }));
        }
        let in_window = self.vs.wrapping_sub(self.nnr) < self.config.window;
        if !in_window || self.sent.is_full() {
            return;
        }
        let Some(fdu) = self.wait.take() else { return };
        // Transmit type-AD frame (§5.2.x): N(S) := V(S), V(S) + 1, on the sent queue.
        let ns = self.vs;
        if self.sent.is_empty() {
            self.tx_count = 1;
        }
        if let Err(s) = self.sent.push(Sent {
            ns,
            fdu: fdu.clone(),
            to_be_retransmitted: false,
        }) {
            self.wait = Some(s.fdu); // cannot happen: checked not full
            return;
        }
        self.vs = self.vs.wrapping_add(1);
        self.timer = Some(now_ms);
        out(FopOutput::Transmit(FopFrame {
            kind: FrameKind::Ad,
            ns,
            data: FrameData::Fdu(fdu),
        }));
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
                FopOutput::NegativeConfirm { ns: 0 },
                FopOutput::Alert(AlertCode::T1)
            ]
        );
        assert_eq!(f.state(), FopState::Initial);
    }

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
                FopOutput::NegativeConfirm { ns: 0 },
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
}
