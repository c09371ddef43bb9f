//! SDLS on the mission's frames: where the security header and the MAC go in a TC and a TM
//! transfer frame, and the FECF written again over the frame as sent.
//!
//! - TC (232.0-B-4 with 355.0-B-2 §4.1.1): primary header, segment header, security header,
//!   ciphertext, MAC, FECF. Only data frames (AD, BD) are protected; a BC frame (Unlock, Set
//!   V(R)) goes in clear, as YAMCS sends it (decision `sdls-clear-bc`).
//! - TM (132.0-B-3 with 355.0-B-2 §4.1.2): primary header, security header, ciphertext (the
//!   packet zone, [`TmFrameParams::with_security`]), MAC, OCF (the CLCW), FECF. The OCF and the
//!   FECF are outside the MAC, as the standard has them.
//!
//! A receiver checks the frame as sent first (length, FECF, addressing: corruption is
//! refused as corruption, for nothing), then verifies SDLS in a copy, and reads the packets
//! from the plaintext.

use super::table::{SaTable, Verified};
use super::{SdlsError, SdlsRefusal, HEADER_LEN, MAC_LEN, OVERHEAD};
use crate::ccsds::pec;
use crate::link::sdls::sa::Channel;
use crate::link::tc_frame::{
    TcContent, TcFrame, TcFrameRepr, FECF_LEN, MAX_FRAME_LEN, SEGMENT_HEADER_LEN,
    TC_PRIMARY_HEADER_LEN,
};
use crate::link::tm_frame::{TmFrameParams, TmFrameRepr, PRIMARY_HEADER_LEN};
use core::ops::Range;

/// The longest TC packet data a protected mission frame carries: 256 octets less headers,
/// SDLS and the FECF.
pub const TC_MAX_DATA: usize =
    MAX_FRAME_LEN - TC_PRIMARY_HEADER_LEN - SEGMENT_HEADER_LEN - OVERHEAD - FECF_LEN;

/// A TM channel's parameters with room for SDLS: the security header before the packet zone,
/// the MAC after it ([`TmFrameParams::with_security`]); `None` when no packet octet would be
/// left.
pub fn secured_tm_params(params: TmFrameParams) -> Option<TmFrameParams> {
    // 14 and 16 octets: both conversions hold.
    let header = u8::try_from(HEADER_LEN).ok()?;
    let mac = u8::try_from(MAC_LEN).ok()?;
    params.with_security(header, mac)
}

/// Writes the FECF over the rest of the frame.
fn refresh_fecf(frame: &mut [u8]) {
    if let Some((body, fecf)) = frame.split_last_chunk_mut::<FECF_LEN>() {
        *fecf = pec(body).to_be_bytes();
    }
}

/// Where the security header starts in a TC frame: after the primary header, and after the
/// segment header when the frame has one.
const fn tc_sec_start(segmented: bool) -> usize {
    if segmented {
        TC_PRIMARY_HEADER_LEN + SEGMENT_HEADER_LEN
    } else {
        TC_PRIMARY_HEADER_LEN
    }
}

/// `repr`, an AD or BD frame with the FECF, protected under `spi` into `out`: its length.
pub fn protect_tc<const N: usize>(
    table: &mut SaTable<N>,
    spi: u16,
    repr: &TcFrameRepr<'_>,
    out: &mut [u8],
) -> Result<usize, SdlsError> {
    let (data, map_id) = match repr.content {
        TcContent::Ad { map_id, data } | TcContent::Bd { map_id, data } => (data, map_id),
        TcContent::Bc(_) => return Err(SdlsError::ControlFrame),
    };
    let too_long = SdlsError::TooLong {
        max: TC_MAX_DATA,
        found: data.len(),
    };
    let mut scratch = [0u8; MAX_FRAME_LEN];
    scratch
        .get_mut(HEADER_LEN..)
        .and_then(|s| s.get_mut(..data.len()))
        .ok_or(too_long)?
        .copy_from_slice(data);
    let field_len = data.len().checked_add(OVERHEAD).ok_or(too_long)?;
    let field = scratch.get(..field_len).ok_or(too_long)?;
    let content = match repr.content {
        TcContent::Ad { .. } => TcContent::Ad {
            map_id,
            data: field,
        },
        _ => TcContent::Bd {
            map_id,
            data: field,
        },
    };
    let framed = TcFrameRepr { content, ..*repr };
    let n = framed.emit(out).map_err(|_| too_long)?;
    let frame = out.get_mut(..n).ok_or(too_long)?;
    let sec_start = tc_sec_start(map_id.is_some());
    // The frame was emitted with its FECF: n is at least FECF_LEN.
    table.protect(spi, frame, sec_start, n.saturating_sub(FECF_LEN))?;
    refresh_fecf(frame);
    Ok(n)
}

/// Verifies a checked AD or BD frame (its FECF and addressing already checked): copies it into
/// `buf`, verifies and decrypts it there; the plaintext data's range in `buf`.
pub fn verify_tc<const N: usize>(
    table: &mut SaTable<N>,
    frame: &TcFrame<&[u8]>,
    buf: &mut [u8; MAX_FRAME_LEN],
) -> Result<(Verified, Range<usize>), SdlsRefusal> {
    let bytes = frame.as_bytes();
    let n = bytes.len();
    let sec_start = tc_sec_start(frame.segment().is_some());
    let mac_end = n.saturating_sub(if frame.fecf().is_some() { FECF_LEN } else { 0 });
    let truncated = SdlsRefusal::Truncated {
        needed: sec_start.saturating_add(OVERHEAD),
        found: mac_end,
    };
    let copy = buf.get_mut(..n).ok_or(truncated)?;
    copy.copy_from_slice(bytes);
    let channel = Channel {
        spacecraft_id: frame.spacecraft_id().get(),
        vcid: frame.vcid().get(),
    };
    let verified = table.verify(copy, sec_start, mac_end, channel)?;
    // Verified: the frame holds the security header and the MAC between sec_start and
    // mac_end, so neither bound saturates.
    let data = sec_start.saturating_add(HEADER_LEN)..mac_end.saturating_sub(MAC_LEN);
    Ok((verified, data))
}

/// A TM frame the framer wrote under `params` (with room for SDLS), protected in place under
/// `spi`, its FECF written again.
pub fn protect_tm<const N: usize>(
    table: &mut SaTable<N>,
    spi: u16,
    params: &TmFrameParams,
    frame: &mut [u8],
) -> Result<(), SdlsError> {
    let len = params.frame_len();
    let frame = frame.get_mut(..len).ok_or(SdlsError::Layout {
        sec_start: PRIMARY_HEADER_LEN,
        mac_end: params.ocf_start(),
        len,
    })?;
    table.protect(spi, frame, PRIMARY_HEADER_LEN, params.ocf_start())?;
    if params.fecf() {
        refresh_fecf(frame);
    }
    Ok(())
}

/// Verifies a parsed TM frame (`parsed`, from `bytes` under `params`: FECF and addressing
/// already checked) in `buf`: the frame with its packet zone in plaintext.
pub fn verify_tm<'b, const N: usize>(
    table: &mut SaTable<N>,
    params: &TmFrameParams,
    parsed: &TmFrameRepr<'_>,
    bytes: &[u8],
    buf: &'b mut [u8],
) -> Result<(Verified, TmFrameRepr<'b>), SdlsRefusal> {
    let len = params.frame_len();
    let truncated = SdlsRefusal::Truncated {
        needed: len,
        found: bytes.len().min(buf.len()),
    };
    let copy = buf.get_mut(..len).ok_or(truncated)?;
    copy.copy_from_slice(bytes.get(..len).ok_or(truncated)?);
    let channel = Channel {
        spacecraft_id: parsed.spacecraft_id,
        vcid: parsed.vcid,
    };
    let verified = table.verify(copy, PRIMARY_HEADER_LEN, params.ocf_start(), channel)?;
    let data = buf.get(params.data_range()).unwrap_or(&[]);
    Ok((verified, TmFrameRepr { data, ..*parsed }))
}
