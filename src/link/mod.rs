//! The space data link: CCSDS TC transfer frames (232.0-B) made reliable by COP-1 (232.1-B:
//! the ground's FOP-1, the on-board FARM-1 and the CLCW that reports it), and fixed-length TM
//! transfer frames (132.0-B) that carry the telemetry packets and the CLCW back. The layer
//! between the space packets ([`crate::ccsds`]) and a radio or a UDP socket: a frame in,
//! packets out, and the other way round; no I/O and no clock of its own (time comes in as an
//! argument, in milliseconds, as everywhere in this crate).
//!
//! One module per concept, each in the style of the packet layer (a checked view over the
//! octets, a `Repr` with `parse`/`emit`, every check refused by name):
//!
//! | module | what | standard |
//! |---|---|---|
//! | [`tc_frame`] | the TC transfer frame: primary header, segment header, FECF; the control commands (Unlock, Set V(R)) | 232.0-B-4 §4.1 |
//! | [`clcw`] | the Communications Link Control Word | 232.0-B-4 §4.2, 232.1-B-2 §4.2.1 |
//! | [`farm`] | FARM-1, the receiving end of COP-1 | 232.1-B-2 §6 |
//! | [`fop`] | FOP-1, the sending end of COP-1 (the simulator's ground and the tests) | 232.1-B-2 §5 |
//! | [`tm_frame`] | the TM transfer frame: primary header, data field status, OCF, FECF | 132.0-B-3 §4.1 |
//! | [`tm_framer`] | packets multiplexed into fixed-length TM frames, idle data, the CLCW in every OCF | 132.0-B-3 §4.1.4, §4.2 |
//! | [`extract`] | the ground's packet extractor: packets out of TM frames, lost frames detected | 132.0-B-3 §4.1.2.7, §4.1.2.4 |
//! | [`sdls`] | Space Data Link Security: AES-256-GCM on the frames' data, security associations, anti-replay | 355.0-B-2 |
//!
//! The choices the standards leave to a mission (spacecraft IDs, virtual channels, frame
//! lengths, the FARM window, the idle period) are in `spec/ccsds/link.toml`, each with its
//! decision.
// req: D:link-spacecraft-id, D:link-tc-frame, D:link-cop1, D:link-tm-frame

pub mod clcw;
pub mod extract;
pub mod farm;
pub mod fop;
pub mod sdls;
pub mod tc_frame;
pub mod tm_frame;
pub mod tm_framer;

/// A word's low bits as a narrower integer, what `as` would keep, taken through the word's
/// octets (the standard's R5: no `as`). The fields of the headers are masked or shifted
/// first, so that nothing above is dropped; where the word is wider on purpose (the CLCW's
/// report value is its last octet) that is the point.
pub(crate) mod low {
    /// The low octet of a 16-bit word.
    pub(crate) const fn u8_of_u16(w: u16) -> u8 {
        let [_, low] = w.to_be_bytes();
        low
    }

    /// The low octet of a 32-bit word.
    pub(crate) const fn u8_of_u32(w: u32) -> u8 {
        let [.., low] = w.to_be_bytes();
        low
    }

    /// The low octet of a `usize` (whatever its width).
    pub(crate) const fn u8_of_usize(w: usize) -> u8 {
        let [.., low] = w.to_be_bytes();
        low
    }
}

/// Which service a TC transfer frame asks for: its bypass and control command flags
/// (232.0-B-4 §4.1.2.3). The fourth combination (bypass clear, control command set) is not a
/// frame type, and [`tc_frame`] refuses it by name.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "kebab-case"))]
pub enum FrameKind {
    /// Type-AD: data under the sequence-controlled service (COP-1 checks its sequence number).
    Ad,
    /// Type-BD: data under the expedited service (bypasses FARM-1's sequence checks).
    Bd,
    /// Type-BC: a control command to FARM-1 (Unlock or Set V(R)).
    Bc,
}

/// A COP-1 control command, the data field of a type-BC frame (232.0-B-4 §4.1.3.3.2,
/// 232.1-B-2 §6.3.8): `Unlock` is the one octet `0x00`; `SetVr(v)` the three octets
/// `0x82 0x00 v`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "kebab-case"))]
pub enum ControlCommand {
    /// Leave Lockout (and Wait): FARM-1 goes to Open.
    Unlock,
    /// Set V(R), the next expected frame sequence number, to this value.
    SetVr(u8),
}
