//! The server board's durable store read from any octets (`mmic::node::server::store`): what a
//! flash region or a keys partition holds is whatever the flash kept or a person flashed, so its
//! readers must refuse it by name or read exactly what their writers would write.
//!
//! The harnesses (`tests/harnesses/store.rs`) and the fuzz target `server_store` call these.

use mmic::link::sdls::Key256;
use mmic::node::server::store::keys::{self, KeysError};
use mmic::node::server::store::log::{self, Record, RECORD_LEN};
use mmic::node::server::store::queue::{job_entry, job_of};
use mmic::units::BoardNumber;

/// Any 20 octets as a flash log record: free only when all `0xFF`; an entry or a header is
/// exactly what its writer writes for it; anything else is invalid (a torn or foreign record).
/// Whether it held an entry or a header.
pub fn check_log_record(r: &[u8; RECORD_LEN]) -> bool {
    match log::decode(r) {
        Record::Free => {
            assert!(
                r.iter().all(|&b| b == 0xFF),
                "free but not erased: {r:02x?}"
            );
            false
        }
        Record::Entry(e) => {
            assert_eq!(log::encode_entry(&e).as_ref(), Some(r), "{e:?}");
            true
        }
        Record::Header(g) => {
            assert_eq!(&log::encode_header(g), r, "header {g}");
            true
        }
        Record::Invalid => {
            assert!(!r.iter().all(|&b| b == 0xFF));
            false
        }
    }
}

/// Any octets as a keys partition: refused by a named check, or read into keys that the writer
/// writes back as exactly the same octets (none of them weak).
pub fn check_keys_partition(part: &[u8]) -> bool {
    match keys::parse(part) {
        Err(e) => {
            assert!(KeysError::NAMES.contains(&e.name()), "{e:?}");
            false
        }
        Ok(set) => {
            let first = set.spis().next().expect("a read partition has a key");
            let filler = set.get(first).expect("a read SPI has its key");
            let mut found: [(u16, &Key256); keys::MAX_KEYS] = [(0, filler); keys::MAX_KEYS];
            let mut count = 0;
            for s in set.spis() {
                let k = set.get(s).expect("a read SPI has its key");
                assert!(k.check().is_ok());
                found[count] = (s, k);
                count += 1;
            }
            let found = &found[..count];
            let mut out = [0xFFu8; keys::HEADER_LEN + keys::MAX_KEYS * keys::ENTRY_LEN + 4];
            let n = keys::emit(found, &mut out).expect("read keys write back");
            assert_eq!(&out[..n], &part[..n], "the keys partition is not canonical");
            true
        }
    }
}

/// Any 96-bit value as a queue slot of robot `board` (slot `slot`): refused, or a telecommand
/// whose entry is exactly that value.
pub fn check_queue_value(board: BoardNumber, slot: u8, value: u128) -> bool {
    match job_of(board, value) {
        None => false,
        Some(job) => {
            assert_eq!(job.request.apid, mmic::pus::robot_apid(board));
            assert_eq!(job_entry(board, slot, Some(&job)).value, value, "{job:?}");
            true
        }
    }
}
