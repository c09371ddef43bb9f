//! The mission's security associations (`spec/ccsds/sdls.toml`): one for each robot's
//! telecommands, one for its telemetry, each under its own key.
//!
//! ```
//! use mmic::link::sdls::mission;
//! use mmic::units::BoardNumber;
//!
//! assert_eq!(mission::tc_spi(BoardNumber::ONE), 257); // = the robot's spacecraft ID
//! assert_eq!(mission::tm_spi(BoardNumber::ONE), 513);
//! ```

use super::counter::{ReplayWindow, TxCounter};
use super::key::Key256;
use super::mask;
use super::sa::{Channel, Role, SecurityAssociation};
use crate::link::tc_frame::{SpacecraftId, MISSION_VCID};
use crate::link::tm_frame::TM_VCID;
use crate::units::BoardNumber;

/// The TC association's SPI of robot `n`: 0x100 + n, its spacecraft ID.
pub const fn tc_spi(board: BoardNumber) -> u16 {
    u16::from_be_bytes([0x01, board.get()])
}

/// The TM association's SPI of robot `n`: 0x200 + n.
pub const fn tm_spi(board: BoardNumber) -> u16 {
    u16::from_be_bytes([0x02, board.get()])
}

/// The server board's anti-replay window for telecommands, W = 2^20: an authentic frame up to
/// this far ahead of the last accepted one is followed. Every COP-1 transmission takes a fresh
/// IV, so a long outage moves the ground's counter ahead; beyond W the receiver refuses every
/// frame for good (only a new key or its stored floor rewritten recovers): at the ground's
/// worst, about 110 transmissions per 30 s FOP-1 cycle, 2^20 is some 80 hours of outage.
pub const TC_WINDOW: u32 = 1 << 20;
/// The server board's TC floor is reserved 16 counters at a time (a flash write per 16
/// frames). After a restart the window resumes at the exact last IV the store kept with
/// FARM-1's progress (`node::server::store`), so no frame of the ground is refused as a replay;
/// from the floor alone it would refuse up to 24 of them, which COP-1 sends again.
pub const TC_RX_BLOCK: u32 = 16;
/// The ground's TC counter is reserved 64 at a time.
pub const TC_TX_BLOCK: u32 = 64;
/// The server board's TM counter is reserved 256 at a time (about one flash write every two
/// minutes at two frames a second).
pub const TM_TX_BLOCK: u32 = 256;
/// The ground's TM window: frames lost in a row up to this many are followed (YAMCS's
/// `seqNumWindow` is the same).
pub const TM_WINDOW: u32 = 100_000;
/// The ground's TM floor is reserved 16 at a time: a restarted ground refuses at most 24 of
/// the server board's next TM frames (12 s at two a second, less than a telecommand's 30 s
/// over frames), and a frame is refused as not reserved only after some 8 lost in a row.
/// (256 left a restarted ground deaf for three minutes: nothing sends TM frames again; 4 had
/// frames refused after ordinary bursts of loss.)
pub const TM_RX_BLOCK: u32 = 16;

fn tc_channel(board: BoardNumber) -> Channel {
    Channel {
        spacecraft_id: SpacecraftId::of_board(board).get(),
        vcid: MISSION_VCID,
    }
}

fn tm_channel(board: BoardNumber) -> Channel {
    Channel {
        spacecraft_id: SpacecraftId::of_board(board).get(),
        vcid: TM_VCID,
    }
}

/// The server board's end of robot `board`'s telecommands; `stored`, the floor it kept.
pub fn tc_receiver(board: BoardNumber, key: Key256, stored: Option<u128>) -> SecurityAssociation {
    let window = ReplayWindow::boot(stored, TC_WINDOW, TC_RX_BLOCK);
    SecurityAssociation::new(
        tc_spi(board),
        key,
        tc_channel(board),
        mask::TC,
        Role::Receive(window),
    )
}

/// The ground's end of robot `board`'s telecommands; `stored`, the reservation it kept.
pub fn tc_sender(board: BoardNumber, key: Key256, stored: Option<u128>) -> SecurityAssociation {
    let counter = TxCounter::boot(stored, TC_TX_BLOCK);
    SecurityAssociation::new(
        tc_spi(board),
        key,
        tc_channel(board),
        mask::TC,
        Role::Send(counter),
    )
}

/// The server board's end of robot `board`'s telemetry; `stored`, the reservation it kept.
pub fn tm_sender(board: BoardNumber, key: Key256, stored: Option<u128>) -> SecurityAssociation {
    let counter = TxCounter::boot(stored, TM_TX_BLOCK);
    SecurityAssociation::new(
        tm_spi(board),
        key,
        tm_channel(board),
        mask::TM,
        Role::Send(counter),
    )
}

/// The ground's end of robot `board`'s telemetry; `stored`, the floor it kept.
pub fn tm_receiver(board: BoardNumber, key: Key256, stored: Option<u128>) -> SecurityAssociation {
    let window = ReplayWindow::boot(stored, TM_WINDOW, TM_RX_BLOCK);
    SecurityAssociation::new(
        tm_spi(board),
        key,
        tm_channel(board),
        mask::TM,
        Role::Receive(window),
    )
}
