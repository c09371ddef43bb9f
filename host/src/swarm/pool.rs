//! Seeds run on several threads, their outcomes taken in the order the seeds were given: a
//! run is a pure function of its seed, so the swarm's report of the same seeds is the same
//! whatever the number of threads (only the wall time differs).
//!
//! ```
//! use mmic_host::swarm::pool::in_order;
//! let mut seen = Vec::new();
//! in_order(&mut (1..=20u64), 3, &|| true, &|s| s * s, &mut |s, sq| {
//!     seen.push((s, sq));
//!     s < 15 // stop after seed 15
//! });
//! assert_eq!(seen, (1..=15).map(|s| (s, s * s)).collect::<Vec<_>>());
//! ```

use std::collections::BTreeMap;
use std::sync::mpsc;

/// A worker's message: its number, and the outcome of the seed it ran (its place in the order,
/// the seed, the outcome), none when it is ready for its first.
type Done<T> = (usize, Option<(u64, u64, T)>);

/// The threads a swarm uses by default: one per core the process may use.
pub fn default_jobs() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// Runs `run` on the seeds `seeds` gives, on `jobs` threads, and hands each outcome to `take`
/// in the seeds' order, until `take` says stop (false), `seeds` ends, or `go_on` says no more
/// seeds be taken (checked before each). A seed is taken from `seeds` only to be run; after a
/// stop, the outcomes of the seeds still running are not taken.
pub fn in_order<T: Send>(
    seeds: &mut dyn Iterator<Item = u64>,
    jobs: usize,
    go_on: &dyn Fn() -> bool,
    run: &(dyn Fn(u64) -> T + Sync),
    take: &mut dyn FnMut(u64, T) -> bool,
) {
    if jobs <= 1 {
        while go_on() {
            let Some(seed) = seeds.next() else { break };
            if !take(seed, run(seed)) {
                break;
            }
        }
        return;
    }
    std::thread::scope(|s| {
        let (done_tx, done) = mpsc::channel::<Done<T>>();
        let workers: Vec<mpsc::Sender<Option<(u64, u64)>>> = (0..jobs)
            .map(|w| {
                let (tx, rx) = mpsc::channel::<Option<(u64, u64)>>();
                let done = done_tx.clone();
                s.spawn(move || worker(w, &rx, &done, run));
                tx
            })
            .collect();
        drop(done_tx);
        let mut order = Order::default();
        let mut live = jobs;
        while live > 0 {
            let Ok((w, outcome)) = done.recv() else { break };
            if let Some((k, seed, t)) = outcome {
                order.arrived(k, seed, t, take);
            }
            let next = if order.stopped || !go_on() {
                None
            } else {
                seeds.next().map(|seed| order.given(seed))
            };
            live -= usize::from(next.is_none());
            // A worker that has ended its loop has nothing to hear.
            let _ = workers[w].send(next);
        }
    });
}

/// One thread: says it is ready, then runs each seed it is given until told to stop.
fn worker<T>(
    w: usize,
    seeds: &mpsc::Receiver<Option<(u64, u64)>>,
    done: &mpsc::Sender<Done<T>>,
    run: &(dyn Fn(u64) -> T + Sync),
) {
    if done.send((w, None)).is_err() {
        return;
    }
    while let Ok(Some((k, seed))) = seeds.recv() {
        if done.send((w, Some((k, seed, run(seed))))).is_err() {
            return;
        }
    }
}

/// The outcomes that arrived ahead of an earlier seed's, held until it comes.
struct Order<T> {
    given: u64,
    next: u64,
    waiting: BTreeMap<u64, (u64, T)>,
    stopped: bool,
}

impl<T> Default for Order<T> {
    fn default() -> Self {
        Order {
            given: 0,
            next: 0,
            waiting: BTreeMap::new(),
            stopped: false,
        }
    }
}

impl<T> Order<T> {
    /// Seed `seed` given to a worker: its place in the order.
    fn given(&mut self, seed: u64) -> (u64, u64) {
        self.given += 1;
        (self.given - 1, seed)
    }

    /// The outcome of the `k`th seed given arrived: it and those after it that wait, taken.
    fn arrived(&mut self, k: u64, seed: u64, t: T, take: &mut dyn FnMut(u64, T) -> bool) {
        self.waiting.insert(k, (seed, t));
        while let Some((seed, t)) = self.waiting.remove(&self.next) {
            self.next += 1;
            if !self.stopped && !take(seed, t) {
                self.stopped = true;
            }
        }
    }
}
