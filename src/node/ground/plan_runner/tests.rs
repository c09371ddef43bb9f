use super::*;
use crate::command::Reconfiguration;
use crate::motion::State;
use crate::wire::command::CommandRepr;

/// A settled robot in `mode` answering `sent`.
fn answer(sent: &CommandRepr, mode: Mode) -> HeartbeatRepr {
    HeartbeatRepr {
        last_seq: sent.seq,
        mode,
        ..HeartbeatRepr::default()
    }
}

/// Ticks every 100 ms from `from` until a packet goes out; answers it 20 ms later as a
/// settled robot in `mode` would. Returns what went out and the answer's tick.
fn exchange(
    run: &mut PlanRunner,
    steps: &[PlanStep],
    from: u32,
    mode: Mode,
) -> (u32, Option<CommandRepr>, PlanTick) {
    let mut now = from;
    while now < from + 10_000 {
        if let Some(p) = run.tick(steps, now).send {
            let t = run.heartbeat(steps, now + 20, &answer(&p, mode));
            return (now + 20, Some(p), t);
        }
        now += 100;
    }
    (now, None, PlanTick::default())
}

#[test]
fn an_interjection_takes_the_next_slot_ahead_of_the_next_step_and_of_polling() {
    let steps = [
        PlanStep::Command(Command::Mode(Mode::Operational)),
        PlanStep::Wait { ms: 3000 },
        PlanStep::Command(Command::Mode(Mode::Standby)),
    ];
    let mut run = PlanRunner::new(uplink::Config::default(), BoardNumber::ONE);
    let first = run.tick(&steps, 0).send;
    assert_eq!(first.map(|p| p.command), Some(steps_command(&steps[0])));
    // Interjected while the step's command is outstanding: it waits for that answer.
    assert_eq!(run.interject(Command::SystemFault), Ok(()));
    assert_eq!(run.tick(&steps, 50).send, None, "one command outstanding");
    let hb = first.map(|p| answer(&p, Mode::Operational));
    let done = hb.and_then(|hb| run.heartbeat(&steps, 60, &hb).done);
    assert_eq!(done.map(|d| d.outcome), Some(Outcome::Accepted));
    // The mode step settles by polling; the interjection goes out in the next slot
    // instead of that poll, with the next number.
    let (now, sent, t) = exchange(&mut run, &steps, 100, Mode::Operational);
    assert_eq!(sent.map(|p| p.command), Some(Command::SystemFault));
    assert_eq!(sent.map(|p| p.seq), first.map(|p| p.seq + 1));
    assert_eq!(t.done.map(|d| d.command), Some(Command::SystemFault));
    assert_eq!(run.interjections_waiting(), 0);
    assert_eq!(run.step(), 0, "its answer does not advance the plan");
    // Then polling resumes and the plan runs to its end, each number once.
    let mut seqs = heapless::Vec::<u16, 64>::new();
    for p in [first, sent].into_iter().flatten() {
        let _ = seqs.push(p.seq);
    }
    let mut now = now;
    while run.end().is_none() && now < 60_000 {
        let (t, p, _) = exchange(&mut run, &steps, now + 100, Mode::Operational);
        if let Some(p) = p {
            let _ = seqs.push(p.seq);
        }
        now = t;
    }
    assert_eq!(run.end(), Some(PlanEnd::Completed));
    assert!(seqs.windows(2).all(|w| w[1] == w[0] + 1), "{seqs:?}");
}

fn steps_command(s: &PlanStep) -> Command {
    match s {
        PlanStep::Command(c) => *c,
        PlanStep::Wait { .. } => Command::Heartbeat,
    }
}

#[test]
fn an_accepted_stop_holds_the_plan_until_an_accepted_reset() {
    let steps = [
        PlanStep::Wait { ms: 1000 },
        PlanStep::Command(Command::Mode(Mode::Standby)),
    ];
    let mut run = PlanRunner::new(uplink::Config::default(), BoardNumber::ONE);
    // The wait starts and polls; the Stop goes out in the next slot.
    let (now, sent, _) = exchange(&mut run, &steps, 0, Mode::Operational);
    assert_eq!(sent.map(|p| p.command), Some(Command::Heartbeat));
    assert_eq!(run.interject(Command::Stop), Ok(()));
    let (now, sent, _) = exchange(&mut run, &steps, now + 100, Mode::Operational);
    assert_eq!(sent.map(|p| p.command), Some(Command::Stop));
    assert!(run.held());
    // The wait ends, but no step starts while held: only polls go out.
    let mut now = now;
    for _ in 0..5 {
        let (t, sent, _) = exchange(&mut run, &steps, now + 100, Mode::Operational);
        assert_eq!(sent.map(|p| p.command), Some(Command::Heartbeat));
        now = t;
    }
    assert_eq!(run.step(), 1);
    assert_eq!(run.interject(Command::Reset), Ok(()));
    let (now, sent, _) = exchange(&mut run, &steps, now + 100, Mode::Operational);
    assert_eq!(sent.map(|p| p.command), Some(Command::Reset));
    assert!(!run.held());
    let (_, sent, _) = exchange(&mut run, &steps, now + 100, Mode::Operational);
    assert_eq!(sent.map(|p| p.command), Some(Command::Mode(Mode::Standby)));
}

#[test]
fn a_held_motion_does_not_count_as_settled() {
    let steps = [
        PlanStep::Command(Command::Arm {
            side: crate::units::Side::A,
            target: crate::command::ServoTarget::Contract,
        }),
        PlanStep::Command(Command::Mode(Mode::Standby)),
    ];
    let mut run = PlanRunner::new(uplink::Config::default(), BoardNumber::ONE);
    let (now, _, _) = exchange(&mut run, &steps, 0, Mode::Operational);
    assert_eq!(run.interject(Command::Stop), Ok(()));
    let (now, sent, _) = exchange(&mut run, &steps, now + 100, Mode::Operational);
    assert_eq!(sent.map(|p| p.command), Some(Command::Stop));
    // Settled-looking answers while stopped: the step is not finished.
    let mut now = now;
    for _ in 0..3 {
        now = exchange(&mut run, &steps, now + 100, Mode::Operational).0;
    }
    assert_eq!(run.step(), 0);
    assert_eq!(run.interject(Command::Reset), Ok(()));
    let (now, _, _) = exchange(&mut run, &steps, now + 100, Mode::Operational);
    let (_, _, _) = exchange(&mut run, &steps, now + 100, Mode::Operational);
    assert_eq!(run.step(), 1, "settled after the reset");
}

#[test]
fn interjections_are_handed_back_when_full_or_after_the_end_never_dropped() {
    let mut run = PlanRunner::new(uplink::Config::default(), BoardNumber::ONE);
    for _ in 0..INTERJECTIONS {
        assert_eq!(run.interject(Command::SystemFault), Ok(()));
    }
    assert_eq!(
        run.interject(Command::Stop),
        Err(InterjectError::Full {
            command: Command::Stop,
            waiting: INTERJECTIONS
        })
    );
    // Every waiting one goes out, in order, before the (empty) plan completes.
    let mut sent = 0;
    let mut now = 0;
    while run.end().is_none() && now < 60_000 {
        let (t, p, _) = exchange(&mut run, &[], now, Mode::Standby);
        sent += p.is_some() as usize;
        now = t + 100;
        if p.is_none() {
            run.tick(&[], now);
        }
    }
    assert_eq!(sent, INTERJECTIONS);
    assert_eq!(run.end(), Some(PlanEnd::Completed));
    assert_eq!(
        run.interject(Command::Reset),
        Err(InterjectError::Ended {
            command: Command::Reset,
            end: PlanEnd::Completed
        })
    );
}

#[test]
fn an_unacknowledged_interjection_ends_the_plan() {
    let cfg = uplink::Config {
        max_attempts: 2,
        ..uplink::Config::default()
    };
    let steps = [PlanStep::Wait { ms: 60_000 }];
    let mut run = PlanRunner::new(cfg, BoardNumber::ONE);
    assert_eq!(run.interject(Command::Stop), Ok(()));
    let mut end = None;
    for now in (0..20_000).step_by(100) {
        end = end.or(run.tick(&steps, now).end);
    }
    assert_eq!(end, Some(PlanEnd::Unacknowledged { step: 0 }));
}

#[test]
fn a_misstated_reconfiguration_goes_out_once_with_a_wrong_initial_state(
) -> Result<(), crate::command::ReconfigurationError> {
    let a_m = Reconfiguration::new(State::A, State::M)?;
    let m_b = Reconfiguration::new(State::M, State::B)?;
    let steps = [
        PlanStep::Command(Command::Mode(Mode::Operational)),
        PlanStep::Command(Command::Reconfigure(a_m)),
        PlanStep::Command(Command::Reconfigure(m_b)),
    ];
    let mut run = PlanRunner::new(uplink::Config::default(), BoardNumber::ONE);
    run.misstate_next_reconfiguration();
    let mut reconfigurations = heapless::Vec::<Reconfiguration, 8>::new();
    let mut now = 0;
    while run.end().is_none() && now < 60_000 {
        let (t, p, _) = exchange(&mut run, &steps, now, Mode::Operational);
        if let Some(Command::Reconfigure(r)) = p.map(|p| p.command) {
            let _ = reconfigurations.push(r);
        }
        now = t + 100;
    }
    assert_eq!(reconfigurations.len(), 2, "{reconfigurations:?}");
    assert_eq!(reconfigurations[0], misstated(a_m));
    assert_ne!(reconfigurations[0].initial(), State::A);
    assert_eq!(reconfigurations[0].target(), State::M);
    assert_eq!(reconfigurations[1], m_b, "only the next one");
    Ok(())
}

#[test]
fn a_restarted_ground_goes_on_between_steps_and_ends_an_open_step_as_restarted() {
    let steps = [
        PlanStep::Command(Command::Mode(Mode::Operational)),
        PlanStep::Wait { ms: 3000 },
        PlanStep::Command(Command::Mode(Mode::Standby)),
    ];
    let cfg = uplink::Config::default();
    let fresh = |run: &PlanRunner| {
        let up = Uplink::starting_at(cfg, BoardNumber::ONE, run.uplink().next_seq());
        PlanRunner::restarted(up, run.kept())
    };
    let mut run = PlanRunner::new(cfg, BoardNumber::ONE);
    // Before anything was sent: the plan starts over at step 0, numbered as before.
    assert_eq!(fresh(&run).end(), None);
    assert_eq!(fresh(&run).step(), 0);
    // Step 0 outstanding: unknown, the plan ends there and nothing goes out again.
    let sent = run.tick(&steps, 0).send.unwrap();
    let mut again = fresh(&run);
    assert_eq!(again.end(), Some(PlanEnd::Restarted { step: 0 }));
    assert_eq!(again.tick(&steps, 5000).send, None);
    // Accepted, and the wait of step 1 running: the plan goes on at step 1, numbering past
    // every number given out before; an interjection still waiting is kept and sent first.
    run.heartbeat(&steps, 20, &answer(&sent, Mode::Operational));
    // Settling (polls) is open too.
    assert_eq!(fresh(&run).end(), Some(PlanEnd::Restarted { step: 0 }));
    let mut now = 100;
    while run.step() == 0 {
        now = exchange(&mut run, &steps, now, Mode::Operational).0 + 100;
    }
    assert_eq!(run.step(), 1);
    run.interject(Command::Stop).unwrap();
    let mut again = fresh(&run);
    assert_eq!((again.step(), again.end()), (1, None));
    let first = again.tick(&steps, now).send.unwrap();
    assert_eq!(first.command, Command::Stop);
    assert!(first.seq > sent.seq);
    // An ended plan stays ended.
    let mut ended = PlanRunner::new(cfg, BoardNumber::ONE);
    let (_, _, t) = exchange(&mut ended, &[steps[0]], 0, Mode::Operational);
    assert!(t.end.is_none());
    let _ = exchange(&mut ended, &[steps[0]], 200, Mode::Operational);
    ended.tick(&[steps[0]], 400);
    let end = ended.end();
    assert_eq!(fresh(&ended).end(), end);
}

/// A link that reports motions' ends (as the PUS and frame links do), scripted by the test:
/// the outstanding command is answered with `answer` at the next tick, and `end` is reported
/// at the tick after it is set.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
struct Scripted {
    out: Option<(u16, Command)>,
    next: u16,
    answer: Option<Outcome>,
    end: Option<(u16, MotionEnd)>,
}

impl Scripted {
    const fn new() -> Scripted {
        Scripted {
            out: None,
            next: 1,
            answer: None,
            end: None,
        }
    }
}

impl Link for Scripted {
    type Packet = u16;
    const POLLS: bool = false;

    fn is_idle(&self) -> bool {
        self.out.is_none()
    }

    fn submit(&mut self, command: Command) -> Option<u16> {
        if self.out.is_some() {
            return None;
        }
        let seq = self.next;
        self.next += 1;
        self.out = Some((seq, command));
        Some(seq)
    }

    fn tick(&mut self, _now: u32) -> LinkTick<u16> {
        let mut t = LinkTick {
            ended: self.end.take(),
            ..LinkTick::default()
        };
        if let (Some((seq, command)), Some(outcome)) = (self.out, self.answer.take()) {
            self.out = None;
            t.done = Some(Done {
                seq,
                command,
                outcome,
                attempts: 1,
            });
        } else {
            t.send = self.out.map(|(seq, _)| seq);
        }
        t
    }
}

fn arm_extend() -> Command {
    Command::Arm {
        side: crate::units::Side::A,
        target: crate::command::ServoTarget::Extend,
    }
}

/// Ticks the runner until its outstanding command is `c`, answers it accepted; its number.
/// (`cfg(test)` again: the coding standard's scan reads this file on its own.)
#[cfg(test)]
fn accept(run: &mut PlanRunner<Scripted>, steps: &[PlanStep], c: Command) -> u16 {
    let t = run.tick(steps, 0);
    let seq = t.send.unwrap_or(0);
    assert_eq!(run.uplink().out, Some((seq, c)));
    run.up.answer = Some(Outcome::Accepted);
    let t = run.tick(steps, 10);
    assert_eq!(
        t.done.map(|d| (d.seq, d.outcome)),
        Some((seq, Outcome::Accepted))
    );
    seq
}

/// Over a link that reports motions' ends: a motion step is done when the link reports its
/// end (the next step goes out then), not at an end reported for another number or before
/// its start was accepted.
#[test]
fn a_motion_step_is_done_at_its_own_end_reported_by_the_link() {
    let steps = [
        PlanStep::Command(arm_extend()),
        PlanStep::Command(Command::Mode(Mode::Standby)),
    ];
    let mut run = PlanRunner::over(Scripted::new());
    assert_eq!(run.tick(&steps, 0).send, Some(1));
    // An end before the start was answered: the step is not settling yet, nothing moves on.
    run.up.end = Some((1, MotionEnd::Completed));
    run.tick(&steps, 5);
    assert_eq!(run.step(), 0);
    run.up.answer = Some(Outcome::Accepted);
    run.tick(&steps, 10);
    // Another number's end.
    run.up.end = Some((7, MotionEnd::Completed));
    assert_eq!(run.tick(&steps, 20).send, None);
    assert_eq!(run.step(), 0);
    // Its own end: done, and the next step goes out at the next tick.
    run.up.end = Some((1, MotionEnd::Completed));
    run.tick(&steps, 30);
    assert_eq!(run.step(), 1);
    assert_eq!(run.tick(&steps, 40).send, Some(2));
    assert_eq!(run.uplink().out, Some((2, Command::Mode(Mode::Standby))));
}

/// A motion's end that came while a Stop held the plan: the step is done once the Reset is
/// accepted, not before.
#[test]
fn a_motion_that_ended_while_held_is_done_after_the_reset() {
    let steps = [
        PlanStep::Command(arm_extend()),
        PlanStep::Command(Command::Mode(Mode::Standby)),
    ];
    let mut run = PlanRunner::over(Scripted::new());
    let seq = accept(&mut run, &steps, arm_extend());
    assert_eq!(run.interject(Command::Stop), Ok(()));
    accept(&mut run, &steps, Command::Stop);
    assert!(run.held());
    run.up.end = Some((seq, MotionEnd::Completed));
    for now in [20, 30, 40] {
        assert_eq!(run.tick(&steps, now).send, None);
    }
    assert_eq!(run.step(), 0, "held: the ended step is not done");
    assert_eq!(run.interject(Command::Reset), Ok(()));
    accept(&mut run, &steps, Command::Reset);
    assert!(!run.held());
    run.tick(&steps, 50);
    assert_eq!(run.step(), 1);
    assert_eq!(
        run.uplink().out.map(|(_, c)| c),
        Some(Command::Mode(Mode::Standby))
    );
}

/// A mode step's reported end does not finish it (it waits for a settled status), and a
/// motion whose end the link never heard ends the plan as unacknowledged at that step.
#[test]
fn a_mode_step_waits_for_its_status_and_an_unheard_end_ends_the_plan() {
    let steps = [PlanStep::Command(Command::Mode(Mode::Operational))];
    let mut run = PlanRunner::over(Scripted::new());
    let seq = accept(&mut run, &steps, Command::Mode(Mode::Operational));
    run.up.end = Some((seq, MotionEnd::Completed));
    run.tick(&steps, 20);
    assert_eq!((run.step(), run.end()), (0, None));

    let steps = [PlanStep::Command(arm_extend())];
    let mut run = PlanRunner::over(Scripted::new());
    let seq = accept(&mut run, &steps, arm_extend());
    run.up.end = Some((seq, MotionEnd::Unacknowledged));
    let t = run.tick(&steps, 20);
    assert_eq!(t.end, Some(PlanEnd::Unacknowledged { step: 0 }));
}

/// A step that neither moves nor changes the mode is done when accepted: the next step goes
/// out in the next slot, no poll in between.
#[test]
fn a_step_that_does_not_move_is_done_when_accepted() {
    let steps = [
        PlanStep::Command(Command::ClearFaults),
        PlanStep::Command(Command::Mode(Mode::Standby)),
    ];
    let mut run = PlanRunner::new(uplink::Config::default(), BoardNumber::ONE);
    let (now, sent, t) = exchange(&mut run, &steps, 0, Mode::Operational);
    assert_eq!(sent.map(|p| p.command), Some(Command::ClearFaults));
    assert_eq!(t.done.map(|d| d.outcome), Some(Outcome::Accepted));
    assert_eq!(run.step(), 1);
    let (_, sent, _) = exchange(&mut run, &steps, now + 100, Mode::Operational);
    assert_eq!(sent.map(|p| p.command), Some(Command::Mode(Mode::Standby)));
}

/// Over PUS: a step whose telecommand the gateway rejects at acceptance (a failure code that
/// is no refusal of board A) ends the plan as rejected, with the gateway's code; a rejection
/// of a telecommand that is not the runner's does not.
#[test]
fn a_step_rejected_at_acceptance_over_pus_ends_the_plan_as_rejected() {
    use crate::node::ground::pus;
    use crate::pus::request::ST_VERIFICATION;
    use crate::pus::verification::{Failure, Report, Stage, FAILURE_LEN};
    let steps = [PlanStep::Command(Command::Mode(Mode::Operational))];
    let mut run = PlanRunner::pus(pus::Config::default(), BoardNumber::ONE);
    let tc = run.tick(&steps, 0).send.map(|p| p.request);
    let Some(request) = tc else {
        panic!("the step's telecommand goes out");
    };
    let rejected = |seq_count| Report {
        stage: Stage::Acceptance,
        request: crate::pus::verification::RequestId {
            seq_count,
            ..request
        },
        failure: Some(Failure {
            code: 0x0005,
            data: 0,
        }),
    };
    let mut buf = [0u8; FAILURE_LEN];
    let other = rejected(request.seq_count + 1);
    let n = other.emit(&mut buf);
    let t = run.telemetry(&steps, 10, ST_VERIFICATION, other.subservice(), &buf[..n]);
    assert_eq!(t.end, None, "not the runner's telecommand");
    let ours = rejected(request.seq_count);
    let n = ours.emit(&mut buf);
    let t = run.telemetry(&steps, 20, ST_VERIFICATION, ours.subservice(), &buf[..n]);
    assert_eq!(
        t.end,
        Some(PlanEnd::Rejected {
            step: 0,
            code: 0x0005
        })
    );
}
