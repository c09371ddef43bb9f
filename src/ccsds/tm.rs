//! A whole PUS-C telemetry packet: primary header, TM secondary header with its CUC time
//! field, source data, packet error control. [`Tm`] is a checked view of the bytes;
//! [`TmRepr`] the packet's fields, whose source data borrows the bytes it was parsed from (or
//! the caller's, to emit).
//!
//! ```
//! use mmic::ccsds::cuc::Cuc;
//! use mmic::ccsds::primary::{Apid, SeqCount};
//! use mmic::ccsds::tm::{Tm, TmRepr};
//! use mmic::ccsds::tm_header::TmSecondaryHeader;
//!
//! let repr = TmRepr {
//!     apid: Apid::new(0x42).unwrap(),
//!     seq_count: SeqCount::new(9).unwrap(),
//!     header: TmSecondaryHeader { service: 17, subservice: 2, time: Cuc::from_millis(1500), ..Default::default() },
//!     source_data: &[],
//! };
//! let mut buf = [0u8; 64];
//! let n = repr.emit(&mut buf).unwrap();
//! assert_eq!(n, 21); // the shortest TM: 6 + 13 + 2
//! let tm = Tm::new_checked(&buf[..n], &[0x42]).unwrap();
//! assert_eq!((tm.service(), tm.subservice(), tm.time().to_millis()), (17, 2, 1500));
//! assert_eq!(TmRepr::parse(&buf[..n], &[0x42]), Ok(repr));
//! ```

use super::error::{EmitError, PacketError};
use super::packet::{check, packet_len, view_accessors, write, Checked, FixedHeader};
use super::primary::{Apid, PacketType, PrimaryHeader, PrimaryLayout, SeqCount};
use super::tm_header::{TmSecondaryHeader, TmSecondaryLayout};
use zerocopy::{FromBytes, Immutable, IntoBytes, KnownLayout, Unaligned};

/// Octets before the source data: primary (6) and secondary (13, time included) headers.
pub const TM_HEADER_LEN: usize = 19;
/// Octets of a telemetry packet without source data.
pub const TM_MIN_LEN: usize = TM_HEADER_LEN + super::PEC_LEN;
/// Most source data octets in one telemetry packet (a data field of 65,536 octets).
pub const TM_MAX_SOURCE_DATA: usize = super::packet::MAX_PACKET_LEN - TM_MIN_LEN;

/// The fixed header of a telemetry packet, byte for byte.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, Hash, FromBytes, IntoBytes, KnownLayout, Immutable, Unaligned,
)]
#[repr(C)]
pub struct TmHeaderLayout {
    /// Octets 0–5.
    pub primary: PrimaryLayout,
    /// Octets 6–18.
    pub secondary: TmSecondaryLayout,
}

impl FixedHeader for TmHeaderLayout {
    const KIND: PacketType = PacketType::Tm;
}

const _: () = assert!(<TmHeaderLayout as FixedHeader>::LEN == TM_HEADER_LEN);
const _: () = assert!(<TmHeaderLayout as FixedHeader>::MAX_DATA_LEN == TM_MAX_SOURCE_DATA);

/// Byte ranges of a telemetry packet's fixed fields, from the layout (the source data runs
/// from [`field::SOURCE_DATA_START`] to two octets before the end).
pub mod field {
    use super::*;
    use crate::ccsds::cuc::CucLayout;
    use crate::wire::layout::span;
    use core::ops::Range;
    use zerocopy::byteorder::big_endian::U16;
    /// Primary header.
    pub const PRIMARY: Range<usize> = span!(TmHeaderLayout, primary, PrimaryLayout);
    /// PUS version and spacecraft time reference status.
    pub const VERSION_TIME_REF: Range<usize> =
        span!(TmHeaderLayout, secondary.version_time_ref, u8);
    /// Service type ID.
    pub const SERVICE: Range<usize> = span!(TmHeaderLayout, secondary.service, u8);
    /// Message subtype ID.
    pub const SUBSERVICE: Range<usize> = span!(TmHeaderLayout, secondary.subservice, u8);
    /// Message type counter.
    pub const COUNTER: Range<usize> = span!(TmHeaderLayout, secondary.counter, U16);
    /// Destination ID.
    pub const DESTINATION_ID: Range<usize> = span!(TmHeaderLayout, secondary.destination_id, U16);
    /// Time (CUC).
    pub const TIME: Range<usize> = span!(TmHeaderLayout, secondary.time, CucLayout);
    /// First octet of the source data.
    pub const SOURCE_DATA_START: usize = TIME.end;
}

/// A telemetry packet whose every [`PacketError`] check has passed, over its bytes (the ground
/// side's parser, and the simulator's; the robot only emits telemetry).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Tm<'a>(Checked<'a, TmHeaderLayout>);

impl<'a> Tm<'a> {
    view_accessors!();

    /// Checks `bytes` as one whole telemetry packet (see [`PacketError`] for the checks and their
    /// order) whose APID is one of `accepted`.
    pub fn new_checked(bytes: &'a [u8], accepted: &[u16]) -> Result<Tm<'a>, PacketError> {
        check::<TmHeaderLayout>(bytes, accepted).map(Tm)
    }

    /// The secondary header.
    pub fn secondary(&self) -> TmSecondaryHeader {
        TmSecondaryHeader::from(&self.0.header.secondary)
    }

    /// Message type counter.
    pub fn counter(&self) -> u16 {
        self.0.header.secondary.counter.get()
    }

    /// Destination ID.
    pub fn destination_id(&self) -> u16 {
        self.0.header.secondary.destination_id.get()
    }

    /// Time the packet was made.
    pub fn time(&self) -> crate::ccsds::cuc::Cuc {
        crate::ccsds::cuc::Cuc::from(&self.0.header.secondary.time)
    }

    /// The source data (between the time field and the CRC).
    pub fn source_data(&self) -> &'a [u8] {
        self.0.data
    }

    /// The packet's fields.
    pub fn repr(&self) -> TmRepr<'a> {
        TmRepr {
            apid: self.apid(),
            seq_count: self.seq_count(),
            header: self.secondary(),
            source_data: self.0.data,
        }
    }
}

/// A telemetry packet's fields. The source data is borrowed, as a telecommand's application
/// data is (see [`crate::ccsds::tc::TcRepr`] for why).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct TmRepr<'a> {
    /// Application process the packet comes from.
    pub apid: Apid,
    /// Packet sequence count.
    pub seq_count: SeqCount,
    /// Secondary header.
    pub header: TmSecondaryHeader,
    /// Source data.
    pub source_data: &'a [u8],
}

impl<'a> TmRepr<'a> {
    /// Checks `bytes` (see [`Tm::new_checked`]) and returns the fields.
    pub fn parse(bytes: &'a [u8], accepted: &[u16]) -> Result<TmRepr<'a>, PacketError> {
        Tm::new_checked(bytes, accepted).map(|tc| tc.repr())
    }

    /// Octets of the packet (saturating at `usize::MAX` for data no packet can hold, which
    /// [`TmRepr::emit`] refuses).
    #[expect(
        clippy::len_without_is_empty,
        reason = "a length of this type is never zero"
    )]
    pub const fn len(&self) -> usize {
        TM_MIN_LEN.saturating_add(self.source_data.len())
    }

    /// Writes the packet into the front of `out`, CRC included; the number of octets
    /// written. Refused when `out` is shorter than [`TmRepr::len`] or the source data
    /// longer than [`TM_MAX_SOURCE_DATA`].
    pub fn emit(&self, out: &mut [u8]) -> Result<usize, EmitError> {
        let len = packet_len::<TmHeaderLayout>(self.source_data.len())?;
        let header = TmHeaderLayout {
            primary: PrimaryLayout::from(&PrimaryHeader::pus(
                PacketType::Tm,
                self.apid,
                self.seq_count,
                len,
            )),
            secondary: TmSecondaryLayout::from(&self.header),
        };
        write(&header, self.source_data, out)
    }
}
