//! Why octets are not a TM frame under the given parameters, and why a frame could not be written:
//! one variant a check, each with its name (`spec/ccsds/bad-inputs.toml`, parser `tm-frame`).

/// Why octets are not a TM transfer frame under the given [`TmFrameParams`]. Each variant
/// names one check; [`TmFrameRepr::parse`] runs them in the order of [`TmFrameError::NAMES`]
/// (the order of the variants) and reports the first that fails:
///
/// 1. `length`: the octets against the fixed frame length;
/// 2. `version` … `ocf-flag`: the header's fields fixed for every frame of the mission;
/// 3. `fecf`: the CRC-16 over the frame (when the FECF is present);
/// 4. `spacecraft-id`, `vcid`: the frame's addressee, against the caller's;
/// 5. `synch-flag` … `segment-length-id`: the data field status says "packets";
/// 6. `first-header-pointer`: inside the data field, or one of its two reserved values.
///
/// As for [`crate::ccsds::PacketError`]: fixed fields before the CRC, so that a frame of
/// another version or layout is refused for what it is; the addressee after the CRC, so that a
/// corrupted ID is reported as corruption and a foreign one only when the frame is intact. The
/// synchronisation flag and its companions come before the first header pointer because they
/// say whether the pointer means anything (with the synch flag set it is undefined, §4.1.2.7.6).
///
/// [`TmFrameParams`]: super::TmFrameParams
/// [`TmFrameRepr::parse`]: super::TmFrameRepr::parse
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum TmFrameError {
    /// Not exactly the frame length of the physical channel.
    #[error("TM frame: {found} octets, the frame length is {expected}")]
    Length {
        /// The managed frame length.
        expected: usize,
        /// Octets given.
        found: usize,
    },
    /// Transfer frame version number other than `00`.
    #[error("TM frame: version number must be {expected}, found {found}")]
    Version {
        /// 0.
        expected: u8,
        /// Bits 0–1.
        found: u8,
    },
    /// The secondary header flag is set: the mission's frames have none (decision
    /// `link-tm-frame`), so the data field would start elsewhere.
    #[error("TM frame: secondary header flag set, the mission's frames have no secondary header")]
    SecondaryHeaderFlag,
    /// The OCF flag disagrees with the managed parameter.
    #[error("TM frame: OCF flag must be {expected}, found {found}")]
    OcfFlag {
        /// Whether the channel carries an OCF.
        expected: bool,
        /// Bit 15.
        found: bool,
    },
    /// The FECF disagrees with the CRC of the other octets.
    #[error("TM frame: FECF carried {carried:#06x}, computed {computed:#06x}")]
    Fecf {
        /// The last two octets, big-endian.
        carried: u16,
        /// CRC-16/CCITT-FALSE of the others.
        computed: u16,
    },
    /// Another spacecraft's frame.
    #[error("TM frame: spacecraft ID must be {expected:#05x}, found {found:#05x}")]
    SpacecraftId {
        /// The receiver's spacecraft ID.
        expected: u16,
        /// Bits 2–11.
        found: u16,
    },
    /// Another virtual channel's frame.
    #[error("TM frame: VCID must be {expected}, found {found}")]
    Vcid {
        /// The receiver's VCID.
        expected: u8,
        /// Bits 12–14.
        found: u8,
    },
    /// The synchronisation flag is set: the data field would not be octet-synchronised packets
    /// (VCA service, which the mission does not use).
    #[error("TM frame: synchronisation flag set, the mission's data fields hold packets")]
    SynchFlag,
    /// The packet order flag is set, reserved (0) when the synch flag is 0 (§4.1.2.7.4).
    #[error("TM frame: packet order flag set, reserved when the synchronisation flag is 0")]
    PacketOrderFlag,
    /// Segment length ID other than `11`, required when the synch flag is 0 (§4.1.2.7.5).
    #[error("TM frame: segment length ID must be {expected:#04b}, found {found:#04b}")]
    SegmentLengthId {
        /// `0b11`.
        expected: u8,
        /// Bits 35–36.
        found: u8,
    },
    /// The first header pointer is neither inside the data field nor `0x7FF`/`0x7FE`.
    #[error(
        "TM frame: first header pointer {found:#05x} lies outside the {data_len}-octet data field"
    )]
    FirstHeaderPointer {
        /// Octets of the data field.
        data_len: usize,
        /// Bits 37–47.
        found: u16,
    },
}

impl TmFrameError {
    /// Every check's name, in the order the parser runs them.
    pub const NAMES: [&'static str; 11] = [
        "length",
        "version",
        "secondary-header-flag",
        "ocf-flag",
        "fecf",
        "spacecraft-id",
        "vcid",
        "synch-flag",
        "packet-order-flag",
        "segment-length-id",
        "first-header-pointer",
    ];

    /// The failed check's name (`spec/ccsds/bad-inputs.toml`).
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
            TmFrameError::Length { .. } => 0,
            TmFrameError::Version { .. } => 1,
            TmFrameError::SecondaryHeaderFlag => 2,
            TmFrameError::OcfFlag { .. } => 3,
            TmFrameError::Fecf { .. } => 4,
            TmFrameError::SpacecraftId { .. } => 5,
            TmFrameError::Vcid { .. } => 6,
            TmFrameError::SynchFlag => 7,
            TmFrameError::PacketOrderFlag => 8,
            TmFrameError::SegmentLengthId { .. } => 9,
            TmFrameError::FirstHeaderPointer { .. } => 10,
        }
    }
}

/// Why a frame could not be written.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum TmEmitError {
    /// The caller's buffer is shorter than the frame.
    #[error("the frame needs {expected} octets, the buffer has {found}")]
    BufferTooSmall {
        /// The frame length.
        expected: usize,
        /// The buffer's length.
        found: usize,
    },
    /// The data field is not exactly as long as the parameters make it.
    #[error("the data field must be {expected} octets, found {found}")]
    DataLength {
        /// [`TmFrameParams::data_len`].
        ///
        /// [`TmFrameParams::data_len`]: super::TmFrameParams::data_len
        expected: usize,
        /// Octets given.
        found: usize,
    },
    /// An OCF given on a channel without one, or none on a channel with one.
    #[error("the channel's OCF flag is {expected}, the frame has an OCF: {found}")]
    Ocf {
        /// [`TmFrameParams::ocf`].
        ///
        /// [`TmFrameParams::ocf`]: super::TmFrameParams::ocf
        expected: bool,
        /// Whether the repr holds an OCF.
        found: bool,
    },
    /// A field whose value its bits cannot carry, or a first header pointer outside the data
    /// field.
    #[error("{field} {found} does not fit (at most {max})")]
    Field {
        /// The field.
        field: &'static str,
        /// Largest value.
        max: u32,
        /// Value given.
        found: u32,
    },
}
