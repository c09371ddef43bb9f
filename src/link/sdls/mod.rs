//! Space Data Link Security (CCSDS 355.0-B-2): authenticated encryption of the TC and TM
//! frames' data under security associations, with an anti-replay counter, byte for byte as
//! YAMCS 5.12.8's `SecurityAssociationAes256Gcm128` does it.
//!
//! ```
//! use mmic::link::sdls::{
//!     mask, Channel, Key256, ReplayWindow, Role, SaTable, SecurityAssociation, TxCounter,
//! };
//! use mmic::link::sdls::{HEADER_LEN, MAC_LEN};
//!
//! let channel = Channel { spacecraft_id: 0x101, vcid: 0 };
//! // Both ends hold the key (here a made-up one: real keys come from outside the tree).
//! let key = || Key256::from_bytes([0x5a; 32]);
//! let mut ground = SecurityAssociation::new(
//!     257, key(), channel, mask::TC, Role::Send(TxCounter::boot(None, 16)));
//! let mut robot: SaTable<2> = SaTable::new();
//! robot.add(SecurityAssociation::new(
//!     257, key(), channel, mask::TC, Role::Receive(ReplayWindow::boot(None, 4096, 16)))).unwrap();
//! // Each end reserves its first block of counters (the shell would write it to flash).
//! ground.persisted(ground.due().unwrap());
//! let (spi, floor) = robot.due().next().unwrap();
//! robot.persisted(spi, floor);
//!
//! // A TC frame: 5 + 1 header octets, the security header, 4 octets of data, the MAC.
//! let mut frame = [0u8; 6 + HEADER_LEN + 4 + MAC_LEN];
//! frame[..6].copy_from_slice(&[0x01, 0x01, 0x00, 0x27, 0x00, 0xc0]);
//! frame[6 + HEADER_LEN..][..4].copy_from_slice(b"move");
//! let n = frame.len();
//! ground.protect(&mut frame, 6, n).unwrap();
//! assert_ne!(&frame[20..24], b"move"); // encrypted
//! let sent = frame;
//!
//! let verified = robot.verify(&mut frame, 6, n, channel).unwrap();
//! assert_eq!(verified.iv.get(), 0);
//! assert_eq!(&frame[20..24], b"move");
//!
//! // The same frame again is a replay; a flipped bit fails the MAC.
//! let mut again = sent;
//! assert_eq!(robot.verify(&mut again, 6, n, channel).unwrap_err().name(), "replay");
//! let mut next = sent;
//! ground.protect(&mut next, 6, n).unwrap();
//! next[4] ^= 1; // the frame sequence number: under the MAC by the mission's mask
//! assert_eq!(robot.verify(&mut next, 6, n, channel).unwrap_err().name(), "bad-mac");
//! assert_eq!(robot.counters().refused_total(), 2);
//! ```
//!
//! | module | what |
//! |---|---|
//! | [`iv`] | the 96-bit IV, which is the anti-replay sequence number |
//! | [`key`] | the 256-bit key: never shown, zeroized on drop |
//! | [`counter`] | the sender's counter and the receiver's window, each under a durable reservation |
//! | [`sa`] | one security association: protect and verify a frame in place |
//! | [`table`] | the associations by SPI, with the refusals counted per reason |
//! | [`mask`] | the authentication masks: the mission's, and YAMCS's defaults for comparison |
//! | [`frames`] | where SDLS goes in a TC and a TM frame; the FECF over the frame as sent |
//! | [`mission`] | the mission's associations: SPIs, windows, blocks (`spec/ccsds/sdls.toml`) |
//!
//! The layout (355.0-B-2 §4.1, YAMCS's): the security header is the SPI (2 octets) and the IV
//! (12), right after the frame's headers (a TC frame's segment header, a TM frame's primary
//! header); the trailer is the 16-octet GCM tag, before the OCF and the FECF, which stay
//! outside the MAC. The choices (SPIs, masks, windows, blocks) are in `spec/ccsds/sdls.toml`.
// req: D:sdls-suite, D:sdls-auth-mask, D:sdls-counters, D:sdls-keys

pub mod counter;
pub mod frames;
pub mod iv;
pub mod key;
pub mod mask;
pub mod mission;
pub mod sa;
pub mod table;

pub use counter::{ReplayWindow, TxCounter};
pub use iv::{Iv, IV_LEN};
pub use key::{Key256, KEY_LEN};
pub use sa::{AuthMask, Channel, Role, SecurityAssociation};
pub use table::{SaTable, SdlsCounters, Verified};

/// Octets of the SPI.
pub const SPI_LEN: usize = 2;
/// Octets of the security header: SPI and IV.
pub const HEADER_LEN: usize = SPI_LEN + IV_LEN;
/// Octets of the security trailer: the GCM tag (128 bits, the SDLS baseline).
pub const MAC_LEN: usize = 16;
/// What SDLS adds to a frame.
pub const OVERHEAD: usize = HEADER_LEN + MAC_LEN;

/// Why a receiving end refused a frame, in the order the checks run. A refused frame changes
/// nothing but the counter of its reason ([`SdlsCounters`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum SdlsRefusal {
    /// Too short for the security header and trailer.
    #[error("SDLS: the frame needs {needed} octets for its headers, security header and MAC, has {found}")]
    Truncated {
        /// Octets needed.
        needed: usize,
        /// Octets there.
        found: usize,
    },
    /// No association has this SPI (or it is one of our sending ones).
    #[error("SDLS: no security association with SPI {spi}")]
    UnknownSpi {
        /// The frame's SPI.
        spi: u16,
    },
    /// The SPI's association protects another spacecraft or virtual channel.
    #[error("SDLS: SPI {spi} protects {expected:?}, the frame is of {found:?}")]
    WrongChannel {
        /// The frame's SPI.
        spi: u16,
        /// The association's channel.
        expected: sa::Channel,
        /// The frame's.
        found: sa::Channel,
    },
    /// The IV is the last one accepted or older: a replay.
    #[error("SDLS: IV {found:#x} is not after the last accepted {last:#x}: a replay")]
    Replay {
        /// The window's last IV.
        last: u128,
        /// The frame's.
        found: u128,
    },
    /// The IV is further ahead than the window.
    #[error("SDLS: IV {found:#x} is more than {window} ahead of the last accepted {last:#x}")]
    TooFarAhead {
        /// The window's last IV.
        last: u128,
        /// The frame's.
        found: u128,
        /// W.
        window: u32,
    },
    /// The MAC does not verify: a changed frame, or another key.
    #[error("SDLS: the MAC under SPI {spi} does not verify")]
    BadMac {
        /// The frame's SPI.
        spi: u16,
    },
    /// An authentic frame beyond the durable floor (the sender restarted, or many frames
    /// were lost): refused until the next reservation is written; the sender's
    /// retransmission under a fresh IV is accepted then.
    #[error("SDLS: IV {found:#x} is beyond the durable floor {floor:#x}")]
    NotReserved {
        /// The floor.
        floor: u128,
        /// The frame's IV.
        found: u128,
    },
}

impl SdlsRefusal {
    /// Every reason's name, in the order the checks run.
    pub const NAMES: [&'static str; 7] = [
        "truncated",
        "unknown-spi",
        "wrong-channel",
        "replay",
        "too-far-ahead",
        "bad-mac",
        "not-reserved",
    ];

    /// The reason's name (the counters, the ST\[5\] events).
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

    /// The reason's place in the check order (0 = first).
    pub const fn position(&self) -> usize {
        match self {
            SdlsRefusal::Truncated { .. } => 0,
            SdlsRefusal::UnknownSpi { .. } => 1,
            SdlsRefusal::WrongChannel { .. } => 2,
            SdlsRefusal::Replay { .. } => 3,
            SdlsRefusal::TooFarAhead { .. } => 4,
            SdlsRefusal::BadMac { .. } => 5,
            SdlsRefusal::NotReserved { .. } => 6,
        }
    }
}

/// Why a sending end could not protect a frame, or a key or table could not be set up.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, thiserror::Error)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum SdlsError {
    /// A key of the wrong length.
    #[error("SDLS: a key has {expected} octets, found {found}")]
    KeyLength {
        /// 32.
        expected: usize,
        /// Octets given.
        found: usize,
    },
    /// The security header and trailer do not fit where the caller put them.
    #[error("SDLS: security header at {sec_start} and MAC ending at {mac_end} do not fit a {len}-octet frame")]
    Layout {
        /// Where the security header starts.
        sec_start: usize,
        /// Where the MAC ends.
        mac_end: usize,
        /// The frame's length.
        len: usize,
    },
    /// The mask reaches past the security header.
    #[error("SDLS: a {mask}-octet authentication mask reaches past the security header's end at {header_end}")]
    MaskTooLong {
        /// The mask's length.
        mask: usize,
        /// Where the security header ends.
        header_end: usize,
    },
    /// The association receives.
    #[error("SDLS: SPI {spi} is a receiving association")]
    NotSender {
        /// Its SPI.
        spi: u16,
    },
    /// No association has this SPI.
    #[error("SDLS: no security association with SPI {spi}")]
    NoSuchSpi {
        /// The SPI asked for.
        spi: u16,
    },
    /// The next IV is not below the durable reservation yet: the shell has not confirmed the
    /// write it was asked for.
    #[error("SDLS: the next IV {next:#x} is not below the durable reservation {reserved:#x}")]
    CounterNotReserved {
        /// The next IV.
        next: u128,
        /// The reservation.
        reserved: u128,
    },
    /// Every IV of the association was used: it needs a new key.
    #[error("SDLS: every 2^96 IV of the association was used; it needs a new key")]
    CounterExhausted,
    /// A BC frame: COP-1's control commands go in clear (decision `sdls-clear-bc`).
    #[error("SDLS: BC frames are not protected")]
    ControlFrame,
    /// The data does not fit a protected frame.
    #[error("SDLS: {found} octets of data, more than a protected frame's {max}")]
    TooLong {
        /// The most a protected frame carries.
        max: usize,
        /// Octets given.
        found: usize,
    },
    /// The cipher refused (a plaintext longer than GCM allows; not reachable with frames).
    #[error("SDLS: the cipher refused the frame")]
    Cipher,
}
