//! The packets of the host benchmarks (`benches/wire.rs`, `benches/ccsds.rs`), for counting
//! their parse's instructions on RV32 (`mmic-rv32 --parsers`): the same octets, the same
//! checks, so that the noisy nanoseconds of the host have an exact instruction count beside
//! them.
//!
//! ```
//! use mmic_replay::parsers::{Sample, SAMPLES};
//! for s in SAMPLES {
//!     let p = Sample::new(s);
//!     assert!(p.parse(), "{}", s.name());
//! }
//! ```

use mmic::ccsds::primary::{Apid, SeqCount};
use mmic::ccsds::tc::TcRepr;
use mmic::ccsds::tc_header::{AckFlags, TcSecondaryHeader};
use mmic::command::{Command, ServoTarget};
use mmic::faults::{Fault, Faults};
use mmic::mode::Mode;
use mmic::motion::State;
use mmic::units::{BoardNumber, PulseWidth, Side};
use mmic::wire::b_command::{BCommandRepr, BPower};
use mmic::wire::command::CommandRepr;
use mmic::wire::heartbeat::HeartbeatRepr;
use mmic::wire::internal_heartbeat::InternalHeartbeatRepr;

/// The APID of the telecommand (benches/ccsds.rs).
pub const APID: u16 = 0x042;
const APP_DATA: [u8; 3] = [0x60, b'm', b'a'];

/// The parsers measured.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// `CommandRepr::parse`, 14 B.
    Command,
    /// `BCommandRepr::parse`, 15 B.
    BCommand,
    /// `InternalHeartbeatRepr::parse`, 47 B.
    InternalHeartbeat,
    /// `HeartbeatRepr::parse`, 66 B.
    Heartbeat,
    /// `TcRepr::parse` of a TC(8,1), 16 B.
    PusTc,
}

/// Every parser, in table order.
pub const SAMPLES: [Kind; 5] = [
    Kind::Command,
    Kind::BCommand,
    Kind::InternalHeartbeat,
    Kind::Heartbeat,
    Kind::PusTc,
];

impl Kind {
    /// The row's name, as benches/README.md names it.
    pub const fn name(self) -> &'static str {
        match self {
            Kind::Command => "parse command, 14 B",
            Kind::BCommand => "parse B command, 15 B",
            Kind::InternalHeartbeat => "parse internal heartbeat, 47 B",
            Kind::Heartbeat => "parse heartbeat, 66 B",
            Kind::PusTc => "PUS TC(8,1) parse+validate, 16 B",
        }
    }
}

/// One parser's input.
#[derive(Debug, Clone, Copy)]
pub struct Sample {
    kind: Kind,
    bytes: [u8; 66],
    len: usize,
}

impl Sample {
    /// The benchmarks' packet of `kind`.
    pub fn new(kind: Kind) -> Sample {
        let mut bytes = [0u8; 66];
        let len = match kind {
            Kind::Command => put(
                &mut bytes,
                &CommandRepr {
                    board: BoardNumber::ONE,
                    command: Command::Arm {
                        side: Side::B,
                        target: ServoTarget::Position(PulseWidth::saturating(1200)),
                    },
                    seq: 0,
                }
                .to_bytes(),
            ),
            Kind::BCommand => put(
                &mut bytes,
                &BCommandRepr {
                    seq: 3,
                    power: BPower {
                        regulator: true,
                        arm: true,
                        gripper: true,
                        bolter: false,
                    },
                    stop: false,
                    arm_target: PulseWidth::CENTER,
                    gripper_target: PulseWidth::MAX,
                    bolter: None,
                }
                .to_bytes(),
            ),
            Kind::InternalHeartbeat => put(
                &mut bytes,
                &InternalHeartbeatRepr {
                    command_received: 9,
                    ..InternalHeartbeatRepr::default()
                }
                .to_bytes(),
            ),
            Kind::Heartbeat => put(
                &mut bytes,
                &HeartbeatRepr {
                    target_state: Some(State::M),
                    faults: Faults::EMPTY.with(Fault::LowBattery),
                    mode: Mode::Operational,
                    ..HeartbeatRepr::default()
                }
                .to_bytes(),
            ),
            Kind::PusTc => {
                // Both are in range: a failure leaves an empty packet, which `parse` refuses.
                let (Ok(apid), Ok(seq_count)) = (Apid::new(APID), SeqCount::new(7)) else {
                    return Sample {
                        kind,
                        bytes,
                        len: 0,
                    };
                };
                let tc = TcRepr {
                    apid,
                    seq_count,
                    header: TcSecondaryHeader {
                        ack: AckFlags::ALL,
                        service: 8,
                        subservice: 1,
                        source_id: 1,
                    },
                    app_data: &APP_DATA,
                };
                tc.emit(&mut bytes).unwrap_or(0)
            }
        };
        Sample { kind, bytes, len }
    }

    /// The packet's octets.
    pub fn bytes(&self) -> &[u8] {
        self.bytes.get(..self.len).unwrap_or(&[])
    }

    /// Parses and validates the packet; true if it is accepted (it always should be).
    #[inline(never)]
    pub fn parse(&self) -> bool {
        let b = core::hint::black_box(self.bytes());
        match self.kind {
            Kind::Command => CommandRepr::parse(b).is_ok(),
            Kind::BCommand => BCommandRepr::parse(b).is_ok(),
            Kind::InternalHeartbeat => InternalHeartbeatRepr::parse(b).is_ok(),
            Kind::Heartbeat => HeartbeatRepr::parse(b).is_ok(),
            Kind::PusTc => TcRepr::parse(b, &[APID]).is_ok(),
        }
    }
}

fn put(d: &mut [u8; 66], s: &[u8]) -> usize {
    if let Some(t) = d.get_mut(..s.len()) {
        t.copy_from_slice(s);
    }
    s.len()
}
