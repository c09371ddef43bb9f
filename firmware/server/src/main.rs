//! The server board (Figure 4): commands from the opsUI on the USB serial line go into the
//! library's pending slots (`mmic::node::server::relay`); each loop visits one robot with a pending
//! command as the library's `Visit` says: connect, send, forward the heartbeat that comes
//! back by the visit's deadline, disconnect.
//!
//! The USB serial line carries the opsUI's packets only: this binary prints nothing after
//! start-up (a panic message would reach the opsUI, whose deframer drops it as garbage).
#![no_std]
#![no_main]

use embassy_executor::Spawner;
use embassy_net::tcp::TcpSocket;
use embassy_net::{Ipv4Address, Stack};
use embassy_time::{with_timeout, Duration, Ticker};
use esp_backtrace as _;
use esp_hal::usb::usb_serial_jtag::{UsbSerialJtag, UsbSerialJtagRx, UsbSerialJtagTx};
use esp_hal::Blocking;
use mmic::node::server::relay::{Accepted, Server, ServerError};
use mmic::node::server::visit::{Heartbeat, Visit};
use mmic::wire::command::COMMAND_LEN;
use mmic::wire::PacketKind;
use support::link::{ByteSink, ByteSource, Link};
use support::net;

esp_bootloader_esp_idf::esp_app_desc!();

/// How long a visit lasts at most, connecting and waiting for the heartbeat (the host
/// simulator's `visit_ms`), ms.
const VISIT_MS: u32 = 200;
/// The loop's period while no command is pending, and the opsUI line's idle time.
const IDLE: Duration = Duration::from_millis(10);

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
    wifi::boot!(p);
    let (rx, tx) = UsbSerialJtag::new(p.USB_DEVICE).split();
    let ops = OpsUi(rx, tx);

    // Start-up: WiFi station on the lab's access point at the server's fixed address.
    let stack = wifi::start(&spawner, p.WIFI, net::SERVER);
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
        let Some(mut visit) = Visit::next(&mut glue.srv, wifi::now_ms(), VISIT_MS) else {
            continue;
        };
        let mut sock = TcpSocket::new(stack, &mut rx_buf, &mut tx_buf);
        sock.set_timeout(Some(wifi::ms(VISIT_MS)));
        let to = (
            Ipv4Address::from(net::robot(visit.board().get())),
            net::PORT,
        );
        let left = visit.left_ms(wifi::now_ms()).unwrap_or(0);
        if let Ok(Ok(())) = with_timeout(wifi::ms(left), sock.connect(to)).await {
            if wifi::write_all(&mut sock, visit.packet()).await {
                visit.written(&mut glue.srv);
                if let Some(hb) = heartbeat(&mut sock, &mut visit).await {
                    glue.forward(&mut ops, &hb);
                }
            }
            sock.close();
            let _ = with_timeout(IDLE, sock.flush()).await;
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
    /// Counts.
    counters: Counters,
}

impl ServerGlue {
    /// No robot known.
    const fn new() -> Self {
        ServerGlue {
            srv: Server::new(),
            ground: Link::new(PacketKind::Command),
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

    /// The visit's heartbeat, written to the opsUI's line.
    fn forward(&mut self, ops: &mut impl ByteSink, hb: &Heartbeat) {
        if ops.write(hb) {
            self.counters.forwarded += 1;
        } else {
            self.counters.ops_errors = self.counters.ops_errors.saturating_add(1);
        }
    }
}
