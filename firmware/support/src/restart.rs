//! Restarts on the device (issue 29, point 4): the watchdogs' feeding gate, and why the chip
//! last started. Pure: the esp-hal side (the RTC and timer-group watchdogs, the ROM's reset
//! reason, the panic mark in RTC memory) is `hw::watchdog`, which only moves these values.
//!
//! A board's watchdogs are fed only through a [`Gate`], by the control loop, after a tick
//! that returned: a tick that hangs never feeds, a tick that panics never reaches the feed
//! (and the panic handler resets the chip), so either way the board restarts into Table 7's
//! power-on (Standby, servos unpowered, nothing resumed: `BoardA::restarted`). The timeouts are
//! `spec/watchdog.toml`'s ([`CONTROL_TIMEOUT_MS`], [`RTC_TIMEOUT_MS`]).

use mmic::restart::ResetCause;

/// The timer-group watchdog's timeout, ms (`spec/watchdog.toml` `control_timeout_ms`): armed
/// when the control loop starts, fed after every complete tick.
pub const CONTROL_TIMEOUT_MS: u32 = 1000;
/// The RTC watchdog's timeout, ms (`spec/watchdog.toml` `rtc_timeout_ms`): armed at start-up,
/// so it covers the boot up to the first complete tick, fed through the same gate.
pub const RTC_TIMEOUT_MS: u32 = 4000;

// Each covers many control periods, and the backstop outlasts the control watchdog.
const _: () = assert!(
    CONTROL_TIMEOUT_MS >= 10 * crate::control::TICK_MS && RTC_TIMEOUT_MS > CONTROL_TIMEOUT_MS
);

/// What the gate feeds: the board's watchdogs.
pub trait Feed {
    /// Restarts every watchdog's count.
    fn feed(&mut self);
}

/// The watchdogs behind the one door the control loop opens: [`Gate::begin`] marks a tick
/// begun, [`Tick::complete`] marks it complete and feeds, once. There is no other way to
/// feed: a [`Tick`] is not `Copy` and `complete` takes it, so one tick feeds at most once; a
/// tick dropped unfinished (the stack unwinding from a panic, on the host) or never finished
/// (a hang) does not feed.
pub struct Gate<D: Feed> {
    dogs: D,
    begun: u32,
    fed: u32,
}

/// A tick in progress: [`Tick::complete`] feeds the watchdogs.
#[must_use = "a tick feeds the watchdogs only when completed"]
pub struct Tick<'g, D: Feed> {
    gate: &'g mut Gate<D>,
}

impl<D: Feed> Gate<D> {
    /// The gate over `dogs` (armed by the shell).
    pub const fn new(dogs: D) -> Self {
        Gate {
            dogs,
            begun: 0,
            fed: 0,
        }
    }

    /// Marks a tick begun.
    pub fn begin(&mut self) -> Tick<'_, D> {
        self.begun = self.begun.wrapping_add(1);
        Tick { gate: self }
    }

    /// Runs one tick (`tick`) between [`Gate::begin`] and [`Tick::complete`]: the watchdogs are
    /// fed once `tick` returns, and never if it does not.
    pub fn run<R>(&mut self, tick: impl FnOnce() -> R) -> R {
        let t = self.begin();
        let r = tick();
        t.complete();
        r
    }

    /// Ticks begun (wrapping).
    pub const fn begun(&self) -> u32 {
        self.begun
    }

    /// Feeds given (wrapping): one per complete tick.
    pub const fn fed(&self) -> u32 {
        self.fed
    }

    /// The watchdogs (for the shell's logs, and tests).
    pub const fn dogs(&self) -> &D {
        &self.dogs
    }
}

impl<D: Feed> Tick<'_, D> {
    /// Marks the tick complete and feeds the watchdogs.
    pub fn complete(self) {
        self.gate.dogs.feed();
        self.gate.fed = self.gate.fed.wrapping_add(1);
    }
}

/// The mark the panic handler leaves in RTC memory before it resets the chip
/// (`hw::watchdog`): a word no power-on content is likely to hold ("PANC"), not a flag,
/// because RTC memory holds noise after a power cycle.
pub const PANIC_MARK: u32 = 0x5041_4E43;

/// Whether a word of RTC memory read at start-up is the panic mark.
pub const fn panicked(word: u32) -> bool {
    word == PANIC_MARK
}

/// The reset cause of the chip's reset reason `code` (the ROM's `rtc_get_reset_reason`,
/// esp-hal's `SocResetReason` as a number) and whether the panic handler left its mark
/// ([`panicked`]).
///
/// The codes are ESP-IDF's `soc_reset_reason_t`, numbered alike on the ESP32, the C3 and the
/// C6 (a code means the same on every chip that has it): power-on and the chip-enable pin
/// (0x01, which the C3 also reports for some brown-outs), software (0x03, 0x0C), deep sleep
/// (0x05), SDIO (0x06), the timer groups' watchdogs (0x07, 0x08, 0x0B, 0x11), the RTC
/// watchdog (0x09, 0x0D, 0x10), the super watchdog (0x12), brown-out (0x0F), a power glitch
/// (0x17), a clock glitch (0x13), an eFuse CRC error (0x14), the USB serial or JTAG
/// controller (0x15, 0x16; 0x18 on the C6), the ESP32's CPU 0 resetting CPU 1 (0x0E).
///
/// The panic mark turns a software or watchdog reset into [`ResetCause::Panic`]: the panic
/// handler resets by software, or a watchdog bites while it prints. Any other reset cleared or
/// did not come from it.
pub const fn reset_cause(code: u32, panic_mark: bool) -> ResetCause {
    let cause = match code {
        0x01 => ResetCause::PowerOn,
        0x03 | 0x0C => ResetCause::Software,
        0x07 | 0x08 | 0x09 | 0x0B | 0x0D | 0x10 | 0x11 | 0x12 => ResetCause::Watchdog,
        // A power glitch is the supply's, as a brown-out: the operator's response is the same.
        0x0F | 0x17 => ResetCause::BrownOut,
        // A host reset the chip through its USB controller (a flasher's reset, as the EN pin).
        0x15 | 0x16 | 0x18 => ResetCause::External,
        _ => ResetCause::Other,
    };
    match cause {
        ResetCause::Software | ResetCause::Watchdog if panic_mark => ResetCause::Panic,
        c => c,
    }
}
