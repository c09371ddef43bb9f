//! The checks and the writing that telecommands and telemetry share: a PUS packet is a fixed
//! header (primary + secondary), user data, and the packet error control. `tc` and `tm` differ
//! only in their fixed header's layout, which they hand in as `H`.

use super::error::{EmitError, PacketError};
use super::primary::{PacketType, PrimaryHeader, PRIMARY_LEN, UNSEGMENTED, VERSION};
use super::{pec, PEC_LEN, PUS_VERSION};
use zerocopy::{FromBytes, Immutable, IntoBytes, KnownLayout, Unaligned};

/// Most octets in a space packet: 6 of primary header and at most 65,536 in the data field.
pub const MAX_PACKET_LEN: usize = PRIMARY_LEN + 65536;

/// The fixed header of a PUS packet type: its primary header, then its secondary header,
/// whose first octet's high nibble is the PUS version.
pub(crate) trait FixedHeader:
    FromBytes + IntoBytes + KnownLayout + Immutable + Unaligned + Sized
{
    /// Telecommand or telemetry.
    const KIND: PacketType;
    /// Octets of the fixed header.
    const LEN: usize = core::mem::size_of::<Self>();
    /// Octets of the shortest packet: no user data.
    const MIN_PACKET_LEN: usize = Self::LEN + PEC_LEN;
    /// Most user data octets in one packet.
    const MAX_DATA_LEN: usize = MAX_PACKET_LEN - Self::MIN_PACKET_LEN;
}

/// A packet that passed every check: what the views `Tc` and `Tm` hold.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Checked<'a, H> {
    pub bytes: &'a [u8],
    pub header: &'a H,
    pub primary: PrimaryHeader,
    pub data: &'a [u8],
    pub pec: u16,
}

/// Runs the checks of [`PacketError`] in their order on `bytes` as a packet with fixed header
/// `H`, accepting the APIDs in `accepted`.
#[inline]
pub(crate) fn check<'a, H: FixedHeader>(
    bytes: &'a [u8],
    accepted: &[u16],
) -> Result<Checked<'a, H>, PacketError> {
    let kind = H::KIND;
    let truncated = PacketError::Truncated {
        kind,
        expected: H::MIN_PACKET_LEN,
        found: bytes.len(),
    };
    if bytes.len() < H::MIN_PACKET_LEN {
        return Err(truncated);
    }
    let (body, pec_bytes) = bytes.split_last_chunk::<PEC_LEN>().ok_or(truncated)?;
    let (header, data) = H::ref_from_prefix(body).map_err(|_| truncated)?;
    let primary = PrimaryHeader::read(bytes).ok_or(truncated)?;
    check_primary(&primary, kind, bytes.len())?;
    let pus_version = bytes.get(PRIMARY_LEN).map_or(0, |b| b >> 4);
    if pus_version != PUS_VERSION {
        return Err(PacketError::PusVersion {
            kind,
            expected: PUS_VERSION,
            found: pus_version,
        });
    }
    let carried = u16::from_be_bytes(*pec_bytes);
    let computed = pec(body);
    if carried != computed {
        return Err(PacketError::Checksum {
            kind,
            carried,
            computed,
        });
    }
    // A loop rather than `contains`, whose slice specialisation is an out-of-line call: 0.8 ns
    // of a 15-ns TC parse (issue 25).
    #[expect(
        clippy::manual_contains,
        reason = "a loop rather than `contains`, whose slice specialisation is an out-of-line call (issue 25)"
    )]
    let known = accepted.iter().any(|&a| a == primary.apid);
    if !known {
        return Err(PacketError::Apid {
            kind,
            found: primary.apid,
        });
    }
    Ok(Checked {
        bytes,
        header,
        primary,
        data,
        pec: carried,
    })
}

/// The primary header's checks of [`PacketError`], in their order: version, type, secondary
/// header flag, sequence flags, and the length it states against the `len` octets received.
#[inline]
fn check_primary(primary: &PrimaryHeader, kind: PacketType, len: usize) -> Result<(), PacketError> {
    if primary.version != VERSION {
        return Err(PacketError::Version {
            kind,
            expected: VERSION,
            found: primary.version,
        });
    }
    if primary.packet_type != kind {
        return Err(PacketError::PacketType {
            expected: kind,
            found: primary.packet_type,
        });
    }
    if !primary.secondary_header {
        return Err(PacketError::SecondaryHeaderFlag {
            kind,
            expected: 1,
            found: 0,
        });
    }
    if primary.seq_flags != UNSEGMENTED {
        return Err(PacketError::SequenceFlags {
            kind,
            expected: UNSEGMENTED,
            found: primary.seq_flags,
        });
    }
    if primary.total_len() != len {
        return Err(PacketError::Length {
            kind,
            expected: primary.total_len(),
            found: len,
        });
    }
    Ok(())
}

/// Octets of a packet with fixed header `H` and `data_len` octets of user data, or the error
/// if that is more than a packet holds.
pub(crate) fn packet_len<H: FixedHeader>(data_len: usize) -> Result<usize, EmitError> {
    match H::MIN_PACKET_LEN.checked_add(data_len) {
        Some(n) if data_len <= H::MAX_DATA_LEN => Ok(n),
        _ => Err(EmitError::DataTooLong {
            max: H::MAX_DATA_LEN,
            found: data_len,
        }),
    }
}

/// Writes `header`, `data` and the packet error control into the front of `out`; the length.
/// `header` must be built for `packet_len::<H>(data.len())` octets.
pub(crate) fn write<H: FixedHeader>(
    header: &H,
    data: &[u8],
    out: &mut [u8],
) -> Result<usize, EmitError> {
    let len = packet_len::<H>(data.len())?;
    let too_small = EmitError::BufferTooSmall {
        expected: len,
        found: out.len(),
    };
    let packet = out.get_mut(..len).ok_or(too_small)?;
    let (body, pec_out) = packet.split_last_chunk_mut::<PEC_LEN>().ok_or(too_small)?;
    let (head, user) = body.split_at_mut(H::LEN.min(body.len()));
    head.copy_from_slice(header.as_bytes());
    user.copy_from_slice(data);
    *pec_out = pec(body).to_be_bytes();
    Ok(len)
}

/// The accessors every checked view (`Tc`, `Tm`: a `Checked` in field 0) has alike.
macro_rules! view_accessors {
    () => {
        /// The whole packet.
        pub fn as_bytes(&self) -> &'a [u8] {
            self.0.bytes
        }

        /// The primary header.
        pub fn primary(&self) -> PrimaryHeader {
            self.0.primary
        }

        /// The APID (one of those the parser accepted).
        pub fn apid(&self) -> Apid {
            Apid::masked(self.0.primary.apid)
        }

        /// The packet sequence count.
        pub fn seq_count(&self) -> SeqCount {
            SeqCount::masked(self.0.primary.seq_count)
        }

        /// Service type ID.
        pub fn service(&self) -> u8 {
            self.0.header.secondary.service
        }

        /// Message subtype ID.
        pub fn subservice(&self) -> u8 {
            self.0.header.secondary.subservice
        }

        /// The packet error control as carried (and checked).
        pub fn pec(&self) -> u16 {
            self.0.pec
        }
    };
}
pub(crate) use view_accessors;
