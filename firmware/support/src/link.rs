//! One direction of a byte link (UART, TCP) to packets of one kind, through the library's
//! [`Deframer`]: garbage and partial packets resync there and are counted there.

use mmic::wire::deframer::{Deframed, Deframer};
use mmic::wire::PacketKind;

/// A non-blocking byte source (a UART's receive FIFO).
pub trait ByteSource {
    /// Copies what has arrived, up to `buf.len()` bytes (0: nothing; an error counts as 0).
    fn read(&mut self, buf: &mut [u8]) -> usize;
}

/// A byte sink (a UART's transmitter).
pub trait ByteSink {
    /// Sends `bytes`; false when they did not all go out.
    fn write(&mut self, bytes: &[u8]) -> bool;
}

/// Deframer buffer, bytes.
pub const BUF: usize = 256;

/// Packets of one kind from a byte stream, with counts of what was not one.
pub struct Link {
    d: Deframer<BUF>,
    kind: PacketKind,
    /// Valid packets of another kind, dropped.
    pub other_kind: u32,
}

impl Link {
    /// Takes packets of `kind`.
    pub const fn new(kind: PacketKind) -> Self {
        Link {
            d: Deframer::new(),
            kind,
            other_kind: 0,
        }
    }

    /// Bytes dropped by the deframer so far (garbage, false headers, cut packets).
    pub const fn discarded(&self) -> u64 {
        self.d.discarded_total()
    }

    /// Packets of this link's kind found so far, plus those of other kinds.
    pub const fn frames(&self) -> u64 {
        self.d.frames_total()
    }

    /// The next packet, oldest first: from what is buffered, else from what `src` has now. A
    /// read that brings nothing while a partial packet is buffered means the line went idle:
    /// the deframer resyncs past it ([`Deframer::resync`]).
    pub fn next<const L: usize>(&mut self, src: &mut impl ByteSource) -> Option<[u8; L]> {
        if let Some(p) = self.poll(false) {
            return Some(p);
        }
        let mut buf = [0u8; BUF];
        let n = src.read(&mut buf[..self.d.free()]);
        self.d.push(&buf[..n]);
        self.poll(n == 0)
    }

    /// Pushes all of `bytes` (a TCP read) and hands every packet of this kind to `sink`.
    pub fn feed<const L: usize>(&mut self, mut bytes: &[u8], mut sink: impl FnMut([u8; L])) {
        while !bytes.is_empty() {
            bytes = &bytes[self.d.push(bytes)..];
            while let Some(p) = self.poll(false) {
                sink(p);
            }
        }
    }

    fn poll<const L: usize>(&mut self, idle: bool) -> Option<[u8; L]> {
        loop {
            let e = if idle { self.d.resync() } else { self.d.poll() }?;
            match e {
                Deframed::Frame(f) if f.kind() == self.kind => {
                    if let Ok(p) = f.as_bytes().try_into() {
                        return Some(p);
                    }
                    self.other_kind = self.other_kind.saturating_add(1);
                }
                Deframed::Frame(_) => self.other_kind = self.other_kind.saturating_add(1),
                Deframed::Discarded(_) => {}
            }
        }
    }
}
