//! The hip PI controller never overflows (debug builds and cargo bolero's fuzz profile check
//! every arithmetic operation) and its output always lies within the configured range around
//! the stop pulse, for arbitrary gains, targets, readings and tick times (clock wrap included).
//! Random under `cargo test`, Kani-ready (`cargo kani --tests`: a proof over 6 ticks).

use mmic::control::hip::{Config, HipController};
use mmic::units::HipAngle;

const TICKS: usize = 6;

#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(8))]
fn hip_controller_never_overflows_and_saturates() {
    bolero::check!()
        .with_type::<([i32; 7], u32, u32, [(u16, u16, u16); TICKS])>()
        .for_each(|(g, shift, t0, ticks)| {
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
        });
}
