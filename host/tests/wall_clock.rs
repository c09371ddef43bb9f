//! The tests that wait on the wall clock (real threads, sockets, pseudo-terminals and child
//! processes on paced time), run side by side in one test, each on a thread of its own.
//!
//! They mostly sleep: one after the other on libtest's threads (two on a 2-core machine) they
//! held the binary for over a minute; side by side they take as long as the longest (the space
//! data link over lossy UDP, about 14 s; the serial opsUI on the whole demo plan took 27 s, so
//! it runs a short plan here and the whole demo in CI, after the README's command:
//! `opsui_serial.rs`) and less than one core between them. They need that core when their
//! time comes (the opsUI's simulator, another process, must answer within 140 ms: the
//! paper's 700 ms at `--scale 5`): started first, beside the computing tests (the swarm's take
//! both cores), they missed their windows on a loaded machine (measured: 4 runs in 5 failed).
//! libtest runs tests in the order of their names, and `wall_clock::` comes after every other
//! module here: this test starts last, when at most one computing test is left to run beside it.

//! `MMIC_WALL_CLOCK=<part of a name>` runs only the matching ones (libtest's filter cannot
//! reach inside this test).

use crate::{fleet, opsui_serial, realtime, sdls, security};

/// A check's name (its module and function, as libtest named the checks before they ran side
/// by side), and the check.
type Check = (&'static str, fn());

/// Run side by side, the longest first.
const CHECKS: [Check; 9] = [
    (
        "realtime::the_space_data_link_over_lossy_udp_completes_the_demo_and_counts_its_frames",
        realtime::the_space_data_link_over_lossy_udp_completes_the_demo_and_counts_its_frames,
    ),
    (
        "sdls::the_realtime_engine_secures_its_own_ground_with_keys_made_at_run_time",
        sdls::the_realtime_engine_secures_its_own_ground_with_keys_made_at_run_time,
    ),
    (
        "opsui_serial::a_short_plan_runs_over_a_serial_line_every_command_once",
        opsui_serial::a_short_plan_runs_over_a_serial_line_every_command_once,
    ),
    (
        "realtime::board_a_board_b_and_the_ground_restart_on_the_wall_clock",
        realtime::board_a_board_b_and_the_ground_restart_on_the_wall_clock,
    ),
    (
        "fleet::a_realtime_fleet_polls_every_robot_over_real_sockets",
        fleet::a_realtime_fleet_polls_every_robot_over_real_sockets,
    ),
    (
        "realtime::thirty_percent_wifi_loss_over_tcp_runs_nothing_twice",
        realtime::thirty_percent_wifi_loss_over_tcp_runs_nothing_twice,
    ),
    (
        "realtime::the_demo_completes_over_real_transports_as_in_virtual_time",
        realtime::the_demo_completes_over_real_transports_as_in_virtual_time,
    ),
    (
        "fleet::mmic_fleet_sweeps_and_plots",
        fleet::mmic_fleet_sweeps_and_plots,
    ),
    (
        "security::the_external_ground_simulator_keeps_its_counters_across_processes",
        security::the_external_ground_simulator_keeps_its_counters_across_processes,
    ),
];
/// Every check in `CHECKS` (or those `MMIC_WALL_CLOCK` names) side by side; fails naming every
/// check that failed, after all have ended.
// req: P3.1, P3.3
#[test]
fn the_wall_clock_tests_side_by_side() {
    let only = std::env::var("MMIC_WALL_CLOCK").unwrap_or_default();
    let named = |(name, _): &Check| name.contains(&only);
    let chosen: Vec<Check> = CHECKS.into_iter().filter(named).collect();
    assert!(
        !chosen.is_empty(),
        "MMIC_WALL_CLOCK={only} matches no check"
    );
    let failed = side_by_side(&chosen);
    assert!(failed.is_empty(), "failed: {failed:?}");
}

/// Every check started at once, each on a thread named after it (a failure's panic message
/// names it): the names of those that failed, once all have ended.
fn side_by_side(checks: &[Check]) -> Vec<&'static str> {
    std::thread::scope(|scope| {
        let running: Vec<_> = checks
            .iter()
            .map(|&(name, check)| {
                let thread = std::thread::Builder::new().name(name.into());
                let handle = thread.spawn_scoped(scope, check);
                (name, handle.expect("spawn a check's thread"))
            })
            .collect();
        running
            .into_iter()
            .filter_map(|(name, handle)| handle.join().is_err().then_some(name))
            .collect()
    })
}
