//! The hip PI controller never overflows (debug builds and cargo bolero's fuzz profile check
//! every arithmetic operation) and its output always lies within the configured range around
//! the stop pulse, for arbitrary gains, targets, readings and tick times (clock wrap included).
//! Random under `cargo test`, Kani-ready (`cargo kani --tests`: a proof over 6 ticks).

use mmic::control::hip::{Config, HipController};
use mmic::units::HipAngle;

const TICKS: usize = 6;

/// Under `cargo test`: exhaustively, every configuration whose seven gains are each i32::MIN,
/// −1, 0, 1 or i32::MAX (the extremes where an overflow would be, and the signs; the output
/// limit `(g0 ^ g1) % 1200` then takes negative, zero and saturating values), with smoothing
/// shifts 0, 8, 31 and u32::MAX, over two tick sequences of extreme errors (a half turn, the
/// 0/35999 wrap of the angle, none) after 0, 1 and 65,535 ms, from 100 ms before the u32 wrap;
/// then sampled inputs.
// req: P5.5
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(8))]
fn hip_controller_never_overflows_and_saturates() {
    #[cfg(not(any(kani, fuzzing)))]
    {
        const G: [i32; 5] = [i32::MIN, -1, 0, 1, i32::MAX];
        const SHIFT: [u32; 4] = [0, 8, 31, u32::MAX];
        const TICKS_OF: [[(u16, u16, u16); TICKS]; 2] = [
            [
                (0, 18000, 0),
                (35999, 0, 65535),
                (0, 35999, 1),
                (18000, 18000, 65535),
                (35999, 35999, 0),
                (0, 0, 100),
            ],
            [
                (18000, 0, 1),
                (18000, 0, 1),
                (18000, 0, 65535),
                (0, 18000, 65535),
                (0, 18000, 1),
                (35999, 1, 65535),
            ],
        ];
        let name = "hip_controller_never_overflows_and_saturates";
        crate::ledger::exhaustive(
            name,
            5u64.pow(7) * 4 * 2,
            (crate::ledger::seq::<_, 7>(0usize..5), 0usize..4, 0usize..2),
            |&(g, shift, ticks)| {
                hip(
                    &g.map(|k| G[k]),
                    SHIFT[shift],
                    u32::MAX - 100,
                    &TICKS_OF[ticks],
                );
            },
        );
        crate::ledger::sampled::<([i32; 7], u32, u32, [(u16, u16, u16); TICKS])>(
            name,
            200_000,
            |(g, shift, t0, ticks)| hip(g, *shift, *t0, ticks),
        );
        return;
    }
    #[allow(unreachable_code)]
    bolero::check!()
        .with_type::<([i32; 7], u32, u32, [(u16, u16, u16); TICKS])>()
        .for_each(|(g, shift, t0, ticks)| hip(g, *shift, *t0, ticks));
}

/// The property of [`hip_controller_never_overflows_and_saturates`].
fn hip(g: &[i32; 7], shift: u32, t0: u32, ticks: &[(u16, u16, u16)]) {
    let (shift, t0) = (&shift, &t0);
    let cfg = Config {
        position_band: g[0],
        speed: g[1],
        servo_gain: g[2],
        kp_velocity_q8: g[3],
        ki_velocity_q8: g[4],
        kp_position_q8: g[5],
        ki_position_q8: g[6],
        max_offset_us: (g[0] ^ g[1]) % 1200,
        smoothing_shift: *shift,
    };
    let max = cfg.max_offset_us.clamp(0, 1000);
    let mut c = HipController::new(cfg);
    let mut now = *t0;
    for &(target, measured, dt) in ticks.iter() {
        now = now.wrapping_add(dt as u32);
        let out = c.step(
            HipAngle::wrapping(target),
            HipAngle::wrapping(measured),
            now,
        );
        let off = out.micros() as i32 - 1500;
        assert!(off.abs() <= max, "output {} outside ±{max}", out.micros());
    }
}
