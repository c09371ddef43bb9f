//! The esp-hal side of [`crate::restart`]: the chip's two watchdogs behind the feeding gate,
//! the reset reason read at start-up, and the panic handler's mark in RTC memory.
//!
//! - The RTC watchdog (`rtc_cntl::Rwdt`), armed at start-up by [`Dogs::arm`] with
//!   [`RTC_TIMEOUT_MS`]: it covers the boot up to the first complete tick, and stays as the
//!   backstop that resets the RTC domain too.
//! - Timer group 1's watchdog (`timer::timg::Wdt<TIMG1>`; group 0's timer runs esp-rtos),
//!   armed by [`Dogs::arm_control`] when the control loop starts, with [`CONTROL_TIMEOUT_MS`].
//!
//! Both reset the whole system at stage 0 (esp-hal's `enable`: the other stages off). Both are
//! fed only by [`crate::restart::Gate`], after a complete tick.
//!
//! On a panic, esp-backtrace (features `custom-pre-backtrace`, `custom-halt`) calls
//! `custom_pre_backtrace` before it prints, which leaves [`PANIC_MARK`] in RTC fast memory,
//! and `custom_halt` after, which resets the chip by software. A watchdog that bites while the
//! handler prints finds the mark too. The next start reads and clears it ([`reset_cause`]).

use crate::restart::{self, Feed, CONTROL_TIMEOUT_MS, PANIC_MARK, RTC_TIMEOUT_MS};
use esp_hal::peripherals::{RTC_TIMER, TIMG1};
use esp_hal::rtc_cntl::{Rtc, Rwdt, RwdtStage};
use esp_hal::system::Cpu;
use esp_hal::time::Duration;
use esp_hal::timer::timg::{MwdtStage, TimerGroup, Wdt};
use mmic::restart::ResetCause;
use portable_atomic::{AtomicU32, Ordering};

/// The panic mark, kept across software and watchdog resets (zeroed at power-on by esp-hal,
/// noise possible after a reset during that zeroing: hence a whole word, [`PANIC_MARK`]).
#[esp_hal::ram(unstable(rtc_fast, persistent))]
static MARK: AtomicU32 = AtomicU32::new(0);

/// Why the chip started: the ROM's reset reason of CPU 0 as a [`ResetCause`], and its code
/// (for the log). Clears the panic mark. Call once, at start-up.
pub fn reset_cause() -> (ResetCause, u32) {
    let code = esp_hal::rom::rtc_get_reset_reason(Cpu::ProCpu as u32);
    let mark = MARK.load(Ordering::SeqCst);
    MARK.store(0, Ordering::SeqCst);
    (restart::reset_cause(code, restart::panicked(mark)), code)
}

/// The board's two watchdogs.
pub struct Dogs {
    rtc: Rwdt,
    control: Wdt<TIMG1<'static>>,
}

fn ms(ms: u32) -> Duration {
    Duration::from_millis(ms.into())
}

impl Dogs {
    /// Arms the RTC watchdog ([`RTC_TIMEOUT_MS`]); the timer group's waits for
    /// [`Dogs::arm_control`]. Start-up, right after `esp_hal::init` (which disables both).
    pub fn arm(rtc_timer: RTC_TIMER<'static>, timg1: TIMG1<'static>) -> Dogs {
        let mut rtc = Rtc::new(rtc_timer).rwdt;
        // The timeout before the enable: the count must not run against a stale one.
        rtc.set_timeout(RwdtStage::Stage0, ms(RTC_TIMEOUT_MS));
        rtc.enable();
        rtc.feed();
        Dogs {
            rtc,
            control: TimerGroup::new(timg1).wdt,
        }
    }

    /// Arms the timer group's watchdog ([`CONTROL_TIMEOUT_MS`]): when the control loop starts.
    pub fn arm_control(&mut self) {
        self.control
            .set_timeout(MwdtStage::Stage0, ms(CONTROL_TIMEOUT_MS));
        self.control.enable();
        self.control.feed();
    }
}

impl Feed for Dogs {
    fn feed(&mut self) {
        self.rtc.feed();
        self.control.feed();
    }
}

/// esp-backtrace's hook before it prints a panic: the mark for the next start.
#[no_mangle]
fn custom_pre_backtrace() {
    MARK.store(PANIC_MARK, Ordering::SeqCst);
}

/// esp-backtrace's end of a panic: reset now, rather than spin until a watchdog bites.
#[no_mangle]
fn custom_halt() -> ! {
    esp_hal::system::software_reset()
}
