//! The server board towards the ground over the space data link (issue 28), the CCSDS gateway
//! image: not the paper's server board, which relays the opsUI's serial line and is
//! firmware/server-paper. TC transfer frames
//! arrive on UDP port [`net::TC_PORT`] and go into the library's `FrameGateway` (SDLS, FARM-1
//! per robot, the PUS gateway); the legacy commands it makes
//! go to board A in visits (connect, send, the heartbeat by the visit's deadline, disconnect:
//! the library's `Visit`, as before); the heartbeats go back into the gateway; the TM transfer
//! frames it says are due go to the ground at [`net::GROUND`]:[`net::TM_PORT`]. The watchdogs
//! are fed only after a complete pass of the glue (`support::restart`, `support::wdt`).
//!
//! The image carries no key. At start-up it reads the SDLS keys from the flash partition
//! `mmic_keys` and clears the buffer they were read into; the durable store (SDLS counters, key
//! fingerprints, FARM-1's progress, the gateway's kept telecommand keys) is the log in
//! `mmic_ctr` (server-ccsds/partitions.csv; both written apart from the image, firmware/README.md
//! "Keys"). Whatever the flash holds — no partition table, a partition missing, a keys
//! partition blank, corrupt or with a weak key, a store blank, of another key or of other
//! robots — nothing here panics: the robots that cannot start have their links stopped, the
//! reason logged at start-up and every [`STATUS_MS`], and the board runs on (WiFi up,
//! watchdogs fed) for the others.
//!
//! Every step is `support::server` (host-tested in support/tests/server.rs and security.rs);
//! this file is the sockets, the flash and the tasks.
#![no_std]
#![no_main]

use core::task::{Context, Poll, Waker};
use embassy_executor::Spawner;
use embassy_futures::select::select3;
use embassy_net::tcp::TcpSocket;
use embassy_net::udp::{PacketMetadata, RecvError, UdpSocket};
use embassy_net::{IpAddress, IpEndpoint, Ipv4Address, Stack};
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::channel::Channel;
use embassy_time::{with_timeout, Duration, Timer};
use esp_backtrace as _;
use esp_bootloader_esp_idf::partitions::{
    self, FlashRegion, PartitionEntry, PARTITION_TABLE_MAX_LEN,
};
use esp_storage::FlashStorage;
use mmic::node::server::frames::{FrameConfig, FRAME_LEN};
use mmic::node::server::store::keys::KeySet;
use mmic::node::server::visit::{Heartbeat, Visit};
use mmic::units::BoardNumber;
use mmic::wire::command::COMMAND_LEN;
use mmic::wire::heartbeat::HEARTBEAT_LEN;
use static_cell::StaticCell;
use support::counters::{FlashLog, LogState};
use support::net;
use support::restart::Gate;
use support::server::{
    keys_from, open_store, BoardLink, Clock, Datagrams, LinkStop, PartitionFault, ServerGlue,
    ENTRIES_PER_ROBOT, FOREIGN, KEYS_READ,
};
use support::wdt::{self, Dogs};
use zeroize::Zeroize;

esp_bootloader_esp_idf::esp_app_desc!();

// `ROBOTS`, from `MMIC_ROBOTS` (build.rs).
include!(concat!(env!("OUT_DIR"), "/robots.rs"));

/// The flash partition of the SDLS keys (server-ccsds/partitions.csv): written apart from the image.
const KEYS_PARTITION: &str = "mmic_keys";
/// The flash partition of the durable store (server-ccsds/partitions.csv): two 4 KiB sectors.
const COUNTERS_PARTITION: &str = "mmic_ctr";
/// Robots served.
const R: usize = ROBOTS.len();
/// The robots served, as board numbers (checked when the image is built).
const BOARDS: [BoardNumber; R] = {
    let mut out = [BoardNumber::ONE; R];
    let mut i = 0;
    while i < R {
        out[i] = match BoardNumber::new(ROBOTS[i]) {
            Ok(b) => b,
            Err(_) => panic!("MMIC_ROBOTS: board numbers 1..=255"),
        };
        i += 1;
    }
    out
};
/// Keys the store holds: every key a served robot can have (never full).
const ENTRIES: usize = ENTRIES_PER_ROBOT * R;
/// The longest the main loop sleeps while nothing is due (a heartbeat a visit brought back
/// waits at most this long), ms.
const IDLE_MS: u32 = 10;
/// How often the status line (and the reasons of stopped links) is logged, ms.
const STATUS_MS: u32 = 30_000;
/// The partitions' raw type and subtype (server-ccsds/partitions.csv: data, undefined).
const DATA: u8 = 0x01;
const UNDEFINED: u8 = 0x06;

type Flash = partitions::NorFlashRegion<'static, 'static, 'static>;
type Log = FlashLog<Flash, ENTRIES, FOREIGN>;
type Glue = ServerGlue<Log, R>;

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
    let (keys, store) = partitions(FLASH.init(FlashStorage::new(p.FLASH)));
    if let Ok(log) = &store {
        report_store(log);
    }
    let config = FrameConfig::default();
    // Each robot's link from what the store kept, secured under its keys; the keys dropped
    // (zeroized) once the gateway holds them.
    let glue = GLUE.init(ServerGlue::new(
        config,
        &BOARDS,
        keys.as_ref().map_err(|e| *e),
        store,
    ));
    drop(keys);
    report(glue);

    // Start-up: WiFi station on the lab's access point at the server's fixed address.
    let stack = wifi::start(&spawner, p.WIFI, net::SERVER);
    spawner.spawn(visits(stack, config.gateway.uplink.timeout_ms).expect("visit task"));
    serve(stack, glue, dogs).await
}

/// The keys and the durable store, or why not. Nothing the flash holds makes this panic: a
/// partition table that does not read, a partition missing or of another kind, a keys
/// partition refused, a log that does not open, each becomes the reason the links stop.
fn partitions(
    flash: &'static mut FlashStorage<'static>,
) -> (Result<KeySet, LinkStop>, Result<Log, LinkStop>) {
    let (keys_entry, ctr_entry) = {
        let mut table = [0u8; PARTITION_TABLE_MAX_LEN];
        match partitions::read_partition_table(flash, &mut table) {
            Ok(pt) => (
                pt.iter().find(|e| labelled(e, KEYS_PARTITION)),
                pt.iter().find(|e| labelled(e, COUNTERS_PARTITION)),
            ),
            Err(_) => {
                return (
                    Err(LinkStop::KeysPartition(PartitionFault::Table)),
                    Err(LinkStop::StorePartition(PartitionFault::Table)),
                )
            }
        }
    };
    let keys = usable(keys_entry)
        .map_err(LinkStop::KeysPartition)
        .and_then(|e| read_keys(e, flash));
    let store = usable(ctr_entry)
        .map_err(LinkStop::StorePartition)
        .and_then(|e| {
            let region = REGION.init(e.as_flash_region(flash));
            region
                .as_nor_flash()
                .map_err(|_| LinkStop::StorePartition(PartitionFault::Kind))
        })
        .and_then(|nor| open_store(nor, &BOARDS));
    (keys, store)
}

/// Whether the partition's label is `name`, compared as octets (the label is flash content:
/// `label_as_str` would take any octets for UTF-8).
fn labelled(e: &PartitionEntry, name: &str) -> bool {
    let label = e.label();
    let len = label
        .iter()
        .position(|&b| b == 0 || b == 0xFF)
        .unwrap_or(label.len());
    label.get(..len) == Some(name.as_bytes())
}

/// The partition, if it is there and data/undefined as server-ccsds/partitions.csv has it (its
/// type is checked before esp-bootloader-esp-idf reads it as one it knows).
fn usable(entry: Option<PartitionEntry>) -> Result<PartitionEntry, PartitionFault> {
    let e = entry.ok_or(PartitionFault::Absent)?;
    if e.raw_type() != DATA || e.raw_subtype() != UNDEFINED {
        return Err(PartitionFault::Kind);
    }
    Ok(e)
}

/// The keys partition's first [`KEYS_READ`] octets, parsed (through the flash's decryption
/// when the partition is flagged encrypted and flash encryption is on); the buffer is
/// cleared either way.
fn read_keys(e: PartitionEntry, flash: &mut FlashStorage<'static>) -> Result<KeySet, LinkStop> {
    #[repr(align(4))]
    struct Buf([u8; KEYS_READ]);
    let mut region = e.as_flash_region(flash);
    let n = KEYS_READ.min(region.partition_size());
    let mut buf = Buf([0; KEYS_READ]);
    let part = buf.0.get_mut(..n).unwrap_or(&mut []);
    match region.read(0, part) {
        Ok(()) => keys_from(part),
        Err(_) => {
            part.zeroize();
            Err(LinkStop::KeysPartition(PartitionFault::Read))
        }
    }
}

/// The store as it opened: what it held, and the entries of robots not served.
fn report_store(log: &Log) {
    let state = match log.state() {
        LogState::Blank => "erased: not provisioned",
        LogState::NoHeader => "no valid sector header: corrupt or not provisioned",
        LogState::Active { .. } => "open",
    };
    esp_println::println!(
        "durable store mmic_ctr: {state}, generation {}, {} entries, {} free slots",
        log.generation(),
        log.entries().len(),
        log.free_slots()
    );
    if !log.foreign().is_empty() || log.dropped() > 0 {
        esp_println::println!(
            "durable store mmic_ctr: {} entries of robots this image does not serve set apart \
             (not used), {} more left out",
            log.foreign().len(),
            log.dropped()
        );
        for e in log.foreign() {
            esp_println::println!("  not served: key {:#06x}", e.key);
        }
    }
}

/// Each robot's link: served, or stopped and why.
fn report(glue: &Glue) {
    for b in BOARDS {
        if glue.serves(b) {
            esp_println::println!("robot {}: link served (SDLS)", b.get());
        }
    }
    for (b, why) in glue.stopped() {
        esp_println::println!("robot {}: link STOPPED ({}): {why}", b.get(), why.name());
    }
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
    let mut status_at = wifi::now_ms().wrapping_add(STATUS_MS);
    loop {
        let next = gate.run(|| glue.poll(&mut clock, &mut ground, &mut board));
        if (wifi::now_ms().wrapping_sub(status_at) as i32) >= 0 {
            status_at = status_at.wrapping_add(STATUS_MS);
            status(glue);
        }
        let wait = support::server::sleep_ms(next, wifi::now_ms(), IDLE_MS);
        select3(
            ground.sock.wait_recv_ready(),
            HEARTBEATS.ready_to_receive(),
            Timer::after(wifi::ms(wait)),
        )
        .await;
    }
}

/// The periodic status line: the glue's counts, a failing store, and every stopped link again.
fn status(glue: &mut Glue) {
    let c = *glue.counts();
    esp_println::println!(
        "t={} tc={} tc_elsewhere={} tm={} tm_unsent={} commands={} busy={} heartbeats={} \
         store_writes={} store_failed={} backoff_ms={:?}",
        wifi::now_ms(),
        c.tc_datagrams,
        c.tc_elsewhere,
        c.tm_frames,
        c.tm_unsent,
        c.commands,
        c.commands_busy,
        c.heartbeats,
        c.store_writes,
        c.store_failed,
        glue.backoff_ms()
    );
    for (b, why) in glue.stopped() {
        esp_println::println!("robot {}: link STOPPED ({}): {why}", b.get(), why.name());
    }
}

/// The ground's UDP socket, polled without blocking.
struct Ground<'a> {
    sock: UdpSocket<'a>,
    to: IpEndpoint,
}

impl Datagrams for Ground<'_> {
    fn recv(&mut self, buf: &mut [u8]) -> Option<(usize, Option<[u8; 4]>)> {
        let mut cx = Context::from_waker(Waker::noop());
        match self.sock.poll_recv_from(buf, &mut cx) {
            Poll::Ready(Ok((n, meta))) => Some((n, Some(v4(meta.endpoint).0))),
            // Longer than any TC frame: an empty datagram, which the frame checks refuse (its
            // source unknown).
            Poll::Ready(Err(RecvError::Truncated)) => Some((0, None)),
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

/// An endpoint as the glue's checks take it (the stack runs IPv4 only).
fn v4(e: IpEndpoint) -> net::Endpoint {
    let IpAddress::Ipv4(a) = e.addr;
    (a.octets(), e.port)
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
/// disconnect. A connection whose peer is not the visited board A (`net::visit_peer`) is
/// aborted before a byte is sent or taken.
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
            let peer = sock.remote_endpoint().map(v4);
            if net::visit_peer(board, peer) && wifi::write_all(&mut sock, visit.packet()).await {
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
