//! The server board towards the ground over the space data link (issue 28): TC transfer frames
//! arrive on UDP port [`net::TC_PORT`] and go into the library's `FrameGateway` (SDLS, FARM-1
//! per robot, the PUS gateway); the legacy commands it makes
//! go to board A in visits (connect, send, the heartbeat by the visit's deadline, disconnect:
//! the library's `Visit`, as before); the heartbeats go back into the gateway; the TM transfer
//! frames it says are due go to the ground at [`net::GROUND`]:[`net::TM_PORT`]. The SDLS
//! counters persist in the flash partition `mmic_ctr` (server/partitions.csv). The watchdogs
//! are fed only after a complete pass of the glue (`support::restart`, `support::wdt`).
//!
//! Every step is `support::server::ServerGlue::poll` (host-tested in support/tests/server.rs);
//! this file is the sockets, the flash and the tasks.
#![no_std]
#![no_main]

use core::task::{Context, Poll, Waker};
use embassy_executor::Spawner;
use embassy_futures::select::select3;
use embassy_net::tcp::TcpSocket;
use embassy_net::udp::{PacketMetadata, RecvError, UdpSocket};
use embassy_net::{IpEndpoint, Ipv4Address, Stack};
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::channel::Channel;
use embassy_time::{with_timeout, Duration, Timer};
use esp_backtrace as _;
use esp_bootloader_esp_idf::partitions::{self, FlashRegion, PARTITION_TABLE_MAX_LEN};
use esp_storage::FlashStorage;
use mmic::node::server::frames::{FrameConfig, FRAME_LEN};
use mmic::node::server::visit::{Heartbeat, Visit};
use mmic::units::BoardNumber;
use mmic::wire::command::COMMAND_LEN;
use mmic::wire::heartbeat::HEARTBEAT_LEN;
use static_cell::StaticCell;
use support::counters::FlashCounters;
use support::net;
use support::restart::Gate;
use support::server::{BoardLink, Clock, Datagrams, ServerGlue};
use support::wdt::{self, Dogs};

esp_bootloader_esp_idf::esp_app_desc!();

// `ROBOTS` and `KEYS`, from `MMIC_ROBOTS` and `MMIC_SDLS_KEY_DIR` (build.rs).
include!(concat!(env!("OUT_DIR"), "/keys.rs"));

/// The flash partition of the SDLS counters (server/partitions.csv): two 4 KiB sectors.
const COUNTERS_PARTITION: &str = "mmic_ctr";
/// Robots served.
const R: usize = ROBOTS.len();
/// SPIs the counter store holds: two per robot.
const SPIS: usize = 2 * R;
/// The longest the main loop sleeps while nothing is due (a heartbeat a visit brought back
/// waits at most this long), ms.
const IDLE_MS: u32 = 10;

type Flash = partitions::NorFlashRegion<'static, 'static, 'static>;
type Glue = ServerGlue<FlashCounters<Flash, SPIS>, R>;

/// Board A visits asked for by the gateway, and the heartbeats they brought back.
static VISITS: Channel<CriticalSectionRawMutex, (BoardNumber, [u8; COMMAND_LEN]), R> =
    Channel::new();
static HEARTBEATS: Channel<CriticalSectionRawMutex, Heartbeat, R> = Channel::new();

static FLASH: StaticCell<FlashStorage<'static>> = StaticCell::new();
static REGION: StaticCell<FlashRegion<'static, 'static>> = StaticCell::new();
static GLUE: StaticCell<Glue> = StaticCell::new();

#[esp_rtos::main]
async fn main(spawner: Spawner) -> ! {
    wifi::boot!(p);
    // The RTC watchdog from here: it covers the start-up up to the first complete pass.
    let (cause, code) = wdt::reset_cause();
    let dogs = Dogs::arm(p.RTC_TIMER, p.TIMG1);
    esp_println::println!("mmic server board, reset reason {code:#04x}: {cause}");
    let store = FlashCounters::open(counters_flash(p.FLASH)).expect("SDLS counters in flash");
    let mut robots = [BoardNumber::ONE; R];
    for (r, n) in robots.iter_mut().zip(ROBOTS) {
        *r = BoardNumber::new(n).expect("MMIC_ROBOTS");
    }
    let config = FrameConfig::default();
    // Each robot's link secured with SDLS under the keys built into the image, its counters
    // restored from flash.
    let glue = GLUE.init(ServerGlue::new(config, &robots, &KEYS, store).expect("robots and keys"));

    // Start-up: WiFi station on the lab's access point at the server's fixed address.
    let stack = wifi::start(&spawner, p.WIFI, net::SERVER);
    spawner.spawn(visits(stack, config.gateway.uplink.timeout_ms).expect("visit task"));
    serve(stack, glue, dogs).await
}

/// The counters' partition as NOR flash. Start-up only: an image flashed without
/// server/partitions.csv has no such partition, and must not run without durable counters.
fn counters_flash(flash: esp_hal::peripherals::FLASH<'static>) -> Flash {
    let flash = FLASH.init(FlashStorage::new(flash));
    let mut table = [0u8; PARTITION_TABLE_MAX_LEN];
    let pt = partitions::read_partition_table(flash, &mut table).expect("partition table");
    let entry = pt
        .iter()
        .find(|e| e.label_as_str() == COUNTERS_PARTITION)
        .expect("no mmic_ctr partition: flash with --partition-table server/partitions.csv");
    let region = REGION.init(entry.as_flash_region(flash));
    region.as_nor_flash().expect("mmic_ctr is not encrypted")
}

/// The loop: one pass of the glue, then sleep until a datagram, a heartbeat or the gateway's
/// next deadline (1 ms to [`IDLE_MS`]). The watchdogs are fed after each complete pass.
async fn serve(stack: Stack<'static>, glue: &'static mut Glue, mut dogs: Dogs) -> ! {
    let (mut rx_meta, mut tx_meta) = ([PacketMetadata::EMPTY; 8], [PacketMetadata::EMPTY; 8]);
    let (mut rx_buf, mut tx_buf) = ([0u8; 8 * 256], [0u8; 8 * FRAME_LEN]);
    let mut sock = UdpSocket::new(stack, &mut rx_meta, &mut rx_buf, &mut tx_meta, &mut tx_buf);
    sock.bind(net::TC_PORT).expect("TC port");
    let to = IpEndpoint::new(Ipv4Address::from(net::GROUND).into(), net::TM_PORT);
    let mut ground = Ground { sock, to };
    let (mut clock, mut board) = (Uptime, Visits);
    dogs.arm_control();
    let mut gate = Gate::new(dogs);
    loop {
        let next = gate.run(|| glue.poll(&mut clock, &mut ground, &mut board));
        let wait = support::server::sleep_ms(next, wifi::now_ms(), IDLE_MS);
        select3(
            ground.sock.wait_recv_ready(),
            HEARTBEATS.ready_to_receive(),
            Timer::after(wifi::ms(wait)),
        )
        .await;
    }
}

/// The ground's UDP socket, polled without blocking.
struct Ground<'a> {
    sock: UdpSocket<'a>,
    to: IpEndpoint,
}

impl Datagrams for Ground<'_> {
    fn recv(&mut self, buf: &mut [u8]) -> Option<usize> {
        let mut cx = Context::from_waker(Waker::noop());
        match self.sock.poll_recv_from(buf, &mut cx) {
            Poll::Ready(Ok((n, _))) => Some(n),
            // Longer than any TC frame: an empty datagram, which the frame checks refuse.
            Poll::Ready(Err(RecvError::Truncated)) => Some(0),
            Poll::Pending => None,
        }
    }

    fn send(&mut self, datagram: &[u8]) -> bool {
        let mut cx = Context::from_waker(Waker::noop());
        matches!(
            self.sock.poll_send_to(datagram, self.to, &mut cx),
            Poll::Ready(Ok(()))
        )
    }
}

/// The clock of the library's state machines.
struct Uptime;

impl Clock for Uptime {
    fn now_ms(&mut self) -> u32 {
        wifi::now_ms()
    }
}

/// Board A, through the visit task.
struct Visits;

impl BoardLink for Visits {
    fn command(&mut self, board: BoardNumber, packet: [u8; COMMAND_LEN]) -> bool {
        VISITS.try_send((board, packet)).is_ok()
    }

    fn heartbeat(&mut self) -> Option<[u8; HEARTBEAT_LEN]> {
        HEARTBEATS.try_receive().ok()
    }
}

/// Figure 4's visits, one at a time: connect to board A of the robot, send the command, take
/// the first heartbeat by the visit's deadline (`wait_ms`, the gateway's uplink timeout),
/// disconnect.
#[embassy_executor::task]
async fn visits(stack: Stack<'static>, wait_ms: u32) {
    let (mut rx_buf, mut tx_buf) = ([0u8; 256], [0u8; 256]);
    loop {
        let (board, packet) = VISITS.receive().await;
        let mut visit = Visit::new(wifi::now_ms(), board, packet, wait_ms);
        let mut sock = TcpSocket::new(stack, &mut rx_buf, &mut tx_buf);
        sock.set_timeout(Some(wifi::ms(wait_ms)));
        let to = (Ipv4Address::from(net::robot(board.get())), net::PORT);
        let left = visit.left_ms(wifi::now_ms()).unwrap_or(0);
        if let Ok(Ok(())) = with_timeout(wifi::ms(left), sock.connect(to)).await {
            if wifi::write_all(&mut sock, visit.packet()).await {
                if let Some(hb) = heartbeat(&mut sock, &mut visit).await {
                    // Full only if the main loop stopped taking them: dropped, and the
                    // gateway's uplink asks again.
                    let _ = HEARTBEATS.try_send(hb);
                }
            }
            sock.close();
            let _ = with_timeout(Duration::from_millis(IDLE_MS.into()), sock.flush()).await;
        }
        sock.abort();
    }
}

/// The visited robot's first heartbeat by the visit's deadline.
async fn heartbeat(sock: &mut TcpSocket<'_>, visit: &mut Visit) -> Option<Heartbeat> {
    let mut buf = [0u8; 128];
    loop {
        let left = visit.left_ms(wifi::now_ms())?;
        match with_timeout(wifi::ms(left), sock.read(&mut buf)).await {
            Ok(Ok(n)) if n > 0 => {
                if let Some(hb) = visit.received(&buf[..n]) {
                    return Some(hb);
                }
            }
            _ => return None,
        }
    }
}
