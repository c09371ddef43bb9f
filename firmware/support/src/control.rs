//! The 10 ms control tick of boards A and B: read the sensors, filter them
//! ([`Frontend::push`]), step the library's node, drive its outputs, move its packets. The
//! order is the host simulator's (host/src/sim/nodes.rs).

use crate::link::{ByteSink, ByteSource, Link};
use mmic::bolter::Drive;
use mmic::bolter::MuxLines;
use mmic::node::board_a::{self, BoardA};
use mmic::node::board_b::{self, BoardB};
use mmic::node::handoff::{Consumer, Producer};
use mmic::sensors::frontend::{self, Frontend, WINDOW};
use mmic::units::PulseWidth;
use mmic::wire::command::COMMAND_LEN;
use mmic::wire::heartbeat::HEARTBEAT_LEN;
use mmic::wire::PacketKind;

/// The control period, ms (Section 3).
pub const TICK_MS: u32 = 10;
/// Hand-off queue slots (holds one fewer).
pub const QUEUE: usize = 8;

/// One tick's readings of a side; `None` where the device did not answer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Reading {
    /// ADS7828 codes CH0..CH7.
    pub adc: Option<[u16; 8]>,
    /// MPU-6000 accelerations X, Y, Z.
    pub accel: Option<[i16; 3]>,
    /// Hip encoder raw angle (board A).
    pub encoder: Option<u16>,
    /// Arm contraction switch.
    pub arm_contracted: bool,
    /// Bolter home switch.
    pub bolter_at_home: bool,
}

/// A side's sensors.
pub trait Sensors {
    /// This tick's readings.
    fn read(&mut self) -> Reading;
}

/// The levels of the bolter motor driver's three lines for a drive: (direction, translate
/// enable, rotate enable). Translation and rotation share the direction line: down and rotate
/// run forward, up and counter-rotate-up backward (see README.md, pin map).
pub const fn bolter_lines(d: Drive) -> [bool; 3] {
    match d {
        Drive::Idle => [false, false, false],
        Drive::Down => [true, true, false],
        Drive::Up => [false, true, false],
        Drive::Rotate => [true, false, true],
        Drive::CounterRotateUp => [false, true, true],
    }
}

/// A side's outputs.
pub trait Actuators {
    /// Servo pulses at 50 Hz (none: no pulse, unpowered): arm, gripper, hip (board A).
    fn servos(&mut self, arm: Option<PulseWidth>, gripper: Option<PulseWidth>, hip: Option<PulseWidth>);
    /// The 7.4 V regulator enable line.
    fn regulator(&mut self, on: bool);
    /// The bolter's drive lines ([`bolter_lines`]) and the ADG1604's A0/A1.
    fn bolter(&mut self, lines: [bool; 3], mux: MuxLines);
}

/// What the glue counts that the library does not see.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Counters {
    /// Ticks not run because the ADC or the encoder did not answer (see README.md, gaps).
    pub sensor_gaps: u32,
    /// Packets the serial line did not take.
    pub tx_errors: u32,
    /// Events that did not fit a tick's outputs.
    pub events_lost: u32,
}

/// Board A's control task.
pub struct ControlA<'q> {
    /// The library's board A.
    pub a: BoardA,
    front: Frontend<WINDOW>,
    commands: Consumer<'q, COMMAND_LEN, QUEUE>,
    heartbeats: Producer<'q, HEARTBEAT_LEN, QUEUE>,
    /// Board B's serial line, receive side.
    pub from_b: Link,
    /// Counts.
    pub counters: Counters,
}

impl<'q> ControlA<'q> {
    /// Board A with its ends of the two hand-off queues.
    pub fn new(
        cfg: board_a::Config,
        front: frontend::Config,
        commands: Consumer<'q, COMMAND_LEN, QUEUE>,
        heartbeats: Producer<'q, HEARTBEAT_LEN, QUEUE>,
    ) -> Self {
        ControlA {
            a: BoardA::new(cfg),
            front: Frontend::new(front),
            commands,
            heartbeats,
            from_b: Link::new(PacketKind::InternalHeartbeat),
            counters: Counters::default(),
        }
    }

    /// Heartbeats given up because the WiFi task's queue was full.
    pub const fn heartbeats_dropped(&self) -> u32 {
        self.heartbeats.dropped()
    }

    /// One tick at `now` ms; returns the library's outputs (for logs), none when a reading
    /// was missing and the tick did not run.
    pub fn tick(
        &mut self,
        now: u32,
        sensors: &mut impl Sensors,
        out: &mut impl Actuators,
        uart: &mut (impl ByteSource + ByteSink),
    ) -> Option<board_a::Outputs> {
        let r = sensors.read();
        // Library gap: `Frontend::Raw` and `board_a::Inputs` have no "no reading" for the ADC
        // or the hip encoder, so without one the tick is not run (counted) rather than fed an
        // invented value. Nothing is taken from the queues or the serial line meanwhile.
        let (Some(adc), Some(encoder)) = (r.adc, r.encoder) else {
            self.counters.sensor_gaps = self.counters.sensor_gaps.saturating_add(1);
            return None;
        };
        let f = self.front.push(&frontend::Raw { adc, accel: r.accel, encoder });
        let inputs = board_a::Inputs {
            command: self.commands.pop(),
            from_b: self.from_b.next(uart),
            electrical: f.electrical,
            hip: f.hip,
            gravity: f.gravity,
            arm_contracted: r.arm_contracted,
            bolter_at_home: r.bolter_at_home,
        };
        let o = self.a.tick(now, &inputs);
        out.servos(o.arm, o.gripper, o.hip);
        out.regulator(o.regulator);
        out.bolter(bolter_lines(o.bolter), o.mux);
        if let Some(b) = o.to_b {
            if !uart.write(&b) {
                self.counters.tx_errors = self.counters.tx_errors.saturating_add(1);
            }
        }
        if let Some(hb) = o.heartbeat {
            if let Err(full) = self.heartbeats.push(hb) {
                self.heartbeats.give_up(full);
            }
        }
        self.counters.events_lost = self.counters.events_lost.saturating_add(o.events_lost.into());
        Some(o)
    }
}

/// Board A's WiFi task, receive side: command packets from the server's TCP stream into the
/// control task's queue (a full queue gives the packet up, counted by the library).
pub fn commands_in(link: &mut Link, bytes: &[u8], q: &mut Producer<'_, COMMAND_LEN, QUEUE>) {
    link.feed(bytes, |p| {
        if let Err(full) = q.push(p) {
            q.give_up(full);
        }
    });
}

/// Board B's control task.
pub struct ControlB {
    /// The library's board B.
    pub b: BoardB,
    front: Frontend<WINDOW>,
    /// Board A's serial line, receive side.
    pub from_a: Link,
    /// Counts.
    pub counters: Counters,
}

impl ControlB {
    /// Board B.
    pub fn new(cfg: board_b::Config, front: frontend::Config) -> Self {
        ControlB {
            b: BoardB::new(cfg),
            front: Frontend::new(front),
            from_a: Link::new(PacketKind::BCommand),
            counters: Counters::default(),
        }
    }

    /// One tick at `now` ms, as [`ControlA::tick`] (board B has no hip: its encoder reading
    /// is not used).
    pub fn tick(
        &mut self,
        now: u32,
        sensors: &mut impl Sensors,
        out: &mut impl Actuators,
        uart: &mut (impl ByteSource + ByteSink),
    ) -> Option<board_b::Outputs> {
        let r = sensors.read();
        let Some(adc) = r.adc else {
            self.counters.sensor_gaps = self.counters.sensor_gaps.saturating_add(1);
            return None;
        };
        // Board B's front end ignores the encoder field (mmic::sensors::frontend::Raw).
        let f = self.front.push(&frontend::Raw { adc, accel: r.accel, encoder: 0 });
        let inputs = board_b::Inputs {
            command: self.from_a.next(uart),
            electrical: f.electrical,
            gravity: f.gravity,
            arm_contracted: r.arm_contracted,
            bolter_at_home: r.bolter_at_home,
        };
        let o = self.b.tick(now, &inputs);
        out.servos(o.arm, o.gripper, None);
        out.regulator(o.regulator);
        out.bolter(bolter_lines(o.bolter), o.mux);
        if let Some(hb) = o.heartbeat {
            if !uart.write(&hb) {
                self.counters.tx_errors = self.counters.tx_errors.saturating_add(1);
            }
        }
        Some(o)
    }
}
