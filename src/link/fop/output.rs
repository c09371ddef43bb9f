//! Everything FOP-1 tells its users: frames to send, confirmations, and why it stopped the AD
//! service (232.1-B-2 §5.2's "Alert" reason codes).

use crate::link::{ControlCommand, FrameKind};

/// Why FOP-1 stopped the AD service (232.1-B-2 §5.2.x "Alert" reason codes).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "kebab-case"))]
pub enum AlertCode {
    /// "LIMIT": Retransmit reported with the transmission limit reached.
    Limit,
    /// "T1": the timer ran out with the transmission count at the limit.
    T1,
    /// "LOCKOUT": the CLCW reports FARM-1 in Lockout.
    Lockout,
    /// "SYNCH": the CLCW's flags contradict what FOP-1 sent.
    Synch,
    /// "NN(R)": N(R) outside NN(R)..=V(S).
    NnR,
    /// "CLCW": the Wait flag where the state does not allow it.
    Clcw,
    /// "TERM": a Terminate directive.
    Term,
}

impl AlertCode {
    /// The standard's code.
    pub const fn name(self) -> &'static str {
        match self {
            AlertCode::Limit => "LIMIT",
            AlertCode::T1 => "T1",
            AlertCode::Lockout => "LOCKOUT",
            AlertCode::Synch => "SYNCH",
            AlertCode::NnR => "NN(R)",
            AlertCode::Clcw => "CLCW",
            AlertCode::Term => "TERM",
        }
    }
}

/// What a frame carries.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "kebab-case"))]
pub enum FrameData<P> {
    /// An FDU (AD or BD frame).
    Fdu(P),
    /// A control command (BC frame).
    Control(ControlCommand),
}

/// A frame for the transport: its kind, its N(S) (0 for BD and BC frames, 232.0-B-4
/// §4.1.2.7.3) and its data.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct FopFrame<P> {
    /// AD, BD or BC.
    pub kind: FrameKind,
    /// N(S).
    pub ns: u8,
    /// FDU or control command.
    pub data: FrameData<P>,
}

/// Everything FOP-1 tells its users.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "kebab-case"))]
pub enum FopOutput<P> {
    /// Send this frame (a first transmission or a retransmission).
    Transmit(FopFrame<P>),
    /// The AD frame N(S) = `ns` was acknowledged ("Positive Confirm").
    Confirmed {
        /// Its N(S).
        ns: u8,
    },
    /// The AD frame N(S) = `ns` was purged unacknowledged ("Negative Confirm"): FARM-1 may or
    /// may not have it. Its FDU comes back, so that nothing is lost silently: the caller
    /// decides whether to send it again (the PUS layer's request keys make a second copy
    /// harmless).
    NegativeConfirm {
        /// Its N(S).
        ns: u8,
        /// Its FDU.
        fdu: P,
    },
    /// An FDU of the wait queue was purged, never sent ("Reject").
    Rejected(P),
    /// The pending initiate directive completed: the AD service runs.
    InitiateConfirmed,
    /// The AD service stopped ("Alert").
    Alert(AlertCode),
    /// The AD service was suspended (timeout type 1); [`Directive::Resume`] takes it up.
    ///
    /// [`Directive::Resume`]: super::Directive::Resume
    Suspended,
}
