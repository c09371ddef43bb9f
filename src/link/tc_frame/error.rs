//! Why octets are not a TC frame, and why a frame could not be written: one variant a check,
//! each with its name (the names `spec/ccsds/bad-inputs.toml` and the CLI print).

/// Why bytes are not a TC transfer frame this receiver accepts. Each variant names one check;
/// [`TcFrame::new_checked`] runs them in the order of [`TcFrameError::NAMES`] (the order of the
/// variants here) and reports the first that fails:
///
/// 1. `truncated`: fewer octets than the shortest frame (header, one data octet, FECF);
/// 2. `version`, `flags`, `spare`: the primary header's fixed fields, in bit order (the
///    version `00`; the flags not `(0, 1)`; the reserved spare `00`);
/// 3. `length`: the frame length field against the octets given (both ways);
/// 4. `too-long`: the frame against the channel's longest;
/// 5. `fecf`: the CRC-16 over the whole frame before it (skipped without an FECF);
/// 6. `spacecraft-id`, `vcid`: the addressing, against the channel's configuration;
/// 7. `sequence-flags`, `map-id`: the segment header of an AD or BD frame on a VC that has
///    one (whole packets only; an accepted MAP);
/// 8. `control-command`: a BC frame's data field is Unlock or Set V(R);
/// 9. `packet-boundary`: not a check of the frame but of its data, run by
///    [`TcFrame::packets`]: the data is whole space packets, back to back.
///
/// The rationale is that of [`crate::ccsds::PacketError`]: the fields fixed for every TC
/// frame first (a frame of another protocol is refused for what it is), the length before the
/// FECF (the length says where the FECF is), the addressing after the FECF (a corrupted
/// spacecraft ID or VCID is reported as corruption, a foreign one only when the frame is
/// intact), and the content last.
///
/// [`TcFrame::new_checked`]: super::TcFrame::new_checked
/// [`TcFrame::packets`]: super::TcFrame::packets
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum TcFrameError {
    /// Fewer octets than the shortest frame.
    #[error("TC frame: {found} octets, fewer than the shortest frame ({expected})")]
    Truncated {
        /// Header, one data octet, and the FECF if the channel has one.
        expected: usize,
        /// Octets given.
        found: usize,
    },
    /// Transfer frame version number other than `00`.
    #[error("TC frame: transfer frame version number must be {expected}, found {found}")]
    Version {
        /// 0.
        expected: u8,
        /// Bits 0–1.
        found: u8,
    },
    /// Bypass flag 0 with control command flag 1: no frame type.
    #[error("TC frame: bypass flag {bypass} with control command flag {control} is no frame type")]
    Flags {
        /// Bit 2.
        bypass: u8,
        /// Bit 3.
        control: u8,
    },
    /// The reserved spare bits are not `00`.
    #[error("TC frame: reserved spare must be {expected}, found {found:#04b}")]
    Spare {
        /// 0.
        expected: u8,
        /// Bits 4–5.
        found: u8,
    },
    /// The frame length field disagrees with the number of octets given.
    #[error("TC frame: the frame length field says {expected} octets, found {found}")]
    Length {
        /// Total length the field declares (field + 1).
        expected: usize,
        /// Octets given.
        found: usize,
    },
    /// Longer than the channel's longest frame.
    #[error("TC frame: {found} octets, longer than this channel's {max}")]
    TooLong {
        /// The channel's longest frame.
        max: usize,
        /// The frame's length.
        found: usize,
    },
    /// The FECF disagrees with the CRC of the other octets.
    #[error("TC frame: FECF carried {carried:#06x}, computed {computed:#06x}")]
    Fecf {
        /// The last two octets, big-endian.
        carried: u16,
        /// CRC-16/CCITT-FALSE of the others.
        computed: u16,
    },
    /// Another spacecraft's frame.
    #[error("TC frame: spacecraft ID {found:#05x}, this receiver is {expected:#05x}")]
    SpacecraftId {
        /// The receiver's.
        expected: u16,
        /// The frame's.
        found: u16,
    },
    /// A virtual channel the receiver does not have.
    #[error("TC frame: virtual channel {found} is not one this receiver accepts")]
    Vcid {
        /// The frame's VCID.
        found: u8,
    },
    /// Segment header sequence flags other than `0b11`: a segment of a packet, which we do
    /// not reassemble.
    #[error("TC frame: sequence flags must be {expected:#04b} (unsegmented), found {found:#04b}")]
    SequenceFlags {
        /// `0b11`.
        expected: u8,
        /// The segment header's bits 0–1.
        found: u8,
    },
    /// A MAP the virtual channel does not accept.
    #[error("TC frame: MAP {found} is not one virtual channel {vcid} accepts")]
    MapId {
        /// The frame's VCID.
        vcid: u8,
        /// The segment header's MAP ID.
        found: u8,
    },
    /// A BC frame whose data field is neither Unlock nor Set V(R).
    #[error("TC frame: a control command of {len} octets starting {head:02x?} is neither Unlock nor Set V(R)")]
    ControlCommand {
        /// Octets in the data field.
        len: usize,
        /// Its first three octets (zeros past its end).
        head: [u8; 3],
    },
    /// The data of an AD or BD frame does not end on a packet boundary: the packet at `at`
    /// needs `needed` octets (its primary header's, or the length its header declares),
    /// only `left` remain.
    #[error("TC frame: the packet at octet {at} of the data needs {needed} octets, {left} left")]
    PacketBoundary {
        /// Offset of the packet in the frame's data.
        at: usize,
        /// Octets the packet needs: 6 for its header, or its declared total length.
        needed: usize,
        /// Octets left in the data from `at`.
        left: usize,
    },
}

impl TcFrameError {
    /// Every check's name, in the order they run.
    pub const NAMES: [&'static str; 13] = [
        "truncated",
        "version",
        "flags",
        "spare",
        "length",
        "too-long",
        "fecf",
        "spacecraft-id",
        "vcid",
        "sequence-flags",
        "map-id",
        "control-command",
        "packet-boundary",
    ];

    /// The failed check's name (`spec/ccsds/bad-inputs.toml`, CLI output).
    #[cfg_attr(
        not(test),
        expect(
            clippy::indexing_slicing,
            reason = "position() maps each variant to its place in NAMES, one entry per variant"
        )
    )]
    pub const fn name(&self) -> &'static str {
        Self::NAMES[self.position()]
    }

    /// The failed check's place in the check order (0 = first).
    pub const fn position(&self) -> usize {
        match self {
            TcFrameError::Truncated { .. } => 0,
            TcFrameError::Version { .. } => 1,
            TcFrameError::Flags { .. } => 2,
            TcFrameError::Spare { .. } => 3,
            TcFrameError::Length { .. } => 4,
            TcFrameError::TooLong { .. } => 5,
            TcFrameError::Fecf { .. } => 6,
            TcFrameError::SpacecraftId { .. } => 7,
            TcFrameError::Vcid { .. } => 8,
            TcFrameError::SequenceFlags { .. } => 9,
            TcFrameError::MapId { .. } => 10,
            TcFrameError::ControlCommand { .. } => 11,
            TcFrameError::PacketBoundary { .. } => 12,
        }
    }
}

/// Why a frame could not be written.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum TcEmitError {
    /// The caller's buffer is shorter than the frame.
    #[error("the frame needs {expected} octets, the buffer has {found}")]
    BufferTooSmall {
        /// The frame's length.
        expected: usize,
        /// The buffer's length.
        found: usize,
    },
    /// More data than one TC frame holds (1024 octets in all).
    #[error("a frame of {found} octets, at most {max} fit the frame length field")]
    FrameTooLong {
        /// [`TC_MAX_FRAME_LEN`](super::TC_MAX_FRAME_LEN).
        max: usize,
        /// The frame's length with this data.
        found: usize,
    },
}
