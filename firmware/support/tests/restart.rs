//! Restarts on the device (issue 29, point 4): the watchdogs' feeding gate, the reset-cause
//! table, and board A's durable record across a reset at every point of a tick.

use std::cell::{Cell, RefCell};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::rc::Rc;
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::{mpsc, Arc};

use embedded_storage::nor_flash::{ErrorType, NorFlash, NorFlashErrorKind, ReadNorFlash};
use mmic::bolter::MuxLines;
use mmic::command::Command;
use mmic::mode::Mode;
use mmic::node::robot::board_a::{self, Durable, Event};
use mmic::node::robot::handoff::PacketQueue;
use mmic::refusal::Refusal;
use mmic::restart::{Boot, ResetCause};
use mmic::sensors::frontend::{self, Raw};
use mmic::units::{BoardNumber, PulseWidth};
use mmic::wire::command::{CommandRepr, COMMAND_LEN};
use mmic::wire::heartbeat::{HeartbeatRepr, HEARTBEAT_LEN};
use mmic_fw_support::control::{Actuators, ControlA, Counters, Reading, Sensors, QUEUE};
use mmic_fw_support::counters::{LogError, RECORD_LEN};
use mmic_fw_support::durable::{self, FlashDurable, Keep};
use mmic_fw_support::link::{ByteSink, ByteSource};
use mmic_fw_support::restart::{self, reset_cause, Feed, Gate, PANIC_MARK};

mod common;
use common::{Ram, SECTOR};

// ---------------------------------------------------------------------------------------------
// The gate.

/// Watchdogs that count their feeds (shared with another thread in the hang test).
#[derive(Default, Clone)]
struct Dogs(Arc<AtomicU32>);

impl Feed for Dogs {
    fn feed(&mut self) {
        self.0.fetch_add(1, Ordering::SeqCst);
    }
}

impl Dogs {
    fn fed(&self) -> u32 {
        self.0.load(Ordering::SeqCst)
    }
}

#[test]
fn a_complete_tick_feeds_once() {
    let dogs = Dogs::default();
    let mut gate = Gate::new(dogs.clone());
    for k in 1..=5 {
        let r = gate.run(|| k * 2);
        assert_eq!(r, k * 2);
        assert_eq!((dogs.fed(), gate.fed(), gate.begun()), (k, k, k));
    }
    // By hand: begun, complete, one feed.
    let t = gate.begin();
    assert_eq!(dogs.fed(), 5);
    t.complete();
    assert_eq!(dogs.fed(), 6);
}

#[test]
fn a_tick_that_does_not_complete_does_not_feed() {
    let dogs = Dogs::default();
    let mut gate = Gate::new(dogs.clone());
    gate.run(|| ());
    // Begun and dropped (the tick returned early without completing): no feed.
    drop(gate.begin());
    assert_eq!((dogs.fed(), gate.begun(), gate.fed()), (1, 2, 1));
    // A tick that panics: the panic leaves the gate before the feed.
    let r = catch_unwind(AssertUnwindSafe(|| {
        gate.run(|| panic!("a tick that panics"))
    }));
    assert!(r.is_err());
    assert_eq!((dogs.fed(), gate.begun(), gate.fed()), (1, 3, 1));
    // The next complete tick feeds again (on the device the panic has reset the chip).
    gate.run(|| ());
    assert_eq!(dogs.fed(), 2);
}

#[test]
fn a_hung_tick_never_feeds() {
    let dogs = Dogs::default();
    let (entered_tx, entered) = mpsc::channel();
    let (release, released) = mpsc::channel::<()>();
    let mut gate = Gate::new(dogs.clone());
    let control = std::thread::spawn(move || {
        gate.run(|| {
            entered_tx.send(()).unwrap();
            // Hangs until released (on the device: forever, until the watchdog bites).
            released.recv().unwrap();
        });
        gate.fed()
    });
    entered.recv().unwrap();
    for _ in 0..20 {
        std::thread::sleep(std::time::Duration::from_millis(5));
        assert_eq!(dogs.fed(), 0, "a tick still running fed the watchdogs");
    }
    release.send(()).unwrap();
    assert_eq!(control.join().unwrap(), 1);
    assert_eq!(dogs.fed(), 1);
}

// ---------------------------------------------------------------------------------------------
// The reset cause.

#[test]
fn reset_reasons_map_to_causes() {
    use ResetCause::*;
    // (code, esp-hal's SocResetReason on the C3 / C6 / ESP32, cause)
    let table: &[(u32, &str, ResetCause)] = &[
        (0x01, "ChipPowerOn", PowerOn),
        (0x03, "CoreSw", Software),
        (0x05, "CoreDeepSleep", Other),
        (0x06, "CoreSDIO (C6, ESP32)", Other),
        (0x07, "CoreMwdt0", Watchdog),
        (0x08, "CoreMwdt1", Watchdog),
        (0x09, "CoreRtcWdt", Watchdog),
        (0x0B, "Cpu0Mwdt0", Watchdog),
        (0x0C, "Cpu0Sw", Software),
        (0x0D, "Cpu0RtcWdt", Watchdog),
        (0x0E, "Cpu1Cpu0 (ESP32)", Other),
        (0x0F, "SysBrownOut", BrownOut),
        (0x10, "SysRtcWdt", Watchdog),
        (0x11, "Cpu0Mwdt1", Watchdog),
        (0x12, "SysSuperWdt", Watchdog),
        (0x13, "SysClkGlitch (C3)", Other),
        (0x14, "CoreEfuseCrc", Other),
        (0x15, "CoreUsbUart", External),
        (0x16, "CoreUsbJtag", External),
        (0x17, "CorePwrGlitch (C3)", BrownOut),
        (0x18, "Cpu0JtagCpu (C6)", External),
    ];
    for code in 0..=0x40u32 {
        let want = table
            .iter()
            .find(|(c, _, _)| *c == code)
            .map_or(Other, |r| r.2);
        let name = table
            .iter()
            .find(|(c, _, _)| *c == code)
            .map_or("no such reason", |r| r.1);
        assert_eq!(reset_cause(code, false), want, "{code:#04x} {name}");
        // The panic mark makes software and watchdog resets panics, nothing else.
        let marked = match want {
            Software | Watchdog => Panic,
            c => c,
        };
        assert_eq!(
            reset_cause(code, true),
            marked,
            "{code:#04x} {name}, marked"
        );
    }
    assert_eq!(reset_cause(u32::MAX, false), Other);
    // Every cause but the two no chip reports is reached.
    for c in ResetCause::ALL {
        let reached = (0..0x40).any(|k| reset_cause(k, false) == c || reset_cause(k, true) == c);
        assert_eq!(reached, c != Unreported, "{c}");
    }
    assert!(restart::panicked(PANIC_MARK));
    assert!(!restart::panicked(0) && !restart::panicked(!PANIC_MARK));
}

// ---------------------------------------------------------------------------------------------
// Board A's durable record.

#[test]
fn the_record_round_trips_through_the_log_value() {
    let d = Durable {
        last_seq: 0xBEEF,
        outcome: Some(Refusal::from_wire(1).unwrap()),
        boots: 0x1234,
    };
    let v = durable::to_value(&d);
    assert_eq!(v >> 40, 0);
    assert_eq!(durable::from_value(v), Some(d));
    // More than a record, or an outcome byte that is no refusal: no record.
    assert_eq!(durable::from_value(v | 1 << 40), None);
    assert_eq!(durable::from_value(0xFF << 16), None);
    assert_eq!(durable::from_value(0), Some(Durable::default()));
}

/// Board A's sensors at rest: 12.0 V battery, 7.4 V regulator, no current, −1 g on Y, the hip
/// at 180°, both switches closed.
struct Rest;

impl Sensors for Rest {
    fn read(&mut self) -> Reading {
        Reading {
            raw: Raw {
                adc: Some([3276, 0, 0, 0, 0, 3030, 0, 0]),
                accel: Some([0, -16384, 0]),
                encoder: Some(0x0800),
            },
            arm_contracted: true,
            bolter_at_home: true,
        }
    }
}

/// Outputs, which can lose the power when the tick drives them (after the library's tick,
/// before the durable record is written).
#[derive(Default)]
struct Outs {
    cut: bool,
}

impl Actuators for Outs {
    fn servos(&mut self, _: [Option<PulseWidth>; 3]) {
        if self.cut {
            panic!("power cut mid-tick");
        }
    }
    fn regulator(&mut self, _: bool) {}
    fn bolter(&mut self, _: [bool; 3], _: MuxLines) {}
}

/// Board B's line, silent.
struct Quiet;

impl ByteSource for Quiet {
    fn read(&mut self, _: &mut [u8]) -> usize {
        0
    }
}

impl ByteSink for Quiet {
    fn write(&mut self, _: &[u8]) -> bool {
        true
    }
}

/// The flash, shared with the test so that it can cut the power in the middle of a tick.
#[derive(Clone)]
struct Shared(Rc<RefCell<Ram>>);

impl ErrorType for Shared {
    type Error = NorFlashErrorKind;
}

impl ReadNorFlash for Shared {
    const READ_SIZE: usize = Ram::READ_SIZE;
    fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), Self::Error> {
        self.0.borrow_mut().read(offset, bytes)
    }
    fn capacity(&self) -> usize {
        self.0.borrow().capacity()
    }
}

impl NorFlash for Shared {
    const WRITE_SIZE: usize = Ram::WRITE_SIZE;
    const ERASE_SIZE: usize = Ram::ERASE_SIZE;
    fn erase(&mut self, from: u32, to: u32) -> Result<(), Self::Error> {
        self.0.borrow_mut().erase(from, to)
    }
    fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), Self::Error> {
        self.0.borrow_mut().write(offset, bytes)
    }
}

/// The store, which can lose the power right after a write succeeded (after the ahead
/// record, before the library's tick).
struct Cut {
    inner: FlashDurable<Shared>,
    after_write: Rc<Cell<bool>>,
}

impl Keep for Cut {
    fn load(&mut self) -> Option<Durable> {
        self.inner.load()
    }
    fn keep(&mut self, d: &Durable) -> Result<(), LogError> {
        self.inner.keep(d)?;
        if self.after_write.get() {
            panic!("power cut after a write");
        }
        Ok(())
    }
}

/// Where a life ends.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Reset {
    /// The power fails after this many octets of flash traffic (erased or programmed) in the
    /// tick that takes the last packet: before, inside or after either record.
    Octets(usize),
    /// Right after the ahead record's write returned.
    AfterAhead,
    /// After the library's tick, while driving the outputs (before the durable record).
    MidTick,
    /// After the tick (the next one never comes).
    AfterTick,
}

/// What one life of board A saw.
struct Life {
    flash: Ram,
    events: Vec<Event>,
    heartbeats: Vec<HeartbeatRepr>,
    boot: Boot,
    counters: Counters,
    /// The last tick completed.
    completed: bool,
}

fn cmd(seq: u16, command: Command) -> [u8; COMMAND_LEN] {
    CommandRepr {
        board: BoardNumber::ONE,
        command,
        seq,
    }
    .to_bytes()
}

/// One life of board A on `flash` after a reset for `cause`: ticks once idle, then once with
/// each packet of `packets`; `reset` ends it in the last packet's tick.
fn life(flash: Ram, cause: ResetCause, packets: &[[u8; 14]], reset: Option<Reset>) -> Life {
    let mut rx: PacketQueue<COMMAND_LEN, QUEUE> = PacketQueue::new();
    let mut tx: PacketQueue<HEARTBEAT_LEN, QUEUE> = PacketQueue::new();
    let (mut wifi_in, control_in) = rx.split();
    let (control_out, mut wifi_out) = tx.split();
    let shared = Shared(Rc::new(RefCell::new(flash)));
    let after_write = Rc::new(Cell::new(false));
    let store = Cut {
        inner: FlashDurable::open(shared.clone()).expect("the store opens"),
        after_write: after_write.clone(),
    };
    let mut ctl = ControlA::new(
        board_a::Config::default(),
        frontend::Config::default(),
        control_in,
        control_out,
        store,
        cause,
    );
    let boot = ctl.a.boot();
    let dogs = Dogs::default();
    let mut gate = Gate::new(dogs.clone());
    let mut outs = Outs::default();
    let (mut events, mut heartbeats) = (Vec::new(), Vec::new());
    let mut now = 0;
    let mut completed = true;
    for (i, p) in [None]
        .into_iter()
        .chain(packets.iter().map(Some))
        .enumerate()
    {
        if let Some(p) = p {
            wifi_in.push(*p).expect("room in the queue");
        }
        match (i == packets.len()).then_some(reset).flatten() {
            Some(Reset::Octets(n)) => shared.0.borrow_mut().budget = Some(n),
            Some(Reset::AfterAhead) => after_write.set(true),
            Some(Reset::MidTick) => outs.cut = true,
            Some(Reset::AfterTick) | None => {}
        }
        let fed = dogs.fed();
        let r = catch_unwind(AssertUnwindSafe(|| {
            gate.run(|| ctl.tick(now, &mut Rest, &mut outs, &mut Quiet))
        }));
        now += 10;
        completed = r.is_ok();
        if let Ok(o) = r {
            events.extend(o.events.iter().copied());
        }
        // A tick that did not complete fed nothing; one that did, once.
        assert_eq!(dogs.fed(), fed + u32::from(completed));
        while let Some(hb) = wifi_out.pop() {
            heartbeats.push(HeartbeatRepr::parse(&hb).expect("a valid heartbeat"));
        }
    }
    let counters = ctl.counters;
    drop(ctl);
    let flash = shared.0.borrow().clone().reset();
    Life {
        flash,
        events,
        heartbeats,
        boot,
        counters,
        completed,
    }
}

fn executed(events: &[Event], seq: u16) -> usize {
    events
        .iter()
        .filter(|e| matches!(e, Event::Executed { seq: s, .. } if *s == seq))
        .count()
}

/// The command before the reset: accepted (a mode change, one record written ahead) or refused
/// (Reset with nothing to resume: the ahead record, then the refusal after the tick).
const COMMANDS: [Command; 2] = [Command::Mode(Mode::Operational), Command::Reset];

/// Board A's store from a first life on a fresh flash that took command 4 (its record and the
/// boot count written), and, with `fill`, records until one slot of the sector is left.
fn first_life(fill: bool) -> Ram {
    let l = life(
        Ram::new(2),
        ResetCause::PowerOn,
        &[cmd(4, Command::ClearFaults)],
        None,
    );
    assert_eq!(l.boot, Boot::after(ResetCause::PowerOn, 1));
    assert_eq!(executed(&l.events, 4), 1);
    let mut flash = l.flash;
    if fill {
        let mut s = FlashDurable::open(flash).unwrap();
        let d = s.load().expect("the first life's record");
        // The next life writes its boot count in the last slot; its ahead record compacts.
        while s.log().free_slots() > 1 {
            s.keep(&d).unwrap();
        }
        flash = s.release();
    }
    flash
}

/// Life 1 takes command 5 and is reset at `reset`; life 2 gets the same packet again (the
/// ground's resend). Command 5 runs at most once over both lives, and once when life 1 never
/// took it; life 2 answers it either way.
fn check(fill: bool, c: Command, reset: Reset) {
    let what = format!("{c:?}, reset {reset:?}, sector full {fill}");
    let packet = cmd(5, c);
    let l1 = life(
        first_life(fill),
        ResetCause::Watchdog,
        &[packet],
        Some(reset),
    );
    assert_eq!(l1.boot, Boot::after(ResetCause::Watchdog, 2), "{what}");
    let l2 = life(l1.flash, ResetCause::Panic, &[packet], None);
    assert_eq!(l2.boot, Boot::after(ResetCause::Panic, 3), "{what}");
    assert!(l2.completed && l2.counters == Counters::default(), "{what}");
    let (once, twice) = (executed(&l1.events, 5), executed(&l2.events, 5));
    assert!(once + twice <= 1, "{what}: run twice");
    // Taken in life 1 (its ahead record written): answered in life 2, not run.
    let taken = l1.counters.unkept == 0;
    assert_eq!(twice, usize::from(!taken), "{what}");
    if taken {
        assert!(
            l2.events.contains(&Event::Duplicate { seq: 5 }),
            "{what}: {:?}",
            l2.events
        );
    }
    // Life 2's heartbeat acknowledges command 5 and tells of the restart.
    let hb = l2.heartbeats.last().expect("a heartbeat in life 2");
    assert_eq!((hb.last_seq, hb.boot), (5, l2.boot), "{what}");
    if twice == 0 {
        assert_eq!(hb.mode, Mode::Standby, "{what}: resumed");
    }
    // A life whose every write went through runs the command in that life.
    if matches!(reset, Reset::AfterTick) {
        assert_eq!((once, l1.counters), (1, Counters::default()), "{what}");
    }
}

#[test]
fn a_command_taken_before_a_reset_is_answered_after_it_never_run_twice() {
    for c in COMMANDS {
        for reset in [Reset::AfterAhead, Reset::MidTick, Reset::AfterTick] {
            check(false, c, reset);
        }
        // Before, inside and after the ahead record, inside and after the refusal's record.
        for n in 0..=2 * RECORD_LEN + 1 {
            check(false, c, Reset::Octets(n));
        }
    }
}

#[test]
fn a_reset_anywhere_in_the_compaction_an_ahead_record_starts_loses_nothing() {
    // The compaction: erase the other sector, copy the record, its header; then the record.
    let traffic = SECTOR + 3 * RECORD_LEN + 1;
    let full = first_life(true);
    assert_eq!(
        FlashDurable::open(full.clone()).unwrap().log().free_slots(),
        1
    );
    let packet = cmd(5, Command::Reset);
    let l = life(full, ResetCause::Watchdog, &[packet], None);
    assert_eq!(FlashDurable::open(l.flash).unwrap().log().generation(), 2);
    for n in 0..=traffic {
        check(true, Command::Reset, Reset::Octets(n));
    }
    check(true, Command::Reset, Reset::AfterTick);
}

#[test]
fn a_fresh_flash_starts_board_a_at_its_first_boot() {
    let l = life(Ram::new(2), ResetCause::PowerOn, &[], None);
    assert_eq!(l.boot, Boot::after(ResetCause::PowerOn, 1));
    assert_eq!(l.boot.to_wire(), 0x21);
    let mut s = FlashDurable::open(l.flash).unwrap();
    assert_eq!(
        s.load(),
        Some(Durable {
            last_seq: 0,
            outcome: None,
            boots: 1
        })
    );
}

#[test]
fn a_flash_that_takes_no_write_takes_no_command_and_the_board_still_ticks() {
    // The power budget is spent before the first write of the command's tick, every time.
    let packets = [cmd(5, Command::Mode(Mode::Operational))];
    let l = life(
        first_life(false),
        ResetCause::Watchdog,
        &packets,
        Some(Reset::Octets(0)),
    );
    assert!(l.completed);
    assert_eq!(executed(&l.events, 5), 0);
    // One write tried (the ahead record); the tick changed nothing else to write.
    assert_eq!((l.counters.unkept, l.counters.store_failed), (1, 1));
    // Not taken, not answered: the ground sends it again.
    assert!(l.heartbeats.is_empty());
}

/// spec/watchdog.toml's value of `key` (its `[watchdog]` table: `key = value  # why`).
fn spec_ms(key: &str) -> u32 {
    let p = concat!(env!("CARGO_MANIFEST_DIR"), "/../../spec/watchdog.toml");
    let text = std::fs::read_to_string(p).expect("spec/watchdog.toml");
    let line = text
        .lines()
        .find(|l| l.split('=').next().map(str::trim) == Some(key))
        .unwrap_or_else(|| panic!("spec/watchdog.toml has no {key}"));
    let value = line.split('=').nth(1).unwrap().split('#').next().unwrap();
    value.trim().parse().expect("a number of ms")
}

#[test]
fn the_timeouts_are_spec_watchdogs() {
    assert_eq!(restart::CONTROL_TIMEOUT_MS, spec_ms("control_timeout_ms"));
    assert_eq!(restart::RTC_TIMEOUT_MS, spec_ms("rtc_timeout_ms"));
}
