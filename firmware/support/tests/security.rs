//! Issue 38 in the server image's and board A's glue, on the host: a store that is blank, of
//! another key, or full of other robots' entries, and a keys partition that is blank, corrupt
//! or weak, stop that robot's link (named), never the board, never a panic, and leave the
//! flash as it was; a failing flash is left alone for a doubling wait; FARM-1's progress and
//! the gateway's kept telecommand keys survive a restart (a telecommand forwarded before it is
//! not run again after it, FARM-1 resumes at its V(R)); BC frames from elsewhere than the
//! ground's address are not obeyed; board A keeps a command connection only from the server
//! board, the server takes a visit's heartbeat only from the visited board A; the WiFi
//! passphrase has no default.

mod bench;
mod common;

use std::cell::{Cell, RefCell};
use std::rc::Rc;

use bench::{clear, config, keys_of, partition, provisioned, read_keys, tc, tc_for, Bench};
use common::Ram;
use crc::{Crc, CRC_32_ISO_HDLC};
use embedded_storage::nor_flash::{ErrorType, NorFlash, NorFlashErrorKind, ReadNorFlash};
use mmic::command::Command;
use mmic::link::tc_frame::TcContent;
use mmic::link::ControlCommand;
use mmic::node::server::frames::Origin;
use mmic::node::server::store::keys::{self, KeysError};
use mmic::node::server::store::{self, log, End, Entry, Resume, Stopped};
use mmic::pus::verification::Stage;
use mmic::units::BoardNumber;
use mmic_fw_support::counters::{FlashLog, LogState};
use mmic_fw_support::net;
use mmic_fw_support::server::{
    open_store, LinkStop, PartitionFault, ServerGlue, BACKOFF_MAX_MS, BACKOFF_MIN_MS,
    ENTRIES_PER_ROBOT, FOREIGN,
};

fn b(n: u8) -> BoardNumber {
    BoardNumber::new(n).unwrap()
}

fn refused<const R: usize, St: mmic_fw_support::counters::EntryStore>(b: &Bench<R, St>) -> u32 {
    b.glue.gateway().refused().iter().sum()
}

fn stops<const R: usize, St: mmic_fw_support::counters::EntryStore>(b: &Bench<R, St>) -> usize {
    b.board
        .commands
        .iter()
        .filter(|c| c.command == Command::Stop)
        .count()
}

// ---------------------------------------------------------------------------------------------
// The store.

/// Robot 2's keys are in the partition but its store was never provisioned: its link is
/// stopped (unprovisioned, naming the SPI), its frames are refused before any FARM-1, and robot
/// 1 is served as before.
#[test]
fn a_blank_store_stops_that_robots_link_and_the_board_serves_the_others() {
    let glue = bench::glue([1, 2], &partition(&[1, 2]), provisioned(&[1]));
    assert_eq!(
        glue.stopped(),
        [(b(2), LinkStop::Boot(Stopped::Unprovisioned { spi: 0x102 }))]
    );
    assert!(glue.serves(b(1)) && !glue.serves(b(2)));
    assert_eq!(glue.stopped()[0].1.name(), "unprovisioned");
    let mut bench = Bench::with(glue, clear);
    bench.run(50);
    let before = refused(&bench);
    // Robot 2's telecommand as anyone could send it (its link would take BD frames in clear
    // were it served without SDLS).
    bench
        .udp
        .from_ground(bench::bd(2, &tc_for(2, 8, 1, 0, &[6])));
    bench.send(&tc(8, 1, 0, &[6]));
    bench.run(3000);
    assert_eq!(refused(&bench) - before, 1);
    assert!(bench.board.commands.iter().all(|c| c.board == b(1)));
    assert_eq!(stops(&bench), 1);
    assert_eq!(bench.heard.completed, [0]);
    // Robot 1's telemetry says why robot 2's link is stopped: ST[5] link_stopped (0x0005),
    // board 2, reason 0 (unprovisioned), at severity 4.
    assert!(
        bench.heard.events.contains(&vec![0, 5, 2, 0, 0, 0]),
        "{:?}",
        bench.heard.events
    );
    assert!(bench.heard.packets.contains(&(5, 4)));
}

/// An erased counters partition (`espflash erase-region`): every link stopped, nothing sent,
/// nothing written — the store is not made into a fresh one, whose counters at 0 would reuse
/// IVs under the same keys.
#[test]
fn an_erased_store_stops_every_link_and_stays_erased() {
    let glue = bench::glue([1], &partition(&[1]), Ram::erased(2));
    assert_eq!(
        glue.stopped(),
        [(b(1), LinkStop::Boot(Stopped::Unprovisioned { spi: 257 }))]
    );
    let mut bench = Bench::with(glue, clear);
    assert_eq!(bench.glue.store().unwrap().state(), LogState::Blank);
    bench.udp.from_ground(bench::bd(1, &tc(8, 1, 0, &[6])));
    bench.run(3000);
    assert!(bench.board.commands.is_empty() && bench.tm_ivs.is_empty());
    assert_eq!(refused(&bench), 1);
    let ram = bench::flash_of(&mut bench.glue);
    assert!(ram.mem.iter().all(|&x| x == 0xFF));
    assert_eq!(ram.erases, 0);
}

/// The store provisioned for another TM key (a spare board's, or keys changed without
/// provisioning): the link is stopped (other key, naming the SPI) and the store left as it
/// was, so the right keys find it whole afterwards.
#[test]
fn a_store_of_another_key_stops_the_link_and_is_left_whole() {
    let (tc_key, _) = keys_of(1);
    let other = bench::key(777);
    let mut part = vec![0xFF; 4096];
    keys::emit(&[(257, &tc_key), (513, &other)], &mut part).unwrap();
    let ram = provisioned(&[1]);
    let image = ram.mem.clone();
    let glue = bench::glue([1], &part, ram);
    assert_eq!(
        glue.stopped(),
        [(b(1), LinkStop::Boot(Stopped::OtherKey { spi: 513 }))]
    );
    let mut bench = Bench::with(glue, clear);
    bench.run(2000);
    assert!(bench.tm_ivs.is_empty() && bench.board.commands.is_empty());
    let ram = bench::flash_of(&mut bench.glue);
    assert_eq!(ram.mem, image);
    // With its own keys the same store starts the link.
    let glue = bench::glue([1], &partition(&[1]), ram.reset());
    assert!(glue.stopped().is_empty() && glue.serves(b(1)));
}

/// A store holding other robots' entries and keys of no robot (another image's, or written by
/// hand), nearly full: robot 1 is served, the others' entries are set apart (reported: the
/// first [`FOREIGN`] kept, the rest counted), and the compactions robot 1's traffic causes
/// carry them, with no `Full` and no panic.
#[test]
fn a_store_with_other_robots_entries_is_served_and_reports_them() {
    let mut entries = Vec::new();
    for n in 2..=9u8 {
        let (tc_key, tm_key) = keys_of(n);
        entries
            .extend(store::provision(End::Server, b(n), &tc_key, &tm_key, Resume::FRESH).unwrap());
    }
    for k in 0..150u16 {
        entries.push(Entry {
            key: 0x7000 + k,
            aux: 0,
            value: u128::from(k),
        });
    }
    let foreign = entries.len();
    let (tc_key, tm_key) = keys_of(1);
    entries.extend(store::provision(End::Server, b(1), &tc_key, &tm_key, Resume::FRESH).unwrap());
    let mut image = vec![0u8; 2 * common::SECTOR];
    log::image(&entries, common::SECTOR, &mut image).unwrap();
    let mut glue = bench::glue([1], &partition(&[1]), Ram::from_image(&image));
    assert!(glue.stopped().is_empty(), "{:?}", glue.stopped());
    let log = glue.store().unwrap();
    assert_eq!(log.foreign().len(), FOREIGN);
    assert_eq!(log.dropped() as usize, foreign - FOREIGN);
    assert!(log.free_slots() < 20);
    let mut bench = Bench::with(glue, clear);
    bench.run(100);
    for seq in 0..12 {
        bench.send(&tc(17, 1, seq, &[]));
        bench.run(300);
    }
    bench.run(2000);
    assert_eq!(bench.heard.completed, (0..12).collect::<Vec<u16>>());
    let log = bench.glue.store().unwrap();
    assert!(log.generation() >= 2, "no compaction: {}", log.generation());
    assert!(bench.glue.counts().store_failed == 0);
    let ram = bench::flash_of(&mut bench.glue);
    let boards = [b(1)];
    let log: bench::Log = open_store(ram.reset(), &boards).unwrap();
    assert_eq!(log.foreign().len(), FOREIGN);
    assert!(log.entries().len() <= ENTRIES_PER_ROBOT);
}

// ---------------------------------------------------------------------------------------------
// The keys partition.

/// A keys partition with robot 1's keys whose TM key is replaced by `weak` (the CRC made good).
fn with_weak_key(weak: [u8; 32]) -> Vec<u8> {
    let mut part = partition(&[1]);
    let at = keys::HEADER_LEN + keys::ENTRY_LEN + 4;
    part[at..at + 32].copy_from_slice(&weak);
    let body = keys::HEADER_LEN + 2 * keys::ENTRY_LEN;
    let crc = Crc::<u32>::new(&CRC_32_ISO_HDLC).checksum(&part[..body]);
    part[body..body + 4].copy_from_slice(&crc.to_be_bytes());
    part
}

/// Blank, corrupt, weak or absent: every link stopped with the reason, the board runs, nothing
/// is sent or written, the read buffer cleared (`read_keys` checks it).
#[test]
fn a_blank_corrupt_or_weak_keys_partition_stops_every_link() {
    let mut corrupt = partition(&[1, 2]);
    corrupt[40] ^= 0x01;
    let (test_name, test_key) = mmic::link::sdls::key::test_keys()[0];
    let cases: Vec<(&str, Result<_, LinkStop>)> = vec![
        ("blank", read_keys(&[0xFF; 4096])),
        ("corrupt", read_keys(&corrupt)),
        ("all zero", read_keys(&with_weak_key([0; 32]))),
        (test_name, read_keys(&with_weak_key(test_key))),
        (
            "absent",
            Err(LinkStop::KeysPartition(PartitionFault::Absent)),
        ),
    ];
    for (what, keys) in cases {
        let why = keys.as_ref().err().copied().expect(what);
        match (what, why) {
            ("blank", LinkStop::Keys(KeysError::Blank))
            | ("corrupt", LinkStop::Keys(KeysError::Crc { .. }))
            | ("absent", LinkStop::KeysPartition(PartitionFault::Absent)) => {}
            (_, LinkStop::Keys(KeysError::Weak { spi: 513, .. })) => {}
            _ => panic!("{what}: {why:?}"),
        }
        let ram = provisioned(&[1, 2]);
        let image = ram.mem.clone();
        let boards = [b(1), b(2)];
        let glue: ServerGlue<bench::Log, 2> = ServerGlue::new(
            config(),
            &boards,
            keys.as_ref().map_err(|e| *e),
            open_store(ram, &boards),
        );
        assert_eq!(glue.stopped(), [(b(1), why), (b(2), why)], "{what}");
        // The reason reads well and shows no key.
        let line = glue.stopped()[0].1.to_string();
        assert!(line.contains("mmic_keys"), "{what}: {line}");
        let mut bench = Bench::with(glue, clear);
        bench.udp.from_ground(bench::bd(1, &tc(8, 1, 0, &[6])));
        bench.run(1000);
        assert!(
            bench.tm_ivs.is_empty() && bench.board.commands.is_empty(),
            "{what}"
        );
        assert_eq!(bench::flash_of(&mut bench.glue).mem, image, "{what}");
    }
}

/// The counters partition missing or unreadable: every link stopped, the board runs.
#[test]
fn no_counters_partition_stops_every_link() {
    let keys = read_keys(&partition(&[1]));
    let glue: ServerGlue<bench::Log, 1> = ServerGlue::new(
        config(),
        &[b(1)],
        keys.as_ref().map_err(|e| *e),
        Err(LinkStop::StorePartition(PartitionFault::Absent)),
    );
    assert_eq!(
        glue.stopped(),
        [(b(1), LinkStop::StorePartition(PartitionFault::Absent))]
    );
    let mut bench = Bench::with(glue, clear);
    bench.run(500);
    assert!(bench.glue.store().is_none() && bench.tm_ivs.is_empty());
}

// ---------------------------------------------------------------------------------------------
// A failing flash.

/// NOR flash that fails every erase and write while `fail` is set, and notes when each was
/// tried (the test's clock, `now`).
#[derive(Clone)]
struct Faulty {
    ram: Rc<RefCell<Ram>>,
    fail: Rc<Cell<bool>>,
    now: Rc<Cell<u32>>,
    tries: Rc<RefCell<Vec<u32>>>,
}

impl ErrorType for Faulty {
    type Error = NorFlashErrorKind;
}

impl ReadNorFlash for Faulty {
    const READ_SIZE: usize = 4;
    fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), Self::Error> {
        self.ram.borrow_mut().read(offset, bytes)
    }
    fn capacity(&self) -> usize {
        self.ram.borrow().capacity()
    }
}

impl Faulty {
    fn attempt(&mut self) -> Result<(), NorFlashErrorKind> {
        self.tries.borrow_mut().push(self.now.get());
        if self.fail.get() {
            Err(NorFlashErrorKind::Other)
        } else {
            Ok(())
        }
    }
}

impl NorFlash for Faulty {
    const WRITE_SIZE: usize = 4;
    const ERASE_SIZE: usize = common::SECTOR;
    fn erase(&mut self, from: u32, to: u32) -> Result<(), Self::Error> {
        self.attempt()?;
        self.ram.borrow_mut().erase(from, to)
    }
    fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), Self::Error> {
        self.attempt()?;
        self.ram.borrow_mut().write(offset, bytes)
    }
}

/// A flash that fails every write from some instant: the glue tries again after 10 ms, then
/// after a wait that doubles to 1 s (counted), not on every pass; the progress it could not
/// write holds back the TM frames and the visit; once the flash works again the telecommand
/// runs once and completes.
#[test]
fn a_failing_flash_write_backs_off() {
    let faulty = Faulty {
        ram: Rc::new(RefCell::new(provisioned(&[1]))),
        fail: Rc::new(Cell::new(false)),
        now: Rc::new(Cell::new(0)),
        tries: Rc::new(RefCell::new(Vec::new())),
    };
    type Log = FlashLog<Faulty, { ENTRIES_PER_ROBOT }, { FOREIGN }>;
    let keys = read_keys(&partition(&[1]));
    let log: Result<Log, _> = open_store(faulty.clone(), &[b(1)]);
    let glue: ServerGlue<Log, 1> =
        ServerGlue::new(config(), &[b(1)], keys.as_ref().map_err(|e| *e), log);
    let mut bench = Bench::with(glue, clear);
    let step = |bench: &mut Bench<1, Log>| {
        bench.clock.0 += 1;
        faulty.now.set(bench.clock.0);
        bench.pass();
    };
    for _ in 0..200 {
        step(&mut bench);
    }
    assert_eq!(bench.glue.counts().store_failed, 0);
    faulty.fail.set(true);
    faulty.tries.borrow_mut().clear();
    bench.send(&tc(8, 1, 0, &[6]));
    let mut frames_at_failure = None;
    for _ in 0..3000 {
        step(&mut bench);
        if frames_at_failure.is_none() && !faulty.tries.borrow().is_empty() {
            frames_at_failure = Some(bench.tm_ivs.len());
        }
    }
    let tries = faulty.tries.borrow().clone();
    // One write tried per try; the waits between tries double from 10 ms to 1 s.
    let gaps: Vec<u32> = tries.windows(2).map(|w| w[1] - w[0]).collect();
    let mut want = Vec::new();
    let mut w = BACKOFF_MIN_MS;
    for _ in 0..gaps.len() {
        want.push(w);
        w = (2 * w).min(BACKOFF_MAX_MS);
    }
    assert_eq!(gaps, want, "tries at {tries:?}");
    assert!(
        (9..=11).contains(&tries.len()),
        "{} tries in 3 s",
        tries.len()
    );
    let c = *bench.glue.counts();
    assert_eq!(c.store_failed as usize, tries.len());
    assert!(c.store_deferred > 2000, "{c:?}");
    assert_eq!(bench.glue.backoff_ms(), Some(BACKOFF_MAX_MS));
    // Held back: no TM frame (its CLCW would show the unkept V(R)), no visit with the Stop.
    assert_eq!(Some(bench.tm_ivs.len()), frames_at_failure);
    assert_eq!(stops(&bench), 0);
    // The flash works again: within the wait, the progress is kept and everything goes on.
    faulty.fail.set(false);
    for _ in 0..3000 {
        step(&mut bench);
    }
    assert_eq!(bench.glue.backoff_ms(), None);
    assert_eq!(stops(&bench), 1);
    assert_eq!(bench.heard.completed, [0]);
    assert_eq!(bench.glue.counts().store_failed as usize, tries.len());
}

// ---------------------------------------------------------------------------------------------
// Across a restart.

/// A telecommand forwarded to board A just before the server board restarts (its heartbeat
/// lost with the restart): after the restart FARM-1 resumes at its V(R), the ground's resend of
/// the telecommand under the same key is answered and not run again (the gateway's kept keys,
/// decision `restart-server`), and commanding goes on.
#[test]
fn the_kept_keys_and_farm_progress_survive_a_restart() {
    let mut bench = Bench::new(clear);
    bench.run(100);
    bench.board.silent = true;
    bench.send(&tc(8, 1, 0, &[6]));
    assert!(bench.run_until(3000, |b| stops(b) == 1));
    let vr = bench.glue.gateway().farm(b(1)).unwrap().vr();
    assert!(vr >= 1);
    // The restart, with the command in flight.
    let ram = bench::flash_of(&mut bench.glue);
    bench.glue = bench::glue([1], &partition(&[1]), ram.reset());
    assert!(
        bench.glue.stopped().is_empty(),
        "{:?}",
        bench.glue.stopped()
    );
    assert_eq!(bench.glue.gateway().farm(b(1)).unwrap().vr(), vr);
    assert!(bench.glue.gateway().kept(b(1)).is_some());
    bench.board.silent = false;
    bench.heard = Default::default();
    // The ground heard no completion: it sends the telecommand again under the same key, once
    // a second until it hears of it (the first TM frame after the restart is refused by the
    // ground's SDLS as beyond its durable floor, with the reports it carried: decision
    // `restart-server`).
    let mut resends = 0;
    while !bench.heard.reports.iter().any(|r| r.0 == 0) && resends < 5 {
        bench.send(&tc(8, 1, 0, &[6]));
        resends += 1;
        bench.run(1000);
    }
    assert!(
        bench.heard.reports.iter().any(|r| r.0 == 0),
        "{:?}, {:?}",
        bench.heard,
        bench.ground_refused
    );
    bench.run(1000);
    assert_eq!(
        stops(&bench),
        1,
        "the telecommand ran again after the restart"
    );
    assert!(
        !bench.heard.completed.contains(&0),
        "{:?}",
        bench.heard.reports
    );
    // FARM-1 took every resend at once: none refused as out of sequence or replayed.
    let farm = bench.glue.gateway().farm(b(1)).unwrap();
    assert_eq!(farm.vr(), vr.wrapping_add(resends));
    assert_eq!(farm.counters().discarded, [0; 6]);
    let sec = bench.glue.gateway().security(b(1)).unwrap();
    assert_eq!(sec.refused_total(), 0, "{sec:?}");
    // And commanding goes on.
    bench.send(&tc(17, 1, 1, &[]));
    assert!(bench.run_until(3000, |b| b.heard.completed.contains(&1)));
    assert_eq!(stops(&bench), 1);
    assert!(bench
        .heard
        .reports
        .iter()
        .any(|&(seq, stage, ok)| seq == 0 && stage != Stage::Completion && !ok));
}

/// A telecommand FARM-1 accepted and the gateway still held in its queue when the server board
/// restarted (board A had not answered yet: the gateway holds telecommands until its first
/// heartbeat) is restored from the store's queue and runs once after the restart: the ground,
/// whose CLCW acknowledged it, never sends it again (decision `restart-server`, write-ahead).
#[test]
fn a_telecommand_queued_at_a_restart_runs_once_after_it() {
    let mut bench = Bench::new(clear);
    bench.board.silent = true;
    bench.run(100);
    bench.send(&tc(8, 1, 0, &[6]));
    bench.run(500);
    assert_eq!(stops(&bench), 0);
    assert!(bench.heard.accepted.contains(&0), "{:?}", bench.heard);
    assert_eq!(bench.glue.gateway().gateway().queued(b(1)).len(), 1);
    let ram = bench::flash_of(&mut bench.glue);
    bench.glue = bench::glue([1], &partition(&[1]), ram.reset());
    assert!(bench.glue.stopped().is_empty());
    assert_eq!(bench.glue.gateway().gateway().queued(b(1)).len(), 1);
    bench.board.silent = false;
    assert!(bench.run_until(3000, |b| stops(b) == 1));
    bench.run(2000);
    assert_eq!(stops(&bench), 1, "the restored telecommand ran again");
    // Its reports may be lost with the first TM frames after the restart (the ground's SDLS
    // refuses them as beyond its floor: decision sdls-counters); commanding goes on.
    bench.send(&tc(17, 1, 1, &[]));
    assert!(bench.run_until(3000, |b| b.heard.completed.contains(&1)));
    assert_eq!(stops(&bench), 1);
}

// ---------------------------------------------------------------------------------------------
// Who may speak.

/// Set V(R) from another station on the ground's network, or from a source the socket cannot
/// name: FARM-1 does not obey it (counted by the library and the glue); from the ground's
/// address, it does (232.1). The ground's data frames are judged by SDLS wherever they come
/// from.
#[test]
fn bc_frames_from_elsewhere_are_not_obeyed() {
    let mut bench = Bench::new(clear);
    bench.run(100);
    assert_eq!(bench.glue.gateway().farm(b(1)).unwrap().vr(), 0);
    let set = bench::frame(1, TcContent::Bc(ControlCommand::SetVr(7)));
    bench
        .udp
        .inbox
        .push_back((set.clone(), Some([192, 168, 4, 66])));
    bench.udp.inbox.push_back((set.clone(), None));
    bench.run(1);
    assert_eq!(bench.glue.gateway().farm(b(1)).unwrap().vr(), 0);
    assert_eq!(bench.glue.gateway().counters(b(1)).unwrap().bc_origin, 2);
    assert_eq!(bench.glue.counts().tc_elsewhere, 2);
    bench.udp.from_ground(set);
    bench.run(1);
    assert_eq!(bench.glue.gateway().farm(b(1)).unwrap().vr(), 7);
    assert_eq!(bench.glue.gateway().counters(b(1)).unwrap().bc_origin, 2);
    assert_eq!(net::origin(Some(net::GROUND)), Origin::Ground);
    assert_eq!(net::origin(Some(net::SERVER)), Origin::Elsewhere);
    assert_eq!(net::origin(None), Origin::Elsewhere);
}

/// Board A keeps an accepted command connection only from the server board's address (any
/// port): the ground, another robot's board A, any station, an unnamed peer are aborted.
#[test]
fn board_a_takes_commands_only_from_the_server_board() {
    assert!(net::command_peer(Some((net::SERVER, 49152))));
    assert!(net::command_peer(Some((net::SERVER, 1))));
    for other in [
        net::GROUND,
        net::robot(1),
        net::robot(2),
        [192, 168, 4, 66],
        [192, 168, 5, 2],
        [10, 0, 0, 2],
        [0, 0, 0, 0],
        [255, 255, 255, 255],
    ] {
        assert!(!net::command_peer(Some((other, 49152))), "{other:?}");
    }
    assert!(!net::command_peer(None));
}

/// The server board takes a visit's heartbeat only from the visited robot's board A, at its
/// address and command port.
#[test]
fn a_visit_takes_a_heartbeat_only_from_the_visited_board_a() {
    for n in [1u8, 2, 7, 245] {
        let at = net::robot(n);
        assert!(net::visit_peer(b(n), Some((at, net::PORT))), "{n}");
        assert!(!net::visit_peer(b(n), Some((at, 5001))), "{n}");
        assert!(!net::visit_peer(b(n), None), "{n}");
        let other = net::robot(n.wrapping_add(1));
        assert!(!net::visit_peer(b(n), Some((other, net::PORT))), "{n}");
        assert!(
            !net::visit_peer(b(n), Some((net::SERVER, net::PORT))),
            "{n}"
        );
        assert!(
            !net::visit_peer(b(n), Some((net::GROUND, net::PORT))),
            "{n}"
        );
    }
}

/// No default passphrase: missing, too short, too long, not printable ASCII, or the old public
/// default are refused with the reason (the WiFi images' build evaluates this).
#[test]
fn the_wifi_passphrase_has_no_default() {
    assert!(net::password(None).unwrap_err().contains("not set"));
    assert!(net::password(Some(net::OLD_DEFAULT_PASSWORD))
        .unwrap_err()
        .contains("old public default"));
    assert!(net::password(Some("1234567"))
        .unwrap_err()
        .contains("shorter"));
    let long: &'static str = Box::leak("x".repeat(64).into_boxed_str());
    assert!(net::password(Some(long)).unwrap_err().contains("longer"));
    assert!(net::password(Some("tab\there-x"))
        .unwrap_err()
        .contains("ASCII"));
    assert!(net::password(Some("pässwört-1"))
        .unwrap_err()
        .contains("ASCII"));
    let ok63: &'static str = Box::leak("y".repeat(63).into_boxed_str());
    for p in ["12345678", "correct horse battery", ok63, "mmic-password2"] {
        assert_eq!(net::password(Some(p)), Ok(p));
    }
    // Every message names the variable.
    for bad in [None, Some("short"), Some(net::OLD_DEFAULT_PASSWORD)] {
        assert!(net::password(bad).unwrap_err().starts_with("MMIC_PASSWORD"));
    }
}

/// No stop reason shows a key: the keys' octets appear in no `Display` or `Debug` of the glue.
#[test]
fn no_reason_shows_a_key() {
    let part = with_weak_key([0x5A; 32]);
    let glue = bench::glue([1, 2], &part, provisioned(&[1]));
    let text = format!("{glue:?} {:?}", glue.stopped());
    let text = text
        + &glue
            .stopped()
            .iter()
            .map(|(_, w)| w.to_string())
            .collect::<String>();
    // Robot 1's TC key and robot 2's keys (its TM key was replaced by a weak one).
    for k in [2, 4, 5].map(bench::key_bytes) {
        let hex: String = k.iter().map(|x| format!("{x:02x}")).collect();
        let dec: String = k.iter().map(|x| format!("{x}, ")).collect();
        assert!(
            !text.contains(&hex[..16]) && !text.contains(&dec[..24]),
            "{text}"
        );
    }
}
