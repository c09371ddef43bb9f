//! Neither parse nor build: the image every other one is measured against.
#![no_std]
#![no_main]

use core::hint::black_box;
use mmic_flash_ccsds::{fields, HK, TC};

#[no_mangle]
pub extern "C" fn _start() -> ! {
    mmic_flash_ccsds::legacy();
    black_box((black_box(&TC[..]), black_box(&HK[..]), fields()));
    loop {}
}
