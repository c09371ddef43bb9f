//! The recorded scenario: a header (protocol, robot, start state, the gateway's timing) and
//! the calls of one robot's nodes in the order the virtual-time engine made them, each with
//! its time and the bytes or readings it was given. Little-endian throughout.
//!
//! ```text
//! header  "MMICRPL1" protocol:u8 board:u8 state:u8      (protocol: 0 legacy, 1 PUS, 2 PUS over frames,
//!                                                        3 PUS over frames secured with SDLS)
//!         period_ms:u32 timeout_ms:u32 max_attempts:u8 poll_ms:u32 hk_interval_ms:u32 hk_enabled:u8
//!         [tc_key:32 tm_key:32]                          (protocol 3 only: the run's test keys)
//! record  tag:u8 t_ms:u32 body            (body by tag, see [`Record`])
//! reading flags:u8 [adc:8×u16] [accel:3×i16] [encoder:u16]
//!         flags: 1 adc, 2 accel, 4 encoder, 8 arm contracted, 16 bolter at home
//! bytes   len:u16 bytes
//! ```
//!
//! The format has one version: a trace of an older build reads the same (protocol 2 only
//! added a value, and with it the server board's `ServerIn` records carry TC transfer frames
//! instead of PUS packets; the link's own settings are [`FrameConfig`]'s defaults with the
//! header's gateway timing, as the engine runs it; protocol 3 added the run's SDLS test keys
//! after the header, [`TestKeys`]).
//!
//! ```
//! use mmic_replay::trace::{Header, Protocol, Reading, Record, Trace};
//! let h = Header::demo(Protocol::Legacy);
//! let mut bytes = Vec::new();
//! h.emit(&mut bytes);
//! Record::TickA { t: 10, reading: Reading::default() }.emit(&mut bytes);
//! Record::ToB { t: 12, bytes: &[1, 2, 3] }.emit(&mut bytes);
//! let trace = Trace::parse(&bytes).unwrap();
//! assert_eq!(trace.header, h);
//! let records: Vec<_> = trace.records().collect::<Result<_, _>>().unwrap();
//! assert_eq!(records[1], Record::ToB { t: 12, bytes: &[1, 2, 3] });
//! ```

use crate::Sink;
use mmic::link::sdls::{Key256, KEY_LEN};
use mmic::motion::State;
use mmic::node::exactly_once::uplink;
use mmic::node::server::frames::FrameConfig;
use mmic::node::server::gateway;
use mmic::sensors::frontend::Raw;
use mmic::units::BoardNumber;

/// The file's first eight bytes.
pub const MAGIC: &[u8; 8] = b"MMICRPL1";
/// The header's length, bytes (a protocol-3 trace's two keys follow it: 64 more).
pub const HEADER_LEN: usize = 8 + 3 + 4 + 4 + 1 + 4 + 4 + 1;

/// Why a trace cannot be read.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum TraceError {
    /// The first bytes are not [`MAGIC`].
    #[error("not a replay trace: the first 8 bytes are not \"MMICRPL1\"")]
    Magic,
    /// The input ends inside the header or a record.
    #[error("trace cut at byte {at}: {needed} more bytes needed")]
    Truncated {
        /// Where the cut part starts.
        at: usize,
        /// Bytes missing.
        needed: usize,
    },
    /// A record tag no [`Record`] has.
    #[error("unknown record tag {tag} at byte {at}")]
    Tag {
        /// The tag found.
        tag: u8,
        /// Where.
        at: usize,
    },
    /// A header field out of its range.
    #[error("header field {field} is {found}, out of range")]
    Header {
        /// The field's name.
        field: &'static str,
        /// The value found.
        found: u32,
    },
}

/// How the ground talks to the server board.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Protocol {
    /// The paper's packets: the server board relays (`mmic::node::server::relay`).
    Legacy = 0,
    /// PUS-C: the server board is the gateway (`mmic::node::server::gateway`).
    Pus = 1,
    /// PUS-C behind the space data link (`mmic sim --link frames`): the server board is the
    /// frame gateway (`mmic::node::server::frames`), the ground's bytes are TC transfer frames
    /// and what it sends back TM transfer frames.
    PusFrames = 2,
    /// [`Protocol::PusFrames`] with the link secured by SDLS (`mmic sim --link frames --sdls`):
    /// the TC frames are verified and decrypted, the TM frames protected, under the
    /// [`Header::sdls`] test keys.
    PusFramesSdls = 3,
}

/// The SDLS keys of a [`Protocol::PusFramesSdls`] trace, robot 1's TC and TM keys: **test
/// keys**, made at random for the one simulation run that recorded the trace (`mmic replay
/// --record-scenarios`) and written into it so that a replay verifies and protects the same
/// frames. Never a mission's keys: the engine refuses to record a run whose keys were given
/// (`--sdls-keys`). Never shown: `Debug` prints `TestKeys(..)`.
#[derive(Clone, Copy, PartialEq, Eq)]
pub struct TestKeys {
    tc: [u8; KEY_LEN],
    tm: [u8; KEY_LEN],
}

impl TestKeys {
    /// The keys' octets (made by the recorder for its run).
    pub const fn new(tc: [u8; KEY_LEN], tm: [u8; KEY_LEN]) -> TestKeys {
        TestKeys { tc, tm }
    }

    /// The TC and TM keys.
    pub fn keys(&self) -> (Key256, Key256) {
        (Key256::from_bytes(self.tc), Key256::from_bytes(self.tm))
    }
}

impl core::fmt::Debug for TestKeys {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str("TestKeys(..)")
    }
}

/// The scenario's fixed settings.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Header {
    /// The server board's protocol.
    pub protocol: Protocol,
    /// The robot's number.
    pub board: BoardNumber,
    /// The state the robot starts in.
    pub start: State,
    /// The gateway's timing (used with [`Protocol::Pus`] and [`Protocol::PusFrames`]).
    pub gateway: gateway::Config,
    /// With [`Protocol::PusFramesSdls`] (and only then): the run's SDLS test keys.
    pub sdls: Option<TestKeys>,
}

impl Header {
    /// The frame gateway's settings of a [`Protocol::PusFrames`] trace: the link's defaults
    /// (`spec/ccsds/link.toml`) around the header's gateway timing, as the engine builds it.
    pub fn frame_config(&self) -> FrameConfig {
        FrameConfig {
            gateway: self.gateway,
            ..FrameConfig::default()
        }
    }

    /// Robot 1 in state `a` with the gateway's defaults: the simulator's demo.
    pub fn demo(protocol: Protocol) -> Header {
        Header {
            protocol,
            board: BoardNumber::ONE,
            start: State::A,
            gateway: gateway::Config::default(),
            sdls: None,
        }
    }

    /// Writes the header.
    pub fn emit(&self, out: &mut impl Sink) {
        let g = &self.gateway;
        out.put(MAGIC);
        out.put(&[
            self.protocol as u8,
            self.board.get(),
            self.start.index() as u8,
        ]);
        out.put(&g.uplink.period_ms.to_le_bytes());
        out.put(&g.uplink.timeout_ms.to_le_bytes());
        out.put(&[g.uplink.max_attempts]);
        out.put(&g.poll_ms.to_le_bytes());
        out.put(&g.hk_interval_ms.to_le_bytes());
        out.put(&[u8::from(g.hk_enabled)]);
        if let (Protocol::PusFramesSdls, Some(k)) = (self.protocol, &self.sdls) {
            out.put(&k.tc);
            out.put(&k.tm);
        }
    }

    fn parse(r: &mut Reader<'_>) -> Result<Header, TraceError> {
        if r.take(8)? != MAGIC {
            return Err(TraceError::Magic);
        }
        let protocol = match r.u8()? {
            0 => Protocol::Legacy,
            1 => Protocol::Pus,
            2 => Protocol::PusFrames,
            3 => Protocol::PusFramesSdls,
            p => return Err(header("protocol", p.into())),
        };
        let b = r.u8()?;
        let board = BoardNumber::new(b).map_err(|_| header("board", b.into()))?;
        let s = r.u8()?;
        let start = State::from_index(s.into()).ok_or(header("state", s.into()))?;
        let uplink = uplink::Config {
            period_ms: r.u32()?,
            timeout_ms: r.u32()?,
            max_attempts: r.u8()?,
        };
        let gateway = gateway::Config {
            uplink,
            poll_ms: r.u32()?,
            hk_interval_ms: r.u32()?,
            hk_enabled: r.u8()? != 0,
        };
        let sdls = match protocol {
            Protocol::PusFramesSdls => Some(test_keys(r)?),
            _ => None,
        };
        Ok(Header {
            protocol,
            board,
            start,
            gateway,
            sdls,
        })
    }
}

/// A protocol-3 header's two keys, each refused if [`Key256::check`] would refuse it (the
/// engine could not have secured a link with it: the replay would not either).
fn test_keys(r: &mut Reader<'_>) -> Result<TestKeys, TraceError> {
    let mut key = |field: &'static str| -> Result<[u8; KEY_LEN], TraceError> {
        let b: [u8; KEY_LEN] = r.take(KEY_LEN)?.try_into().map_err(|_| header(field, 0))?;
        match Key256::from_bytes(b).check() {
            Ok(()) => Ok(b),
            Err(_) => Err(header(field, 0)),
        }
    };
    let tc = key("TC key (a weak key)")?;
    let tm = key("TM key (a weak key)")?;
    Ok(TestKeys { tc, tm })
}

fn header(field: &'static str, found: u32) -> TraceError {
    TraceError::Header { field, found }
}

/// One side's readings of one tick: the raw device values (`None`: the device did not
/// answer) and the two switches.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Reading {
    /// ADS7828 codes, IMU accelerations, hip encoder.
    pub raw: Raw,
    /// Arm contraction switch closed.
    pub arm_contracted: bool,
    /// Bolter home switch closed.
    pub bolter_at_home: bool,
}

impl Default for Reading {
    /// No device answered, both switches open.
    fn default() -> Reading {
        Reading {
            raw: Raw {
                adc: None,
                accel: None,
                encoder: None,
            },
            arm_contracted: false,
            bolter_at_home: false,
        }
    }
}

impl Reading {
    fn emit(&self, out: &mut impl Sink) {
        let flags = u8::from(self.raw.adc.is_some())
            | u8::from(self.raw.accel.is_some()) << 1
            | u8::from(self.raw.encoder.is_some()) << 2
            | u8::from(self.arm_contracted) << 3
            | u8::from(self.bolter_at_home) << 4;
        out.put(&[flags]);
        for c in self.raw.adc.iter().flatten() {
            out.put(&c.to_le_bytes());
        }
        for a in self.raw.accel.iter().flatten() {
            out.put(&a.to_le_bytes());
        }
        if let Some(e) = self.raw.encoder {
            out.put(&e.to_le_bytes());
        }
    }

    fn parse(r: &mut Reader<'_>) -> Result<Reading, TraceError> {
        let flags = r.u8()?;
        let adc = if flags & 1 != 0 {
            let mut a = [0u16; 8];
            for c in &mut a {
                *c = r.u16()?;
            }
            Some(a)
        } else {
            None
        };
        let accel = if flags & 2 != 0 {
            let mut a = [0i16; 3];
            for c in &mut a {
                *c = r.u16()? as i16;
            }
            Some(a)
        } else {
            None
        };
        let encoder = if flags & 4 != 0 { Some(r.u16()?) } else { None };
        Ok(Reading {
            raw: Raw {
                adc,
                accel,
                encoder,
            },
            arm_contracted: flags & 8 != 0,
            bolter_at_home: flags & 16 != 0,
        })
    }
}

/// One call into a node, at `t` ms (every variant's `t`); `reading` is the side's sensors of
/// that tick, `bytes` what arrived.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[allow(missing_docs)]
pub enum Record<'a> {
    /// Board A's control task ticks with side A's readings.
    TickA { t: u32, reading: Reading },
    /// Board B ticks with side B's readings.
    TickB { t: u32, reading: Reading },
    /// Bytes from board B reach board A's serial line.
    ToA { t: u32, bytes: &'a [u8] },
    /// Bytes from board A reach board B's serial line.
    ToB { t: u32, bytes: &'a [u8] },
    /// Board A's WiFi task takes the server board's connection.
    WifiOpen { t: u32 },
    /// The server board's connection closes.
    WifiClose { t: u32 },
    /// Command bytes reach board A's WiFi task on the open connection.
    WifiBytes { t: u32, bytes: &'a [u8] },
    /// Board A's WiFi task writes the queued heartbeats (or discards them, unconnected).
    WifiDrain { t: u32 },
    /// Bytes from the ground reach the server board: a PUS packet (or the legacy serial
    /// line's bytes), or a TC transfer frame with [`Protocol::PusFrames`].
    ServerIn { t: u32, bytes: &'a [u8] },
    /// The server board's loop runs (between visits).
    ServerLoop { t: u32 },
    /// Bytes from board A reach the server board during its visit.
    ServerHeartbeat { t: u32, bytes: &'a [u8] },
}

/// Which node a record drives, for the cost tables.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Node {
    /// Board A's control task (core 1): its tick and its serial line.
    AControl = 0,
    /// Board A's WiFi task (core 0).
    AWifi = 1,
    /// Board B: its tick and its serial line.
    B = 2,
    /// The server board: the legacy relay or the PUS gateway.
    Server = 3,
}

impl Node {
    /// Every node, in table order.
    pub const ALL: [Node; 4] = [Node::AControl, Node::AWifi, Node::B, Node::Server];

    /// The node's name in tables.
    pub const fn name(self) -> &'static str {
        match self {
            Node::AControl => "board A control",
            Node::AWifi => "board A WiFi",
            Node::B => "board B",
            Node::Server => "server board",
        }
    }
}

impl Record<'_> {
    /// The record's tag.
    pub const fn tag(&self) -> u8 {
        match self {
            Record::TickA { .. } => 1,
            Record::TickB { .. } => 2,
            Record::ToA { .. } => 3,
            Record::ToB { .. } => 4,
            Record::WifiOpen { .. } => 5,
            Record::WifiClose { .. } => 6,
            Record::WifiBytes { .. } => 7,
            Record::WifiDrain { .. } => 8,
            Record::ServerIn { .. } => 9,
            Record::ServerLoop { .. } => 10,
            Record::ServerHeartbeat { .. } => 11,
        }
    }

    /// The record's time, ms.
    pub const fn t(&self) -> u32 {
        match *self {
            Record::TickA { t, .. }
            | Record::TickB { t, .. }
            | Record::ToA { t, .. }
            | Record::ToB { t, .. }
            | Record::WifiOpen { t }
            | Record::WifiClose { t }
            | Record::WifiBytes { t, .. }
            | Record::WifiDrain { t }
            | Record::ServerIn { t, .. }
            | Record::ServerLoop { t }
            | Record::ServerHeartbeat { t, .. } => t,
        }
    }

    /// The node the record drives.
    pub const fn node(&self) -> Node {
        match self {
            Record::TickA { .. } | Record::ToA { .. } => Node::AControl,
            Record::WifiOpen { .. }
            | Record::WifiClose { .. }
            | Record::WifiBytes { .. }
            | Record::WifiDrain { .. } => Node::AWifi,
            Record::TickB { .. } | Record::ToB { .. } => Node::B,
            Record::ServerIn { .. }
            | Record::ServerLoop { .. }
            | Record::ServerHeartbeat { .. } => Node::Server,
        }
    }

    /// Writes the record.
    pub fn emit(&self, out: &mut impl Sink) {
        out.put(&[self.tag()]);
        out.put(&self.t().to_le_bytes());
        match self {
            Record::TickA { reading, .. } | Record::TickB { reading, .. } => reading.emit(out),
            Record::ToA { bytes, .. }
            | Record::ToB { bytes, .. }
            | Record::WifiBytes { bytes, .. }
            | Record::ServerIn { bytes, .. }
            | Record::ServerHeartbeat { bytes, .. } => {
                let n = u16::try_from(bytes.len()).unwrap_or(u16::MAX);
                out.put(&n.to_le_bytes());
                out.put(bytes.get(..usize::from(n)).unwrap_or(bytes));
            }
            Record::WifiOpen { .. }
            | Record::WifiClose { .. }
            | Record::WifiDrain { .. }
            | Record::ServerLoop { .. } => {}
        }
    }
}

/// A parsed trace: its header and its records' bytes.
#[derive(Debug, Clone, Copy)]
pub struct Trace<'a> {
    /// The settings.
    pub header: Header,
    body: &'a [u8],
    /// Where the body starts in the file ([`HEADER_LEN`], and the keys of a protocol-3 trace).
    offset: usize,
}

impl<'a> Trace<'a> {
    /// Reads the header; the records are read as they are iterated.
    pub fn parse(bytes: &'a [u8]) -> Result<Trace<'a>, TraceError> {
        let mut r = Reader { b: bytes, at: 0 };
        let header = Header::parse(&mut r)?;
        Ok(Trace {
            header,
            body: bytes.get(r.at..).unwrap_or(&[]),
            offset: r.at,
        })
    }

    /// The records, in order; an error ends the iteration.
    pub fn records(&self) -> Records<'a> {
        Records {
            r: Reader {
                b: self.body,
                at: 0,
            },
            failed: false,
            offset: self.offset,
        }
    }
}

/// The records of a [`Trace`].
#[derive(Debug, Clone)]
pub struct Records<'a> {
    r: Reader<'a>,
    failed: bool,
    offset: usize,
}

impl<'a> Iterator for Records<'a> {
    type Item = Result<Record<'a>, TraceError>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.failed || self.r.at >= self.r.b.len() {
            return None;
        }
        let rec = self.read();
        self.failed = rec.is_err();
        Some(rec)
    }
}

impl<'a> Records<'a> {
    fn read(&mut self) -> Result<Record<'a>, TraceError> {
        let r = &mut self.r;
        let at = r.at + self.offset;
        let tag = r.u8()?;
        let t = r.u32()?;
        Ok(match tag {
            1 => Record::TickA {
                t,
                reading: Reading::parse(r)?,
            },
            2 => Record::TickB {
                t,
                reading: Reading::parse(r)?,
            },
            3 => Record::ToA {
                t,
                bytes: r.bytes()?,
            },
            4 => Record::ToB {
                t,
                bytes: r.bytes()?,
            },
            5 => Record::WifiOpen { t },
            6 => Record::WifiClose { t },
            7 => Record::WifiBytes {
                t,
                bytes: r.bytes()?,
            },
            8 => Record::WifiDrain { t },
            9 => Record::ServerIn {
                t,
                bytes: r.bytes()?,
            },
            10 => Record::ServerLoop { t },
            11 => Record::ServerHeartbeat {
                t,
                bytes: r.bytes()?,
            },
            tag => return Err(TraceError::Tag { tag, at }),
        })
    }
}

/// A cursor over little-endian fields.
#[derive(Debug, Clone)]
struct Reader<'a> {
    b: &'a [u8],
    at: usize,
}

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize) -> Result<&'a [u8], TraceError> {
        let end = self.at.saturating_add(n);
        let s = self.b.get(self.at..end).ok_or(TraceError::Truncated {
            at: self.at,
            needed: end - self.b.len().min(end),
        })?;
        self.at = end;
        Ok(s)
    }

    fn u8(&mut self) -> Result<u8, TraceError> {
        Ok(self.take(1)?.first().copied().unwrap_or(0))
    }

    fn u16(&mut self) -> Result<u16, TraceError> {
        let mut a = [0u8; 2];
        a.copy_from_slice(self.take(2)?);
        Ok(u16::from_le_bytes(a))
    }

    fn u32(&mut self) -> Result<u32, TraceError> {
        let mut a = [0u8; 4];
        a.copy_from_slice(self.take(4)?);
        Ok(u32::from_le_bytes(a))
    }

    fn bytes(&mut self) -> Result<&'a [u8], TraceError> {
        let n = self.u16()?;
        self.take(n.into())
    }
}
