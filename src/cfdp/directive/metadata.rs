//! The Metadata PDU (727.0-B-5 §5.2.5): a transaction's first directive, what the file is.
//!
//! | octets | field |
//! |---|---|
//! | 0 | directive code `0x07` |
//! | 1 | reserved (7), closure requested (6), reserved (5–4), checksum type (3–0) |
//! | 2–5 | file size (32 bits: no large files) |
//! | 6– | source file name (LV), destination file name (LV), options (TLVs) |

use super::super::codes::ChecksumType;
use super::super::error::PduError;
use super::super::field::{Reader, Writer};
use super::super::tlv::{self, Tlvs};

/// A Metadata PDU's fields.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct MetadataRepr<'a> {
    /// Class 1: the receiver sends a Finished PDU at the end.
    pub closure_requested: bool,
    /// The checksum of the EOF.
    pub checksum: ChecksumType,
    /// The file's size, octets.
    pub file_size: u32,
    /// The file's name at the sender (0 to 255 octets).
    pub source: &'a [u8],
    /// The file's name at the receiver (0 to 255 octets).
    pub dest: &'a [u8],
    /// The options: filestore requests, messages to user, fault handler overrides, flow label.
    pub options: Tlvs<'a>,
}

impl<'a> MetadataRepr<'a> {
    /// Reads the fields after the directive code.
    pub(super) fn read(r: &mut Reader<'a>) -> Result<MetadataRepr<'a>, PduError> {
        let b = r.u8()?;
        let file_size = r.u32()?;
        let source = r.lv()?;
        let dest = r.lv()?;
        Ok(MetadataRepr {
            closure_requested: b & 0x40 != 0,
            checksum: ChecksumType::from_bits(b),
            file_size,
            source,
            dest,
            options: Tlvs::parse(r.rest())?,
        })
    }

    /// Octets after the directive code.
    pub(super) fn len(&self) -> usize {
        7usize
            .saturating_add(self.source.len())
            .saturating_add(self.dest.len())
            .saturating_add(self.options.as_bytes().len())
    }

    /// Writes the fields after the directive code.
    pub(super) fn write(&self, w: &mut Writer<'_>) -> Result<(), PduError> {
        let closure = if self.closure_requested { 0x40 } else { 0 };
        w.u8(closure | self.checksum.value())?;
        w.u32(self.file_size)?;
        tlv::write_lv(w, self.source)?;
        tlv::write_lv(w, self.dest)?;
        w.put(self.options.as_bytes())
    }
}
