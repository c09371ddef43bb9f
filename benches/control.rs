//! One step of each Section 5 piece. Run: `cargo bench -p mmic-benches --bench control`.

use criterion::{criterion_group, criterion_main, Criterion};
use mmic::bolter::{BolterDirection, BolterSide, Config, Coordinator, Job, Sensed};
use mmic::command::{BolterPair, Fasteners};
use mmic::control::hip::{Config as HipConfig, HipController};
use mmic::control::interp::{Interpolator, Rate};
use mmic::sensors::adc::{electrical, Scaling};
use mmic::sensors::imu::gravity;
use mmic::sensors::MovingAverage;
use mmic::units::{HipAngle, PulseWidth};
use std::hint::black_box;
use std::time::Duration;

fn pieces(c: &mut Criterion) {
    let mut g = c.benchmark_group("control step");
    let mut f = MovingAverage::<50>::new();
    let mut x = 0u16;
    g.bench_function("moving average push+mean (50)", |b| {
        b.iter(|| {
            x = x.wrapping_add(7);
            f.push(black_box(x));
            f.mean()
        })
    });
    let s = Scaling::default();
    g.bench_function("ADS7828 scaling, 8 channels", |b| {
        b.iter(|| electrical(&s, black_box([2900, 800, 400, 100, 50, 3030, 1200, 0])))
    });
    g.bench_function("IMU gravity", |b| {
        b.iter(|| gravity(black_box([30, -16000, 200])))
    });
    let mut hip = HipController::new(HipConfig::default());
    let mut t = 0u32;
    g.bench_function("hip PI step", |b| {
        b.iter(|| {
            t = t.wrapping_add(10);
            hip.step(
                black_box(HipAngle::new(9000).unwrap()),
                black_box(HipAngle::new((t / 10 % 36000) as u16).unwrap()),
                t,
            )
        })
    });
    let mut i = Interpolator::new(PulseWidth::MIN, Rate::default());
    g.bench_function("interpolator tick", |b| {
        b.iter(|| {
            t = t.wrapping_add(10);
            if i.done() {
                let next = if i.now() == PulseWidth::MIN {
                    PulseWidth::MAX
                } else {
                    PulseWidth::MIN
                };
                i.set_target(next, t);
            }
            i.tick(black_box(t))
        })
    });
    let cfg = Config::default();
    let mut coord = Coordinator::new();
    coord.start(
        Job {
            direction: BolterDirection::Bolt,
            fasteners: Fasteners::All,
        },
        0,
    );
    let mut side = BolterSide::new();
    g.bench_function("bolter coordinator + side executor", |b| {
        b.iter(|| {
            t = t.wrapping_add(10);
            let aux = side.aux();
            let out = coord.step(&cfg, t, &aux, Some(&aux));
            if let Some((seq, o)) = out.order {
                side.order(seq, Some(o), t);
            }
            side.tick(
                &cfg.side,
                t,
                Sensed {
                    i_bo: cfg.side.lock_threshold_ma.max(cfg.side.push_threshold_ma),
                    at_home: true,
                },
            );
            if coord.status() != mmic::bolter::Status::Running {
                coord.start(
                    Job {
                        direction: BolterDirection::Bolt,
                        fasteners: Fasteners::Pair(BolterPair::P1),
                    },
                    t,
                );
            }
        })
    });
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().measurement_time(Duration::from_secs(2)).warm_up_time(Duration::from_millis(500)).sample_size(30);
    targets = pieces
}
criterion_main!(benches);
