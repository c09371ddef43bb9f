//! The paper's server board (Section 3, Figure 4): the opsUI's command packets arrive on the
//! USB serial line ("RS232 over USB": the USB-Serial-JTAG peripheral's CDC-ACM port) and wait
//! in the library's pending slots (`mmic::node::server::relay`, the paper's "command byte");
//! each loop visits one robot with a pending command as the library's `Visit` says — connect
//! to its board A, check that the peer is that board A (`net::visit_peer`), send, forward the
//! heartbeat that comes back within `relay::VISIT_MS` to the serial line unchanged, disconnect.
//! Every step is `support::relay` (host-tested in support/tests/relay.rs); this file is the
//! USB line, the socket and the loop.
//!
//! Beside it, firmware/server-ccsds is the server board towards a CCSDS ground (SDLS, FARM-1,
//! PUS); this image is the paper's, with the paper's protocol: no SDLS, no authentication on
//! the serial line (docs/security.md), no flash partition, nothing kept across a restart (the
//! opsUI resends until it hears a heartbeat; board A's log answers a command it already ran).
//!
//! The USB serial line carries the opsUI's packets: this image prints one line at start-up
//! (the reset cause, which the opsUI's deframer drops as garbage) and nothing after. The
//! watchdogs are fed only after a complete pass (`support::restart::Gate`, `support::wdt`); no
//! `unwrap`/`expect` after start-up.
#![no_std]
#![no_main]

use embassy_executor::Spawner;
use embassy_net::tcp::TcpSocket;
use embassy_net::{IpAddress, Ipv4Address, Stack};
use embassy_time::{with_timeout, Timer};
use esp_backtrace as _;
use esp_hal::usb::usb_serial_jtag::{UsbSerialJtag, UsbSerialJtagRx, UsbSerialJtagTx};
use esp_hal::Blocking;
use mmic::node::server::relay::VISIT_MS;
use support::link::{ByteSink, ByteSource};
use support::net;
use support::relay::{Connection, Relay, CLOSE_MS};
use support::restart::Gate;
use support::server::Clock;
use support::wdt::{self, Dogs};

esp_bootloader_esp_idf::esp_app_desc!();

/// The pause between passes, ms: the serial line's idle poll, part of the serial line's share
/// of the opsUI's window (`relay::SERIAL_RESERVE_MS`).
const IDLE_MS: u32 = 10;
/// How long a heartbeat waits for the USB host to take it, ms. A host that polls reads the 66
/// octets within its 1 ms frames; one that takes nothing for this long is not reading (the
/// opsUI not attached), so the heartbeat is dropped and counted rather than the loop stalling
/// into the watchdog.
const OPS_WRITE_MS: u32 = 20;

#[esp_rtos::main]
async fn main(spawner: Spawner) -> ! {
    wifi::boot!(p);
    // The RTC watchdog from here: it covers the start-up up to the first complete pass.
    let (cause, code) = wdt::reset_cause();
    let dogs = Dogs::arm(p.RTC_TIMER, p.TIMG1);
    // The last line printed: from here the serial line is the opsUI's.
    esp_println::println!("mmic server board (paper relay), reset reason {code:#04x}: {cause}");
    let (rx, tx) = UsbSerialJtag::new(p.USB_DEVICE).split();
    // Start-up: WiFi station on the lab's access point at the server's fixed address.
    let stack = wifi::start(&spawner, p.WIFI, net::SERVER);
    serve(stack, OpsUi { rx, tx }, dogs).await
}

/// Figure 4's loop: one pass of the relay (the serial line, then at most one visit), the
/// watchdogs fed after each complete one, then [`IDLE_MS`].
async fn serve(stack: Stack<'static>, mut ops: OpsUi, mut dogs: Dogs) -> ! {
    let (mut rx_buf, mut tx_buf) = ([0u8; 256], [0u8; 256]);
    let mut relay = Relay::new();
    dogs.arm_control();
    let mut gate = Gate::new(dogs);
    loop {
        let tick = gate.begin();
        let open = socket(stack, &mut rx_buf, &mut tx_buf);
        relay.pass(&mut ops, open, &mut Uptime).await;
        tick.complete();
        Timer::after(wifi::ms(IDLE_MS)).await;
    }
}

/// The visit's socket, made only when a command is pending (the relay calls it then).
fn socket<'a>(
    stack: Stack<'static>,
    rx: &'a mut [u8],
    tx: &'a mut [u8],
) -> impl FnOnce() -> Tcp<'a> {
    move || {
        let mut sock = TcpSocket::new(stack, rx, tx);
        sock.set_timeout(Some(wifi::ms(VISIT_MS)));
        Tcp(sock)
    }
}

/// The opsUI's line: the USB-Serial-JTAG peripheral's CDC-ACM port, polled.
struct OpsUi {
    rx: UsbSerialJtagRx<'static, Blocking>,
    tx: UsbSerialJtagTx<'static, Blocking>,
}

impl ByteSource for OpsUi {
    fn read(&mut self, buf: &mut [u8]) -> usize {
        // `drain_rx_fifo` stores a waiting byte before it looks at the buffer's length: an
        // empty buffer (the deframer full) would panic there.
        if buf.is_empty() {
            return 0;
        }
        self.rx.drain_rx_fifo(buf)
    }
}

impl ByteSink for OpsUi {
    /// Byte by byte into the 64-octet FIFO, flushing when it is full, for at most
    /// [`OPS_WRITE_MS`] (esp-hal's blocking `write` waits for the host without end).
    fn write(&mut self, bytes: &[u8]) -> bool {
        let start = wifi::now_ms();
        let in_time = || wifi::now_ms().wrapping_sub(start) <= OPS_WRITE_MS;
        for &b in bytes {
            while self.tx.write_byte_nb(b).is_err() {
                let _ = self.tx.flush_tx_nb();
                if !in_time() {
                    return false;
                }
            }
        }
        while self.tx.flush_tx_nb().is_err() {
            if !in_time() {
                return false;
            }
        }
        true
    }
}

/// One visit's TCP connection to a board A.
struct Tcp<'a>(TcpSocket<'a>);

impl Connection for Tcp<'_> {
    async fn connect(&mut self, to: net::Endpoint, within_ms: u32) -> bool {
        let to = (Ipv4Address::from(to.0), to.1);
        matches!(
            with_timeout(wifi::ms(within_ms), self.0.connect(to)).await,
            Ok(Ok(()))
        )
    }

    fn peer(&self) -> Option<net::Endpoint> {
        self.0.remote_endpoint().map(|e| {
            // The stack runs IPv4 only.
            let IpAddress::Ipv4(a) = e.addr;
            (a.octets(), e.port)
        })
    }

    async fn write_all(&mut self, bytes: &[u8]) -> bool {
        wifi::write_all(&mut self.0, bytes).await
    }

    async fn read(&mut self, buf: &mut [u8], within_ms: u32) -> usize {
        match with_timeout(wifi::ms(within_ms), self.0.read(buf)).await {
            Ok(Ok(n)) => n,
            _ => 0,
        }
    }

    async fn close(&mut self) {
        self.0.close();
        let _ = with_timeout(wifi::ms(CLOSE_MS), self.0.flush()).await;
        self.0.abort();
    }

    async fn abort(&mut self) {
        self.0.abort();
        let _ = with_timeout(wifi::ms(CLOSE_MS), self.0.flush()).await;
    }
}

/// The clock of the library's visit.
struct Uptime;

impl Clock for Uptime {
    fn now_ms(&mut self) -> u32 {
        wifi::now_ms()
    }
}
