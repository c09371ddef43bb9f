//! A cursor over a directive's data field, reading and writing big-endian fields with the
//! checks every directive shares: a field cut short is [`PduError::Truncated`] with the
//! octets needed and found, counted from the data field's start.

use super::error::PduError;

/// Reads fields from the front of a data field.
pub(super) struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> Reader<'a> {
    /// A reader at the start of `bytes`.
    pub(super) const fn new(bytes: &'a [u8]) -> Reader<'a> {
        Reader { bytes, at: 0 }
    }

    /// The next `n` octets.
    pub(super) fn take(&mut self, n: usize) -> Result<&'a [u8], PduError> {
        let end = self.at.saturating_add(n);
        let got = self.bytes.get(self.at..end).ok_or(PduError::Truncated {
            expected: end,
            found: self.bytes.len(),
        })?;
        self.at = end;
        Ok(got)
    }

    /// The next octet.
    pub(super) fn u8(&mut self) -> Result<u8, PduError> {
        let b = self.take(1)?;
        Ok(b.first().copied().unwrap_or(0))
    }

    /// The next four octets, big-endian.
    pub(super) fn u32(&mut self) -> Result<u32, PduError> {
        let b = self.take(4)?;
        Ok(b.first_chunk::<4>().map_or(0, |c| u32::from_be_bytes(*c)))
    }

    /// An LV (a file name): a length octet, then that many octets, all within the field
    /// (`lv` otherwise, with the octets declared and those left).
    pub(super) fn lv(&mut self) -> Result<&'a [u8], PduError> {
        let n = usize::from(self.u8()?);
        let left = self.bytes.len().saturating_sub(self.at);
        if n > left {
            return Err(PduError::Lv {
                declared: n,
                found: left,
            });
        }
        self.take(n)
    }

    /// Every octet left.
    pub(super) fn rest(&mut self) -> &'a [u8] {
        let rest = self.bytes.get(self.at..).unwrap_or(&[]);
        self.at = self.bytes.len();
        rest
    }

    /// Refuses octets left after a directive of fixed length (`trailing`).
    pub(super) fn end(&self) -> Result<(), PduError> {
        if self.at < self.bytes.len() {
            return Err(PduError::Trailing {
                expected: self.at,
                found: self.bytes.len(),
            });
        }
        Ok(())
    }
}

/// Writes fields into a data field sized beforehand.
pub(super) struct Writer<'a> {
    out: &'a mut [u8],
    at: usize,
}

impl<'a> Writer<'a> {
    /// A writer at the start of `out`.
    pub(super) fn new(out: &'a mut [u8]) -> Writer<'a> {
        Writer { out, at: 0 }
    }

    /// Writes `bytes` next.
    pub(super) fn put(&mut self, bytes: &[u8]) -> Result<(), PduError> {
        let end = self.at.saturating_add(bytes.len());
        let found = self.out.len();
        let dst = self
            .out
            .get_mut(self.at..end)
            .ok_or(PduError::Buffer { needed: end, found })?;
        dst.copy_from_slice(bytes);
        self.at = end;
        Ok(())
    }

    /// Writes one octet.
    pub(super) fn u8(&mut self, b: u8) -> Result<(), PduError> {
        self.put(&[b])
    }

    /// Writes four octets, big-endian.
    pub(super) fn u32(&mut self, v: u32) -> Result<(), PduError> {
        self.put(&v.to_be_bytes())
    }

    /// Octets written.
    pub(super) const fn written(&self) -> usize {
        self.at
    }
}
