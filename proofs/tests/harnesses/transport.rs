//! The transports' session machines over arbitrary event sequences: board A's WiFi session
//! (`node::robot::wifi_session`) and the server board's visit (`node::server::visit`), each against a model
//! written from its module's rules. Under `cargo test`: exhaustive and sampled parts (see the
//! ledger); `cargo bolero test`: fuzzing; `cargo kani --tests`: proofs (Kani not run here).

use mmic::command::Command;
use mmic::node::robot::wifi_session::{Outgoing, WifiConfig, WifiSession};
use mmic::node::server::visit::Visit;
use mmic::units::BoardNumber;
use mmic::wire::command::{CommandRepr, COMMAND_LEN};
use mmic::wire::heartbeat::{HeartbeatRepr, HEARTBEAT_LEN};

/// Events per run of the WiFi session.
const N: usize = 5;
/// Reads per visit.
const V: usize = 4;
/// The session's idle limit in the harness, ms.
const IDLE: u32 = 100;
/// Time steps an event may come after the last one, ms: none, one, and the idle limit ±1.
const DT: [u32; 4] = [0, 1, IDLE - 1, IDLE];
/// Read lengths: one byte, a cut packet, a whole packet, a packet and a half.
const READ: [usize; 4] = [1, 5, COMMAND_LEN, COMMAND_LEN + 7];
/// The clock starts shortly before the u32 wrap, so idleness is judged across it.
const T0: u32 = u32::MAX - 150;

/// Board A's WiFi session, any events: a heartbeat goes out exactly while a connection is
/// open (else it is dropped), every heartbeat is counted once either way; a connection's
/// stream of commands reaches the control task whole, one per 14 bytes read on that
/// connection, nothing of an earlier connection's cut packet and nothing read while closed;
/// the connection is expired exactly when it has been open `idle_ms` without bytes.
///
/// Under `cargo test`: exhaustively, every sequence of 5 events of 16 letters (open, close,
/// heartbeat, read of 1/5/14/21 bytes of a command stream; each after 0, 1, 99 or 100 ms,
/// the idle limit being 100 ms), from just before the u32 wrap; then sampled inputs.
// req: P3.14
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(40))]
fn the_wifi_session_sends_only_while_open_and_hands_on_whole_commands() {
    #[cfg(not(any(kani, fuzzing)))]
    {
        let name = "the_wifi_session_sends_only_while_open_and_hands_on_whole_commands";
        crate::ledger::exhaustive(
            name,
            16u64.pow(N as u32),
            crate::ledger::seq::<_, N>((0u8..4, 0u8..4)),
            |ops| wifi(ops),
        );
        crate::ledger::sampled::<[(u8, u8); N]>(name, 200_000, |ops| wifi(ops));
        return;
    }
    #[allow(unreachable_code)]
    bolero::check!()
        .with_type::<[(u8, u8); N]>()
        .for_each(|ops| wifi(ops));
}

/// The property of [`the_wifi_session_sends_only_while_open_and_hands_on_whole_commands`]:
/// event `(kind, arg)`, after `DT[arg % 4]` ms; kind % 4: open, close, heartbeat, read of
/// `READ[arg % 4]` bytes.
fn wifi(ops: &[(u8, u8)]) {
    let command = CommandRepr {
        board: BoardNumber::ONE,
        command: Command::Stop,
        seq: 7,
    }
    .to_bytes();
    let stream: [u8; 4 * COMMAND_LEN] = core::array::from_fn(|i| command[i % COMMAND_LEN]);
    let mut w = WifiSession::new(WifiConfig { idle_ms: IDLE });
    let mut now = T0;
    // The model: open since (last bytes), bytes of this connection's stream read so far.
    let (mut open, mut last, mut offset) = (false, T0, 0usize);
    let (mut heartbeats, mut handed) = (0u32, 0usize);
    for &(kind, arg) in ops.iter() {
        now = now.wrapping_add(DT[arg as usize % 4]);
        assert_eq!(w.expired(now), open && now.wrapping_sub(last) >= IDLE);
        match kind % 4 {
            0 => {
                let mut stale = 0;
                w.open(now, [[arg; HEARTBEAT_LEN]], |hb| {
                    assert_eq!(hb, [arg; HEARTBEAT_LEN]);
                    stale += 1;
                });
                assert_eq!(
                    stale, 1,
                    "a heartbeat queued before the connection is dropped"
                );
                heartbeats += 1;
                (open, last, offset) = (true, now, 0);
            }
            1 => {
                assert_eq!(w.close(), open);
                open = false;
            }
            2 => {
                let hb = [arg; HEARTBEAT_LEN];
                let expect = if open {
                    Outgoing::Send(hb)
                } else {
                    Outgoing::Drop(hb)
                };
                assert_eq!(w.heartbeat(hb), expect);
                heartbeats += 1;
            }
            _ => {
                let len = READ[arg as usize % 4].min(stream.len() - offset % COMMAND_LEN);
                let from = offset % COMMAND_LEN;
                let mut got = 0usize;
                w.received(now, &stream[from..from + len], |c| {
                    assert_eq!(c, command);
                    got += 1;
                });
                if open {
                    assert_eq!(got, (offset + len) / COMMAND_LEN - offset / COMMAND_LEN);
                    (last, offset) = (now, offset + len);
                } else {
                    assert_eq!(got, 0, "nothing is read while closed");
                }
                handed += got;
            }
        }
        assert_eq!(w.is_open(), open);
        let c = w.counts();
        assert_eq!(c.sent + c.unconnected, heartbeats);
        assert_eq!(c.commands as usize, handed);
        assert_eq!(c.other_kind, 0);
    }
}

/// The server board's visit, any reads and times: the answer is the first whole heartbeat of
/// the visit's stream, returned once, when its last byte is read (garbage and a command packet
/// before it are skipped); the visit may be waited on exactly until its deadline, `wait_ms`
/// after its start, or until answered.
///
/// Under `cargo test`: exhaustively, waits of 0, 1 and 200 ms from 2 starts (0 and 50 ms
/// before the u32 wrap) × every sequence of 4 events of 16 letters (read of 1, 9, 30 or 66
/// bytes of a stream of garbage, a command and two heartbeats; each after 0, 1, 99 or 100 ms);
/// then sampled inputs.
// req: P3.7, P3.8
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(40))]
fn the_visit_ends_at_its_first_heartbeat_or_its_deadline() {
    #[cfg(not(any(kani, fuzzing)))]
    {
        let name = "the_visit_ends_at_its_first_heartbeat_or_its_deadline";
        crate::ledger::exhaustive(
            name,
            6 * 16u64.pow(V as u32),
            (0u8..3, 0u8..2, crate::ledger::seq::<_, V>((0u8..4, 0u8..4))),
            |(w, s, ops)| visit(*w, *s, ops),
        );
        crate::ledger::sampled::<(u8, u8, [(u8, u8); V])>(name, 200_000, |(w, s, ops)| {
            visit(*w, *s, ops)
        });
        return;
    }
    #[allow(unreachable_code)]
    bolero::check!()
        .with_type::<(u8, u8, [(u8, u8); V])>()
        .for_each(|(w, s, ops)| visit(*w, *s, ops));
}

/// The property of [`the_visit_ends_at_its_first_heartbeat_or_its_deadline`]: wait
/// `[0, 1, 200][w % 3]` ms from start `[MAX - 50, 0][s % 2]`; event `(len, dt)` reads
/// `[1, 9, 30, 66][len % 4]` bytes after `DT[dt % 4]` ms.
fn visit(w: u8, s: u8, ops: &[(u8, u8)]) {
    let wait = [0, 1, 200][w as usize % 3];
    let start = [u32::MAX - 50, 0][s as usize % 2];
    let command = CommandRepr {
        board: BoardNumber::ONE,
        command: Command::Stop,
        seq: 3,
    }
    .to_bytes();
    let hb = HeartbeatRepr::default().to_bytes();
    // Garbage, a command, then two heartbeats (the second differs: the first is the answer).
    const GARBAGE: usize = 5;
    let answer_end = GARBAGE + COMMAND_LEN + HEARTBEAT_LEN;
    let mut stream = [0u8; GARBAGE + COMMAND_LEN + 2 * HEARTBEAT_LEN];
    stream[..GARBAGE].copy_from_slice(b"MIx\0\xff");
    stream[GARBAGE..GARBAGE + COMMAND_LEN].copy_from_slice(&command);
    stream[GARBAGE + COMMAND_LEN..answer_end].copy_from_slice(&hb);
    let second = HeartbeatRepr {
        last_seq: 9,
        ..HeartbeatRepr::default()
    }
    .to_bytes();
    stream[answer_end..].copy_from_slice(&second);
    let mut v = Visit::new(start, BoardNumber::ONE, command, wait);
    assert_eq!(*v.packet(), command);
    let (mut now, mut offset, mut answered) = (start, 0usize, false);
    for &(len, dt) in ops.iter() {
        now = now.wrapping_add(DT[dt as usize % 4]);
        let elapsed = now.wrapping_sub(start);
        let left = v.left_ms(now);
        if answered || elapsed >= wait {
            assert_eq!(left, None);
        } else {
            assert_eq!(left, Some(wait - elapsed));
        }
        let len = [1, 9, 30, 66][len as usize % 4].min(stream.len() - offset);
        let got = v.received(&stream[offset..offset + len]);
        let ends_here = !answered && offset < answer_end && offset + len >= answer_end;
        assert_eq!(got, ends_here.then_some(hb));
        answered |= ends_here;
        assert_eq!(v.answered(), answered);
        offset += len;
    }
}
