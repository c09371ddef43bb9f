//! mmic::link on top of mmic::ccsds: what `ours` does, through the space data link as the
//! server board runs it. The TC(8,1) arrives in an AD frame (`TcFrame::new_checked`, FARM-1's
//! `Farm::frame`, `packets()`, then `TcRepr::parse` of each); the TM(3,25) leaves in a TM frame
//! (`TmFramer::push` + `next_frame`, the OCF FARM-1's CLCW).
#![no_std]
#![no_main]

use core::hint::black_box;
use mmic::ccsds::cuc::Cuc;
use mmic::ccsds::primary::{Apid, SeqCount};
use mmic::ccsds::tc::TcRepr;
use mmic::ccsds::tm::TmRepr;
use mmic::ccsds::tm_header::{TimeRefStatus, TmSecondaryHeader};
use mmic::link::farm::{Farm, FarmWindow};
use mmic::link::tc_frame::{mission, SpacecraftId, TcFrame};
use mmic::link::tm_frame::{TmFrameParams, TM_FRAME_LEN};
use mmic::link::tm_framer::TmFramer;
use mmic_flash_ccsds::{fields, HK, TC_FRAME};

#[no_mangle]
pub extern "C" fn _start() -> ! {
    mmic_flash_ccsds::legacy();
    let Ok(scid) = SpacecraftId::new(black_box(0x142)) else {
        loop {}
    };
    let config = mission(scid);
    let mut farm = Farm::new(FarmWindow::MISSION);
    if let Ok(frame) = TcFrame::new_checked(black_box(&TC_FRAME[..]), &config) {
        let verdict = farm.frame(frame.kind(), frame.seq(), frame.control_command(), true);
        black_box(verdict);
        for p in frame.packets().flatten() {
            let tc = TcRepr::parse(p, black_box(&[0x42]));
            black_box(
                tc.map(|r| (r.header.service, r.header.subservice, r.app_data.len()))
                    .ok(),
            );
        }
    }
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
    let Ok(n) = tm.emit(&mut out) else { loop {} };
    let Some(params) = TmFrameParams::mission(black_box(0x142)) else {
        loop {}
    };
    let mut framer = TmFramer::<512>::new(params, 500);
    black_box(framer.push(out.get(..n).unwrap_or(&[])).is_ok());
    let clcw = farm.clcw(Default::default(), false, false).emit();
    let mut frame = [0u8; TM_FRAME_LEN];
    black_box(framer.next_frame(black_box(0), clcw, &mut frame).ok());
    black_box(&frame);
    loop {}
}
