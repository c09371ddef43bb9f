//! Harnesses for the server board's durable store (`mmic::node::server::store`, issue 38): what
//! a flash region or a keys partition holds is read exactly as its writer wrote it, or refused
//! (`mmic_proofs::store`).
//!
//! Each runs as a randomised test under `cargo test`, as a fuzz target under `cargo bolero
//! test`, and as a proof under `cargo kani --tests` (Kani not installed here: not run). The
//! longest loop is the keys partition's CRC over at most 12 + 2 × 36 octets: unwind 90.

use mmic::link::sdls::Key256;
use mmic::node::server::store::keys::{self, ENTRY_LEN, HEADER_LEN};
use mmic::node::server::store::log::{encode_entry, encode_header, RECORD_LEN};
use mmic::node::server::store::queue::job_entry;
use mmic::node::server::store::Entry;
use mmic::units::BoardNumber;
use mmic_proofs::store::{check_keys_partition, check_log_record, check_queue_value};

/// Sampled values per harness under `cargo test` (see `crate::ledger`).
#[cfg(not(any(kani, fuzzing)))]
const SAMPLED: u64 = 100_000;

/// The three records every one-octet change starts from: an entry, a header, an erased slot.
#[cfg(not(any(kani, fuzzing)))]
fn records() -> [[u8; RECORD_LEN]; 3] {
    [
        encode_entry(&Entry {
            key: 0x2001,
            aux: 7,
            value: 0x1234_5678_9abc,
        })
        .expect("a 96-bit value"),
        encode_header(9),
        [0xFF; RECORD_LEN],
    ]
}

/// Any 20 octets: a free slot only when erased, an entry or a header exactly as written, or
/// invalid.
///
/// Under `cargo test`: exhaustively, every value of every octet of an entry, a header and an
/// erased slot (the others as written), then sampled records.
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(21))]
fn log_record_is_canonical_or_invalid() {
    #[cfg(not(any(kani, fuzzing)))]
    {
        let name = "log_record_is_canonical_or_invalid";
        crate::ledger::exhaustive(
            name,
            3 * RECORD_LEN as u64 * 256,
            (0usize..3, 0usize..RECORD_LEN, bolero::produce::<u8>()),
            |&(which, at, v)| {
                let mut r = records()[which];
                r[at] = v;
                check_log_record(&r);
            },
        );
        crate::ledger::sampled(name, SAMPLED, |r: &[u8; RECORD_LEN]| {
            check_log_record(r);
        });
        return;
    }
    #[allow(unreachable_code)]
    bolero::check!()
        .with_type::<[u8; RECORD_LEN]>()
        .for_each(|r| {
            check_log_record(r);
        });
}

/// A keys partition of two keys (SPIs 257 and 513), written by the library's writer.
#[cfg(not(any(kani, fuzzing)))]
fn partition() -> [u8; HEADER_LEN + 2 * ENTRY_LEN + 4] {
    let k = |s: u8| Key256::from_bytes(core::array::from_fn(|i| (i as u8).wrapping_mul(53) ^ s));
    let (a, b) = (k(1), k(2));
    let mut out = [0u8; HEADER_LEN + 2 * ENTRY_LEN + 4];
    keys::emit(&[(257, &a), (513, &b)], &mut out).expect("two keys fit");
    out
}

/// Any octets (a length, then up to 88): refused by a named check, or keys that write back
/// exactly the same octets.
///
/// Under `cargo test`: exhaustively, every value of every octet of a partition of two keys
/// (its CRC then fails, or, for the CRC's own octets, it is the check that refuses), and every
/// length of it cut short; then sampled partitions.
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(90))]
fn keys_partition_is_canonical_or_refused_by_name() {
    #[cfg(not(any(kani, fuzzing)))]
    {
        let name = "keys_partition_is_canonical_or_refused_by_name";
        let n = HEADER_LEN + 2 * ENTRY_LEN + 4;
        crate::ledger::exhaustive(
            &format!("{name} (octets)"),
            n as u64 * 256,
            (0..n, bolero::produce::<u8>()),
            |&(at, v)| {
                let mut p = partition();
                p[at] = v;
                check_keys_partition(&p);
            },
        );
        crate::ledger::exhaustive(&format!("{name} (cut)"), n as u64 + 1, 0..=n, |&len| {
            let accepted = check_keys_partition(&partition()[..len]);
            assert_eq!(accepted, len == n, "cut to {len}");
        });
        crate::ledger::sampled(name, SAMPLED, |&(len, p): &(u8, [u8; 88])| {
            check_keys_partition(&p[..usize::from(len) % 89]);
        });
        return;
    }
    #[allow(unreachable_code)]
    bolero::check!()
        .with_type::<(u8, [u8; 88])>()
        .for_each(|&(len, p)| {
            check_keys_partition(&p[..usize::from(len) % 89]);
        });
}

/// Any 96-bit value in any slot of any robot: refused, or a queued telecommand whose entry is
/// exactly that value.
///
/// Under `cargo test`: exhaustively, every value of every octet of a queued Stop's entry (the
/// others as written), then sampled values.
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(8))]
fn queue_slot_is_canonical_or_refused() {
    let check = |&(board, slot, value): &(u8, u8, u128)| {
        if let Ok(b) = BoardNumber::new(board) {
            check_queue_value(b, slot % 16, value % (1u128 << 96));
        }
    };
    #[cfg(not(any(kani, fuzzing)))]
    {
        let name = "queue_slot_is_canonical_or_refused";
        let one = BoardNumber::ONE;
        let stop = job_entry(
            one,
            0,
            Some(&mmic::node::server::gateway::Job {
                request: mmic::pus::verification::RequestId {
                    apid: 0x101,
                    seq_count: 0x1234,
                },
                source_id: 9,
                ack: 0xF,
                command: mmic::command::Command::Stop,
                alive: false,
            }),
        )
        .value;
        crate::ledger::exhaustive(
            name,
            12 * 256,
            (0usize..12, bolero::produce::<u8>()),
            |&(at, v)| {
                let mut b = stop.to_be_bytes();
                b[4 + at] = v;
                check(&(1, 0, u128::from_be_bytes(b)));
            },
        );
        crate::ledger::sampled(name, SAMPLED, check);
        return;
    }
    #[allow(unreachable_code)]
    bolero::check!()
        .with_type::<(u8, u8, u128)>()
        .for_each(check);
}
