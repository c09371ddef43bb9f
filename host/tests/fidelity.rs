//! Board A against the paper on the whole robot, in lock-step (`mmic_host::sim::lockstep`):
//! each test is one defect of issue 13 and failed before its fix (spec/decisions.toml and
//! spec/modes.toml give the readings taken).

use mmic::bolter::Drive;
use mmic::command::{BolterCommand, Command, Reconfiguration, ServoTarget};
use mmic::faults::Fault;
use mmic::mode::Mode;
use mmic::motion::State;
use mmic::node::robot::board_a::Event;
use mmic::refusal::Refusal;
use mmic::units::Side;
use mmic_host::sim::lockstep::Robot;
use mmic_host::sim::PlantConfig;

fn operational(state: State) -> Robot {
    let mut r = Robot::new(state, PlantConfig::default());
    let hb = r
        .command(Command::Mode(Mode::Operational))
        .expect("answered");
    assert_eq!((hb.mode, hb.refusal), (Mode::Operational, None));
    assert!(r.run_until(10_000, |r| !r.a.in_motion()), "homed");
    r
}

fn reconfigure(from: State, to: State) -> Command {
    Command::Reconfigure(Reconfiguration::new(from, to).expect("matched states"))
}

fn accepted(r: &mut Robot, c: Command) {
    let hb = r.command(c).expect("answered");
    assert_eq!(hb.refusal, None, "{c:?} refused");
}

/// a -> b turns the hip through 90°: stopped once the hip has turned 10°.
fn stopped_mid_turn() -> (Robot, f64) {
    let mut r = operational(State::A);
    accepted(&mut r, reconfigure(State::A, State::B));
    assert!(
        r.run_until(40_000, |r| (r.hip() - 18_000.0).abs() > 1_000.0),
        "the hip turns"
    );
    accepted(&mut r, Command::Stop);
    assert!(r.events_since(r.now).any(|e| *e == Event::Paused));
    let at_stop = r.hip();
    (r, at_stop)
}

/// Defect 1: Table 1's Stop is an emergency stop of the current motion, so the hip holds too
/// (it used to finish the turn, up to 90° in 9 s). The servos hold where they are.
// req: T1/stop
#[test]
fn stop_holds_the_hip_mid_turn_and_every_servo() {
    let (mut r, at_stop) = stopped_mid_turn();
    r.run_for(1_000);
    let (hip_1s, servos_1s) = (r.hip(), [r.plant.servos(0), r.plant.servos(1)]);
    r.run_for(5_000);
    // The hip's lag and the position loop settle it within a degree or two of where it was.
    assert!(
        (r.hip() - at_stop).abs() < 200.0,
        "hip moved {:.2}° after the Stop",
        (r.hip() - at_stop) / 100.0
    );
    assert!((r.hip() - hip_1s).abs() < 30.0, "still turning after 1 s");
    assert_eq!([r.plant.servos(0), r.plant.servos(1)], servos_1s);
    assert_eq!(r.a.mode(), Mode::Operational);
}

/// Defect 3: Reset resumes the interrupted reconfiguration from the step where it stopped,
/// and it completes.
// req: T1/reset
#[test]
fn reset_resumes_the_reconfiguration_a_stop_interrupted() {
    let (mut r, _) = stopped_mid_turn();
    r.run_for(3_000);
    // While stopped, a new motion is refused: the operator resumes or changes mode.
    let hb = r
        .command(reconfigure(State::A, State::M))
        .expect("answered");
    assert_eq!(hb.refusal, Some(Refusal::Stopped));
    let t = r.now;
    accepted(&mut r, Command::Reset);
    assert!(r.events_since(t).any(|e| *e == Event::Resumed));
    assert!(
        r.run_until(60_000, |r| r
            .events_since(t)
            .any(|e| *e == Event::Reached(State::B))),
        "resumed to b"
    );
    assert!(r.run_until(5_000, |r| !r.a.in_motion()));
    let hb = r.command(Command::Heartbeat).expect("answered");
    assert!(hb.command_complete && hb.faults.is_empty(), "{hb:?}");
    assert_eq!(r.a.state(), Some(State::B));
}

/// Defect 3: Reset with nothing to resume, or after the mode changed, is refused by name.
// req: T1/reset, D:stop-and-reset
#[test]
fn reset_is_refused_with_nothing_to_resume() {
    let mut r = operational(State::A);
    let hb = r.command(Command::Reset).expect("answered");
    assert_eq!(hb.refusal, Some(Refusal::NothingToResume));
    // A Stop with nothing in motion holds and keeps nothing.
    accepted(&mut r, Command::Stop);
    let hb = r.command(Command::Reset).expect("answered");
    assert_eq!(hb.refusal, Some(Refusal::NothingToResume));
    let (mut r, _) = stopped_mid_turn();
    accepted(&mut r, Command::Mode(Mode::Safed));
    let hb = r.command(Command::Reset).expect("answered");
    assert_eq!(hb.refusal, Some(Refusal::NothingToResume));
    assert!(!r.a.paused());
}

/// Defect 1: entering Safed mid-turn holds the hip as well (Table 7: hold hip/arms position).
// req: P7.8
#[test]
fn safed_mid_turn_holds_the_hip() {
    let mut r = operational(State::A);
    accepted(&mut r, reconfigure(State::A, State::B));
    assert!(r.run_until(40_000, |r| (r.hip() - 18_000.0).abs() > 1_000.0));
    accepted(&mut r, Command::Mode(Mode::Safed));
    let at = r.hip();
    r.run_for(5_000);
    assert!(
        (r.hip() - at).abs() < 200.0,
        "hip moved {:.2}° in Safed",
        (r.hip() - at) / 100.0
    );
}

/// Defect 4: what Safed accepts runs on both sides: arm B extends in Safed (board A used to
/// keep B's stop flag set in Safed, so B held). A Stop in Safed with nothing moving does not
/// lock the arm commands out; one that interrupts an arm move is resumed by Reset in Safed.
// req: T7/commands, P7.8
#[test]
fn safed_arm_commands_run_on_side_b_and_stop_reset_work_there() {
    let mut r = operational(State::A);
    accepted(&mut r, Command::Mode(Mode::Safed));
    r.run_for(500);
    accepted(&mut r, Command::Stop);
    accepted(
        &mut r,
        Command::Arm {
            side: Side::B,
            target: ServoTarget::Extend,
        },
    );
    r.run_for(200);
    accepted(&mut r, Command::Stop);
    // The servo lags its pulse by a tick or two.
    r.run_for(100);
    let held = r.plant.servos(1).0;
    r.run_for(1_000);
    assert_eq!(r.plant.servos(1).0, held, "arm B holds after the Stop");
    assert!(held > 950.0 && held < 2_000.0, "stopped mid-travel: {held}");
    accepted(&mut r, Command::Reset);
    assert!(
        r.run_until(5_000, |r| r.plant.servos(1).0 >= 2_099.0),
        "arm B extends in Safed after Reset: at {}",
        r.plant.servos(1).0
    );
    assert_eq!(r.a.mode(), Mode::Safed);
}

/// Defect 2: "move bolters down" descends both bolters and stops there: nothing engages or
/// rotates (it used to run a whole bolt of pair 1).
// req: T1/bolter, D:bolters-down
#[test]
fn move_bolters_down_only_descends() {
    let mut r = operational(State::A);
    let t = r.now;
    accepted(&mut r, Command::Bolter(BolterCommand::Down));
    let mut drives = Vec::new();
    let ended = r.run_until(15_000, |r| {
        drives.push([r.plant.bolter_drive(0), r.plant.bolter_drive(1)]);
        r.events_since(t)
            .any(|e| matches!(e, Event::BoltersDown { .. }))
    });
    assert!(ended, "the job ends");
    assert!(r
        .events_since(t)
        .any(|e| *e == Event::BoltersDown { contact: true }));
    assert!(drives.contains(&[Drive::Down, Drive::Down]), "both descend");
    assert!(
        drives
            .iter()
            .flatten()
            .all(|d| matches!(d, Drive::Down | Drive::Idle)),
        "only descending: {drives:?}"
    );
    // And they stay down: nothing drives them afterwards.
    r.run_for(2_000);
    assert_eq!(r.plant.bolter_drive(0), Drive::Idle);
    assert!(!r
        .events_since(t)
        .any(|e| matches!(e, Event::Pair { .. } | Event::Bolting(_))));
    assert!(r.a.faults().is_empty());
}

/// Defect 8: an arm command board B never acknowledges (the A->B direction dead, B's
/// heartbeats still arriving) raises internal communication loss, as Table 8 says. Before,
/// the A->B number only changed with bolter orders, B echoed 0, and the rule never fired.
// req: P7.19
#[test]
fn an_unacknowledged_arm_command_raises_internal_comm_loss() {
    let mut r = operational(State::A);
    r.a_to_b = false;
    let t = r.now;
    accepted(
        &mut r,
        Command::Arm {
            side: Side::B,
            target: ServoTarget::Extend,
        },
    );
    assert!(
        r.run_until(2_000, |r| r.a.faults().contains(Fault::InternalCommLoss)),
        "no comm loss"
    );
    let took = r.now - t;
    // comm_max_unacked sends at the 50 ms resend period.
    assert!(took <= 600, "{took} ms");
    assert_eq!(r.a.mode(), Mode::Safed);
}

/// Defect 9: the idle overcurrent check runs at the start (and end) of a reconfiguration,
/// not continuously: a robot at rest with a bolter drawing more than its idle limit (but
/// under the absolute one) is no fault until a reconfiguration is asked for; then the check
/// fails, the motion does not start and the robot is Safed.
// req: P7.16
#[test]
fn the_idle_check_runs_when_a_reconfiguration_starts_not_while_idle() {
    let mut r = operational(State::A);
    r.plant.stuck_bolter_ma = 300.0;
    r.run_for(5_000);
    assert!(r.a.faults().is_empty(), "{:?}", r.a.faults());
    let servos = [r.plant.servos(0), r.plant.servos(1)];
    accepted(&mut r, reconfigure(State::A, State::M));
    assert!(r.run_until(2_000, |r| r
        .a
        .faults()
        .contains(Fault::BolterOvercurrentIdle)));
    assert_eq!(r.a.mode(), Mode::Safed);
    r.run_for(2_000);
    assert_eq!(
        [r.plant.servos(0), r.plant.servos(1)],
        servos,
        "nothing moved"
    );
}

/// Defect 9: command complete (heartbeat byte 54) comes after the idle check at the end.
// req: P7.16
#[test]
fn command_complete_follows_the_idle_check_at_the_end() {
    let mut r = operational(State::A);
    accepted(&mut r, reconfigure(State::A, State::M));
    assert!(r.run_until(60_000, |r| r.a.state() == Some(State::M)));
    let reached = r.now;
    let hb = r.command(Command::Heartbeat).expect("answered");
    assert!(!hb.command_complete, "complete before the end check");
    assert!(r.run_until(3_000, |r| !r.a.in_motion()));
    let hb = r.command(Command::Heartbeat).expect("answered");
    assert!(hb.command_complete);
    let settle = mmic::node::robot::board_a::Config::default().idle_settle_ms;
    assert!(r.now - reached >= settle, "{} ms", r.now - reached);
}

/// Found in the review (same kind as the defects above): Table 8's "after executing an arm
/// contraction command, the contraction is not sensed by hardware" holds for either arm, but
/// board A checked only arm A. Arm B's switch travels in Table 4 byte 44.
// req: P7.15
#[test]
fn an_arm_b_contraction_the_switch_does_not_sense_is_arm_not_contracted() {
    for side in [Side::A, Side::B] {
        let mut r = operational(State::A);
        let arm = |target| Command::Arm { side, target };
        accepted(&mut r, arm(ServoTarget::Extend));
        assert!(r.run_until(5_000, |r| !r.a.in_motion()));
        r.plant.dead_switch[side as usize] = true;
        accepted(&mut r, arm(ServoTarget::Contract));
        assert!(
            r.run_until(5_000, |r| r.a.faults().contains(Fault::ArmNotContracted)),
            "{side:?}: no fault"
        );
        assert_eq!(r.a.mode(), Mode::Safed, "{side:?}");
        // With a working switch the same contraction is no fault.
        let mut r = operational(State::A);
        accepted(&mut r, arm(ServoTarget::Extend));
        assert!(r.run_until(5_000, |r| !r.a.in_motion()));
        accepted(&mut r, arm(ServoTarget::Contract));
        r.run_for(5_000);
        assert!(r.a.faults().is_empty(), "{side:?}: {:?}", r.a.faults());
    }
}

/// Issue 14 (firmware): a sensor that stops answering is never read as a plausible value.
/// Side A's ADC silent mid-turn: the averages stand for one window (50 ticks, 500 ms), then
/// the project's sensor loss takes the robot to Safed and the hip holds. No low battery or
/// overcurrent is judged from the stale averages.
// req: D:sensor-loss
#[test]
fn a_silent_adc_a_is_sensor_loss_after_one_window_then_safed() {
    let mut r = operational(State::A);
    accepted(&mut r, reconfigure(State::A, State::B));
    assert!(r.run_until(40_000, |r| (r.hip() - 18_000.0).abs() > 1_000.0));
    let t = r.now;
    r.plant.config_mut().adc_silent_at = [Some(t + 10), None];
    r.run_for(480);
    assert_eq!(
        r.a.mode(),
        Mode::Operational,
        "not before the window is over"
    );
    r.run_for(40);
    assert_eq!(r.a.mode(), Mode::Safed);
    assert_eq!(
        r.a.faults(),
        mmic::faults::Faults::EMPTY.with(Fault::SensorLoss)
    );
    let at = r.hip();
    r.run_for(5_000);
    assert!((r.hip() - at).abs() < 200.0, "hip moved in Safed");
    assert_eq!(
        r.a.faults(),
        mmic::faults::Faults::EMPTY.with(Fault::SensorLoss)
    );
}

/// The hip encoder silent mid-turn: the hip gets the stop pulse from the first tick without a
/// reading (it is not steered from a guessed angle), then sensor loss, Safed.
// req: D:sensor-loss
#[test]
fn a_silent_hip_encoder_stops_the_hip_at_once_then_sensor_loss() {
    let mut r = operational(State::A);
    accepted(&mut r, reconfigure(State::A, State::B));
    assert!(r.run_until(40_000, |r| (r.hip() - 18_000.0).abs() > 1_000.0));
    r.plant.config_mut().encoder_silent_at = Some(r.now + 20);
    r.tick();
    assert_ne!(
        r.out_a.as_ref().and_then(|o| o.hip).map(|p| p.micros()),
        Some(1500)
    );
    r.tick();
    assert_eq!(
        r.out_a.as_ref().and_then(|o| o.hip).map(|p| p.micros()),
        Some(1500)
    );
    let at = r.hip();
    r.run_for(300);
    assert!((r.hip() - at).abs() < 100.0, "the hip kept turning blind");
    assert!(r.run_until(300, |r| r.a.mode() == Mode::Safed));
    assert!(r.a.faults().contains(Fault::SensorLoss));
}

/// Side B's ADC silent: Table 4 has no byte for it, so board B holds and falls silent, and
/// board A raises internal comm loss (Safed).
// req: P7.19, D:sensor-loss
#[test]
fn a_silent_adc_b_silences_board_b_and_is_internal_comm_loss() {
    let mut r = operational(State::A);
    r.plant.config_mut().adc_silent_at = [None, Some(r.now + 10)];
    r.run_for(600);
    assert_eq!(r.out_b.as_ref().and_then(|o| o.heartbeat), None);
    assert!(r.run_until(3_000, |r| r.a.mode() == Mode::Safed));
    assert_eq!(
        r.a.faults(),
        mmic::faults::Faults::EMPTY.with(Fault::InternalCommLoss)
    );
}

/// An ADC that never answers from power-up: sensor loss at once; its empty averages (0 V)
/// are not judged, so no low battery is raised however long it lasts.
// req: D:sensor-loss
#[test]
fn an_adc_silent_from_power_up_is_sensor_loss_never_low_battery() {
    let plant = PlantConfig {
        adc_silent_at: [Some(0), None],
        ..PlantConfig::default()
    };
    let mut r = Robot::new(State::A, plant);
    r.run_for(10_000);
    assert_eq!(
        r.a.faults(),
        mmic::faults::Faults::EMPTY.with(Fault::SensorLoss)
    );
    let hb = r
        .command(Command::Mode(Mode::Operational))
        .expect("answered");
    assert_eq!(hb.refusal, Some(Refusal::FaultConditionHolds));
}
