//! The 10 ms control tick of boards A and B: read the sensors, filter them
//! ([`Frontend::push`]), step the library's node, drive its outputs, move its packets. The
//! order is the host simulator's (host/src/sim/nodes.rs).

use crate::link::{ByteSink, ByteSource, Link};
use mmic::bolter::{Drive, MuxLines};
use mmic::node::robot::board_a::{self, BoardA};
use mmic::node::robot::handoff::{Consumer, Producer};
use mmic::node::robot::wifi_session::WifiSession;
use mmic::sensors::frontend::{self, Frontend, WINDOW};
use mmic::units::PulseWidth;
use mmic::wire::command::COMMAND_LEN;
use mmic::wire::heartbeat::HEARTBEAT_LEN;
use mmic::wire::PacketKind;

/// The control period, ms (Section 3).
pub const TICK_MS: u32 = 10;
/// Hand-off queue slots (holds one fewer).
pub const QUEUE: usize = 8;

/// One tick's readings of a side: the devices' ([`frontend::Raw`]: ADS7828 codes CH0..CH7,
/// MPU-6000 accelerations X, Y, Z, the hip encoder's raw angle on board A; `None` where the
/// device did not answer — the library decides what follows), and the arm contraction and
/// bolter home switches.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[allow(missing_docs)]
pub struct Reading {
    pub raw: frontend::Raw,
    pub arm_contracted: bool,
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
    /// Servo pulses at 50 Hz, arm, gripper, hip (board A); none: no pulse, unpowered.
    fn servos(&mut self, pulses: [Option<PulseWidth>; 3]);
    /// The 7.4 V regulator enable line.
    fn regulator(&mut self, on: bool);
    /// The bolter's drive lines ([`bolter_lines`]) and the ADG1604's A0/A1.
    fn bolter(&mut self, lines: [bool; 3], mux: MuxLines);
}

/// What the glue counts: packets the serial line did not take (failed sensor reads: `Side`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[allow(missing_docs)]
pub struct Counters {
    pub tx_errors: u32,
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

    /// One tick at `now` ms; returns the library's outputs (for logs).
    pub fn tick(
        &mut self,
        now: u32,
        sensors: &mut impl Sensors,
        out: &mut impl Actuators,
        uart: &mut (impl ByteSource + ByteSink),
    ) -> board_a::Outputs {
        let r = sensors.read();
        let f = self.front.push(&r.raw);
        let (command, from_b) = (self.commands.pop(), self.from_b.next(uart));
        let inputs =
            board_a::Inputs::sensed(&f, r.arm_contracted, r.bolter_at_home, command, from_b);
        let o = self.a.tick(now, &inputs);
        out.servos([o.arm, o.gripper, o.hip]);
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
        o
    }
}

/// Board A's WiFi task, receive side: the command packets the library's session finds in
/// bytes read from the server's TCP stream at `now`, into the control task's queue (a full
/// queue gives the packet up, counted by the library).
pub fn commands_in(
    session: &mut WifiSession,
    now: u32,
    bytes: &[u8],
    q: &mut Producer<'_, COMMAND_LEN, QUEUE>,
) {
    session.received(now, bytes, |p| {
        if let Err(full) = q.push(p) {
            q.give_up(full);
        }
    });
}
