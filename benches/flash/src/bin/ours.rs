//! mmic::ccsds: `TcRepr::parse` (every check) and `TmRepr::emit`.
#![no_std]
#![no_main]

use core::hint::black_box;
use mmic::ccsds::cuc::Cuc;
use mmic::ccsds::primary::{Apid, SeqCount};
use mmic::ccsds::tc::TcRepr;
use mmic::ccsds::tm::TmRepr;
use mmic::ccsds::tm_header::{TimeRefStatus, TmSecondaryHeader};
use mmic_flash_ccsds::{fields, HK, TC};

#[no_mangle]
pub extern "C" fn _start() -> ! {
    mmic_flash_ccsds::legacy();
    let tc = TcRepr::parse(black_box(&TC[..]), black_box(&[0x42]));
    black_box(tc.map(|r| (r.header.service, r.header.subservice, r.app_data.len())).ok());
    let (apid, seq, service, subservice, counter, dest, coarse, fine) = fields();
    let (Ok(apid), Ok(seq_count)) = (Apid::new(apid), SeqCount::new(seq)) else {
        loop {}
    };
    let tm = TmRepr {
        apid,
        seq_count,
        header: TmSecondaryHeader {
            time_ref_status: TimeRefStatus::default(),
            service,
            subservice,
            counter,
            destination_id: dest,
            time: Cuc { coarse, fine },
        },
        source_data: black_box(&HK[..]),
    };
    let mut out = [0u8; 128];
    black_box(tm.emit(&mut out).ok());
    black_box(&out);
    loop {}
}
