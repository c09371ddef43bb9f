//! The checked view over a TM frame's octets (`TmFrame`): the checks of [`super::TmFrameError`] in
//! their order, one named step each, and the accessors of a frame that passed them.

use super::{
    field, FirstHeaderPointer, TmFrameError, TmFrameParams, TmFrameRepr, FECF_LEN,
    FHP_NO_PACKET_START, FHP_ONLY_IDLE_DATA, MAX_SPACECRAFT_ID, OCF_LEN, SEGMENT_LENGTH_ID,
    VERSION,
};
use crate::ccsds::pec;
use crate::link::low::u8_of_u16;

/// A frame whose every [`TmFrameError`] check has passed, over its octets.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TmFrame<'a> {
    bytes: &'a [u8],
    params: TmFrameParams,
}

/// Octet `i` of `b`, 0 past its end (only read after the length check).
fn octet(b: &[u8], i: usize) -> u8 {
    b.get(i).copied().unwrap_or(0)
}

impl<'a> TmFrame<'a> {
    /// Checks `bytes` as one TM frame under `params` (see [`TmFrameError`] for the checks and
    /// their order).
    pub fn new_checked(
        bytes: &'a [u8],
        params: &TmFrameParams,
    ) -> Result<TmFrame<'a>, TmFrameError> {
        let p = *params;
        let (id, status) = check_fixed(bytes, &p)?;
        check_fecf(bytes, &p)?;
        check_address(id, &p)?;
        check_status(status, &p)?;
        Ok(TmFrame { bytes, params: p })
    }

    /// The frame's octets.
    pub fn as_bytes(&self) -> &'a [u8] {
        self.bytes
    }
    fn id(&self) -> u16 {
        u16::from_be_bytes([octet(self.bytes, 0), octet(self.bytes, 1)])
    }
    /// Spacecraft ID (the parameters').
    pub fn spacecraft_id(&self) -> u16 {
        (self.id() >> 4) & MAX_SPACECRAFT_ID
    }
    /// VCID (the parameters').
    pub fn vcid(&self) -> u8 {
        u8_of_u16((self.id() >> 1) & 0x7)
    }
    /// Master channel frame count.
    pub fn mc_frame_count(&self) -> u8 {
        octet(self.bytes, field::MC_FRAME_COUNT)
    }
    /// Virtual channel frame count.
    pub fn vc_frame_count(&self) -> u8 {
        octet(self.bytes, field::VC_FRAME_COUNT)
    }
    /// The first header pointer.
    pub fn first_header_pointer(&self) -> FirstHeaderPointer {
        FirstHeaderPointer::from_field(u16::from_be_bytes([
            octet(self.bytes, 4),
            octet(self.bytes, 5),
        ]))
    }
    /// The data field.
    pub fn data(&self) -> &'a [u8] {
        self.bytes.get(self.params.data_range()).unwrap_or(&[])
    }
    /// The OCF, when the channel carries one.
    pub fn ocf(&self) -> Option<[u8; OCF_LEN]> {
        if !self.params.ocf {
            return None;
        }
        self.bytes
            .get(self.params.ocf_start()..)
            .and_then(|o| o.first_chunk::<OCF_LEN>())
            .copied()
    }
    /// The frame's fields.
    pub fn repr(&self) -> TmFrameRepr<'a> {
        TmFrameRepr {
            spacecraft_id: self.spacecraft_id(),
            vcid: self.vcid(),
            mc_frame_count: self.mc_frame_count(),
            vc_frame_count: self.vc_frame_count(),
            first_header_pointer: self.first_header_pointer(),
            data: self.data(),
            ocf: self.ocf(),
        }
    }
}

/// Checks 1 and 2 (`length`, `version` … `ocf-flag`): the frame's length and the header's
/// fields fixed for every frame of the mission, before the CRC (a frame of another version or
/// layout is refused for what it is); the identification and the data field status octets.
#[inline]
fn check_fixed(bytes: &[u8], p: &TmFrameParams) -> Result<(u16, u16), TmFrameError> {
    if bytes.len() != p.frame_len {
        return Err(TmFrameError::Length {
            expected: p.frame_len,
            found: bytes.len(),
        });
    }
    let id = u16::from_be_bytes([octet(bytes, 0), octet(bytes, 1)]);
    let version = u8_of_u16(id >> 14);
    if version != VERSION {
        return Err(TmFrameError::Version {
            expected: VERSION,
            found: version,
        });
    }
    let status = u16::from_be_bytes([octet(bytes, 4), octet(bytes, 5)]);
    if status & 0x8000 != 0 {
        return Err(TmFrameError::SecondaryHeaderFlag);
    }
    let ocf_flag = id & 1 != 0;
    if ocf_flag != p.ocf {
        return Err(TmFrameError::OcfFlag {
            expected: p.ocf,
            found: ocf_flag,
        });
    }
    Ok((id, status))
}

/// Check 3 (`fecf`): the CRC-16 over the frame before it, when the channel has one.
#[inline]
fn check_fecf(bytes: &[u8], p: &TmFrameParams) -> Result<(), TmFrameError> {
    if p.fecf {
        let (body, fecf) = bytes.split_at(bytes.len().saturating_sub(FECF_LEN));
        let carried = u16::from_be_bytes([octet(fecf, 0), octet(fecf, 1)]);
        let computed = pec(body);
        if carried != computed {
            return Err(TmFrameError::Fecf { carried, computed });
        }
    }
    Ok(())
}

/// Check 4 (`spacecraft-id`, `vcid`): the frame's addressee, after the CRC, so that a
/// corrupted ID is reported as corruption and a foreign one only when the frame is intact.
#[inline]
fn check_address(id: u16, p: &TmFrameParams) -> Result<(), TmFrameError> {
    let spacecraft_id = (id >> 4) & MAX_SPACECRAFT_ID;
    if spacecraft_id != p.spacecraft_id {
        return Err(TmFrameError::SpacecraftId {
            expected: p.spacecraft_id,
            found: spacecraft_id,
        });
    }
    let vcid = u8_of_u16((id >> 1) & 0x7);
    if vcid != p.vcid {
        return Err(TmFrameError::Vcid {
            expected: p.vcid,
            found: vcid,
        });
    }
    Ok(())
}

/// Checks 5 and 6 (`synch-flag` … `segment-length-id`, `first-header-pointer`): the data field
/// status says "packets", and only then is its first header pointer read (with the synch flag
/// set it means nothing, 132.0-B-3 §4.1.2.7.6).
#[inline]
fn check_status(status: u16, p: &TmFrameParams) -> Result<(), TmFrameError> {
    if status & 0x4000 != 0 {
        return Err(TmFrameError::SynchFlag);
    }
    if status & 0x2000 != 0 {
        return Err(TmFrameError::PacketOrderFlag);
    }
    let segment = u8_of_u16((status >> 11) & 0b11);
    if segment != SEGMENT_LENGTH_ID {
        return Err(TmFrameError::SegmentLengthId {
            expected: SEGMENT_LENGTH_ID,
            found: segment,
        });
    }
    let fhp = status & 0x7ff;
    if usize::from(fhp) >= p.data_len() && fhp != FHP_NO_PACKET_START && fhp != FHP_ONLY_IDLE_DATA {
        return Err(TmFrameError::FirstHeaderPointer {
            data_len: p.data_len(),
            found: fhp,
        });
    }
    Ok(())
}
