//! Board A and board B as pure nodes: every command class is answered by a heartbeat that
//! acknowledges its sequence number, runs once however often it arrives, and the A–B link's
//! loss takes an Operational robot to Safed within the timeout.

use mmic::arbitrary::for_each_variant_class;
use mmic::command::Command;
use mmic::faults::Fault;
use mmic::mode::Mode;
use mmic::motion::geometry::single_move;
use mmic::motion::State;
use mmic::node::robot::board_a::{self, BoardA, Event, Inputs};
use mmic::node::robot::board_b::{self, BoardB};
use mmic::refusal::Refusal;
use mmic::units::{BoardNumber, Electrical, HipAngle, PulseWidth};
use mmic::wire::command::CommandRepr;
use mmic::wire::heartbeat::HeartbeatRepr;

fn send(
    a: &mut BoardA,
    now: u32,
    command: Command,
    seq: u16,
) -> (Option<HeartbeatRepr>, Vec<Event>) {
    let packet = CommandRepr {
        board: BoardNumber::ONE,
        command,
        seq,
    }
    .to_bytes();
    let out = a.tick(
        now,
        &Inputs {
            command: Some(packet),
            ..Inputs::at_home()
        },
    );
    let hb = out.heartbeat.map(|b| HeartbeatRepr::parse(&b).unwrap());
    (hb, out.events.iter().copied().collect())
}

fn executed(events: &[Event]) -> Vec<u16> {
    events
        .iter()
        .filter_map(|e| match e {
            Event::Executed { seq, .. } => Some(*seq),
            _ => None,
        })
        .collect()
}

/// spec/modes.toml's `[accepts]`: the command kinds Table 7 accepts in each mode.
fn accepted_kinds() -> std::collections::BTreeMap<String, Vec<String>> {
    #[derive(serde::Deserialize)]
    struct Spec {
        accepts: std::collections::BTreeMap<String, Vec<String>>,
    }
    let p = concat!(env!("CARGO_MANIFEST_DIR"), "/spec/modes.toml");
    let s: Spec = toml::from_str(&std::fs::read_to_string(p).unwrap()).unwrap();
    s.accepts
}

/// The answer Table 7 and the refusal codes (spec/modes.toml, src/refusal.rs's meanings) give
/// command `c` met in `mode` by a robot at rest in state a, with no fault and nothing stopped
/// (none = accepted): a kind the mode does not accept is `not_allowed_in_mode`; Reset with
/// nothing kept is `nothing_to_resume`; a reconfiguration from another state, or a primitive
/// whose final state is not one move from a, is `initial_state_mismatch`.
fn table7_answer(mode: Mode, c: &Command) -> Option<Refusal> {
    let accepts = accepted_kinds();
    if !accepts[mode.name()].iter().any(|k| k == c.kind().name()) {
        return Some(Refusal::NotAllowedInMode);
    }
    match c {
        Command::Reset => Some(Refusal::NothingToResume),
        Command::Reconfigure(r) if r.initial() != State::A => Some(Refusal::InitialStateMismatch),
        Command::Primitive(m)
            if single_move(State::A, m.target()).map(|(_, p)| p) != Some(m.primitive()) =>
        {
            Some(Refusal::InitialStateMismatch)
        }
        _ => None,
    }
}

/// Every command class in every mode, met by boards A and B linked and at rest in state a:
/// the answer is exactly the one [`table7_answer`] gives (a supervisor accepting a primitive
/// in Standby, or refusing an arm command in Safed, fails here), and the supervisor's mode
/// after it is the one the command asks for, or unchanged.
// req: T7/commands, T1/*, P7.4, P7.5
#[test]
fn every_command_class_in_every_mode_gets_the_answer_table_7_gives() {
    let mut cases = 0;
    for start in [Mode::Standby, Mode::Operational, Mode::Safed] {
        for_each_variant_class(PulseWidth::CENTER, HipAngle::new(9000).unwrap(), |c| {
            let mut a = BoardA::in_state(board_a::Config::default(), State::A);
            let mut b = BoardB::with_pose(
                board_b::Config::default(),
                board_a::Config::default().arm.contracted,
                board_a::Config::default().gripper.extended,
            );
            let mut linked = Linked::default();
            if start != Mode::Standby {
                linked.tick(&mut a, &mut b, Some((Command::Mode(Mode::Operational), 1)));
            }
            if start == Mode::Safed {
                linked.tick(&mut a, &mut b, Some((Command::Mode(Mode::Safed), 2)));
            }
            for _ in 0..150 {
                linked.tick(&mut a, &mut b, None);
            }
            assert_eq!(a.mode(), start);
            assert!(!a.in_motion() && a.faults().is_empty(), "at rest, no fault");
            let hb = linked
                .tick(&mut a, &mut b, Some((c, 10)))
                .expect("answered");
            assert_eq!(hb.last_seq, 10);
            assert_eq!(hb.refusal, table7_answer(start, &c), "{start} {c:?}");
            match (c, hb.refusal) {
                (Command::Mode(m), None) => assert_eq!(a.mode(), m, "{c:?}"),
                (Command::SystemFault, None) if start == Mode::Operational => {
                    assert_eq!(a.mode(), Mode::Standby)
                }
                _ => assert_eq!(a.mode(), start, "{start} {c:?}"),
            }
            cases += 1;
        });
    }
    assert_eq!(cases, 3 * 61);
}

/// Boards A and B wired to each other, ticking every 10 ms.
#[derive(Default)]
struct Linked {
    now: u32,
    to_b: Option<[u8; mmic::wire::b_command::B_COMMAND_LEN]>,
    to_a: Option<[u8; mmic::wire::internal_heartbeat::INTERNAL_HEARTBEAT_LEN]>,
}

impl Linked {
    /// One tick of both boards, with a command for A; returns A's heartbeat.
    fn tick(
        &mut self,
        a: &mut BoardA,
        b: &mut BoardB,
        command: Option<(Command, u16)>,
    ) -> Option<HeartbeatRepr> {
        self.now += 10;
        let packet = command.map(|(command, seq)| {
            CommandRepr {
                board: BoardNumber::ONE,
                command,
                seq,
            }
            .to_bytes()
        });
        let out_a = a.tick(
            self.now,
            &Inputs {
                command: packet,
                from_b: self.to_a,
                ..Inputs::at_home()
            },
        );
        let out_b = b.tick(
            self.now,
            &board_b::Inputs {
                command: self.to_b,
                ..b_inputs()
            },
        );
        self.to_b = out_a.to_b;
        self.to_a = out_b.heartbeat;
        out_a.heartbeat.map(|h| HeartbeatRepr::parse(&h).unwrap())
    }
}

// req: P3.14
#[test]
fn every_command_class_in_every_starting_mode_runs_once_and_is_acknowledged() {
    let mut cases = 0;
    for start in [Mode::Standby, Mode::Operational, Mode::Safed] {
        for_each_variant_class(PulseWidth::CENTER, HipAngle::new(9000).unwrap(), |c| {
            let mut a = BoardA::in_state(board_a::Config::default(), State::A);
            if start != Mode::Standby {
                send(&mut a, 0, Command::Mode(Mode::Operational), 1);
            }
            if start == Mode::Safed {
                send(&mut a, 5, Command::Mode(Mode::Safed), 2);
            }
            assert_eq!(a.mode(), start);
            let (hb, ev) = send(&mut a, 10, c, 10);
            let hb = hb.expect("answered");
            assert_eq!(hb.last_seq, 10, "{c:?}");
            assert_eq!(executed(&ev), [10], "{c:?} ran once");
            let first = hb.refusal;
            assert_eq!(a.last_command(), (10, first));
            // The same packet again, and again later: answered alike, never run.
            for t in [20, 700] {
                let (hb, ev) = send(&mut a, t, c, 10);
                let hb = hb.expect("answered");
                assert_eq!((hb.last_seq, hb.refusal), (10, first), "{c:?}");
                assert!(executed(&ev).is_empty());
                assert!(ev.contains(&Event::Duplicate { seq: 10 }));
            }
            // A late copy of an older command.
            let (hb, ev) = send(&mut a, 30, Command::Stop, 9);
            assert_eq!(hb.map(|h| h.last_seq), Some(10));
            assert!(ev.contains(&Event::Stale { seq: 9 }) && executed(&ev).is_empty());
            cases += 1;
        });
    }
    assert_eq!(cases, 3 * 61);
}

/// Heartbeat byte 62 has one meaning (spec/decisions.toml, `heartbeat-byte-62`): the outcome of
/// the command the heartbeat reports on — the packet it answers when board A judges that
/// packet now (a new sequenced command, or an unsequenced one), and for a copy it does not
/// judge again (duplicate, stale) the command bytes 57–58 name. So whenever the answered
/// packet is sequenced, byte 62 is the outcome of the number in bytes 57–58, whatever
/// unsequenced commands came in between.
// req: T3/refusal, D:heartbeat-byte-62
#[test]
fn byte_62_reports_the_command_the_heartbeat_reports_on() {
    let arm = Command::Arm {
        side: mmic::units::Side::A,
        target: mmic::command::ServoTarget::Extend,
    };
    let refused = Some(Refusal::NotAllowedInMode);
    let mut a = BoardA::new(board_a::Config::default());
    let mut t = 0;
    let mut answer = |a: &mut BoardA, c: Command, seq: u16| {
        t += 10;
        let hb = send(a, t, c, seq).0.expect("answered");
        (hb.last_seq, hb.refusal)
    };
    // Standby: a sequenced arm command is refused, and its heartbeat says so.
    assert_eq!(answer(&mut a, arm, 10), (10, refused));
    // Unsequenced packets report themselves: accepted, refused.
    assert_eq!(answer(&mut a, Command::Heartbeat, 0), (10, None));
    assert_eq!(answer(&mut a, arm, 0), (10, refused));
    assert_eq!(answer(&mut a, Command::Heartbeat, 0), (10, None));
    // Copies report the command bytes 57–58 name (10, refused), not the last packet judged
    // (an accepted heartbeat request) nor what the copy itself would have earned.
    assert_eq!(answer(&mut a, arm, 10), (10, refused));
    assert_eq!(answer(&mut a, Command::Heartbeat, 0), (10, None));
    assert_eq!(answer(&mut a, Command::Heartbeat, 9), (10, refused));
    // A new sequenced command reports itself; an unsequenced one refused after it, itself;
    // then a stale copy of 10 reports 11 (accepted), neither 10's refusal nor the last
    // packet's.
    assert_eq!(
        answer(&mut a, Command::Mode(Mode::Operational), 11),
        (11, None)
    );
    assert_eq!(
        answer(&mut a, Command::Reset, 0),
        (11, Some(Refusal::NothingToResume))
    );
    assert_eq!(answer(&mut a, arm, 10), (11, None));
}

// req: T2/board, T2/checksum
#[test]
fn packets_for_others_or_broken_get_no_answer_and_malformed_ones_a_refusal() {
    let mut a = BoardA::new(board_a::Config::default());
    let other = CommandRepr {
        board: BoardNumber::new(2).unwrap(),
        command: Command::Stop,
        seq: 1,
    }
    .to_bytes();
    let out = a.tick(
        0,
        &Inputs {
            command: Some(other),
            ..Inputs::at_home()
        },
    );
    assert!(out.heartbeat.is_none());
    assert!(matches!(out.events[0], Event::OtherRobot { .. }));
    let mut broken = CommandRepr {
        board: BoardNumber::ONE,
        command: Command::Stop,
        seq: 1,
    }
    .to_bytes();
    broken[13] ^= 0x40;
    let out = a.tick(
        10,
        &Inputs {
            command: Some(broken),
            ..Inputs::at_home()
        },
    );
    assert!(out.heartbeat.is_none());
    assert!(matches!(out.events[0], Event::Rejected(_)));
    // Opcode 0xff with sequence number 77 in bytes 10-11, sealed: no command, but ours.
    let mut unknown = CommandRepr {
        board: BoardNumber::ONE,
        command: Command::Stop,
        seq: 77,
    }
    .to_bytes();
    unknown[5] = 0xff;
    let c = mmic::wire::checksum::crc16(&unknown[..12]).to_le_bytes();
    unknown[12..].copy_from_slice(&c);
    let out = a.tick(
        20,
        &Inputs {
            command: Some(unknown),
            ..Inputs::at_home()
        },
    );
    let hb = HeartbeatRepr::parse(&out.heartbeat.unwrap()).unwrap();
    assert_eq!(
        (hb.last_seq, hb.refusal),
        (77, Some(Refusal::UnknownCommand))
    );
    // The same unknown opcode, sealed, for robot 2: not ours, so no answer (robot 2 answers
    // it), and this robot's log is untouched.
    let mut theirs = CommandRepr {
        board: BoardNumber::new(2).unwrap(),
        command: Command::Stop,
        seq: 78,
    }
    .to_bytes();
    theirs[5] = 0xff;
    let c = mmic::wire::checksum::crc16(&theirs[..12]).to_le_bytes();
    theirs[12..].copy_from_slice(&c);
    let out = a.tick(
        30,
        &Inputs {
            command: Some(theirs),
            ..Inputs::at_home()
        },
    );
    assert!(out.heartbeat.is_none());
    assert!(matches!(out.events[0], Event::Rejected(_)));
    assert_eq!(a.last_command(), (77, Some(Refusal::UnknownCommand)));
}

fn b_inputs() -> board_b::Inputs {
    board_b::Inputs {
        electrical: Electrical {
            v_bat: 12_000,
            v_reg: 7_400,
            ..Electrical::default()
        },
        arm_contracted: true,
        ..board_b::Inputs::default()
    }
}

/// Boards A and B from Operational in state a, ticking every 10 ms from 10 ms to `until`;
/// at each tick `link(t)` says whether (A->B, B->A) deliver, and `each(t, &a, heard)` looks at
/// A after the tick (`heard`: a B heartbeat reached A in it) and may stop the run by returning
/// false.
fn run_linked(
    until: u32,
    link: impl Fn(u32) -> (bool, bool),
    mut each: impl FnMut(u32, &BoardA, bool) -> bool,
) {
    let mut a = BoardA::in_state(board_a::Config::default(), State::A);
    let mut b = BoardB::with_pose(
        board_b::Config::default(),
        board_a::Config::default().arm.contracted,
        board_a::Config::default().gripper.extended,
    );
    send(&mut a, 0, Command::Mode(Mode::Operational), 1);
    let (mut to_b, mut to_a) = (None, None);
    for t in (10..until).step_by(10) {
        let (ab, ba) = link(t);
        let heard = ba && to_a.is_some();
        let out_a = a.tick(
            t,
            &Inputs {
                from_b: if ba { to_a } else { None },
                ..Inputs::at_home()
            },
        );
        let out_b = b.tick(
            t,
            &board_b::Inputs {
                command: if ab { to_b } else { None },
                ..b_inputs()
            },
        );
        to_b = out_a.to_b;
        to_a = out_b.heartbeat;
        if !each(t, &a, heard) {
            return;
        }
    }
}

// req: P4.1, P7.19
#[test]
fn a_and_b_run_together_without_fault_and_link_loss_is_safed_within_the_timeout() {
    let cut = 5_000;
    let mut safed_at = None;
    run_linked(
        8_000,
        |t| (t < cut, t < cut),
        |t, a, _| {
            if t < cut {
                assert!(
                    a.faults().is_empty(),
                    "no fault while linked (t = {t}): {:?}",
                    a.faults()
                );
                assert_eq!(a.mode(), Mode::Operational);
            } else if safed_at.is_none() && a.mode() == Mode::Safed {
                safed_at = Some(t);
                assert!(a.faults().contains(Fault::InternalCommLoss));
            }
            true
        },
    );
    let latency = safed_at.expect("Safed") - cut;
    assert!(
        latency <= mmic::safety::detect::Config::default().comm_timeout_ms,
        "{latency} ms"
    );
    eprintln!("Safed {latency} ms after the A-B link was cut");
}

/// Runs A and B linked for 3 s, from Operational, dropping B's heartbeats from 1 s on in one
/// burst of `silence_ms`; returns when A faulted and when it last heard B (ms), if it faulted.
fn faulted_after_heartbeat_burst(silence_ms: u32) -> Option<(u32, u32)> {
    let dropped = |t: u32| (1_000..1_000 + silence_ms).contains(&t);
    let (mut fault, mut last_heard) = (None, 0);
    run_linked(
        3_000,
        |t| (true, !dropped(t)),
        |t, a, heard| {
            if heard {
                last_heard = t;
            }
            if a.faults().is_empty() {
                return true;
            }
            assert_eq!(
                a.faults(),
                mmic::faults::Faults::EMPTY.with(Fault::InternalCommLoss)
            );
            fault = Some((t, last_heard));
            false
        },
    );
    fault
}

// req: P7.19, T8/internal_comm_loss
#[test]
fn lost_b_heartbeats_fault_only_past_the_timeout() {
    // Board A keeps refreshing its A->B command every 50 ms meanwhile: refreshes of an
    // acknowledged command are not unacknowledged sends (spec/decisions.toml,
    // comm-loss-unacknowledged).
    // Dropping heartbeats for up to 450 ms leaves B silent for less than the 500 ms timeout
    // (its period is 50 ms).
    for burst in (10..=450).step_by(10) {
        assert_eq!(faulted_after_heartbeat_burst(burst), None, "{burst} ms");
    }
    // Longer: the fault comes at the first tick after 500 ms of silence, not before.
    for burst in (550..=1_000).step_by(50) {
        let (t, heard) = faulted_after_heartbeat_burst(burst).expect("faults");
        assert_eq!(
            t - heard,
            510,
            "burst {burst} ms: faulted at {t}, last heard {heard}"
        );
    }
}
