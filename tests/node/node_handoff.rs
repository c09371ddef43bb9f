//! The two-core hand-off (Section 3) under real concurrency: one OS thread produces numbered,
//! checksummed packets into an 8-slot `node::robot::handoff` queue, another consumes them. Every
//! packet must arrive exactly once, in order, byte for byte (no loss, duplication or tearing).

use mmic::node::robot::handoff::PacketQueue;
use mmic::wire::checksum::crc16;

/// Two million packets; under Miri (.ci/miri), which interprets some 100x slower but checks
/// every access of the queue's `unsafe` code (heapless) for data races and undefined
/// behaviour, with its weak-memory emulation and random preemption, 256 (32 laps of the ring;
/// a thousand took 32 s a lane there).
const PACKETS: u64 = if cfg!(miri) { 256 } else { 2_000_000 };

fn packet(i: u64) -> [u8; 14] {
    let mut p = [0u8; 14];
    p[..8].copy_from_slice(&i.to_le_bytes());
    p[8..12].copy_from_slice(&(i as u32 ^ 0xa5a5_5a5a).to_le_bytes());
    let c = crc16(&p[..12]);
    p[12..].copy_from_slice(&c.to_le_bytes());
    p
}

/// A side that finds the queue full (or empty) waits: natively it spins, as the cores do; under
/// Miri, whose scheduler preempts a thread only now and then, it yields, so that the other
/// thread runs instead of a spin the interpreter would step through.
fn wait() {
    if cfg!(miri) {
        std::thread::yield_now();
    } else {
        std::hint::spin_loop();
    }
}

// req: P2.11, P3.17, P3.18
#[test]
fn two_threads_exchange_packets_without_loss_duplication_or_tearing() {
    let mut q: PacketQueue<14, 8> = PacketQueue::new();
    let (mut tx, mut rx) = q.split();
    let mut full = 0u64;
    let t0 = std::time::Instant::now();
    std::thread::scope(|s| {
        s.spawn(|| {
            for i in 0..PACKETS {
                let mut p = packet(i);
                // The WiFi task keeps a refused packet and tries again: nothing is given up.
                while let Err(back) = tx.push(p) {
                    p = back.0;
                    full += 1;
                    wait();
                }
            }
            assert_eq!(tx.dropped(), 0);
        });
        s.spawn(|| {
            let mut next = 0u64;
            while next < PACKETS {
                if let Some(p) = rx.pop() {
                    assert_eq!(
                        crc16(&p[..12]),
                        u16::from_le_bytes([p[12], p[13]]),
                        "torn packet {next}"
                    );
                    let i = u64::from_le_bytes(p[..8].try_into().unwrap());
                    assert_eq!(i, next, "lost or duplicated");
                    assert_eq!(p, packet(i));
                    next += 1;
                } else {
                    wait();
                }
            }
            assert_eq!(rx.pop(), None);
        });
    });
    eprintln!(
        "{PACKETS} packets in {:?}; the producer found the queue full {full} times",
        t0.elapsed()
    );
}
