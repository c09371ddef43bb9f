//! Packet parse+validate and emit, the deframer, and the CRC table choice, with spacepackets'
//! 13-byte PUS-C telecommand parse measured in the same run as the reference.
//! Run: `cargo bench -p mmic-benches --bench wire` (about a minute). Results: benches/README.md.

use arbitrary_int::{u11, u14};
use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use mmic::command::{Command, ServoTarget};
use mmic::faults::{Fault, Faults};
use mmic::mode::Mode;
use mmic::motion::State;
use mmic::units::{BoardNumber, PulseWidth, Side};
use mmic::wire::b_command::{BCommandRepr, BPower};
use mmic::wire::command::CommandRepr;
use mmic::wire::deframer::{Deframed, Deframer};
use mmic::wire::heartbeat::HeartbeatRepr;
use mmic::wire::internal_heartbeat::InternalHeartbeatRepr;
use spacepackets::ecss::tc::{PusTcCreator, PusTcReader, PusTcSecondaryHeader};
use spacepackets::ecss::{CreatorConfig, MessageTypeId};
use spacepackets::SpHeader;
use std::hint::black_box;
use std::time::Duration;

fn pus_tc() -> Vec<u8> {
    let sph = SpHeader::new_for_unseg_tc(u11::new(0x42), u14::new(7), 0);
    let tc = PusTcCreator::new_no_app_data(
        sph,
        PusTcSecondaryHeader::new_simple(MessageTypeId::new(17, 1)),
        CreatorConfig::default(),
    );
    let bytes = tc.to_vec().expect("PUS TC");
    assert_eq!(bytes.len(), 13, "reference TC must be 13 bytes");
    PusTcReader::new(&bytes).expect("reference TC parses");
    bytes
}

fn samples() -> (
    CommandRepr,
    HeartbeatRepr,
    InternalHeartbeatRepr,
    BCommandRepr,
) {
    let cmd = CommandRepr {
        board: BoardNumber::ONE,
        command: Command::Arm {
            side: Side::B,
            target: ServoTarget::Position(PulseWidth::new(1200).unwrap()),
        },
        seq: 0,
    };
    let hb = HeartbeatRepr {
        target_state: Some(State::M),
        faults: Faults::EMPTY.with(Fault::LowBattery),
        mode: Mode::Operational,
        ..HeartbeatRepr::default()
    };
    let ihb = InternalHeartbeatRepr {
        command_received: 9,
        ..InternalHeartbeatRepr::default()
    };
    let bc = BCommandRepr {
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
    };
    (cmd, hb, ihb, bc)
}

fn parse(c: &mut Criterion) {
    let (cmd, hb, ihb, bc) = samples();
    let (cmd_b, hb_b, ihb_b, bc_b, tc) = (
        cmd.to_bytes(),
        hb.to_bytes(),
        ihb.to_bytes(),
        bc.to_bytes(),
        pus_tc(),
    );
    let mut g = c.benchmark_group("parse");
    g.bench_function("spacepackets PusTcReader::new (13 B, reference)", |b| {
        b.iter(|| PusTcReader::new(black_box(&tc)).is_ok())
    });
    g.bench_function("command (14 B)", |b| {
        b.iter(|| CommandRepr::parse(black_box(&cmd_b)).is_ok())
    });
    g.bench_function("b-command (15 B)", |b| {
        b.iter(|| BCommandRepr::parse(black_box(&bc_b)).is_ok())
    });
    g.bench_function("internal-heartbeat (47 B)", |b| {
        b.iter(|| InternalHeartbeatRepr::parse(black_box(&ihb_b)).is_ok())
    });
    g.bench_function("heartbeat (66 B)", |b| {
        b.iter(|| HeartbeatRepr::parse(black_box(&hb_b)).is_ok())
    });
    g.finish();
}

fn emit(c: &mut Criterion) {
    let (cmd, hb, ihb, bc) = samples();
    let mut g = c.benchmark_group("emit");
    g.bench_function("command (14 B)", |b| {
        let mut out = [0u8; 14];
        b.iter(|| black_box(&cmd).emit(&mut out))
    });
    g.bench_function("b-command (15 B)", |b| {
        let mut out = [0u8; 15];
        b.iter(|| black_box(&bc).emit(&mut out))
    });
    g.bench_function("internal-heartbeat (47 B)", |b| {
        let mut out = [0u8; 47];
        b.iter(|| black_box(&ihb).emit(&mut out))
    });
    g.bench_function("heartbeat (66 B)", |b| {
        let mut out = [0u8; 66];
        b.iter(|| black_box(&hb).emit(&mut out))
    });
    g.finish();
}

fn deframer(c: &mut Criterion) {
    let (cmd, hb, ihb, bc) = samples();
    let mut stream = Vec::new();
    for i in 0..32u8 {
        stream.extend_from_slice(&cmd.to_bytes());
        stream.extend_from_slice(&hb.to_bytes());
        if i % 4 == 0 {
            stream.extend_from_slice(b"MI\x00garbage");
        }
        stream.extend_from_slice(&ihb.to_bytes());
        stream.extend_from_slice(&bc.to_bytes());
    }
    let mut g = c.benchmark_group("deframer");
    g.throughput(Throughput::Bytes(stream.len() as u64));
    g.bench_function("mixed stream, 64-byte reads", |b| {
        b.iter(|| {
            let mut d = Deframer::<256>::new();
            let mut frames = 0u32;
            for chunk in black_box(&stream).chunks(64) {
                d.feed(chunk, |e| {
                    if let Deframed::Frame(_) = e {
                        frames += 1
                    }
                });
            }
            assert_eq!(frames, 128);
        })
    });
    g.finish();
}

fn crc_tables(c: &mut Criterion) {
    const ALG: &crc::Algorithm<u16> = &crc::CRC_16_IBM_3740;
    let none = crc::Crc::<u16, crc::NoTable>::new(ALG);
    let one = crc::Crc::<u16, crc::Table<1>>::new(ALG);
    let sixteen = crc::Crc::<u16, crc::Table<16>>::new(ALG);
    let data = [0x5au8; 64];
    let mut g = c.benchmark_group("crc16");
    for len in [12usize, 64] {
        g.bench_with_input(
            BenchmarkId::new("NoTable (0 B flash)", len),
            &len,
            |b, &n| b.iter(|| none.checksum(black_box(&data[..n]))),
        );
        g.bench_with_input(
            BenchmarkId::new("Table<1> (512 B flash, small-crc-table)", len),
            &len,
            |b, &n| b.iter(|| one.checksum(black_box(&data[..n]))),
        );
        g.bench_with_input(
            BenchmarkId::new("Table<16> (8 KiB flash, default)", len),
            &len,
            |b, &n| b.iter(|| sixteen.checksum(black_box(&data[..n]))),
        );
        g.bench_with_input(
            BenchmarkId::new("mmic crc16 (the Table<16> tables, the library's loop)", len),
            &len,
            |b, &n| b.iter(|| mmic::wire::checksum::crc16(black_box(&data[..n]))),
        );
    }
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().measurement_time(Duration::from_secs(2)).warm_up_time(Duration::from_millis(500)).sample_size(50);
    targets = parse, emit, deframer, crc_tables
}
criterion_main!(benches);
