//! The A/B bolter handshake, model-checked by explicit-state search: board A's coordinator and
//! side-A executor, board B's executor, an A→B link and a B→A link that lose and duplicate
//! messages (FIFO: a serial line does not reorder), both sides' sensor events in any order, and
//! time that can jump past every timeout at any moment. A side's sensor event is a reading just
//! at the threshold of every current-sensed step with the home switch closed (whatever step runs,
//! it ends); every other tick reads a current just below every threshold with the switch open
//! (no step ends). Every reachable state is checked:
//!
//! - side B never runs a step A has not ordered, and is never more than one order behind;
//! - when B is one order behind while A proceeds normally (not a retry), B's step is finished:
//!   A moved on only on B's report that it had completed that same step;
//! - from every reachable state the job can still end (Done or Failed);
//! - a bolting failure is declared only on the last attempt's failed sensed step, or at any
//!   attempt when a step that ends at home (Retract, CounterRotate, ReturnHome) times out: the
//!   bolter cannot get home, so no retry makes sense (`Coordinator::attempt_failed`);
//! - liveness under fairness, in the same model without time jumps (no timeouts) and without
//!   losses on either link: no failure is reachable, and from every reachable state Done is
//!   reachable. In a finite graph, that means every run that takes each transition enabled
//!   infinitely often infinitely often (strong fairness: every delivery, heartbeat and end
//!   signal eventually happens) reaches Done — a run staying away from Done forever would
//!   visit some state infinitely often and, by fairness, every state reachable from it,
//!   Done among them. The first property alone (the job can end) would hold through the
//!   timeouts even if the handshake could never complete.
//!
//! The state and transition counts are asserted: a change to the coordinator or executor that
//! changes the reachable space shows here and in the README's row.

use hashbrown::HashTable;
use mmic::bolter::{BolterDirection, BolterSide, Config, Coordinator, Job, Sensed, Status};
use mmic::command::{BolterPair, Fasteners};
use mmic::faults::Fault;
use mmic::wire::b_command::BolterOrder;
use mmic::wire::internal_heartbeat::BolterAux;
use std::collections::VecDeque;
use std::hash::BuildHasher;
// The 2.8 M states' index hashes with rustc's FxHash (rustc-hash): std's SipHash, made to resist
// flooding by chosen keys, was most of the walk's time, and the keys are the model's own states (a
// weak hash only makes the map slower, never wrong). From a crate rather than written here: its
// `#[inline]` steps then compile without coverage counters in CI's instrumented run, where a
// hasher of this file's own took two thirds of the walk (33 s against 12 s uninstrumented, issue 40).
use rustc_hash::FxBuildHasher;

#[derive(Clone, Copy, PartialEq, Eq, Hash, Debug)]
struct World {
    coord: Coordinator,
    a: BolterSide,
    b: BolterSide,
    ab: Option<(u8, Option<BolterOrder>)>,
    ba: Option<BolterAux>,
    b_seen: Option<BolterAux>,
    now: u32,
}

const JUMP: u32 = 1 << 30; // past every timeout, and the clock cycles through 4 values

/// `lossy`: links may lose messages and time may jump past every timeout (the full model);
/// otherwise neither happens (the fairness model).
/// At most nine successors: A's tick, two end signals, delivered and lost on each link, B's
/// heartbeat and the time jump.
type Successors = heapless::Vec<World, 9>;

/// Pushes `x` into `out`: nine places suffice (see [`Successors`]).
fn put(out: &mut Successors, x: World) {
    assert!(out.push(x).is_ok(), "more than nine successors");
}

fn successors(cfg: &Config, w: &World, lossy: bool) -> Successors {
    let (push, lock) = (cfg.side.push_threshold_ma, cfg.side.lock_threshold_ma);
    // The end event: I_bo just reaches the higher threshold (so every sensed step's), home.
    let all = Sensed {
        i_bo: push.max(lock),
        at_home: true,
    };
    // No event: I_bo one mA short of the lower threshold, away from home.
    let none = Sensed {
        i_bo: push.min(lock) - 1,
        at_home: false,
    };
    let mut out = Successors::new();
    // A's control loop: coordinator tick, side A follows, a fresh snapshot goes on the link.
    let mut x = *w;
    let o = x.coord.step(cfg, x.now, &x.a.aux(), x.b_seen.as_ref());
    let (seq, order) = match o.order {
        Some((s, ord)) => (s, Some(ord)),
        None => (x.a.aux().seq, None),
    };
    x.a.order(seq, order, x.now);
    x.a.tick(&cfg.side, x.now, none);
    x.ab = Some((seq, order));
    put(&mut out, x);
    // Side A's end signal for its step.
    let mut x = *w;
    x.a.tick(&cfg.side, x.now, all);
    put(&mut out, x);
    // Side B's end signal.
    let mut x = *w;
    x.b.tick(&cfg.side, x.now, all);
    put(&mut out, x);
    // A→B delivered (kept on the link: it may be delivered again), or lost.
    if let Some((seq, order)) = w.ab {
        let mut x = *w;
        x.b.order(seq, order, x.now);
        put(&mut out, x);
        if lossy {
            let mut x = *w;
            x.ab = None;
            put(&mut out, x);
        }
    }
    // B sends its heartbeat; B→A delivered (duplicable) or lost.
    let mut x = *w;
    x.b.tick(&cfg.side, x.now, none);
    x.ba = Some(x.b.aux());
    put(&mut out, x);
    if let Some(aux) = w.ba {
        let mut x = *w;
        x.b_seen = Some(aux);
        put(&mut out, x);
        if lossy {
            let mut x = *w;
            x.ba = None;
            put(&mut out, x);
        }
    }
    // Time jumps past every timeout.
    if lossy {
        let mut x = *w;
        x.now = x.now.wrapping_add(JUMP);
        put(&mut out, x);
    }
    out
}

fn check(w: &World) {
    use mmic::bolter::BolterStep;
    let b = w.b.aux();
    if let (Some((seq, o)), Some(step)) = (w.coord.order(), b.step) {
        let lag = seq.wrapping_sub(b.seq);
        assert!(
            lag <= 1,
            "B ahead of or more than one order behind A: {w:?}"
        );
        if lag == 0 {
            assert_eq!(
                (step, b.pair, b.direction),
                (o.step, Some(o.pair), Some(o.direction))
            );
        } else if o.step != BolterStep::ReturnHome {
            let ended = match step {
                BolterStep::Descend | BolterStep::DescendEngage => b.threshold_reached,
                BolterStep::Rotate => b.locked,
                _ => b.at_home,
            };
            assert!(ended, "A moved on while B's step is unfinished: {w:?}");
        }
    }
}

fn explore(job: Job, lossy: bool) -> Counts {
    let cfg = Config::default();
    let mut start = World {
        coord: Coordinator::new(),
        a: BolterSide::new(),
        b: BolterSide::new(),
        ab: None,
        ba: None,
        b_seen: None,
        now: 0,
    };
    start.coord.start(job, 0);
    // The index holds each state's number, the state itself only in `states`: 4 octets a slot
    // instead of a `World` and a `usize` (a `HashMap<World, usize>` spent 40 % of the walk
    // missing the cache in its 2.8 M slots of 80-odd octets; issue 40).
    // Room for the full model's counts (`COUNTS`) from the start: growing the index rehashed
    // every state again and again (8 % of the walk).
    let (room, edge_room) = if lossy {
        (2_900_000, 20_000_000)
    } else {
        (128, 1024)
    };
    let fx = FxBuildHasher;
    let mut index: HashTable<u32> = HashTable::with_capacity(room);
    let mut states = Vec::with_capacity(room);
    states.push(start);
    // Every transition (from, to), in one array: millions of small lists cost more than the walk.
    let mut edges: Vec<(u32, u32)> = Vec::with_capacity(edge_room);
    index.insert_unique(fx.hash_one(start), 0, |&m| fx.hash_one(states[m as usize]));
    let mut queue = VecDeque::from([0usize]);
    let mut terminal = [0usize; 3]; // done, bolting failure, side B never reported (motion timeout)
    while let Some(i) = queue.pop_front() {
        let w = states[i];
        check(&w);
        match w.coord.status() {
            Status::Done => terminal[0] += 1,
            Status::Failed(Fault::BoltingFailure) => terminal[1] += 1,
            Status::Failed(_) => terminal[2] += 1,
            _ => {}
        }
        if matches!(w.coord.status(), Status::Done | Status::Failed(_)) {
            continue;
        }
        for n in successors(&cfg, &w, lossy) {
            let hash = fx.hash_one(n);
            let j = match index.find(hash, |&k| states[k as usize] == n) {
                Some(&k) => k as usize,
                None => {
                    let k = states.len();
                    states.push(n);
                    queue.push_back(k);
                    let id = u32::try_from(k).expect("under 5 M states");
                    index.insert_unique(hash, id, |&m| fx.hash_one(states[m as usize]));
                    k
                }
            };
            edges.push((i as u32, j as u32));
            if states[j].coord.status() == Status::Failed(Fault::BoltingFailure) {
                use mmic::bolter::BolterStep::*;
                let at = &states[i].coord;
                let home_failed = !matches!(at.current_step(), Descend | DescendEngage | Rotate);
                assert!(
                    at.attempt() == 3 || home_failed,
                    "bolting failure declared at attempt {}",
                    at.attempt()
                );
            }
        }
        assert!(states.len() < 5_000_000, "state space too large");
    }
    // Liveness: every state reaches a terminal one (reverse reachability from terminals).
    // The reverse edges grouped by target (a counting sort): rev[start[j]..start[j + 1]].
    let mut start = vec![0usize; states.len() + 1];
    for &(_, j) in &edges {
        start[j as usize + 1] += 1;
    }
    for k in 1..start.len() {
        start[k] += start[k - 1];
    }
    let mut fill = start.clone();
    let mut rev = vec![0u32; edges.len()];
    for &(i, j) in &edges {
        rev[fill[j as usize]] = i;
        fill[j as usize] += 1;
    }
    let mut can_end = vec![false; states.len()];
    let mut q: VecDeque<usize> = (0..states.len())
        .filter(|&i| matches!(states[i].coord.status(), Status::Done | Status::Failed(_)))
        .collect();
    for &i in &q {
        can_end[i] = true;
    }
    while let Some(j) = q.pop_front() {
        for &i in &rev[start[j]..start[j + 1]] {
            let i = i as usize;
            if !can_end[i] {
                can_end[i] = true;
                q.push_back(i);
            }
        }
    }
    let stuck = can_end.iter().filter(|c| !**c).count();
    assert_eq!(stuck, 0, "{stuck} states cannot reach the end of the job");
    if !lossy {
        // Only Done ends a job here, so "can end" is "can reach Done".
        assert!(
            states
                .iter()
                .all(|w| !matches!(w.coord.status(), Status::Failed(_))),
            "a job failed with no timeout and no loss"
        );
    }
    let transitions = edges.len();
    (states.len(), transitions, terminal)
}

/// The counts the README quotes, per direction: (states, transitions, terminal states
/// done / bolting failure / motion timeout), full model then fairness model.
type Counts = (usize, usize, [usize; 3]);
const COUNTS: [(BolterDirection, Counts, Counts); 2] = [
    (
        BolterDirection::Bolt,
        (2_803_572, 19_960_800, [1280, 3584, 36196]),
        (122, 716, [1, 0, 0]),
    ),
    (
        BolterDirection::Unbolt,
        (2_803_572, 19_960_800, [1280, 3584, 36196]),
        (122, 716, [1, 0, 0]),
    ),
];

/// One direction's full and fair models, against its row of [`COUNTS`].
fn check_direction(direction: BolterDirection) {
    let (_, full, fair) = COUNTS
        .into_iter()
        .find(|(d, _, _)| *d == direction)
        .expect("a row per direction");
    let job = Job {
        direction,
        fasteners: Fasteners::Pair(BolterPair::P2),
    };
    let got = explore(job, true);
    println!("bolter handshake ({direction:?}, one pair): {} states, {} transitions, terminal done/bolting-failure/motion-timeout {:?}", got.0, got.1, got.2);
    assert!(
        got.2.iter().all(|&c| c > 0),
        "every outcome must be reachable: {:?}",
        got.2
    );
    let got_fair = explore(job, false);
    println!("  no timeouts, no losses: {} states, {} transitions, terminal {:?}; every one reaches Done", got_fair.0, got_fair.1, got_fair.2);
    assert!(got_fair.2[0] > 0);
    assert_eq!(
        (got, got_fair),
        (full, fair),
        "{direction:?}: counts changed"
    );
}

// One test per direction: libtest runs them side by side (each is some 2.8 M states).
// req: P5.13, P5.14
#[test]
fn handshake_single_pair_bolt() {
    check_direction(BolterDirection::Bolt);
}

// req: P5.14
#[test]
fn handshake_single_pair_unbolt() {
    check_direction(BolterDirection::Unbolt);
}

/// The default coordinator is a new one: no job, idle.
#[test]
fn the_default_coordinator_is_idle() {
    let c = Coordinator::default();
    assert_eq!(c, Coordinator::new());
    assert_eq!(c.status(), Status::Idle);
}
