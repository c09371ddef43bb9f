//! CFDP entities (`mmic::cfdp::entity`) end to end: a ground entity sends files to a robot's
//! entity over a simulated link that loses, duplicates and reorders PDUs, in class 1 and
//! class 2, for many seeds. Each run ends with both sides' events; the file arrives exact, or
//! it is not under its name and the sender reports a fault; no incoming file is left behind.

use crate::common::Rng;
use mmic::cfdp::codes::ConditionCode;
use mmic::cfdp::entity::{Config, Entity, Event, MemoryStore, Put};
use mmic::cfdp::header::Mode;
use std::collections::BinaryHeap;

type Node = Entity<4, 16, 16>;
type Store = MemoryStore<6, 8192>;

/// The link's behaviour, each direction alike.
#[derive(Debug, Clone, Copy)]
struct Link {
    loss: f64,
    dup: f64,
    /// Latency 10 ms plus up to this much more (reordering when larger than the PDU spacing).
    jitter_ms: u64,
}

/// A PDU in flight: due time, an order number, the octets, toward the robot or not.
type Flight = std::cmp::Reverse<(u64, u64, Vec<u8>, bool)>;

/// What a run ended with.
#[derive(Debug)]
struct Outcome {
    sent: Option<Event>,
    received: Option<Event>,
    delivered: Option<Vec<u8>>,
    left_incoming: usize,
    now: u64,
}

fn run(seed: u64, file: &[u8], mode: Mode, closure: bool, link: Link) -> Outcome {
    let mut rng = Rng::seeded(seed);
    let mut ground = Node::new(Config::mission(0x15), 1);
    let mut robot = Node::new(Config::mission(0x42), 1);
    let (mut gs, mut rs) = (Store::new(), Store::new());
    gs.put(b"plan.json", file).unwrap();
    let mut put = Put::new(b"plan.json", b"plans/next.json", mode).unwrap();
    put.closure = closure;
    ground.put(0, 0x42, put, &mut gs).unwrap();
    let mut flights: BinaryHeap<Flight> = BinaryHeap::new();
    let mut order = 0u64;
    let (mut sent, mut received) = (None, None);
    let mut buf = [0u8; 512];
    let mut now = 0u64;
    while now < 600_000 {
        for (to_robot, node, store) in [(true, &mut ground, &mut gs), (false, &mut robot, &mut rs)]
        {
            // Paced as a radio would: at most 8 PDUs a 10 ms step.
            for _ in 0..8 {
                let Some(n) = node.poll(now, store, &mut buf) else {
                    break;
                };
                for _ in 0..1 + usize::from(rng.chance(link.dup)) {
                    if !rng.chance(link.loss) {
                        let due = now + 10 + rng.next() % (link.jitter_ms + 1);
                        order += 1;
                        flights.push(std::cmp::Reverse((due, order, buf[..n].to_vec(), to_robot)));
                    }
                }
            }
        }
        while flights.peek().is_some_and(|f| f.0 .0 <= now) {
            let std::cmp::Reverse((_, _, bytes, to_robot)) = flights.pop().unwrap();
            let r = if to_robot {
                robot.handle(now, &bytes, &mut rs)
            } else {
                ground.handle(now, &bytes, &mut gs)
            };
            // Late PDUs of ended transactions are refused, nothing else.
            if let Err(e) = r {
                assert!(
                    matches!(
                        e,
                        mmic::cfdp::entity::HandleError::Ended(_)
                            | mmic::cfdp::entity::HandleError::Unknown(_)
                    ),
                    "seed {seed}: {e}"
                );
            }
        }
        if let Some(e) = ground.take_event() {
            assert!(sent.replace(e).is_none(), "seed {seed}: two events");
        }
        if let Some(e) = robot.take_event() {
            assert!(received.replace(e).is_none(), "seed {seed}: two events");
        }
        if sent.is_some() && received.is_some() && ground.active() == 0 && robot.active() == 0 {
            break;
        }
        now += 10;
    }
    Outcome {
        sent,
        received,
        delivered: rs.get(b"plans/next.json").map(<[u8]>::to_vec),
        left_incoming: rs.incoming(),
        now,
    }
}

/// A file of `len` octets from `seed`.
fn file(seed: u64, len: usize) -> Vec<u8> {
    let mut rng = Rng(seed | 1);
    (0..len).map(|_| rng.next() as u8).collect()
}

/// The invariants of every run.
fn check(seed: u64, o: &Outcome, data: &[u8], mode: Mode) {
    let Some(Event::Sent {
        condition: sent, ..
    }) = o.sent.clone()
    else {
        panic!("seed {seed}: the sender never ended: {o:?}");
    };
    assert_eq!(
        o.left_incoming, 0,
        "seed {seed}: an incoming file left behind"
    );
    if let Some(got) = &o.delivered {
        assert_eq!(got, data, "seed {seed}: delivered, not exact");
    }
    if mode == Mode::Acknowledged && sent == ConditionCode::NoError {
        // Class 2: the sender's success is the receiver's Finished, sent only once the file
        // was kept.
        assert!(
            o.delivered.is_some(),
            "seed {seed}: the sender's success, no file"
        );
    }
    match &o.received {
        Some(Event::Received {
            delivered: true,
            condition,
            ..
        }) => {
            assert_eq!(*condition, ConditionCode::NoError);
            assert!(
                o.delivered.is_some(),
                "seed {seed}: said delivered, not in the store"
            );
        }
        Some(Event::Received {
            delivered: false,
            condition,
            ..
        }) => {
            assert_ne!(*condition, ConditionCode::NoError, "seed {seed}");
            assert!(
                o.delivered.is_none(),
                "seed {seed}: in the store, said not delivered"
            );
        }
        Some(other) => panic!("seed {seed}: {other:?}"),
        // A receiver that never heard a PDU has nothing to say.
        None => assert!(o.delivered.is_none()),
    }
}

// req: 727.0-B-5/CFDP-18, 727.0-B-5/CFDP-27
#[test]
#[cfg_attr(
    miri,
    ignore = "nine transfers of up to 8,000 octets: natively; under Miri the entities run in tests/ccsds/cfdp_edges.rs"
)]
fn class2_without_loss_delivers_every_file_size() {
    for len in [0usize, 1, 3, 4, 479, 480, 481, 1500, 8000] {
        let data = file(len as u64, len);
        let o = run(
            1,
            &data,
            Mode::Acknowledged,
            false,
            Link {
                loss: 0.0,
                dup: 0.0,
                jitter_ms: 0,
            },
        );
        check(1, &o, &data, Mode::Acknowledged);
        assert_eq!(o.delivered.as_deref(), Some(&data[..]), "{len} octets");
        assert!(matches!(
            o.sent,
            Some(Event::Sent {
                condition: ConditionCode::NoError,
                ..
            })
        ));
    }
}

// req: 727.0-B-5/CFDP-27, 727.0-B-5/CFDP-28, 727.0-B-5/CFDP-29, 727.0-B-5/CFDP-30
#[test]
#[cfg_attr(
    miri,
    ignore = "300 simulated transfers: natively; under Miri the entities run in tests/ccsds/cfdp_edges.rs"
)]
fn class2_through_loss_duplication_and_reordering() {
    let (mut delivered, mut runs) = (0, 0);
    for seed in 1..=300u64 {
        let data = file(seed, 500 + (seed as usize * 37) % 6000);
        let link = Link {
            loss: [0.05, 0.2, 0.4][seed as usize % 3],
            dup: 0.1,
            jitter_ms: 40,
        };
        let o = run(seed, &data, Mode::Acknowledged, false, link);
        check(seed, &o, &data, Mode::Acknowledged);
        runs += 1;
        if o.delivered.is_some() {
            delivered += 1;
        } else {
            // Both ends report the fault (five NAKs in a row without progress at 40 % loss).
            println!(
                "seed {seed} loss {}: {:?} / {:?} at {} ms",
                link.loss, o.sent, o.received, o.now
            );
            assert!(!matches!(
                o.sent,
                Some(Event::Sent {
                    condition: ConditionCode::NoError,
                    ..
                })
            ));
        }
        if let Some(Event::Sent {
            condition: ConditionCode::NoError,
            ..
        }) = o.sent
        {
            assert!(
                o.delivered.is_some(),
                "seed {seed}: sender's success, no file"
            );
        }
    }
    // Class 2 recovers from loss: nearly every run delivers.
    assert!(
        delivered * 100 >= runs * 95,
        "{delivered} of {runs} delivered"
    );
    println!("class 2: {delivered} of {runs} delivered");
}

// req: 727.0-B-5/CFDP-25, 727.0-B-5/CFDP-26
#[test]
#[cfg_attr(
    miri,
    ignore = "202 simulated transfers: natively; under Miri the entities run in tests/ccsds/cfdp_edges.rs"
)]
fn class1_delivers_without_loss_and_never_a_wrong_file() {
    let data = file(9, 3000);
    let clean = Link {
        loss: 0.0,
        dup: 0.0,
        jitter_ms: 0,
    };
    for closure in [false, true] {
        let o = run(9, &data, Mode::Unacknowledged, closure, clean);
        check(9, &o, &data, Mode::Unacknowledged);
        assert_eq!(o.delivered.as_deref(), Some(&data[..]));
    }
    let mut delivered = 0;
    for seed in 1..=200u64 {
        let link = Link {
            loss: 0.1,
            dup: 0.1,
            jitter_ms: 40,
        };
        let o = run(seed, &data, Mode::Unacknowledged, seed % 2 == 0, link);
        check(seed, &o, &data, Mode::Unacknowledged);
        delivered += usize::from(o.delivered.is_some());
    }
    println!("class 1 at 10 % loss: {delivered} of 200 delivered");
}

// req: D:cfdp-timers
#[test]
#[cfg_attr(
    miri,
    ignore = "parses spec/ TOML: 7 s under Miri, and no dependency's unsafe code the other spec tests do not reach"
)]
fn the_entity_profile_in_spec_is_the_librarys() {
    let t: toml::Table = toml::from_str(&crate::ccsds::repo("spec/ccsds/cfdp.toml")).unwrap();
    let e = &t["entity"];
    let c = Config::mission(0x42);
    let int = |k: &str| e[k].as_integer().unwrap();
    assert_eq!(int("ack_timeout_ms"), i64::from(c.ack_timeout_ms));
    assert_eq!(int("ack_limit"), i64::from(c.ack_limit));
    assert_eq!(int("nak_timeout_ms"), i64::from(c.nak_timeout_ms));
    assert_eq!(int("nak_limit"), i64::from(c.nak_limit));
    assert_eq!(int("inactivity_ms"), i64::from(c.inactivity_ms));
    assert_eq!(int("file_data"), i64::from(c.file_data));
    assert_eq!(e["immediate_nak"].as_bool(), Some(c.immediate_nak));
    assert_eq!(e["crc"].as_bool(), Some(c.crc));
    assert_eq!(e["fault_handler"].as_str(), Some("cancel"));
    for code in 1..16u8 {
        let condition = mmic::cfdp::codes::ConditionCode::from_code(code);
        if let Some(condition) = condition {
            assert_eq!(
                c.handlers.handler(condition),
                mmic::cfdp::entity::FaultHandler::Cancel
            );
        }
    }
    // A full file data PDU fits YAMCS's 512 octets, a CRC included.
    let h = c.lengths.header_len();
    assert!(h + 4 + usize::from(c.file_data) + 2 <= mmic::cfdp::MAX_PDU_LEN);
}
