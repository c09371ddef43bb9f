//! The paper's server board (firmware/server-paper) on the host: the opsUI's serial line, the
//! visit's TCP connection and the clock mocked around `support::relay`. What each test shows is
//! Figure 4's loop as the library's `Server` and `Visit` decide it, moved by the glue without
//! a change: the command reaches board A as the opsUI wrote it, the heartbeat reaches the
//! opsUI as board A wrote it, the "command byte" stays set until the command was written, and
//! a visit lasts `relay::VISIT_MS` at most.

use core::future::Future;
use core::pin::pin;
use core::task::{Context, Poll, Waker};
use mmic::command::Command;
use mmic::node::server::relay::VISIT_MS;
use mmic::units::BoardNumber;
use mmic::wire::checksum::crc16;
use mmic::wire::command::{CommandRepr, COMMAND_LEN};
use mmic::wire::heartbeat::HeartbeatRepr;
use mmic_fw_support::link::{ByteSink, ByteSource};
use mmic_fw_support::net::{self, Endpoint};
use mmic_fw_support::relay::{Connection, Outcome, Relay};
use mmic_fw_support::server::Clock;
use std::cell::Cell;
use std::collections::VecDeque;
use std::rc::Rc;

/// Runs a pass: the mocks never wait, so it is ready at the first poll.
fn block_on<F: Future>(f: F) -> F::Output {
    let mut f = pin!(f);
    match f.as_mut().poll(&mut Context::from_waker(Waker::noop())) {
        Poll::Ready(r) => r,
        Poll::Pending => panic!("a mock waited"),
    }
}

/// The clock, advanced by the mocked connection as time passes on it.
#[derive(Clone, Default)]
struct Now(Rc<Cell<u32>>);

impl Now {
    fn advance(&self, ms: u32) {
        self.0.set(self.0.get().wrapping_add(ms));
    }
}

impl Clock for Now {
    fn now_ms(&mut self) -> u32 {
        self.0.get()
    }
}

/// The opsUI's serial line: what the opsUI wrote, and what the server board wrote back.
#[derive(Default)]
struct Ops {
    to_server: VecDeque<u8>,
    to_opsui: Vec<u8>,
}

impl ByteSource for Ops {
    fn read(&mut self, buf: &mut [u8]) -> usize {
        let n = buf.len().min(self.to_server.len());
        for (b, x) in buf.iter_mut().zip(self.to_server.drain(..n)) {
            *b = x;
        }
        n
    }
}

impl ByteSink for Ops {
    fn write(&mut self, bytes: &[u8]) -> bool {
        self.to_opsui.extend_from_slice(bytes);
        true
    }
}

/// The robots' board A as the visits find them: reachable or not, who answers the connect,
/// what comes back and when.
#[derive(Default)]
struct Lab {
    now: Now,
    unreachable: bool,
    /// The peer the socket names; `None`: the address connected to.
    peer: Option<Endpoint>,
    /// Bytes board A sends after the command, and how long after the read began.
    answer: Option<(Vec<u8>, u32)>,
    connects: Vec<Endpoint>,
    /// What board A received.
    received: Vec<u8>,
    /// How each connection ended.
    ended: Vec<&'static str>,
}

/// One visit's connection into the lab.
struct Tcp<'a> {
    lab: &'a mut Lab,
    to: Option<Endpoint>,
}

impl Connection for Tcp<'_> {
    async fn connect(&mut self, to: Endpoint, within_ms: u32) -> bool {
        self.lab.connects.push(to);
        if self.lab.unreachable {
            self.lab.now.advance(within_ms);
            return false;
        }
        self.lab.now.advance(5);
        self.to = Some(to);
        true
    }
    fn peer(&self) -> Option<Endpoint> {
        self.lab.peer.or(self.to)
    }
    async fn write_all(&mut self, bytes: &[u8]) -> bool {
        self.lab.received.extend_from_slice(bytes);
        true
    }
    async fn read(&mut self, buf: &mut [u8], within_ms: u32) -> usize {
        match self.lab.answer.take() {
            Some((bytes, after)) if after < within_ms => {
                self.lab.now.advance(after);
                buf[..bytes.len()].copy_from_slice(&bytes);
                bytes.len()
            }
            late => {
                self.lab.answer = late;
                self.lab.now.advance(within_ms);
                0
            }
        }
    }
    async fn close(&mut self) {
        self.lab.ended.push("close");
    }
    async fn abort(&mut self) {
        self.lab.ended.push("abort");
    }
}

fn two() -> BoardNumber {
    BoardNumber::new(2).unwrap()
}

fn stop(seq: u16) -> [u8; COMMAND_LEN] {
    CommandRepr {
        board: two(),
        command: Command::Stop,
        seq,
    }
    .to_bytes()
}

/// One pass of the relay over the mocks.
fn pass(relay: &mut Relay, ops: &mut Ops, lab: &mut Lab) -> Outcome {
    let mut clock = lab.now.clone();
    block_on(relay.pass(ops, || Tcp { lab, to: None }, &mut clock))
}

#[test]
fn a_command_from_the_ops_line_reaches_board_a_unchanged() {
    let (mut relay, mut ops, mut lab) = (Relay::new(), Ops::default(), Lab::default());
    // Line noise before the packet: the deframer resyncs past it.
    ops.to_server.extend(b"\x00MI\xFF");
    ops.to_server.extend(stop(7));
    assert_eq!(pass(&mut relay, &mut ops, &mut lab), Outcome::Unanswered);
    assert_eq!(lab.connects, [(net::robot(2), net::PORT)]);
    assert_eq!(lab.received, stop(7));
    // The "command byte" is cleared once the packet was written.
    assert_eq!(relay.slots().pending(two()), None);
    assert_eq!((relay.counts().queued, relay.counts().delivered), (1, 1));
    assert_eq!(relay.ops_link().discarded(), 4);
}

#[test]
fn the_heartbeat_goes_back_to_the_ops_line_unchanged() {
    let (mut relay, mut ops, mut lab) = (Relay::new(), Ops::default(), Lab::default());
    let hb = HeartbeatRepr {
        board: two(),
        ..HeartbeatRepr::default()
    }
    .to_bytes();
    // Garbage on the connection before the heartbeat: the visit's deframer drops it.
    let mut answer = b"xx".to_vec();
    answer.extend_from_slice(&hb);
    lab.answer = Some((answer, 40));
    ops.to_server.extend(stop(1));
    assert_eq!(pass(&mut relay, &mut ops, &mut lab), Outcome::Answered);
    assert_eq!(ops.to_opsui, hb);
    assert_eq!(lab.ended, ["close"]);
    assert_eq!(relay.counts().forwarded, 1);
}

#[test]
fn a_resend_and_a_superseded_packet_are_counted() {
    let (mut relay, mut ops, mut lab) = (Relay::new(), Ops::default(), Lab::default());
    for p in [stop(1), stop(1), stop(2)] {
        ops.to_server.extend(p);
    }
    pass(&mut relay, &mut ops, &mut lab);
    let c = *relay.counts();
    assert_eq!((c.queued, c.resends, c.superseded), (2, 1, 1), "{c:?}");
    // Only the newest reached board A.
    assert_eq!(lab.received, stop(2));
}

#[test]
fn an_invalid_packet_is_refused_and_counted() {
    let (mut relay, mut ops, mut lab) = (Relay::new(), Ops::default(), Lab::default());
    // Board 0, its checksum right: the deframer passes it, the library's parse refuses it.
    let mut bad = stop(1);
    bad[4] = 0;
    let crc = crc16(&bad[..COMMAND_LEN - 2]).to_le_bytes();
    bad[COMMAND_LEN - 2..].copy_from_slice(&crc);
    ops.to_server.extend(bad);
    assert_eq!(pass(&mut relay, &mut ops, &mut lab), Outcome::Idle);
    assert_eq!(relay.counts().invalid, 1);
    assert_eq!(relay.slots().pending_count(), 0);
    assert!(lab.connects.is_empty());
}

#[test]
fn a_failed_connect_keeps_the_command_pending_for_the_next_loop() {
    let (mut relay, mut ops, mut lab) = (Relay::new(), Ops::default(), Lab::default());
    ops.to_server.extend(stop(3));
    lab.unreachable = true;
    assert_eq!(pass(&mut relay, &mut ops, &mut lab), Outcome::Unreachable);
    // The connect had the whole visit, and no more.
    assert_eq!(lab.now.0.get(), VISIT_MS);
    assert_eq!(relay.slots().pending(two()), Some(stop(3)));
    assert!(lab.received.is_empty());
    // The next loop: reachable, and the same packet goes, with nothing new from the opsUI.
    lab.unreachable = false;
    assert_eq!(pass(&mut relay, &mut ops, &mut lab), Outcome::Unanswered);
    assert_eq!(lab.received, stop(3));
    let c = *relay.counts();
    assert_eq!((c.unreachable, c.delivered, c.queued), (1, 1, 1), "{c:?}");
}

#[test]
fn the_visit_ends_at_visit_ms_without_an_answer() {
    let (mut relay, mut ops, mut lab) = (Relay::new(), Ops::default(), Lab::default());
    lab.now.0.set(1_000);
    // Board A answers, but only at the visit's end: too late for the opsUI's 0.7 s.
    let hb = HeartbeatRepr::default().to_bytes().to_vec();
    lab.answer = Some((hb, VISIT_MS));
    ops.to_server.extend(stop(4));
    assert_eq!(pass(&mut relay, &mut ops, &mut lab), Outcome::Unanswered);
    assert_eq!(lab.now.0.get(), 1_000 + VISIT_MS);
    assert!(ops.to_opsui.is_empty());
    assert_eq!(lab.ended, ["close"]);
    assert_eq!(relay.counts().unanswered, 1);
    // The visit is the opsUI's window less the serial line's share (decision relay-visit-window).
    assert_eq!(
        VISIT_MS + mmic::node::server::relay::SERIAL_RESERVE_MS,
        mmic::node::server::relay::ANSWER_MS
    );
}

#[test]
fn a_peer_that_is_not_the_visited_board_a_gets_nothing() {
    let (mut relay, mut ops, mut lab) = (Relay::new(), Ops::default(), Lab::default());
    // Robot 3's board A, and a station posing at robot 2's address from another port.
    for peer in [(net::robot(3), net::PORT), (net::robot(2), 5001)] {
        lab.peer = Some(peer);
        lab.answer = Some((HeartbeatRepr::default().to_bytes().to_vec(), 1));
        ops.to_server.extend(stop(5));
        assert_eq!(pass(&mut relay, &mut ops, &mut lab), Outcome::ForeignPeer);
    }
    assert!(lab.received.is_empty());
    assert!(ops.to_opsui.is_empty());
    assert_eq!(lab.ended, ["abort", "abort"]);
    assert_eq!(relay.slots().pending(two()), Some(stop(5)));
    assert_eq!(relay.counts().foreign_peers, 2);
}
