//! The bolter's current sensing (Section 5, Figure 8's asterisks): the side executor ends
//! Descend and DescendEngage when the filtered I_bo reaches the push threshold and Rotate when it
//! reaches the lock threshold, exactly at `I_bo >= threshold`; no current ends any other step;
//! the defaults are spec/control/bolter.toml's and sit between the bolter's idle and absolute
//! limits (spec/modes.toml); and through the library's 50-sample moving average a push ends
//! well inside its timeout while the push's filtered current cannot end the Rotate that follows.

use mmic::bolter::{BolterDirection, BolterSide, BolterStep, Drive, Sensed, SideConfig};
use mmic::command::BolterPair;
use mmic::sensors::adc::{Channel, CODE_MAX};
use mmic::sensors::frontend::{self, Frontend, Raw, WINDOW};
use mmic::wire::b_command::BolterOrder;
use proptest::prelude::*;
use serde::Deserialize;

use crate::common;

const SENSED: [BolterStep; 3] = [
    BolterStep::Descend,
    BolterStep::DescendEngage,
    BolterStep::Rotate,
];
const HOME: [BolterStep; 3] = [
    BolterStep::Retract,
    BolterStep::CounterRotate,
    BolterStep::ReturnHome,
];

fn order(step: BolterStep, direction: BolterDirection) -> Option<BolterOrder> {
    Some(BolterOrder {
        pair: BolterPair::P2,
        direction,
        step,
    })
}

/// A fresh side ordered `step` at 0 ms, then one tick at 10 ms reading `r`.
fn one_tick(
    cfg: &SideConfig,
    step: BolterStep,
    direction: BolterDirection,
    r: Sensed,
) -> BolterSide {
    let mut side = BolterSide::new();
    side.order(1, order(step, direction), 0);
    side.tick(cfg, 10, r);
    side
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Spec {
    current: Current,
    home: Home,
    timeouts: Timeouts,
    attempts: Attempts,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Current {
    push_threshold_ma: u16,
    lock_threshold_ma: u16,
    comparison: String,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Home {
    sensing: String,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Timeouts {
    sensed_ms: u32,
    home_ms: u32,
    link_margin_ms: u32,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Attempts {
    max: u8,
}

#[derive(Deserialize)]
struct Modes {
    thresholds: Thresholds,
}

#[derive(Deserialize)]
struct Thresholds {
    idle: Limits,
    absolute: Limits,
}

#[derive(Deserialize)]
struct Limits {
    bolter: u16,
}

fn spec_text(rel: &str) -> String {
    let p = format!("{}/spec/{rel}", env!("CARGO_MANIFEST_DIR"));
    std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("{p}: {e}"))
}

#[test]
fn bolter_defaults_equal_spec() {
    let spec: Spec = toml::from_str(&spec_text("control/bolter.toml")).unwrap();
    let cfg = mmic::bolter::Config::default();
    let side = cfg.side;
    assert_eq!(
        (side.push_threshold_ma, side.lock_threshold_ma),
        (
            spec.current.push_threshold_ma,
            spec.current.lock_threshold_ma
        )
    );
    assert_eq!(spec.current.comparison, ">=");
    assert_eq!(spec.home.sensing, "switch");
    assert_eq!(
        (side.sensed_ms, side.home_ms, cfg.link_margin_ms),
        (
            spec.timeouts.sensed_ms,
            spec.timeouts.home_ms,
            spec.timeouts.link_margin_ms
        )
    );
    assert_eq!(cfg.max_attempts, spec.attempts.max);
    // Board B runs the same executor with the same defaults.
    assert_eq!(mmic::node::robot::board_b::Config::default().bolter, side);
    assert_eq!(mmic::node::robot::board_a::Config::default().bolter, cfg);

    // Both thresholds lie strictly between the bolter's idle limit and its absolute limit, as
    // spec/modes.toml states them and as the fault detectors use them: a push or a lock is
    // detected before the absolute limit's overcurrent fault could fire.
    let modes: Modes = toml::from_str(&spec_text("modes.toml")).unwrap();
    let limits = mmic::safety::detect::Config::default();
    let (idle, absolute) = (
        modes.thresholds.idle.bolter,
        modes.thresholds.absolute.bolter,
    );
    assert_eq!(
        (idle, absolute),
        (limits.idle.bolter, limits.absolute.bolter)
    );
    for t in [side.push_threshold_ma, side.lock_threshold_ma] {
        assert!(
            idle < t && t < absolute,
            "{t} mA outside ({idle}, {absolute})"
        );
    }
    // The lock threshold is above what the moving average carries over from a push that just
    // ended: at most one sample's share of the largest step a current below the absolute limit
    // can make, past the push threshold.
    let carry = side.push_threshold_ma + absolute / WINDOW as u16;
    assert!(
        side.lock_threshold_ma > carry,
        "lock {} mA, push carry-over up to {carry} mA",
        side.lock_threshold_ma
    );
}

// req: P5.11, P5.12
#[test]
fn each_sensed_step_ends_at_its_own_threshold_and_not_one_ma_below() {
    let cfg = SideConfig::default();
    let (push, lock) = (cfg.push_threshold_ma, cfg.lock_threshold_ma);
    for direction in [BolterDirection::Bolt, BolterDirection::Unbolt] {
        for step in SENSED {
            let t = cfg.threshold(step).unwrap();
            assert_eq!(
                t,
                if step == BolterStep::Rotate {
                    lock
                } else {
                    push
                }
            );
            for (i_bo, ends) in [
                (0, false),
                (t - 1, false),
                (t, true),
                (t + 1, true),
                (u16::MAX, true),
            ] {
                let side = one_tick(
                    &cfg,
                    step,
                    direction,
                    Sensed {
                        i_bo,
                        at_home: false,
                    },
                );
                let aux = side.aux();
                let flag = if step == BolterStep::Rotate {
                    aux.locked
                } else {
                    aux.threshold_reached
                };
                assert_eq!(flag, ends, "{step:?} {direction:?} at {i_bo} mA");
                assert_eq!(side.drive() == Drive::Idle, ends, "{step:?} at {i_bo} mA");
                assert!(!aux.timed_out);
            }
        }
        // Rotate is not ended by a current that only passes the push threshold (a push's
        // leftover), and the home switch ends no current-sensed step.
        let side = one_tick(
            &cfg,
            BolterStep::Rotate,
            direction,
            Sensed {
                i_bo: lock - 1,
                at_home: true,
            },
        );
        assert_eq!(side.drive(), Drive::Rotate);
        assert!(!side.aux().threshold_reached && !side.aux().locked);
    }
}

// req: P5.11
#[test]
fn a_current_spike_outside_a_sensed_step_ends_nothing() {
    let cfg = SideConfig::default();
    let spike = Sensed {
        i_bo: u16::MAX,
        at_home: false,
    };
    for step in HOME {
        assert_eq!(cfg.threshold(step), None);
        let mut side = one_tick(&cfg, step, BolterDirection::Bolt, spike);
        let running = side.drive();
        assert_ne!(running, Drive::Idle, "{step:?} ended on a current spike");
        let aux = side.aux();
        assert!(
            !aux.threshold_reached && !aux.locked && !aux.at_home,
            "{aux:?}"
        );
        // It still ends on the home switch, and still times out without it.
        side.tick(
            &cfg,
            20,
            Sensed {
                i_bo: u16::MAX,
                at_home: true,
            },
        );
        assert_eq!(side.drive(), Drive::Idle);
        assert!(side.aux().at_home && !side.aux().timed_out);
        let mut side = one_tick(&cfg, step, BolterDirection::Bolt, spike);
        side.tick(&cfg, cfg.home_ms + 11, spike);
        assert!(side.aux().timed_out, "{step:?} spike instead of timeout");
    }
    // Idle: a spike latches nothing, so the next order starts clean anyway.
    let mut side = BolterSide::new();
    side.tick(&cfg, 10, spike);
    assert_eq!(side.aux(), BolterSide::new().aux());
    // A spike after a sensed step ended (the other side still running) changes nothing either.
    let mut side = one_tick(
        &cfg,
        BolterStep::Descend,
        BolterDirection::Bolt,
        Sensed {
            i_bo: cfg.push_threshold_ma,
            at_home: false,
        },
    );
    let done = side.aux();
    side.tick(&cfg, 20, spike);
    assert_eq!(side.aux(), done);
    assert_eq!(side.drive(), Drive::Idle);
}

fn step_strategy() -> impl Strategy<Value = BolterStep> {
    prop::sample::select(BolterStep::ALL.to_vec())
}

proptest! {
    #![proptest_config(common::prop::config(2048))]

    /// For any thresholds, any step and any current: one tick ends a current-sensed step iff
    /// `i_bo >= threshold(step)`, and never ends another (without the home switch). The
    /// current is drawn near the thresholds half of the time.
    // req: P5.12
    #[test]
    fn the_decision_is_exactly_i_bo_at_least_the_threshold(
        push in any::<u16>(),
        lock in any::<u16>(),
        step in step_strategy(),
        unbolt in any::<bool>(),
        near in any::<bool>(),
        delta in -2i32..=2,
        raw in any::<u16>(),
    ) {
        let cfg = SideConfig { push_threshold_ma: push, lock_threshold_ma: lock, ..SideConfig::default() };
        let t = cfg.threshold(step);
        let i_bo = match (near, t) {
            (true, Some(t)) => (t as i32 + delta).clamp(0, u16::MAX as i32) as u16,
            _ => raw,
        };
        let direction = if unbolt { BolterDirection::Unbolt } else { BolterDirection::Bolt };
        let side = one_tick(&cfg, step, direction, Sensed { i_bo, at_home: false });
        let aux = side.aux();
        let expected = t.is_some_and(|t| i_bo >= t);
        let latched = aux.threshold_reached || aux.locked;
        prop_assert_eq!(latched, expected);
        prop_assert_eq!(aux.locked, expected && step == BolterStep::Rotate);
        let terminal = matches!(step, BolterStep::Done | BolterStep::Failed);
        prop_assert_eq!(side.drive() == Drive::Idle, expected || terminal);
    }
}

/// A side through the library's front end: the plant's currents (mA) become ADS7828 codes, the
/// 50-sample moving average filters them, and the executor decides on the result, one tick per
/// 10 ms. Returns the filtered I_bo.
struct FilteredSide {
    frontend: Frontend<WINDOW>,
    side: BolterSide,
}

impl FilteredSide {
    fn new() -> FilteredSide {
        let mut s = FilteredSide {
            frontend: Frontend::new(frontend::Config::default()),
            side: BolterSide::new(),
        };
        // At rest long enough to fill the window.
        for _ in 0..WINDOW {
            s.push(IDLE_MA);
        }
        s
    }

    fn push(&mut self, ma: u16) -> u16 {
        let fs = frontend::Config::default().scaling.full_scale[Channel::IBo as usize] as u32;
        let mut adc = [0u16; 8];
        adc[Channel::IBo as usize] = ((ma as u32 * CODE_MAX as u32 + fs / 2) / fs) as u16;
        self.frontend
            .push(&Raw {
                adc: Some(adc),
                accel: None,
                encoder: None,
            })
            .electrical
            .i_bo
    }

    /// Runs `step` from `t0` until it ends or times out; `plant(ms into the step)` is the
    /// current drawn while the motor is driven (the idle current once the step has ended).
    /// Returns how long the step ran and whether it timed out.
    fn run(
        &mut self,
        cfg: &SideConfig,
        t0: u32,
        step: BolterStep,
        plant: impl Fn(u32) -> u16,
    ) -> (u32, bool) {
        self.side
            .order(t0 as u8, order(step, BolterDirection::Bolt), t0);
        let mut t = 0;
        loop {
            t += 10;
            let ma = if self.side.drive() == Drive::Idle {
                IDLE_MA
            } else {
                plant(t)
            };
            let i_bo = self.push(ma);
            self.side.tick(
                cfg,
                t0 + t,
                Sensed {
                    i_bo,
                    at_home: false,
                },
            );
            if self.side.drive() == Drive::Idle {
                return (t, self.side.aux().timed_out);
            }
        }
    }
}

const IDLE_MA: u16 = 40;
const RUNNING_MA: u16 = 450;
/// The bolter's travel to its fastener and the head's rotation until the fastener locks, as in
/// the host simulator's plant.
const TRAVEL_MS: u32 = 800;
const ROTATE_MS: u32 = 1000;

#[test]
fn through_the_moving_average_a_push_ends_well_inside_its_timeout_and_never_ends_rotate() {
    let cfg = SideConfig::default();
    let absolute = mmic::safety::detect::Config::default().absolute.bolter;
    // The simulator's pushing and stall currents, and the largest below the overcurrent limit.
    for (pushing, stalled) in [(1350, 1600), (absolute, absolute)] {
        for locks in [true, false] {
            let mut s = FilteredSide::new();
            let (descend, timed_out) = s.run(&cfg, 0, BolterStep::DescendEngage, |t| {
                if t > TRAVEL_MS {
                    pushing
                } else {
                    RUNNING_MA
                }
            });
            assert!(!timed_out, "push at {pushing} mA timed out");
            let lag = descend - TRAVEL_MS;
            assert!(
                lag <= 10 * WINDOW as u32 && descend < cfg.sensed_ms / 2,
                "push at {pushing} mA ended {lag} ms after contact ({descend} ms in all)"
            );
            // Rotate ordered at once (the worst case: no handshake delay for the push's
            // filtered current to decay).
            let (rotate, timed_out) = s.run(&cfg, descend, BolterStep::Rotate, |t| {
                if locks && t > ROTATE_MS {
                    stalled
                } else {
                    RUNNING_MA
                }
            });
            if locks {
                assert!(!timed_out);
                assert!(
                    rotate > ROTATE_MS && rotate - ROTATE_MS <= 10 * WINDOW as u32,
                    "lock at {stalled} mA: Rotate ran {rotate} ms"
                );
            } else {
                assert!(
                    timed_out && rotate > cfg.sensed_ms,
                    "a fastener that never locks: Rotate ran {rotate} ms, timed out {timed_out}"
                );
            }
            println!(
                "push {pushing} mA: Descend ended {lag} ms after contact; lock {stalled} mA \
                 (locks {locks}): Rotate ran {rotate} ms"
            );
        }
    }
}
