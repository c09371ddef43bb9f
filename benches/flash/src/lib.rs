//! What the measurement images share: the inputs, hidden from the optimiser, and the
//! panic handler. Each image in `src/bin/` parses one telecommand and builds one telemetry
//! packet; `baseline` does neither, so its size is subtracted.
#![no_std]

/// The TC(8,1) of benches/ccsds.rs (16 octets), in RAM so the optimiser cannot read it.
pub static TC: [u8; 16] = [
    0x18, 0x42, 0xc0, 0x07, 0x00, 0x09, 0x2f, 0x08, 0x01, 0x00, 0x01, 0x60, 0x6d, 0x61, 0, 0,
];

/// The same TC(8,1), its CRC this time, in an AD frame of spacecraft 0x142 (robot 0x42), VC 0,
/// N(S) 3, MAP 0, with its FECF (24 octets): what the `link` image parses.
pub static TC_FRAME: [u8; 24] = [
    0x01, 0x42, 0x00, 0x17, 0x03, 0xc0, 0x18, 0x42, 0xc0, 0x07, 0x00, 0x09, 0x2f, 0x08, 0x01, 0x00,
    0x01, 0x60, 0x6d, 0x61, 0x50, 0xe9, 0xba, 0xe1,
];

/// A housekeeping report's 60 octets of parameters.
pub static HK: [u8; 60] = [0x5a; 60];

/// The same telemetry fields for both builders, from a value the optimiser cannot see.
pub fn fields() -> (u16, u16, u8, u8, u16, u16, u32, u16) {
    core::hint::black_box((0x42, 9, 3, 25, 3, 1, 90, 0x8000))
}

/// With the feature `with-legacy`: parses a legacy command packet (Table 2), as every firmware
/// image does; without it, nothing.
pub fn legacy() {
    #[cfg(feature = "with-legacy")]
    {
        static COMMAND: [u8; 14] = *b"MICM\x01\x02\0\0\0\0\0\0\0\0";
        let r = mmic::wire::command::CommandRepr::parse(core::hint::black_box(&COMMAND[..]));
        core::hint::black_box(r.is_ok());
    }
}

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    loop {}
}
