//! Bolting statistics: a fastener model with the per-attempt success rates implied by the
//! paper's ground demo (2,524 fastener pairs: 2,307 bolted at the first attempt, 103 at the
//! second, 28 at the third, 86 failed) drives the real coordinator and both sides' executors
//! over 25,240 pairs. The attempt histogram must match Figure 10's percentages within four
//! binomial standard deviations per bin, and every failed pair must end in the (un)bolting
//! failure fault, which takes an Operational robot to Standby.

use mmic::bolter::{
    BolterDirection, BolterSide, BolterStep, Config, Coordinator, Job, Sensed, Status,
};
use mmic::command::{BolterPair, Command, Fasteners};
use mmic::faults::{Fault, Faults};
use mmic::mode::Mode;
use mmic::safety::supervisor::{Incoming, Input, Supervisor};

/// splitmix64: a small, seeded, reproducible generator.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
}

const DEMO: [u32; 4] = [2307, 103, 28, 86];

/// A moving bolter's filtered current, mA: under both thresholds.
const RUNNING_MA: u16 = 450;
/// A bolter pushing its fastener: over the push threshold, under the lock threshold.
const PUSHING_MA: u16 = 1100;
/// A head stalled on a locked (released) fastener: over the lock threshold, under the 2000 mA
/// overcurrent limit.
const STALLED_MA: u16 = 1600;

/// What a side's sensors read `t` ms into `step`: the bolter meets its fastener (descents) or
/// the fastener locks (Rotate, only if `lock`) or the bolter is home (the other steps) after
/// `after` ms; the current runs at [`RUNNING_MA`] before that.
fn readings(step: BolterStep, t: u32, after: u32, lock: bool) -> Sensed {
    let i_bo = match step {
        BolterStep::Descend | BolterStep::DescendEngage if t >= after => PUSHING_MA,
        BolterStep::Rotate if lock && t >= after => STALLED_MA,
        _ => RUNNING_MA,
    };
    let at_home = !matches!(
        step,
        BolterStep::Descend | BolterStep::DescendEngage | BolterStep::Rotate
    ) && t >= after;
    Sensed { i_bo, at_home }
}

/// Runs one pair; `succeeds[k]` says whether attempt k+1 locks. Returns (attempts, status).
fn run_pair(cfg: &Config, succeeds: [bool; 3]) -> (u8, Status) {
    let mut coord = Coordinator::new();
    let (mut a, mut b) = (BolterSide::new(), BolterSide::new());
    coord.start(
        Job {
            direction: BolterDirection::Bolt,
            fasteners: Fasteners::Pair(BolterPair::P1),
        },
        0,
    );
    let mut step_since = 0u32;
    let mut last_order = None;
    let mut attempts = 1;
    for tick in 0..10_000u32 {
        let now = tick * 10;
        let out = coord.step(cfg, now, &a.aux(), Some(&b.aux()));
        match out.status {
            Status::Running => {}
            s => return (attempts, s),
        }
        attempts = coord.attempt();
        let (seq, order) = out.order.expect("running");
        if last_order != Some(seq) {
            last_order = Some(seq);
            step_since = now;
        }
        a.order(seq, Some(order), now);
        b.order(seq, Some(order), now);
        let t = now - step_since;
        let lock = succeeds[(coord.attempt() - 1) as usize];
        let after = if order.step == BolterStep::Rotate {
            200
        } else {
            100
        };
        let sig = readings(order.step, t, after, lock);
        a.tick(&cfg.side, now, sig);
        b.tick(&cfg.side, now, sig);
    }
    panic!("pair never finished");
}

#[test]
fn attempt_histogram_matches_figure_10() {
    let total: u32 = DEMO.iter().sum();
    assert_eq!(total, 2524);
    // Conditional success probabilities implied by the demo.
    let p1 = DEMO[0] as f64 / total as f64;
    let p2 = DEMO[1] as f64 / (total - DEMO[0]) as f64;
    let p3 = DEMO[2] as f64 / (total - DEMO[0] - DEMO[1]) as f64;
    let cfg = Config::default();
    // The model's currents sit where the plant's do: running under both thresholds, pushing
    // between them, stalled over the lock threshold and under the overcurrent limit.
    let limit = mmic::safety::detect::Config::default().absolute.bolter;
    assert!(RUNNING_MA < cfg.side.push_threshold_ma);
    assert!((cfg.side.push_threshold_ma..cfg.side.lock_threshold_ma).contains(&PUSHING_MA));
    assert!((cfg.side.lock_threshold_ma..=limit).contains(&STALLED_MA));
    let mut rng = Rng(0x4d4d_4943_2d49);
    let n = 25_240u32;
    let mut hist = [0u32; 4];
    for _ in 0..n {
        let succeeds = [rng.next() < p1, rng.next() < p2, rng.next() < p3];
        let (attempts, status) = run_pair(&cfg, succeeds);
        let first = succeeds.iter().position(|&s| s);
        match (first, status) {
            (Some(k), Status::Done) => {
                assert_eq!(attempts as usize, k + 1);
                hist[k] += 1;
            }
            (None, Status::Failed(Fault::BoltingFailure)) => {
                assert_eq!(attempts, 3);
                hist[3] += 1;
            }
            other => panic!("model and state machine disagree: {other:?}"),
        }
    }
    println!(
        "bolting statistics over {n} pairs: first {} second {} third {} failed {}",
        hist[0], hist[1], hist[2], hist[3]
    );
    for (bin, (&got, &demo)) in hist.iter().zip(DEMO.iter()).enumerate() {
        let p = demo as f64 / total as f64;
        let sigma = (n as f64 * p * (1.0 - p)).sqrt();
        let expected = n as f64 * p;
        println!(
            "  bin {bin}: {:.2}% (Figure 10: {:.2}%), {:.1} sigma",
            100.0 * got as f64 / n as f64,
            100.0 * p,
            (got as f64 - expected) / sigma
        );
        assert!(
            (got as f64 - expected).abs() <= 4.0 * sigma,
            "bin {bin}: {got} vs {expected:.0} ± {:.0}",
            4.0 * sigma
        );
    }
}

#[test]
fn a_failed_pair_takes_an_operational_robot_to_standby() {
    let (attempts, status) = run_pair(&Config::default(), [false; 3]);
    assert_eq!(
        (attempts, status),
        (3, Status::Failed(Fault::BoltingFailure))
    );
    let mut s = Supervisor::new();
    s.step(&Input {
        command: Some(Incoming::Command(Command::Mode(Mode::Operational))),
        ..Input::quiet()
    });
    let out = s.step(&Input {
        faults: Faults::EMPTY.with(Fault::BoltingFailure),
        ..Input::quiet()
    });
    assert_eq!(out.mode, Mode::Standby);
    assert!(out.faults.contains(Fault::BoltingFailure));
}

#[test]
fn all_four_stops_at_the_first_failing_pair() {
    let cfg = Config::default();
    let mut coord = Coordinator::new();
    let (mut a, mut b) = (BolterSide::new(), BolterSide::new());
    coord.start(
        Job {
            direction: BolterDirection::Unbolt,
            fasteners: Fasteners::All,
        },
        0,
    );
    let mut pairs_seen = vec![];
    let mut since = (0u8, 0u32);
    for tick in 0..100_000u32 {
        let now = tick * 10;
        let out = coord.step(&cfg, now, &a.aux(), Some(&b.aux()));
        if out.status != Status::Running {
            assert_eq!(out.status, Status::Failed(Fault::BoltingFailure));
            assert_eq!(pairs_seen, [1, 2, 3], "stopped at pair 3, never ran pair 4");
            return;
        }
        let (seq, order) = out.order.unwrap();
        if pairs_seen.last() != Some(&order.pair.number()) {
            pairs_seen.push(order.pair.number());
        }
        if since.0 != seq {
            since = (seq, now);
        }
        a.order(seq, Some(order), now);
        b.order(seq, Some(order), now);
        let t = now - since.1;
        // Pair 3 never releases.
        let lock = order.pair != BolterPair::P3;
        let sig = readings(order.step, t, 50, lock);
        a.tick(&cfg.side, now, sig);
        b.tick(&cfg.side, now, sig);
    }
    panic!("job never ended");
}
