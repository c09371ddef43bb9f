//! Replays a recorded scenario through one robot's nodes, on any target: the same library
//! calls the virtual-time engine made (`mmic sim --record`), in the same order, with the same
//! bytes, readings and times, each answered by one output record ([`out`]). Built for x86-64
//! by `mmic replay` and for `riscv32imc-unknown-none-elf` by the bare-metal runner
//! (`benches/rv32/runner`, under QEMU): the two outputs must be identical, byte for byte.
//!
//! What runs per record is the shells' glue around the library's pure nodes, as the engine
//! (`host/src/sim/engine`) and the firmware (`firmware/support`) do it: board A's control tick
//! (the hand-off queue's next command, the next internal heartbeat from the serial line, side
//! A's [`Frontend`], [`BoardA::tick`], the heartbeat into the other hand-off queue), board A's
//! WiFi task (commands deframed into the queue; heartbeats drained), board B's tick, and the
//! server board (the legacy relay [`Server`], the PUS [`Gateway`], or the gateway behind the
//! space data link, [`FrameGateway`]: TC frames in, TM frames out). No `unsafe`, no
//! allocation, no panic on any trace.
//!
//! ```
//! use mmic_replay::{trace::{Header, Protocol, Reading, Record}, Replay};
//! let mut r = Replay::new(&Header::demo(Protocol::Legacy));
//! let mut out = Vec::new();
//! r.step(&Record::TickA { t: 0, reading: Reading::default() }, &mut out, &mut ());
//! let rec = mmic_replay::out::records(&out).next().unwrap();
//! assert_eq!((rec.tag, rec.t), (1, 0));
//! ```
#![no_std]
#![forbid(unsafe_code)]
#![warn(missing_docs)]

#[cfg(feature = "std")]
extern crate std;

pub mod cost;
pub mod out;
pub mod parsers;
pub mod trace;

use heapless::{Deque, Vec};
use mmic::link::tm_frame::TM_FRAME_LEN;
use mmic::node::robot::board_a::{self, BoardA};
use mmic::node::robot::board_b::{self, BoardB};
use mmic::node::robot::handoff::PacketQueue;
use mmic::node::robot::wifi_session::{Outgoing, WifiConfig, WifiSession};
use mmic::node::server::frames::FrameGateway;
use mmic::node::server::gateway::{self, Gateway, Out};
use mmic::node::server::relay::{Accepted, Server};
use mmic::node::server::visit::Visit;
use mmic::sensors::frontend::{self, Frontend, WINDOW};
use mmic::units::PulseWidth;
use mmic::wire::b_command::B_COMMAND_LEN;
use mmic::wire::command::COMMAND_LEN;
use mmic::wire::deframer::{Deframed, Deframer};
use mmic::wire::heartbeat::{HeartbeatRepr, HEARTBEAT_LEN};
use mmic::wire::internal_heartbeat::INTERNAL_HEARTBEAT_LEN;
use out::{Field, RecordWriter};
use trace::{Header, Protocol, Record};

/// Where output bytes go (a file through semihosting, a `Vec` on the host).
pub trait Sink {
    /// Appends `bytes`.
    fn put(&mut self, bytes: &[u8]);
}

#[cfg(feature = "std")]
impl Sink for std::vec::Vec<u8> {
    fn put(&mut self, bytes: &[u8]) {
        self.extend_from_slice(bytes);
    }
}

/// The parts of a call, for the cost tables: the runner reads the instruction counter at each.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// Moving packets: queues, deframers.
    Glue = 0,
    /// The sensor front end ([`Frontend::push`]).
    FrontEnd = 1,
    /// The node's own tick or call ([`BoardA::tick`], [`BoardB::tick`], the relay, the gateway).
    Node = 2,
    /// Writing the output record: not part of the node's cost.
    Record = 3,
}

impl Phase {
    /// Every phase, in table order.
    pub const ALL: [Phase; 4] = [Phase::Glue, Phase::FrontEnd, Phase::Node, Phase::Record];

    /// The phase's name in tables.
    pub const fn name(self) -> &'static str {
        match self {
            Phase::Glue => "glue",
            Phase::FrontEnd => "front end",
            Phase::Node => "node",
            Phase::Record => "output record",
        }
    }
}

/// One library call of the frame gateway inside a record's node phase, timed on its own (a
/// server loop makes several: each TC frame, the tick, each TM frame handed out).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Call {
    /// [`FrameGateway::tc_frame`]: the frame checks, FARM-1, the packets into the gateway and
    /// their reports into the TM framer.
    TcFrame = 0,
    /// [`FrameGateway::tick`]: the gateway's resends, polls and housekeeping.
    Tick = 1,
    /// [`FrameGateway::frame`]: one TM frame written (or the answer that none is due).
    Frame = 2,
    /// [`FrameGateway::heartbeat`]: a heartbeat's reports into the TM framer.
    Heartbeat = 3,
}

impl Call {
    /// Every call, in table order.
    pub const ALL: [Call; 4] = [Call::TcFrame, Call::Tick, Call::Frame, Call::Heartbeat];

    /// The call's name in tables.
    pub const fn name(self) -> &'static str {
        match self {
            Call::TcFrame => "tc_frame",
            Call::Tick => "tick",
            Call::Frame => "frame",
            Call::Heartbeat => "heartbeat",
        }
    }
}

/// Told where a call's phases begin (the runner counts instructions; the host does nothing).
pub trait Meter {
    /// The call enters phase `p`.
    fn enter(&mut self, p: Phase);

    /// The library call `c` starts (`start`) or has returned; the phase does not change.
    fn call(&mut self, c: Call, start: bool) {
        let _ = (c, start);
    }
}

impl Meter for () {
    fn enter(&mut self, _: Phase) {}
}

/// The gateway of the simulator: one robot, eight waiting telecommands, 64 remembered keys.
pub type ReplayGateway = Gateway<1, 8, 64>;

/// The gateway behind the space data link, with the simulator's sizes (`host/src/sim/engine`'s
/// `SimFrameGateway`: one robot, eight waiting telecommands, 64 remembered keys, 4 KiB of TM
/// packets waiting): the same sizes, or the two runs' outputs diverge (a framer that fills
/// sooner loses other reports).
pub type ReplayFrameGateway = FrameGateway<1, 8, 64, 4096>;

/// The largest telemetry packet the gateway writes, bytes.
pub const MAX_TM_LEN: usize = mmic::ccsds::tm::TM_MIN_LEN + gateway::MAX_TM_DATA;

/// The largest packet from the ground the server board keeps, bytes (a longer datagram is
/// reported in the output record and dropped).
pub const MAX_GROUND_PACKET: usize = 256;

/// Packets waiting in the engine's unbounded queues fit in these (a fuller one is reported).
const QUEUE: usize = 32;

// No allocator: the gateway lives in place (the replay holds one board).
#[allow(clippy::large_enum_variant)]
enum Board {
    Relay(Server<4>),
    Gateway(ReplayGateway),
    Frames(ReplayFrameGateway),
}

/// One robot's nodes, and the glue between them.
pub struct Replay {
    header: Header,
    a: BoardA,
    front_a: Frontend<WINDOW>,
    b: BoardB,
    front_b: Frontend<WINDOW>,
    commands: PacketQueue<COMMAND_LEN, 8>,
    heartbeats: PacketQueue<HEARTBEAT_LEN, 8>,
    a_reader: Deframer<256>,
    a_from_b: Deque<[u8; INTERNAL_HEARTBEAT_LEN], QUEUE>,
    b_reader: Deframer<256>,
    b_from_a: Deque<[u8; B_COMMAND_LEN], QUEUE>,
    wifi: WifiSession,
    board: Board,
    visit: Option<Visit>,
    inbox: Deque<Vec<u8, MAX_GROUND_PACKET>, QUEUE>,
    server_reader: Deframer<256>,
    w: RecordWriter,
}

/// A pulse as a number: µs, 0 for none.
fn us(p: Option<PulseWidth>) -> u16 {
    p.map_or(0, PulseWidth::micros)
}

/// The packets a deframer finds in `bytes`, handed to `f` one by one.
fn frames(d: &mut Deframer<256>, bytes: &[u8], mut f: impl FnMut(mmic::wire::deframer::Frame)) {
    d.feed(bytes, |e| {
        if let Deframed::Frame(fr) = e {
            f(fr);
        }
    });
}

/// A serial line's bytes through its deframer: every packet of the queue's length queued (as
/// the engine does, whatever its kind); returns the packets found and those the queue refused.
fn serial<const L: usize>(
    d: &mut Deframer<256>,
    bytes: &[u8],
    q: &mut Deque<[u8; L], QUEUE>,
) -> (u32, u32) {
    let (mut n, mut over) = (0u32, 0u32);
    frames(d, bytes, |f| {
        if let Ok(p) = f.as_bytes().try_into() {
            n += 1;
            over += u32::from(q.push_back(p).is_err());
        }
    });
    (n, over)
}

impl Replay {
    /// The nodes at the start of a scenario.
    pub fn new(h: &Header) -> Replay {
        let board = match h.protocol {
            Protocol::Legacy => Board::Relay(Server::new()),
            Protocol::Pus => {
                let mut g = ReplayGateway::new(h.gateway);
                g.add(h.board);
                Board::Gateway(g)
            }
            Protocol::PusFrames => {
                let mut g = ReplayFrameGateway::new(h.frame_config());
                g.add(h.board);
                Board::Frames(g)
            }
            Protocol::PusFramesSdls => Board::Frames(secured(h)),
        };
        Replay {
            header: *h,
            a: BoardA::in_state(
                board_a::Config {
                    board: h.board,
                    ..board_a::Config::default()
                },
                h.start,
            ),
            front_a: Frontend::new(frontend::Config::default()),
            b: BoardB::new(board_b::Config::default()),
            front_b: Frontend::new(frontend::Config {
                hip_encoder: false,
                ..frontend::Config::default()
            }),
            commands: PacketQueue::new(),
            heartbeats: PacketQueue::new(),
            a_reader: Deframer::new(),
            a_from_b: Deque::new(),
            b_reader: Deframer::new(),
            b_from_a: Deque::new(),
            wifi: WifiSession::new(WifiConfig::default()),
            board,
            visit: None,
            inbox: Deque::new(),
            server_reader: Deframer::new(),
            w: RecordWriter::new(),
        }
    }

    /// Board A, as the replay left it.
    pub fn board_a(&self) -> &BoardA {
        &self.a
    }

    /// Runs one record and writes its output record to `out`; `m` is told the phases.
    ///
    /// Each kind of record runs in a function of its own that is never inlined, so that a
    /// call's stack holds only what its node needs (the RV32 runner measures it).
    pub fn step(&mut self, r: &Record<'_>, out: &mut impl Sink, m: &mut impl Meter) {
        m.enter(Phase::Glue);
        self.w.begin(r.tag(), r.t());
        match *r {
            Record::TickA { t, reading } => self.tick_a(t, &reading, m),
            Record::TickB { t, reading } => self.tick_b(t, &reading, m),
            Record::ToA { bytes, .. } => self.serial_a(bytes, m),
            Record::ToB { bytes, .. } => self.serial_b(bytes, m),
            Record::WifiOpen { t } => self.wifi_open(t, m),
            Record::WifiClose { .. } => {
                self.wifi.close();
                m.enter(Phase::Record);
            }
            Record::WifiBytes { t, bytes } => self.wifi_bytes(t, bytes, m),
            Record::WifiDrain { .. } => self.wifi_drain(m),
            Record::ServerIn { bytes, .. } => self.server_in(bytes, m),
            Record::ServerLoop { t } => self.server_loop(t, m),
            Record::ServerHeartbeat { t, bytes } => self.server_heartbeat(t, bytes, m),
        }
        m.enter(Phase::Record);
        self.w.end(out);
    }

    /// Board A's control task: the next command and internal heartbeat, the front end, the
    /// tick, the heartbeat into the WiFi task's queue.
    #[inline(never)]
    fn tick_a(&mut self, t: u32, reading: &trace::Reading, m: &mut impl Meter) {
        let command = self.commands.split().1.pop();
        let from_b = self.a_from_b.pop_front();
        m.enter(Phase::FrontEnd);
        let f = self.front_a.push(&reading.raw);
        m.enter(Phase::Node);
        let (arm, home) = (reading.arm_contracted, reading.bolter_at_home);
        let o = self
            .a
            .tick(t, &board_a::Inputs::sensed(&f, arm, home, command, from_b));
        m.enter(Phase::Glue);
        let full = o
            .heartbeat
            .is_some_and(|hb| self.heartbeats.split().0.push(hb).is_err());
        m.enter(Phase::Record);
        tick_a_record(&mut self.w, command, from_b, &o, &self.a, full);
    }

    /// Board B: the next command, the front end, the tick.
    #[inline(never)]
    fn tick_b(&mut self, t: u32, reading: &trace::Reading, m: &mut impl Meter) {
        let command = self.b_from_a.pop_front();
        m.enter(Phase::FrontEnd);
        let f = self.front_b.push(&reading.raw);
        m.enter(Phase::Node);
        let (arm, home) = (reading.arm_contracted, reading.bolter_at_home);
        let o = self
            .b
            .tick(t, &board_b::Inputs::sensed(&f, arm, home, command));
        m.enter(Phase::Record);
        tick_b_record(&mut self.w, command, &o);
    }

    /// Board A's serial line: internal heartbeats deframed into the control task's queue.
    #[inline(never)]
    fn serial_a(&mut self, bytes: &[u8], m: &mut impl Meter) {
        let (n, over) = serial(&mut self.a_reader, bytes, &mut self.a_from_b);
        m.enter(Phase::Record);
        queued_record(&mut self.w, n, over);
    }

    /// Board B's serial line: B commands deframed into its queue.
    #[inline(never)]
    fn serial_b(&mut self, bytes: &[u8], m: &mut impl Meter) {
        let (n, over) = serial(&mut self.b_reader, bytes, &mut self.b_from_a);
        m.enter(Phase::Record);
        queued_record(&mut self.w, n, over);
    }

    /// Board A's WiFi task takes a connection (the library's session): a fresh deframer,
    /// stale heartbeats dropped.
    #[inline(never)]
    fn wifi_open(&mut self, t: u32, m: &mut impl Meter) {
        let mut n = 0u32;
        let (_, mut queued) = self.heartbeats.split();
        self.wifi
            .open(t, core::iter::from_fn(|| queued.pop()), |_| n += 1);
        m.enter(Phase::Record);
        self.w.u32(Field::Discarded, n);
    }

    /// Board A's WiFi task: the session's command packets into the control task's queue.
    #[inline(never)]
    fn wifi_bytes(&mut self, t: u32, bytes: &[u8], m: &mut impl Meter) {
        let (mut n, mut full) = (0u32, 0u32);
        let (mut p, _) = self.commands.split();
        self.wifi.received(t, bytes, |c| {
            n += 1;
            full += u32::from(p.push(c).is_err());
        });
        m.enter(Phase::Record);
        queued_record(&mut self.w, n, full);
    }

    /// Board A's WiFi task writes the queued heartbeats (or drops them, unconnected), as the
    /// session says.
    #[inline(never)]
    fn wifi_drain(&mut self, m: &mut impl Meter) {
        let open = self.wifi.is_open();
        let mut dropped = 0u32;
        while let Some(hb) = self.heartbeats.split().1.pop() {
            match self.wifi.heartbeat(hb) {
                Outgoing::Send(hb) => {
                    m.enter(Phase::Record);
                    self.w.bytes(Field::Sent, &hb);
                    m.enter(Phase::Glue);
                }
                Outgoing::Drop(_) => dropped += 1,
            }
        }
        if !open {
            m.enter(Phase::Record);
            self.w.u32(Field::Discarded, dropped);
        }
    }

    #[inline(never)]
    fn server_in(&mut self, bytes: &[u8], m: &mut impl Meter) {
        let (mut n, mut over) = (0u32, 0u32);
        let inbox = &mut self.inbox;
        let mut keep = |b: &[u8]| {
            n += 1;
            let ok = Vec::from_slice(b).map(|v| inbox.push_back(v).is_ok());
            over += u32::from(!matches!(ok, Ok(true)));
        };
        match self.board {
            Board::Relay(_) => {
                m.enter(Phase::Node);
                frames(&mut self.server_reader, bytes, |f| keep(f.as_bytes()));
            }
            Board::Gateway(_) | Board::Frames(_) => keep(bytes),
        }
        m.enter(Phase::Record);
        queued_record(&mut self.w, n, over);
    }

    #[inline(never)]
    fn server_loop(&mut self, now: u32, m: &mut impl Meter) {
        let mut io = ServerIo {
            inbox: &mut self.inbox,
            w: &mut self.w,
            visit: &mut self.visit,
            number: self.header.board,
            now,
        };
        m.enter(Phase::Node);
        match &mut self.board {
            Board::Relay(srv) => relay_loop(srv, &mut io, m),
            Board::Gateway(g) => gateway_loop(g, &mut io, m),
            Board::Frames(g) => frames_loop(g, &mut io, m),
        }
    }

    #[inline(never)]
    fn server_heartbeat(&mut self, now: u32, bytes: &[u8], m: &mut impl Meter) {
        m.enter(Phase::Node);
        let Some(hb) = self.visit.as_mut().and_then(|v| v.received(bytes)) else {
            return;
        };
        match &mut self.board {
            Board::Relay(_) => {
                m.enter(Phase::Record);
                self.w.bytes(Field::Sent, &hb);
            }
            Board::Gateway(g) => gateway_heartbeat(g, &mut self.w, now, &hb, m),
            Board::Frames(g) => frames_heartbeat(g, &mut self.w, now, &hb, m),
        }
    }
}

/// A heartbeat into the PUS gateway, its reports into the record.
#[inline(never)]
fn gateway_heartbeat(
    g: &mut ReplayGateway,
    w: &mut RecordWriter,
    now: u32,
    hb: &[u8; HEARTBEAT_LEN],
    m: &mut impl Meter,
) {
    if let Ok(h) = HeartbeatRepr::parse(hb) {
        let o = g.heartbeat(now, &h);
        reports(w, g, o, now, m);
    }
}

/// A heartbeat into the frame gateway, the TM frames due into the record (as the engine's
/// `heartbeat_at_server` with `--link frames`).
#[inline(never)]
fn frames_heartbeat(
    g: &mut ReplayFrameGateway,
    w: &mut RecordWriter,
    now: u32,
    hb: &[u8; HEARTBEAT_LEN],
    m: &mut impl Meter,
) {
    if let Ok(h) = HeartbeatRepr::parse(hb) {
        m.call(Call::Heartbeat, true);
        g.heartbeat(now, &h);
        m.call(Call::Heartbeat, false);
    }
    tm_frames(w, g, now, m);
}

/// What a server board's loop works on besides its node: the ground's packets waiting, the
/// output record, the current visit.
struct ServerIo<'r> {
    inbox: &'r mut Deque<Vec<u8, MAX_GROUND_PACKET>, QUEUE>,
    w: &'r mut RecordWriter,
    visit: &'r mut Option<Visit>,
    number: mmic::units::BoardNumber,
    now: u32,
}

// Each board's loop in a function of its own, never inlined, so that a call's stack holds the
// buffers of its own node only (the RV32 runner measures it).
/// The legacy relay's loop: the ground's commands accepted, the next visit.
#[inline(never)]
fn relay_loop(srv: &mut Server<4>, io: &mut ServerIo<'_>, m: &mut impl Meter) {
    let (number, now) = (io.number, io.now);
    while let Some(p) = io.inbox.pop_front() {
        let Ok(packet) = <[u8; COMMAND_LEN]>::try_from(p.as_slice()) else {
            continue;
        };
        let r = srv.accept(&packet);
        m.enter(Phase::Record);
        match r {
            Ok(Accepted::Superseded(old)) => {
                io.w.debug(Field::Accepted, &"Superseded");
                io.w.bytes(Field::Accepted, &old);
            }
            Ok(a) => io.w.debug(Field::Accepted, &a),
            Err(e) => io.w.debug(Field::Refused, &e),
        }
        m.enter(Phase::Node);
    }
    // The replay keeps no deadline: the trace has a heartbeat record only while
    // the engine's visit was current.
    if let Some(visit) = Visit::next(srv, now, u32::MAX / 2) {
        visit.written(srv);
        let (board, packet) = (visit.board(), *visit.packet());
        if board == number {
            *io.visit = Some(visit);
        }
        m.enter(Phase::Record);
        io.w.u8(Field::Visit, board.get());
        io.w.bytes(Field::Visit, &packet);
    }
}

/// The PUS gateway's loop: the telecommands, the tick and its reports, the next visit.
#[inline(never)]
fn gateway_loop(g: &mut ReplayGateway, io: &mut ServerIo<'_>, m: &mut impl Meter) {
    let (number, now) = (io.number, io.now);
    while let Some(p) = io.inbox.pop_front() {
        match g.tc_packet(&p) {
            Ok(o) => reports(io.w, g, o, now, m),
            Err(e) => {
                m.enter(Phase::Record);
                io.w.debug(Field::Refused, &e);
                m.enter(Phase::Node);
            }
        }
    }
    let o = g.tick(now);
    let visit = o
        .to_robots
        .iter()
        .find(|(b, _)| *b == number)
        .map(|(_, c)| c.to_bytes());
    reports(io.w, g, o, now, m);
    if let Some(packet) = visit {
        *io.visit = Some(Visit::new(now, number, packet, u32::MAX / 2));
        m.enter(Phase::Record);
        io.w.u8(Field::Visit, number.get());
        io.w.bytes(Field::Visit, &packet);
    } else {
        let d = g.next_deadline(now);
        m.enter(Phase::Record);
        io.w.u32(Field::Deadline, d.unwrap_or(u32::MAX));
    }
}

/// The frame gateway's loop, as the engine's `frames_loop`: the TC frames through FARM-1 into
/// the gateway, the tick, the TM frames due, the next visit.
#[inline(never)]
fn frames_loop(g: &mut ReplayFrameGateway, io: &mut ServerIo<'_>, m: &mut impl Meter) {
    let (number, now) = (io.number, io.now);
    // As the engine's `frames_loop`: what is due kept first, the TC frames through FARM-1
    // into the gateway (nothing kept between them: an SDLS window's next reservation is
    // written after the batch, as the engine does), the tick, the TM frames due, the next
    // visit.
    keep(g);
    while let Some(f) = io.inbox.pop_front() {
        m.call(Call::TcFrame, true);
        let got = g.tc_frame(now, &f);
        m.call(Call::TcFrame, false);
        m.enter(Phase::Record);
        io.w.debug(Field::TcFrame, &got);
        m.enter(Phase::Node);
    }
    m.call(Call::Tick, true);
    keep(g);
    let mut to_robots = g.tick(now);
    // As the engine's `tick_gateway`: a telecommand held until the store says it left the
    // queue leaves in this pass.
    if to_robots.is_empty() && !g.durable_due::<1>().is_empty() {
        keep(g);
        to_robots = g.tick(now);
    }
    m.call(Call::Tick, false);
    let visit = to_robots
        .iter()
        .find(|(b, _)| *b == number)
        .map(|(_, c)| c.to_bytes());
    tm_frames(io.w, g, now, m);
    if let Some(packet) = visit {
        *io.visit = Some(Visit::new(now, number, packet, u32::MAX / 2));
        m.enter(Phase::Record);
        io.w.u8(Field::Visit, number.get());
        io.w.bytes(Field::Visit, &packet);
    } else {
        let d = g.next_deadline(now);
        m.enter(Phase::Record);
        io.w.u32(Field::Deadline, d.unwrap_or(u32::MAX));
    }
}

/// The frame gateway of a [`Protocol::PusFramesSdls`] trace, as the engine boots it with keys
/// made for the run (`sim::durable::provision_memory`, then `boot_gateway`): the server
/// board's store provisioned for the header's test keys, booted from it, the link secured,
/// what it asks to keep confirmed. Fails closed: if any step refuses (unreachable with the
/// keys `Trace::parse` checked), the gateway serves no robot and every frame is refused.
fn secured(h: &Header) -> ReplayFrameGateway {
    use mmic::node::server::store::{self, End, Resume};
    let mut g = ReplayFrameGateway::new(h.frame_config());
    let Some((tc, tm)) = h.sdls.as_ref().map(trace::TestKeys::keys) else {
        return g;
    };
    let Ok(entries) = store::provision(End::Server, h.board, &tc, &tm, Resume::FRESH) else {
        return g;
    };
    let lookup = |k: u16| {
        entries
            .iter()
            .find(|e| e.key == k)
            .map(|e| (e.aux, e.value))
    };
    let Ok(boot) = store::boot(End::Server, h.board, &tc, &tm, lookup) else {
        return g;
    };
    if !g.add(h.board) || g.secure(h.board, tc, tm, boot.stored).is_err() {
        return ReplayFrameGateway::new(h.frame_config());
    }
    keep(&mut g);
    g
}

/// What the gateway asks to keep, confirmed at once (the engine's store in memory, written
/// before anything that depends on it leaves: `sim::durable::persist_gateway`).
fn keep(g: &mut ReplayFrameGateway) {
    for e in g.durable_due::<16>() {
        g.durable_written(&e);
    }
}

/// The TM frames due at `now`, each into the record (as the engine's `tm_frames` sends them).
/// What is due is kept first (the engine's `tm_frames`: with SDLS, a TM frame waits for its
/// counter's reservation).
fn tm_frames(w: &mut RecordWriter, g: &mut ReplayFrameGateway, now: u32, m: &mut impl Meter) {
    keep(g);
    let mut buf = [0u8; TM_FRAME_LEN];
    loop {
        m.call(Call::Frame, true);
        let f = g.frame(now, &mut buf);
        m.call(Call::Frame, false);
        let Some((_, n)) = f else {
            return;
        };
        m.enter(Phase::Record);
        w.bytes(Field::TmFrame, buf.get(..n).unwrap_or(&[]));
        m.enter(Phase::Node);
    }
}

/// The gateway's reports, encoded at `now`, into the record.
fn reports<const M: usize>(
    w: &mut RecordWriter,
    g: &mut ReplayGateway,
    o: Out<M>,
    now: u32,
    m: &mut impl Meter,
) {
    if o.overflow > 0 {
        m.enter(Phase::Record);
        w.u16(Field::Overflow, o.overflow);
        m.enter(Phase::Node);
    }
    for tm in &o.reports {
        let mut b = [0u8; MAX_TM_LEN];
        let r = g.encode(tm, now, &mut b);
        m.enter(Phase::Record);
        match r {
            Ok(n) => w.bytes(Field::Report, b.get(..n).unwrap_or(&[])),
            Err(e) => w.debug(Field::Error, &e),
        }
        m.enter(Phase::Node);
    }
}

/// Packets a read found (`n`), and those its queue could not take (`over`).
pub fn queued_record(w: &mut RecordWriter, n: u32, over: u32) {
    w.u32(Field::Queued, n);
    if over > 0 {
        w.u32(Field::Discarded, over);
    }
}

/// Board A's control tick, as a record: what it took, what it drove and sent, where it is.
pub fn tick_a_record(
    w: &mut RecordWriter,
    command: Option<[u8; COMMAND_LEN]>,
    from_b: Option<[u8; INTERNAL_HEARTBEAT_LEN]>,
    o: &board_a::Outputs,
    a: &BoardA,
    handoff_full: bool,
) {
    if let Some(c) = command {
        w.bytes(Field::Command, &c);
    }
    if let Some(b) = from_b {
        w.bytes(Field::FromB, &b);
    }
    w.u16(Field::Hip, us(o.hip));
    w.u16(Field::Arm, us(o.arm));
    w.u16(Field::Gripper, us(o.gripper));
    w.u8(Field::Regulator, o.regulator.into());
    w.debug(Field::Bolter, &o.bolter);
    w.u8(Field::Mux, u8::from(o.mux.a0) | u8::from(o.mux.a1) << 1);
    if let Some(b) = o.to_b {
        w.bytes(Field::ToB, &b);
    }
    if let Some(h) = o.heartbeat {
        w.bytes(Field::Heartbeat, &h);
    }
    if !o.events.is_empty() {
        w.debug(Field::Events, &o.events);
    }
    if o.events_lost > 0 {
        w.u8(Field::EventsLost, o.events_lost);
    }
    w.debug(Field::Mode, &a.mode());
    w.u32(Field::Faults, a.faults().bits());
    w.debug(Field::State, &a.state());
    w.u8(Field::InMotion, a.in_motion().into());
    if handoff_full {
        w.u8(Field::HandoffFull, 1);
    }
}

/// Board B's tick, as a record.
pub fn tick_b_record(
    w: &mut RecordWriter,
    command: Option<[u8; B_COMMAND_LEN]>,
    o: &board_b::Outputs,
) {
    if let Some(c) = command {
        w.bytes(Field::Command, &c);
    }
    w.u16(Field::Arm, us(o.arm));
    w.u16(Field::Gripper, us(o.gripper));
    w.u8(Field::Regulator, o.regulator.into());
    w.debug(Field::Bolter, &o.bolter);
    w.u8(Field::Mux, u8::from(o.mux.a0) | u8::from(o.mux.a1) << 1);
    if let Some(h) = o.heartbeat {
        w.bytes(Field::InternalHeartbeat, &h);
    }
    w.u8(Field::LinkLost, o.link_lost.into());
    if let Some(e) = o.rejected {
        w.debug(Field::Rejected, &e);
    }
}
