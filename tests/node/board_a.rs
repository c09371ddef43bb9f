//! Board A's own effect on the actuators of both sides when a Stop arrives or the robot enters
//! Safed mid-motion (Table 1's Stop, Table 7's Safed: every actuator holds where it is): side
//! A's arm, gripper and hip outputs, side A's bolter and the multiplexer, and what the A→B
//! commands tell board B (stop flag, arm and gripper targets, bolter order) — and, through
//! board B, B's own servo and bolter outputs. Boards A and B are linked tick by tick, at rest in
//! state a and Operational before each motion.

use mmic::bolter::{Drive, MuxLines};
use mmic::command::{BolterCommand, Command, ServoTarget};
use mmic::command::{BolterPair, Fasteners};
use mmic::faults::Fault;
use mmic::mode::Mode;
use mmic::motion::{map, Primitive, State};
use mmic::node::robot::board_a::{self, BoardA, Event, Inputs};
use mmic::node::robot::board_b::{self, BoardB};
use mmic::refusal::Refusal;
use mmic::units::{BoardNumber, Electrical, HipAngle, PulseWidth, Side};
use mmic::wire::b_command::BCommandRepr;
use mmic::wire::command::CommandRepr;
use mmic::wire::heartbeat::HeartbeatRepr;
use mmic::wire::internal_heartbeat::InternalHeartbeatRepr;

/// Boards A and B linked both ways every tick, and the plant they drive: each side's arm
/// contraction switch and bolter.
struct Rig {
    a: BoardA,
    b: BoardB,
    now: u32,
    seq: u16,
    to_b: Option<[u8; mmic::wire::b_command::B_COMMAND_LEN]>,
    to_a: Option<[u8; mmic::wire::internal_heartbeat::INTERNAL_HEARTBEAT_LEN]>,
    /// The last A→B command sent.
    last_b: Option<BCommandRepr>,
    /// Each side's arm pulse at the last tick (none: unpowered, where it was).
    arm_pulse: [Option<PulseWidth>; 2],
    /// A side whose arm switch never closes (an arm stuck short of contracted, or a dead
    /// switch).
    switch_stuck: [bool; 2],
    /// A side whose arm switch is closed whatever the arm does (a switch stuck closed).
    switch_stuck_closed: [bool; 2],
    /// Each side's bolter.
    bolters: [Bolter; 2],
    /// Each side's bolter drive at the last tick.
    drives: [Drive; 2],
    /// Each side's filtered voltages and currents (I_bo aside: the bolter's).
    electrical: [Electrical; 2],
    /// The last internal heartbeat board A received, and whether it came at the last tick.
    heard_b: Option<(InternalHeartbeatRepr, bool)>,
    /// Board B's heartbeats are lost on the serial line until this time, ms.
    b_lost_until: u32,
    /// Board B reports arm B at this pulse whatever its servo does (a stalled arm, as a servo
    /// that reports its position would say it).
    b_arm_stuck: Option<PulseWidth>,
    /// Board A's hip encoder gives no reading (`Inputs::hip` is `None`).
    no_hip: bool,
}

/// A bolter over a fastener, as its current sensor and home switch see it: driven down, it
/// travels `contact_ms` (default `CONTACT_MS`) before it touches and pushes (I_bo past the push threshold) — unless
/// no fastener is `there`, when it never touches; rotated while touching, it locks the
/// fastener after `LOCK_MS` and stalls (I_bo past the lock threshold) — unless the fastener is
/// seized, when the head turns on it without locking (for the first `seized` rotations);
/// driven up, it is back on its home switch after as long as it went down.
#[derive(Debug, Clone, Copy)]
struct Bolter {
    travel_ms: u32,
    rotated_ms: u32,
    rotating: bool,
    i_bo: u16,
    there: bool,
    seized: u8,
    contact_ms: u32,
}

impl Default for Bolter {
    fn default() -> Bolter {
        Bolter {
            travel_ms: 0,
            rotated_ms: 0,
            rotating: false,
            i_bo: 0,
            there: true,
            seized: 0,
            contact_ms: CONTACT_MS,
        }
    }
}

const CONTACT_MS: u32 = 500;
const LOCK_MS: u32 = 300;

impl Bolter {
    fn step(&mut self, d: Drive, ms: u32) {
        let touching = self.there && self.travel_ms >= self.contact_ms;
        if self.rotating && d != Drive::Rotate && self.seized > 0 {
            self.seized -= 1;
        }
        self.rotating = d == Drive::Rotate;
        match d {
            Drive::Down => self.travel_ms = (self.travel_ms + ms).min(self.contact_ms + 1_000),
            Drive::Rotate if touching && self.seized == 0 => self.rotated_ms += ms,
            Drive::Up | Drive::CounterRotateUp => {
                self.travel_ms = self.travel_ms.saturating_sub(ms);
                self.rotated_ms = 0;
            }
            _ => {}
        }
        if self.there {
            self.travel_ms = self.travel_ms.min(self.contact_ms);
        }
        let touching = self.there && self.travel_ms >= self.contact_ms;
        self.i_bo = match d {
            Drive::Idle => 0,
            Drive::Down if touching => 1_100,
            Drive::Rotate if self.rotated_ms >= LOCK_MS => 1_300,
            Drive::Rotate => 500,
            _ => 300,
        };
    }

    fn at_home(&self) -> bool {
        self.travel_ms == 0
    }
}

/// What both boards drove in one tick.
#[derive(Debug, Clone)]
struct Tick {
    a: board_a::Outputs,
    b: board_b::Outputs,
    hb: Option<HeartbeatRepr>,
}

impl Rig {
    /// Linked, Operational, at rest in state a.
    fn operational() -> Rig {
        Rig::operational_with(board_a::Config::default())
    }

    /// The same with board A configured by `cfg`.
    fn operational_with(cfg: board_a::Config) -> Rig {
        Rig::operational_board(BoardA::in_state(cfg, State::A))
    }

    /// The same with board A as `a` is (for one that tracks no state: `BoardA::new`).
    fn operational_board(a: BoardA) -> Rig {
        let mut r = Rig {
            a,
            b: BoardB::with_pose(
                board_b::Config::default(),
                board_a::Config::default().arm.contracted,
                board_a::Config::default().gripper.extended,
            ),
            now: 0,
            seq: 0,
            to_b: None,
            to_a: None,
            last_b: None,
            arm_pulse: [None; 2],
            switch_stuck: [false; 2],
            switch_stuck_closed: [false; 2],
            bolters: [Bolter::default(); 2],
            drives: [Drive::Idle; 2],
            electrical: [Inputs::at_home().electrical; 2],
            heard_b: None,
            b_lost_until: 0,
            b_arm_stuck: None,
            no_hip: false,
        };
        r.send(Command::Mode(Mode::Operational));
        r.run(150);
        assert_eq!(r.a.mode(), Mode::Operational);
        assert!(!r.a.in_motion() && r.a.faults().is_empty());
        r
    }

    /// Side `i`'s arm switch: closed within 15 µs of the contracted pulse.
    fn switch(&self, i: usize) -> bool {
        let contracted = board_a::Config::default().arm.contracted.micros();
        self.switch_stuck_closed[i]
            || (!self.switch_stuck[i]
                && self.arm_pulse[i].is_none_or(|p| p.micros() <= contracted + 15))
    }

    fn tick(&mut self, command: Option<Command>) -> Tick {
        self.now += 10;
        for (b, d) in self.bolters.iter_mut().zip(self.drives) {
            b.step(d, 10);
        }
        let packet = command.map(|command| {
            self.seq += 1;
            CommandRepr {
                board: BoardNumber::ONE,
                command,
                seq: self.seq,
            }
            .to_bytes()
        });
        let a = self.a.tick(
            self.now,
            &Inputs {
                command: packet,
                from_b: self.to_a,
                electrical: Electrical {
                    i_bo: self.bolters[0].i_bo,
                    ..self.electrical[0]
                },
                arm_contracted: self.switch(0),
                bolter_at_home: self.bolters[0].at_home(),
                hip: Inputs::at_home().hip.filter(|_| !self.no_hip),
                ..Inputs::at_home()
            },
        );
        self.heard_b = match self.to_a {
            Some(bytes) => Some((InternalHeartbeatRepr::parse(&bytes).unwrap(), true)),
            None => self.heard_b.map(|(h, _)| (h, false)),
        };
        let b = self.b.tick(
            self.now,
            &board_b::Inputs {
                command: self.to_b,
                electrical: Electrical {
                    i_bo: self.bolters[1].i_bo,
                    ..self.electrical[1]
                },
                arm_contracted: self.switch(1),
                bolter_at_home: self.bolters[1].at_home(),
                ..board_b::Inputs::default()
            },
        );
        self.to_b = a.to_b;
        self.to_a = b.heartbeat.filter(|_| self.now >= self.b_lost_until);
        if let (Some(stuck), Some(bytes)) = (self.b_arm_stuck, self.to_a) {
            let mut hb = InternalHeartbeatRepr::parse(&bytes).unwrap();
            hb.arm_b_now = stuck;
            self.to_a = Some(hb.to_bytes());
        }
        if let Some(bytes) = a.to_b {
            self.last_b = Some(BCommandRepr::parse(&bytes).unwrap());
        }
        for (i, pulse) in [a.arm, b.arm].into_iter().enumerate() {
            if pulse.is_some() {
                self.arm_pulse[i] = pulse;
            }
        }
        self.drives = [a.bolter, b.bolter];
        Tick {
            a: a.clone(),
            b,
            hb: a.heartbeat.map(|h| HeartbeatRepr::parse(&h).unwrap()),
        }
    }

    fn send(&mut self, c: Command) -> Tick {
        let t = self.tick(Some(c));
        assert_eq!(t.hb.and_then(|h| h.refusal), None, "{c:?} refused");
        t
    }

    fn run(&mut self, ticks: u32) -> Tick {
        let mut last = self.tick(None);
        for _ in 1..ticks {
            last = self.tick(None);
        }
        last
    }
}

/// After `stopper` mid-motion, for 2 s: every output of both sides stays where it was when
/// the stop arrived, and the A→B command says hold, with B's targets where B is.
fn assert_frozen(r: &mut Rig, at_stop: &Tick, what: &str) {
    let b_cmd = r.last_b.expect("A commands B");
    assert!(b_cmd.stop, "{what}: B told to hold");
    assert_eq!(b_cmd.bolter, None, "{what}: no bolter order to B");
    let held = b_cmd;
    for _ in 0..200 {
        let t = r.tick(None);
        assert_eq!(t.a.arm, at_stop.a.arm, "{what}: arm A moved");
        assert_eq!(t.a.gripper, at_stop.a.gripper, "{what}: gripper A moved");
        assert_eq!(t.a.bolter, Drive::Idle, "{what}: bolter A driven");
        assert_eq!(t.b.bolter, Drive::Idle, "{what}: bolter B driven");
        assert_eq!(t.b.arm, at_stop.b.arm, "{what}: arm B moved");
        assert_eq!(t.b.gripper, at_stop.b.gripper, "{what}: gripper B moved");
        let b_cmd = r.last_b.expect("A commands B");
        assert!(b_cmd.stop, "{what}: B released");
        // The targets A sends B stay put (where B last reported itself when the hold began),
        // and B obeys the hold flag over them.
        assert_eq!(
            (b_cmd.arm_target, b_cmd.gripper_target),
            (held.arm_target, held.gripper_target),
            "{what}: B's targets changed during the hold"
        );
        assert_eq!(b_cmd.bolter, None);
    }
}

fn arm(side: Side, target: ServoTarget) -> Command {
    Command::Arm { side, target }
}

// req: T1/stop, D:stop-and-reset
#[test]
fn stop_mid_motion_freezes_both_arms_and_keeps_the_motion_for_reset() {
    for side in [Side::A, Side::B] {
        let mut r = Rig::operational();
        let rest = r.tick(None);
        r.send(arm(side, ServoTarget::Extend));
        r.run(30);
        let moving = r.tick(None);
        let (before, now) = match side {
            Side::A => (rest.a.arm, moving.a.arm),
            Side::B => (rest.b.arm, moving.b.arm),
        };
        assert_ne!(before, now, "arm {side:?} is on its way");
        assert!(r.a.in_motion());
        let at_stop = r.send(Command::Stop);
        // B applies the hold one link period later: take its outputs once it has.
        let at_stop = Tick {
            b: r.run(10).b,
            ..at_stop
        };
        assert!(r.a.paused(), "the stopped motion is kept for Reset");
        assert_frozen(&mut r, &at_stop, &format!("Stop, arm {side:?}"));
        assert_eq!(r.a.mode(), Mode::Operational);
        // Paused, nothing moves: no longer in motion (side B held where the hold reached it,
        // not where its last report before the Stop put it), and no motion timeout.
        assert!(!r.a.in_motion(), "arm {side:?}: in motion while paused");
        assert!(r.a.faults().is_empty(), "{:?}", r.a.faults());
        // Reset resumes it: the arm moves on to its target.
        r.send(Command::Reset);
        let after = r.run(300);
        let (stopped, now) = match side {
            Side::A => (at_stop.a.arm, after.a.arm),
            Side::B => (at_stop.b.arm, after.b.arm),
        };
        assert_ne!(stopped, now, "Reset resumed arm {side:?}");
    }
}

// req: P7.8
#[test]
fn entering_safed_mid_motion_freezes_both_sides_and_drops_the_motion() {
    for side in [Side::A, Side::B] {
        let mut r = Rig::operational();
        r.send(arm(side, ServoTarget::Extend));
        r.run(30);
        assert!(r.a.in_motion());
        let at_stop = r.send(Command::Mode(Mode::Safed));
        let at_stop = Tick {
            b: r.run(10).b,
            ..at_stop
        };
        assert_eq!(r.a.mode(), Mode::Safed);
        assert!(!r.a.paused(), "a mode change keeps nothing for Reset");
        assert!(at_stop.a.regulator, "Safed keeps the regulator on");
        assert_frozen(&mut r, &at_stop, &format!("Safed, arm {side:?}"));
    }
}

// req: T1/stop
#[test]
fn stop_and_safed_end_a_bolting_job_on_both_sides() {
    for stopper in [Command::Stop, Command::Mode(Mode::Safed)] {
        let mut r = Rig::operational();
        r.send(Command::Bolter(BolterCommand::Bolt(Fasteners::Pair(
            BolterPair::P2,
        ))));
        let running = r.run(20);
        assert_eq!(running.a.bolter, Drive::Down, "bolter A descends");
        assert_eq!(running.b.bolter, Drive::Down, "bolter B descends");
        assert!(r.last_b.unwrap().bolter.is_some());
        let at_stop = r.send(stopper);
        assert_eq!(
            at_stop.a.bolter,
            Drive::Idle,
            "{stopper:?}: bolter A idle at once"
        );
        let at_stop = Tick {
            b: r.run(10).b,
            ..at_stop
        };
        assert_frozen(&mut r, &at_stop, &format!("{stopper:?} during bolting"));
    }
}

// req: T1/stop
#[test]
fn stop_mid_turn_holds_the_hip_where_it_is_read() {
    let mut r = Rig::operational();
    let rest = r.tick(None);
    // The hip reads 180° throughout (the rig's encoder): ordered to 90°, it is driven.
    r.send(Command::Hip(mmic::command::HipTarget::RightAngleCw));
    let turning = r.run(5);
    assert_ne!(turning.a.hip, rest.a.hip, "the hip is driven towards 90°");
    r.send(Command::Stop);
    // Held at its reading: driven as at rest there.
    for _ in 0..50 {
        let t = r.tick(None);
        assert_eq!(t.a.hip, rest.a.hip, "the hip holds at its reading");
    }
}

/// The first move of the map from state a that turns nothing: an arm extends, the hip stays
/// straight (the rig's encoder reads 180° throughout).
fn extend_from_a() -> Command {
    let (_, to, p) = map::moves()
        .find(|(from, _, p)| {
            *from == State::A && matches!(p, Primitive::FwdExtend | Primitive::BackExtend)
        })
        .expect("a primitive extends an arm from a");
    Command::primitive(p, to).unwrap()
}

/// One motion at a time: from the tick after a primitive is accepted until the idle check at
/// its end, the robot counts as in motion at every tick (`BoardA::in_motion`) and a command
/// that moves is refused as busy — also at the ticks where every module has reached one
/// step's targets and the next step has not yet set its own, when no servo is on its way.
// req: T1/primitive
#[test]
fn a_primitive_is_in_motion_and_refuses_other_moves_at_every_tick_until_it_ends() {
    let mut r = Rig::operational();
    r.send(extend_from_a());
    let mut ms = 0;
    loop {
        // Each tick, another move is asked for: refused, and the primitive goes on.
        let t = r.tick(Some(arm(Side::B, ServoTarget::Extend)));
        ms += 10;
        assert_eq!(
            t.hb.and_then(|h| h.refusal),
            Some(Refusal::Busy),
            "a second motion accepted {ms} ms into the primitive"
        );
        assert!(r.a.in_motion(), "not in motion {ms} ms into the primitive");
        assert!(
            !t.hb.unwrap().command_complete,
            "command complete {ms} ms into the primitive"
        );
        if t.a.events.iter().any(|e| matches!(e, Event::Reached(_))) {
            break;
        }
        assert!(ms < 30_000, "the primitive did not end in 30 s");
    }
    assert!(r.a.faults().is_empty(), "{:?}", r.a.faults());
    assert_ne!(r.a.state(), Some(State::A), "the primitive moved the robot");
}

/// Section 7's idle check at the end of a reconfiguration reads the currents at rest: after
/// the primitive reaches its state the robot stays busy, and command complete (heartbeat byte
/// 54) stays unset, until it has been still for `idle_settle_ms` (the sensor averages no
/// longer hold the motion's currents); then the check passes and command complete is set.
// req: T3/command_complete, D:command-complete, D:idle-check-settling
#[test]
fn command_complete_waits_until_the_robot_has_rested_idle_settle_ms_after_the_primitive() {
    let settle = board_a::Config::default().idle_settle_ms;
    let mut r = Rig::operational();
    r.send(extend_from_a());
    let mut reached_at = None;
    for _ in 0..3_000 {
        let t = r.tick(None);
        if t.a.events.iter().any(|e| matches!(e, Event::Reached(_))) {
            reached_at = Some(r.now);
            break;
        }
    }
    let reached_at = reached_at.expect("the primitive reaches its state");
    // Still busy, and not complete, while the robot settles.
    while r.now + 10 < reached_at + settle {
        let t = r.tick(Some(Command::ClearFaults));
        assert!(
            r.a.in_motion(),
            "idle {} ms after the state was reached",
            r.now - reached_at
        );
        assert!(
            !t.hb.unwrap().command_complete,
            "complete before the idle check"
        );
    }
    // Then, within two link periods of the settle time, complete.
    let mut complete = false;
    for _ in 0..10 {
        let t = r.tick(Some(Command::ClearFaults));
        if !r.a.in_motion() && t.hb.unwrap().command_complete {
            complete = true;
            break;
        }
    }
    assert!(
        complete,
        "not complete {} ms after the state was reached",
        r.now - reached_at
    );
    assert!(r.a.faults().is_empty(), "{:?}", r.a.faults());
}

/// A reconfiguration accepted while the averaged currents still hold the last motion waits for
/// the idle check at its start (Section 7; `Config::idle_settle_ms`): its first primitive
/// starts — the moving side's gripper releases — only once the robot has been still for
/// `idle_settle_ms`, not as soon as it is accepted.
#[test]
fn a_primitive_accepted_right_after_a_motion_starts_once_the_robot_has_rested() {
    let settle = board_a::Config::default().idle_settle_ms;
    let mut r = Rig::operational();
    // A single-module move there and back; the primitive comes at the first idle tick.
    for target in [ServoTarget::Extend, ServoTarget::Contract] {
        r.send(arm(Side::A, target));
        while {
            r.tick(None);
            r.a.in_motion()
        } {}
    }
    let still_at = r.now;
    let hb = r.send(extend_from_a()).hb.unwrap();
    // The grippers' targets: side A's as A drives it, side B's as A commands B.
    let before = (hb.gripper_a_target, r.last_b.unwrap().gripper_target);
    // Nothing moves while the robot settles; then the moving side's gripper releases.
    let mut started = None;
    for _ in 0..(settle / 10 + 20) {
        let hb = r.tick(Some(Command::ClearFaults)).hb.unwrap();
        if (hb.gripper_a_target, r.last_b.unwrap().gripper_target) != before {
            started = Some(r.now);
            break;
        }
    }
    let started = started.expect("the primitive starts");
    assert!(
        started >= still_at + settle,
        "started {} ms after the robot came to rest",
        started - still_at
    );
    assert!(started <= still_at + settle + 100);
}

/// Entering Operational sends the hip to the configured home angle (`safety.hip_home`: the
/// contracted-gripped configuration the hip mismatch check reads against), not to a fixed
/// 180°: a robot whose home is at 90°, reading 90°, is held there.
// req: P7.6
#[test]
fn entering_operational_sends_the_hip_to_its_configured_home() {
    let home = HipAngle::new(9_000).unwrap();
    let mut cfg = board_a::Config::default();
    cfg.safety.hip_home = home;
    // The pulse that holds a hip at its target (a default board at rest at 180°).
    let mut reference = Rig::operational();
    let hold = reference.tick(None).a.hip;
    let mut a = BoardA::new(cfg);
    // The settings a shell restarting the board reads back: the ones it was started with.
    assert_eq!(a.config(), cfg);
    let inputs = |command| Inputs {
        command,
        hip: Some(home),
        ..Inputs::at_home()
    };
    let packet = CommandRepr {
        board: BoardNumber::ONE,
        command: Command::Mode(Mode::Operational),
        seq: 1,
    }
    .to_bytes();
    let out = a.tick(10, &inputs(Some(packet)));
    let hb = HeartbeatRepr::parse(&out.heartbeat.unwrap()).unwrap();
    assert_eq!((hb.mode, hb.refusal), (Mode::Operational, None));
    assert!(hb.faults.is_empty(), "{:?}", hb.faults);
    assert_eq!(hb.hip_target, home, "the hip is sent home");
    for t in 2..100 {
        let out = a.tick(t * 10, &inputs(None));
        assert_eq!(out.hip, hold, "the hip is driven away from its home");
    }
}

fn gripper(side: Side, target: ServoTarget) -> Command {
    Command::Gripper { side, target }
}

/// Waits (at most 10 s) until board A no longer counts a motion.
fn until_idle(r: &mut Rig) {
    for _ in 0..1_000 {
        r.tick(None);
        if !r.a.in_motion() {
            return;
        }
    }
    panic!("still in motion after 10 s");
}

/// A single-module move (Table 1's arm and gripper commands, on either side) is a motion
/// until its servo is at the target, as the heartbeat reports it: meanwhile the robot is in
/// motion, another move is refused as busy, and command complete (byte 54) is unset; then
/// the motion ends with command complete set (spec/decisions.toml, `command-complete`).
// req: T1/arm, T1/gripper, P5.1
#[test]
fn a_single_module_move_is_a_motion_until_its_servo_is_at_its_target() {
    let cfg = board_a::Config::default();
    for c in [
        arm(Side::A, ServoTarget::Extend),
        arm(Side::B, ServoTarget::Extend),
        gripper(Side::A, ServoTarget::Contract),
        gripper(Side::B, ServoTarget::Contract),
    ] {
        let mut r = Rig::operational();
        r.send(c);
        let t = r.tick(Some(Command::Hip(mmic::command::HipTarget::Straight)));
        assert_eq!(
            t.hb.unwrap().refusal,
            Some(Refusal::Busy),
            "{c:?}: a second move accepted"
        );
        // The servo as the heartbeat reports it (side B's as board B reported it).
        let there = |hb: &HeartbeatRepr| match c {
            Command::Arm { side: Side::A, .. } => {
                hb.arm_a_now == hb.arm_a_target && hb.arm_a_target == cfg.arm.extended
            }
            Command::Arm { side: Side::B, .. } => {
                hb.arm_b_now == hb.arm_b_target && hb.arm_b_target == cfg.arm.extended
            }
            Command::Gripper { side: Side::A, .. } => {
                hb.gripper_a_now == hb.gripper_a_target
                    && hb.gripper_a_target == cfg.gripper.contracted
            }
            _ => {
                hb.gripper_b_now == hb.gripper_b_target
                    && hb.gripper_b_target == cfg.gripper.contracted
            }
        };
        let mut ms = 10;
        loop {
            let hb = r.tick(Some(Command::ClearFaults)).hb.unwrap();
            ms += 10;
            if !there(&hb) {
                assert!(r.a.in_motion(), "{c:?}: not in motion at {ms} ms");
                assert!(!hb.command_complete, "{c:?}: complete at {ms} ms");
            }
            if !r.a.in_motion() {
                assert!(there(&hb), "{c:?}");
                assert!(hb.command_complete, "{c:?}: ended, not complete");
                break;
            }
            assert!(ms < 10_000, "{c:?}: still moving after 10 s");
        }
        assert!(ms > 500, "{c:?}: a full travel takes time");
    }
}

/// Section 5: the heartbeat's present arm value is the last interpolated pulse board A sent to
/// the servo, not a measurement: mid-move it trails the target, pulse by pulse.
// req: P5.4
#[test]
fn the_heartbeats_present_arm_value_is_the_last_pulse_sent() {
    let mut r = Rig::operational();
    r.send(arm(Side::A, ServoTarget::Extend));
    let mut trailing = 0;
    for _ in 0..300 {
        let hb = r.tick(Some(Command::Heartbeat)).hb.expect("a heartbeat");
        assert_eq!(Some(hb.arm_a_now), r.arm_pulse[0]);
        trailing += u32::from(hb.arm_a_now != hb.arm_a_target);
    }
    assert!(trailing > 10, "{trailing} heartbeats mid-move");
}

/// Table 8's "arm not fully contracted": after a contract arm command, once the arm has
/// finished its travel, its contraction switch must close within the confirm time
/// (`motion.confirm_ms`). A switch that stays open raises the fault (and the robot is
/// safed) — not while the arm is still on its way, and not when the switch closes.
// req: P5.3, P7.15, T8/arm_not_contracted
#[test]
fn an_arm_contraction_is_a_fault_when_the_switch_stays_open_past_the_confirm_time() {
    let cfg = board_a::Config::default();
    let confirm = cfg.motion.confirm_ms;
    for side in [Side::A, Side::B] {
        for stuck in [false, true] {
            let mut r = Rig::operational();
            r.send(arm(side, ServoTarget::Extend));
            until_idle(&mut r);
            r.switch_stuck[side as usize] = stuck;
            r.send(arm(side, ServoTarget::Contract));
            let mut arrived = None;
            let mut faulted = None;
            for _ in 0..800 {
                let t = r.tick(None);
                let pulse = match side {
                    Side::A => t.a.arm,
                    Side::B => t.b.arm,
                };
                if arrived.is_none() && pulse == Some(cfg.arm.contracted) {
                    arrived = Some(r.now);
                }
                if r.a.faults().contains(Fault::ArmNotContracted) {
                    faulted = Some(r.now);
                    break;
                }
            }
            let arrived = arrived.unwrap_or_else(|| panic!("{side:?}: arm never contracted"));
            if stuck {
                let at = faulted.unwrap_or_else(|| panic!("{side:?}: stuck switch, no fault"));
                if side == Side::A {
                    // Board A sees its arm at the end of its travel the tick after it drove
                    // the last pulse; the fault comes at the first tick more than
                    // `confirm_ms` after that, the timeout convention of the sequencer's
                    // Confirm step.
                    assert_eq!(at, arrived + 10 + confirm + 10, "{side:?}: fault tick");
                } else {
                    // Board B's report of its arm reaches A a link period or so later.
                    assert!(
                        at > arrived + confirm,
                        "{side:?}: fault {} ms after the arm arrived",
                        at as i64 - arrived as i64
                    );
                    assert!(at <= arrived + confirm + 200, "{side:?}: fault late");
                }
                assert_eq!(r.a.mode(), Mode::Safed);
            } else {
                assert_eq!(faulted, None, "{side:?}: the switch closed");
                assert_eq!(r.a.mode(), Mode::Operational);
            }
        }
    }
}

/// Runs until board A reports the end of a bolting job or of a "move bolters down" (at most
/// `max_ms`), checking at every tick before it that the job counts as a motion (another move
/// is refused as busy), that the heartbeat names the pair being worked on (byte 55) and an
/// attempt 1..=3 (byte 56), and that both sides' multiplexers select that pair. Returns every
/// event of board A meanwhile, the last tick's included, and the attempts the heartbeats
/// reported, in order, without repeats.
fn bolt_until_end(r: &mut Rig, max_ms: u32) -> (Vec<Event>, Vec<u8>) {
    let mut events = Vec::new();
    let mut attempts: Vec<u8> = Vec::new();
    let mut pair = None;
    for i in 0..max_ms / 10 {
        // Every 7th tick, another move is asked for.
        let probe = i % 7 == 3;
        let moving = r.a.in_motion();
        let t = r.tick(probe.then_some(arm(Side::A, ServoTarget::Extend)));
        events.extend(t.a.events.iter().copied());
        let end =
            t.a.events
                .iter()
                .any(|e| matches!(e, Event::Bolting(_) | Event::BoltersDown { .. }));
        if end {
            return (events, attempts);
        }
        assert!(i == 0 || moving, "not in motion {} ms into the job", i * 10);
        // The pair in force, as board A orders it.
        if let Some(p) = r.last_b.and_then(|b| b.bolter).map(|o| o.pair) {
            pair = Some(p);
        }
        if probe {
            let hb = t.hb.unwrap();
            assert_eq!(
                hb.refusal,
                Some(Refusal::Busy),
                "a move accepted {} ms into the job",
                i * 10
            );
            assert_eq!(hb.active_bolter, pair, "byte 55");
            let n = hb.bolter_attempt.get();
            assert!((1..=3).contains(&n), "byte 56: attempt {n}");
            if attempts.last() != Some(&n) {
                attempts.push(n);
            }
        }
        if t.a.bolter != Drive::Idle {
            assert_eq!(t.a.mux, MuxLines::for_pair(pair.unwrap()), "side A's mux");
        }
        if t.b.bolter != Drive::Idle {
            assert_eq!(t.b.mux, MuxLines::for_pair(pair.unwrap()), "side B's mux");
        }
    }
    panic!("the job did not end in {max_ms} ms: {events:?}");
}

fn pairs(events: &[Event]) -> Vec<(BolterPair, u8, bool)> {
    events
        .iter()
        .filter_map(|e| match e {
            Event::Pair { pair, attempts, ok } => Some((*pair, *attempts, *ok)),
            _ => None,
        })
        .collect()
}

/// Bolting all four pairs, boards A and B linked, the plant's fasteners answering as they
/// should: both sides run Figure 8's steps pair after pair, each pair is fastened at the first
/// attempt (events name them in order), the job ends done with no fault, the robot is in
/// motion (and refuses other moves) until then and reports command complete after.
// req: P4.1, P5.9
#[test]
fn bolting_all_four_pairs_runs_both_sides_pair_after_pair_to_done() {
    let mut r = Rig::operational();
    r.send(Command::Bolter(BolterCommand::Bolt(Fasteners::All)));
    let (events, attempts) = bolt_until_end(&mut r, 60_000);
    assert_eq!(attempts, [1], "every pair at its first attempt");
    assert_eq!(
        pairs(&events),
        [
            (BolterPair::P1, 1, true),
            (BolterPair::P2, 1, true),
            (BolterPair::P3, 1, true),
            (BolterPair::P4, 1, true)
        ]
    );
    assert_eq!(events.last(), Some(&Event::Bolting(None)));
    assert!(r.a.faults().is_empty(), "{:?}", r.a.faults());
    let hb = r.tick(Some(Command::ClearFaults)).hb.unwrap();
    assert!(!r.a.in_motion());
    assert!(hb.command_complete, "bolting done: command complete");
    assert_eq!(r.a.mode(), Mode::Operational);
}

/// A fastener that side B's head cannot lock at first (it turns on it; Rotate times out):
/// the attempt is abandoned — both bolters go home — and the pair is tried again, fastened at
/// the second attempt (Figure 10's "twice"); the other pairs are unaffected.
// req: T3/bolter_attempt, P5.9
#[test]
fn a_pair_that_does_not_lock_at_first_is_fastened_at_its_second_attempt() {
    let mut r = Rig::operational();
    r.send(Command::Bolter(BolterCommand::Bolt(Fasteners::Pair(
        BolterPair::P3,
    ))));
    r.bolters[1].seized = 1;
    let (events, attempts) = bolt_until_end(&mut r, 60_000);
    assert_eq!(attempts, [1, 2], "the heartbeat's attempt (byte 56)");
    assert_eq!(pairs(&events), [(BolterPair::P3, 2, true)]);
    assert_eq!(events.last(), Some(&Event::Bolting(None)));
    assert!(r.a.faults().is_empty(), "{:?}", r.a.faults());
    assert_eq!(r.a.mode(), Mode::Operational);
}

/// A fastener that never locks on side A: after the third failed attempt (Table 8: three) the
/// pair is given up, the job fails with Table 8's (un)bolting failure, and the robot goes to
/// Standby (fully gripped: cutting power cannot drop it).
// req: T8/bolting_failure
#[test]
fn a_pair_that_never_locks_fails_the_job_after_three_attempts() {
    let mut r = Rig::operational();
    r.send(Command::Bolter(BolterCommand::Bolt(Fasteners::Pair(
        BolterPair::P1,
    ))));
    r.bolters[0].seized = u8::MAX;
    let (events, attempts) = bolt_until_end(&mut r, 60_000);
    assert_eq!(attempts, [1, 2, 3], "the heartbeat's attempt (byte 56)");
    assert_eq!(pairs(&events), [(BolterPair::P1, 3, false)]);
    assert!(
        events.contains(&Event::Bolting(Some(Fault::BoltingFailure))),
        "{events:?}"
    );
    assert!(r.a.faults().contains(Fault::BoltingFailure));
    assert_eq!(r.a.mode(), Mode::Standby);
}

/// Table 1's "move bolters down": both bolters descend until their currents say they touch,
/// and stop there; the job ends reporting contact, with no fault. When one side finds nothing
/// to touch, its descent times out: the job still ends (nothing was bolted, so no failure),
/// reporting no contact.
// req: T1/bolter, D:bolters-down
#[test]
fn moving_the_bolters_down_ends_when_both_touch_or_a_descent_times_out() {
    for b_there in [true, false] {
        let mut r = Rig::operational();
        r.bolters[1].there = b_there;
        r.send(Command::Bolter(BolterCommand::Down));
        let start = r.now;
        let (events, _) = bolt_until_end(&mut r, 10_000);
        assert_eq!(
            events.last(),
            Some(&Event::BoltersDown { contact: b_there })
        );
        let took = r.now - start;
        if b_there {
            assert!(took < CONTACT_MS + 500, "took {took} ms");
        } else {
            assert!(took > board_a::Config::default().bolter.side.sensed_ms);
        }
        assert!(r.a.faults().is_empty(), "{:?}", r.a.faults());
        // Down and stopped there: neither bolter is driven any more.
        let t = r.run(20);
        assert_eq!((t.a.bolter, t.b.bolter), (Drive::Idle, Drive::Idle));
        assert!(!r.a.in_motion());
    }
}

/// Section 7's idle check at the start of a reconfiguration: a current over its at-rest limit
/// (the robot not gripping its face, an arm stuck), on either side — side A's as board A
/// measures it, side B's as board B judged it — raises that module's idle overcurrent fault
/// once the robot has rested, the robot is safed, and the motion does not start. The same
/// current, below the operational limits, faults nothing while no reconfiguration starts.
// req: P7.16
#[test]
fn an_idle_overcurrent_at_the_start_keeps_the_primitive_from_starting() {
    let limits = board_a::Config::default().safety.idle;
    for side in [Side::A, Side::B] {
        for fault in [
            Fault::LocomotionOvercurrentIdle,
            Fault::GripperOvercurrentIdle,
        ] {
            let mut r = Rig::operational();
            let e = &mut r.electrical[side as usize];
            match fault {
                Fault::LocomotionOvercurrentIdle => e.i_loc = limits.locomotion + 100,
                _ => e.i_grip = limits.gripper + 100,
            }
            r.run(100);
            assert!(
                r.a.faults().is_empty(),
                "{side:?} {fault:?}: no check at rest"
            );
            let hb = r.send(extend_from_a()).hb.unwrap();
            let grippers = (hb.gripper_a_target, r.last_b.unwrap().gripper_target);
            r.run(100);
            assert_eq!(r.a.faults().iter().collect::<Vec<_>>(), [fault], "{side:?}");
            assert_eq!(r.a.mode(), Mode::Safed, "{side:?} {fault:?}");
            let hb = r.tick(Some(Command::ClearFaults)).hb.unwrap();
            assert_eq!(
                (hb.gripper_a_target, r.last_b.unwrap().gripper_target),
                grippers,
                "{side:?} {fault:?}: a gripper released"
            );
            assert_eq!(r.a.state(), Some(State::A));
        }
    }
}

/// A matched state other than a.
fn matched_other_than_a() -> State {
    State::ALL
        .into_iter()
        .find(|s| *s != State::A && s.is_matched())
        .unwrap()
}

/// Table 8's initial state mismatch: a reconfiguration whose initial state is not the state
/// the robot is in is refused with that reason, latches the fault (Standby: the robot is
/// gripped), and nothing moves; the same reconfiguration from where the robot is, is accepted.
// req: P7.10, T8/initial_state_mismatch
#[test]
fn a_reconfiguration_from_another_state_is_refused_as_an_initial_state_mismatch() {
    let target = matched_other_than_a();
    let mut r = Rig::operational();
    let wrong = Command::reconfigure(target, State::A).unwrap();
    let t = r.tick(Some(wrong));
    assert_eq!(t.hb.unwrap().refusal, Some(Refusal::InitialStateMismatch));
    assert!(t.a.events.contains(&Event::Executed {
        seq: r.seq,
        command: Some(wrong),
        refusal: Some(Refusal::InitialStateMismatch)
    }));
    assert!(r.a.faults().contains(Fault::InitialStateMismatch));
    assert_eq!(r.a.mode(), Mode::Standby);
    assert_eq!(r.a.state(), Some(State::A));
    assert!(!r.a.in_motion());

    let mut r = Rig::operational();
    let right = Command::reconfigure(State::A, target).unwrap();
    assert_eq!(r.tick(Some(right)).hb.unwrap().refusal, None);
    r.run(2);
    assert!(r.a.in_motion());
    assert!(r.a.faults().is_empty());
}

/// The events say what happened, each once: a command refused names the command and the
/// reason; entering a mode is one mode event (none while the mode holds); a fault latched is
/// one fault event naming it (none while it stays latched).
#[test]
fn events_name_refused_commands_mode_changes_and_new_faults_once() {
    let mut r = Rig::operational();
    // Nothing to resume: refused, and the event names the Reset.
    let t = r.tick(Some(Command::Reset));
    assert_eq!(
        t.a.events.as_slice(),
        [Event::Executed {
            seq: r.seq,
            command: Some(Command::Reset),
            refusal: Some(Refusal::NothingToResume)
        }]
    );
    // The Assembly System's fault: Standby at once (nothing moves).
    let mut events = r.tick(Some(Command::SystemFault)).a.events.to_vec();
    for _ in 0..50 {
        events.extend(r.tick(None).a.events.iter().copied());
    }
    let modes: Vec<_> = events
        .iter()
        .filter(|e| matches!(e, Event::Mode { .. }))
        .collect();
    assert_eq!(
        modes,
        [&Event::Mode {
            from: Mode::Operational,
            to: Mode::Standby
        }]
    );
    let faults: Vec<_> = events
        .iter()
        .filter_map(|e| match e {
            Event::Faults(f) => Some(f.iter().collect::<Vec<_>>()),
            _ => None,
        })
        .collect();
    assert_eq!(faults, [[Fault::AssemblySystem]]);
    // Back to Operational: one mode event, no fault event (the fault is old).
    let mut events = r
        .tick(Some(Command::Mode(Mode::Operational)))
        .a
        .events
        .to_vec();
    for _ in 0..50 {
        events.extend(r.tick(None).a.events.iter().copied());
    }
    assert_eq!(
        events
            .iter()
            .filter(|e| matches!(e, Event::Mode { .. } | Event::Faults(_)))
            .collect::<Vec<_>>(),
        [&Event::Mode {
            from: Mode::Standby,
            to: Mode::Operational
        }]
    );
}

/// Power Control (Table 1): a module switched off in Operational gets no pulse while the
/// others are driven — on side A by board A, on side B by board B as the A→B command's power
/// flags tell it; switched on again, it is driven.
// req: T1/power_control
#[test]
fn a_module_switched_off_is_not_driven_and_the_others_are() {
    use mmic::command::PowerTarget;
    use mmic::units::Module;
    let powered = |r: &Rig, t: &Tick| {
        let p = r.last_b.unwrap().power;
        [
            t.a.hip.is_some(),
            t.a.arm.is_some(),
            t.a.gripper.is_some(),
            p.arm && t.b.arm.is_some(),
            p.gripper && t.b.gripper.is_some(),
            p.bolter,
        ]
    };
    let modules = [
        Module::Hip,
        Module::ArmA,
        Module::GripperA,
        Module::ArmB,
        Module::GripperB,
        Module::BolterB,
    ];
    for (i, m) in modules.into_iter().enumerate() {
        let mut r = Rig::operational();
        let t = r.tick(None);
        assert_eq!(powered(&r, &t), [true; 6]);
        r.send(Command::Power {
            target: PowerTarget::Module(m),
            on: false,
        });
        let mut want = [true; 6];
        want[i] = false;
        let t = r.run(10);
        assert_eq!(powered(&r, &t), want, "{m:?} off");
        r.send(Command::Power {
            target: PowerTarget::Module(m),
            on: true,
        });
        let t = r.run(10);
        assert_eq!(powered(&r, &t), [true; 6], "{m:?} on");
    }
}

/// Power Control of a bolter: with bolter A switched off, a bolting job leaves side A's motor
/// unpowered (idle) while side B's descends.
// req: T1/power_control
#[test]
fn a_bolter_switched_off_is_not_driven() {
    use mmic::command::PowerTarget;
    use mmic::units::Module;
    let mut r = Rig::operational();
    r.send(Command::Power {
        target: PowerTarget::Module(Module::BolterA),
        on: false,
    });
    r.send(Command::Bolter(BolterCommand::Down));
    for _ in 0..20 {
        let t = r.tick(None);
        assert_eq!(t.a.bolter, Drive::Idle, "bolter A driven while off");
    }
    assert_eq!(r.tick(None).b.bolter, Drive::Down, "bolter B descends");
}

/// Table 1's hip commands set the hip's target: a preset to its angle, any other angle to
/// itself, home to the configured home angle.
// req: T1/hip
#[test]
fn a_hip_command_sets_the_angle_it_names() {
    use mmic::command::HipTarget;
    let home = board_a::Config::default().safety.hip_home;
    let angle = HipAngle::new(12_345).unwrap();
    for (h, want) in [
        (HipTarget::RightAngleCw, HipAngle::new(9_000).unwrap()),
        (HipTarget::RightAngleCcw, HipAngle::new(27_000).unwrap()),
        (HipTarget::Angle(angle), angle),
        (HipTarget::Home, home),
    ] {
        let mut r = Rig::operational();
        r.send(Command::Hip(h));
        let hb = r.tick(Some(Command::ClearFaults)).hb.unwrap();
        assert_eq!(hb.hip_target, want, "{h:?}");
    }
}

/// A reconfiguration over primitives that turn nothing (the rig's hip reads 180° throughout):
/// from a to a matched state two or more primitives away, run primitive after primitive, it
/// reaches its target, which the board then tracks, with no fault and command complete.
// req: P6.5, T1/reconfiguration
#[test]
fn a_reconfiguration_runs_its_primitives_to_its_target() {
    use mmic::motion::route;
    let straight = |p: &Primitive| {
        matches!(
            p,
            Primitive::FwdExtend
                | Primitive::BackExtend
                | Primitive::FwdContract
                | Primitive::BackContract
        )
    };
    let target = State::ALL
        .into_iter()
        .find(|s| {
            let plan = route::lookup(State::A, *s);
            s.is_matched() && plan.primitives().len() >= 2 && plan.primitives().iter().all(straight)
        })
        .expect("a matched state reached without turning");
    let mut r = Rig::operational();
    r.send(Command::reconfigure(State::A, target).unwrap());
    let mut reached = Vec::new();
    for _ in 0..6_000 {
        let t = r.tick(None);
        reached.extend(t.a.events.iter().filter_map(|e| match e {
            Event::Reached(s) => Some(*s),
            _ => None,
        }));
        if !r.a.in_motion() {
            break;
        }
    }
    assert_eq!(reached.last(), Some(&target), "{reached:?}");
    assert_eq!(r.a.state(), Some(target));
    assert!(r.a.faults().is_empty(), "{:?}", r.a.faults());
    let hb = r.tick(Some(Command::ClearFaults)).hb.unwrap();
    assert!(hb.command_complete);
    assert_eq!(hb.target_state, Some(target));
}

/// A matched state reached from a without a turn (the rig does not model the hip), through at
/// least two primitives: the last one contracts an arm into the match, which its switch must
/// confirm.
fn straight_target() -> State {
    use mmic::motion::route;
    let straight = |p: &Primitive| {
        matches!(
            p,
            Primitive::FwdExtend
                | Primitive::BackExtend
                | Primitive::FwdContract
                | Primitive::BackContract
        )
    };
    State::ALL
        .into_iter()
        .find(|s| {
            let plan = route::lookup(State::A, *s);
            s.is_matched() && plan.primitives().len() >= 2 && plan.primitives().iter().all(straight)
        })
        .expect("a matched state reached without turning")
}

/// Issue 39 item 4 (spec/decisions.toml, `initial-state-sensors`): a dead arm switch at rest,
/// then a reconfiguration from where the robot is. The arm is commanded contracted (the PWM
/// values the state is estimated from agree with the command's initial state), its switch does
/// not sense it: Table 8's arm not fully contracted, Safed (hip and arms held, powered), the
/// command refused with arm_not_contracted — not an initial state mismatch and Standby, which
/// would tell the operator that their belief of where the robot is was wrong. At rest, before
/// the reconfiguration, nothing checks the switch.
// req: T8/arm_not_contracted, D:initial-state-sensors
#[test]
fn a_dead_arm_switch_at_rest_is_arm_not_contracted_when_a_reconfiguration_arrives() {
    let target = straight_target();
    for side in Side::ALL {
        let mut r = Rig::operational();
        r.switch_stuck[side as usize] = true;
        r.run(100);
        assert!(r.a.faults().is_empty(), "{side:?}: {:?}", r.a.faults());
        let c = Command::reconfigure(State::A, target).unwrap();
        let t = r.tick(Some(c));
        assert_eq!(
            r.a.faults().iter().collect::<Vec<_>>(),
            [Fault::ArmNotContracted],
            "{side:?}"
        );
        assert_eq!(r.a.mode(), Mode::Safed, "{side:?}");
        assert!(t.a.events.contains(&Event::Executed {
            seq: r.seq,
            command: Some(c),
            refusal: Some(Refusal::ArmNotContracted)
        }));
        let hb = t.hb.unwrap();
        assert_eq!(hb.refusal, Some(Refusal::ArmNotContracted), "{side:?}");
        assert!(hb.faults.contains(Fault::ArmNotContracted));
        assert!(!hb.faults.contains(Fault::InitialStateMismatch));
        // Nothing moved: the robot is where it was, its arms held powered and contracted.
        let t = r.run(300);
        assert_eq!(r.a.state(), Some(State::A));
        assert!(!r.a.in_motion());
        let contracted = board_a::Config::default().arm.contracted;
        assert_eq!((t.a.arm, t.b.arm), (Some(contracted), Some(contracted)));
    }
}

/// The same dead switch during the reconfiguration (as before issue 39): the motion's last
/// contraction is not confirmed, Table 8's arm not fully contracted, Safed, the target never
/// reached; no initial state mismatch.
// req: T8/arm_not_contracted, P7.15
#[test]
fn a_switch_that_dies_during_a_reconfiguration_is_arm_not_contracted() {
    let target = straight_target();
    for side in Side::ALL {
        let mut r = Rig::operational();
        r.send(Command::reconfigure(State::A, target).unwrap());
        r.run(50);
        assert!(r.a.in_motion());
        r.switch_stuck[side as usize] = true;
        let mut reached = None;
        for _ in 0..6_000 {
            let t = r.tick(None);
            reached = reached.or(t.a.events.iter().find_map(|e| match e {
                Event::Reached(s) if *s == target => Some(*s),
                _ => None,
            }));
            if !r.a.faults().is_empty() {
                break;
            }
        }
        assert_eq!(
            r.a.faults().iter().collect::<Vec<_>>(),
            [Fault::ArmNotContracted],
            "{side:?}"
        );
        assert_eq!(r.a.mode(), Mode::Safed, "{side:?}");
        assert_eq!(reached, None, "{side:?}");
        assert_ne!(r.a.state(), Some(target));
    }
}

/// With every switch working, a reconfiguration from any state but the one the robot is in
/// (a, tracked, arms commanded contracted) is an initial state mismatch: refused by that name,
/// Standby (the robot is gripped), nothing else latched.
// req: P7.10, T8/initial_state_mismatch
#[test]
fn a_wrong_initial_state_with_working_switches_is_an_initial_state_mismatch_from_every_state() {
    let mut n = 0;
    for initial in State::ALL.into_iter().filter(|s| *s != State::A) {
        let target = State::MATCHED.into_iter().find(|s| *s != initial).unwrap();
        let mut r = Rig::operational();
        let c = Command::reconfigure(initial, target).unwrap();
        let hb = r.tick(Some(c)).hb.unwrap();
        assert_eq!(hb.refusal, Some(Refusal::InitialStateMismatch), "{initial}");
        assert_eq!(
            r.a.faults().iter().collect::<Vec<_>>(),
            [Fault::InitialStateMismatch],
            "{initial}"
        );
        assert_eq!(r.a.mode(), Mode::Standby, "{initial}");
        n += 1;
    }
    assert_eq!(n, 14);
}

/// The state is estimated from the arms' commanded PWM values, not their switches: an arm
/// commanded extended puts the robot in no matched state, so a reconfiguration from a (the
/// tracked state) is an initial state mismatch — with the arm's switch open as it should be,
/// and also with the switch stuck closed, which a check reading the switches took for a
/// contracted arm (and accepted the command). Not arm not fully contracted: the arm is not
/// commanded contracted.
// req: P7.10
#[test]
fn an_arm_commanded_extended_is_in_no_matched_state_whatever_its_switch_says() {
    let target = straight_target();
    for side in Side::ALL {
        for stuck_closed in [false, true] {
            let what = format!("arm {side:?} extended, switch stuck closed {stuck_closed}");
            let mut r = Rig::operational();
            r.send(arm(side, ServoTarget::Extend));
            until_idle(&mut r);
            r.switch_stuck_closed[side as usize] = stuck_closed;
            r.run(10);
            let hb = r
                .tick(Some(Command::reconfigure(State::A, target).unwrap()))
                .hb
                .unwrap();
            assert_eq!(
                r.a.faults().iter().collect::<Vec<_>>(),
                [Fault::InitialStateMismatch],
                "{what}"
            );
            assert_eq!(hb.refusal, Some(Refusal::InitialStateMismatch), "{what}");
            assert_eq!(r.a.mode(), Mode::Standby, "{what}");
        }
    }
}

/// A bolting job accepted while board B still reports a bolter order (its last job's) waits
/// until B reports its bolter idle, so that B cannot take the new job's first order for its
/// previous one (spec/control/bolter.md): meanwhile neither side is ordered anything; then the
/// job runs.
#[test]
fn a_new_bolting_job_waits_until_board_b_reports_its_bolter_idle() {
    let mut r = Rig::operational();
    r.send(Command::Bolter(BolterCommand::Down));
    bolt_until_end(&mut r, 10_000);
    // At once the next job: B's last report, as A heard it, still names the first job's step.
    r.send(Command::Bolter(BolterCommand::Down));
    let mut waited = 0;
    for _ in 0..100 {
        let t = r.tick(None);
        let (heard, _) = r.heard_b.unwrap();
        if heard.bolter_aux.step.is_none() {
            break;
        }
        waited += 1;
        assert_eq!(t.a.bolter, Drive::Idle, "side A ordered while B is busy");
        assert_eq!(r.last_b.unwrap().bolter, None, "B ordered while busy");
    }
    assert!(
        waited > 0,
        "B reported idle before the job came: nothing tested"
    );
    let (events, _) = bolt_until_end(&mut r, 10_000);
    assert_eq!(events.last(), Some(&Event::BoltersDown { contact: true }));
}

/// Stop, then Reset at once, mid-descent after board B reported its bolter touching: the
/// resumed step is ordered afresh on both sides, and only a report B makes of it since — one
/// naming an A→B packet sent after the Reset — counts for side B. B's report from before the
/// Stop never completes it, even when side A completes at once and B's next heartbeats are
/// lost on the line for a while (spec/control/bolter.md, "Stop and Reset").
#[test]
fn a_report_from_before_a_stop_never_completes_the_resumed_step() {
    let mut r = Rig::operational();
    r.bolters[1].contact_ms = 200;
    r.bolters[0].contact_ms = 2_000;
    r.send(Command::Bolter(BolterCommand::Down));
    // Until A hears that B's bolter touches.
    for _ in 0..200 {
        r.tick(None);
        if r.heard_b
            .is_some_and(|(h, _)| h.bolter_aux.threshold_reached)
        {
            break;
        }
    }
    assert!(r.heard_b.unwrap().0.bolter_aux.threshold_reached);
    r.send(Command::Stop);
    let t = r.send(Command::Reset);
    // Side A's fastener is right under it: it touches within a tick or two of resuming; B's
    // heartbeats of the next 200 ms are lost (well within the link's 500 ms timeout).
    r.bolters[0].contact_ms = r.bolters[0].travel_ms + 10;
    r.b_lost_until = r.now + 200;
    let mut since_reset: Vec<u8> =
        t.a.to_b
            .map(|b| BCommandRepr::parse(&b).unwrap().seq)
            .into_iter()
            .collect();
    let mut fresh = false;
    for _ in 0..500 {
        let t = r.tick(None);
        if let Some((h, true)) = r.heard_b {
            fresh |= h.bolter_aux.step.is_some() && since_reset.contains(&h.bolter_aux.seq);
        }
        if let Some(b) = t.a.to_b {
            since_reset.push(BCommandRepr::parse(&b).unwrap().seq);
        }
        if let Some(e) =
            t.a.events
                .iter()
                .find(|e| matches!(e, Event::BoltersDown { .. }))
        {
            assert!(
                fresh,
                "the resumed step ended on B's report from before the Stop"
            );
            assert_eq!(e, &Event::BoltersDown { contact: true });
            return;
        }
    }
    panic!("the resumed job did not end");
}

/// A Stop with nothing moving holds board B too (the A→B stop flag); the next command that
/// moves side B lifts the hold, and B's arm goes to its new target.
#[test]
fn after_a_stop_a_command_for_side_b_lifts_the_hold() {
    let extended = board_a::Config::default().arm.extended;
    let mut r = Rig::operational();
    r.send(Command::Stop);
    r.run(10);
    assert!(r.last_b.unwrap().stop, "B told to hold");
    r.send(arm(Side::B, ServoTarget::Extend));
    until_idle(&mut r);
    let t = r.run(10);
    assert!(!r.last_b.unwrap().stop, "B still held");
    assert_eq!(t.b.arm, Some(extended), "B's arm did not extend");
}

/// The time a Stop holds a bolting job is no stall: paused mid-step for longer than a step
/// may take, the job resumes on Reset with the step's clock restarted and completes, with no
/// timeout.
#[test]
fn a_bolting_job_paused_longer_than_a_step_timeout_completes_after_reset() {
    let cfg = board_a::Config::default().bolter;
    let mut r = Rig::operational();
    r.send(Command::Bolter(BolterCommand::Bolt(Fasteners::Pair(
        BolterPair::P2,
    ))));
    r.run(20);
    r.send(Command::Stop);
    assert!(r.a.paused());
    r.run((cfg.side.sensed_ms + cfg.link_margin_ms) / 10 + 100);
    r.send(Command::Reset);
    let (events, _) = bolt_until_end(&mut r, 30_000);
    assert_eq!(pairs(&events), [(BolterPair::P2, 1, true)]);
    assert_eq!(events.last(), Some(&Event::Bolting(None)));
    assert!(r.a.faults().is_empty(), "{:?}", r.a.faults());
}

/// Issue 24, item 2: a module motion outside a primitive or a bolting job has a deadline, its
/// size over the actuator's speed plus a margin (spec/control/servos.toml, `[deadline]`). The
/// rig's hip reads 180° throughout, as a hip switched off by Power Control would: a quarter
/// turn commanded to it runs 9 s nominal + 5 s margin, then raises the motion timeout (Safed),
/// stops, and the robot is no longer in motion. With a low battery during the motion, the
/// deferred Standby is not waited for forever either: the timeout's Safed wins (Safed over
/// Standby). Before the fix the robot stayed in motion for ever.
#[test]
fn a_hip_that_cannot_move_times_out_after_its_budget() {
    use mmic::command::{HipTarget, PowerTarget};
    use mmic::units::Module;
    for low_battery in [false, true] {
        let mut r = Rig::operational();
        r.send(Command::Power {
            target: PowerTarget::Module(Module::Hip),
            on: false,
        });
        let start = r.now;
        r.send(Command::Hip(HipTarget::RightAngleCw));
        if low_battery {
            r.electrical[0].v_bat = 9_500;
        }
        let budget = 9_000 + board_a::Config::default().deadline.hip_margin_ms;
        let mut ended = None;
        while r.now - start < budget + 2_000 {
            let t = r.tick(None);
            let faults: Vec<Fault> =
                t.a.events
                    .iter()
                    .filter_map(|e| match e {
                        Event::Faults(f) => Some(f.iter().collect::<Vec<_>>()),
                        _ => None,
                    })
                    .flatten()
                    .collect();
            if faults.contains(&Fault::MotionTimeout) {
                ended = Some(r.now - start);
                break;
            }
            assert!(r.a.in_motion(), "at {} ms", r.now - start);
            assert_eq!(r.a.mode(), Mode::Operational, "at {} ms", r.now - start);
        }
        let at = ended.expect("no motion timeout: in motion for ever");
        assert!((budget..=budget + 20).contains(&at), "timed out at {at} ms");
        assert_eq!(r.a.mode(), Mode::Safed);
        let hb = r.tick(Some(Command::Heartbeat)).hb.unwrap();
        assert!(!hb.command_complete, "a timed-out move never completes");
        r.run(10);
        assert!(!r.a.in_motion(), "still in motion after the timeout");
        assert_eq!(r.a.faults().contains(Fault::LowBattery), low_battery);
        assert!(r.a.faults().contains(Fault::MotionTimeout));
    }
}

/// The same for a servo: side B's arm, reported short of its target by board B (stalled), times
/// out after its interpolation time (900 → 2100 µs at 10 µs per 20 ms: 2.4 s) + the 1 s servo
/// margin, with or without a low battery meanwhile; a move that does arrive (side A's, or B's
/// when its reports follow) never times out.
#[test]
fn a_stalled_arm_times_out_after_its_budget_and_a_free_one_does_not() {
    let cfg = board_a::Config::default();
    for low_battery in [false, true] {
        let mut r = Rig::operational();
        r.b_arm_stuck = Some(cfg.arm.contracted);
        let start = r.now;
        r.send(arm(Side::B, ServoTarget::Extend));
        if low_battery {
            r.electrical[0].v_bat = 9_500;
        }
        let budget = 2_400 + cfg.deadline.servo_margin_ms;
        let mut at = None;
        while r.now - start < budget + 2_000 {
            r.tick(None);
            if r.a.faults().contains(Fault::MotionTimeout) {
                at = Some(r.now - start);
                break;
            }
            assert!(r.a.in_motion());
        }
        let at = at.expect("no motion timeout: in motion for ever");
        // Armed a tick after the command was taken, from where B last reported its arm.
        assert!((budget..=budget + 60).contains(&at), "timed out at {at} ms");
        assert_eq!(r.a.mode(), Mode::Safed);
        assert_eq!(r.a.faults().contains(Fault::LowBattery), low_battery);
        r.b_arm_stuck = None;
        r.run(20);
        assert!(!r.a.in_motion());
    }
    for side in [Side::A, Side::B] {
        let mut r = Rig::operational();
        r.send(arm(side, ServoTarget::Extend));
        until_idle(&mut r);
        r.run(600);
        assert!(r.a.faults().is_empty(), "{side:?}: {:?}", r.a.faults());
        assert_eq!(r.a.mode(), Mode::Operational);
    }
}

/// Issue 24, item 3: board B powered 2 s after board A. Until B's first heartbeat board A has
/// no side-B battery voltage, so it judges none: no low battery (before the fix it judged the
/// 0 mV of an empty report and latched low_battery 0.5 s after start-up). What A does judge is
/// B's silence: internal_comm_loss latches after 500 ms, as spec/decisions.toml
/// (`comm-loss-at-start-up`) records; with B heard, clear_faults clears it and the robot enters
/// Operational.
#[test]
fn board_b_powered_two_seconds_after_board_a_is_no_low_battery() {
    let cfg = board_a::Config::default();
    let mut a = BoardA::in_state(cfg, State::A);
    let mut b = BoardB::with_pose(
        board_b::Config::default(),
        cfg.arm.contracted,
        cfg.gripper.extended,
    );
    let (mut to_a, mut to_b) = (None, None);
    let mut seq = 0;
    let mut send = |c: Command| {
        seq += 1;
        Some(
            CommandRepr {
                board: BoardNumber::ONE,
                command: c,
                seq,
            }
            .to_bytes(),
        )
    };
    let mut answers = vec![];
    for t in (10..=4_000).step_by(10) {
        let command = match t {
            3_000 => send(Command::ClearFaults),
            3_010 => send(Command::Mode(Mode::Operational)),
            _ => None,
        };
        let out = a.tick(
            t,
            &Inputs {
                command,
                from_b: to_a.take(),
                ..Inputs::at_home()
            },
        );
        if let Some(h) = out.heartbeat {
            answers.push(HeartbeatRepr::parse(&h).unwrap().refusal);
        }
        assert!(
            !a.faults().contains(Fault::LowBattery),
            "low battery latched at {t} ms"
        );
        if t >= 2_000 {
            let o = b.tick(
                t,
                &board_b::Inputs {
                    command: to_b.take(),
                    electrical: Inputs::at_home().electrical,
                    arm_contracted: true,
                    bolter_at_home: true,
                    ..board_b::Inputs::default()
                },
            );
            to_a = o.heartbeat;
            to_b = out.to_b;
        }
        if t == 2_000 {
            assert_eq!(
                a.faults().iter().collect::<Vec<_>>(),
                [Fault::InternalCommLoss]
            );
        }
    }
    assert_eq!(answers, [None, None]);
    assert_eq!(a.mode(), Mode::Operational);
    assert!(a.faults().is_empty(), "{:?}", a.faults());
}

/// Issue 24, item 4: an arm or gripper position outside the module's travel would drive the
/// servo against its end stop. The packet refuses one outside the library's travel (arm
/// 900..=2100, gripper 1000..=2000 µs: `CommandError::OutOfTravel`, so board A answers
/// invalid_parameter), and board A refuses one outside its own configured travel the same way;
/// nothing moves. The ends of the travel are accepted.
#[test]
fn arm_and_gripper_targets_outside_their_travel_are_refused() {
    use mmic::wire::checksum::crc16;
    let mut r = Rig::operational();
    // On the wire: arm A to 2101 µs (opcode 0x22, bytes 8-9), sealed by hand since the
    // library's encoder is fed only commands within the travel by its users.
    let cases = [(0x22u8, 8usize, 2101u16), (0x2a, 8, 999), (0x26, 10, 899)];
    for (seq, (id, slot, us)) in (600u16..).zip(cases) {
        let mut p = CommandRepr {
            board: BoardNumber::ONE,
            command: Command::Heartbeat,
            seq,
        }
        .to_bytes();
        p[5] = id;
        p[slot..slot + 2].copy_from_slice(&us.to_le_bytes());
        if slot == 10 {
            // Arm B's position takes bytes 10-11; its sequence number moves to bytes 6-7.
            p[6..8].copy_from_slice(&seq.to_le_bytes());
        }
        let crc = crc16(&p[..12]).to_le_bytes();
        p[12..].copy_from_slice(&crc);
        let e = CommandRepr::parse(&p).unwrap_err().to_string();
        assert!(e.contains("travel"), "{id:#x} {us}: {e}");
        let out = r.a.tick(
            r.now + 10,
            &Inputs {
                command: Some(p),
                ..Inputs::at_home()
            },
        );
        r.now += 10;
        let hb = HeartbeatRepr::parse(&out.heartbeat.unwrap()).unwrap();
        assert_eq!(
            (hb.last_seq, hb.refusal),
            (seq, Some(Refusal::InvalidParameter)),
            "{id:#x} {us}"
        );
    }
    // Board A's own travel, narrower than the library's: refused within the library's,
    // accepted at its ends.
    let cfg = board_a::Config {
        arm: mmic::control::interp::Travel {
            contracted: PulseWidth::new(1000).unwrap(),
            extended: PulseWidth::new(2000).unwrap(),
        },
        ..board_a::Config::default()
    };
    let cfg = board_a::Config {
        gripper: mmic::control::interp::Travel {
            contracted: PulseWidth::new(1100).unwrap(),
            extended: PulseWidth::new(2000).unwrap(),
        },
        ..cfg
    };
    let mut r = Rig::operational_with(cfg);
    let at = |us| ServoTarget::Position(PulseWidth::new(us).unwrap());
    for c in [
        arm(Side::B, at(2050)),
        arm(Side::A, at(999)),
        gripper(Side::A, at(1050)),
    ] {
        let hb = r.tick(Some(c)).hb.unwrap();
        assert_eq!(hb.refusal, Some(Refusal::InvalidParameter), "{c:?}");
        assert!(!r.a.in_motion(), "{c:?}: moved");
    }
    r.send(arm(Side::A, at(2000)));
    until_idle(&mut r);
    r.send(arm(Side::B, at(1000)));
    until_idle(&mut r);
    assert!(r.a.faults().is_empty());
}

/// The module budget is for motions without step timeouts of their own: a primitive's steps and
/// a bolting job's are timed by the sequencer and the coordinator. Side B's arm reported stalled
/// during a primitive's Move times out at the Move step's 15 s (the sequencer's motion timeout),
/// not at the 3.4 s an arm command would get; during a bolting job a side-B servo reported off
/// its target does not stop the job, and once the job has ended the module budget takes over.
#[test]
fn primitives_and_bolting_jobs_are_timed_by_their_steps_not_by_the_module_budget() {
    let cfg = board_a::Config::default();
    let mut r = Rig::operational();
    let start = r.now;
    r.send(extend_from_a());
    r.b_arm_stuck = Some(cfg.arm.contracted);
    let mut at = None;
    while r.now - start < 30_000 {
        r.tick(None);
        if r.a.faults().contains(Fault::MotionTimeout) {
            at = Some(r.now - start);
            break;
        }
    }
    let at = at.expect("the stalled primitive timed out");
    assert!(
        at > cfg.motion.move_ms,
        "timed out at {at} ms, before the Move step's {} ms",
        cfg.motion.move_ms
    );
    let mut r = Rig::operational();
    r.send(Command::Bolter(BolterCommand::Bolt(Fasteners::Pair(
        BolterPair::from_number(1).unwrap(),
    ))));
    r.run(5);
    // Side B's arm reported away from its target from now on.
    r.b_arm_stuck = Some(PulseWidth::new(2000).unwrap());
    let mut ended = None;
    for i in 0..3_000 {
        let t = r.tick(None);
        assert!(
            !r.a.faults().contains(Fault::MotionTimeout),
            "motion timeout {} ms into the job",
            i * 10
        );
        if let Some(e) = t.a.events.iter().find(|e| matches!(e, Event::Bolting(_))) {
            ended = Some(*e);
            break;
        }
    }
    assert_eq!(ended, Some(Event::Bolting(None)), "the job completes");
    // Then the report is a module off its target with no step timing it: 1100 µs of arm
    // travel (2.2 s) + the 1 s margin.
    let end = r.now;
    while !r.a.faults().contains(Fault::MotionTimeout) {
        r.tick(None);
        assert!(r.now - end <= 3_300, "no timeout after the job");
    }
    assert!(r.now - end >= 3_200, "{} ms", r.now - end);
}

/// After a timeout the budget is not armed again while the module stays off its target (one
/// fault, not one per budget); once the modules have come to rest, a module pushed off its
/// target again is timed again.
#[test]
fn a_timed_out_motion_is_not_timed_again_until_the_modules_rest() {
    let cfg = board_a::Config::default();
    let mut r = Rig::operational();
    r.b_arm_stuck = Some(cfg.arm.contracted);
    r.send(arm(Side::B, ServoTarget::Extend));
    r.run(400);
    assert!(r.a.faults().contains(Fault::MotionTimeout));
    assert_eq!(r.a.mode(), Mode::Safed);
    // Still reported off target: cleared, it stays cleared.
    r.send(Command::ClearFaults);
    for _ in 0..1_000 {
        r.tick(None);
        assert!(
            r.a.faults().is_empty(),
            "timed out again: {:?}",
            r.a.faults()
        );
    }
    // At rest (the report follows the servo again), then off target again: timed again.
    r.b_arm_stuck = None;
    r.run(10);
    assert!(!r.a.in_motion());
    r.b_arm_stuck = Some(cfg.arm.contracted);
    r.run(10);
    assert!(r.a.in_motion());
    let start = r.now;
    while !r.a.faults().contains(Fault::MotionTimeout) {
        r.tick(None);
        assert!(r.now - start < 5_000, "not timed again");
    }
}

/// Section 7: "When switching to 'opmode', actuators are set to go to their home position" —
/// also when Operational is entered again after Safed held them where they were: arm B, held
/// half-way out, goes back to contracted, within the module budget and with no fault.
// req: P7.6
#[test]
fn re_entering_operational_sends_the_servos_home_again() {
    let cfg = board_a::Config::default();
    let mut r = Rig::operational();
    r.send(arm(Side::B, ServoTarget::Extend));
    r.run(120);
    r.send(Command::Mode(Mode::Safed));
    r.run(50);
    let held = r.heard_b.unwrap().0.arm_b_now;
    assert!(held > cfg.arm.contracted, "arm B held out at {held:?}");
    r.send(Command::Mode(Mode::Operational));
    until_idle(&mut r);
    let hb = r.heard_b.unwrap().0;
    assert_eq!(
        (hb.arm_b_now, hb.arm_b_target),
        (cfg.arm.contracted, cfg.arm.contracted)
    );
    assert!(r.a.faults().is_empty(), "{:?}", r.a.faults());
    assert_eq!(r.a.mode(), Mode::Operational);
}

/// The budget starts when the modules start to move: a side-B servo reported off its target
/// long after the last motion ended gets its whole budget (2.4 s of travel + 1 s), not the
/// deadline of the motion before.
#[test]
fn a_budget_starts_with_its_motion() {
    let cfg = board_a::Config::default();
    let mut r = Rig::operational();
    r.send(arm(Side::B, ServoTarget::Extend));
    until_idle(&mut r);
    r.run(1_000);
    assert!(r.a.faults().is_empty());
    r.b_arm_stuck = Some(cfg.arm.contracted);
    let start = r.now;
    while !r.a.faults().contains(Fault::MotionTimeout) {
        r.tick(None);
        assert!(r.now - start < 5_000, "never timed out");
    }
    assert!(
        r.now - start >= 3_400,
        "timed out {} ms after",
        r.now - start
    );
}

/// A report from board B that fails its check is an event, and board A goes on as if it had
/// heard nothing that tick: the same state as a twin whose report was lost.
#[test]
fn a_corrupted_report_from_b_is_rejected_as_if_lost() {
    let mut r = Rig::operational();
    r.run(5);
    let mut bad = r.to_a.expect("B reports every tick");
    bad[9] ^= 0x04;
    let err = InternalHeartbeatRepr::parse(&bad).unwrap_err();
    let mut twin = r.a;
    let inputs = |from_b| Inputs {
        from_b,
        ..Inputs::at_home()
    };
    let out = r.a.tick(r.now + 10, &inputs(Some(bad)));
    assert_eq!(out.events.as_slice(), [Event::Rejected(err)]);
    let quiet = twin.tick(r.now + 10, &inputs(None));
    assert!(quiet.events.is_empty());
    assert_eq!(r.a, twin);
}

/// A deferred fault (low battery) latched while an accepted reconfiguration waits for the
/// robot to rest: the reconfiguration's first primitive never starts, and Standby follows
/// (Table 8: a deferred fault waits for the motion in progress; none had started).
#[test]
fn a_deferred_fault_while_a_reconfiguration_waits_to_start_drops_it() {
    // Settling longer than the battery's debounce: the fault comes while the check waits.
    let defaults = board_a::Config::default();
    let cfg = board_a::Config {
        idle_settle_ms: 2_000,
        safety: mmic::safety::detect::Config {
            low_battery_ms: 100,
            ..defaults.safety
        },
        ..defaults
    };
    let mut r = Rig::operational_with(cfg);
    for target in [ServoTarget::Extend, ServoTarget::Contract] {
        r.send(arm(Side::A, target));
        while {
            r.tick(None);
            r.a.in_motion()
        } {}
    }
    let hb = r.send(extend_from_a()).hb.unwrap();
    r.tick(Some(Command::ClearFaults));
    assert!(
        r.a.in_motion(),
        "the reconfiguration waits for the idle check"
    );
    let before = (hb.gripper_a_target, r.last_b.unwrap().gripper_target);
    r.electrical = [Electrical {
        v_bat: 9_000,
        ..r.electrical[0]
    }; 2];
    let mut events = Vec::new();
    for _ in 0..300 {
        let t = r.tick(Some(Command::ClearFaults));
        events.extend(t.a.events.iter().copied());
        let hb = t.hb.unwrap();
        assert_eq!(
            (hb.gripper_a_target, r.last_b.unwrap().gripper_target),
            before,
            "a primitive started at {} ms",
            r.now
        );
    }
    assert_eq!(r.a.mode(), Mode::Standby);
    assert!(r.a.faults().contains(Fault::LowBattery));
    assert!(!r.a.in_motion());
    assert!(!events.iter().any(|e| matches!(e, Event::Reached(_))));
    assert!(events.contains(&Event::Mode {
        from: Mode::Operational,
        to: Mode::Standby
    }));
}

/// A second Stop while a first one holds a motion keeps the first one's motion: no second
/// pause (the motion kept is not replaced by the held one), and Reset resumes the arm towards
/// the target it had before the first Stop.
// req: D:stop-and-reset
#[test]
fn a_second_stop_keeps_the_motion_the_first_one_kept_for_reset() {
    let mut r = Rig::operational();
    let rest = r.tick(None);
    r.send(arm(Side::A, ServoTarget::Extend));
    r.run(30);
    let first = r.send(Command::Stop);
    assert!(
        first.a.events.contains(&Event::Paused),
        "{:?}",
        first.a.events
    );
    let held = r.run(20);
    let second = r.send(Command::Stop);
    assert!(
        !second.a.events.contains(&Event::Paused),
        "a second pause: {:?}",
        second.a.events
    );
    assert!(r.a.paused(), "the first Stop's motion is still kept");
    assert_eq!(
        r.run(20).a.arm,
        held.a.arm,
        "the arm holds after the second Stop"
    );
    let reset = r.send(Command::Reset);
    assert!(reset.a.events.contains(&Event::Resumed));
    let after = r.run(300);
    assert_ne!(after.a.arm, held.a.arm, "Reset resumed the first motion");
    assert_ne!(after.a.arm, rest.a.arm);
    assert!(!r.a.paused());
}

/// A board that tracks no state (booted without knowing where it is) refuses a primitive as an
/// initial state mismatch: no move of the map starts from an unknown state.
// req: T1/primitive
#[test]
fn a_board_that_tracks_no_state_refuses_a_primitive_as_an_initial_state_mismatch() {
    let mut r = Rig::operational_board(BoardA::new(board_a::Config::default()));
    assert_eq!(r.a.state(), None);
    let hb = r.tick(Some(extend_from_a())).hb.unwrap();
    assert_eq!(hb.refusal, Some(Refusal::InitialStateMismatch));
    assert!(!r.a.in_motion());
}

/// A reconfiguration arriving in a tick without a hip encoder reading: in Operational the
/// unread hip counts as not at its target, so the robot is busy and the command refused as
/// such; in Standby, Table 7 refuses it (not allowed in the mode) before Table 8's
/// initial-state check, which cannot confirm any state without the hip: no fault is latched.
// req: T8/initial_state_mismatch
#[test]
fn a_reconfiguration_without_a_hip_reading_is_refused_and_latches_no_fault() {
    let cmd = Command::reconfigure(State::A, straight_target()).unwrap();
    for (mode, refusal) in [
        (Mode::Operational, Refusal::Busy),
        (Mode::Standby, Refusal::NotAllowedInMode),
    ] {
        let mut r = Rig::operational();
        r.send(Command::Mode(mode));
        r.run(10);
        r.no_hip = true;
        let hb = r.tick(Some(cmd)).hb.unwrap();
        r.no_hip = false;
        assert_eq!(hb.refusal, Some(refusal), "{mode:?}");
        assert!(r.a.faults().is_empty(), "{mode:?}: {:?}", r.a.faults());
        assert_eq!(r.a.mode(), mode);
    }
    let mut r = Rig::operational();
    r.send(cmd);
    r.run(2);
    assert!(r.a.in_motion(), "accepted with the hip reading");
}

/// A bolting job that fails at its first step (the step limit below one tick: a motion
/// timeout before either side reported) names no pair: none was worked on. The job's end
/// names the fault.
// req: D:motion-timeout
#[test]
fn a_bolting_job_failing_at_its_first_step_names_no_pair() {
    let defaults = board_a::Config::default();
    let cfg = board_a::Config {
        bolter: mmic::bolter::Config {
            side: mmic::bolter::SideConfig {
                sensed_ms: 5,
                home_ms: 5,
                ..defaults.bolter.side
            },
            link_margin_ms: 0,
            ..defaults.bolter
        },
        ..defaults
    };
    let mut r = Rig::operational_with(cfg);
    r.send(Command::Bolter(BolterCommand::Bolt(Fasteners::Pair(
        BolterPair::P2,
    ))));
    let events = r.tick(None).a.events;
    assert!(
        events.contains(&Event::Bolting(Some(Fault::MotionTimeout))),
        "{events:?}"
    );
    assert!(pairs(&events).is_empty(), "{events:?}");
    assert!(r.a.faults().contains(Fault::MotionTimeout));
}
