//! Exhaustive corruption: every 1-, 2- and 3-bit error in a valid command packet (14 bytes,
//! 112 bits) and in a valid internal heartbeat (47 bytes, 376 bits) is refused by `parse`.
//!
//! This must hold for any packet up to 32751 data bits, because CRC-16/CCITT-FALSE (generator
//! 0x11021 = (x + 1)·p(x), p primitive of degree 15) has Hamming distance 4 there: every
//! error of odd weight is caught by the (x + 1) factor, every 2-bit error by the primitive
//! factor's period 32767. The test does not rely on that argument: it runs every corruption
//! through the real `parse` and counts who refused it.
//!
//! An error that touches the header is refused by the header check (it runs before the
//! checksum check, and any flipped header bit changes the header); every other error must be
//! refused by the checksum check, since the CRC catches it before any field is looked at. The
//! expected counts follow from that by counting combinations: C(n, w) − C(n − 32, w) errors of
//! weight w touch the 32 header bits.
//!
//! Under Miri (.ci/miri), which interprets some 100x slower, only the 1-bit errors run (488 of
//! 9,094,124 corruptions): each bit of both packets through `parse` once.

use mmic::command::Command;
use mmic::units::BoardNumber;
use mmic::wire::command::CommandRepr;
use mmic::wire::internal_heartbeat::InternalHeartbeatRepr;
use mmic::wire::{WireError, HEADER_LEN};
use std::time::Instant;

/// The heaviest error weight flipped: 3, or 1 under Miri.
const MAX_WEIGHT: usize = if cfg!(miri) { 1 } else { 3 };

/// C(n, k).
fn choose(n: u64, k: u64) -> u64 {
    (0..k).fold(1, |acc, i| acc * (n - i) / (i + 1))
}

/// Refusals by check, per error weight.
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq)]
struct Refusals {
    header: u64,
    checksum: u64,
}

fn flip(bytes: &mut [u8], bit: usize) {
    bytes[bit / 8] ^= 0x80 >> (bit % 8);
}

/// Flips every combination of 1, 2 and 3 bits of `packet` (1 under Miri), asserts that `parse`
/// refuses each one by the header or checksum check, and returns the refusals per weight.
fn corrupt_all<T: std::fmt::Debug>(
    name: &str,
    packet: &[u8],
    parse: impl Fn(&[u8]) -> Result<T, WireError>,
) -> [Refusals; 3] {
    assert!(
        parse(packet).is_ok(),
        "{name}: the uncorrupted packet must parse"
    );
    let n = packet.len() * 8;
    let mut buf = packet.to_vec();
    let mut out = [Refusals::default(); 3];
    let mut judge = |buf: &[u8], weight: usize| match parse(buf) {
        Err(WireError::Header { .. }) => out[weight - 1].header += 1,
        Err(WireError::Checksum { .. }) => out[weight - 1].checksum += 1,
        other => panic!("{name}: {weight}-bit error {buf:02x?} gave {other:?}"),
    };
    let start = Instant::now();
    for i in 0..n {
        flip(&mut buf, i);
        judge(&buf, 1);
        for j in (i + 1..n).filter(|_| MAX_WEIGHT >= 2) {
            flip(&mut buf, j);
            judge(&buf, 2);
            for k in (j + 1..n).filter(|_| MAX_WEIGHT >= 3) {
                flip(&mut buf, k);
                judge(&buf, 3);
                flip(&mut buf, k);
            }
            flip(&mut buf, j);
        }
        flip(&mut buf, i);
    }
    assert_eq!(buf, packet);
    let total: u64 = out.iter().map(|r| r.header + r.checksum).sum();
    println!(
        "{name}: {n} bits, {total} corruptions refused in {:.2?}: {out:?}",
        start.elapsed()
    );
    out
}

/// The counts the header/checksum argument predicts for an `n`-bit packet (none above
/// `MAX_WEIGHT`).
fn expected(n: u64) -> [Refusals; 3] {
    let h = (HEADER_LEN * 8) as u64;
    [1, 2, 3].map(|w| {
        if w as usize > MAX_WEIGHT {
            return Refusals::default();
        }
        Refusals {
            header: choose(n, w) - choose(n - h, w),
            checksum: choose(n - h, w),
        }
    })
}

// req: T2/checksum, D:checksum
#[test]
fn every_1_2_3_bit_error_in_a_command_packet_is_refused() {
    let packet = CommandRepr {
        board: BoardNumber::new(7).unwrap(),
        command: Command::reconfigure(mmic::motion::State::H, mmic::motion::State::N).unwrap(),
        seq: 0,
    }
    .to_bytes();
    let got = corrupt_all("command", &packet, CommandRepr::parse);
    assert_eq!(got, expected(112));
    let total: u64 = got.iter().map(|r| r.header + r.checksum).sum();
    if MAX_WEIGHT == 3 {
        assert_eq!(total, 112 + choose(112, 2) + choose(112, 3));
        assert_eq!(total, 234_248);
    } else {
        assert_eq!(total, 112);
    }
}

// req: T4/checksum, D:checksum
#[test]
fn every_1_2_3_bit_error_in_an_internal_heartbeat_is_refused() {
    let packet = InternalHeartbeatRepr {
        command_received: 43,
        ..Default::default()
    }
    .to_bytes();
    let got = corrupt_all("internal heartbeat", &packet, InternalHeartbeatRepr::parse);
    assert_eq!(got, expected(376));
    let total: u64 = got.iter().map(|r| r.header + r.checksum).sum();
    if MAX_WEIGHT == 3 {
        assert_eq!(total, 376 + choose(376, 2) + choose(376, 3));
        assert_eq!(total, 8_859_876);
    } else {
        assert_eq!(total, 376);
    }
}
