//! The server board's glue on the host, between the library's ground end (`GroundLink`: FOP-1,
//! SDLS, the packet extractor) and a mocked board A: a mocked UDP socket that tells each
//! datagram's source, the durable log on a RAM NOR flash provisioned as the provisioning tool
//! does (`store::provision` and `log::image`, the `mmic_ctr` image), the keys as the image
//! reads them from the keys partition (`keys::emit`, then the glue's `keys_from`). Keys are
//! made at run time; none is in the tree.
#![allow(dead_code)]

use std::collections::VecDeque;

use crate::common::{Ram, SECTOR};

use mmic::ccsds::primary::{Apid, SeqCount};
use mmic::ccsds::tc::TcRepr;
use mmic::ccsds::tc_header::{AckFlags, TcSecondaryHeader};
use mmic::ccsds::tm::TmRepr;
use mmic::link::sdls::Key256;
use mmic::link::tc_frame::{
    MapId, SpacecraftId, TcContent, TcFrameRepr, Vcid, MISSION_MAP_ID, MISSION_VCID,
};
use mmic::mode::Mode;
use mmic::node::ground::frames::GroundLink;
use mmic::node::server::frames::FrameConfig;
use mmic::node::server::gateway::Config;
use mmic::node::server::store::keys::{self, KeySet};
use mmic::node::server::store::{self, log, End, Resume};
use mmic::pus::verification::{Report, Stage};
use mmic::units::BoardNumber;
use mmic::wire::command::{CommandRepr, COMMAND_LEN};
use mmic::wire::heartbeat::{HeartbeatRepr, HEARTBEAT_LEN};
use mmic_fw_support::counters::{EntryStore, FlashLog};
use mmic_fw_support::net;
use mmic_fw_support::server::{
    keys_from, open_store, BoardLink, Clock, Datagrams, LinkStop, ServerGlue, ENTRIES_PER_ROBOT,
    FOREIGN, KEYS_READ,
};

/// The durable log of a server board serving up to two robots.
pub type Log = FlashLog<Ram, { 2 * ENTRIES_PER_ROBOT }, FOREIGN>;

/// The mocked UDP socket: datagrams waiting (with their source address), datagrams sent to the
/// ground.
#[derive(Default)]
pub struct Udp {
    pub inbox: VecDeque<(Vec<u8>, Option<[u8; 4]>)>,
    pub sent: Vec<Vec<u8>>,
}

impl Udp {
    /// A datagram from the ground's address.
    pub fn from_ground(&mut self, d: Vec<u8>) {
        self.inbox.push_back((d, Some(net::GROUND)));
    }
}

impl Datagrams for Udp {
    fn recv(&mut self, buf: &mut [u8]) -> Option<(usize, Option<[u8; 4]>)> {
        let (d, from) = self.inbox.pop_front()?;
        let n = d.len().min(buf.len());
        buf[..n].copy_from_slice(&d[..n]);
        Some((n, from))
    }
    fn send(&mut self, datagram: &[u8]) -> bool {
        self.sent.push(datagram.to_vec());
        true
    }
}

/// Board A behind the visits: answers every command with a heartbeat naming its number, at the
/// next pass (unless `silent`: the visit's heartbeat is lost); refuses commands while `busy`.
#[derive(Default)]
pub struct BoardA {
    pub commands: Vec<CommandRepr>,
    pub answers: VecDeque<[u8; HEARTBEAT_LEN]>,
    pub busy: bool,
    pub silent: bool,
}

impl BoardLink for BoardA {
    fn command(&mut self, board: BoardNumber, packet: [u8; COMMAND_LEN]) -> bool {
        if self.busy {
            return false;
        }
        let c = CommandRepr::parse(&packet).unwrap();
        assert_eq!(c.board, board);
        self.commands.push(c);
        if !self.silent {
            let hb = HeartbeatRepr {
                board,
                last_seq: c.seq,
                mode: Mode::Operational,
                ..HeartbeatRepr::default()
            };
            self.answers.push_back(hb.to_bytes());
        }
        true
    }
    fn heartbeat(&mut self) -> Option<[u8; HEARTBEAT_LEN]> {
        self.answers.pop_front()
    }
}

pub struct Ms(pub u32);

impl Clock for Ms {
    fn now_ms(&mut self) -> u32 {
        self.0
    }
}

/// A key that passes the library's weak-key check, different per run (`which` tells keys of
/// one run apart).
pub fn key(which: u64) -> Key256 {
    let k = Key256::from_bytes(key_bytes(which));
    assert!(k.check().is_ok());
    k
}

/// The octets of [`key`]`(which)`.
pub fn key_bytes(which: u64) -> [u8; 32] {
    use std::sync::OnceLock;
    static RUN: OnceLock<u64> = OnceLock::new();
    let run = *RUN.get_or_init(|| {
        std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .unwrap()
            .as_nanos() as u64
    });
    let mut x = (run ^ which.wrapping_mul(0x9E37_79B9_7F4A_7C15)) | 1;
    core::array::from_fn(|_| {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        x as u8
    })
}

/// Robot `n`'s TC and TM keys for this run.
pub fn keys_of(n: u8) -> (Key256, Key256) {
    (key(2 * u64::from(n)), key(2 * u64::from(n) + 1))
}

/// The keys partition holding the keys of `robots` (`keys::emit`), as the image reads it.
pub fn partition(robots: &[u8]) -> Vec<u8> {
    let ks: Vec<(u16, Key256)> = robots
        .iter()
        .flat_map(|&n| {
            let b = BoardNumber::new(n).unwrap();
            let (tc, tm) = keys_of(n);
            [
                (mmic::link::sdls::mission::tc_spi(b), tc),
                (mmic::link::sdls::mission::tm_spi(b), tm),
            ]
        })
        .collect();
    let refs: Vec<(u16, &Key256)> = ks.iter().map(|(s, k)| (*s, k)).collect();
    let mut part = vec![0xFF; 4096];
    keys::emit(&refs, &mut part).unwrap();
    part
}

/// The key set the image reads from `part` (its first [`KEYS_READ`] octets).
pub fn read_keys(part: &[u8]) -> Result<KeySet, LinkStop> {
    let mut buf = part[..KEYS_READ].to_vec();
    let k = keys_from(&mut buf);
    assert!(
        buf.iter().all(|&b| b == 0),
        "the read buffer was not cleared"
    );
    k
}

/// The counters partition as `mmic sdls image` makes it for `robots` (their keys' fingerprints
/// and first counters), on a RAM flash.
pub fn provisioned(robots: &[u8]) -> Ram {
    let mut entries = Vec::new();
    for &n in robots {
        let (tc, tm) = keys_of(n);
        let b = BoardNumber::new(n).unwrap();
        entries.extend(store::provision(End::Server, b, &tc, &tm, Resume::FRESH).unwrap());
    }
    let mut image = vec![0u8; 2 * SECTOR];
    log::image(&entries, SECTOR, &mut image).unwrap();
    Ram::from_image(&image)
}

pub fn config() -> FrameConfig {
    FrameConfig {
        gateway: Config {
            hk_enabled: false,
            ..Config::default()
        },
        ..FrameConfig::default()
    }
}

/// The glue serving `robots`, started as the image starts it: keys from `part`, the log on
/// `ram`.
pub fn glue<const R: usize>(robots: [u8; R], part: &[u8], ram: Ram) -> ServerGlue<Log, R> {
    let boards = robots.map(|n| BoardNumber::new(n).unwrap());
    let keys = read_keys(part);
    ServerGlue::new(
        config(),
        &boards,
        keys.as_ref().map_err(|e| *e),
        open_store(ram, &boards),
    )
}

/// The flash under a glue's log, taken out (the glue is then done with).
pub fn flash_of<const R: usize>(glue: &mut ServerGlue<Log, R>) -> Ram {
    let log = glue.store().expect("a store");
    std::mem::replace(log, Log::open(Ram::erased(2)).unwrap()).release()
}

/// TC(`service`,`sub`) for robot `n` numbered `seq`.
pub fn tc_for(n: u8, service: u8, sub: u8, seq: u16, data: &[u8]) -> Vec<u8> {
    let mut b = vec![0u8; 13 + data.len()];
    TcRepr {
        apid: Apid::new(0x100 + u16::from(n)).unwrap(),
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

/// TC(`service`,`sub`) for robot 1 numbered `seq`.
pub fn tc(service: u8, sub: u8, seq: u16, data: &[u8]) -> Vec<u8> {
    tc_for(1, service, sub, seq, data)
}

/// A TC frame for robot `n` carrying `content` (N(S) 0), as anyone on the ground's network
/// could make one: no key.
pub fn frame(n: u8, content: TcContent<'_>) -> Vec<u8> {
    let mut out = vec![0u8; 300];
    let len = TcFrameRepr {
        spacecraft_id: SpacecraftId::of_board(BoardNumber::new(n).unwrap()),
        vcid: Vcid::new(MISSION_VCID).unwrap(),
        seq: 0,
        content,
    }
    .emit(&mut out)
    .unwrap();
    out.truncate(len);
    out
}

/// A BD frame in clear for robot `n` carrying `packet`.
pub fn bd(n: u8, packet: &[u8]) -> Vec<u8> {
    frame(
        n,
        TcContent::Bd {
            map_id: Some(MapId::new(MISSION_MAP_ID).unwrap()),
            data: packet,
        },
    )
}

/// What the ground heard.
#[derive(Default, Debug)]
pub struct Heard {
    /// (service, subservice) of every TM packet.
    pub packets: Vec<(u8, u8)>,
    pub accepted: Vec<u16>,
    pub completed: Vec<u16>,
    /// Every verification report: (sequence count, stage, success).
    pub reports: Vec<(u16, Stage, bool)>,
    /// The source data of every ST[5] event report.
    pub events: Vec<Vec<u8>>,
}

pub type Ground = GroundLink<10, 64, 1024>;

/// The ground end of robot `n`'s link, secured with its keys (its own counters kept for the
/// test, as provisioned: IVs from 0, nothing accepted).
pub fn ground(n: u8) -> Ground {
    let (tc, tm) = keys_of(n);
    let mut g = Ground::new(BoardNumber::new(n).unwrap());
    g.secure(tc, tm, (None, None));
    persist_ground(&mut g);
    g
}

/// The ground's durable counters, written and confirmed at once.
pub fn persist_ground(g: &mut Ground) {
    for (spi, v) in g.due().collect::<Vec<_>>() {
        g.persisted(spi, v);
    }
}

/// The ground and the server board of robot 1 (of `R` robots served, its durable store `St`),
/// and board A.
pub struct Bench<const R: usize, St: EntryStore = Log> {
    pub ground: Ground,
    pub glue: ServerGlue<St, R>,
    pub udp: Udp,
    pub board: BoardA,
    pub clock: Ms,
    pub heard: Heard,
    /// A datagram wrapper between the ground and the UDP socket (an attacker's stand-in).
    pub wrap: fn(&[u8]) -> Vec<u8>,
    /// The TC datagrams the ground sent.
    pub uplink: Vec<Vec<u8>>,
    /// The IVs of every TM frame the server board sent.
    pub tm_ivs: Vec<u128>,
    /// The TM frames the ground refused, why.
    pub ground_refused: Vec<String>,
}

pub fn clear(f: &[u8]) -> Vec<u8> {
    f.to_vec()
}

/// A protected frame's IV (octets 8..20: after the 6-octet primary header and the SPI).
pub fn iv(f: &[u8]) -> u128 {
    u128::from_be_bytes([&[0u8; 4][..], &f[8..20]].concat().try_into().unwrap())
}

impl Bench<1> {
    /// Robot 1 provisioned and served.
    pub fn new(wrap: fn(&[u8]) -> Vec<u8>) -> Self {
        Bench::with(glue([1], &partition(&[1]), provisioned(&[1])), wrap)
    }
}

impl<const R: usize, St: EntryStore> Bench<R, St> {
    pub fn with(glue: ServerGlue<St, R>, wrap: fn(&[u8]) -> Vec<u8>) -> Self {
        let mut b = Bench {
            ground: ground(1),
            glue,
            uplink: Vec::new(),
            udp: Udp::default(),
            board: BoardA::default(),
            clock: Ms(0),
            heard: Heard::default(),
            wrap,
            tm_ivs: Vec::new(),
            ground_refused: Vec::new(),
        };
        let mut up = Vec::new();
        b.ground.start(0, &mut |f: &[u8]| up.push(wrap(f)));
        b.deliver(up);
        b
    }

    fn deliver(&mut self, up: Vec<Vec<u8>>) {
        self.uplink.extend(up.iter().cloned());
        for d in up {
            self.udp.from_ground(d);
        }
    }

    pub fn send(&mut self, packet: &[u8]) {
        let (now, wrap) = (self.clock.0, self.wrap);
        let mut up = Vec::new();
        self.ground
            .send(packet, now, &mut |f: &[u8]| up.push(wrap(f)))
            .unwrap();
        persist_ground(&mut self.ground);
        self.deliver(up);
    }

    /// One pass of the glue at the clock's time, and the ground's answer to what it sent.
    pub fn pass(&mut self) {
        let now = self.clock.0;
        self.glue
            .poll(&mut self.clock, &mut self.udp, &mut self.board);
        let wrap = self.wrap;
        let mut up = Vec::new();
        for f in std::mem::take(&mut self.udp.sent) {
            self.tm_ivs.push(iv(&f));
            let mut tms = Vec::new();
            let got = self.ground.tm_frame(
                now,
                &f,
                &mut |t: &[u8]| up.push(wrap(t)),
                &mut |p: &[u8]| tms.push(p.to_vec()),
            );
            // The ground's SDLS may refuse a frame: beyond its durable floor after the server
            // board's restart moved the TM IVs a reservation ahead (it keeps the next floor,
            // and takes the next frame).
            if let Err(e) = got {
                self.ground_refused.push(format!("{e:?}"));
            }
            persist_ground(&mut self.ground);
            for p in tms {
                let tm = TmRepr::parse(&p, &[0x101]).unwrap();
                let (s, sub) = (tm.header.service, tm.header.subservice);
                self.heard.packets.push((s, sub));
                if s == 5 {
                    self.heard.events.push(tm.source_data.to_vec());
                }
                if s == 1 {
                    let r = Report::parse(sub, tm.source_data).unwrap();
                    let seq = r.request.seq_count;
                    self.heard.reports.push((seq, r.stage, r.failure.is_none()));
                    match (r.stage, r.failure) {
                        (Stage::Acceptance, None) => self.heard.accepted.push(seq),
                        (Stage::Completion, None) => self.heard.completed.push(seq),
                        _ => {}
                    }
                }
            }
        }
        self.ground.tick(now, &mut |f: &[u8]| up.push(wrap(f)));
        persist_ground(&mut self.ground);
        self.deliver(up);
    }

    /// Runs `ms` milliseconds in 1 ms passes.
    pub fn run(&mut self, ms: u32) {
        for _ in 0..ms {
            self.clock.0 += 1;
            self.pass();
        }
    }

    /// Runs 1 ms passes until `done` holds, at most `ms`; whether it did.
    pub fn run_until(&mut self, ms: u32, done: impl Fn(&Self) -> bool) -> bool {
        for _ in 0..ms {
            if done(self) {
                return true;
            }
            self.clock.0 += 1;
            self.pass();
        }
        done(self)
    }
}
