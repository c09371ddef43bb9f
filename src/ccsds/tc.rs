//! A whole PUS-C telecommand: primary header, TC secondary header, application data, packet
//! error control. [`Tc`] is a checked view of the bytes; [`TcRepr`] the packet's fields, whose
//! application data borrows the bytes it was parsed from (or the caller's, to emit).
//!
//! ```
//! use mmic::ccsds::primary::{Apid, SeqCount};
//! use mmic::ccsds::tc::{Tc, TcRepr};
//! use mmic::ccsds::tc_header::{AckFlags, TcSecondaryHeader};
//!
//! let repr = TcRepr {
//!     apid: Apid::new(0x42).unwrap(),
//!     seq_count: SeqCount::new(7).unwrap(),
//!     header: TcSecondaryHeader { ack: AckFlags::ALL, service: 8, subservice: 1, source_id: 1 },
//!     app_data: &[0x60, b'm', b'a'],
//! };
//! let mut buf = [0u8; 64];
//! let n = repr.emit(&mut buf).unwrap();
//! assert_eq!(n, repr.len());
//! let tc = Tc::new_checked(&buf[..n], &[0x42]).unwrap();
//! assert_eq!((tc.service(), tc.subservice(), tc.app_data()), (8, 1, &[0x60, b'm', b'a'][..]));
//! assert_eq!(TcRepr::parse(&buf[..n], &[0x42]), Ok(repr));
//! ```

use super::error::{EmitError, PacketError};
use super::packet::{check, packet_len, view_accessors, write, Checked, FixedHeader};
use super::primary::{Apid, PacketType, PrimaryHeader, PrimaryLayout, SeqCount};
use super::tc_header::{TcSecondaryHeader, TcSecondaryLayout};
use zerocopy::{FromBytes, Immutable, IntoBytes, KnownLayout, Unaligned};

/// Octets before the application data: primary (6) and secondary (5) headers.
pub const TC_HEADER_LEN: usize = 11;
/// Octets of a telecommand without application data.
pub const TC_MIN_LEN: usize = TC_HEADER_LEN + super::PEC_LEN;
/// Most application data octets in one telecommand (a data field of 65,536 octets).
pub const TC_MAX_APP_DATA: usize = super::packet::MAX_PACKET_LEN - TC_MIN_LEN;

/// The fixed header of a telecommand, byte for byte.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, FromBytes, IntoBytes, KnownLayout, Immutable, Unaligned,
)]
#[repr(C)]
pub struct TcHeaderLayout {
    /// Octets 0–5.
    pub primary: PrimaryLayout,
    /// Octets 6–10.
    pub secondary: TcSecondaryLayout,
}

impl FixedHeader for TcHeaderLayout {
    const KIND: PacketType = PacketType::Tc;
}

const _: () = assert!(<TcHeaderLayout as FixedHeader>::LEN == TC_HEADER_LEN);
const _: () = assert!(<TcHeaderLayout as FixedHeader>::MAX_DATA_LEN == TC_MAX_APP_DATA);

/// Byte ranges of a telecommand's fixed fields, from the layout (the application data runs
/// from [`field::APP_DATA_START`] to two octets before the end).
pub mod field {
    use super::*;
    use crate::wire::layout::span;
    use core::ops::Range;
    use zerocopy::byteorder::big_endian::U16;
    /// Primary header.
    pub const PRIMARY: Range<usize> = span!(TcHeaderLayout, primary, PrimaryLayout);
    /// PUS version and acknowledgement flags.
    pub const VERSION_ACK: Range<usize> = span!(TcHeaderLayout, secondary.version_ack, u8);
    /// Service type ID.
    pub const SERVICE: Range<usize> = span!(TcHeaderLayout, secondary.service, u8);
    /// Message subtype ID.
    pub const SUBSERVICE: Range<usize> = span!(TcHeaderLayout, secondary.subservice, u8);
    /// Source ID.
    pub const SOURCE_ID: Range<usize> = span!(TcHeaderLayout, secondary.source_id, U16);
    /// First octet of the application data.
    pub const APP_DATA_START: usize = SOURCE_ID.end;
}

/// A telecommand whose every [`PacketError`] check has passed, over its bytes. Application
/// data is not judged here: its service and subservice decide what it must be, which is the
/// services layer's business; they read it from [`Tc::app_data`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Tc<'a>(Checked<'a, TcHeaderLayout>);

impl<'a> Tc<'a> {
    view_accessors!();

    /// Checks `bytes` as one whole telecommand (see [`PacketError`] for the checks and their
    /// order) whose APID is one of `accepted`.
    #[inline]
    pub fn new_checked(bytes: &'a [u8], accepted: &[u16]) -> Result<Tc<'a>, PacketError> {
        check::<TcHeaderLayout>(bytes, accepted).map(Tc)
    }

    /// The secondary header.
    #[inline]
    pub fn secondary(&self) -> TcSecondaryHeader {
        TcSecondaryHeader::from(&self.0.header.secondary)
    }

    /// Source ID.
    pub fn source_id(&self) -> u16 {
        self.0.header.secondary.source_id.get()
    }

    /// The application data (between the secondary header and the CRC).
    pub fn app_data(&self) -> &'a [u8] {
        self.0.data
    }

    /// The packet's fields.
    #[inline]
    pub fn repr(&self) -> TcRepr<'a> {
        TcRepr {
            apid: self.apid(),
            seq_count: self.seq_count(),
            header: self.secondary(),
            app_data: self.0.data,
        }
    }
}

/// A telecommand's fields. The application data is borrowed: parsing copies nothing, and a
/// service builds its arguments in its own buffer. (A `heapless::Vec` with a capacity
/// parameter would make the type own its data, at the price of a copy per parse, a capacity
/// on every signature and up to 64 KiB of stack for the largest packet.)
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct TcRepr<'a> {
    /// Application process the telecommand is for.
    pub apid: Apid,
    /// Packet sequence count.
    pub seq_count: SeqCount,
    /// Secondary header.
    pub header: TcSecondaryHeader,
    /// Application data.
    pub app_data: &'a [u8],
}

impl<'a> TcRepr<'a> {
    /// Checks `bytes` (see [`Tc::new_checked`]) and returns the fields.
    #[inline]
    pub fn parse(bytes: &'a [u8], accepted: &[u16]) -> Result<TcRepr<'a>, PacketError> {
        Tc::new_checked(bytes, accepted).map(|tc| tc.repr())
    }

    /// Octets of the packet (saturating at `usize::MAX` for data no packet can hold, which
    /// [`TcRepr::emit`] refuses).
    #[expect(
        clippy::len_without_is_empty,
        reason = "a length of this type is never zero"
    )]
    pub const fn len(&self) -> usize {
        TC_MIN_LEN.saturating_add(self.app_data.len())
    }

    /// Writes the packet into the front of `out`, CRC included; the number of octets
    /// written. Refused when `out` is shorter than [`TcRepr::len`] or the application data
    /// longer than [`TC_MAX_APP_DATA`].
    pub fn emit(&self, out: &mut [u8]) -> Result<usize, EmitError> {
        let len = packet_len::<TcHeaderLayout>(self.app_data.len())?;
        let header = TcHeaderLayout {
            primary: PrimaryLayout::from(&PrimaryHeader::pus(
                PacketType::Tc,
                self.apid,
                self.seq_count,
                len,
            )),
            secondary: TcSecondaryLayout::from(&self.header),
        };
        write(&header, self.app_data, out)
    }
}
