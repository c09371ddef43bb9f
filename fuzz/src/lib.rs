//! Coverage-guided fuzz targets for mmic's four parsers and its deframer (and the CCSDS layers'
//! parsers, services and COP-1), and their seed corpus.
//!
//! The targets are the bolero tests in `tests/targets.rs`; the properties they check are the
//! functions of `mmic-proofs`, shared with the proof harnesses. Under plain `cargo test` each
//! target runs for a second on random inputs and replays its committed seed corpus
//! (`tests/__fuzz__/<target>/corpus/`); under `cargo bolero test` it is fuzzed with libFuzzer.
//! See `fuzz/README.md` for the commands.
//!
//! This library generates that seed corpus: valid packets and near misses (one length, header,
//! checksum or field check away from valid) for each parser, and short streams for the
//! deframer. `cargo run -p mmic-fuzz --bin mmic-fuzz-seeds` writes them; the test
//! `tests/seeds.rs` fails when the committed files differ from what [`seeds`] generates.
//!
//! ```
//! let seeds = mmic_fuzz::seeds();
//! assert!(mmic_fuzz::TARGETS.iter().all(|t| seeds.iter().any(|s| s.target == *t)));
//! ```

use mmic::bolter::{BolterDirection, BolterStep};
use mmic::ccsds::cuc::Cuc;
use mmic::ccsds::primary::{Apid, PacketType, SeqCount};
use mmic::ccsds::tc::TcRepr;
use mmic::ccsds::tc_header::{AckFlags, TcSecondaryHeader};
use mmic::ccsds::tm::TmRepr;
use mmic::ccsds::tm_header::TmSecondaryHeader;
use mmic::command::{BolterPair, Command, HipTarget, PowerTarget, ServoTarget};
use mmic::mode::Mode;
use mmic::motion::{Primitive, State};
use mmic::units::{BoardNumber, HipAngle, Module, PulseWidth, Side};
use mmic::wire::b_command::{BCommandRepr, BolterOrder};
use mmic::wire::command::CommandRepr;
use mmic::wire::heartbeat::HeartbeatRepr;
use mmic::wire::internal_heartbeat::InternalHeartbeatRepr;
use mmic::wire::PacketKind;
use mmic_proofs::seal;

/// The fuzz targets, one per parser and one for the deframer (test names in
/// `tests/targets.rs`, and the names `cargo bolero test` takes).
pub const TARGETS: [&str; 20] = [
    "command_parser",
    "heartbeat_parser",
    "internal_heartbeat_parser",
    "b_command_parser",
    "deframer_stream",
    "pus_tc_parser",
    "pus_tm_parser",
    "pus_request",
    "pus_housekeeping",
    "pus_verification",
    "tm_frame_parser",
    "tm_extractor",
    "tc_frame_parser",
    "link_clcw",
    "link_cop",
    "sdls_tc_verify",
    "sdls_tm_verify",
    "pus_event",
    "server_store",
    "cfdp_pdu",
];

/// Target name of the CCSDS/PUS parser for `kind`.
pub fn pus_target(kind: PacketType) -> &'static str {
    match kind {
        PacketType::Tc => TARGETS[5],
        PacketType::Tm => TARGETS[6],
    }
}

/// Seeds of `pus_request`: service, subservice and application data of a valid request of
/// each kind, and near misses (one argument out of range, one octet short).
pub fn pus_requests() -> Vec<(&'static str, Vec<u8>)> {
    let mut out = vec![
        ("are-you-alive", vec![17, 1]),
        ("hk-enable", vec![3, 5, 1, 1]),
        ("hk-interval", vec![3, 31, 1, 1, 0, 0, 0x03, 0xE8]),
        ("hk-interval-too-short", vec![3, 31, 1, 1, 0, 0, 0, 50]),
        ("unknown-service", vec![9, 1]),
    ];
    let commands = [
        ("stop", Command::Stop),
        (
            "arm-position",
            Command::Arm {
                side: Side::B,
                target: ServoTarget::Position(PulseWidth::CENTER),
            },
        ),
        (
            "hip-angle",
            Command::Hip(HipTarget::Angle(HipAngle::wrapping(4500))),
        ),
        (
            "reconfigure",
            Command::reconfigure(State::A, State::M).expect("matched"),
        ),
        (
            "power",
            Command::Power {
                target: PowerTarget::Module(Module::BolterB),
                on: true,
            },
        ),
        ("mode", Command::Mode(Mode::Operational)),
    ];
    for (name, c) in commands {
        let mut buf = [0u8; mmic::pus::function::MAX_LEN];
        let n = mmic::pus::function::encode(&c, &mut buf).expect("a function");
        let mut v = vec![8, 1];
        v.extend_from_slice(&buf[..n]);
        out.push((name, v.clone()));
        v.pop();
        out.push((
            match name {
                "stop" => "stop-no-id",
                "arm-position" => "arm-position-short",
                "hip-angle" => "hip-angle-short",
                "reconfigure" => "reconfigure-short",
                "power" => "power-short",
                _ => "mode-short",
            },
            v,
        ));
    }
    out
}

/// Valid PUS packets, named: a telecommand and a telemetry packet without and with user data.
pub fn valid_pus_packets() -> Vec<(PacketType, &'static str, Vec<u8>)> {
    let apid = Apid::new(0x042).expect("11 bits");
    let tc = |name, seq, service, subservice, app_data: &[u8]| {
        let r = TcRepr {
            apid,
            seq_count: SeqCount::new(seq).expect("14 bits"),
            header: TcSecondaryHeader {
                ack: AckFlags::ALL,
                service,
                subservice,
                source_id: 1,
            },
            app_data,
        };
        let mut out = vec![0u8; r.len()];
        r.emit(&mut out).expect("fits");
        (PacketType::Tc, name, out)
    };
    let tm = |name, seq, service, subservice, source_data: &[u8]| {
        let r = TmRepr {
            apid,
            seq_count: SeqCount::new(seq).expect("14 bits"),
            header: TmSecondaryHeader {
                time_ref_status: Default::default(),
                service,
                subservice,
                counter: seq,
                destination_id: 1,
                time: Cuc::from_millis(90_500),
            },
            source_data,
        };
        let mut out = vec![0u8; r.len()];
        r.emit(&mut out).expect("fits");
        (PacketType::Tm, name, out)
    };
    vec![
        tc("tc-17-1-ping", 7, 17, 1, &[]),
        tc("tc-8-1-function", 8, 8, 1, &[0x60, b'm', b'a']),
        tm("tm-17-2-alive", 9, 17, 2, &[]),
        tm("tm-3-25-housekeeping", 10, 3, 25, &[1, 2, 3, 4, 5, 6, 7, 8]),
    ]
}

/// The near misses of each valid PUS packet: name suffix, the check that must refuse it, and
/// the octets.
pub fn pus_near_misses(packet: &[u8]) -> Vec<(&'static str, &'static str, Vec<u8>)> {
    let n = packet.len();
    let with = |at: usize, f: &dyn Fn(u8) -> u8| {
        let mut b = packet.to_vec();
        b[at] = f(b[at]);
        mmic_proofs::ccsds::reseal(&mut b);
        b
    };
    let mut long = packet.to_vec();
    long.push(0);
    let mut checksum = packet.to_vec();
    checksum[n - 1] ^= 0x01;
    let mut apid = packet.to_vec();
    apid[1] ^= 0x01;
    mmic_proofs::ccsds::reseal(&mut apid);
    vec![
        ("-truncated", "truncated", packet[..7].to_vec()),
        ("-version-miss", "version", with(0, &|b| b | 0x20)),
        ("-type-miss", "packet-type", with(0, &|b| b ^ 0x10)),
        ("-segment-miss", "sequence-flags", with(2, &|b| b & 0x3f)),
        ("-long", "length", long),
        ("-pus-a", "pus-version", with(6, &|b| (b & 0x0f) | 0x10)),
        ("-checksum-miss", "checksum", checksum),
        ("-apid-miss", "apid", apid),
    ]
}

/// Seeds of `tc_frame_parser`: frames of `mmic_proofs::link::CONFIGS[0]`'s channel
/// (spacecraft 0x101, VC 0, MAP 0, FECF): AD and BD frames carrying the TC(17,1) ping, BC
/// Unlock and BC Set V(R) = 5, and for the AD frame one near miss per check of
/// `TcFrameError::NAMES`, named after it (the length field and FECF rewritten where the defect
/// is before them). The check each must fail, or `None` for the valid ones.
pub fn tc_frame_seeds() -> Vec<(String, Option<&'static str>, Vec<u8>)> {
    use mmic::link::tc_frame::{MapId, SpacecraftId, TcContent, TcFrameRepr, Vcid};
    use mmic::link::ControlCommand;
    use mmic_proofs::link::reseal;
    let ping = valid_pus_packets()
        .into_iter()
        .find(|(_, name, _)| *name == "tc-17-1-ping")
        .map(|(_, _, b)| b)
        .expect("the ping");
    let map_id = Some(MapId::new(0).expect("6 bits"));
    let frame = |content| {
        let r = TcFrameRepr {
            spacecraft_id: SpacecraftId::new(0x101).expect("10 bits"),
            vcid: Vcid::new(0).expect("6 bits"),
            seq: 0,
            content,
        };
        let mut out = vec![0u8; r.len()];
        r.emit(&mut out).expect("fits");
        out
    };
    let ad = frame(TcContent::Ad {
        map_id,
        data: &ping,
    });
    let mut out = vec![
        ("ad-ping".to_string(), None, ad.clone()),
        (
            "bd-ping".to_string(),
            None,
            frame(TcContent::Bd {
                map_id,
                data: &ping,
            }),
        ),
        (
            "bc-unlock".to_string(),
            None,
            frame(TcContent::Bc(ControlCommand::Unlock)),
        ),
        (
            "bc-set-vr-5".to_string(),
            None,
            frame(TcContent::Bc(ControlCommand::SetVr(5))),
        ),
    ];
    let with = |at: usize, f: &dyn Fn(u8) -> u8| {
        let mut b = ad.clone();
        b[at] = f(b[at]);
        reseal(&mut b, true);
        b
    };
    let mut long = ad.clone();
    long.push(0);
    let mut too_long = ad.clone();
    too_long.splice(6..6, [0u8; 44]);
    reseal(&mut too_long, true);
    let mut fecf = ad.clone();
    *fecf.last_mut().expect("non-empty") ^= 0x01;
    let mut bc = frame(TcContent::Bc(ControlCommand::SetVr(5)));
    bc[6] = 0x01;
    reseal(&mut bc, true);
    let mut cut = ad.clone();
    cut.remove(18);
    reseal(&mut cut, true);
    let misses: [(&str, Vec<u8>); 13] = [
        ("truncated", ad[..7].to_vec()),
        ("version", with(0, &|b| b | 0x40)),
        ("flags", with(0, &|b| b | 0x10)),
        ("spare", with(0, &|b| b | 0x08)),
        ("length", long),
        ("too-long", too_long),
        ("fecf", fecf),
        ("spacecraft-id", with(1, &|b| b ^ 0x03)),
        ("vcid", with(2, &|b| b | 0x08)),
        ("sequence-flags", with(5, &|b| b & 0x3f)),
        ("map-id", with(5, &|b| b | 0x01)),
        ("control-command", bc),
        ("packet-boundary", cut),
    ];
    for (check, bytes) in misses {
        out.push((format!("ad-ping-{check}"), Some(check), bytes));
    }
    out
}

/// One seed file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SeedFile {
    /// Target it belongs to (one of [`TARGETS`]).
    pub target: &'static str,
    /// File name in the target's corpus directory.
    pub name: String,
    /// Contents.
    pub bytes: Vec<u8>,
}

/// Target name of the parser for `kind`.
pub fn parser_target(kind: PacketKind) -> &'static str {
    match kind {
        PacketKind::Command => TARGETS[0],
        PacketKind::Heartbeat => TARGETS[1],
        PacketKind::InternalHeartbeat => TARGETS[2],
        PacketKind::BCommand => TARGETS[3],
    }
}

fn pw(us: u16) -> PulseWidth {
    PulseWidth::new(us).expect("valid pulse width")
}

/// Valid packets of every kind, named.
pub fn valid_packets() -> Vec<(PacketKind, &'static str, Vec<u8>)> {
    let board = BoardNumber::new(7).expect("valid board");
    let cmd = |name, command| {
        (
            PacketKind::Command,
            name,
            CommandRepr {
                board,
                command,
                seq: 0,
            }
            .to_bytes()
            .to_vec(),
        )
    };
    vec![
        cmd("stop", Command::Stop),
        cmd("mode-operational", Command::Mode(Mode::Operational)),
        cmd(
            "arm-b-1200us",
            Command::Arm {
                side: Side::B,
                target: ServoTarget::Position(pw(1200)),
            },
        ),
        cmd(
            "gripper-a-extend",
            Command::Gripper {
                side: Side::A,
                target: ServoTarget::Extend,
            },
        ),
        cmd(
            "hip-angle-35999",
            Command::Hip(HipTarget::Angle(HipAngle::new(35999).expect("valid angle"))),
        ),
        // Primitive 7 (backTurnCW) from e reaches a or d: byte 8 names d.
        cmd(
            "primitive-7-to-d",
            Command::primitive(Primitive::BackTurnCw, State::D).expect("valid primitive command"),
        ),
        cmd(
            "reconfigure-h-to-n",
            Command::reconfigure(State::H, State::N).expect("valid reconfiguration"),
        ),
        cmd(
            "power-off-bolter-b",
            Command::Power {
                target: PowerTarget::Module(Module::BolterB),
                on: false,
            },
        ),
        (
            PacketKind::Heartbeat,
            "default",
            HeartbeatRepr::default().to_bytes().to_vec(),
        ),
        (
            PacketKind::InternalHeartbeat,
            "default",
            InternalHeartbeatRepr::default().to_bytes().to_vec(),
        ),
        (
            PacketKind::BCommand,
            "unbolt-pair-3-rotate",
            BCommandRepr {
                seq: 42,
                power: Default::default(),
                stop: false,
                arm_target: pw(1800),
                gripper_target: pw(2200),
                bolter: Some(BolterOrder {
                    pair: BolterPair::P3,
                    direction: BolterDirection::Unbolt,
                    step: BolterStep::Rotate,
                }),
            }
            .to_bytes()
            .to_vec(),
        ),
    ]
}

/// A byte of each packet whose value is out of its field's domain when set to `value`: the
/// field near misses (the checksum is rewritten, so only the field check fails).
fn field_miss(kind: PacketKind) -> (usize, u8) {
    use core::mem::offset_of;
    use mmic::wire::{
        b_command::BCommandPacket, command::CommandPacket, heartbeat::HeartbeatPacket,
        internal_heartbeat::InternalHeartbeatPacket,
    };
    match kind {
        // Opcode 0: unassigned.
        PacketKind::Command => (offset_of!(CommandPacket, command), 0x00),
        // Mode 0: no mode.
        PacketKind::Heartbeat => (offset_of!(HeartbeatPacket, mode), 0x00),
        // Arm contracted 2: not a boolean.
        PacketKind::InternalHeartbeat => (offset_of!(InternalHeartbeatPacket, arm_contracted), 2),
        // Flags: undefined bit 5.
        PacketKind::BCommand => (offset_of!(BCommandPacket, flags), 0x20),
    }
}

/// Every seed file of every target.
pub fn seeds() -> Vec<SeedFile> {
    let mut out = Vec::new();
    let valid = valid_packets();
    for (kind, name, bytes) in &valid {
        let target = parser_target(*kind);
        let mut push = |suffix: &str, bytes: Vec<u8>| {
            out.push(SeedFile {
                target,
                name: format!("{name}{suffix}"),
                bytes,
            })
        };
        push("", bytes.clone());
        // Checksum near miss: the last bit of the checksum flipped.
        let mut b = bytes.clone();
        *b.last_mut().expect("non-empty") ^= 0x01;
        push("-checksum-miss", b);
        // Header near miss: the next kind's header.
        let other = PacketKind::ALL[(PacketKind::ALL
            .iter()
            .position(|k| k == kind)
            .expect("kind")
            + 1)
            % 4];
        let mut b = bytes.clone();
        b[..4].copy_from_slice(&other.header());
        push("-header-miss", b);
        // Length near misses: one byte short, one byte long.
        push("-short", bytes[..bytes.len() - 1].to_vec());
        let mut b = bytes.clone();
        b.push(0);
        push("-long", b);
        // Field near miss, with a correct checksum.
        let (at, value) = field_miss(*kind);
        let mut b = bytes.clone();
        b[at] = value;
        seal(*kind, &mut b);
        push("-field-miss", b);
    }
    for (kind, name, bytes) in valid_pus_packets() {
        let target = pus_target(kind);
        out.push(SeedFile {
            target,
            name: name.to_string(),
            bytes: bytes.clone(),
        });
        for (suffix, _, b) in pus_near_misses(&bytes) {
            out.push(SeedFile {
                target,
                name: format!("{name}{suffix}"),
                bytes: b,
            });
        }
    }
    // The services layer: service, subservice, then the application data.
    for (name, bytes) in pus_requests() {
        out.push(SeedFile {
            target: TARGETS[7],
            name: name.to_string(),
            bytes,
        });
    }
    // TM(3,25) source data: the report of a heartbeat, and one field out of range.
    let mut hk = [0u8; mmic::pus::housekeeping::REPORT_LEN];
    mmic::pus::housekeeping::emit(&HeartbeatRepr::default(), &mut hk);
    out.push(SeedFile {
        target: TARGETS[8],
        name: "default-heartbeat".into(),
        bytes: hk.to_vec(),
    });
    let mut bad = hk;
    bad[2] = 9; // mode 9
    out.push(SeedFile {
        target: TARGETS[8],
        name: "mode-out-of-range".into(),
        bytes: bad.to_vec(),
    });
    // TM(1,x): the subservice, then the source data of a success and a failure report.
    for (name, sub, failure) in [
        ("completion-success", 7u8, None),
        ("start-failure", 4, Some(6u8)),
    ] {
        let r = mmic::pus::verification::Report {
            stage: if sub == 7 {
                mmic::pus::verification::Stage::Completion
            } else {
                mmic::pus::verification::Stage::Start
            },
            request: mmic::pus::verification::RequestId {
                apid: 0x101,
                seq_count: 9,
            },
            failure: failure.map(mmic::pus::verification::Failure::refusal),
        };
        let mut b = [0u8; mmic::pus::verification::FAILURE_LEN];
        let n = r.emit(&mut b);
        let mut v = vec![sub];
        v.extend_from_slice(&b[..n]);
        out.push(SeedFile {
            target: TARGETS[9],
            name: name.into(),
            bytes: v,
        });
    }
    // TM(5,x): the severity, then the source data of an event of each kind, and near misses.
    for (name, e) in [
        (
            "mode-changed",
            mmic::pus::event::Event::ModeChanged {
                from: mmic::mode::Mode::Standby,
                to: mmic::mode::Mode::Operational,
            },
        ),
        (
            "security",
            mmic::pus::event::Event::Security {
                reason: 5,
                refused: 3,
                spi: 0x101,
            },
        ),
    ] {
        let mut v = vec![e.severity()];
        v.extend_from_slice(&e.to_bytes());
        out.push(SeedFile {
            target: TARGETS[17],
            name: name.into(),
            bytes: v.clone(),
        });
        v[0] = 4 - (v[0] % 4); // another severity
        out.push(SeedFile {
            target: TARGETS[17],
            name: format!("{name}-wrong-severity"),
            bytes: v,
        });
    }
    for (name, _, bytes) in tc_frame_seeds() {
        out.push(SeedFile {
            target: TARGETS[12],
            name,
            bytes,
        });
    }
    out.extend(tm_seeds());
    out.extend(sdls_seeds());
    out.extend(store_seeds());
    out.extend(cfdp_seeds());
    // Deframer: 4 bytes of chunk plan (chunk sizes 1 + b % 70), then the stream.
    let packet = |k: PacketKind| {
        valid
            .iter()
            .find(|(kind, _, _)| *kind == k)
            .map(|(_, _, b)| b.clone())
            .expect("a valid packet of each kind")
    };
    let cmd = packet(PacketKind::Command);
    let mut streams: Vec<(&str, Vec<u8>)> = Vec::new();
    let mut s = b"\x00junk".to_vec();
    s.extend_from_slice(&cmd);
    streams.push(("garbage-then-command", s));
    let mut s = Vec::new();
    for k in PacketKind::ALL {
        s.extend_from_slice(&packet(k));
    }
    streams.push(("all-four-back-to-back", s));
    let mut s = b"MIHB".to_vec();
    s.extend_from_slice(&[0xaa; 7]);
    s.extend_from_slice(&cmd);
    streams.push(("false-header-hides-command", s));
    let mut s = cmd.clone();
    *s.last_mut().expect("non-empty") ^= 0x80;
    s.extend_from_slice(&cmd);
    s.extend_from_slice(b"MI");
    streams.push(("bad-checksum-good-packet-header-prefix", s));
    // A header's first three bytes right before a packet: with the packet's first byte they
    // form a false header, and the packet starts inside it.
    let mut s = b"MIC".to_vec();
    s.extend_from_slice(&cmd);
    s.extend_from_slice(b"MI");
    s.extend_from_slice(&packet(PacketKind::InternalHeartbeat));
    streams.push(("partial-header-then-packet", s));
    for (name, stream) in streams {
        for (plan_name, plan) in [
            ("one-read", [69u8, 69, 69, 69]),
            ("bytewise", [0, 0, 0, 0]),
            ("mixed", [4, 12, 1, 30]),
        ] {
            let mut bytes = plan.to_vec();
            bytes.extend_from_slice(&stream);
            out.push(SeedFile {
                target: TARGETS[4],
                name: format!("{name}-{plan_name}"),
                bytes,
            });
        }
    }
    // The CLCW: valid words and one near miss per check (232.0-B-4 §4.2).
    for (name, word) in [
        ("open-vr-7", 0x0100_0007u32),
        ("retransmit-farm-b-2", 0x0100_0c07),
        ("lockout-wait-vc-63", 0x01fc_3000),
        ("type-miss", 0x8100_0007),
        ("version-miss", 0x2100_0007),
        ("cop-miss", 0x0000_0007),
        ("spare-miss", 0x0100_0107),
    ] {
        out.push(SeedFile {
            target: TARGETS[13],
            name: name.into(),
            bytes: word.to_be_bytes().to_vec(),
        });
    }
    // COP-1: octet 0 even for FARM-1, odd for FOP-1; octet 1 the window (FARM: 9 gives
    // W = 20) or the FOP's options (0: running, timeout type 0, T1 restarted after Wait);
    // then FARM events of three octets (selector, N(S), flag) or FOP inputs of two.
    let farm = |events: &[(u8, u8, u8)]| {
        let mut b = vec![0u8, 9];
        for &(sel, ns, flag) in events {
            b.extend_from_slice(&[sel, ns, flag]);
        }
        b
    };
    let fop = |inputs: &[(u8, u8)]| {
        let mut b = vec![1u8, 0];
        for &(sel, v) in inputs {
            b.extend_from_slice(&[sel, v]);
        }
        b
    };
    for (name, bytes) in [
        ("farm-in-order", farm(&[(0, 0, 1), (0, 1, 1), (0, 2, 1)])),
        (
            "farm-gap-lockout-unlock",
            farm(&[(0, 0, 1), (0, 2, 1), (0, 200, 1), (5, 0, 1), (0, 1, 1)]),
        ),
        (
            "farm-wait-release",
            farm(&[(0, 0, 0), (7, 0, 1), (0, 0, 1)]),
        ),
        (
            "fop-window-ack",
            fop(&[(0, 1), (0, 2), (0, 3), (0, 4), (2, 3), (2, 4)]),
        ),
        (
            "fop-retransmit-timer",
            fop(&[(0, 1), (0, 2), (2, 0x12), (6, 0), (5, 200), (2, 3)]),
        ),
    ] {
        out.push(SeedFile {
            target: TARGETS[14],
            name: name.into(),
            bytes,
        });
    }
    out
}

/// Seeds of the TM link targets: for `tm_frame_parser`, the reference frame of the
/// `tm-frame` bad-input rows and one near miss per check (the field changed, the FECF
/// rewritten); for `tm_extractor`, link runs (frame-length selector, loss mask, steps: see
/// `mmic_proofs::link_tm::check_link`) and two frames as the framer makes them.
pub fn tm_seeds() -> Vec<SeedFile> {
    use mmic_proofs::link_tm::{reference_frame, reseal};
    let mut out = Vec::new();
    let good = reference_frame();
    let mut frame = |name: &str, edits: &[(usize, u8)]| {
        let mut b = good.clone();
        for &(at, v) in edits {
            b[at] = v;
        }
        if !edits.is_empty() {
            reseal(&mut b);
        }
        out.push(SeedFile {
            target: TARGETS[10],
            name: name.into(),
            bytes: b,
        });
    };
    frame("reference", &[]);
    frame("version-1", &[(0, 0x54)]);
    frame("secondary-header", &[(4, 0x98)]);
    frame("no-ocf", &[(1, 0x20)]);
    frame("other-spacecraft", &[(1, 0x31)]);
    frame("vc-1", &[(1, 0x23)]);
    frame("synch", &[(4, 0x58)]);
    frame("packet-order", &[(4, 0x38)]);
    frame("segment-01", &[(4, 0x10)]);
    frame("fhp-244", &[(5, 0xf4)]);
    frame("no-packet-start", &[(4, 0x1f), (5, 0xff)]);
    frame("only-idle-data", &[(4, 0x1f), (5, 0xfe)]);
    let mut fecf = good.clone();
    fecf[10] ^= 0x04;
    out.push(SeedFile {
        target: TARGETS[10],
        name: "fecf".into(),
        bytes: fecf,
    });
    for (name, bytes) in [
        ("two-packets", vec![0u8, 0xff, 0x28]),
        (
            "spanning-and-flushes",
            vec![0, 0xfe, 0, 0xdc, 0x29, 0, 0xff],
        ),
        (
            "short-frames-with-loss",
            vec![55, 0x12, 0x40, 0, 0, 0, 0, 0, 0, 0xff, 0x60, 0, 0xa0],
        ),
    ] {
        out.push(SeedFile {
            target: TARGETS[11],
            name: name.into(),
            bytes,
        });
    }
    let mut two = vec![0u8];
    two.extend(&good);
    two.extend(&good);
    out.push(SeedFile {
        target: TARGETS[11],
        name: "reference-frame-twice".into(),
        bytes: two,
    });
    out
}

/// Seeds of the SDLS targets, under the fixed test keys of `mmic_proofs::sdls::test_key`
/// (made at run time, not secrets), with the verdict a fresh secured end gives each (`None`:
/// accepted): for `sdls_tc_verify`, AD and BD frames with a ping protected under IVs 0 and 3
/// (the fresh gateway's floor takes 0..=15), the AD frame under IV 2^95 (a replay), under 40
/// (authentic, beyond the durable floor), under 2^21 (beyond the window of 2^20), with its
/// MAC's last bit flipped (FECF rewritten), under the TM key, in clear, and BC Unlock (in
/// clear by design); for `sdls_tm_verify`, an idle TM frame and one with a packet under IVs 0
/// and 1, one with a bit of its data flipped (FECF rewritten), under the TC key, and one in
/// clear.
pub fn sdls_seed_frames() -> Vec<(&'static str, String, Option<&'static str>, Vec<u8>)> {
    use mmic::link::tc_frame::{MapId, SpacecraftId, TcContent, TcFrameRepr, Vcid};
    use mmic::link::ControlCommand;
    use mmic_proofs::sdls::{ping, protected_tc, protected_tm, refresh_fecf};
    let (tc, tm) = (TARGETS[15], TARGETS[16]);
    let mut out = Vec::new();
    let frame = |iv: u128, bd: bool| {
        let mut b = [0u8; 256];
        let n = protected_tc(iv, bd, 0, &ping(1), &mut b);
        b[..n].to_vec()
    };
    out.push((tc, "ad-ping-iv-0".to_string(), None, frame(0, false)));
    out.push((tc, "bd-ping-iv-3".into(), None, frame(3, true)));
    out.push((
        tc,
        "ad-ping-iv-2-95".into(),
        Some("replay"),
        frame(1 << 95, false),
    ));
    out.push((
        tc,
        "ad-ping-iv-40".into(),
        Some("not-reserved"),
        frame(40, false),
    ));
    out.push((
        tc,
        "ad-ping-iv-2-21".into(),
        Some("too-far-ahead"),
        frame(1 << 21, false),
    ));
    let mut bad = frame(0, false);
    let n = bad.len();
    bad[n - 3] ^= 1;
    refresh_fecf(&mut bad);
    out.push((tc, "ad-ping-bad-mac".into(), Some("bad-mac"), bad));
    // Protected under the TM key (the TC SPI written back: the MAC is the other key's).
    let mut other = [0u8; 256];
    let p = ping(1);
    let repr = |content| TcFrameRepr {
        spacecraft_id: SpacecraftId::new(0x101).expect("10 bits"),
        vcid: Vcid::new(0).expect("VC 0"),
        seq: 0,
        content,
    };
    let ad = repr(TcContent::Ad {
        map_id: MapId::new(0).ok(),
        data: &p,
    });
    let mut t: mmic::link::sdls::SaTable<1> = mmic::link::sdls::SaTable::new();
    let _ = t.add(mmic::link::sdls::SecurityAssociation::new(
        mmic_proofs::sdls::TC_SPI,
        mmic_proofs::sdls::test_key(1),
        mmic_proofs::sdls::tc_channel(),
        mmic::link::sdls::mask::TC,
        mmic::link::sdls::Role::Send(mmic::link::sdls::TxCounter::boot(None, 16)),
    ));
    let due: Vec<_> = t.due().collect();
    for (spi, v) in due {
        t.persisted(spi, v);
    }
    let n =
        mmic::link::sdls::frames::protect_tc(&mut t, mmic_proofs::sdls::TC_SPI, &ad, &mut other)
            .expect("protected");
    out.push((
        tc,
        "ad-ping-other-key".into(),
        Some("bad-mac"),
        other[..n].to_vec(),
    ));
    let mut clear = [0u8; 64];
    let n = ad.emit(&mut clear).expect("fits");
    out.push((
        tc,
        "ad-ping-clear".into(),
        Some("unknown-spi"),
        clear[..n].to_vec(),
    ));
    let n = repr(TcContent::Bc(ControlCommand::Unlock))
        .emit(&mut clear)
        .expect("fits");
    out.push((tc, "bc-unlock".into(), None, clear[..n].to_vec()));

    let clcw = [0x01, 0x00, 0x00, 0x00];
    out.push((
        tm,
        "idle-iv-0".into(),
        None,
        protected_tm(0, &[], clcw).to_vec(),
    ));
    let mut report = [0u8; 18];
    report[..6].copy_from_slice(&[0x09, 0x01, 0xc0, 0x00, 0x00, 0x0b]);
    out.push((
        tm,
        "packet-iv-1".into(),
        None,
        protected_tm(1, &report, clcw).to_vec(),
    ));
    let mut bad = protected_tm(1, &report, clcw);
    bad[30] ^= 0x10;
    mmic_proofs::link_tm::reseal(&mut bad);
    out.push((tm, "packet-bad-mac".into(), Some("bad-mac"), bad.to_vec()));
    // The same frame under the TC key: emitted, then protected by a TM association with it.
    let mut t: mmic::link::sdls::SaTable<1> = mmic::link::sdls::SaTable::new();
    let _ = t.add(mmic::link::sdls::mission::tm_sender(
        mmic::units::BoardNumber::ONE,
        mmic_proofs::sdls::test_key(0),
        Some(0),
    ));
    let due: Vec<_> = t.due().collect();
    for (spi, v) in due {
        t.persisted(spi, v);
    }
    let mut other = protected_tm(0, &report, clcw);
    let params = mmic_proofs::sdls::tm_params();
    mmic::link::sdls::frames::protect_tm(&mut t, mmic_proofs::sdls::TM_SPI, &params, &mut other)
        .expect("protected");
    out.push((
        tm,
        "packet-other-key".into(),
        Some("bad-mac"),
        other.to_vec(),
    ));
    // In clear: the mission's TM frame without SDLS (its first octets are no SPI of ours).
    let plain = mmic::link::tm_frame::TmFrameParams::mission(0x101).expect("params");
    let data = [0x55u8; 244];
    let f = mmic::link::tm_frame::TmFrameRepr {
        spacecraft_id: 0x101,
        vcid: 0,
        mc_frame_count: 0,
        vc_frame_count: 0,
        first_header_pointer: mmic::link::tm_frame::FirstHeaderPointer::OnlyIdleData,
        data: &data,
        ocf: Some(clcw),
    };
    let mut b = [0u8; 256];
    f.emit(&plain, &mut b).expect("emits");
    out.push((tm, "idle-clear".into(), Some("unknown-spi"), b.to_vec()));
    out
}

/// [`sdls_seed_frames`] as seed files.
pub fn sdls_seeds() -> Vec<SeedFile> {
    sdls_seed_frames()
        .into_iter()
        .map(|(target, name, _, bytes)| SeedFile {
            target,
            name,
            bytes,
        })
        .collect()
}

/// Seeds of `server_store` (a selector octet, then the reader's input): a log entry record, a
/// sector header, a keys partition of one key (a fixed test key made at run time: not a secret),
/// a queued Stop's slot value.
pub fn store_seeds() -> Vec<SeedFile> {
    use mmic::node::server::store::{keys, log, queue, Entry};
    let target = TARGETS[18];
    let mut out = Vec::new();
    let mut push = |name: &str, selector: u8, body: &[u8]| {
        let mut bytes = vec![selector];
        bytes.extend_from_slice(body);
        out.push(SeedFile {
            target,
            name: name.to_string(),
            bytes,
        });
    };
    let entry = Entry {
        key: 0x0201,
        aux: 0,
        value: 0x100,
    };
    if let Some(r) = log::encode_entry(&entry) {
        push("log-entry", 0, &r);
    }
    push("log-header", 0, &log::encode_header(3));
    let key = mmic::link::sdls::Key256::from_bytes(core::array::from_fn(|i| {
        (i as u8).wrapping_mul(31) ^ 0x5c
    }));
    let mut part = [0xFFu8; keys::HEADER_LEN + keys::ENTRY_LEN + 4];
    if keys::emit(&[(257, &key)], &mut part).is_ok() {
        push("keys-partition", 1, &part);
    }
    let job = mmic::node::server::gateway::Job {
        request: mmic::pus::verification::RequestId {
            apid: 0x101,
            seq_count: 7,
        },
        source_id: 9,
        ack: 0xF,
        command: mmic::command::Command::Stop,
        alive: false,
    };
    let v = queue::job_entry(mmic::units::BoardNumber::ONE, 3, Some(&job)).value;
    let mut body = vec![1u8, 3];
    body.extend_from_slice(&v.to_be_bytes()[4..]);
    push("queue-slot", 2, &body);
    out
}

/// Seeds of `cfdp_pdu`: YAMCS's EOF PDU (its PacketParseTest), the same with the CRC flag and
/// its CRC, a file data PDU, a near miss of each check of `PduError` the PDU reader runs, one
/// PDU of each directive as LibreCube writes it, and near misses of the directive checks.
pub fn cfdp_seeds() -> Vec<SeedFile> {
    use mmic::cfdp::header::{Direction, Lengths, Mode, PduHeader, PduType};
    let target = TARGETS[19];
    let header = |pdu_type, crc| PduHeader {
        pdu_type,
        direction: Direction::TowardReceiver,
        mode: Mode::Acknowledged,
        crc,
        segmentation: false,
        lengths: Lengths::MISSION,
        data_len: 0,
        source: 0x18,
        seq: 1,
        dest: 0x15,
    };
    let eof_data = [0x04, 0x80, 0, 0, 0, 0, 0, 0, 0x65, 0xfc];
    let pdu = |h: PduHeader, data: &[u8]| {
        let mut out = [0u8; 64];
        let n = mmic::cfdp::emit(&h, data, &mut out).expect("fits");
        out[..n].to_vec()
    };
    let mut yamcs = pdu(header(PduType::Directive, false), &eof_data);
    yamcs[0] = 0x00; // YAMCS writes version 000
    let crc = pdu(header(PduType::Directive, true), &eof_data);
    let data = pdu(
        header(PduType::FileData, false),
        &[0, 0, 0, 0, b'p', b'l', b'a', b'n'],
    );
    let with = |b: &[u8], at: usize, v: u8| {
        let mut b = b.to_vec();
        b[at] = v;
        b
    };
    let named = [
        ("eof-yamcs", yamcs.clone()),
        ("eof-crc", crc.clone()),
        ("file-data", data),
        ("truncated", yamcs[..3].to_vec()),
        ("version-2", with(&yamcs, 0, 0x40)),
        ("large-file", with(&yamcs, 0, 0x01)),
        ("segment-metadata", with(&yamcs, 3, 0x1b)),
        ("length-short", yamcs[..yamcs.len() - 1].to_vec()),
        (
            "crc-miss",
            with(&crc, crc.len() - 1, crc[crc.len() - 1] ^ 1),
        ),
    ];
    // One PDU of each directive and file data, as LibreCube's cfdp 0.2.0 writes them
    // (tests/ccsds/cfdp_directive.rs), and a near miss of each directive check.
    let librecube = [
        ("librecube-metadata", "20001f1301020a0b0c0d03040740000004d208706c616e2e7478740f2f726f626f742f706c616e2e747874"),
        ("librecube-file-data", "3000091301020a0b0c0d03040000001068656c6c6f"),
        ("librecube-eof", "20000a1301020a0b0c0d03040400181c2015000004d2"),
        ("librecube-finished", "2800021301020a0b0c0d0304050a"),
        ("librecube-ack-eof", "2800031301020a0b0c0d0304064001"),
        ("librecube-ack-finished", "2000031301020a0b0c0d0304065102"),
        ("librecube-nak", "2800191301020a0b0c0d030408000000000000040000000000000000000000020000000300"),
        ("librecube-prompt", "2000021301020a0b0c0d03040980"),
        ("librecube-keep-alive", "2800051301020a0b0c0d03040c00000200"),
        ("directive-unknown", "2000011301020a0b0c0d030403"),
        ("ack-of-metadata", "2800031301020a0b0c0d0304067001"),
        ("nak-backwards", "2800111301020a0b0c0d03040800000000000004000000020000000100"),
        ("eof-fault-location", "20000e1301020a0b0c0d03040450000000000000000006020304"),
        // Found by the campaign: a 2-octet fault location in a PDU of 3-octet IDs.
        ("eof-fault-location-length", "20000e2101020a0b0c0d03040450000000000000000006020304"),
    ];
    let named = named.into_iter().chain(librecube.map(|(name, hex)| {
        let bytes = (0..hex.len())
            .step_by(2)
            .map(|i| u8::from_str_radix(&hex[i..i + 2], 16).expect("hex"))
            .collect();
        (name, bytes)
    }));
    named
        .into_iter()
        .map(|(name, bytes)| SeedFile {
            target,
            name: name.to_string(),
            bytes,
        })
        .collect()
}
