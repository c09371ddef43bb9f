//! The ground's PUS link across a ground restart (decision `restart-ground`), which robot an
//! APID names, an ST[1] report written into too small a buffer, and the link's edges:
//! telemetry that does not read, rejections, one TC at a time, a motion's end given up, the
//! heartbeat request's TC(17,1).

use mmic::node::ground::pus::{Config, TcLink};
use mmic::pus::robot_of_apid;
use mmic::pus::verification::{Failure, Report, RequestId, Stage, FAILURE_LEN, SUCCESS_LEN};
use mmic::pus::ROBOT_APID_BASE;
use mmic::units::BoardNumber;

/// A restarted ground's link numbers on from the count it kept (its low 14 bits), and keeps
/// numbering from there when restarted again.
#[test]
fn a_restarted_ground_numbers_on_from_the_kept_count() {
    let board = BoardNumber::new(3).unwrap();
    let fresh = TcLink::new(Config::default(), board);
    assert_eq!(fresh.next_count(), 0);
    let link = TcLink::starting_at(Config::default(), board, 0x4005);
    assert_eq!(link.next_count(), 5);
    assert_eq!(link.apid(), fresh.apid());
    assert_eq!(link.restarted().next_count(), 5);
}

/// An APID names a robot only inside the robots' block, above its base.
#[test]
fn only_the_robots_block_names_a_robot() {
    assert_eq!(robot_of_apid(ROBOT_APID_BASE + 1), Some(BoardNumber::ONE));
    assert_eq!(
        robot_of_apid(ROBOT_APID_BASE + 255).map(BoardNumber::get),
        Some(255)
    );
    for apid in [0, ROBOT_APID_BASE, ROBOT_APID_BASE + 256, 0x7ff] {
        assert_eq!(robot_of_apid(apid), None, "{apid:#x}");
    }
}

/// A report's source data does not fit a shorter buffer: nothing is written, 0.
#[test]
fn a_report_into_too_small_a_buffer_writes_nothing() {
    let request = RequestId {
        apid: ROBOT_APID_BASE + 1,
        seq_count: 9,
    };
    let ok = Report {
        stage: Stage::Start,
        request,
        failure: None,
    };
    let failed = Report {
        failure: Some(Failure { code: 3, data: 7 }),
        ..ok
    };
    for (r, len) in [(ok, SUCCESS_LEN), (failed, FAILURE_LEN)] {
        let mut big = [0xeeu8; FAILURE_LEN];
        assert_eq!(r.emit(&mut big), len);
        let mut short = vec![0xeeu8; len - 1];
        assert_eq!(r.emit(&mut short), 0);
        assert!(short.iter().all(|&b| b == 0xee));
    }
}

fn arm_extend() -> mmic::command::Command {
    mmic::command::Command::Arm {
        side: mmic::units::Side::A,
        target: mmic::command::ServoTarget::Extend,
    }
}

fn report(link: &TcLink, seq_count: u16, stage: Stage, failure: Option<Failure>) -> Report {
    Report {
        stage,
        request: RequestId {
            apid: link.apid(),
            seq_count,
        },
        failure,
    }
}

/// Telemetry that does not read tells the link nothing: a malformed ST[1] report, a malformed
/// ST[3] housekeeping report (the status stays unknown), a service the link does not follow.
#[test]
fn telemetry_that_does_not_read_tells_nothing() {
    use mmic::node::ground::link::Link;
    use mmic::node::ground::pus::Heard;
    let mut link = TcLink::new(Config::default(), BoardNumber::ONE);
    let seq = link.submit(arm_extend()).unwrap();
    link.tick(0);
    let before = link;
    for (service, subservice, data) in [
        (1u8, 1u8, &[0xffu8][..]),
        (3, 25, &[1, 2, 3]),
        (200, 1, &[]),
    ] {
        let heard = link.telemetry(service, subservice, data);
        assert_eq!(heard, Heard::default(), "TM({service},{subservice})");
    }
    assert_eq!(link.status(), None);
    assert_eq!(link, before);
    assert_eq!(link.outstanding(), Some(seq));
}

/// ST[1] reports the link does not take as an outcome: one for another robot's APID is
/// ignored; a failed acceptance, and a failed start whose code is no refusal (nor one of the
/// gateway's own), are handed up as rejections with their numbers, the TC no longer pending.
#[test]
fn rejections_and_reports_for_others_over_pus() {
    use mmic::node::ground::link::Link;
    let mut link = TcLink::new(Config::default(), BoardNumber::ONE);
    let seq = link.submit(arm_extend()).unwrap();
    link.tick(0);
    let other = Report {
        request: RequestId {
            apid: link.apid() + 1,
            seq_count: seq,
        },
        ..report(&link, seq, Stage::Acceptance, None)
    };
    assert_eq!(link.report(&other), Default::default());
    assert_eq!(link.outstanding(), Some(seq));

    let bad = Failure {
        code: 5,
        data: 0x0102,
    };
    let heard = link.report(&report(&link, seq, Stage::Acceptance, Some(bad)));
    assert_eq!(heard.rejected, Some((seq, bad)));
    assert_eq!(heard.done, None);
    assert_eq!(link.outstanding(), None);

    let seq = link.submit(arm_extend()).unwrap();
    link.tick(10);
    link.report(&report(&link, seq, Stage::Acceptance, None));
    let odd = Failure {
        code: 0x0300,
        data: 0,
    };
    let heard = link.report(&report(&link, seq, Stage::Start, Some(odd)));
    assert_eq!(heard.rejected, Some((seq, odd)));
    assert_eq!((heard.done, link.outstanding()), (None, None));
}

/// One TC at a time: a submit while another awaits its start is refused (no number given).
#[test]
fn a_submit_while_a_tc_awaits_its_start_is_refused() {
    use mmic::node::ground::link::Link;
    let mut link = TcLink::new(Config::default(), BoardNumber::ONE);
    let seq = link.submit(arm_extend()).unwrap();
    assert_eq!(link.submit(mmic::command::Command::Stop), None);
    assert_eq!(link.outstanding(), Some(seq));
    assert!(!link.is_idle());
}

/// A started motion whose completion is never reported: the link asks for it every query
/// period, `max_attempts` times, then gives it up as an end not heard.
#[test]
fn a_motions_unreported_end_is_given_up_after_max_attempts() {
    use mmic::node::exactly_once::uplink::Outcome;
    use mmic::node::ground::link::{Link, MotionEnd};
    let cfg = Config {
        query_ms: 100,
        max_attempts: 3,
        ..Config::default()
    };
    let mut link = TcLink::new(cfg, BoardNumber::ONE);
    let seq = link.submit(arm_extend()).unwrap();
    link.tick(0);
    link.report(&report(&link, seq, Stage::Acceptance, None));
    let started = link.report(&report(&link, seq, Stage::Start, None));
    assert_eq!(started.done.map(|d| d.outcome), Some(Outcome::Accepted));
    let (mut queries, mut ended) = (0, None);
    for now in (10..10_000).step_by(10) {
        let t = link.tick(now);
        if let Some(q) = t.send {
            assert_eq!(q.request.seq_count, seq, "a query for the motion");
            queries += 1;
        }
        if t.ended.is_some() {
            assert_eq!(t.attempt, Some(false));
            ended = t.ended;
            break;
        }
    }
    assert_eq!(ended, Some((seq, MotionEnd::Unacknowledged)));
    assert_eq!(queries, 3);
}

/// A heartbeat request goes out as TC(17,1) with no application data; a function as TC(8,1).
#[test]
fn a_heartbeat_request_is_tc_17_1_without_data() {
    use mmic::ccsds::tc::TcRepr;
    use mmic::node::ground::pus::{TcOut, MAX_TC_LEN};
    let request = RequestId {
        apid: ROBOT_APID_BASE + 1,
        seq_count: 7,
    };
    let hb = TcOut {
        request,
        source_id: 4,
        command: mmic::command::Command::Heartbeat,
    };
    assert_eq!(hb.service(), (17, 1));
    let mut buf = [0u8; MAX_TC_LEN];
    let n = hb.emit(&mut buf).unwrap();
    let tc = TcRepr::parse(&buf[..n], &[request.apid]).unwrap();
    assert_eq!((tc.header.service, tc.header.subservice), (17, 1));
    assert_eq!(tc.header.source_id, 4);
    assert_eq!(tc.seq_count.get(), 7);
    assert!(tc.app_data.is_empty());
    let f = TcOut {
        command: arm_extend(),
        ..hb
    };
    assert_eq!(f.service(), (8, 1));
    let n = f.emit(&mut buf).unwrap();
    assert!(!TcRepr::parse(&buf[..n], &[request.apid])
        .unwrap()
        .app_data
        .is_empty());
}

/// A start failure with UNACKNOWLEDGED (board A never answered the gateway) or RESTARTED (the
/// gateway restarted after taking the TC) ends the TC as unacknowledged: run at most once,
/// its outcome not known; neither is read as a refusal.
#[test]
fn a_start_failure_unacknowledged_or_restarted_ends_the_tc_unacknowledged() {
    use mmic::node::exactly_once::uplink::Outcome;
    use mmic::node::ground::link::Link;
    use mmic::pus::verification::{RESTARTED, UNACKNOWLEDGED};
    for code in [UNACKNOWLEDGED, RESTARTED] {
        let mut link = TcLink::new(Config::default(), BoardNumber::ONE);
        let seq = link.submit(arm_extend()).unwrap();
        link.tick(0);
        link.report(&report(&link, seq, Stage::Acceptance, None));
        let failure = Failure { code, data: 0 };
        let heard = link.report(&report(&link, seq, Stage::Start, Some(failure)));
        assert_eq!(
            heard.done.map(|d| d.outcome),
            Some(Outcome::Unacknowledged),
            "{code:#06x}"
        );
        assert_eq!(
            (heard.rejected, link.outstanding()),
            (None, None),
            "{code:#06x}"
        );
    }
}
