//! Several CFDP transactions at once, both ways (`mmic::cfdp::entity`): the ground sends three
//! plans (two in class 2, one in class 1) while the robot sends two logs down, all over one
//! link that loses, copies and reorders PDUs. Every transaction ends once at each end; each
//! file arrives exact under its own name, or both ends report a fault; none is mixed with
//! another's octets. A put beyond the entity's capacity, and a new transaction arriving at a
//! full entity, are refused by name.

use crate::common::Rng;
use mmic::cfdp::codes::ConditionCode;
use mmic::cfdp::entity::{
    Config, Entity, Event, HandleError, MemoryStore, Put, PutError, TransactionId,
};
use mmic::cfdp::header::Mode;
use std::collections::{BTreeMap, BinaryHeap};

type Node = Entity<6, 16, 16>;
type Store = MemoryStore<12, 4096>;

const GROUND: u64 = 0x15;
const ROBOT: u64 = 0x42;

/// A file to send: its names, its class, its octets.
struct Transfer {
    from_ground: bool,
    source: &'static [u8],
    dest: &'static [u8],
    mode: Mode,
    data: Vec<u8>,
}

fn transfers(seed: u64) -> Vec<Transfer> {
    let mut rng = Rng(seed | 1);
    let mut data = |len: usize| (0..len).map(|_| rng.next() as u8).collect::<Vec<u8>>();
    let t = |from_ground, source, dest, mode, data| Transfer {
        from_ground,
        source,
        dest,
        mode,
        data,
    };
    vec![
        t(true, b"a", b"plans/a", Mode::Acknowledged, data(1500)),
        t(true, b"b", b"plans/b", Mode::Acknowledged, data(700)),
        t(true, b"c", b"plans/c", Mode::Unacknowledged, data(300)),
        t(false, b"log", b"logs/a", Mode::Acknowledged, data(2000)),
        t(false, b"events", b"logs/s", Mode::Acknowledged, data(900)),
    ]
}

/// Runs every transfer at once over a link losing and copying `loss` and `dup` percent of
/// the PDUs, with up to 40 ms of jitter: each end's events by transaction, and both stores.
fn run(seed: u64, loss: u64, dup: u64) -> (BTreeMap<TransactionId, Vec<Event>>, Store, Store) {
    let mut rng = Rng::seeded(seed);
    let mut ends = [
        (Node::new(Config::mission(GROUND), 1), Store::new()),
        (Node::new(Config::mission(ROBOT), 1), Store::new()),
    ];
    for t in transfers(seed) {
        let (node, store) = &mut ends[usize::from(!t.from_ground)];
        store.put(t.source, &t.data).unwrap();
        let peer = if t.from_ground { ROBOT } else { GROUND };
        let put = Put::new(t.source, t.dest, t.mode).unwrap();
        node.put(0, peer, put, store).unwrap();
    }
    let mut events: BTreeMap<TransactionId, Vec<Event>> = BTreeMap::new();
    let mut flights = BinaryHeap::new();
    let (mut order, mut buf) = (0u64, [0u8; 512]);
    for step in 0..60_000u64 {
        let now = step * 10;
        for (k, (node, store)) in ends.iter_mut().enumerate() {
            for _ in 0..8 {
                let Some(n) = node.poll(now, store, &mut buf) else {
                    break;
                };
                for _ in 0..1 + usize::from(rng.below(dup)) {
                    if !rng.below(loss) {
                        order += 1;
                        let due = now + 10 + rng.next() % 41;
                        flights.push(std::cmp::Reverse((due, order, buf[..n].to_vec(), 1 - k)));
                    }
                }
            }
        }
        while flights.peek().is_some_and(|f| f.0 .0 <= now) {
            let std::cmp::Reverse((_, _, bytes, to)) = flights.pop().unwrap();
            let (node, store) = &mut ends[to];
            if let Err(e) = node.handle(now, &bytes, store) {
                let late = matches!(e, HandleError::Ended(_) | HandleError::Unknown(_));
                assert!(late, "seed {seed}: {e}");
            }
        }
        for (node, _) in &mut ends {
            while let Some(e) = node.take_event() {
                let id = match &e {
                    Event::Sent { id, .. } | Event::Received { id, .. } => *id,
                };
                events.entry(id).or_default().push(e);
            }
        }
        if ends.iter().all(|(n, _)| n.active() == 0) && events.len() == 5 {
            break;
        }
    }
    let [(_, gs), (_, rs)] = ends;
    (events, gs, rs)
}

/// The invariants of one run.
fn check(seed: u64, loss: u64, dup: u64) -> usize {
    let (events, gs, rs) = run(seed, loss, dup);
    assert_eq!(events.len(), 5, "seed {seed}: transactions {events:?}");
    let mut delivered = 0;
    let (mut ground_seq, mut robot_seq) = (0, 0);
    for t in transfers(seed) {
        // Sequence numbers are taken in put order at each end, from 1.
        let (id, store) = if t.from_ground {
            ground_seq += 1;
            (
                TransactionId {
                    source: GROUND,
                    seq: ground_seq,
                },
                &rs,
            )
        } else {
            robot_seq += 1;
            (
                TransactionId {
                    source: ROBOT,
                    seq: robot_seq,
                },
                &gs,
            )
        };
        let evs = &events[&id];
        let sent = evs
            .iter()
            .filter(|e| matches!(e, Event::Sent { .. }))
            .count();
        assert_eq!(sent, 1, "seed {seed} {id:?}: the sender's end once");
        let received: Vec<_> = evs
            .iter()
            .filter_map(|e| match e {
                Event::Received {
                    condition,
                    delivered,
                    ..
                } => Some((*condition, *delivered)),
                Event::Sent { .. } => None,
            })
            .collect();
        assert!(received.len() <= 1, "seed {seed} {id:?}: two ends");
        let got = store.get(t.dest);
        match received.first() {
            Some((ConditionCode::NoError, true)) => {
                assert_eq!(got, Some(t.data.as_slice()), "seed {seed}: {:?}", t.dest);
                delivered += 1;
            }
            Some((c, false)) => {
                assert_ne!(*c, ConditionCode::NoError);
                assert_eq!(got, None, "seed {seed}: kept, said not");
            }
            other => assert!(
                other.is_none() && got.is_none() && t.mode == Mode::Unacknowledged,
                "seed {seed}: {other:?}"
            ),
        }
        let success = evs.iter().any(|e| {
            matches!(
                e,
                Event::Sent {
                    condition: ConditionCode::NoError,
                    ..
                }
            )
        });
        if t.mode == Mode::Acknowledged && success {
            assert_eq!(
                got,
                Some(t.data.as_slice()),
                "seed {seed}: success, no file"
            );
        }
    }
    assert_eq!(
        rs.incoming() + gs.incoming(),
        0,
        "seed {seed}: incoming left"
    );
    delivered
}

// req: 727.0-B-5/CFDP-31
#[test]
#[cfg_attr(miri, ignore = "natively: 40 runs of five transfers")]
fn five_transfers_at_once_both_ways_arrive_exact_or_fail_on_both_ends() {
    let mut delivered = 0;
    for seed in 0..20 {
        assert_eq!(check(seed, 0, 0), 5, "seed {seed}: without loss, all five");
        delivered += check(seed, 20, 5);
    }
    // At 20 % loss the class-1 plan is often lost, the class-2 files nearly never: 90 of 100
    // delivered (2026-11-29).
    assert!(delivered >= 80, "delivered {delivered} of 100 at 20 % loss");
}

/// A put beyond the capacity and a new transaction reaching a full entity are refused by name,
/// counted, and change nothing else.
// req: 727.0-B-5/CFDP-31
#[test]
fn a_full_entity_refuses_puts_and_new_transactions_by_name() {
    let mut ground = Entity::<1, 4, 4>::new(Config::mission(GROUND), 1);
    let mut robot = Entity::<1, 4, 4>::new(Config::mission(ROBOT), 1);
    // A small store: this test runs under Miri too.
    let (mut gs, mut rs) = (MemoryStore::<4, 64>::new(), MemoryStore::<4, 64>::new());
    gs.put(b"a", b"plan").unwrap();
    rs.put(b"log", b"entries").unwrap();
    let put = || Put::new(b"a", b"plans/a", Mode::Acknowledged).unwrap();
    ground.put(0, ROBOT, put(), &mut gs).unwrap();
    assert_eq!(
        ground.put(0, ROBOT, put(), &mut gs),
        Err(PutError::Full { capacity: 1 })
    );
    assert_eq!(
        ground.next_seq(),
        2,
        "a refused put takes no sequence number"
    );
    // The robot is busy sending its log; the ground's Metadata finds it full.
    let log = Put::new(b"log", b"logs/a", Mode::Acknowledged).unwrap();
    robot.put(0, GROUND, log, &mut rs).unwrap();
    let mut buf = [0u8; 512];
    let n = ground.poll(0, &mut gs, &mut buf).unwrap();
    let before = (robot.active(), robot.next_seq(), rs.clone());
    assert_eq!(
        robot.handle(0, &buf[..n], &mut rs),
        Err(HandleError::Full { capacity: 1 })
    );
    assert_eq!(robot.counters().full, 1);
    assert_eq!((robot.active(), robot.next_seq(), rs), before);
}
