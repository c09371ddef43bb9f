//! The ground's end of the space data link, for the simulator's ground and the tests (the real
//! ground is YAMCS, configured alike: ground/yamcs/links/frames.yaml): telecommand packets go
//! out in TC transfer frames under FOP-1, TM transfer frames come in, their CLCW goes to FOP-1
//! and their packets out of the [`Extractor`].
//!
//! The link initiates the AD service with a CLCW check when it starts (FOP-1 waits for the
//! first CLCW; the server board sends one at least every idle period), and again, with Set
//! V(R) to its own V(S), after every alert (the transmission limit reached, a lockout),
//! preceded by an Unlock when the last CLCW showed FARM-1 in Lockout (which Set V(R) does not
//! leave). The
//! packets of the frames FOP-1 purged then go to the front of the outbox and are sent again:
//! FARM-1 may have passed some of them already, and the gateway's request keys make such a
//! copy harmless (it is answered, never run twice).
//!
//! ```
//! use mmic::link::clcw::Clcw;
//! use mmic::link::tm_frame::{FirstHeaderPointer, TmFrameParams, TmFrameRepr, TM_FRAME_LEN};
//! use mmic::node::ground::frames::GroundLink;
//! use mmic::units::BoardNumber;
//!
//! let mut g: GroundLink<10, 8, 512> = GroundLink::new(BoardNumber::ONE);
//! let mut frames = Vec::new();
//! g.start(0, &mut |f: &[u8]| frames.push(f.to_vec()));
//! // A packet waits until a CLCW confirms the initiation.
//! # use mmic::ccsds::{primary::{Apid, SeqCount}, tc::TcRepr, tc_header::{AckFlags, TcSecondaryHeader}};
//! let mut ping = [0u8; 13];
//! TcRepr { apid: Apid::new(0x101).unwrap(), seq_count: SeqCount::new(0).unwrap(),
//!          header: TcSecondaryHeader { ack: AckFlags::ALL, service: 17, subservice: 1, source_id: 0 },
//!          app_data: &[] }.emit(&mut ping).unwrap();
//! assert!(g.send(&ping, 0, &mut |f: &[u8]| frames.push(f.to_vec())).is_ok());
//! assert!(frames.is_empty());
//! // An idle TM frame carrying FARM-1's CLCW (Open, V(R) = 0).
//! let params = TmFrameParams::mission(0x101).unwrap();
//! let clcw = Clcw::default(); // COP-1 in effect, VC 0, V(R) = 0, no flag
//! let tm = TmFrameRepr { spacecraft_id: 0x101, vcid: 0, mc_frame_count: 0, vc_frame_count: 0,
//!     first_header_pointer: FirstHeaderPointer::OnlyIdleData, data: &[0x55; 244],
//!     ocf: Some(clcw.emit()) };
//! let mut buf = [0u8; TM_FRAME_LEN];
//! tm.emit(&params, &mut buf).unwrap();
//! g.tm_frame(10, &buf, &mut |f: &[u8]| frames.push(f.to_vec()), &mut |_p: &[u8]| {}).unwrap();
//! // Initiated: the ping went out as AD frame N(S) = 0.
//! assert_eq!(frames.len(), 1);
//! assert_eq!(frames[0][4], 0);
//! ```
// req: D:pus-ground-under-cop1

use crate::link::clcw::Clcw;
use crate::link::extract::{ExtractCounters, Extractor};
use crate::link::fop::{
    AlertCode, Directive, Fop, FopConfig, FopFrame, FopOutput, FopState, FrameData,
};
use crate::link::sdls::{self, frames as secured, Key256, SaTable, SdlsCounters, SdlsRefusal};
use crate::link::tc_frame::{self, MapId, SpacecraftId, TcContent, TcFrameRepr, Vcid};
use crate::link::tm_frame::{TmFrameError, TmFrameParams, TmFrameRepr};
use crate::link::{ControlCommand, FrameKind};
use crate::node::ground::pus::MAX_TC_LEN;
use crate::units::BoardNumber;
use heapless::{Deque, Vec};

/// A telecommand packet on its way.
pub type Packet = Vec<u8, MAX_TC_LEN>;

/// The longest TC frame the link writes: headers, one packet, SDLS, FECF.
pub const MAX_FRAME_LEN: usize = tc_frame::TC_PRIMARY_HEADER_LEN
    + tc_frame::SEGMENT_HEADER_LEN
    + MAX_TC_LEN
    + sdls::OVERHEAD
    + tc_frame::FECF_LEN;

/// Why a TM frame went no further than the link.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
pub enum TmRefusal {
    /// A frame check ([`TmFrameError`]).
    #[error(transparent)]
    Frame(#[from] TmFrameError),
    /// SDLS ([`SdlsRefusal`]): neither its packets nor its CLCW were used.
    #[error(transparent)]
    Security(#[from] SdlsRefusal),
}

impl TmRefusal {
    /// The check's name.
    pub const fn name(&self) -> &'static str {
        match self {
            TmRefusal::Frame(e) => e.name(),
            TmRefusal::Security(e) => e.name(),
        }
    }
}

/// What the link did. Each counter wraps at `u32::MAX`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct GroundCounters {
    /// Packets FOP-1 took for transfer.
    pub packets: u32,
    /// AD frames sent, first transmissions and retransmissions.
    pub ad_frames: u32,
    /// Of those, retransmissions.
    pub retransmissions: u32,
    /// BC frames sent (Unlock, Set V(R)).
    pub bc_frames: u32,
    /// AD frames acknowledged by a CLCW.
    pub confirmed: u32,
    /// AD frames FOP-1 gave up on (purged after an alert): their packets go to the front of
    /// the outbox again.
    pub purged: u32,
    /// CLCWs received.
    pub clcws: u32,
    /// CLCWs reporting Lockout.
    pub lockouts: u32,
    /// Alerts, by [`AlertCode`] in declaration order (Limit, T1, Lockout, Synch, NN(R),
    /// CLCW, Term).
    pub alerts: [u32; 7],
    /// Initiations of the AD service (the first, and one after each alert).
    pub initiations: u32,
    /// TM frames refused by a frame check.
    pub tm_refused: u32,
    /// Purged packets that found the outbox full: lost, and counted here.
    pub dropped: u32,
    /// AD or BD frames SDLS could not protect (the counter's reservation not written yet):
    /// not sent; FOP-1 sends them again.
    pub unprotected: u32,
}

/// Why a packet was not taken: the outbox is full (the packet is handed back).
#[derive(Debug, Clone, PartialEq, Eq, Hash, thiserror::Error)]
#[error("the link's outbox is full ({capacity} packets)")]
pub struct OutboxFull {
    /// The outbox's capacity.
    pub capacity: usize,
}

/// The ground's end of one robot's link: FOP-1 with window `K`, `Q` packets waiting for it,
/// an extractor of `N` octets.
#[derive(Debug, Clone)]
pub struct GroundLink<const K: usize, const Q: usize, const N: usize> {
    board: BoardNumber,
    spacecraft_id: SpacecraftId,
    fop: Fop<Packet, K>,
    outbox: Deque<Packet, Q>,
    extractor: Extractor<N>,
    tm: Option<TmFrameParams>,
    counters: GroundCounters,
    /// SDLS, when the link is secured: the TC (sending) and TM (receiving) associations.
    sdls: Option<SaTable<2>>,
    /// The last CLCW showed FARM-1 in Lockout: the next re-initiation unlocks it first.
    locked_out: bool,
}

impl<const K: usize, const Q: usize, const N: usize> GroundLink<K, Q, N> {
    /// The link to robot `board` (spacecraft `0x100 + n`), FOP-1 with the mission's
    /// parameters (`spec/ccsds/link.toml`), not yet started.
    pub fn new(board: BoardNumber) -> Self {
        Self::with(board, FopConfig::MISSION)
    }

    /// The same with other FOP-1 parameters.
    pub fn with(board: BoardNumber, fop: FopConfig) -> Self {
        let spacecraft_id = SpacecraftId::of_board(board);
        GroundLink {
            board,
            spacecraft_id,
            fop: Fop::new(fop),
            outbox: Deque::new(),
            extractor: Extractor::new(),
            tm: TmFrameParams::mission(spacecraft_id.get()),
            counters: GroundCounters::default(),
            sdls: None,
            locked_out: false,
        }
    }

    /// Secures the link with SDLS (`crate::link::sdls::mission`): AD and BD frames protected
    /// under `tc_key` (each transmission under a fresh IV), TM frames verified under
    /// `tm_key` (a frame that does not verify gives neither packets nor CLCW); `stored`, the
    /// durable counters: the TC reservation and the TM floor.
    pub fn secure(&mut self, tc_key: Key256, tm_key: Key256, stored: (Option<u128>, Option<u128>)) {
        let board = self.board;
        let mut table = SaTable::new();
        let _ = table.add(sdls::mission::tc_sender(board, tc_key, stored.0));
        let _ = table.add(sdls::mission::tm_receiver(board, tm_key, stored.1));
        self.tm = self.tm.and_then(secured::secured_tm_params);
        self.sdls = Some(table);
    }

    /// SDLS's counters, when the link is secured.
    pub fn security(&self) -> Option<&SdlsCounters> {
        self.sdls.as_ref().map(|t| t.counters())
    }

    /// The durable numbers to write now, (SPI, value); confirm each with
    /// [`GroundLink::persisted`].
    pub fn due(&self) -> impl Iterator<Item = (u16, u128)> + '_ {
        self.sdls.iter().flat_map(|t| t.due())
    }

    /// The shell wrote `value` for `spi` durably.
    pub fn persisted(&mut self, spi: u16, value: u128) -> bool {
        self.sdls.as_mut().is_some_and(|t| t.persisted(spi, value))
    }

    /// FOP-1's state.
    pub fn state(&self) -> FopState {
        self.fop.state()
    }

    /// FOP-1 itself (V(S), NN(R), the sent queue).
    pub const fn fop(&self) -> &Fop<Packet, K> {
        &self.fop
    }

    /// What the link did.
    pub const fn counters(&self) -> &GroundCounters {
        &self.counters
    }

    /// What the extractor did (lost TM frames, dropped packets).
    pub const fn extract_counters(&self) -> &ExtractCounters {
        self.extractor.counters()
    }

    /// Packets waiting for FOP-1.
    pub fn waiting(&self) -> usize {
        self.outbox.len()
    }

    /// Initiates the AD service with a CLCW check: packets wait until a CLCW confirms it.
    pub fn start(&mut self, now: u32, emit: &mut impl FnMut(&[u8])) {
        self.counters.initiations = self.counters.initiations.wrapping_add(1);
        let mut outs: Vec<FopOutput<Packet>, 4> = Vec::new();
        self.fop
            .directive(Directive::InitiateWithClcw, now, &mut |o| {
                let _ = outs.push(o);
            });
        self.handle(outs, now, emit);
    }

    /// Queues a telecommand packet for transfer; frames due go to `emit`.
    pub fn send(
        &mut self,
        packet: &[u8],
        now: u32,
        emit: &mut impl FnMut(&[u8]),
    ) -> Result<(), OutboxFull> {
        let full = OutboxFull { capacity: Q };
        let p = Packet::from_slice(packet).map_err(|_| full.clone())?;
        self.outbox.push_back(p).map_err(|_| full)?;
        self.pump(now, emit);
        Ok(())
    }

    /// A TM frame from the robot: its CLCW to FOP-1 (retransmissions go to `emit`), its
    /// packets to `packet`.
    pub fn tm_frame(
        &mut self,
        now: u32,
        bytes: &[u8],
        emit: &mut impl FnMut(&[u8]),
        packet: &mut impl FnMut(&[u8]),
    ) -> Result<(), TmRefusal> {
        let Some(params) = self.tm else {
            return Ok(());
        };
        let mut frame = match TmFrameRepr::parse(bytes, &params) {
            Ok(f) => f,
            Err(e) => {
                self.counters.tm_refused = self.counters.tm_refused.wrapping_add(1);
                return Err(e.into());
            }
        };
        let mut plain = [0u8; crate::link::tm_frame::TM_FRAME_LEN];
        if let Some(table) = self.sdls.as_mut() {
            match secured::verify_tm(table, &params, &frame, bytes, &mut plain) {
                Ok((_, f)) => frame = f,
                Err(e) => return Err(e.into()),
            }
        }
        self.extractor.frame(&frame, |p| packet(p));
        if let Some(clcw) = frame.ocf.and_then(|w| Clcw::parse(&w).ok()) {
            self.counters.clcws = self.counters.clcws.wrapping_add(1);
            if clcw.lockout {
                self.counters.lockouts = self.counters.lockouts.wrapping_add(1);
            }
            self.locked_out = clcw.lockout;
            let mut outs: Vec<FopOutput<Packet>, 24> = Vec::new();
            self.fop.clcw(&clcw, now, &mut |o| {
                let _ = outs.push(o);
            });
            self.handle(outs, now, emit);
        }
        self.pump(now, emit);
        Ok(())
    }

    /// Time passes: timer T1 (retransmissions, or an alert at the transmission limit).
    pub fn tick(&mut self, now: u32, emit: &mut impl FnMut(&[u8])) {
        let mut outs: Vec<FopOutput<Packet>, 24> = Vec::new();
        self.fop.tick(now, &mut |o| {
            let _ = outs.push(o);
        });
        self.handle(outs, now, emit);
        self.pump(now, emit);
    }

    /// When the link next needs [`GroundLink::tick`]: T1's expiry.
    pub fn next_deadline(&self) -> Option<u32> {
        self.fop.timer_deadline()
    }

    /// Hands FOP-1 the next waiting packets while its wait queue is free and it is Active.
    ///
    /// Not while it retransmits: every new AD frame restarts timer T1 (232.1-B-2, "Transmit
    /// Type-AD Frame"; YAMCS does the same), so new packets arriving faster than T1 would
    /// postpone the retransmission of a frame lost twice for as long as they keep coming
    /// (the simulator's ground, resending unanswered telecommands every second, did exactly
    /// that). Held here, they go once the CLCW shows the lost frame accepted.
    fn pump(&mut self, now: u32, emit: &mut impl FnMut(&[u8])) {
        while !self.fop.waiting() && self.fop.state() == FopState::Active {
            let Some(p) = self.outbox.pop_front() else {
                return;
            };
            let mut outs: Vec<FopOutput<Packet>, 24> = Vec::new();
            let taken = self.fop.transfer_ad(p, now, &mut |o| {
                let _ = outs.push(o);
            });
            match taken {
                Ok(()) => self.counters.packets = self.counters.packets.wrapping_add(1),
                Err(p) => {
                    // Not now (AD service not running): back to the front, in order.
                    let _ = self.outbox.push_front(p);
                    self.handle(outs, now, emit);
                    return;
                }
            }
            self.handle(outs, now, emit);
        }
    }

    /// FOP-1's outputs: frames written and emitted, counts kept, re-initiation after an
    /// alert.
    fn handle<const M: usize>(
        &mut self,
        outs: Vec<FopOutput<Packet>, M>,
        now: u32,
        emit: &mut impl FnMut(&[u8]),
    ) {
        let mut alerted = false;
        // Purged and rejected packets, oldest first: back to the front of the outbox, in
        // order, to go again after the re-initiation (nothing is lost; the gateway's request
        // keys make a copy that FARM-1 had already passed harmless).
        let mut back: Vec<Packet, M> = Vec::new();
        for o in outs {
            match o {
                FopOutput::Transmit(f) => self.transmit(&f, emit),
                FopOutput::Confirmed { .. } => {
                    self.counters.confirmed = self.counters.confirmed.wrapping_add(1);
                }
                FopOutput::NegativeConfirm { fdu, .. } => {
                    self.counters.purged = self.counters.purged.wrapping_add(1);
                    let _ = back.push(fdu);
                }
                FopOutput::Rejected(p) => {
                    let _ = back.push(p);
                }
                FopOutput::Alert(code) => {
                    if let Some(a) = self.counters.alerts.get_mut(alert_index(code)) {
                        *a = a.wrapping_add(1);
                    }
                    alerted = true;
                }
                FopOutput::InitiateConfirmed | FopOutput::Suspended => {}
            }
        }
        for p in back.into_iter().rev() {
            if self.outbox.push_front(p).is_err() {
                self.counters.dropped = self.counters.dropped.wrapping_add(1);
            }
        }
        // Retransmissions: AD frames sent beyond the packets taken.
        self.counters.retransmissions = self
            .counters
            .ad_frames
            .wrapping_sub(self.counters.packets.min(self.counters.ad_frames));
        if alerted {
            self.reinitiate(now, emit);
        }
    }

    /// A frame FOP-1 sends: written (a data frame under SDLS when the link is secured),
    /// counted, and emitted.
    fn transmit(&mut self, f: &FopFrame<Packet>, emit: &mut impl FnMut(&[u8])) {
        let c = &mut self.counters;
        let content = match &f.data {
            FrameData::Fdu(p) if f.kind == FrameKind::Ad => {
                c.ad_frames = c.ad_frames.wrapping_add(1);
                TcContent::Ad {
                    map_id: MapId::new(tc_frame::MISSION_MAP_ID).ok(),
                    data: p,
                }
            }
            FrameData::Fdu(p) => TcContent::Bd {
                map_id: MapId::new(tc_frame::MISSION_MAP_ID).ok(),
                data: p,
            },
            FrameData::Control(cmd) => {
                c.bc_frames = c.bc_frames.wrapping_add(1);
                TcContent::Bc(*cmd)
            }
        };
        let repr = TcFrameRepr {
            spacecraft_id: self.spacecraft_id,
            vcid: Vcid::new(tc_frame::MISSION_VCID).unwrap_or_default(),
            seq: f.ns,
            content,
        };
        let mut buf = [0u8; MAX_FRAME_LEN];
        let spi = tc_spi(self.spacecraft_id);
        let n = match self.sdls.as_mut() {
            Some(t) if f.kind != FrameKind::Bc => {
                // Each transmission under a fresh IV; one that cannot be protected yet (its
                // counter not reserved) is not sent, and FOP-1's timer sends it again.
                let n = secured::protect_tc(t, spi, &repr, &mut buf);
                if n.is_err() {
                    self.counters.unprotected = self.counters.unprotected.wrapping_add(1);
                }
                n.ok()
            }
            _ => repr.emit(&mut buf).ok(),
        };
        if let Some(n) = n {
            emit(buf.get(..n).unwrap_or(&[]));
        }
    }

    /// After an alert: the AD service initiated again with Set V(R) = V(S), counted, so that
    /// commanding goes on without an operator.
    fn reinitiate(&mut self, now: u32, emit: &mut impl FnMut(&[u8])) {
        self.counters.initiations = self.counters.initiations.wrapping_add(1);
        if self.locked_out {
            // FARM-1 obeys Set V(R) in Open and Wait only (232.1-B-2 Table 6-1, E8): out
            // of Lockout it takes an Unlock, sent first. Without it a link locked out
            // (a forged Set V(R) into the lockout area, a restarted FARM-1 at V(R) = 0)
            // stayed locked for good, every re-initiation ignored.
            self.emit_bc(ControlCommand::Unlock, 0, emit);
        }
        let vs = self.fop.vs();
        let mut again: Vec<FopOutput<Packet>, 4> = Vec::new();
        self.fop
            .directive(Directive::InitiateWithSetVr(vs), now, &mut |o| {
                let _ = again.push(o);
            });
        // One level deep: an initiation's outputs are a BC frame and no alert.
        for o in again {
            if let FopOutput::Transmit(f) = o
                && let FrameData::Control(cmd) = f.data
            {
                self.emit_bc(cmd, f.ns, emit);
            }
        }
    }

    /// A BC frame (in clear: SDLS protects data frames only), counted.
    fn emit_bc(&mut self, cmd: ControlCommand, ns: u8, emit: &mut impl FnMut(&[u8])) {
        self.counters.bc_frames = self.counters.bc_frames.wrapping_add(1);
        let repr = TcFrameRepr {
            spacecraft_id: self.spacecraft_id,
            vcid: Vcid::new(tc_frame::MISSION_VCID).unwrap_or_default(),
            seq: ns,
            content: TcContent::Bc(cmd),
        };
        let mut buf = [0u8; 8];
        if let Ok(n) = repr.emit(&mut buf) {
            emit(buf.get(..n).unwrap_or(&[]));
        }
    }
}

/// The TC SPI of the robot with this spacecraft ID (`sdls::mission::tc_spi`).
const fn tc_spi(scid: SpacecraftId) -> u16 {
    scid.get()
}

/// The counter index of an alert code.
const fn alert_index(code: AlertCode) -> usize {
    match code {
        AlertCode::Limit => 0,
        AlertCode::T1 => 1,
        AlertCode::Lockout => 2,
        AlertCode::Synch => 3,
        AlertCode::NnR => 4,
        AlertCode::Clcw => 5,
        AlertCode::Term => 6,
    }
}
