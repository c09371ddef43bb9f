//! The simulator's and the host tools' tests: the engine, the realtime engine over real
//! transports, the fault swarm and its shards, fleets, replay, restarts, SDLS and the security
//! checks of every host mode. The CLI's tests are `tests/cli/`.
//!
//! One test binary, each file a module: the binary links once, and the tests that wait on the
//! wall clock run side by side in one test (`clock`), started first, beside the ones that
//! compute, each of which runs on one thread ([`JOBS`]).

mod clock;
mod engine;
mod fidelity;
mod fleet;
mod opsui_serial;
mod pus;
mod realtime;
mod replay;
mod restarts;
mod sdls;
mod security;
mod sim;
mod sim_timing;
mod swarm;
mod swarm_equivalence;
mod swarm_shard;

use mmic_host::swarm::{scenario::Options, Report};
use std::time::Duration;

/// The threads a test here may use for its own work: one. libtest runs two tests at once (a
/// thread per core on CI's 2-core machines); while the wall-clock checks run (`clock`, the
/// first 27 s), one of its threads is theirs, and a test beside them that took every core would
/// make them miss their windows. A swarm's report is the same on any number of threads
/// (`mmic_host::swarm::pool`): its threads are checked by the pool's own example and by the
/// command-line tests and CI steps that run `mmic swarm` on every core.
pub(crate) const JOBS: usize = 1;

/// [`mmic_host::swarm::swarm`] on [`JOBS`] threads: the seeds from `seed_start` on, at most
/// `max_runs` of them.
pub(crate) fn swarm_on_test_jobs(
    seed_start: u64,
    budget: Duration,
    max_runs: Option<u64>,
    stop_at_failures: usize,
    opts: &Options,
    progress: &mut dyn FnMut(String),
) -> Report {
    mmic_host::swarm::swarm_over(
        &mut mmic_host::swarm::seeds_from(seed_start, max_runs),
        budget,
        stop_at_failures,
        JOBS,
        opts,
        progress,
    )
}
