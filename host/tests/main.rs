//! The simulator's and the host tools' tests: the engine, the realtime engine over real
//! transports, the fault swarm and its shards, fleets, replay, restarts, SDLS and the security
//! checks of every host mode. The CLI's tests are `tests/cli/`.
//!
//! One test binary, each file a module: the binary links once, and the tests that wait on the
//! wall clock run side by side in one test (`wall_clock`), after the ones that compute.

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
mod wall_clock;
