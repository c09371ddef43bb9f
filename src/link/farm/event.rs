//! What happens to FARM-1, as the frame parser and the higher procedures say it, and the
//! event number of Table 6-1 each is (`spec/ccsds/farm-1.toml` names the rows by it).

use crate::link::{ControlCommand, FrameKind};

/// What happens to FARM-1: a valid frame, a frame that failed validation, or the higher
/// procedures freeing the buffer.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "kebab-case"))]
pub enum FarmEvent {
    /// A valid type-AD frame with sequence number `ns`; `buffer_ready` says whether the
    /// higher procedures can take its FDU now (E1 or E2).
    Ad {
        /// N(S).
        ns: u8,
        /// Room for the FDU.
        buffer_ready: bool,
    },
    /// A valid type-BD frame (E6): accepted whatever the state.
    Bd,
    /// A valid type-BC frame with its control command (E7 Unlock, E8 Set V(R)).
    Bc(ControlCommand),
    /// A frame that failed validation (E9).
    Invalid,
    /// The higher procedures freed the buffer (E10, "buffer release signal").
    BufferRelease,
}

impl FarmEvent {
    /// The event of a frame as the frame parser reads it: an AD or BD frame without a
    /// control command, a BC frame with one; any other combination is [`FarmEvent::Invalid`].
    pub const fn of_frame(
        kind: FrameKind,
        ns: u8,
        control: Option<ControlCommand>,
        buffer_ready: bool,
    ) -> FarmEvent {
        match (kind, control) {
            (FrameKind::Ad, None) => FarmEvent::Ad { ns, buffer_ready },
            (FrameKind::Bd, None) => FarmEvent::Bd,
            (FrameKind::Bc, Some(c)) => FarmEvent::Bc(c),
            _ => FarmEvent::Invalid,
        }
    }
}

/// The event numbers of 232.1-B-2 Table 6-1 (E11, "report", is [`Farm::clcw`]: it changes
/// nothing).
///
/// [`Farm::clcw`]: super::Farm::clcw
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[expect(
    missing_docs,
    reason = "the events are named E1 to E10 as in 232.1-B-2 Table 6-1; the type's docs say so"
)]
pub enum EventId {
    E1,
    E2,
    E3,
    E4,
    E5,
    E6,
    E7,
    E8,
    E9,
    E10,
}

impl EventId {
    /// Every event, in the table's order.
    pub const ALL: [EventId; 10] = [
        EventId::E1,
        EventId::E2,
        EventId::E3,
        EventId::E4,
        EventId::E5,
        EventId::E6,
        EventId::E7,
        EventId::E8,
        EventId::E9,
        EventId::E10,
    ];

    /// "E1" … "E10".
    pub const fn name(self) -> &'static str {
        match self {
            EventId::E1 => "E1",
            EventId::E2 => "E2",
            EventId::E3 => "E3",
            EventId::E4 => "E4",
            EventId::E5 => "E5",
            EventId::E6 => "E6",
            EventId::E7 => "E7",
            EventId::E8 => "E8",
            EventId::E9 => "E9",
            EventId::E10 => "E10",
        }
    }
}
