//! The space data link end to end in the library: the ground's [`GroundLink`] (FOP-1, the
//! packet extractor) and the server board's [`FrameGateway`] (FARM-1, the PUS gateway, the TM
//! framer) over frame channels that lose, duplicate and reorder, with a board A that answers
//! every legacy command at once. Every telecommand reaches the gateway exactly once and in
//! order (its ST[1] acceptance reports, read back through the TM frames, say so), whatever the
//! channels do; COP-1 retransmits what they lose.

use crate::common::Rng;
use mmic::ccsds::tm::TmRepr;
use mmic::link::farm::{DiscardReason, FarmState};
use mmic::link::fop::FopState;
use mmic::link::sdls::{mission, Key256};
use mmic::mode::Mode;
use mmic::node::ground::frames::GroundLink;
use mmic::node::server::frames::{FrameConfig, FrameGateway, Stored};
use mmic::node::server::gateway::Config;
use mmic::pus::verification::{Report, Stage};
use mmic::units::BoardNumber;
use mmic::wire::heartbeat::HeartbeatRepr;

type Server = FrameGateway<1, 4, 64, 4096>;
type Ground = GroundLink<10, 64, 1024>;

/// A frame channel: each frame lost, duplicated or held back with the given probabilities,
/// otherwise delivered after 2..=6 ms; seeded (tests/common's generator, xorshift64*).
struct Channel {
    rng: Rng,
    loss: f64,
    dup: f64,
    reorder: f64,
    queue: Vec<(u32, Vec<u8>)>,
    sent: u32,
    lost: u32,
    last: u32,
}

impl Channel {
    fn new(seed: u64, loss: f64, dup: f64, reorder: f64) -> Channel {
        Channel {
            rng: Rng(seed | 1),
            loss,
            dup,
            reorder,
            queue: Vec::new(),
            sent: 0,
            lost: 0,
            last: 0,
        }
    }

    fn uniform(&mut self) -> f64 {
        self.rng.uniform()
    }

    fn send(&mut self, now: u32, frame: &[u8]) {
        self.sent += 1;
        if self.uniform() < self.loss {
            self.lost += 1;
            return;
        }
        let copies = if self.uniform() < self.dup { 2 } else { 1 };
        for _ in 0..copies {
            // In order (after the last frame in order), unless held back to be overtaken.
            let mut at = (now + 2 + (self.uniform() * 5.0) as u32).max(self.last);
            self.last = at;
            if self.uniform() < self.reorder {
                at += 40;
            }
            self.queue.push((at, frame.to_vec()));
        }
    }

    fn due(&mut self, now: u32) -> Vec<Vec<u8>> {
        let (due, rest): (Vec<_>, Vec<_>) = self.queue.drain(..).partition(|(t, _)| *t <= now);
        self.queue = rest;
        let mut due = due;
        due.sort_by_key(|(t, _)| *t); // stable: frames due together keep their order
        due.into_iter().map(|(_, f)| f).collect()
    }
}

/// TC(8,1) perform function 6, Stop (spec/ccsds/functions.toml), numbered `seq`.
fn stop(seq: u16) -> Vec<u8> {
    crate::pus::function_tc(seq, &[6])
}

/// SDLS on both ends, and an attacker on the uplink.
#[derive(Clone, Copy, Default)]
struct Secure {
    /// Both ends secured (keys made from the seed at run time; no key is in the tree).
    sdls: bool,
    /// Of every step, the chance that the attacker sends a captured TC frame again, or a
    /// copy with one bit flipped (its FECF made good again, so that it reaches SDLS).
    attack: f64,
}

struct Run {
    /// Legacy commands board A ran (distinct sequence numbers answered).
    executed: usize,
    /// Legacy commands board A was given (copies included).
    given: usize,
    /// Frames the attacker sent.
    attacks: u32,
    /// The TC frames the uplink delivered (with an attacker: the first 1,000).
    captured: Vec<Vec<u8>>,
    /// The durable store: (end, SPI) → value.
    store: std::collections::BTreeMap<(&'static str, u16), u128>,
    /// The IVs of the TM frames the server sent.
    tm_ivs: Vec<u128>,
    /// When the last telecommand completed (the ground heard it), ms.
    done_ms: u32,
    /// The ST[5] SDLS reports the ground heard: (when, refused, reason).
    security_events: Vec<(u32, u16, u8)>,
    accepted: Vec<u16>,
    completed: Vec<u16>,
    ground: Ground,
    server: Server,
    up: Channel,
    down: Channel,
}

/// `n` pings sent at once through channels with `loss`, `dup` and `reorder` each way, for at
/// most `limit_ms` of simulated time (1 ms steps); board A answers every command 3 ms later.
/// What the server board asks to keep (SDLS counters, FARM-1's progress, the kept keys),
/// written to the run's store and confirmed, as a shell does before anything that depends on
/// it leaves the board.
fn keep(server: &mut Server, store: &mut std::collections::BTreeMap<(&'static str, u16), u128>) {
    for e in server.durable_due::<16>() {
        store.insert(("server", e.key), e.value);
        assert!(server.durable_written(&e), "{e:?}");
    }
}

fn run(n: u16, seed: u64, loss: f64, dup: f64, reorder: f64, limit_ms: u32) -> Run {
    run_secure(n, seed, loss, dup, reorder, limit_ms, Secure::default())
}

fn run_secure(
    n: u16,
    seed: u64,
    loss: f64,
    dup: f64,
    reorder: f64,
    limit_ms: u32,
    secure: Secure,
) -> Run {
    let board = BoardNumber::ONE;
    let mut server = Server::new(FrameConfig {
        gateway: Config {
            hk_enabled: false,
            ..Config::default()
        },
        ..FrameConfig::default()
    });
    assert!(server.add(board));
    let mut ground = Ground::new(board);
    let mut up = Channel::new(seed, loss, dup, reorder);
    let mut down = Channel::new(seed ^ 0x5555, loss, dup, reorder);
    let mut attacker = Channel::new(seed ^ 0xa77a, 0.0, 0.0, 0.0);
    let mut captured: Vec<Vec<u8>> = Vec::new();
    let (mut attacks, mut given) = (0u32, 0usize);
    let mut tm_ivs = Vec::new();
    let mut done_ms = 0;
    let mut security_events = Vec::new();
    // The durable store of both ends' SDLS counters.
    let mut store = std::collections::BTreeMap::new();
    if secure.sdls {
        let key = |k: u64| {
            let mut c = Channel::new(seed.wrapping_mul(31).wrapping_add(k), 0.0, 0.0, 0.0);
            let bytes: Vec<u8> = (0..32).map(|_| (c.uniform() * 256.0) as u8).collect();
            Key256::from_slice(&bytes).unwrap()
        };
        assert!(server
            .secure(board, key(1), key(2), Stored::default())
            .is_ok());
        ground.secure(key(1), key(2), (None, None));
    }
    let (mut accepted, mut completed) = (Vec::new(), Vec::new());
    let mut answers: Vec<(u32, u16)> = Vec::new();
    let mut ran = std::collections::BTreeSet::new();
    ground.start(0, &mut |f: &[u8]| up.send(0, f));
    for s in 0..n {
        ground
            .send(&stop(s), 0, &mut |f: &[u8]| up.send(0, f))
            .unwrap();
    }
    for now in 0..limit_ms {
        keep(&mut server, &mut store);
        for (spi, v) in ground.due().collect::<Vec<_>>() {
            store.insert(("ground", spi), v);
            ground.persisted(spi, v);
        }
        for f in up.due(now) {
            if secure.sdls && captured.len() < 1000 {
                captured.push(f.clone());
            }
            server.tc_frame(now, &f);
            keep(&mut server, &mut store);
        }
        if secure.attack > 0.0 && !captured.is_empty() && attacker.uniform() < secure.attack {
            let pick = (attacker.uniform() * captured.len() as f64) as usize;
            let mut f = captured[pick.min(captured.len() - 1)].clone();
            if attacker.uniform() < 0.5 {
                let bit = (attacker.uniform() * (f.len() - 2) as f64 * 8.0) as usize;
                f[bit / 8] ^= 0x80 >> (bit % 8);
                let n = f.len();
                let crc = mmic::ccsds::pec(&f[..n - 2]);
                f[n - 2..].copy_from_slice(&crc.to_be_bytes());
            }
            attacks += 1;
            server.tc_frame(now, &f);
        }
        for f in down.due(now) {
            let mut tms = Vec::new();
            let _ = ground.tm_frame(
                now,
                &f,
                &mut |t: &[u8]| up.send(now, t),
                &mut |p: &[u8]| tms.push(p.to_vec()),
            );
            for p in tms {
                let tm = TmRepr::parse(&p, &[0x101]).unwrap();
                if tm.header.service == 5 {
                    let e = mmic::pus::event::Event::parse(tm.header.subservice, tm.source_data);
                    if let Ok(mmic::pus::event::Event::Security {
                        reason, refused, ..
                    }) = e
                    {
                        security_events.push((now, refused, reason));
                    }
                }
                if tm.header.service == 1 {
                    let r = Report::parse(tm.header.subservice, tm.source_data).unwrap();
                    match (r.stage, r.failure) {
                        (Stage::Acceptance, None) => accepted.push(r.request.seq_count),
                        (Stage::Completion, None) => completed.push(r.request.seq_count),
                        (_, None) => {}
                        (stage, Some(f)) => panic!("{stage:?} failed: {f:?}"),
                    }
                }
            }
        }
        ground.tick(now, &mut |f: &[u8]| up.send(now, f));
        for (b, c) in server.tick(now) {
            assert_eq!(b, board);
            if c.command == mmic::command::Command::Stop {
                ran.insert(c.seq);
                given += 1;
            }
            answers.push((now + 3, c.seq));
        }
        let (due, rest): (Vec<_>, Vec<_>) = answers.iter().partition(|(t, _)| *t <= now);
        answers = rest;
        for (_, seq) in due {
            let hb = HeartbeatRepr {
                last_seq: seq,
                mode: Mode::Operational,
                ..HeartbeatRepr::default()
            };
            server.heartbeat(now, &hb);
        }
        let mut buf = [0u8; 256];
        while let Some((_, len)) = server.frame(now, &mut buf) {
            if secure.sdls {
                tm_ivs.push(u128::from_be_bytes(
                    [&[0u8; 4][..], &buf[8..20]].concat().try_into().unwrap(),
                ));
            }
            down.send(now, &buf[..len]);
        }
        if completed.len() == n as usize && done_ms == 0 {
            done_ms = now;
        }
        if completed.len() == n as usize && ground.fop().sent_len() == 0 {
            break;
        }
    }
    Run {
        executed: ran.len(),
        given,
        attacks,
        captured,
        store,
        tm_ivs,
        done_ms,
        security_events,
        accepted,
        completed,
        ground,
        server,
        up,
        down,
    }
}

// req: 232.0-B-4/TC-1, 232.0-B-4/TC-6, 232.0-B-4/TC-13, 232.0-B-4/TC-14, 232.0-B-4/TC-26
// req: 232.0-B-4/TC-27, 232.0-B-4/TC-28, 232.0-B-4/TC-34, 132.0-B-3/TM-41, 132.0-B-3/TM-65
// req: 232.1-B-2/FARM-10
#[test]
fn a_clean_link_delivers_every_telecommand_once_in_order() {
    let r = run(12, 1, 0.0, 0.0, 0.0, 20_000);
    let want: Vec<u16> = (0..12).collect();
    assert_eq!(r.accepted, want);
    assert_eq!(r.completed, want);
    assert_eq!(r.executed, want.len());
    let c = r.ground.counters();
    assert_eq!((c.packets, c.confirmed, c.alerts), (12, 12, [0; 7]));
    assert_eq!(r.ground.state(), FopState::Active);
    let farm = r.server.farm(BoardNumber::ONE).unwrap();
    assert_eq!((farm.vr(), farm.counters().accepted_ad), (12, 12));
    // Nothing lost: FARM-1 discarded only for want of room (the queue holds 4 of the 12) and
    // the frames FOP-1 had sent after one it refused (ahead of V(R)), or copies it had
    // passed (behind): go-back-N, never a lockout.
    for reason in [
        DiscardReason::LockoutArea,
        DiscardReason::Locked,
        DiscardReason::Invalid,
    ] {
        assert_eq!(farm.counters().discarded(reason), 0, "{reason:?}");
    }
    let no_buffer = farm.counters().discarded(DiscardReason::NoBuffer);
    assert_eq!(c.ad_frames, 12 + c.retransmissions);
    assert!(c.retransmissions >= no_buffer.min(1), "{c:?} {no_buffer}");
    println!(
        "clean: {} retransmissions after {no_buffer} frames found no room",
        c.retransmissions
    );
}

// req: 232.1-B-2/FARM-3, 232.1-B-2/FOP-7
#[test]
fn a_lossy_duplicating_reordering_link_still_delivers_once_in_order() {
    // 20 % of frames lost each way, 10 % duplicated, 10 % overtaken: many seeds. The ground
    // hears what survives of the reports (a lost TM frame takes its reports with it; the PUS
    // layer above asks again): those it hears come once and in order.
    let (mut retransmissions, mut alerts, mut lost) = (0, 0, 0);
    for seed in 1..=40 {
        let r = run(12, seed, 0.2, 0.1, 0.1, 120_000);
        assert_eq!(
            r.executed, 12,
            "seed {seed}: board A ran {} commands",
            r.executed
        );
        for heard in [&r.accepted, &r.completed] {
            // In order, counting each request at its first report (after an alert, the copies
            // the ground sends again are answered with their latest report once more).
            let mut first = heard.clone();
            let mut seen = std::collections::BTreeSet::new();
            first.retain(|s| seen.insert(*s));
            assert!(
                first.windows(2).all(|w| w[0] < w[1]),
                "seed {seed}: {heard:?}"
            );
        }
        // FARM-1 passes each frame once; after an alert the ground sends the purged packets
        // again in new frames, and the gateway's request keys answer those copies.
        let farm = r.server.farm(BoardNumber::ONE).unwrap();
        let packets = r.server.counters(BoardNumber::ONE).unwrap().tc_packets;
        if r.ground.counters().alerts.iter().sum::<u32>() == 0 {
            assert_eq!(
                farm.counters().accepted_ad,
                12,
                "seed {seed}: FARM-1 accepted each frame once"
            );
            assert_eq!(packets, 12, "seed {seed}");
        } else {
            assert!(
                packets >= 12 && farm.counters().accepted_ad == packets,
                "seed {seed}"
            );
        }
        assert!(
            r.up.lost > 0 && r.down.lost > 0,
            "seed {seed}: the channels lost nothing"
        );
        retransmissions += r.ground.counters().retransmissions;
        alerts += r.ground.counters().alerts.iter().sum::<u32>();
        lost += r.up.lost + r.down.lost;
    }
    assert!(retransmissions > 0);
    println!("40 runs: {lost} frames lost, {retransmissions} retransmissions, {alerts} alerts");
}

// req: 232.1-B-2/FARM-5, 232.1-B-2/FARM-9
#[test]
fn a_full_queue_holds_frames_back_with_wait_and_loses_none() {
    // Board A never answers: the gateway's queue (4) fills, FARM-1 goes to Wait, and FOP-1
    // keeps the rest. Nothing is refused at the PUS level for a full queue.
    let board = BoardNumber::ONE;
    let mut server = Server::new(FrameConfig::default());
    server.add(board);
    let mut ground = Ground::new(board);
    let mut frames: Vec<Vec<u8>> = Vec::new();
    ground.start(0, &mut |f: &[u8]| frames.push(f.to_vec()));
    let mut buf = [0u8; 256];
    let (_, n) = server.frame(0, &mut buf).unwrap();
    ground
        .tm_frame(
            0,
            &buf[..n],
            &mut |f: &[u8]| frames.push(f.to_vec()),
            &mut |_p: &[u8]| {},
        )
        .unwrap();
    for s in 0..8 {
        ground
            .send(&stop(s), 1, &mut |f: &[u8]| frames.push(f.to_vec()))
            .unwrap();
    }
    // The gateway holds telecommands until board A's first heartbeat: the queue takes 4.
    let mut store = std::collections::BTreeMap::new();
    for f in frames.drain(..) {
        server.tc_frame(2, &f);
        keep(&mut server, &mut store);
    }
    let farm = server.farm(board).unwrap();
    assert_eq!(farm.state(), FarmState::Wait);
    assert_eq!(farm.vr(), 4);
    assert_eq!(server.gateway().queue_room(board), Some(0));
    // The CLCW says Wait; the ground stops sending new frames.
    let (_, n) = server.frame(3, &mut buf).unwrap();
    ground
        .tm_frame(
            3,
            &buf[..n],
            &mut |f: &[u8]| frames.push(f.to_vec()),
            &mut |_p: &[u8]| {},
        )
        .unwrap();
    assert_eq!(ground.state(), FopState::RetransmitWithWait);
    assert!(frames.is_empty());
}

/// SDLS on both ends over the lossy link, with an attacker on the uplink who sends captured
/// frames again (replays) or with one bit flipped (the FECF made good): every telecommand is
/// still given to board A exactly once per request, every attack is refused by SDLS (none
/// reaches FARM-1 or the PUS layer), and the ground's retransmissions, each under a fresh IV,
/// get through.
// req: 232.0-B-4/TC-49, 132.0-B-3/TM-89, 132.0-B-3/TM-90, 132.0-B-3/TM-91, 132.0-B-3/TM-92
// req: 132.0-B-3/TM-93, 132.0-B-3/TM-94, 132.0-B-3/TM-95, 132.0-B-3/TM-96, 132.0-B-3/TM-97
// req: 132.0-B-3/TM-100, 132.0-B-3/TM-101, 132.0-B-3/TM-102, 355.0-B-2/SDLS-1
// req: 355.0-B-2/SDLS-13, 355.0-B-2/SDLS-14
#[test]
#[cfg_attr(miri, ignore = "AES under Miri: minutes per seed")]
fn sdls_under_attack_delivers_once_and_refuses_every_forgery() {
    let (mut attacks, mut refused) = (0u32, 0u32);
    for seed in 1..=12 {
        let secure = Secure {
            sdls: true,
            attack: 0.02,
        };
        let r = run_secure(12, seed, 0.2, 0.1, 0.1, 120_000, secure);
        assert_eq!(
            r.executed, 12,
            "seed {seed}: board A ran {} commands",
            r.executed
        );
        let link = r.server.counters(BoardNumber::ONE).unwrap();
        assert_eq!(
            link.tc_packets_refused, 0,
            "seed {seed}: a forged packet reached the PUS layer"
        );
        let sec = r.server.security(BoardNumber::ONE).unwrap();
        // Replays and forgeries are refused; a replay that FARM-1 had passed before is
        // refused as a replay, and no attack frame was accepted: every accepted frame is one
        // of the ground's transmissions.
        let ground = r.ground.counters();
        assert!(
            sec.accepted <= ground.ad_frames + ground.bc_frames,
            "seed {seed}: SDLS accepted {} frames, the ground sent {}",
            sec.accepted,
            ground.ad_frames
        );
        // Every attack frame is refused, by a frame check (a flip in a fixed header field) or
        // by SDLS (replays, and the channel's own duplicates, too).
        let checks: u32 = r.server.refused().iter().sum();
        assert!(
            sec.refused_total() + checks >= r.attacks,
            "seed {seed}: {sec:?} {}",
            r.attacks
        );
        assert_eq!(
            r.given, r.executed,
            "seed {seed}: board A was given a command twice"
        );
        // The ground refuses only the downlink's duplicates and overtaken frames, as replays.
        let tm = r.ground.security().unwrap();
        assert_eq!(
            tm.refused_total(),
            tm.refused_for("replay"),
            "seed {seed}: {tm:?}"
        );
        attacks += r.attacks;
        refused += sec.refused_total();
    }
    assert!(attacks > 100, "{attacks}");
    println!("12 runs: {attacks} attack frames, SDLS refused {refused} frames");
}

/// Counters survive a restart of the server board: a new gateway started from the durable
/// store refuses every data frame captured before the restart (as a replay), and its TM
/// counter continues above every IV used before (no IV under the TM key twice).
#[test]
#[cfg_attr(miri, ignore = "AES under Miri: minutes")]
fn sdls_counters_survive_a_restart_of_the_server_board() {
    let secure = Secure {
        sdls: true,
        attack: 0.0,
    };
    let r = run_secure(12, 7, 0.0, 0.0, 0.0, 20_000, secure);
    assert_eq!(r.executed, 12);
    let board = BoardNumber::ONE;
    let (tc_spi, tm_spi) = (mission::tc_spi(board), mission::tm_spi(board));
    let stored = Stored {
        tc: r.store.get(&("server", tc_spi)).copied(),
        tm: r.store.get(&("server", tm_spi)).copied(),
        // Without FARM-1's progress: the window resumes from the floor alone.
        progress: None,
    };
    assert!(stored.tc.is_some() && stored.tm.is_some(), "{:?}", r.store);
    let mut again = Server::new(FrameConfig::default());
    assert!(again.add(board));
    // The same keys as the run's (made from its seed the same way).
    let key = |k: u64| {
        let mut c = Channel::new(7u64.wrapping_mul(31).wrapping_add(k), 0.0, 0.0, 0.0);
        let bytes: Vec<u8> = (0..32).map(|_| (c.uniform() * 256.0) as u8).collect();
        Key256::from_slice(&bytes).unwrap()
    };
    assert!(again.secure(board, key(1), key(2), stored).is_ok());
    let mut store = std::collections::BTreeMap::new();
    keep(&mut again, &mut store);
    let data_frames: Vec<_> = r.captured.iter().filter(|f| f[0] & 0x10 == 0).collect();
    assert!(data_frames.len() >= 12);
    for f in &data_frames {
        let got = again.tc_frame(0, f);
        assert_eq!(got.verdict.unwrap_err().name(), "replay", "{f:02x?}");
    }
    assert_eq!(
        again.security(board).unwrap().refused_for("replay") as usize,
        data_frames.len()
    );
    let mut buf = [0u8; 256];
    let (_, n) = again.frame(1_000, &mut buf).unwrap();
    let iv = u128::from_be_bytes([&[0u8; 4][..], &buf[8..20]].concat().try_into().unwrap());
    let before = r.tm_ivs.iter().max().copied().unwrap();
    assert!(
        iv > before,
        "the TM IV after the restart {iv} is not above {before}"
    );
    assert_eq!(n, 256);
}

/// A flood of bad frames does not delay the good ones: the same run (seed, channels, the
/// ground's commands) with an attacker sending a replayed or forged TC frame every
/// millisecond (1,000 a second, about 20 times the ground's own frames) completes its
/// telecommands in the same order, FARM-1 accepting each frame once, and no later than a TM
/// frame's gathering time (20 ms) after the quiet run (the ST[5] reports the flood causes
/// share the TM frames, which moves the downlink's timing by a few ms either way); the
/// refusals are reported in ST[5] at most once per reason a second, and the reports count
/// every refused frame.
// req: 355.0-B-2/SDLS-15
#[test]
#[cfg_attr(miri, ignore = "AES under Miri: minutes")]
fn a_flood_of_bad_frames_does_not_delay_good_ones() {
    let quiet = run_secure(
        12,
        3,
        0.0,
        0.0,
        0.0,
        60_000,
        Secure {
            sdls: true,
            attack: 0.0,
        },
    );
    let flood = run_secure(
        12,
        3,
        0.0,
        0.0,
        0.0,
        60_000,
        Secure {
            sdls: true,
            attack: 1.0,
        },
    );
    assert_eq!(quiet.completed, (0..12).collect::<Vec<u16>>());
    assert_eq!(flood.completed, quiet.completed);
    assert!(
        flood.done_ms <= quiet.done_ms + 20,
        "the flood delayed the telecommands: {} ms against {} ms",
        flood.done_ms,
        quiet.done_ms
    );
    let accepted = |r: &Run| {
        r.server
            .farm(BoardNumber::ONE)
            .unwrap()
            .counters()
            .accepted_ad
    };
    assert_eq!((accepted(&flood), accepted(&quiet)), (12, 12));
    let sec = *flood.server.security(BoardNumber::ONE).unwrap();
    assert!(
        flood.attacks >= flood.done_ms / 2,
        "{} attacks in {} ms",
        flood.attacks,
        flood.done_ms
    );
    // Rate-limited: at most one report per reason per second (7 reasons).
    let secs = flood.done_ms / 1000 + 2;
    assert!(
        flood.security_events.len() as u32 <= 7 * secs,
        "{} reports in {secs} s",
        flood.security_events.len()
    );
    for reason in 0..7u8 {
        let mut times = flood
            .security_events
            .iter()
            .filter(|e| e.2 == reason)
            .map(|e| e.0);
        if let Some(mut prev) = times.next() {
            for t in times {
                assert!(
                    t - prev >= 990,
                    "reason {reason}: reports {prev} and {t} ms"
                );
                prev = t;
            }
        }
    }
    // Every refusal counted in a report, but those of the last second still waiting.
    let reported: u32 = flood.security_events.iter().map(|e| u32::from(e.1)).sum();
    let checks: u32 = flood.server.refused().iter().sum();
    assert!(reported <= sec.refused_total(), "{reported} > {sec:?}");
    assert!(reported > 0 && sec.refused_total() + checks >= flood.attacks);
    assert!(quiet.security_events.is_empty());
    println!(
        "flood: {} attack frames in {} ms, {} refused by SDLS, {} ST[5] reports counting {reported}; done at {} ms (quiet: {} ms)",
        flood.attacks,
        flood.done_ms,
        sec.refused_total(),
        flood.security_events.len(),
        flood.done_ms,
        quiet.done_ms
    );
}

/// A robot is served once, and no more robots than the gateway has places for.
#[test]
fn a_robot_is_served_once_and_the_places_are_counted() {
    let mut server = Server::new(FrameConfig::default());
    assert!(server.add(BoardNumber::ONE));
    assert!(!server.add(BoardNumber::ONE), "served twice");
    assert!(
        !server.add(BoardNumber::new(2).unwrap()),
        "one place (R = 1)"
    );
}
