//! The ground's packet extractor (CCSDS 132.0-B-3 §4.1.2.7 and §4.1.2.6, the receiving side of
//! §4.1.4): checked TM frames of one virtual channel in, whole space packets out, through a
//! callback, reassembled in a buffer of `N` octets (no allocation).
//!
//! ```
//! use mmic::link::extract::Extractor;
//! use mmic::link::tm_frame::{TmFrameParams, TmFrameRepr, TM_FRAME_LEN};
//! use mmic::link::tm_framer::TmFramer;
//!
//! let params = TmFrameParams::mission(0x142).unwrap();
//! let mut framer = TmFramer::<1024>::new(params, 500);
//! // A 300-octet packet: longer than a data field (244), it spans two frames.
//! let mut packet = [0xa5u8; 300];
//! packet[..6].copy_from_slice(&[0x08, 0x42, 0xc0, 0x00, 0x01, 0x25]); // 0x125 + 7 = 300
//! framer.push(&packet).unwrap();
//! let mut extractor = Extractor::<512>::new();
//! let mut got = Vec::new();
//! let mut frame = [0u8; TM_FRAME_LEN];
//! for t in [0, 500] {
//!     framer.next_frame(t, [0; 4], &mut frame).unwrap();
//!     let f = TmFrameRepr::parse(&frame, &params).unwrap();
//!     extractor.frame(&f, |p| got.push(p.to_vec()));
//! }
//! assert_eq!(got, [packet.to_vec()]);
//! let c = extractor.counters();
//! assert_eq!((c.frames, c.packets, c.idle_packets, c.lost_frames), (2, 1, 1, 0));
//! ```
//!
//! How it reads the stream, and what it does when the stream breaks:
//!
//! * The packets of a VC's data fields form one octet stream; each packet's primary header
//!   says how long it is. A frame's first header pointer says where the first packet that
//!   starts in it starts: the octets before it continue the packet in reassembly.
//! * **Lost frames** show as a gap in the virtual channel frame count (mod 256, §4.1.2.6): the
//!   gap is counted in `lost_frames`, a packet in reassembly is dropped and counted in
//!   `dropped`, never spliced with the next frame's octets, and extraction resumes at the next
//!   first header pointer. (A loss of a multiple of 256 frames cannot be seen in the count.) The first frame
//!   sets the count.
//! * **A repeated or stale frame** (a VC frame count equal to the last one, or less than
//!   [`STALE_WINDOW`] behind it: the transport duplicated or reordered it; a space link does
//!   neither, a UDP link or a relay may) is skipped whole and counted (`repeated`): its packets
//!   came with the first copy, or were given up when the gap was seen; taking them now would
//!   deliver them out of order. A loss of 128 frames or more in a row reads the same way.
//! * **A first header pointer that disagrees** with the packet in reassembly (the packet ends
//!   before it, or has not ended at it) counts in `bad_fhp`; the pointer wins: a packet not yet
//!   ended is dropped (`dropped`), the octets between a packet's end and the pointer skipped.
//! * **Idle packets** (APID `0x7FF`) are skipped and counted (`idle_packets`), never buffered;
//!   **only-idle-data frames** (pointer `0x7FE`) are counted (`idle_frames`) and their data
//!   field ignored; a packet in reassembly survives them, as in YAMCS's `VcTmPacketHandler`.
//! * **A packet longer than the buffer** is skipped and counted (`too_long`), never truncated.

use super::tm_frame::{FirstHeaderPointer, TmFrameRepr};
use crate::ccsds::primary::{PrimaryHeader, PRIMARY_LEN};

/// The idle packets' APID.
const IDLE_APID: u16 = 0x7ff;

/// What the extractor has seen (all counts wrap at `u32::MAX`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct ExtractCounters {
    /// Frames handed in.
    pub frames: u32,
    /// Frames missing by the gaps of the VC frame count.
    pub lost_frames: u32,
    /// Only-idle-data frames.
    pub idle_frames: u32,
    /// Packets delivered.
    pub packets: u32,
    /// Packets (or packet headers) in reassembly dropped: cut by a lost frame, or by a first
    /// header pointer that disagreed. Cut idle packets do not count, unless cut inside their
    /// header (their APID unknown).
    pub dropped: u32,
    /// Idle packets skipped.
    pub idle_packets: u32,
    /// Packets longer than the buffer, skipped.
    pub too_long: u32,
    /// First header pointers that disagreed with the packet in reassembly.
    pub bad_fhp: u32,
    /// Frames whose VC frame count is the last one's or up to [`STALE_WINDOW`] − 1 behind it:
    /// copies and frames overtaken in transport, skipped whole.
    pub repeated: u32,
}

/// Where the extractor is in the packet stream.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum State {
    /// Out of step: waiting for a first header pointer.
    Sync,
    /// Collecting a packet's primary header (the octets so far in the buffer).
    Header,
    /// In a packet of `total` octets with `got` of them seen.
    Body {
        total: usize,
        got: usize,
        kind: Kind,
    },
}

/// What becomes of the packet in reassembly.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    /// Kept in the buffer, delivered at its end.
    Keep,
    /// An idle packet: skipped.
    Idle,
    /// Longer than the buffer: skipped (already counted).
    TooLong,
}

/// How far behind the last VC frame count a frame is taken for a copy or a late one (half the
/// count's range: a gap of up to 128 frames is a loss, a count up to 128 behind is stale).
pub const STALE_WINDOW: u8 = 128;

/// The packet extractor of one virtual channel, reassembling packets of up to `N` octets
/// (`N` at least 6: the header is collected in the same buffer).
#[derive(Debug, Clone)]
pub struct Extractor<const N: usize> {
    buf: heapless::Vec<u8, N>,
    state: State,
    last_vc_count: Option<u8>,
    counters: ExtractCounters,
}

impl<const N: usize> Default for Extractor<N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const N: usize> Extractor<N> {
    const _ROOM_FOR_A_HEADER: () = assert!(N >= PRIMARY_LEN);

    /// An extractor that has seen no frame.
    pub const fn new() -> Extractor<N> {
        let () = Self::_ROOM_FOR_A_HEADER;
        Extractor {
            buf: heapless::Vec::new(),
            state: State::Sync,
            last_vc_count: None,
            counters: ExtractCounters {
                frames: 0,
                lost_frames: 0,
                idle_frames: 0,
                packets: 0,
                dropped: 0,
                idle_packets: 0,
                too_long: 0,
                bad_fhp: 0,
                repeated: 0,
            },
        }
    }

    /// The counters.
    pub const fn counters(&self) -> &ExtractCounters {
        &self.counters
    }

    /// Whether a packet is in reassembly (its rest expected in the next frame): not when out
    /// of step, nor between packets (the last one ended with the last data field).
    pub fn in_packet(&self) -> bool {
        match self.state {
            State::Sync => false,
            State::Header => !self.buf.is_empty(),
            State::Body { .. } => true,
        }
    }

    /// Takes the next frame of the VC (parsed and checked: [`TmFrameRepr::parse`]) and hands
    /// every packet that ends in it to `on_packet`, whole, in order.
    pub fn frame(&mut self, frame: &TmFrameRepr<'_>, mut on_packet: impl FnMut(&[u8])) {
        let c = &mut self.counters;
        c.frames = c.frames.wrapping_add(1);
        let count = frame.vc_frame_count;
        if let Some(last) = self.last_vc_count {
            if last.wrapping_sub(count) < STALE_WINDOW {
                // The frame again, or one overtaken by later frames (a UDP link or a relay
                // may duplicate and reorder; a space link does neither): its packets came
                // with the first copy, or were dropped when the gap was seen.
                c.repeated = c.repeated.wrapping_add(1);
                return;
            }
            let gap = count.wrapping_sub(last).wrapping_sub(1);
            if gap != 0 {
                c.lost_frames = c.lost_frames.wrapping_add(u32::from(gap));
                self.abandon();
            }
        }
        self.last_vc_count = Some(count);
        let data = frame.data;
        let start = match frame.first_header_pointer {
            FirstHeaderPointer::OnlyIdleData => {
                self.counters.idle_frames = self.counters.idle_frames.wrapping_add(1);
                return;
            }
            FirstHeaderPointer::NoPacketStart => None,
            FirstHeaderPointer::Packet(p) => Some(usize::from(p).min(data.len())),
        };
        if matches!(self.state, State::Header) && self.buf.is_empty() {
            // Between packets: the next one starts at octet 0 of this data field.
            if start != Some(0) {
                self.counters.bad_fhp = self.counters.bad_fhp.wrapping_add(1);
            }
            self.state = State::Sync;
        }
        // The octets before the first header pointer continue the packet in reassembly.
        let cont = data.get(..start.unwrap_or(data.len())).unwrap_or(&[]);
        if self.in_packet() {
            let used = self.feed(cont, false, &mut on_packet);
            let ended_early = used < cont.len();
            let unfinished = start.is_some() && self.in_packet();
            if ended_early || unfinished {
                self.counters.bad_fhp = self.counters.bad_fhp.wrapping_add(1);
                self.abandon();
            }
        }
        if let Some(s) = start {
            self.buf.clear();
            self.state = State::Header;
            let _ = self.feed(data.get(s..).unwrap_or(&[]), true, &mut on_packet);
        }
    }

    /// Drops the packet in reassembly (counted unless it is a known idle or too-long one).
    fn abandon(&mut self) {
        let skipped = matches!(
            self.state,
            State::Body {
                kind: Kind::Idle | Kind::TooLong,
                ..
            }
        );
        if self.in_packet() && !skipped {
            self.counters.dropped = self.counters.dropped.wrapping_add(1);
        }
        self.state = State::Sync;
        self.buf.clear();
    }

    /// Feeds `bytes` to the packet in reassembly; with `starts`, a packet's end is followed
    /// by the next packet's header, without, the feeding stops there (the octets before a
    /// first header pointer belong to one packet). Returns the octets used.
    fn feed(&mut self, bytes: &[u8], starts: bool, on_packet: &mut impl FnMut(&[u8])) -> usize {
        // `at` stays within `bytes` (each step takes at most what is left), and a body's `got`
        // stays below its `total` (a packet is its 6 header octets and at least one more):
        // the saturating forms below never saturate.
        let mut at = 0usize;
        while at < bytes.len() {
            let rest = bytes.get(at..).unwrap_or(&[]);
            match self.state {
                State::Sync => break,
                State::Header => at = at.saturating_add(self.feed_header(rest)),
                State::Body { total, got, kind } => {
                    let take = total.saturating_sub(got).min(rest.len());
                    if kind == Kind::Keep {
                        for &b in rest.get(..take).unwrap_or(&[]) {
                            let _ = self.buf.push(b);
                        }
                    }
                    at = at.saturating_add(take);
                    let got = got.saturating_add(take);
                    if got < total {
                        self.state = State::Body { total, got, kind };
                        continue;
                    }
                    self.packet_end(kind, on_packet);
                    self.state = if starts { State::Header } else { State::Sync };
                    if !starts {
                        break;
                    }
                }
            }
        }
        at
    }

    /// Takes what `bytes` holds of the primary header in reassembly; once whole, the packet's
    /// length and what becomes of it (kept, idle, or too long for the buffer: counted, and
    /// skipped). Returns the octets used.
    fn feed_header(&mut self, bytes: &[u8]) -> usize {
        // The buffer holds less than a header while one is collected.
        let take = PRIMARY_LEN.saturating_sub(self.buf.len()).min(bytes.len());
        for &b in bytes.get(..take).unwrap_or(&[]) {
            let _ = self.buf.push(b);
        }
        if let Some(h) = PrimaryHeader::read(&self.buf) {
            let total = h.total_len();
            let kind = if h.apid == IDLE_APID {
                Kind::Idle
            } else if total > N {
                self.counters.too_long = self.counters.too_long.wrapping_add(1);
                Kind::TooLong
            } else {
                Kind::Keep
            };
            if kind != Kind::Keep {
                self.buf.clear();
            }
            self.state = State::Body {
                total,
                got: PRIMARY_LEN,
                kind,
            };
        }
        take
    }

    /// A packet's last octet arrived: a kept one handed out, an idle one counted.
    fn packet_end(&mut self, kind: Kind, on_packet: &mut impl FnMut(&[u8])) {
        match kind {
            Kind::Keep => {
                self.counters.packets = self.counters.packets.wrapping_add(1);
                on_packet(&self.buf);
            }
            Kind::Idle => self.counters.idle_packets = self.counters.idle_packets.wrapping_add(1),
            Kind::TooLong => {}
        }
        self.buf.clear();
    }
}
