//! The small codes inside CFDP's directives (727.0-B-5 §5.2): which directive, the condition
//! code of a transaction's end, the Finished PDU's delivery code and file status, the ACK's
//! transaction status, and the Metadata PDU's checksum type.
//!
//! ```
//! use mmic::cfdp::codes::{ConditionCode, DirectiveCode};
//!
//! assert_eq!(DirectiveCode::from_code(0x0c), Some(DirectiveCode::KeepAlive));
//! assert_eq!(ConditionCode::from_code(8), Some(ConditionCode::InactivityDetected));
//! assert_eq!(ConditionCode::from_code(12), None); // reserved
//! ```

crate::wire_enum::wire_enum! {
    /// A file directive's code, the first octet of its data field (Table 5-4).
    #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
    #[cfg_attr(feature = "defmt", derive(defmt::Format))]
    #[cfg_attr(feature = "serde", derive(serde::Serialize))]
    pub enum DirectiveCode: u8 {
        /// End of file: the sender has sent every octet (or gives up).
        Eof = 0x04 => "eof",
        /// The receiver's end of the transaction.
        Finished = 0x05 => "finished",
        /// Acknowledges an EOF or a Finished PDU (class 2).
        Ack = 0x06 => "ack",
        /// The file's name, size and checksum type: a transaction's first PDU.
        Metadata = 0x07 => "metadata",
        /// The receiver asks again for what it lacks (class 2).
        Nak = 0x08 => "nak",
        /// The sender asks for a NAK or a Keep Alive now.
        Prompt = 0x09 => "prompt",
        /// The receiver's progress (class 2).
        KeepAlive = 0x0c => "keep-alive",
    }

    /// Every directive, in code order.
    const ALL;
    /// The code on the wire.
    pub const fn code(self) -> u8;
    /// The code's directive; none for a code 727.0-B-5 does not define.
    pub const fn from_code(b: u8) -> Option<Self>;
    /// Its name.
    pub const fn name(self) -> &'static str;
}

crate::wire_enum::wire_enum! {
    /// Why a transaction ended, or `NoError` (Table 5-5); 12 and 13 are reserved.
    #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
    #[cfg_attr(feature = "defmt", derive(defmt::Format))]
    #[cfg_attr(feature = "serde", derive(serde::Serialize))]
    pub enum ConditionCode: u8 {
        /// No error.
        NoError = 0 => "no-error",
        /// An EOF or Finished PDU went unacknowledged too often.
        PositiveAckLimitReached = 1 => "positive-ack-limit-reached",
        /// No Keep Alive for too long.
        KeepAliveLimitReached = 2 => "keep-alive-limit-reached",
        /// A PDU of the other class.
        InvalidTransmissionMode = 3 => "invalid-transmission-mode",
        /// The filestore refused the file.
        FilestoreRejection = 4 => "filestore-rejection",
        /// The file's checksum is not the EOF's.
        FileChecksumFailure = 5 => "file-checksum-failure",
        /// The file data disagrees with the file size.
        FileSizeError = 6 => "file-size-error",
        /// NAKs sent too often for one gap.
        NakLimitReached = 7 => "nak-limit-reached",
        /// Nothing received for the inactivity time.
        InactivityDetected = 8 => "inactivity-detected",
        /// The file is not what its type says.
        InvalidFileStructure = 9 => "invalid-file-structure",
        /// The check timer expired too often (class 1).
        CheckLimitReached = 10 => "check-limit-reached",
        /// The Metadata's checksum type is not one this entity computes.
        UnsupportedChecksumType = 11 => "unsupported-checksum-type",
        /// A Suspend.request was received.
        SuspendRequestReceived = 14 => "suspend-request-received",
        /// A Cancel.request was received.
        CancelRequestReceived = 15 => "cancel-request-received",
    }

    /// Every condition, in code order.
    const ALL;
    /// The four-bit code.
    pub const fn code(self) -> u8;
    /// The code's condition; none for the reserved 12 and 13 (and above 15).
    pub const fn from_code(b: u8) -> Option<Self>;
    /// Its name.
    pub const fn name(self) -> &'static str;
}

crate::wire_enum::wire_enum! {
    /// What the receiver kept of the file (Finished PDU, two bits).
    #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
    #[cfg_attr(feature = "defmt", derive(defmt::Format))]
    #[cfg_attr(feature = "serde", derive(serde::Serialize))]
    pub enum FileStatus: u8 {
        /// Discarded on purpose.
        DiscardedDeliberately = 0 => "discarded-deliberately",
        /// Discarded: the filestore refused it.
        DiscardedFilestoreRejection = 1 => "discarded-filestore-rejection",
        /// Kept in the filestore.
        Retained = 2 => "retained",
        /// Not said.
        Unreported = 3 => "unreported",
    }

    /// Every status, in code order.
    const ALL;
    /// The two-bit code.
    pub const fn code(self) -> u8;
    /// The code's status.
    pub const fn from_code(b: u8) -> Option<Self>;
    /// Its name.
    pub const fn name(self) -> &'static str;
}

crate::wire_enum::wire_enum! {
    /// Where the acknowledging entity's transaction stands (ACK PDU, two bits).
    #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
    #[cfg_attr(feature = "defmt", derive(defmt::Format))]
    #[cfg_attr(feature = "serde", derive(serde::Serialize))]
    pub enum TransactionStatus: u8 {
        /// Not known.
        Undefined = 0 => "undefined",
        /// Still running.
        Active = 1 => "active",
        /// Ended.
        Terminated = 2 => "terminated",
        /// Never heard of.
        Unrecognized = 3 => "unrecognized",
    }

    /// Every status, in code order.
    const ALL;
    /// The two-bit code.
    pub const fn code(self) -> u8;
    /// The code's status.
    pub const fn from_code(b: u8) -> Option<Self>;
    /// Its name.
    pub const fn name(self) -> &'static str;
}

/// The checksum a Metadata PDU announces (four bits, the SANA registry's): any value is
/// carried; a receiver that does not compute it ends with
/// [`ConditionCode::UnsupportedChecksumType`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct ChecksumType(u8);

impl ChecksumType {
    /// The modular checksum (type 0, Annex F.2; YAMCS's `MODULAR`): the mission's.
    pub const MODULAR: ChecksumType = ChecksumType(0);
    /// The null checksum (type 15: always 0; YAMCS's `NULL`).
    pub const NULL: ChecksumType = ChecksumType(15);

    /// The type of the low four bits of `b`.
    pub const fn from_bits(b: u8) -> ChecksumType {
        ChecksumType(b & 0x0f)
    }

    /// The four-bit value.
    pub const fn value(self) -> u8 {
        self.0
    }
}
