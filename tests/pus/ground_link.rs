//! The ground's PUS link across a ground restart (decision `restart-ground`), which robot an
//! APID names, and an ST[1] report written into too small a buffer.

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
