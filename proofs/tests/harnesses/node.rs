//! The nodes' commanding pieces over arbitrary inputs of fixed length: board A's
//! exactly-once log, the ground's uplink, the server's pending slots and the two-core hand-off
//! queue. Under `cargo test`: random inputs; `cargo bolero test`: fuzzing; `cargo kani --tests`:
//! proofs over all inputs of the fixed length (Kani not run here).

use mmic::command::Command;
use mmic::node::exactly_once::uplink::{Config, Outcome, Uplink};
use mmic::node::exactly_once::{newer, Admission, CommandLog};
use mmic::node::robot::handoff::PacketQueue;
use mmic::node::server::relay::{Accepted, Server};
use mmic::refusal::Refusal;
use mmic::units::BoardNumber;
use mmic::wire::command::CommandRepr;
use mmic::wire::heartbeat::HeartbeatRepr;

const N: usize = 8;

/// Whatever order copies arrive in (duplicated, reordered, late), board A's log runs each
/// sequence number at most once, and the number it reports is the newest it ran.
///
/// Under `cargo test`: exhaustively, every sequence of 7 arrivals of 5 consecutive numbers
/// (duplicates, reorders and stale copies of each kind) from 6 bases — 0, 1, the half range,
/// and 4, 2 and 1 below the u16 wrap, so that the skipped number 0 falls at each position;
/// then sampled inputs.
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(10))]
fn the_command_log_runs_each_number_at_most_once() {
    #[cfg(not(any(kani, fuzzing)))]
    {
        const BASE: [u16; 6] = [0, 1, 0x7ffe, 0xfffc, 0xfffe, 0xffff];
        let name = "the_command_log_runs_each_number_at_most_once";
        crate::ledger::exhaustive(
            name,
            6 * 5u64.pow(7),
            (0usize..6, crate::ledger::seq::<_, 7>(0u8..5)),
            |(b, arrivals)| command_log(BASE[*b], arrivals),
        );
        crate::ledger::sampled::<(u16, [u8; N])>(name, 200_000, |(base, arrivals)| {
            command_log(*base, arrivals)
        });
        return;
    }
    #[allow(unreachable_code)]
    bolero::check!()
        .with_type::<(u16, [u8; N])>()
        .for_each(|(base, arrivals)| command_log(*base, arrivals));
}

/// The property of [`the_command_log_runs_each_number_at_most_once`].
fn command_log(base: u16, arrivals: &[u8]) {
    let base = &base;
    let mut log = CommandLog::new();
    let mut ran = [false; 16];
    let mut newest: Option<u16> = None;
    for &a in arrivals.iter() {
        // Copies of 16 consecutive numbers (the ground's numbering, wrap included);
        // 0 is never a sequenced number: the ground skips it.
        let seq = base.wrapping_add((a % 16) as u16);
        if seq == 0 {
            continue;
        }
        let k = seq.wrapping_sub(*base) as usize % 16;
        match log.admit(seq) {
            Admission::Execute => {
                assert!(!ran[k], "{seq} ran twice");
                ran[k] = true;
                assert!(newest.is_none_or(|n| newer(seq, n)));
                newest = Some(seq);
                log.record(seq, None);
            }
            Admission::Duplicate => assert_eq!(Some(seq), newest),
            Admission::Stale => assert!(newest.is_some_and(|n| newer(n, seq))),
        }
        assert_eq!(log.last().0, newest.unwrap_or(0));
    }
}

/// The uplink under arbitrary time steps and heartbeats (any robot, any number, any refusal):
/// one command outstanding at a time, transmissions carry only its number, no more than
/// `max_attempts` transmissions, and every submitted command ends exactly once — acknowledged
/// only by a heartbeat carrying its number.
///
/// Under `cargo test`: exhaustively, every sequence of 6 events over 12 letters — a tick after
/// 0, 699, 700, 701 or 1200 ms (the timeout and the period, the timeout ±1), a heartbeat from
/// this robot carrying the outstanding number minus one, itself or plus one, with and without a
/// refusal, and one from another robot carrying the outstanding number; then sampled inputs.
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(10))]
fn the_uplink_ends_every_command_exactly_once() {
    #[cfg(not(any(kani, fuzzing)))]
    {
        // (dt, what, board, refusal) of each letter: `what` even = tick; odd = heartbeat whose
        // number is the outstanding one plus (what / 2 % 3) - 1; board 0 = this robot.
        const LETTER: [(u16, u8, u8, u8); 12] = [
            (0, 0, 0, 0),
            (699, 0, 0, 0),
            (700, 0, 0, 0),
            (701, 0, 0, 0),
            (1200, 0, 0, 0),
            (0, 1, 0, 0),
            (0, 3, 0, 0),
            (0, 5, 0, 0),
            (0, 1, 0, 3),
            (0, 3, 0, 3),
            (0, 5, 0, 3),
            (0, 3, 1, 0),
        ];
        let name = "the_uplink_ends_every_command_exactly_once";
        crate::ledger::exhaustive(
            name,
            12u64.pow(6),
            crate::ledger::seq::<_, 6>(0usize..12),
            |letters| uplink(&letters.map(|l| LETTER[l])),
        );
        crate::ledger::sampled::<[(u16, u8, u8, u8); N]>(name, 200_000, |events| uplink(events));
        return;
    }
    #[allow(unreachable_code)]
    bolero::check!()
        .with_type::<[(u16, u8, u8, u8); N]>()
        .for_each(|events| uplink(events));
}

/// The property of [`the_uplink_ends_every_command_exactly_once`].
fn uplink(events: &[(u16, u8, u8, u8)]) {
    let cfg = Config {
        period_ms: 1200,
        timeout_ms: 700,
        max_attempts: 3,
    };
    let mut up = Uplink::new(cfg, BoardNumber::ONE);
    let mut now = 0u32;
    let mut submitted: Option<u16> = None;
    let mut sends = 0u8;
    let mut ended = 0u32;
    let mut submissions = 0u32;
    for &(dt, what, board, refusal) in events.iter() {
        now = now.wrapping_add(dt as u32);
        if up.is_idle() {
            if let Ok(seq) = up.submit(Command::Stop) {
                assert!(seq != 0 && Some(seq) != submitted);
                submitted = Some(seq);
                sends = 0;
                submissions += 1;
            }
        } else {
            assert!(up.submit(Command::Reset).is_err(), "one at a time");
        }
        let t = if what % 2 == 0 {
            up.tick(now)
        } else {
            // A heartbeat for the outstanding number, a neighbour, or another robot.
            let seq = submitted
                .unwrap_or(0)
                .wrapping_add((what / 2 % 3) as u16)
                .wrapping_sub(1);
            let hb = HeartbeatRepr {
                board: BoardNumber::new(1 + board % 2).unwrap_or(BoardNumber::ONE),
                last_seq: seq,
                refusal: Refusal::from_wire(refusal % 8),
                ..HeartbeatRepr::default()
            };
            let t = up.heartbeat(now, &hb);
            if let Some(d) = t.done {
                assert!(hb.board == BoardNumber::ONE && hb.last_seq == d.seq);
                let want = match hb.refusal {
                    None => Outcome::Accepted,
                    Some(r) => Outcome::Refused(r),
                };
                assert_eq!(d.outcome, want);
            }
            t
        };
        if let Some(p) = t.send {
            assert_eq!(Some(p.seq), submitted);
            sends += 1;
            assert!(sends <= cfg.max_attempts);
        }
        if let Some(d) = t.done {
            assert_eq!(Some(d.seq), submitted);
            assert_eq!(d.attempts, sends);
            ended += 1;
            assert!(up.is_idle());
        }
        let (ok, n) = up.efficiency().counts();
        assert!(ok <= n && n <= 100);
    }
    assert!(ended == submissions || ended + 1 == submissions);
}

/// The server's slots under arbitrary accepts, visits and deliveries: a pending packet leaves
/// only when delivered or handed back as superseded, and a visit offers only pending packets.
///
/// Under `cargo test`: exhaustively, every sequence of 5 operations over 18 letters: accept /
/// visit / deliver × robot 1..=3 × number 1 or 2 (the generator's third number behaves as the
/// second: a different number from the same robot): enough to fill both slots, be refused,
/// resend, hand a packet back and deliver; then sampled inputs.
// req: P3.6
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(10))]
fn the_server_never_drops_a_pending_command_silently() {
    #[cfg(not(any(kani, fuzzing)))]
    {
        let name = "the_server_never_drops_a_pending_command_silently";
        crate::ledger::exhaustive(
            name,
            18u64.pow(5),
            crate::ledger::seq::<_, 5>((0u8..3, 0u8..3, 0u8..2)),
            |ops| server(ops),
        );
        crate::ledger::sampled::<[(u8, u8, u8); N]>(name, 200_000, |ops| server(ops));
        return;
    }
    #[allow(unreachable_code)]
    bolero::check!()
        .with_type::<[(u8, u8, u8); N]>()
        .for_each(|ops| server(ops));
}

/// The property of [`the_server_never_drops_a_pending_command_silently`].
fn server(ops: &[(u8, u8, u8)]) {
    let mut s: Server<2> = Server::new();
    // Shadow: robot (1..=3) -> pending packet.
    let mut shadow: [Option<[u8; 14]>; 4] = [None; 4];
    for &(op, robot, seq) in ops.iter() {
        let r = 1 + robot % 3;
        let board = BoardNumber::new(r).unwrap_or(BoardNumber::ONE);
        let packet = CommandRepr {
            board,
            command: Command::Heartbeat,
            seq: 1 + (seq % 3) as u16,
        }
        .to_bytes();
        match op % 3 {
            0 => match s.accept(&packet) {
                Ok(a) => {
                    let old = shadow[r as usize].replace(packet);
                    match a {
                        Accepted::Queued => assert_eq!(old, None),
                        Accepted::Resend => assert_eq!(old, Some(packet)),
                        Accepted::Superseded(p) => assert_eq!(old, Some(p)),
                    }
                }
                Err(_) => {
                    // Full: only when two other robots hold pending packets.
                    let others = (1..=3usize)
                        .filter(|&k| k != r as usize && shadow[k].is_some())
                        .count();
                    assert_eq!(others, 2);
                }
            },
            1 => {
                if let Some((b, p)) = s.next_visit() {
                    assert_eq!(shadow[b.get() as usize], Some(p));
                } else {
                    assert!(shadow.iter().all(|p| p.is_none()));
                }
            }
            _ => {
                s.delivered(board, &packet);
                if shadow[r as usize] == Some(packet) {
                    shadow[r as usize] = None;
                }
            }
        }
        for k in 1..=3u8 {
            let b = BoardNumber::new(k).unwrap_or(BoardNumber::ONE);
            assert_eq!(s.pending(b), shadow[k as usize]);
        }
    }
}

/// The hand-off queue against a FIFO model (one thread): every packet pushed is popped once,
/// in order, byte for byte; a full queue hands the packet back.
///
/// Under `cargo test`: exhaustively, every sequence of 8 operations (the harness's length)
/// over pop and push of 3 distinct packets: fills, overflows and drains at every position;
/// then sampled inputs.
// req: P3.18
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(10))]
fn the_handoff_queue_is_a_fifo_that_hands_back_when_full() {
    #[cfg(not(any(kani, fuzzing)))]
    {
        let name = "the_handoff_queue_is_a_fifo_that_hands_back_when_full";
        crate::ledger::exhaustive(
            name,
            6u64.pow(8),
            crate::ledger::seq::<_, N>((bolero::produce::<bool>(), 0u8..3)),
            |ops| handoff(ops),
        );
        crate::ledger::sampled::<[(bool, u8); N]>(name, 200_000, |ops| handoff(ops));
        return;
    }
    #[allow(unreachable_code)]
    bolero::check!()
        .with_type::<[(bool, u8); N]>()
        .for_each(|ops| handoff(ops));
}

/// The property of [`the_handoff_queue_is_a_fifo_that_hands_back_when_full`].
fn handoff(ops: &[(bool, u8)]) {
    let mut q: PacketQueue<14, 4> = PacketQueue::new();
    let (mut p, mut c) = q.split();
    let mut model = [[0u8; 14]; N];
    let (mut head, mut tail) = (0usize, 0usize);
    for &(push, v) in ops.iter() {
        if push {
            let packet = [v; 14];
            match p.push(packet) {
                Ok(()) => {
                    model[tail] = packet;
                    tail += 1;
                }
                Err(back) => {
                    assert_eq!(back.0, packet);
                    assert_eq!(tail - head, 3, "full means N - 1 = 3 waiting");
                }
            }
        } else {
            let got = c.pop();
            if head < tail {
                assert_eq!(got, Some(model[head]));
                head += 1;
            } else {
                assert_eq!(got, None);
            }
        }
        assert_eq!(c.len(), tail - head);
    }
}
