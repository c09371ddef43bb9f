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
