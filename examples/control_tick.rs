//! One control tick of Section 5's parts, as board A's loop would run it: push the eight ADC
//! channels through their 50-sample moving averages and scale them, read gravity and the hip
//! encoder, step the hip PI controller, the arm and gripper interpolators and the bolter
//! coordinator with side A's executor. Used to count instructions per tick:
//!
//! ```sh
//! cargo build --release --example control_tick
//! valgrind --tool=callgrind --callgrind-out-file=/dev/null target/release/examples/control_tick 1
//! valgrind --tool=callgrind --callgrind-out-file=/dev/null target/release/examples/control_tick 10001
//! # instructions per tick = (total of the second − total of the first) / 10000
//! ```

use mmic::bolter::{BolterDirection, BolterSide, Config as BolterConfig, Coordinator, Job, Sensed};
use mmic::command::{BolterPair, Fasteners};
use mmic::control::hip::{Config as HipConfig, HipController};
use mmic::control::interp::{Interpolator, Rate};
use mmic::sensors::adc::{electrical, Scaling};
use mmic::sensors::encoder::hip_angle;
use mmic::sensors::imu::gravity;
use mmic::sensors::MovingAverage;
use mmic::units::{HipAngle, PulseWidth};
use std::hint::black_box;

struct Loop {
    filters: [MovingAverage<50>; 8],
    scaling: Scaling,
    hip: HipController,
    servos: [Interpolator; 2],
    coord: Coordinator,
    side: BolterSide,
    bolter_cfg: BolterConfig,
}

impl Loop {
    fn new() -> Loop {
        let mut coord = Coordinator::new();
        coord.start(
            Job {
                direction: BolterDirection::Bolt,
                fasteners: Fasteners::Pair(BolterPair::P1),
            },
            0,
        );
        let mut servos = [Interpolator::new(PulseWidth::MIN, Rate::default()); 2];
        for s in &mut servos {
            s.set_target(PulseWidth::MAX, 0);
        }
        Loop {
            filters: core::array::from_fn(|_| MovingAverage::new()),
            scaling: Scaling::default(),
            hip: HipController::new(HipConfig::default()),
            servos,
            coord,
            side: BolterSide::new(),
            bolter_cfg: BolterConfig::default(),
        }
    }

    #[inline(never)]
    fn tick(&mut self, now: u32, raw: [u16; 8], accel: [i16; 3], encoder: u16) -> u32 {
        let mut codes = [0u16; 8];
        for (i, f) in self.filters.iter_mut().enumerate() {
            f.push(raw[i]);
            codes[i] = f.mean().unwrap_or(0);
        }
        let e = electrical(&self.scaling, codes);
        let g = gravity(accel);
        let angle = hip_angle(encoder, 0);
        let hip_out = self
            .hip
            .step(HipAngle::new(9000).unwrap_or(HipAngle::ZERO), angle, now);
        let mut pw = 0u32;
        for s in &mut self.servos {
            pw += s.tick(now).micros() as u32;
        }
        let aux = self.side.aux();
        let out = self.coord.step(&self.bolter_cfg, now, &aux, Some(&aux));
        if let Some((seq, order)) = out.order {
            self.side.order(seq, Some(order), now);
        }
        self.side.tick(
            &self.bolter_cfg.side,
            now,
            Sensed {
                i_bo: e.i_bo,
                at_home: false,
            },
        );
        pw + hip_out.micros() as u32 + e.v_bat as u32 + g.map_or(0, |g| g.axis as u32)
    }
}

fn main() {
    let n: u32 = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(1000);
    let mut l = Loop::new();
    let mut acc = 0u32;
    for t in 0..n {
        let raw = [
            2900,
            800 + (t % 7) as u16,
            400,
            100,
            50,
            3030,
            1200 + (t % 500) as u16,
            0,
        ];
        acc = acc.wrapping_add(l.tick(
            black_box(t * 10),
            black_box(raw),
            black_box([30, -16000, 200]),
            black_box((t % 4096) as u16),
        ));
    }
    println!("{n} ticks, checksum {acc}");
}
