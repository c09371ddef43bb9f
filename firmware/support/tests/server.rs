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
use mmic::link::sdls::Key256;
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
    sleep_ms, BoardLink, Clock, Datagrams, GlueError, SdlsKey, ServerGlue,
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

struct Bench {
    ground: GroundLink<10, 64, 1024>,
    glue: ServerGlue<Map, 1>,
    udp: Udp,
    board: BoardA,
    clock: Ms,
    heard: Heard,
    /// A datagram wrapper between the ground and the UDP socket (an attacker's stand-in).
    wrap: fn(&[u8]) -> Vec<u8>,
    /// The TC datagrams the ground sent.
    uplink: Vec<Vec<u8>>,
}

impl Bench {
    fn new(wrap: fn(&[u8]) -> Vec<u8>) -> Self {
        let keys = keys();
        let glue = ServerGlue::new(config(), &[BoardNumber::ONE], &keys, Map::default()).unwrap();
        // The ground holds the same keys; its counters live with it for the test.
        let mut ground = GroundLink::new(BoardNumber::ONE);
        ground.secure(
            Key256::from_bytes(keys[0].key),
            Key256::from_bytes(keys[1].key),
            (None, None),
        );
        persist_ground(&mut ground);
        let mut b = Bench {
            ground,
            glue,
            uplink: Vec::new(),
            udp: Udp::default(),
            board: BoardA::default(),
            clock: Ms(0),
            heard: Heard::default(),
            wrap,
        };
        let mut up = Vec::new();
        b.ground.start(0, &mut |f: &[u8]| up.push(wrap(f)));
        b.uplink.extend(up.iter().cloned());
        b.udp.inbox.extend(up);
        b
    }

    fn send(&mut self, packet: &[u8]) {
        let (now, wrap) = (self.clock.0, self.wrap);
        let mut up = Vec::new();
        self.ground
            .send(packet, now, &mut |f: &[u8]| up.push(wrap(f)))
            .unwrap();
        persist_ground(&mut self.ground);
        self.uplink.extend(up.iter().cloned());
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
            persist_ground(&mut self.ground);
            self.uplink.extend(up.iter().cloned());
            self.udp.inbox.extend(up);
        }
    }
}

fn clear(f: &[u8]) -> Vec<u8> {
    f.to_vec()
}

/// The ground's durable counters, written and confirmed at once.
fn persist_ground(g: &mut GroundLink<10, 64, 1024>) {
    for (spi, v) in g.due().collect::<Vec<_>>() {
        g.persisted(spi, v);
    }
}

#[test]
fn an_are_you_alive_crosses_the_link_and_board_a_answers_it() {
    let mut b = Bench::new(clear);
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
    assert_eq!((c.commands_busy, c.store_failed, c.tm_unsent), (0, 0, 0));
    let sec = b.glue.gateway().security(BoardNumber::ONE).unwrap();
    assert_eq!(sec.refused_total(), 0, "{sec:?}");
    assert!(sec.accepted >= 1 && sec.protected >= 4, "{sec:?}");
    assert!(c.tm_frames >= 4, "{c:?}");
    let farm = b.glue.gateway().farm(BoardNumber::ONE).unwrap();
    assert_eq!(farm.vr(), 1);
}

#[test]
fn a_stop_reaches_board_a_as_the_legacy_stop_and_completes() {
    let mut b = Bench::new(clear);
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
    let mut b = Bench::new(clear);
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
    let mut b = Bench::new(clear);
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
    let e = ServerGlue::<_, 1>::new(config(), &[BoardNumber::ONE], &only_tc, Map::default())
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
}

/// An attacker on the ground's UDP port: every TC frame the ground sent, sent again (replays),
/// and each with one bit flipped in its data field (the FECF made good): SDLS refuses every
/// one before FARM-1, board A is given nothing more, and the link still works.
#[test]
fn sdls_refuses_replays_and_forgeries_before_farm() {
    let mut b = Bench::new(clear);
    b.run(50);
    b.send(&tc(8, 1, 0, &[6]));
    b.run(2000);
    assert_eq!(b.heard.completed, [0]);
    let stops = |b: &Bench| {
        b.board
            .commands
            .iter()
            .filter(|c| c.command == Command::Stop)
            .count()
    };
    assert_eq!(stops(&b), 1);
    let data: Vec<Vec<u8>> = b
        .uplink
        .iter()
        .filter(|f| f[0] & 0x10 == 0)
        .cloned()
        .collect();
    assert!(!data.is_empty());
    let farm_before = b
        .glue
        .gateway()
        .farm(BoardNumber::ONE)
        .unwrap()
        .counters()
        .accepted_ad;
    let mut attacks = 0;
    for f in &data {
        b.udp.inbox.push_back(f.clone());
        attacks += 1;
        for at in [6, 8, 20, f.len() - 3] {
            let mut g = f.clone();
            g[at] ^= 0x01;
            let n = g.len();
            let crc = mmic::ccsds::pec(&g[..n - 2]);
            g[n - 2..].copy_from_slice(&crc.to_be_bytes());
            b.udp.inbox.push_back(g);
            attacks += 1;
        }
    }
    b.run(10);
    let sec = *b.glue.gateway().security(BoardNumber::ONE).unwrap();
    assert_eq!(sec.refused_total(), attacks, "{sec:?}");
    assert_eq!(
        b.glue
            .gateway()
            .farm(BoardNumber::ONE)
            .unwrap()
            .counters()
            .accepted_ad,
        farm_before
    );
    assert_eq!(stops(&b), 1, "board A was given a command again");
    // The ground's next command still goes through.
    b.send(&tc(8, 1, 1, &[6]));
    b.run(2000);
    assert_eq!(b.heard.completed, [0, 1]);
    assert_eq!(stops(&b), 2);
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
    let mut b = Bench::new(clear);
    b.run(50);
    let now = b.clock.0;
    let next = b.glue.poll(&mut b.clock, &mut b.udp, &mut b.board).unwrap();
    // Something is always due within the TM idle period (500 ms) and the poll period (250 ms).
    let d = next.wrapping_sub(now);
    assert!(d <= 500, "next deadline {d} ms away");
}

/// The SDLS counters in flash survive a reset of the server board: a new glue on the same
/// flash refuses every TC data frame taken before the reset (as a replay), and its TM frames'
/// IVs continue above every IV used before it.
#[test]
fn the_counters_survive_a_reset_of_the_server_board_in_flash() {
    type Flash = FlashCounters<Ram, 2>;
    let keys = keys();
    let mut ground = GroundLink::<10, 64, 1024>::new(BoardNumber::ONE);
    ground.secure(
        Key256::from_bytes(keys[0].key),
        Key256::from_bytes(keys[1].key),
        (None, None),
    );
    persist_ground(&mut ground);
    let store = Flash::open(Ram::new(2)).unwrap();
    let mut glue: ServerGlue<Flash, 1> =
        ServerGlue::new(config(), &[BoardNumber::ONE], &keys, store).unwrap();
    let (mut udp, mut board, mut clock) = (Udp::default(), BoardA::default(), Ms(0));
    let mut uplink: Vec<Vec<u8>> = Vec::new();
    let mut tm_ivs: Vec<u128> = Vec::new();
    let iv =
        |f: &[u8]| u128::from_be_bytes([&[0u8; 4][..], &f[8..20]].concat().try_into().unwrap());
    ground.start(0, &mut |f: &[u8]| uplink.push(f.to_vec()));
    udp.inbox.extend(uplink.iter().cloned());
    let mut sent_stop = false;
    for _ in 0..5000 {
        clock.0 += 1;
        let now = clock.0;
        glue.poll(&mut clock, &mut udp, &mut board);
        let mut up = Vec::new();
        for f in std::mem::take(&mut udp.sent) {
            tm_ivs.push(iv(&f));
            ground
                .tm_frame(now, &f, &mut |t: &[u8]| up.push(t.to_vec()), &mut |_| {})
                .unwrap();
        }
        if !sent_stop && now == 100 {
            ground
                .send(&tc(8, 1, 0, &[6]), now, &mut |f: &[u8]| up.push(f.to_vec()))
                .unwrap();
            sent_stop = true;
        }
        ground.tick(now, &mut |f: &[u8]| up.push(f.to_vec()));
        persist_ground(&mut ground);
        uplink.extend(up.iter().cloned());
        udp.inbox.extend(up);
    }
    assert!(board.commands.iter().any(|c| c.command == Command::Stop));
    assert!(tm_ivs.len() >= 10, "{} TM frames", tm_ivs.len());
    // Reset: a new glue on the same flash.
    let ram = std::mem::replace(glue.store(), Flash::open(Ram::new(2)).unwrap()).release();
    let store = Flash::open(ram.reset()).unwrap();
    let mut glue: ServerGlue<Flash, 1> =
        ServerGlue::new(config(), &[BoardNumber::ONE], &keys, store).unwrap();
    let data: Vec<Vec<u8>> = uplink
        .iter()
        .filter(|f| f[0] & 0x10 == 0)
        .cloned()
        .collect();
    assert!(!data.is_empty());
    udp.inbox.extend(data.iter().cloned());
    udp.sent.clear();
    for _ in 0..600 {
        clock.0 += 1;
        glue.poll(&mut clock, &mut udp, &mut board);
    }
    let sec = glue.gateway().security(BoardNumber::ONE).unwrap();
    assert_eq!(sec.refused_for("replay") as usize, data.len(), "{sec:?}");
    assert_eq!(sec.accepted, 0);
    let before = tm_ivs.iter().max().copied().unwrap();
    assert!(!udp.sent.is_empty());
    for f in &udp.sent {
        assert!(
            iv(f) > before,
            "a TM IV {} at or below {before} after the reset",
            iv(f)
        );
    }
}
