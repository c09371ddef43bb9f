//! The robot's physics, as much as the firmware can notice: servos that move at a limited
//! speed, a continuous hip servo with lag, currents that rise while something moves, pushes
//! or hits an obstacle, a battery that sags with current and time, fasteners that lock with a
//! probability, and gravity readings that follow the state the robot is in. Injected faults
//! ([`super::inject`]) act here where they are physical: a jammed fastener, a dead
//! contraction switch, an obstacle on a bolter, gripper or arm, an offset hip encoder, a
//! sagging battery. It reads out raw: ADS7828 codes with a few codes of noise, accelerations
//! with noise, the encoder's count; each board's shell passes them through the library's
//! sensor front end (`mmic::sensors::frontend`, Section 2's 50-sample averages) as the
//! firmware would.
//!
//! The bolters report what the firmware's current sensing needs (Section 5): a bolter draws a
//! running current while it moves, more once it presses its fastener (it is driven further down
//! than it can go), and more still once the rotating head stalls on a locked fastener; the
//! firmware decides the end of those steps from I_bo alone. Only "at home" is a switch.
//!
//! Simplifications, stated: the gravity readings are those of the pose of the state the robot
//! last reached (the plant does not integrate the kinematics), computed here from the arm
//! directions, a hip axis and the IMU frames ([`imu_gravity`]), not through the estimator's
//! model (`mmic::motion::estimate::predict`), so that the simulator tests the estimate; both sides'
//! bolters share one lock roll per attempt (a face's fastener pair locks or does not);
//! the lock probability of consecutive attempts on one pair follows Figure 10's demo
//! (2307/2524, then 103/217, then 28/114: spec/hardware.toml `[figure10]`, checked by
//! host/tests/sim.rs); unbolting uses the same roll, "locked" then meaning
//! "released" (the head stalls at the end of the unlocking turn alike).

use mmic::bolter::{Drive, MuxLines};
use mmic::motion::geometry::arm_direction;
use mmic::motion::State;
use mmic::sensors::adc::{Channel, Scaling, CODE_MAX};
use mmic::sensors::frontend::Raw;
use mmic::units::{Axis, Gravity, PulseWidth, Side, Sign};

/// Plant parameters and injected faults.
#[derive(Debug, Clone)]
pub struct PlantConfig {
    /// Probability that the fastener locks at the 1st, 2nd, 3rd consecutive attempt on a pair.
    pub lock_probability: [f64; 3],
    /// Battery voltage at rest, full, mV.
    pub battery_mv: f64,
    /// Battery internal resistance, Ω (mV per mA).
    pub internal_ohm: f64,
    /// Discharge, mV per simulated second.
    pub drain_mv_per_s: f64,
    /// From this time on (ms) the battery is nearly empty (rest voltage 9.6 V).
    pub low_battery_at: Option<u32>,
    /// At this time (ms) arm A hits an obstacle: its current jumps to 3.5 A for 500 ms.
    pub overcurrent_at: Option<u32>,
    /// From this time on (ms) no fastener locks (or releases): every rotation runs without the
    /// stall current, so every attempt times out and the third raises the (un)bolting failure
    /// fault (Table 8: Standby). Models a jammed fastener or a misplaced voxel (Section 8).
    pub jammed_fastener_at: Option<u32>,
    /// At this time (ms) bolter A hits an obstacle: its current jumps to 2.6 A, above the
    /// 2000 mA bolter limit, for 500 ms (Table 8: bolter module overcurrent, Safed).
    pub bolter_obstacle_at: Option<u32>,
    /// At this time (ms) gripper A meets an obstacle: its current jumps to 2.5 A (above the
    /// 1.5 A absolute limit) for 500 ms. The firmware sees the current through a 50-sample
    /// average: at 2.5 A it crosses 1.5 A after 30 samples of the pulse, so the obstacle is
    /// seen even when a loaded host runs a board's 10 ms tick late now and then.
    pub gripper_obstacle_at: Option<u32>,
    /// From this time on (ms) arm A's contraction switch is dead: it never closes.
    pub arm_switch_dead_at: Option<u32>,
    /// From this time on (ms) the hip encoder reads [`hip_encoder_offset`](Self::hip_encoder_offset)
    /// off the hip's true angle (a slipped magnet, a bad connection). The firmware's hip check
    /// looks only when Operational is entered, so from 0 (power-up) it is caught at once.
    pub hip_encoder_offset_at: Option<u32>,
    /// The encoder's error once offset, 0.01°.
    pub hip_encoder_offset: u16,
    /// From this time on (ms) the ADS7828 of side A, B (index 0, 1) does not answer: no
    /// voltage or current reading at all (an I2C fault). Not a Table 8 fault: the firmware's
    /// sensor loss (spec/decisions.toml, `sensor-loss`).
    pub adc_silent_at: [Option<u32>; 2],
    /// From this time on (ms) the hip encoder does not answer.
    pub encoder_silent_at: Option<u32>,
    /// RNG seed (fastener locks).
    pub seed: u64,
    /// Pulse at which an arm's contraction switch closes (the firmware's "contracted").
    pub arm_contracted: PulseWidth,
}

impl Default for PlantConfig {
    fn default() -> PlantConfig {
        PlantConfig {
            lock_probability: [2307.0 / 2524.0, 103.0 / 217.0, 28.0 / 114.0],
            battery_mv: 12_600.0,
            internal_ohm: 0.3,
            drain_mv_per_s: 2.0,
            low_battery_at: None,
            overcurrent_at: None,
            jammed_fastener_at: None,
            bolter_obstacle_at: None,
            gripper_obstacle_at: None,
            arm_switch_dead_at: None,
            hip_encoder_offset_at: None,
            // 30°: three times the hip check's 10° tolerance.
            hip_encoder_offset: 3000,
            adc_silent_at: [None; 2],
            encoder_silent_at: None,
            seed: 1,
            arm_contracted: mmic::node::robot::board_a::Config::default().arm.contracted,
        }
    }
}

#[derive(Debug, Clone, Copy, Default)]
struct Bolter {
    pos: f64,
    rotating_ms: f64,
    drive: Option<Drive>,
}

/// What one board drives.
#[derive(Debug, Clone, Copy)]
pub struct Drives {
    /// Arm servo pulse; none = unpowered.
    pub arm: Option<PulseWidth>,
    /// Gripper servo pulse.
    pub gripper: Option<PulseWidth>,
    /// Regulator.
    pub regulator: bool,
    /// Bolter motor.
    pub bolter: Drive,
    /// Bolter multiplexer.
    pub mux: MuxLines,
}

impl Drives {
    /// Nothing driven: a board that is down (restarting) powers nothing.
    pub fn off() -> Drives {
        Drives {
            arm: None,
            gripper: None,
            regulator: false,
            bolter: Drive::Idle,
            mux: MuxLines::default(),
        }
    }
}

/// What one side's sensors read: the raw readings the library's front end
/// ([`mmic::sensors::frontend`]) filters, and the digital inputs.
#[derive(Debug, Clone, Copy)]
pub struct Senses {
    /// ADS7828 codes, IMU accelerations and (side A) the hip encoder's count.
    pub raw: Raw,
    /// Arm contraction switch.
    pub arm_contracted: bool,
    /// Bolter home switch: the bolter is in its initial configuration (its current is among
    /// the ADC codes, channel I_bo).
    pub bolter_at_home: bool,
}

/// The plant.
pub struct Plant {
    cfg: PlantConfig,
    rng: fastrand::Rng,
    /// Sensor noise (a separate stream, so that noise does not change the lock rolls).
    noise: fastrand::Rng,
    last: u32,
    arm: [f64; 2],
    gripper: [f64; 2],
    drives: [Option<Drives>; 2],
    arm_moving: [bool; 2],
    gripper_moving: [bool; 2],
    hip: f64,
    hip_speed: f64,
    hip_cmd: Option<PulseWidth>,
    bolter: [Bolter; 2],
    lock: Option<bool>,
    tries: usize,
    pair: Option<MuxLines>,
    /// The state the robot last reached (drives the gravity readings).
    pub state: State,
    /// Extra current side A's bolter draws at all times, mA: a bolter caught in a fastener
    /// (Section 7's example for the idle check). 0 = none.
    pub stuck_bolter_ma: f64,
    /// Per side (0 = A, 1 = B): the arm's contraction switch is dead and never closes.
    pub dead_switch: [bool; 2],
    gravity: (Option<Gravity>, Option<Gravity>),
    /// Whether `turn` may skip libm's `fmod` ([`Plant::set_shortcuts`]).
    shortcuts: bool,
}

const SERVO_US_PER_S: f64 = 2000.0;
/// A bolter's travel between home and its fastener, ms.
pub const BOLTER_TRAVEL_MS: f64 = 800.0;
/// How long the heads rotate before a fastener that locks does, ms.
pub const ROTATE_MS: f64 = 1000.0;
/// Bolter current, mA: unpowered or holding.
pub const BOLTER_IDLE_MA: f64 = 40.0;
/// Moving (translating or rotating freely): under both thresholds and, like the other
/// modules, no idle fault while it settles.
pub const BOLTER_RUNNING_MA: f64 = 450.0;
/// Pressing the fastener: over the push threshold (1000 mA by default), under the 2000 mA
/// overcurrent limit. (Over the lock threshold too: Rotate never sees it raw, and the filtered
/// current a push leaves behind ends just past the push threshold.)
pub const BOLTER_PUSHING_MA: f64 = 1350.0;
/// The head stalled on a locked (released) fastener: over the lock threshold (1200 mA by
/// default), under the 2000 mA overcurrent limit.
pub const BOLTER_LOCKED_MA: f64 = 1600.0;
/// Bolter A against an obstacle (`bolter_obstacle_at`): over the 2000 mA limit.
pub const BOLTER_OBSTACLE_MA: f64 = 2600.0;
/// ADC noise, codes either side.
const NOISE: i32 = 5;
/// How long an injected obstacle lasts, ms.
const OBSTACLE_MS: u32 = 500;

/// `c` centidegrees within one turn: `c.rem_euclid(36000.0)`, without libm's `fmod` (a
/// software loop on x86-64) when `c` is already in the turn and `shortcut` (nearly every call:
/// the hip turns a little per tick), where `fmod` gives `c` itself, exactly.
fn turn(c: f64, shortcut: bool) -> f64 {
    if shortcut && (0.0..36000.0).contains(&c) {
        c
    } else {
        c.rem_euclid(36000.0)
    }
}

/// `now` is at or after the injection time `at`, if one is set.
fn at_or_after(at: Option<u32>, now: u32) -> bool {
    at.is_some_and(|t| now >= t)
}

/// `now` is within `ms` of the injection time `at`, if one is set.
fn within(at: Option<u32>, now: u32, ms: u32) -> bool {
    at.is_some_and(|t| now >= t && now - t < ms)
}

impl Plant {
    /// The robot at rest in `state`, arms contracted, grippers closed, hip at 180°.
    pub fn new(cfg: PlantConfig, state: State) -> Plant {
        let a = mmic::node::robot::board_a::Config::default();
        let mut p = Plant {
            rng: fastrand::Rng::with_seed(cfg.seed),
            noise: fastrand::Rng::with_seed(cfg.seed ^ 0x5eed_5e45),
            last: 0,
            arm: [a.arm.contracted.micros() as f64; 2],
            gripper: [a.gripper.extended.micros() as f64; 2],
            drives: [None; 2],
            arm_moving: [false; 2],
            gripper_moving: [false; 2],
            hip: 18000.0,
            hip_speed: 0.0,
            hip_cmd: None,
            bolter: [Bolter::default(); 2],
            lock: None,
            tries: 0,
            pair: None,
            state,
            stuck_bolter_ma: 0.0,
            dead_switch: [false; 2],
            gravity: (None, None),
            shortcuts: true,
            cfg,
        };
        p.set_state(state);
        p
    }

    /// Whether the plant takes its exact shortcuts (`turn` without `fmod` where the angle is
    /// already within the turn): on by default; off for the swarm's equivalence test, which
    /// finds the same readings.
    pub fn set_shortcuts(&mut self, on: bool) {
        self.shortcuts = on;
    }

    /// The robot reached `s`: its IMUs now read gravity in that pose.
    pub fn set_state(&mut self, s: State) {
        self.state = s;
        let (a, b) = imu_gravity(s);
        self.gravity = (Some(a), Some(b));
    }

    /// Board A's outputs (side A and the hip).
    pub fn drive_a(&mut self, d: Drives, hip: Option<PulseWidth>) {
        self.drives[0] = Some(d);
        self.hip_cmd = hip;
    }

    /// Board B's outputs.
    pub fn drive_b(&mut self, d: Drives) {
        self.drives[1] = Some(d);
    }

    /// Advances the physics to `now` (ms).
    pub fn advance(&mut self, now: u32) {
        let dt = now.saturating_sub(self.last) as f64;
        self.last = now.max(self.last);
        if dt <= 0.0 {
            return;
        }
        for side in 0..2 {
            let d = self.drives[side];
            let step = SERVO_US_PER_S * dt / 1000.0;
            let follow = |x: &mut f64, cmd: Option<PulseWidth>| -> bool {
                match cmd {
                    Some(c) if d.is_some_and(|d| d.regulator) => {
                        let target = c.micros() as f64;
                        let before = *x;
                        *x += (target - *x).clamp(-step, step);
                        (*x - before).abs() > 1e-9
                    }
                    _ => false,
                }
            };
            self.arm_moving[side] = follow(&mut self.arm[side], d.and_then(|d| d.arm));
            self.gripper_moving[side] = follow(&mut self.gripper[side], d.and_then(|d| d.gripper));
            let drive = d.map_or(Drive::Idle, |d| d.bolter);
            let b = &mut self.bolter[side];
            match drive {
                Drive::Down => b.pos = (b.pos + dt / BOLTER_TRAVEL_MS).min(1.0),
                Drive::Up | Drive::CounterRotateUp => {
                    b.pos = (b.pos - dt / BOLTER_TRAVEL_MS).max(0.0)
                }
                Drive::Rotate => b.rotating_ms += dt,
                Drive::Idle => {}
            }
            if drive != Drive::Rotate {
                b.rotating_ms = 0.0;
            }
            b.drive = Some(drive);
        }
        // One lock roll per attempt, shared by both sides of the pair.
        let mux = self.drives[0].map(|d| d.mux);
        if mux != self.pair {
            self.pair = mux;
            self.tries = 0;
        }
        let rotating = self.bolter.iter().any(|b| b.drive == Some(Drive::Rotate));
        let jammed = self.cfg.jammed_fastener_at.is_some_and(|t| now >= t);
        if rotating && self.lock.is_none() {
            let p = self.cfg.lock_probability[self.tries.min(2)];
            // Rolled even when jammed, so that a jam does not shift later rolls.
            let ok = self.rng.f64() < p && !jammed;
            self.lock = Some(ok);
            self.tries = if ok { 0 } else { self.tries + 1 };
        }
        if jammed && self.lock == Some(true) {
            // Jammed during a rotation: that one does not lock either.
            self.lock = Some(false);
        }
        if !rotating {
            self.lock = None;
        }
        // The continuous hip servo: 10 (0.01°/s) per µs off 1500, 50 ms lag.
        let cmd = match self.hip_cmd {
            Some(p) if self.drives[0].is_some_and(|d| d.regulator) => {
                (p.micros() as f64 - 1500.0) * 10.0
            }
            _ => 0.0,
        };
        self.hip_speed += (cmd - self.hip_speed) * (dt / 50.0).min(1.0);
        self.hip = turn(self.hip + self.hip_speed * dt / 1000.0, self.shortcuts);
    }

    /// The configuration, to schedule a fault at a time chosen during a run (the lock-step
    /// tests: "from now on the ADC is silent").
    pub fn config_mut(&mut self) -> &mut PlantConfig {
        &mut self.cfg
    }

    /// The hip's true angle, 0.01° (what the encoder reads, before its 12-bit rounding).
    pub fn hip_centidegrees(&self) -> f64 {
        self.hip
    }

    /// Side `side`'s (0 = A, 1 = B) arm and gripper positions, as servo pulses (µs).
    pub fn servos(&self, side: usize) -> (f64, f64) {
        (self.arm[side % 2], self.gripper[side % 2])
    }

    /// Whether side `side`'s arm and gripper servos moved in the last step of the physics.
    pub fn moving(&self, side: usize) -> (bool, bool) {
        (self.arm_moving[side % 2], self.gripper_moving[side % 2])
    }

    /// What side `side`'s bolter motor was last driven to do.
    pub fn bolter_drive(&self, side: usize) -> Drive {
        self.bolter[side % 2].drive.unwrap_or(Drive::Idle)
    }

    /// The hip encoder's raw reading at `now` (12 bits, 4096 counts per turn, 0 at hip 0°),
    /// offset once [`PlantConfig::hip_encoder_offset_at`] has passed.
    pub fn encoder(&self, now: u32) -> u16 {
        let off = if at_or_after(self.cfg.hip_encoder_offset_at, now) {
            self.cfg.hip_encoder_offset as f64
        } else {
            0.0
        };
        ((turn(self.hip + off, self.shortcuts) / 36000.0 * 4096.0).floor() as u32 % 4096) as u16
    }

    /// What side `side` (0 = A, 1 = B) reads at `now`.
    pub fn sense(&mut self, side: usize, now: u32) -> Senses {
        let d = self.drives[side];
        let reg = d.is_some_and(|d| d.regulator);
        let b = self.bolter[side];
        let drive = b.drive.unwrap_or(Drive::Idle);
        let pushing = drive == Drive::Down && b.pos >= 1.0;
        let locked =
            drive == Drive::Rotate && b.rotating_ms >= ROTATE_MS && self.lock == Some(true);
        let hip_moving = side == 0 && self.hip_speed.abs() > 50.0;
        let obstacle = side == 0 && within(self.cfg.overcurrent_at, now, OBSTACLE_MS);
        let gripper_obstacle = side == 0 && within(self.cfg.gripper_obstacle_at, now, OBSTACLE_MS);
        // Moving draws more, but stays under the idle limits (400 mA locomotion, 200 mA
        // gripper): a servo still settling when the firmware's idle check starts is no fault.
        let i_loc = if reg { 120.0 } else { 0.0 }
            + if self.arm_moving[side] { 150.0 } else { 0.0 }
            + if hip_moving { 100.0 } else { 0.0 }
            + if obstacle { 3500.0 } else { 0.0 };
        let i_grip = if reg { 60.0 } else { 0.0 }
            + if self.gripper_moving[side] {
                100.0
            } else {
                0.0
            };
        let i_grip = if gripper_obstacle { 2500.0 } else { i_grip };
        let bolter_obstacle = side == 0
            && self
                .cfg
                .bolter_obstacle_at
                .is_some_and(|t| now >= t && now < t + 500);
        let i_bo = if bolter_obstacle {
            BOLTER_OBSTACLE_MA
        } else if pushing {
            BOLTER_PUSHING_MA
        } else if locked {
            BOLTER_LOCKED_MA
        } else if drive == Drive::Idle {
            BOLTER_IDLE_MA
        } else {
            BOLTER_RUNNING_MA
        } + if side == 0 { self.stuck_bolter_ma } else { 0.0 };
        let i_3v3 = 80.0;
        let i_bat = i_loc + i_grip + i_bo + i_3v3;
        let rest = match self.cfg.low_battery_at {
            Some(t) if now >= t => 9_600.0,
            _ => self.cfg.battery_mv - self.cfg.drain_mv_per_s * now as f64 / 1000.0,
        };
        let v_bat = rest - i_bat * self.cfg.internal_ohm;
        // The ADS7828's codes, with ±NOISE codes of uniform noise (about ±6 mA on I_loc).
        let scaling = Scaling::default();
        let noise = &mut self.noise;
        let mut code = |ch: Channel, x: f64| {
            let fs = scaling.full_scale[ch as usize] as f64;
            let n = noise.i32(-NOISE..=NOISE) as f64;
            code_of(x / fs * CODE_MAX as f64 + n)
        };
        let adc = [
            code(Channel::VBat, v_bat),
            code(Channel::IBat, i_bat),
            code(Channel::ILoc, i_loc),
            code(Channel::IGrip, i_grip),
            code(Channel::I3v3, i_3v3),
            code(Channel::VReg, if reg { 7_400.0 } else { 0.0 }),
            code(Channel::IBo, i_bo),
            0,
        ];
        let g = if side == 0 {
            self.gravity.0
        } else {
            self.gravity.1
        };
        let accel = g.map(|g| {
            let mut a = [0i16; 3].map(|_| self.noise.i16(-400..=400));
            a[match g.axis {
                Axis::X => 0,
                Axis::Y => 1,
                Axis::Z => 2,
            }] = match g.sign {
                Sign::Positive => 16_384,
                Sign::Negative => -16_384,
            } + self.noise.i16(-400..=400);
            a
        });
        Senses {
            raw: Raw {
                adc: (!at_or_after(self.cfg.adc_silent_at[side], now)).then_some(adc),
                accel,
                encoder: (side == 0 && !at_or_after(self.cfg.encoder_silent_at, now))
                    .then(|| self.encoder(now)),
            },
            arm_contracted: !self.dead_switch[side]
                && self.arm[side] <= self.cfg.arm_contracted.micros() as f64 + 15.0
                && !(side == 0 && at_or_after(self.cfg.arm_switch_dead_at, now)),
            bolter_at_home: b.pos <= 0.0,
        }
    }
}

/// Gravity as the two IMUs read it in state `s`, from the plant's own geometry: the structure
/// stands with its +Z up (gravity −Z); each board's IMU frame is x = its arm's direction,
/// z = the hip axis, y = z × x (spec/motion/estimation.md); the hip axis is arm A × arm B when
/// the arms are at an angle, and in a pose with the arms in line (where no sensor shows it) the
/// first of ±X, ±Y, ±Z across the arms; an IMU reads gravity as its largest component. Only
/// the arm directions (the definition of the states) come from the library.
pub fn imu_gravity(s: State) -> (Gravity, Gravity) {
    type V = [i32; 3];
    let v = |x: [i8; 3]| -> V { [x[0].into(), x[1].into(), x[2].into()] };
    let cross = |p: V, q: V| -> V {
        [
            p[1] * q[2] - p[2] * q[1],
            p[2] * q[0] - p[0] * q[2],
            p[0] * q[1] - p[1] * q[0],
        ]
    };
    let dot = |p: V, q: V| -> i32 { p[0] * q[0] + p[1] * q[1] + p[2] * q[2] };
    let (a, b) = (v(arm_direction(s, Side::A)), v(arm_direction(s, Side::B)));
    let hip = match cross(a, b) {
        [0, 0, 0] => [
            [1, 0, 0],
            [-1, 0, 0],
            [0, 1, 0],
            [0, -1, 0],
            [0, 0, 1],
            [0, 0, -1],
        ]
        .into_iter()
        .find(|h| dot(*h, a) == 0)
        .unwrap_or([0, 0, 1]),
        c => c,
    };
    let g: V = [0, 0, -1];
    let read = |arm: V| -> Gravity {
        let comps = [
            (Axis::X, dot(g, arm)),
            (Axis::Y, dot(g, cross(hip, arm))),
            (Axis::Z, dot(g, hip)),
        ];
        let (axis, val) = comps
            .into_iter()
            .max_by_key(|c| c.1.abs())
            .unwrap_or((Axis::Z, -1));
        Gravity {
            axis,
            sign: if val > 0 {
                Sign::Positive
            } else {
                Sign::Negative
            },
        }
    };
    (read(a), read(b))
}

/// `v` rounded half away from zero and held to the ADC's codes: the same as
/// `v.round().clamp(0.0, CODE_MAX as f64) as u16`, without a call to libm's `round` (the
/// baseline x86-64 has no rounding instruction), the sensing's largest cost after its draws.
/// Between -0.5 and `CODE_MAX` the truncation is exact and so is the fraction it leaves.
fn code_of(v: f64) -> u16 {
    let max = CODE_MAX as f64;
    if v.is_nan() || v <= -0.5 {
        return 0;
    }
    if v >= max {
        return CODE_MAX;
    }
    let t = v as i64;
    let rounded = if v - t as f64 >= 0.5 { t + 1 } else { t };
    rounded.clamp(0, CODE_MAX as i64) as u16
}

#[cfg(test)]
mod gravity_tests {
    use super::imu_gravity;
    use mmic::motion::estimate::{consistent, ArmPwm, Config, Readings};
    use mmic::motion::State;
    use mmic::units::{HipAngle, PerSide};

    /// The plant's gravity (its own geometry) against the library's estimator: in every state,
    /// with the hip at the state's angle and the arms' PWM values of its pose, the estimate holds the
    /// true state. A plant that read its gravity through `predict` could not fail this.
    #[test]
    fn the_plants_gravity_is_estimated_as_the_true_state() {
        for s in State::ALL {
            let (ga, gb) = imu_gravity(s);
            let hips: &[u16] = if s.kind() == mmic::motion::StateKind::Turn {
                &[9000, 27000]
            } else {
                &[18000]
            };
            let (c, e) = (ArmPwm::Contracted, ArmPwm::Extended);
            let arms: &[(ArmPwm, ArmPwm)] = if s.is_matched() {
                &[(c, c)]
            } else {
                &[(c, e), (e, c), (e, e)]
            };
            let mut found = false;
            for &h in hips {
                for &(ca, cb) in arms {
                    let r = Readings {
                        gravity_a: Some(ga),
                        gravity_b: Some(gb),
                        arm: PerSide::new(ca, cb),
                        hip: HipAngle::new(h).unwrap(),
                    };
                    found |= consistent(&Config::default(), &r).contains(s);
                }
            }
            assert!(
                found,
                "{s}: the plant's gravity {ga:?} {gb:?} is not estimated as {s}"
            );
        }
    }
}

#[cfg(test)]
mod code_tests {
    use super::{code_of, CODE_MAX};

    /// `code_of` is `round` then `clamp` exactly: at every half, next to it, out of range,
    /// and at a million seeded values across the codes.
    #[test]
    fn code_of_is_round_then_clamp() {
        let max = CODE_MAX as f64;
        let reference = |v: f64| v.round().clamp(0.0, max) as u16;
        let mut vs = vec![
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            -1e300,
            1e300,
            -0.0,
            0.0,
            max,
            max + 0.5,
            max - 0.5,
            0.49999999999999994,
            -0.49999999999999994,
        ];
        for k in -10..=(CODE_MAX as i32 + 10) {
            let h = k as f64 + 0.5;
            vs.extend([h, h.next_down(), h.next_up(), k as f64, -h]);
        }
        let mut rng = fastrand::Rng::with_seed(7);
        vs.extend((0..1_000_000).map(|_| rng.f64() * (max + 20.0) - 10.0));
        for v in vs {
            assert_eq!(code_of(v), reference(v), "{v:?}");
        }
    }
}
