//! A TC frame's fields (`TcFrameRepr`, `TcContent`): parsed from a checked view, and written back
//! into octets with the headers and FECF they imply.

use super::{
    ControlCommand, FrameKind, MapId, SpacecraftId, TcEmitError, TcFrame, TcFrameConfig,
    TcFrameError, TcPrimaryHeader, Vcid, FECF_LEN, SEGMENT_HEADER_LEN, TC_MAX_FRAME_LEN,
    TC_PRIMARY_HEADER_LEN, TC_VERSION, UNSEGMENTED,
};
use crate::ccsds::pec;

/// What an AD, BD or BC frame carries.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "kebab-case"))]
pub enum TcContent<'a> {
    /// Type-AD: data under COP-1's sequence control.
    Ad {
        /// The MAP of the segment header (unsegmented), if the VC has one.
        map_id: Option<MapId>,
        /// The data after the segment header: whole space packets.
        data: &'a [u8],
    },
    /// Type-BD: data bypassing FARM-1's sequence checks.
    Bd {
        /// The MAP of the segment header (unsegmented), if the VC has one.
        map_id: Option<MapId>,
        /// The data after the segment header: whole space packets.
        data: &'a [u8],
    },
    /// Type-BC: a control command to FARM-1.
    Bc(ControlCommand),
}

impl TcContent<'_> {
    /// AD, BD or BC.
    pub const fn kind(&self) -> FrameKind {
        match self {
            TcContent::Ad { .. } => FrameKind::Ad,
            TcContent::Bd { .. } => FrameKind::Bd,
            TcContent::Bc(_) => FrameKind::Bc,
        }
    }

    /// Octets of the data field: segment header, data, or the control command.
    const fn data_field_len(&self) -> usize {
        match self {
            TcContent::Ad { map_id, data } | TcContent::Bd { map_id, data } => {
                let seg = if map_id.is_some() {
                    SEGMENT_HEADER_LEN
                } else {
                    0
                };
                seg.saturating_add(data.len())
            }
            TcContent::Bc(c) => c.len(),
        }
    }
}

/// A TC frame's fields. The data is borrowed, as in [`crate::ccsds::tc::TcRepr`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct TcFrameRepr<'a> {
    /// The spacecraft (robot) the frame is for.
    pub spacecraft_id: SpacecraftId,
    /// Its virtual channel.
    pub vcid: Vcid,
    /// Frame sequence number N(S): COP-1's for AD frames; carried as is in BD and BC frames,
    /// whose sequence FARM-1 does not check (FOP-1 sends 0 there).
    pub seq: u8,
    /// What it carries, and so its kind.
    pub content: TcContent<'a>,
}

impl<'a> TcFrameRepr<'a> {
    /// Checks `bytes` (see [`TcFrame::new_checked`]) and returns the fields.
    pub fn parse(
        bytes: &'a [u8],
        config: &TcFrameConfig<'_>,
    ) -> Result<TcFrameRepr<'a>, TcFrameError> {
        let frame = TcFrame::new_checked(bytes, config)?;
        let header = frame.header;
        let segment_header = frame.segment_header;
        // Rebuilt from `bytes` (not `frame`) so the data borrows the caller's octets.
        let field = bytes
            .get(TC_PRIMARY_HEADER_LEN..bytes.len().saturating_sub(config.fecf_len()))
            .unwrap_or(&[]);
        let map_id = frame.map_id();
        let data = if segment_header {
            field.get(SEGMENT_HEADER_LEN..).unwrap_or(&[])
        } else {
            field
        };
        let content = match frame.kind {
            FrameKind::Ad => TcContent::Ad { map_id, data },
            FrameKind::Bd => TcContent::Bd { map_id, data },
            FrameKind::Bc => TcContent::Bc(ControlCommand::parse(field)?),
        };
        Ok(TcFrameRepr {
            spacecraft_id: SpacecraftId::masked(header.spacecraft_id),
            vcid: Vcid::masked(header.vcid),
            seq: header.seq,
            content,
        })
    }

    /// AD, BD or BC.
    pub const fn kind(&self) -> FrameKind {
        self.content.kind()
    }

    /// Octets of the frame with an FECF (saturating for data no frame holds, which
    /// [`TcFrameRepr::emit`] refuses).
    #[expect(
        clippy::len_without_is_empty,
        reason = "a length of this type is never zero"
    )]
    pub const fn len(&self) -> usize {
        self.len_with(true)
    }

    /// Octets of the frame, with or without the FECF.
    pub const fn len_with(&self, fecf: bool) -> usize {
        let f = if fecf { FECF_LEN } else { 0 };
        TC_PRIMARY_HEADER_LEN
            .saturating_add(f)
            .saturating_add(self.content.data_field_len())
    }

    /// Writes the frame, FECF included, into the front of `out`; the number of octets
    /// written. Refused when `out` is too short or the frame longer than
    /// [`TC_MAX_FRAME_LEN`]. Whether the result suits a channel (its longest frame, its
    /// segment header) is the caller's: the same frame parses back with a [`TcFrameConfig`]
    /// that agrees.
    pub fn emit(&self, out: &mut [u8]) -> Result<usize, TcEmitError> {
        self.emit_with(true, out)
    }

    /// [`TcFrameRepr::emit`], with or without the FECF (for channels without one).
    pub fn emit_with(&self, fecf: bool, out: &mut [u8]) -> Result<usize, TcEmitError> {
        let len = self.len_with(fecf);
        let too_long = TcEmitError::FrameTooLong {
            max: TC_MAX_FRAME_LEN,
            found: len,
        };
        if len > TC_MAX_FRAME_LEN {
            return Err(too_long);
        }
        let too_small = TcEmitError::BufferTooSmall {
            expected: len,
            found: out.len(),
        };
        let frame = out.get_mut(..len).ok_or(too_small)?;
        // len is at most TC_MAX_FRAME_LEN (1,024, checked above): the conversion holds.
        let frame_length = u16::try_from(len.saturating_sub(1)).map_err(|_| too_long)?;
        let (bypass, control) = self.kind().flags();
        let header = TcPrimaryHeader {
            version: TC_VERSION,
            bypass,
            control,
            spare: 0,
            spacecraft_id: self.spacecraft_id.get(),
            vcid: self.vcid.get(),
            frame_length,
            seq: self.seq,
        };
        let (head, rest) = frame.split_at_mut(TC_PRIMARY_HEADER_LEN);
        head.copy_from_slice(&header.to_bytes());
        let f = if fecf { FECF_LEN } else { 0 };
        // The frame holds the FECF it counted (len_with).
        let field_len = rest.len().saturating_sub(f);
        let field = rest.get_mut(..field_len).ok_or(too_small)?;
        match self.content {
            TcContent::Ad { map_id, data } | TcContent::Bd { map_id, data } => {
                let data_out = match map_id {
                    Some(m) => {
                        let (seg, d) = field.split_at_mut(SEGMENT_HEADER_LEN);
                        seg.fill(UNSEGMENTED << 6 | m.get());
                        d
                    }
                    None => field,
                };
                data_out.copy_from_slice(data);
            }
            TcContent::Bc(c) => {
                let (bytes, n) = c.to_bytes();
                field.copy_from_slice(bytes.get(..n).unwrap_or(&[]));
            }
        }
        if fecf {
            let (body, fecf_out) = frame.split_last_chunk_mut::<FECF_LEN>().ok_or(too_small)?;
            *fecf_out = pec(body).to_be_bytes();
        }
        Ok(len)
    }
}
