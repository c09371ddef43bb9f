//! The esp-hal side of the glue's traits: LEDC servo pulses, GPIO lines, the blocking UART.

use crate::control::Actuators;
use crate::link::{ByteSink, ByteSource};
use esp_hal::gpio::{AnyPin, DriveMode, Input, InputConfig, Level, Output, OutputConfig, Pull};
use esp_hal::ledc::channel::{self, Channel, ChannelHW, ChannelIFace};
use esp_hal::ledc::timer::{self, Timer, TimerIFace};
use esp_hal::ledc::{LSGlobalClkSource, Ledc, LowSpeed};
use esp_hal::peripherals::LEDC;
use esp_hal::time::Rate;
use esp_hal::uart::Uart;
use esp_hal::Blocking;
use mmic::bolter::MuxLines;
use mmic::units::PulseWidth;
use static_cell::StaticCell;

/// LEDC duty (14 bits of a 20 ms period) of a pulse; none: 0, no pulse.
pub const fn duty(p: Option<PulseWidth>) -> u32 {
    match p {
        Some(p) => p.micros() as u32 * (1 << 14) / 20_000,
        None => 0,
    }
}

fn out(pin: AnyPin<'static>) -> Output<'static> {
    Output::new(pin, Level::Low, OutputConfig::default())
}

/// The side's input switches (pulled up; a closed switch reads low).
pub fn switches(pins: [AnyPin<'static>; 2]) -> [Input<'static>; 2] {
    pins.map(|p| Input::new(p, InputConfig::default().with_pull(Pull::Up)))
}

/// A side's outputs on the chip.
pub struct Outputs {
    _ledc: Ledc<'static>,
    servos: [Channel<'static, LowSpeed>; 3],
    bolter: [Output<'static>; 3],
    mux: [Output<'static>; 2],
    regulator: Output<'static>,
}

static TIMER: StaticCell<Timer<'static, LowSpeed>> = StaticCell::new();

impl Outputs {
    /// LEDC timer 0 at 50 Hz with channels 0–2 on the servo pins (arm, gripper, hip), every
    /// line low, no pulse. Start-up only (call once; panics on a configuration error).
    pub fn new(
        ledc: LEDC<'static>,
        servos: [AnyPin<'static>; 3],
        bolter: [AnyPin<'static>; 3],
        mux: [AnyPin<'static>; 2],
        regulator: AnyPin<'static>,
    ) -> Self {
        let mut ledc = Ledc::new(ledc);
        ledc.set_global_slow_clock(LSGlobalClkSource::APBClk);
        let t = TIMER.init(ledc.timer::<LowSpeed>(timer::Number::Timer0));
        t.configure(timer::config::Config {
            duty: timer::config::Duty::Duty14Bit,
            clock_source: timer::LSClockSource::APBClk,
            frequency: Rate::from_hz(50),
        })
        .expect("LEDC timer");
        let t: &'static Timer<'static, LowSpeed> = t;
        let [s0, s1, s2] = servos;
        let mut servos = [
            ledc.channel(channel::Number::Channel0, s0),
            ledc.channel(channel::Number::Channel1, s1),
            ledc.channel(channel::Number::Channel2, s2),
        ];
        for c in servos.iter_mut() {
            let cfg = channel::config::Config {
                timer: t,
                duty_pct: 0,
                drive_mode: DriveMode::PushPull,
            };
            c.configure(cfg).expect("LEDC channel");
        }
        Outputs {
            _ledc: ledc,
            servos,
            bolter: bolter.map(out),
            mux: mux.map(out),
            regulator: out(regulator),
        }
    }
}

impl Actuators for Outputs {
    fn servos(&mut self, pulses: [Option<PulseWidth>; 3]) {
        for (c, p) in self.servos.iter().zip(pulses) {
            c.set_duty_hw(duty(p));
        }
    }

    fn regulator(&mut self, on: bool) {
        self.regulator.set_level(Level::from(on));
    }

    fn bolter(&mut self, lines: [bool; 3], mux: MuxLines) {
        for (o, l) in self.bolter.iter_mut().zip(lines) {
            o.set_level(Level::from(l));
        }
        self.mux[0].set_level(Level::from(mux.a0));
        self.mux[1].set_level(Level::from(mux.a1));
    }
}

/// The A–B serial line.
pub struct Serial {
    /// The UART.
    pub uart: Uart<'static, Blocking>,
    /// Receive errors (overrun, framing, parity): the bytes are lost, the deframer resyncs.
    pub rx_errors: u32,
}

impl ByteSource for Serial {
    fn read(&mut self, buf: &mut [u8]) -> usize {
        match self.uart.read_buffered(buf) {
            Ok(n) => n,
            Err(_) => {
                self.rx_errors = self.rx_errors.saturating_add(1);
                0
            }
        }
    }
}

impl ByteSink for Serial {
    fn write(&mut self, bytes: &[u8]) -> bool {
        matches!(self.uart.write(bytes), Ok(n) if n == bytes.len())
    }
}
