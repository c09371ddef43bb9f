//! Board B on its own: it follows A's targets for each servo separately, holds on A's stop
//! flag, and judges the A→B link silent exactly past its timeout.

use mmic::node::robot::board_b::{BoardB, Config, Inputs, Outputs};
use mmic::units::{Electrical, PulseWidth};
use mmic::wire::b_command::{BCommandRepr, BPower};

fn command(seq: u8, arm: PulseWidth, gripper: PulseWidth, stop: bool) -> [u8; 15] {
    BCommandRepr {
        seq,
        power: BPower {
            regulator: true,
            arm: true,
            gripper: true,
            bolter: true,
        },
        stop,
        arm_target: arm,
        gripper_target: gripper,
        bolter: None,
    }
    .to_bytes()
}

fn inputs(command: Option<[u8; 15]>) -> Inputs {
    Inputs {
        command,
        electrical: Electrical {
            v_bat: 12_000,
            v_reg: 7_400,
            ..Electrical::default()
        },
        arm_contracted: true,
        ..Inputs::default()
    }
}

/// Each servo goes to its own target: a command that moves only the gripper moves the
/// gripper (and not the arm), one that moves only the arm moves the arm.
// req: P4.2, P4.3
#[test]
fn each_servo_follows_its_own_target() {
    let cfg = Config::default();
    let pw = |us| PulseWidth::new(us).unwrap();
    let (arm0, grip0) = (cfg.arm.contracted, cfg.gripper.extended);
    for (arm, grip) in [(arm0, pw(1500)), (pw(1500), grip0), (pw(1400), pw(1600))] {
        let mut b = BoardB::new(cfg);
        let mut last = None;
        for t in 0..300u32 {
            // A re-sends its snapshot every 50 ms, with a new number each time.
            let c = (t % 5 == 0).then(|| command((t / 5) as u8, arm, grip, false));
            last = Some(b.tick(t * 10, &inputs(c)));
        }
        let out = last.unwrap();
        assert_eq!(out.arm, Some(arm), "arm to {arm:?}");
        assert_eq!(out.gripper, Some(grip), "gripper to {grip:?}");
    }
}

/// The link is silent strictly after `link_timeout_ms` without a command: B holds and says
/// so at the first tick past it, not at the timeout itself.
#[test]
fn the_link_is_lost_exactly_past_its_timeout() {
    let cfg = Config::default();
    for heard_at in [0u32, 1_000, u32::MAX - 200] {
        let mut b = BoardB::new(cfg);
        let c = command(1, cfg.arm.contracted, cfg.gripper.extended, false);
        assert!(!b.tick(heard_at, &inputs(Some(c))).link_lost);
        let at = heard_at.wrapping_add(cfg.link_timeout_ms);
        assert!(!b.tick(at, &inputs(None)).link_lost, "at the timeout");
        let out = b.tick(at.wrapping_add(1), &inputs(None));
        assert!(out.link_lost, "one ms past it");
        assert_eq!(out.bolter, mmic::bolter::Drive::Idle);
    }
}

/// B holds its servos where they are when the link falls silent, and when its ADC is lost
/// (then also saying nothing), each on its own, mid-move; a command afterwards moves it on.
// req: P4.3
#[test]
fn silence_or_a_lost_adc_alone_holds_the_servos_mid_move() {
    let cfg = Config::default();
    let target = PulseWidth::new(1500).unwrap();
    for cause in ["silence", "adc"] {
        let mut b = BoardB::new(cfg);
        let mut t = 0u32;
        let mut out = b.tick(
            t,
            &inputs(Some(command(1, target, cfg.gripper.extended, false))),
        );
        // Moving: heard every 50 ms for 300 ms.
        for k in 1..=30u32 {
            t += 10;
            let c = (k % 5 == 0).then(|| command(1 + k as u8, target, cfg.gripper.extended, false));
            out = b.tick(t, &inputs(c));
        }
        let moving = out.arm;
        assert_ne!(moving, Some(target), "still on its way");
        let mut held = None;
        for _ in 0..100 {
            t += 10;
            let mut inp = inputs(None);
            inp.lost.adc = cause == "adc";
            out = b.tick(t, &inp);
            if cause == "adc" {
                assert_eq!(out.heartbeat, None, "blind B says nothing");
            }
            if out.link_lost || cause == "adc" {
                let h = *held.get_or_insert(out.arm);
                assert_eq!(out.arm, h, "{cause}: the arm holds");
            }
        }
        assert!(held.is_some(), "{cause}: held");
        assert_ne!(
            held,
            Some(Some(target)),
            "{cause}: held short of the target"
        );
    }
}

/// B's heartbeat goes out every `heartbeat_period_ms`, on the first tick of each period and
/// on no other.
// req: P4.5
#[test]
fn heartbeats_every_period_and_no_more() {
    let cfg = Config::default();
    let mut b = BoardB::new(cfg);
    let mut sent = vec![];
    for t in (0..1_000u32).step_by(10) {
        if b.tick(t, &inputs(None)).heartbeat.is_some() {
            sent.push(t);
        }
    }
    let want: Vec<u32> = (0..1_000)
        .step_by(cfg.heartbeat_period_ms as usize)
        .collect();
    assert_eq!(sent, want);
}

/// B drives its bolter only with the regulator on and the bolter powered, and not while it
/// holds.
#[test]
fn the_bolter_is_driven_only_when_powered_and_not_held() {
    use mmic::bolter::{BolterDirection, BolterPair, BolterStep, Drive};
    use mmic::wire::b_command::BolterOrder;
    let cfg = Config::default();
    let order = BolterOrder {
        pair: BolterPair::P1,
        direction: BolterDirection::Bolt,
        step: BolterStep::Descend,
    };
    for (regulator, bolter, stop) in [
        (false, false, false),
        (true, true, false),
        (false, true, false),
        (true, false, false),
        (true, true, true),
    ] {
        let mut b = BoardB::new(cfg);
        let c = BCommandRepr {
            seq: 1,
            power: BPower {
                regulator,
                arm: true,
                gripper: true,
                bolter,
            },
            stop,
            arm_target: cfg.arm.contracted,
            gripper_target: cfg.gripper.extended,
            bolter: Some(order),
        }
        .to_bytes();
        let out = b.tick(0, &inputs(Some(c)));
        // The servos' pulses likewise need the regulator (and their own power bit, on here).
        assert_eq!(out.arm.is_some(), regulator);
        assert_eq!(out.gripper.is_some(), regulator);
        let want = if regulator && bolter && !stop {
            Drive::Down
        } else {
            Drive::Idle
        };
        assert_eq!(
            out.bolter, want,
            "regulator {regulator} bolter {bolter} stop {stop}"
        );
    }
}

/// A servo gets its pulse only with the regulator on and its own power bit set.
#[test]
fn each_servo_is_driven_only_with_the_regulator_and_its_power_bit() {
    let cfg = Config::default();
    for (regulator, arm, gripper) in [
        (true, true, false),
        (true, false, true),
        (false, true, true),
        (true, true, true),
    ] {
        let mut b = BoardB::new(cfg);
        let c = BCommandRepr {
            seq: 1,
            power: BPower {
                regulator,
                arm,
                gripper,
                bolter: false,
            },
            stop: false,
            arm_target: cfg.arm.contracted,
            gripper_target: cfg.gripper.extended,
            bolter: None,
        }
        .to_bytes();
        let out = b.tick(0, &inputs(Some(c)));
        assert_eq!(out.arm.is_some(), regulator && arm);
        assert_eq!(out.gripper.is_some(), regulator && gripper);
        assert_eq!(out.regulator, regulator);
    }
}

/// A command that fails its check is reported rejected and not taken: board B goes on as
/// if nothing had come (the same outputs, tick after tick, as a twin that heard nothing).
#[test]
fn a_corrupted_command_is_rejected_and_not_taken() {
    let cfg = Config::default();
    let pw = |us| PulseWidth::new(us).unwrap();
    let mut b = BoardB::new(cfg);
    let out = b.tick(0, &inputs(Some(command(1, pw(1400), pw(1600), false))));
    assert_eq!(out.rejected, None);
    let mut twin = b;
    let mut bad = command(2, pw(1700), pw(1300), true);
    bad[7] ^= 0x10;
    let err = BCommandRepr::parse(&bad).unwrap_err();
    let out = b.tick(10, &inputs(Some(bad)));
    assert_eq!(out.rejected, Some(err));
    let quiet = twin.tick(10, &inputs(None));
    assert_eq!(
        Outputs {
            rejected: None,
            ..out
        },
        quiet
    );
    for t in 2..100u32 {
        assert_eq!(
            b.tick(t * 10, &inputs(None)),
            twin.tick(t * 10, &inputs(None))
        );
    }
}
