//! The server board (Figure 4): commands from the opsUI on the USB serial line go into the
//! library's pending slots (`mmic::node::server::relay`); each loop visits one robot with a pending
//! command: connect, send, forward the heartbeat that comes back, disconnect.
//!
//! The USB serial line carries the opsUI's packets only: this binary prints nothing after
//! start-up (a panic message would reach the opsUI, whose deframer drops it as garbage).
#![no_std]
#![no_main]

use embassy_executor::Spawner;
use embassy_net::tcp::TcpSocket;
use embassy_net::{Ipv4Address, Ipv4Cidr, Runner, Stack, StackResources, StaticConfigV4};
use embassy_time::{with_timeout, Duration, Instant, Ticker, Timer};
use esp_backtrace as _;
use esp_hal::clock::CpuClock;
use esp_hal::ram;
use esp_hal::rng::Rng;
use esp_hal::timer::timg::TimerGroup;
use esp_hal::usb::usb_serial_jtag::{UsbSerialJtag, UsbSerialJtagRx, UsbSerialJtagTx};
use esp_hal::Blocking;
use esp_radio::wifi::{self, sta::StationConfig, AuthenticationMethodConfig, Interface};
use mmic::node::server::relay::{Accepted, Server, ServerError};
use mmic::wire::command::COMMAND_LEN;
use mmic::wire::heartbeat::HEARTBEAT_LEN;
use mmic::wire::PacketKind;
use static_cell::StaticCell;
use support::link::{ByteSink, ByteSource, Link};
use support::net;

esp_bootloader_esp_idf::esp_app_desc!();

/// How long a visit waits for the connection and for the heartbeat (the host simulator's
/// `visit_ms`).
const VISIT: Duration = Duration::from_millis(200);
/// The loop's period while no command is pending, and the opsUI line's idle time.
const IDLE: Duration = Duration::from_millis(10);

static NET: StaticCell<StackResources<3>> = StaticCell::new();

/// The opsUI's line: USB serial (CDC-ACM of the USB-Serial-JTAG peripheral).
struct OpsUi(
    UsbSerialJtagRx<'static, Blocking>,
    UsbSerialJtagTx<'static, Blocking>,
);

impl ByteSource for OpsUi {
    fn read(&mut self, buf: &mut [u8]) -> usize {
        self.0.drain_rx_fifo(buf)
    }
}

impl ByteSink for OpsUi {
    fn write(&mut self, bytes: &[u8]) -> bool {
        self.1.write(bytes).is_ok()
    }
}

#[esp_rtos::main]
async fn main(spawner: Spawner) -> ! {
    let p = esp_hal::init(esp_hal::Config::default().with_cpu_clock(CpuClock::max()));
    esp_alloc::heap_allocator!(#[ram(reclaimed)] size: 64 * 1024);
    esp_alloc::heap_allocator!(size: 36 * 1024);
    let timg0 = TimerGroup::new(p.TIMG0);
    esp_rtos::start(timg0.timer0, p.FROM_CPU_INTR0);
    let (rx, tx) = UsbSerialJtag::new(p.USB_DEVICE).split();
    let ops = OpsUi(rx, tx);

    // Start-up: WiFi station on the lab's access point at the server's fixed address.
    let auth =
        AuthenticationMethodConfig::Wpa2Personal(net::PASSWORD.try_into().expect("password"));
    let sta = StationConfig::default()
        .with_ssid(net::SSID.try_into().expect("SSID"))
        .with_authentication(auth);
    let radio_cfg =
        wifi::ControllerConfig::default().with_initial_config(wifi::Config::Station(sta));
    let controller = wifi::WifiController::new(p.WIFI, radio_cfg).expect("WiFi");
    let ip = StaticConfigV4 {
        address: Ipv4Cidr::new(Ipv4Address::from(net::SERVER), 24),
        gateway: None,
        dns_servers: Default::default(),
    };
    let rng = Rng::new();
    let seed = (u64::from(rng.random()) << 32) | u64::from(rng.random());
    let (stack, runner) = embassy_net::new(
        Interface::station(),
        embassy_net::Config::ipv4_static(ip),
        NET.init(StackResources::new()),
        seed,
    );
    spawner.spawn(connection(controller).expect("connection task"));
    spawner.spawn(net_task(runner).expect("net task"));
    serve(stack, ops).await
}

/// Figure 4's loop.
async fn serve(stack: Stack<'static>, mut ops: OpsUi) -> ! {
    let mut glue = ServerGlue::new();
    let (mut rx_buf, mut tx_buf) = ([0u8; 256], [0u8; 256]);
    let mut ticker = Ticker::every(IDLE);
    loop {
        ticker.next().await;
        glue.take_ground(&mut ops);
        let Some((robot, packet)) = glue.srv.next_visit() else {
            continue;
        };
        let mut sock = TcpSocket::new(stack, &mut rx_buf, &mut tx_buf);
        sock.set_timeout(Some(VISIT));
        let to = (Ipv4Address::from(net::robot(robot.get())), net::PORT);
        if let Ok(Ok(())) = with_timeout(VISIT, sock.connect(to)).await {
            if write_all(&mut sock, &packet).await {
                glue.srv.delivered(robot, &packet);
                if let Some(hb) = heartbeat(&mut sock, &mut glue).await {
                    if !ops.write(&hb) {
                        glue.counters.ops_errors = glue.counters.ops_errors.saturating_add(1);
                    }
                }
            }
            sock.close();
            let _ = with_timeout(IDLE, sock.flush()).await;
        }
        sock.abort();
    }
}

/// The visited robot's first heartbeat within [`VISIT`].
async fn heartbeat(sock: &mut TcpSocket<'_>, glue: &mut ServerGlue) -> Option<[u8; HEARTBEAT_LEN]> {
    let until = Instant::now() + VISIT;
    let mut buf = [0u8; 128];
    // A new connection: nothing of the last one's stream is kept.
    glue.robot = Link::new(PacketKind::Heartbeat);
    loop {
        let left = until.checked_duration_since(Instant::now())?;
        match with_timeout(left, sock.read(&mut buf)).await {
            Ok(Ok(n)) if n > 0 => {
                if let Some(hb) = glue.take_robot(&buf[..n]) {
                    return Some(hb);
                }
            }
            _ => return None,
        }
    }
}

async fn write_all(sock: &mut TcpSocket<'_>, mut bytes: &[u8]) -> bool {
    while !bytes.is_empty() {
        match sock.write(bytes).await {
            Ok(0) | Err(_) => return false,
            Ok(n) => bytes = &bytes[n..],
        }
    }
    true
}

/// Keeps the station associated: reconnects after a drop.
#[embassy_executor::task]
async fn connection(mut controller: wifi::WifiController<'static>) {
    loop {
        if controller.connect_async().await.is_ok() {
            let _ = controller.wait_for_disconnect_async().await;
        }
        Timer::after_millis(1000).await;
    }
}

#[embassy_executor::task]
async fn net_task(mut runner: Runner<'static, Interface>) {
    runner.run().await
}

/// Robots one server board serves.
const ROBOTS: usize = 4;

/// What the server glue counts.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
struct Counters {
    /// Commands the library refused (invalid, or no free slot).
    refused: u32,
    /// Pending commands replaced by a newer one from the ground.
    superseded: u32,
    /// Heartbeats forwarded to the opsUI.
    forwarded: u32,
    /// Heartbeats the opsUI's line did not take.
    ops_errors: u32,
}

/// The server board's state besides its sockets.
struct ServerGlue {
    /// The library's pending slots.
    srv: Server<ROBOTS>,
    /// The opsUI's serial line, receive side.
    ground: Link,
    /// The visited robot's TCP stream.
    robot: Link,
    /// Counts.
    counters: Counters,
}

impl ServerGlue {
    /// No robot known.
    const fn new() -> Self {
        ServerGlue {
            srv: Server::new(),
            ground: Link::new(PacketKind::Command),
            robot: Link::new(PacketKind::Heartbeat),
            counters: Counters {
                refused: 0,
                superseded: 0,
                forwarded: 0,
                ops_errors: 0,
            },
        }
    }

    /// Takes every command the opsUI's line has now into the pending slots.
    fn take_ground(&mut self, line: &mut impl ByteSource) {
        while let Some(p) = self.ground.next::<COMMAND_LEN>(line) {
            match self.srv.accept(&p) {
                Ok(Accepted::Queued | Accepted::Resend) => {}
                Ok(Accepted::Superseded(_)) => self.counters.superseded += 1,
                Err(ServerError::Invalid(_) | ServerError::Full { .. }) => {
                    self.counters.refused += 1
                }
            }
        }
    }

    /// Bytes from the visited robot; the first heartbeat in them, to forward.
    fn take_robot(&mut self, bytes: &[u8]) -> Option<[u8; HEARTBEAT_LEN]> {
        let mut hb = None;
        self.robot.feed(bytes, |p| {
            hb.get_or_insert(p);
        });
        if hb.is_some() {
            self.counters.forwarded += 1;
        }
        hb
    }
}
