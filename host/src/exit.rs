//! The `mmic` tool's process exit codes: a leaf module, so that every command module can name
//! them without depending on the command line ([`crate::cli`]).

/// Success.
pub const EXIT_OK: u8 = 0;
/// The bytes are not a valid packet.
pub const EXIT_INVALID_PACKET: u8 = 1;
/// Bad input: unknown kind or state, invalid JSON, malformed hex, usage error.
pub const EXIT_INPUT: u8 = 2;
/// A file could not be written, or stdout is closed.
pub const EXIT_IO: u8 = 3;
/// `mmic sim`: the host fell too far behind the simulated clock for the outcome to count.
pub const EXIT_HOST: u8 = 4;
/// `mmic opsui`, `mmic sim --opsui-serial`: the serial device cannot be opened or set up
/// (nothing was sent).
pub const EXIT_SERIAL_OPEN: u8 = 5;
/// `mmic opsui`: the serial line was lost before the plan ended (end of file, hang-up, I/O
/// error); the command outstanding, if any, ran at most once.
pub const EXIT_LINE_LOST: u8 = 6;
/// `mmic opsui`: the plan ended at a step the robot never acknowledged (every attempt went
/// unanswered; it ran at most once).
pub const EXIT_UNACKNOWLEDGED: u8 = 7;
