//! The TC primary header's five octets and their fields, decoded but not judged: the one place
//! that knows where each field's bits lie (232.0-B-4 §4.1.2).

use super::TC_PRIMARY_HEADER_LEN;

/// The primary header's fields as they lie in the octets, decoded but not judged.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct TcPrimaryHeader {
    /// Transfer frame version number (2 bits).
    pub version: u8,
    /// Bypass flag.
    pub bypass: bool,
    /// Control command flag.
    pub control: bool,
    /// Reserved spare (2 bits).
    pub spare: u8,
    /// Spacecraft ID (10 bits).
    pub spacecraft_id: u16,
    /// Virtual channel ID (6 bits).
    pub vcid: u8,
    /// Frame length field: octets in the frame minus 1 (10 bits).
    pub frame_length: u16,
    /// Frame sequence number N(S).
    pub seq: u8,
}

impl TcPrimaryHeader {
    /// Decodes the first five octets of `bytes`; `None` if there are fewer.
    pub fn read(bytes: &[u8]) -> Option<TcPrimaryHeader> {
        let h: &[u8; TC_PRIMARY_HEADER_LEN] = bytes.first_chunk()?;
        let [b0, b1, b2, b3, seq] = *h;
        Some(TcPrimaryHeader {
            version: b0 >> 6,
            bypass: b0 & 0x20 != 0,
            control: b0 & 0x10 != 0,
            spare: (b0 >> 2) & 0b11,
            spacecraft_id: u16::from_be_bytes([b0 & 0b11, b1]),
            vcid: b2 >> 2,
            frame_length: u16::from_be_bytes([b2 & 0b11, b3]),
            seq,
        })
    }

    /// The frame's total length in octets as the frame length field says: field + 1.
    pub fn total_len(&self) -> usize {
        // At most 65,536.
        usize::from(self.frame_length).saturating_add(1)
    }

    /// The five octets (fields wider than their bits are masked).
    pub const fn to_bytes(&self) -> [u8; TC_PRIMARY_HEADER_LEN] {
        let [scid_hi, scid_lo] = self.spacecraft_id.to_be_bytes();
        let [len_hi, len_lo] = self.frame_length.to_be_bytes();
        [
            (self.version & 0b11) << 6
                | if self.bypass { 1 << 5 } else { 0 }
                | if self.control { 1 << 4 } else { 0 }
                | (self.spare & 0b11) << 2
                | scid_hi & 0b11,
            scid_lo,
            (self.vcid & 0x3f) << 2 | len_hi & 0b11,
            len_lo,
            self.seq,
        ]
    }
}
