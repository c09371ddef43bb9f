//! Board A's shell glue on the host with mocked peripherals: a command arrives over "TCP" (cut
//! and behind garbage), crosses the hand-off queue, one control tick reads the sensors over a
//! mocked I2C bus (the drivers' exact traffic), drives the outputs, and the heartbeat comes
//! back through the other queue. And: a missing ADC reading is never turned into a value — the
//! library gets "no reading" and raises its sensor loss (spec/decisions.toml, `sensor-loss`).

use core::cell::RefCell;
use core::convert::Infallible;
use embedded_hal::i2c::ErrorKind;
use embedded_hal_mock::eh1::i2c::{Mock, Transaction as Tx};
use mmic::bolter::MuxLines;
use mmic::command::Command;
use mmic::mode::Mode;
use mmic::node::robot::board_a;
use mmic::node::robot::handoff::PacketQueue;
use mmic::node::robot::wifi_session::{WifiConfig, WifiSession};
use mmic::restart::ResetCause;
use mmic::sensors::frontend;
use mmic::units::{BoardNumber, PulseWidth};
use mmic::wire::command::CommandRepr;
use mmic::wire::heartbeat::{HeartbeatRepr, HEARTBEAT_LEN};
use mmic::wire::PacketKind;
use mmic_fw_support::control::{commands_in, Actuators, ControlA, QUEUE};
use mmic_fw_support::durable::FlashDurable;
use mmic_fw_support::link::{ByteSink, ByteSource, Link};
use mmic_fw_support::sensors::Side;

mod common;
use common::Ram;

fn store() -> FlashDurable<Ram> {
    FlashDurable::open(Ram::new(2)).unwrap()
}

/// A switch.
struct Sw(bool);
impl embedded_hal::digital::ErrorType for Sw {
    type Error = Infallible;
}
impl embedded_hal::digital::InputPin for Sw {
    fn is_high(&mut self) -> Result<bool, Infallible> {
        Ok(!self.0)
    }
    fn is_low(&mut self) -> Result<bool, Infallible> {
        Ok(self.0)
    }
}

/// What the outputs were last set to.
#[derive(Default, Debug)]
struct Outs {
    servos: Option<[Option<PulseWidth>; 3]>,
    regulator: Option<bool>,
    bolter: Option<([bool; 3], MuxLines)>,
}
impl Actuators for Outs {
    fn servos(&mut self, pulses: [Option<PulseWidth>; 3]) {
        self.servos = Some(pulses);
    }
    fn regulator(&mut self, on: bool) {
        self.regulator = Some(on);
    }
    fn bolter(&mut self, lines: [bool; 3], mux: MuxLines) {
        self.bolter = Some((lines, mux));
    }
}

/// A serial line: bytes to deliver, bytes sent.
#[derive(Default)]
struct Line {
    rx: Vec<u8>,
    tx: Vec<u8>,
}
impl ByteSource for Line {
    fn read(&mut self, buf: &mut [u8]) -> usize {
        let n = buf.len().min(self.rx.len());
        buf[..n].copy_from_slice(&self.rx[..n]);
        self.rx.drain(..n);
        n
    }
}
impl ByteSink for Line {
    fn write(&mut self, bytes: &[u8]) -> bool {
        self.tx.extend_from_slice(bytes);
        true
    }
}

const IMU: u8 = 0x68;
const ADC: u8 = 0x48;
const ENC: u8 = 0x36;

/// One tick's I2C traffic: (IMU set-up,) accelerations, the eight ADC channels (12.0 V
/// battery, 7.4 V regulator, no current), the encoder at 180°. `adc_fails`: CH0 NACKs.
fn tick_traffic(first: bool, adc_fails: bool) -> Vec<Tx> {
    let mut t = Vec::new();
    if first {
        t.push(Tx::write_read(IMU, vec![0x75], vec![0x68]));
        t.push(Tx::write(IMU, vec![0x6B, 0x01]));
        t.push(Tx::write(IMU, vec![0x1C, 0x00]));
    }
    t.push(Tx::write_read(IMU, vec![0x3B], vec![0, 0, 0xC0, 0, 0, 0])); // −1 g on Y
    let codes: [u16; 8] = [3276, 0, 0, 0, 0, 3030, 0, 0];
    let cmd = [0x8C, 0xCC, 0x9C, 0xDC, 0xAC, 0xEC, 0xBC, 0xFC];
    if adc_fails {
        t.push(Tx::write_read(ADC, vec![0x8C], vec![0, 0]).with_error(ErrorKind::Other));
    } else {
        for (c, code) in cmd.iter().zip(codes) {
            t.push(Tx::write_read(ADC, vec![*c], code.to_be_bytes().to_vec()));
        }
    }
    t.push(Tx::write_read(ENC, vec![0x0B], vec![0x20]));
    t.push(Tx::write_read(ENC, vec![0x0C], vec![0x08, 0x00]));
    t
}

#[test]
fn board_a_command_to_heartbeat_through_the_glue() {
    let mut rx: PacketQueue<14, QUEUE> = PacketQueue::new();
    let mut tx: PacketQueue<HEARTBEAT_LEN, QUEUE> = PacketQueue::new();
    let (mut wifi_in, control_in) = rx.split();
    let (control_out, mut wifi_out) = tx.split();

    let mut traffic = tick_traffic(true, true);
    traffic.extend(tick_traffic(false, false));
    let bus = RefCell::new(Mock::new(&traffic));
    let mut side = Side::new(&bus, [Sw(true), Sw(true)], true);
    let mut ctl = ControlA::new(
        board_a::Config::default(),
        frontend::Config::default(),
        control_in,
        control_out,
        store(),
        ResetCause::PowerOn,
    );
    let (mut outs, mut uart) = (Outs::default(), Line::default());
    uart.rx = b"\x00\xffMI noise".to_vec(); // garbage on board B's line

    // Tick 1: the ADC does not answer (never heard): the tick runs, the library gets no
    // reading and raises sensor loss; nothing is driven in Standby, nothing answered.
    let out = ctl.tick(0, &mut side, &mut outs, &mut uart);
    assert!(ctl.a.faults().contains(mmic::faults::Fault::SensorLoss));
    assert_eq!(outs.servos, Some([None; 3]));
    assert!(out.heartbeat.is_none() && wifi_out.pop().is_none());

    // The WiFi task: the server's packet, behind garbage and cut in two TCP reads.
    let cmd = CommandRepr {
        board: BoardNumber::ONE,
        command: Command::Mode(Mode::Operational),
        seq: 1,
    }
    .to_bytes();
    let mut tcp = WifiSession::new(WifiConfig::default());
    tcp.open(0, core::iter::empty(), drop);
    commands_in(&mut tcp, 1, b"junk\x4d", &mut wifi_in);
    commands_in(&mut tcp, 2, &cmd[..6], &mut wifi_in);
    commands_in(&mut tcp, 3, &cmd[6..], &mut wifi_in);
    assert_eq!((tcp.counts().commands, tcp.discarded()), (1, 5));

    // Tick 2: the ADC answers, so no condition holds: the command runs and its heartbeat
    // reaches the WiFi task's queue, still reporting the latched sensor loss.
    let out = ctl.tick(10, &mut side, &mut outs, &mut uart);
    let hb = wifi_out.pop().expect("a heartbeat for the WiFi task");
    let hb = HeartbeatRepr::parse(&hb).expect("a valid heartbeat");
    assert_eq!(
        (hb.mode, hb.last_seq, hb.refusal),
        (Mode::Operational, 1, None)
    );
    assert!(hb.faults.contains(mmic::faults::Fault::SensorLoss));
    assert_eq!(ctl.a.mode(), Mode::Operational);
    assert_eq!(outs.regulator, Some(out.regulator));
    assert!(outs.servos.is_some() && outs.bolter.is_some());
    // The garbage on B's line was dropped and counted when the line went idle.
    assert_eq!(ctl.from_b.discarded(), 10);
    bus.borrow_mut().done();
    assert_eq!(side.errors, [1, 0, 0]);
    assert_eq!(wifi_in.dropped(), 0);
}

/// Boards A and B over the mocked A–B line for two seconds, with garbage written into B's
/// heartbeat stream every 50 ms: every heartbeat still arrives (the deframer resyncs and
/// counts the garbage), so board A never sees an internal communication loss.
#[test]
fn garbage_on_the_b_line_resyncs_and_the_link_holds() {
    use mmic::faults::Fault;
    use mmic::node::robot::board_b::{self, BoardB};
    let mut rx: PacketQueue<14, QUEUE> = PacketQueue::new();
    let mut tx: PacketQueue<HEARTBEAT_LEN, QUEUE> = PacketQueue::new();
    let (_wifi_in, control_in) = rx.split();
    let (control_out, _wifi_out) = tx.split();
    const TICKS: u32 = 200;
    let mut traffic = tick_traffic(true, false);
    for _ in 1..TICKS {
        traffic.extend(tick_traffic(false, false));
    }
    let bus = RefCell::new(Mock::new(&traffic));
    let mut side = Side::new(&bus, [Sw(true), Sw(true)], true);
    let fcfg = frontend::Config::default();
    let mut ctl = ControlA::new(
        board_a::Config::default(),
        fcfg,
        control_in,
        control_out,
        store(),
        ResetCause::PowerOn,
    );
    let mut b = BoardB::new(board_b::Config::default());
    let mut to_b = Link::new(PacketKind::BCommand);
    let (mut outs, mut uart) = (Outs::default(), Line::default());
    let (mut heartbeats, mut garbage) = (0, 0);
    for k in 0..TICKS {
        let now = k * 10;
        ctl.tick(now, &mut side, &mut outs, &mut uart);
        let mut command = None;
        to_b.feed(&std::mem::take(&mut uart.tx), |p| command = Some(p));
        let inputs = board_b::Inputs {
            command,
            electrical: board_a::Inputs::at_home().electrical,
            gravity: None,
            arm_contracted: true,
            bolter_at_home: true,
            lost: frontend::Lost::NONE,
        };
        if let Some(hb) = b.tick(now, &inputs).heartbeat {
            uart.rx.extend_from_slice(b"\x55MI\x00zz");
            garbage += 6;
            uart.rx.extend_from_slice(&hb);
            heartbeats += 1;
        }
    }
    assert!(heartbeats >= 35, "{heartbeats}");
    assert!(!ctl.a.faults().contains(Fault::InternalCommLoss));
    assert!(ctl.from_b.frames() + 1 >= heartbeats);
    assert_eq!(ctl.from_b.discarded(), garbage);
    assert!(to_b.frames() > 0 && to_b.discarded() == 0);
    bus.borrow_mut().done();
}
