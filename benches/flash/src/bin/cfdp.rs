//! A CFDP entity of the mission's profile (`mmic::cfdp::entity`, two transactions) taking a PDU
//! from RAM, sending a file and polling for what to send: the receiving and sending sides,
//! the directives' parsers and emitters, the gap list, the memory store (issue 42).
#![no_std]
#![no_main]

use core::hint::black_box;
use mmic::cfdp::entity::{Config, Entity, MemoryStore, Put};
use mmic::cfdp::header::Mode;
use mmic_flash_ccsds::{fields, HK, TC};

/// A Metadata PDU (LibreCube's of tests/ccsds/cfdp_directive.rs), in RAM.
static PDU: [u8; 43] = [
    0x20, 0x00, 0x1f, 0x13, 0x01, 0x02, 0x0a, 0x0b, 0x0c, 0x0d, 0x03, 0x04, 0x07, 0x40, 0x00, 0x00,
    0x04, 0xd2, 0x08, b'p', b'l', b'a', b'n', b'.', b't', b'x', b't', 0x0f, b'/', b'r', b'o', b'b',
    b'o', b't', b'/', b'p', b'l', b'a', b'n', b'.', b't', b'x', b't',
];

#[no_mangle]
pub extern "C" fn _start() -> ! {
    mmic_flash_ccsds::legacy();
    black_box((black_box(&TC[..]), black_box(&HK[..]), fields()));
    let mut entity = Entity::<2, 16, 16>::new(Config::mission(black_box(0x0304)), black_box(1));
    let mut store = MemoryStore::<4, 1024>::new();
    let mut out = [0u8; 512];
    let now = black_box(0u64);
    let _ = black_box(entity.handle(now, black_box(&PDU[..]), &mut store));
    if let Some(put) = Put::new(b"log", b"log", Mode::Acknowledged) {
        let _ = black_box(entity.put(now, 0x15, put, &mut store));
    }
    while let Some(n) = entity.poll(black_box(now), &mut store, &mut out) {
        black_box(&out[..n]);
    }
    black_box(entity.take_event());
    loop {}
}
