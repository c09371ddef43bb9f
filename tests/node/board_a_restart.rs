//! Board A crashing while it takes a command (decision `restart-board-a`): whatever the instant,
//! the copy a sender resends after the restart is never run again, and it is never
//! acknowledged as accepted unless it ran: a crash between the record written ahead of the
//! tick and the one written after it answers "restarted while taking it" (byte 62 = 10), which
//! the uplink ends as unacknowledged.

use mmic::command::Command;
use mmic::mode::Mode;
use mmic::node::exactly_once::uplink::{self, Outcome, Uplink};
use mmic::node::robot::board_a::{BoardA, Config, Event, Inputs};
use mmic::refusal::Refusal;
use mmic::restart::ResetCause;
use mmic::units::BoardNumber;
use mmic::wire::heartbeat::HeartbeatRepr;

/// Where the power is cut while board A takes `command`.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Cut {
    /// After the ahead write, before the tick.
    BeforeTick,
    /// After the tick, before the after-tick write.
    BeforeWrite,
    /// After both writes.
    AfterWrites,
}

#[test]
fn a_copy_after_a_crash_mid_command_is_never_run_again_nor_acknowledged_falsely() {
    // Operational from Standby is accepted; Stop in Standby is refused (nothing to stop).
    for command in [Command::Mode(Mode::Operational), Command::Stop] {
        for cut in [Cut::BeforeTick, Cut::BeforeWrite, Cut::AfterWrites] {
            let mut up = Uplink::new(uplink::Config::default(), BoardNumber::ONE);
            let seq = up.submit(command).unwrap();
            let packet = up.tick(0).send.unwrap().to_bytes();
            let mut a = BoardA::new(Config::default());
            let mut flash = a.ahead(Some(&packet)).expect("a new sequenced command");
            assert_eq!(flash.outcome, Some(Refusal::Restarted), "the ahead record");
            let mut ran = None;
            if cut != Cut::BeforeTick {
                let out = a.tick(
                    0,
                    &Inputs {
                        command: Some(packet),
                        ..Inputs::at_home()
                    },
                );
                ran = out.events.iter().find_map(|e| match e {
                    Event::Executed {
                        seq: s, refusal, ..
                    } if *s == seq => Some(*refusal),
                    _ => None,
                });
                if cut == Cut::AfterWrites {
                    flash = a.durable();
                }
            }
            // Power cut; board A boots from flash and the uplink's resend (the same packet)
            // arrives.
            let mut a = BoardA::restarted(Config::default(), Some(flash), ResetCause::PowerOn);
            let out = a.tick(
                10,
                &Inputs {
                    command: Some(packet),
                    ..Inputs::at_home()
                },
            );
            let what = format!("{command:?} cut {cut:?}");
            assert!(
                !out.events
                    .iter()
                    .any(|e| matches!(e, Event::Executed { .. })),
                "{what}: run again"
            );
            let hb = HeartbeatRepr::parse(&out.heartbeat.unwrap()).unwrap();
            assert_eq!(hb.last_seq, seq, "{what}");
            let done = up.heartbeat(20, &hb).done.expect("the copy is answered");
            let want = match (cut, ran) {
                (Cut::AfterWrites, Some(None)) => Outcome::Accepted,
                (Cut::AfterWrites, Some(Some(r))) => Outcome::Refused(r),
                // Not known whether it ran: unknown, never "accepted".
                _ => Outcome::Unacknowledged,
            };
            assert_eq!(done.outcome, want, "{what} (first run: {ran:?})");
        }
    }
}

/// The five-octet record reads back as written, for every outcome; an outcome byte that is
/// no refusal code reads back as nothing (the shell then boots as from a fresh flash).
#[test]
fn the_durable_record_round_trips_and_refuses_an_unknown_outcome() {
    use mmic::node::robot::board_a::Durable;
    let outcomes = std::iter::once(None).chain(Refusal::ALL.into_iter().map(Some));
    for (i, outcome) in outcomes.enumerate() {
        let d = Durable {
            last_seq: 0x1234u16.wrapping_add(i as u16),
            outcome,
            boots: 0xfe01,
        };
        let b = d.to_bytes();
        assert_eq!(b[2], outcome.map_or(0, Refusal::to_wire));
        assert_eq!(
            [b[0], b[1], b[3], b[4]],
            [0x34u8.wrapping_add(i as u8), 0x12, 0x01, 0xfe]
        );
        assert_eq!(Durable::from_bytes(&b), Some(d));
    }
    let unknown = (1..=u8::MAX)
        .find(|x| Refusal::from_wire(*x).is_none())
        .unwrap();
    assert_eq!(Durable::from_bytes(&[1, 0, unknown, 2, 0]), None);
}

/// Nothing is written ahead for a packet board A will not run: another robot's command, a
/// packet failing its check, or no packet at all; a new command of its own is.
// req: D:restart-board-a
#[test]
fn nothing_is_written_ahead_for_a_packet_board_a_does_not_run() {
    let a = BoardA::new(Config::default());
    let ours = |board: u8| {
        let mut up = Uplink::new(uplink::Config::default(), BoardNumber::new(board).unwrap());
        up.submit(Command::Stop).unwrap();
        up.tick(0).send.unwrap().to_bytes()
    };
    assert!(
        a.ahead(Some(&ours(1))).is_some(),
        "a new command of its own"
    );
    assert_eq!(a.ahead(Some(&ours(2))), None, "another robot's");
    let mut broken = ours(1);
    broken[3] ^= 0x10;
    assert_eq!(a.ahead(Some(&broken)), None, "a packet failing its check");
    assert_eq!(a.ahead(None), None, "no packet");
}
