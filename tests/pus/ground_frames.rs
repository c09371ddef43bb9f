//! The ground's end of the space data link ([`GroundLink`]) at its edges, against the server
//! board's [`FrameGateway`] with no loss: a TM frame refused by its own check, a frame whose
//! OCF holds no CLCW, the alerts of timer T1 and of the transmission limit and the
//! re-initiation after them, a frame SDLS cannot protect yet.

use mmic::link::fop::{FopConfig, FopState};
use mmic::node::ground::frames::{GroundLink, TmRefusal};
use mmic::node::server::frames::{FrameConfig, FrameGateway};
use mmic::units::BoardNumber;

type Server = FrameGateway<1, 4, 64, 4096>;
type Ground = GroundLink<10, 64, 1024>;

fn server() -> Server {
    let mut s = Server::new(FrameConfig::default());
    assert!(s.add(BoardNumber::ONE));
    s
}

/// The next TM frame the server board sends (with its CLCW), at or after `now`.
fn tm_frame(server: &mut Server, now: u32) -> Vec<u8> {
    let mut buf = [0u8; 2048];
    for t in now..now + 10_000 {
        if let Some((_, n)) = server.frame(t, &mut buf) {
            return buf[..n].to_vec();
        }
    }
    panic!("no TM frame in 10 s");
}

/// A ground link made Active by the server's first CLCW; the TC frames it sent so far.
fn active(fop: FopConfig) -> (Ground, Server, Vec<Vec<u8>>) {
    let mut ground = Ground::with(BoardNumber::ONE, fop);
    let mut server = server();
    let mut sent = Vec::new();
    ground.start(0, &mut |f: &[u8]| sent.push(f.to_vec()));
    assert_eq!(ground.state(), FopState::InitialisingWithoutBc);
    let f = tm_frame(&mut server, 0);
    ground
        .tm_frame(0, &f, &mut |t: &[u8]| sent.push(t.to_vec()), &mut |_| {})
        .unwrap();
    assert_eq!(ground.state(), FopState::Active);
    (ground, server, sent)
}

/// A TM frame failing its frame check is refused by that check's name, and counted.
#[test]
fn a_tm_frame_failing_its_check_is_refused_by_the_checks_name() {
    let mut ground = Ground::new(BoardNumber::ONE);
    let mut f = tm_frame(&mut server(), 0);
    f[0] ^= 0x40; // the version field
    let e = ground
        .tm_frame(0, &f, &mut |_| {}, &mut |_| {})
        .unwrap_err();
    let TmRefusal::Frame(inner) = e else {
        panic!("refused by SDLS on a link without it: {e:?}");
    };
    assert_eq!(e.name(), inner.name());
    assert_eq!(ground.counters().tm_refused, 1);
}

/// A TM frame whose OCF holds no CLCW (its first bit says another report) still gives its
/// packets; FOP-1 learns nothing from it (no CLCW counted).
#[test]
fn a_tm_frame_without_a_clcw_gives_no_clcw() {
    let (mut ground, mut server, _) = active(FopConfig::MISSION);
    let clcws = ground.counters().clcws;
    let mut f = tm_frame(&mut server, 100);
    let n = f.len();
    f[n - 6] |= 0x80; // the OCF's type flag: a project-specific report, no CLCW
    let crc = mmic::ccsds::pec(&f[..n - 2]);
    f[n - 2..].copy_from_slice(&crc.to_be_bytes());
    assert_eq!(
        ground.tm_frame(100, &f, &mut |_| panic!("nothing to send"), &mut |_| {}),
        Ok(())
    );
    assert_eq!(ground.counters().clcws, clcws);
    assert_eq!(ground.counters().tm_refused, 0);
}

/// An AD frame never acknowledged: FOP-1 sends it again at each expiry of timer T1 (its
/// deadline told to the shell) until the transmission limit, then alerts (T1); the packet goes
/// back to the outbox and the link initiates itself again.
#[test]
fn t1_expiring_at_the_limit_alerts_and_the_link_initiates_again() {
    let fop = FopConfig {
        tx_limit: 3,
        t1_ms: 500,
        ..FopConfig::MISSION
    };
    let (mut ground, _server, _) = active(fop);
    assert_eq!(
        ground.next_deadline(),
        None,
        "nothing outstanding, no timer"
    );
    let mut sent = 0;
    ground
        .send(&crate::pus::function_tc(1, &[6]), 1000, &mut |_| sent += 1)
        .unwrap();
    assert_eq!((sent, ground.waiting()), (1, 0));
    let mut expiries = 0;
    while ground.counters().alerts[1] == 0 {
        let at = ground
            .next_deadline()
            .expect("T1 runs while the frame is outstanding");
        assert_eq!(at, 1000 + 500 * (expiries + 1), "T1's expiry");
        ground.tick(at, &mut |_| sent += 1);
        expiries += 1;
        assert!(expiries <= 3, "no alert after {expiries} expiries");
    }
    let c = *ground.counters();
    assert_eq!(c.ad_frames, 3, "sent {} times in all", c.ad_frames);
    assert_eq!(c.alerts, [0, 1, 0, 0, 0, 0, 0], "T1's alert");
    assert_eq!(
        (c.purged, ground.waiting()),
        (1, 1),
        "the packet back in the outbox"
    );
    assert_eq!(c.initiations, 2);
}

/// FARM-1 asks for a retransmission (a frame lost before one it received) on a link whose
/// transmission limit is one (no retransmission allowed): FOP-1 alerts (LIMIT, 232.1-B-2's
/// E102), and both packets go back to the outbox for the re-initiated link.
#[test]
fn retransmissions_asked_for_past_the_limit_alert_limit() {
    let fop = FopConfig {
        tx_limit: 1,
        ..FopConfig::MISSION
    };
    let (mut ground, mut server, _) = active(fop);
    let mut frames = Vec::new();
    for seq in [1, 2] {
        ground
            .send(
                &crate::pus::function_tc(seq, &[6]),
                10,
                &mut |f: &[u8]| frames.push(f.to_vec()),
            )
            .unwrap();
    }
    assert_eq!(frames.len(), 2);
    // The first is lost, the second arrives: FARM-1 sees the gap and asks for retransmission.
    server.tc_frame(20, &frames[1]);
    let mut now = 30;
    while ground.counters().alerts[0] == 0 && now < 10_000 {
        let f = tm_frame(&mut server, now);
        // Every retransmission is lost too.
        ground.tm_frame(now, &f, &mut |_| {}, &mut |_| {}).unwrap();
        now += 100;
    }
    let c = *ground.counters();
    assert_eq!(c.alerts, [1, 0, 0, 0, 0, 0, 0], "LIMIT");
    assert_eq!(ground.waiting(), 2, "both packets back in the outbox");
    assert!(c.initiations >= 2);
}

/// On a secured link, an AD frame whose IV counter is not reserved yet (the shell has not
/// written the TC reservation) is not sent, and counted; once it is written, T1 sends it.
#[test]
fn a_frame_sdls_cannot_protect_yet_waits_for_the_reservation() {
    use mmic::link::sdls::{mission, Key256};
    use mmic::node::server::frames::Stored;
    let key = |b: u8| Key256::from_slice(&[b; 32]).unwrap();
    let mut server = server();
    assert!(server
        .secure(BoardNumber::ONE, key(0x5a), key(0xa5), Stored::default())
        .is_ok());
    for e in server.durable_due::<16>() {
        assert!(server.durable_written(&e));
    }
    let mut ground = Ground::new(BoardNumber::ONE);
    ground.secure(key(0x5a), key(0xa5), (None, None));
    let mut sent = Vec::new();
    ground.start(0, &mut |f: &[u8]| sent.push(f.to_vec()));
    // The TM floor written, the TC reservation not yet.
    let tm_spi = mission::tm_spi(BoardNumber::ONE);
    for (spi, v) in ground.due().collect::<Vec<_>>() {
        if spi == tm_spi {
            assert!(ground.persisted(spi, v));
        }
    }
    let f = tm_frame(&mut server, 0);
    let r = ground.tm_frame(0, &f, &mut |_| {}, &mut |_| {});
    assert_eq!(r, Ok(()));
    assert_eq!(ground.state(), FopState::Active);
    ground
        .send(&crate::pus::function_tc(1, &[6]), 10, &mut |f: &[u8]| {
            sent.push(f.to_vec())
        })
        .unwrap();
    assert!(sent.is_empty(), "nothing sent unprotected");
    assert_eq!(ground.counters().unprotected, 1);
    for (spi, v) in ground.due().collect::<Vec<_>>() {
        assert!(ground.persisted(spi, v));
    }
    let at = ground.next_deadline().unwrap();
    ground.tick(at, &mut |f: &[u8]| sent.push(f.to_vec()));
    assert_eq!(sent.len(), 1, "sent once the reservation is written");
    assert_eq!(ground.counters().unprotected, 1);
}
