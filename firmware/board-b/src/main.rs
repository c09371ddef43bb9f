//! Board B (Figure 7): side B's sensors and outputs, and the serial line to board A. One
//! embassy task: every 10 ms, read, filter, `BoardB::tick`, drive, send its heartbeat when
//! the library says one is due (every 50 ms). Its watchdogs are fed only after a complete
//! tick (`support::restart`, `support::wdt`); it keeps nothing across a restart.
#![no_std]
#![no_main]

use core::cell::RefCell;
use embassy_executor::Spawner;
use embassy_time::{Duration, Instant, Ticker};
use esp_backtrace as _;
use esp_hal::clock::CpuClock;
use esp_hal::gpio::Input;
use esp_hal::i2c::master::{Config as I2cConfig, I2c};
use esp_hal::time::Rate;
use esp_hal::timer::timg::TimerGroup;
use esp_hal::uart::{Config as UartConfig, Uart};
use esp_hal::Blocking;
use esp_println::println;
use mmic::node::robot::board_b;
use mmic::node::robot::board_b::BoardB;
use mmic::sensors::frontend;
use mmic::sensors::frontend::{Frontend, WINDOW};
use mmic::wire::PacketKind;
use static_cell::StaticCell;
use support::control::{bolter_lines, Actuators, Counters, Sensors, TICK_MS};
use support::hw::{self, Serial};
use support::link::{ByteSink, ByteSource, Link};
use support::restart::Gate;
use support::sensors::Side;
use support::wdt::{self, Dogs};

esp_bootloader_esp_idf::esp_app_desc!();

/// Status line period, ticks.
const STATUS_TICKS: u32 = 500;

static BUS: StaticCell<RefCell<I2c<'static, Blocking>>> = StaticCell::new();

#[esp_rtos::main]
async fn main(_spawner: Spawner) -> ! {
    let p = esp_hal::init(esp_hal::Config::default().with_cpu_clock(CpuClock::max()));
    let timg0 = TimerGroup::new(p.TIMG0);
    esp_rtos::start(timg0.timer0, p.FROM_CPU_INTR0);
    // The RTC watchdog from here: it covers the start-up up to the first complete tick.
    let (cause, code) = wdt::reset_cause();
    let mut dogs = Dogs::arm(p.RTC_TIMER, p.TIMG1);
    println!(
        "mmic board B on {}, reset reason {code:#04x}: {cause}",
        support::chip::CHIP
    );

    // Start-up: a peripheral that cannot be configured is a build or wiring error.
    let pins = support::take_pins!(p);
    let i2c_cfg = I2cConfig::default().with_frequency(Rate::from_khz(400));
    let i2c = I2c::new(p.I2C0, i2c_cfg).expect("I2C config");
    let bus = BUS.init(RefCell::new(i2c.with_sda(pins.sda).with_scl(pins.scl)));
    let mut side: Side<'_, _, Input<'static>> = Side::new(bus, hw::switches(pins.switches), false);
    let mut outs = hw::Outputs::new(p.LEDC, pins.servos, pins.bolter, pins.mux, pins.regulator);
    let [tx, rx] = pins.uart;
    let uart = Uart::new(p.UART1, UartConfig::default().with_baudrate(support::BAUD))
        .expect("UART config")
        .with_tx(tx)
        .with_rx(rx);
    let mut serial = Serial { uart, rx_errors: 0 };
    // Board B has no hip encoder: its silence is no loss.
    let front = frontend::Config {
        hip_encoder: false,
        ..frontend::Config::default()
    };
    let mut ctl = ControlB::new(board_b::Config::default(), front);

    let mut ticker = Ticker::every(Duration::from_millis(TICK_MS.into()));
    let mut ticks = 0u32;
    dogs.arm_control();
    let mut gate = Gate::new(dogs);
    loop {
        let now = Instant::now().as_millis() as u32;
        gate.run(|| ctl.tick(now, &mut side, &mut outs, &mut serial));
        ticks = ticks.wrapping_add(1);
        if ticks.is_multiple_of(STATUS_TICKS) {
            println!(
                "t={now} i2c={:?} rx_err={} discarded={} frames={}",
                side.errors,
                serial.rx_errors,
                ctl.from_a.discarded(),
                ctl.from_a.frames()
            );
        }
        ticker.next().await;
    }
}

/// Board B's control task.
pub struct ControlB {
    /// The library's board B.
    pub b: BoardB,
    front: Frontend<WINDOW>,
    /// Board A's serial line, receive side.
    pub from_a: Link,
    /// Counts.
    pub counters: Counters,
}

impl ControlB {
    /// Board B.
    pub fn new(cfg: board_b::Config, front: frontend::Config) -> Self {
        ControlB {
            b: BoardB::new(cfg),
            front: Frontend::new(front),
            from_a: Link::new(PacketKind::BCommand),
            counters: Counters::default(),
        }
    }

    /// One tick at `now` ms, as `support::control::ControlA::tick`.
    pub fn tick(
        &mut self,
        now: u32,
        sensors: &mut impl Sensors,
        out: &mut impl Actuators,
        uart: &mut (impl ByteSource + ByteSink),
    ) -> board_b::Outputs {
        let r = sensors.read();
        let f = self.front.push(&r.raw);
        let command = self.from_a.next(uart);
        let inputs = board_b::Inputs::sensed(&f, r.arm_contracted, r.bolter_at_home, command);
        let o = self.b.tick(now, &inputs);
        out.servos([o.arm, o.gripper, None]);
        out.regulator(o.regulator);
        out.bolter(bolter_lines(o.bolter), o.mux);
        if let Some(hb) = o.heartbeat {
            if !uart.write(&hb) {
                self.counters.tx_errors = self.counters.tx_errors.saturating_add(1);
            }
        }
        o
    }
}
