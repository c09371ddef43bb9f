//! The one-bit fields of a CFDP PDU's header (727.0-B-5 §5.1): what the PDU is, which way it
//! travels, and the transmission mode, shared by the header, the directives and the errors.
//!
//! ```
//! use mmic::cfdp::header::{Direction, Mode, PduType};
//!
//! assert_ne!(Direction::TowardReceiver, Direction::TowardSender);
//! assert_ne!(Mode::Acknowledged, Mode::Unacknowledged);
//! assert_ne!(PduType::Directive, PduType::FileData);
//! ```

/// File directive (0) or file data (1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub enum PduType {
    /// A file directive PDU (Metadata, EOF, Finished, ACK, NAK, Prompt, Keep Alive).
    Directive,
    /// A file data PDU.
    FileData,
}

/// Which way the PDU travels.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub enum Direction {
    /// From the sending entity to the receiving one.
    TowardReceiver,
    /// From the receiving entity back to the sending one.
    TowardSender,
}

/// Acknowledged (class 2, reliable) or unacknowledged (class 1) transmission.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub enum Mode {
    /// Class 2: NAKs, EOF and Finished acknowledged.
    Acknowledged,
    /// Class 1: sent once, nothing acknowledged.
    Unacknowledged,
}
