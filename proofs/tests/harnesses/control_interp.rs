//! Interpolation over arbitrary start, target, rate and tick times (clock wrap included):
//! monotone towards the target, never past it, ending exactly on it, each tick moving at most
//! one step per elapsed period. Random under `cargo test`, Kani-ready.

use mmic::control::interp::{Interpolator, Rate};
use mmic::units::PulseWidth;

#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(10))]
fn interpolation_is_monotone_and_lands_on_target() {
    bolero::check!()
        .with_type::<(u16, u16, u8, u8, u32, [u16; 8])>()
        .for_each(|(a, b, step, period, t0, dts)| {
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
        });
}
