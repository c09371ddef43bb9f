//! The 10 ms control tick of boards A and B: read the sensors, filter them
//! ([`Frontend::push`]), step the library's node, drive its outputs, move its packets. The
//! order is the host simulator's (host/src/sim/nodes.rs).

use crate::durable::Keep;
use crate::link::{ByteSink, ByteSource, Link};
use mmic::bolter::{Drive, MuxLines};
use mmic::node::robot::board_a::{self, BoardA, Durable};
use mmic::node::robot::handoff::{Consumer, Producer};
use mmic::node::robot::wifi_session::WifiSession;
use mmic::restart::ResetCause;
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

/// What the glue counts: packets the serial line did not take (failed sensor reads: `Side`),
/// and on board A the durable record's writes that failed (`store_failed`) and the commands
/// not taken because their record could not be written first (`unkept`: the ground resends).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[allow(missing_docs)]
pub struct Counters {
    pub tx_errors: u32,
    pub store_failed: u32,
    pub unkept: u32,
}

/// Board A's control task, with its durable record's store `K` (decision
/// `restart-board-a-storage`).
pub struct ControlA<'q, K: Keep> {
    /// The library's board A.
    pub a: BoardA,
    front: Frontend<WINDOW>,
    commands: Consumer<'q, COMMAND_LEN, QUEUE>,
    heartbeats: Producer<'q, HEARTBEAT_LEN, QUEUE>,
    /// Board B's serial line, receive side.
    pub from_b: Link,
    /// Counts.
    pub counters: Counters,
    keep: K,
    /// The record the store holds (what a reset would find), as far as this task knows.
    kept: Option<Durable>,
}

impl<'q, K: Keep> ControlA<'q, K> {
    /// Board A after a start for `cause`, from what `keep` kept (Table 7's power-on: Standby,
    /// servos unpowered, nothing resumed; the exactly-once log as it was; the boot count one
    /// more, written after the first tick), with its ends of the two hand-off queues.
    pub fn new(
        cfg: board_a::Config,
        front: frontend::Config,
        commands: Consumer<'q, COMMAND_LEN, QUEUE>,
        heartbeats: Producer<'q, HEARTBEAT_LEN, QUEUE>,
        mut keep: K,
        cause: ResetCause,
    ) -> Self {
        let kept = keep.load();
        ControlA {
            a: BoardA::restarted(cfg, kept, cause),
            front: Frontend::new(front),
            commands,
            heartbeats,
            from_b: Link::new(PacketKind::InternalHeartbeat),
            counters: Counters::default(),
            keep,
            kept,
        }
    }

    /// The store.
    pub const fn store(&self) -> &K {
        &self.keep
    }

    /// Writes `d` unless the store holds it; false when the write failed (counted).
    fn persist(&mut self, d: Durable) -> bool {
        if self.kept == Some(d) {
            return true;
        }
        match self.keep.keep(&d) {
            Ok(()) => {
                self.kept = Some(d);
                true
            }
            Err(_) => {
                self.counters.store_failed = self.counters.store_failed.saturating_add(1);
                false
            }
        }
    }

    /// Heartbeats given up because the WiFi task's queue was full.
    pub const fn heartbeats_dropped(&self) -> u32 {
        self.heartbeats.dropped()
    }

    /// One tick at `now` ms; returns the library's outputs (for logs). The command it takes
    /// is written ahead (`BoardA::ahead`) before the library's tick, and not taken when that
    /// write fails; what the tick changed (`BoardA::durable`) is written after it.
    pub fn tick(
        &mut self,
        now: u32,
        sensors: &mut impl Sensors,
        out: &mut impl Actuators,
        uart: &mut (impl ByteSource + ByteSink),
    ) -> board_a::Outputs {
        let r = sensors.read();
        let f = self.front.push(&r.raw);
        let (mut command, from_b) = (self.commands.pop(), self.from_b.next(uart));
        if let Some(ahead) = self.a.ahead(command.as_ref()) {
            if !self.persist(ahead) {
                self.counters.unkept = self.counters.unkept.saturating_add(1);
                command = None;
            }
        }
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
        // What the tick changed, after the outputs and before the heartbeat that reports it
        // leaves; a failed write is tried again after the next tick.
        self.persist(self.a.durable());
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
