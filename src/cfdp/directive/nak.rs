//! The NAK PDU (727.0-B-5 §5.2.6): the receiver asks again for the parts of the file, or the
//! metadata, it lacks within a scope.
//!
//! | octets | field |
//! |---|---|
//! | 0 | directive code `0x08` |
//! | 1–4 | start of scope |
//! | 5–8 | end of scope |
//! | 9– | segment requests: start and end offsets, four octets each (`0`–`0`: the metadata) |

use super::super::error::PduError;
use super::super::field::{Reader, Writer};

/// Octets of one segment request.
pub const SEGMENT_LEN: usize = 8;

/// The segment requests of a NAK: as read (octets checked whole), or as a sender gives them.
#[derive(Debug, Clone, Copy)]
pub enum Segments<'a> {
    /// Octets from a PDU, a whole number of requests, each in order.
    Wire(&'a [u8]),
    /// Requests to write, `(start, end)` each.
    Pairs(&'a [(u32, u32)]),
}

impl<'a> Segments<'a> {
    /// The requests, `(start, end)` each.
    pub fn iter(&self) -> impl Iterator<Item = (u32, u32)> + 'a {
        let (wire, pairs) = match *self {
            Segments::Wire(w) => (w, &[][..]),
            Segments::Pairs(p) => (&[][..], p),
        };
        wire.chunks_exact(SEGMENT_LEN)
            .map(|c| {
                let (s, e) = c.split_at(4);
                (be32(s), be32(e))
            })
            .chain(pairs.iter().copied())
    }

    /// How many requests.
    pub fn len(&self) -> usize {
        match *self {
            Segments::Wire(w) => w.len() / SEGMENT_LEN,
            Segments::Pairs(p) => p.len(),
        }
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

impl PartialEq for Segments<'_> {
    fn eq(&self, other: &Self) -> bool {
        self.iter().eq(other.iter())
    }
}

impl Eq for Segments<'_> {}

/// A NAK PDU's fields.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NakRepr<'a> {
    /// Start of the scope, an offset.
    pub start: u32,
    /// End of the scope, an offset.
    pub end: u32,
    /// The segment requests.
    pub segments: Segments<'a>,
}

impl<'a> NakRepr<'a> {
    /// Reads the fields after the directive code: the scope and each request in order
    /// (`nak-range`), their octets a whole number of requests (`nak-segments`).
    pub(super) fn read(r: &mut Reader<'a>) -> Result<NakRepr<'a>, PduError> {
        let start = r.u32()?;
        let end = r.u32()?;
        in_order(start, end)?;
        let rest = r.rest();
        if !rest.len().is_multiple_of(SEGMENT_LEN) {
            return Err(PduError::NakSegments { found: rest.len() });
        }
        let segments = Segments::Wire(rest);
        for (s, e) in segments.iter() {
            in_order(s, e)?;
        }
        Ok(NakRepr {
            start,
            end,
            segments,
        })
    }

    /// Octets after the directive code.
    pub(super) fn len(&self) -> usize {
        SEGMENT_LEN.saturating_add(self.segments.len().saturating_mul(SEGMENT_LEN))
    }

    /// Writes the fields after the directive code, refusing what parse refuses.
    pub(super) fn write(&self, w: &mut Writer<'_>) -> Result<(), PduError> {
        in_order(self.start, self.end)?;
        w.u32(self.start)?;
        w.u32(self.end)?;
        for (s, e) in self.segments.iter() {
            in_order(s, e)?;
            w.u32(s)?;
            w.u32(e)?;
        }
        Ok(())
    }
}

/// A scope or a request whose end is before its start is refused (`nak-range`).
fn in_order(start: u32, end: u32) -> Result<(), PduError> {
    if end < start {
        return Err(PduError::NakRange { start, end });
    }
    Ok(())
}

/// Four octets, big-endian (fewer read as zero: never, as the chunks are whole).
fn be32(b: &[u8]) -> u32 {
    b.first_chunk::<4>().map_or(0, |c| u32::from_be_bytes(*c))
}
