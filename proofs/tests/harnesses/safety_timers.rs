//! The fault timers over arbitrary time sequences, including the wrap of the u32 millisecond
//! clock: each harness compares the detector with a direct computation on 64-bit absolute time.
//! Under `cargo test`: random inputs; `cargo bolero test`: fuzzing; `cargo kani --tests`: a
//! proof over all inputs of the fixed length (8 samples; 12 events for comm loss).

use mmic::safety::detect::{CommMonitor, Config, LowBattery};

const SAMPLES: usize = 8;
/// Events of the comm-loss harness: enough for the ten unacknowledged sends.
#[cfg(not(kani))]
const COMM_EVENTS: usize = 32;
#[cfg(kani)]
const COMM_EVENTS: usize = 12;

/// Low battery fires at a sample iff the voltage has been below 10.0 V at every sample of a run
/// ending there whose span is more than 500 ms; the clock may start anywhere, wrap included.
///
/// Under `cargo test` (see proofs/README.md, the ledger): exhaustively, every run of 4 samples
/// whose steps are 0, 1, 250, 499, 500 or 501 ms and whose voltages are each of the four
/// below/not-below pairs, from 4 clock starts (0, and 499, 250 and 0 ms before the u32 wrap):
/// the spans those steps add up to include 499, 500 and 501 ms (the threshold ±1) inside one
/// run, across the wrap, and a run broken at every position; then sampled inputs of the full
/// type.
// req: P7.11, T8/low_battery
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(10))]
fn low_battery_fires_exactly_after_half_a_second() {
    #[cfg(not(any(kani, fuzzing)))]
    {
        const DT: [u16; 6] = [0, 1, 250, 499, 500, 501];
        const LOW: [(bool, bool); 4] = [(false, false), (true, false), (false, true), (true, true)];
        const START: [u32; 4] = [0, u32::MAX - 499, u32::MAX - 250, u32::MAX];
        crate::ledger::exhaustive(
            "low_battery_fires_exactly_after_half_a_second",
            4 * 24u64.pow(4),
            (
                0usize..4,
                crate::ledger::seq::<_, 4>((0usize..6, 0usize..4)),
            ),
            |(start, run)| {
                let samples = run.map(|(dt, low)| (DT[dt], LOW[low].0, LOW[low].1));
                low_battery(START[*start], &samples);
            },
        );
        crate::ledger::sampled::<(u32, [(u16, bool, bool); SAMPLES])>(
            "low_battery_fires_exactly_after_half_a_second",
            500_000,
            |(start, samples)| low_battery(*start, samples),
        );
        return;
    }
    #[allow(unreachable_code)]
    bolero::check!()
        .with_type::<(u32, [(u16, bool, bool); SAMPLES])>()
        .for_each(|(start, samples)| low_battery(*start, samples));
}

/// The property of [`low_battery_fires_exactly_after_half_a_second`] for one run.
fn low_battery(start: u32, samples: &[(u16, bool, bool)]) {
    let cfg = Config::default();
    let mut lb = LowBattery::default();
    let mut abs: u64 = start as u64;
    let mut run_start: Option<u64> = None;
    for (i, &(dt, low_a, low_b)) in samples.iter().enumerate() {
        if i > 0 {
            abs += dt as u64;
        }
        let now = abs as u32; // the wrapping clock the robot sees
        let (va, vb) = (
            if low_a { 9_999 } else { 10_000 },
            if low_b { 9_999 } else { 12_600 },
        );
        let below = low_a || low_b;
        run_start = if below {
            Some(run_start.unwrap_or(abs))
        } else {
            None
        };
        let expected = run_start.is_some_and(|s| abs - s > 500);
        assert_eq!(lb.update(&cfg, now, va, Some(vb)), expected, "sample {i}");
    }
}

/// Comm loss fires iff B has been silent for more than the timeout (counting from the first
/// tick) or a command B has not acknowledged has been sent ten times (resends of the number
/// B last echoed are refreshes and do not count).
///
/// Under `cargo test`: exhaustively, (timing) every sequence of 6 events over 11 letters — a
/// tick after 0, 1, 250, 499, 500 or 501 ms (silences of 500 and 501 ms, the threshold and one
/// past, arise within a run), a heartbeat echoing 0 or 1 at once, one echoing 0 after 501 ms,
/// a send of 0 or of 1 — from the clock's 0 and from 250 ms before the u32 wrap; (counting)
/// every sequence of 12 events over a send of 0, a send of 1 and a heartbeat echoing 0: ten
/// sends of an unacknowledged number with every interleaving of refreshes and
/// acknowledgements (1 is symmetric to 0); then sampled inputs.
// req: P7.19, T8/internal_comm_loss
#[test]
#[cfg_attr(kani, kani::proof, kani::unwind(14))]
fn comm_loss_fires_exactly_after_timeout_or_ten_unacknowledged_sends() {
    #[cfg(not(any(kani, fuzzing)))]
    {
        // (dt, what, seq): what 0 = tick, 1 = heartbeat echoing seq, 2 = send of seq.
        const TIMING: [(u16, u8, u8); 11] = [
            (0, 0, 0),
            (1, 0, 0),
            (250, 0, 0),
            (499, 0, 0),
            (500, 0, 0),
            (501, 0, 0),
            (0, 1, 0),
            (0, 1, 1),
            (501, 1, 0),
            (0, 2, 0),
            (0, 2, 1),
        ];
        const COUNTING: [(u16, u8, u8); 3] = [(0, 2, 0), (0, 2, 1), (0, 1, 0)];
        let name = "comm_loss_fires_exactly_after_timeout_or_ten_unacknowledged_sends";
        crate::ledger::exhaustive(
            &format!("{name} (timing)"),
            2 * 11u64.pow(6),
            (
                bolero::produce::<bool>(),
                crate::ledger::seq::<_, 6>(0usize..11),
            ),
            |(wrap, letters)| {
                let start = if *wrap { u32::MAX - 250 } else { 0 };
                comm_loss(start, &letters.map(|l| TIMING[l]));
            },
        );
        crate::ledger::exhaustive(
            &format!("{name} (counting)"),
            3u64.pow(12),
            crate::ledger::seq::<_, 12>(0usize..3),
            |letters| comm_loss(0, &letters.map(|l| COUNTING[l])),
        );
        crate::ledger::sampled::<(u32, [(u16, u8, u8); COMM_EVENTS])>(
            name,
            200_000,
            |(start, events)| comm_loss(*start, events),
        );
        return;
    }
    #[allow(unreachable_code)]
    bolero::check!()
        .with_type::<(u32, [(u16, u8, u8); COMM_EVENTS])>()
        .for_each(|(start, events)| comm_loss(*start, events));
}

/// The property of [`comm_loss_fires_exactly_after_timeout_or_ten_unacknowledged_sends`].
fn comm_loss(start: u32, events: &[(u16, u8, u8)]) {
    let start = &start;
    let cfg = Config::default();
    let mut c = CommMonitor::default();
    let mut abs: u64 = *start as u64;
    let mut last_heard: Option<u64> = None; // last heartbeat, or the first tick
    let mut last_obs: u64 = abs; // last tick or heartbeat
    let mut pending: Option<(u8, u8)> = None; // (seq, sends)
    let mut acked: Option<u8> = None; // the number B last echoed
    for (i, &(dt, what, seq)) in events.iter().enumerate() {
        if i > 0 {
            abs += dt as u64;
        }
        let now = abs as u32;
        match what % 4 {
            0 => {
                c.tick(now);
                last_heard.get_or_insert(abs);
                last_obs = abs;
            }
            1 => {
                c.heartbeat(now, seq % 2);
                last_heard = Some(abs);
                last_obs = abs;
                acked = Some(seq % 2);
                if pending.is_some_and(|(p, _)| p == seq % 2) {
                    pending = None;
                }
            }
            _ => {
                c.sent(seq % 2);
                pending = match pending {
                    _ if acked == Some(seq % 2) => pending,
                    Some((p, n)) if p == seq % 2 => Some((p, n.saturating_add(1))),
                    _ => Some((seq % 2, 1)),
                };
            }
        }
        // Silence is measured up to the last tick or heartbeat the monitor has seen.
        let silent = last_heard.map_or(0, |h| last_obs - h);
        let expected = silent > 500 || pending.is_some_and(|(_, n)| n >= 10);
        assert_eq!(c.lost(&cfg), expected, "event {i}");
    }
}
