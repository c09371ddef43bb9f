//! The server board's glue towards the ground on the host: the library's ground end
//! (`GroundLink`: FOP-1, the packet extractor) sends PUS telecommands in TC transfer frames over
//! a mocked UDP socket; the glue runs them through FARM-1 and the gateway, its legacy commands
//! reach a mocked board A (which answers each with a heartbeat at the next pass, as a visit
//! does), and the TM transfer frames that come back carry the ground's reports and the CLCW.

use std::collections::{BTreeMap, VecDeque};

mod common;
use common::Ram;

use mmic::ccsds::primary::{Apid, SeqCount};
use mmic::ccsds::tc::TcRepr;
use mmic::ccsds::tc_header::{AckFlags, TcSecondaryHeader};
use mmic::ccsds::tm::TmRepr;
use mmic::command::Command;
use mmic::mode::Mode;
use mmic::node::ground::frames::GroundLink;
use mmic::node::server::frames::FrameConfig;
use mmic::node::server::gateway::Config;
use mmic::pus::verification::{Report, Stage};
use mmic::units::BoardNumber;
use mmic::wire::command::{CommandRepr, COMMAND_LEN};
use mmic::wire::heartbeat::{HeartbeatRepr, HEARTBEAT_LEN};
use mmic_fw_support::counters::{CounterError, CounterStore, FlashCounters};
use mmic_fw_support::server::{
    security, sleep_ms, BoardLink, Clear, Clock, Datagrams, FrameSecurity, GlueError, SdlsKey,
    ServerGlue,
};

/// The mocked UDP socket: datagrams from the ground waiting, datagrams sent to it.
#[derive(Default)]
struct Udp {
    inbox: VecDeque<Vec<u8>>,
    sent: Vec<Vec<u8>>,
}
impl Datagrams for Udp {
    fn recv(&mut self, buf: &mut [u8]) -> Option<usize> {
        let d = self.inbox.pop_front()?;
        let n = d.len().min(buf.len());
        buf[..n].copy_from_slice(&d[..n]);
        Some(n)
    }
    fn send(&mut self, datagram: &[u8]) -> bool {
        self.sent.push(datagram.to_vec());
        true
    }
}

/// Board A behind the visits: answers every command with a heartbeat naming its number, at the
/// next pass; refuses commands while `busy`.
#[derive(Default)]
struct BoardA {
    commands: Vec<CommandRepr>,
    answers: VecDeque<[u8; HEARTBEAT_LEN]>,
    busy: bool,
}
impl BoardLink for BoardA {
    fn command(&mut self, board: BoardNumber, packet: [u8; COMMAND_LEN]) -> bool {
        if self.busy {
            return false;
        }
        let c = CommandRepr::parse(&packet).unwrap();
        assert_eq!(c.board, board);
        self.commands.push(c);
        let hb = HeartbeatRepr {
            board,
            last_seq: c.seq,
            mode: Mode::Operational,
            ..HeartbeatRepr::default()
        };
        self.answers.push_back(hb.to_bytes());
        true
    }
    fn heartbeat(&mut self) -> Option<[u8; HEARTBEAT_LEN]> {
        self.answers.pop_front()
    }
}

struct Ms(u32);
impl Clock for Ms {
    fn now_ms(&mut self) -> u32 {
        self.0
    }
}

/// A counter store in RAM.
#[derive(Default)]
struct Map(BTreeMap<u16, u128>);
impl CounterStore for Map {
    fn load(&mut self, spi: u16) -> Option<u128> {
        self.0.get(&spi).copied()
    }
    fn store(&mut self, spi: u16, value: u128) -> Result<(), CounterError> {
        self.0.insert(spi, value);
        Ok(())
    }
}

/// Random keys for robot 1's two SAs (made at run time; the glue only checks they are there).
fn keys() -> Vec<SdlsKey> {
    let mut seed = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .unwrap()
        .as_nanos() as u64
        | 1;
    [257u16, 513]
        .iter()
        .map(|&spi| {
            let mut key = [0u8; 32];
            for b in &mut key {
                seed ^= seed << 13;
                seed ^= seed >> 7;
                seed ^= seed << 17;
                *b = seed as u8;
            }
            SdlsKey { spi, key }
        })
        .collect()
}

fn config() -> FrameConfig {
    FrameConfig {
        gateway: Config {
            hk_enabled: false,
            ..Config::default()
        },
        ..FrameConfig::default()
    }
}

/// TC(`service`,`sub`) for robot 1 numbered `seq`.
fn tc(service: u8, sub: u8, seq: u16, data: &[u8]) -> Vec<u8> {
    let mut b = vec![0u8; 13 + data.len()];
    TcRepr {
        apid: Apid::new(0x101).unwrap(),
        seq_count: SeqCount::new(seq).unwrap(),
        header: TcSecondaryHeader {
            ack: AckFlags::ALL,
            service,
            subservice: sub,
            source_id: 9,
        },
        app_data: data,
    }
    .emit(&mut b)
    .unwrap();
    b
}

/// What the ground heard.
#[derive(Default, Debug)]
struct Heard {
    /// (service, subservice) of every TM packet.
    packets: Vec<(u8, u8)>,
    accepted: Vec<u16>,
    completed: Vec<u16>,
}

struct Bench<Sec: FrameSecurity> {
    ground: GroundLink<10, 64, 1024>,
    glue: ServerGlue<Sec, Map, 1>,
    udp: Udp,
    board: BoardA,
    clock: Ms,
    heard: Heard,
    /// A datagram wrapper between the ground and the UDP socket (the test's frame security).
    wrap: fn(&[u8]) -> Vec<u8>,
}

impl<Sec: FrameSecurity> Bench<Sec> {
    fn new(sec: Sec, wrap: fn(&[u8]) -> Vec<u8>) -> Self {
        let glue =
            ServerGlue::new(config(), &[BoardNumber::ONE], &keys(), sec, Map::default()).unwrap();
        let mut b = Bench {
            ground: GroundLink::new(BoardNumber::ONE),
            glue,
            udp: Udp::default(),
            board: BoardA::default(),
            clock: Ms(0),
            heard: Heard::default(),
            wrap,
        };
        let mut up = Vec::new();
        b.ground.start(0, &mut |f: &[u8]| up.push(wrap(f)));
        b.udp.inbox.extend(up);
        b
    }

    fn send(&mut self, packet: &[u8]) {
        let (now, wrap) = (self.clock.0, self.wrap);
        let mut up = Vec::new();
        self.ground
            .send(packet, now, &mut |f: &[u8]| up.push(wrap(f)))
            .unwrap();
        self.udp.inbox.extend(up);
    }

    /// Runs `ms` milliseconds in 1 ms passes.
    fn run(&mut self, ms: u32) {
        for _ in 0..ms {
            self.clock.0 += 1;
            let now = self.clock.0;
            self.glue
                .poll(&mut self.clock, &mut self.udp, &mut self.board);
            let wrap = self.wrap;
            let mut up = Vec::new();
            for f in std::mem::take(&mut self.udp.sent) {
                let mut tms = Vec::new();
                self.ground
                    .tm_frame(
                        now,
                        &f,
                        &mut |t: &[u8]| up.push(wrap(t)),
                        &mut |p: &[u8]| tms.push(p.to_vec()),
                    )
                    .unwrap();
                for p in tms {
                    let tm = TmRepr::parse(&p, &[0x101]).unwrap();
                    let (s, sub) = (tm.header.service, tm.header.subservice);
                    self.heard.packets.push((s, sub));
                    if s == 1 {
                        let r = Report::parse(sub, tm.source_data).unwrap();
                        match (r.stage, r.failure) {
                            (Stage::Acceptance, None) => {
                                self.heard.accepted.push(r.request.seq_count)
                            }
                            (Stage::Completion, None) => {
                                self.heard.completed.push(r.request.seq_count)
                            }
                            _ => {}
                        }
                    }
                }
            }
            self.ground.tick(now, &mut |f: &[u8]| up.push(wrap(f)));
            self.udp.inbox.extend(up);
        }
    }
}

fn clear(f: &[u8]) -> Vec<u8> {
    f.to_vec()
}

#[test]
fn an_are_you_alive_crosses_the_link_and_board_a_answers_it() {
    let mut b = Bench::new(Clear, clear);
    b.run(50);
    b.send(&tc(17, 1, 0, &[]));
    b.run(2000);
    assert!(b.heard.packets.contains(&(17, 2)), "{:?}", b.heard);
    assert_eq!(b.heard.accepted, [0]);
    assert_eq!(b.heard.completed, [0]);
    // Board A was visited (the gateway's polls and the heartbeat request), and every visit's
    // heartbeat went back into the gateway.
    assert!(!b.board.commands.is_empty());
    let c = *b.glue.counts();
    assert_eq!(c.heartbeats as usize, b.board.commands.len());
    assert_eq!((c.commands_busy, c.tc_insecure, c.tm_unsent), (0, 0, 0));
    assert!(c.tm_frames >= 4, "{c:?}");
    let farm = b.glue.gateway().farm(BoardNumber::ONE).unwrap();
    assert_eq!(farm.vr(), 1);
}

#[test]
fn a_stop_reaches_board_a_as_the_legacy_stop_and_completes() {
    let mut b = Bench::new(Clear, clear);
    b.run(50);
    for seq in 0..3 {
        // TC(8,1) perform function 6: Stop (spec/ccsds/functions.toml).
        b.send(&tc(8, 1, seq, &[6]));
    }
    b.run(3000);
    assert_eq!(b.heard.accepted, [0, 1, 2]);
    assert_eq!(b.heard.completed, [0, 1, 2]);
    let stops: Vec<u16> = b
        .board
        .commands
        .iter()
        .filter(|c| c.command == Command::Stop)
        .map(|c| c.seq)
        .collect();
    assert_eq!(stops.len(), 3, "{:?}", b.board.commands);
    let farm = b.glue.gateway().farm(BoardNumber::ONE).unwrap();
    assert_eq!(farm.vr(), 3);
}

#[test]
fn a_busy_board_link_delays_commands_and_the_uplink_sends_them_again() {
    let mut b = Bench::new(Clear, clear);
    b.run(50);
    b.board.busy = true;
    b.send(&tc(8, 1, 0, &[6]));
    b.run(600);
    let busy = b.glue.counts().commands_busy;
    assert!(busy >= 1, "{:?}", b.glue.counts());
    assert!(b.heard.completed.is_empty());
    b.board.busy = false;
    b.run(3000);
    assert_eq!(b.heard.completed, [0]);
    assert!(b.board.commands.iter().any(|c| c.command == Command::Stop));
}

#[test]
fn a_garbage_datagram_is_refused_by_the_frame_checks_and_reaches_no_robot() {
    let mut b = Bench::new(Clear, clear);
    b.run(50);
    let before = b.board.commands.len();
    let refused_before: u32 = b.glue.gateway().refused().iter().sum();
    let datagrams_before = b.glue.counts().tc_datagrams;
    b.udp.inbox.push_back(vec![0x55; 40]);
    b.udp.inbox.push_back(vec![0x20; 300]); // longer than any TC frame: cut, then refused
    b.run(1);
    let refused: u32 = b.glue.gateway().refused().iter().sum();
    assert_eq!(refused - refused_before, 2);
    // At most the gateway's own poll went to board A meanwhile.
    assert!(b.board.commands.len() <= before + 1);
    assert_eq!(b.glue.counts().tc_datagrams - datagrams_before, 2);
}

#[test]
fn a_robot_without_both_keys_is_not_served() {
    let only_tc: Vec<SdlsKey> = keys().into_iter().filter(|k| k.spi == 257).collect();
    let e = ServerGlue::<_, _, 1>::new(
        config(),
        &[BoardNumber::ONE],
        &only_tc,
        Clear,
        Map::default(),
    )
    .err()
    .unwrap();
    assert_eq!(e, GlueError::NoKey { board: 1, spi: 513 });
    // And the key never shows in Debug.
    let k = SdlsKey {
        spi: 257,
        key: [0xA7; 32],
    };
    let shown = format!("{k:?}");
    assert!(shown.contains("257") && !shown.contains("167") && !shown.contains("a7"));
    let _ = security(&keys());
}

/// A stand-in frame security: TC datagrams carry a 2-octet marker in front, which it checks
/// and strips; each TM frame advances a counter kept in the store (SPI 513), as the SDLS
/// sender's IV will be.
struct Marked;
impl FrameSecurity for Marked {
    fn tc_in<S: CounterStore>(&mut self, _: &mut S, _: u32, frame: &mut [u8]) -> Option<usize> {
        if frame.len() < 2 || frame[..2] != [0xAB, 0xCD] {
            return None;
        }
        frame.copy_within(2.., 0);
        Some(frame.len() - 2)
    }
    fn tm_out<S: CounterStore>(
        &mut self,
        store: &mut S,
        _: &mut [u8],
        len: usize,
    ) -> Option<usize> {
        let n = store.load(513).unwrap_or(0) + 1;
        store.store(513, n).ok()?;
        Some(len)
    }
}

fn marked(f: &[u8]) -> Vec<u8> {
    let mut d = vec![0xAB, 0xCD];
    d.extend_from_slice(f);
    d
}

#[test]
fn the_frame_security_sits_between_the_socket_and_the_gateway_with_the_store() {
    let mut b = Bench::new(Marked, marked);
    b.run(50);
    b.send(&tc(8, 1, 0, &[6]));
    b.run(2000);
    assert_eq!(b.heard.completed, [0]);
    // A frame without the marker is refused before the gateway sees it.
    let frames_before = b
        .glue
        .gateway()
        .counters(BoardNumber::ONE)
        .unwrap()
        .tc_frames;
    b.udp.inbox.push_back(tc(8, 1, 1, &[6]));
    b.run(1);
    assert_eq!(b.glue.counts().tc_insecure, 1);
    let c = b.glue.gateway().counters(BoardNumber::ONE).unwrap();
    assert_eq!(c.tc_frames, frames_before);
    // Every TM frame sent advanced the stored counter.
    let sent = b.glue.counts().tm_frames;
    assert_eq!(b.glue.store().load(513), Some(u128::from(sent)));
}

#[test]
fn the_shell_sleeps_until_the_deadline_within_bounds() {
    assert_eq!(sleep_ms(None, 5, 10), 10);
    assert_eq!(sleep_ms(Some(8), 5, 10), 3);
    assert_eq!(sleep_ms(Some(500), 5, 10), 10);
    // Due now, or already past (also across the clock's wrap): a pass almost at once.
    assert_eq!(sleep_ms(Some(5), 5, 10), 1);
    assert_eq!(sleep_ms(Some(4), 5, 10), 1);
    assert_eq!(sleep_ms(Some(u32::MAX), 2, 10), 1);
    assert_eq!(sleep_ms(Some(3), u32::MAX - 1, 10), 5);
}

#[test]
fn a_pass_reports_the_gateways_next_deadline() {
    let mut b = Bench::new(Clear, clear);
    b.run(50);
    let now = b.clock.0;
    let next = b.glue.poll(&mut b.clock, &mut b.udp, &mut b.board).unwrap();
    // Something is always due within the TM idle period (500 ms) and the poll period (250 ms).
    let d = next.wrapping_sub(now);
    assert!(d <= 500, "next deadline {d} ms away");
}

/// The stand-in security of [`Marked`] with the counters in flash: the TM counter a reset
/// finds is the one the last frame stored, and passes go on from it.
#[test]
fn the_counters_survive_a_reset_of_the_server_board_in_flash() {
    type Flash = FlashCounters<Ram, 2>;
    let store = Flash::open(Ram::new(2)).unwrap();
    let mut glue: ServerGlue<Marked, Flash, 1> =
        ServerGlue::new(config(), &[BoardNumber::ONE], &keys(), Marked, store).unwrap();
    let (mut udp, mut board, mut clock) = (Udp::default(), BoardA::default(), Ms(0));
    // Five seconds of idle link: a TM frame every 500 ms at least, each stored.
    for _ in 0..5000 {
        clock.0 += 1;
        glue.poll(&mut clock, &mut udp, &mut board);
    }
    let sent = glue.counts().tm_frames;
    assert!(sent >= 10, "{sent} TM frames");
    assert_eq!(udp.sent.len() as u32, sent);
    // Reset: a new glue on the same flash.
    let ram = std::mem::replace(glue.store(), Flash::open(Ram::new(2)).unwrap()).release();
    assert_eq!(ram.overwrites, 0);
    let store = Flash::open(ram.reset()).unwrap();
    let mut glue: ServerGlue<Marked, Flash, 1> =
        ServerGlue::new(config(), &[BoardNumber::ONE], &keys(), Marked, store).unwrap();
    assert_eq!(glue.store().load(513), Some(u128::from(sent)));
    for _ in 0..1000 {
        clock.0 += 1;
        glue.poll(&mut clock, &mut udp, &mut board);
    }
    let more = glue.counts().tm_frames;
    assert!(more >= 2);
    assert_eq!(glue.store().load(513), Some(u128::from(sent + more)));
}
