//! Board A (Figures 5 and 6): the robot's primary board. Two embassy tasks stand for the
//! paper's two cores, joined by the library's hand-off queues: the WiFi task (accepts the
//! server board's TCP connection — from the server board's address only, `net::command_peer`:
//! any other peer is aborted at once — and does what the library's `WifiSession` says: command
//! packets into the rx queue, the heartbeats of the tx queue back) and the 10 ms control task
//! (sensors, `BoardA::tick`, servos, bolter, regulator, the serial line to board B).
//!
//! Board A keeps its exactly-once log and boot count in the flash partition `mmic_a`
//! (board-a/partitions.csv) and starts from it as Table 7's power-on says; its watchdogs are
//! fed only after a complete control tick (`support::restart`, `support::wdt`).
#![no_std]
#![no_main]

use core::cell::RefCell;
use embassy_executor::Spawner;
use embassy_net::tcp::TcpSocket;
use embassy_net::{IpAddress, Stack};
use embassy_time::{with_timeout, Duration, Instant, Ticker, Timer};
use esp_backtrace as _;
use esp_bootloader_esp_idf::partitions::{self, FlashRegion, PARTITION_TABLE_MAX_LEN};
use esp_hal::gpio::Input;
use esp_hal::i2c::master::{Config as I2cConfig, I2c};
use esp_hal::time::Rate;
use esp_hal::uart::{Config as UartConfig, Uart};
use esp_hal::Blocking;
use esp_println::println;
use esp_storage::FlashStorage;
use mmic::node::robot::board_a;
use mmic::node::robot::handoff::{Consumer, PacketQueue, Producer};
use mmic::node::robot::wifi_session::{Outgoing, WifiConfig, WifiSession};
use mmic::sensors::frontend;
use mmic::units::BoardNumber;
use mmic::wire::command::COMMAND_LEN;
use mmic::wire::heartbeat::HEARTBEAT_LEN;
use static_cell::StaticCell;
use support::control::{commands_in, ControlA, QUEUE, TICK_MS};
use support::durable::FlashDurable;
use support::hw::{self, Serial};
use support::net;
use support::restart::Gate;
use support::sensors::Side;
use support::wdt::{self, Dogs};

esp_bootloader_esp_idf::esp_app_desc!();

/// The robot's number (its board A address, and the commands it takes), at build time.
const BOARD: &str = match option_env!("MMIC_BOARD") {
    Some(n) => n,
    None => "1",
};
/// Status line period, ticks.
const STATUS_TICKS: u32 = 500;
/// The flash partition of board A's record (board-a/partitions.csv): two 4 KiB sectors.
const DURABLE_PARTITION: &str = "mmic_a";

type Flash = partitions::NorFlashRegion<'static, 'static, 'static>;
type Control = ControlA<'static, FlashDurable<Flash>>;

type Bus = RefCell<I2c<'static, Blocking>>;
static BUS: StaticCell<Bus> = StaticCell::new();
static RX: StaticCell<PacketQueue<COMMAND_LEN, QUEUE>> = StaticCell::new();
static TX: StaticCell<PacketQueue<HEARTBEAT_LEN, QUEUE>> = StaticCell::new();
static FLASH: StaticCell<FlashStorage<'static>> = StaticCell::new();
static REGION: StaticCell<FlashRegion<'static, 'static>> = StaticCell::new();

#[esp_rtos::main]
async fn main(spawner: Spawner) -> ! {
    wifi::boot!(p);
    // The RTC watchdog from here: it covers the start-up up to the first complete tick.
    let (cause, code) = wdt::reset_cause();
    let dogs = Dogs::arm(p.RTC_TIMER, p.TIMG1);
    println!(
        "mmic board A{BOARD} on {}, reset reason {code:#04x}: {cause}",
        support::chip::CHIP
    );

    // Start-up: a peripheral that cannot be configured is a build or wiring error.
    let n: u8 = BOARD.parse().expect("MMIC_BOARD: 1..=255");
    let board = BoardNumber::new(n).expect("MMIC_BOARD: a board number");
    let pins = support::take_pins!(p);
    let i2c_cfg = I2cConfig::default().with_frequency(Rate::from_khz(400));
    let i2c = I2c::new(p.I2C0, i2c_cfg).expect("I2C config");
    let bus = BUS.init(RefCell::new(i2c.with_sda(pins.sda).with_scl(pins.scl)));
    let side = Side::new(bus, hw::switches(pins.switches), true);
    let outs = hw::Outputs::new(p.LEDC, pins.servos, pins.bolter, pins.mux, pins.regulator);
    let [tx, rx] = pins.uart;
    let uart = Uart::new(p.UART1, UartConfig::default().with_baudrate(support::BAUD))
        .expect("UART config")
        .with_tx(tx)
        .with_rx(rx);
    let serial = Serial { uart, rx_errors: 0 };
    let (cmd_in, cmd_out) = RX.init(PacketQueue::new()).split();
    let (hb_in, hb_out) = TX.init(PacketQueue::new()).split();
    let cfg = board_a::Config {
        board,
        ..Default::default()
    };
    // Table 7's power-on, with the exactly-once log and boot count flash kept.
    let store = FlashDurable::open(durable_flash(p.FLASH)).expect("board A's record in flash");
    let front = frontend::Config::default();
    let ctl = ControlA::new(cfg, front, cmd_out, hb_in, store, cause);
    println!("boot {:?}, kept {:?}", ctl.a.boot(), ctl.a.durable());
    spawner.spawn(control(ctl, side, outs, serial, dogs).expect("control task"));

    // WiFi: station on the lab's access point, board A at its fixed address.
    let stack = wifi::start(&spawner, p.WIFI, net::robot(n));
    wifi_task(stack, cmd_in, hb_out).await
}

/// Board A's record's partition as NOR flash. Start-up only: an image flashed without
/// board-a/partitions.csv has no such partition, and must not run without its log (a command
/// could run twice across a restart).
fn durable_flash(flash: esp_hal::peripherals::FLASH<'static>) -> Flash {
    let flash = FLASH.init(FlashStorage::new(flash));
    let mut table = [0u8; PARTITION_TABLE_MAX_LEN];
    let pt = partitions::read_partition_table(flash, &mut table).expect("partition table");
    let entry = pt
        .iter()
        .find(|e| e.label_as_str() == DURABLE_PARTITION)
        .expect("no mmic_a partition: flash with --partition-table board-a/partitions.csv");
    let region = REGION.init(entry.as_flash_region(flash));
    region.as_nor_flash().expect("mmic_a is not encrypted")
}

/// The control task: one library tick every 10 ms, the watchdogs fed after each complete one.
#[embassy_executor::task]
async fn control(
    mut ctl: Control,
    mut side: Side<'static, I2c<'static, Blocking>, Input<'static>>,
    mut outs: hw::Outputs,
    mut serial: Serial,
    mut dogs: Dogs,
) {
    let mut ticker = Ticker::every(Duration::from_millis(TICK_MS.into()));
    let mut ticks = 0u32;
    dogs.arm_control();
    let mut gate = Gate::new(dogs);
    loop {
        let now = Instant::now().as_millis() as u32;
        let o = gate.run(|| ctl.tick(now, &mut side, &mut outs, &mut serial));
        for e in &o.events {
            println!("t={now} {e:?}");
        }
        ticks = ticks.wrapping_add(1);
        if ticks.is_multiple_of(STATUS_TICKS) {
            println!(
                "t={now} mode={:?} i2c={:?} rx_err={} b_discarded={} hb_dropped={} {:?} free={}",
                ctl.a.mode(),
                side.errors,
                serial.rx_errors,
                ctl.from_b.discarded(),
                ctl.heartbeats_dropped(),
                ctl.counters,
                ctl.store().log().free_slots()
            );
        }
        ticker.next().await;
    }
}

/// The WiFi task: one server connection at a time; a dropped connection is accepted again.
/// A connection from any peer but the server board (`net::command_peer`) is aborted as soon
/// as it is accepted, before a byte of it is read: it never holds the one slot. What to do
/// with each connection's bytes and each heartbeat is the library's session's.
async fn wifi_task(
    stack: Stack<'static>,
    mut commands: Producer<'static, COMMAND_LEN, QUEUE>,
    mut heartbeats: Consumer<'static, HEARTBEAT_LEN, QUEUE>,
) -> ! {
    let (mut rx_buf, mut tx_buf) = ([0u8; 256], [0u8; 256]);
    let mut session = WifiSession::new(WifiConfig::default());
    let mut refused = 0u32;
    loop {
        let mut sock = TcpSocket::new(stack, &mut rx_buf, &mut tx_buf);
        sock.set_timeout(Some(Duration::from_secs(5)));
        if sock.accept(net::PORT).await.is_err() {
            Timer::after_millis(10).await;
            continue;
        }
        let peer = sock.remote_endpoint().map(|e| {
            let IpAddress::Ipv4(a) = e.addr;
            (a.octets(), e.port)
        });
        if !net::command_peer(peer) {
            // Reset at once (the RST flushed out within 10 ms), then listen again.
            sock.abort();
            let _ = with_timeout(Duration::from_millis(10), sock.flush()).await;
            refused = refused.wrapping_add(1);
            if refused.is_power_of_two() {
                println!("refused a command connection from {peer:?} ({refused} so far)");
            }
            continue;
        }
        // Heartbeats made while no server was connected are dropped (counted by the session).
        session.open(
            wifi::now_ms(),
            core::iter::from_fn(|| heartbeats.pop()),
            drop,
        );
        let mut buf = [0u8; 128];
        'conn: loop {
            match with_timeout(Duration::from_millis(2), sock.read(&mut buf)).await {
                Ok(Ok(0)) | Ok(Err(_)) => break 'conn,
                Ok(Ok(n)) => commands_in(&mut session, wifi::now_ms(), &buf[..n], &mut commands),
                Err(_) if session.expired(wifi::now_ms()) => break 'conn,
                Err(_) => {}
            }
            while let Some(hb) = heartbeats.pop() {
                if let Outgoing::Send(hb) = session.heartbeat(hb) {
                    if !wifi::write_all(&mut sock, &hb).await {
                        break 'conn;
                    }
                }
            }
        }
        session.close();
        let c = session.counts();
        println!(
            "server gone: discarded={} unconnected={} commands={} sent={}",
            session.discarded(),
            c.unconnected,
            c.commands,
            c.sent
        );
        sock.abort();
        let _ = with_timeout(Duration::from_millis(100), sock.flush()).await;
    }
}
