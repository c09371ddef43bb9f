//! spec/boards.toml: the nodes' timing defaults equal the code's, and board B does at those
//! numbers what the file says: a heartbeat each period, and the hold (the project's addition)
//! once board A has been silent past the timeout.

use mmic::motion::estimate;
use mmic::node::exactly_once::uplink;
use mmic::node::robot::board_a;
use mmic::node::robot::board_b::{self, BoardB};
use mmic::node::server::relay;
use mmic::sensors::frontend;
use mmic::units::{Axis, PulseWidth, Sign};
use mmic::wire::b_command::{BCommandRepr, BPower};
use serde::Deserialize;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Boards {
    board_a: BoardA,
    board_b: BoardB2,
    ground: Ground,
    server: ServerSpec,
    /// Read by the host's opsUI (host/src/serial.rs, tested there).
    #[allow(dead_code)]
    ops_line: OpsLine,
    sensor_frontend: Frontend,
    estimate: Estimate,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct BoardA {
    b_period_ms: u32,
    idle_settle_ms: u32,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct BoardB2 {
    heartbeat_period_ms: u32,
    link_timeout_ms: u32,
    holds_on_silence: bool,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Ground {
    period_ms: u32,
    timeout_ms: u32,
    efficiency_window: u8,
    max_attempts: u8,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ServerSpec {
    answer_ms: u32,
    serial_reserve_ms: u32,
    visit_ms: u32,
}

/// The serial line's settings: read by the host's opsUI (`mmic opsui`), checked here for
/// the values only.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(dead_code)]
struct OpsLine {
    baud: u32,
    data_bits: u8,
    parity: String,
    stop_bits: u8,
    flow_control: String,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Frontend {
    loss_ticks: u16,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Estimate {
    up: String,
    hip_tolerance: u16,
}

fn spec() -> Boards {
    let p = concat!(env!("CARGO_MANIFEST_DIR"), "/../../spec/boards.toml");
    toml::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
}

// req: P8.3, P8.4, P8.5
#[test]
fn the_nodes_defaults_equal_spec_boards() {
    let s = spec();
    let a = board_a::Config::default();
    assert_eq!(
        (a.b_period_ms, a.idle_settle_ms),
        (s.board_a.b_period_ms, s.board_a.idle_settle_ms)
    );
    let b = board_b::Config::default();
    assert_eq!(
        (b.heartbeat_period_ms, b.link_timeout_ms),
        (s.board_b.heartbeat_period_ms, s.board_b.link_timeout_ms)
    );
    let g = uplink::Config::default();
    assert_eq!(
        (g.period_ms, g.timeout_ms, g.max_attempts),
        (
            s.ground.period_ms,
            s.ground.timeout_ms,
            s.ground.max_attempts
        )
    );
    assert_eq!(uplink::Efficiency::WINDOW, s.ground.efficiency_window);
    assert_eq!(
        (relay::ANSWER_MS, relay::SERIAL_RESERVE_MS, relay::VISIT_MS),
        (
            s.server.answer_ms,
            s.server.serial_reserve_ms,
            s.server.visit_ms
        )
    );
    // The relay's window is the opsUI's, less the serial line's share.
    assert_eq!(s.server.answer_ms, g.timeout_ms);
    assert_eq!(s.server.visit_ms + s.server.serial_reserve_ms, g.timeout_ms);
    assert_eq!(
        frontend::Config::default().loss_ticks,
        s.sensor_frontend.loss_ticks
    );
    let e = estimate::Config::default();
    let (axis, sign) = e.up;
    let sign = if sign == Sign::Positive { '+' } else { '-' };
    let axis = match axis {
        Axis::X => 'X',
        Axis::Y => 'Y',
        Axis::Z => 'Z',
    };
    assert_eq!(format!("{sign}{axis}"), s.estimate.up);
    assert_eq!(e.hip_tolerance, s.estimate.hip_tolerance);
}

/// Board B at its defaults, ticked every 10 ms after one A→B command: a heartbeat every
/// `heartbeat_period_ms` throughout, `link_lost` exactly once board A has been silent longer
/// than `link_timeout_ms`, from then on arm B held at its last pulse however far from its
/// target; the next command from A lifts the hold and the arm moves again.
// req: P4.5
#[test]
fn board_b_heartbeats_every_period_and_holds_once_board_a_falls_silent() {
    let s = spec().board_b;
    assert!(s.holds_on_silence);
    let mut b = BoardB::new(board_b::Config::default());
    let command = |seq, us| {
        BCommandRepr {
            seq,
            power: BPower {
                regulator: true,
                arm: true,
                gripper: true,
                bolter: false,
            },
            stop: false,
            arm_target: PulseWidth::new(us).unwrap(),
            gripper_target: PulseWidth::CENTER,
            bolter: None,
        }
        .to_bytes()
    };
    let mut beats = Vec::new();
    let mut held = None;
    let heard_at = 0;
    for now in (0..=1500).step_by(10) {
        let inputs = board_b::Inputs {
            command: (now == heard_at).then(|| command(1, 2500)),
            ..board_b::Inputs::default()
        };
        let out = b.tick(now, &inputs);
        if out.heartbeat.is_some() {
            beats.push(now);
        }
        let silent = now - heard_at > s.link_timeout_ms;
        assert_eq!(out.link_lost, silent, "at {now} ms");
        let arm = out.arm.expect("powered");
        match held {
            None if silent => held = Some(arm),
            Some(h) => assert_eq!(arm, h, "arm B moved at {now} ms while holding"),
            None => {}
        }
        assert_ne!(
            arm.micros(),
            2500,
            "the arm reached its target: nothing to hold"
        );
    }
    assert!(held.is_some());
    let gaps: Vec<u32> = beats.windows(2).map(|w| w[1] - w[0]).collect();
    assert_eq!(beats.len() as u32, 1500 / s.heartbeat_period_ms + 1);
    assert!(gaps.iter().all(|&g| g == s.heartbeat_period_ms), "{gaps:?}");
    // Board A speaks again: the hold is lifted and arm B goes on towards its new target.
    let held = held.unwrap();
    let out = b.tick(
        1510,
        &board_b::Inputs {
            command: Some(command(2, 2500)),
            ..board_b::Inputs::default()
        },
    );
    assert!(!out.link_lost);
    let out = b.tick(1610, &board_b::Inputs::default());
    assert!(out.arm.unwrap() > held);
}
