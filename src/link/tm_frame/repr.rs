//! A TM frame's fields (`TmFrameRepr`): read from a checked view, and written back into octets
//! with the header, OCF and FECF they imply (the framer shares the sealing step).

use super::{
    FirstHeaderPointer, TmEmitError, TmFrame, TmFrameError, TmFrameParams, FECF_LEN,
    MAX_SPACECRAFT_ID, MAX_VCID, OCF_LEN, PRIMARY_HEADER_LEN, SEGMENT_LENGTH_ID, VERSION,
};
use crate::ccsds::pec;

/// A TM frame's fields (the fixed ones, version, flags and segment length ID, are implied).
/// The data field borrows the octets it was parsed from, or the caller's to emit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct TmFrameRepr<'a> {
    /// Spacecraft ID (10 bits).
    pub spacecraft_id: u16,
    /// Virtual channel ID (3 bits).
    pub vcid: u8,
    /// Master channel frame count.
    pub mc_frame_count: u8,
    /// Virtual channel frame count.
    pub vc_frame_count: u8,
    /// The first header pointer.
    pub first_header_pointer: FirstHeaderPointer,
    /// The data field, exactly [`TmFrameParams::data_len`] octets.
    pub data: &'a [u8],
    /// The OCF (the CLCW), present exactly when the channel carries one.
    pub ocf: Option<[u8; OCF_LEN]>,
}

impl<'a> TmFrameRepr<'a> {
    /// Checks `bytes` (see [`TmFrame::new_checked`]) and returns the fields.
    pub fn parse(bytes: &'a [u8], params: &TmFrameParams) -> Result<TmFrameRepr<'a>, TmFrameError> {
        TmFrame::new_checked(bytes, params).map(|f| f.repr())
    }

    /// Writes the frame into the front of `out`, FECF included (when the channel has one); the
    /// number of octets written, [`TmFrameParams::frame_len`]. The spacecraft ID and VCID are
    /// the repr's (a frame for another receiver can be built; its parser refuses it). Refused
    /// when a field does not fit its bits, the first header pointer lies outside the data
    /// field, the data field's length or the OCF's presence disagree with `params`, or `out`
    /// is too short.
    pub fn emit(&self, params: &TmFrameParams, out: &mut [u8]) -> Result<usize, TmEmitError> {
        let p = params;
        let field = |field, max: u32, found: u32| {
            if found > max {
                Err(TmEmitError::Field { field, max, found })
            } else {
                Ok(())
            }
        };
        field(
            "spacecraft ID",
            u32::from(MAX_SPACECRAFT_ID),
            u32::from(self.spacecraft_id),
        )?;
        field("VCID", u32::from(MAX_VCID), u32::from(self.vcid))?;
        if let FirstHeaderPointer::Packet(at) = self.first_header_pointer {
            field(
                "first header pointer",
                // At most 0x7fd, so the conversion cannot fail.
                u32::try_from(p.data_len().saturating_sub(1).min(0x7fd)).unwrap_or(0x7fd),
                u32::from(at),
            )?;
        }
        if self.data.len() != p.data_len() {
            return Err(TmEmitError::DataLength {
                expected: p.data_len(),
                found: self.data.len(),
            });
        }
        if self.ocf.is_some() != p.ocf {
            return Err(TmEmitError::Ocf {
                expected: p.ocf,
                found: self.ocf.is_some(),
            });
        }
        let too_small = TmEmitError::BufferTooSmall {
            expected: p.frame_len,
            found: out.len(),
        };
        let frame = out.get_mut(..p.frame_len).ok_or(too_small)?;
        if let Some(d) = frame.get_mut(p.data_range()) {
            d.copy_from_slice(self.data);
        }
        self.seal(p, frame);
        Ok(p.frame_len)
    }

    /// Writes header, OCF and FECF around the data field already in `frame` (exactly
    /// `p.frame_len` octets; the fields already checked): what [`TmFrameRepr::emit`] and the
    /// framer, which builds the data field in place, share. `self.data` is not read.
    pub(crate) fn seal(&self, p: &TmFrameParams, frame: &mut [u8]) {
        let id = (u16::from(VERSION) << 14)
            | ((self.spacecraft_id & MAX_SPACECRAFT_ID) << 4)
            | (u16::from(self.vcid & MAX_VCID) << 1)
            | u16::from(p.ocf);
        let status = (u16::from(SEGMENT_LENGTH_ID) << 11) | self.first_header_pointer.field();
        let [i0, i1] = id.to_be_bytes();
        let [s0, s1] = status.to_be_bytes();
        let header = [i0, i1, self.mc_frame_count, self.vc_frame_count, s0, s1];
        if let Some(h) = frame.get_mut(..PRIMARY_HEADER_LEN) {
            h.copy_from_slice(&header);
        }
        if let Some(ocf) = self.ocf {
            let at = frame.get_mut(p.ocf_start()..);
            if let Some(o) = at.and_then(|f| f.first_chunk_mut::<OCF_LEN>()) {
                *o = ocf;
            }
        }
        if p.fecf {
            let whole = frame.get_mut(..p.frame_len);
            if let Some((body, f)) = whole.and_then(|w| w.split_last_chunk_mut::<FECF_LEN>()) {
                *f = pec(body).to_be_bytes();
            }
        }
    }
}
