//! One robot of the virtual-time engine: its nodes (board A and its WiFi task, board B, the
//! plant, the server board, the ground's end of its link), the queues and readers between
//! them, its six simulated hops, and what its nodes keep across a restart.

use super::agenda::Hop;
use super::attacker::Attacker;
use super::link::{Link, LinkModel};
use crate::sim::durable::{self, Durable};
use crate::sim::plant::Plant;
use crate::sim::shell::{SideA, SideB};
use crate::sim::{FrameStats, LinkLayer, PlantConfig, Protocol, SdlsConfig, SimConfig};
use mmic::link::sdls::Key256;
use mmic::node::ground::frames::GroundLink;
use mmic::node::robot::board_a::{self, BoardA, Durable as KeptA};
use mmic::node::robot::board_b::{self, BoardB};
use mmic::node::robot::handoff::PacketQueue;
use mmic::node::robot::wifi_session::{WifiConfig, WifiSession};
use mmic::node::server::gateway::{Gateway, Kept};
use mmic::node::server::relay::Server;
use mmic::node::server::visit::Visit;
use mmic::units::BoardNumber;
use mmic::wire::b_command::B_COMMAND_LEN;
use mmic::wire::command::COMMAND_LEN;
use mmic::wire::deframer::Deframer;
use mmic::wire::heartbeat::HEARTBEAT_LEN;
use mmic::wire::internal_heartbeat::INTERNAL_HEARTBEAT_LEN;
use std::collections::VecDeque;

/// One robot, eight waiting telecommands, 64 remembered keys (as the realtime engine's).
pub(super) type SimGateway = Gateway<1, 8, 64>;

/// The PUS gateway behind the space data link (`--link frames`): the same sizes, 4 KiB of
/// TM packets waiting for frames. The replay's own type (`mmic_replay::ReplayFrameGateway`),
/// so that a recorded trace replays with the same sizes.
pub(super) type SimFrameGateway = mmic_replay::ReplayFrameGateway;

/// The ground's end of a robot's space data link: FOP-1's window K = 10, 64 packets waiting,
/// packets of up to 1 KiB reassembled.
pub(super) type SimGroundLink = GroundLink<10, 64, 1024>;

/// The commands a gateway's tick hands to the robots (one robot here).
pub(super) type Visits = heapless::Vec<(BoardNumber, mmic::wire::command::CommandRepr), 1>;

/// Marks the copy of a duplicated packet in its delivery's connection number (connection
/// numbers count up from 1 and stay far below this bit).
pub(super) const DUPLICATE: u64 = 1 << 63;

/// The server board's logic: the legacy relay, the PUS gateway, or the PUS gateway behind the
/// space data link.
pub(super) enum Board {
    Relay(Server<4>),
    Gateway(Box<SimGateway>),
    Frames(Box<SimFrameGateway>),
}

/// One robot's nodes and links.
pub(super) struct Robot {
    pub(super) number: BoardNumber,
    pub(super) names: [String; 4],
    pub(super) a: SideA,
    pub(super) b: SideB,
    pub(super) plant: Plant,
    pub(super) commands: PacketQueue<COMMAND_LEN, 8>,
    pub(super) heartbeats: PacketQueue<HEARTBEAT_LEN, 8>,
    /// Board A's serial reader (from board B) and what it has deframed.
    pub(super) a_reader: Deframer<256>,
    pub(super) a_from_b: VecDeque<[u8; INTERNAL_HEARTBEAT_LEN]>,
    /// Board B's serial reader (from board A).
    pub(super) b_reader: Deframer<256>,
    pub(super) b_from_a: VecDeque<[u8; B_COMMAND_LEN]>,
    pub(super) b_lost: bool,
    /// Board A's WiFi task (the library's session) and its open connection's number.
    pub(super) wifi: WifiSession,
    pub(super) wifi_conn: u64,
    /// The server board's logic: reached through [`Robot::board_mut`], which marks it for
    /// [`Robot::persist`].
    board: Board,
    /// The server board changed since [`Robot::persist`] last wrote all it asked to keep.
    board_changed: bool,
    /// The server board's visit in progress: its connection's number, the library's visit.
    pub(super) visit: Option<(u64, Visit)>,
    /// Packets from the ground waiting for the server board's loop.
    pub(super) inbox: VecDeque<Vec<u8>>,
    pub(super) server_reader: Deframer<256>,
    /// The gateway's next wake, and its token (a wake with an older token is stale).
    pub(super) server_wake: Option<(u64, u64)>,
    /// The ground's reader of this robot's serial line (legacy).
    pub(super) ground_reader: Deframer<256>,
    /// The ground's end of the space data link (`--link frames`).
    pub(super) ground_link: Option<Box<SimGroundLink>>,
    pub(super) links: [Link; 6],
    /// The durable store of both ends (`sim::durable`): SDLS counters, FARM-1's progress, the
    /// kept telecommand keys behind frames. Memory for the run, or with given keys the state
    /// file: a server board or ground that starts again boots from it.
    pub(super) store: Durable,
    /// With SDLS and an attacker: the attacker on the uplink.
    pub(super) attacker: Option<Attacker>,
    /// Board A's flash: its exactly-once log and boot count (decision `restart-board-a`).
    pub(super) kept_a: Option<KeptA>,
    /// The server board's flash without frames: its PUS gateway's newest TC key per source
    /// (`restart-server`; behind frames they are in `store`).
    pub(super) kept_server: Kept,
    /// With SDLS: the robot's (TC, TM) keys, as provisioned in the server board's image.
    pub(super) keys: Option<(Key256, Key256)>,
    /// Board A, board B, the server board: down (restarting) until their `Up` event.
    pub(super) down: [bool; 4],
    /// The restarts of each node so far.
    pub(super) restarts: [u32; 4],
    /// The space data link's figures of the ends' earlier lives (a restarted end counts
    /// from 0 again).
    pub(super) past_frames: FrameStats,
}

/// Robot `i`'s six hops (ground to server and back, server to board A and back, A to B and
/// back), each with its own seeded stream.
fn links(cfg: &SimConfig, seed: u64) -> [Link; 6] {
    let mut ab = cfg.links.ab.clone();
    if let Some(t) = cfg.cut_b_at {
        ab.cuts.push((t, None));
    }
    let link = |model: &LinkModel, loss: f64, k: u64, stream: bool| {
        Link::new(
            model.clone(),
            loss,
            seed.wrapping_add(k * 7919) ^ 0x11_4c_5e_ed,
            stream,
        )
    };
    let ground_stream = cfg.protocol == Protocol::Legacy;
    // With SDLS the uplink keeps order under jitter, as a space link does: the receiver's
    // anti-replay window takes only IVs above the last accepted one, so a datagram link
    // that lets frames sent together overtake each other would refuse the earlier ones as
    // replays, and FOP-1's go-back-N, sending its window again under fresh IVs each time,
    // could find it shuffled every round (seen: 590 TC frames for 14 accepted). The
    // reordering fault model (a frame held back) still applies.
    let secured = cfg.sdls.is_some() && cfg.link == LinkLayer::Frames;
    [
        link(
            &cfg.links.ground,
            cfg.serial_loss,
            4,
            ground_stream || secured,
        ),
        link(&cfg.links.ground, cfg.serial_loss, 3, ground_stream),
        link(&cfg.links.wifi, cfg.wifi_loss, 5, true),
        link(&cfg.links.wifi, cfg.wifi_loss, 6, true),
        link(&ab, cfg.ab_loss, 1, true),
        link(&ab, cfg.ab_loss, 2, true),
    ]
}

/// Robot `i`'s space data link with SDLS: its keys and store, the ground's end secured, and
/// the attacker on its uplink if the run has one.
fn secure(
    cfg: &SimConfig,
    sdls: &SdlsConfig,
    i: usize,
    state: Option<&Durable>,
    ground_link: &mut Option<Box<SimGroundLink>>,
) -> std::io::Result<((Key256, Key256), Durable, Option<Attacker>)> {
    let number = board_number(i);
    let seed = cfg.seed.wrapping_mul(1000).wrapping_add(i as u64);
    // Made once: both ends (and the server board after a restart, as from its flash)
    // share them. Keys that cannot be made stop the run (never a link in clear).
    let (keys, store) = sdls.robot(cfg.seed, i, state)?;
    let mut attacker = None;
    if let Some(gl) = ground_link {
        durable::boot_ground(gl, number, &store, keys.clone())?;
        attacker = (sdls.attack > 0.0).then(|| Attacker::new(sdls.attack, seed));
    }
    Ok((keys, store, attacker))
}

impl Robot {
    pub(super) fn new(
        cfg: &SimConfig,
        i: usize,
        state: Option<&Durable>,
    ) -> std::io::Result<Robot> {
        let number = board_number(i);
        let seed = cfg.seed.wrapping_mul(1000).wrapping_add(i as u64);
        let mut plant = Plant::new(
            PlantConfig {
                seed,
                ..cfg.plant.clone()
            },
            cfg.start_state,
        );
        plant.set_shortcuts(cfg.shortcuts);
        let frames = cfg.protocol == Protocol::Pus && cfg.link == LinkLayer::Frames;
        let mut ground_link = frames.then(|| Box::new(SimGroundLink::new(number)));
        let (keys, store, attacker) = match cfg.sdls.as_ref().filter(|_| frames) {
            Some(s) => {
                let (k, d, a) = secure(cfg, s, i, state, &mut ground_link)?;
                (Some(k), d, a)
            }
            None => (None, Durable::memory(), None),
        };
        let board = server_board(cfg, number, None, &store, keys.clone())?;
        let a = BoardA::in_state(board_a_config(number), cfg.start_state);
        let mut r = Robot::with(number, i, SideA::new(a), plant, board, links(cfg, seed));
        r.ground_link = ground_link;
        r.store = store;
        r.attacker = attacker;
        r.keys = keys;
        r.persist();
        Ok(r)
    }

    /// Robot `i` with these nodes, everything else as at power-on.
    fn with(
        number: BoardNumber,
        i: usize,
        a: SideA,
        plant: Plant,
        board: Board,
        links: [Link; 6],
    ) -> Robot {
        Robot {
            number,
            names: [
                format!("board_a{}", i + 1),
                format!("board_b{}", i + 1),
                format!("server{}", i + 1),
                "ground".to_string(),
            ],
            a,
            b: SideB::new(BoardB::new(board_b::Config::default())),
            plant,
            commands: PacketQueue::new(),
            heartbeats: PacketQueue::new(),
            a_reader: Deframer::new(),
            a_from_b: VecDeque::new(),
            b_reader: Deframer::new(),
            b_from_a: VecDeque::new(),
            b_lost: false,
            wifi: WifiSession::new(WifiConfig::default()),
            wifi_conn: 0,
            board,
            board_changed: true,
            visit: None,
            inbox: VecDeque::new(),
            server_reader: Deframer::new(),
            server_wake: None,
            ground_reader: Deframer::new(),
            ground_link: None,
            links,
            store: Durable::memory(),
            attacker: None,
            kept_a: None,
            kept_server: Kept::new(),
            keys: None,
            down: [false; 4],
            restarts: [0; 4],
            past_frames: FrameStats::default(),
        }
    }

    /// The server board's logic, to read.
    pub(super) fn board(&self) -> &Board {
        &self.board
    }

    /// The server board's logic, to call: it may then have something to keep.
    pub(super) fn board_mut(&mut self) -> &mut Board {
        self.board_changed = true;
        &mut self.board
    }

    /// The server board after a restart.
    pub(super) fn set_board(&mut self, board: Board) {
        *self.board_mut() = board;
    }

    /// The gateway's tick behind frames, with what it asks kept written first; a telecommand
    /// held until the store says so leaves in this pass (`durable::tick_gateway`). None
    /// without frames.
    pub(super) fn tick_frames(&mut self, now: u32) -> Option<Visits> {
        self.board_changed = true;
        match &mut self.board {
            Board::Frames(g) => Some(durable::tick_gateway(g, &self.store, now)),
            _ => None,
        }
    }

    /// Writes what both ends ask to keep to the store and confirms it (memory: at once; a
    /// state file: flushed to the disk first). The server board is asked only if it was
    /// called (or had something written) since it last had nothing to keep: what it asks is a
    /// function of its state alone, so the answer would be the same nothing.
    pub(super) fn persist(&mut self) {
        if self.board_changed {
            let kept = match &self.board {
                Board::Gateway(g) => g.kept(self.number),
                Board::Frames(g) => g.kept(self.number),
                Board::Relay(_) => None,
            };
            if let Some(k) = kept {
                self.kept_server = k;
            }
            self.board_changed = match &mut self.board {
                // Written: asked again at the next call, which finds nothing more due.
                Board::Frames(g) => durable::write_due(g, &self.store) != Some(0),
                _ => false,
            };
        }
        if let Some(gl) = &mut self.ground_link {
            durable::persist_ground(gl, &self.store);
        }
    }

    /// The server board goes down: its space data link figures join its earlier lives'.
    pub(super) fn keep_server_figures(&mut self) {
        if let Board::Frames(g) = &self.board {
            self.past_frames.add_server(g, self.number);
        }
    }

    /// This robot's space data link figures, over every life of both ends.
    pub(super) fn frames(&self) -> FrameStats {
        let mut s = self.past_frames;
        if let Some(gl) = &self.ground_link {
            s.add_ground(gl);
        }
        if let Board::Frames(g) = &self.board {
            s.add_server(g, self.number);
        }
        s
    }

    /// A hop's link name and its two ends' names in the log (as the realtime engine names them).
    pub(super) fn ends(&self, hop: Hop, protocol: Protocol) -> (&'static str, &str, &str) {
        let ground_link = match protocol {
            Protocol::Legacy => "serial_ground",
            Protocol::Pus => "udp_ground",
        };
        let [a, b, s, _] = &self.names;
        match hop {
            Hop::GroundToServer => (ground_link, "ground", s),
            Hop::ServerToGround => (ground_link, s, "ground"),
            Hop::ServerToA => ("wifi", s, a),
            Hop::AToServer => ("wifi", a, s),
            Hop::AToB => ("serial_ab", a, b),
            Hop::BToA => ("serial_ab", b, a),
        }
    }
}

/// Robot `i`'s board number: 1..=255 by index (each robot has its own server board, so
/// numbers may repeat in a larger fleet: they only need to match between a robot's ground
/// runner, server board and board A).
pub(super) fn board_number(i: usize) -> BoardNumber {
    BoardNumber::new((i % 255) as u8 + 1).unwrap_or(BoardNumber::ONE)
}

/// Board A's configuration as robot `number`.
pub(super) fn board_a_config(number: BoardNumber) -> board_a::Config {
    board_a::Config {
        board: number,
        ..board_a::Config::default()
    }
}

/// Robot `i`'s server board as it starts: at power-on, or after a restart from what its flash
/// kept (behind frames `store`: the kept telecommand keys, FARM-1's progress, the SDLS
/// counters; the PUS gateway over packets its `kept` keys).
pub(super) fn server_board(
    cfg: &SimConfig,
    number: BoardNumber,
    kept: Option<Kept>,
    store: &Durable,
    keys: Option<(Key256, Key256)>,
) -> Result<Board, durable::BootError> {
    Ok(match cfg.protocol {
        Protocol::Legacy => Board::Relay(Server::new()),
        Protocol::Pus if cfg.link == LinkLayer::Frames => {
            Board::Frames(durable::boot_gateway(cfg.gateway, number, store, keys)?)
        }
        Protocol::Pus => {
            let mut g = Box::new(SimGateway::new(cfg.gateway));
            match kept {
                Some(k) => g.add_restarted(number, k),
                None => g.add(number),
            };
            Board::Gateway(g)
        }
    })
}
