//! Sensor processing: the moving average equals the naive mean for every window content
//! (including before the window is full); ADC scaling is monotone, exact at the ends and within
//! half a unit of the real value; the IMU picks the dominant axis; the encoder maps onto the
//! hip angle range; the front end equals scaling the naive mean of each channel and the
//! gravity of the naive mean of each acceleration (signed, over the ticks that had an IMU
//! sample).

use mmic::sensors::adc::{electrical, scale, Channel, Scaling, CODE_MAX};
use mmic::sensors::encoder::hip_angle;
use mmic::sensors::frontend::{self, Frontend, Raw};
use mmic::sensors::imu::gravity;
use mmic::sensors::MovingAverage;
use mmic::units::Sign;
use proptest::prelude::*;

use crate::common;

fn naive(samples: &[u16], n: usize) -> Option<u16> {
    let w = &samples[samples.len().saturating_sub(n)..];
    if w.is_empty() {
        None
    } else {
        Some((w.iter().map(|&x| x as u64).sum::<u64>() / w.len() as u64) as u16)
    }
}

/// Floor of the mean of signed samples, as the front end computes it (offset by 32768).
fn naive_signed(samples: &[i16], n: usize) -> Option<i16> {
    let u: Vec<u16> = samples.iter().map(|&a| (a as i32 + 32768) as u16).collect();
    naive(&u, n).map(|m| (m as i32 - 32768) as i16)
}

proptest! {
    #![proptest_config(common::prop::config(256))]
    // req: P2.10
    #[test]
    fn frontend_equals_scaling_the_naive_means(
        ticks in prop::collection::vec((
            prop::option::weighted(0.9, any::<[u16; 8]>()),
            prop::option::of(any::<[i16; 3]>()),
            prop::option::weighted(0.9, any::<u16>()),
        ), 1..120),
        zero in any::<u16>(),
    ) {
        // Never lost (loss_ticks at its maximum): missing readings only leave the averages;
        // what loss does is the harness `frontend_stays_in_range_…` and the unit tests.
        let cfg = frontend::Config {
            scaling: Scaling::default(),
            encoder_zero: zero,
            hip_encoder: true,
            loss_ticks: u16::MAX,
        };
        let mut f = Frontend::<50>::new(cfg);
        for i in 0..ticks.len() {
            let (adc, accel, enc) = ticks[i];
            let out = f.push(&Raw { adc, accel, encoder: enc });
            let codes: [u16; 8] = core::array::from_fn(|ch| {
                let col: Vec<u16> = ticks[..=i].iter().filter_map(|t| t.0).map(|c| c[ch]).collect();
                naive(&col, 50).unwrap_or(0)
            });
            prop_assert_eq!(out.electrical, electrical(&Scaling::default(), codes));
            let seen: Vec<[i16; 3]> = ticks[..=i].iter().filter_map(|t| t.1).collect();
            let want = if seen.is_empty() {
                None
            } else {
                let axis = |k: usize| {
                    let col: Vec<i16> = seen.iter().map(|a| a[k]).collect();
                    naive_signed(&col, 50).unwrap_or(0)
                };
                gravity([axis(0), axis(1), axis(2)])
            };
            prop_assert_eq!(out.gravity, want);
            prop_assert_eq!(out.hip, enc.map(|e| hip_angle(e, zero)));
        }
    }

    // req: P2.10
    #[test]
    fn moving_average_equals_the_naive_mean(samples in prop::collection::vec(any::<u16>(), 0..200)) {
        let mut f = MovingAverage::<50>::new();
        prop_assert_eq!(f.mean(), None);
        for i in 0..samples.len() {
            f.push(samples[i]);
            prop_assert_eq!(f.mean(), naive(&samples[..=i], 50));
            prop_assert_eq!(f.len(), (i + 1).min(50));
        }
    }

    // req: P2.5
    #[test]
    fn imu_picks_the_largest_axis(a in any::<[i16; 3]>()) {
        match gravity(a) {
            None => prop_assert_eq!(a, [0, 0, 0]),
            Some(g) => {
                let i = g.axis as usize;
                let m = a[i].unsigned_abs();
                prop_assert!(a.iter().all(|x| x.unsigned_abs() <= m));
                prop_assert_eq!(g.sign == Sign::Positive, a[i] > 0);
            }
        }
    }
}

// req: P2.10
#[test]
fn moving_average_extremes_and_small_windows() {
    // Every window content of a 3-sample filter over the values {0, 1, 65534, 65535}, every
    // order: 4^6 sequences of length 6.
    let vals = [0u16, 1, 65534, 65535];
    for code in 0..4usize.pow(6) {
        let seq: Vec<u16> = (0..6).map(|k| vals[(code / 4usize.pow(k)) % 4]).collect();
        let mut f = MovingAverage::<3>::new();
        for i in 0..seq.len() {
            f.push(seq[i]);
            assert_eq!(f.mean(), naive(&seq[..=i], 3), "{seq:?} at {i}");
        }
    }
    let mut f = MovingAverage::<50>::new();
    for _ in 0..1000 {
        f.push(u16::MAX);
    }
    assert_eq!(f.mean(), Some(u16::MAX));
}

// req: P2.6
#[test]
fn adc_scaling_is_monotone_exact_at_the_ends_and_rounded() {
    let s = Scaling::default();
    for ch in Channel::ALL {
        let fs = s.full_scale[ch as usize] as f64;
        let mut prev = 0;
        for code in 0..=CODE_MAX + 10 {
            let v = scale(&s, ch, code);
            assert!(v >= prev, "{ch:?} not monotone at {code}");
            prev = v;
            let exact = code.min(CODE_MAX) as f64 * fs / CODE_MAX as f64;
            assert!(
                (v as f64 - exact).abs() <= 0.5,
                "{ch:?} code {code}: {v} vs {exact}"
            );
        }
        assert_eq!(scale(&s, ch, 0), 0);
        assert_eq!(scale(&s, ch, CODE_MAX), s.full_scale[ch as usize]);
    }
    let e = electrical(&s, [2730, 4095, 0, 0, 0, 3071, 0, 1234]);
    assert_eq!((e.v_bat, e.i_bat, e.v_reg), (10_000, 10_000, 7_499)); // 3071 × 10000 / 4095 = 7499.4
}

// req: P2.9
#[test]
fn encoder_covers_the_turn() {
    let mut prev = None;
    for raw in 0..4096u16 {
        let a = hip_angle(raw, 0).centidegrees();
        assert!(a < 36000);
        if let Some(p) = prev {
            assert!(a > p, "monotone within the turn at {raw}");
        }
        prev = Some(a);
        // An offset rotates the scale.
        assert_eq!(hip_angle(raw, raw).centidegrees(), 0);
    }
    assert_eq!(hip_angle(1024, 0).centidegrees(), 9000);
    assert_eq!(hip_angle(4095, 0).centidegrees(), 35991);
}

// req: P2.6, P2.10
#[test]
fn adc_scaling_equals_spec() {
    #[derive(serde::Deserialize)]
    struct Spec {
        channel: Vec<Ch>,
        filter: toml::Value,
        encoder: toml::Value,
    }
    #[derive(serde::Deserialize)]
    struct Ch {
        ch: usize,
        full_scale: u16,
    }
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/spec/control/adc.toml"
    ))
    .unwrap();
    let spec: Spec = toml::from_str(&text).unwrap();
    let s = Scaling::default();
    assert_eq!(spec.channel.len(), 8);
    for c in &spec.channel {
        assert_eq!(s.full_scale[c.ch], c.full_scale, "CH{}", c.ch);
        assert_eq!(Channel::ALL[c.ch] as usize, c.ch);
    }
    assert_eq!(spec.filter["window"].as_integer(), Some(50));
    assert_eq!(
        spec.encoder["counts_per_turn"].as_integer(),
        Some(mmic::sensors::encoder::COUNTS as i64)
    );
}
