//! The on-board side of the TM link: whole space packets in, fixed-length TM transfer frames
//! out, on one virtual channel (CCSDS 132.0-B-3 §4.1.4, §4.2.2 "Packet Processing" and
//! "Virtual Channel Generation").
//!
//! ```
//! use mmic::link::tm_frame::{FirstHeaderPointer, TmFrameParams, TmFrameRepr, TM_FRAME_LEN};
//! use mmic::link::tm_framer::TmFramer;
//!
//! let params = TmFrameParams::mission(0x142).unwrap();
//! let mut framer = TmFramer::<1024>::new(params, 500);
//! // A 13-octet packet (data length field 6) waits; a frame is due (none sent yet).
//! let packet = [0x08, 0x42, 0xc0, 0x00, 0x00, 0x06, 1, 2, 3, 4, 5, 6, 7];
//! framer.push(&packet).unwrap();
//! assert!(framer.frame_due(0));
//! let mut frame = [0u8; TM_FRAME_LEN];
//! assert_eq!(framer.next_frame(0, [0x01, 0, 0, 0], &mut frame), Ok(256));
//! let f = TmFrameRepr::parse(&frame, &params).unwrap();
//! assert_eq!(f.first_header_pointer, FirstHeaderPointer::Packet(0));
//! assert_eq!(&f.data[..13], &packet);
//! // The rest of the data field is one idle packet: APID 0x7FF, 244 - 13 = 231 octets.
//! assert_eq!(&f.data[13..19], &[0x07, 0xff, 0xc0, 0x00, 0x00, 231 - 7]);
//! assert_eq!(f.ocf, Some([0x01, 0, 0, 0]));
//! // Nothing waits: not due before the idle period, then an only-idle-data frame.
//! assert!(!framer.frame_due(499));
//! assert!(framer.frame_due(500));
//! framer.next_frame(500, [0x01, 0, 0, 0], &mut frame).unwrap();
//! let f = TmFrameRepr::parse(&frame, &params).unwrap();
//! assert_eq!((f.first_header_pointer, f.vc_frame_count), (FirstHeaderPointer::OnlyIdleData, 1));
//! ```
//!
//! The choices, each where the standard leaves one:
//!
//! * **Packets are laid end to end** across frames: a packet that does not fit the rest of a
//!   data field continues in the next frame(s) (§4.1.4); the first header pointer of
//!   each frame points at the first packet that *starts* in it, `0x7FF` when none does
//!   (§4.1.2.7.6).
//! * **Never dropped silently**: [`TmFramer::push`] takes a whole packet or refuses it with
//!   [`PushError::Full`] (the room there is), and the caller keeps it. It also refuses octets
//!   whose primary header's length field disagrees with their length ([`PushError::NotAPacket`]):
//!   the packet stream is delimited by those fields alone, so one wrong field would shift every
//!   later packet for the ground.
//! * **When a frame must go before it is full** (the caller calls [`TmFramer::next_frame`]:
//!   [`TmFramer::frame_due`] says the idle period elapsed, or the caller flushes) the rest of
//!   the data field is one idle packet (133.0-B-2 §4.1.3.3.4: APID `0x7FF`; data octets
//!   [`IDLE_OCTET`] as `spec/ccsds/link.toml` says; sequence count 0; type TM; no secondary
//!   header). When the room left is shorter than the shortest idle packet (7 octets), a
//!   7-octet idle packet starts there anyway and **spills over** into the next frame, whose
//!   first header pointer then points past its tail — the ground extracts it as any packet
//!   that spans frames (and drops it as idle). No octet of a data field is left outside a
//!   packet, so the ground never has to guess. YAMCS reads it so too: its `PacketDecoder`
//!   (`yamcs-core/.../tctm/ccsds/`) collects a primary header across frames and skips packets
//!   of APID `0x7FF` by default.
//! * **A frame with nothing waiting at all** (no packet, no packet in flight, no idle tail) is
//!   an only-idle-data frame (first header pointer `0x7FE`, §4.1.2.7.6), its data field
//!   [`IDLE_OCTET`]s: the ground discards it without looking into its data field (YAMCS's
//!   `VcTmPacketHandler` counts it as an idle frame and keeps any packet it is reassembling,
//!   as [`crate::link::extract`] does). It only goes out when no packet is in flight, so it
//!   never cuts one.
//! * **Counts**: the master and virtual channel frame counts go up by one per frame, mod 256
//!   (§4.1.2.5, §4.1.2.6); with one VC per master channel they are equal.
//! * **The OCF** of every frame is the CLCW the caller hands to [`TmFramer::next_frame`]
//!   (when the channel carries an OCF), the FECF the CRC of [`crate::ccsds::pec`].

use super::tm_frame::{FirstHeaderPointer, TmEmitError, TmFrameParams, TmFrameRepr, OCF_LEN};
use crate::ccsds::primary::{PrimaryHeader, PRIMARY_LEN};

/// The data octets of idle packets and of only-idle-data frames (`spec/ccsds/link.toml`
/// `[tm] idle_fill`).
pub const IDLE_OCTET: u8 = 0x55;
/// The idle packets' APID (133.0-B-2 §4.1.3.3.4).
pub const IDLE_APID: u16 = 0x7ff;
/// Octets of the shortest space packet, and so of the shortest idle packet: six of header
/// and one of data.
pub const MIN_PACKET_LEN: usize = PRIMARY_LEN + 1;
/// The mission's idle period: a frame at least this often, so that the ground gets the CLCW
/// (`[tm] idle_period_ms`).
pub const IDLE_PERIOD_MS: u32 = 500;

/// The primary header of an idle packet of `len` octets (7..=65542).
pub const fn idle_header(len: usize) -> [u8; PRIMARY_LEN] {
    // The packet data length field: the low 16 bits (what `as u16` kept), in range for
    // the lengths this takes.
    let [.., l0, l1] = len.saturating_sub(MIN_PACKET_LEN).to_be_bytes();
    // Version 0, type TM, no secondary header, APID 0x7FF; unsegmented, count 0.
    [0x07, 0xff, 0xc0, 0x00, l0, l1]
}

/// Why [`TmFramer::push`] did not take a packet: the caller still has it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum PushError {
    /// Not enough room for the whole packet: try again after frames have gone.
    #[error("the framer has room for {free} octets, the packet has {needed}")]
    Full {
        /// The packet's length.
        needed: usize,
        /// Octets free now.
        free: usize,
    },
    /// Not one whole space packet: shorter than 7 octets, or its data length field says
    /// another length.
    #[error("not a whole space packet: its header says {expected} octets, found {found}")]
    NotAPacket {
        /// Length the data length field declares (0 when there is no whole header).
        expected: usize,
        /// Octets given.
        found: usize,
    },
}

/// The on-board TM framer of one virtual channel: up to `N` octets of packets wait (see the
/// module docs for the choices).
#[derive(Debug, Clone)]
pub struct TmFramer<const N: usize> {
    params: TmFrameParams,
    idle_period_ms: u32,
    /// The waiting octets: first the rest of the packet in flight (`in_flight` octets), then
    /// whole packets.
    queue: heapless::Deque<u8, N>,
    /// Octets at the queue's front that continue a packet already started in a frame.
    in_flight: usize,
    /// Octets of a 7-octet idle packet still to send (0..=6): its spilled tail.
    idle_tail: usize,
    mc_frame_count: u8,
    vc_frame_count: u8,
    last_frame_ms: Option<u32>,
}

impl<const N: usize> TmFramer<N> {
    /// A framer of frames under `params` (its spacecraft ID and VCID are the frames'), sending
    /// a frame at least every `idle_period_ms`; counts start at 0.
    pub const fn new(params: TmFrameParams, idle_period_ms: u32) -> TmFramer<N> {
        TmFramer {
            params,
            idle_period_ms,
            queue: heapless::Deque::new(),
            in_flight: 0,
            idle_tail: 0,
            mc_frame_count: 0,
            vc_frame_count: 0,
            last_frame_ms: None,
        }
    }

    /// The frame parameters.
    pub const fn params(&self) -> &TmFrameParams {
        &self.params
    }

    /// When the last frame went out (`None`: none yet); the next is due by the idle period
    /// after it.
    pub const fn last_frame_ms(&self) -> Option<u32> {
        self.last_frame_ms
    }

    /// Octets waiting (packets, the rest of the one in flight).
    pub fn waiting(&self) -> usize {
        self.queue.len()
    }

    /// Octets [`TmFramer::push`] can take now.
    pub fn free(&self) -> usize {
        // The queue holds at most N octets.
        N.saturating_sub(self.queue.len())
    }

    /// Queues one whole space packet (any APID, PUS or not: its primary header's length field
    /// is all the framer reads), or refuses it, leaving the framer as it was.
    pub fn push(&mut self, packet: &[u8]) -> Result<(), PushError> {
        let expected = PrimaryHeader::read(packet).map_or(0, |h| h.total_len());
        if expected != packet.len() {
            return Err(PushError::NotAPacket {
                expected,
                found: packet.len(),
            });
        }
        if packet.len() > self.free() {
            return Err(PushError::Full {
                needed: packet.len(),
                free: self.free(),
            });
        }
        for &b in packet {
            // Room checked above: never refused.
            let _ = self.queue.push_back(b);
        }
        Ok(())
    }

    /// Whether a frame should go at `now_ms`: what waits fills a data field, or the idle
    /// period has elapsed since the last frame (or none has gone yet), so that the CLCW
    /// reaches the ground that often.
    pub fn frame_due(&self, now_ms: u32) -> bool {
        // Both bounded by the queue's capacity and 6: the sum cannot saturate.
        if self.queue.len().saturating_add(self.idle_tail) >= self.params.data_len() {
            return true;
        }
        match self.last_frame_ms {
            None => true,
            Some(t) => now_ms.wrapping_sub(t) >= self.idle_period_ms,
        }
    }

    /// The next frame, written into the front of `out`, with `clcw` as its OCF (ignored on a
    /// channel without OCF); its length. The data field takes what waits, in order, and when
    /// that does not fill it, an idle packet fills the rest (see the module docs); nothing
    /// waiting at all makes an only-idle-data frame. Refused, the framer unchanged, when `out`
    /// is shorter than the frame.
    pub fn next_frame(
        &mut self,
        now_ms: u32,
        clcw: [u8; OCF_LEN],
        out: &mut [u8],
    ) -> Result<usize, TmEmitError> {
        let p = self.params;
        let too_small = TmEmitError::BufferTooSmall {
            expected: p.frame_len(),
            found: out.len(),
        };
        let frame = out.get_mut(..p.frame_len()).ok_or(too_small)?;
        let only_idle = self.idle_tail == 0 && self.in_flight == 0 && self.queue.is_empty();
        let mut fhp = if only_idle {
            FirstHeaderPointer::OnlyIdleData
        } else {
            FirstHeaderPointer::NoPacketStart
        };
        if let Some(data) = frame.get_mut(p.data_range()) {
            if only_idle {
                data.fill(IDLE_OCTET);
            } else {
                self.fill(data, &mut fhp);
            }
        }
        let repr = TmFrameRepr {
            spacecraft_id: p.spacecraft_id(),
            vcid: p.vcid(),
            mc_frame_count: self.mc_frame_count,
            vc_frame_count: self.vc_frame_count,
            first_header_pointer: fhp,
            data: &[],
            ocf: if p.ocf() { Some(clcw) } else { None },
        };
        repr.seal(&p, frame);
        self.mc_frame_count = self.mc_frame_count.wrapping_add(1);
        self.vc_frame_count = self.vc_frame_count.wrapping_add(1);
        self.last_frame_ms = Some(now_ms);
        Ok(p.frame_len())
    }

    /// Fills `data` from the idle tail, the packet in flight, whole packets and an idle packet,
    /// in that order; `fhp` gets the offset of the first packet start.
    fn fill(&mut self, data: &mut [u8], fhp: &mut FirstHeaderPointer) {
        // `at` never passes `len`, each `n` is at most what it is taken from, and the idle
        // tail is shorter than an idle packet: the saturating forms never saturate.
        let len = data.len();
        let mut at = 0usize;
        // 1. The spilled tail of a 7-octet idle packet.
        if self.idle_tail > 0 {
            let idle = idle_packet_7();
            let from = MIN_PACKET_LEN.saturating_sub(self.idle_tail);
            let n = self.idle_tail.min(len);
            let tail = idle.get(from..).and_then(|t| t.get(..n));
            copy(data, at, tail.unwrap_or(&[]));
            self.idle_tail = self.idle_tail.saturating_sub(n);
            at = at.saturating_add(n);
        }
        // 2. The rest of the packet in flight.
        if at < len && self.in_flight > 0 {
            let n = self.in_flight.min(len.saturating_sub(at));
            self.pop_into(data, at, n);
            self.in_flight = self.in_flight.saturating_sub(n);
            at = at.saturating_add(n);
        }
        // 3. Whole packets, the last one perhaps cut (it continues in the next frame).
        while at < len && !self.queue.is_empty() {
            self.mark(fhp, at);
            let total = self.head_len();
            let n = total.min(len.saturating_sub(at));
            self.pop_into(data, at, n);
            self.in_flight = total.saturating_sub(n);
            at = at.saturating_add(n);
        }
        // 4. An idle packet in the rest, spilling over if the rest is shorter than 7 octets.
        if at < len {
            self.mark(fhp, at);
            let room = len.saturating_sub(at);
            if room >= MIN_PACKET_LEN {
                copy(data, at, &idle_header(room));
                let body = data.get_mut(at..).and_then(|p| p.get_mut(PRIMARY_LEN..));
                if let Some(rest) = body {
                    rest.fill(IDLE_OCTET);
                }
            } else {
                copy(data, at, idle_packet_7().get(..room).unwrap_or(&[]));
                self.idle_tail = MIN_PACKET_LEN.saturating_sub(room);
            }
        }
    }

    fn mark(&self, fhp: &mut FirstHeaderPointer, at: usize) {
        // `at` lies in the data field, under MAX_FRAME_LEN octets: it fits the pointer.
        if let (FirstHeaderPointer::NoPacketStart, Ok(at)) = (*fhp, u16::try_from(at)) {
            *fhp = FirstHeaderPointer::Packet(at);
        }
    }

    /// Length of the packet at the queue's front (its header is whole: `push` checked it).
    fn head_len(&self) -> usize {
        let h: [u8; PRIMARY_LEN] =
            core::array::from_fn(|i| self.queue.get(i).copied().unwrap_or(0));
        PrimaryHeader::read(&h).map_or(MIN_PACKET_LEN, |h| h.total_len())
    }

    /// Moves `n` octets from the queue's front into `data[at..]`.
    fn pop_into(&mut self, data: &mut [u8], at: usize, n: usize) {
        for slot in data.iter_mut().skip(at).take(n) {
            *slot = self.queue.pop_front().unwrap_or(IDLE_OCTET);
        }
    }
}

/// The shortest idle packet, the one that spills over.
const fn idle_packet_7() -> [u8; MIN_PACKET_LEN] {
    let h = idle_header(MIN_PACKET_LEN);
    [h[0], h[1], h[2], h[3], h[4], h[5], IDLE_OCTET]
}

/// `src` into `data` at `at` (clipped to `data`).
fn copy(data: &mut [u8], at: usize, src: &[u8]) {
    for (d, s) in data.iter_mut().skip(at).zip(src) {
        *d = *s;
    }
}
