//! Finding packets in a byte stream (serial lines, TCP), with a fixed-capacity buffer.
//!
//! The deframer looks for a known header, waits until the whole packet has arrived and accepts
//! it only if its checksum holds. A header whose checksum fails costs exactly one byte: the
//! scan resumes at the next byte, so a valid packet that starts inside a false candidate (or
//! right after garbage) is never lost. Every dropped byte is counted and reported, in stream
//! order, before the next packet.
//!
//! A false header near the end of a burst (garbage that happens to read `MIHB`, say) makes the
//! deframer wait for as many bytes as that packet would need, since only then can the checksum
//! rule it out; packets behind it are delayed, not lost. A shell that knows the line went idle
//! (packets arrive in one burst) calls [`Deframer::resync`] to rule the candidate out at once.
//!
//! ```
//! use mmic::wire::deframer::{Deframer, Deframed};
//! use mmic::wire::command::CommandRepr;
//! use mmic::command::Command;
//! use mmic::units::BoardNumber;
//!
//! let pkt = CommandRepr { board: BoardNumber::ONE, command: Command::Stop, seq: 0 }.to_bytes();
//! let mut d = Deframer::<128>::new();
//! let mut seen = Vec::new();
//! // Garbage, then the packet split across two reads.
//! d.feed(b"\x00MI?", |e| seen.push(e));
//! d.feed(&pkt[..5], |e| seen.push(e));
//! d.feed(&pkt[5..], |e| seen.push(e));
//! assert_eq!(seen.len(), 2);
//! assert_eq!(seen[0], Deframed::Discarded(4));
//! match &seen[1] {
//!     Deframed::Frame(f) => assert_eq!(CommandRepr::parse(f.as_bytes()).unwrap().command, Command::Stop),
//!     other => panic!("{other:?}"),
//! }
//! ```
// req: D:deframing, D:headers

use super::{checksum, PacketKind, CHECKSUM_LEN, HEADER_LEN, MAX_PACKET_LEN};

/// A packet whose header and checksum hold (its fields are checked by the `Repr` parsers).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Frame {
    kind: PacketKind,
    bytes: [u8; MAX_PACKET_LEN],
}

impl Frame {
    /// Which packet this is, from its header.
    pub const fn kind(&self) -> PacketKind {
        self.kind
    }

    /// The packet's bytes, header to checksum.
    pub fn as_bytes(&self) -> &[u8] {
        // A packet's length is at most `MAX_PACKET_LEN`: the fallback never shows.
        self.bytes.get(..self.kind.len()).unwrap_or_default()
    }
}

/// What the deframer found next in the stream.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Deframed {
    /// This many bytes were dropped: no header, or a header whose checksum failed.
    Discarded(usize),
    /// A packet.
    Frame(Frame),
}

/// Stream deframer with an `N`-byte buffer (`N` ≥ 66, the longest packet).
#[derive(Debug, Clone)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Deframer<const N: usize> {
    buf: [u8; N],
    len: usize,
    pending_discard: usize,
    discarded_total: u64,
    frames_total: u64,
}

impl<const N: usize> Default for Deframer<N> {
    fn default() -> Self {
        Self::new()
    }
}

/// How the bytes at the start of a slice relate to the headers.
enum HeaderMatch {
    /// A full header of this kind.
    Full(PacketKind),
    /// The slice is shorter than a header and is a prefix of one.
    Prefix,
    /// Cannot start a header.
    No,
}

/// How the first bytes of `b` relate to the packet headers.
fn header_at(b: &[u8]) -> HeaderMatch {
    // Four bytes or more: one word compared per kind (a slice compare calls `memcmp`, four
    // times a buffered byte, most of a deframed packet's cost in the fault swarm; issue 40).
    if let Some(w) = b.first_chunk::<HEADER_LEN>() {
        return match PacketKind::ALL.into_iter().find(|k| k.header() == *w) {
            Some(kind) => HeaderMatch::Full(kind),
            None => HeaderMatch::No,
        };
    }
    // Shorter: the first bytes of some header, or not (an empty slice is a prefix of all).
    let prefix = PacketKind::ALL
        .into_iter()
        .any(|k| b.iter().zip(k.header()).all(|(x, y)| *x == y));
    if prefix {
        HeaderMatch::Prefix
    } else {
        HeaderMatch::No
    }
}

impl<const N: usize> Deframer<N> {
    const CAPACITY_OK: () = assert!(
        N >= MAX_PACKET_LEN,
        "deframer buffer must hold the longest packet (66 bytes)"
    );

    /// An empty deframer.
    pub const fn new() -> Self {
        let () = Self::CAPACITY_OK;
        Deframer {
            buf: [0; N],
            len: 0,
            pending_discard: 0,
            discarded_total: 0,
            frames_total: 0,
        }
    }

    /// Free buffer space: how many bytes the next [`push`](Self::push) takes at most.
    pub const fn free(&self) -> usize {
        // `len <= N` always: never saturates.
        N.saturating_sub(self.len)
    }

    /// Bytes buffered and not yet resolved into packets or discards.
    pub const fn buffered(&self) -> usize {
        self.len
    }

    /// Bytes dropped since creation.
    pub const fn discarded_total(&self) -> u64 {
        self.discarded_total
    }

    /// Packets delivered since creation.
    pub const fn frames_total(&self) -> u64 {
        self.frames_total
    }

    /// Copies as much of `data` as fits and returns how many bytes were taken. Call
    /// [`poll`](Self::poll) until it returns `None` to make room; nothing is dropped here.
    pub fn push(&mut self, data: &[u8]) -> usize {
        let free = self.buf.get_mut(self.len..).unwrap_or_default();
        let n = data.len().min(free.len());
        if let (Some(dst), Some(src)) = (free.get_mut(..n), data.get(..n)) {
            dst.copy_from_slice(src);
        }
        // At most `N`: never saturates.
        self.len = self.len.saturating_add(n);
        n
    }

    fn drop_front(&mut self, n: usize) {
        self.buf.copy_within(n..self.len, 0);
        // `n <= len` (the callers drop what they scanned): never saturates.
        self.len = self.len.saturating_sub(n);
    }

    fn discard(&mut self, n: usize) {
        self.drop_front(n);
        // Counters that stop at their maximum (the pending count is at most `N` anyway).
        self.pending_discard = self.pending_discard.saturating_add(n);
        let n = u64::try_from(n).unwrap_or(u64::MAX);
        self.discarded_total = self.discarded_total.saturating_add(n);
    }

    /// The next event, or `None` when more bytes are needed.
    pub fn poll(&mut self) -> Option<Deframed> {
        loop {
            // Skip to the first byte that can start a header.
            let mut start = self.len;
            for i in 0..self.len {
                if !matches!(header_at(&self.buf[i..self.len]), HeaderMatch::No) {
                    start = i;
                    break;
                }
            }
            if start > 0 {
                self.discard(start);
            }
            if self.pending_discard > 0 {
                let n = self.pending_discard;
                self.pending_discard = 0;
                return Some(Deframed::Discarded(n));
            }
            let kind = match header_at(&self.buf[..self.len]) {
                HeaderMatch::Full(kind) => kind,
                // Empty, or a header's first bytes: wait for more.
                HeaderMatch::Prefix | HeaderMatch::No => return None,
            };
            let need = kind.len();
            if self.len < need {
                return None;
            }
            // `need <= len <= N` just above, and a packet is longer than its checksum: neither
            // `?` returns.
            let frame = self.buf.get(..need)?;
            let (body, crc) = frame.split_last_chunk::<CHECKSUM_LEN>()?;
            if checksum::packet_crc(kind, body) == u16::from_le_bytes(*crc) {
                let mut bytes = [0u8; MAX_PACKET_LEN];
                if let Some(dst) = bytes.get_mut(..need) {
                    dst.copy_from_slice(frame);
                }
                self.drop_front(need);
                // A counter that stops at its maximum.
                self.frames_total = self.frames_total.saturating_add(1);
                return Some(Deframed::Frame(Frame { kind, bytes }));
            }
            // A false header: drop its first byte only and look again.
            self.discard(1);
        }
    }

    /// The line has gone idle: an incomplete packet at the head of the buffer will never be
    /// completed, so drop its first byte and scan on. Returns the next event, as [`poll`](Self::poll).
    pub fn resync(&mut self) -> Option<Deframed> {
        if let Some(e) = self.poll() {
            return Some(e);
        }
        if self.len == 0 {
            return None;
        }
        self.discard(1);
        self.poll()
    }

    /// Pushes all of `data`, handing every event to `sink` in stream order.
    pub fn feed(&mut self, mut data: &[u8], mut sink: impl FnMut(Deframed)) {
        loop {
            let n = self.push(data);
            // `n <= data.len()`: the fallback never shows.
            data = data.get(n..).unwrap_or_default();
            while let Some(e) = self.poll() {
                sink(e);
            }
            if data.is_empty() {
                return;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use crate::command::Command;
    use crate::units::BoardNumber;
    use crate::wire::command::CommandRepr;
    use crate::wire::heartbeat::HeartbeatRepr;
    use std::vec::Vec;

    /// Every test below starts from `Default` (the shells call `new`, the same empty
    /// deframer: clippy's new_without_default asks for both).
    fn run<const N: usize>(chunks: &[&[u8]]) -> (Vec<Vec<u8>>, usize) {
        let mut d = Deframer::<N>::default();
        let (mut frames, mut dropped) = (Vec::new(), 0);
        for c in chunks {
            d.feed(c, |e| match e {
                Deframed::Frame(f) => frames.push(f.as_bytes().to_vec()),
                Deframed::Discarded(n) => dropped += n,
            });
        }
        assert_eq!(d.discarded_total(), dropped as u64);
        (frames, dropped)
    }

    // req: D:deframing
    #[test]
    fn false_header_does_not_hide_a_following_packet() {
        let pkt = CommandRepr {
            board: BoardNumber::ONE,
            command: Command::Reset,
            seq: 0,
        }
        .to_bytes();
        // A heartbeat header (66-byte candidate) whose span covers a whole valid command.
        let mut stream = Vec::from(&b"MIHB"[..]);
        stream.extend_from_slice(&[0xAA; 7]);
        stream.extend_from_slice(&pkt);
        // More traffic completes the false candidate, the checksum rules it out, and the
        // command behind it comes out first.
        let mut more = stream.clone();
        more.extend_from_slice(&pkt);
        more.extend_from_slice(&pkt);
        more.extend_from_slice(&pkt);
        let (frames, dropped) = run::<66>(&[&more]);
        assert_eq!(
            frames,
            [pkt.to_vec(), pkt.to_vec(), pkt.to_vec(), pkt.to_vec()]
        );
        assert_eq!(dropped, 11);
        // On an idle line, resync rules it out without waiting.
        let mut d = Deframer::<66>::new();
        let mut events = Vec::new();
        d.feed(&stream, |e| events.push(e));
        assert!(events.is_empty());
        while let Some(e) = d.resync() {
            events.push(e);
        }
        assert_eq!(events.len(), 2, "{events:?}");
        assert_eq!(events[0], Deframed::Discarded(11));
        assert!(matches!(events[1], Deframed::Frame(f) if f.as_bytes() == pkt));
    }

    // req: D:deframing
    #[test]
    fn byte_by_byte_delivery_finds_every_packet() {
        let a = CommandRepr {
            board: BoardNumber::ONE,
            command: Command::Stop,
            seq: 0,
        }
        .to_bytes();
        let b = HeartbeatRepr::default().to_bytes();
        let mut stream = Vec::new();
        stream.extend_from_slice(b"junk");
        stream.extend_from_slice(&a);
        stream.extend_from_slice(b"MI");
        stream.extend_from_slice(&b);
        stream.extend_from_slice(&a);
        let chunks: Vec<&[u8]> = stream.chunks(1).collect();
        let (frames, dropped) = run::<66>(&chunks);
        assert_eq!(frames, [a.to_vec(), b.to_vec(), a.to_vec()]);
        assert_eq!(dropped, 6);
    }

    // req: D:deframing
    #[test]
    fn trailing_header_prefix_waits_for_more() {
        let mut d = Deframer::<66>::new();
        assert_eq!(d.push(b"xxMI"), 4);
        assert_eq!(d.poll(), Some(Deframed::Discarded(2)));
        assert_eq!(d.poll(), None);
        assert_eq!(d.buffered(), 2);
    }
}
