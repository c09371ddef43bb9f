//! The server board's glue towards the ground on the host: the library's ground end
//! (`GroundLink`: FOP-1, SDLS, the packet extractor) sends PUS telecommands in TC transfer
//! frames over a mocked UDP socket; the glue runs them through SDLS, FARM-1 and the gateway,
//! its legacy commands reach a mocked board A (which answers each with a heartbeat at the next
//! pass, as a visit does), and the TM transfer frames that come back carry the ground's
//! reports and the CLCW. The store is the durable log on a RAM flash as the provisioning tool
//! makes it, the keys as the image reads them from the keys partition (`tests/bench`).

mod bench;
mod common;

use bench::{clear, tc, Bench};
use mmic::command::Command;
use mmic::units::BoardNumber;
use mmic_fw_support::server::{sleep_ms, LinkStop};

#[test]
fn an_are_you_alive_crosses_the_link_and_board_a_answers_it() {
    let mut b = Bench::new(clear);
    b.run(50);
    b.send(&tc(17, 1, 0, &[]));
    b.run(2000);
    assert!(b.heard.packets.contains(&(17, 2)), "{:?}", b.heard);
    assert_eq!(b.heard.accepted, [0]);
    assert_eq!(b.heard.completed, [0]);
    // Board A was visited (the gateway's polls and the heartbeat request), and every visit's
    // heartbeat went back into the gateway.
    assert!(!b.board.commands.is_empty());
    let c = *b.glue.counts();
    assert_eq!(c.heartbeats as usize, b.board.commands.len());
    assert_eq!((c.commands_busy, c.store_failed, c.tm_unsent), (0, 0, 0));
    let sec = b.glue.gateway().security(BoardNumber::ONE).unwrap();
    assert_eq!(sec.refused_total(), 0, "{sec:?}");
    assert!(sec.accepted >= 1 && sec.protected >= 4, "{sec:?}");
    assert!(c.tm_frames >= 4, "{c:?}");
    let farm = b.glue.gateway().farm(BoardNumber::ONE).unwrap();
    assert_eq!(farm.vr(), 1);
}

#[test]
fn a_stop_reaches_board_a_as_the_legacy_stop_and_completes() {
    let mut b = Bench::new(clear);
    b.run(50);
    for seq in 0..3 {
        // TC(8,1) perform function 6: Stop (spec/ccsds/functions.toml).
        b.send(&tc(8, 1, seq, &[6]));
    }
    b.run(3000);
    assert_eq!(b.heard.accepted, [0, 1, 2]);
    assert_eq!(b.heard.completed, [0, 1, 2]);
    let stops: Vec<u16> = b
        .board
        .commands
        .iter()
        .filter(|c| c.command == Command::Stop)
        .map(|c| c.seq)
        .collect();
    assert_eq!(stops.len(), 3, "{:?}", b.board.commands);
    let farm = b.glue.gateway().farm(BoardNumber::ONE).unwrap();
    assert_eq!(farm.vr(), 3);
}

#[test]
fn a_busy_board_link_delays_commands_and_the_uplink_sends_them_again() {
    let mut b = Bench::new(clear);
    b.run(50);
    b.board.busy = true;
    b.send(&tc(8, 1, 0, &[6]));
    b.run(600);
    let busy = b.glue.counts().commands_busy;
    assert!(busy >= 1, "{:?}", b.glue.counts());
    assert!(b.heard.completed.is_empty());
    b.board.busy = false;
    b.run(3000);
    assert_eq!(b.heard.completed, [0]);
    assert!(b.board.commands.iter().any(|c| c.command == Command::Stop));
}

#[test]
fn a_garbage_datagram_is_refused_by_the_frame_checks_and_reaches_no_robot() {
    let mut b = Bench::new(clear);
    b.run(50);
    let before = b.board.commands.len();
    let refused_before: u32 = b.glue.gateway().refused().iter().sum();
    let datagrams_before = b.glue.counts().tc_datagrams;
    b.udp.from_ground(vec![0x55; 40]);
    b.udp.from_ground(vec![0x20; 300]); // longer than any TC frame: cut, then refused
    b.run(1);
    let refused: u32 = b.glue.gateway().refused().iter().sum();
    assert_eq!(refused - refused_before, 2);
    // At most the gateway's own poll went to board A meanwhile.
    assert!(b.board.commands.len() <= before + 1);
    assert_eq!(b.glue.counts().tc_datagrams - datagrams_before, 2);
}

/// A keys partition without one of the robot's keys: its link is stopped (named), nothing is
/// sent, its frames reach nothing, and the board runs on.
#[test]
fn a_robot_without_both_keys_is_not_served() {
    use mmic::node::server::store::keys;
    let (tc_key, _) = bench::keys_of(1);
    let mut part = vec![0xFF; 4096];
    keys::emit(&[(257, &tc_key)], &mut part).unwrap();
    let glue = bench::glue([1], &part, bench::provisioned(&[1]));
    assert_eq!(
        glue.stopped(),
        [(BoardNumber::ONE, LinkStop::NoKey { spi: 513 })]
    );
    let mut b = Bench::with(glue, clear);
    b.send(&tc(8, 1, 0, &[6]));
    // The ground's FOP-1 waits for a CLCW that never comes: a frame as anyone could send it.
    b.udp.from_ground(bench::bd(1, &tc(8, 1, 1, &[6])));
    b.run(2000);
    assert!(b.board.commands.is_empty());
    assert!(b.heard.packets.is_empty() && b.tm_ivs.is_empty());
    assert!(b.glue.gateway().refused().iter().sum::<u32>() > 0);
    // Nothing names a key.
    let shown = format!("{:?} {}", b.glue, b.glue.stopped()[0].1);
    assert!(shown.contains("513"), "{shown}");
}

/// An attacker on the ground's UDP port: every TC frame the ground sent, sent again (replays),
/// and each with one bit flipped in its data field (the FECF made good): SDLS refuses every
/// one before FARM-1, board A is given nothing more, and the link still works.
#[test]
fn sdls_refuses_replays_and_forgeries_before_farm() {
    let mut b = Bench::new(clear);
    b.run(50);
    b.send(&tc(8, 1, 0, &[6]));
    b.run(2000);
    assert_eq!(b.heard.completed, [0]);
    let stops = |b: &Bench<1>| {
        b.board
            .commands
            .iter()
            .filter(|c| c.command == Command::Stop)
            .count()
    };
    assert_eq!(stops(&b), 1);
    let data: Vec<Vec<u8>> = b
        .uplink
        .iter()
        .filter(|f| f[0] & 0x10 == 0)
        .cloned()
        .collect();
    assert!(!data.is_empty());
    let farm_before = b
        .glue
        .gateway()
        .farm(BoardNumber::ONE)
        .unwrap()
        .counters()
        .accepted_ad;
    let mut attacks = 0;
    for f in &data {
        b.udp.from_ground(f.clone());
        attacks += 1;
        for at in [6, 8, 20, f.len() - 3] {
            let mut g = f.clone();
            g[at] ^= 0x01;
            let n = g.len();
            let crc = mmic::ccsds::pec(&g[..n - 2]);
            g[n - 2..].copy_from_slice(&crc.to_be_bytes());
            b.udp.from_ground(g);
            attacks += 1;
        }
    }
    b.run(10);
    let sec = *b.glue.gateway().security(BoardNumber::ONE).unwrap();
    assert_eq!(sec.refused_total(), attacks, "{sec:?}");
    assert_eq!(
        b.glue
            .gateway()
            .farm(BoardNumber::ONE)
            .unwrap()
            .counters()
            .accepted_ad,
        farm_before
    );
    assert_eq!(stops(&b), 1, "board A was given a command again");
    // The ground's next command still goes through.
    b.send(&tc(8, 1, 1, &[6]));
    b.run(2000);
    assert_eq!(b.heard.completed, [0, 1]);
    assert_eq!(stops(&b), 2);
}

#[test]
fn the_shell_sleeps_until_the_deadline_within_bounds() {
    assert_eq!(sleep_ms(None, 5, 10), 10);
    assert_eq!(sleep_ms(Some(8), 5, 10), 3);
    assert_eq!(sleep_ms(Some(500), 5, 10), 10);
    // Due now, or already past (also across the clock's wrap): a pass almost at once.
    assert_eq!(sleep_ms(Some(5), 5, 10), 1);
    assert_eq!(sleep_ms(Some(4), 5, 10), 1);
    assert_eq!(sleep_ms(Some(u32::MAX), 2, 10), 1);
    assert_eq!(sleep_ms(Some(3), u32::MAX - 1, 10), 5);
}

#[test]
fn a_pass_reports_the_gateways_next_deadline() {
    let mut b = Bench::new(clear);
    b.run(50);
    let now = b.clock.0;
    let next = b.glue.poll(&mut b.clock, &mut b.udp, &mut b.board).unwrap();
    // Something is always due within the TM idle period (500 ms) and the poll period (250 ms).
    let d = next.wrapping_sub(now);
    assert!(d <= 500, "next deadline {d} ms away");
}

/// The SDLS counters in flash survive a reset of the server board: a new glue on the same
/// flash refuses every TC data frame taken before the reset (as a replay), and its TM frames'
/// IVs continue above every IV used before it.
#[test]
fn the_counters_survive_a_reset_of_the_server_board_in_flash() {
    let mut b = Bench::new(clear);
    b.run(100);
    b.send(&tc(8, 1, 0, &[6]));
    b.run(5000);
    assert!(b.board.commands.iter().any(|c| c.command == Command::Stop));
    assert!(b.tm_ivs.len() >= 10, "{} TM frames", b.tm_ivs.len());
    // Reset: a new glue on the same flash.
    let ram = bench::flash_of(&mut b.glue);
    let mut glue = bench::glue([1], &bench::partition(&[1]), ram.reset());
    assert!(glue.stopped().is_empty(), "{:?}", glue.stopped());
    let data: Vec<Vec<u8>> = b
        .uplink
        .iter()
        .filter(|f| f[0] & 0x10 == 0)
        .cloned()
        .collect();
    assert!(!data.is_empty());
    for d in &data {
        b.udp.from_ground(d.clone());
    }
    b.udp.sent.clear();
    for _ in 0..600 {
        b.clock.0 += 1;
        glue.poll(&mut b.clock, &mut b.udp, &mut b.board);
    }
    let sec = glue.gateway().security(BoardNumber::ONE).unwrap();
    assert_eq!(sec.refused_for("replay") as usize, data.len(), "{sec:?}");
    assert_eq!(sec.accepted, 0);
    let before = b.tm_ivs.iter().max().copied().unwrap();
    assert!(!b.udp.sent.is_empty());
    for f in &b.udp.sent {
        let iv = bench::iv(f);
        assert!(
            iv > before,
            "a TM IV {iv} at or below {before} after the reset"
        );
    }
}
