//! Board A's bolter coordinator: runs a bolt or unbolt job over one pair or all four, ordering
//! both sides step by step and retrying a timed-out attempt up to three attempts in all. A
//! step that ends at home and times out fails the job at once, at any attempt: the next
//! attempt would start from a home the bolter did not reach (Table 8 names only the three
//! attempts; spec/decisions.toml, `bolting-failure-at-home`).
// req: P5.9, P5.13, T8/bolting_failure

use super::side::{ended, SideConfig};
use super::{
    BolterAttempt, BolterAux, BolterDirection, BolterOrder, BolterPair, BolterStep, Fasteners,
};
use crate::faults::Fault;
use crate::units::Instant;

/// Coordinator settings.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Config {
    /// Side A's step timeouts and current thresholds; the coordinator's own patience with
    /// side B is derived from the same timeouts.
    pub side: SideConfig,
    /// Extra time the coordinator waits for side B's report beyond the side timeout before it
    /// gives up on the step (motion timeout: the link itself is judged by the communication
    /// monitor). Default 1000 ms.
    pub link_margin_ms: u32,
    /// Attempts per pair (Table 8: three).
    pub max_attempts: u8,
}

impl Default for Config {
    fn default() -> Config {
        Config {
            side: SideConfig::default(),
            link_margin_ms: 1000,
            max_attempts: 3,
        }
    }
}

/// A bolting job.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Job {
    /// Bolt or unbolt.
    pub direction: BolterDirection,
    /// One pair, or 1–4 in order.
    pub fasteners: Fasteners,
}

/// Where the coordinator is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Status {
    /// No job.
    Idle,
    /// Running.
    Running,
    /// Every pair of the job done.
    Done,
    /// Stopped on this fault: bolting failure after the last attempt, or the motion timeout
    /// when side B never reported the step.
    Failed(Fault),
}

/// What the coordinator asks for this tick.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Output {
    /// The order for both sides and the sequence number it was first issued with (send to B
    /// in every A→B command until it changes; apply to side A's executor).
    pub order: Option<(u8, BolterOrder)>,
    /// Heartbeat byte 55.
    pub active: Option<BolterPair>,
    /// Heartbeat byte 56.
    pub attempt: BolterAttempt,
    /// Status.
    pub status: Status,
}

/// The coordinator.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Coordinator {
    job: Option<Job>,
    pair: BolterPair,
    attempt: u8,
    step: BolterStep,
    retrying: bool,
    seq: u8,
    last: Instant,
    waited_ms: u32,
    status: Status,
    /// Table 1's "move bolters down": the job ends when both bolters have descended.
    descend_only: bool,
}

impl Default for Coordinator {
    fn default() -> Self {
        Self::new()
    }
}

fn reported(aux: &BolterAux, seq: u8, o: &BolterOrder) -> bool {
    aux.seq == seq
        && aux.step == Some(o.step)
        && aux.pair == Some(o.pair)
        && aux.direction == Some(o.direction)
}

impl Coordinator {
    /// Idle.
    pub const fn new() -> Coordinator {
        Coordinator {
            job: None,
            pair: BolterPair::P1,
            attempt: 0,
            step: BolterStep::Descend,
            retrying: false,
            seq: 0,
            last: Instant::ZERO,
            waited_ms: 0,
            status: Status::Idle,
            descend_only: false,
        }
    }

    /// Starts a job at `now` (replacing any running one).
    pub fn start(&mut self, job: Job, now: u32) {
        let pair = match job.fasteners {
            Fasteners::Pair(p) => p,
            Fasteners::All => BolterPair::P1,
        };
        self.job = Some(job);
        self.status = Status::Running;
        self.descend_only = false;
        self.begin_pair(pair, now);
    }

    /// Starts Table 1's "move bolters down" at `now`: both bolters of the pair the multiplexer
    /// selects when idle (pair 1, lines low-low; spec/decisions.toml `bolters-down`) descend
    /// until the current says they touch, and stop there. Nothing engages or rotates; the job
    /// ends Done when both sides touched or a descent timed out (the sides' reports tell
    /// which); a timeout is no (un)bolting failure, since nothing was bolted.
    pub fn start_down(&mut self, now: u32) {
        self.start(
            Job {
                direction: BolterDirection::Bolt,
                fasteners: Fasteners::Pair(BolterPair::P1),
            },
            now,
        );
        self.descend_only = true;
    }

    /// Whether the running or last job is a "move bolters down".
    pub const fn descend_only(&self) -> bool {
        self.descend_only
    }

    /// Resumes at `now` after a pause (a Stop, then Reset): the step in force is ordered again
    /// (the executors, ordered idle by the Stop, adopt it afresh) and its timeout counts anew.
    pub fn resume(&mut self, now: u32) {
        self.last = Instant::from_millis(now);
        self.waited_ms = 0;
    }

    /// Stops: the sides are ordered idle.
    pub fn stop(&mut self) {
        self.job = None;
        self.status = Status::Idle;
    }

    fn begin_pair(&mut self, pair: BolterPair, now: u32) {
        self.pair = pair;
        self.attempt = 1;
        self.goto(BolterStep::Descend, now);
    }

    fn goto(&mut self, step: BolterStep, now: u32) {
        self.step = step;
        self.seq = self.seq.wrapping_add(1);
        self.last = Instant::from_millis(now);
        self.waited_ms = 0;
    }

    /// The current order.
    pub fn order(&self) -> Option<(u8, BolterOrder)> {
        match (self.status, self.job) {
            (Status::Running, Some(j)) => Some((
                self.seq,
                BolterOrder {
                    pair: self.pair,
                    direction: j.direction,
                    step: self.step,
                },
            )),
            _ => None,
        }
    }

    /// Status.
    pub const fn status(&self) -> Status {
        self.status
    }

    /// Attempt on the current pair, 1..=3 (meaningful while running).
    pub const fn attempt(&self) -> u8 {
        self.attempt
    }

    /// Step being run (meaningful while running).
    pub const fn current_step(&self) -> BolterStep {
        self.step
    }

    /// One tick: `a` is side A's executor report, `b` the latest side-B report received (if any).
    pub fn step(&mut self, cfg: &Config, now: u32, a: &BolterAux, b: Option<&BolterAux>) -> Output {
        if let (Status::Running, Some((seq, o))) = (self.status, self.order()) {
            let limit = cfg
                .side
                .sensed_ms
                .max(cfg.side.home_ms)
                .saturating_add(cfg.link_margin_ms);
            self.waited_ms = self
                .waited_ms
                .saturating_add(Instant::from_millis(now).since(self.last).millis())
                .min(limit.saturating_add(1));
            self.last = Instant::from_millis(now);
            let side_done = |x: &BolterAux| {
                reported(x, seq, &o) && ended(o.step, x.threshold_reached, x.locked, x.at_home)
            };
            let side_timed_out = |x: &BolterAux| reported(x, seq, &o) && x.timed_out;
            let a_done = side_done(a);
            let b_done = b.is_some_and(side_done);
            let timed_out = side_timed_out(a) || b.is_some_and(side_timed_out);
            if self.descend_only && (timed_out || (a_done && b_done)) {
                // Down and stopped: touching or not, nothing more to do.
                self.status = Status::Done;
            } else if timed_out {
                self.attempt_failed(cfg, now);
            } else if a_done && b_done {
                self.advance(cfg, now);
            } else if self.waited_ms > limit {
                // Side B never reported this step done or timed out. Not Table 8's internal
                // communication loss: a silent B or an unacknowledged A->B command raises that
                // on its own (safety::detect::CommMonitor) within 500 ms, long before this
                // limit; what is left is a step that did not end (spec/decisions.toml
                // `motion-timeout`).
                self.status = Status::Failed(Fault::MotionTimeout);
            }
        }
        Output {
            order: self.order(),
            active: if self.status == Status::Running {
                Some(self.pair)
            } else {
                None
            },
            attempt: BolterAttempt::new(if self.status == Status::Running {
                self.attempt
            } else {
                0
            })
            .unwrap_or(BolterAttempt::NONE),
            status: self.status,
        }
    }

    fn attempt_failed(&mut self, _cfg: &Config, now: u32) {
        if !matches!(
            self.step,
            BolterStep::Descend | BolterStep::DescendEngage | BolterStep::Rotate
        ) {
            // A step that ends at home timed out: the bolter cannot even get back, so no further
            // attempt makes sense.
            self.status = Status::Failed(Fault::BoltingFailure);
            return;
        }
        self.retrying = true;
        self.goto(BolterStep::ReturnHome, now);
    }

    fn advance(&mut self, cfg: &Config, now: u32) {
        let next = match self.step {
            BolterStep::Descend => BolterStep::Retract,
            BolterStep::Retract => BolterStep::DescendEngage,
            BolterStep::DescendEngage => BolterStep::Rotate,
            BolterStep::Rotate => BolterStep::CounterRotate,
            BolterStep::ReturnHome if self.retrying => {
                self.retrying = false;
                if self.attempt >= cfg.max_attempts.clamp(1, BolterAttempt::MAX) {
                    self.status = Status::Failed(Fault::BoltingFailure);
                    return;
                }
                // Below the clamped maximum (just above), so this never saturates.
                self.attempt = self.attempt.saturating_add(1);
                BolterStep::Descend
            }
            _ => BolterStep::Done,
        };
        if next != BolterStep::Done {
            self.goto(next, now);
            return;
        }
        // This pair is done: next pair of an "all four" job, or the end.
        match (
            self.job.map(|j| j.fasteners),
            self.pair
                .number()
                .checked_add(1)
                .and_then(BolterPair::from_number),
        ) {
            (Some(Fasteners::All), Some(p)) => self.begin_pair(p, now),
            _ => self.status = Status::Done,
        }
    }
}
