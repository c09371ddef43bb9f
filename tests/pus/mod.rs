//! PUS-C services (src/pus/) and the PUS gateway (src/node/server/gateway/): the code equals
//! spec/ccsds/, every command round-trips as a function, every bad input is refused by name.

mod cop1_attack;
mod durable;
mod event;
mod frames;
mod function;
mod gateway;
mod ground_frames;
mod ground_link;
mod housekeeping;

/// TC(8,1) perform function to robot 1 (APID 0x101), numbered `seq`, from source 9 with every
/// report asked for: `app_data` is the function (spec/ccsds/functions.toml), e.g. `[6]`, Stop.
pub fn function_tc(seq: u16, app_data: &[u8]) -> Vec<u8> {
    use mmic::ccsds::primary::{Apid, SeqCount};
    use mmic::ccsds::tc::TcRepr;
    use mmic::ccsds::tc_header::{AckFlags, TcSecondaryHeader};
    let mut b = [0u8; 64];
    let n = TcRepr {
        apid: Apid::new(0x101).unwrap(),
        seq_count: SeqCount::new(seq).unwrap(),
        header: TcSecondaryHeader {
            ack: AckFlags::ALL,
            service: 8,
            subservice: 1,
            source_id: 9,
        },
        app_data,
    }
    .emit(&mut b)
    .unwrap();
    b[..n].to_vec()
}
