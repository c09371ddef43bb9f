//! Interpolation over arbitrary start, target, rate and tick times (clock wrap included):
//! monotone towards the target, never past it, ending exactly on it, each tick moving at most
//! one step per elapsed period. Random under `cargo test`, Kani-ready.

use mmic::control::interp::{Interpolator, Rate};
use mmic::units::PulseWidth;

/// Under `cargo test`: exhaustively, start and target each 0, 500, 501, 1500, 2499, 2500 or
/// 65,535 µs (the saturation at both ends and its ±1, the middle; equal, rising and falling),
/// steps 0, 1, 2, 7 and 255 µs, periods 0, 1, 2, 20 and 255 ms, from the clock's 0 and 1000
/// ms before the u32 wrap, and every sequence of 3 ticks after 0, 1, 2, 19, 20, 21, 255 or
/// 65,535 ms (one period ±1, partial periods banked across ticks); then sampled inputs.
// req: P5.1
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(10))]
fn interpolation_is_monotone_and_lands_on_target() {
    #[cfg(not(any(kani, fuzzing)))]
    {
        const PW: [u16; 7] = [0, 500, 501, 1500, 2499, 2500, 65535];
        const STEP: [u8; 5] = [0, 1, 2, 7, 255];
        const PERIOD: [u8; 5] = [0, 1, 2, 20, 255];
        const DT: [u16; 8] = [0, 1, 2, 19, 20, 21, 255, 65535];
        let name = "interpolation_is_monotone_and_lands_on_target";
        crate::ledger::exhaustive(
            name,
            49 * 25 * 2 * 8u64.pow(3),
            (
                (0usize..7, 0usize..7),
                (0usize..5, 0usize..5),
                bolero::produce::<bool>(),
                crate::ledger::seq::<_, 3>(0usize..8),
            ),
            |&((a, b), (step, period), wrap, dts)| {
                let t0 = if wrap { u32::MAX - 1000 } else { 0 };
                interp(
                    PW[a],
                    PW[b],
                    STEP[step],
                    PERIOD[period],
                    t0,
                    &dts.map(|d| DT[d]),
                );
            },
        );
        crate::ledger::sampled::<(u16, u16, u8, u8, u32, [u16; 8])>(
            name,
            200_000,
            |&(a, b, step, period, t0, dts)| interp(a, b, step, period, t0, &dts),
        );
        return;
    }
    #[allow(unreachable_code)]
    bolero::check!()
        .with_type::<(u16, u16, u8, u8, u32, [u16; 8])>()
        .for_each(|&(a, b, step, period, t0, dts)| interp(a, b, step, period, t0, &dts));
}

/// The property of [`interpolation_is_monotone_and_lands_on_target`].
fn interp(a: u16, b: u16, step: u8, period: u8, t0: u32, dts: &[u16]) {
    let (a, b, step, period, t0) = (&a, &b, &step, &period, &t0);
    let start = PulseWidth::saturating(*a);
    let target = PulseWidth::saturating(*b);
    let rate = Rate {
        step_us: (*step as u16).max(1),
        period_ms: (*period as u32).max(1),
    };
    let mut i = Interpolator::new(start, rate);
    i.set_target(target, *t0);
    let mut t = *t0;
    let mut prev = start.micros();
    let mut banked: u64 = 0;
    for &dt in dts.iter() {
        t = t.wrapping_add(dt as u32);
        banked += dt as u64;
        let now = i.tick(t).micros();
        let (lo, hi) = (
            start.micros().min(target.micros()),
            start.micros().max(target.micros()),
        );
        assert!(now >= lo && now <= hi, "left the segment");
        // Monotone towards the target.
        if target.micros() >= start.micros() {
            assert!(now >= prev);
        } else {
            assert!(now <= prev);
        }
        // Total progress = min(distance, periods elapsed × step).
        let dist = (target.micros() as i64 - start.micros() as i64).unsigned_abs();
        let moved = (now as i64 - start.micros() as i64).unsigned_abs();
        let allowed = (banked / rate.period_ms as u64) * rate.step_us as u64;
        assert_eq!(moved, dist.min(allowed));
        prev = now;
    }
    // Long after: exactly on target.
    let end = i.tick(t.wrapping_add(rate.period_ms * 2100));
    assert_eq!(end, target);
    assert!(i.done());
}
