//! The firmware's WiFi glue, one copy for board A and the server board (each used to carry its
//! own): joining the lab's access point at a fixed address, the tasks that keep the station
//! associated and run the network stack, and writing a whole packet to a TCP socket. What the
//! connections carry, and when, is the library's (`mmic::node::robot::wifi_session`,
//! `mmic::node::server::visit`); this is the radio and the sockets only.
#![no_std]

use embassy_executor::Spawner;
use embassy_net::tcp::TcpSocket;
use embassy_net::{Ipv4Address, Ipv4Cidr, Runner, Stack, StackResources, StaticConfigV4};
use embassy_time::{Duration, Instant, Timer};
use esp_hal::peripherals::WIFI;
use esp_hal::rng::Rng;
use esp_radio::wifi::{self, sta::StationConfig, AuthenticationMethodConfig, Interface};
use static_cell::StaticCell;
use support::net;

static NET: StaticCell<StackResources<3>> = StaticCell::new();

/// The lab access point's WPA2 passphrase, at build time (`MMIC_PASSWORD`). There is no
/// default: without one, or with one WPA2 refuses or the old public default, the build stops
/// here with the reason (`support::net::password`, host-tested).
pub const PASSWORD: &str = match support::net::password(option_env!("MMIC_PASSWORD")) {
    Ok(p) => p,
    Err(why) => panic!("{}", why),
};

/// The radio boards' start-up, as the first statements of `main`: binds `$p` to the chip's
/// peripherals at full clock, gives esp-radio its heap (64 KiB of reclaimed RAM plus 36 KiB,
/// enough for WiFi and TCP) and starts esp-rtos on timer group 0. Expands in the calling
/// crate, which depends on esp-hal, esp-alloc and esp-rtos itself.
#[macro_export]
macro_rules! boot {
    ($p:ident) => {
        let $p = esp_hal::init(
            esp_hal::Config::default().with_cpu_clock(esp_hal::clock::CpuClock::max()),
        );
        esp_alloc::heap_allocator!(#[esp_hal::ram(reclaimed)] size: 64 * 1024);
        esp_alloc::heap_allocator!(size: 36 * 1024);
        let timg0 = esp_hal::timer::timg::TimerGroup::new($p.TIMG0);
        esp_rtos::start(timg0.timer0, $p.FROM_CPU_INTR0);
    };
}

/// Brings the radio up as a station on the lab's access point ([`net::SSID`]) at `address`
/// (a /24 on the lab network, no gateway), spawns the tasks that keep it associated and run
/// the network stack, and returns the stack. Start-up only: a radio that cannot be configured
/// is a build or wiring error, so it panics with the reason.
pub fn start(spawner: &Spawner, radio: WIFI<'static>, address: [u8; 4]) -> Stack<'static> {
    let auth = AuthenticationMethodConfig::Wpa2Personal(PASSWORD.try_into().expect("password"));
    let sta = StationConfig::default()
        .with_ssid(net::SSID.try_into().expect("SSID"))
        .with_authentication(auth);
    let radio_cfg =
        wifi::ControllerConfig::default().with_initial_config(wifi::Config::Station(sta));
    let controller = wifi::WifiController::new(radio, radio_cfg).expect("WiFi");
    let ip = StaticConfigV4 {
        address: Ipv4Cidr::new(Ipv4Address::from(address), 24),
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
    stack
}

/// The time the library's session machines take, ms since boot (wrapping, as they expect).
pub fn now_ms() -> u32 {
    Instant::now().as_millis() as u32
}

/// `ms` as an embassy duration.
pub fn ms(ms: u32) -> Duration {
    Duration::from_millis(ms.into())
}

/// Writes all of `bytes`; false when the connection failed first.
pub async fn write_all(sock: &mut TcpSocket<'_>, mut bytes: &[u8]) -> bool {
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
