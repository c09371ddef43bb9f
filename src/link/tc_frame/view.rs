//! The checked view over a TC frame's octets (`TcFrame`): the checks of [`super::TcFrameError`] in
//! their order, one named step each, and the accessors of a frame that passed them; and the
//! iterator over the whole packets of its data (`Packets`).

use super::{
    ControlCommand, FrameKind, MapId, SpacecraftId, TcContent, TcFrameConfig, TcFrameError,
    TcFrameRepr, TcPrimaryHeader, VcConfig, Vcid, FECF_LEN, SEGMENT_HEADER_LEN, TC_MAX_FRAME_LEN,
    TC_PRIMARY_HEADER_LEN, TC_VERSION, UNSEGMENTED,
};
use crate::ccsds::pec;
use crate::ccsds::primary::{PrimaryHeader, PRIMARY_LEN};

/// A TC frame whose every [`TcFrameError`] check (but `packet-boundary`) has passed, over its
/// octets: `T` is the buffer (`&[u8]`, an array, a `heapless::Vec`, ...).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TcFrame<T: AsRef<[u8]>> {
    buffer: T,
    pub(super) header: TcPrimaryHeader,
    pub(super) kind: FrameKind,
    pub(super) segment_header: bool,
    fecf: bool,
}

impl<T: AsRef<[u8]>> TcFrame<T> {
    /// Checks `buffer` as one whole TC frame of the channel `config` describes (see
    /// [`TcFrameError`] for the checks and their order).
    pub fn new_checked(buffer: T, config: &TcFrameConfig<'_>) -> Result<TcFrame<T>, TcFrameError> {
        let bytes = buffer.as_ref();
        let (header, kind) = check_header(bytes, config)?;
        check_fecf(bytes, config)?;
        let vc = check_address(&header, config)?;
        let frame = TcFrame {
            buffer,
            header,
            kind,
            segment_header: vc.segment_header && kind != FrameKind::Bc,
            fecf: config.fecf,
        };
        frame.check_segment(vc)?;
        if kind == FrameKind::Bc {
            ControlCommand::parse(frame.data_field())?;
        }
        Ok(frame)
    }

    /// Checks 7 (`sequence-flags`, `map-id`): a segment header, when the frame has one, says
    /// "whole packets" and names a MAP the channel accepts.
    #[inline]
    fn check_segment(&self, vc: &VcConfig) -> Result<(), TcFrameError> {
        if let Some((flags, map_id)) = self.segment() {
            if flags != UNSEGMENTED {
                return Err(TcFrameError::SequenceFlags {
                    expected: UNSEGMENTED,
                    found: flags,
                });
            }
            if vc.map_ids >> map_id.get() & 1 == 0 {
                return Err(TcFrameError::MapId {
                    vcid: self.header.vcid,
                    found: map_id.get(),
                });
            }
        }
        Ok(())
    }

    /// The buffer back.
    pub fn into_inner(self) -> T {
        self.buffer
    }

    /// The whole frame.
    pub fn as_bytes(&self) -> &[u8] {
        self.buffer.as_ref()
    }

    /// The primary header.
    pub fn header(&self) -> TcPrimaryHeader {
        self.header
    }

    /// AD, BD or BC.
    pub fn kind(&self) -> FrameKind {
        self.kind
    }

    /// The spacecraft ID (the receiver's).
    pub fn spacecraft_id(&self) -> SpacecraftId {
        SpacecraftId::masked(self.header.spacecraft_id)
    }

    /// The virtual channel (one the receiver accepts).
    pub fn vcid(&self) -> Vcid {
        Vcid::masked(self.header.vcid)
    }

    /// The frame sequence number N(S).
    pub fn seq(&self) -> u8 {
        self.header.seq
    }

    /// The frame data field: everything between the primary header and the FECF (the
    /// segment header included, when there is one).
    pub fn data_field(&self) -> &[u8] {
        let bytes = self.buffer.as_ref();
        let end = bytes
            .len()
            .saturating_sub(if self.fecf { FECF_LEN } else { 0 });
        bytes.get(TC_PRIMARY_HEADER_LEN..end).unwrap_or(&[])
    }

    /// The segment header's sequence flags and MAP ID, if the frame has one.
    pub fn segment(&self) -> Option<(u8, MapId)> {
        if !self.segment_header {
            return None;
        }
        let b = *self.data_field().first()?;
        Some((b >> 6, MapId::masked(b)))
    }

    /// The MAP ID, if the frame has a segment header.
    pub fn map_id(&self) -> Option<MapId> {
        self.segment().map(|(_, m)| m)
    }

    /// The data an AD or BD frame carries (after the segment header), or a BC frame's
    /// control command octets.
    pub fn data(&self) -> &[u8] {
        let field = self.data_field();
        if self.segment_header {
            field.get(SEGMENT_HEADER_LEN..).unwrap_or(&[])
        } else {
            field
        }
    }

    /// The control command of a BC frame; `None` for AD and BD frames.
    pub fn control_command(&self) -> Option<ControlCommand> {
        match self.kind {
            FrameKind::Bc => ControlCommand::parse(self.data_field()).ok(),
            FrameKind::Ad | FrameKind::Bd => None,
        }
    }

    /// The FECF as carried (and checked), if the channel has one.
    pub fn fecf(&self) -> Option<u16> {
        let bytes = self.buffer.as_ref();
        match (self.fecf, bytes.last_chunk::<FECF_LEN>()) {
            (true, Some(f)) => Some(u16::from_be_bytes(*f)),
            _ => None,
        }
    }

    /// The whole space packets of an AD or BD frame's data, in order (none for a BC frame):
    /// see [`Packets`].
    pub fn packets(&self) -> Packets<'_> {
        match self.kind {
            FrameKind::Ad | FrameKind::Bd => Packets::new(self.data()),
            FrameKind::Bc => Packets::new(&[]),
        }
    }

    /// The frame's fields.
    pub fn repr(&self) -> TcFrameRepr<'_> {
        let content = match self.kind {
            FrameKind::Ad => TcContent::Ad {
                map_id: self.map_id(),
                data: self.data(),
            },
            FrameKind::Bd => TcContent::Bd {
                map_id: self.map_id(),
                data: self.data(),
            },
            FrameKind::Bc => {
                TcContent::Bc(self.control_command().unwrap_or(ControlCommand::Unlock))
            }
        };
        TcFrameRepr {
            spacecraft_id: self.spacecraft_id(),
            vcid: self.vcid(),
            seq: self.header.seq,
            content,
        }
    }
}

/// The error of a frame shorter than the channel's shortest: check 1's, and the fallback of
/// the steps after it (which cannot meet a shorter frame once it has passed).
fn truncated(bytes: &[u8], config: &TcFrameConfig<'_>) -> TcFrameError {
    TcFrameError::Truncated {
        expected: config.min_frame_len(),
        found: bytes.len(),
    }
}

/// Checks 1 to 4 (`truncated`, `version`, `flags`, `spare`, `length`, `too-long`): the
/// header's fixed fields and the frame's length, before anything is read past the header.
#[inline]
fn check_header(
    bytes: &[u8],
    config: &TcFrameConfig<'_>,
) -> Result<(TcPrimaryHeader, FrameKind), TcFrameError> {
    let n = bytes.len();
    if n < config.min_frame_len() {
        return Err(truncated(bytes, config));
    }
    let header = TcPrimaryHeader::read(bytes).ok_or(truncated(bytes, config))?;
    if header.version != TC_VERSION {
        return Err(TcFrameError::Version {
            expected: TC_VERSION,
            found: header.version,
        });
    }
    let kind = FrameKind::from_flags(header.bypass, header.control).ok_or(TcFrameError::Flags {
        bypass: u8::from(header.bypass),
        control: u8::from(header.control),
    })?;
    if header.spare != 0 {
        return Err(TcFrameError::Spare {
            expected: 0,
            found: header.spare,
        });
    }
    if header.total_len() != n {
        return Err(TcFrameError::Length {
            expected: header.total_len(),
            found: n,
        });
    }
    let max = config.max_frame_len.min(TC_MAX_FRAME_LEN);
    if n > max {
        return Err(TcFrameError::TooLong { max, found: n });
    }
    Ok((header, kind))
}

/// Check 5 (`fecf`): the CRC-16 over the frame before it, when the channel has one; after the
/// length (which says where the FECF is), before the addressing (so that a corrupted address
/// is reported as corruption).
#[inline]
fn check_fecf(bytes: &[u8], config: &TcFrameConfig<'_>) -> Result<(), TcFrameError> {
    if config.fecf {
        let (body, carried) = bytes
            .split_last_chunk::<FECF_LEN>()
            .ok_or(truncated(bytes, config))?;
        let carried = u16::from_be_bytes(*carried);
        let computed = pec(body);
        if carried != computed {
            return Err(TcFrameError::Fecf { carried, computed });
        }
    }
    Ok(())
}

/// Check 6 (`spacecraft-id`, `vcid`): the frame is this receiver's, on a channel it has; the
/// channel's parameters for the checks after it.
#[inline]
fn check_address<'c>(
    header: &TcPrimaryHeader,
    config: &'c TcFrameConfig<'_>,
) -> Result<&'c VcConfig, TcFrameError> {
    if header.spacecraft_id != config.spacecraft_id.get() {
        return Err(TcFrameError::SpacecraftId {
            expected: config.spacecraft_id.get(),
            found: header.spacecraft_id,
        });
    }
    config
        .vc(header.vcid)
        .ok_or(TcFrameError::Vcid { found: header.vcid })
}

/// The whole space packets in a frame's data, each by its primary header's packet data length
/// (CCSDS 133.0-B-2 §4.1.3.5; several may be blocked in one frame, none spans two). An item is
/// a packet's octets, not judged (the packet layer's parsers do that); the data must end on a
/// packet boundary, or the last item is [`TcFrameError::PacketBoundary`] and the iteration
/// ends.
#[derive(Debug, Clone)]
pub struct Packets<'a> {
    data: &'a [u8],
    at: usize,
    failed: bool,
}

impl<'a> Packets<'a> {
    /// The packets of `data` (an AD or BD frame's data, after the segment header).
    pub const fn new(data: &'a [u8]) -> Packets<'a> {
        Packets {
            data,
            at: 0,
            failed: false,
        }
    }
}

impl<'a> Iterator for Packets<'a> {
    type Item = Result<&'a [u8], TcFrameError>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.failed {
            return None;
        }
        let rest = self.data.get(self.at..).filter(|r| !r.is_empty())?;
        let needed = PrimaryHeader::read(rest).map_or(PRIMARY_LEN, |h| h.total_len());
        match rest.get(..needed) {
            Some(packet) if PrimaryHeader::read(rest).is_some() => {
                // Within `data`: `packet` was taken from it.
                self.at = self.at.saturating_add(needed);
                Some(Ok(packet))
            }
            _ => {
                self.failed = true;
                Some(Err(TcFrameError::PacketBoundary {
                    at: self.at,
                    needed,
                    left: rest.len(),
                }))
            }
        }
    }
}
