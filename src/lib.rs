//! # mmic — the MMIC-I robot's firmware as a checked library
//!
//! MMIC-I (NASA Ames, ARMADAS) is an inchworm robot that crawls inside a lattice of voxels,
//! grips faces and bolts them together. This crate is the robot's firmware logic as pure,
//! allocation-free functions: the packets of the paper's Tables 2–4 (and the A→B command the
//! paper leaves out), the command set of Table 1, and the types the rest of the firmware is
//! built from. Every packet is a fixed-size [`zerocopy`] view plus a typed `Repr` with
//! `parse`/`emit`, in the manner of smoltcp's `wire` module.
//!
//! ```
//! use mmic::command::{Command, ServoTarget};
//! use mmic::units::{BoardNumber, Side};
//! use mmic::wire::command::{CommandRepr, COMMAND_LEN};
//!
//! let repr = CommandRepr {
//!     board: BoardNumber::new(1).unwrap(),
//!     command: Command::Arm { side: Side::A, target: ServoTarget::Contract },
//!     seq: 0, // 0: unsequenced, as in the paper
//! };
//! let mut bytes = [0u8; COMMAND_LEN];
//! repr.emit(&mut bytes);
//! assert_eq!(CommandRepr::parse(&bytes), Ok(repr));
//!
//! // One flipped bit anywhere is caught (here by the CRC-16/CCITT-FALSE checksum).
//! bytes[5] ^= 0x10;
//! assert!(CommandRepr::parse(&bytes).is_err());
//! ```
//!
//! # Reading order
//!
//! The modules read bottom-up: each uses only those of the rows below it, and those before it
//! in its own row, so there is no import circle (`tests/layering.rs` holds the code to this
//! table, which it reads from one list of its own).
//!
//! | layer | modules | what they hold |
//! |---|---|---|
//! | checks | `arbitrary` | feature `proptest`: the proptest strategies of every `Repr` and the types they are built from (the CCSDS headers' too), and the exhaustive enumerations of the command set; what the checks use and the robot does not |
//! | node | `node` | the boards, the gateway and the ground station: everything wired together |
//! | pus | `pus` | the PUS-C services: what each telecommand means and what each report carries |
//! | link | `link` | the space data link: TC transfer frames with COP-1 (FARM-1, FOP-1, the CLCW) and fixed-length TM transfer frames |
//! | ccsds | `ccsds`, `cfdp` | the CCSDS space packets and PUS headers the services travel in; the file delivery protocol's PDUs (727.0-B-5) |
//! | wire | `wire` | the paper's packets (Tables 2–4, the A→B command), byte by byte |
//! | behaviour | `sensors`, `control`, `motion`, `safety` | the robot's logic: filters, servo and hip control, the motion sequencer, the safety supervisor; it speaks only the vocabulary, never a packet |
//! | vocabulary | `mode`, `faults`, `refusal`, `restart`, `pose`, `bolter`, `command` | what the robot and its operator talk about: modes, faults, refusal codes, reset causes and boot counts, states and primitives, the bolter's steps, the command set |
//! | ground | `units`, `wire_enum` | checked quantities (pulse widths, angles, board numbers) and the C-like enum macro |
//!
//! The behaviour stands below the packets because nothing in it needs one, while the services
//! read the safety tables (an event's severity is Table 8's deferral).
//!
//! Design decisions that the paper leaves open (header bytes, checksum, units, command IDs)
//! are listed with their rationale in `spec/decisions.toml` of the repository.
#![no_std]
#![forbid(unsafe_code)]
#![deny(missing_docs)]
// No panics on any input: outside the tests, no unwrap, expect, panic! or unreachable!, no
// indexing or slicing the compiler cannot check, no unchecked arithmetic, no `as`; every
// exception to a lint says why (clippy denies them in CI, for the host and for RV32). The rules
// and what enforces each: docs/coding-standard.md; the exceptions: docs/evidence/lint-record.md.
#![cfg_attr(
    not(test),
    deny(
        clippy::unwrap_used,
        clippy::expect_used,
        clippy::panic,
        clippy::panic_in_result_fn,
        clippy::todo,
        clippy::unimplemented,
        clippy::unreachable,
        clippy::indexing_slicing,
        clippy::arithmetic_side_effects,
        clippy::as_conversions,
        clippy::allow_attributes_without_reason
    )
)]

// First: the modules below declare their C-like enums with it.
mod wire_enum;

#[cfg(feature = "proptest")]
pub mod arbitrary;
pub mod bolter;
pub mod ccsds;
pub mod cfdp;
pub mod command;
pub mod control;
pub mod faults;
pub mod link;
pub mod mode;
pub mod motion;
pub mod node;
pub mod pose;
pub mod pus;
pub mod refusal;
pub mod restart;
pub mod safety;
pub mod sensors;
pub mod units;
pub mod wire;

/// With the `defmt` feature, the types a firmware logs are `defmt::Format` (checked here at
/// compile time, so a type that loses its derive fails the build for the RISC-V target in CI).
#[cfg(feature = "defmt")]
const _: () = {
    const fn format<T: defmt::Format>() {}
    format::<wire::command::CommandRepr>();
    format::<wire::heartbeat::HeartbeatRepr>();
    format::<wire::internal_heartbeat::InternalHeartbeatRepr>();
    format::<wire::b_command::BCommandRepr>();
    format::<wire::WireError>();
    format::<command::Command>();
    format::<mode::Mode>();
    format::<faults::Faults>();
    format::<faults::Fault>();
    format::<refusal::Refusal>();
    format::<pose::State>();
    format::<pose::Primitive>();
    format::<command::PrimitiveMove>();
    format::<bolter::BolterPair>();
    format::<node::robot::board_a::Event>();
    format::<units::PulseWidth>();
    format::<units::HipAngle>();
    format::<ccsds::tc::TcRepr<'static>>();
    format::<ccsds::tm::TmRepr<'static>>();
    format::<ccsds::PacketError>();
    format::<pus::PusError>();
    format::<ccsds::EmitError>();
};
