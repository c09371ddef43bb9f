//! spacepackets 0.19: `PusTcReader::new` and `PusTmCreator::write_to_slice`.
#![no_std]
#![no_main]

use core::hint::black_box;
use mmic_flash_ccsds::{fields, HK, TC};
use spacepackets::ecss::tc::PusTcReader;
use spacepackets::ecss::tm::{PusTmCreator, PusTmSecondaryHeader};
use spacepackets::ecss::{CreatorConfig, MessageTypeId, PusPacket};
use spacepackets::SpHeader;

#[no_mangle]
pub extern "C" fn _start() -> ! {
    mmic_flash_ccsds::legacy();
    let tc = PusTcReader::new(black_box(&TC[..]));
    black_box(tc.map(|r| (r.service_type_id(), r.message_subtype_id(), r.app_data().len())).ok());
    let (apid, seq, service, subservice, counter, dest, coarse, fine) = fields();
    let (Some(apid), Some(seq)) = (
        arbitrary_int::u11::try_new(apid).ok(),
        arbitrary_int::u14::try_new(seq).ok(),
    ) else {
        loop {}
    };
    let mut stamp = [0u8; 6];
    stamp[..4].copy_from_slice(&coarse.to_be_bytes());
    stamp[4..].copy_from_slice(&fine.to_be_bytes());
    let sph = SpHeader::new_for_unseg_tm(apid, seq, 0);
    let sec = PusTmSecondaryHeader::new(MessageTypeId::new(service, subservice), counter, dest, &stamp);
    let tm = PusTmCreator::new(sph, sec, black_box(&HK[..]), CreatorConfig::default());
    let mut out = [0u8; 128];
    black_box(tm.write_to_slice(&mut out).ok());
    black_box(&out);
    loop {}
}
